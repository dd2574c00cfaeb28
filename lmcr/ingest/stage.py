"""Parquet staging written by parallel workers, and the single-writer load into DuckDB."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import duckdb
import pyarrow as pa
import pyarrow.parquet as pq

from lmcr.files import atomic_path
from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.ingest.sources import Source
from lmcr.store import insert_rows, transaction

DOCUMENT_SCHEMA = pa.schema(
    [
        ("corpus", pa.string()),
        ("source", pa.string()),
        ("doc_id", pa.string()),
        ("title", pa.string()),
        ("category", pa.string()),
        ("subset", pa.string()),
        ("url", pa.string()),
        ("source_file", pa.string()),
        ("position", pa.int32()),
    ]
)
SENTENCE_SCHEMA = pa.schema(
    [
        ("corpus", pa.string()),
        ("source", pa.string()),
        ("doc_id", pa.string()),
        ("sent_id", pa.int32()),
        ("kind", pa.string()),
        ("text", pa.string()),
        ("n_words", pa.int32()),
        ("source_file", pa.string()),
        ("position", pa.int32()),
        ("seg_start", pa.float64()),
        ("seg_end", pa.float64()),
    ]
)
QUARANTINE_SCHEMA = pa.schema(
    [
        ("stage", pa.string()),
        ("corpus", pa.string()),
        ("source_file", pa.string()),
        ("position", pa.int32()),
        ("reason", pa.string()),
        ("record", pa.string()),
    ]
)
TABLES = {"documents": DOCUMENT_SCHEMA, "sentences": SENTENCE_SCHEMA, "quarantine": QUARANTINE_SCHEMA}


@dataclass(frozen=True)
class StagedFile:
    """A parsed source as Parquet files plus its counts, ready for `load_staged`."""

    source_file: str
    sha256: str
    format: str
    corpus: str
    encoding: str
    parquet: dict[str, str]
    records_in: int
    records_loaded: int
    records_quarantined: int
    documents: int
    sentences: int
    words: int


def write_parquet_atomic(rows: list[dict], schema: pa.Schema, path: Path) -> None:
    """Write rows as Parquet under a temporary name and rename, so readers never see half a file."""
    with atomic_path(path) as tmp:
        pq.write_table(pa.Table.from_pylist(rows, schema=schema), tmp)


def stage(source: Source, parsed: ParsedFile, sha256: str, staging_dir: Path) -> StagedFile:
    """Write one parsed source to `staging_dir/ingest/<sha256>-<corpus>.<table>.parquet`."""
    rows = {"documents": parsed.documents, "sentences": parsed.sentences, "quarantine": parsed.rejects}
    paths: dict[str, str] = {}
    for table, schema in TABLES.items():
        path = staging_dir / "ingest" / f"{sha256[:24]}-{source.corpus}.{table}.parquet"
        write_parquet_atomic(rows[table], schema, path)
        paths[table] = str(path)
    return StagedFile(
        source_file=source.key,
        sha256=sha256,
        format=source.format,
        corpus=source.corpus,
        encoding=source.encoding or "",
        parquet=paths,
        records_in=parsed.records_in,
        records_loaded=parsed.records_loaded,
        records_quarantined=len(parsed.rejects),
        documents=len(parsed.documents),
        sentences=len(parsed.sentences),
        words=parsed.words,
    )


def already_loaded(con: duckdb.DuckDBPyConnection, source: Source, sha256: str) -> bool:
    """True when this exact content (same bytes, adapter and encoding) is loaded, from this path (a
    re-ingest is a no-op) or another (a copy: loading it again would count every sentence twice). A path
    already loaded into another corpus is an IngestError: re-ingesting it must not move its rows."""
    other = con.execute(
        "select corpus from ingested_files where source_file = ? and corpus <> ?", [source.key, source.corpus]
    ).fetchone()
    if other:
        raise IngestError(
            source.key,
            None,
            f"already loaded into corpus {other[0]!r}, not {source.corpus!r}; "
            "its rows stay there (ingest it with the same flag)",
        )
    row = con.execute(
        "select 1 from ingested_files where sha256 = ? and format = ? and encoding = ?",
        [sha256, source.format, source.encoding or ""],
    ).fetchone()
    return row is not None


def _delete_rows(con: duckdb.DuckDBPyConnection, source_file: str) -> None:
    for table in ("documents", "sentences"):
        con.execute(f"delete from {table} where source_file = ?", [source_file])
    con.execute("delete from quarantine where stage = 'ingest' and source_file = ?", [source_file])
    con.execute("delete from ingested_files where source_file = ?", [source_file])


def remove_sources(con: duckdb.DuckDBPyConnection, paths: list[str]) -> list[dict]:
    """Remove ingested sources (as stored, or the same file by absolute path) with their documents,
    sentences and quarantined records, in one transaction; returns the removed `ingested_files` rows.
    Their frames go with the next frame build. A path that was never ingested is an IngestError and
    nothing is removed."""
    stored = {key: Path(key).resolve() for (key,) in con.execute("select source_file from ingested_files").fetchall()}
    keys = []
    for path in paths:
        match = path if path in stored else next((k for k, p in stored.items() if p == Path(path).resolve()), None)
        if match is None:
            raise IngestError(str(path), None, "not an ingested source: nothing removed")
        keys.append(match)
    removed = []
    with transaction(con):
        for key in dict.fromkeys(keys):
            cursor = con.execute("select * from ingested_files where source_file = ?", [key])
            names = [d[0] for d in cursor.description]
            removed.append(dict(zip(names, cursor.fetchone())))
            _delete_rows(con, key)
    return removed


def _replace_rows(con: duckdb.DuckDBPyConnection, staged: StagedFile) -> None:
    _delete_rows(con, staged.source_file)
    clash = con.execute(
        "select d.doc_id, d.source_file from documents d join read_parquet(?) p using (doc_id) limit 1",
        [staged.parquet["documents"]],
    ).fetchone()
    if clash:
        raise IngestError(
            staged.source_file, None, f"document id {clash[0]!r} is already loaded from {clash[1]}; rename one file"
        )
    for table, schema in TABLES.items():
        columns = ", ".join(schema.names)
        con.execute(f"insert into {table} ({columns}) select {columns} from read_parquet(?)", [staged.parquet[table]])
    insert_rows(
        con,
        "ingested_files",
        [
            {
                k: getattr(staged, k)
                for k in (
                    "source_file",
                    "sha256",
                    "format",
                    "corpus",
                    "encoding",
                    "records_in",
                    "records_loaded",
                    "records_quarantined",
                    "documents",
                    "sentences",
                    "words",
                )
            }
        ],
    )


def load_staged(con: duckdb.DuckDBPyConnection, staged: StagedFile) -> None:
    """Replace a source's rows with its staged Parquet in one transaction (all or nothing)."""
    with transaction(con):
        _replace_rows(con, staged)
