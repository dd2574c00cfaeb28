"""Commonsense from ConceptNet, learned: a knowledge-base completion model (Li et al. 2016, "Commonsense
Knowledge Base Completion", the bilinear model over averaged word vectors) trained on ConceptNet
triples, and the completion term that asks it about a frame's fillers.

The model scores a triple (relation, head, tail) as u_h^T M_r u_t, with u = tanh(W avg(word vectors) + b)
the phrase's encoding and one matrix per relation. Because phrases are read through word vectors it
answers for objects ConceptNet never names ("landfill bin", "storage box two") from the words they share
with those it does: the graph alone (the `conceptnet` baseline) knows a concept or nothing.

The term reads each frame's role fillers against its Theme through the relation ConceptNet uses for
that role (`RELATION_OF_ROLE`: where a thing is put is where it is found, AtLocation; a tool is used for
the act, UsedFor "<verb> <theme>") and adds log sigma(score) per role: how likely ConceptNet's own
graph would hold that edge. A frame with no Theme, or only roles without a relation, scores 0.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Callable, Collection
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from lmcr.errors import LMCRError, one_line
from lmcr.files import atomic_path
from lmcr.frame import Frame
from lmcr.scorers.within_role import centred, role_sets

# The ConceptNet relation that states a role of a frame, and which way round (see the module's docstring).
RELATION_OF_ROLE = {"Destination": "AtLocation", "Source": "AtLocation", "Instrument": "UsedFor"}
WEIGHT = 3.0  # the term's weight in sums: of 1 and 3, the better on the external sets (docs/guide/complete.md)
WORD = re.compile(r"[a-z]+")


@dataclass(frozen=True)
class KBCConfig:
    """The model's size and training. The one setting measured: cn100k dev2 accuracy 0.873
    (`bench/bench_commonsense.py`); none was tuned."""

    hidden: int = 100
    epochs: int = 10
    batch: int = 256
    lr: float = 2e-3
    negatives: int = 3  # corrupted triples per true one: head, tail and relation in turn
    seed: int = 0


class CommonsenseModelError(LMCRError, ValueError):
    """A saved commonsense model that cannot be read."""


def keyed_vectors_lookup(kv) -> tuple[Callable[[str], np.ndarray | None], int]:
    """A gensim KeyedVectors as a word -> vector function (None for a word it lacks) and its dimension."""
    return (lambda w: kv[w] if w in kv.key_to_index else None), kv.vector_size


def words_of(phrase: str) -> list[str]:
    """A phrase's words as the model reads them: lowercased, letters only."""
    return WORD.findall(phrase.lower())


def _torch_model(relations: int, base, hidden: int):
    """The bilinear model over a word table: `base` (words x dim, the word vectors, kept fixed) plus a
    learned correction per word, so that the words ConceptNet uses move and the others keep their meaning."""
    import torch
    from torch import nn

    class Bilinear(nn.Module):
        def __init__(self):
            super().__init__()
            self.register_buffer("base", torch.as_tensor(base, dtype=torch.float32))
            self.delta = nn.Parameter(torch.zeros_like(self.base))
            self.encode = nn.Linear(self.base.shape[1], hidden)
            self.relation = nn.Parameter(torch.randn(relations, hidden, hidden) / hidden)

        def forward(self, head, rel, tail):
            """Scores of (head mean vectors, relation ids, tail mean vectors)."""
            u, v = torch.tanh(self.encode(head)), torch.tanh(self.encode(tail))
            return torch.einsum("bi,bij,bj->b", u, self.relation[rel], v)

    return Bilinear()


