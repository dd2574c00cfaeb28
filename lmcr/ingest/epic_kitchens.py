"""EPIC-KITCHENS narrations: CSV files with a `narration` column, either EPIC-100's (keyed by
`narration_id`, "P01_01_0") or EPIC-55's train action narrations (`video_id` and timestamps, no id).

A file or a folder of them is one source, so that the files' overlap is settled in one place: one record
per narration id, one document per video (participant/video, in narration order). EPIC-55 rows get the id
EPIC-100 gives the same narration, `<video>_<n>` with n its place in the video; where two files hold the
same id, the EPIC-100 files (newer, re-annotated) come first and the first text wins, so a repeat is not
a new record. Files in a folder without a `narration` column (the verb and noun class lists) are not
narration files and are skipped; a single such file is an error.
"""

from __future__ import annotations

import csv
import re
from collections import Counter, defaultdict
from pathlib import Path

from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.jsonl import InputError, decode_utf8, read_bytes

ID = re.compile(r"^(?P<video>(?P<participant>P\d+)_\d+)_(?P<n>\d+)$")
VIDEO = re.compile(r"^P\d+_\d+$")


def narration_files(path: Path) -> list[Path]:
    """The CSV files an EPIC source reads: the file itself, or the folder's CSVs with a narration column,
    EPIC-100 style (with ids) before EPIC-55 style, each group in path order."""
    if not path.is_dir():
        return [path]
    headers = {f: _header(f) for f in sorted(path.rglob("*.csv"))}
    files = [f for f, h in headers.items() if "narration" in h]
    return sorted(files, key=lambda f: ("narration_id" not in headers[f], f.as_posix()))


def _header(path: Path) -> list[str]:
    with open(path, "rb") as handle:
        first = handle.readline().decode("utf-8-sig", "replace")
    return next(csv.reader([first]), [])


def _rows(path: Path, label: str):
    """(line, row dict or None, problem) per data line; undecodable or ragged lines carry a problem."""
    raw = read_bytes(path)
    lines = raw.split(b"\n")
    header = next(csv.reader([lines[0].decode("utf-8-sig", "replace")]), [])
    if "narration" not in header:
        raise IngestError(label, 1, "no 'narration' column: not an EPIC-KITCHENS narration file")
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        try:
            fields = next(csv.reader([decode_utf8(line.rstrip(b"\r"), f"{label}:{number}")]))
        except InputError as exc:
            yield number, None, str(exc).split(": ", 1)[1]
            continue
        except csv.Error as exc:
            yield number, None, f"not CSV: {exc}"
            continue
        if len(fields) != len(header):
            yield number, None, f"{len(fields)} fields, the header has {len(header)}"
            continue
        yield number, dict(zip(header, fields)), None


def _narration_id(row: dict, place: Counter) -> tuple[str | None, str | None]:
    """(id, problem): the row's narration id, or EPIC-55's `<video>_<n>` from its place in the video."""
    if "narration_id" in row:
        nid = row["narration_id"].strip()
        return (nid, None) if ID.match(nid) else (None, f"bad narration_id {nid!r} (want P01_01_0)")
    video = (row.get("video_id") or "").strip()
    if not VIDEO.match(video):
        return None, f"no narration_id and bad video_id {video!r} (want P01_01)"
    n = place[video]
    place[video] += 1
    return f"{video}_{n}", None


def parse_epic_kitchens(path: Path, corpus: str = "household") -> ParsedFile:
    """Read one narration file or a folder of them; a malformed line is quarantined with its file and line."""
    parsed = ParsedFile(str(path), "epic_kitchens", corpus)
    files = narration_files(path)
    if not files:
        raise IngestError(str(path), None, "folder holds no EPIC-KITCHENS narration CSV (no 'narration' column)")
    texts: dict[str, tuple[str, str]] = {}  # narration id -> (text, subset)
    for file in files:
        label = file.relative_to(path).as_posix() if path.is_dir() else str(file)
        place: Counter[str] = Counter()
        for line, row, problem in _rows(file, label):
            nid, problem = (None, problem) if problem else _narration_id(row, place)
            text = (row or {}).get("narration", "").strip()
            if not problem and not text:
                problem = "empty narration"
            if problem:
                parsed.reject(line, f"{label}:{line}: {problem}", row or "")
                continue
            texts.setdefault(nid, (text, "epic-100" if "narration_id" in row else "epic-55"))
    videos: dict[str, list[tuple[int, str, str]]] = defaultdict(list)
    for nid, (text, subset) in texts.items():
        match = ID.match(nid)
        videos[match["video"]].append((int(match["n"]), text, subset))
    for position, video in enumerate(sorted(videos), start=1):
        narrations = sorted(videos[video])
        parsed.add_document(
            f"epic:{video}",
            "epic_kitchens",
            position,
            [("instruction", text) for _, text, _ in narrations],
            category=video.split("_")[0],
            subset=narrations[0][2],
            records=len(narrations),
        )
    return parsed
