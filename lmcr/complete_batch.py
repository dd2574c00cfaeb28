"""The completion batch of `lmcr complete`: JSONL of {id, instruction, objects} in, one completion per line
out (the CLI contract's format)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

from lmcr.complete import CompletionConfig, CompletionError, complete
from lmcr.errors import one_line
from lmcr.jsonl import InputError, read_jsonl
from lmcr.scorers.registry import Scorer
from lmcr.srl.instruction import NoPredicateError
from lmcr.srl.parser import FrameParser

COMPLETE_FIELDS = {"id": (str, int), "instruction": str, "objects": list}  # a `lmcr complete --input` line


def read_complete_input(path: Path) -> list[tuple[int, dict]]:
    """The (line, record) pairs of a completion batch; malformed JSONL (objects not a list of strings
    included) raises InputError naming file and line."""
    records = list(read_jsonl(path, required=COMPLETE_FIELDS))
    for line, record in records:
        if not all(isinstance(o, str) for o in record["objects"]):
            raise InputError(f"{path}:{line}: field 'objects' must be a list of strings")
    return records


def complete_batch(
    parser: FrameParser,
    scorer: Scorer,
    config: CompletionConfig,
    records: list[tuple[int, dict]],
    path: Path,
    log: Callable[[str], None] = lambda message: None,
) -> Iterator[dict]:
    """Each record completed, in order, as soon as it is done. A record that cannot be completed (no known
    predicate, no usable objects, a text the parser cannot take) gets {"id", "error"}, `log` hears it with
    its place (`path` and line), and the batch goes on."""
    for line, record in records:
        try:
            completion = complete(parser, scorer, record["instruction"], record["objects"], config)
            yield {"id": record["id"], **completion.to_json()}
        except (NoPredicateError, CompletionError, InputError) as exc:
            log(f"{path}:{line}: {one_line(exc)}")
            yield {"id": record["id"], "error": one_line(exc)}
