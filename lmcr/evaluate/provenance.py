"""Where a report's figures come from: the rating files and corpus files (with sha256), the checkpoint
versions (with their manifest's sha256), the code (git commit), the date and the machine; and whether
any of it is the embedded sample, which the report then says in a banner."""

from __future__ import annotations

import datetime as dt
import os
import platform
from pathlib import Path

from lmcr import __version__
from lmcr.checkout import REPO_ROOT, git_commit
from lmcr.files import file_sha256
from lmcr.store import read_connection

SAMPLE_DIR = REPO_ROOT / "data" / "sample"


def machine() -> str:
    return f"{platform.node()} ({platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()})"


def sample_hashes() -> set[str]:
    """sha256 of every file of the embedded sample: a copy of a sample file elsewhere is still the sample."""
    return {file_sha256(p) for p in SAMPLE_DIR.rglob("*") if p.is_file()} if SAMPLE_DIR.exists() else set()


def recorded_files(db: Path | None, table: str) -> list[dict]:
    """{file, sha256} of each input file a store recorded in `table` (ingested_files, rating_files);
    none when there is no such store or table."""
    if db is None or not Path(db).is_file():
        return []
    con = read_connection(db)
    try:
        if not con.execute("select count(*) from duckdb_tables() where table_name = ?", [table]).fetchone()[0]:
            return []
        rows = con.execute(f"select distinct source_file, sha256 from {table} order by all").fetchall()
    finally:
        con.close()
    return [{"file": f, "sha256": h} for f, h in rows]


def collect(ratings: Path, db: Path | None, checkpoints: dict[str, Path]) -> dict:
    """The provenance of one evaluation; `checkpoints` maps each evaluated LM setting to its version folder."""
    corpus_files = recorded_files(db, "ingested_files")
    rating_files = (
        [{"file": str(ratings), "sha256": file_sha256(Path(ratings))}]
        if Path(ratings).suffix == ".csv"
        else recorded_files(ratings, "rating_files")
    )
    sample = sample_hashes()
    from_sample = [f["file"] for f in rating_files + corpus_files if f["sha256"] in sample]
    return {
        "date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "lmcr": __version__,
        "git_commit": git_commit() or "unknown (not a git checkout)",
        "machine": machine(),
        "ratings": rating_files,
        "corpus": corpus_files,
        "checkpoints": [
            {"setting": s, "version": p.name, "manifest_sha256": file_sha256(p / "manifest.json")}
            for s, p in sorted(checkpoints.items())
        ],
        "sample_files": from_sample,
    }
