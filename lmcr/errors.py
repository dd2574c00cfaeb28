"""What every LMCR error shares: a reason that fits the command line's one line."""

from __future__ import annotations


class LMCRError(Exception):
    """Base of LMCR's own errors. Its message is already the one line a user reads (file, line, reason);
    the command line prints it as it is. Each subclass also derives from the built-in error it refines
    (ValueError for bad input, RuntimeError for a broken state), so callers may catch either."""


def one_line(reason: object, limit: int | None = None) -> str:
    """An exception (or text) as one line: DuckDB, gensim and torch put hints and context on further
    lines; `limit` cuts what a library may make very long."""
    text = " ".join(str(reason).split())
    return text if limit is None else text[:limit]
