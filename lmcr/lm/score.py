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

Precision (`precision`): "auto" runs the LSTM and multiplies the decoder in bfloat16 where the CPU
does so natively, as training's "auto" autocast ran them (it puts the LSTM and every product in bf16),
else fp32; the softmax and the sums stay fp32. A completion's calls have few rows, so they are bound by
reading weights (the decoder's 14k x 256, each LSTM layer's 2 x 1024 x 256), and bf16 halves that. The
kernels are oneDNN's; the decoder and the trie walk's one-step LSTM calls use weights laid out for it
once (`_prepacked`, `_OneStep`), where `F.linear` and `nn.LSTM` would lay them out at every call.
Log-probabilities move by a few hundredths of a nat per text (README: what that does to Table I and
the dev instructions). Where the CPU has no bf16 (AVX2 only), "auto" holds the decoder's and the
LSTM's weights in fp16 instead, through fbgemm's kernel for them (fp32 sums), and the LSTM reads the
shared prefix a step at a time with them too (`_OneStep`): completion among 40 objects went from 20.5
to 17.6 ms p50, 30.4 to 22.9 ms with a purpose clause (interleaved runs, 2 cores), and on the full
store no score moved by more than 0.0035 nats (Table I, the dev instructions and every external
request's best guess unchanged). "fp32" keeps every product in fp32.
"""

from __future__ import annotations

import copy
import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass

import torch
from torch.nn import functional as F

from lmcr.lexicon import Lexicon
from lmcr.lm.checkpoint import Checkpoint
from lmcr.lm.linearize import linearize, tokens
from lmcr.lm.train import pick_precision
from lmcr.lm.vocab import BOS, UNK

NORMS = ("sum", "mean")
# Frames whose score reads the instruction's context (`LMScorer.score_frames`): the best by the frame
# alone. A dev scene holds 4-5 objects, so there every frame reads it; the cap bounds the cost in large
# scenes. With every dev instruction's scene filled to 40 objects, the caps 3, 5, 7 and 10 pick the same
# objects (`bench/bench_complete.py --scene-size 40`), and each frame read costs a decoder row per word.
CONTEXT_TOP = 5
DECODER_BLOCK = 4096  # rows per decoder call: 4096 x 14k-word vocabulary = 235 MB of logits at most


def _native_rnn(rnn, x: torch.Tensor, state=None):
    """`rnn` on `x` with PyTorch's own kernel (only the oneDNN flag changes, for the call): oneDNN's
    builds a primitive per call, ~0.3 ms for the trie walk's one-step, few-row fp32 calls against
    ~0.1 ms (same numbers to 1e-5). (`torch.backends.mkldnn.flags` would also reset the TF32 setting,
    and warn about it.)"""
    before = torch.backends.mkldnn.enabled
    torch.backends.mkldnn.enabled = False
    try:
        return rnn(x, state)
    finally:
        torch.backends.mkldnn.enabled = before


def _prepacked(weight: torch.Tensor, bias: torch.Tensor | None = None) -> Callable[[torch.Tensor], torch.Tensor]:
    """x -> x @ weight.T + bias, the weight put in oneDNN's layout once, here. `F.linear` lays it out
    again at every call, which for a completion's few rows costs more than the product (the decoder's
    14k x 256 in bf16: 0.30 -> 0.14 ms for 7 rows, 0.85 -> 0.67 ms for 40). The ops are PyTorch's own,
    those its compiler uses for frozen CPU models; `F.linear` where this build lacks them or oneDNN has
    no bf16 on this CPU. The same numbers as `F.linear` (tests/test_lm.py)."""
    try:
        usable = torch.backends.mkldnn.is_available() and (
            weight.dtype != torch.bfloat16 or torch.ops.mkldnn._is_mkldnn_bf16_supported()
        )
        packed = torch.ops.mkldnn._reorder_linear_weight(weight, None) if usable else None
    except (AttributeError, RuntimeError):  # a build without these oneDNN ops
        packed = None
    if packed is None:  # inputs in the weight's precision, as the packed product takes them
        return lambda x: F.linear(x.to(weight.dtype), weight, None if bias is None else bias.to(weight.dtype))
    return lambda x: torch.ops.mkldnn._linear_pointwise(x, packed, bias, "none", [], "")


Product = Callable[[torch.Tensor], torch.Tensor]


def _half_weights(weight: torch.Tensor, bias: torch.Tensor | None = None) -> Product | None:
    """x -> x @ weight.T + bias with the weight held in fp16 and the products summed in fp32 (fbgemm's
    kernel, which AVX2 runs converting fp16 as it loads it), or None where this build lacks it. Where
    the CPU has no bf16, a completion's products are bound by reading the weights (the decoder's
    14k x 256; bench/bench_complete.py), and fp16 halves that; see `LMScorer` for what it changes."""
    try:
        packed = torch.ops.quantized.linear_prepack_fp16(
            weight.detach().float(), None if bias is None else bias.detach().float()
        )

        def product(x: torch.Tensor) -> torch.Tensor:
            return torch.ops.quantized.linear_dynamic_fp16(x.float(), packed)

        product(torch.zeros(1, weight.shape[1]))  # a CPU fbgemm cannot run on fails here, not in a completion
    except (AttributeError, NotImplementedError, RuntimeError):  # a build or a CPU without fbgemm
        return None
    return product


class _OneStep:
    """An LSTM a time step at a time, each layer's four gates one product of [input, h] with the weights
    laid out once (`_prepacked`, or `_half_weights` where `half`); the gates and the cell in fp32. The
    trie walk's calls below the shared prefix are one step for a few rows, where oneDNN's LSTM, laying
    out its weights at every call, takes 0.3 ms and this 0.14 ms (bf16, 3 rows, 2 layers of 256). With
    fp16 weights it also reads the shared prefix, a step at a time."""

    def __init__(self, rnn: torch.nn.LSTM, half: bool = False):
        self.dtype = torch.float32 if half else rnn.weight_ih_l0.dtype
        self.hidden = (rnn.num_layers, rnn.hidden_size)
        product = _half_weights if half else _prepacked
        self.layers = [
            product(
                torch.cat([getattr(rnn, f"weight_ih_l{k}"), getattr(rnn, f"weight_hh_l{k}")], 1).detach(),
                (getattr(rnn, f"bias_ih_l{k}") + getattr(rnn, f"bias_hh_l{k}")).detach().float(),
            )
            for k in range(rnn.num_layers)
        ]

    def __call__(self, x: torch.Tensor, state: tuple[torch.Tensor, torch.Tensor] | None = None):
        """x (B, T, E) and state ((layers, B, H) twice, None: zeros), fp32, as `nn.LSTM` takes and gives them."""
        if state is None:
            zeros = torch.zeros(self.hidden[0], x.shape[0], self.hidden[1])
            state = (zeros, zeros)
        outputs = []
        for t in range(x.shape[1]):
            inp, hs, cs = x[:, t], [], []
            for k, gates in enumerate(self.layers):
                i, f, g, o = gates(torch.cat([inp, state[0][k]], 1).to(self.dtype)).float().chunk(4, 1)
                c = torch.sigmoid(f) * state[1][k] + torch.sigmoid(i) * torch.tanh(g)
                inp = torch.sigmoid(o) * torch.tanh(c)
                hs.append(inp)
                cs.append(c)
            outputs.append(inp)
            state = (torch.stack(hs), torch.stack(cs))
        return torch.stack(outputs, 1), state


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
        self.lex: Lexicon | None = None  # whose templates frames are read with (None: the workspace's lexicon)
        decoder = self.model.decoder
        self.precision = pick_precision(precision, decoder.weight.device)
        dtype = torch.bfloat16 if self.precision == "bf16" else decoder.weight.dtype
        self._decoder = (decoder.weight.detach().to(dtype), decoder.bias.detach())
        # "auto" without bf16: fp16 weights (the decoder's, then the LSTM's) where fbgemm's kernel runs here
        half = _half_weights(self._decoder[0]) if precision == "auto" and self.precision == "fp32" else None
        self.half = half is not None
        self._decode = half or _prepacked(self._decoder[0])
        # The LSTM in the same precision, a copy: the model's own weights stay fp32 for training code.
        self._rnn = copy.deepcopy(self.model.rnn).to(dtype) if dtype != decoder.weight.dtype else self.model.rnn
        self._step = _OneStep(self._rnn, self.half)
        self._unk = self.vocab.words.index(UNK)
        with torch.no_grad():  # the LSTM's output and state after <s>, where every text starts (`_prefix`)
            self._start = self._lstm(self.model.embed(torch.tensor([[self.vocab.words.index(BOS)]])), few_rows=True)

    def _lstm(self, x: torch.Tensor, state=None, few_rows: bool = False):
        """The LSTM on `x` (B, T, E) from `state`, in the scorer's precision; fp32 in and out. One step
        from a state (the trie walk below the shared prefix), and every run with fp16 weights, is
        `_OneStep`; longer runs are oneDNN's in bf16, and in fp32 PyTorch's own kernel for `few_rows`
        (`_native_rnn`)."""
        if self.half or (x.shape[1] == 1 and state is not None):
            return self._step(x, state)
        if self._rnn is self.model.rnn:
            return _native_rnn(self._rnn, x, state) if few_rows else self._rnn(x, state)
        low = self._decoder[0].dtype
        out, (h, c) = self._rnn(x.to(low), None if state is None else (state[0].to(low), state[1].to(low)))
        return out.float(), (h.float(), c.float())

    def _prefix(self, ids: list[int]) -> tuple[torch.Tensor, tuple[torch.Tensor, torch.Tensor]]:
        """The LSTM over a shared prefix (`ids`, <s> first as `encode` gives it), from the state after <s>
        that `__init__` read: the same for every text, so no request pays for it."""
        first, state = self._start
        if len(ids) == 1:
            return first, state
        out, state = self._lstm(self.model.embed(torch.tensor([ids[1:]])), state, few_rows=True)
        return torch.cat([first, out], 1), state

    def encode(self, text: str) -> list[int]:
        ids = self.vocab.encode(tokens(text, self.checkpoint.articles))
        return ids if self.score_end else ids[:-1]

    def logprobs(self, texts: list[str]) -> list[tuple[float, int]]:
        """(total log-probability, number of scored tokens) for each text."""
        out: list[tuple[float, int]] = []
        for start in range(0, len(texts), self.chunk):
            seqs = [self.encode(t) for t in texts[start : start + self.chunk]]
            totals = self._score(seqs)
            out += [(totals[i], len(seq) - 1) for i, seq in enumerate(seqs)]
        return out

    def score(self, texts: list[str], norm: str = "sum") -> list[float]:
        if norm not in NORMS:  # a bug: no command or configuration sets `norm`
            raise ValueError(f"norm must be one of {NORMS}")
        return [_normed(total, n, norm) for total, n in self.logprobs(texts)]

    def score_frames(
        self,
        frames: list[tuple[str, dict[str, str]]],
        context: str = "",
        norm: str = "sum",
        spans: list[tuple[int, int]] | None = None,
    ) -> list[float]:
        """Scores of complete frames (predicate, roles) in this checkpoint's linearisation; with
        `context`, of each frame's text followed by it ("pour milk into mug" + "for my tea"): the score
        adds log P(context | frame), how well the frame serves what was said around it (`add_context`:
        read after the CONTEXT_TOP best frames of each of `spans`, by default all). The context continues
        the LSTM from where each frame's text ended (`_Walk`), so the frames are not read twice."""
        if norm not in NORMS:  # a bug: no command or configuration sets `norm`
            raise ValueError(f"norm must be one of {NORMS}")
        ctx = self.context_ids(context)
        if not frames or not ctx:
            return self.score(self.frame_texts(frames), norm)  # in chunks: an evaluation's frames come at once
        walk = self.read_texts(self.frame_texts(frames))
        lengths = [len(seq) - 1 for seq in walk.seqs]
        scores = [_normed(total, n, norm) for total, n in zip(walk.totals, lengths)]

        def gains(top: list[int]) -> list[float]:
            extra = self.context_logprobs(walk, top, ctx)
            return [_normed(walk.totals[i] + x, lengths[i] + len(ctx), norm) - scores[i] for i, x in zip(top, extra)]

        return add_context(scores, gains, spans)

    def score_frame_groups(
        self, groups: list[list[tuple[str, dict[str, str]]]], context: str = ""
    ) -> list[list[float]]:
        """`score_frames` of each group, all read in one pass (`in_one_pass`)."""
        return in_one_pass(self.score_frames, groups, context)

    def frame_texts(self, frames: list[tuple[str, dict[str, str]]]) -> list[str]:
        return [linearize(self.checkpoint.linearization, predicate, roles, self.lex) for predicate, roles in frames]

    def context_ids(self, context: str) -> list[int]:
        """The context's token ids as this model reads them after a frame (no <s>, no </s>)."""
        return self.vocab.encode(tokens(context, self.checkpoint.articles))[1:-1] if context else []

    def reads_like(self, other: LMScorer) -> bool:
        """Whether this model reads a frame as the same text as `other` does (`frame_texts`)."""
        return self.checkpoint.linearization == other.checkpoint.linearization and self.lex is other.lex

    def read_texts(self, texts: list[str]) -> _Walk:
        """One walk over frames' texts (`walk.totals`: each one's total log-probability) that keeps the
        LSTM states a context is read on from (`context_logprobs`)."""
        return self._walk([self.encode(t) for t in texts], keep_states=True)

    def context_logprobs(self, walk: _Walk, which: list[int], ctx: list[int]) -> list[float]:
        """log P(context | frame) for the frames `which` of a `read_texts` walk."""
        return self._continue(walk, [walk.trie.leaf_of[i] for i in which], ctx)  # oneDNN: one call, many rows

    @torch.no_grad()
    def _score(self, seqs: list[list[int]]) -> list[float]:
        if not seqs:
            return []
        return self._walk(seqs).totals

    def _edge_logprobs(self, rows: torch.Tensor, picks: torch.Tensor, tokens_: torch.Tensor) -> torch.Tensor:
        """log P(tokens_[j] | rows[picks[j]]) for each j, an unknown word charged its share of <unk>. The
        decoder's softmax runs once over all rows, a block at a time (one read of its weights per block,
        bounded memory), instead of once per trie level."""
        unknown = (tokens_ == self._unk) * math.log(self.vocab.unk_types)
        # a completion's few rows skip the blocks' bookkeeping: 0.2-0.35 ms less per completion (paired runs)
        if len(rows) <= DECODER_BLOCK:
            return F.log_softmax(self._logits(rows), dim=-1)[picks, tokens_] - unknown
        edge = torch.empty(len(picks))
        for start in range(0, len(rows), DECODER_BLOCK):
            logp = F.log_softmax(self._logits(rows[start : start + DECODER_BLOCK]), dim=-1)
            mine = (picks >= start) & (picks < start + DECODER_BLOCK)
            edge[mine] = logp[picks[mine] - start, tokens_[mine]]
        return edge - unknown

    def _logits(self, rows: torch.Tensor) -> torch.Tensor:
        """The decoder's fp32 logits of LSTM output `rows`, multiplied in the scorer's precision."""
        weight, bias = self._decoder
        return torch.add(self._decode(rows.to(weight.dtype)), bias)  # fp32 out: one pass, no copy

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
        out, state = self._prefix(seqs[0][:shared])  # (1, L, H)
        rows, row_of = [out[0]], {n: n for n in range(shared)}
        walk = _Walk(trie, seqs, [], {}, [])
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
            out, frontier = self._lstm(x, (frontier[0][:, pick], frontier[1][:, pick]), few_rows=True)
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
            edge[1:] = self._edge_logprobs(
                torch.cat(rows),
                torch.tensor([row_of[trie.parent[n]] for n in children]),
                torch.tensor([trie.token[n] for n in children]),
            )
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
        out, _ = self._lstm(x, (h, c))
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
    seqs: list[list[int]]  # the texts' token ids
    totals: list[float]
    state_of: dict[int, tuple[int, int]]  # node -> (index into states, position in that batch)
    states: list[tuple[torch.Tensor, torch.Tensor]]


