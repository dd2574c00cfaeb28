"""Table I and the Fig. 4 sweeps: every method's accuracy on the same seeded scenarios."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from lmcr.evaluate.ratings import RatedFrame
from lmcr.evaluate.scenarios import accuracy, build_scenarios

LAMBDAS = (0.6, 0.8, 1.0, 1.2, 1.4, 1.6, 1.8, 2.0)
KS = (4, 6, 10, 20, 30, 40)


@dataclass(frozen=True)
class EvalConfig:
    lam: float = 1.0  # Table I and the k sweep
    k: int = 6  # Table I and the lambda sweep
    lambdas: tuple[float, ...] = LAMBDAS
    ks: tuple[int, ...] = KS
    per_verb: int = 50
    seed: int = 0
    # a k whose scenarios cover fewer verbs than this is skipped (too few negatives), and said so
    min_verbs: int = 3


@dataclass
class Results:
    config: EvalConfig
    table1: dict[str, dict[str, float]] = field(default_factory=dict)  # method -> verb/'all' -> accuracy
    vs_lambda: dict[str, dict[float, float]] = field(default_factory=dict)
    vs_k: dict[str, dict[int, float]] = field(default_factory=dict)
    scenarios: dict[str, int] = field(default_factory=dict)  # "lambda=1,k=6" -> count
    skipped: dict[str, dict[str, str]] = field(default_factory=dict)  # sweep point -> verb -> reason
    skipped_k: dict[int, str] = field(default_factory=dict)

    def to_json(self) -> dict:
        return {
            "config": self.config.__dict__,
            "table1": self.table1,
            "vs_lambda": {m: {f"{x:g}": a for x, a in v.items()} for m, v in self.vs_lambda.items()},
            "vs_k": {m: {str(x): a for x, a in v.items()} for m, v in self.vs_k.items()},
            "scenarios": self.scenarios,
            "skipped": self.skipped,
            "skipped_k": {str(k): why for k, why in self.skipped_k.items()},
        }


def score_rated(rated: list[RatedFrame], scorers: dict[str, Callable]) -> dict[str, dict[tuple, float]]:
    """Each method's score of every rated frame (one batched call per method)."""
    frames = [r.frame for r in rated]
    return {name: dict(zip((r.key for r in rated), fn(frames))) for name, fn in scorers.items()}


def evaluate(rated: list[RatedFrame], scores: dict[str, dict[tuple, float]], config: EvalConfig) -> Results:
    results = Results(config)

    def point(lam: float, k: int) -> list:
        scenarios, skipped = build_scenarios(rated, lam, k, config.per_verb, config.seed)
        name = f"lambda={lam:g},k={k}"
        results.scenarios[name] = len(scenarios)
        if skipped:
            results.skipped[name] = skipped
        return scenarios

    headline = point(config.lam, config.k)
    results.table1 = {m: accuracy(headline, s) for m, s in scores.items()}
    for lam in config.lambdas:
        scenarios = point(lam, config.k)
        for m, s in scores.items():
            results.vs_lambda.setdefault(m, {})[lam] = accuracy(scenarios, s).get("all", float("nan"))
    for k in config.ks:
        scenarios = point(config.lam, k)
        verbs = {sc.verb for sc in scenarios}
        if len(verbs) < config.min_verbs:
            results.skipped_k[k] = (
                f"only {len(verbs)} verbs have a positive and {k - 1} negatives at lambda={config.lam:g}"
            )
            continue
        for m, s in scores.items():
            results.vs_k.setdefault(m, {})[k] = accuracy(scenarios, s)["all"]
    return results
