"""Commands of the DuckDB store: `migrate` it, show its `schema`, and run `sql` or a named `query` on it
(read-only)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Literal

import typer

from lmcr.cli.common import app, console, fail, print_rows
from lmcr.workspace import Workspace

PARAM_OPTION = typer.Option([], "--param", help="NAME=VALUE for a $NAME parameter (repeatable), e.g. corpus=all.")
FORMAT_OPTION = typer.Option("table", "--format", help="Output format.")
DB_OPTION = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb).")
QueryFormat = Literal["table", "csv", "json"]


@app.command()
def migrate(db: Path | None = DB_OPTION) -> None:
    """Apply pending `sql/NNN_*.sql` migrations to the store."""
    ws = Workspace.from_env(db=db)
    ws.connect().close()
    console.print(f"{ws.db} is up to date")


@app.command()
def schema(out: Path | None = typer.Option(None, "--out", help="Write the page here (default: print it).")) -> None:
    """The store's schema page: tables, views, columns, types and what each holds, from the catalog."""
    from lmcr.catalog import schema_page
    from lmcr.files import atomic_path

    page = schema_page(Workspace.from_env().sql_dir)
    if out is None:
        sys.stdout.write(page)
        return
    with atomic_path(out) as tmp:
        tmp.write_text(page, encoding="utf-8")
    console.print(f"wrote {out}")


@app.command("sql")
def sql_command(
    statement: str = typer.Argument(..., help="One SQL statement, run read-only against the store."),
    param: list[str] = PARAM_OPTION,
    fmt: QueryFormat = FORMAT_OPTION,
    db: Path | None = DB_OPTION,
) -> None:
    """Run SQL on the store (read-only) and print the result as a table, CSV or JSON lines."""
    from lmcr.store import run_query

    _print_result(*run_query(Workspace.from_env(db=db).db, statement, _params(param)), fmt)


@app.command("query")
def query_command(
    name: str = typer.Argument(..., help="A named query: sql/queries/NAME.sql."),
    param: list[str] = PARAM_OPTION,
    fmt: QueryFormat = FORMAT_OPTION,
    db: Path | None = DB_OPTION,
) -> None:
    """Run a named query of sql/queries/ (read-only) and print the result."""
    from lmcr.store import named_query, run_query

    ws = Workspace.from_env(db=db)
    _print_result(*run_query(ws.db, named_query(ws.sql_dir, name), _params(param)), fmt)


def _params(items: list[str]) -> dict[str, str]:
    pairs = [item.partition("=") for item in items]
    bad = [item for item, (_, eq, _) in zip(items, pairs) if not eq]
    if bad:
        fail(f"--param takes NAME=VALUE, not {bad[0]!r}")
    return {key.strip(): value for key, _, value in pairs}


def _print_result(columns: list[str], rows: list[tuple], fmt: str) -> None:
    """A query result on stdout: a rich table, CSV with a header, or one JSON object per row."""
    import csv
    import json

    if fmt == "csv":
        writer = csv.writer(sys.stdout)
        writer.writerow(columns)
        writer.writerows(rows)
    elif fmt == "json":
        for row in rows:
            print(json.dumps(dict(zip(columns, row)), default=str, ensure_ascii=False))
    else:
        print_rows(f"{len(rows):,} rows", [dict(zip(columns, row)) for row in rows])
