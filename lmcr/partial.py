"""A batch's output kept as it is written: each finished line goes into a visible sidecar `OUT.partial`
(flushed per line), which becomes OUT when the batch ends. A batch killed midway keeps what finished
there, and the same command run again resumes it: `OUT.partial.json` beside the sidecar names the input
(its sha256) and the command's options the lines belong to. A sidecar of another input or other options is
refused, never deleted: it may hold hours of work.

The output never exists partially under the user's name: OUT appears whole, when the last line is done."""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Iterator
from contextlib import suppress
from dataclasses import dataclass
from pathlib import Path

from lmcr.files import OutputError, check_output_file, file_sha256, output_error, output_target

SIDECAR, STAMP = ".partial", ".partial.json"


@dataclass
class PartialOutput:
    """The sidecar of one batch output: `output` as the user named it, the lines kept from an earlier run of
    the same command on the same input (`done` of them), and the stamp that says whose lines they are."""

    output: Path
    stamp: dict
    kept: list[str]
    kept_bytes: int  # the sidecar's length up to its last finished line (a line cut off by a kill is dropped)

    @property
    def sidecar(self) -> Path:
        target = output_target(self.output)
        return target.with_name(target.name + SIDECAR)

    @property
    def stamp_file(self) -> Path:
        target = output_target(self.output)
        return target.with_name(target.name + STAMP)

    @property
    def done(self) -> int:
        return len(self.kept)

    @classmethod
    def open(cls, output: Path, input: Path, options: dict) -> PartialOutput:
        """The sidecar of `output` for a batch of `input` run with `options` (JSON values): its finished
        lines when an earlier run of the same batch left one, else none. A sidecar of another input or other
        options, or one without its stamp, is an OutputError naming it. `output` is checked as every
        output file is (`check_output_file`); an unreadable `input` raises OSError."""
        output = Path(output)
        check_output_file(output, reads=input)
        found = cls(output, {"input_sha256": file_sha256(input), "options": options}, [], 0)
        if not found.sidecar.exists():
            return found
        try:
            saved = json.loads(found.stamp_file.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            saved = None
        if saved != found.stamp:
            whose = "no stamp" if saved is None else "of another input or other options"
            raise OutputError(
                f"{found.sidecar}: an unfinished batch output ({whose}) is in the way of {output}; run the same "
                f"command on the same input to resume it, or move it away"
            )
        found.kept, found.kept_bytes = _finished_lines(found.sidecar.read_bytes())
        return found

    def write(self, records: Iterable[dict]) -> Iterator[dict]:
        """Append each record to the sidecar as it comes (yielding it on once it is on disk); when `records`
        end, the sidecar becomes the output and its stamp goes. A failure midway leaves the sidecar."""
        target = output_target(self.output)
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            self.stamp_file.write_text(json.dumps(self.stamp), encoding="utf-8")
            with open(self.sidecar, "ab") as out:
                out.truncate(self.kept_bytes)
                for record in records:
                    out.write((json.dumps(record, ensure_ascii=False) + "\n").encode("utf-8"))
                    out.flush()
                    yield record
            os.replace(self.sidecar, target)
        except OSError as exc:
            error = output_error(self.output, exc, self.sidecar, self.stamp_file, target)
            if error is None:
                raise
            raise error from exc
        with suppress(OSError):
            self.stamp_file.unlink()


def _finished_lines(raw: bytes) -> tuple[list[str], int]:
    """The sidecar's finished lines (each a whole JSON object ending in a newline) and their length in bytes;
    what follows the first line that is not (cut off by a kill midway through writing it) is dropped."""
    lines, end = [], 0
    for line in raw.splitlines(keepends=True):
        try:
            ok = line.endswith(b"\n") and isinstance(json.loads(line), dict)
        except ValueError:
            ok = False
        if not ok:
            break
        lines.append(line.decode("utf-8"))
        end += len(line)
    return lines, end
