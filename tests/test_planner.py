"""The joint-space planner (OMPL RRT-Connect) on synthetic obstacles: no pybullet, no robot."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("ompl")

from lmcr.robot.joint_paths import RESOLUTION, joint_path, segment_clash, smooth_path  # noqa: E402

LIMITS = np.array([[-2.0, 2.0]] * 7)


def _wall(q) -> str | None:
    """A slab across the first joint's middle, open only where the second joint is above 1."""
    return "the wall" if abs(q[0]) < 0.2 and q[1] < 1.0 else None


def test_a_blocked_straight_motion_goes_around_and_every_step_is_clear():
    q0, q1 = np.full(7, 0.0) + [-1, 0, 0, 0, 0, 0, 0], np.full(7, 0.0) + [1, 0, 0, 0, 0, 0, 0]
    assert segment_clash(_wall, q0, q1) == "the wall"
    for seed in range(1, 21):  # twenty different searches
        path = joint_path(_wall, q0, q1, LIMITS, seed=seed)
        assert path is not None and np.allclose(path[0], q0) and np.allclose(path[-1], q1)
        for a, b in zip(path, path[1:]):  # checked at the planner's resolution, as the executor follows it
            assert segment_clash(_wall, a, b) is None
        assert any(q[1] >= 1.0 for q in path)  # it went through the opening


def test_a_search_gives_the_same_path_whatever_was_planned_before():
    q0, q1 = np.zeros(7) + [-1, 0, 0, 0, 0, 0, 0], np.zeros(7) + [1, 0, 0, 0, 0, 0, 0]
    first = joint_path(_wall, q0, q1, LIMITS)
    joint_path(_wall, q0 + 0.1, q1 - 0.1, LIMITS, seed=5)  # another search in between
    again = joint_path(_wall, q0, q1, LIMITS)
    assert np.array_equal(np.array(first), np.array(again))
    assert not np.array_equal(np.array(first), np.array(joint_path(_wall, q0, q1, LIMITS, seed=2)))


def _length(path) -> float:
    return sum(float(np.linalg.norm(b - a)) for a, b in zip(path, path[1:]))


def test_a_path_found_unshortened_is_shortened_later_to_a_clear_path_no_longer_than_it():
    """A search left unshortened (`smooth=False`) returns the path as found, clear; `smooth_path` then
    shortens it, clear by the same check, the same way whatever was planned between."""
    q0, q1 = np.zeros(7) + [-1, 0, 0, 0, 0, 0, 0], np.zeros(7) + [1, 0, 0, 0, 0, 0, 0]
    for seed in range(1, 11):
        raw = joint_path(_wall, q0, q1, LIMITS, seed=seed, smooth=False)
        assert raw is not None and np.allclose(raw[0], q0) and np.allclose(raw[-1], q1)
        assert all(segment_clash(_wall, a, b) is None for a, b in zip(raw, raw[1:]))
        short = smooth_path(_wall, raw, LIMITS)
        assert np.allclose(short[0], q0) and np.allclose(short[-1], q1)
        assert all(segment_clash(_wall, a, b) is None for a, b in zip(short, short[1:]))
        assert _length(short) <= _length(raw) + 1e-9 and any(q[1] >= 1.0 for q in short)
        joint_path(_wall, q0 + 0.1, q1 - 0.1, LIMITS, seed=5)  # another search in between
        assert np.array_equal(np.array(short), np.array(smooth_path(_wall, raw, LIMITS)))
    straight = [q0 + [0, 2, 0, 0, 0, 0, 0], q1 + [0, 2, 0, 0, 0, 0, 0]]  # over the wall: nothing to shorten
    assert smooth_path(_wall, straight, LIMITS) is straight


def test_an_impossible_motion_stops_at_its_budget_of_checks():
    checks = []

    def closed(q):
        checks.append(1)
        return "the wall" if abs(q[0]) < 0.2 else None

    q0, q1 = np.full(7, -1.0), np.full(7, 1.0)
    assert joint_path(closed, q0, q1, LIMITS, budget=800) is None
    straight = int(np.ceil(2.0 / RESOLUTION))  # the straight segment is tried first
    assert len(checks) <= straight + 800 + 200  # the planner notices the budget between its iterations


def test_without_a_budget_only_the_straight_motion_is_taken():
    """What a motion that may touch its object gets: the straight segment when clear, else nothing
    (a detour planned with that object ignored could sweep through it)."""
    q0, q1 = np.zeros(7) + [-1, 0, 0, 0, 0, 0, 0], np.zeros(7) + [1, 0, 0, 0, 0, 0, 0]
    assert joint_path(_wall, q0, q1, LIMITS, budget=0) is None
    over = np.zeros(7) + [0, 1.5, 0, 0, 0, 0, 0]
    assert [list(q) for q in joint_path(_wall, q0 + over, q1 + over, LIMITS, budget=0)] == [
        list(q0 + over),
        list(q1 + over),
    ]


def test_a_motion_to_or_from_a_clashing_configuration_is_refused_at_once():
    """RRT-Connect waits for a valid goal without counting a check: a goal inside the wall (an open lid in
    the way of the arm's start) searched for ever."""
    checks = []

    def counted(q):
        checks.append(1)
        return _wall(q)

    outside, inside = np.zeros(7) + [-1, 0, 0, 0, 0, 0, 0], np.zeros(7)
    assert joint_path(counted, outside, inside, LIMITS) is None
    assert joint_path(counted, inside, outside, LIMITS) is None
    assert len(checks) < 200
