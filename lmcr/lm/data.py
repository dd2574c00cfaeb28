"""Training sequences and length-bucketed batches (sorted by length: almost no padding)."""

from __future__ import annotations

import random

import torch


def bucket_batches(seqs: list[list[int]], max_tokens: int, seed: int | None = None) -> list[torch.Tensor]:
    """Batches of similar-length sequences, each at most `max_tokens` padded tokens, as (B, T) tensors;
    batch order shuffled with `seed` (None keeps length order, for evaluation)."""
    order = sorted(range(len(seqs)), key=lambda i: (len(seqs[i]), i))
    batches: list[list[int]] = []
    current: list[int] = []
    for i in order:
        # sorted ascending, so the newcomer is the longest: the padded size is (n + 1) * its length
        if current and (len(current) + 1) * len(seqs[i]) > max_tokens:
            batches.append(current)
            current = []
        current.append(i)
    if current:
        batches.append(current)
    if seed is not None:
        random.Random(seed).shuffle(batches)
    return [_pad([seqs[i] for i in batch]) for batch in batches]


def _pad(rows: list[list[int]]) -> torch.Tensor:
    out = torch.zeros(len(rows), max(len(r) for r in rows), dtype=torch.long)
    for k, row in enumerate(rows):
        out[k, : len(row)] = torch.tensor(row, dtype=torch.long)
    return out


def split_by_document(keys: list[str], val_fraction: float = 0.05) -> list[bool]:
    """True for held-out rows, chosen by a hash of the document key (no document on both sides)."""
    cut = int(val_fraction * 1000)
    held = [int.from_bytes(key.encode()[-8:].rjust(8, b"\0"), "big") * 2654435761 % 1000 < cut for key in keys]
    if not any(held) and len(set(keys)) > 1:  # a small corpus still gets one validation document
        held = [key == keys[-1] for key in keys]
    return held
