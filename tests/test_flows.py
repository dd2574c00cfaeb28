"""The flows end to end against one local Prefect server (the pipeline's own, `flows.server`), with the
process-pool task runner."""

from __future__ import annotations

import json

import duckdb
import pytest

from flows.ingest import ingest_flow
from lmcr.scorers.registry import COMPLETION_METHOD
from tests.mturk import write_results


def test_ingest_flow_on_sample(prefect_api, sample_dir, tmp_path):
    kwargs = dict(
        youcook2=[str(sample_dir / "youcook2")],
        recipes=[str(sample_dir / "nyc"), str(sample_dir / "recipes_json" / "recipes_sample.jsonl")],
        data_dir=str(tmp_path),
    )
    summary = ingest_flow(**kwargs)
    by_corpus = {row["corpus"]: row for row in summary}
    assert by_corpus["youcook2"]["quarantined"] == 3
    assert by_corpus["recipes"]["records_in"] == 10 + 11
    again = ingest_flow(**kwargs)
    assert again == summary
    con = duckdb.connect(str(tmp_path / "lmcr.duckdb"), read_only=True)
    assert con.execute("select count(*) from ingested_files").fetchone()[0] == 4


def test_frames_flow_on_sample(prefect_api, sample_dir, tmp_path):
    from flows.frames import frames_flow

    ingest_flow(youcook2=[str(sample_dir / "youcook2")], recipes=[str(sample_dir / "nyc")], data_dir=str(tmp_path))
    result = frames_flow(shard_size=30, data_dir=str(tmp_path))
    assert not result["skipped"] and result["sentences"] > 60
    assert {row["predicate"] for row in result["counts"]} >= {"pour", "heat", "fry", "sprinkle"}
    assert frames_flow(shard_size=30, data_dir=str(tmp_path)) == {"skipped": True}


def test_frames_flow_on_a_local_dask_cluster(prefect_api, sample_dir, tmp_path):
    from flows.frames import run_frames

    ingest_flow(recipes=[str(sample_dir / "recipes_json" / "recipes_sample.jsonl")], data_dir=str(tmp_path))
    result = run_frames(workers=2, dask="local", shard_size=20, data_dir=str(tmp_path))
    assert not result["skipped"] and result["sentences"] > 20
    con = duckdb.connect(str(tmp_path / "lmcr.duckdb"), read_only=True)
    assert con.execute("select count(*) from frames where predicate = 'pour'").fetchone()[0] >= 5


def test_train_flow_publishes_requested_settings(prefect_api, sample_dir, tmp_path):
    from flows.frames import frames_flow
    from flows.train import train_flow

    ingest_flow(youcook2=[str(sample_dir / "youcook2")], data_dir=str(tmp_path))
    frames_flow(shard_size=100, data_dir=str(tmp_path))
    results = train_flow(
        settings=["frame-youcook2", "sentence-youcook2"], embedding=16, layers=1, max_epochs=2, data_dir=str(tmp_path)
    )
    assert [r["setting"] for r in results] == ["frame-youcook2", "sentence-youcook2"]
    assert all((tmp_path / "checkpoints" / r["setting"] / "LATEST").exists() for r in results)
    with pytest.raises(ValueError, match="corpus must be one of .*not 'nyc'"):
        train_flow(settings=["frame-nyc"], data_dir=str(tmp_path))
    evaluate_on_trained(tmp_path)


def evaluate_on_trained(tmp_path):
    """The evaluate flow on the checkpoints just trained and a small ratings file: report and calibration."""
    from flows.evaluate import evaluate_flow

    objects = ["cup", "glass", "mug", "bowl", "scissors", "knife", "towel", "sponge", "oven", "sink"]
    rows = [
        ["H", f"A{i}", "W", "Approved", "pour", "Theme", "water", "Destination", obj, "5" if i < 3 else "1"]
        for i, obj in enumerate(objects)
    ]
    write_results(tmp_path / "ratings.csv", rows)
    results = evaluate_flow(
        ratings=str(tmp_path / "ratings.csv"),
        out=str(tmp_path / "report"),
        methods=["sentence_lm", "frame_lm", "sentence_lm+frame_counts", "random"],
        settings=["sentence_lm/youcook2"],
        corpus="youcook2",
        per_verb=5,
        data_dir=str(tmp_path),
    )
    assert set(results["table1"]) == {
        "sentence_lm",
        "frame_lm",
        "sentence_lm+frame_counts",
        "random",
        "sentence_lm/youcook2",
    }
    assert (tmp_path / "report" / "report.html").exists() and (tmp_path / "report" / "fig4d.png").exists()
    # one file per method, named by its fingerprint too; none for the random baseline
    calibrated = sorted(p.name.rsplit("-", 1)[0] for p in (tmp_path / "calibration").glob("*.json"))
    assert calibrated == ["frame_lm-youcook2", "sentence_lm+frame_counts-youcook2", "sentence_lm-youcook2"]


