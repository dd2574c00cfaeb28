"""Choosing a corpus's mixture weight on the dev sets: under each weight of a short grid, Table I
accuracy of one method on rated frames and, when instructions are given, the share of instructions it
completes right in their scenes. The best mean of the two wins (each dev set counts the same: the rated
frames are recipe steps, the instructions what people say to the robot at home), ties going to the
smaller weight (the plain pool when it ties)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from lmcr.complete import CompletionConfig
from lmcr.evaluate.instructions import instruction_accuracy, load_instructions
from lmcr.evaluate.protocol import EvalConfig, evaluate, score_rated
from lmcr.evaluate.ratings import RatedFrame
from lmcr.files import file_sha256
from lmcr.jsonl import InputError
from lmcr.methods import MethodResources, make_scorer
from lmcr.mixture import GRID, Mixture, save


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


def choose_mixture(rated: list[RatedFrame], res: MethodResources, method: str, corpus: str = "household",
                   grid: tuple[float, ...] = GRID, config: EvalConfig = EvalConfig(),
                   log: Callable[[str], None] = print,
                   instructions: DevInstructions | None = None) -> tuple[Mixture, dict[float, dict[str, float]]]:
    """The weight of `corpus` (others 1) under which `method` does best on the dev sets, and for every
    weight tried its accuracies ('table1', and 'instructions' when given)."""
    accuracy: dict[float, dict[str, float]] = {}
    for weight in sorted(grid):
        mixed = replace(res, corpus="all", mixture=Mixture.of({corpus: weight}))
        scorer = make_scorer(method, mixed)
        scores = score_rated(rated, {method: scorer})
        accuracy[weight] = {"table1": evaluate(rated, scores, replace(config, lambdas=(), ks=())).table1[method]["all"]}
        line = f"{method} with {corpus} weighted {weight:g}: Table I accuracy {accuracy[weight]['table1']:.3f}"
        if instructions is not None:
            # the best guess decides (a question counts when it proposes the right object): the
            # completion thresholds, calibrated per mixture later, do not enter
            done = instruction_accuracy(instructions.parser, scorer, CompletionConfig(), instructions.records)
            accuracy[weight]["instructions"] = done.accuracy
            line += f", instructions {done.right}/{done.total} = {done.accuracy:.3f}"
        log(line)
    return Mixture.of({corpus: best_weight(accuracy)}), accuracy


def best_weight(accuracy: dict[float, dict[str, float]]) -> float:
    """The weight with the best mean accuracy over the dev sets, the smaller weight on a tie."""
    return max(accuracy, key=lambda w: (sum(accuracy[w].values()) / len(accuracy[w]), -w))


def choose_and_save(rated: list[RatedFrame], ratings: Path, res: MethodResources, method: str, data_dir: Path,
                    corpus: str = "household", grid: tuple[float, ...] = GRID, config: EvalConfig = EvalConfig(),
                    log: Callable[[str], None] = print,
                    instructions: DevInstructions | None = None) -> tuple[Mixture, Path]:
    """`choose_mixture` on the frames rated in `ratings` (and the `instructions`), saved in `data_dir` with
    how it was chosen."""
    chosen, accuracy = choose_mixture(rated, res, method, corpus, grid, config, log, instructions)
    path = save(data_dir, chosen, {"chosen_for": method, "corpus": corpus, "ratings": str(ratings),
                                   "ratings_sha256": _sha256(ratings),
                                   "instructions": str(instructions.path) if instructions else None,
                                   "instructions_sha256": _sha256(instructions.path) if instructions else None,
                                   "accuracy": {f"{w:g}": {k: round(a, 4) for k, a in acc.items()}
                                                for w, acc in accuracy.items()}})
    return chosen, path


def _sha256(path: Path) -> str | None:
    return file_sha256(Path(path)) if Path(path).is_file() else None
