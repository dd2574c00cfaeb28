"""Co-occurrence baseline: co(x, y) = count(x, y) / (count(x) count(y)) over corpus sentences.

The paper scores a frame (v, a1, a2) whose a2 is the candidate as g = co(v, a2) + co(a1, a2). We score
every frame as co(v, a1) + co(v, a2) + co(a1, a2): within a scenario one argument is fixed, so the
extra term is the same for every candidate and the ranking is the paper's, whichever role varies.
A pair never seen together scores 0.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable
from itertools import combinations

from lmcr.frame import Frame
from lmcr.lm.linearize import tokens
from lmcr.scorers.baselines.terms import Lemmatizer, TermMatcher


def frame_terms(frame: Frame) -> list[str]:
    """[verb, arg1, arg2] of a complete frame, arguments in role order ([verb, arg] of a purpose clause's
    frame with one role: "hand me something to pour")."""
    verb, values = frame
    return [verb, *values.values()]


def pair_sum(frame: Frame, pair: Callable[[str, str], float]) -> float:
    """pair(v, a1) + pair(v, a2) + pair(a1, a2): every baseline's score over a frame's terms, each pair of
    them once (pair(v, a1) alone for a frame with one role)."""
    return sum(pair(a, b) for a, b in combinations(frame_terms(frame), 2))


class CooccurrenceScorer:
    """Counts terms and term pairs per sentence, scanning the corpus again only for unseen terms."""

    def __init__(self, sentences: Callable[[], Iterable[str]], lemmatizer: Lemmatizer, terms: Iterable[str] = ()):
        self.sentences = sentences
        self.lemmatizer = lemmatizer
        self.single: Counter[str] = Counter()
        self.pairs: Counter[tuple[str, str]] = Counter()
        self.indexed: set[str] = set()
        self.n_sentences = 0
        self.index(terms)

    def index(self, terms: Iterable[str]) -> None:
        """Make sure the counts cover `terms` (one pass over the corpus for all indexed terms)."""
        wanted = self.indexed | set(terms)
        if wanted == self.indexed:
            return
        matcher = TermMatcher(wanted, self.lemmatizer)
        single, pairs, n = Counter(), Counter(), 0
        for text in self.sentences():
            n += 1
            found = matcher.find(tokens(text))
            if found:
                single.update(found)
                pairs.update(combinations(sorted(found), 2))
        self.single, self.pairs, self.indexed, self.n_sentences = single, pairs, wanted, n

    def co(self, x: str, y: str) -> float:
        denominator = self.single[x] * self.single[y]
        return self.pairs[tuple(sorted((x, y)))] / denominator if denominator else 0.0

    def score_frames(self, frames: list[Frame]) -> list[float]:
        self.index(t for f in frames for t in frame_terms(f))
        return [pair_sum(f, self.co) for f in frames]
