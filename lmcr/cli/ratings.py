"""The `annotate` commands: crowd plausibility ratings, from MTurk tasks out to ratings in and their
quality."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import typer

from lmcr.annotate.hits import HitSettings
from lmcr.cli.common import MTURK_SECONDS, SEED, app, console, fail, open_store, print_rows, split_names
from lmcr.workspace import Workspace

annotate_app = typer.Typer(
    help="Crowd plausibility ratings: MTurk results in, aggregates in DuckDB.", no_args_is_help=True
)
app.add_typer(annotate_app, name="annotate")


@annotate_app.command("ingest")
def annotate_ingest(
    results: list[Path] = typer.Argument(..., help="MTurk batch-results CSV files."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Load MTurk batch results (single- or multi-item layout); defects are quarantined or flagged."""
    from lmcr.annotate.results import ingest_ratings
    from lmcr.store import check_contracts

    ws = Workspace.from_env(db=db)
    con = open_store(ws)
    rows = [ingest_ratings(con, path) for path in results]
    check_contracts(con, ws.sql_dir, "ratings")
    for r in rows:
        if r.get("skipped"):
            console.print(f"{r['source_file']}: already loaded (same sha256), nothing changed")
    loaded = [
        {"file": Path(r["source_file"]).name} | {k: v for k, v in r.items() if k != "source_file"}
        for r in rows
        if not r.get("skipped")
    ]
    if loaded:
        print_rows("rating files", loaded)
    n, frames = con.execute(
        "select count(*), count(distinct (verb, role1, arg1, role2, arg2)) from valid_ratings"
    ).fetchone()
    console.print(f"{n:,} valid ratings of {frames:,} frames in {ws.db}")


@annotate_app.command("tasks")
def annotate_tasks(
    out: Path = typer.Option(..., help="Folder for batch.csv, hit_template.html, preview.html, tasks.json."),
    mode: Literal["protocol", "corpus", "disagreement"] = typer.Option("protocol", help="Which frames to ask about."),
    per_hit: int = typer.Option(10, min=1, max=100, help="Sentences per HIT."),
    gold_per_hit: int = typer.Option(
        1, min=0, max=99, help="Gold check items per HIT (from near-unanimous past ratings)."
    ),
    n_frames: int | None = typer.Option(None, min=1, help="Frames to ask about (corpus / disagreement)."),
    methods: str = typer.Option("sentence_lm,frame_lm", help="Scorers compared by the disagreement mode."),
    verbs: str = typer.Option(
        "", help="Comma-separated predicates to ask about, hand-written or learned ('put away'); default the eleven."
    ),
    batch: str = typer.Option("batch", help="Batch name recorded with the gold items."),
    seed: int = typer.Option(0, **SEED, help="Seed of the frame order and HIT layout."),
    title: str = typer.Option(HitSettings.title, help="HIT title workers see in the marketplace."),
    description: str = typer.Option(HitSettings.description, help="HIT description."),
    keywords: str = typer.Option(HitSettings.keywords, help="Comma-separated search keywords."),
    reward: str = typer.Option(HitSettings.reward, help="US dollars per assignment, e.g. 0.30."),
    duration: int = typer.Option(
        HitSettings.assignment_duration_s, **MTURK_SECONDS, help="Seconds a worker has for one HIT."
    ),
    lifetime: int = typer.Option(HitSettings.lifetime_s, **MTURK_SECONDS, help="Seconds the HITs stay available."),
    assignments: int = typer.Option(HitSettings.assignments, min=1, max=1_000_000, help="Workers per HIT."),
    min_approval_rate: int = typer.Option(
        HitSettings.min_approval_rate, min=0, max=100, help="Qualification: least approval rate in percent (0: none)."
    ),
    min_approved_hits: int = typer.Option(
        HitSettings.min_approved_hits, min=0, help="Qualification: least approved HITs (0: none)."
    ),
    locale: str = typer.Option(HitSettings.locale, help="Qualification: worker country, two-letter code ('': any)."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Write an MTurk batch of plausibility-rating HITs with gold checks, its template and a preview."""
    from lmcr.annotate.tasks import TaskConfig, generate_tasks
    from lmcr.lexicon import normalize_name

    ws = Workspace.from_env(db=db)
    config = TaskConfig(
        mode=mode,
        per_hit=per_hit,
        gold_per_hit=gold_per_hit,
        n_frames=n_frames,
        seed=seed,
        batch=batch,
        verbs=tuple(normalize_name(v) for v in split_names(verbs)),
    )
    settings = HitSettings(
        title=title,
        description=description,
        keywords=keywords,
        reward=reward,
        assignment_duration_s=duration,
        lifetime_s=lifetime,
        assignments=assignments,
        min_approval_rate=min_approval_rate,
        min_approved_hits=min_approved_hits,
        locale=locale,
    )
    scorers = {m: ws.scorer(m) for m in split_names(methods)} if mode == "disagreement" else None
    meta = generate_tasks(open_store(ws), out, config, scorers, settings)
    console.print(
        f"{meta['frames']:,} frames in {meta['hits']:,} HITs ({meta['gold_items']} gold items of "
        f"{meta['gold_available']} available) -> {out / 'batch.csv'}; check {out / 'preview.html'}"
    )


@annotate_app.command("quality")
def annotate_quality(
    decisions: Path | None = typer.Option(None, help="Write the Approve/Reject re-upload CSV here."),
    aggregates: Path | None = typer.Option(None, help="Write per-frame mean, n and Dawid-Skene label (CSV)."),
    max_spam: float = typer.Option(
        0.5, min=0.0, max=1.0, help="Reject workers MACE calls spammers with this probability."
    ),
    min_gold_accuracy: float = typer.Option(0.5, min=0.0, max=1.0, help="Reject assignments failing more gold checks."),
    db: Path | None = typer.Option(None, help="DuckDB store."),
) -> None:
    """Krippendorff's alpha overall and per verb, the worker table, and approve/reject decisions."""
    from lmcr.annotate.quality import QualityRules, alpha_by_verb, dawid_skene, worker_table, write_decisions
    from lmcr.annotate.quality import decisions as decide
    from lmcr.files import atomic_path

    ws = Workspace.from_env(db=db)
    con = open_store(ws)
    if not con.execute("select count(*) from ratings").fetchone()[0]:
        fail(f"no ratings in {ws.db}: run `lmcr annotate ingest RESULTS.csv` first")
    print_rows(
        "Krippendorff's alpha (interval)", [{"verbs": k, "alpha": f"{v:.3f}"} for k, v in alpha_by_verb(con).items()]
    )
    table = worker_table(con)
    print_rows(
        "workers",
        [{k: (str(v) if isinstance(v, float) else v) for k, v in row.items()} for row in table.to_dict("records")],
    )
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
