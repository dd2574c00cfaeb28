"""What every LMCR error shares: a reason that fits the command line's one line."""

from __future__ import annotations


def one_line(reason: object, limit: int | None = None) -> str:
    """An exception (or text) as one line: DuckDB, gensim and torch put hints and context on further
    lines; `limit` cuts what a library may make very long."""
    text = " ".join(str(reason).split())
    return text if limit is None else text[:limit]
