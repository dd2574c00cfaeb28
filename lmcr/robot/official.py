"""The official Baxter description (Rethink Robotics' `baxter_common`, BSD) made loadable by pybullet.

`baxter_description/urdf/baxter.urdf` names its meshes `package://PKG/...DAE`; pybullet reads neither
ROS package paths nor COLLADA, so each is resolved against the folder holding the packages and replaced
by its STL twin. The URDF's grippers are placeholders; the electric gripper is attached as the
end-effector xacros configure it (finger type, slot, tip), with the numbers read from those xacros:
no xacro is evaluated and nothing in the files is run.
"""

from __future__ import annotations

import hashlib
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

from defusedxml import ElementTree as SafeET

from lmcr.errors import LMCRError
from lmcr.files import atomic_path
from lmcr.robot.baxter import FINGER_TRAVEL

XACRO = "{http://www.ros.org/wiki/xacro}"
SLOT_PITCH, SLOT_ZERO = 0.0095, 0.011  # electric gripper: finger slot spacing and first-slot offset (xacro)


class RobotModelError(LMCRError, ValueError):
    """The robot description cannot be made loadable."""


def official_urdf(urdf: Path, cache_dir: Path) -> Path:
    """A pybullet-loadable copy of the official URDF at `urdf` (inside `baxter_common/`), written once
    per source under `cache_dir`."""
    urdf = Path(urdf).resolve()
    if len(urdf.parents) < 3:
        raise RobotModelError(f"{urdf}: expected baxter_common/baxter_description/urdf/baxter.urdf")
    robot = _loadable_robot(urdf, urdf.parents[2])
    _add_missing_inertials(robot)
    text = ET.tostring(robot, encoding="unicode")
    path = Path(cache_dir) / f"baxter-official-{hashlib.sha256(text.encode()).hexdigest()[:12]}.urdf"
    if not path.exists():
        with atomic_path(path) as tmp:
            tmp.write_text(text, encoding="utf-8")
    return path


def _loadable_robot(urdf: Path, root: Path) -> ET.Element:
    """The URDF's robot element with its meshes as STL files under `root` (baxter_common/, holding
    baxter_description/ and rethink_ee_description/), no Gazebo or transmission tags, and the electric
    grippers spelt out."""
    try:  # defusedxml refuses entity tricks with a ValueError; a missing xacro or number is a KeyError/OSError
        robot = SafeET.parse(urdf).getroot()
        for mesh in robot.iter("mesh"):
            mesh.set("filename", str(_mesh_file(root, mesh.get("filename", ""), urdf)))
        for tag in ("gazebo", "transmission"):
            for element in robot.findall(tag):
                robot.remove(element)
        for side in ("left", "right"):
            _replace_gripper(robot, root, side)
    except RobotModelError:
        raise
    except (OSError, SafeET.ParseError, KeyError, ValueError) as exc:
        raise RobotModelError(f"{urdf}: cannot read the robot description ({exc!r:.120})") from exc
    return robot


def _add_missing_inertials(robot: ET.Element) -> None:
    """A tiny mass for the frames without one: pybullet would warn and make them 1 kg."""
    for link in robot.findall("link"):
        if link.find("inertial") is None:
            link.append(
                ET.fromstring(
                    '<inertial><origin xyz="0 0 0"/><mass value="0.0001"/>'
                    '<inertia ixx="1e-8" ixy="0" ixz="0" iyy="1e-8" iyz="0" izz="1e-8"/></inertial>'
                )
            )


def _mesh_file(root: Path, name: str, urdf: Path) -> Path:
    """`package://PKG/a/b.DAE` -> root/PKG/a/b.STL (the STL twin of a COLLADA mesh)."""
    if not name.startswith("package://"):
        raise RobotModelError(f"{urdf}: mesh {name!r} is not a package:// path")
    path = (root / name[len("package://") :]).resolve()
    if root.resolve() not in path.parents:
        raise RobotModelError(f"{urdf}: mesh {name!r} points outside {root}")
    stl = path.with_suffix(".STL")
    for candidate in (stl, path.with_suffix(".stl"), path):
        if candidate.exists() and candidate.suffix.lower() in (".stl", ".obj"):
            return candidate
    raise RobotModelError(f"{urdf}: no STL twin of mesh {name!r} (looked for {stl})")


def _numbers(path: Path) -> dict[str, float]:
    """The numeric `xacro:property` values of a xacro file."""
    text = path.read_text(encoding="utf-8")
    return {m[1]: float(m[2]) for m in re.finditer(r'name="(\w+)"\s+value="(-?[\d.]+)"', text)}


