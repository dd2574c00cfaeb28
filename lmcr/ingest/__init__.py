"""Corpus ingestion: raw cooking corpora in, one clean sentence corpus out.

`expand_inputs` turns user paths into sources, `parse_source` runs the right adapter, `stage` writes
the result as Parquet (safe from parallel workers) and `load_staged` loads it into DuckDB as the
single writer, replacing that source's earlier rows in one transaction.
"""

from __future__ import annotations

from lmcr.ingest.records import IngestError, ParsedFile
from lmcr.ingest.sources import FORMATS, Source, detect_format, expand_corpora, expand_inputs, parse_source
from lmcr.ingest.stage import StagedFile, already_loaded, load_staged, stage

__all__ = [
    "FORMATS",
    "IngestError",
    "ParsedFile",
    "Source",
    "StagedFile",
    "already_loaded",
    "detect_format",
    "expand_corpora",
    "expand_inputs",
    "load_staged",
    "parse_source",
    "stage",
]
