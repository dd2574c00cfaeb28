"""The end-to-end benchmark's batch timing (bench/bench_end_to_end.py): each instruction's time read from
the batch's sidecar as its lines appear, a failed batch reported, and the batch ended with a benchmark
that fails."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from lmcr.checkout import REPO_ROOT

WRITER = """
import os, sys, time
out = sys.argv[1]
with open(out + ".partial", "w") as f:
    for k, pause in enumerate((0.6, 1.2, 0.6)):
        time.sleep(pause)
        f.write('{"id": "%d"}\\n' % k)
        f.flush()
os.replace(out + ".partial", out)
"""


@pytest.fixture
def bench(monkeypatch):
    monkeypatch.syspath_prepend(str(REPO_ROOT / "bench"))
    import bench_end_to_end

    return bench_end_to_end


def test_each_instruction_is_timed_as_its_line_appears(bench, tmp_path):
    out = tmp_path / "out.jsonl"
    wall, times = bench.timed_batch([sys.executable, "-c", WRITER, str(out)], out)
    assert len(times) == 3 and out.read_text().count("\n") == 3
    assert times[1] == pytest.approx(1.2, abs=0.35) and times[2] == pytest.approx(0.6, abs=0.35)
    assert times[0] >= 0.6 and wall >= sum(times) - 0.01


def test_an_instruction_is_timed_on_its_own_clock_too(bench):
    """The first interval between result lines holds the start of `lmcr execute`; each line's own
    `seconds` do not, and an error line has none. Each count of those over SLOW is its own."""
    outs = [
        {"seconds": {"perceive_and_complete": 0.5, "plan_and_execute": 25.3}},
        {"error": "no known predicate"},
        {"seconds": {"perceive_and_complete": 0.2, "plan_and_execute": 1.0}},
    ]
    text, figures = bench.timing([31.5, 0.4, 1.3], outs)
    assert figures["per instruction max s"] == 31.5 and figures["instructions over 30 s"] == 1
    assert figures["first line s (with the start of lmcr execute)"] == 31.5
    assert figures["own clock max s"] == 25.8 and figures["own clock over 30 s"] == 0
    assert figures["own clock median s"] == pytest.approx(13.5)
    assert "own clock: median 13.5 s, max 25.8 s, over 30 s: 0" in text


def test_a_failed_batch_is_an_error(bench, tmp_path):
    with pytest.raises(subprocess.CalledProcessError):
        bench.timed_batch([sys.executable, "-c", "raise SystemExit(3)"], tmp_path / "out.jsonl")


def test_a_benchmark_that_fails_while_polling_ends_its_batch(bench, tmp_path):
    out, pid_file = tmp_path / "out.jsonl", tmp_path / "pid"
    # the batch notes its pid, then makes its sidecar unreadable (a folder): the next poll fails
    batch = (
        f"import os, time; open({str(pid_file)!r}, 'w').write(str(os.getpid())); "
        f"os.mkdir({str(out) + '.partial'!r}); time.sleep(60)"
    )
    with pytest.raises(IsADirectoryError):
        bench.timed_batch([sys.executable, "-c", batch], out)
    with pytest.raises(ProcessLookupError):  # ended and reaped with the benchmark, not left running
        os.kill(int(pid_file.read_text()), 0)


@pytest.fixture
def external_robot(monkeypatch):
    monkeypatch.syspath_prepend(str(REPO_ROOT / "bench"))
    import bench_external_robot

    return bench_external_robot


TIDY = {
    "id": "t-1",
    "instruction": "put the sweater away",
    "objects": ["sweater", "basket", "drawer", "closet"],
    "missing": "Destination",
    "expected": {"predicate": "put", "roles": {"Theme": "sweater", "Destination": "basket"}},
    "expected_any": ["basket", "closet"],
    "verb": "put away",
}


def test_an_external_item_gets_a_scene_of_its_objects_built_like_known_ones(external_robot):
    """Objects with a body keep it; the Theme without one is built like the stand-in of a moved thing, the
    missing role's candidates like a place to put it; a tool's class decides an Instrument's stand-in."""
    scene = external_robot.scene_for(TIDY, "place", seed=3)
    assert scene["objects"] == [
        {"label": "sweater", "like": "sponge"},
        {"label": "basket"},
        {"label": "drawer"},
        {"label": "closet", "like": "basket"},
    ]
    wipe = {**TIDY, "objects": ["mirror", "cloth", "sponge"], "missing": "Instrument", "verb": "clean"}
    wipe["expected"] = {"predicate": "clean", "roles": {"Theme": "mirror", "Instrument": "cloth"}}
    assert external_robot.scene_for(wipe, "wipe", seed=3)["objects"][:2] == [
        {"label": "mirror", "like": "cutting board"},
        {"label": "cloth", "like": "sponge"},
    ]


def test_a_crowded_item_holds_its_theme_and_one_that_will_not_fit_is_an_error(external_robot):
    """A plate that leaves no room beside a fridge, a drawer, a shelf and a stove is in the hand."""
    from lmcr.jsonl import InputError

    plate = {"predicate": "put", "roles": {"Theme": "plate", "Destination": "shelf"}}
    crowded = {**TIDY, "objects": ["plate", "fridge", "drawer", "shelf", "stove"], "expected": plate}
    scene = external_robot.scene_for(crowded, "place", seed=1)
    assert scene["holding"] == {"label": "plate"} and "plate" not in [o["label"] for o in scene["objects"]]
    more = {**crowded, "objects": [*crowded["objects"], "oven", "sink", "trash can"]}
    with pytest.raises(InputError, match="cannot all fit|no free spot"):
        external_robot.scene_for(more, "place", 1)


@pytest.mark.parametrize(
    "frame, right",
    [
        ({"predicate": "put away", "roles": {"Theme": "sweater", "Destination": "closet"}}, True),
        ({"predicate": "put away", "roles": {"Theme": "sweater", "Destination": "drawer"}}, False),
        ({"predicate": "put", "roles": {"Theme": "sweater", "Destination": "basket"}}, False),  # the particle
        ({"predicate": "put away", "roles": {"Theme": "basket", "Destination": "closet"}}, False),
    ],
)
def test_an_external_item_is_completed_right_by_its_verb_its_theme_and_any_right_object(external_robot, frame, right):
    assert external_robot.completed_right(TIDY, {"frame": frame}) == right
    assert not external_robot.completed_right(TIDY, {"error": "no known predicate"})
