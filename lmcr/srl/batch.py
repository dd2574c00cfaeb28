"""The SRL batches: `lmcr srl --input` (JSONL of {id, text} in, {id, text, frames} per line out, as in
the CLI contract) and the instruction check of `lmcr srl-eval --instructions`."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

from lmcr.jsonl import check_text, read_jsonl
from lmcr.srl.evaluate import instruction_correct
from lmcr.srl.instruction import NoPredicateError, parse_instruction
from lmcr.srl.parser import FrameParser

SRL_FIELDS = {"id": (str, int), "text": str}  # a `lmcr srl --input` line


def read_srl_input(path: Path) -> list[tuple[int, dict]]:
    """The (line, record) pairs of an SRL batch; malformed JSONL, or a text the parser cannot take (too
    long), raises InputError naming file and line."""
    records = []
    for line, record in read_jsonl(path, SRL_FIELDS):
        check_text(record["text"], f"{path}:{line}")
        records.append((line, record))
    return records


def srl_batch(parser: FrameParser, records: list[tuple[int, dict]], all_predicates: bool = False) -> Iterator[dict]:
    """Each record's frames, in order, as soon as each is parsed: the robot's predicates' frames, and with
    `all_predicates` the generic frames of other verbs too."""
    found = parser.pipe(record["text"] for _, record in records)
    for (_, record), frames in zip(records, found):
        yield {
            "id": record["id"],
            "text": record["text"],
            "frames": [f.to_json() for f in frames if all_predicates or f.known],
        }


def parse_instructions(parser: FrameParser, tasks: list[dict]) -> Iterator[tuple[dict, dict | None, bool]]:
    """Each instruction task {instruction, expected, missing} parsed: the task, the frame parsed (None
    when no robot predicate was found) and whether it is the expected one."""
    for task in tasks:
        try:
            frame = parse_instruction(parser, task["instruction"]).to_json()
        except NoPredicateError:
            frame = None
        yield task, frame, instruction_correct(frame, task["expected"], task.get("missing"), parser.lex.object_pronouns)
