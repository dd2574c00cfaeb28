"""A complete (or candidate) verb frame: a predicate and its roles in order, e.g. (pour, Theme: water,
Destination: cup). Frozen and hashable, so frames are set members and dict keys as they are; scorers,
completion, rating tasks and evaluation all pass this one type. (A frame found in text, with spans, is
`lmcr.srl.mentions.FrameMention`.) Also the frames CSV (`FRAME_COLUMNS`, other columns kept): read and
validated against the lexicon, and written back with one score column per method."""

from __future__ import annotations

import csv
import hashlib
import json
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

from lmcr.files import atomic_path
from lmcr.jsonl import InputError, read_lines
from lmcr.lexicon import Lexicon, load_lexicon

# The columns of a two-role frame wherever frames are tables: the frames CSV, rating tasks and results.
FRAME_COLUMNS = ("verb", "role1", "arg1", "role2", "arg2")


@dataclass(frozen=True)
class Frame:
    predicate: str
    roles: tuple[tuple[str, str], ...]  # (role, value) in the order the frame states them

    @classmethod
    def of(cls, predicate: str, roles: Mapping[str, str]) -> Frame:
        """From a predicate and a role -> value mapping (its order kept)."""
        return cls(predicate, tuple(roles.items()))

    @property
    def role_map(self) -> dict[str, str]:
        return dict(self.roles)

    @property
    def key(self) -> tuple[str, ...]:
        """(predicate, role1, value1, role2, value2, ...): the rating tables' columns."""
        return (self.predicate, *(part for pair in self.roles for part in pair))

    @property
    def id(self) -> str:
        """A stable identifier independent of role order: 'f-' + 12 hex digits."""
        text = json.dumps([self.predicate, sorted(self.roles)])
        return "f-" + hashlib.sha256(text.encode()).hexdigest()[:12]

    def to_json(self) -> dict:
        return {"predicate": self.predicate, "roles": self.role_map}

    def __iter__(self) -> Iterator:
        """`verb, roles = frame`: the predicate and a role -> value dict."""
        yield self.predicate
        yield self.role_map


@dataclass(frozen=True)
class FrameRow:
    """One row of a frames CSV: its line, its frame and the row as read (other columns kept)."""

    line: int
    frame: Frame
    raw: dict


def read_frames_csv(path: Path, *, reserved: Callable[[str], bool]) -> tuple[list[str], list[FrameRow]]:
    """Rows of a frames CSV (`FRAME_COLUMNS`, other columns kept), validated against the lexicon: a bad row
    fails with file, line and reason. A column for which `reserved` holds (named like a method, whose score
    would silently replace it) is refused."""
    lex = load_lexicon()
    reader = csv.DictReader(read_lines(path))
    try:
        columns = reader.fieldnames or []
        missing = [c for c in FRAME_COLUMNS if c not in columns]
        if missing:
            raise InputError(f"{path}:1: missing columns {missing}")
        taken = [c for c in columns if reserved(c)]
        if taken:
            raise InputError(f"{path}:1: column {taken[0]!r} is named like a method; rename it")
        rows = [
            FrameRow(reader.line_num, _frame_of(row, path, reader.line_num, lex, len(columns)), row) for row in reader
        ]
    except csv.Error as exc:
        raise InputError(f"{path}:{reader.line_num}: not CSV: {exc}") from exc
    return columns, rows


def _frame_of(row: dict, path: Path, line: int, lex: Lexicon, n_columns: int) -> Frame:
    """The frame of one frames-CSV row, validated against the lexicon."""
    if None in row:
        raise InputError(f"{path}:{line}: {n_columns + len(row[None])} fields, the header has {n_columns}")
    verb = (row["verb"] or "").strip().lower()
    spec = lex.predicates.get(verb)
    if spec is None:
        raise InputError(
            f"{path}:{line}: unknown verb {row['verb']!r} "
            f"(one of {', '.join(lex.hand_written)}, or a predicate learned from the corpora)"
        )
    roles = {
        (row["role1"] or "").strip(): (row["arg1"] or "").strip().lower(),
        (row["role2"] or "").strip(): (row["arg2"] or "").strip().lower(),
    }
    if set(roles) != set(spec.roles):
        raise InputError(f"{path}:{line}: roles {sorted(roles)} are not {verb}'s {list(spec.roles)}")
    if not all(roles.values()):
        raise InputError(f"{path}:{line}: empty argument")
    return Frame.of(verb, roles)


def write_scores_csv(path: Path, columns: list[str], rows: list[FrameRow], scores: dict[str, list[float]]) -> None:
    """Input columns plus one column per method, written under a temporary name and renamed."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as out:
        writer = csv.DictWriter(out, fieldnames=columns + [m for m in scores if m not in columns])
        writer.writeheader()
        for k, row in enumerate(rows):
            writer.writerow({**row.raw, **{m: f"{values[k]:.6f}" for m, values in scores.items()}})
