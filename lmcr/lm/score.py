"""Batched log-probabilities of many texts at once, sharing work across common prefixes.

Candidate frames share most of their text ("pour water into the cup", "... the mug", ...). The texts
are put in a token trie. The prefix they all share goes through the LSTM as one sequence; below it
the trie is evaluated level by level: one batched LSTM step per depth for every node that has
children, one softmax per such node, and each text's score is the sum of its edges' log-
probabilities. Cost grows with the number of distinct prefixes, not with the number of texts.

Normalisation (`norm`): "sum" is the total log-probability (the default), "mean" divides by the number
of scored tokens. Chosen by measurement on the dev ratings (`bench/bench_lm.py --ratings`): with the
sentence LM trained on all data, Spearman correlation with the mean crowd rating over 1,155 frames is
0.298 for sum and 0.271 for mean. The end-of-sentence token is not
scored by default: the sentence LM learned instruction sentences that usually continue ("... and
stir"), so P(</s>) measures sentence length habits, not plausibility. An unknown word is charged
log(unk_types) on top of P(<unk>): its share of the probability the model pools over rare words.
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from dataclasses import dataclass

import torch
from torch.nn import functional as F

from lmcr.lm.checkpoint import Checkpoint
from lmcr.lm.linearize import linearize, tokens
from lmcr.lm.vocab import UNK

NORMS = ("sum", "mean")
# Frames whose score reads the instruction's context (`LMScorer.score_frames`). A dev scene holds 5-7
# objects, so there every frame reads it; the cap bounds the cost in large scenes (40 objects: the bench).
CONTEXT_TOP = 10


@contextmanager
def _native_lstm():
    """PyTorch's own LSTM kernel instead of oneDNN's for the duration (only that flag changes)."""
    before = torch.backends.mkldnn.enabled
    torch.backends.mkldnn.enabled = False
    try:
        yield
    finally:
        torch.backends.mkldnn.enabled = before


@dataclass
class _Trie:
    parent: list[int]
    token: list[int]
    depth: list[int]
    has_children: list[bool]
    leaf_of: list[int]

    @classmethod
    def build(cls, seqs: list[list[int]]) -> _Trie:
        trie = cls([-1], [seqs[0][0] if seqs else 0], [0], [False], [])
        index: dict[tuple[int, int], int] = {}
        for seq in seqs:
            node = 0
            for tok in seq[1:]:
                child = index.get((node, tok))
                if child is None:
                    child = index[(node, tok)] = len(trie.parent)
                    trie.parent.append(node)
                    trie.token.append(tok)
                    trie.depth.append(trie.depth[node] + 1)
                    trie.has_children.append(False)
                trie.has_children[node] = True
                node = child
            trie.leaf_of.append(node)
        return trie


class LMScorer:
    """Scores texts or complete frames with a loaded checkpoint."""

    def __init__(self, checkpoint: Checkpoint, score_end: bool = False, chunk: int = 50_000):
        self.checkpoint = checkpoint
        self.model = checkpoint.model.eval()
        self.vocab = checkpoint.vocab
        self.score_end = score_end
        self.chunk = chunk

    def encode(self, text: str) -> list[int]:
        ids = self.vocab.encode(tokens(text, self.checkpoint.articles))
        return ids if self.score_end else ids[:-1]

    def logprobs(self, texts: list[str]) -> list[tuple[float, int]]:
        """(total log-probability, number of scored tokens) for each text."""
        out: list[tuple[float, int]] = []
        for start in range(0, len(texts), self.chunk):
            seqs = [self.encode(t) for t in texts[start:start + self.chunk]]
            totals = self._score(seqs)
            out += [(totals[i], len(seq) - 1) for i, seq in enumerate(seqs)]
        return out

    def score(self, texts: list[str], norm: str = "sum") -> list[float]:
        if norm not in NORMS:
            raise ValueError(f"norm must be one of {NORMS}")
        return [total / max(n, 1) if norm == "mean" else total for total, n in self.logprobs(texts)]

    def score_frames(self, frames: list[tuple[str, dict[str, str]]], context: str = "", norm: str = "sum") -> list[float]:
        """Scores of complete frames (predicate, roles) in this checkpoint's linearisation; with
        `context`, of each frame's text followed by it ("pour milk into mug" + "for my tea"): the score
        adds log P(context | frame), how well the frame serves what was said around it.

        The context is read after the CONTEXT_TOP frames this model scores best, the others get the
        lowest context term of those: past the shared frame prefix every candidate's context costs a
        softmax over the vocabulary per word, and a frame this far down is not what was meant."""
        texts = [linearize(self.checkpoint.linearization, predicate, roles) for predicate, roles in frames]
        scores = self.score(texts, norm)
        if not context.strip() or not frames:
            return scores
        top = sorted(range(len(texts)), key=lambda i: -scores[i])[:CONTEXT_TOP]
        with_context = self.score([f"{texts[i]} {context}" for i in top], norm)
        gains = {i: after - scores[i] for i, after in zip(top, with_context)}
        floor = min(gains.values())
        return [s + gains.get(i, floor) for i, s in enumerate(scores)]

    @torch.no_grad()
    def _score(self, seqs: list[list[int]]) -> list[float]:
        if not seqs:
            return []
        # oneDNN's LSTM builds a primitive per call: ~0.3 ms for these one-step, few-row calls against
        # ~0.1 ms for the native kernel (same numbers to 1e-5), and scoring is nothing but such calls.
        with _native_lstm():
            edge, trie = self._edges(seqs)
        # An unknown word gets its share of <unk>'s pooled probability, not all of it.
        unk, share = self.vocab.words.index(UNK), math.log(self.vocab.unk_types)
        edge[torch.tensor(trie.token) == unk] -= share
        total = edge.tolist()
        for node in range(1, len(total)):  # parents precede children: cumulative sums in one pass
            total[node] += total[trie.parent[node]]
        return [total[leaf] for leaf in trie.leaf_of]

    def _edges(self, seqs: list[list[int]]) -> tuple[torch.Tensor, _Trie]:
        """Log-probability of each trie edge (indexed by its child node), and the trie."""
        trie = _Trie.build(seqs)
        model = self.model
        edge = torch.zeros(len(trie.parent))
        levels: dict[int, list[int]] = {}
        for node, depth in enumerate(trie.depth):
            levels.setdefault(depth, []).append(node)
        # The prefix all texts share ("<s> pour water into the") is nodes 0..L-1 (the first text made
        # them in order): one LSTM call and one decoder call over it, not one of each per token.
        shared = min(len(s) for s in seqs)
        shared = next((i for i in range(1, shared) if any(s[i] != seqs[0][i] for s in seqs)), shared)
        out, state = model.rnn(model.embed(torch.tensor([seqs[0][:shared]])))  # (1, L, E)
        if shared > 1:
            logp = F.log_softmax(model.decoder(out[0, :-1]), dim=-1)  # (L-1, V)
            edge[1:shared] = logp[torch.arange(shared - 1), torch.tensor(seqs[0][1:shared])]
        frontier_out, frontier_pos = out[:, -1], {shared - 1: 0}
        for depth in range(shared, max(levels) + 1):
            nodes = levels[depth]
            parents = [frontier_pos[trie.parent[n]] for n in nodes]
            logp = F.log_softmax(model.decoder(frontier_out), dim=-1)  # (P, V) for the frontier nodes
            edge[nodes] = logp[parents, [trie.token[n] for n in nodes]]
            grow = [n for n in nodes if trie.has_children[n]]
            if not grow:
                break
            pick = torch.tensor([frontier_pos[trie.parent[n]] for n in grow])
            x = model.embed(torch.tensor([trie.token[n] for n in grow])).unsqueeze(1)  # (G, 1, E)
            out, state = model.rnn(x, (state[0][:, pick], state[1][:, pick]))
            frontier_out, frontier_pos = out[:, 0], {n: i for i, n in enumerate(grow)}
        return edge, trie
