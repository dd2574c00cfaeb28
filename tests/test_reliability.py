"""Regression tests for what a hostile or careless user broke: output folders that held user files,
code run from data files, checkpoint checks bypassed, promotion before recording, non-ASCII ratings,
tracebacks, and silent wrong results. One test per case, model-free where possible."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import duckdb
import pytest
import torch
from typer.testing import CliRunner

from lmcr.checkout import REPO_ROOT
from lmcr.cli import app
from lmcr.files import OUTPUT_MARKER, OutputError, atomic_dir, atomic_path
from lmcr.ingest import IngestError, expand_inputs
from lmcr.ingest.run import ingest_sources
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting

runner = CliRunner()


def tiny_model() -> tuple[RecurrentLM, Vocab]:
    torch.manual_seed(0)
    vocab = Vocab.build([["pour", "water", "into", "the", "cup"]], min_freq=1)
    return RecurrentLM(LMConfig(len(vocab), embedding=8, layers=1)), vocab


def one_line_error(result) -> str:
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    return lines[0]


# 1. --out never deletes what LMCR did not write


def test_output_folder_with_user_files_is_refused_and_kept(tmp_path):
    out = tmp_path / "report"
    out.mkdir()
    (out / "thesis.tex").write_text("years of work")
    with pytest.raises(OutputError, match="not an LMCR output"):
        with atomic_dir(out) as tmp:
            (tmp / "report.md").write_text("x")
    assert (out / "thesis.tex").read_text() == "years of work"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # no temporary folder left


def test_lmcr_output_is_replaced_but_a_file_added_to_it_stops_the_replacement(tmp_path):
    out = tmp_path / "report"
    for text in ("first", "second"):
        with atomic_dir(out) as tmp:
            (tmp / "report.md").write_text(text)
    assert (out / "report.md").read_text() == "second"
    assert json.loads((out / OUTPUT_MARKER).read_text())["files"] == ["report.md"]
    (out / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="notes.txt"):
        with atomic_dir(out) as tmp:
            (tmp / "report.md").write_text("third")
    assert (out / "notes.txt").read_text() == "mine" and (out / "report.md").read_text() == "second"


def test_evaluate_and_annotate_tasks_refuse_a_user_folder_before_working(tmp_path, sample_dir):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "keep.txt").write_text("keep")
    env = {"LMCR_DATA_DIR": str(tmp_path / "data")}
    evaluated = runner.invoke(
        app,
        ["evaluate", "--ratings", str(sample_dir / "ratings" / "sample_ratings_mturk.csv"), "--out", str(out)],
        env=env,
    )
    assert "not an LMCR output" in one_line_error(evaluated)
    tasks = runner.invoke(app, ["annotate", "tasks", "--out", str(out)], env=env)
    assert "not an LMCR output" in one_line_error(tasks)
    assert (out / "keep.txt").read_text() == "keep" and sorted(p.name for p in out.iterdir()) == ["keep.txt"]


def test_a_file_output_that_is_a_folder_is_refused(tmp_path):
    with pytest.raises(OutputError, match="is a folder"):
        with atomic_path(tmp_path) as tmp:
            tmp.write_text("x")


def test_render_into_a_folder_is_refused_before_the_simulation(tmp_path, sample_dir):
    scene, env = str(sample_dir / "scenes" / "pour_me_some_water.json"), {"LMCR_DATA_DIR": str(tmp_path / "data")}
    result = runner.invoke(app, ["execute", "pour me some water", "--scene", scene, "--render", str(tmp_path)], env=env)
    assert "is a folder" in one_line_error(result)
    render = str(tmp_path / "out.txt")
    bad_suffix = runner.invoke(app, ["execute", "pour me some water", "--scene", scene, "--render", render], env=env)
    assert ".png or .gif" in one_line_error(bad_suffix)


# 3. the checkpoint check cannot be bypassed


@pytest.fixture
def published(tmp_path):
    model, vocab = tiny_model()
    root = tmp_path / "checkpoints"
    sentence = ckpt.publish(root, Setting("sentence"), model, vocab, {}, {})
    frame = ckpt.publish(root, Setting("frame"), model, vocab, {}, {})
    return root, sentence, frame


def test_a_file_dropped_from_the_manifest_is_refused(published):
    _, path, _ = published
    manifest = json.loads((path / "manifest.json").read_text())
    del manifest["files"]["model.pt"]
    (path / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ckpt.CheckpointError, match="not the version's files"):
        ckpt.load(path)
    manifest["files"] = {}
    (path / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(ckpt.CheckpointError, match="not the version's files"):
        ckpt.load(path)


def test_an_extra_file_in_a_checkpoint_is_refused(published):
    _, path, _ = published
    (path / "model.pt.orig").write_bytes(b"x")
    with pytest.raises(ckpt.CheckpointError, match="beyond or short of the manifest"):
        ckpt.load(path)


def test_latest_must_name_a_version_of_its_own_setting(published):
    root, _, frame = published
    (root / "sentence-all" / "LATEST").write_text(f"../frame-all/{frame.name}\n")
    with pytest.raises(ckpt.CheckpointError, match="not a version name"):
        ckpt.load(root / "sentence-all")
    (root / "sentence-all" / "LATEST").write_text("v20990101-000000-1\n")
    with pytest.raises(ckpt.CheckpointError, match="not in"):
        ckpt.load(root / "sentence-all")


def test_a_frame_model_copied_into_the_sentence_setting_is_refused(published):
    root, _, frame = published
    shutil.copytree(frame, root / "sentence-all" / "v20990101-000000-1")
    (root / "sentence-all" / "LATEST").write_text("v20990101-000000-1\n")
    with pytest.raises(ckpt.CheckpointError, match="is frame-all/"):
        ckpt.load(root / "sentence-all")


# 4. record, then promote; killed publishes are cleaned up


def test_a_failed_run_record_leaves_latest_where_it_was(tmp_path, monkeypatch):
    from lmcr.lm import run as lm_run
    from lmcr.lm.corpus import TrainingText
    from lmcr.lm.train import TrainConfig
    from lmcr.store import StoreBusyError, connect

    paths_db = tmp_path / "lmcr.duckdb"
    text = TrainingText(
        ["pour water into the cup".split()] * 4,
        ["pour water into the cup".split()],
        {"linearization": "sentence", "corpus": "all", "corpus_sha256": "x"},
    )
    monkeypatch.setattr(lm_run, "training_text", lambda con, setting, **kwargs: text)
    opened = []

    def open_store():
        opened.append(1)
        if len(opened) > 1:
            raise StoreBusyError(f"store busy: another lmcr process is writing {paths_db}")
        return connect(paths_db, REPO_ROOT / "sql")

    with pytest.raises(StoreBusyError):
        lm_run.train_setting(
            open_store,
            tmp_path / "ck",
            Setting("sentence"),
            LMConfig(0, 8, 1, 0.0),
            TrainConfig(max_epochs=1, max_minutes=None),
            min_freq=1,
        )
    assert not (tmp_path / "ck" / "sentence-all" / "LATEST").exists()


def test_publish_removes_versions_left_half_written_by_a_killed_process(tmp_path):
    model, vocab = tiny_model()
    setting = tmp_path / "sentence-all"
    setting.mkdir()
    dead = setting / ".v20260101-000000-1.999999999.tmp"  # no such pid
    legacy = setting / ".v20260101-000000-2.tmp"
    alive = setting / f".v20260101-000000-3.{os.getpid()}.tmp"  # a publish still under way
    for folder in (dead, legacy, alive):
        folder.mkdir()
    ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})
    assert not dead.exists() and not legacy.exists() and alive.exists()


KILL_SCRIPT = """
import sys, time
from pathlib import Path
import torch
from lmcr.lm.run import train_setting
from lmcr.lm import run as lm_run
from lmcr.lm.corpus import TrainingText
from lmcr.lm.model import LMConfig
from lmcr.lm.train import TrainConfig
from lmcr.setting import Setting
from lmcr.store import connect
root, db = Path(sys.argv[1]), Path(sys.argv[2])
text = TrainingText([["pour", "water"]] * 4, [["pour", "water"]], {"linearization": "sentence", "corpus": "all",
                    "corpus_sha256": "x"})
