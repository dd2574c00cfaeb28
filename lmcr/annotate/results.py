"""MTurk batch results in: parse a results CSV (single- or multi-item layout) into assignments and
rated items, validate each item, and load them into DuckDB in one transaction.

Defects real downloads have, and what happens to them:
- a rejected assignment is stored with its status and never aggregated (the `valid_ratings` view);
- the same assignment downloaded twice with the same answers is ignored (a newer status wins);
  with different answers it is flagged (`assignments.conflict`) and leaves the aggregates;
- an answer that is not an integer 1-5, or an item missing a required input field, goes to the
  quarantine table with file, line and reason; a slot with no input at all is not an item;
- the same file ingested twice is recognised by its sha256 and changes nothing.
"""

from __future__ import annotations

import csv
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path

import duckdb

from lmcr.files import file_sha256
from lmcr.frame import FRAME_COLUMNS
from lmcr.jsonl import InputError, read_lines
from lmcr.store import insert_rows, transaction

META = ("HITId", "AssignmentId", "WorkerId", "AssignmentStatus")
OPTIONAL_FIELDS = ("frame_id", "sentence")
RATINGS = frozenset("12345")  # exactly these ASCII digits: str.isdigit() also accepts "٣" and "²"


def _count(value: str | None) -> int | None:
    """An ASCII decimal count column (WorkTimeInSeconds, MaxAssignments), else None."""
    return int(value) if value and value.isascii() and value.isdigit() else None


@dataclass
class Assignment:
    row: dict
    line: int
    items: list[dict] = field(default_factory=list)  # valid items
    bad: list[tuple[int, str, dict]] = field(default_factory=list)  # (slot, reason, item)

    @property
    def assignment_id(self) -> str:
        return self.row["AssignmentId"]

    @property
    def content_sha256(self) -> str:
        """What the worker saw and answered: a re-download with the same hash is the same work."""
        answers = {k: v for k, v in self.row.items() if k.startswith(("Input.", "Answer.")) and v}
        return hashlib.sha256(json.dumps([self.row["WorkerId"], answers], sort_keys=True).encode()).hexdigest()

    @property
    def n_items(self) -> int:
        return len(self.items) + len(self.bad)


@dataclass
class ParsedResults:
    path: Path
    sha256: str
    layout: str
    rows: int
    assignments: list[Assignment]


def _slots(columns: list[str], path: Path) -> tuple[str, list[str]]:
    """The layout and the column suffixes of its item slots ('' for single-item)."""
    missing = [c for c in META if c not in columns]
    if missing:
        raise InputError(f"{path}:1: not an MTurk batch-results file, missing columns {missing}")
    if "Input.verb" in columns:
        return "single", [""]
    # Slot columns are Input.verb_1 .. Input.verb_N (ASCII digits); other Input.verb_* columns are not slots.
    suffixes = sorted(
        (
            s
            for s in (c.removeprefix("Input.verb") for c in columns if c.startswith("Input.verb_"))
            if _count(s[1:]) is not None
        ),
        key=lambda s: int(s[1:]),
    )
    if not suffixes:
        raise InputError(f"{path}:1: no Input.verb or Input.verb_1 column")
    return "multi", suffixes


def _item(row: dict, suffix: str) -> tuple[dict | None, str | None]:
    """(item, None) for a valid slot, (item, reason) for a defective one, (None, None) for an empty slot."""
    get = lambda name: (row.get(name) or "").strip()  # noqa: E731
    fields = {f: get(f"Input.{f}{suffix}") for f in FRAME_COLUMNS + OPTIONAL_FIELDS}
    answer = get(f"Answer.rating{suffix}")
    if not any(fields.values()) and not answer:
        return None, None
    item = {
        **{f: fields[f] or None for f in OPTIONAL_FIELDS},
        **{f: fields[f].lower() if f.startswith("arg") or f == "verb" else fields[f] for f in FRAME_COLUMNS},
        "item": int(suffix[1:]) if suffix else 1,
        "answer": answer,
    }
    empty = [f"Input.{f}{suffix}" for f in FRAME_COLUMNS if not fields[f]]
    if empty:
        return item, f"missing required input {', '.join(empty)}"
    if answer not in RATINGS:
        return item, f"Answer.rating{suffix} = {answer!r} is not an integer rating 1-5"
    item["rating"] = int(answer)
    return item, None


def parse_results(path: Path) -> ParsedResults:
    """Every assignment row of a results file with its valid and defective items."""
    path = Path(path)
    reader = csv.DictReader(read_lines(path))
    try:
        layout, suffixes = _slots(reader.fieldnames or [], path)
        assignments, rows = [], 0
        for row in reader:
            rows += 1
            assignments.append(_assignment(row, reader.line_num, suffixes, len(reader.fieldnames)))
    except csv.Error as exc:
        raise InputError(f"{path}:{reader.line_num}: not CSV: {exc}") from exc
    return ParsedResults(path, file_sha256(path), layout, rows, assignments)


