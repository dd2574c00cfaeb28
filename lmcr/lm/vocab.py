"""Word vocabulary with a frequency cut-off: rare words share `<unk>`."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

PAD, UNK, BOS, EOS = "<pad>", "<unk>", "<s>", "</s>"
SPECIALS = (PAD, UNK, BOS, EOS)


@dataclass(frozen=True)
class Vocab:
    """Index <-> word; index 0 is padding (ignored by the loss).

    `unk_types` is how many distinct training words `<unk>` stands for: a scorer charges an unknown
    word log(unk_types), its share of the pooled probability, so a rare object is not scored as if it
    were the whole rare-word mass.
    """

    words: tuple[str, ...]
    unk_types: int = 1

    def __post_init__(self) -> None:
        object.__setattr__(self, "_index", {w: i for i, w in enumerate(self.words)})

    @classmethod
    def build(cls, sequences: Iterable[list[str]], min_freq: int = 3, max_size: int = 30_000) -> Vocab:
        """Words seen at least `min_freq` times, the `max_size` most frequent (ties broken alphabetically)."""
        counts = Counter(w for seq in sequences for w in seq)
        kept = sorted(
            (w for w, n in counts.items() if n >= min_freq and w not in SPECIALS), key=lambda w: (-counts[w], w)
        )[: max_size - len(SPECIALS)]
        return cls(SPECIALS + tuple(kept), max(1, len(counts) - len(kept)))

    def __len__(self) -> int:
        return len(self.words)

    def encode(self, words: list[str]) -> list[int]:
        """<s> words </s> as ids, unknown words as <unk>."""
        unk = self._index[UNK]
        return [self._index[BOS]] + [self._index.get(w, unk) for w in words] + [self._index[EOS]]

    def to_json(self) -> dict:
        return {"words": list(self.words), "unk_types": self.unk_types}

    @classmethod
    def from_json(cls, data: dict) -> Vocab:
        return cls(tuple(data["words"]), int(data["unk_types"]))