lm_run.training_text = lambda con, setting, **kwargs: text
print("ready", flush=True)
for _ in range(int(sys.argv[4])):
    train_setting(lambda: connect(db, Path(sys.argv[3])), root, Setting("sentence"), LMConfig(0, 8, 1, 0.0),
                  TrainConfig(max_epochs=1, max_minutes=None), min_freq=1)
"""


def test_killed_publish_and_promote_always_leave_a_loadable_recorded_latest(tmp_path):
    """A training process publishing versions in a loop is killed (SIGKILL) at random moments; after each
    kill LATEST (when there is one) loads and has its lm_runs row."""
    import random

    rng = random.Random(7)
    root, db = tmp_path / "ck", tmp_path / "lmcr.duckdb"
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}

    def start(loops: int) -> subprocess.Popen:
        proc = subprocess.Popen(
            [sys.executable, "-c", KILL_SCRIPT, str(root), str(db), str(REPO_ROOT / "sql"), str(loops)],
            stdout=subprocess.PIPE,
            env=env,
        )
        assert proc.stdout.readline().strip() == b"ready"
        return proc

    assert start(1).wait() == 0  # one version published and promoted
    latest = root / "sentence-all" / "LATEST"
    versions = set()
    for _ in range(5):
        before = latest.read_text()
        proc = start(1000)
        # the first publish of a process takes a second or more (warm-up; longer on a busy machine), later
        # ones ~0.1 s: kill at a random moment after this process has published one
        deadline = time.monotonic() + 120
        while latest.read_text() == before and time.monotonic() < deadline:
            time.sleep(0.02)
        time.sleep(rng.uniform(0.0, 1.5))
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        loaded = ckpt.load(root / "sentence-all")
        versions.add(loaded.path.name)
        con = duckdb.connect(str(db))
        rows = con.execute("select count(*) from lm_runs where checkpoint = ?", [str(loaded.path)]).fetchone()[0]
        con.close()
        assert rows == 1
    assert len(versions) > 1  # the kills came while versions were being published
    assert start(1).wait() == 0
    assert not list((root / "sentence-all").glob(".v*.tmp"))  # what the kills left half-written is gone


# 5. ratings are exactly the ASCII digits 1-5


def test_non_ascii_digits_are_quarantined_not_ratings(con, tmp_path):
    from lmcr.annotate.results import ingest_ratings

    header = (
        "HITId,AssignmentId,WorkerId,AssignmentStatus,WorkTimeInSeconds,Input.verb,Input.role1,Input.arg1,"
        "Input.role2,Input.arg2,Answer.rating"
    )
    rows = [
        f"H1,A{k},W{k},Submitted,²,pour,Theme,water,Destination,cup,{answer}"
        for k, answer in enumerate(["٣", "²", "4", "３"])
    ]
    path = tmp_path / "r.csv"
    path.write_text("\n".join([header, *rows]) + "\n", encoding="utf-8")
    counts = ingest_ratings(con, path)
    assert (counts["items_loaded"], counts["items_quarantined"]) == (1, 3)
    assert con.execute("select rating from ratings").fetchall() == [(4,)]
    assert con.execute("select work_seconds from assignments").fetchall() == [(None,)]


# 6. one line, never a traceback


def test_a_busy_store_is_one_line(tmp_path, sample_dir):
    db = tmp_path / "data" / "lmcr.duckdb"
    db.parent.mkdir()
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import duckdb, sys, time; c = duckdb.connect(sys.argv[1]); print('held', flush=True); time.sleep(60)",
            str(db),
        ],
        stdout=subprocess.PIPE,
    )
    try:
        assert holder.stdout.readline().strip() == b"held"
        result = runner.invoke(
            app, ["ingest", "--recipes", str(sample_dir / "nyc")], env={"LMCR_DATA_DIR": str(db.parent)}
        )
        assert (
            one_line_error(result)
            == f"error: store busy: another lmcr process is writing {db}; try again when it finishes"
        )
    finally:
        holder.kill()
        holder.wait()


def test_undecodable_jsonl_names_file_and_line(tmp_path):
    path = tmp_path / "in.jsonl"
    path.write_bytes(b'{"id": 1, "text": "fry the egg"}\n{"id": 2, "text": "caf\xe9"}\n')
    result = runner.invoke(app, ["srl", "--input", str(path), "--output", str(tmp_path / "o.jsonl")])
    assert f"{path}:2: not UTF-8 (byte 0xe9 at column 23)" in one_line_error(result)


def test_a_lone_surrogate_never_reaches_the_parser(tmp_path):
    path = tmp_path / "in.jsonl"
    path.write_text('{"id": 1, "text": "fry the \\udc80 egg"}\n', encoding="utf-8")
    result = runner.invoke(app, ["srl", "--input", str(path), "--output", str(tmp_path / "o.jsonl")])
    assert "unpaired surrogate" in one_line_error(result)


def test_a_corrupt_gzip_corpus_is_one_line(tmp_path):
    path = tmp_path / "r.jsonl.gz"
    path.write_bytes(b"\x1f\x8b\x08\x00" + b"\x00" * 6 + b"garbage")
    result = runner.invoke(app, ["ingest", "--recipes", str(path)], env={"LMCR_DATA_DIR": str(tmp_path / "data")})
    assert str(path) in one_line_error(result)


def test_a_folder_where_a_file_is_expected_is_one_line(tmp_path):
    result = runner.invoke(app, ["score", "--frames", str(tmp_path), "--out", str(tmp_path / "s.csv")])
    assert f"{tmp_path}: cannot read" in one_line_error(result)


def test_a_non_object_youcook2_database_is_one_line(tmp_path):
    path = tmp_path / "yc.json"
    path.write_text('{"database": [1, 2]}')
    result = runner.invoke(app, ["ingest", "--youcook2", str(path)], env={"LMCR_DATA_DIR": str(tmp_path / "data")})
    assert '"database" is a list' in one_line_error(result)


# 7. no silent wrong results


def test_an_ingested_file_is_not_moved_to_another_corpus(con, paths, sample_dir, tmp_path):
    path = tmp_path / "recipes.jsonl"
    shutil.copy(sample_dir / "recipes_json" / "recipes_sample.jsonl", path)
    ingest_sources(con, expand_inputs([path], "recipes"), paths.staging)
    before = con.execute("select corpus, count(*) from sentences group by 1").fetchall()
    with pytest.raises(IngestError, match="already loaded into corpus 'recipes'"):
        ingest_sources(con, expand_inputs([path], "youcook2", "recipe_json"), paths.staging)
    assert con.execute("select corpus, count(*) from sentences group by 1").fetchall() == before


def test_a_copy_of_a_loaded_file_is_skipped_and_a_new_encoding_reloads(con, paths, sample_dir, tmp_path):
    original = sample_dir / "nyc" / "mealmaster_sample_cp437.mmf"
    copy = tmp_path / "copy.mmf"
    shutil.copy(original, copy)
    loaded, _ = ingest_sources(con, expand_inputs([original], "recipes"), paths.staging)
    sentences = con.execute("select count(*) from sentences").fetchone()[0]
    loaded, skipped = ingest_sources(con, expand_inputs([copy], "recipes"), paths.staging)
    assert (loaded, len(skipped)) == ([], 1)
    assert con.execute("select count(*) from sentences").fetchone()[0] == sentences
    loaded, _ = ingest_sources(con, expand_inputs([original], "recipes", encoding="latin-1"), paths.staging)
    assert len(loaded) == 1
    assert con.execute(
        "select encoding from ingested_files where source_file = ?", [str(original.resolve())]
    ).fetchone() == ("latin-1",)


@pytest.mark.model
def test_unknown_objects_are_never_chosen_silently():
    """A detection outside the robot's vocabulary may be the best guess, but it is always asked about."""
    from lmcr.complete import CompletionConfig, complete
    from lmcr.srl.parser import load_parser

    parser = load_parser()

    def prefer_unknown(frames, context=""):
        return [10.0 if f.role_map["Destination"] == "flux capacitor" else 0.0 for f in frames]

    confident = CompletionConfig(set_threshold=0.5)
    out = complete(parser, prefer_unknown, "pour me some water", ["flux capacitor", "cup"], confident)
    assert out.frame.role_map["Destination"] == "flux capacitor" and out.unfamiliar_objects == ("flux capacitor",)
    assert out.candidates[0].probability > 0.99 and out.prediction_set == ("flux capacitor",)
    assert out.question == "Should I pour water into the flux capacitor?"  # confident: confirmed alone
    alone = complete(parser, prefer_unknown, "pour me some water", ["flux capacitor"], confident)
    assert alone.question == "Should I pour water into the flux capacitor?"
    known = complete(parser, prefer_unknown, "pour me some water", ["bowl", "cup"], confident)
    assert known.unfamiliar_objects == () and known.question == "Should I pour water into the bowl or the cup?"


