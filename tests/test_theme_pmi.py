"""The theme_pmi term: the sentence LM's score less its score with the Theme unsaid, within a role; model-free
(a stand-in LM whose log-probabilities are a filler's prior plus a Theme-filler association)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from lmcr.frame import Frame
from lmcr.scorers import registry
from lmcr.scorers.resources import MethodResources
from lmcr.scorers.theme_pmi import PLACEHOLDER, WEIGHT, masked, theme_pmi_scorer

# "bed" is said far more often than "hamper" after any Theme; a stained shirt goes with the hamper
PRIOR = {"bed": -2.0, "hamper": -6.0, "table": -3.0}
ASSOCIATION = {("stained shirt", "hamper"): 3.5, ("book", "table"): 1.0}
LEARNED = frozenset({"put away", "wipe", "pour"})


class StandInLM:
    """log P(frame) = the Destination's prior + its association with the Theme ("it" has none); it
    keeps every frame it was asked about."""

    def __init__(self):
        self.asked: list[Frame] = []

    def __call__(self, frames: list[Frame], context: str = "") -> list[float]:
        self.asked += frames
        out = []
        for frame in frames:
            roles = frame.role_map
            place = roles.get("Destination", "")
            out.append(PRIOR.get(place, -4.0) + ASSOCIATION.get((roles.get("Theme"), place), 0.0) - len(context) / 100)
        return out


def put_away(theme: str, place: str) -> Frame:
    return Frame.of("put away", {"Theme": theme, "Destination": place})


def test_the_term_undoes_the_fillers_prior_and_keeps_what_the_theme_says():
    lm = StandInLM()
    frames = [put_away("stained shirt", "bed"), put_away("stained shirt", "hamper")]
    plain = lm(frames)
    summed = [p + t for p, t in zip(plain, theme_pmi_scorer(lm, LEARNED)(frames))]
    assert plain[0] > plain[1]  # the LM alone: the bed
    assert summed[1] > summed[0]  # with the term: the hamper
    # at weight 1 what is left is the association alone (the prior cancels), centred
    pure = theme_pmi_scorer(lm, LEARNED, weight=1.0)(frames)
    assert [p + t - (plain[0] + pure[0]) for p, t in zip(plain, pure)] == pytest.approx([0.0, 3.5])


def test_the_term_is_centred_and_weighed():
    frames = [put_away("book", "bed"), put_away("book", "hamper"), put_away("book", "table")]
    scores = theme_pmi_scorer(StandInLM(), LEARNED)(frames)
    assert sum(scores) == pytest.approx(0.0)
    mean = sum(PRIOR.values()) / 3
    assert scores == pytest.approx([-WEIGHT * (PRIOR[p] - mean) for p in ("bed", "hamper", "table")])


def test_frames_that_differ_only_in_their_theme_score_zero():
    """The Theme is what is missing ("dispose of it in the bin"): the masked frames are one text."""
    lm = StandInLM()
    frames = [put_away(theme, "hamper") for theme in ("stained shirt", "book", "cup")]
    assert theme_pmi_scorer(lm, LEARNED)(frames) == [0.0, 0.0, 0.0]
    assert lm.asked == [put_away(PLACEHOLDER, "hamper")]  # each masked frame is scored once


def test_a_frame_without_a_theme_or_with_a_theme_alone_scores_zero():
    lm = StandInLM()
    frames = [Frame.of("wipe", {"Theme": "counter"}), Frame.of("pour", {"Destination": "cup"}), put_away("book", "bed")]
    assert masked(frames[0]) is None and masked(frames[1]) is None
    assert theme_pmi_scorer(lm, LEARNED)(frames) == [0.0, 0.0, 0.0]  # the third is alone in its group


def test_roles_and_predicates_are_centred_apart():
    lm = StandInLM()
    frames = [
        put_away("book", "bed"),
        put_away("book", "table"),
        Frame.of("put away", {"Theme": "book", "Instrument": "bed"}),
        Frame.of("put away", {"Theme": "book", "Instrument": "hamper"}),
    ]
    scores = theme_pmi_scorer(lm, LEARNED)(frames)
    assert scores[0] + scores[1] == pytest.approx(0.0) and scores[2] + scores[3] == pytest.approx(0.0)
    assert scores[0] < 0  # the bed's prior is the higher
    assert scores[2] == 0.0  # the stand-in has no Instrument prior: both masked frames score alike


def test_the_eleven_score_zero():
    """On the eleven's dev sets the term cost an instruction ("heat the milk" in the glass): 0 for them."""
    lm = StandInLM()
    frames = [Frame.of("pour", {"Theme": "milk", "Destination": p}) for p in ("bed", "hamper")]
    assert theme_pmi_scorer(lm, frozenset({"put away"}))(frames) == [0.0, 0.0]
    assert theme_pmi_scorer(lm, LEARNED)(frames) != [0.0, 0.0]
    assert lm.asked == [Frame.of("pour", {"Theme": PLACEHOLDER, "Destination": p}) for p in ("bed", "hamper")]


def test_the_registry_term_reads_the_sentence_lm_the_method_loaded(tmp_path, monkeypatch):
    """'sentence_lm+theme_pmi' loads the checkpoint once; a checkpoint trained again is loaded again. The
    masked frames are read with the context too."""
    loads, contexts = [], []

    class Loaded:
        lex = None

        def __init__(self):
            loads.append(self)

        def score_frames(self, frames, context=""):
            contexts.append(context)
            return StandInLM()(frames, context)

    manifest = {"sha": "a"}
    monkeypatch.setattr(registry, "load_lm", lambda res, lin, corpus: Loaded())
    monkeypatch.setattr(registry, "_lm_fingerprint", lambda lin: lambda res: manifest["sha"])
    monkeypatch.setattr(registry, "load_lexicon", lambda learned: SimpleNamespace(learned=LEARNED))
    registry._LAST_LM.clear()
    res = MethodResources(checkpoints=tmp_path, predicates=False)
    scorer = registry.make_scorer("sentence_lm+theme_pmi", res)
    frames = [put_away("stained shirt", "bed"), put_away("stained shirt", "hamper")]
    plain = registry.make_scorer("sentence_lm", res)(frames)
    summed = scorer(frames, "for my tea")
    assert len(loads) == 1 and summed[1] > summed[0] and plain[0] > plain[1]
    assert contexts[-2:] == ["for my tea", "for my tea"]  # the LM's own reading, then the term's
    assert registry.SCORERS["theme_pmi"].within_role and "theme_pmi" in registry.TERMS
    manifest["sha"] = "b"  # trained again
    registry.make_scorer("sentence_lm+theme_pmi", res)
    assert len(loads) == 2
    registry._LAST_LM.clear()
