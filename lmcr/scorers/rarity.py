"""How rare each filler of a frame is in the corpus: the term that turns a frame's log-probability into
a pointwise-mutual-information-like score.

An LM or count model scores log P(frame), which rises with how common the fillers are anyway: "dump the
pan into the bowl" outscores "dump the cheese into the bowl" because "pan" is a frequent word, not
because pans are dumped into bowls (surface-form competition, Holtzman et al. 2021). Adding

    rarity(frame) = -WEIGHT * sum over fillers o of log P(o),  P(o) = (c(o) + 1) / (N + 1)

with c(o) the occurrences of the phrase o (its last word may take -s or -es) in the setting's corpus
sentences and N their words, gives log P(frame) - WEIGHT log P(fillers): at WEIGHT = 1 per expert the
PMI of the frame, at 0 the plain score. 'sentence_lm+frame_counts+rarity' subtracts it once for two
experts (0.3 each). WEIGHT = 0.6 was chosen on the dev ratings among 0.4, 0.5, 0.6, 0.7 and 0.8 (mean
Table I accuracy at lambda=1, k=6 over five scenario draws: .889, .900, .902, .902, .898; 0: .874); the
frequencies are the corpus's, nothing is written by hand.

The detector's objects are counted up front by one scan of the sentences; a phrase met later (a label
outside the vocabulary) is looked up in the word n-gram index (`ngram_index.py`), and scanned for only
when the index cannot hold it. A phrase counted alone and a phrase looked up agree, except that the scan
finds a phrase only where its words stand one space apart and the index also across punctuation
("coffee-table"), and that one scan for several phrases counts an occurrence once, for the longest.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable
from pathlib import Path

from lmcr.files import cached_json
from lmcr.frame import Frame
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.ngram_index import NgramIndex
from lmcr.store import named_query, read_connection

WEIGHT = 0.6


def phrase_pattern(phrases: Iterable[str]) -> str:
    """A regex alternation of the phrases, longest first (so 'black pepper' is not read as 'pepper')."""
    return "|".join(re.escape(p) for p in sorted(set(phrases), key=lambda p: (-len(p), p)))


class PhraseCounts:
    """Occurrences of filler phrases in the corpus sentences of a setting (in `all`, each corpus weighted
    as a mixture weighs it), counted in one pass for every phrase not seen before and kept. `words` is
    the store's words per source corpus (`scorers.resources.corpus_words`); `index`, when given, gives
    the n-gram index in which phrases met while scoring are looked up (called at the first of them)."""

    def __init__(
        self,
        db: Path,
        sql_dir: Path,
        words: dict[str, int],
        corpus: str = "all",
        mixture: Mixture = Mixture(),
        index: Callable[[], NgramIndex] | None = None,
    ):
        self.db, self.sql_dir, self.index = Path(db), sql_dir, index
        self.weights = mixture.parts(corpus)
        self.words = float(
            sum(mixture.weight(c) * n for c, n in words.items()) if corpus == "all" else words.get(corpus, 0)
        )
        self.counts: dict[str, float] = {}

    def count(self, phrases: Iterable[str]) -> None:
        """Count the phrases not counted yet (one query per corpus for all of them)."""
        todo = sorted({p.lower() for p in phrases if p.lower() not in self.counts})
        if not todo:
            return
        found: dict[str, float] = dict.fromkeys(todo, 0.0)
        con = read_connection(self.db)
        try:
            for part, weight in self.weights.items():
                rows = con.execute(
                    named_query(self.sql_dir, "phrase_counts"), {"phrases": phrase_pattern(todo), "corpus": part}
                ).fetchall()
                for phrase, n in rows:
                    found[phrase] = found.get(phrase, 0.0) + weight * n
        finally:
            con.close()
        self.counts.update(found)

    def count_cached(self, phrases: Iterable[str], cache: Path) -> None:
        """Count the phrases, read from `cache` when it holds them for this corpus (the caller names the
        file by the corpus content), else counted and saved there: a scan of the full store takes about a
        second, every `lmcr complete` would pay it."""
        phrases = sorted({p.lower() for p in phrases})

        def counted() -> dict:
            self.count(phrases)
            return {"words": self.words, "counts": self.counts}

        def usable(saved) -> bool:
            counts = saved["counts"]
            return (
                saved["words"] == self.words
                and set(phrases) <= set(counts)
                and all(isinstance(n, (int, float)) for n in counts.values())
            )

        self.counts.update({p: float(n) for p, n in cached_json(cache, usable, counted)["counts"].items()})

    def look_up(self, phrases: Iterable[str]) -> None:
        """Count the phrases not counted yet: in the n-gram index where there is one and the phrase is
        indexable, by a scan otherwise."""
        todo = {p.lower() for p in phrases if p.lower() not in self.counts}
        if todo and self.index is not None:
            index = self.index()
            looked = {p: index.count(p, self.weights) for p in todo}
            self.counts.update({p: n for p, n in looked.items() if n is not None})
        self.count(todo)

    def log_p(self, phrase: str) -> float:
        """log P(phrase), add-one smoothed (a phrase never seen is as rare as one occurrence in N + 1)."""
        key = phrase.lower()
        self.look_up([key])
        return math.log((self.counts[key] + 1.0) / (self.words + 1.0))

    def rarity(self, frames: list[Frame]) -> list[float]:
        """-WEIGHT * sum of log P(filler) for each frame."""
        self.look_up(value for frame in frames for _, value in frame.roles)
        return [-WEIGHT * sum(self.log_p(value) for _, value in frame.roles) for frame in frames]
