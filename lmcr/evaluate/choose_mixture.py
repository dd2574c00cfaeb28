"""Choosing a corpus's mixture weight on the dev sets: under each weight of a short grid, Table I
accuracy of one method on rated frames and, when instructions are given, the share of instructions it
completes right in their scenes. The best mean of the two wins (each dev set counts the same: the rated
frames are recipe steps, the instructions what people say to the robot at home), ties going to the
smaller weight (the plain pool when it ties). With instructions, the weight of the method's context term
(lmcr/scorers/context_pmi.py) is chosen at the same time, on the instructions: the rated frames have none."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from lmcr.complete import CompletionConfig
from lmcr.evaluate.instructions import instruction_accuracy, load_instructions
from lmcr.evaluate.protocol import EvalConfig, evaluate, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.files import file_sha256
from lmcr.jsonl import InputError
from lmcr.scorers.context_pmi import GRID as CONTEXT_GRID
from lmcr.scorers.mixture import GRID, Mixture, save
from lmcr.scorers.registry import make_scorer
from lmcr.scorers.resources import MethodResources


@dataclass(frozen=True)
class DevInstructions:
    """Instructions to choose on as well: their records, the file they came from and the parser."""

    records: list[dict]
    path: Path
    parser: object

    @classmethod
    def read(cls, path: Path, make_parser: Callable[[], object]) -> DevInstructions:
        """The instructions of a JSONL file (a bad line or an empty file raises InputError), and the
        parser, made once the file is known to be good."""
        records = load_instructions(Path(path))
        if not records:
            raise InputError(f"{path}: no instructions")
        return cls(records, Path(path), make_parser())


def choose_mixture(
    rated: list[RatedFrame],
    res: MethodResources,
    method: str,
    corpus: str = "household",
    grid: tuple[float, ...] = GRID,
    config: EvalConfig = EvalConfig(),
    log: Callable[[str], None] = print,
    instructions: DevInstructions | None = None,
) -> tuple[Mixture, float | None, dict[float, dict]]:
    """The weight of `corpus` (others 1) under which `method` does best on the dev sets, the weight of its
    context term chosen with it (None when there are no instructions or the method has no such term), and
    for every weight tried its accuracies ('table1', and 'instructions' by context weight when given)."""
    accuracy: dict[float, dict] = {}
    context_grid = CONTEXT_GRID if instructions is not None and "context_pmi" in method.split("+") else ()
    for weight in sorted(grid):
        mixed = replace(res, corpus="all", mixture=Mixture.of({corpus: weight}))
        scorer_at = _context_weighted(method, mixed)
        scores = score_rated(rated, {method: scorer_at(res.context_weight)})
        accuracy[weight] = {"table1": evaluate(rated, scores, replace(config, lambdas=(), ks=())).table1[method]["all"]}
        line = f"{method} with {corpus} weighted {weight:g}: Table I accuracy {accuracy[weight]['table1']:.3f}"
        if instructions is not None:
            by_context = {}
            for context_weight in context_grid or (res.context_weight,):
                # the rated frames have no context: this weight changes the instructions alone
                scorer = scorer_at(context_weight)
                # the best guess decides (a question counts when it proposes the right object): the
                # completion thresholds, calibrated per mixture later, do not enter
                done = instruction_accuracy(instructions.parser, scorer, CompletionConfig(), instructions.records)
                by_context[context_weight] = done.accuracy
                line += f", instructions {done.right}/{done.total} = {done.accuracy:.3f}" + (
                    f" (context weight {context_weight:g})" if context_grid else ""
                )
            accuracy[weight]["instructions"] = by_context
        log(line)
    weight, context_weight = best_choice(accuracy)
    return Mixture.of({corpus: weight}), context_weight if context_grid else None, accuracy


def _context_weighted(method: str, res: MethodResources) -> Callable[[float], Callable[..., list[float]]]:
    """`method`'s scorer at any weight of its context term, from one scoring of each candidate set: the
    term is linear in its weight, so the rest of the method and the unscaled term are scored once per
    (frames, context) and kept for the next weight (a method without the term ignores the weight)."""
    parts = method.split("+")
    if "context_pmi" not in parts:
        scorer = make_scorer(method, res)
        return lambda weight: scorer
    rest = make_scorer("+".join(p for p in parts if p != "context_pmi"), res)
    term = make_scorer("context_pmi", replace(res, context_weight=1.0))
    kept: dict[tuple, tuple[list[float], list[float]]] = {}

    def scored(frames: list, context: str) -> tuple[list[float], list[float]]:
        key = (tuple(frames), context)
        if key not in kept:
            kept[key] = (rest(frames, context), term(frames, context))
        return kept[key]

    def at(weight: float):
        return lambda frames, context="": [a + weight * b for a, b in zip(*scored(frames, context))]

    return at


def best_choice(accuracy: dict[float, dict]) -> tuple[float, float | None]:
    """The corpus weight and context weight with the best mean accuracy over the dev sets (Table I alone
    without instructions: no context weight); ties go to the smaller corpus weight, then to the context
    weight nearest 1 (the term unscaled), then to the smaller one."""

    def candidates():
        for weight, acc in accuracy.items():
            for context_weight, done in (acc.get("instructions") or {None: None}).items():
                mean = acc["table1"] if done is None else (acc["table1"] + done) / 2
                yield mean, weight, context_weight

    def rank(candidate):
        mean, weight, context_weight = candidate
        nearness = -abs(math.log(context_weight)) if context_weight else 0.0
        return mean, -weight, nearness, -(context_weight or 0.0)

    _, weight, context_weight = max(candidates(), key=rank)
    return weight, context_weight


def choose_and_save(
    rated: list[RatedFrame],
    ratings: Path,
    res: MethodResources,
    method: str,
    data_dir: Path,
    corpus: str = "household",
    grid: tuple[float, ...] = GRID,
    config: EvalConfig = EvalConfig(),
    log: Callable[[str], None] = print,
    instructions: DevInstructions | None = None,
) -> tuple[Mixture, float | None, Path]:
    """`choose_mixture` on the frames rated in `ratings` (and the `instructions`), saved in `data_dir` with
    how it was chosen."""
    chosen, context_weight, accuracy = choose_mixture(rated, res, method, corpus, grid, config, log, instructions)
    path = save(
        data_dir,
        chosen,
        {
            "chosen_for": method,
            "corpus": corpus,
            "ratings": str(ratings),
            "ratings_sha256": _sha256(ratings),
            "instructions": str(instructions.path) if instructions else None,
            "instructions_sha256": _sha256(instructions.path) if instructions else None,
            "accuracy": {f"{w:g}": _rounded(acc) for w, acc in accuracy.items()},
        },
        context_weight,
    )
    return chosen, context_weight, path


def _rounded(accuracy: dict) -> dict:
    """An accuracy entry for the JSON file: 4 decimals, the instructions' keyed by context weight."""
    out = {"table1": round(accuracy["table1"], 4)}
    if "instructions" in accuracy:
        out["instructions"] = {f"{w:g}": round(a, 4) for w, a in accuracy["instructions"].items()}
    return out


def _sha256(path: Path) -> str | None:
    return file_sha256(Path(path)) if Path(path).is_file() else None