def add_context(
    scores: list[float], gains_of: Callable[[list[int]], list[float]], spans: list[tuple[int, int]] | None = None
) -> list[float]:
    """`scores` plus each frame's context term: `gains_of(tops)` for the CONTEXT_TOP best frames of each
    span of frames (`spans`, [start, end) each; by default all the frames), the lowest of a span's for its
    others. Every frame that reads the context costs a softmax over the vocabulary per word, and a frame
    this far down is not what was meant. The spans' best are read in one call."""
    spans = [(0, len(scores))] if spans is None else spans
    tops = [sorted(range(*span), key=lambda i: -scores[i])[:CONTEXT_TOP] for span in spans]
    read = [i for top in tops for i in top]
    gains = dict(zip(read, gains_of(read))) if read else {}
    out = list(scores)
    for (start, end), top in zip(spans, tops):
        floor = min((gains[i] for i in top), default=0.0)
        for i in range(start, end):
            out[i] += gains.get(i, floor)
    return out


def in_one_pass(
    score_frames: Callable[..., list[float]], groups: list[list[tuple[str, dict[str, str]]]], context: str
) -> list[list[float]]:
    """Each group's scores, as `score_frames(group, context)` gives them, from one call on all the groups'
    frames: one walk of their texts' trie and one read of the context after the best of each group, not a
    walk and a read per group (a completion's frames and the stated_pmi term's masked frames)."""
    frames = [f for group in groups for f in group]
    ends = list(itertools.accumulate(len(group) for group in groups))
    spans = list(zip([0, *ends[:-1]], ends))
    scores = score_frames(frames, context, spans=spans) if frames else []
    return [scores[start:end] for start, end in spans]


