"""Evaluate flow: ratings from the store (or an MTurk CSV) -> scores of every method -> Table I and
Fig. 4 report, published as Prefect artifacts (the Table I table, the report's markdown and a link to
its HTML). The evaluation task is cached on what it reads (LM versions, ratings, frame builds and its
parameters) and on the code that computes it, so an unchanged re-run of the pipeline costs nothing."""

from __future__ import annotations

import hashlib
import json
from dataclasses import replace
from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_link_artifact, create_markdown_artifact, create_table_artifact
from prefect.cache_policies import NO_CACHE

from lmcr.checkout import library_fingerprint
from lmcr.evaluate.protocol import EvalConfig
from lmcr.evaluate.ratings import load_ratings
from lmcr.evaluate.run import SETTINGS, run_evaluation
from lmcr.files import cached_json, file_sha256
from lmcr.lexicon import load_lexicon
from lmcr.lm import checkpoint as ckpt
from lmcr.scorers.context_pmi import WEIGHT as CONTEXT_WEIGHT
from lmcr.scorers.mixture import FILE as MIXTURE_FILE
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.registry import COMPLETION_METHOD, EVALUATED
from lmcr.scorers.resources import MethodResources
from lmcr.setting import Setting
from lmcr.store import read_connection
from lmcr.workspace import Workspace


def evaluation_key(parameters: dict) -> str:
    """Cache key of an evaluation: the LM versions in use, the ratings (the store's rating files or the
    CSV's content), the frame builds (frame_counts), the parameters, the library's code and this flow's
    source, and whether the report is still there (a deleted report is written again)."""
    report_there = (Path(parameters["out"]) / "report.md").exists()
    return inputs_key(parameters["res"], Path(parameters["ratings"]), [report_there, parameters])


