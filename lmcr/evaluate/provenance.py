"""Where a report's figures come from: the rating files and corpus files (with sha256), the checkpoint
versions (with their manifest's sha256), the code (git commit), the date and the machine; and whether
any of it is the embedded sample, which the report then says in a banner."""

from __future__ import annotations

import datetime as dt
import os
import platform
from pathlib import Path

from lmcr import __version__
from lmcr.config import REPO_ROOT, git_commit
from lmcr.files import file_sha256
from lmcr.store import read_connection

SAMPLE_DIR = REPO_ROOT / "data" / "sample"


def machine() -> str:
    return f"{platform.node()} ({platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()})"


def sample_hashes() -> set[str]:
    """sha256 of every file of the embedded sample: a copy of a sample file elsewhere is still the sample."""
    return {file_sha256(p) for p in SAMPLE_DIR.rglob("*") if p.is_file()} if SAMPLE_DIR.exists() else set()


def _store_files(db: Path | None, ratings: Path) -> tuple[list[dict], list[dict]]:
    """(rating files, corpus files) recorded in the store, each {file, sha256}."""
    rating_rows, corpus_rows = [], []
    for path in {p for p in (db, ratings) if p is not None and Path(p).exists() and Path(p).suffix != ".csv"}:
        con = read_connection(path)
        try:
            tables = {t for (t,) in con.execute("select table_name from duckdb_tables()").fetchall()}
            if "rating_files" in tables and Path(path) == Path(ratings):
                rating_rows += con.execute("select source_file, sha256 from rating_files order by 1").fetchall()
            if "ingested_files" in tables:
                corpus_rows += con.execute("select source_file, sha256 from ingested_files order by 1").fetchall()
        finally:
            con.close()
    as_dicts = lambda rows: [{"file": f, "sha256": h} for f, h in sorted(set(rows))]  # noqa: E731
    return as_dicts(rating_rows), as_dicts(corpus_rows)


def collect(ratings: Path, db: Path | None, checkpoints: dict[str, Path]) -> dict:
    """The provenance of one evaluation; `checkpoints` maps each evaluated LM setting to its version folder."""
    rating_files, corpus_files = _store_files(db, ratings)
    if Path(ratings).suffix == ".csv":
        rating_files = [{"file": str(ratings), "sha256": file_sha256(Path(ratings))}]
    sample = sample_hashes()
    from_sample = [f["file"] for f in rating_files + corpus_files if f["sha256"] in sample]
    return {
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "lmcr": __version__,
        "git_commit": git_commit(),
        "machine": machine(),
        "ratings": rating_files,
        "corpus": corpus_files,
        "checkpoints": [{"setting": s, "version": p.name, "manifest_sha256": file_sha256(p / "manifest.json")}
                        for s, p in sorted(checkpoints.items())],
        "sample_files": from_sample,
    }
