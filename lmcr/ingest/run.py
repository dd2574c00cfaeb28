"""Ingest sources into the store: plan (skip unchanged), parse and stage in parallel, load serially."""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import duckdb

from lmcr.ingest.sources import Source, parse_source
from lmcr.ingest.stage import StagedFile, already_loaded, load_staged, stage
from lmcr.store import check_contracts, named_query, query_dicts


def plan(con: duckdb.DuckDBPyConnection, sources: list[Source]) -> tuple[list[tuple[Source, str]], list[Source]]:
    """Split sources into (source, sha256) to ingest and the ones to skip: already loaded with this
    content, or a copy of content loaded from another path (or listed earlier in this call)."""
    todo, skipped, seen = [], [], set()
    for source in sources:
        sha = source.sha256()
        identity = (sha, source.format, source.encoding or "")
        if identity in seen or already_loaded(con, source, sha):
            skipped.append(source)
        else:
            todo.append((source, sha))
        seen.add(identity)
    return todo, skipped


def parse_and_stage(source: Source, sha256: str, staging_dir: Path) -> StagedFile:
    """Parse one source and write it to Parquet; safe to run in parallel worker processes."""
    return stage(source, parse_source(source), sha256, staging_dir)


def ingest_sources(
    con: duckdb.DuckDBPyConnection,
    sources: list[Source],
    staging_dir: Path,
    workers: int = 2,
    on_loaded: Callable[[StagedFile], None] | None = None,
) -> tuple[list[StagedFile], list[Source]]:
    """Ingest every changed source; return what was loaded and what was skipped as unchanged."""
    todo, skipped = plan(con, sources)
    loaded: list[StagedFile] = []

    def finish(staged: StagedFile) -> None:
        load_staged(con, staged)
        loaded.append(staged)
        if on_loaded:
            on_loaded(staged)

    if workers <= 1 or len(todo) <= 1:
        for source, sha in todo:
            finish(parse_and_stage(source, sha, staging_dir))
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            # Largest first, so the long pole starts at once.
            ordered = sorted(todo, key=lambda t: -_size(t[0].path))
            futures = [pool.submit(parse_and_stage, s, sha, staging_dir) for s, sha in ordered]
            for future in as_completed(futures):
                finish(future.result())
    return loaded, skipped


def _size(path: Path) -> int:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) if path.is_dir() else path.stat().st_size


def corpus_summary(con: duckdb.DuckDBPyConnection, sql_dir: Path) -> list[dict]:
    """Per corpus: records in, loaded, quarantined, documents, sentences, words; contracts checked first."""
    check_contracts(con, sql_dir, prefix="ingest_")
    return query_dicts(con, named_query(sql_dir, "corpus_summary"))
