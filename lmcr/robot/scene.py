"""Kitchen scenes: the scene file (CLI contract), object shapes sized like the real thing, and the
objects' placement on the table (`world.py` builds them in pybullet).

Table frame: origin at the table-top centre, +x away from the robot, +y to its left; objects stand
within |x| <= 0.3 and |y| <= 0.5. Containers (cups, bowls, pots, the sink, ...) are open boxes built
from a floor and four walls; bottles and jugs hold liquids, shakers hold powders, food is a box,
sphere or cylinder.

An object of a label the robot has no model of ("closet", "sweater") may say which known object it is
built as (`"like": "storage box"`): the words (the completion, the replies) are its label's, its body,
motions and checks those of the known one (`SceneObject.shape`).

Every object is an instance with an id: an object may give one (`{"label": "cup", "id": "red cup"}`),
else it is assigned in scene order: "cup" for the first cup, "cup#2", "cup#3" for the next ones (see
lmcr.instances). Ids differ; an id that is a label belongs to an object of that label; the held object's
id is its label. Objects without `xy` are placed only when all of them could fit: their outlines, with
the clearance between neighbours, must not need more than the table's area (checked before any is
placed), and the placement gives up after PLACEMENT_CHECKS overlap checks.
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field
from pathlib import Path

from lmcr.instances import DuplicateIdError, assign_ids, id_problem
from lmcr.jsonl import InputError, decode_utf8, parse_json, read_bytes
from lmcr.lexicon import load_lexicon
from lmcr.robot.household import household, tools

TABLE_CENTRE = (0.60, 0.0)  # in the robot's base frame (x forward), metres: as near as the pedestal allows
TABLE_TOP = 0.75  # height above the floor
TABLE_SIZE = (0.7, 1.2)
X_LIMIT, Y_LIMIT = 0.3, 0.5
HAND_OFF = (-1.6, 0.0)  # where a held object waits (behind the robot, on the floor) until it is put in the hand
LAYOUT_ATTEMPTS = 20  # seeded random layouts tried before the objects are packed tight
PACKING_ATTEMPTS = 200  # seeded tight packings tried before a scene's objects are said not to fit
PACKING_GAP = 0.022  # between packed neighbours: the 2 cm that counts as clear, and the 3-decimal rounding
CLEAR = 0.02  # metres between two objects' outlines for them not to overlap
# overlap checks (a spot against one placed object) at most, over all layouts of one scene: a crowded scene
# that will not fit is given up on in seconds, not minutes
PLACEMENT_CHECKS = 2_000_000

# label -> (kind, size): container (width, depth, height, wall), bottle (radius, height),
# food shapes ("box", sx, sy, sz) / ("sphere", r) / ("cyl", r, h)
LIQUIDS = ("water", "milk", "wine", "oil", "vinegar", "honey", "soy sauce")
POWDERS = ("salt", "sugar", "flour", "black pepper", "cinnamon", "parsley", "cheese")
CONTAINERS = {
    "cup": (0.08, 0.08, 0.10),
    "glass": (0.07, 0.07, 0.12),
    "mug": (0.09, 0.09, 0.10),
    "bowl": (0.16, 0.16, 0.07),
    "plate": (0.24, 0.24, 0.025),
    "pan": (0.26, 0.26, 0.05),
    "pot": (0.22, 0.22, 0.15),
    "skillet": (0.26, 0.26, 0.05),
    "blender": (0.18, 0.18, 0.22),
    "microwave": (0.30, 0.26, 0.12),
    "oven": (0.34, 0.30, 0.12),
    "sink": (0.36, 0.30, 0.10),
    "cutting board": (0.30, 0.20, 0.02),
    "soup": (0.16, 0.16, 0.07),
    "salad": (0.18, 0.18, 0.08),
    "chocolate": (0.14, 0.14, 0.06),
    "batter": (0.14, 0.14, 0.06),  # food served in a bowl
    # the household's receptacles and the person's hand (household.json), by the box around them
    **{label: r.size for label, r in household().items()},
}
FOOD = {
    "onion": ("sphere", 0.035),
    "garlic": ("sphere", 0.025),
    "potato": ("sphere", 0.04),
    "tomato": ("sphere", 0.035),
    "apple": ("sphere", 0.04),
    "strawberry": ("sphere", 0.02),
    "egg": ("sphere", 0.025),
    "ice": ("box", 0.03, 0.03, 0.03),
    "banana": ("box", 0.16, 0.035, 0.035),
    "bell pepper": ("sphere", 0.04),
    "bread": ("box", 0.10, 0.08, 0.03),
    "steak": ("box", 0.14, 0.09, 0.025),
    "chicken": ("box", 0.12, 0.08, 0.04),
    "fish": ("box", 0.18, 0.06, 0.03),
    "rice": ("cyl", 0.04, 0.06),
    "pasta": ("cyl", 0.035, 0.08),
    "cake": ("cyl", 0.09, 0.06),
    "pizza": ("cyl", 0.12, 0.015),
    "butter": ("box", 0.08, 0.04, 0.03),
    "spoon": ("box", 0.16, 0.03, 0.02),
    "scissors": ("box", 0.16, 0.07, 0.015),
    "sponge": ("box", 0.09, 0.06, 0.03),
    "towel": ("box", 0.20, 0.14, 0.015),
    "pastry brush": ("box", 0.18, 0.03, 0.02),
}
# tools held by a grip, with the parts it takes (a knife's handle and blade, a lid's knob): household.json
TOOLS = tools()
WALL = 0.006  # a kitchen container's walls and floor, this thick
BOTTLE = (0.03, 0.16)  # radius, height of bottles and jugs
SHAKER = (0.025, 0.09)


@dataclass
class SceneObject:
    label: str
    xy: tuple[float, float]
    body: int = -1
    id: str = ""  # this object among those sharing its label (lmcr.instances); assigned by its Scene when empty
    link: int = -1  # the body's link things are put in (a drawer's), -1 the body itself
    joint: int = -1  # the joint that opens it (a drawer's slide, a lid's hinge), -1 none
    like: str = ""  # the known label whose body it is built as (an object the robot has no model of), "" its own

    @property
    def shape(self) -> str:
        """The label whose body, motions and checks the object has: its own, or the one it is built `like`."""
        return self.like or self.label

    @property
    def name(self) -> str:
        """How plans and checks name the object: its id (its label before a Scene gave it one)."""
        return self.id or self.label

    @property
    def kind(self) -> str:
        if self.shape in CONTAINERS:
            return "container"
        if self.shape in TOOLS:
            return "tool"
        if self.shape in LIQUIDS:
            return "bottle"
        if self.shape in POWDERS:
            return "shaker"
        return "food"


@dataclass
class Scene:
    objects: list[SceneObject]  # on the table
    seed: int = 0
    holding: SceneObject | None = None  # in the robot's hand at the start (not on the table)
    bodies: dict[int, SceneObject] = field(default_factory=dict)  # the table objects by body
    table: int = -1

    def __post_init__(self) -> None:
        """Every object gets its id (lmcr.instances): the ones it was given are kept, and must differ."""
        present = self.present
        ids = assign_ids([o.label for o in present], [o.id or None for o in present])
        for obj, ident in zip(present, ids):
            obj.id = ident

    @property
    def present(self) -> list[SceneObject]:
        """Everything in the scene: the objects on the table and the one in the hand."""
        return [*self.objects, *([self.holding] if self.holding else [])]

    def find(self, name: str) -> SceneObject:
        """The object with id `name`, else the first one labelled `name`."""
        present = self.present
        found = next((o for o in present if o.id == name), None) or next((o for o in present if o.label == name), None)
        if found is None:
            raise KeyError(f"no {name!r} on the table (there are: {', '.join(o.id for o in self.objects)})")
        return found

    def instances(self, label: str) -> list[SceneObject]:
        """Every object labelled `label`, the one in the hand first."""
        return sorted((o for o in self.present if o.label == label), key=lambda o: o is not self.holding)

    def shapes(self) -> dict[str, str]:
        """Each label's shape (`SceneObject.shape`): what the labels a frame names are built as."""
        return {o.label: o.shape for o in self.present}


