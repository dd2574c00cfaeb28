"""The household's tools (a knife, a lid, foil, a ladle) and the motions that use them: cut (the food sawn
through and swapped for its pieces), cover (a lid set on the rim) and serve (a ladle filled in one container
and tipped out into another), each checked in the world after it."""

from __future__ import annotations

import json
import math

import numpy as np
import pybullet as p
import pytest

from lmcr.frame import Frame
from lmcr.robot import tasks
from lmcr.robot.household import HouseholdError, read_tools, tools
from lmcr.robot.scene import TABLE_TOP, height, make_scene, outline, scene_from_json, solid_shape
from lmcr.robot.world import build_world


def test_the_shipped_tools_are_a_knife_with_a_blade_a_lid_and_foil():
    found = tools()
    knife, lid = found["knife"], found["lid"]
    assert knife.blade is not None and knife.blade_width == pytest.approx(0.004) and knife.blade_axis == (1, 0, 0)
    assert lid.blade is None and lid.grip[2] == pytest.approx(lid.size[2])  # held by the top of its knob
    # the scene's shapes follow the data; a knife lies as the kitchen's did (20 cm by 2.5 cm)
    assert outline("knife") == pytest.approx((0.1, 0.0125, False)) and height("lid") == pytest.approx(0.033)
    assert tasks.Variant().half_across("knife") == pytest.approx(0.0125)  # across its handle, not its length
    scene = scene_from_json({"objects": [{"label": "foil"}, {"label": "pot"}], "holding": "knife"}, "scene")
    assert scene.holding.kind == "tool" and scene.objects[0].kind == "tool"


KNIFE = {
    "parts": [{"half": [0.1, 0.01, 0.02], "at": [0, 0, 0.02]}],
    "grip": [-0.05, 0, 0.04],
    "grip_width": 0.02,
    "mass": 0.1,
}


@pytest.mark.parametrize(
    "entry, reason",
    [
        ({**KNIFE, "grip": [0.5, 0, 0.04]}, "'grip' .* lies outside the tool"),
        ({**KNIFE, "blade": [0.05, 0.0]}, "blade: must be 3"),
        ({**KNIFE, "grip_width": 0.5}, "'grip_width' must be"),
        ({**KNIFE, "grip_width": 0}, "'grip_width' must be"),
        ({k: v for k, v in KNIFE.items() if k != "grip"}, "grip: must be 3"),
        ({**KNIFE, "parts": []}, "needs an 'open_box' or"),
        ([1, 2], "is not a JSON object"),
    ],
)
def test_a_bad_tool_is_one_line_naming_the_file_and_label(tmp_path, entry, reason):
    path = tmp_path / "household.json"
    path.write_text(json.dumps({"receptacles": {}, "tools": {"knife": entry}}))
    with pytest.raises(HouseholdError, match=reason) as err:
        read_tools(path)
    assert str(err.value).startswith(f"{path}: 'knife'") and "\n" not in str(err.value)


def test_a_blade_must_lie_in_a_part_and_a_label_cannot_be_receptacle_and_tool(tmp_path):
    path = tmp_path / "household.json"
    two = {
        "parts": [
            {"half": [0.05, 0.01, 0.01], "at": [-0.05, 0, 0.01]},
            {"half": [0.05, 0.01, 0.02], "at": [0.05, 0, 0.02]},
        ]
    }
    path.write_text(json.dumps({"receptacles": {}, "tools": {"knife": {**KNIFE, **two, "blade": [-0.05, 0, 0.03]}}}))
    with pytest.raises(HouseholdError, match="'blade' .* lies in none of the parts"):
        read_tools(path)
    shelf = {"parts": KNIFE["parts"], "mass": 0, "surface": "top", "motion": "place"}
    path.write_text(json.dumps({"receptacles": {"knife": shelf}, "tools": {"knife": KNIFE}}))
    with pytest.raises(HouseholdError, match="both a receptacle and a tool"):
        read_tools(path)