def _gripper_parameters(root: Path, side: str) -> dict[str, str]:
    path = root / "baxter_description" / "urdf" / f"{side}_end_effector.urdf.xacro"
    element = SafeET.parse(path).getroot().find(f"{XACRO}rethink_electric_gripper")
    if element is None:
        raise RobotModelError(f"{path}: no rethink_electric_gripper")
    return dict(element.attrib)


def _replace_gripper(robot: ET.Element, root: Path, side: str) -> None:
    """Drop the URDF's gripper placeholders of one arm and attach the configured electric gripper."""
    for tag, names in (
        ("link", (f"{side}_gripper_base", f"{side}_gripper")),
        ("joint", (f"{side}_gripper_base", f"{side}_endpoint")),
    ):
        for element in robot.findall(tag):
            if element.get("name") in names:
                robot.remove(element)
    params = _gripper_parameters(root, side)
    meshes = root / "rethink_ee_description" / "meshes" / "electric_gripper"
    finger = params["l_finger"]
    sizes = _numbers(root / "rethink_ee_description" / "urdf" / "electric_gripper" / "fingers" / f"{finger}.xacro")
    length, width = sizes["finger_length"], sizes["finger_width"]
    box = (sizes["finger_box_height"], sizes["finger_box_width"], length)
    base_rpy = f"{-math.pi / 2} {math.pi} 0"
    parts = [
        f'<link name="{side}_gripper_base"><visual><origin rpy="{base_rpy}" xyz="0 0 0"/><geometry>'
        f'<mesh filename="{meshes / "electric_gripper_base.STL"}"/></geometry></visual>'
        f'<collision><origin rpy="{base_rpy}" xyz="0 0 0"/><geometry><cylinder length="0.1" radius="0.029"/>'
        f'</geometry></collision><inertial><origin xyz="0 0 0"/><mass value="0.3"/>'
        f'<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>',
        f'<joint name="{side}_gripper_base" type="fixed"><origin rpy="0 0 0" xyz="0 0 0.025"/>'
        f'<parent link="{side}_hand"/><child link="{side}_gripper_base"/></joint>',
        f'<link name="{side}_gripper"><inertial><origin xyz="0 0 0"/><mass value="0.0001"/>'
        f'<inertia ixx="1e-8" ixy="0" ixz="0" iyy="1e-8" iyz="0" izz="1e-8"/></inertial></link>',
        f'<joint name="{side}_endpoint" type="fixed"><origin rpy="0 0 0" xyz="0 0 {length + 0.02}"/>'
        f'<parent link="{side}_gripper_base"/><child link="{side}_gripper"/></joint>',
    ]
    for name, reflect in (("l", 1), ("r", -1)):
        slot = int(params[f"{name}_finger_slot"])
        offset = reflect * ((slot - 1) * SLOT_PITCH - SLOT_ZERO)
        limits = (0.0, FINGER_TRAVEL) if reflect == 1 else (-FINGER_TRAVEL, 0.0)
        rpy = f"0 0 {-math.pi / 2 * (reflect + 1)}"
        link = f"{side[0]}_gripper_{name}_finger"
        parts += [
            f'<link name="{link}"><visual><origin rpy="{rpy}" xyz="0 0 0"/><geometry>'
            f'<mesh filename="{meshes / "fingers" / (params[f"{name}_finger"] + ".STL")}"/></geometry></visual>'
            f'<collision><origin rpy="{rpy}" xyz="0 {width * reflect} {sizes["finger_box_length"]}"/><geometry>'
            f'<box size="{box[0]} {box[1]} {box[2]}"/></geometry></collision><inertial><origin xyz="0 0 0"/>'
            '<mass value="0.02"/><inertia ixx="1e-5" ixy="0" ixz="0" iyy="1e-5" iyz="0" izz="1e-5"/>'
            "</inertial></link>",
            f'<joint name="{side[0]}_gripper_{name}_finger_joint" type="prismatic"><origin rpy="0 0 0" '
            f'xyz="0 {offset} 0.02"/><axis xyz="0 1 0"/><parent link="{side}_gripper_base"/><child link="{link}"/>'
            f'<limit effort="20" lower="{limits[0]}" upper="{limits[1]}" velocity="5"/></joint>',
        ]
    for part in parts:
        robot.append(ET.fromstring(part))
