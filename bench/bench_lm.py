"""Benchmark: LMCR's LM training vs the PyTorch word_language_model example configuration, and scoring.

Usage: python bench/bench_lm.py [--db STORE] [--tokens N] [--checkpoint DIR ...] [--ratings CSV] [--skip-training]
       [--json PATH]
1. Both trainers get the same recipe sentences (first N training tokens, same vocabulary, same
   held-out documents) on this machine: the reference for one epoch, ours epoch by epoch until its
   validation perplexity is at least as good (at most --max-epochs). The reference is the example's default
   configuration re-implemented: 2-layer LSTM, 200 embedding/hidden, dropout 0.2, untied, full
   softmax, a continuous token stream in 20 columns, BPTT 35, SGD lr 20, clip 0.25. Prints tokens/s,
   validation perplexity (per sentence, both the same way), the speed ratio and the training time each
   needed for that perplexity.
2. Scoring: candidate frames/s for every verb x object x object combination of the robot's vocabulary
   with each published checkpoint given, and with --ratings the Spearman correlation of its `sum` and
   `mean` scores with the mean dev rating (how the default normalisation was chosen).
"""

from __future__ import annotations

import argparse
import itertools
import math
import time
from pathlib import Path

import torch
from record import add_json_option, write_results
from scipy.stats import spearmanr
from torch import nn

from lmcr.evaluate.ratings import load_ratings
from lmcr.lexicon import load_lexicon
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import training_text
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.score import LMScorer
from lmcr.lm.train import TrainConfig, train_lm
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting
from lmcr.store import read_connection
from lmcr.workspace import Workspace

OBJECTS = load_lexicon().objects


class ExampleLM(nn.Module):
    """The word_language_model example's LSTM model at its defaults (untied, full softmax)."""

    def __init__(self, vocab: int, size: int = 200, layers: int = 2, dropout: float = 0.2):
        super().__init__()
        self.drop = nn.Dropout(dropout)
        self.encoder = nn.Embedding(vocab, size)
        self.rnn = nn.LSTM(size, size, layers, dropout=dropout)
        self.decoder = nn.Linear(size, vocab)

    def forward(self, x, hidden):
        out, hidden = self.rnn(self.drop(self.encoder(x)), hidden)
        return self.decoder(self.drop(out)), hidden