def test_annotate_flow_ingests_and_aggregates(prefect_api, tmp_path):

    from flows.annotate import annotate_flow
    from lmcr.annotate.tasks import TaskConfig

    path = write_results(
        tmp_path / "results.csv",
        [
            ["H", f"A{i}{j}", worker, "Approved", "pour", "Theme", "water", "Destination", obj, rating]
            for i, worker in enumerate(["W1", "W2", "W3"])
            for j, (obj, rating) in enumerate([("cup", 5 - (i == 2)), ("scissors", 1 + (i == 1)), ("bowl", 3)])
        ],
    )
    out = annotate_flow(
        tasks_out=str(tmp_path / "tasks"),
        task_config=TaskConfig(n_frames=20),
        results=[str(path), str(path)],
        decisions_out=str(tmp_path / "decisions.csv"),
        data_dir=str(tmp_path / "data"),
    )
    assert out["tasks"]["frames"] == 20 and (tmp_path / "tasks" / "batch.csv").exists()
    assert out["ingested"][0]["items_loaded"] == 9 and out["ingested"][1]["skipped"]
    assert 0.8 < out["aggregate"]["alpha"]["all"] <= 1 and out["aggregate"]["workers"] == 3
    assert (tmp_path / "decisions.csv").exists()


def test_pipeline_end_to_end_and_unchanged_rerun(prefect_api, tmp_path):
    from flows.pipeline import PipelineParams, pipeline_flow

    params = PipelineParams(data_dir=str(tmp_path), embedding=16, max_epochs=2, per_verb=5)
    first = pipeline_flow(params)
    assert (tmp_path / "report" / "report.html").exists()
    assert set(first["checkpoints"]) == {"sentence-all", "frame-all", "sentence-household", "frame-household"}
    chosen = json.loads((tmp_path / "mixture.json").read_text())  # the household weight, chosen on both dev sets
    assert set(chosen["accuracy"]) == {"1", "3", "10", "30", "100"} and chosen["chosen_for"] == COMPLETION_METHOD
    assert set(chosen["accuracy"]["1"]) == {"table1", "instructions"} and chosen["instructions_sha256"]
    # with the context term's weight, chosen on the instructions at the same time
    assert set(chosen["accuracy"]["1"]["instructions"]) == {"0.5", "1", "2"} and chosen["context_weight"] in (0.5, 1, 2)
    assert first["table1"]["sentence_lm"]["all"] >= 0 and "conceptnet" in first["table1"]
    assert first["executor_check"]["frame"]["predicate"] == "pour" and "grasped" in first["executor_check"]["checks"]
    # The sample ratings cover the 11 verbs at lambda=1, k=6; the report says it is the sample and where it came from.
    assert set(first["table1"]["sentence_lm"]) == {
        "all",
        "blend",
        "brush",
        "dip",
        "dump",
        "fill",
        "fry",
        "heat",
        "pour",
        "rub",
        "season",
        "sprinkle",
    }
    report = (tmp_path / "report" / "report.md").read_text(encoding="utf-8")
    assert "**Sample data.**" in report and "## Provenance" in report and "sample_ratings_mturk.csv" in report
    assert f"weight of the context term in completion: {chosen['context_weight']:g}" in report
    assert "Checkpoint sentence-all: `v" in report and "paper " not in report.split("## Fig. 4A")[0]
    page = (tmp_path / "report" / "report.html").read_text(encoding="utf-8")
    assert '<div class="scroll"><table>' in page and "<blockquote>" in page and page.count("data:image/png") == 4
    second = pipeline_flow(params)
    assert second["checkpoints"] == first["checkpoints"]  # unchanged corpus and config: training skipped
    speech = tmp_path / "speech" / "en-us"  # the speech model: built once, kept on the unchanged re-run
    assert (speech / "LATEST").exists() and len([v for v in speech.iterdir() if v.name.startswith("v")]) == 1
    assert second["table1"] == first["table1"]
    # What a Prefect UI user sees of the run: Table I, the report and the executor check as artifacts.
    assert {"table-i", "evaluation-report", "evaluation-report-html", "executor-check"} <= artifact_keys()


def artifact_keys() -> set[str]:
    import asyncio

    from prefect.client.orchestration import get_client

    async def read() -> set[str]:
        async with get_client() as client:
            return {a.key for a in await client.read_artifacts()}

    return asyncio.run(read())