def solid_shape(label: str) -> tuple:
    """("sphere", r), ("cyl", r, h) or ("box", sx, sy, sz) of an object that is not a container."""
    if label in LIQUIDS:
        return ("cyl", *BOTTLE)
    if label in POWDERS:
        return ("cyl", *SHAKER)
    return FOOD[label]


def depth(label: str) -> float:
    """How far below a container's top its floor's top is (0: things rest on its top, as on a shelf, or on
    a solid object)."""
    found = household().get(label)
    if found is not None:
        return found.depth
    return CONTAINERS[label][2] - WALL if label in CONTAINERS else 0.0


def has_shape(label: str) -> bool:
    """Whether the simulated world has a shape for `label` (a kitchen object, a household receptacle or tool)."""
    return label in CONTAINERS or label in FOOD or label in LIQUIDS or label in POWDERS or label in TOOLS


def robot_objects() -> set[str]:
    """The labels a scene may use: the lexicon's objects and the household's receptacles and tools."""
    return set(load_lexicon().objects) | set(household()) | set(TOOLS)


def footprint(label: str) -> float:
    """Half the object's widest side on the table (its radius when it is round)."""
    half_x, half_y, _ = outline(label)
    return max(half_x, half_y)


def height(label: str) -> float:
    """How tall an object stands on the table."""
    if label in CONTAINERS:
        return CONTAINERS[label][2]
    if label in TOOLS:
        return TOOLS[label].size[2]
    shape = solid_shape(label)
    return 2 * shape[1] if shape[0] == "sphere" else shape[-1]  # cylinder height, box z size


