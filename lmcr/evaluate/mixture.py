"""Choosing a corpus's mixture weight on rated frames: Table I accuracy of one method under each
weight of a short grid; the best wins, ties going to the smaller weight (the plain pool when it ties)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from lmcr.evaluate.protocol import EvalConfig, evaluate, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.files import file_sha256
from lmcr.methods import MethodResources, make_scorer
from lmcr.mixture import GRID, Mixture, save


def choose_mixture(rated: list[RatedFrame], res: MethodResources, method: str, corpus: str = "household",
                   grid: tuple[float, ...] = GRID, config: EvalConfig = EvalConfig(),
                   log: Callable[[str], None] = print) -> tuple[Mixture, dict[float, float]]:
    """The weight of `corpus` (others 1) under which `method` ranks the rated frames best at Table I's
    lambda and k, and the accuracy of every weight tried."""
    accuracy: dict[float, float] = {}
    for weight in sorted(grid):
        mixed = replace(res, corpus="all", mixture=Mixture.of({corpus: weight}))
        scores = score_rated(rated, {method: make_scorer(method, mixed)})
        accuracy[weight] = evaluate(rated, scores, replace(config, lambdas=(), ks=())).table1[method]["all"]
        log(f"{method} with {corpus} weighted {weight:g}: Table I accuracy {accuracy[weight]:.3f}")
    best = max(accuracy, key=lambda w: (accuracy[w], -w))
    return Mixture.of({corpus: best}), accuracy


def choose_and_save(rated: list[RatedFrame], ratings: Path, res: MethodResources, method: str, data_dir: Path,
                    corpus: str = "household", grid: tuple[float, ...] = GRID, config: EvalConfig = EvalConfig(),
                    log: Callable[[str], None] = print) -> tuple[Mixture, Path]:
    """`choose_mixture` on the frames rated in `ratings`, saved in `data_dir` with how it was chosen."""
    chosen, accuracy = choose_mixture(rated, res, method, corpus, grid, config, log)
    path = save(data_dir, chosen, {"chosen_for": method, "corpus": corpus, "ratings": str(ratings),
                                   "ratings_sha256": file_sha256(Path(ratings)) if Path(ratings).is_file() else None,
                                   "accuracy": {f"{w:g}": round(a, 4) for w, a in accuracy.items()}})
    return chosen, path
