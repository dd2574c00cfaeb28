"""Retrofitting word vectors to the ConceptNet graph (Faruqui et al. 2015), the step that turns GloVe and
word2vec into ConceptNet Numberbatch; here the stand-in for the relatedness the paper asked the ConceptNet
API for.

Every concept of the edge list is a node. A node starts from its GloVe vector (a phrase, "soy sauce",
from the mean of its words; a node with no known word starts empty) and is pulled towards its
neighbours, keeping to its start:

    q_i <- (a_i q^_i + sum_j q_j / deg_i) / (a_i + 1),   a_i = 1 if the node had a start vector, else 0

ten times (Faruqui's setting, beta_ij = 1/deg_i, alpha = 1). Nodes without a start vector end as the
mean of their neighbours: the graph lends a vector to concepts GloVe never saw. Relatedness is the cosine
of the retrofitted vectors; words outside the graph keep their GloVe vector.
"""

from __future__ import annotations

import numpy as np
from gensim.models import KeyedVectors
from scipy import sparse

ITERATIONS = 10


def start_vectors(nodes: list[str], vectors: KeyedVectors) -> tuple[np.ndarray, np.ndarray]:
    """Unit start vectors of the nodes (the mean of a phrase's known words) and which nodes have one."""
    start = np.zeros((len(nodes), vectors.vector_size), dtype=np.float32)
    known = np.zeros(len(nodes), dtype=bool)
    for i, node in enumerate(nodes):
        words = [w for w in node.split() if w in vectors.key_to_index]
        if words:
            mean = np.mean([vectors[w] for w in words], axis=0)
            norm = np.linalg.norm(mean)
            if norm > 0:
                start[i], known[i] = mean / norm, True
    return start, known


def retrofit(edges: list[tuple[str, str, float]], vectors: KeyedVectors, iterations: int = ITERATIONS) -> KeyedVectors:
    """GloVe (or any vectors) retrofitted to the edges: graph nodes keyed by their text ("soy sauce"),
    every other word of `vectors` as it was."""
    index: dict[str, int] = {}
    for head, tail, _ in edges:
        index.setdefault(head, len(index))
        index.setdefault(tail, len(index))
    nodes = list(index)
    rows = [index[h] for h, _, _ in edges] + [index[t] for _, t, _ in edges]
    cols = [index[t] for _, t, _ in edges] + [index[h] for h, _, _ in edges]
    adjacency = sparse.csr_matrix((np.ones(len(rows), dtype=np.float32), (rows, cols)), shape=(len(nodes),) * 2)
    adjacency.data[:] = 1.0  # an edge listed twice (or under two relations) is one neighbour
    degree = np.asarray(adjacency.sum(axis=1)).ravel()
    mean_of_neighbours = sparse.diags(1.0 / np.maximum(degree, 1)) @ adjacency
    start, known = start_vectors(nodes, vectors)
    alpha = known.astype(np.float32)[:, None]
    has_neighbours = (degree > 0).astype(np.float32)[:, None]
    q = start.copy()
    for _ in range(iterations):
        q = (alpha * start + mean_of_neighbours @ q) / np.maximum(alpha + has_neighbours, 1)
    out = KeyedVectors(vectors.vector_size, count=0)
    extra = [w for w in vectors.index_to_key if w not in index]
    out.vectors = np.vstack([q, vectors.vectors[[vectors.key_to_index[w] for w in extra]]]).astype(np.float32)
    out.index_to_key = nodes + extra
    out.key_to_index = {w: i for i, w in enumerate(out.index_to_key)}
    return out