def outline(label: str) -> tuple[float, float, bool]:
    """The object's outline on the table: half extents along x and y, and whether it is round (then
    both are its radius); boxes and containers stand square to the table's edges."""
    if label in CONTAINERS or label in TOOLS:
        w, d, _ = CONTAINERS[label] if label in CONTAINERS else TOOLS[label].size
        return w / 2, d / 2, False
    shape = solid_shape(label)
    if shape[0] in ("sphere", "cyl"):
        return shape[1], shape[1], True
    return shape[1] / 2, shape[2] / 2, False


def gap_between(a: str, axy, b: str, bxy) -> float:
    """The shortest distance between two objects' outlines on the table (0 when they overlap)."""
    (ax, ay, a_round), (bx, by, b_round) = outline(a), outline(b)
    dx, dy = abs(axy[0] - bxy[0]), abs(axy[1] - bxy[1])
    if a_round and b_round:
        return max(0.0, math.hypot(dx, dy) - ax - bx)
    # a round one is its centre grown by its radius: measure from the box (grown by the other box's
    # half extents) and take the radius off
    radius = ax if a_round else bx if b_round else 0.0
    hx = (0 if a_round else ax) + (0 if b_round else bx)
    hy = (0 if a_round else ay) + (0 if b_round else by)
    return max(0.0, math.hypot(max(0.0, dx - hx), max(0.0, dy - hy)) - radius)


def _overlap(a: str, axy, b: str, bxy) -> bool:
    return gap_between(a, axy, b, bxy) < CLEAR


def room_needed(label: str) -> float:
    """The table area (m²) an object takes up with the half of CLEAR around it that no neighbour may use:
    these grown outlines never overlap, so together they fit in the table grown by CLEAR / 2 each side."""
    half_x, half_y, round_ = outline(label)
    if round_:
        return math.pi * (half_x + CLEAR / 2) ** 2
    return (2 * half_x + CLEAR) * (2 * half_y + CLEAR)


def _check_room(objects: list[SceneObject], where: str) -> None:
    """Fail at once when the objects cannot fit on the table whatever their places (their grown outlines
    need more area than there is): a scene of 10,000 cups is known not to fit without placing any."""
    needed = sum(room_needed(o.shape) for o in objects)
    table = (2 * X_LIMIT + CLEAR) * (2 * Y_LIMIT + CLEAR)
    if needed > table:
        free = sum(1 for o in objects if o.xy is None)
        raise InputError(
            f"{where}: {len(objects):,} objects ({free:,} without a position) need {needed:.2f} m² "
            f"of the table's {table:.2f} m²: they cannot all fit"
        )


