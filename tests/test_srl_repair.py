"""Mending compounds the parser split (hand-built parses, no model)."""

from __future__ import annotations

from lmcr.lexicon import load_lexicon
from lmcr.srl.compounds import Compounds
from lmcr.srl.mentions import extract_frames
from lmcr.srl.repair import mend_modal_nouns, rejoin_split_compounds
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


def modal_mended(spec: str) -> list[tuple[str, dict]]:
    doc = mend_modal_nouns(make_doc(spec))
    return [(f.predicate, f.roles) for f in extract_frames(doc, LEX, None) if f.known]


def test_a_noun_read_as_a_modal_is_the_noun_of_its_phrase():
    """ "can" after the words of a noun phrase and before no verb is the noun: as a preposition's object,
    in the place of the adjective the parser made the object, and as the sentence's head, the verb read as
    its subject."""
    assert modal_mended("dump/VB/ROOT/0 it/PRP/dobj/0 into/IN/prep/0 that/DT/det/5 empty/JJ/amod/5 can/MD/pobj/2") == [
        ("dump", {"Theme": "it", "Destination": "can"})
    ]
    assert modal_mended("dump/VB/ROOT/0 the/DT/det/2 empty/JJ/dobj/0 can/MD/punct/0") == [
        ("dump", {"Theme": "can", "Destination": None})
    ]
    assert modal_mended("pour/NN/nsubj/4 into/IN/prep/0 the/DT/det/3 empty/JJ/pobj/1 can/MD/ROOT/4") == [
        ("pour", {"Theme": None, "Destination": "can"})
    ]


def test_a_modal_that_governs_a_verb_stays_one():
    spec = "you/PRP/nsubj/2 can/MD/aux/2 pour/VB/ROOT/2 the/DT/det/4 milk/NN/dobj/2"
    assert modal_mended(spec) == [("pour", {"Theme": "milk", "Destination": None})]
    spec = "the/DT/det/1 milk/NN/nsubj/3 can/MD/aux/3 boil/VB/ROOT/3"
    assert [t.tag_ for t in mend_modal_nouns(make_doc(spec))] == ["DT", "NN", "MD", "VB"]
