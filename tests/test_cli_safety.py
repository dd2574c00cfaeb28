"""What a query, a usage mistake, an output path, a checkpoint, a requested method and the evaluation cache
may do (issue 48): a query reads the store and nothing else, every mistake is one line and exit 1, every
output path follows one rule, a pickled checkpoint is named and refused, a requested method that cannot be
built is an error, cached evaluations are JSON, and the defaults need only what the pipeline trains."""

from __future__ import annotations

import inspect
import json
import pickle
from pathlib import Path

import pytest
import torch
from typer.testing import CliRunner

from lmcr import cli
from lmcr.checkout import SQL_DIR
from lmcr.cli import app
from lmcr.files import OUTPUT_MARKER, OutputError, atomic_dir, atomic_path, file_sha256
from lmcr.lm import checkpoint as ckpt
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting
from lmcr.store import connect, query_params

runner = CliRunner()
ENV_INPUTS = ("LMCR_DB", "LMCR_VECTORS", "LMCR_CONCEPTNET", "LMCR_PAPER")


@pytest.fixture(autouse=True)
def no_inputs_from_env(monkeypatch):
    for name in ENV_INPUTS:
        monkeypatch.delenv(name, raising=False)


def one_line_error(result) -> str:
    """The contract: exit 1, one line on stderr starting 'error: ', no traceback, no temporary name."""
    assert result.exit_code == 1 and "Traceback" not in result.output, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.stderr
    assert ".tmp" not in lines[0] and ".old" not in lines[0], lines[0]
    return lines[0]


# 1. a query reads the store and nothing else


@pytest.fixture
def store(tmp_path) -> Path:
    db = tmp_path / "data" / "lmcr.duckdb"
    connect(db, SQL_DIR).close()
    return db


def test_every_named_query_runs_on_the_locked_down_connection(store):
    values = {"corpus": "all", "phrases": "cup|glass", "min_sentences": "1", "max_words": "3"}
    for path in sorted((SQL_DIR / "queries").glob("*.sql")):
        wanted = query_params(path.read_text(encoding="utf-8"))
        result = runner.invoke(
            app,
            [
                "query",
                path.stem,
                "--db",
                str(store),
                "--format",
                "json",
                *[a for p in wanted for a in ("--param", f"{p}={values[p]}")],
            ],
        )
        assert result.exit_code == 0, (path.stem, result.output)


