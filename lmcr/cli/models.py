"""Commands of the language models and scorers: `train` a checkpoint, `score` frames, `evaluate` as in the
paper, choose the corpus `mixture`, and `complete` instructions with the detected objects."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Literal

import typer

from lmcr.cli.common import (
    CONCEPTNET_HELP,
    SEED,
    VECTORS_HELP,
    CorpusSetting,
    app,
    console,
    fail,
    note,
    one_or_batch,
    print_rows,
    split_names,
    write_batch,
)
from lmcr.evaluate.protocol import EvalConfig
from lmcr.lm.hyperparams import MIN_FREQ, LMConfig, TrainConfig
from lmcr.scorers.mixture import GRID as MIXTURE_GRID
from lmcr.scorers.registry import COMPLETION_METHOD, EVALUATED, METHODS
from lmcr.setting import ALL_SETTINGS, LINEARIZATIONS, SOURCE_CORPORA, Setting
from lmcr.workspace import Workspace

CHECKPOINT_ROOT_HELP = "Checkpoint root (default $LMCR_DATA_DIR/checkpoints)."
RATINGS_HELP = "MTurk batch-results CSV, or a DuckDB store with ingested ratings."


@app.command()
def train(
    linearization: Literal[LINEARIZATIONS] = typer.Option("sentence", help="Linearisation of the training text."),
    corpus: CorpusSetting = typer.Option("all", help="Corpus setting."),
    embedding: int = typer.Option(LMConfig.embedding, min=2, max=8192, help="Embedding = hidden size."),
    layers: int = typer.Option(LMConfig.layers, min=1, max=16, help="LSTM layers."),
    dropout: float = typer.Option(LMConfig.dropout, min=0.0, max=0.9, help="Dropout between layers and on embeddings."),
    max_epochs: int = typer.Option(
        TrainConfig.max_epochs, min=1, max=1000, help="Most epochs; the best by validation perplexity is kept."
    ),
    max_minutes: float | None = typer.Option(
        TrainConfig.max_minutes, min=0.1, help="Start no epoch likely to end past this budget."
    ),
    batch_tokens: int = typer.Option(TrainConfig.batch_tokens, min=64, max=10_000_000, help="Padded tokens per batch."),
    lr: float = typer.Option(TrainConfig.lr, min=1e-7, max=1.0, help="Adam learning rate."),
    decay_epochs: int = typer.Option(
        TrainConfig.decay_epochs, min=0, max=1000, help="Last epochs over which the rate decays linearly (0: none)."
    ),
    min_freq: int = typer.Option(MIN_FREQ, min=1, help="Vocabulary frequency cut-off."),
    seed: int = typer.Option(TrainConfig.seed, **SEED, help="Seed of the initial weights and the batch order."),
    device: str | None = typer.Option(None, help="cpu | cuda (default: cuda when present)"),
    precision: Literal["auto", "bf16", "fp32"] = typer.Option(
        "auto", help="auto: bf16 autocast where the hardware has it."
    ),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Train a language model on a corpus setting and publish its checkpoint."""
    from lmcr.lm.run import train_setting

    ws = Workspace.from_env(db=db)
    path = train_setting(
        ws.connect,
        ws.checkpoints,
        Setting(linearization, corpus),
        LMConfig(0, embedding, layers, dropout),
        TrainConfig(
            max_epochs=max_epochs,
            device=device,
            max_minutes=max_minutes,
            precision=precision,
            lr=lr,
            decay_epochs=decay_epochs,
            batch_tokens=batch_tokens,
            seed=seed,
        ),
        min_freq=min_freq,
        on_epoch=_show_epoch,
    )
    console.print(f"published {path}")


def _show_epoch(row: dict) -> None:
    console.print(
        f"epoch {row['epoch']}: train ppl {row['train_ppl']:.1f} ({row['objective']} softmax), "
        f"val ppl {row['val_ppl']:.1f}, {row['tokens_per_s']:,.0f} tokens/s on {row['device']}, "
        f"{row['precision']} ({row['seconds']:.0f}s)"
    )