@pytest.mark.parametrize(
    "frame, motion, expected",
    [
        (Frame.of("slice", {"Theme": "bread", "Instrument": "knife"}), "cut", "cut"),
        (Frame.of("chop", {"Theme": "banana", "Instrument": "knife"}), "cut", "cut"),
        (Frame.of("cut", {"Theme": "bread", "Instrument": "spoon"}), "cut", None),  # no blade
        (Frame.of("cut", {"Theme": "pizza", "Instrument": "knife"}), "cut", None),  # wider than the blade saws
        (Frame.of("cut", {"Theme": "cup", "Instrument": "knife"}), "cut", None),  # not food
        (Frame.of("cover", {"Theme": "pot", "Instrument": "lid"}), "cover", "cover"),
        (Frame.of("cover", {"Theme": "bowl", "Instrument": "foil"}), "cover", "cover"),
        (Frame.of("cover", {"Theme": "bowl", "Instrument": "plate"}), "cover", "cover"),  # a plate on a bowl
        (Frame.of("cover", {"Theme": "pot", "Instrument": "knife"}), "cover", None),  # does not span it
        (Frame.of("cover", {"Theme": "bread", "Instrument": "foil"}), "cover", None),  # no opening
        (Frame.of("cut", {"Theme": "bread", "Destination": "bowl"}), "cut", None),  # into: not a cut
        (Frame.of("ladle", {"Theme": "soup", "Destination": "bowl"}), "serve", "serve"),  # the ladle found
        (Frame.of("scoop", {"Theme": "pot", "Destination": "cup", "Instrument": "ladle"}), "serve", "serve"),
        (Frame.of("scoop", {"Theme": "soup", "Destination": "bowl", "Instrument": "knife"}), "serve", None),
        (Frame.of("scoop", {"Theme": "bread", "Destination": "bowl"}), "serve", None),  # nothing to scoop in
        (Frame.of("scoop", {"Theme": "soup", "Destination": "trash can"}), "serve", "dispose"),  # a receptacle's
        (Frame.of("scoop", {"Theme": "soup", "Instrument": "ladle"}), "serve", None),  # into nothing
    ],
)
def test_a_tool_verb_gets_its_motion_only_when_the_tool_can_do_it(frame, motion, expected):
    task = tasks.task_for(frame, motion)
    assert (task.motion if task else None) == expected


def _run(tmp_path, layout: list, frame: Frame, motion: str) -> dict:
    from lmcr.robot.act import run_plan
    from lmcr.robot.plan import Plan, Planner

    scene = make_scene(layout)
    planner = Planner(build_world(scene, tmp_path), scene, scene.table)
    before = _bodies()
    task = tasks.task_for(frame, motion)
    task = task.with_source({r: scene.find(label) for r, label in frame.role_map.items()})
    held, target = (scene.find(frame.role_map[r]) for r in (task.held_role, task.target_role))
    plan = planner.plan(task, held, target, holding=False)
    assert isinstance(plan, Plan), plan
    others = [o for o in scene.objects if o not in (held, target)]
    out = run_plan(plan, held, target, others, planner)
    return {**out, "held": held, "target": target, "new_bodies": _bodies() - before, "gone": before - _bodies()}


def _bodies() -> set[int]:
    return {p.getBodyUniqueId(k) for k in range(p.getNumBodies())}


@pytest.mark.parametrize("food, xy", [("bread", [0.1, -0.2]), ("banana", [0.05, -0.1]), ("apple", [0.1, 0.05])])
def test_food_is_sawn_through_and_lies_in_two_pieces_either_side_of_the_blade(sim, tmp_path, food, xy):
    layout = [("knife", [-0.1, 0.25]), (food, xy), ("cup", [0.2, 0.3])]
    out = _run(tmp_path, layout, Frame.of("cut", {"Theme": food, "Instrument": "knife"}), "cut")
    checks = out["checks"]
    assert out["success"] and checks["in_pieces"] and checks["pieces_in_place"] and checks["lifted_out"], out
    assert checks["knocked"] == []
    # the food's body is gone, swapped for two pieces that lie on the table where it was
    pieces = out["new_bodies"]
    assert len(out["gone"]) == 1 and len(pieces) == 2 and out["target"].body in pieces
    assert all(TABLE_TOP < p.getBasePositionAndOrientation(b)[0][2] < TABLE_TOP + height(food) for b in pieces)


