"""The household's receptacles, the person and the tools, described in data (`household.json`), not code:
bins, boxes, a shelf, a stove, a drawer, a fridge, a dish drawer, a cupboard, a hand held out over the
table; a knife, a lid, a ladle, a whisk, foil. Each receptacle is its shape (an open box, or boxes put
together, or a URDF body with joints), its mass (0: fixed in place), the surface things are put on
(inside it below the rim, or on its top) and the motion that puts a Theme there (place, dispose, hand
over). The scene takes them as objects like the kitchen's containers; the world builds them from their
parts; a learned verb's frame with a Theme and a Destination is carried out with the Destination's
motion (`tasks.task_for`). A tool is its shape, its mass, where the hand holds it (`grip`) and, for a
knife, its blade's edge, for a ladle, its bowl.

A light module (json only): the scene's validation reads the vocabulary without loading the simulator."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from lmcr.errors import LMCRError

HOUSEHOLD_FILE = Path(__file__).with_name("household.json")
MOTIONS = ("place", "dispose", "hand over")  # the motions that put a Theme at a Destination
SURFACES = ("inside", "top")
ENTRIES = ("top", "front")  # how things go into an opened receptacle: lowered from above, or in through its front
CENTRED = 0.001  # metres: how far off the origin the middle of a body's parts may lie

Box = tuple[tuple[float, float, float], tuple[float, float, float]]  # half extents, centre


class HouseholdError(LMCRError, ValueError):
    """The household file is not a valid description of receptacles."""


@dataclass(frozen=True)
class Opening:
    """How a shut receptacle is opened, filled and shut again: a drawer slides out on a prismatic `joint`, a
    chest fridge's lid turns up on a revolute one, a cupboard's door swings out on one. The hand holds the
    `handle` (the bar's middle, in the frame of the link the joint moves) and moves it along the joint's
    travel, `opens` (metres or radians: the joint stands at -opens when open), and back; things go to the
    `middle` of the floor of the `link` they are put in (its frame; the URDF's root link for a box that
    stays put), at most `headroom` tall (what shuts passes over them, or what the box has room for), by its
    `entry`: lowered from the `top`, or carried in through the `front` (a cupboard's). Within `shut` of its
    closed end (joint units) it counts as shut."""

    link: str
    joint: str
    opens: float
    handle: tuple[float, float, float]
    middle: tuple[float, float, float]
    headroom: float
    shut: float = 0.01
    entry: str = "top"

    def joint_at(self, open_: bool) -> float:
        """The joint's value with the receptacle open (-opens) or shut (0)."""
        return -self.opens if open_ else 0.0


@dataclass(frozen=True)
class Tool:
    """A tool the hand holds to act on something: its shape (boxes, in a frame whose origin is the middle of
    its footprint on the table top), the box around it (`size`), mass, colour, the point whose top the
    fingertips hold (`grip`, body frame) and how wide it is across there, the middle of a `blade`'s edge
    and of the floor of a `scoop`'s bowl, with the middle of the bowl's `lip` (body frame; None without one)."""

    label: str
    parts: tuple[Box, ...]
    size: tuple[float, float, float]
    mass: float
    colour: tuple[float, float, float, float]
    grip: tuple[float, float, float]
    grip_width: float
    blade: tuple[float, float, float] | None = None
    scoop: tuple[float, float, float] | None = None  # the middle of the floor of the bowl a ladle fills
    lip: tuple[float, float, float] | None = None  # ... and of the bowl's rim it is tipped out over

    @property
    def blade_part(self) -> Box:
        """The part whose underside is the blade's edge (the one the `blade` point lies in)."""
        return next(part for part in self.parts if _in_part(self.blade, part))

    @property
    def blade_width(self) -> float:
        """How thick the blade is (what a cut leaves between the pieces)."""
        return 2 * min(self.blade_part[0][:2])

    @property
    def blade_reach(self) -> float:
        """Half the blade's length along its edge, from the `blade` point."""
        return max(self.blade_part[0][:2])

    @property
    def blade_axis(self) -> tuple[float, float, float]:
        """The direction of the blade's edge in the body frame (its part's longer side)."""
        half = self.blade_part[0]
        return (1.0, 0.0, 0.0) if half[0] >= half[1] else (0.0, 1.0, 0.0)


@dataclass(frozen=True)
class Receptacle:
    """One receptacle: its shape (boxes in a frame whose origin is the middle of its footprint on the
    table top, or a URDF body), the box it needs (`size`: width along x, depth along y, height), how far
    below its top things put inside go (`depth`, 0 when they rest on top), mass, where things go, the
    motion that puts them there, and its `opening` when it is shut (a drawer, a lidded chest)."""

    label: str
    parts: tuple[Box, ...]
    size: tuple[float, float, float]
    depth: float
    mass: float
    surface: str
    motion: str
    colour: tuple[float, float, float, float]
    urdf: Path | None = None
    opening: Opening | None = None


def _bounds(parts: tuple[Box, ...]) -> tuple[list[float], list[float]]:
    """The lowest and highest coordinate the parts reach along x, y and z."""
    return [min(c[k] - h[k] for h, c in parts) for k in range(3)], [
        max(c[k] + h[k] for h, c in parts) for k in range(3)
    ]


def _around(parts: tuple[Box, ...]) -> tuple[float, float, float]:
    """Width (x), depth (y) and height of the box around the parts, from the table top up (the
    footprint is centred on the origin: `_parts` checks it)."""
    lo, hi = _bounds(parts)
    return 2 * max(-lo[0], hi[0]), 2 * max(-lo[1], hi[1]), hi[2]


def _inner_depth(parts: tuple[Box, ...], surface: str) -> float:
    """How far below the top the lowest part's top is (an open box's floor); 0 for things set on top."""
    if surface == "top":
        return 0.0
    floor = min(parts, key=lambda part: part[1][2])
    return _around(parts)[2] - (floor[1][2] + floor[0][2])


def open_box(width: float, depth: float, height: float, wall: float, raised: float = 0.0) -> tuple[Box, ...]:
    """A floor and four walls `wall` thick: a cup, a bin, a cupped hand (`raised` above the table)."""
    t, z = wall, raised
    return (
        ((width / 2, depth / 2, t / 2), (0.0, 0.0, z + t / 2)),
        ((t / 2, depth / 2, height / 2), (width / 2 - t / 2, 0.0, z + height / 2)),
        ((t / 2, depth / 2, height / 2), (-width / 2 + t / 2, 0.0, z + height / 2)),
        ((width / 2, t / 2, height / 2), (0.0, depth / 2 - t / 2, z + height / 2)),
        ((width / 2, t / 2, height / 2), (0.0, -depth / 2 + t / 2, z + height / 2)),
    )


def _numbers(value: object, n: int, where: str, positive: bool = False) -> tuple[float, ...]:
    ok = (
        isinstance(value, list)
        and len(value) == n
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in value)
    )
    if not ok or (positive and min(value) <= 0):
        kind = "positive numbers" if positive else "numbers"
        raise HouseholdError(f"{where}: must be {n} finite {kind}, not {value!r:.60}")
    return tuple(float(v) for v in value)


def _number(entry: dict, key: str, where: str, default: float | None = None) -> float:
    value = entry.get(key, default)
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not math.isfinite(value) or value < 0:
        raise HouseholdError(f"{where}: '{key}' must be a number >= 0, not {value!r:.40}")
    return float(value)


def _parts(entry: dict, where: str) -> tuple[Box, ...]:
    if "open_box" in entry:
        w, d, h = _numbers(entry["open_box"], 3, f"{where}: open_box", positive=True)
        wall = _number(entry, "wall", where)
        if not 0 < wall < min(w, d) / 2:
            raise HouseholdError(f"{where}: 'wall' must be thinner than half the box, not {wall}")
        return open_box(w, d, h, wall, _number(entry, "raised", where, 0.0))
    parts = entry.get("parts")
    if not isinstance(parts, list) or not parts or not all(isinstance(x, dict) for x in parts):
        raise HouseholdError(f"{where}: needs an 'open_box' or a non-empty 'parts' list of {{half, at}}")
    boxes = tuple(
        (_numbers(x.get("half"), 3, f"{where}: part {k} half", True), _numbers(x.get("at"), 3, f"{where}: part {k} at"))
        for k, x in enumerate(parts)
    )
    lo, hi = _bounds(boxes)
    if lo[2] < -1e-9:
        raise HouseholdError(f"{where}: a part reaches below the table top")
    for k, axis in enumerate("xy"):
        # the outline, and so a tool's ends and where things go, is measured from the origin both ways
        if abs(lo[k] + hi[k]) > CENTRED:
            raise HouseholdError(
                f"{where}: the parts' footprint must be centred on the origin, but runs {lo[k]:g} to {hi[k]:g} "
                f"along {axis}"
            )
    return boxes


def _choice(entry: dict, key: str, allowed: tuple[str, ...], where: str) -> str:
    value = entry.get(key)
    if value not in allowed:
        raise HouseholdError(f"{where}: '{key}' must be one of {', '.join(allowed)}, not {value!r:.40}")
    return value


def _section(path: Path, key: str) -> dict:
    """One section of a household file (label -> description); a file without it is refused."""
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise HouseholdError(f"{path}: not a readable JSON file ({exc})") from None
    entries = data.get(key) if isinstance(data, dict) else None
    if not isinstance(entries, dict):
        raise HouseholdError(f"{path}: needs a '{key}' object (label -> description)")
    return entries


def read_household(path: Path) -> dict[str, Receptacle]:
    """The receptacles of a household file, by label, validated (a bad entry: one line naming it)."""
    entries = _section(path, "receptacles")
    return {label: _receptacle(label, entry, Path(path), f"{path}: {label!r}") for label, entry in entries.items()}


def read_tools(path: Path) -> dict[str, Tool]:
    """The tools of a household file, by label, validated (a bad entry: one line naming it)."""
    found = {label: _tool(label, entry, f"{path}: {label!r}") for label, entry in _section(path, "tools").items()}
    if clash := set(found) & set(read_household(path)):
        raise HouseholdError(f"{path}: {sorted(clash)[0]!r} is both a receptacle and a tool")
    return found


def _tool(label: str, entry: object, where: str) -> Tool:
    if not isinstance(entry, dict):
        raise HouseholdError(f"{where}: is not a JSON object")
    parts = _parts(entry, where)
    size = _around(parts)
    grip = _numbers(entry.get("grip"), 3, f"{where}: grip")
    width = _number(entry, "grip_width", where)
    blade = _numbers(entry["blade"], 3, f"{where}: blade") if "blade" in entry else None
    scoop = _numbers(entry["scoop"], 3, f"{where}: scoop") if "scoop" in entry else None
    lip = _numbers(entry["lip"], 3, f"{where}: lip") if "lip" in entry else None
    if (scoop is None) != (lip is None):
        raise HouseholdError(f"{where}: a 'scoop' needs its 'lip' and a 'lip' its 'scoop'")
    for name, point in (("grip", grip), ("blade", blade), ("scoop", scoop), ("lip", lip)):
        if point is not None and not _within(point, size):
            raise HouseholdError(f"{where}: '{name}' {list(point)} lies outside the tool")
    if blade is not None and not any(_in_part(blade, part) for part in parts):
        raise HouseholdError(f"{where}: 'blade' {list(blade)} lies in none of the parts")
    if not 0 < width <= min(size[:2]):
        raise HouseholdError(f"{where}: 'grip_width' must be more than 0 and at most the tool's width, not {width}")
    colour = _numbers(entry.get("colour", [0.6, 0.6, 0.6, 1]), 4, f"{where}: colour")
    return Tool(label, parts, size, _number(entry, "mass", where), colour, grip, width, blade, scoop, lip)


def _in_part(point: tuple[float, float, float], part: Box) -> bool:
    """Whether a point lies in a part (a box: half extents, centre), its faces included."""
    half, centre = part
    return all(abs(point[k] - centre[k]) <= half[k] + 1e-9 for k in range(3))


def _within(point: tuple[float, float, float], size: tuple[float, float, float]) -> bool:
    """Whether a point (body frame) lies within the box around a body of `size`."""
    x, y, z = point
    return abs(x) <= size[0] / 2 + 1e-9 and abs(y) <= size[1] / 2 + 1e-9 and -1e-9 <= z <= size[2] + 1e-9


def _receptacle(label: str, entry: object, path: Path, where: str) -> Receptacle:
    if not isinstance(entry, dict):
        raise HouseholdError(f"{where}: is not a JSON object")
    colour = _numbers(entry.get("colour", [0.6, 0.6, 0.6, 1]), 4, f"{where}: colour")
    mass, surface = _number(entry, "mass", where), _choice(entry, "surface", SURFACES, where)
    motion = _choice(entry, "motion", MOTIONS, where)
    if "urdf" not in entry:
        parts = _parts(entry, where)
        return Receptacle(label, parts, _around(parts), _inner_depth(parts, surface), mass, surface, motion, colour)
    urdf = entry["urdf"]
    if not isinstance(urdf, str) or not (path.parent / urdf).is_file():
        raise HouseholdError(f"{where}: 'urdf' must name a URDF file beside the household file, not {urdf!r:.60}")
    size = _numbers(entry.get("size"), 3, f"{where}: size", positive=True)
    depth = _number(entry, "depth", where)
    if depth > size[2]:
        raise HouseholdError(f"{where}: 'depth' {depth} is deeper than the body is tall ({size[2]})")
    opening = _opening(entry["opening"], f"{where}: opening") if "opening" in entry else None
    return Receptacle(label, (), size, depth, mass, surface, motion, colour, path.parent / urdf, opening)


def _opening(entry: object, where: str) -> Opening:
    if not isinstance(entry, dict) or not all(isinstance(entry.get(k), str) for k in ("link", "joint")):
        raise HouseholdError(f"{where}: needs the 'link' and the 'joint' (names in the URDF)")
    handle = _numbers(entry.get("handle"), 3, f"{where}: handle")
    middle = _numbers(entry.get("middle"), 3, f"{where}: middle")
    opens, headroom = _number(entry, "opens", where), _number(entry, "headroom", where)
    shut = _number(entry, "shut", where, default=Opening.shut)
    way_in = _choice({"entry": Opening.entry, **entry}, "entry", ENTRIES, where)
    return Opening(entry["link"], entry["joint"], opens, handle, middle, headroom, shut, way_in)


@cache
def household() -> dict[str, Receptacle]:
    """The shipped household's receptacles by label."""
    return read_household(HOUSEHOLD_FILE)


@cache
def tools() -> dict[str, Tool]:
    """The shipped household's tools by label."""
    return read_tools(HOUSEHOLD_FILE)
