"""A Baxter URDF written from the robot's published kinematics, with simple geometry.

pybullet ships no Baxter. Joint origins, axes and limits below are those of Rethink Robotics'
`baxter_description` (arm mounts on the torso at +-45 degrees, seven revolute joints per arm
s0 s1 e0 e1 w0 w1 w2, each about its local z axis), then the hand, the electric gripper base and a
parallel gripper with two prismatic fingers. Links are cylinders and boxes of roughly the real size;
masses are the published ones rounded. `LMCR_BAXTER_URDF` / `--urdf` use the official description instead
(`official.py`).
"""

from __future__ import annotations

import math
from pathlib import Path

from lmcr.files import atomic_path

HALF_PI = math.pi / 2
PEDESTAL_HEIGHT = 0.93  # floor to Baxter's base frame

# (joint, parent link, child link, origin xyz, origin rpy, (lower, upper) limits, child mass, child shape)
# shape: ("cyl", radius, length, z offset of its centre) or ("box", sx, sy, sz, z offset)
# One joint a row, so the table reads as Baxter's kinematic chain (kept by fmt: off, allowed past 120 columns).
# fmt: off
ARM_CHAIN = [
    ("s0", "arm_mount", "upper_shoulder", (0.055695, 0, 0.011038), (0, 0, 0), (-1.70167633, 1.70167633), 5.70, ("cyl", 0.06, 0.27, 0.135)),
    ("s1", "upper_shoulder", "lower_shoulder", (0.069, 0, 0.27035), (-HALF_PI, 0, 0), (-2.147, 1.047), 3.23, ("cyl", 0.06, 0.10, 0.0)),
    ("e0", "lower_shoulder", "upper_elbow", (0.102, 0, 0), (HALF_PI, 0, HALF_PI), (-3.0541961, 3.0541961), 4.31, ("cyl", 0.055, 0.26, 0.13)),
    ("e1", "upper_elbow", "lower_elbow", (0.069, 0, 0.26242), (-HALF_PI, -HALF_PI, 0), (-0.05, 2.618), 2.07, ("cyl", 0.05, 0.10, 0.0)),
    ("w0", "lower_elbow", "upper_forearm", (0.10359, 0, 0), (HALF_PI, 0, HALF_PI), (-3.059, 3.059), 2.25, ("cyl", 0.045, 0.27, 0.135)),
    ("w1", "upper_forearm", "lower_forearm", (0.01, 0, 0.2707), (-HALF_PI, -HALF_PI, 0), (-1.57079632679, 2.094), 1.61, ("cyl", 0.045, 0.10, 0.0)),
    ("w2", "lower_forearm", "wrist", (0.115975, 0, 0), (HALF_PI, 0, HALF_PI), (-3.059, 3.059), 0.35, ("cyl", 0.04, 0.10, 0.05)),
]
# fmt: on
ARM_MOUNTS = {
    "left": ((0.024645, 0.219645, 0.118588), (0, 0, math.pi / 4)),
    "right": ((0.024645, -0.219645, 0.118588), (0, 0, -math.pi / 4)),
}
HAND_OFFSET = 0.11355  # wrist -> hand
GRIPPER_BASE_OFFSET = 0.025  # hand -> gripper base
ENDPOINT_OFFSET = 0.1327  # gripper base -> between the fingertips
FINGER_TRAVEL = 0.020833  # each finger's prismatic range
JOINTS = tuple(name for name, *_ in ARM_CHAIN)


def _fmt(values) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _link(name: str, mass: float, shape: tuple, color: str = "0.6 0.1 0.1 1", solid: bool = True) -> str:
    if shape[0] == "cyl":
        _, radius, length, z = shape
        geometry = f'<cylinder radius="{radius}" length="{length}"/>'
    else:
        _, sx, sy, sz, z = shape
        geometry = f'<box size="{sx} {sy} {sz}"/>'
    inertia = max(mass * 0.01, 1e-5)
    body = f'<origin xyz="0 0 {z}"/><geometry>{geometry}</geometry>'
    return (
        f'<link name="{name}"><inertial><origin xyz="0 0 {z}"/><mass value="{mass}"/>'
        f'<inertia ixx="{inertia}" iyy="{inertia}" izz="{inertia}" ixy="0" ixz="0" iyz="0"/></inertial>'
        f'<visual>{body}<material name="{name}_m"><color rgba="{color}"/></material></visual>'
        + (f"<collision>{body}</collision>" if solid else "")
        + "</link>"
    )