def load_scene(path: Path) -> Scene:
    """Read and validate a scene file; objects without `xy` are placed at random (seeded)."""
    data = parse_json(decode_utf8(read_bytes(path), Path(path)), str(path), multiline=True)
    return scene_from_json(data, str(path))


def scene_from_json(data: object, where: str) -> Scene:
    """A scene from the scene format's decoded JSON (a file's, or a batch line's `scene`)."""
    if not isinstance(data, dict) or not isinstance(data.get("objects"), list):
        raise InputError(f"{where}: a scene is an object with an 'objects' list")
    seed = data.get("seed", 0)
    if not isinstance(seed, int) or isinstance(seed, bool):
        raise InputError(f"{where}: 'seed' must be an integer, not {seed!r:.40}")
    items = []
    for k, obj in enumerate(data["objects"]):
        if not isinstance(obj, dict):
            raise InputError(f"{where}: object {k} is not a JSON object")
        items.append((obj.get("label"), obj.get("xy"), obj.get("id"), obj.get("like")))
    holding, held_like = _held(data.get("holding"), where)
    if holding in [item[0] for item in items]:
        raise InputError(f"{where}: the {holding} cannot be both in the hand ('holding') and on the table")
    return make_scene(items, seed, where, holding, held_like)


def _held(holding: object, where: str) -> tuple[str | None, str | None]:
    """The held object's label and what it is built like: `"holding": "water"`, or an object
    `{"label": "book", "like": "sponge"}` for one the robot has no model of."""
    if holding is None:
        return None, None
    label, like = (holding.get("label"), holding.get("like")) if isinstance(holding, dict) else (holding, None)
    wrong = _unbuildable(label, like, {*load_lexicon().objects, *TOOLS})
    if wrong == "label":
        raise InputError(f"{where}: 'holding' must be a known object label, not {label!r:.60}")
    if wrong == "like":
        raise InputError(
            f"{where}: 'holding' ({label}): 'like' must be a known object the hand can hold, not {like!r:.60}"
        )
    return label, like


def _unbuildable(label: object, like: object, vocabulary: set[str]) -> str | None:
    """Which of an object's fields keeps it from being built: "like" when it is given but names no known
    object, "label" when the label is no usable name or neither it nor a like is known; None when it can be."""
    if like is not None and (not isinstance(like, str) or like not in vocabulary):
        return "like"
    if not isinstance(label, str) or (label not in vocabulary and like is None) or id_problem(label):
        return "label"
    return None


def _check_like(labels: list, likes: list, vocabulary: set[str], where: str) -> None:
    """Each object's label is known, or it is built like a known one; a label is built one way in a scene
    (a frame names labels, and each names one shape)."""
    built: dict[str, str | None] = {}
    for k, (label, like) in enumerate(zip(labels, likes)):
        wrong = _unbuildable(label, like, vocabulary)
        if wrong == "like":
            raise InputError(
                f"{where}: object {k} ({label!r:.60}): 'like' must be a known object label, not {like!r:.60}"
            )
        if wrong == "label":
            raise InputError(
                f"{where}: object {k}: unknown label {label!r:.60} (give 'like', the known object it is built as)"
            )
        if built.setdefault(label, like) != like:
            raise InputError(
                f"{where}: object {k} ({label}): built like {like!r}, but an earlier {label} like {built[label]!r}"
            )


def _check_ids(labels: list[str], given: list, vocabulary: set[str], holding: str | None, where: str) -> None:
    """The ids given to objects are usable and differ (from each other and from the held object's, its
    label); an id that is an object label is an object of that label (an id names one object)."""
    for k, (label, ident) in enumerate(zip(labels, given)):
        if ident is None:
            continue
        if problem := id_problem(ident):
            raise InputError(f"{where}: object {k}: {problem}")
        if ident in vocabulary and ident != label:
            raise InputError(f"{where}: object {k} ({label}): id {ident!r} is another object's label")
    try:
        assign_ids(labels + ([holding] if holding else []), given + ([holding] if holding else []))
    except DuplicateIdError as exc:
        held = f" (the held {holding}'s)" if holding and exc.second == len(labels) else ""
        raise InputError(
            f"{where}: duplicate object id {exc.ident!r}: objects {exc.first} and {exc.second}{held}"
        ) from None


