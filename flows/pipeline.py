"""The end-to-end pipeline: ingest -> frames -> speech model -> train -> annotate -> evaluate -> publish ->
executor check.

Each stage is the flow of its own issue; the last one has the simulated Baxter execute an instruction
completed by the published checkpoint. Unchanged stages cost little on a re-run: ingestion skips
sources whose sha256 it has loaded, the frame build skips when its fingerprint (sentences, code,
lexicon) is unchanged, training keeps a checkpoint trained on the same corpus content and
configuration, rating files already loaded are skipped, and the evaluate flow's task is cached on the
checkpoint versions, the ratings, the frame builds and its own source (results persisted). The evaluate
flow publishes Table I and the report as artifacts, and the executor check is one too.

Run the main job on the embedded sample: `python -m flows.pipeline` (what `make demo` does).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from prefect import flow, get_run_logger, task
from prefect.artifacts import create_table_artifact
from pydantic import BaseModel, Field

from flows.annotate import annotate_flow
from flows.evaluate import evaluate_flow
from flows.frames import frames_flow
from flows.ingest import ingest_flow
from flows.server import ServerStartError, run_with_server
from flows.speech import speech_flow
from flows.train import train_flow
from lmcr.checkout import REPO_ROOT
from lmcr.evaluate.protocol import EvalConfig
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.lm.hyperparams import LMConfig, TrainConfig
from lmcr.scorers.registry import COMPLETION_METHOD, EVALUATED
from lmcr.workspace import Workspace

SAMPLE = REPO_ROOT / "data" / "sample"


class PipelineParams(BaseModel):
    """Typed parameters (validated by the Prefect UI); defaults run the embedded sample."""

    youcook2: list[str] = Field(default_factory=lambda: [str(SAMPLE / "youcook2")])
    recipes: list[str] = Field(
        default_factory=lambda: [
            str(SAMPLE / p)
            for p in ("nyc", "recipes_json/recipes_sample.jsonl", "recipes_json/folder", "feeding_america")
        ]
    )
    household: list[str] = Field(default_factory=lambda: [str(SAMPLE / "household")])
    ratings: list[str] = Field(default_factory=lambda: [str(SAMPLE / "ratings" / "sample_ratings_mturk.csv")])
    # instructions in scenes the household weight is chosen on besides the ratings (the repo's own set)
    instructions: str | None = str(REPO_ROOT / "data" / "eval" / "instructions_own.jsonl")
    conceptnet: str | None = str(SAMPLE / "conceptnet" / "edges.txt")
    vectors: str | None = None
    paper: str | None = None  # the paper's LaTeX source: its Table I beside ours in the report
    # the household LMs: the experts a chosen corpus mixture interpolates with each all-corpora LM
    # (lmcr/scorers/mixture.py); the default methods (frame_lm among them) load them once a mixture is chosen
    settings: list[str] = Field(
        default_factory=lambda: ["sentence-all", "frame-all", "sentence-household", "frame-household"]
    )
    methods: list[str] = Field(default_factory=lambda: list(EVALUATED))
    shard_size: int = Field(FrameCorpusConfig.shard_size, gt=0)
    embedding: int = Field(LMConfig.embedding, gt=0)
    max_epochs: int = Field(TrainConfig.max_epochs, gt=0)
    max_minutes: float | None = Field(TrainConfig.max_minutes, gt=0)
    per_verb: int = Field(EvalConfig.per_verb, gt=0)
    seed: int = 0
    executor_instruction: str = "pour me some water"
    executor_scene: str = str(SAMPLE / "scenes" / "pour_me_some_water.json")
    data_dir: str | None = None


@task(name="executor-check")
def executor_check_task(instruction: str, scene: str, data_dir: str | None) -> dict:
    """The default completion (published sentence LM times the frame counts) completes an instruction and
    the simulated Baxter carries it out."""
    from lmcr.robot.execute import execute
    from lmcr.robot.scene import load_scene

    ws = Workspace.from_env(data_dir=data_dir)
    scorer, config = ws.completion_scorer(COMPLETION_METHOD)
    out = execute(instruction, load_scene(Path(scene)), ws.parser(), scorer, config, ws.robot)
    return {k: out[k] for k in ("frame", "chosen_object", "success", "checks")}


@flow(name="pipeline", log_prints=True)
def pipeline_flow(params: PipelineParams = PipelineParams()) -> dict:
    """Run every stage; returns where the report and the checkpoints are."""
    logger = get_run_logger()
    data_dir = params.data_dir
    ingest_flow(youcook2=params.youcook2, recipes=params.recipes, household=params.household, data_dir=data_dir)
    frames_flow(shard_size=params.shard_size, data_dir=data_dir)
    speech_flow(data_dir=data_dir)
    trained = train_flow(
        settings=params.settings,
        embedding=params.embedding,
        max_epochs=params.max_epochs,
        max_minutes=params.max_minutes,
        skip_unchanged=True,
        data_dir=data_dir,
    )
    annotate_flow(results=params.ratings, data_dir=data_dir)
    evaluation = evaluate_flow(
        methods=params.methods,
        settings=params.settings,
        conceptnet=params.conceptnet,
        vectors=params.vectors,
        per_verb=params.per_verb,
        seed=params.seed,
        data_dir=data_dir,
        paper=params.paper,
        instructions=params.instructions,
    )
    check = executor_check_task(params.executor_instruction, params.executor_scene, data_dir)
    logger.info("executor check %r: %s", params.executor_instruction, "success" if check["success"] else "FAILED")
    create_table_artifact(
        key="executor-check",
        description=f"simulated Baxter: {params.executor_instruction!r}",
        table=[
            {
                "instruction": params.executor_instruction,
                "chosen_object": check["chosen_object"],
                "frame": json.dumps(check["frame"]["roles"]),
                "success": check["success"],
            }
        ],
    )
    checkpoints = {r["setting"]: r["checkpoint"] for r in trained}
    report = str(Workspace.from_env(data_dir=data_dir).report / "report.html")
    print(f"report: {report}")
    for setting, path in checkpoints.items():
        print(f"checkpoint {setting}: {path}")
    return {"report": report, "checkpoints": checkpoints, "table1": evaluation["table1"], "executor_check": check}


def main(argv: list[str]) -> int:
    """`python -m flows.pipeline ['{"param": value, ...}']`: the pipeline against one local Prefect server
    (or `$PREFECT_API_URL`'s); a server that cannot start is one line on stderr and exit status 1."""
    params = PipelineParams(**json.loads(argv[0])) if argv else PipelineParams()
    try:
        run_with_server(pipeline_flow, params)
    except ServerStartError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted: the run's Prefect server is stopped", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