def inputs_key(res: MethodResources, ratings: Path, extra: list) -> str:
    """Cache key of what a task reads: the LM versions in use, the ratings (the store's rating files or the
    CSV's content), the frame builds, the library's code and this flow's source, and `extra` (its
    parameters)."""
    versions = [str(ckpt.resolve(p.parent)) for p in sorted(Path(res.checkpoints).glob("*/LATEST"))]
    if res.db is not None and ratings.resolve() == Path(res.db).resolve():
        with read_connection(res.db) as con:
            rating_files = con.execute("select sha256 from rating_files order by 1").fetchall()
    else:
        rating_files = file_sha256(ratings) if ratings.is_file() else str(ratings)
    frames = []
    if res.db is not None and Path(res.db).exists():
        with read_connection(res.db) as con:
            frames = con.execute("select fingerprint from frame_builds order by built_at").fetchall()
    code = [library_fingerprint(), file_sha256(Path(__file__))]
    blob = json.dumps([versions, rating_files, frames, code, extra], default=str, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()


@task(name="evaluate", retries=0, cache_policy=NO_CACHE)  # its own JSON cache, below
def evaluate_task(
    ratings: str,
    out: str,
    methods: list[str],
    settings: list[str],
    res: MethodResources,
    per_verb: int,
    seed: int,
    ws: Workspace,
    optional: list[str] | None = None,
) -> dict:
    """Table I and Fig. 4 on the ratings; completion of the LM methods calibrated into the workspace. The
    result is cached as plain JSON in the workspace (`cache/evaluate-KEY.json`, read with `json` alone:
    nothing in it can run code), so an unchanged re-run returns the same without evaluating."""
    key = evaluation_key(
        {
            "ratings": ratings,
            "out": out,
            "methods": methods,
            "settings": settings,
            "res": res,
            "per_verb": per_verb,
            "seed": seed,
            "optional": optional,
        }
    )

    def evaluate() -> dict:
        rated = load_ratings(Path(ratings), ws.sql_dir, set(load_lexicon().predicates))
        results = run_evaluation(
            rated,
            res,
            methods,
            settings,
            EvalConfig(per_verb=per_verb, seed=seed),
            Path(out),
            ws.calibration,
            log=get_run_logger().info,
            ratings_source=Path(ratings),
            paper=ws.paper,
            optional=optional or (),
        )
        return json.loads(json.dumps(results.to_json()))  # as a cached run reads it back

    usable = lambda saved: isinstance(saved, dict) and isinstance(saved.get("table1"), dict)  # noqa: E731
    return cached_json(ws.data_dir / "cache" / f"evaluate-{key}.json", usable, evaluate)


@task(name="choose-mixture", cache_policy=NO_CACHE)  # its own JSON cache, below
def mixture_task(ratings: str, res: MethodResources, ws: Workspace, instructions: str | None = None) -> str:
    """Choose the household weight of the pooled setting on the ratings (and on the instructions, with the
    context term's weight: `lmcr mixture`) and save them. The choice is kept as plain JSON in the workspace
    (`cache/mixture-KEY.json`, keyed on what it reads: the LMs, ratings, frames and instructions, and on the
    code): an unchanged re-run, whose mixture file still holds that choice, does not choose again (16 s of the
    sample pipeline's re-run)."""
    from lmcr.evaluate.choose_mixture import DevInstructions, choose_and_save

    # the mixture in use and the context term's weight are what is chosen here: not inputs of the choice
    neutral = replace(res, mixture=Mixture(), context_weight=CONTEXT_WEIGHT)
    dev_sha = file_sha256(Path(instructions)) if instructions and Path(instructions).is_file() else instructions
    key = inputs_key(neutral, Path(ratings), [COMPLETION_METHOD, neutral, dev_sha])
    mixture_file = ws.data_dir / MIXTURE_FILE

    def choose() -> dict:
        rated = load_ratings(Path(ratings), ws.sql_dir, set(load_lexicon().predicates))
        dev = DevInstructions.read(Path(instructions), ws.parser) if instructions else None
        chosen, context_weight, path = choose_and_save(
            rated, Path(ratings), res, COMPLETION_METHOD, ws.data_dir, log=get_run_logger().info, instructions=dev
        )
        label = chosen.label + (f", context weight {context_weight:g}" if context_weight else "")
        return {"chosen": label, "mixture_sha256": file_sha256(path)}

    def usable(saved) -> bool:  # the choice stands while the mixture file is the one it wrote
        return mixture_file.is_file() and saved["mixture_sha256"] == file_sha256(mixture_file)

    return cached_json(ws.data_dir / "cache" / f"mixture-{key}.json", usable, choose)["chosen"]


@task(name="calibrate-learned-verbs")
def calibrate_learned_task(requests: str, methods: list[str], res: MethodResources, ws: Workspace) -> dict:
    """The learned verbs' completion calibrated on household requests (`lmcr evaluate --requests`) for
    each method the ratings calibrated: method -> what was done."""
    from lmcr.evaluate.external import calibrate_learned_verbs, read_requests

    items = read_requests(Path(requests))
    return calibrate_learned_verbs(ws, res, methods, items, log=get_run_logger().info)


@flow(name="evaluate")
def evaluate_flow(
    ratings: str | None = None,
    out: str | None = None,
    methods: list[str] | None = None,
    settings: list[str] | None = None,
    conceptnet: str | None = None,
    vectors: str | None = None,
    per_verb: int = EvalConfig.per_verb,
    seed: int = 0,
    corpus: str = "all",
    data_dir: str | None = None,
    paper: str | None = None,
    mixture: bool = True,
    instructions: str | None = None,
    requests: str | None = None,
) -> dict:
    """Evaluate on `ratings` (default: the store's ingested ratings) and write the report to `out`
    (default `$LMCR_DATA_DIR/report`); `corpus` is the LM setting of the Table I methods. With `mixture`
    and a household sentence LM published, the household weight is chosen on the same ratings first
    (and on `instructions`, a JSONL of instructions in scenes, when given), so the default completion is
    evaluated and calibrated under it. `methods` and `settings` default to every method (EVALUATED) and LM
    setting (any spelling `Setting.parse` reads); a default that cannot be built (a setting not trained) is
    skipped with a note, while one given explicitly must build. With `requests` (household requests in the
    external sets' format, a file or a folder), the learned verbs' completion is calibrated on them too,
    and the result says so under `learned_verbs`."""
    optional = [*(EVALUATED if methods is None else ()), *(SETTINGS if settings is None else ())]
    methods = list(EVALUATED) if methods is None else methods
    settings = list(SETTINGS) if settings is None else [Setting.parse(s).label for s in settings]
    ws = Workspace.from_env(data_dir=data_dir)
    if paper:
        ws = replace(ws, paper=Path(paper))
    res = ws.resources(corpus=corpus, vectors=vectors, conceptnet=conceptnet, seed=seed)
    if mixture and corpus == "all" and (ws.checkpoints / Setting("sentence", "household").name / "LATEST").exists():
        get_run_logger().info("chosen: %s", mixture_task(ratings or str(ws.db), res, ws, instructions))
        res = ws.resources(corpus=corpus, vectors=vectors, conceptnet=conceptnet, seed=seed)
        if not res.mixture.plain:  # the report shows what the mixture changed (added here: may be skipped)
            methods, optional = [*methods, f"{COMPLETION_METHOD}@plain"], [*optional, f"{COMPLETION_METHOD}@plain"]
    report = Path(out or ws.report)
    results = evaluate_task(ratings or str(ws.db), str(report), methods, settings, res, per_verb, seed, ws, optional)
    if requests:
        done = [m for m in methods if m in results["table1"]]
        results = {**results, "learned_verbs": calibrate_learned_task(requests, done, res, ws)}
    create_table_artifact(
        key="table-i",
        description="Table I overall accuracy (lambda=1, k=6)",
        table=[
            {"method": m, "overall": round(acc.get("all", float("nan")), 3)} for m, acc in results["table1"].items()
        ],
    )
    create_markdown_artifact(
        key="evaluation-report",
        markdown=(report / "report.md").read_text(encoding="utf-8"),
        description=str(report / "report.html"),
    )
    create_link_artifact(key="evaluation-report-html", link=(report / "report.html").resolve().as_uri())
    return results
