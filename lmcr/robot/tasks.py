"""One motion program per predicate, and per class of motion of the learned verbs (place, dispose, hand
over, cook, stir, wipe, cut, cover, serve): the steps (gripper poses, grasp, release, pouring) that act out a
completed frame, computed from the objects' geometry, and the checks that say whether it worked.

A program is built for one way of doing the task (`Variant`: the gripper's turn about the vertical when
it grasps, the direction it tilts to pour); the planner tries variants until one is feasible. Poses are
exact, not corrected while moving: the held object's pose in the hand is known from the grasp, so the
gripper pose that puts a bottle's mouth over the cup's centre is computed, not searched for.

Over 400 lines on purpose: the programs and their checks share the same geometry helpers (rims, mouths,
grasp heights, a tool's grip) and read as one table of motions; a module per predicate would repeat the
helpers' imports for a dozen lines each.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np
import pybullet as p

from lmcr.frame import Frame
from lmcr.robot.arm import DOWN, relative_pose
from lmcr.robot.household import household
from lmcr.robot.scene import (
    CONTAINERS,
    FOOD,
    TABLE_TOP,
    TOOLS,
    WALL,
    SceneObject,
    depth,
    footprint,
    has_shape,
    height,
    outline,
    world_xy,
)

CARRY_HEIGHTS = (0.40, 0.33, 0.26)  # above the table, tried in turn: the far corners are reached lower
TILT = math.radians(100)  # how far a bottle turns to pour: its opening then points a little down
POUR_HEIGHT = 0.10  # the opening this far above the target's rim: low enough to aim, high enough for the hand
DUMP_HEIGHTS = (0.03, 0.07, 0.11)  # the dumped object's middle this far above the target's rim, tried in turn
SHAKE_HEIGHT = 0.18  # a shaker's opening above the target: flat targets (pizza, steak) leave the hand no room lower
SIDE_GRIP, SIDE_GRIP_MIN = 0.6, 0.075  # side grasps hold 60 % up the object, at least 7.5 cm above the table
SIDE_APPROACH = 0.12  # a side grasp starts this far back along the gripper's axis
PITCHES = (0.0, 0.5)  # the gripper upright, or leaning forward to reach the far side of the table
# ... or further, into a cupboard through its front: the hand then trails low behind what it holds, under the top
FRONT_LEAN = 0.9
TURNS = (0.0, 0.8, -0.8)  # radians the hand may turn about the vertical while carrying
# ... and further for a tool held by a long handle (a ladle): where the handle points decides whether the
# arm can tip its bowl over the target
WIDE_TURNS = (1.6, -1.6)
GRIP_GAP = 0.005  # fingertips this far above the held object's top when it is grasped
GRIP_END = 0.04  # a long object held off its middle is held at least this far from its end
HAND_OFFER = 0.008  # an object handed over is held out with its underside this far above the person's palm
HAND_GAP = 0.03  # ... and lies in the hand while its underside is at most this far above the palm
WIPE_HEIGHT, WIPE_CLEAR = 0.005, 0.008  # a wiping tool's underside this far above the surface, its edge from a wall
WIPE_APPROACH = 0.05  # it comes down onto the surface, and leaves it, straight from this far above
WIPE_OVERLAP, WIPED = 0.9, 0.95  # rows overlap by a tenth of the tool's width; this share of the surface is wiped
STIR_RADIUS, STIR_TURNS = 0.025, 2  # the tool's tip circles this far round the middle, this many times
STIR_DEPTH, STIR_CLEAR = 0.03, 0.015  # its tip this far below the rim, this far clear of the walls
HANDLE_BAR = 0.015  # a drawer's or a lid's handle bar, this thick
# a lid is turned along its arc in chords this far apart (0.15 m out, a chord bows under 1 mm off the arc),
# the hand leaning forward this far (radians) all the while: held straight down, the bar of an open lid on
# the far side of the table is out of reach (its hold lets the bar turn, so the hand need not turn with it)
CHORD, LID_LEAN = math.radians(10), 0.3
# what opening and shutting is called, by how the joint moves: a drawer slides, a lid turns up, a door out
OPENING_WORDS = {
    ("slide", True): "pull {} open",
    ("slide", False): "push {} shut",
    ("lid", True): "lift {} open",
    ("lid", False): "lower {} shut",
    ("door", True): "swing {} open",
    ("door", False): "swing {} shut",
}
HANDLE_APPROACH = 0.1  # the hand comes onto a handle, and leaves it, along its own axis from this far
PUT_DOWN_HEIGHT = 0.005  # an object put down is let go with its underside this far above the table
# an object put in through a cupboard's front is let go with its underside this far over the floor (over
# the 1 cm every motion keeps from what it does not touch), after coming up to the opening with its near
# side this far before the front
FRONT_LIFT, FRONT_CLEAR = 0.015, 0.03
FRONT_DOOR = 0.02  # ... and stood at least this far behind the front, for the door to shut clear of it
CUT_STROKES, SAW = 3, 0.015  # a cut saws down through the food in this many strokes, the blade this far back and forth
CUT_ABOVE, CUT_CLEAR = 0.03, 0.004  # the edge starts this far above the food; it ends this far above the board
CUT_THROUGH = 0.006  # the food is cut through when the edge came this near its underside
HANDLE_OFF = 0.005  # while sawing, the blade's end next to the handle stays this far off the food
COVER_GAP = 0.005  # a lid is let go with its underside this far above the rim
LEVEL = math.radians(5)  # a lid tilted more than this does not sit on the rim
# a ladle's bowl dips with its floor this far below the rim of what it scoops from, at least this far above
# its floor; it carries this many grains (the content) and is tipped out this far above the target's rim
SCOOP_DEPTH, SCOOP_FLOOR, SCOOP_GRAINS, TIP_HEIGHTS = 0.045, 0.015, 12, (0.06, 0.03, 0.1)
TIPS = tuple(math.radians(a) for a in (15, 30, 45))  # it is tipped out in steps, its spout kept in place
LEVEL_CARRY, LEVEL_LEG = 0.08, 0.08  # ... carried level this far above the higher rim, in legs this long
SERVED = 0.6  # this share of what the ladle carried must end in the target
# where the arm cannot tip it out over the target's middle (a bowl at the far edge of its reach), the spout
# is held this share of the way from the middle to the target's inner wall on the robot's side
SPOUT_NEAR = 0.8


@dataclass(frozen=True)
class Step:
    """A gripper pose to reach (`kind` "move", first reachable of `positions`), or an action."""

    # move | home, park (to the arm's start, out of the way) | grasp | release | spill | give (a person takes it)
    # | blade in (a knife goes into food) | cut (the food is cut through when the blade went down through it)
    # | scoop (a ladle fills where it is) | run out (what it carries is let go of) | empty (wait while it runs out)
    kind: str
    name: str = ""
    positions: tuple = ()
    orientation: tuple = DOWN
    # what this motion may touch, "held" | "target", or "table" (a lift from it); it may also pass close
    # over the table, the rest is kept clear
    touches: str = ""
    probe: str = ""  # a name to record the held object's pose under once the pose is reached
    particles: int = 0
    # the held object goes into the target through its opening: though the motion may touch the target
    # (what is in it), the object must pass the walls clear
    into: bool = False
    straight: bool = False  # the gripper moves along the straight line (pulling a drawer on its slide)
    # a pose so hemmed in (the hand inside a cupboard) or so turned (a stirring tool stood on its end over the
    # pot, which most grasps of it cannot reach) that it decides the variant: it is checked, reach and
    # clearance with the object held as planned, before any motion to it is planned
    decides: bool = False

    @property
    def moves(self) -> bool:
        """Whether the arm moves in this step (to a gripper pose, or to its start or parked configuration)."""
        return self.kind in ("move", "home", "park")


@dataclass(frozen=True)
class Variant:
    """One way to do the task (radians): the gripper's yaw when grasping, how far it leans away from the
    robot (reaching the far side of the table needs the hand pitched forward) and the way it tilts."""

    yaw: float = 0.0  # a side grasp's heading: the horizontal direction the gripper points in
    pitch: float = 0.0
    tilt_sign: int = 1  # which way it turns to pour
    side: bool = False  # grasped from the side (bottles and shakers, to pour), not by the top
    turn: float = 0.0  # how far the hand turns about the vertical between the grasp and the target
    shift: tuple = (0.0, 0.0)  # a top grasp this far (x, y metres) from the top's middle, along a long object
    narrow: bool = False  # a top grasp approached with the fingers closed to the object's width

    def half_across(self, label: str) -> float:
        """Half the object's width between the fingers: a round one's radius, or a box's extent along
        the line a top grasp's fingers close on (across a long object's narrow side)."""
        if label in TOOLS and not self.side:  # held by its grip: a knife's handle, a lid's knob
            return TOOLS[label].grip_width / 2
        half_x, half_y, round_ = outline(label)
        if self.side or round_:
            return footprint(label)
        return abs(math.sin(self.yaw)) * half_x + abs(math.cos(self.yaw)) * half_y

    def approach_width(self, label: str) -> float | None:
        """The half-width the fingers are set for on the way to the grasp (None: fully open). A top
        grasp's fingertips stop above the object, so a `narrow` one comes with the fingers closed to its
        width and passes close to its neighbours; open fingers forgive an object that stands a few
        millimetres off where it was planned (one just set down), so they are tried first."""
        return self.half_across(label) if self.narrow and not self.side else None

    def at_target(self) -> tuple:
        """The gripper orientation over the target: the grasp's, turned about the vertical (the held
        object stays upright)."""
        return _turned(self.upright(), self.turn)

    def upright(self) -> tuple:
        """The gripper orientation that grasps, and carries the grasped object upright."""
        if self.side:  # gripper axis horizontal along the heading, fingers either side of the object
            return p.getQuaternionFromEuler((0, math.pi / 2, self.yaw))
        lean = p.getQuaternionFromAxisAngle((0, 1, 0), -self.pitch)  # gripper axis towards +x (away)
        return p.multiplyTransforms([0, 0, 0], lean, [0, 0, 0], _turned(DOWN, self.yaw))[1]


@dataclass
class Geometry:
    """The task's objects as they stand when planning starts (measured once: planning moves the held
    object about): the held one's pose (in the hand when it is already held) and the target's top
    centre and outline."""

    held: SceneObject
    target: SceneObject
    held_pos: tuple = ()
    held_orn: tuple = ()
    held_top: np.ndarray = field(default_factory=lambda: np.zeros(3))
    target_top: np.ndarray = field(default_factory=lambda: np.zeros(3))
    target_box: tuple = ()
    grasped: tuple | None = None  # the held object's pose in the hand as found after the grasp, if not as planned
    source: SceneObject | None = None  # what a ladle scoops from (Task.source)

    @classmethod
    def measure(cls, held: SceneObject, target: SceneObject, source: SceneObject | None = None) -> Geometry:
        pos, orn = p.getBasePositionAndOrientation(held.body)
        lo, hi = p.getAABB(target.body, target.link)  # a drawer's: what things are put in
        tpos = opening_point(target, "middle") if target.joint >= 0 else p.getBasePositionAndOrientation(target.body)[0]
        return cls(
            held,
            target,
            pos,
            orn,
            np.array([pos[0], pos[1], p.getAABB(held.body)[1][2]]),
            np.array([tpos[0], tpos[1], hi[2]]),
            (lo, hi),
            source=source,
        )

    def grip_pose(self, variant: Variant) -> tuple[np.ndarray, tuple]:
        """The gripper pose that grasps the held object by its top (a tool by its grip's), or from the side
        around its body (high enough for the hand to clear the table)."""
        if self.held.shape in TOOLS and not variant.side:
            grip = p.multiplyTransforms(self.held_pos, self.held_orn, TOOLS[self.held.shape].grip, [0, 0, 0, 1])[0]
            return np.asarray(grip) + [0, 0, GRIP_GAP], variant.upright()
        if variant.side:
            return self.held_top - [
                0,
                0,
                height(self.held.shape) - side_grip_height(self.held.shape),
            ], variant.upright()
        return self.held_top + [*variant.shift, GRIP_GAP], variant.upright()

    def in_hand(self, variant: Variant) -> tuple[tuple, tuple]:
        """The held object's pose relative to the gripper after the grasp (as found, once it is known)."""
        if self.grasped is not None:
            return self.grasped
        return relative_pose(*self.grip_pose(variant), self.held_pos, self.held_orn)

    def point_in_hand(self, variant: Variant, local) -> np.ndarray:
        """A point given in the held object's frame, in the gripper's frame."""
        rel_pos, rel_orn = self.in_hand(variant)
        return np.asarray(p.multiplyTransforms(rel_pos, rel_orn, local, [0, 0, 0, 1])[0])

    @property
    def opening(self) -> float:
        """How far the held object's opening (just above its top) is above its origin, in its own frame."""
        return self.held_top[2] - self.held_pos[2] + 0.012

    def mouth(self, variant: Variant) -> np.ndarray:
        """The held object's opening in the gripper's frame."""
        return self.point_in_hand(variant, [0, 0, self.opening])

    @property
    def underside_z(self) -> float:
        """How far the held object's underside is above its origin, in its own frame."""
        return self.held_top[2] - height(self.held.shape) - self.held_pos[2]

    def bottom(self, variant: Variant) -> np.ndarray:
        """The middle of the held object's underside in the gripper's frame."""
        return self.point_in_hand(variant, [0, 0, self.underside_z])

    def underside(self, variant: Variant, orientation) -> tuple[float, float, float]:
        """The held object's underside as the gripper holds it at `orientation`: its half-extents along the
        world's x and y about its middle (one the grasp left turned in the hand spans more than its outline)
        and how far its lowest corner hangs below its middle (one left tilted)."""
        half_x, half_y, _ = outline(self.held.shape)
        z = self.underside_z
        middle = self.bottom(variant)
        corners = [self.point_in_hand(variant, [x * half_x, y * half_y, z]) - middle for x in (1, -1) for y in (1, -1)]
        # each corner's offset from the middle in the world, the gripper at `orientation`
        offsets = [p.multiplyTransforms([0, 0, 0], orientation, list(c), [0, 0, 0, 1])[0] for c in corners]
        # rounded to a tenth of a millimetre: an object held square spans its outline, not a float's noise off it
        return (
            round(max(abs(o[0]) for o in offsets), 4),
            round(max(abs(o[1]) for o in offsets), 4),
            round(max(0.0, -min(o[2] for o in offsets)), 4),
        )

    def centre(self, variant: Variant) -> np.ndarray:
        """The held object's middle in the gripper's frame."""
        return self.point_in_hand(variant, [0, 0, self.held_top[2] - height(self.held.shape) / 2 - self.held_pos[2]])


def opening_point(target: SceneObject, which: str) -> np.ndarray:
    """A shut receptacle's `handle` (on the link its joint moves) or the `middle` of the floor things are put
    on (on the link that holds them) in the world, where it now stands (open or shut; household.json)."""
    link = target.joint if which == "handle" else target.link  # pybullet numbers a joint's child link as it
    pos, orn = link_frame(target.body, link)
    return np.asarray(
        p.multiplyTransforms(pos, orn, getattr(household()[target.shape].opening, which), (0, 0, 0, 1))[0]
    )


def link_frame(body: int, link: int) -> tuple[tuple, tuple]:
    """A link's frame as its URDF describes it, in the world (-1: the root link). pybullet gives a root
    link's pose at its centre of mass, which its URDF's inertial origin sets off the link's frame (a
    cupboard's mass is in the middle of its box, above the floor things are put on)."""
    if link >= 0:
        return p.getLinkState(body, link)[4:6]
    pos, orn = p.getBasePositionAndOrientation(body)
    inertial_pos, inertial_orn = p.getDynamicsInfo(body, -1)[3:5]
    return p.multiplyTransforms(pos, orn, *p.invertTransform(inertial_pos, inertial_orn))


def hinged(target: SceneObject) -> bool:
    """Whether the joint that opens the target turns (a lid's hinge) rather than slides (a drawer)."""
    return p.getJointInfo(target.body, target.joint)[2] == p.JOINT_REVOLUTE


def opening_steps(target: SceneObject, opening: bool) -> list[Step]:
    """Open a drawer, a lid or a door (or shut it) by its handle: the gripper comes onto the bar along its
    own axis, holds it, moves it along the joint's whole travel (straight along a slide; round a hinge in
    chords of CHORD, leaning LID_LEAN forward, the bar turning in the hold), lets go and draws back straight."""
    found = household()[target.shape].opening
    turns = hinged(target)
    start, end = p.getJointState(target.body, target.joint)[0], found.joint_at(opening)
    pieces = max(1, math.ceil(abs(end - start) / CHORD)) if turns else 1
    lean = LID_LEAN if turns else 0.0
    orn = Variant(
        pitch=lean
    ).upright()  # the fingers along the bar, over it: across it, one would meet a drawer's front
    axis = np.array([math.sin(lean), 0.0, -math.cos(lean)])  # the way the fingers point
    grip = opening_point(target, "handle") - axis * (HANDLE_BAR / 2 + GRIP_GAP)
    path = _moved_with(target, grip, [start + (end - start) * k / pieces for k in range(1, pieces + 1)])
    kind = ("door" if _upright_axis(target) else "lid") if turns else "slide"
    name = OPENING_WORDS[kind, opening].format(f"the {target.name}")
    return [
        move(f"above the {target.name}'s handle", grip - axis * HANDLE_APPROACH, orn),
        move(f"on the {target.name}'s handle", grip, orn, touches="target"),
        Step("hook", f"hold the {target.name}'s handle"),
        *(
            Step("move", name if pieces == 1 else f"{name} ({k}/{pieces})", (to,), orn, "target", straight=True)
            for k, to in enumerate(path, 1)
        ),
        Step("unhook", "let go of the handle"),
        # straight off the bar: a joint-space move with the target ignored swept a hand through an open lid
        Step("move", "up from the handle", (path[-1] - axis * HANDLE_APPROACH,), orn, "target", straight=True),
    ]


def _upright_axis(target: SceneObject) -> bool:
    """Whether the target's hinge turns about the vertical (a door's), not about a level axis (a lid's)."""
    axis = p.getJointInfo(target.body, target.joint)[13]
    orn = p.getLinkState(target.body, target.joint)[5]
    return abs(p.multiplyTransforms([0, 0, 0], orn, axis, [0, 0, 0, 1])[0][2]) > 0.9


def _moved_with(target: SceneObject, point: np.ndarray, values: list[float]) -> list[np.ndarray]:
    """Where a point held to the link the target's joint moves goes as the joint takes each of `values`
    (the joint is left where it was)."""
    joint, body = target.joint, target.body
    was = p.getJointState(body, joint)[0]
    pos, orn = p.getLinkState(body, joint)[4:6]
    local = p.multiplyTransforms(*p.invertTransform(pos, orn), point, (0, 0, 0, 1))[0]
    found = []
    try:
        for value in values:
            p.resetJointState(body, joint, value)
            pos, orn = p.getLinkState(body, joint)[4:6]
            found.append(np.asarray(p.multiplyTransforms(pos, orn, local, (0, 0, 0, 1))[0]))
    finally:
        p.resetJointState(body, joint, was)
    return found


def side_grip_height(label: str) -> float:
    """How far above the table a side grasp holds the object: SIDE_GRIP of its height, at least SIDE_GRIP_MIN."""
    return max(SIDE_GRIP * height(label), SIDE_GRIP_MIN)


def _turned(orientation, yaw: float) -> tuple:
    """`orientation` turned by `yaw` about the vertical."""
    return p.multiplyTransforms([0, 0, 0], p.getQuaternionFromEuler((0, 0, yaw)), [0, 0, 0], orientation)[1]


def tilted(variant: Variant, angle: float = TILT) -> tuple:
    """The gripper orientation with the grasped object turned `angle`: a side grasp rolls the wrist about
    the gripper's axis; a top grasp turns about the line between the fingers (about any other axis a
    finger would end up under the opening, in the way of what pours; a tool lying flat, turned a quarter,
    stands on its end)."""
    upright = variant.at_target()
    axis = np.asarray(p.getMatrixFromQuaternion(upright)).reshape(3, 3)[:, 2 if variant.side else 1]
    turn = p.getQuaternionFromAxisAngle(axis.tolist(), variant.tilt_sign * angle)
    return p.multiplyTransforms([0, 0, 0], turn, [0, 0, 0], upright)[1]


def gripper_for(point_in_hand: np.ndarray, orientation, goal) -> np.ndarray:
    """The gripper position that puts a point of the hand (gripper frame) at `goal` in orientation `orientation`."""
    offset = p.multiplyTransforms([0, 0, 0], orientation, point_in_hand.tolist(), [0, 0, 0, 1])[0]
    return np.asarray(goal) - offset


def gripper_over(point_in_hand: np.ndarray, orientation) -> float:
    """How high the gripper stands over a point of the hand (gripper frame) at `orientation`: the lower
    the point hangs, the higher."""
    return float(gripper_for(point_in_hand, orientation, [0, 0, 0])[2])


def variants(
    held: SceneObject,
    side_first: bool = False,
    opening: float = 0.0,
    turns: bool = False,
    wide: bool = False,
    front: bool = False,
) -> list[Variant]:
    """The grasps that suit the held object's shape (fingers across a long object; a round one also from
    the diagonals, after the others at each lean: between two neighbours only a diagonal may fit), upright or leaning
    forward, each tilting either way when the task `turns` it; `side_first` (pouring, putting in through a
    front), side grasps first where the object fits between the fingers, `opening` wide less a centimetre
    (the hand then stays high while it pours, level behind it as it goes in), headed from the robot towards
    the object. A `wide` task's hand also turns by WIDE_TURNS. A task that puts the object in through a
    `front` first tries each leaning grasp leaning further (FRONT_LEAN): the hand then trails behind the
    object, under the box's top; the grasps then go most leaning first."""
    found = _grasps(held, side_first, opening, turns, wide)
    if not front:
        return found
    leaning = [replace(v, pitch=FRONT_LEAN) for v in found if v.pitch == max(PITCHES)]
    return sorted(leaning + found, key=lambda v: -v.pitch)


def _grasps(held: SceneObject, side_first: bool, opening: float, turns: bool, wide: bool) -> list[Variant]:
    half_x, half_y, round_ = outline(held.shape)
    yaws, shifts = [0.0, math.pi / 2, -math.pi / 2], [(0.0, 0.0)]
    if round_:  # a square box held across its corners would not fit between fingers set for its sides
        yaws += [math.pi / 4, -math.pi / 4]
    if not round_ and abs(2 * half_x - 2 * half_y) > 0.02:
        long_x = half_x > half_y
        yaws = [0.0, math.pi] if long_x else [math.pi / 2, -math.pi / 2]
        # a long object may also be held nearer either end, the hand then further from a neighbour (a
        # tool only by its grip)
        reach = (max(half_x, half_y) - GRIP_END) * np.array([1.0, 0.0] if long_x else [0.0, 1.0])
        shifts += [tuple(reach), tuple(-reach)] if reach.max() > 0 and held.shape not in TOOLS else []
    signs = (1, -1) if turns else (1,)
    top = [
        Variant(yaw, pitch, sign, turn=turn, shift=shift)
        for shift in shifts
        for pitch in PITCHES
        for yaw in yaws
        for turn in (TURNS + WIDE_TURNS if wide else TURNS)
        for sign in signs
    ]
    narrow = [replace(v, narrow=True) for v in top]  # last: where no grasp with open fingers is clear
    if (
        not side_first
        or 2 * footprint(held.shape) > opening - 0.01
        or side_grip_height(held.shape) >= height(held.shape)
    ):
        return (
            top + narrow
        )  # a side grasp needs the body between the fingers: lower than its grip, it is held by the top
    x, y = world_xy(held.xy)
    heading = math.atan2(y, x)
    side = [
        Variant(heading + a, 0.0, sign, side=True, turn=turn)
        for a in (0.0, 0.5, -0.5)
        for turn in TURNS
        for sign in signs
    ]
    return side + top + narrow


def above(xy, name: str, orientation=DOWN, touches: str = "") -> Step:
    return Step(
        "move", name, tuple(np.array([xy[0], xy[1], TABLE_TOP + h]) for h in CARRY_HEIGHTS), orientation, touches
    )


def move(
    name: str, position, orientation=DOWN, touches: str = "", probe: str = "", into: bool = False, decides: bool = False
) -> Step:
    return Step(
        "move", name, (np.asarray(position, dtype=float),), orientation, touches, probe, into=into, decides=decides
    )


def pick(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Approach from above and grasp the top, or from the side around the body; lift (nothing to do
    when the object is already in the hand)."""
    if holding:
        return []
    pos, orn = g.grip_pose(v)
    name = g.held.name
    if v.side:
        back = np.array([math.cos(v.yaw), math.sin(v.yaw), 0.0]) * SIDE_APPROACH
        return [
            move(f"next to {name}", pos - back, orn),
            move(f"grip {name}", pos, orn, touches="held"),
            Step("grasp", f"grasp {name}"),
            move(f"lift {name}", pos + [0, 0, 0.12], orn, touches="table"),
        ]
    return [
        above(pos, f"above {name}", orn),
        move(f"grip {name}", pos, orn, touches="held"),
        Step("grasp", f"grasp {name}"),
        above(pos, f"lift {name}", orn, touches="table"),
    ]


def over_target(g: Geometry, v: Variant, name: str = "") -> Step:
    """Carrying height with the held object's middle over the target's."""
    orn = v.at_target()
    offset = gripper_for(g.centre(v), orn, [0, 0, 0])
    return above(g.target_top + offset, name or f"over {g.target.name}", orn)


def program_pour(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the opening above the target's centre, tilted; let the liquid run; turn back upright."""
    tilt = tilted(v)
    spout = gripper_for(g.mouth(v), tilt, g.target_top + [0, 0, POUR_HEIGHT])
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move("tilt to pour", spout, tilt),
        Step("spill", "pour", particles=30),
        over_target(g, v),
    ]


def program_sprinkle(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the shaker's opening above the target, tilted, and shake three times."""
    tilt = tilted(v)
    spout = gripper_for(g.mouth(v), tilt, g.target_top + [0, 0, SHAKE_HEIGHT])
    steps = [*pick(g, v, holding), over_target(g, v), move("tilt", spout, tilt)]
    for k in range(3):
        steps += [
            move(f"shake {k + 1} down", spout - [0, 0, 0.02], tilt),
            Step("spill", "shake", particles=8),
            move(f"shake {k + 1} up", spout, tilt),
        ]
    return [*steps, over_target(g, v)]


def program_place(g: Geometry, v: Variant, holding: bool, press: bool = False) -> list[Step]:
    """Lower the held object into or onto the target and let go (heat, fry; blend also presses)."""
    orn, t = v.at_target(), g.target_top
    steps = [*pick(g, v, holding), over_target(g, v), _lower_into(g, v), Step("release", "let go")]
    if press:
        steps += [move("above lid", t + [0, 0, 0.06], orn), move("press", t + [0, 0, 0.02], orn, touches="target")]
    return [*steps, above(t, "retreat", orn)]


def _lower_into(g: Geometry, v: Variant) -> Step:
    """Lower the held object into the target (onto it, when things rest on its top): its bottom 1.5 cm
    above the target's floor, but the hand stays above a deep container's rim (it drops the rest)."""
    orn, t = v.at_target(), g.target_top
    drop = -gripper_over(g.bottom(v), orn)  # how far the gripper is above the object's bottom
    bottom = max(t[2] - depth(g.target.shape) + 0.015, t[2] + 0.01 - drop)
    lower = gripper_for(g.bottom(v), orn, [t[0], t[1], bottom])
    # into a container it passes the walls clear (a bottle wider than a glass's opening would end on its rim)
    walled = _walled(g.target.shape)
    return move(f"lower {'into' if walled else 'onto'} {g.target.name}", lower, orn, touches="target", into=walled)


def program_put_in(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Put the held object into an opened cupboard through its front (a receptacle whose `entry` is
    "front"): carried to stand before the opening at the height it will stand at inside, moved straight in
    along the way the box faces to the middle of its floor, let go, the hand drawn straight back out and
    up. Every motion keeps clear of the box, its open door and what stands in it."""
    orn, name, half = v.at_target(), g.target.name, footprint(g.held.shape)
    floor = opening_point(g.target, "middle")
    inside_ = gripper_for(g.centre(v), orn, floor + [0, 0, FRONT_LIFT + height(g.held.shape) / 2])
    front = g.target_box[0][0]  # the box's near side (its root link's box: the door is a link of its own)
    before = inside_ - [floor[0] - (front - FRONT_CLEAR - half), 0.0, 0.0]
    # the middle of the floor, else as near the front as leaves the door room to shut (the far end of the
    # arm's reach)
    nearest = max(0.0, floor[0] - (front + FRONT_DOOR + half))
    return [
        *pick(g, v, holding),
        move(f"before the {name}", before, orn),
        Step("move", f"into the {name}", (inside_, inside_ - [nearest, 0.0, 0.0]), orn, straight=True, decides=True),
        Step("release", "let go"),
        Step("move", f"out of the {name}", (before,), orn, straight=True),
        above(before, "retreat", orn),
    ]


def program_hand_over(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the object out just above the person's palm, let the person take it, then let go and draw back."""
    orn, t = v.at_target(), g.target_top
    offer = gripper_for(g.bottom(v), orn, t + [0, 0, HAND_OFFER])
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move(f"hold out to {g.target.name}", offer, orn, touches="target"),
        Step("give", f"{g.target.name} takes it"),
        Step("release", "let go"),
        above(g.target_top, "retreat", orn),
    ]


def program_dump(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Carry the object over the target, turn the hand over and let go."""
    tilt = tilted(v)
    # lowest first (what falls stays where it lands); higher ones when the hand, turned, would meet the rim
    turned = tuple(
        gripper_for(g.centre(v), tilt, g.target_top + [0, 0, h + height(g.held.shape) / 2]) for h in DUMP_HEIGHTS
    )
    return [
        *pick(g, v, holding),
        over_target(g, v),
        Step("move", "turn over", turned, tilt),
        Step("release", "let go"),
        over_target(g, v),
    ]


def program_dip(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Lower the held object below the target's rim, then lift it back out. Into a container (a bowl of
    batter) it must pass the walls; food that is not served in one (flour, a shaker here) it presses into."""
    orn, t = v.at_target(), g.target_top
    dip = gripper_for(g.bottom(v), orn, t - [0, 0, 0.02 + 0.3 * height(g.held.shape)])
    out = gripper_for(g.bottom(v), orn, t + [0, 0, 0.06])
    into = g.target.shape in CONTAINERS
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move("dip", dip, orn, touches="target", probe="dip", into=into),
        move("lift out", out, orn, touches="target", probe="lifted"),
    ]


def program_stroke(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the object just above the target's surface and stroke across it four times."""
    orn, t = v.at_target(), g.target_top
    lo, hi = g.target_box
    reach = max(0.02, (hi[0] - lo[0]) / 2 - 0.03)
    # the held object's underside skims the surface, 1 cm above it
    strokes = [
        move(
            f"stroke {k + 1}",
            gripper_for(g.bottom(v), orn, t + [reach if k % 2 else -reach, 0, 0.01]),
            orn,
            touches="target",
            probe=f"stroke {k + 1}",
        )
        for k in range(4)
    ]
    return [*pick(g, v, holding), over_target(g, v), *strokes, over_target(g, v)]


def _walled(label: str) -> bool:
    """Whether things put on the object lie on a floor within walls (an open container)."""
    return label in CONTAINERS and depth(label) > 0


def surface(target: SceneObject, box: tuple) -> tuple[float, float, float, float, float]:
    """The surface a tool wipes: a container's floor within its walls, else the object's top, as x and y
    bounds and height (`box` the target's AABB)."""
    (lo, hi), inset = box, (WALL if _walled(target.shape) else 0.0)
    return lo[0] + inset, hi[0] - inset, lo[1] + inset, hi[1] - inset, hi[2] - depth(target.shape)


def fits_on(tool: str, label: str) -> bool:
    """Whether a wiping tool lies flat on the surface with room to move (within a container's walls, which
    must be lower than the tool: the hand holding it stays above the rim)."""
    return why_not_wipe(tool, label) is None


def why_not_wipe(tool: str, label: str) -> str | None:
    """Why the `tool` cannot wipe the `label` (`fits_on`), as a template of {tool} and {theme}; None when
    it can."""
    if not has_shape(tool) or not has_shape(label):
        return "the robot has no model of the {tool} or the {theme} to wipe with"
    if depth(label) >= height(tool):
        return "the {theme} is deeper inside than the {tool} is tall: the hand holding it would hit its walls"
    (tx, ty, _), (sx, sy, _) = outline(tool), outline(label)
    inset = WALL + WIPE_CLEAR if _walled(label) else WIPE_CLEAR
    if min(tx, ty) > min(sx, sy) - inset or max(tx, ty) > max(sx, sy) - inset:
        return "the {tool} does not lie flat on the {theme} with room to move"
    return None


def program_wipe(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the tool flat on the surface and wipe it in rows, each the tool's width from the last, back
    and forth from edge to edge until it has gone over the whole surface; then lift it."""
    orn = v.upright()  # not turned while carried: the tool lies square to the surface, as it lay on the table
    x0, x1, y0, y1, z = surface(g.target, g.target_box)
    # the tool as it is held: one set down and picked up again may lie turned or tilted in the hand, and its
    # corners must keep clear of the walls and its lowest one above the surface
    hx, hy, drop = g.underside(v, orn)
    z += drop
    xs = (x0 + hx + WIPE_CLEAR, x1 - hx - WIPE_CLEAR)
    rows = max(1, math.ceil((y1 - y0 - 2 * WIPE_CLEAR) / (2 * hy * WIPE_OVERLAP)))
    ys = np.linspace(y0 + hy + WIPE_CLEAR, y1 - hy - WIPE_CLEAR, rows) if rows > 1 else [(y0 + y1) / 2]
    strokes = []
    for k, y in enumerate(ys):
        for end, x in enumerate(xs[:: -1 if k % 2 else 1]):
            at = gripper_for(g.bottom(v), orn, [x, y, z + WIPE_HEIGHT])
            name, probe = f"wipe row {k + 1} {'to' if end else 'from'}", f"row {k + 1} {end}"
            strokes.append(Step("move", name, (at,), orn, "target", probe, straight=True))  # level: no dip in the floor
    # down onto the surface and back up straight: a joint-space move there could sweep the tool through a rim
    first, last = strokes[0].positions[0], strokes[-1].positions[0]
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move("above the first row", first + [0, 0, WIPE_APPROACH], orn),
        *strokes,
        Step("move", "lift it", (last + [0, 0, WIPE_APPROACH],), orn, "target", straight=True),
    ]


def long_ends(g: Geometry) -> list[list[float]]:
    """The two ends of the held object's long side, halfway up, in its body frame."""
    half_x, half_y, _ = outline(g.held.shape)
    middle = g.held_top[2] - height(g.held.shape) / 2 - g.held_pos[2]
    return [[s * half_x, 0, middle] if half_x >= half_y else [0, s * half_y, middle] for s in (1, -1)]


def lower_end(g: Geometry, v: Variant, orientation) -> np.ndarray:
    """The end of the held object's long side that points down with the gripper at `orientation` (a tool
    stood on its end), in the gripper's frame."""
    in_hand = [g.point_in_hand(v, end) for end in long_ends(g)]
    return max(in_hand, key=lambda e: gripper_over(e, orientation))


def working_end_down(g: Geometry, v: Variant) -> Variant:
    """The variant whose quarter turn stands the held tool on its working end: the end of its long side
    away from where the hand holds it (a whisk's head, not its handle). An object without a grip (a spoon)
    stands on either end, as the variant turns it. The hand then points towards the handle's end, so a
    variant that would have tilted the other way turns the hand half round instead: a tool has as many
    headings over the target to try as a spoon."""
    tool = TOOLS.get(g.held.shape)
    if tool is None:
        return v
    v = v if v.tilt_sign > 0 else replace(v, turn=v.turn + math.pi)
    working = g.point_in_hand(v, max(long_ends(g), key=lambda end: math.dist(end[:2], tool.grip[:2])))
    sign = max((1, -1), key=lambda s: gripper_over(working, tilted(replace(v, tilt_sign=s), math.pi / 2)))
    return replace(v, tilt_sign=sign)


def stirs(tool: str, label: str) -> bool:
    """Whether the `tool` stirs in the `label`: a tool that is no vessel, its end narrower than the inside
    of a kitchen container (a spoon in the soup; not a microwave in the butter, nor a spoon in a bin)."""
    return why_not_stir(tool, label) is None


def why_not_stir(tool: str, label: str) -> str | None:
    """Why the `tool` cannot stir in the `label` (`stirs`), as a template of {tool} and {theme}; None when
    it can."""
    if not has_shape(tool) or tool in CONTAINERS:
        return "the {tool} is no tool to stir with"
    if label not in CONTAINERS or label in household():
        return "the {theme} is not in a kitchen container to stir it in"
    (tx, ty, _), (sx, sy, _) = outline(tool), outline(label)
    if min(tx, ty) + STIR_CLEAR > min(sx, sy) - WALL:
        return "the {tool}'s end does not fit inside the {theme}"
    return None


def program_stir(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Stand the tool on its (working) end over the container, lower its tip STIR_DEPTH below the rim
    (between the walls), circle it STIR_TURNS times round the middle, and lift it out."""
    v = working_end_down(g, v)
    orn, t = tilted(v, math.pi / 2), g.target_top
    tip = lower_end(g, v, orn)
    lo, hi = g.target_box
    room = min(hi[0] - lo[0], hi[1] - lo[1]) / 2 - STIR_CLEAR - footprint(g.held.shape)
    radius, below = max(0.0, min(STIR_RADIUS, room)), min(STIR_DEPTH, depth(g.target.shape) - 0.015)
    at = [
        [t[0] + radius * math.cos(a), t[1] + radius * math.sin(a), t[2] - below]
        for a in np.linspace(0, 2 * math.pi * STIR_TURNS, 6 * STIR_TURNS + 1)[1:]
    ]
    name = g.target.name
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move(f"stand it up over {name}", gripper_for(tip, orn, t + [0, 0, 0.04]), orn, decides=True),
        move(f"into {name}", gripper_for(tip, orn, [*at[-1][:2], at[-1][2]]), orn, "target", into=True),
        *[
            move(f"stir {k + 1}", gripper_for(tip, orn, point), orn, "target", f"stir {k + 1}")
            for k, point in enumerate(at)
        ],
        move(f"out of {name}", gripper_for(tip, orn, t + [0, 0, 0.04]), orn, "target", "lifted"),
    ]


def cuts(tool: str, label: str) -> bool:
    """Whether the `tool` cuts the `label` through: a blade, and food whose short side it spans while it saws
    (drawn SAW back and forth across the food's middle, the handle kept off the food)."""
    return why_not_cut(tool, label) is None


def why_not_cut(tool: str, label: str) -> str | None:
    """Why the `tool` cannot cut the `label` through (`cuts`), as a template of {tool} and {theme}; None
    when it can."""
    found = TOOLS.get(tool)
    if found is None or found.blade is None:
        return "the {tool} has no blade"
    if label not in FOOD:
        return "the {theme} is no food a blade cuts"
    half_x, half_y, _ = outline(label)
    if min(half_x, half_y) + SAW > found.blade_reach - HANDLE_OFF + 1e-9:
        return f"the {{tool}}'s blade cannot saw through the {{theme}}, {2 * min(half_x, half_y):.2f} m across"
    return None


def program_cut(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Hold the knife's blade upright over the food's middle, along its short side, and saw down through
    it to the board in CUT_STROKES strokes (the blade drawn back and forth), then lift it out. Whether the
    food was cut through is seen when the strokes end (`act` then swaps it for its pieces)."""
    tool, (half_x, half_y, _) = TOOLS[g.held.shape], outline(g.target.shape)
    # the handle to one side or the other (the two ways of doing it), the blade across a long food
    heading = (math.pi / 2 if half_x > half_y else 0.0) + (0.0 if v.tilt_sign > 0 else math.pi)
    orn = _turned(v.upright(), heading)
    edge = g.point_in_hand(v, tool.blade)
    ahead = g.point_in_hand(v, np.add(tool.blade, np.multiply(tool.blade_axis, SAW)))
    along = gripper_for(edge, orn, [0, 0, 0]) - gripper_for(ahead, orn, [0, 0, 0])  # SAW along the edge, in the world
    (x, y, top), bottom = g.target_top, g.target_box[0][2]

    def edge_at(sawed: float, z: float) -> np.ndarray:
        return gripper_for(edge, orn, [x, y, z]) + sawed * along

    depths = np.linspace(top, bottom + CUT_CLEAR, CUT_STROKES + 1)[1:]
    name, start = g.target.name, edge_at(0.0, top + CUT_ABOVE)
    return [
        *pick(g, v, holding),
        above(start, f"over {name}", orn),
        move(f"the blade over {name}", start, orn),
        Step("blade in", f"into {name}"),
        *[
            Step("move", f"cut {k + 1}", (edge_at((-1.0) ** k, z),), orn, "target", f"cut {k + 1}", straight=True)
            for k, z in enumerate(depths)
        ],
        Step("cut", f"through {name}"),
        Step("move", f"lift the {g.held.name} out", (start,), orn, "target", "lifted", straight=True),
    ]


def covers(tool: str, label: str) -> bool:
    """Whether the `tool` covers the `label`: a container with an opening, and a tool that lies over all of
    it (a lid, foil; a plate on a bowl)."""
    return why_not_cover(tool, label) is None


def why_not_cover(tool: str, label: str) -> str | None:
    """Why the `tool` cannot cover the `label` (`covers`), as a template of {tool} and {theme}; None when
    it can."""
    if tool == label or not has_shape(tool):
        return "the {tool} is nothing to cover it with"
    if not has_shape(label) or not _walled(label):
        return "the {theme} is no open container to cover"
    (tx, ty, _), (sx, sy, _) = outline(tool), outline(label)
    if tx < sx or ty < sy:
        return "the {tool} is smaller than the {theme}'s opening"
    return None


def program_cover(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Carry the lid (or foil) square over the container, lower it until its underside is COVER_GAP above
    the rim, let go (it settles on the rim) and draw back."""
    orn, t = v.upright(), g.target_top
    lower = gripper_for(g.bottom(v), orn, t + [0, 0, COVER_GAP])
    return [
        *pick(g, v, holding),
        over_target(g, v),
        move(f"lower it onto {g.target.name}", lower, orn, touches="target"),
        Step("release", "let go"),
        above(t, "retreat", orn),
    ]


def scoops(tool: str) -> bool:
    """Whether the `tool` has a bowl to carry content in (a ladle)."""
    return tool in TOOLS and TOOLS[tool].scoop is not None


def serves(source: str, target: str, tool: str | None) -> bool:
    """Whether content can be served from `source` into `target` (both hold things within walls) with the
    `tool` (a ladle; None: the one the robot finds on the table)."""
    return _walled(source) and _walled(target) and source != target and (tool is None or scoops(tool))


def program_serve(g: Geometry, v: Variant, holding: bool) -> list[Step]:
    """Dip the ladle's bowl into the container it serves from (its floor SCOOP_DEPTH below the rim, at
    least SCOOP_FLOOR above the container's floor), fill it there, lift it out level, carry it over the
    target, and tip it out spout first in TIPS, the spout held TIP_HEIGHTS above the target's middle; then
    level again the same way and lift it."""
    tool, orn = TOOLS[g.held.shape], v.at_target()
    bowl, lip = g.point_in_hand(v, tool.scoop), g.point_in_hand(v, tool.lip)
    lo, hi = p.getAABB(g.source.body, g.source.link)
    x, y = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2
    bottom = max(hi[2] - SCOOP_DEPTH, hi[2] - depth(g.source.shape) + SCOOP_FLOOR)
    dip, lifted = gripper_for(bowl, orn, [x, y, bottom]), gripper_for(bowl, orn, [x, y, hi[2] + 0.03])
    # the way of turning the hand that tips the bowl down (the other would run the content down the handle)
    sign = max((1, -1), key=lambda s: gripper_over(bowl, tilted(replace(v, tilt_sign=s), TIPS[-1])))
    tips = [tilted(replace(v, tilt_sign=sign), angle) for angle in TIPS]
    spouts = _spouts(g)
    pours = tuple(gripper_for(lip, orn, spout) for spout in spouts)  # level, the spout over the target
    name, into = g.source.name, g.target.name
    return [
        *pick(g, v, holding),
        above(lifted, f"over {name}", orn),
        move(f"above {name}", lifted, orn),
        Step("move", f"dip into {name}", (dip,), orn, straight=True),
        Step("scoop", f"fill it from {name}"),
        Step("move", f"lift it out of {name}", (lifted,), orn, straight=True),
        # carried level on straight lines (a joint-space motion turns the hand between its ends, and the
        # open spout would spill): up, across, and down to the spout over the target
        *_level_carry(lifted, pours[0], orn, into),
        Step("move", f"its spout over {into}", pours, orn, straight=True),
        Step("run out", "let the content go"),
        # (the spout a little higher or lower where the arm cannot tip it further where it is)
        *[
            Step("move", f"tip it out {k + 1}", tuple(gripper_for(lip, t, at) for at in spouts), t, straight=True)
            for k, t in enumerate(tips)
        ],
        Step("empty", "let it run out"),
        # level again the way it tipped (clear of the target's rim as it was), then up and away
        *[
            Step("move", f"level it {k + 1}", tuple(gripper_for(lip, t, at) for at in spouts), t, straight=True)
            for k, t in enumerate([*tips[-2::-1], orn])
        ],
        Step("move", "lift it", tuple(x + [0, 0, LEVEL_CARRY] for x in pours), orn, straight=True),
    ]


def _spouts(g: Geometry) -> list[np.ndarray]:
    """Where a ladle's spout is held over the target, in the order tried: TIP_HEIGHTS over its middle, then
    the same heights moved SPOUT_NEAR of the way towards its inner wall on the robot's side (the robot's
    base stands at the origin): the content still falls inside, and the arm reaches a few centimetres less
    far."""
    middle = [g.target_top + [0, 0, h] for h in TIP_HEIGHTS]
    lo, hi = g.target_box
    inner = min(hi[0] - lo[0], hi[1] - lo[1]) / 2 - WALL  # a target served into has walls (`serves`)
    towards = -g.target_top[:2] / np.linalg.norm(g.target_top[:2])  # it stands on the table, off the origin
    near = np.array([*(towards * SPOUT_NEAR * inner), 0.0])
    return middle + [m + near for m in middle]


def _level_carry(start: np.ndarray, end: np.ndarray, orn, into: str) -> list[Step]:
    """Straight up from `start`, across and down to LEVEL_CARRY above `end` without turning the hand, in
    legs at most LEVEL_LEG long (each solved from the last: one long line's end may be solved in another
    arm configuration, and the hand would turn on the way to it); a leg across goes higher where the
    lower way is blocked (past a tall bin)."""
    top = max(start[2], end[2]) + LEVEL_CARRY
    corners = [start, np.array([*start[:2], top]), np.array([*end[:2], top]), end + [0, 0, LEVEL_CARRY]]
    legs = []
    for a, b in zip(corners, corners[1:]):
        n = max(1, math.ceil(float(np.linalg.norm(b - a)) / LEVEL_LEG))
        across = a[2] == b[2] == top
        legs += [(a + (b - a) * k / n, across and k < n) for k in range(1, n + 1)]
    return [
        Step("move", f"carry it to {into} {k + 1}", (x, x + [0, 0, LEVEL_CARRY]) if up else (x,), orn, straight=True)
        for k, (x, up) in enumerate(legs)
    ]


def put_down(xy: tuple[float, float]) -> Task:
    """Pick the object up (unless it is in the hand), set it down upright at the free table spot `xy`
    and park the arm: the object is in the way of a task in the hand or out of one arm's reach, and the
    task then starts afresh from there."""

    def program(g: Geometry, v: Variant, holding: bool) -> list[Step]:
        orn = v.at_target()
        lower = gripper_for(g.bottom(v), orn, [*world_xy(xy), TABLE_TOP + PUT_DOWN_HEIGHT])
        return [
            *pick(g, v, holding),
            above(lower, "over a free spot", orn),
            move(f"put the {g.held.name} down", lower, orn, touches="table"),
            Step("release", "let go"),
            above(lower, "away from it", orn),
            Step("park", "out of the way"),
        ]

    return Task("", "", program, lambda held, target, out: {"ok": True})


@dataclass
class Outcome:
    """What happened while the program ran: particles poured, the held object's poses at probes, whether
    the rest was planned afresh after the pick-up."""

    particles: list[int] = field(default_factory=list)
    probes: dict[str, tuple] = field(default_factory=dict)  # name -> (position, AABB)
    replanned: bool = False
    taken: bool = False  # the person took the object handed over
    pieces: list[int] = field(default_factory=list)  # the bodies a cut food became
    clinging: list[int] = field(default_factory=list)  # what holds a ladle's content in it while carried
    cut: tuple = ()  # the cut's plane: a point on it and its normal (world)


def inside(target: SceneObject, point, above: float = 0.05) -> bool:
    """Whether a point lies within the target's outline (a drawer's: the drawer's own, wherever it is),
    above the table and at most `above` over its rim (0.01: held in it, as a liquid must be; more:
    resting on top of it)."""
    lo, hi = p.getAABB(target.body, target.link)
    return lo[0] <= point[0] <= hi[0] and lo[1] <= point[1] <= hi[1] and TABLE_TOP - 0.01 <= point[2] <= hi[2] + above


def share_inside(target: SceneObject, bodies: list[int], above: float) -> float:
    hits = sum(inside(target, p.getBasePositionAndOrientation(b)[0], above) for b in bodies)
    return round(hits / max(len(bodies), 1), 3)


def check_pour(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    share = share_inside(target, out.particles, above=0.01)  # a liquid must stay inside, below the rim
    return {"liquid_in_target": share, "ok": share >= 0.6}


def check_sprinkle(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    share = share_inside(target, out.particles, above=0.05)
    return {"powder_on_target": share, "ok": share >= 0.6}


def check_in_target(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """In (or on) the target; a drawer or a lidded box must also be shut again."""
    ok = inside(target, p.getBasePositionAndOrientation(held.body)[0])
    if target.joint < 0:
        return {"in_target": ok, "ok": ok}
    shut = bool(p.getJointState(target.body, target.joint)[0] > -household()[target.shape].opening.shut)
    return {"in_target": ok, "shut": shut, "ok": ok and shut}


def check_in_bin(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Thrown away: the object lies inside the bin, below its rim (not caught on it)."""
    ok = inside(target, p.getBasePositionAndOrientation(held.body)[0], above=0.0)
    return {"in_bin": ok, "ok": ok}


def check_handed_over(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Handed over: the person took the object (it lay in the hand when given) and it is still there once
    the robot has let go and drawn back."""
    there = in_palm(held, target)
    return {"taken": out.taken, "in_persons_hand": there, "ok": bool(out.taken and there)}


def in_palm(held: SceneObject, person: SceneObject) -> bool:
    """Whether the object lies in the person's hand: its middle over the palm, its underside at most
    HAND_GAP above the palm's top (and not sunk through it)."""
    pos, _ = p.getBasePositionAndOrientation(held.body)
    lo, hi = p.getAABB(person.body)
    underside = p.getAABB(held.body)[0][2]
    return bool(lo[0] <= pos[0] <= hi[0] and lo[1] <= pos[1] <= hi[1] and hi[2] - 0.01 <= underside <= hi[2] + HAND_GAP)


def check_wiped(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Wiped: the share of the surface (a 5 mm grid, WIPE_CLEAR in from its edges: the tool keeps that far
    from a wall) the tool's footprint went over, row by row as it was seen at each row's two ends, is at
    least WIPED."""
    x0, x1, y0, y1, _ = surface(target, p.getAABB(target.body, target.link))
    x0, x1, y0, y1 = x0 + WIPE_CLEAR, x1 - WIPE_CLEAR, y0 + WIPE_CLEAR, y1 - WIPE_CLEAR
    rows = {}
    for name, (_, (lo, hi)) in out.probes.items():
        if name.startswith("row "):
            rows.setdefault(name.split()[1], []).append((lo, hi))
    swept = [
        (min(b[0][0] for b in ends), max(b[1][0] for b in ends), min(b[0][1] for b in ends), max(b[1][1] for b in ends))
        for ends in rows.values()
    ]
    grid = [(x, y) for x in np.arange(x0, x1, 0.005) for y in np.arange(y0, y1, 0.005)]
    covered = sum(any(a <= x <= b and c <= y <= d for a, b, c, d in swept) for x, y in grid) / max(len(grid), 1)
    return {"wiped_share": round(covered, 3), "ok": covered >= WIPED}


def check_stir(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Stirred: at every point of the circles the tool reached below the rim within the container's
    outline, and it came back out."""
    rim = p.getAABB(target.body, target.link)[1][2]
    circle = [v for k, v in out.probes.items() if k.startswith("stir")]
    stirred = bool(circle) and all(box[0][2] < rim and inside(target, pos, above=1.0) for pos, box in circle)
    lifted = "lifted" in out.probes and out.probes["lifted"][1][0][2] > rim
    return {"stirred": stirred, "lifted_out": bool(lifted), "ok": stirred and bool(lifted)}


def check_cut(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Cut: the food is in pieces, one each side of the blade's plane, still about where the food lay (on
    the board, not flung away), and the knife came back out above them."""
    if not out.pieces:
        return {"in_pieces": False, "pieces_in_place": False, "lifted_out": False, "ok": False}
    point, normal = out.cut
    at = [np.asarray(p.getBasePositionAndOrientation(b)[0]) for b in out.pieces]
    sides = {bool(np.dot(x - point, normal) > 0) for x in at}
    # a piece may roll over onto its flat side (half an apple rolls about 1.6 of its radius), not further
    near = all(np.linalg.norm((x - point)[:2]) <= 2 * footprint(target.shape) + 0.03 and x[2] >= TABLE_TOP for x in at)
    top = max(p.getAABB(b)[1][2] for b in out.pieces)
    lifted = "lifted" in out.probes and out.probes["lifted"][1][0][2] > top
    pieces = len(out.pieces) >= 2 and sides == {True, False}
    return {"in_pieces": pieces, "pieces_in_place": near, "lifted_out": lifted, "ok": pieces and near and lifted}


def check_served(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Served: the ladle was filled in the container it served from, and at least SERVED of what it
    carried lies in the target (below its rim)."""
    filled = len(out.particles) >= SCOOP_GRAINS
    share = share_inside(target, out.particles, above=0.01) if filled else 0.0
    return {"filled": filled, "served_share": share, "ok": bool(filled and share >= SERVED)}


def check_covered(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    """Covered: the lid (foil) rests on the container's rim, level, over the whole opening."""
    (lo, hi), (tlo, thi) = p.getAABB(held.body), p.getAABB(target.body, target.link)
    over = all(lo[k] <= tlo[k] + WALL and hi[k] >= thi[k] - WALL for k in (0, 1))
    on_rim = thi[2] - 0.005 <= lo[2] <= thi[2] + 0.01
    up = np.asarray(p.getMatrixFromQuaternion(p.getBasePositionAndOrientation(held.body)[1])).reshape(3, 3)[:, 2]
    level = bool(math.acos(min(1.0, abs(up[2]))) <= LEVEL)
    return {"over_opening": over, "on_rim": on_rim, "level": level, "ok": bool(over and on_rim and level)}


def check_dip(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    rim = p.getAABB(target.body)[1][2]
    pos, box = out.probes["dip"]
    dipped = box[0][2] < rim and inside(target, pos)
    lifted = out.probes["lifted"][1][0][2] > rim
    return {"dipped_below_rim": bool(dipped), "lifted_out": bool(lifted), "ok": bool(dipped and lifted)}


def check_stroke(held: SceneObject, target: SceneObject, out: Outcome) -> dict:
    lo, hi = p.getAABB(target.body)
    on = all(
        lo[0] - 0.02 <= pos[0] <= hi[0] + 0.02 and lo[1] - 0.02 <= pos[1] <= hi[1] + 0.02
        for name, (pos, _) in out.probes.items()
        if name.startswith("stroke")
    )
    return {"over_target": bool(on), "ok": bool(on)}


@dataclass(frozen=True)
class Task:
    held_role: str  # the role whose object the gripper holds
    target_role: str  # the role whose object it acts on
    program: Callable[[Geometry, Variant, bool], list[Step]]
    check: Callable[[SceneObject, SceneObject, Outcome], dict]
    pours: bool = False  # the held object's contents run out of its opening
    turns: bool = False  # the held object is turned over (pouring or dumping): either way will do
    motion: str = ""  # the class of motion it is (a learned verb's), else the predicate's own program
    square: bool = False  # the held object stays square to the table (the program turns it, if at all)
    wide: bool = False  # the hand may also turn by WIDE_TURNS while carrying (a tool with a long handle)
    sideways: bool = False  # side grasps are tried first where the object fits (as for pouring), not poured
    source_role: str = ""  # the role of a third object the motion works with (serve: what it scoops from)
    # ... that object, once the instruction's objects are known (`with_source`)
    source: SceneObject | None = field(default=None, compare=False)

    def with_source(self, objects: dict[str, SceneObject]) -> Task:
        """The task for the instruction's `objects` (role -> object): with its source when it has one."""
        return replace(self, source=objects[self.source_role]) if self.source_role else self


TASKS = {
    "pour": Task("Theme", "Destination", program_pour, check_pour, pours=True, turns=True),
    "fill": Task("Theme", "Destination", program_pour, check_pour, pours=True, turns=True),
    "sprinkle": Task("Theme", "Destination", program_sprinkle, check_sprinkle, pours=True, turns=True),
    "season": Task("Instrument", "Theme", program_sprinkle, check_sprinkle, pours=True, turns=True),
    "heat": Task("Theme", "Instrument", program_place, check_in_target),
    "fry": Task("Theme", "Instrument", program_place, check_in_target),
    "blend": Task("Theme", "Destination", lambda g, v, h: program_place(g, v, h, press=True), check_in_target),
    "dump": Task("Theme", "Destination", program_dump, check_in_target, turns=True),
    "dip": Task("Theme", "Destination", program_dip, check_dip),
    "brush": Task("Theme", "Destination", program_stroke, check_stroke),
    "rub": Task("Theme", "Destination", program_stroke, check_stroke),
}

# How a Theme is put at a Destination, by the Destination's motion (household.json; a kitchen container
# takes things placed into it): the motions of every learned verb whose frame has both roles
MOTIONS = {
    "place": Task("Theme", "Destination", program_place, check_in_target, motion="place"),
    "dispose": Task("Theme", "Destination", program_place, check_in_bin, motion="dispose"),
    "hand over": Task("Theme", "Destination", program_hand_over, check_handed_over, motion="hand over"),
}
# placing into a receptacle entered through its front (a cupboard): held from the side first where the
# object fits between the fingers (the hand then goes in level behind it, not above it)
PUT_IN = Task("Theme", "Destination", program_put_in, check_in_target, motion="place", sideways=True)
# the motions of a learned verb's class that work with a tool (the Instrument) on the Theme
TOOL_MOTIONS = {
    "stir": Task("Instrument", "Theme", program_stir, check_stir, turns=True, motion="stir"),
    "wipe": Task("Instrument", "Theme", program_wipe, check_wiped, motion="wipe"),
    "cut": Task("Instrument", "Theme", program_cut, check_cut, turns=True, motion="cut", square=True),
    "cover": Task("Instrument", "Theme", program_cover, check_covered, motion="cover", square=True),
}
# a verb of the serve class: a ladle (the Instrument, stated or found on the table) carries the Theme's
# content into the Destination
SERVE = Task("Instrument", "Destination", program_serve, check_served, motion="serve", source_role="Theme", wide=True)
# whether a tool can do its class's motion to the Theme at all (its shape): others are tried in the world
# why a tool motion's tool cannot act on its Theme (None when it can): a template of {tool} and {theme}
TOOL_UNFIT = {"wipe": why_not_wipe, "cut": why_not_cut, "cover": why_not_cover, "stir": why_not_stir}
# a verb of the cook class puts the Theme in or on what cooks it, as the paper's heat does: the Instrument
# ("reheat the soup in the microwave", "bake the bread in the oven") or, when the verb takes none, the
# Destination; by the role it is put at
COOK = {
    role: Task("Theme", role, program_place, check_in_target, motion="cook") for role in ("Instrument", "Destination")
}

# opening a drawer or a lid or shutting it (`opening_steps`, planned beside the task): a part of putting
# something into it, checked with the task
OPENING = Task("", "", lambda g, v, holding: [], lambda held, target, out: {"ok": True}, motion="opening")


def task_for(frame: Frame, verb_motion: str | None = None) -> Task | None:
    """The motion program of a completed frame: the paper's predicate's own; for a learned verb's frame
    that puts a Theme at a Destination, the motion a household receptacle there asks for ("throw out the
    peel" into a bin: dispose; "bring me the soap": hand over; "put the milk away" in a drawer: place),
    or, at a kitchen container, placing when the verb's learned class (`verb_motion`) is `place` ("put the
    apple in the bowl"; not "cut the bread into the bowl"); for a frame with a tool, the tool motion of the
    verb's class ("whisk the batter with the spoon": stir; "slice the bread with the knife": cut; "cover the pot
    with the lid": cover) when the tool's shape can do it; a verb of the serve class ladles the Theme's
    content into the Destination ("ladle the soup into the bowl"); one of the cook class puts the Theme in
    or on what cooks it (`cooks`), and so does one of the place class given what cooks for a tool and no
    place. None when the robot has no motion for it."""
    if frame.predicate in TASKS:
        return TASKS[frame.predicate]
    roles = frame.role_map
    if verb_motion == "serve" and {"Theme", "Destination"} <= set(roles) and roles["Destination"] not in household():
        served = serves(roles["Theme"], roles["Destination"], roles.get("Instrument"))
        return SERVE if served else None
    # a placing verb whose frame names no place but a tool that cooks ("warm up the cookies", the corpus's
    # "warm it up in the microwave" learned as its Instrument) puts the Theme in it, as the cook class does
    if verb_motion == "cook" or (verb_motion == "place" and "Destination" not in roles):
        return _cook_task(roles)
    if verb_motion in TOOL_MOTIONS and {"Theme", "Instrument"} <= set(roles):
        return TOOL_MOTIONS[verb_motion] if unfit_tool(frame, verb_motion) is None else None
    if not {"Theme", "Destination"} <= set(roles):
        return None
    found = household().get(roles["Destination"])
    if found is not None:
        in_front = found.motion == "place" and found.opening is not None and found.opening.entry == "front"
        return PUT_IN if in_front else MOTIONS[found.motion]
    return MOTIONS["place"] if verb_motion == "place" else None


def unfit_tool(frame: Frame, verb_motion: str | None) -> str | None:
    """Why the tool of a frame of a learned verb cannot do its class's tool motion on the Theme (a template
    of {tool} and {theme}: "the {tool} has no blade"); None when it can, or when the verb's class has no
    tool motion or the frame no tool."""
    roles = frame.role_map
    if verb_motion not in TOOL_UNFIT or not {"Theme", "Instrument"} <= set(roles):
        return None
    return TOOL_UNFIT[verb_motion](roles["Instrument"], roles["Theme"])


def cooks(label: str) -> bool:
    """Whether a Theme can be put in or on `label` to be cooked there: a kitchen container with walls (a
    pan, a pot, a microwave, an oven), or a household place things are put (the stove, a shelf); not a bin,
    the person, or a tool."""
    found = household().get(label)
    if found is not None:
        return found.motion == "place"
    return _walled(label) and label not in TOOLS


def _cook_task(roles: dict[str, str]) -> Task | None:
    """The cook class's task for a frame's roles: the Theme put at its Instrument, else its Destination."""
    role = "Instrument" if "Instrument" in roles else "Destination"
    return COOK[role] if "Theme" in roles and role in roles and cooks(roles[role]) else None