@pytest.mark.parametrize(
    "make_statement",
    [
        lambda d: f"copy (select 1 as x) to '{d / 'victim.txt'}'",
        lambda d: f"copy (select 1 as x) to '{d / 'new.csv'}'",
        lambda d: f"export database '{d / 'exported'}'",
        lambda d: "select * from read_csv('/etc/passwd')",
        lambda d: f"select * from read_text('{d / 'victim.txt'}')",
        lambda d: f"select * from read_blob('{d / 'victim.txt'}')",
        lambda d: "select * from glob('~/*')",
        lambda d: f"select * from glob('{d}/*')",
        lambda d: f"attach '{d / 'data' / 'lmcr.duckdb'}' as again (read_only)",
        lambda d: f"attach '{d / 'other.duckdb'}' as other",
        lambda d: "install httpfs",
        lambda d: "load httpfs",
        lambda d: "set enable_external_access = true",
        lambda d: "set lock_configuration = false",
        lambda d: "set autoload_known_extensions = true",
        lambda d: f"select 1; copy (select 2 as x) to '{d / 'victim.txt'}'",
    ],
    ids=[
        "copy-over-a-file",
        "copy-to-a-new-file",
        "export-database",
        "read-csv",
        "read-text",
        "read-blob",
        "glob-home",
        "glob-folder",
        "attach-the-store",
        "attach-a-new-store",
        "install",
        "load",
        "set-external-access",
        "unlock",
        "set-autoload",
        "second-statement",
    ],
)
def test_a_query_cannot_touch_a_file_or_unlock_itself(store, tmp_path, make_statement):
    victim = tmp_path / "victim.txt"
    victim.write_text("the user's own\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    result = runner.invoke(app, ["sql", make_statement(tmp_path), "--db", str(store)])
    one_line_error(result)
    assert victim.read_text() == "the user's own\n" and sorted(p.name for p in tmp_path.iterdir()) == before
    assert "the user's own" not in result.stdout


def test_the_connection_itself_refuses_what_the_statement_check_stops_first(store, tmp_path):
    """Two layers: statements other than queries are refused by kind, and the connection's locked
    configuration refuses them as well, should a kind ever be let through."""
    import duckdb

    from lmcr.store import query_connection

    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    con = query_connection(store)
    try:
        for statement in [
            f"copy (select 1 as x) to '{victim}'",
            f"export database '{tmp_path / 'out'}'",
            f"attach '{tmp_path / 'other.duckdb'}' as other",
            "load httpfs",
            "install httpfs",
            "set enable_external_access = true",
            "set lock_configuration = false",
        ]:
            with pytest.raises(duckdb.Error, match="disabled|locked"):
                con.execute(statement)
    finally:
        con.close()
    assert victim.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["data", "victim.txt"]


# 2. usage mistakes: one line, exit 1, naming the option and the value


@pytest.mark.parametrize(
    "args, said",
    [
        (["ingest", "--format", "nosuch", "--recipes", "x"], ["--format", "nosuch"]),
        (["score", "--corpus", "../../x", "--frames", "a.csv", "--out", "b.csv"], ["--corpus", "../../x"]),
        (["ingest", "--workers", "0", "--recipes", "x"], ["--workers", "0"]),
        (["ingest", "--workers", "-3", "--recipes", "x"], ["--workers", "-3"]),
        (["annotate", "tasks", "--out", "o", "--per-hit", "many"], ["--per-hit", "many"]),
        (["score", "--frames", "a.csv"], ["--out"]),
        (["ingest", "--nosuch"], ["--nosuch"]),
        (["nosuch"], ["nosuch"]),
        (["--data-dir"], ["--data-dir"]),
    ],
)
def test_a_usage_error_is_one_line_naming_option_and_value(args, said):
    line = one_line_error(runner.invoke(app, args))
    assert all(word in line for word in said), line


def test_help_is_still_help():
    assert "Usage" in runner.invoke(app, []).output and "Usage" in runner.invoke(app, ["annotate"]).output
    assert runner.invoke(app, ["score", "--help"]).exit_code == 0


def numeric_options() -> list[tuple[list[str], str, object]]:
    """(command path, option, typer's OptionInfo) of every int or float option of every command."""
    commands = [([c.name or c.callback.__name__], c.callback) for c in app.registered_commands]
    commands += [
        ([g.name, c.name or c.callback.__name__], c.callback)
        for g in app.registered_groups
        for c in g.typer_instance.registered_commands
    ]
    found = []
    for path, callback in commands:
        for name, param in inspect.signature(callback).parameters.items():
            if str(param.annotation).split(" |")[0] in ("int", "float"):
                info = param.default
                found.append(
                    (
                        path,
                        next((d for d in info.param_decls if d.startswith("--")), "--" + name.replace("_", "-")),
                        info,
                    )
                )
    return found


def test_every_numeric_option_is_range_checked():
    options = numeric_options()
    assert len(options) >= 25
    for path, option, info in options:
        assert info.min is not None, (path, option)
        below = info.min - 1
        line = one_line_error(runner.invoke(app, [*path, option, str(below)]))
        assert option in line and str(below) in line, line
        if info.max is not None:
            assert option in one_line_error(runner.invoke(app, [*path, option, str(info.max + 1)]))


def test_an_io_error_while_ingesting_names_the_file(tmp_path):
    mem = Path("/proc/self/mem")  # reading it from offset 0 is an I/O error, with no file name from the read
    if not mem.exists():
        pytest.skip("no /proc/self/mem")
    env = {"LMCR_DATA_DIR": str(tmp_path / "data")}
    for extra in ([], ["--format", "recipe_json"]):  # failing while sniffing the format, and while hashing
        line = one_line_error(runner.invoke(app, ["ingest", "--recipes", str(mem), *extra], env=env))
        assert "/mem: cannot read: Input/output error" in line, line


# 3. output paths: one rule for files and folders


def unwritable_folder(tmp_path) -> Path:
    """A folder no file can be created in: read-only permissions, or (as root, who ignores them) /sys."""
    ro = tmp_path / "read-only"
    ro.mkdir(exist_ok=True)
    ro.chmod(0o555)
    for folder in (ro, Path("/sys")):
        try:
            (folder / "probe").touch()
        except OSError:
            return folder
        (folder / "probe").unlink()
    pytest.skip("no unwritable folder here")


def test_a_file_output_follows_the_rule(tmp_path):
    page = ["schema", "--out"]
    real = tmp_path / "real.md"
    real.write_text("old")
    link = tmp_path / "link.md"
    link.symlink_to(real)
    assert runner.invoke(app, [*page, str(link)]).exit_code == 0
    assert (
        link.is_symlink()
        and real.read_text().startswith("#")
        and sorted(p.name for p in tmp_path.iterdir()) == ["link.md", "real.md"]
    )
    dangling = tmp_path / "dangling.md"
    dangling.symlink_to(tmp_path / "made" / "target.md")
    assert runner.invoke(app, [*page, str(dangling)]).exit_code == 0
    assert dangling.is_symlink() and (tmp_path / "made" / "target.md").read_text().startswith("#")
    nested = tmp_path / "new" / "deeper" / "page.md"  # missing parent folders are created
    assert runner.invoke(app, [*page, str(nested)]).exit_code == 0 and nested.is_file()
    (tmp_path / "afile").write_text("x")
    for bad, reason in [
        (unwritable_folder(tmp_path) / "page.md", "cannot write there"),
        (unwritable_folder(tmp_path) / "sub" / "page.md", "cannot write there"),
        (tmp_path / "afile" / "page.md", "is a file, not a folder"),
        (tmp_path / "new", "is a folder"),
    ]:
        line = one_line_error(runner.invoke(app, [*page, str(bad)]))
        assert f"error: {bad}: " in line and reason in line, line
    loop = tmp_path / "loop.md"
    loop.symlink_to(loop)
    assert f"{loop}: " in one_line_error(runner.invoke(app, [*page, str(loop)]))


def test_the_folder_helper_follows_a_link_and_leaves_nothing_behind(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "LINK"
    link.symlink_to(real)
    for text in ("first", "second"):  # an empty folder, then LMCR's own output: both replaced
        with atomic_dir(link) as tmp:
            (tmp / "report.md").write_text(text)
        assert link.is_symlink() and (real / "report.md").read_text() == text
        assert sorted(p.name for p in tmp_path.iterdir()) == ["LINK", "real"]
    (real / "thesis.tex").write_text("mine")
    with pytest.raises(OutputError, match=f"^{link}: holds files LMCR did not write"):
        with atomic_dir(link) as tmp:
            (tmp / "report.md").write_text("third")
    assert (real / "thesis.tex").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["LINK", "real"]


def test_a_write_error_inside_the_block_names_the_users_path(tmp_path):
    out = tmp_path / "scores.csv"
    with pytest.raises(OutputError, match=f"^{out}: cannot write: No space left on device"):
        with atomic_path(out) as tmp:
            tmp.write_text("partial")
            raise OSError(28, "No space left on device")  # a full disk: a write's error has no file name
    assert sorted(p.name for p in tmp_path.iterdir()) == []


@pytest.fixture
def evaluate_out(tmp_path, sample_dir):
    """`lmcr evaluate` with the random baseline alone (nothing to train), writing to a given --out."""
    args = [
        "evaluate",
        "--ratings",
        str(sample_dir / "ratings" / "sample_ratings_mturk.csv"),
        "--methods",
        "random",
        "--settings",
        "random",
        "--out",
    ]
    return lambda out: runner.invoke(app, [*args, str(out)], env={"LMCR_DATA_DIR": str(tmp_path / "data")})


def test_evaluate_out_follows_the_rule(tmp_path, evaluate_out):
    real = tmp_path / "real"
    real.mkdir()
    link = tmp_path / "LINK"
    link.symlink_to(real)
    for _ in range(2):  # to a link to an empty folder, then to the link to its own report
        result = evaluate_out(link)
        assert result.exit_code == 0, result.output
        assert link.is_symlink() and (real / "report.html").is_file() and (real / OUTPUT_MARKER).is_file()
        assert sorted(p.name for p in tmp_path.iterdir() if p.name != "data") == ["LINK", "real"]
    nested = tmp_path / "new" / "deeper" / "report"
    assert evaluate_out(nested).exit_code == 0 and (nested / "report.md").is_file()
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "keep.txt").write_text("keep")
    (tmp_path / "LINK2").symlink_to(mine)
    (tmp_path / "afile").write_text("x")
    for bad, reason in [
        (mine, "not an LMCR output"),
        (tmp_path / "LINK2", "not an LMCR output"),
        (unwritable_folder(tmp_path) / "report", "cannot write there"),
        (tmp_path / "afile", "exists and is not a folder"),
        (tmp_path / "afile" / "report", "is a file, not a folder"),
    ]:
        line = one_line_error(evaluate_out(bad))
        assert f"error: {bad}: " in line and reason in line, line
    assert (mine / "keep.txt").read_text() == "keep" and sorted(p.name for p in mine.iterdir()) == ["keep.txt"]
    assert (tmp_path / "LINK2").is_symlink()


# 4. a checkpoint's model.pt is a weights-only state dict or refused, by name


class TouchOnLoad:
    """Unpickling this creates a file: proof that code ran."""

    def __init__(self, marker: Path):
        self.marker = marker

    def __reduce__(self):
        return Path.touch, (self.marker,)


@pytest.fixture
def published(tmp_path) -> Path:
    torch.manual_seed(0)
    vocab = Vocab.build([["pour", "water", "into", "the", "cup"]], min_freq=1)
    model = RecurrentLM(LMConfig(len(vocab), embedding=8, layers=1))
    return ckpt.publish(tmp_path / "checkpoints", Setting("sentence"), model, vocab, {}, {})


def replace_model(version: Path, content: bytes) -> Path:
    """Overwrite model.pt and re-hash the manifest over it, as someone who can write the folder can."""
    (version / "model.pt").write_bytes(content)
    manifest = json.loads((version / "manifest.json").read_text())
    manifest["files"]["model.pt"] = file_sha256(version / "model.pt")
    (version / "manifest.json").write_text(json.dumps(manifest))
    return version / "model.pt"


def test_a_pickle_in_model_pt_is_refused_by_name_and_never_run(published, tmp_path):
    marker = tmp_path / "code-ran"
    state = {k: v for k, v in torch.load(published / "model.pt", weights_only=True).items()}
    model_pt = replace_model(published, pickle.dumps({**state, "payload": TouchOnLoad(marker)}, protocol=2))
    with pytest.raises(ckpt.CheckpointError) as caught:
        ckpt.load(published)
    assert str(caught.value) == f"{model_pt}: not a weights-only state dict; refusing to load it"
    assert not marker.exists()
    frames = tmp_path / "frames.csv"
    frames.write_text("verb,role1,arg1,role2,arg2\npour,Theme,water,Destination,cup\n")
    command = ["score", "--frames", str(frames), "--out", str(tmp_path / "s.csv"), "--methods", "sentence_lm"]
    result = runner.invoke(
        app, [*command, "--checkpoint", str(tmp_path / "checkpoints")], env={"LMCR_DATA_DIR": str(tmp_path / "data")}
    )
    line = one_line_error(result)
    assert str(model_pt) in line and "refusing to load it" in line and "weights_only" not in line
    assert "internal error" not in line and not marker.exists() and not (tmp_path / "s.csv").exists()


@pytest.mark.parametrize(
    "cut, reason",
    [
        (lambda data: b"", "empty file"),
        (lambda data: data[: len(data) // 2], "not a torch weights file"),  # cut short
        (None, "not a state dict of named tensors"),  # loads weights-only, but holds no tensors
    ],
)
def test_an_unusable_model_pt_says_why(published, cut, reason):
    if cut is None:
        torch.save({"weight": 1.0}, published / "model.pt")
        cut = bytes
    model_pt = replace_model(published, cut((published / "model.pt").read_bytes()))
    with pytest.raises(ckpt.CheckpointError, match=f"^{model_pt}: {reason}"):
        ckpt.load(published)


# 5. a method asked for must build; only defaults are skipped, with a note


def evaluate_sample(tmp_path, sample_dir, out: str, *args: str):
    """`lmcr evaluate` on the sample's ratings into `out`, with a data folder of its own."""
    ratings = str(sample_dir / "ratings" / "sample_ratings_mturk.csv")
    command = ["evaluate", "--ratings", ratings, "--out", out, *args]
    return runner.invoke(app, command, env={"LMCR_DATA_DIR": str(tmp_path / "data")})


@pytest.mark.parametrize(
    "args, method",
    [
        (["--methods", "word2vec", "--vectors", "BAD"], "word2vec"),
        (["--methods", "conceptnet", "--conceptnet", "BAD"], "conceptnet"),
        (["--methods", "conceptnet_retrofit", "--conceptnet", "BAD", "--vectors", "BAD"], "conceptnet_retrofit"),
        (["--methods", "conceptnet"], "conceptnet"),  # no edge file at all
        (["--methods", "sentence_lm"], "sentence_lm"),  # no checkpoint
        (["--methods", "random", "--settings", "frame_lm/household"], "frame_lm/household"),
    ],
)
def test_a_requested_method_that_cannot_be_built_is_an_error(tmp_path, sample_dir, args, method):
    (tmp_path / "BAD").write_text("not vectors, not edges\n")
    result = evaluate_sample(tmp_path, sample_dir, str(tmp_path / "report"), *args)
    assert f"method {method}: cannot be built" in one_line_error(result)
    assert not (tmp_path / "report").exists()


def test_default_methods_that_cannot_be_built_are_skipped_with_a_note(tmp_path, sample_dir, monkeypatch):
    monkeypatch.chdir(tmp_path)  # `--vectors BAD` relative, as a user types it
    (tmp_path / "BAD").write_text("not vectors\n")
    result = evaluate_sample(tmp_path, sample_dir, "report", "--vectors", "BAD", "--settings", "random")
    assert result.exit_code == 0, result.output
    assert "word2vec not evaluated: BAD:1" in result.stderr and "conceptnet not evaluated" in result.stderr
    assert json.loads((tmp_path / "report" / "figures.json").read_text())["table1"].keys() == {"random"}


def test_requests_to_calibrate_on_are_read_before_the_evaluation(tmp_path, sample_dir):
    """A bad requests file is refused in one line naming file and line, before any report is written;
    --requests asks for a calibration, so --no-calibrate beside it is refused too."""
    bad = tmp_path / "requests.jsonl"
    bad.write_text('{"id": 1, "instruction": "put the milk away", "objects": ["milk"]}\n')
    result = evaluate_sample(
        tmp_path, sample_dir, str(tmp_path / "report"), "--methods", "random", "--requests", str(bad)
    )
    assert f"{bad}:1" in one_line_error(result) and not (tmp_path / "report").exists()
    args = ("--methods", "random", "--requests", str(bad), "--no-calibrate")
    result = evaluate_sample(tmp_path, sample_dir, str(tmp_path / "report"), *args)
    assert "--no-calibrate" in one_line_error(result) and not (tmp_path / "report").exists()


# 6. the evaluation's cached result is JSON


def test_the_evaluate_task_caches_json(prefect_api, tmp_path, sample_dir):
    """The evaluation's cache is a JSON file of the workspace, read with `json` alone: the second run
    (report now there) evaluates again, the third is that one read back; a planted file that is not
    the cache's shape is evaluated afresh and replaced, never executed."""
    from prefect import flow

    from flows.evaluate import evaluate_task
    from lmcr.workspace import Workspace

    ws = Workspace.from_env(data_dir=tmp_path / "data")
    ratings = str(sample_dir / "ratings" / "sample_ratings_mturk.csv")
    args = (ratings, str(tmp_path / "report"), ["random"], ["random"], ws.resources(), 5, 0, ws)

    @flow
    def evaluate_three_times() -> list:
        return [evaluate_task(*args) for _ in range(3)]

    results = evaluate_three_times()
    cached = sorted((ws.data_dir / "cache").glob("evaluate-*.json"))
    assert len(cached) == 2 and results[2] == results[1] and results[1]["table1"].keys() == {"random"}
    assert all(json.loads(p.read_text())["table1"].keys() == {"random"} for p in cached)
    touched = [p.stat().st_mtime_ns for p in cached]
    planted = b"\x80\x04cos\nsystem\n(S'touch " + str(tmp_path / "ran").encode() + b"'\ntR."
    for path in cached:
        path.write_bytes(planted)
    again = flow(lambda: evaluate_task(*args))()
    assert again == results[1] and not (tmp_path / "ran").exists()
    remade = [p for p in cached if p.read_bytes() != planted]  # the current key's file: evaluated, rewritten
    assert len(remade) == 1 and json.loads(remade[0].read_text())["table1"].keys() == {"random"}
    assert remade[0].stat().st_mtime_ns != touched[cached.index(remade[0])]


def test_a_library_change_evaluates_and_chooses_again(monkeypatch, tmp_path, sample_dir):
    """The cache keys of the evaluation and of the mixture's choice hold the library's code: after an
    upgrade or an edit of a scorer, the same inputs are no longer answered with what the old code found."""
    import flows.evaluate as flow_module
    from lmcr.workspace import Workspace

    ws = Workspace.from_env(data_dir=tmp_path / "data")
    ratings = sample_dir / "ratings" / "sample_ratings_mturk.csv"
    parameters = {"ratings": str(ratings), "out": str(tmp_path / "report"), "res": ws.resources()}
    before = flow_module.evaluation_key(parameters), flow_module.inputs_key(ws.resources(), ratings, [])
    assert before == (flow_module.evaluation_key(parameters), flow_module.inputs_key(ws.resources(), ratings, []))
    monkeypatch.setattr(flow_module, "library_fingerprint", lambda: "another version of the code")
    after = flow_module.evaluation_key(parameters), flow_module.inputs_key(ws.resources(), ratings, [])
    assert before[0] != after[0] and before[1] != after[1]


def test_the_library_fingerprint_follows_code_and_shipped_files_not_bytecode(tmp_path):
    """Every .py, .json and .sql file under the roots counts, by path and content; bytecode and other
    files do not."""
    from lmcr.checkout import library_fingerprint

    code, sql = tmp_path / "lmcr", tmp_path / "sql"
    (code / "scorers").mkdir(parents=True)
    sql.mkdir()
    (code / "scorers" / "counts.py").write_text("WEIGHT = 0.25\n")
    (code / "lexicon.json").write_text("{}")
    (sql / "001_init.sql").write_text("select 1;")
    first = library_fingerprint.__wrapped__((code, sql))
    (code / "scorers" / "__pycache__").mkdir()
    (code / "scorers" / "__pycache__" / "counts.cpython-311.pyc").write_bytes(b"\x00")
    (code / "notes.txt").write_text("not code")
    assert library_fingerprint.__wrapped__((code, sql)) == first
    for path, text in ((code / "scorers" / "counts.py", "WEIGHT = 0.5\n"), (code / "lexicon.json", '{"a": 1}')):
        old = path.read_text()
        path.write_text(text)
        assert library_fingerprint.__wrapped__((code, sql)) != first
        path.write_text(old)
    (sql / "001_init.sql").rename(sql / "002_init.sql")  # a renamed file is another library
    assert library_fingerprint.__wrapped__((code, sql)) != first
    assert library_fingerprint() == library_fingerprint()  # the shipped library's, once a process


# 7. the defaults need only the checkpoints the pipeline's defaults train


def option_default(command, name: str):
    return inspect.signature(command).parameters[name].default.default


def test_the_defaults_need_only_what_the_pipeline_trains(tmp_path):
    from flows.pipeline import PipelineParams
    from lmcr.evaluate.run import named_method
    from lmcr.scorers.lm_checkpoints import lm_settings
    from lmcr.scorers.mixture import GRID, Mixture
    from lmcr.scorers.registry import EVALUATED
    from lmcr.scorers.resources import MethodResources

    trained = {s for s in PipelineParams().settings}
    defaults = {
        "score": option_default(cli.models.score, "methods").split(","),
        "complete": [option_default(cli.models.complete, "method")],
        "execute": [option_default(cli.robot.execute, "method")],
        "evaluate": list(EVALUATED),
    }  # `lmcr evaluate` and the pipeline's evaluate flow
    # the pipeline may choose any weight of the household corpus (mixture.json), or none
    for mixture in [Mixture(), *(Mixture.of({"household": w}) for w in GRID)]:
        res = MethodResources(checkpoints=tmp_path, mixture=mixture)
        for command, methods in defaults.items():
            for name in methods:
                needed = {s.name for s in lm_settings(*named_method(name, res))}
                assert needed <= trained, (command, name, mixture.label, needed - trained)
    # and what they need under a mixture is the household expert of each linearisation
    mixed = MethodResources(checkpoints=tmp_path, mixture=Mixture.of({"household": 100}))
    assert {s.name for s in lm_settings("sentence_lm+frame_lm", mixed)} == {
        "sentence-all",
        "sentence-household",
        "frame-all",
        "frame-household",
    }