@pytest.mark.model
def test_labels_that_name_nothing_are_ignored():
    """Emoji, digits, invisible characters or a paragraph are no object: never scored, never chosen."""
    from lmcr.complete import CompletionError, complete
    from lmcr.lexicon import is_object_name
    from lmcr.srl.parser import load_parser

    junk = ["😀😀", "\u200b", "123", "x" * 41, "pour the water into the cup and then wash it"]
    assert not any(is_object_name(j.strip()) for j in junk)
    junk.append("into the")  # words, but only function words: the LM's text would lose them
    assert not is_object_name("into the")
    assert all(map(is_object_name, ["salsa", "crème fraîche", "half-and-half", "cutting board"]))
    seen = []
    prefer_junk = lambda frames, context="": [seen.extend(f.role_map.values()) or 0.0 for f in frames]  # noqa: E731
    out = complete(load_parser(), prefer_junk, "pour it", [*junk, "water", "Cutting  Board"])
    assert sorted(out.ignored_objects) == sorted(j.strip() for j in junk if j.strip())
    assert set(out.frame.role_map.values()) == {"water", "cutting board"} and set(seen) == {"water", "cutting board"}
    with pytest.raises(CompletionError, match="no usable objects besides .*no object name"):
        complete(load_parser(), prefer_junk, "pour me some water", junk)


