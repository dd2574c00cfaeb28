"""The flows end to end against one local Prefect server (the pipeline's own, `flows.server`), with the
process-pool task runner."""

from __future__ import annotations

import json

import duckdb
import pytest

from flows.ingest import ingest_flow
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
    requests = tmp_path / "requests.jsonl"
    request = {
        "id": 1,
        "instruction": "put the milk away",
        "objects": ["milk", "bowl", "cup"],
        "missing": "Destination",
    }
    requests.write_text(json.dumps({**request, "expected_any": ["bowl"], "verb": "put away"}) + "\n")
    results = evaluate_flow(
        ratings=str(tmp_path / "ratings.csv"),
        out=str(tmp_path / "report"),
        methods=["sentence_lm", "frame_lm", "sentence_lm+frame_counts", "random"],
        settings=["sentence_lm/youcook2"],
        corpus="youcook2",
        per_verb=5,
        data_dir=str(tmp_path),
        requests=str(requests),
    )
    # each method the ratings calibrated is calibrated on the requests too, or says why not
    assert set(results["learned_verbs"]) == {"sentence_lm", "frame_lm", "sentence_lm+frame_counts"}
    assert all(done.startswith("learned verbs") for done in results["learned_verbs"].values())
    assert set(results["table1"]) == {
        "sentence_lm",
        "frame_lm",
        "sentence_lm+frame_counts",
        "random",
        "sentence_lm/youcook2",
    }
    assert (tmp_path / "report" / "report.html").exists() and (tmp_path / "report" / "fig4d.png").exists()
    # one file per method, named by its fingerprint too; none for the random baseline
    files = [p for p in (tmp_path / "calibration").glob("*.json") if not p.stem.endswith("-requests")]
    calibrated = sorted(p.name.rsplit("-", 1)[0] for p in files)
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