def _assignment(row: dict, line: int, suffixes: list[str], n_columns: int) -> Assignment:
    """One results row: its valid items, and its defective ones with the reason."""
    a = Assignment({k: (v or "").strip() for k, v in row.items() if k}, line)
    empty_meta = [c for c in META if not a.row.get(c)]
    # csv puts the fields of a row longer than the header under None: its columns are shifted.
    extra = f"row has {n_columns + len(row[None])} fields, the header {n_columns}" if None in row else None
    for suffix in suffixes:
        item, reason = _item(row, suffix)
        if item is None:
            continue
        reason = extra or reason or (f"row has no {', '.join(empty_meta)}" if empty_meta else None)
        if reason:
            a.bad.append((item["item"], reason, item))
        else:
            a.items.append(item)
    return a


def load_results(con: duckdb.DuckDBPyConnection, parsed: ParsedResults) -> dict:
    """Load a parsed file in one transaction; returns the file's counts (`skipped` if already loaded)."""
    if con.execute("select 1 from rating_files where sha256 = ?", [parsed.sha256]).fetchone():
        return {"source_file": str(parsed.path), "skipped": True}
    known = dict(con.execute("select assignment_id, content_sha256 from assignments").fetchall())
    counts = dict(
        rows_in=parsed.rows,
        assignments_loaded=0,
        assignments_duplicate=0,
        assignments_conflicting=0,
        items_in=0,
        items_loaded=0,
        items_quarantined=0,
        items_duplicate=0,
    )
    new, hits, workers, ratings, quarantine, status_updates, conflicts = [], {}, {}, [], [], [], []
    source = str(parsed.path)
    for a in parsed.assignments:
        counts["items_in"] += a.n_items
        aid = a.assignment_id
        if aid and aid in known:
            counts["items_duplicate"] += a.n_items
            if known[aid] == a.content_sha256:
                counts["assignments_duplicate"] += 1
                status_updates.append((a.row["AssignmentStatus"], aid))
            else:
                counts["assignments_conflicting"] += 1
                conflicts.append((f"{source}:{a.line}: a later download has different answers", aid))
            continue
        for slot, reason, item in a.bad:
            quarantine.append(
                {
                    "stage": "ratings",
                    "corpus": None,
                    "source_file": source,
                    "position": a.line,
                    "reason": f"line {a.line}, item {slot}: {reason}",
                    "record": json.dumps({"AssignmentId": aid, **item}, sort_keys=True),
                }
            )
        counts["items_quarantined"] += len(a.bad)
        if not a.items:
            continue
        known[aid] = a.content_sha256
        counts["assignments_loaded"] += 1
        counts["items_loaded"] += len(a.items)
        row = a.row
        new.append(
            {
                "assignment_id": aid,
                "hit_id": row["HITId"],
                "worker_id": row["WorkerId"],
                "status": row["AssignmentStatus"],
                "work_seconds": _count(row.get("WorkTimeInSeconds")),
                "submit_time": row.get("SubmitTime") or None,
                "source_file": source,
                "line": a.line,
                "content_sha256": a.content_sha256,
                "conflict": None,
            }
        )
        hits.setdefault(
            row["HITId"],
            {
                "hit_id": row["HITId"],
                "hit_type_id": row.get("HITTypeId") or None,
                "title": row.get("Title") or None,
                "reward": row.get("Reward") or None,
                "max_assignments": _count(row.get("MaxAssignments")),
                "source_file": source,
            },
        )
        workers.setdefault(row["WorkerId"], {"worker_id": row["WorkerId"], "first_file": source})
        ratings += [{"assignment_id": aid, **item} for item in a.items]
    with transaction(con):
        insert_rows(con, "hits", list(hits.values()), "hit_id", CONVERTED)
        insert_rows(con, "workers", list(workers.values()), "worker_id")
        insert_rows(con, "assignments", new, convert=CONVERTED)
        insert_rows(con, "ratings", ratings)
        insert_rows(con, "quarantine", quarantine)
        for sql, params in (
            ("update assignments set status = ? where assignment_id = ?", status_updates),
            ("update assignments set conflict = ? where assignment_id = ?", conflicts),
        ):
            if params:
                con.executemany(sql, params)
        insert_rows(
            con, "rating_files", [{"sha256": parsed.sha256, "source_file": source, "layout": parsed.layout, **counts}]
        )
    return {"source_file": source, "layout": parsed.layout, **counts}


# MTurk's text values converted on insert by the macros of migration 010 ('$0.30', 'Tue Nov 17 ... PST 2026').
CONVERTED = {"reward": "mturk_reward(reward)", "submit_time": "mturk_time(submit_time)"}


def ingest_ratings(con: duckdb.DuckDBPyConnection, path: Path) -> dict:
    """Parse and load one results file; idempotent."""
    return load_results(con, parse_results(path))
