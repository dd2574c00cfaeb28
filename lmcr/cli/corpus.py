"""Commands that build the corpora: `ingest` (sources into the sentence table), `frames` (the frame
corpora), and the semantic role labeller on its own, `srl` and `srl-eval`."""

from __future__ import annotations

import time
from collections import Counter
from pathlib import Path
from typing import Literal

import typer
from rich.console import Console

from lmcr.cli.common import (
    SPACY_MODEL_HELP,
    WORKERS,
    advance,
    app,
    console,
    fail,
    note,
    one_or_batch,
    open_store,
    print_rows,
    progress_bar,
    write_batch,
)
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.workspace import Workspace

SourceFormat = Literal["youcook2", "recipe_json", "mealmaster", "feeding_america", "epic_kitchens", "virtualhome"]
RESOURCES_HELP = "Learned SRL resources (default $LMCR_DATA_DIR/srl)."


@app.command()
def ingest(
    youcook2: list[Path] = typer.Option([], "--youcook2", help="YouCook2 annotations JSON."),
    recipes: list[Path] = typer.Option(
        [], "--recipes", help="Recipe JSONL(.gz)/folder, Meal-Master/NYC text, Feeding America XML (file or folder)."
    ),
    household: list[Path] = typer.Option(
        [], "--household", help="EPIC-KITCHENS narration CSVs and VirtualHome program JSON (files or a folder)."
    ),
    fmt: SourceFormat | None = typer.Option(None, "--format", help="Force the adapter."),
    encoding: str | None = typer.Option(
        None, help="Force the text encoding of Meal-Master files (cp437, latin-1, ...)."
    ),
    workers: int = typer.Option(2, **WORKERS, help="Parallel parser processes."),
    remove: list[str] = typer.Option(
        [], "--remove", help="An ingested source to take out of the store, with its sentences (repeatable)."
    ),
    db: Path | None = typer.Option(None, help="DuckDB store (default $LMCR_DB or data/lmcr.duckdb)."),
) -> None:
    """Ingest cooking and household corpora into the sentence table; unchanged inputs are skipped.
    `--remove` takes sources out first (their frames go with the next `lmcr frames`)."""
    from lmcr.ingest import expand_corpora
    from lmcr.ingest.run import corpus_summary, ingest_sources
    from lmcr.ingest.stage import remove_sources

    if not youcook2 and not recipes and not household and not remove:
        fail("nothing to ingest: give --youcook2, --recipes and/or --household PATH (or --remove PATH)")
    ws = Workspace.from_env(db=db)
    started = time.perf_counter()
    sources = expand_corpora({"youcook2": youcook2, "recipes": recipes, "household": household}, fmt, encoding)
    con = open_store(ws)
    for row in remove_sources(con, remove) if remove else []:
        console.print(f"removed {row['source_file']}: {row['sentences']:,} sentences")
    with progress_bar("ingesting sources", len(sources)) as progress:
        loaded, skipped = ingest_sources(
            con,
            sources,
            ws.staging,
            workers,
            on_loaded=lambda s: (
                advance(progress)
                or progress.console.print(
                    f"loaded {Path(s.source_file).name}: {s.sentences:,} sentences, {s.records_quarantined} quarantined"
                )
            ),
        )
        advance(progress, len(skipped))
    summary = corpus_summary(con, ws.sql_dir)
    elapsed = time.perf_counter() - started
    print_rows(f"corpus in {ws.db}", summary)
    words = sum(s.words for s in loaded)
    console.print(
        f"{len(loaded)} loaded, {len(skipped)} unchanged (skipped) in {elapsed:.1f}s"
        + (f", {words / elapsed:,.0f} words/s" if loaded else "")
    )


