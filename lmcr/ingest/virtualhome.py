"""VirtualHome household programs (`available_examples.json`): a JSON list of strings, each
"Task: Serve a glass of water\\nStep 1: Walk to kitchen\\nStep 2: ...". One program is one document (its
task the title, its steps the sentences); the file repeats programs word for word, and a repeat is the
same record, loaded once."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.jsonl import InputError, decode_utf8, has_surrogates, read_bytes

TASK = re.compile(r"^\s*Task:\s*(.*?)\s*$")
STEP = re.compile(r"^\s*Step\s+\d+:\s*(.*?)\s*$")


def _program(text: str) -> tuple[str, list[str]] | str:
    """(task, steps), or the reason the program is malformed."""
    lines = [line for line in text.splitlines() if line.strip()]
    task = TASK.match(lines[0]) if lines else None
    if not task or not task[1]:
        return "does not start with 'Task: <title>'"
    steps, other = [], []
    for line in lines[1:]:
        step = STEP.match(line)
        (steps if step else other).append(step[1] if step else line)
    if other:
        return f"line {other[0][:60]!r} is not 'Step N: <text>'"
    steps = [s for s in steps if s]
    return (task[1], steps) if steps else "has no steps"


def parse_virtualhome(path: Path, corpus: str = "household") -> ParsedFile:
    """Read the program list; an entry that is not a program is quarantined with its index."""
    parsed = ParsedFile(str(path), "virtualhome", corpus)
    try:
        programs = json.loads(decode_utf8(read_bytes(path), path))
    except InputError as exc:
        raise IngestError(str(path), None, str(exc).split(": ", 1)[1]) from exc
    except (json.JSONDecodeError, RecursionError) as exc:
        raise IngestError(str(path), getattr(exc, "lineno", None), f"not valid JSON: {exc}") from exc
    if not isinstance(programs, list):
        raise IngestError(str(path), None, f"a JSON {type(programs).__name__}, not a list of program strings")
    seen: set[str] = set()
    for position, program in enumerate(programs, start=1):
        if isinstance(program, str) and program in seen:
            continue
        if not isinstance(program, str) or has_surrogates(program):
            parsed.reject(position, f"entry {position}: not a program string", program)
            continue
        seen.add(program)
        read = _program(program)
        if isinstance(read, str):
            parsed.reject(position, f"entry {position}: {read}", program)
            continue
        task, steps = read
        doc_id = "virtualhome:" + hashlib.sha256(program.encode()).hexdigest()[:12]
        parsed.add_document(
            doc_id,
            "virtualhome",
            position,
            [("title", task)] + [("instruction", s) for s in steps],
            title=task,
            records=1,
        )
    return parsed