@app.command()
def score(
    frames_csv: Path = typer.Option(..., "--frames", help="CSV with verb, role1, arg1, role2, arg2."),
    out: Path = typer.Option(..., "--out", help="CSV: the input plus one score column per method."),
    methods: str = typer.Option(
        "sentence_lm,frame_lm", help=f"Comma-separated: {', '.join(METHODS)}; a+b sums the scores of a and b."
    ),
    corpus: CorpusSetting = typer.Option("all", help="Training setting of the LM checkpoints."),
    checkpoint: Path | None = typer.Option(None, help=CHECKPOINT_ROOT_HELP),
    vectors: Path | None = typer.Option(None, help=VECTORS_HELP),
    conceptnet: Path | None = typer.Option(None, help=CONCEPTNET_HELP),
) -> None:
    """Score complete frames with each method (higher = more plausible)."""
    from lmcr.files import check_output_file
    from lmcr.frame import read_frames_csv, write_scores_csv
    from lmcr.scorers.registry import is_method_name

    check_output_file(out, reads=frames_csv)
    ws = Workspace.from_env()
    res = ws.resources(checkpoint, corpus, vectors, conceptnet)
    columns, rows = read_frames_csv(frames_csv, reserved=is_method_name)
    frames = [r.frame for r in rows]
    started = time.perf_counter()
    scores = {m: ws.scorer(m, res)(frames) for m in split_names(methods)}
    elapsed = time.perf_counter() - started
    write_scores_csv(out, columns, rows, scores)
    console.print(f"{len(rows):,} frames x {len(scores)} methods -> {out} ({elapsed:.2f}s)")


@app.command()
def evaluate(
    ratings: Path = typer.Option(..., help=RATINGS_HELP),
    out: Path = typer.Option(..., help="Report folder: report.md, report.html, fig4*.png, figures.json."),
    methods: str | None = typer.Option(
        None,
        show_default=",".join(EVALUATED),
        help="Comma-separated methods for Table I and Fig. 4 A/B. A method given "
        "here must build; a default that cannot is skipped with a note.",
    ),
    settings: str | None = typer.Option(
        None,
        show_default=",".join(s.label for s in ALL_SETTINGS),
        help="LM settings for Fig. 4 C/D (method/corpus); as --methods, a "
        "default setting not trained is skipped with a note.",
    ),
    checkpoint: Path | None = typer.Option(None, help=CHECKPOINT_ROOT_HELP),
    vectors: Path | None = typer.Option(None, help=VECTORS_HELP),
    conceptnet: Path | None = typer.Option(None, help=CONCEPTNET_HELP),
    per_verb: int = typer.Option(EvalConfig.per_verb, min=1, max=100_000, help="Scenarios per verb."),
    seed: int = typer.Option(0, **SEED, help="Seed of the scenario draw (the same for every method)."),
    calibrate: bool = typer.Option(True, help="Calibrate completion of the LM methods on these ratings."),
    paper: Path | None = typer.Option(
        None, help="The paper's LaTeX source: its Table I beside ours (default $LMCR_PAPER; none: no paper columns)."
    ),
    requests: Path | None = typer.Option(
        None,
        help="Household requests (a JSONL file in the external sets' format, or a folder of them) to calibrate "
        "the learned verbs' completion on, beside the ratings' calibration.",
    ),
) -> None:
    """The paper's evaluation on rated frames: Table I, Fig. 4 A-D, with a report."""
    from lmcr.evaluate.run import run_evaluation
    from lmcr.files import check_output_dir

    ws = Workspace.from_env()
    res = ws.resources(checkpoint, "all", vectors, conceptnet, seed)
    check_output_dir(out)  # before the work: a user's folder is refused at once, not after the evaluation
    if requests is not None and not calibrate:
        fail("--requests calibrates completion: it cannot be given with --no-calibrate")
    items = None
    if requests is not None:  # a bad file fails before the evaluation
        from lmcr.evaluate.external import read_requests

        items = read_requests(requests)
    rated = _rated_frames(ratings, ws)
    # what the user named must build; the defaults may be skipped (a setting not trained, no ConceptNet)
    default_methods, default_settings = list(EVALUATED), [s.label for s in ALL_SETTINGS]
    chosen_methods = default_methods if methods is None else split_names(methods)
    chosen_settings = default_settings if settings is None else split_names(settings)
    optional = (default_methods if methods is None else []) + (default_settings if settings is None else [])
    results = run_evaluation(
        rated,
        res,
        chosen_methods,
        chosen_settings,
        EvalConfig(per_verb=per_verb, seed=seed),
        out,
        ws.calibration if calibrate else None,
        log=lambda m: console.print(m, highlight=False),
        ratings_source=ratings,
        paper=paper or ws.paper,
        optional=optional,
    )
    rows = [{"method": m, "overall": f"{acc.get('all', float('nan')):.3f}"} for m, acc in results.table1.items()]
    print_rows(f"Table I overall accuracy (lambda={results.config.lam:g}, k={results.config.k})", rows)
    if items is not None:
        from lmcr.evaluate.external import calibrate_learned_verbs

        methods_run = [m for m in chosen_methods if m in results.table1]
        calibrate_learned_verbs(ws, res, methods_run, items, log=lambda m: console.print(m, highlight=False))
    console.print(f"report: {out / 'report.html'}")


