"""Batched log-probabilities of many texts at once, sharing work across common prefixes.

Candidate frames share most of their text ("pour water into the cup", "... the mug", ...). The texts
are put in a token trie. The prefix they all share goes through the LSTM as one sequence; below it
the trie is evaluated level by level: one batched LSTM step per depth for every node that has
children, then one decoder pass whose softmax rows are those nodes; each text's score is the sum of its
edges' log-probabilities. Cost grows with the number of distinct prefixes, not with the number of texts.

Normalisation (`norm`): "sum" is the total log-probability (the default), "mean" divides by the number
of scored tokens. Chosen by measurement on the dev ratings (`bench/bench_lm.py --ratings`): with the
sentence LM trained on all data, Spearman correlation with the mean crowd rating over 1,155 frames is
0.298 for sum and 0.271 for mean. The end-of-sentence token is not
scored by default: the sentence LM learned instruction sentences that usually continue ("... and
stir"), so P(</s>) measures sentence length habits, not plausibility. An unknown word is charged
log(unk_types) on top of P(<unk>): its share of the probability the model pools over rare words.

Precision (`precision`): "auto" multiplies the decoder in bfloat16 where the CPU does so natively (as
training's "auto"), else fp32; the LSTM, the softmax and the sums stay fp32. A completion's decoder
pass has few rows, so it is bound by reading the 14k x 256 weight matrix, and bf16 halves that:
completion with context over 40 objects took 17.5 ms against 26.5 ms in fp32 on a 2-core AVX512-BF16
CPU (`bench/bench_complete.py`). The bf16 product needs oneDNN (12 rows: 0.7 ms with it, 5.9 ms
without), so only the trie walk's LSTM calls turn it off (`_native_rnn`). Log-probabilities move by
about 0.01 per token; Table I (0.922 for the default method, 0.846 for the sentence LM) and the dev
instructions (57/60) are the same either way, Fig. 4 moved by at most 0.004.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import torch
from torch.nn import functional as F

from lmcr.lm.checkpoint import Checkpoint
from lmcr.lm.linearize import linearize, tokens
from lmcr.lm.train import pick_precision
from lmcr.lm.vocab import UNK

NORMS = ("sum", "mean")
# Frames whose score reads the instruction's context (`LMScorer.score_frames`). A dev scene holds 5-7
# objects, so there every frame reads it; the cap bounds the cost in large scenes (40 objects: the bench).
CONTEXT_TOP = 10
DECODER_BLOCK = 4096  # rows per decoder call: 4096 x 14k-word vocabulary = 235 MB of logits at most


def _native_rnn(model, x: torch.Tensor, state=None):
    """The model's LSTM on `x` with PyTorch's own kernel (only the oneDNN flag changes, for the call):
    oneDNN's builds a primitive per call, ~0.3 ms for the trie walk's one-step, few-row calls against
    ~0.1 ms (same numbers to 1e-5). Only the LSTM: the decoder needs oneDNN, without which a bf16 product
    of 12 rows took 5.9 ms instead of 0.7 ms. (`torch.backends.mkldnn.flags` would also reset the TF32
    setting, and warn about it.)"""
    before = torch.backends.mkldnn.enabled
    torch.backends.mkldnn.enabled = False
    try:
        return model.rnn(x, state)
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

    def __init__(self, checkpoint: Checkpoint, score_end: bool = False, chunk: int = 50_000, precision: str = "auto"):
        self.checkpoint = checkpoint
        self.model = checkpoint.model.eval()
        self.vocab = checkpoint.vocab
        self.score_end = score_end
        self.chunk = chunk
        decoder = self.model.decoder
        self.precision = pick_precision(precision, decoder.weight.device)
        dtype = torch.bfloat16 if self.precision == "bf16" else decoder.weight.dtype
        self._decoder = (decoder.weight.detach().to(dtype), decoder.bias.detach())

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
        return [_normed(total, n, norm) for total, n in self.logprobs(texts)]

    def score_frames(self, frames: list[tuple[str, dict[str, str]]], context: str = "", norm: str = "sum") -> list[float]:
        """Scores of complete frames (predicate, roles) in this checkpoint's linearisation; with
        `context`, of each frame's text followed by it ("pour milk into mug" + "for my tea"): the score
        adds log P(context | frame), how well the frame serves what was said around it.

        The context is read after the CONTEXT_TOP frames this model scores best, the others get the
        lowest context term of those: every candidate's context costs a softmax over the vocabulary
        per word, and a frame this far down is not what was meant. The context continues the LSTM from
        where each frame's text ended (`_Walk`), so the frames are not read twice."""
        if norm not in NORMS:
            raise ValueError(f"norm must be one of {NORMS}")
        if not frames:
            return []
        texts = [linearize(self.checkpoint.linearization, predicate, roles) for predicate, roles in frames]
        ctx = self.vocab.encode(tokens(context, self.checkpoint.articles))[1:-1]
        if not ctx:
            return self.score(texts, norm)  # in chunks: a whole evaluation's frames may come at once
        seqs = [self.encode(t) for t in texts]
        walk = self._walk(seqs, keep_states=True)
        totals = [(walk.totals[i], len(seq) - 1) for i, seq in enumerate(seqs)]
        scores = [_normed(total, n, norm) for total, n in totals]
        top = sorted(range(len(texts)), key=lambda i: -scores[i])[:CONTEXT_TOP]
        extra = self._continue(walk, [walk.trie.leaf_of[i] for i in top], ctx)  # oneDNN: one call, many rows
        gains = {i: _normed(totals[i][0] + x, totals[i][1] + len(ctx), norm) - scores[i] for i, x in zip(top, extra)}
        floor = min(gains.values())
        return [s + gains.get(i, floor) for i, s in enumerate(scores)]

    @torch.no_grad()
    def _score(self, seqs: list[list[int]]) -> list[float]:
        if not seqs:
            return []
        return self._walk(seqs).totals

    def _edge_logprobs(self, rows: torch.Tensor, picks: torch.Tensor, tokens_: torch.Tensor) -> torch.Tensor:
        """log P(tokens_[j] | rows[picks[j]]) for each j, an unknown word charged its share of <unk>. The
        decoder's softmax runs once over all rows, a block at a time (one read of its weights per block,
        bounded memory), instead of once per trie level."""
        edge = torch.empty(len(picks))
        for start in range(0, len(rows), DECODER_BLOCK):
            logp = F.log_softmax(self._logits(rows[start:start + DECODER_BLOCK]), dim=-1)
            mine = (picks >= start) & (picks < start + DECODER_BLOCK)
            edge[mine] = logp[picks[mine] - start, tokens_[mine]]
        unk = self.vocab.words.index(UNK)
        return edge - (tokens_ == unk) * math.log(self.vocab.unk_types)

    def _logits(self, rows: torch.Tensor) -> torch.Tensor:
        """The decoder's fp32 logits of LSTM output `rows`, multiplied in the scorer's precision."""
        weight, bias = self._decoder
        return F.linear(rows.to(weight.dtype), weight).float() + bias

    @torch.no_grad()
    def _walk(self, seqs: list[list[int]], keep_states: bool = False) -> _Walk:
        """Every text's total log-probability, through the trie of the texts.

        The prefix all texts share ("<s> pour water into the") goes through the LSTM as one sequence;
        below it one batched LSTM step per depth for the nodes that have children. Each node with
        children contributes its output as a row of the decoder's input; `keep_states` keeps the LSTM
        state of each (for `_continue`)."""
        trie = _Trie.build(seqs)
        model = self.model
        levels: dict[int, list[int]] = {}
        for node, depth in enumerate(trie.depth):
            levels.setdefault(depth, []).append(node)
        # The shared prefix is nodes 0..L-1 (the first text made them in order); it stops a token short
        # of the shortest text, so that every text's last node has a parent with a kept state.
        shortest = min(len(s) for s in seqs)
        shared = next((i for i in range(1, shortest) if any(s[i] != seqs[0][i] for s in seqs)), shortest)
        shared = max(1, min(shared, shortest - 1))
        out, state = _native_rnn(model, model.embed(torch.tensor([seqs[0][:shared]])))  # (1, L, E)
        rows, row_of = [out[0]], {n: n for n in range(shared)}
        walk = _Walk(trie, [], {}, [])
        if keep_states:
            walk.states.append(state)
            walk.state_of[shared - 1] = (0, 0)
        frontier, frontier_pos = state, {shared - 1: 0}
        for depth in range(shared, max(levels) + 1):
            grow = [n for n in levels[depth] if trie.has_children[n]]
            if not grow:
                break
            pick = torch.tensor([frontier_pos[trie.parent[n]] for n in grow])
            x = model.embed(torch.tensor([trie.token[n] for n in grow])).unsqueeze(1)  # (G, 1, E)
            out, frontier = _native_rnn(model, x, (frontier[0][:, pick], frontier[1][:, pick]))
            frontier_pos = {n: i for i, n in enumerate(grow)}
            offset = len(row_of)  # one row per node mapped so far
            rows.append(out[:, 0])
            row_of.update((n, offset + i) for i, n in enumerate(grow))
            if keep_states:
                walk.states.append(frontier)
                walk.state_of.update((n, (len(walk.states) - 1, i)) for i, n in enumerate(grow))
        children = list(range(1, len(trie.parent)))
        edge = torch.zeros(len(trie.parent))
        if children:
            edge[1:] = self._edge_logprobs(torch.cat(rows), torch.tensor([row_of[trie.parent[n]] for n in children]),
                                           torch.tensor([trie.token[n] for n in children]))
        total = edge.tolist()
        for node in range(1, len(total)):  # parents precede children: cumulative sums in one pass
            total[node] += total[trie.parent[node]]
        walk.totals = [total[leaf] for leaf in trie.leaf_of]
        return walk

    @torch.no_grad()
    def _continue(self, walk: _Walk, leaves: list[int], ctx: list[int]) -> list[float]:
        """log P(ctx | the text ending at each leaf): each leaf's token and the context read on from its
        parent's kept state, all leaves in one LSTM call and one decoder pass."""
        model, trie = self.model, walk.trie
        places = [walk.state_of[trie.parent[leaf]] for leaf in leaves]
        h = torch.cat([walk.states[level][0][:, [pos]] for level, pos in places], dim=1)
        c = torch.cat([walk.states[level][1][:, [pos]] for level, pos in places], dim=1)
        x = model.embed(torch.tensor([[trie.token[leaf], *ctx[:-1]] for leaf in leaves]))  # (N, k, E)
        out, _ = model.rnn(x, (h, c))
        k = len(ctx)
        rows = out.reshape(len(leaves) * k, -1)
        edge = self._edge_logprobs(rows, torch.arange(len(rows)), torch.tensor(ctx * len(leaves)))
        return edge.reshape(len(leaves), k).sum(-1).tolist()


def _normed(total: float, n: int, norm: str) -> float:
    return total / max(n, 1) if norm == "mean" else total


@dataclass
class _Walk:
    """A pass over a trie of texts: each text's total, and the LSTM states kept for continuing it."""

    trie: _Trie
    totals: list[float]
    state_of: dict[int, tuple[int, int]]  # node -> (index into states, position in that batch)
    states: list[tuple[torch.Tensor, torch.Tensor]]