class CommonsenseModel:
    """The trained model: the net, its word table (`words`, rows of `net.base`), relation names, config and
    metrics. A word outside the table is read through `lookup` (the word vectors), unchanged."""

    def __init__(self, net, words: list[str], relations: list[str], config: KBCConfig, metrics: dict, lookup):
        self.net, self.words, self.relations, self.config, self.metrics = net, words, relations, config, metrics
        self.word_index = {w: i for i, w in enumerate(words)}
        self.relation_index = {r: i for i, r in enumerate(relations)}
        self.lookup = lookup
        self.table = (net.base + net.delta).detach().numpy()
        self.phrase_cache: dict[str, np.ndarray] = {}
        self.cache: dict[tuple[str, str, str], float] = {}

    def phrase(self, text: str) -> np.ndarray:
        """The mean vector of a phrase's words (zeros when none is known)."""
        if text not in self.phrase_cache:
            found = []
            for w in words_of(text):
                if w in self.word_index:
                    found.append(self.table[self.word_index[w]])
                elif (v := self.lookup(w)) is not None:
                    found.append(v)
            self.phrase_cache[text] = np.mean(found, axis=0) if found else np.zeros(self.table.shape[1])
        return self.phrase_cache[text]

    def logits(self, triples: list[tuple[str, str, str]]) -> np.ndarray:
        """The raw score of each (relation, head, tail); a relation the model never saw raises KeyError."""
        import torch

        if not triples:
            return np.zeros(0, np.float32)
        rel = torch.tensor([self.relation_index[r] for r, _, _ in triples])
        head = torch.tensor(np.stack([self.phrase(h) for _, h, _ in triples]), dtype=torch.float32)
        tail = torch.tensor(np.stack([self.phrase(t) for _, _, t in triples]), dtype=torch.float32)
        with torch.no_grad():
            return self.net(head, rel, tail).numpy()

    def log_prob(self, triples: list[tuple[str, str, str]]) -> list[float]:
        """log sigma(score) of each triple, remembered (a completion asks the same edges again and again)."""
        new = list(dict.fromkeys(t for t in triples if t not in self.cache))
        for triple, logit in zip(new, self.logits(new)):
            self.cache[triple] = -math.log1p(math.exp(-logit)) if logit > -30 else float(logit)
        return [self.cache[t] for t in triples]

    def save(self, path: Path) -> None:
        """Weights, word table, relation names, config and metrics in one torch file (tensors and plain
        data only), written under a temporary name and renamed."""
        import torch

        payload = {
            "state_dict": self.net.state_dict(),
            "words": self.words,
            "relations": self.relations,
            "config": asdict(self.config),
            "metrics": json.dumps(self.metrics),
        }
        with atomic_path(path) as tmp:
            torch.save(payload, tmp)

    @classmethod
    def load(cls, path: Path, lookup) -> CommonsenseModel:
        """A saved model, read without unpickling code (`weights_only`)."""
        import pickle

        import torch

        try:
            payload = torch.load(path, map_location="cpu", weights_only=True)
            config = KBCConfig(**payload["config"])
            net = _torch_model(len(payload["relations"]), payload["state_dict"]["base"], config.hidden)
            net.load_state_dict(payload["state_dict"])
            words, relations = list(payload["words"]), list(payload["relations"])
            metrics = json.loads(payload["metrics"])
        except (OSError, RuntimeError, KeyError, TypeError, ValueError, pickle.UnpicklingError, EOFError) as exc:
            raise CommonsenseModelError(f"{path}: not a commonsense model: {one_line(exc, 200)}") from exc
        net.eval()
        return cls(net, words, relations, config, metrics, lookup)


def _phrase_words(phrases: list[str], word_index: dict[str, int], pad: int) -> tuple[np.ndarray, np.ndarray]:
    """Every phrase as a row of word ids padded with `pad` (the zero row) and its number of known words
    (at least 1, so that a phrase with none has the zero vector)."""
    rows = [[word_index[w] for w in words_of(p) if w in word_index] for p in phrases]
    width = max(1, max(map(len, rows), default=1))
    ids = np.full((len(rows), width), pad, np.int64)
    for i, row in enumerate(rows):
        ids[i, : len(row)] = row
    return ids, np.array([max(1, len(row)) for row in rows], np.float32)