def complete_with_a_flat_scorer(path, tmp_path, monkeypatch):
    """`lmcr complete --input PATH` with a scorer that rates every frame alike (the parser is real)."""
    import lmcr.complete as completion

    flat = (lambda frames, context="": [0.0] * len(frames), completion.CompletionConfig())
    monkeypatch.setattr(completion, "completion_scorer", lambda *a: flat)
    return runner.invoke(
        app,
        ["complete", "--input", str(path), "--output", str(tmp_path / "o.jsonl")],
        env={"LMCR_DATA_DIR": str(tmp_path / "data")},
    )


def test_an_overlong_instruction_is_a_per_line_error_in_complete(tmp_path, monkeypatch):
    path = tmp_path / "in.jsonl"
    path.write_text(
        json.dumps({"id": "long", "instruction": "pour " + "🥛" * 3000, "objects": ["cup"]}) + "\n", encoding="utf-8"
    )
    result = complete_with_a_flat_scorer(path, tmp_path, monkeypatch)
    assert result.exit_code == 0, result.output
    line = json.loads((tmp_path / "o.jsonl").read_text())
    assert line["id"] == "long" and "the limit is 1,000" in line["error"]


def test_a_line_that_cannot_be_completed_gets_its_error_and_the_batch_goes_on(tmp_path, monkeypatch):
    """A well-formed line in the middle that cannot be parsed (no predicate) or completed (no objects)."""
    lines = [
        {"id": "a", "instruction": "pour me some water", "objects": ["cup", "bowl"]},
        {"id": "b", "instruction": "wash the dishes", "objects": ["cup"]},
        {"id": "c", "instruction": "fry the chicken", "objects": []},
        {"id": "d", "instruction": "heat the leftover pizza", "objects": ["pizza", "microwave"]},
    ]
    path = tmp_path / "in.jsonl"
    path.write_text("".join(json.dumps(line) + "\n" for line in lines), encoding="utf-8")
    result = complete_with_a_flat_scorer(path, tmp_path, monkeypatch)
    assert result.exit_code == 0, result.output
    out = [json.loads(line) for line in (tmp_path / "o.jsonl").read_text().splitlines()]
    assert [o["id"] for o in out] == ["a", "b", "c", "d"]
    assert "error" not in out[0] and out[0]["frame"]["roles"]["Theme"] == "water"
    assert out[1]["error"].startswith("no known predicate in 'wash the dishes'")
    assert "no usable objects" in out[2]["error"]
    assert out[3]["frame"]["roles"] == {"Theme": "pizza", "Instrument": "microwave"}


