"""The rest of an instruction as context, on hand-built parses (no model): what is kept, what is the
request or the frame itself, and that context reaches only the scorers that read text."""

from __future__ import annotations

from lmcr.lexicon import load_lexicon
from lmcr.srl.context import antecedents, served_in, utterance_context
from lmcr.srl.mentions import FrameMention
from tests.srl_docs import make_doc


def mention(doc, predicate: int, roles: dict[str, int | None]) -> FrameMention:
    """A frame whose predicate and role heads are the tokens at these indices."""
    pred = doc[predicate]
    spans = {r: (doc[i].idx, doc[i].idx + len(doc[i])) for r, i in roles.items() if i is not None}
    values = {r: (doc[i].lower_ if i is not None else None) for r, i in roles.items()}
    return FrameMention(pred.lemma_, values, True, pred.idx, pred.idx + len(pred), spans)


def test_purpose_phrase_is_context():
    doc = make_doc("heat/VB/ROOT/0 the/DT/det/2 water/NN/dobj/0 for/IN/prep/0 my/PRP$/poss/5 tea/NN/pobj/3")
    assert utterance_context(doc, mention(doc, 0, {"Theme": 2, "Instrument": None})) == "for my tea"


def test_the_person_served_is_the_request_not_context():
    doc = make_doc(
        "pour/VB/ROOT/0 me/PRP/dative/0 some/DT/det/3 water/NN/dobj/0 for/IN/prep/3 my/PRP$/poss/6 tea/NN/pobj/4"
    )
    assert utterance_context(doc, mention(doc, 0, {"Theme": 3, "Destination": None})) == "for my tea"
    doc = make_doc("give/VB/ROOT/0 the/DT/det/2 dog/NN/dative/0 some/DT/det/4 water/NN/dobj/0")  # a noun is kept
    assert utterance_context(doc, mention(doc, 0, {"Theme": 4, "Destination": None})) == "the dog"


def test_request_and_function_words_alone_are_no_context():
    doc = make_doc(
        "could/MD/aux/2 you/PRP/nsubj/2 pour/VB/ROOT/2 the/DT/det/4 milk/NN/dobj/2 for/IN/prep/2 "
        "me/PRP/pobj/5 ?/./punct/2"
    )
    assert utterance_context(doc, mention(doc, 2, {"Theme": 4, "Destination": None})) == ""


def test_a_second_clause_is_context_and_the_request_is_not():
    doc = make_doc(
        "I/PRP/nsubj/1 need/VBP/ROOT/1 you/PRP/nsubj/4 to/TO/aux/4 fill/VB/xcomp/1 the/DT/det/6 "
        "bowl/NN/dobj/4 ,/,/punct/1 the/DT/det/9 dog/NN/nsubj/10 is/VBZ/ccomp/1 thirsty/JJ/acomp/10"
    )
    assert utterance_context(doc, mention(doc, 4, {"Destination": 6, "Theme": None})) == "the dog is thirsty"


def test_a_clause_before_the_request_is_context_when_it_says_something():
    doc = make_doc(
        "I/PRP/nsubj/1 'm/VBP/ROOT/1 thirsty/JJ/acomp/1 ,/,/punct/1 pour/VB/conj/1 me/PRP/dative/4 "
        "some/DT/det/7 water/NN/dobj/4"
    )
    assert utterance_context(doc, mention(doc, 4, {"Theme": 7, "Destination": None})) == "i 'm thirsty"
    doc = make_doc("please/UH/intj/2 ,/,/punct/2 pour/VB/ROOT/2 the/DT/det/4 wine/NN/dobj/2")
    assert utterance_context(doc, mention(doc, 2, {"Theme": 4, "Destination": None})) == ""
    doc = make_doc(
        "ok/UH/intj/6 ,/,/punct/6 so/RB/advmod/6 ,/,/punct/6 could/MD/aux/6 you/PRP/nsubj/6 fill/VB/ROOT/6 "
        "the/DT/det/8 glass/NN/dobj/6"
    )
    assert utterance_context(doc, mention(doc, 6, {"Destination": 8, "Theme": None})) == ""


def test_placeholder_object_particle_and_stated_role_prepositions_are_the_frame():
    doc = make_doc(
        "dump/VB/ROOT/0 some/DT/dobj/0 into/IN/prep/0 the/DT/det/4 pot/NN/pobj/2 to/TO/aux/6 boil/VB/advcl/0"
    )
    assert utterance_context(doc, mention(doc, 0, {"Theme": None, "Destination": 4})) == "to boil"
    doc = make_doc("rub/VB/ROOT/0 the/DT/det/2 salt/NN/dobj/0 in/RP/prt/0")
    assert utterance_context(doc, mention(doc, 0, {"Theme": 2, "Destination": None})) == ""


def test_a_role_the_robot_cannot_ground_is_said_words_read_as_context():
    doc = make_doc(
        "pour/VB/ROOT/0 a/DT/det/3 little/JJ/amod/3 milk/NN/dobj/0 in/IN/prep/0 my/PRP$/poss/6 coffee/NN/pobj/4"
    )
    pour = mention(doc, 0, {"Theme": 3, "Destination": 6})
    assert utterance_context(doc, pour) == ""  # "in my coffee" is the frame's Destination
    assert utterance_context(doc, pour, said=frozenset({"Destination"})) == "in my coffee"
    doc = make_doc("fill/VB/ROOT/0 the/DT/det/2 thermos/NN/dobj/0")  # a said object is no placeholder
    assert (
        utterance_context(doc, mention(doc, 0, {"Destination": 2, "Theme": None}), said=frozenset({"Destination"}))
        == "the thermos"
    )


