"""Completing instructions said in a scene: how many a completion method gets right.

An instruction record is `{instruction, objects, expected: {predicate, roles}}` (the dev set's lines; other
fields are ignored). It counts as right when the completed frame is the expected one: a completion that
asks a question counts only when its best guess, what the question proposes, is right; an instruction
that cannot be completed (no robot predicate found) counts as wrong, with the reason.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

from lmcr.complete import CompletionConfig, complete
from lmcr.errors import LMCRError
from lmcr.jsonl import InputError, read_jsonl
from lmcr.srl.evaluate import check_expected

FIELDS = {"instruction": str, "objects": list, "expected": dict}


@dataclass(frozen=True)
class InstructionAccuracy:
    """Counts over a set of instructions, and what was completed for each wrong one."""

    total: int = 0
    answered_right: int = 0  # completed without a question, right
    asked: int = 0  # completions that asked
    asked_right: int = 0  # ... whose best guess was right
    # (instruction, completed roles or {"error": why there is no completion}, context)
    wrong: list[tuple[str, dict, str]] = field(default_factory=list)

    @property
    def right(self) -> int:
        return self.answered_right + self.asked_right

    @property
    def accuracy(self) -> float:
        return self.right / self.total if self.total else 0.0

    def summary(self) -> str:
        """One line of counts, then one line per wrong completion."""
        return "\n".join(
            [
                f"dev instructions: {self.right}/{self.total} = {self.accuracy:.3f} right "
                f"({self.answered_right} answered right, {self.asked} questions of which "
                f"{self.asked_right} guess right)",
                *(f"  {text!r}: {roles} (context {context!r})" for text, roles, context in self.wrong),
            ]
        )


def load_instructions(path: Path) -> list[dict]:
    """The records of an instructions JSONL file; a bad line raises InputError naming file and line."""
    records = []
    for line_no, record in read_jsonl(path, FIELDS):
        if not all(isinstance(o, str) for o in record["objects"]):
            raise InputError(f"{path}:{line_no}: field 'objects' must be a list of strings")
        records.append(check_expected(record, f"{path}:{line_no}"))
    return records


def instruction_accuracy(
    parser, scorer: Callable, config: CompletionConfig, records: Iterable[dict]
) -> InstructionAccuracy:
    """Complete each record's instruction among its objects with `scorer` and count the right ones."""
    total = answered_right = asked = asked_right = 0
    wrong = []
    for record in records:
        total += 1
        try:
            out = complete(parser, scorer, record["instruction"], record["objects"], config)
        except LMCRError as exc:  # no predicate found, nothing to fill with: no answer, so a wrong one
            wrong.append((record["instruction"], {"error": str(exc)}, ""))
            continue
        guessed = out.frame.to_json() == record["expected"]
        asked += bool(out.question)
        asked_right += bool(out.question) and guessed
        answered_right += not out.question and guessed
        if not guessed:
            wrong.append((record["instruction"], out.frame.role_map, out.context))
    return InstructionAccuracy(total, answered_right, asked, asked_right, wrong)