def test_ratings_that_are_neither_csv_nor_a_store_are_one_line_and_untouched(tmp_path):
    """A read that fails on a non-store file must not fall back to opening it read-write."""
    path = tmp_path / "ratings.txt"
    path.write_text("hello\n")
    result = runner.invoke(
        app,
        ["evaluate", "--ratings", str(path), "--out", str(tmp_path / "rep")],
        env={"LMCR_DATA_DIR": str(tmp_path / "data")},
    )
    assert str(path) in one_line_error(result)
    assert path.read_text() == "hello\n" and not (tmp_path / "rep").exists()


def test_every_lmcr_error_is_one_lmcr_error():
    """One base the command line knows, each error still the built-in kind its callers catch."""
    import lmcr.complete
    import lmcr.evaluate.paper
    import lmcr.files
    import lmcr.ingest.records
    import lmcr.jsonl
    import lmcr.lm.checkpoint
    import lmcr.robot.execute
    import lmcr.scorers.baselines.vectors
    import lmcr.srl.parser
    import lmcr.store
    import lmcr.versions
    from lmcr.errors import LMCRError

    modules = [
        lmcr.scorers.baselines.vectors,
        lmcr.complete,
        lmcr.evaluate.paper,
        lmcr.robot.execute,
        lmcr.files,
        lmcr.ingest.records,
        lmcr.jsonl,
        lmcr.lm.checkpoint,
        lmcr.srl.parser,
        lmcr.store,
        lmcr.versions,
    ]
    errors = {
        obj
        for m in modules
        for obj in vars(m).values()
        if isinstance(obj, type) and issubclass(obj, Exception) and obj.__module__ == m.__name__
    }
    assert len(errors) >= 12
    assert all(issubclass(e, LMCRError) and issubclass(e, (ValueError, RuntimeError)) for e in errors), errors