def test_only_text_reading_scorers_see_the_context(monkeypatch):
    from lmcr.scorers import registry as methods
    from lmcr.scorers.resources import MethodResources

    seen = {}

    def fake(name, reads):
        def build(res):
            def score(frames, context=None):
                seen[name] = context
                return [0.0] * len(frames)

            return score

        return methods.ScorerSpec(build, reads_context=reads)

    monkeypatch.setitem(methods.SCORERS, "reader", fake("reader", True))
    monkeypatch.setitem(methods.SCORERS, "counter", fake("counter", False))
    scorer = methods.make_scorer("reader+counter", MethodResources(checkpoints=__import__("pathlib").Path(".")))
    assert scorer([("pour", {"Theme": "milk", "Destination": "mug"})], "for my tea") == [0.0]
    assert seen == {"reader": "for my tea", "counter": None}


def test_a_pronoun_role_refers_back_to_the_nouns_before_it_that_agree():
    doc = make_doc(
        "I/PRP/nsubj/2 'd/MD/aux/2 love/VB/ROOT/2 some/DT/det/4 wine/NN/dobj/2 ,/,/punct/2 could/MD/aux/8 "
        "you/PRP/nsubj/8 pour/VB/ccomp/2 it/PRP/dobj/8 ?/./punct/2"
    )
    wine = mention(doc, 8, {"Theme": 9, "Destination": None})
    assert antecedents(doc, wine, "Theme", load_lexicon()) == ["wine"]
    assert antecedents(doc, wine, "Destination", load_lexicon()) == []  # no pronoun there
    doc = make_doc(
        "take/VB/ROOT/0 the/DT/det/2 strawberries/NNS/dobj/0/strawberry and/CC/cc/0 dip/VB/conj/0 "
        "them/PRP/dobj/4 in/IN/prep/4 the/DT/det/9 melted/JJ/amod/9 chocolate/NN/pobj/6"
    )
    dip = mention(doc, 4, {"Theme": 5, "Destination": 9})
    assert antecedents(doc, dip, "Theme", load_lexicon()) == ["strawberry"]  # the chocolate is after, and a role
    doc = make_doc(
        "the/DT/det/1 bread/NN/nsubj/2 is/VBZ/ROOT/2 here/RB/advmod/2 ,/,/punct/2 dip/VB/conj/2 them/PRP/dobj/5"
    )
    assert antecedents(doc, mention(doc, 5, {"Theme": 6, "Destination": None}), "Theme", load_lexicon()) == []  # number


def test_an_antecedent_is_a_verbs_argument_before_a_prepositions_and_never_the_frames_own_words():
    doc = make_doc(
        "take/VB/ROOT/0 the/DT/det/2 pan/NN/dobj/0 from/IN/prep/0 the/DT/det/5 sink/NN/pobj/3 and/CC/cc/0 "
        "heat/VB/conj/0 some/DT/det/9 oil/NN/dobj/7 in/IN/prep/7 it/PRP/pobj/10"
    )
    heat = mention(doc, 7, {"Theme": 9, "Instrument": 11})
    assert antecedents(doc, heat, "Instrument", load_lexicon()) == ["pan", "sink"]  # not the oil: the frame's Theme


def test_a_request_that_serves_someone_names_the_vessel_as_its_measure():
    doc = make_doc("pour/VB/ROOT/0 me/PRP/dative/0 a/DT/det/3 glass/NN/dobj/0 of/IN/prep/3 water/NN/pobj/4")
    assert served_in(doc, mention(doc, 0, {"Theme": 5, "Destination": None}), load_lexicon()) == "glass"
    doc = make_doc("pour/VB/ROOT/0 me/PRP/dobj/0 the/DT/det/3 mugs/NNS/dobj/0/mug of/IN/prep/3 tea/NN/pobj/4")
    assert served_in(doc, mention(doc, 0, {"Theme": 5, "Destination": None}), load_lexicon()) is None  # mugs: counted
    for spec in (
        "pour/VB/ROOT/0 a/DT/det/2 cup/NN/dobj/0 of/IN/prep/2 milk/NN/pobj/3",  # nobody served
        "pour/VB/ROOT/0 me/PRP/dobj/0 half/PDT/predet/4 a/DT/det/4 cup/NN/dobj/0 of/IN/prep/4 milk/NN/pobj/5",
        "pour/VB/ROOT/0 me/PRP/dative/0 two/CD/nummod/3 cup/NN/dobj/0 of/IN/prep/3 tea/NN/pobj/4",
        "pour/VB/ROOT/0 me/PRP/dative/0 a/DT/det/3 lot/NN/dobj/0 of/IN/prep/3 tea/NN/pobj/4",  # no measure
        "pour/VB/ROOT/0 me/PRP/dative/0 some/DT/det/3 water/NN/dobj/0",
    ):
        doc = make_doc(spec)
        theme = next(t.i for t in doc if t.dep_ == "pobj" or t.lower_ == "water")
        assert served_in(doc, mention(doc, 0, {"Theme": theme, "Destination": None}), load_lexicon()) is None, spec