def _valid_xy(xy: object) -> bool:
    return (
        isinstance(xy, list)
        and len(xy) == 2
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in xy)
    )


def make_scene(
    items: list[tuple], seed: int = 0, where: str = "scene", holding: str | None = None, held_like: str | None = None
) -> Scene:
    """Validated objects (known labels or ones built `like` a known one, finite on-table positions that do
    not overlap, different ids), the ones without a position placed at random with `seed`; `holding` is the
    label of what the robot holds (`held_like` what it is built as). An item is (label, xy or None), or with
    an id, or with an id and a like (each may be None)."""
    vocabulary = robot_objects()
    labels = [item[0] for item in items]
    given, likes = ([item[n] if len(item) > n else None for item in items] for n in (2, 3))
    _check_like(labels, likes, vocabulary, where)
    _check_ids(labels, given, vocabulary, holding, where)
    placed: list[SceneObject] = []
    for k, (label, xy, *_) in enumerate(items):
        obj = SceneObject(label, tuple(xy) if xy is not None else None, id=given[k] or "", like=likes[k] or "")
        if xy is not None:
            _check_position(k, obj, xy, placed, where)
        placed.append(obj)
    if any(o.xy is None for o in placed):
        _check_room(placed, where)
        _lay_out(placed, seed, where)
    held = SceneObject(holding, HAND_OFF, like=held_like or "") if holding else None
    return Scene(placed, seed, held)


def _check_position(k: int, obj: SceneObject, xy: object, placed: list[SceneObject], where: str) -> None:
    """Object `k`'s given position: two finite numbers on the table, clear of the objects placed so far."""
    label = obj.label
    if not _valid_xy(xy):
        raise InputError(f"{where}: object {k} ({label}): xy must be two finite numbers [x, y], not {xy!r:.60}")
    if abs(xy[0]) > X_LIMIT or abs(xy[1]) > Y_LIMIT:
        raise InputError(f"{where}: object {k} ({label}): xy {xy} is off the table (|x| <= 0.3, |y| <= 0.5)")
    for other in placed:
        if other.xy is not None and _overlap(obj.shape, xy, other.shape, other.xy):
            raise InputError(f"{where}: object {k} ({label}) overlaps the {other.id or other.label}")


def _lay_out(placed: list[SceneObject], seed: int, where: str) -> None:
    """Give the objects without a position one, trying layouts until one fits every object."""
    free = [o for o in placed if o.xy is None]
    # uniform draws first (seeded "7", "7:1", ...: a scene that fits one is laid out as it always was),
    # then tight packings; an unlucky early spot can leave no room for a later object
    layouts = [(_random_spot, seed if k == 0 else f"{seed}:{k}") for k in range(LAYOUT_ATTEMPTS)]
    layouts += [(_packed_spot, f"{seed}:packed:{k}") for k in range(PACKING_ATTEMPTS)]
    tries = _Tries(PLACEMENT_CHECKS)
    for k, (spot, layout_seed) in enumerate(layouts):
        try:
            _place(placed, spot, random.Random(layout_seed), where, tries)
            return
        except InputError as exc:
            if k == len(layouts) - 1 or tries.left <= 0:
                raise InputError(f"{exc} ({k + 1} layouts tried)") from None
            for obj in free:
                obj.xy = None


class _Tries:
    """The overlap checks a scene's placement may still make (None: no limit)."""

    def __init__(self, left: int | None = None):
        self.left = left

    def spend(self, checks: int, label: str, where: str) -> None:
        if self.left is None:
            return
        self.left -= checks
        if self.left <= 0:
            raise InputError(f"{where}: no free spot for the {label} on the table")


