"""Rated frames for evaluation: mean crowd rating per complete frame, from the store's `frame_ratings`
view or from an MTurk results CSV ingested on the fly into an in-memory store (same validation)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import duckdb

from lmcr import store
from lmcr.annotate.results import ingest_ratings
from lmcr.frame import Frame
from lmcr.jsonl import InputError


@dataclass(frozen=True)
class RatedFrame:
    verb: str
    role1: str
    arg1: str
    role2: str
    arg2: str
    mean: float
    n: int

    @property
    def frame(self) -> Frame:
        return Frame(self.verb, ((self.role1, self.arg1), (self.role2, self.arg2)))

    @property
    def key(self) -> tuple[str, str, str, str, str]:
        return self.verb, self.role1, self.arg1, self.role2, self.arg2


def rated_frames(con: duckdb.DuckDBPyConnection, verbs: set[str] | None = None) -> list[RatedFrame]:
    """Every rated frame of the store (of `verbs` when given), in a stable order."""
    rows = con.execute("select verb, role1, arg1, role2, arg2, mean, n from frame_ratings order by all").fetchall()
    return [RatedFrame(*row) for row in rows if verbs is None or row[0] in verbs]


def load_ratings(source: Path, sql_dir: Path, verbs: set[str] | None = None) -> list[RatedFrame]:
    """Rated frames from a DuckDB store file or an MTurk batch-results CSV."""
    source = Path(source)
    if not source.exists():
        raise FileNotFoundError(f"{source}: no such ratings file or store")
    if source.suffix.lower() == ".csv":
        con = store.connect(":memory:", sql_dir)
        ingest_ratings(con, source)
    else:
        con = store.read_connection(source)
    try:
        return rated_frames(con, verbs)
    except duckdb.CatalogException as exc:
        raise InputError(f"{source}: neither an MTurk results .csv nor an LMCR store with ratings") from exc
    finally:
        con.close()
