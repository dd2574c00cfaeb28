"""ConceptNet baseline: g = rel(v, a1) + rel(v, a2) + rel(a1, a2) (the paper: rel(v, a2) + rel(a1, a2);
the added term is constant within a scenario, see `cooccur`).

The paper queried the ConceptNet API's relatedness, the cosine of ConceptNet Numberbatch vectors.
Offline we rebuild the same kind of quantity from an edge list: Numberbatch starts from the PPMI of
the ConceptNet graph's adjacency matrix reduced by SVD, so we embed every English concept by a
truncated SVD of the PPMI-weighted symmetric adjacency (edges of all relations, weight 1 each) and
take cosines. Without Numberbatch's retrofitting onto word2vec/GloVe and with only
100k edges (`cn100k`) the vectors are coarser than the API's. A user-supplied Numberbatch text file is
used directly. A concept missing from the graph is looked up by its words; with none known its
relatedness is 0.
"""

from __future__ import annotations

import csv
import gzip
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import svds

from lmcr.errors import LMCRError, one_line
from lmcr.scorers.baselines.cooccur import Frame, pair_sum
from lmcr.scorers.baselines.vectors import load_vectors


def _concept(uri_or_text: str) -> str | None:
    """'/c/en/soy_sauce/n' -> 'soy sauce'; plain text is lowercased; other languages -> None."""
    text = uri_or_text.strip()
    if text.startswith("/c/"):
        parts = text.split("/")
        if len(parts) < 4 or parts[2] != "en":
            return None
        text = parts[3]
    return text.replace("_", " ").lower() or None


class ConceptNetFileError(LMCRError, ValueError):
    """A ConceptNet edge file that cannot be read, or a line that is no edge."""


def _relation(name: str) -> str:
    """'/r/AtLocation' -> 'AtLocation'; a cn100k name as it is."""
    return name.rsplit("/", 1)[-1] if name.startswith("/r/") else name


def edge_file(path: Path) -> Path:
    """The file an edge path names: a folder's `train.txt` (cn100k), else the path itself."""
    path = Path(path)
    return path / "train.txt" if path.is_dir() else path


def read_triples(path: Path) -> list[tuple[str, str, str]]:
    """(relation, head, tail) from `relation<TAB>head<TAB>tail[<TAB>...]` lines (cn100k, file or folder:
    its `train.txt`) or ConceptNet assertion CSVs (`uri, rel, /c/en/.., /c/en/.., json`), `.gz` allowed.
    Edges of other languages are left out; a line with fewer than three fields is an error naming it."""
    path = edge_file(path)
    opener = gzip.open if path.suffix == ".gz" else open
    triples = []
    try:
        with opener(path, "rt", encoding="utf-8") as handle:
            for line, row in enumerate(csv.reader(handle, delimiter="\t", quoting=csv.QUOTE_NONE), 1):
                if len(row) >= 5 and row[2].startswith("/c/"):  # assertions: uri, rel, start, end, info
                    relation, head, tail = _relation(row[1]), _concept(row[2]), _concept(row[3])
                elif len(row) >= 3:
                    relation, head, tail = _relation(row[0]), _concept(row[1]), _concept(row[2])
                elif not row:
                    continue  # a blank line
                else:
                    raise ConceptNetFileError(
                        f"{path}:{line}: {len(row)} tab-separated field(s); an edge is relation, head, tail"
                    )
                if head and tail and head != tail:
                    triples.append((relation, head, tail))
    except (OSError, EOFError, UnicodeDecodeError, csv.Error) as exc:
        raise ConceptNetFileError(f"{path}: not a readable ConceptNet edge file: {one_line(exc, 200)}") from exc
    if not triples:
        raise ConceptNetFileError(f"{path}: no English ConceptNet edges found")
    return triples


def read_edges(path: Path) -> list[tuple[str, str, float]]:
    """(head, tail, weight 1) of every English edge of `path` (see `read_triples`), relations left out."""
    return [(head, tail, 1.0) for _, head, tail in read_triples(path)]


def embed_graph(
    edges: list[tuple[str, str, float]], dim: int = 100, seed: int = 0
) -> tuple[dict[str, int], np.ndarray]:
    """Concept index and unit-length SVD embeddings of the PPMI of the symmetric adjacency matrix."""
    index: dict[str, int] = {}
    for head, tail, _ in edges:
        index.setdefault(head, len(index))
        index.setdefault(tail, len(index))
    rows = [index[h] for h, _, _ in edges] + [index[t] for _, t, _ in edges]
    cols = [index[t] for _, t, _ in edges] + [index[h] for h, _, _ in edges]
    weights = [w for _, _, w in edges] * 2
    adj = sparse.coo_matrix((weights, (rows, cols)), shape=(len(index), len(index))).tocsr()
    adj.sum_duplicates()
    degree = np.asarray(adj.sum(axis=1)).ravel()
    coo = adj.tocoo()
    # context distribution smoothing (alpha 0.75), as in word-embedding PPMI
    smoothed = degree**0.75
    pmi = np.log(coo.data * smoothed.sum() / (degree[coo.row] * smoothed[coo.col]))
    keep = pmi > 0
    ppmi = sparse.csr_matrix((pmi[keep], (coo.row[keep], coo.col[keep])), shape=adj.shape)
    k = max(1, min(dim, min(ppmi.shape) - 1))
    u, s, _ = svds(ppmi, k=k, random_state=seed)
    vectors = u * np.sqrt(s)
    norms = np.linalg.norm(vectors, axis=1, keepdims=True)
    return index, vectors / np.where(norms == 0, 1, norms)


class ConceptNetScorer:
    """Relatedness from concept vectors: built from an edge list, or read from a Numberbatch file."""

    def __init__(self, index: dict[str, int], vectors: np.ndarray):
        self.index, self.vectors = index, vectors
        self.cache: dict[str, np.ndarray | None] = {}

    @classmethod
    def from_path(cls, path: Path, dim: int = 100) -> ConceptNetScorer:
        path = Path(path)
        if path.is_file() and "numberbatch" in path.name:
            kv = load_vectors(path)
            keys = [_concept(k) or k for k in kv.index_to_key]
            vecs = kv.vectors / np.maximum(np.linalg.norm(kv.vectors, axis=1, keepdims=True), 1e-12)
            return cls({k: i for i, k in enumerate(keys)}, vecs)
        return cls(*embed_graph(read_edges(path), dim))

    def vector(self, term: str) -> np.ndarray | None:
        if term not in self.cache:
            if term in self.index:
                found = self.vectors[self.index[term]]
            else:
                known = [self.vectors[self.index[w]] for w in term.split() if w in self.index]
                found = np.mean(known, axis=0) if known else None
                if found is not None and np.any(found):
                    found = found / np.linalg.norm(found)
            self.cache[term] = found
        return self.cache[term]

    def score_frames(self, frames: list[Frame]) -> list[float]:
        return relatedness(self.vector)(frames)


def relatedness(vector: Callable[[str], np.ndarray | None]) -> Callable[[list[Frame]], list[float]]:
    """The ConceptNet score of frames from a term's unit vector: summed cosines, 0 for an unknown term."""

    def rel(x: str, y: str) -> float:
        a, b = vector(x), vector(y)
        # Rounded: an SVD basis is unique only up to rotations inside degenerate subspaces, so cosines of
        # two builds differ in the last bits, and a tie (credit 1/t) must not depend on those bits.
        return 0.0 if a is None or b is None else round(float(a @ b), 9)

    return lambda frames: [pair_sum(f, rel) for f in frames]
