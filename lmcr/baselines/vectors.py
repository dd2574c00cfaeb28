"""Word-vector baseline: g = -(dist(v, a1) + dist(v, a2) + dist(a1, a2)), cosine distance.

The paper used pretrained GloVe as g = -(dist(v, a2) + dist(a1, a2)); the added dist(v, a1) is the
same for every candidate of a scenario (see `cooccur`). Vectors come from a file in a data format
(GloVe text, word2vec text or binary, or a `.npy` matrix beside a word list), e.g. the 10k-word GloVe
subset, or are trained with gensim word2vec on our own corpus sentences (`train_word2vec`), because
that subset misses many cooking words. Pickle-based files (gensim's `.kv`/`.model`) are refused: loading
one can run code.

OOV policy: a multiword term ("bell pepper") is the mean of its known words; a term with no known
word has no vector, and its distance to anything is 1.0, what two unrelated (orthogonal) words get.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path

import numpy as np
from gensim.models import KeyedVectors, Word2Vec

from lmcr.baselines.cooccur import Frame, pair_sum
from lmcr.errors import LMCRError, one_line
from lmcr.files import atomic_path
from lmcr.lm.linearize import tokens

UNRELATED = 1.0


PICKLED = (".kv", ".model", ".pkl", ".pickle")


class VectorFileError(LMCRError, ValueError):
    """A vector file that is missing, not in a data format, or malformed."""


def load_vectors(path: Path) -> KeyedVectors:
    """GloVe text (no header), word2vec text or binary (`.bin`), or a `.npy` matrix with its word list
    beside it (`NAME.npy` + `NAME.words.txt`, one word per line). Nothing is unpickled."""
    path = Path(path)
    if path.suffix.lower() in PICKLED:
        raise VectorFileError(f"{path}: pickle-based vector files are not loaded (they can run code); "
                              "give GloVe/word2vec text, word2vec .bin, or .npy with a .words.txt list")
    if not path.is_file():
        raise VectorFileError(f"{path}: no such vector file")
    try:
        if path.suffix.lower() == ".npy":
            return _load_npy(path)
        if path.suffix.lower() == ".bin":
            return KeyedVectors.load_word2vec_format(str(path), binary=True)
        with open(path, encoding="utf-8") as handle:
            first = handle.readline().split()
        has_header = len(first) == 2 and all(x.isdigit() for x in first)
        return KeyedVectors.load_word2vec_format(str(path), binary=False, no_header=not has_header)
    except (ValueError, UnicodeDecodeError, EOFError, OSError, IndexError) as exc:
        raise VectorFileError(f"{path}: not a readable vector file: {one_line(exc, 200)}") from exc


def _load_npy(path: Path) -> KeyedVectors:
    words_file = path.with_suffix(".words.txt")
    if not words_file.is_file():
        raise VectorFileError(f"{path}: no word list {words_file.name} beside it")
    matrix = np.load(path, allow_pickle=False)
    words = words_file.read_text(encoding="utf-8").split("\n")
    words = words[:-1] if words and words[-1] == "" else words
    if matrix.ndim != 2 or len(words) != matrix.shape[0]:
        raise VectorFileError(f"{path}: {matrix.shape} matrix does not match {len(words)} words in {words_file.name}")
    kv = KeyedVectors(matrix.shape[1])
    kv.add_vectors(words, matrix.astype(np.float32))
    return kv


class _Sentences:
    """Re-iterable token lists, as gensim makes several passes."""

    def __init__(self, texts):
        self.texts = texts

    def __iter__(self):
        for text in self.texts():
            yield tokens(text)


def train_word2vec(texts, out: Path, dim: int = 100, window: int = 5, min_count: int = 5, epochs: int = 5,
                   workers: int = 2, seed: int = 1) -> Path:
    """Skip-gram word2vec on the corpus sentences (`texts()` yields strings), saved atomically in word2vec
    binary format (a data format: nothing in the cache can run code when loaded)."""
    model = Word2Vec(sentences=_Sentences(texts), vector_size=dim, window=window, min_count=min_count, sg=1,
                     epochs=epochs, workers=workers, seed=seed)
    with atomic_path(Path(out)) as tmp:
        model.wv.save_word2vec_format(str(tmp), binary=True)
    return Path(out)


class VectorScorer:
    """Scores frames by negative summed cosine distances of their terms' vectors."""

    def __init__(self, vectors: KeyedVectors):
        self.vectors = vectors
        self.cache: dict[str, np.ndarray | None] = {}

    def vector(self, term: str) -> np.ndarray | None:
        if term not in self.cache:
            known = [self.vectors[w] for w in term.split() if w in self.vectors.key_to_index]
            mean = np.mean(known, axis=0) if known else None
            self.cache[term] = None if mean is None or not np.any(mean) else mean / np.linalg.norm(mean)
        return self.cache[term]

    def dist(self, x: str, y: str) -> float:
        a, b = self.vector(x), self.vector(y)
        return UNRELATED if a is None or b is None else 1.0 - float(a @ b)

    def oov(self, terms: Iterable[str]) -> list[str]:
        return sorted({t for t in terms if self.vector(t) is None})

    def score_frames(self, frames: list[Frame]) -> list[float]:
        return [-pair_sum(f, self.dist) for f in frames]
