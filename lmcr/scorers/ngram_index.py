"""An index of the corpus sentences' word n-grams, so that a phrase never counted before is looked up in
microseconds instead of found by a scan of every sentence (about half a second on the full store, paid by
each completion that meets a label outside the detector's vocabulary).

The words are the runs of [a-z0-9_] in the lowercased text (those a phrase scan's `\\b` bounds); every
n-gram of 1 to MAX_WORDS words is counted per corpus (`sql/queries/word_ngrams.sql`) and kept as the
first 8 bytes of its MD5 (`md5_number_upper`, the same number in Python: `key`) with its counts, sorted,
in one `.npz` file (77 MB for the full store, built in about 35 s). A phrase's count is its n-gram's,
its last word also taking -s or -es, as the scan counts it. Phrases of more words, or with other
characters, are not indexable (`words` says None): the caller scans for those. 64-bit keys make a
collision among the ~4M n-grams of the full store about a one-in-a-million chance.
"""

from __future__ import annotations

import hashlib
import re
import sys
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from lmcr.files import atomic_path
from lmcr.store import named_query, read_connection

MAX_WORDS = 3
# the endings a phrase's last word may take where a filler is counted or recognised in text (the named
# queries phrase_counts and context_cooccurrence spell the same rule as a regex, (?:s|es)?)
PLURALS = ("", "s", "es")
WORD = re.compile(r"[a-z0-9_]+")


def key(ngram: str) -> int:
    """The n-gram's key: DuckDB's md5_number_upper, the first 8 bytes of its MD5 read little-endian."""
    return int.from_bytes(hashlib.md5(ngram.encode()).digest()[:8], "little")


def words(phrase: str) -> list[str] | None:
    """The phrase's words as the index holds them, or None when it cannot be looked up: more than
    MAX_WORDS words, or characters besides [a-z0-9_] and single spaces."""
    said = " ".join(phrase.lower().split())
    found = WORD.findall(said)
    return found if found and " ".join(found) == said and len(found) <= MAX_WORDS else None


class NgramIndex:
    """Counts of word n-grams per corpus: `count(phrase, weights)`."""

    def __init__(self, keys: np.ndarray, counts: np.ndarray, corpora: list[str]):
        self.keys, self.counts, self.corpora = keys, counts, corpora

    @classmethod
    def build(cls, db: Path, sql_dir: Path, progress=lambda line: print(line, file=sys.stderr)) -> NgramIndex:
        """Count the store's n-grams (once per corpus content: about 45 s on the full store, 2 cores)."""
        progress(f"indexing the corpus's word n-grams (1-{MAX_WORDS} words), once for this corpus")
        con = read_connection(db)
        try:
            rows = con.execute(
                f"select md5_number_upper(ngram) as key, corpus, n from ({named_query(sql_dir, 'word_ngrams')})",
                {"max_words": MAX_WORDS},
            ).fetchnumpy()
        finally:
            con.close()
        corpora = sorted(set(rows["corpus"].tolist()))
        at = {c: k for k, c in enumerate(corpora)}
        keys, slot = np.unique(np.asarray(rows["key"], dtype=np.uint64), return_inverse=True)
        counts = np.zeros((len(keys), len(corpora)), dtype=np.uint32)
        np.add.at(counts, (slot, np.array([at[c] for c in rows["corpus"]], dtype=np.intp)), rows["n"])
        return cls(keys, counts, corpora)

    def save(self, path: Path) -> None:
        """Write the index to `path` (atomically)."""
        with atomic_path(path) as tmp:
            with open(tmp, "wb") as out:
                np.savez(out, keys=self.keys, counts=self.counts, corpora=np.array(self.corpora, dtype=str))

    @classmethod
    def load(cls, path: Path) -> NgramIndex:
        """The index saved at `path`; OSError or ValueError when it is not one."""
        with np.load(path, allow_pickle=False) as saved:
            keys, counts, corpora = saved["keys"], saved["counts"], [str(c) for c in saved["corpora"]]
        if keys.dtype != np.uint64 or counts.shape != (len(keys), len(corpora)):
            raise ValueError(f"{path}: not an n-gram index")
        return cls(keys, counts, corpora)

    @classmethod
    def cached(cls, db: Path, sql_dir: Path, path: Path) -> NgramIndex:
        """The index kept at `path` (the caller names it by the corpus content), built there when missing
        or unreadable."""
        try:
            return cls.load(path)
        except (OSError, ValueError, KeyError):
            index = cls.build(db, sql_dir)
            index.save(path)
            return index

    def count(self, phrase: str, weights: Mapping[str, float]) -> float | None:
        """The phrase's occurrences (its last word also with -s, -es), each corpus weighted by `weights`;
        None when the phrase is not indexable (`words`)."""
        said = words(phrase)
        if said is None:
            return None
        if not len(self.keys):
            return 0.0
        column = np.array([weights.get(c, weights.get("all", 0.0)) for c in self.corpora])  # "all": every corpus
        wanted = np.array([key(" ".join(said) + end) for end in PLURALS], dtype=np.uint64)
        at = np.searchsorted(self.keys, wanted)
        found = at[(at < len(self.keys)) & (self.keys[np.minimum(at, len(self.keys) - 1)] == wanted)]
        return float((self.counts[found].astype(np.float64) @ column).sum()) if len(found) else 0.0