def train_example(stream: torch.Tensor, vocab: int, batch: int = 20, bptt: int = 35) -> float:
    """One epoch of the example's training loop; returns tokens/s."""
    torch.manual_seed(1111)
    model, loss_fn = ExampleLM(vocab), nn.CrossEntropyLoss()
    cols = stream[: stream.numel() // batch * batch].view(batch, -1).t().contiguous()  # (L, B)
    hidden = None
    model.train()
    started = time.perf_counter()
    for i in range(0, cols.size(0) - 1, bptt):
        seq = min(bptt, cols.size(0) - 1 - i)
        x, y = cols[i : i + seq], cols[i + 1 : i + 1 + seq]
        hidden = None if hidden is None else tuple(h.detach() for h in hidden)
        model.zero_grad()
        out, hidden = model(x, hidden)
        loss_fn(out.view(-1, vocab), y.reshape(-1)).backward()
        nn.utils.clip_grad_norm_(model.parameters(), 0.25)
        with torch.no_grad():
            for p in model.parameters():
                p.add_(p.grad, alpha=-20.0)
    tokens_per_s = cols.numel() / (time.perf_counter() - started)
    train_example.model = model
    return tokens_per_s


@torch.no_grad()
def example_val_ppl(model: ExampleLM, val: list[list[int]], vocab: int) -> float:
    """Per-sentence perplexity (fresh state per sentence), the same measure LMCR's trainer reports."""
    model.eval()
    total, count = 0.0, 0
    for seq in val:
        x = torch.tensor(seq[:-1]).unsqueeze(1)
        out, _ = model(x, None)
        total += float(nn.functional.cross_entropy(out.view(-1, vocab), torch.tensor(seq[1:]), reduction="sum"))
        count += len(seq) - 1
    return math.exp(total / count)


def scoring_speed(path: Path) -> dict:
    """Candidate frames per second of a checkpoint over every predicate x ordered object pair."""
    scorer = LMScorer(ckpt.load(path))
    lex = load_lexicon()
    frames = [
        (verb, dict(zip(spec.roles, pair)))
        for verb, spec in lex.predicates.items()
        for pair in itertools.permutations(OBJECTS, 2)
    ]
    scorer.score_frames(frames[:500])  # warm-up
    started = time.perf_counter()
    scorer.score_frames(frames)
    wall = time.perf_counter() - started
    name = scorer.checkpoint.path.parent.name
    print(f"scoring {name}: {len(frames):,} frames in {wall:.2f}s = {len(frames) / wall:,.0f} frames/s")
    return {
        f"scoring {name}: frames": len(frames),
        f"scoring {name}: s": round(wall, 2),
        f"scoring {name}: frames/s": round(len(frames) / wall),
    }


def normalisation_check(path: Path, ratings_csv: Path) -> dict:
    """Spearman correlation of each normalisation's scores with the mean crowd rating."""
    scorer = LMScorer(ckpt.load(path))
    rated = load_ratings(ratings_csv, Workspace.from_env().sql_dir)  # the store's validation and aggregation
    means = [r.mean for r in rated]
    name, rhos = scorer.checkpoint.path.parent.name, {}
    for norm in ("sum", "mean"):
        rhos[norm] = spearmanr(scorer.score_frames([r.frame for r in rated], norm=norm), means).statistic
    print(f"{name} on {len(rated)} rated dev frames: " + ", ".join(f"{k}: rho={v:.3f}" for k, v in rhos.items()))
    return {
        f"{name}: Spearman rho with the mean rating, {k} ({len(rated)} frames)": round(v, 3) for k, v in rhos.items()
    }


def training_speed(db: Path | None, tokens: int, max_epochs: int) -> dict:
    """The reference trainer for one epoch, ours until it reaches the reference's perplexity."""
    paths = Workspace.from_env(db=db)
    con = read_connection(paths.db)
    text = training_text(con, Setting("sentence", "recipes"))
    train, budget = [], tokens
    for seq in text.train:
        if budget <= 0:
            break
        train.append(seq[:60])
        budget -= len(seq) + 1
    val = [s[:60] for s in text.val[:3000]]
    vocab = Vocab.build(train, min_freq=3)
    train_ids, val_ids = [vocab.encode(s) for s in train], [vocab.encode(s) for s in val]
    stream = torch.tensor([t for s in train_ids for t in s[1:]])  # the example's <eos>-separated stream
    ref_started = time.perf_counter()
    ref_speed = train_example(stream, len(vocab))
    ref_seconds = time.perf_counter() - ref_started
    ref_ppl = example_val_ppl(train_example.model, val_ids, len(vocab))
    print(
        f"reference (word_language_model defaults): {ref_speed:,.0f} tokens/s, val ppl {ref_ppl:.1f} after 1 epoch "
        f"({ref_seconds:.0f}s)"
    )
    model = RecurrentLM(LMConfig(len(vocab)))
    seconds = 0.0

    def show(row: dict) -> None:
        nonlocal seconds
        seconds += row["seconds"]
        print(
            f"lmcr (defaults, {row['objective']} softmax, {row['precision']}) epoch {row['epoch']}: "
            f"{row['tokens_per_s']:,.0f} tokens/s, "
            f"val ppl {row['val_ppl']:.1f} ({seconds:.0f}s of training)"
        )

    # Ours trains until it matches the reference's perplexity (or --max-epochs): the speed claim is
    # tokens/s at equal or better perplexity, and the time to get there is printed beside it.
    history = train_lm(
        model, train_ids, val_ids, TrainConfig(max_epochs=max_epochs, target_ppl=ref_ppl, max_minutes=None), show
    )
    speed = sum(h["tokens_per_s"] * h["seconds"] for h in history) / seconds
    reached = history[-1]["val_ppl"] <= ref_ppl
    print(
        f"speed ratio {speed / ref_speed:.2f}x tokens/s; val ppl {history[-1]['val_ppl']:.1f} vs {ref_ppl:.1f} "
        f"{'reached' if reached else 'NOT reached'} after {len(history)} epoch(s), {seconds:.0f}s vs the "
        f"reference's {ref_seconds:.0f}s ({stream.numel():,} tokens, vocabulary {len(vocab):,})"
    )
    return {
        "training tokens": stream.numel(),
        "vocabulary": len(vocab),
        "reference tokens/s": round(ref_speed),
        "reference val ppl after 1 epoch": round(ref_ppl, 1),
        "lmcr tokens/s": round(speed),
        "lmcr val ppl": round(history[-1]["val_ppl"], 1),
        "lmcr epochs": len(history),
        "speed ratio": round(speed / ref_speed, 2),
        "reference ppl reached": reached,
        "lmcr precision": history[-1]["precision"],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--db", type=Path, default=None)
    parser.add_argument("--tokens", type=int, default=1_000_000)
    parser.add_argument("--checkpoint", type=Path, action="append", default=[])
    parser.add_argument(
        "--ratings", type=Path, default=None, help="dev ratings (MTurk CSV) for the normalisation check"
    )
    parser.add_argument("--skip-training", action="store_true")
    parser.add_argument("--max-epochs", type=int, default=3, help="epochs ours may take to reach the reference's ppl")
    add_json_option(parser, "bench_lm")
    args = parser.parse_args()
    figures = {}
    for path in args.checkpoint:
        figures |= scoring_speed(path)
        if args.ratings:
            figures |= normalisation_check(path, args.ratings)
    if not args.skip_training:
        figures |= training_speed(args.db, args.tokens, args.max_epochs)
    write_results(args.json, "bench_lm", __doc__.splitlines()[0], figures)


if __name__ == "__main__":
    main()
