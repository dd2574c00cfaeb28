"""Mending compounds the parser split (hand-built parses, no model)."""

from __future__ import annotations

from lmcr.lexicon import load_lexicon
from lmcr.srl.compounds import Compounds
from lmcr.srl.mentions import extract_frames
from lmcr.srl.repair import rejoin_split_compounds
from tests.srl_docs import make_doc

LEX = load_lexicon()
LEARNED = Compounds(strong_bigrams=frozenset({"bay leaves", "chili flakes", "bread crumbs"}))


def roles(spec: str, compounds: Compounds | None) -> list[dict]:
    doc = rejoin_split_compounds(make_doc(spec), compounds)
    return [f.roles for f in extract_frames(doc, LEX, compounds) if f.known]


def test_plural_read_as_a_verb_with_the_noun_as_subject():
    spec = (
        "sprinkle/VB/ROOT/0 the/DT/det/2 bay/NN/nsubj/3 leaves/VBZ/ccomp/0/leaf over/IN/prep/3 "
        "the/DT/det/6 stew/NN/pobj/4"
    )
    assert roles(spec, None) == [{"Theme": None, "Destination": None}]  # nothing learned: left as parsed
    assert roles(spec, LEARNED) == [{"Theme": "bay leaf", "Destination": "stew"}]


def test_plural_read_as_a_verb_of_its_own():
    spec = (
        "pour/VB/ROOT/0 the/DT/det/3 hot/JJ/amod/3 oil/NN/dobj/0 over/IN/prep/3 the/DT/det/6 "
        "chili/NN/pobj/4 flakes/VBZ/conj/0/flake"
    )
    assert roles(spec, LEARNED) == [{"Theme": "oil", "Destination": "chili flake"}]


def test_plural_read_as_a_second_object():
    spec = (
        "sprinkle/VB/ROOT/0 the/DT/det/2 bread/NN/dobj/0 crumbs/NNS/dobj/0/crumb over/IN/prep/3 "
        "the/DT/det/6 casserole/NN/pobj/4"
    )
    assert roles(spec, None) == [{"Theme": "bread", "Destination": "casserole"}]
    assert roles(spec, LEARNED) == [{"Theme": "bread crumb", "Destination": "casserole"}]
    # a pair the corpus does not join stays as parsed
    assert roles(spec, Compounds(strong_bigrams=frozenset({"bay leaves"}))) == [
        {"Theme": "bread", "Destination": "casserole"}
    ]


def test_a_gerund_read_as_a_verb_with_its_object():
    """Terse narrations: "pour oil in frying pan" is no fry frame of the pan but a pour into it."""
    learned = Compounds(strong_bigrams=frozenset({"frying pan"}))
    spec = "pour/VB/ROOT/0 oil/NN/dobj/0 in/IN/prep/0 frying/VBG/pcomp/2/fry pan/NN/dobj/3"
    doc = rejoin_split_compounds(make_doc(spec), learned)
    assert [(f.predicate, f.roles) for f in extract_frames(doc, LEX, learned)] == [
        ("pour", {"Theme": "oil", "Destination": "frying pan"})
    ]
    assert [(f.predicate, f.roles) for f in extract_frames(make_doc(spec), LEX, None) if f.known] == [
        ("pour", {"Theme": "oil", "Destination": None}),
        ("fry", {"Theme": "pan", "Instrument": None}),
    ]
    stir = rejoin_split_compounds(make_doc("stir/VB/ROOT/0 frying/VBG/xcomp/0/fry pan/NN/dobj/1"), learned)
    assert [(t.text, t.dep_, t.head.text) for t in stir] == [
        ("stir", "ROOT", "stir"),
        ("frying", "compound", "pan"),
        ("pan", "dobj", "stir"),
    ]
    # a gerund and its object the corpus does not join are a verb and its object
    spec = "start/VB/ROOT/0 frying/VBG/xcomp/0/fry onions/NNS/dobj/1/onion"
    assert roles(spec, learned) == [{"Theme": "onion", "Instrument": None}]
