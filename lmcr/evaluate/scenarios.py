"""Scenarios of the paper's protocol and the accuracy of a method on them.

A rated frame is positive at threshold lambda when its mean rating is above 5 - lambda and negative
when below 1 + lambda (both when lambda >= 2). A scenario keeps the verb and one argument fixed and
offers one positive and k - 1 negatives for the other role; a method is right when the positive scores
highest, and a t-way tie at the top counts 1/t. Scenarios are drawn per verb with a seed derived from
the seed and the verb's name, so every method sees the same ones.
"""

from __future__ import annotations

import hashlib
import random
from collections import defaultdict
from dataclasses import dataclass

from lmcr.errors import LMCRError
from lmcr.evaluate.ratings import RatedFrame


class ScenarioError(LMCRError, ValueError):
    """Ratings that give no scenarios under the settings asked for (lambda, k)."""


@dataclass(frozen=True)
class Scenario:
    verb: str
    fixed_role: str
    fixed_value: str
    positive: RatedFrame
    negatives: tuple[RatedFrame, ...]

    @property
    def candidates(self) -> tuple[RatedFrame, ...]:
        return (self.positive,) + self.negatives


def label(mean: float, lam: float) -> set[str]:
    found = set()
    if mean > 5 - lam:
        found.add("positive")
    if mean < 1 + lam:
        found.add("negative")
    return found


def _groups(frames: list[RatedFrame]) -> dict[tuple[str, str, str], list[RatedFrame]]:
    """(verb, fixed role, fixed value) -> frames varying the other role."""
    groups: dict[tuple[str, str, str], list[RatedFrame]] = defaultdict(list)
    for f in frames:
        groups[(f.verb, f.role1, f.arg1)].append(f)
        groups[(f.verb, f.role2, f.arg2)].append(f)
    return groups


def verb_seed(seed: int, verb: str) -> int:
    return int.from_bytes(hashlib.sha256(f"{seed}:{verb}".encode()).digest()[:8], "big")


def build_scenarios(
    frames: list[RatedFrame], lam: float, k: int, per_verb: int = 50, seed: int = 0
) -> tuple[list[Scenario], dict[str, str]]:
    """Up to `per_verb` scenarios per verb, and for each verb with none the reason.

    Each scenario picks, with the verb's seed, a (group, positive) pair uniformly among all pairs whose
    group has at least k - 1 negatives, then k - 1 distinct negatives of that group. Pairs are drawn
    without replacement until exhausted, then with replacement (fresh negatives each time)."""
    by_verb: dict[str, list] = defaultdict(list)
    for (verb, role, value), members in sorted(_groups(frames).items()):
        pos = [f for f in members if "positive" in label(f.mean, lam)]
        neg = [f for f in members if "negative" in label(f.mean, lam)]
        if len(neg) >= k - 1:
            by_verb[verb] += [(role, value, p, neg) for p in pos if p not in neg]
    verbs = sorted({f.verb for f in frames})
    scenarios, skipped = [], {}
    for verb in verbs:
        pairs = by_verb.get(verb, [])
        if not pairs:
            skipped[verb] = f"no argument group with a positive and {k - 1} negatives at lambda={lam:g}"
            continue
        rng = random.Random(verb_seed(seed, verb))
        order = rng.sample(pairs, len(pairs))
        for i in range(per_verb):
            role, value, positive, negatives = order[i] if i < len(order) else rng.choice(pairs)
            scenarios.append(Scenario(verb, role, value, positive, tuple(rng.sample(negatives, k - 1))))
    return scenarios, skipped


def scenario_credit(scores: list[float]) -> float:
    """Credit of one scenario whose positive is candidate 0: 1/t when it shares the top with t - 1 others."""
    top = max(scores)
    if scores[0] < top:
        return 0.0
    return 1.0 / sum(1 for s in scores if s == top)


def accuracy(scenarios: list[Scenario], score: dict[tuple, float]) -> dict[str, float]:
    """Per-verb and overall ('all') accuracy given each rated frame's score."""
    credit: dict[str, list[float]] = defaultdict(list)
    for sc in scenarios:
        c = scenario_credit([score[f.key] for f in sc.candidates])
        credit[sc.verb].append(c)
        credit["all"].append(c)
    return {verb: sum(v) / len(v) for verb, v in sorted(credit.items())}
