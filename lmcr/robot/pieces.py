"""Food cut in two. The simulation cannot cut a body: while a knife saws, its blade passes through the food
(`act` turns their collisions off), and once the strokes end the world is looked at: when the blade's edge
came down to the food's underside within its outline, the food's body is swapped for its two pieces, each
the part of its volume on one side of the blade's plane (the convex hull of points filling the food
SPACING apart), the blade's width apart, with the food's colour and their shares of its mass."""

from __future__ import annotations

import numpy as np
import pybullet as p
from scipy.spatial import ConvexHull

from lmcr.robot.scene import TOOLS, SceneObject, solid_shape
from lmcr.robot.tasks import CUT_THROUGH

SPACING = 0.0025  # metres between the points that fill the food (a piece's faces are this true)


def cut_through(knife: SceneObject, food: SceneObject) -> tuple[list[int], tuple]:
    """The food's pieces and the cut's plane (a point on it and its normal) when the knife's edge has gone
    through it, the food's body then swapped for them (`food.body` is the first piece); ([], ()) when it
    has not (the edge stayed above the underside, or beside the food)."""
    tool = TOOLS[knife.shape]
    pos, orn = p.getBasePositionAndOrientation(knife.body)
    edge = np.asarray(p.multiplyTransforms(pos, orn, tool.blade, [0, 0, 0, 1])[0])
    turn = np.asarray(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
    normal = turn @ np.cross(tool.blade_axis, (0.0, 0.0, 1.0))  # across the blade
    lo, hi = p.getAABB(food.body)
    over = lo[0] <= edge[0] <= hi[0] and lo[1] <= edge[1] <= hi[1]
    if not over or edge[2] > lo[2] + CUT_THROUGH:
        return [], ()
    pieces = cut_apart(food, edge, normal, tool.blade_width)
    for piece in pieces:  # the blade stands between them: it must not push them apart
        p.setCollisionFilterPair(knife.body, piece, -1, -1, 0)
    return pieces, (edge, normal)


def cut_apart(food: SceneObject, point: np.ndarray, normal: np.ndarray, gap: float) -> list[int]:
    """Swap the food's body for the parts of it either side of the plane through `point` with `normal`,
    `gap` apart; returns the pieces' bodies (`food.body` becomes the first)."""
    pos, orn = p.getBasePositionAndOrientation(food.body)
    colour = p.getVisualShapeData(food.body)[0][7]
    mass = p.getDynamicsInfo(food.body, -1)[0]
    filled = _filling(food.shape, np.asarray(pos), orn)
    side = (filled - point) @ (normal / np.linalg.norm(normal))
    pieces = []
    for part in (filled[side >= gap / 2], filled[side <= -gap / 2]):
        if len(part) >= 4:
            pieces.append(_piece(part, mass * len(part) / len(filled), colour))
    p.removeBody(food.body)
    food.body = pieces[0] if pieces else -1
    return pieces


def _filling(label: str, pos: np.ndarray, orn) -> np.ndarray:
    """Points filling the food's shape SPACING apart (its faces included), in the world."""
    shape = solid_shape(label)
    if shape[0] == "sphere":
        half = np.full(3, shape[1])
    elif shape[0] == "cyl":
        half = np.array([shape[1], shape[1], shape[2] / 2])
    else:
        half = np.asarray(shape[1:]) / 2
    axes = [np.linspace(-h, h, max(3, int(np.ceil(2 * h / SPACING)) + 1)) for h in half]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    if shape[0] == "sphere":
        grid = grid[np.linalg.norm(grid, axis=1) <= shape[1] + 1e-9]
    elif shape[0] == "cyl":
        grid = grid[np.hypot(grid[:, 0], grid[:, 1]) <= shape[1] + 1e-9]
    turn = np.asarray(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
    return grid @ turn.T + pos


def _piece(points: np.ndarray, mass: float, colour) -> int:
    """A body whose shape is the convex hull of `points` (world), resting where they are."""
    hull = ConvexHull(points)
    corners = points[hull.vertices]
    centre = corners.mean(axis=0)
    index = {v: k for k, v in enumerate(hull.vertices)}
    triangles = []
    for a, b, c in hull.simplices:  # each face wound outwards (the renderer draws front faces)
        x, y, z = points[a], points[b], points[c]
        outward = np.dot(np.cross(y - x, z - x), x - centre) >= 0
        triangles += [index[a], index[b], index[c]] if outward else [index[a], index[c], index[b]]
    local = (corners - centre).tolist()
    col = p.createCollisionShape(p.GEOM_MESH, vertices=local)
    vis = p.createVisualShape(p.GEOM_MESH, vertices=local, indices=triangles, rgbaColor=colour)
    body = p.createMultiBody(mass, col, vis, centre.tolist())
    p.changeDynamics(body, -1, rollingFriction=0.002, spinningFriction=0.002)
    return body