class MixedLM:
    """Corpus LMs interpolated, P(frame) = sum_i w_i P_i(frame) (the weights from `lmcr/scorers/mixture.py`),
    with the context read by the first, the LM of every corpus: log P(frame) + log P_1(context | frame).

    Only the first reads it because only its corpus teaches purposes: 5% of the recipe sentences have a
    "for ..." (the purpose clauses a context is made of), 0.3% of the household ones (kitchen
    narrations: "pour milk into cup"), so a household LM's P("for my tea" | frame) says little
    beyond its own text. And each LM that reads the context costs a decoder pass over its rows."""

    def __init__(self, experts: list[tuple[float, LMScorer]]):
        if not experts or any(w <= 0 for w, _ in experts):  # a bug: lm_experts keeps positive weights only
            raise ValueError("a mixture needs LMs with positive weights")
        if any(not lm.reads_like(experts[0][1]) for _, lm in experts):  # a bug: _lm_scorer gives them one lexicon
            raise ValueError("a mixture's LMs must read a frame as the same text")
        self.experts = [(math.log(w), lm) for w, lm in experts]

    def score_frames(
        self, frames: list[tuple[str, dict[str, str]]], context: str = "", spans: list[tuple[int, int]] | None = None
    ) -> list[float]:
        """log sum_i w_i P_i(frame), plus log P_1(context | frame) with a context (read after the best of
        each of `spans`, as `LMScorer.score_frames`)."""
        (_, first), *rest = self.experts
        ctx = first.context_ids(context)
        texts = first.frame_texts(frames)  # once: the experts read frames alike
        walk = first.read_texts(texts) if ctx and frames else None
        columns = [walk.totals if walk else first.score(texts), *(lm.score(texts) for _, lm in rest)]
        mixed = [logsumexp([w + s for (w, _), s in zip(self.experts, values)]) for values in zip(*columns)]
        if walk is None:
            return mixed
        return add_context(mixed, lambda top: first.context_logprobs(walk, top, ctx), spans)

    def score_frame_groups(
        self, groups: list[list[tuple[str, dict[str, str]]]], context: str = ""
    ) -> list[list[float]]:
        """`score_frames` of each group, all read in one pass (`in_one_pass`)."""
        return in_one_pass(self.score_frames, groups, context)


def logsumexp(values: list[float]) -> float:
    top = max(values)
    return top + math.log(sum(math.exp(v - top) for v in values))