def train_model(
    triples: list[tuple[str, str, str]],
    lookup: Callable[[str], np.ndarray | None],
    dim: int,
    config: KBCConfig = KBCConfig(),
    progress: Callable[[str], None] | None = None,
) -> CommonsenseModel:
    """The bilinear model trained on true `triples` against corrupted ones (binary cross-entropy: `k`
    false triples per true one, its head, tail, then relation replaced by a random one, drawn anew
    every epoch)."""
    import torch

    torch.manual_seed(config.seed)
    rng = np.random.default_rng(config.seed)
    relations = sorted({r for r, _, _ in triples})
    phrases = sorted({h for _, h, _ in triples} | {t for _, _, t in triples})
    words = sorted({w for p in phrases for w in words_of(p) if lookup(w) is not None}) + [""]
    base = np.stack([lookup(w) for w in words[:-1]] + [np.zeros(dim)]).astype(np.float32)
    net = _torch_model(len(relations), base, config.hidden)
    word_index = {w: i for i, w in enumerate(words)}
    ids, counts = (torch.from_numpy(a) for a in _phrase_words(phrases, word_index, len(words) - 1))
    phrase_index = {p: i for i, p in enumerate(phrases)}
    rel_of = {r: i for i, r in enumerate(relations)}
    heads = np.array([phrase_index[h] for _, h, _ in triples])
    tails = np.array([phrase_index[t] for _, _, t in triples])
    rels = np.array([rel_of[r] for r, _, _ in triples])

    real = torch.ones(len(words), 1)
    real[-1] = 0  # the padding row stays zero whatever its correction learns

    def mean(phrase_ids):  # the phrases' mean word vectors
        return ((net.base + net.delta) * real)[ids[phrase_ids]].sum(1) / counts[phrase_ids, None]

    optimizer = torch.optim.Adam(net.parameters(), lr=config.lr)
    loss_fn = torch.nn.BCEWithLogitsLoss()
    n = len(triples)
    for epoch in range(config.epochs):
        h, r, t = [heads], [rels], [tails]
        for j in range(config.negatives):  # corrupt the head, the tail, the relation in turn
            kind = j % 3
            h.append(heads[rng.integers(n, size=n)] if kind == 0 else heads)
            t.append(tails[rng.integers(n, size=n)] if kind == 1 else tails)
            r.append(rng.integers(len(relations), size=n) if kind == 2 else rels)
        h, r, t = (torch.from_numpy(np.concatenate(x)) for x in (h, r, t))
        labels = torch.cat([torch.ones(n), torch.zeros(n * config.negatives)])
        order = torch.from_numpy(rng.permutation(len(labels)))
        total = 0.0
        for start in range(0, len(order), config.batch):
            batch = order[start : start + config.batch]
            loss = loss_fn(net(mean(h[batch]), r[batch], mean(t[batch])), labels[batch])
            optimizer.zero_grad()
            loss.backward()
            optimizer.step()
            total += loss.item() * len(batch)
        if progress:
            progress(f"commonsense model epoch {epoch + 1}/{config.epochs}: loss {total / len(order):.4f}")
    net.eval()
    metrics = {"train_triples": n, "words": len(words) - 1, "relations": len(relations)}
    return CommonsenseModel(net, words, relations, config, metrics, lookup)


def _labelled_logits(model: CommonsenseModel, labelled: list[tuple[str, str, str, bool]]):
    """The scores and labels of the labelled triples whose relation the model knows."""
    known = [x for x in labelled if x[0] in model.relation_index]
    return model.logits([x[:3] for x in known]), np.array([x[3] for x in known], bool)


def accuracy(model: CommonsenseModel, labelled: list[tuple[str, str, str, bool]], threshold: float) -> float:
    """Share of labelled triples whose score is on the right side of `threshold`."""
    logits, truth = _labelled_logits(model, labelled)
    return float(np.mean((logits > threshold) == truth)) if len(truth) else 0.0


