"""The frames stage's settings, each default defined once (spaCy-free, so the command line starts fast)."""

from __future__ import annotations

from dataclasses import dataclass

# A build keeps the previous build's compounds and first-word table (and so every text parsed with them)
# while the texts they have not parsed are at most this share of the corpus's distinct texts: a week's new
# file (about 5%) costs its own texts, while a corpus grown by more than a quarter, whose new register the
# old statistics may not know, has both learned anew and everything parsed again.
REUSE_SHARE = 0.25


@dataclass(frozen=True)
class FrameCorpusConfig:
    """Which sentences become frames and how the work is cut."""

    kinds: tuple[str, ...] = ("instruction", "comment")
    shard_size: int = 20_000
    model: str | None = None
    # Texts (spread over the corpus) the imperative first words are learned from before any shard is
    # parsed: 4% of the full corpus's distinct texts, about a minute of one process.
    first_word_sample: int = 40_000
    reuse_share: float = REUSE_SHARE
