"""What the rest of an instruction says about a filler, learned from which words share a document:
"season the apples for the pie" -> cinnamon, because recipes that mention pie mention cinnamon far more
often than recipes at large, and salt barely more.

    context_pmi(frame, context) = WEIGHT * sum over the context's words w and the frame's fillers o of
                                  log [(d(w, o) + 1) (D + 1) / ((d(w) + 1) (d(o) + 1))]

d(w): documents (a recipe, a narrated video, a household program) whose text has the word w; d(o): those
that name the object o (its last word may take -s or -es); d(w, o): both; D: documents (in `all`, each
corpus's documents count as often as the mixture weighs it). The context's words are its tokens that are
not stop words (spaCy's list), held by at least MIN_DOCS documents, and not a word of the filler itself
(a purpose that names the pasta says the pot is for it, not that the pasta is the pot). An instruction
without context scores 0 for every candidate, as without the term, and so does every rated frame of
Table I. The sentence LM reads the context too, but word by word after the frame: this term sees the
whole document a purpose and an object share, and nothing in it is written by hand.

WEIGHT = 1 (log-probability units, as the experts it is added to) of 0.5, 1 and 2 tried on the dev
instructions, which complete the same with each (README, Completion).
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from pathlib import Path

from lmcr.files import cached_json
from lmcr.frame import Frame
from lmcr.lm.linearize import tokens
from lmcr.rarity import phrase_pattern
from lmcr.store import named_query, read_connection

WEIGHT = 1.0
MIN_DOCS = 20  # a word in fewer documents says little and would only grow the table


class ContextCooccurrence:
    """Document counts of words, object phrases and the two together; scores frames given a context."""

    def __init__(self, docs: float, word_docs: dict[str, float], object_docs: dict[str, float],
                 pair_docs: dict[str, dict[str, float]]):
        self.docs, self.word_docs, self.object_docs, self.pair_docs = docs, word_docs, object_docs, pair_docs

    @classmethod
    def count(cls, db: Path, sql_dir: Path, objects: Iterable[str], corpora: dict[str, float],
              min_docs: int = MIN_DOCS) -> ContextCooccurrence:
        """Count in the store's sentences, one query per corpus (`corpora`: corpus -> weight; 'all': 1)."""
        docs, words, objs, pairs = 0.0, {}, {}, {}
        con = read_connection(db)
        try:
            for corpus, weight in corpora.items():
                params = {"phrases": phrase_pattern(o.lower() for o in objects), "corpus": corpus, "min_docs": min_docs}
                for kind, obj, word, n in con.execute(named_query(sql_dir, "context_cooccurrence"), params).fetchall():
                    if kind == "docs":
                        docs += weight * n
                    elif kind == "word":
                        words[word] = words.get(word, 0.0) + weight * n
                    elif kind == "object":
                        objs[obj] = objs.get(obj, 0.0) + weight * n
                    else:
                        pairs.setdefault(obj, {})[word] = pairs.get(obj, {}).get(word, 0.0) + weight * n
        finally:
            con.close()
        return cls(docs, words, objs, pairs)

    @classmethod
    def cached(cls, db: Path, sql_dir: Path, objects: Iterable[str], corpora: dict[str, float],
               cache: Path) -> ContextCooccurrence:
        """The counts from `cache` when it holds them for these objects (the caller names the file by the
        corpus content and mixture), else counted (about 10 s on the full store) and saved there."""
        objects = sorted({o.lower() for o in objects})

        def counted() -> dict:
            found = cls.count(db, sql_dir, objects, corpora)
            return {"objects": objects, "docs": found.docs, "words": found.word_docs,
                    "object_docs": found.object_docs, "pairs": found.pair_docs}

        def usable(saved) -> bool:
            return saved["objects"] == objects and isinstance(saved["docs"], (int, float))

        saved = cached_json(cache, usable, counted)
        return cls(float(saved["docs"]), saved["words"], saved["object_docs"], saved["pairs"])

    def context_words(self, context: str) -> list[str]:
        """The context's counted words of three letters or more that are not stop words, each once, in order."""
        from spacy.lang.en.stop_words import (
            STOP_WORDS,  # imported here: building the term (`lmcr evaluate` does) needs no spaCy
        )

        seen = dict.fromkeys(w for w in tokens(context) if len(w) > 2 and w.isalpha() and w not in STOP_WORDS and w in self.word_docs)
        return list(seen)

    def pmi(self, word: str, obj: str) -> float:
        """log of how much more often documents with `word` name `obj` than documents at large, smoothed."""
        key = obj.lower()
        together = self.pair_docs.get(key, {}).get(word, 0.0)
        return math.log((together + 1) * (self.docs + 1) / ((self.word_docs[word] + 1) * (self.object_docs.get(key, 0.0) + 1)))

    def score(self, frames: list[Frame], context: str = "") -> list[float]:
        """WEIGHT * the summed PMI of the context's words with each frame's fillers (0 without context)."""
        words = self.context_words(context) if context else []
        if not words:
            return [0.0] * len(frames)
        return [WEIGHT * sum(self.pmi(w, value) for _, value in frame.roles for w in words if not _names(w, value))
                for frame in frames]


def _names(word: str, value: str) -> bool:
    """Whether `word` is a word of the filler `value` (or its plural): "pasta" in "boil the pasta"."""
    return any(word in (part, part + "s", part + "es") for part in value.lower().split())