def best_threshold(model: CommonsenseModel, labelled: list[tuple[str, str, str, bool]]) -> float:
    """The threshold that classifies `labelled` best (Li et al.: tuned on dev1, reported on dev2): one of
    at most about 400 cuts between neighbouring scores, the triples scored once."""
    logits, truth = _labelled_logits(model, labelled)
    ordered = np.sort(logits)
    cuts = ((ordered[:-1] + ordered[1:]) / 2)[:: max(1, (len(ordered) - 1) // 400)]
    if not len(cuts):
        return 0.0
    right = [np.mean((logits > c) == truth) for c in cuts]
    return float(cuts[int(np.argmax(right))])


def frame_triples(frame: Frame) -> list[tuple[str, str, str]]:
    """The ConceptNet edges a frame claims (see `RELATION_OF_ROLE`): none without a Theme."""
    roles = frame.role_map
    theme = roles.get("Theme")
    if not theme:
        return []
    out = []
    for role, value in roles.items():
        relation = RELATION_OF_ROLE.get(role)
        if relation == "UsedFor":
            out.append((relation, value, f"{frame.predicate} {theme}"))
        elif relation is not None:
            out.append((relation, theme, value))
    return out


def commonsense_scorer(
    model: CommonsenseModel, weight: float = 1.0, learned: Collection[str] | None = None
) -> Callable[[list[Frame]], list[float]]:
    """The completion term: `weight` times the summed log sigma(score) of each frame's edges, less its mean
    over the frames scored with it that fill the same roles of the same predicate. Centred so, the term
    ranks the fillers of a role and leaves which role to fill to the corpora: the relations' scores are
    not on one scale (an AtLocation edge for a Destination against a UsedFor edge for an Instrument).

    With `learned`, only the frames of those predicates claim edges (the others score 0): the method's
    term leaves the eleven out, whose places are where food is cooked and served, not where it is kept
    (AtLocation's sense), and on whose rated frames it lowered Table I (docs/guide/complete.md)."""

    def score(frames: list[Frame]) -> list[float]:
        edges = [
            [t for t in frame_triples(f) if t[0] in model.relation_index]
            if learned is None or f.predicate in learned
            else []
            for f in frames
        ]
        flat = model.log_prob([t for e in edges for t in e])
        raw, at = {}, 0
        for i, e in enumerate(edges):
            raw[i] = sum(flat[at : at + len(e)])
            at += len(e)
        return centred(raw, role_sets(frames), len(frames), weight)

    return score


def trained_model(
    edges: Path,
    vectors: Path,
    cache: Path,
    progress: Callable[[str], None] | None = None,
    config: KBCConfig = KBCConfig(),
) -> CommonsenseModel:
    """The model for a ConceptNet edge file and a vector file: read from `cache` (a folder) when trained
    before on the same two files and settings, else trained now and saved there under their content hash."""
    from lmcr.scorers.baselines.conceptnet import edge_file, read_triples
    from lmcr.scorers.baselines.vectors import load_vectors

    path = Path(cache) / f"commonsense-{model_digest(edges, vectors, config)}.pt"
    lookup, dim = keyed_vectors_lookup(load_vectors(vectors))
    if path.exists():
        return CommonsenseModel.load(path, lookup)
    model = train_model(read_triples(edges), lookup, dim, config, progress)
    model.metrics |= {"edges": str(edge_file(edges)), "vectors": str(vectors)}
    model.save(path)
    return model


def model_digest(edges: Path, vectors: Path, config: KBCConfig = KBCConfig()) -> str:
    """What a trained model is named by: the content hashes of its edge and vector files and its settings
    (a changed file or setting trains a new model)."""
    import hashlib

    from lmcr.files import file_sha256
    from lmcr.scorers.baselines.conceptnet import ConceptNetFileError, edge_file
    from lmcr.scorers.baselines.vectors import VectorFileError

    hashes = []
    for path, error in ((edge_file(edges), ConceptNetFileError), (Path(vectors), VectorFileError)):
        try:
            hashes.append(file_sha256(path)[:12])
        except OSError as exc:
            raise error(f"{path}: cannot be read: {one_line(exc, 200)}") from exc
    settings = hashlib.sha256(json.dumps(asdict(config), sort_keys=True).encode()).hexdigest()[:8]
    return f"{hashes[0]}-{hashes[1]}-{settings}"
