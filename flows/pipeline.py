"""The end-to-end pipeline: ingest -> frames -> train -> annotate -> evaluate -> publish -> executor check.

Each stage is the flow of its own issue; the last one has the simulated Baxter execute an instruction
completed by the published checkpoint. Unchanged stages cost little on a re-run: ingestion skips
sources whose sha256 it has loaded, the frame build skips when its fingerprint (sentences, code,
lexicon) is unchanged, training keeps a checkpoint trained on the same corpus content and
configuration, rating files already loaded are skipped, and the evaluation is a Prefect-cached task
keyed on the checkpoints' manifests, the ratings and its own source (results persisted).

Run the main job on the embedded sample: `python -m flows.pipeline` (what `make demo` does).
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.cache_policies import TASK_SOURCE, CacheKeyFnPolicy
from pydantic import BaseModel, Field

from flows.annotate import annotate_flow
from flows.frames import frames_flow
from flows.ingest import ingest_flow
from flows.train import train_flow
from lmcr.config import REPO_ROOT, paths_from_env
from lmcr.evaluate.protocol import EvalConfig
from lmcr.evaluate.ratings import load_ratings
from lmcr.evaluate.run import run_evaluation
from lmcr.lm import checkpoint as ckpt
from lmcr.methods import COMPLETION_METHOD, EVALUATED, resources_from_env
from lmcr.srl.lexicon import load_lexicon
from lmcr.store import read_connection

SAMPLE = REPO_ROOT / "data" / "sample"


class PipelineParams(BaseModel):
    """Typed parameters (validated by the Prefect UI); defaults run the embedded sample."""

    youcook2: list[str] = Field(default_factory=lambda: [str(SAMPLE / "youcook2")])
    recipes: list[str] = Field(default_factory=lambda: [str(SAMPLE / p) for p in (
        "nyc", "recipes_json/recipes_sample.jsonl", "recipes_json/folder", "feeding_america")])
    ratings: list[str] = Field(default_factory=lambda: [str(SAMPLE / "ratings" / "sample_ratings_mturk.csv")])
    conceptnet: str | None = str(SAMPLE / "conceptnet" / "edges.txt")
    vectors: str | None = None
    settings: list[str] = Field(default_factory=lambda: ["sentence-all", "frame-all"])
    methods: list[str] = Field(default_factory=lambda: list(EVALUATED))
    shard_size: int = Field(20_000, gt=0)
    embedding: int = Field(256, gt=0)
    max_epochs: int = Field(8, gt=0)
    max_minutes: float | None = Field(55.0, gt=0)
    per_verb: int = Field(50, gt=0)
    seed: int = 0
    executor_instruction: str = "pour me some water"
    executor_scene: str = str(SAMPLE / "scenes" / "pour_me_some_water.json")
    data_dir: str | None = None


def evaluation_key(context, parameters: dict) -> str:
    """Cache key: the checkpoints' manifests, the rating files and the evaluation settings."""
    paths = paths_from_env(data_dir=parameters["data_dir"])
    manifests = sorted(str(p) for p in paths.checkpoints.glob("*/LATEST"))
    versions = [str(ckpt.resolve(Path(p).parent)) for p in manifests]
    with read_connection(paths.db) as con:
        ratings = con.execute("select sha256 from rating_files order by 1").fetchall()
        frames = con.execute("select fingerprint from frame_builds order by built_at").fetchall()  # frame_counts
    blob = json.dumps([versions, ratings, frames, {k: v for k, v in parameters.items() if k != "data_dir"}], default=str)
    return hashlib.sha256(blob.encode()).hexdigest()


@task(name="evaluate-cached", cache_policy=TASK_SOURCE + CacheKeyFnPolicy(cache_key_fn=evaluation_key), persist_result=True)
def evaluate_task(methods: list[str], settings: list[str], conceptnet: str | None, vectors: str | None,
                  per_verb: int, seed: int, data_dir: str | None) -> dict:
    paths = paths_from_env(data_dir=data_dir)
    res = resources_from_env(vectors=vectors, conceptnet=conceptnet, seed=seed, data_dir=data_dir)
    rated = load_ratings(paths.db, paths.sql_dir, set(load_lexicon().predicates))
    results = run_evaluation(rated, res, methods, settings, EvalConfig(per_verb=per_verb, seed=seed),
                             paths.data_dir / "report", paths.data_dir / "calibration", log=get_run_logger().info)
    return {"report": str(paths.data_dir / "report" / "report.html"), "table1": results.table1}


@task(name="executor-check")
def executor_check_task(instruction: str, scene: str, data_dir: str | None) -> dict:
    """The default completion (published sentence LM times the frame counts) completes an instruction and
    the simulated Baxter carries it out."""
    from lmcr.complete import completion_scorer
    from lmcr.executor.execute import execute
    from lmcr.executor.scene import load_scene
    from lmcr.srl.parser import load_parser

    paths = paths_from_env(data_dir=data_dir)
    scorer, config = completion_scorer(COMPLETION_METHOD, resources_from_env(data_dir=data_dir),
                                       paths.data_dir / "calibration")
    out = execute(instruction, load_scene(Path(scene)), load_parser(None, paths.srl_dir), scorer, config,
                  paths.data_dir / "robot")
    return {k: out[k] for k in ("frame", "chosen_object", "success", "checks")}


@flow(name="pipeline", log_prints=True)
def pipeline_flow(params: PipelineParams = PipelineParams()) -> dict:
    """Run every stage; returns where the report and the checkpoints are."""
    logger = get_run_logger()
    data_dir = params.data_dir
    ingest_flow(youcook2=params.youcook2, recipes=params.recipes, data_dir=data_dir)
    frames_flow(shard_size=params.shard_size, data_dir=data_dir)
    trained = train_flow(settings=params.settings, embedding=params.embedding, max_epochs=params.max_epochs,
                         max_minutes=params.max_minutes, skip_unchanged=True, data_dir=data_dir)
    annotate_flow(results=params.ratings, data_dir=data_dir)
    lm_settings = [f"{'sentence_lm' if s.startswith('sentence') else 'frame_lm'}/{s.split('-', 1)[1]}"
                   for s in params.settings]
    evaluation = evaluate_task(params.methods, lm_settings, params.conceptnet, params.vectors, params.per_verb,
                               params.seed, data_dir)
    check = executor_check_task(params.executor_instruction, params.executor_scene, data_dir)
    logger.info("executor check %r: %s", params.executor_instruction, "success" if check["success"] else "FAILED")
    checkpoints = {r["setting"]: r["checkpoint"] for r in trained}
    print(f"report: {evaluation['report']}")
    for setting, path in checkpoints.items():
        print(f"checkpoint {setting}: {path}")
    return {"report": evaluation["report"], "checkpoints": checkpoints, "table1": evaluation["table1"],
            "executor_check": check}


if __name__ == "__main__":
    pipeline_flow(PipelineParams(**json.loads(sys.argv[1])) if len(sys.argv) > 1 else PipelineParams())
