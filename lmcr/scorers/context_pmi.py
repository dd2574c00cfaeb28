"""What the rest of an instruction says about a filler, learned from which words share a sentence with it:
"dump the pasta in to boil" -> the pot, because sentences that say boil name a pot far more often than
sentences at large, and a bowl barely more.

    context_pmi(frame, context) = weight * sum over the context's words w and the frame's fillers o of
                                  log [(n(w, o) + 1) / (n(w) n(o) / N + 1)]

n(w): sentences (recipe steps, titles, ingredient lines, narrations, program steps) with the word w;
n(o): those that name the object o (its last word may take -s or -es); n(w, o): both; N: sentences (in
`all`, each corpus's sentences count as often as the mixture weighs it). n(w) n(o) / N is how many
sentences would name both were the word and the object independent: the log compares what was seen
with what was expected, each plus one sentence. A pair expected in under a sentence and never seen says
nothing (about 0), where the add-one estimate log [(n(w, o) + 1) (N + 1) / ((n(w) + 1) (n(o) + 1))] read
it as strong evidence for: an object named in no sentence (one outside the counted vocabulary, a "landfill
bin") took log (N / n(w)), some 7 nats a word, over every object the corpora know ("I drank it already":
the bins over the soda, docs/guide/complete.md). The context's words are its
tokens that are not stop words (spaCy's list), in at least MIN_SENTENCES sentences, and not a word of the
filler itself (a purpose that names the pasta says the pot is for it, not that the pasta is the pot). An
instruction without context scores 0 for every candidate, as without the term, and so does every rated
frame of Table I. The sentence LM reads the context too, but word by word after the frame: this term
sees every sentence a purpose word and an object share, in any order, and nothing in it is written by
hand. The unit is the sentence, not the document (a recipe, a narrated video): one sentence names a
purpose with the thing it needs ("boil the pasta in a large pot"), a whole recipe names every tool it
uses for every purpose (README, Completion: the figures of both).

The weight multiplies the term in log-probability units, as the experts it is added to: 1 (unscaled)
unless `lmcr mixture` chose another of GRID on the dev instructions, together with the household weight
(lmcr/evaluate/choose_mixture.py); the choice is saved in mixture.json and read into `MethodResources`.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

from lmcr.files import cached_json
from lmcr.frame import Frame
from lmcr.lm.linearize import tokens
from lmcr.scorers.ngram_index import PLURALS
from lmcr.scorers.rarity import phrase_pattern
from lmcr.store import named_query, read_connection

WEIGHT = 1.0  # the unscaled term: what completion uses when no weight was chosen
GRID = (0.5, 1.0, 2.0)  # the weights `lmcr mixture` chooses among
MIN_SENTENCES = 20  # a word in fewer sentences says little and would only grow the table
# the estimate (against the expected count, module docstring), in the calibration's fingerprint: scores of
# another estimate were calibrated for other numbers
ESTIMATE = "expected+1"


class ContextCooccurrence:
    """Sentence counts of words, object phrases and the two together; scores frames given a context."""

    def __init__(
        self,
        sentences: float,
        word_sentences: dict[str, float],
        object_sentences: dict[str, float],
        pair_sentences: dict[str, dict[str, float]],
    ):
        self.sentences, self.word_sentences = sentences, word_sentences
        self.object_sentences, self.pair_sentences = object_sentences, pair_sentences

    @classmethod
    def count(
        cls,
        db: Path,
        sql_dir: Path,
        objects: Iterable[str],
        corpora: dict[str, float],
        min_sentences: int = MIN_SENTENCES,
    ) -> ContextCooccurrence:
        """Count in the store's sentences, one query per corpus (`corpora`: corpus -> weight; 'all': 1)."""
        sentences, words, objs, pairs = 0.0, {}, {}, {}
        con = read_connection(db)
        try:
            for corpus, weight in corpora.items():
                params = {
                    "phrases": phrase_pattern(o.lower() for o in objects),
                    "corpus": corpus,
                    "min_sentences": min_sentences,
                }
                for kind, obj, word, n in con.execute(named_query(sql_dir, "context_cooccurrence"), params).fetchall():
                    if kind == "sentences":
                        sentences += weight * n
                    elif kind == "word":
                        words[word] = words.get(word, 0.0) + weight * n
                    elif kind == "object":
                        objs[obj] = objs.get(obj, 0.0) + weight * n
                    else:
                        pairs.setdefault(obj, {})[word] = pairs.get(obj, {}).get(word, 0.0) + weight * n
        finally:
            con.close()
        return cls(sentences, words, objs, pairs)

    @classmethod
    def cached(
        cls, db: Path, sql_dir: Path, objects: Iterable[str], corpora: dict[str, float], cache: Path
    ) -> ContextCooccurrence:
        """The counts from `cache` when it holds them for these objects (the caller names the file by the
        corpus content and mixture), else counted (about 20 s on the full store) and saved there."""
        objects = sorted({o.lower() for o in objects})

        def counted() -> dict:
            found = cls.count(db, sql_dir, objects, corpora)
            return {
                "objects": objects,
                "sentences": found.sentences,
                "words": found.word_sentences,
                "object_sentences": found.object_sentences,
                "pairs": found.pair_sentences,
            }

        def usable(saved) -> bool:
            return saved["objects"] == objects and isinstance(saved["sentences"], (int, float))

        saved = cached_json(cache, usable, counted)
        return cls(float(saved["sentences"]), saved["words"], saved["object_sentences"], saved["pairs"])

    def context_words(self, context: str) -> list[str]:
        """The context's counted words of three letters or more that are not stop words, each once, in order."""
        from spacy.lang.en.stop_words import (
            STOP_WORDS,  # imported here: building the term (`lmcr evaluate` does) needs no spaCy
        )

        seen = dict.fromkeys(
            w
            for w in tokens(context)
            if len(w) > 2 and w.isalpha() and w not in STOP_WORDS and w in self.word_sentences
        )
        return list(seen)

    def pmi(self, word: str, obj: str) -> float:
        """log of how many more sentences name `word` and `obj` together than would by chance, each plus one
        (0 for an object no sentence names)."""
        key = obj.lower()
        together = self.pair_sentences.get(key, {}).get(word, 0.0)
        expected = self.word_sentences[word] * self.object_sentences.get(key, 0.0) / max(self.sentences, 1.0)
        return math.log((together + 1) / (expected + 1))

    def score(self, frames: list[Frame], context: str = "", weight: float = WEIGHT) -> list[float]:
        """`weight` * the summed PMI of the context's words with each frame's fillers (0 without context)."""
        words = self.context_words(context) if context else []
        if not words:
            return [0.0] * len(frames)
        return [
            weight * sum(self.pmi(w, value) for _, value in frame.roles for w in words if not _names(w, value))
            for frame in frames
        ]


def _names(word: str, value: str) -> bool:
    """Whether `word` is a word of the filler `value` (or its plural): "pasta" in "boil the pasta"."""
    return any(word in {part + end for end in PLURALS} for part in value.lower().split())
