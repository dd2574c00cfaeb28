"""The stated_pmi term: the sentence LM's score less its score with the stated fillers unsaid, within a
role; model-free (a stand-in LM whose log-probabilities are the fillers' priors plus their association)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from lmcr.frame import Frame
from lmcr.scorers import registry
from lmcr.scorers.resources import MethodResources
from lmcr.scorers.stated_pmi import PLACEHOLDER, WEIGHT, masked, stated_pmi_scorer, stated_roles

# "bed" is said far more often than "hamper" after any Theme; a stained shirt goes with the hamper. An
# apple is disposed of far more often than a coke; a coke goes with the recycling bin.
PRIOR = {"bed": -2.0, "hamper": -6.0, "table": -3.0, "recycling bin": -4.0, "apple": -1.0, "coke": -5.0}
ASSOCIATION = {("stained shirt", "hamper"): 3.5, ("book", "table"): 1.0, ("coke", "recycling bin"): 2.0}
LEARNED = frozenset({"put away", "dispose", "wipe", "pour", "heat"})


class StandInLM:
    """log P(frame) = the Theme's and the Destination's priors + their association ("it" has neither);
    it keeps every frame it was asked about."""

    def __init__(self):
        self.asked: list[Frame] = []

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]:
        self.asked += frames
        out = []
        for frame in frames:
            roles = frame.role_map
            theme, place = roles.get("Theme", ""), roles.get("Destination", "")
            prior = PRIOR.get(place, -4.0) + PRIOR.get(theme, 0.0)
            out.append(prior + ASSOCIATION.get((theme, place), 0.0) - len(context) / 100)
        return out


def put_away(theme: str, place: str) -> Frame:
    return Frame.of("put away", {"Theme": theme, "Destination": place})


def dispose(theme: str, place: str) -> Frame:
    return Frame.of("dispose", {"Theme": theme, "Destination": place})


def test_the_term_undoes_the_fillers_prior_and_keeps_what_the_theme_says():
    lm = StandInLM()
    frames = [put_away("stained shirt", "bed"), put_away("stained shirt", "hamper")]
    plain = lm(frames)
    summed = [p + t for p, t in zip(plain, stated_pmi_scorer(lm, LEARNED)(frames))]
    assert plain[0] > plain[1]  # the LM alone: the bed
    assert summed[1] > summed[0]  # with the term: the hamper
    assert lm.asked[2:] == [put_away(PLACEHOLDER, "bed"), put_away(PLACEHOLDER, "hamper")]
    # at weight 1 what is left is the association alone (the prior cancels), centred
    pure = stated_pmi_scorer(lm, LEARNED, weight=1.0)(frames)
    assert [p + t - (plain[0] + pure[0]) for p, t in zip(plain, pure)] == pytest.approx([0.0, 3.5])


def test_the_term_is_centred_and_weighed():
    places = ("bed", "hamper", "table")
    scores = stated_pmi_scorer(StandInLM(), LEARNED)([put_away("book", p) for p in places])
    assert sum(scores) == pytest.approx(0.0)
    mean = sum(PRIOR[p] for p in places) / 3
    assert scores == pytest.approx([-WEIGHT * (PRIOR[p] - mean) for p in places])


def test_a_stated_place_is_masked_when_the_theme_is_the_candidate():
    """ "dispose of it in the recycling bin": which thing? The apple's own frequency is taken out."""
    lm = StandInLM()
    frames = [dispose("apple", "recycling bin"), dispose("coke", "recycling bin")]
    assert stated_roles(frames) == ["Destination"]
    plain = lm(frames)
    summed = [p + t for p, t in zip(plain, stated_pmi_scorer(lm, LEARNED)(frames))]
    assert plain[0] > plain[1] and summed[1] > summed[0]
    assert lm.asked[2:] == [dispose("apple", PLACEHOLDER), dispose("coke", PLACEHOLDER)]


def test_where_every_role_varies_the_theme_is_masked_and_where_none_does_nothing_is():
    """ "Can you dispose of it?" fills the Theme and the place from the scene; a lone frame ranks nothing."""
    both = [dispose("apple", "bed"), dispose("coke", "recycling bin")]
    assert stated_roles(both) == ["Theme"]
    assert stated_roles([both[0], both[0]]) == [] and stated_roles(both[:1]) == []
    lm = StandInLM()
    assert stated_pmi_scorer(lm, LEARNED)(both[:1]) == [0.0] and lm.asked == []
    assert masked(both[1], ["Theme"]) == dispose(PLACEHOLDER, "recycling bin")


