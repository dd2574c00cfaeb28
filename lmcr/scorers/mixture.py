"""Per-corpus mixture weights: how much each source corpus counts when the `all` setting pools them.

The household narrations are about 1% of the text but know what the recipes do not (milk goes into a
glass to drink, dirty water into the sink). A weight w makes each household frame count w times in the
frame counts, and gives the household LM the share of the weighted text in a linear interpolation with
the all-corpora LM: P(text) = (1 - s) P_all(text) + s P_household(text), s = w N_h / (N + (w - 1) N_h)
with N words in all and N_h in household. w = 1 for every corpus is the plain pooled setting.

The weight is learned, not written by hand: `lmcr mixture` scores the dev ratings with each candidate of
a short grid and keeps the best for the default completion method (Table I accuracy at lambda=1, k=6;
with dev instructions, the mean of that and the share of instructions completed right). With
instructions it chooses the weight of the context term (lmcr/scorers/context_pmi.py) on them at the same time:
the rated frames have no context, so that weight changes the instructions alone. Both are saved as
`mixture.json` in the data folder (with the candidates' accuracies and the dev files' hashes), read by
every command that builds scorers, and part of every scorer fingerprint built with them, so a completion
calibration made under one choice is never used under another.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from lmcr.errors import LMCRError
from lmcr.files import atomic_path
from lmcr.setting import SOURCE_CORPORA

FILE = "mixture.json"
GRID = (1.0, 3.0, 10.0, 30.0, 100.0)  # candidate weights for a corpus: a short log-spaced grid


class MixtureError(LMCRError, ValueError):
    """A mixture that names no corpus or a weight that is not a positive number."""


@dataclass(frozen=True)
class Mixture:
    """Corpus -> weight (corpora not named weigh 1), sorted by corpus so equal mixtures are equal."""

    weights: tuple[tuple[str, float], ...] = ()

    @classmethod
    def of(cls, weights: dict[str, float]) -> Mixture:
        for corpus, weight in weights.items():
            if corpus not in SOURCE_CORPORA:
                raise MixtureError(f"mixture: unknown corpus {corpus!r} (one of {', '.join(SOURCE_CORPORA)})")
            if not _positive(weight):
                raise MixtureError(f"mixture: weight of {corpus} must be a positive number, not {weight!r}")
        return cls(tuple(sorted((c, float(w)) for c, w in weights.items() if w != 1)))

    @classmethod
    def parse(cls, text: str) -> Mixture:
        """'household=30' or 'household=30,youcook2=2'; '' or 'plain' is the plain mixture."""
        weights = {}
        text = "" if text.strip() == "plain" else text
        for item in filter(None, (part.strip() for part in text.split(","))):
            corpus, sep, value = item.partition("=")
            if not sep:
                raise MixtureError(f"mixture: write corpus=weight, not {item!r}")
            try:
                weights[corpus.strip()] = float(value)
            except ValueError:
                raise MixtureError(f"mixture: weight of {corpus.strip()} must be a number, not {value!r}") from None
        return cls.of(weights)

    def weight(self, corpus: str) -> float:
        return dict(self.weights).get(corpus, 1.0)

    @property
    def plain(self) -> bool:
        return not self.weights

    @property
    def label(self) -> str:
        """'household=30', or 'plain': how method names, fingerprints and reports name it (`parse` reads it)."""
        return ",".join(f"{c}={w:g}" for c, w in self.weights) or "plain"

    def parts(self, corpus: str) -> dict[str, float]:
        """What a count over the setting `corpus` adds up, each part with its weight: the setting itself
        (weight 1), unless it pools corpora under weights (`all` with a mixture): then each source corpus."""
        if corpus != "all" or self.plain:
            return {corpus: 1.0}
        return {c: self.weight(c) for c in SOURCE_CORPORA}

    def shares(self, words: dict[str, int]) -> dict[str, float]:
        """Each weighted corpus's share of the weighted words: its LM's interpolation weight."""
        total = sum(self.weight(c) * n for c, n in words.items())
        return {c: self.weight(c) * words.get(c, 0) / total for c, _ in self.weights if total}


def _read(path: Path) -> dict:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
        if not isinstance(data, dict):
            raise TypeError("not a JSON object")
        return data
    except (ValueError, TypeError) as exc:
        raise MixtureError(f"{path}: not a mixture file ({exc}); run `lmcr mixture` again") from exc


def load_choice(data_dir: Path) -> tuple[Mixture, float | None]:
    """The mixture chosen by `lmcr mixture` and saved in `data_dir`, and the weight of the context term
    (lmcr/scorers/context_pmi.py) chosen with it on the dev instructions: (plain, None) without a file, None for
    a mixture chosen on rated frames alone. One read for both."""
    path = Path(data_dir) / FILE
    if not path.exists():
        return Mixture(), None
    data = _read(path)
    try:
        mixture = Mixture.of(data["weights"])
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise MixtureError(f"{path}: not a mixture file ({exc}); run `lmcr mixture` again") from exc
    weight = data.get("context_weight")
    if weight is not None and not _positive(weight):
        raise MixtureError(
            f"{path}: context_weight must be a positive number, not {weight!r}; run `lmcr mixture` again"
        )
    return mixture, weight


def load(data_dir: Path) -> Mixture:
    """The chosen mixture saved in `data_dir`, plain when none was chosen."""
    return load_choice(data_dir)[0]


def save(data_dir: Path, mixture: Mixture, provenance: dict, context_weight: float | None = None) -> Path:
    """Write `mixture.json` atomically: the weights (and the context term's, when chosen) and how they
    were chosen."""
    path = Path(data_dir) / FILE
    chosen = {"weights": dict(mixture.weights), **({"context_weight": context_weight} if context_weight else {})}
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps({**chosen, **provenance}, indent=2), encoding="utf-8")
    return path


def _positive(weight) -> bool:
    return isinstance(weight, (int, float)) and not isinstance(weight, bool) and 0 < weight < float("inf")
