"""How far the planning search of one instruction may go before the robot refuses, saying so: seconds of
wall clock and inverse-kinematics solves. A light module: the command line reads its defaults for the
options' help without loading the simulator."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

from lmcr.errors import LMCRError

# The whole search counts (every candidate, arm and grasp, every spot to set an object down first). The
# eleven predicates' plans take tens to hundreds of solves and a few seconds; setting an object down first
# took 200 to 1,100 solves; serving with a ladle, whose hand is headed five ways over the target, found its
# plan only after 2,000 solves in some layouts (4,000 serve 20/20 and 19/20 on two seeds, 2,000 16/20 and
# 18/20). The count stops a search at the same point on any machine, however busy. The wall clock bounds
# what a person waits: 25 s, so that a plan or a refusal comes within 30 s on 2 cores. No plan the
# benchmarks found took more than 11 s; what reached 25 s were refusals (a stir whose soup is out of the
# stir pose's reach from every spot the spoon could be set down at spent its 4,000 solves in 30-32 s on
# the official description), so the clock only binds on a search that would refuse anyway, or on a
# machine over twice as slow.
PLAN_SECONDS, IK_CALLS = 25.0, 4000
# the options' ranges: a budget too small to plan anything is still a budget (it refuses at once)
PLAN_SECONDS_RANGE = {"min": 0.01, "max": 3600.0}
IK_CALLS_RANGE = {"min": 1, "max": 10_000_000}
# The wall clock's default for a machine that is slower or busier than 2 cores (`--plan-seconds` reads it
# too); the test suite sets it to the range's top, so that the IK count alone decides what a search finds.
PLAN_SECONDS_ENV = "LMCR_PLAN_SECONDS"


class BudgetError(LMCRError, ValueError):
    """A budget given in the environment that is no budget."""


def default_plan_seconds() -> float:
    """The wall-clock budget when none is given: $LMCR_PLAN_SECONDS when set, else `PLAN_SECONDS`."""
    text = os.environ.get(PLAN_SECONDS_ENV, "").strip()
    if not text:
        return PLAN_SECONDS
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    low, high = PLAN_SECONDS_RANGE["min"], PLAN_SECONDS_RANGE["max"]
    if not low <= seconds <= high:  # also NaN
        raise BudgetError(f"${PLAN_SECONDS_ENV}={text!r}: not a number of seconds from {low:g} to {high:g}")
    return seconds


@dataclass(frozen=True)
class Budget:
    """The planning search's limits: `seconds` of wall clock, `ik_calls` poses solved."""

    seconds: float = field(default_factory=default_plan_seconds)
    ik_calls: int = IK_CALLS