def test_a_blade_that_stops_above_the_board_has_not_cut_the_food(sim, tmp_path, monkeypatch):
    monkeypatch.setattr(tasks, "CUT_CLEAR", 0.02)  # the edge ends 2 cm over the board: the bread holds together
    layout = [("knife", [-0.1, 0.25]), ("bread", [0.1, -0.2])]
    out = _run(tmp_path, layout, Frame.of("cut", {"Theme": "bread", "Instrument": "knife"}), "cut")
    assert not out["checks"]["in_pieces"] and not out["success"]
    assert out["new_bodies"] == set() and out["gone"] == set()  # the bread's own body is still there, whole


@pytest.mark.parametrize("shape_of", ["apple", "bread", "cake"])
def test_cut_pieces_share_out_the_food_either_side_of_the_plane(sim, shape_of):
    from lmcr.robot.pieces import cut_apart
    from lmcr.robot.scene import SceneObject

    p.resetSimulation()
    food = SceneObject(shape_of, (0.0, 0.0))
    shape = solid_shape(shape_of)
    kind = {"sphere": p.GEOM_SPHERE, "cyl": p.GEOM_CYLINDER, "box": p.GEOM_BOX}[shape[0]]
    size = {"sphere": {"radius": shape[1]}, "cyl": {"radius": shape[1], "height": shape[-1]}}
    size = size.get(shape[0], {"halfExtents": [s / 2 for s in shape[1:]]})
    food.body = p.createMultiBody(0.15, p.createCollisionShape(kind, **size), -1, [0.5, 0.0, 1.0])
    normal = np.array([math.cos(0.3), math.sin(0.3), 0.0])
    pieces = cut_apart(food, np.array([0.5, 0.0, 1.0]), normal, 0.004)
    assert len(pieces) == 2 and food.body == pieces[0]
    sides = [np.dot(np.subtract(p.getBasePositionAndOrientation(b)[0], [0.5, 0.0, 1.0]), normal) for b in pieces]
    assert sides[0] > 0.005 and sides[1] < -0.005  # one each side, the cut through the middle: about halves
    masses = [p.getDynamicsInfo(b, -1)[0] for b in pieces]
    # the food's mass, less the blade's slit (a few per cent), shared out about evenly
    assert 0.88 * 0.15 <= sum(masses) < 0.15 and masses[0] == pytest.approx(masses[1], rel=0.05)


def test_a_lid_is_set_on_the_pot_over_its_whole_opening(sim, tmp_path):
    layout = [("lid", [-0.1, 0.25]), ("pot", [0.1, -0.2]), ("cup", [0.2, 0.05])]
    out = _run(tmp_path, layout, Frame.of("cover", {"Theme": "pot", "Instrument": "lid"}), "cover")
    checks = out["checks"]
    assert out["success"] and checks["over_opening"] and checks["on_rim"] and checks["level"], out
    lid, pot = out["held"], out["target"]
    assert p.getAABB(lid.body)[0][2] == pytest.approx(p.getAABB(pot.body)[1][2], abs=0.005)  # resting on the rim


def test_a_lid_beside_the_pot_or_tipped_does_not_cover_it(sim, tmp_path):
    scene = make_scene([("lid", [-0.1, 0.25]), ("pot", [0.1, -0.2])])
    build_world(scene, tmp_path)
    lid, pot = scene.find("lid"), scene.find("pot")
    beside = tasks.check_covered(lid, pot, tasks.Outcome())
    assert beside == {"over_opening": False, "on_rim": False, "level": True, "ok": False}
    rim = p.getAABB(pot.body)[1][2]
    pot_at = p.getBasePositionAndOrientation(pot.body)[0]
    tipped = p.getQuaternionFromEuler((0.3, 0, 0))
    p.resetBasePositionAndOrientation(lid.body, [pot_at[0], pot_at[1], rim], tipped)
    assert not tasks.check_covered(lid, pot, tasks.Outcome())["level"]