def _rated_frames(ratings: Path, ws: Workspace) -> list:
    """The rated frames of the robot's predicates in `ratings` (a results CSV or a store); none fails."""
    from lmcr.evaluate.ratings import load_ratings
    from lmcr.lexicon import load_lexicon

    rated = load_ratings(ratings, ws.sql_dir, set(load_lexicon().predicates))
    if not rated:
        fail(f"{ratings}: no rated frames of the robot's predicates")
    return rated


@app.command()
def mixture(
    ratings: Path = typer.Option(..., help=RATINGS_HELP),
    corpus: Literal[SOURCE_CORPORA] = typer.Option("household", help="The corpus whose weight is chosen."),
    method: str = typer.Option(COMPLETION_METHOD, help="The method whose Table I accuracy decides."),
    grid: str = typer.Option(",".join(f"{w:g}" for w in MIXTURE_GRID), help="Candidate weights."),
    checkpoint: Path | None = typer.Option(None, help=CHECKPOINT_ROOT_HELP),
    per_verb: int = typer.Option(EvalConfig.per_verb, min=1, max=100_000, help="Scenarios per verb."),
    instructions: Path | None = typer.Option(
        None,
        help="Instructions JSONL ({instruction, objects, expected}) to "
        "choose on as well: the best mean of the two accuracies wins, "
        "and the context term's weight is chosen on them.",
    ),
) -> None:
    """Choose how much a corpus counts in the pooled `all` setting, on rated frames (and instructions, with
    the weight of the context term); saves mixture.json (read by every command that scores, and part of the
    completion calibration's fingerprint)."""
    from lmcr.evaluate.choose_mixture import DevInstructions, choose_and_save

    ws = Workspace.from_env()
    try:
        weights = tuple(float(w) for w in split_names(grid))
    except ValueError:
        fail(f"--grid: not a list of numbers: {grid!r}")
    rated = _rated_frames(ratings, ws)
    dev = DevInstructions.read(instructions, ws.parser) if instructions else None
    chosen, context_weight, path = choose_and_save(
        rated,
        ratings,
        ws.resources(checkpoint),
        method,
        ws.data_dir,
        corpus,
        weights,
        EvalConfig(per_verb=per_verb),
        log=lambda m: console.print(m, highlight=False),
        instructions=dev,
    )
    context = f", context weight {context_weight:g}" if context_weight else ""
    console.print(
        f"{corpus} weight {chosen.weight(corpus):g}{context} saved to {path}; run `lmcr evaluate` to "
        "calibrate completion under it"
    )


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
    from lmcr.complete_batch import complete_batch, read_complete_input

    one_or_batch(None, input, output, "give --input IN.jsonl and --output OUT.jsonl")  # the batch form only
    records = read_complete_input(input)  # bad input fails before the models load
    ws = Workspace.from_env()
    scorer, config = ws.completion_scorer(method, ws.resources(checkpoint, corpus, vectors, conceptnet))
    parser = ws.parser(model)

    def completed(rest):
        return complete_batch(parser, scorer, config, rest, input, log=lambda m: note(m, soft_wrap=True))

    tally = write_batch(output, input, records, completed, "completing")
    console.print(
        f"{tally['lines']:,} instructions -> {output} ({tally['question']} clarifying questions, "
        f"{tally['error']} not completed; {config.source})"
    )