def _joint(name: str, kind: str, parent: str, child: str, xyz, rpy, axis=(0, 0, 1), limits=None) -> str:
    limit = f'<limit lower="{limits[0]}" upper="{limits[1]}" effort="50" velocity="1.5"/>' if limits else ""
    axis_tag = f'<axis xyz="{_fmt(axis)}"/>' if kind != "fixed" else ""
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{_fmt(xyz)}" rpy="{_fmt(rpy)}"/>{axis_tag}{limit}</joint>'
    )


def _arm(side: str) -> list[str]:
    xyz, rpy = ARM_MOUNTS[side]
    parts = [
        _link(f"{side}_arm_mount", 0.1, ("box", 0.05, 0.05, 0.02, 0)),
        _joint(f"{side}_torso_arm_mount", "fixed", "torso", f"{side}_arm_mount", xyz, rpy),
    ]
    for name, parent, child, jxyz, jrpy, limits, mass, shape in ARM_CHAIN:
        parts.append(_link(f"{side}_{child}", mass, shape))
        parts.append(
            _joint(f"{side}_{name}", "revolute", f"{side}_{parent}", f"{side}_{child}", jxyz, jrpy, limits=limits)
        )
    hand, base = f"{side}_hand", f"{side}_gripper_base"
    parts += [
        _link(hand, 0.19, ("cyl", 0.04, 0.03, 0.0), "0.1 0.1 0.1 1"),
        _joint(f"{side}_hand", "fixed", f"{side}_wrist", hand, (0, 0, HAND_OFFSET), (0, 0, 0)),
        _link(base, 0.3, ("box", 0.05, 0.09, 0.04, 0.0), "0.8 0.8 0.8 1"),
        _joint(f"{side}_gripper_base", "fixed", hand, base, (0, 0, GRIPPER_BASE_OFFSET), (0, 0, 0)),
        _link(f"{side}_gripper", 0.0001, ("box", 0.001, 0.001, 0.001, 0.0), "0 0 0 0", solid=False),  # a frame only
        _joint(f"{side}_endpoint", "fixed", base, f"{side}_gripper", (0, 0, ENDPOINT_OFFSET), (0, 0, 0)),
    ]
    for finger, sign, lo, hi in (("l", -1, 0.0, FINGER_TRAVEL), ("r", 1, -FINGER_TRAVEL, 0.0)):
        link = f"{side}_gripper_{finger}_finger"
        parts += [
            _link(link, 0.02, ("box", 0.01, 0.01, 0.11, 0.055), "0.8 0.8 0.8 1"),
            _joint(
                f"{side}_gripper_{finger}_finger_joint",
                "prismatic",
                base,
                link,
                (0, sign * 0.045, 0.02),
                (0, 0, 0),
                axis=(0, 1, 0),
                limits=(lo, hi),
            ),
        ]
    return parts


def urdf_text() -> str:
    """The whole robot: pedestal and torso (fixed), two arms with grippers."""
    parts = [
        '<?xml version="1.0"?>',
        '<robot name="baxter">',
        _link("base", 0.0, ("cyl", 0.01, 0.01, 0.0)),
        _link(
            "pedestal", 60.0, ("cyl", 0.2, PEDESTAL_HEIGHT - 0.1, -(PEDESTAL_HEIGHT - 0.1) / 2 - 0.1), "0.2 0.2 0.2 1"
        ),
        _joint("pedestal_fixed", "fixed", "base", "pedestal", (0, 0, 0), (0, 0, 0)),
        _link("torso", 35.3, ("box", 0.3, 0.35, 0.6, 0.2), "0.2 0.2 0.2 1"),
        _joint("torso_t0", "fixed", "base", "torso", (0, 0, 0), (0, 0, 0)),
    ]
    parts += _arm("left") + _arm("right") + ["</robot>"]
    return "\n".join(parts)


def builtin_urdf(cache_dir: Path) -> Path:
    """Our URDF written (atomically) under `cache_dir`, rewritten only when its text changed."""
    path = Path(cache_dir) / "baxter.urdf"
    text = urdf_text()
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return path