def test_a_frame_without_a_theme_or_with_a_theme_alone_scores_zero():
    lm = StandInLM()
    frames = [Frame.of("wipe", {"Theme": "counter"}), Frame.of("pour", {"Destination": "cup"})]
    assert stated_pmi_scorer(lm, LEARNED)(frames + frames) == [0.0] * 4
    assert lm.asked == []


def test_roles_are_centred_apart_and_a_tool_is_left_to_the_verb():
    """A request whose candidates fill a place or a tool ("cut the bread": into the bowl, with the knife):
    each role's group is centred alone, and what a thing is done with is the verb's preference (TOOLS)."""
    lm = StandInLM()
    frames = [
        put_away("book", "bed"),
        put_away("book", "table"),
        Frame.of("put away", {"Theme": "book", "Instrument": "bed"}),
        Frame.of("put away", {"Theme": "book", "Instrument": "hamper"}),
    ]
    scores = stated_pmi_scorer(lm, LEARNED)(frames)
    assert scores[0] + scores[1] == pytest.approx(0.0) and scores[0] < 0  # the bed's prior is the higher
    assert scores[2:] == [0.0, 0.0]
    assert lm.asked == [put_away(PLACEHOLDER, "bed"), put_away(PLACEHOLDER, "table")]


def test_heating_in_a_glass_is_left_to_the_verb_and_the_eleven_score_zero():
    """Measured with tools masked too, "heat the milk" chose the glass on the dev instructions; the eleven
    are left out whatever their roles (`learned` names the predicates the term reads)."""
    lm = StandInLM()
    pour = [Frame.of("pour", {"Theme": "milk", "Destination": p}) for p in ("bed", "hamper")]
    assert stated_pmi_scorer(lm, LEARNED)(pour) != [0.0, 0.0]
    assert lm.asked == [Frame.of("pour", {"Theme": PLACEHOLDER, "Destination": p}) for p in ("bed", "hamper")]
    heat = [Frame.of("heat", {"Theme": "milk", "Instrument": i}) for i in ("pot", "glass")]
    assert stated_pmi_scorer(lm, LEARNED)(heat) == [0.0, 0.0] and len(lm.asked) == 2
    assert stated_pmi_scorer(lm, frozenset({"put away"}))(pour) == [0.0, 0.0] and len(lm.asked) == 2


def test_the_registry_term_reads_the_sentence_lm_the_method_loaded(tmp_path, monkeypatch):
    """'sentence_lm+stated_pmi' loads the checkpoint once, and reads the request's frames and the term's
    masked frames in one pass, with the context; a checkpoint trained again is loaded again. The sum is
    what the parts scored alone give."""
    loads, passes = [], []

    class Loaded:
        lex = None

        def __init__(self):
            loads.append(self)

        def score_frames(self, frames, context=""):
            passes.append(([list(frames)], context))
            return StandInLM()(frames, context)

        def score_frame_groups(self, groups, context=""):
            passes.append((groups, context))
            return [StandInLM()(group, context) for group in groups]

    manifest = {"sha": "a"}
    monkeypatch.setattr(registry, "load_lm", lambda res, lin, corpus: Loaded())
    monkeypatch.setattr(registry, "_lm_fingerprint", lambda lin: lambda res: manifest["sha"])
    monkeypatch.setattr(registry, "load_lexicon", lambda learned: SimpleNamespace(learned=LEARNED))
    registry._LAST_LM.clear()
    res = MethodResources(checkpoints=tmp_path, predicates=False)
    scorer = registry.make_scorer("sentence_lm+stated_pmi", res)
    frames = [put_away("stained shirt", "bed"), put_away("stained shirt", "hamper")]
    plain = registry.make_scorer("sentence_lm", res)(frames, "for my tea")
    term = registry.make_scorer("stated_pmi", res)(frames, "for my tea")
    passes.clear()
    summed = scorer(frames, "for my tea")
    assert len(loads) == 1 and summed[1] > summed[0] and plain[0] > plain[1]
    assert summed == pytest.approx([p + t for p, t in zip(plain, term)])
    masked_frames = [put_away(PLACEHOLDER, "bed"), put_away(PLACEHOLDER, "hamper")]
    assert passes == [([frames, masked_frames], "for my tea")]  # one pass, the context read after both
    assert registry.SCORERS["stated_pmi"].within_role and "stated_pmi" in registry.TERMS
    manifest["sha"] = "b"  # trained again
    registry.make_scorer("sentence_lm+stated_pmi", res)
    assert len(loads) == 2
    registry._LAST_LM.clear()