def _place(placed: list[SceneObject], spot, rng: random.Random, where: str, tries: _Tries) -> None:
    """Give the objects without a position one, big ones first (they need the room): `spot(obj, others,
    rng, where, tries)` picks it clear of the objects placed so far."""
    for obj in sorted(placed, key=lambda o: -footprint(o.shape)):
        if obj.xy is None:
            obj.xy = spot(obj, [o for o in placed if o.xy is not None and o is not obj], rng, where, tries)


def _packed_spot(
    obj: SceneObject, placed: list[SceneObject], rng: random.Random, where: str, tries: _Tries
) -> tuple[float, float]:
    """A free spot where `obj` touches the table's edges or its neighbours, drawn at random among them (a
    corner-point packing): scenes crowded with big things (an oven, a sink, a cutting board, ...) that
    uniform draws do not fit."""
    touching = _touching_spots(obj.shape, placed)
    tries.spend(len(touching) * max(len(placed), 1), obj.label, where)
    spots = [xy for xy in touching if not any(_overlap(obj.shape, xy, o.shape, o.xy) for o in placed)]
    if not spots:
        raise InputError(f"{where}: no free spot for the {obj.label} on the table")
    return rng.choice(spots)


def _touching_spots(label: str, placed: list[SceneObject]) -> list[tuple[float, float]]:
    """On-table spots where `label` touches a table edge or stands PACKING_GAP from a placed object's
    side, along x and along y (a round object packed as the square around it)."""
    half_x, half_y, _ = outline(label)
    xs, ys = {-X_LIMIT + half_x, X_LIMIT - half_x}, {-Y_LIMIT + half_y, Y_LIMIT - half_y}
    for other in placed:
        other_x, other_y, _ = outline(other.shape)
        xs |= {other.xy[0] + s * (other_x + PACKING_GAP + half_x) for s in (-1, 1)}
        ys |= {other.xy[1] + s * (other_y + PACKING_GAP + half_y) for s in (-1, 1)}
    on_table = [(round(x, 3), round(y, 3)) for x in sorted(xs) for y in sorted(ys)]
    return [xy for xy in on_table if abs(xy[0]) <= X_LIMIT - half_x + 1e-9 and abs(xy[1]) <= Y_LIMIT - half_y + 1e-9]


def _random_spot(
    obj: SceneObject, placed: list[SceneObject], rng: random.Random, where: str, tries: _Tries = _Tries()
) -> tuple[float, float]:
    """A free spot for `obj` drawn uniformly (its shape's outline clear of the placed ones); errors name it
    by its label."""
    margin = footprint(obj.shape)
    for _ in range(500):
        tries.spend(max(len(placed), 1), obj.label, where)
        xy = (rng.uniform(-X_LIMIT + margin, X_LIMIT - margin), rng.uniform(-Y_LIMIT + margin, Y_LIMIT - margin))
        if not any(_overlap(obj.shape, xy, o.shape, o.xy) for o in placed):
            return round(xy[0], 3), round(xy[1], 3)
    raise InputError(f"{where}: no free spot for the {obj.label} on the table")


SPOT_DRAWS = 12  # free spots drawn at random, of which the nearest the robot's edge are tried


def free_spots(scene: Scene, label: str, n: int = 3) -> list[tuple[float, float]]:
    """The `n` spots nearest the middle of the robot's edge (both arms reach there), of `SPOT_DRAWS` drawn
    at random (seeded by the scene's seed), where the `label` would stand clear of the objects on the
    table: where to put down what the hand holds, or what one arm passes to the other, or what stands out
    of reach."""
    rng, spots = random.Random(f"{scene.seed}:put down"), set()
    for _ in range(SPOT_DRAWS):
        try:
            spots.add(_random_spot(SceneObject(label, None), scene.objects, rng, "scene"))
        except InputError:
            break
    return sorted(spots, key=lambda xy: math.hypot(xy[0] + X_LIMIT, xy[1]))[:n]


def world_xy(xy: tuple[float, float]) -> tuple[float, float]:
    return TABLE_CENTRE[0] + xy[0], TABLE_CENTRE[1] + xy[1]
