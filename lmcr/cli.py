"""The `lmcr` command line: batch commands for each stage (formats in the project's CLI contract)."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Optional

import typer
from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from lmcr.config import paths_from_env
from lmcr.ingest import IngestError, expand_inputs
from lmcr.store import ContractViolation, MigrationError, connect

app = typer.Typer(help="LMCR: complete incomplete robot instructions with commonsense learned from recipes.",
                  no_args_is_help=True, pretty_exceptions_enable=False)
console = Console(stderr=True)


def fail(message: str) -> None:
    """Exit non-zero with a one-line reason (the CLI contract)."""
    console.print(f"[red]error:[/red] {message}", highlight=False, soft_wrap=True)
    raise typer.Exit(code=1)


def print_rows(title: str, rows: list[dict]) -> None:
    """Show dict rows as a rich table on stdout."""
    table = Table(title=title)
    for name in rows[0] if rows else []:
        table.add_column(name, justify="right" if isinstance(rows[0][name], (int, float)) else "left")
    for row in rows:
        table.add_row(*(f"{v:,}" if isinstance(v, int) else str(v) for v in row.values()))
    Console(width=None if sys.stdout.isatty() else 120).print(table)


@app.command()
def ingest(
    youcook2: list[Path] = typer.Option([], "--youcook2", help="YouCook2 annotations JSON."),
    recipes: list[Path] = typer.Option([], "--recipes", help="Recipe JSONL(.gz)/folder, Meal-Master/NYC text, Feeding America XML (file or folder)."),
    fmt: Optional[str] = typer.Option(None, "--format", help="Force the adapter: youcook2|recipe_json|mealmaster|feeding_america."),
    encoding: Optional[str] = typer.Option(None, help="Force the text encoding of Meal-Master files (cp437, latin-1, ...)."),
    workers: int = typer.Option(2, help="Parallel parser processes."),
    db: Optional[Path] = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb)."),
) -> None:
    """Ingest cooking corpora into the sentence table; unchanged inputs are skipped."""
    from lmcr.ingest.run import corpus_summary, ingest_sources

    if not youcook2 and not recipes:
        fail("nothing to ingest: give --youcook2 PATH and/or --recipes PATH")
    paths = paths_from_env(db=db)
    started = time.perf_counter()
    try:
        sources = expand_inputs(youcook2, "youcook2", fmt, encoding) + expand_inputs(recipes, "recipes", fmt, encoding)
        con = connect(paths.db, paths.sql_dir)
        columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
        with Progress(*columns, console=console) as progress:
            bar = progress.add_task("ingesting sources", total=len(sources))
            loaded, skipped = ingest_sources(
                con, sources, paths.staging, workers,
                on_loaded=lambda s: progress.advance(bar) or progress.console.print(
                    f"loaded {Path(s.source_file).name}: {s.sentences:,} sentences, {s.records_quarantined} quarantined"),
            )
            progress.advance(bar, len(skipped))
        summary = corpus_summary(con, paths.sql_dir)
    except (IngestError, MigrationError, ContractViolation, ValueError) as exc:
        fail(str(exc))
    elapsed = time.perf_counter() - started
    print_rows(f"corpus in {paths.db}", summary)
    words = sum(s.words for s in loaded)
    console.print(f"{len(loaded)} loaded, {len(skipped)} unchanged (skipped) in {elapsed:.1f}s"
                  + (f", {words / elapsed:,.0f} words/s" if loaded else ""))


@app.command()
def migrate(db: Optional[Path] = typer.Option(None, help="DuckDB store.")) -> None:
    """Apply pending `sql/NNN_*.sql` migrations to the store."""
    paths = paths_from_env(db=db)
    try:
        connect(paths.db, paths.sql_dir).close()
    except MigrationError as exc:
        fail(str(exc))
    console.print(f"{paths.db} is up to date")


def main() -> None:
    """Console-script entry point."""
    app(prog_name="lmcr")


if __name__ == "__main__":
    sys.exit(main())
