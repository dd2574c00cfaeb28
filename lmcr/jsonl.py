"""JSON Lines in and out for the batch commands: line-numbered errors in, atomic files out."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Iterable, Iterator, TextIO

from lmcr.files import atomic_path


class InputError(ValueError):
    """Bad input: names the file and line."""


def open_input(path: Path, newline: str | None = None, encoding: str = "utf-8") -> TextIO:
    """Open an input text file; an unreadable one raises InputError naming it and why."""
    try:
        return open(path, newline=newline, encoding=encoding)
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from exc


def read_jsonl(path: Path, required: dict[str, type | tuple[type, ...]]) -> Iterator[tuple[int, dict]]:
    """(line number, record) for each non-blank line; a line that is not a JSON object with the
    required fields of the required types raises InputError naming file and line."""
    with open_input(path) as handle:
        for line_no, line in enumerate(handle, start=1):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError as exc:
                raise InputError(f"{path}:{line_no}: not valid JSON: {exc.msg}") from exc
            if not isinstance(record, dict):
                raise InputError(f"{path}:{line_no}: expected a JSON object")
            for key, kind in required.items():
                if not isinstance(record.get(key), kind):
                    raise InputError(f"{path}:{line_no}: field {key!r} missing or not {_name(kind)}")
            yield line_no, record


def _name(kind: type | tuple[type, ...]) -> str:
    return " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))


def write_jsonl_atomic(path: Path, records: Iterable[dict]) -> int:
    """Write records to a temporary file beside `path`, then rename: never a partial output."""
    count = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8") as out:
        for record in records:
            out.write(json.dumps(record, ensure_ascii=False) + "\n")
            count += 1
    return count