SERVE = Frame.of("ladle", {"Theme": "soup", "Destination": "bowl", "Instrument": "ladle"})


def test_a_ladle_is_filled_in_the_soup_and_tipped_out_into_the_bowl(sim, tmp_path):
    layout = [("ladle", [-0.1, 0.25]), ("soup", [0.1, -0.2]), ("bowl", [0.05, 0.05]), ("cup", [0.2, 0.3])]
    out = _run(tmp_path, layout, SERVE, "serve")
    checks = out["checks"]
    assert out["success"] and checks["filled"] and checks["served_share"] >= 0.9 and checks["knocked"] == [], out
    bowl = out["target"]
    grains = [b for b in out["new_bodies"] if p.getAABB(b)[1][0] - p.getAABB(b)[0][0] < 0.01]
    assert len(grains) == tasks.SCOOP_GRAINS  # what it served lies in the bowl, and nothing else was made
    lo, hi = p.getAABB(bowl.body)
    assert sum(lo[0] <= p.getBasePositionAndOrientation(g)[0][0] <= hi[0] for g in grains) >= 0.9 * len(grains)


def test_a_ladle_that_stays_above_the_soup_serves_nothing(sim, tmp_path, monkeypatch):
    monkeypatch.setattr(tasks, "SCOOP_DEPTH", -0.04)  # its floor 4 cm over the rim: nothing is taken
    layout = [("ladle", [-0.1, 0.25]), ("soup", [0.1, -0.2]), ("bowl", [0.05, 0.05])]
    out = _run(tmp_path, layout, SERVE, "serve")
    assert out["checks"]["filled"] is False and out["checks"]["served_share"] == 0.0 and not out["success"]
    assert out["new_bodies"] == set()


@pytest.mark.parametrize(
    "motion, roles, said",
    [
        ("cut", {"Theme": "bread", "Instrument": "knife"}, "cut the bread with the knife"),
        ("cover", {"Theme": "pot", "Instrument": "lid"}, "covered the pot with the lid"),
        ("serve", {"Theme": "soup", "Destination": "bowl"}, "served the soup into the bowl"),
        (
            "serve",
            {"Theme": "soup", "Destination": "bowl", "Instrument": "ladle"},
            "served the soup into the bowl with the ladle",
        ),
    ],
)
def test_the_robot_says_it_cut_covered_or_served(motion, roles, said):
    from lmcr.robot.reply import motion_done

    assert motion_done(motion, roles) == said


def test_a_ladle_is_tipped_over_the_targets_middle_first_then_nearer_the_robot_inside_it():
    """The spout's places over a bowl: TIP_HEIGHTS over its middle first, then the same heights moved
    towards the robot's base (the origin) but still inside the bowl's inner walls, for a bowl at the far
    edge of the arm's reach."""
    from lmcr.robot.scene import WALL, SceneObject

    top, half = np.array([0.75, 0.3, 0.82]), 0.08  # a bowl 16 cm across at the table's far left
    box = (top - [half, half, 0.07], top + [half, half, 0.0])
    g = tasks.Geometry(SceneObject("ladle", (0, 0)), SceneObject("bowl", (0, 0)), target_top=top, target_box=box)
    spouts = tasks._spouts(g)
    heights = len(tasks.TIP_HEIGHTS)
    assert [s[2] - top[2] for s in spouts] == pytest.approx(list(tasks.TIP_HEIGHTS) * 2)
    assert all(np.allclose(s[:2], top[:2]) for s in spouts[:heights])
    for near in spouts[heights:]:
        assert np.linalg.norm(near[:2]) < np.linalg.norm(top[:2]) - 0.03  # nearer the robot
        assert np.all(np.abs(near[:2] - top[:2]) < half - WALL)  # inside the inner walls
