"""The frames stage's settings, each default defined once (spaCy-free, so the command line starts fast)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class FrameCorpusConfig:
    """Which sentences become frames and how the work is cut."""

    kinds: tuple[str, ...] = ("instruction", "comment")
    shard_size: int = 20_000
    model: str | None = None
    # Texts (spread over the corpus) the imperative first words are learned from before any shard is
    # parsed: 4% of the full corpus's distinct texts, about a minute of one process.
    first_word_sample: int = 40_000
