"""Detection from the simulated RGB-D camera: segmentation mask + depth -> labels and 3D positions.

In the paper Mask R-CNN gave object masks and classes; here the renderer's segmentation mask gives the
masks and the scene's objects by body their classes and ids (a perfect classifier and tracker), while
positions are measured, not looked up: each mask's pixels are back-projected with the depth buffer and the camera
matrices, and an object's position is the centroid of its visible surface points.

The robot looks from above the table first, then from above either end of it (`VIEWS`), as a person
leans to see behind something: from above alone a countertop cupboard 45 cm tall hides a knife lying
behind it ("put the plastic knife away" was refused for want of a knife on the external sets). An
object is placed by the first view that sees it, so what the overhead view sees is measured as before.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pybullet as p

from lmcr.robot.scene import TABLE_CENTRE, TABLE_SIZE, TABLE_TOP, SceneObject


@dataclass(frozen=True)
class Camera:
    width: int = 320
    height: int = 240
    fov: float = 60.0
    near: float = 0.1
    far: float = 3.0
    eye: tuple[float, float, float] = (TABLE_CENTRE[0] - 0.05, TABLE_CENTRE[1], TABLE_TOP + 1.25)
    target: tuple[float, float, float] = (TABLE_CENTRE[0], TABLE_CENTRE[1], TABLE_TOP)
    up: tuple[float, float, float] = (1.0, 0.0, 0.0)  # image top towards +x: away from the robot

    def matrices(self) -> tuple[list[float], list[float]]:
        view = p.computeViewMatrix(self.eye, self.target, self.up)
        proj = p.computeProjectionMatrixFOV(self.fov, self.width / self.height, self.near, self.far)
        return view, proj

    def world_to_clip(self) -> np.ndarray:
        """The 4x4 matrix from world coordinates to clip space (pybullet's matrices are column-major)."""
        view, proj = self.matrices()
        return np.asarray(proj).reshape(4, 4, order="F") @ np.asarray(view).reshape(4, 4, order="F")


@dataclass(frozen=True)
class Detection:
    label: str
    position: tuple[float, float, float]  # centroid of the visible surface, world frame
    pixels: int
    id: str = ""  # which of the objects with this label (lmcr.instances)


def capture(camera: Camera = Camera(), shaded: bool = False) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """RGB (H, W, 3) uint8, depth buffer (H, W) in [0, 1], segmentation (H, W) body ids (-1: none);
    `shaded`: lit from the side with shadows, for pictures a person looks at."""
    view, proj = camera.matrices()
    light = {"lightDirection": [1.0, 0.6, 2.0], "shadow": 1} if shaded else {}
    _, _, rgb, depth, seg = p.getCameraImage(
        camera.width, camera.height, view, proj, renderer=p.ER_TINY_RENDERER, **light
    )
    rgb = np.reshape(rgb, (camera.height, camera.width, 4))[:, :, :3].astype(np.uint8)
    return rgb, np.reshape(depth, (camera.height, camera.width)), np.reshape(seg, (camera.height, camera.width))


def back_project(depth: np.ndarray, camera: Camera) -> np.ndarray:
    """World coordinates (H, W, 3) of every pixel from the depth buffer."""
    inverse = np.linalg.inv(camera.world_to_clip())
    ys, xs = np.mgrid[0 : camera.height, 0 : camera.width]
    ndc = np.stack(
        [(2 * xs + 1) / camera.width - 1, 1 - (2 * ys + 1) / camera.height, 2 * depth - 1, np.ones_like(depth)], axis=-1
    )
    world = ndc.reshape(-1, 4) @ inverse.T
    return (world[:, :3] / world[:, 3:]).reshape(camera.height, camera.width, 3)


# where the robot looks from: above the table, then above its two ends, 1 m up (about 40 ms a view)
VIEWS = (
    Camera(),
    *(Camera(eye=(TABLE_CENTRE[0] - 0.05, side * TABLE_SIZE[1] / 2, TABLE_TOP + 1.0)) for side in (-1, 1)),
)


def detect(bodies: dict[int, SceneObject], views: tuple[Camera, ...] = VIEWS, min_pixels: int = 5) -> list[Detection]:
    """Every scene object a camera of `views` sees (`bodies`: the scene's objects by body), with its position
    measured in the first view that sees it."""
    found: dict[int, Detection] = {}
    for camera in views:
        _, depth, seg = capture(camera)
        points = back_project(depth, camera)
        for body, obj in bodies.items():
            if body in found:
                continue
            mask = seg == body
            n = int(mask.sum())
            if n >= min_pixels:
                found[body] = Detection(obj.label, tuple(float(v) for v in points[mask].mean(axis=0)), n, obj.id)
    return [found[body] for body in bodies if body in found]
