"""Text inputs of the batch commands, read so that every defect is an InputError naming file and line
(undecodable bytes, lone surrogates, invalid JSON, missing or mistyped fields), and JSON Lines out
through atomic files."""

from __future__ import annotations

import json
from collections.abc import Iterable, Iterator
from pathlib import Path

from lmcr.errors import LMCRError
from lmcr.files import atomic_path

MAX_TEXT_CHARS = 1_000  # an instruction or sentence longer than this is refused (the tokenizer is superlinear)


class InputError(LMCRError, ValueError):
    """Bad input: names the file and line."""


def read_bytes(path: Path) -> bytes:
    """A whole input file's bytes; a missing, unreadable or folder path raises InputError."""
    try:
        return Path(path).read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror}") from exc


def decode_utf8(raw: bytes, where: Path | str) -> str:
    """UTF-8 text (a BOM is dropped); undecodable bytes raise InputError naming `where` and the byte's
    line and column (`where` may already name the line: then only the column is added)."""
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        place = f"{where}:{line}" if isinstance(where, Path) else str(where)
        raise InputError(f"{place}: not UTF-8 (byte 0x{raw[exc.start]:02x} at column {column})") from exc


def read_lines(path: Path) -> list[str]:
    """The decoded lines of a UTF-8 text file, line endings kept (what the csv module wants)."""
    return decode_utf8(read_bytes(path), Path(path)).splitlines(keepends=True)


def has_surrogates(value: object) -> bool:
    """True when a decoded JSON value holds an unpaired surrogate ("\\ud800"): such text cannot be
    encoded, stored or parsed."""
    try:
        json.dumps(value, ensure_ascii=False).encode("utf-8")
    except UnicodeEncodeError:
        return True
    return False


def check_text(value: str, where: str, max_chars: int | None = MAX_TEXT_CHARS) -> str:
    """A text field fit for the parser: no unpaired surrogates (they cannot be encoded, and spaCy fails
    on them) and, with `max_chars`, no longer than that."""
    try:
        value.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise InputError(f"{where}: text has an unpaired surrogate at character {exc.start + 1}") from exc
    if max_chars is not None and len(value) > max_chars:
        raise InputError(f"{where}: text is {len(value):,} characters; the limit is {max_chars:,}")
    return value


def read_jsonl(path: Path, required: dict[str, type | tuple[type, ...]]) -> Iterator[tuple[int, dict]]:
    """(line number, record) for each non-blank line; a line that is not a JSON object with the
    required fields of the required types, or holds a string that cannot be encoded (a lone
    surrogate), raises InputError naming file and line."""
    for line_no, record, error in read_jsonl_lines(path, required):
        if error is not None:
            raise error
        yield line_no, record


def read_jsonl_lines(
    path: Path, required: dict[str, type | tuple[type, ...]]
) -> Iterator[tuple[int, dict | None, InputError | None]]:
    """(line number, record, None) for each good non-blank line and (line number, the decoded object or
    None, InputError) for each bad one, so a batch can report a bad line and go on. Only a file that
    cannot be read at all raises."""
    raw = read_bytes(path)
    for line_no, line in enumerate(raw.split(b"\n"), start=1):
        if not line.strip():
            continue
        try:
            yield line_no, _record(line, required, f"{path}:{line_no}"), None
        except InputError as exc:
            yield line_no, _partial(line), exc


def parse_json(text: str, where: str, multiline: bool = False) -> object:
    """Decoded JSON; invalid or too deeply nested JSON raises InputError naming `where` (and, for a
    `multiline` document, the line of the defect)."""
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{where}{f':{exc.lineno}' if multiline else ''}: not valid JSON: {exc.msg}") from exc
    except RecursionError as exc:
        raise InputError(f"{where}: JSON nested too deeply") from exc


def _record(line: bytes, required: dict[str, type | tuple[type, ...]], where: str) -> dict:
    record = parse_json(decode_utf8(line, where), where)
    if not isinstance(record, dict):
        raise InputError(f"{where}: expected a JSON object")
    for key, kind in required.items():
        value = record.get(key)
        if not isinstance(value, kind) or isinstance(value, bool):
            raise InputError(f"{where}: field {key!r} missing or not {_name(kind)}")
    if has_surrogates(record):
        raise InputError(f"{where}: text has an unpaired surrogate")
    return record


def _partial(line: bytes) -> dict | None:
    """What can be read of a bad line (for its id), or None."""
    try:
        record = json.loads(line.decode("utf-8"))
    except (ValueError, RecursionError):
        return None
    return record if isinstance(record, dict) else None


def _name(kind: type | tuple[type, ...]) -> str:
    return " or ".join(k.__name__ for k in (kind if isinstance(kind, tuple) else (kind,)))


def write_jsonl_atomic(path: Path, records: Iterable[dict]) -> int:
    """Write records to a temporary file beside `path`, then rename: never a partial output. Each line
    reaches the temporary file as soon as its record comes (line-buffered), so a long batch shows progress."""
    count = 0
    with atomic_path(path) as tmp, open(tmp, "w", encoding="utf-8", buffering=1) as out:
        for record in records:
            out.write(json.dumps(record, ensure_ascii=False) + "\n")
            count += 1
    return count