@app.command()
def frames(
    kinds: str = typer.Option(",".join(FrameCorpusConfig.kinds), help="Sentence kinds to parse."),
    shard_size: int = typer.Option(FrameCorpusConfig.shard_size, min=1, help="Distinct texts per worker shard."),
    workers: int = typer.Option(2, **WORKERS, help="Parser processes."),
    model: str | None = typer.Option(None, help=SPACY_MODEL_HELP),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Build the frame corpora from the ingested sentences (skipped when nothing changed)."""
    from lmcr.frame_corpus.build import build_frame_corpus, process_pool
    from lmcr.store import check_contracts, named_query, query_dicts

    ws = Workspace.from_env(db=db)
    config = FrameCorpusConfig(
        kinds=tuple(k.strip() for k in kinds.split(",") if k.strip()),
        shard_size=shard_size,
        model=model or ws.spacy_model,
    )
    con = open_store(ws)
    with progress_bar("parsing shards", None) as progress:  # its total: the shards of new texts (on_start)
        build = build_frame_corpus(
            con,
            ws.staging,
            ws.srl_dir,
            config,
            process_pool(
                workers,
                on_shard=lambda r: advance(progress),
                on_start=lambda shards: progress.update(progress.task_ids[0], total=shards),
            ),
            log=lambda message: progress.update(progress.task_ids[0], description=message),
        )
    check_contracts(con, ws.sql_dir, prefix="frames_")
    print_rows(f"robot-predicate frames in {ws.db}", query_dicts(con, named_query(ws.sql_dir, "frame_counts")))
    if build is None:
        console.print("frame corpus unchanged (skipped)")
    else:
        resources = "kept the last build's" if build["resources_reused"] else "learned new"
        console.print(
            f"{build['sentences']:,} sentences ({build['texts']:,} distinct texts); {resources} compounds and "
            f"first words; parsed {build['texts_parsed']:,} new texts, {build['words_parsed']:,} words in "
            f"{build['wall_s']:.1f}s: {build['words_per_s']:,.0f} words/s; imperative re-parses kept "
            f"{build['kept']:,}/{build['reparsed']:,}"
        )


@app.command()
def predicates(
    verb: str | None = typer.Argument(None, help="Show one predicate (or refused verb) with its evidence."),
    top: int = typer.Option(30, min=0, help="Predicates listed, most evidence first."),
    relearn: bool = typer.Option(False, help="Learn again from the current frame corpus, even if it has a table."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """The predicates learned from the frame corpus: coverage, and each one's roles and evidence."""
    from lmcr.frame_corpus.load import last_build
    from lmcr.frame_corpus.predicates import refresh_predicates
    from lmcr.lexicon import PREDICATES_FILE, load_lexicon

    ws = Workspace.from_env(db=db)
    if not ws.db.exists():
        fail(f"{ws.db}: no store yet (run `lmcr ingest`, then `lmcr frames`)")
    con = open_store(ws)
    build = last_build(con)
    if build is None:
        fail(f"{ws.db}: no frame corpus yet (run `lmcr frames`)")
    refresh_predicates(con, load_lexicon(learned=False), ws.srl_dir, build, force=relearn)
    rows = [
        dict(zip(("predicate", "frames", "roles", "rate", "sentence"), row))
        for row in con.execute(
            "select predicate, frames, role1 || ', ' || role2, round(role2_rate, 3), sentence from learned_predicates"
            " order by frames desc, predicate"
        ).fetchall()
    ]
    lex = load_lexicon(learned=ws.srl_dir / PREDICATES_FILE)
    if verb is not None:
        _show_predicate(verb, rows, lex)
        return
    print_rows(f"predicates learned from {ws.db} (top {top} of {len(rows):,})", rows[:top])
    console.print(f"{len(rows):,} learned, {len(lex.refused):,} verbs refused ({lex.REFUSED_BECAUSE})")


def _show_predicate(verb: str, rows: list[dict], lex) -> None:
    """One predicate's row, a refused verb's evidence, or an error naming the verb."""
    from lmcr.lexicon import normalize_name

    name = normalize_name(verb)
    found = [r for r in rows if r["predicate"] == name]
    if found:
        print_rows(f"learned predicate {name!r}", found)
    elif name in lex.refused:
        console.print(f"{name!r}: refused: {lex.refusal(name)}")
    elif name in lex.predicates:
        console.print(
            f"{name!r}: hand-written ({', '.join(lex.predicates[name].roles)}): {lex.predicates[name].sentence}"
        )
    else:
        fail(f"no predicate {name!r}: the corpora use it too seldom, or never")


@app.command()
def srl(
    text: str | None = typer.Argument(None, help="One instruction to parse and show."),
    input: Path | None = typer.Option(None, "--input", help="JSONL of {id, text}."),
    output: Path | None = typer.Option(None, "--output", help="JSONL of {id, text, frames}."),
    all_predicates: bool = typer.Option(False, help="Also output generic frames of other verbs."),
    model: str | None = typer.Option(None, help=SPACY_MODEL_HELP),
    resources: Path | None = typer.Option(None, help=RESOURCES_HELP),
) -> None:
    """Parse text into verb frames: one instruction shown, or a JSONL batch (see the CLI contract)."""
    from lmcr.jsonl import check_text

    if one_or_batch(text, input, output, 'give either "TEXT" or both --input IN.jsonl and --output OUT.jsonl'):
        from lmcr.srl.batch import read_srl_input, srl_batch

        records = read_srl_input(input)  # bad input fails before the model loads
        parser = Workspace.from_env().parser(model, resources)
        tally = write_batch(output, input, records, lambda rest: srl_batch(parser, rest, all_predicates), "parsing")
        console.print(f"{tally['lines']} records -> {output}")
        return
    parser = Workspace.from_env().parser(model, resources)
    found = parser.parse(check_text(text, "text"))
    for frame in found if all_predicates else [f for f in found if f.known]:
        Console().print(_frame_line(frame), highlight=False)
    if not any(f.known for f in found):
        from lmcr.srl.instruction import no_predicate

        fail(no_predicate(parser.lex, text, found))


def _frame_line(frame) -> str:
    roles = "  ".join(f"{role}={value if value is not None else '?'}" for role, value in frame.roles.items())
    return f"{frame.predicate:10s} {roles}" + ("" if frame.known else "   (generic frame)")


@app.command("srl-eval")
def srl_eval(
    gold: Path = typer.Option(..., "--gold", help="JSONL of {id, text, frames} with gold frames."),
    instructions: Path | None = typer.Option(
        None, help="JSONL of {instruction, expected, missing} to score instruction parsing."
    ),
    model: str | None = typer.Option(None, help=SPACY_MODEL_HELP),
    resources: Path | None = typer.Option(None, help=RESOURCES_HELP),
    show: bool = typer.Option(False, "--show", help="List every sentence with an error and its classes."),
) -> None:
    """Predicate and role precision/recall/F1 against gold frames, per predicate and overall, and the errors
    by class (missed/extra predicate, boundary, lemma, role, missed/extra role, wrong filler)."""
    from lmcr.srl.batch import parse_instructions
    from lmcr.srl.evaluate import read_gold, read_instruction_tasks, score_frames

    records = read_gold(gold)
    if not records:
        fail(f"{gold}: no gold sentences to score")
    tasks = read_instruction_tasks(instructions) if instructions else []
    parser = Workspace.from_env().parser(model, resources)
    predicted = [[f.to_json() for f in found] for found in parser.pipe(r["text"] for r in records)]
    scores = score_frames([r["frames"] for r in records], predicted, set(parser.lex.hand_written))
    print_rows(f"SRL on {gold.name} ({len(records)} sentences)", scores.table())
    _print_error_classes(records, predicted, set(parser.lex.hand_written), show)
    console.print(
        f"resources: compounds={'yes' if parser.compounds else 'no'}, "
        f"role priors={'yes' if parser.priors else 'no'}; imperative re-parses: "
        f"{parser.stats.accepted}/{parser.stats.reparsed} kept"
    )
    if tasks:
        right = 0
        for task, frame, correct in parse_instructions(parser, tasks):
            right += correct
            if not correct:
                note(f"  wrong: {task['instruction']!r} -> {frame}")
        console.print(f"instructions: {right}/{len(tasks)} = {right / len(tasks):.3f} parsed right")


def _print_error_classes(records: list[dict], predicted: list[list[dict]], known: set[str], show: bool) -> None:
    """Counts of SRL errors by class; with `show`, each sentence with errors, its gold and predicted frames."""
    from lmcr.srl.evaluate import ERROR_CLASSES, classify_errors

    errors = classify_errors([r["frames"] for r in records], predicted, known)
    counts = Counter(c for found in errors for c, _ in found)
    console.print("errors by class: " + ", ".join(f"{c} {counts[c]}" for c in ERROR_CLASSES), highlight=False)
    for record, found, pred in zip(records, errors, predicted, strict=True):
        if show and found:
            console.print(
                f"  {record['text']!r}: {', '.join(f'{c} ({d})' for c, d in found)}\n"
                f"    gold {record['frames']}\n    got  {pred}",
                highlight=False,
                soft_wrap=True,
            )
