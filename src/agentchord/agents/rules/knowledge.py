"""What the offline reasoner knows about objects and skills, independent of any task.

Object categories come from names and descriptions (a lexicon) and from geometry
(tall, flat, wider than one gripper). Skill parameters are the ones measured to work
on the simulated ALOHA (the ViperX grippers, the 50 Hz controller): a pour offset and
tilt, the heights of a two-gripper handover on one bar, clearance lifts, park poses.
They are knowledge about the robot and object categories, not about a task: the same
numbers serve every scene in which the category appears.
"""

from __future__ import annotations

from collections.abc import Iterable

from agentchord.agents.scene import SceneObject

# --- categories ---------------------------------------------------------------------------

#: Words that make an object a container (something can be poured or put into it).
CONTAINER_WORDS = frozenset({"cup", "mug", "glass", "bowl", "tray", "box", "basket", "bin", "pot", "jar"})
#: An object no larger than this (m) is handed over from a top grasp by its upper half, raised by
#: HANDOFF_GIVER_RAISE (m): the receiver takes its lower half under the giver's fingertips.
SMALL_HANDOFF = 0.06
HANDOFF_GIVER_RAISE = 0.012
#: Where the giver brings a small object for the hand-off (m; x mirrored for a left giver).
HANDOFF_POSE = (0.02, 0.5, 0.22)
#: Where the inserting arm presents the peg (its tool; x on its own side) and where the other arm holds the socket (m).
INSERT_PRESENT = (0.14, 0.5, 0.2)
INSERT_HOLD = (0.1, 0.5, 0.2)
#: How far (m) from its centre along its long axis each of the pair is taken: near its far end.
INSERT_GRIP_OFFSET = 0.03
#: Words for an object with an opening at its end, not on top (a peg goes in along its axis, in the air).
SOCKET_WORDS = frozenset({"socket", "sleeve", "tube", "receptacle"})
#: Words that make an object a pouring vessel.
POURABLE_WORDS = frozenset({"bottle", "jug", "pitcher", "kettle", "carafe", "flask"})
#: Suffixes of a cloth's corner points (bottom = near edge, top = far edge; l = -x, r = +x).
CLOTH_CORNERS = ("bl", "br", "tl", "tr")
#: Widest horizontal extent one parallel gripper closes on (m); wider objects take both arms.
ONE_HAND_WIDTH = 0.10
#: An object this much taller than wide stands upright and is grasped from the side.
TALL_RATIO = 1.5
#: Thinner than this (m) is flat: grasped from the top and lifted clear before it is carried.
FLAT_HEIGHT = 0.03

# --- skill parameters (measured on the simulated ALOHA) -----------------------------------

#: Tool offset from the receiving container's top point for pouring (m), and the tool's yaw.
POUR_OFFSET = (0.0, -0.09, 0.08)
POUR_YAW = 180.0
#: Roll of the tool that tips the vessel's mouth into the container (deg).
POUR_TILT = 95.0
#: Smallest tilt (deg) that counts as pouring, and the container-mouth tolerance.
POUR_MIN_TILT = 70.0
#: Where the holding arm presents a container to be poured into (m), and its yaw.
RECEIVE_POSE = (0.0, 0.62, 0.15)
#: Where the giving arm holds an object for a handover (m).
HANDOVER_POSE = (0.0, 0.50, 0.25)
#: Side-grasp heights (fraction of the object's height) of the giver and the receiver of a
#: handover: two grippers on one bar need ~11 cm between their tool centres.
HANDOVER_GIVER_HEIGHT = 0.85
HANDOVER_RECEIVER_HEIGHT = 0.2
#: A giver's grip below this fraction of the bar's height leaves the receiver's fingers no room.
HANDOVER_GRIP_LOW = 0.75
#: ... judged only while the bar stands within this tilt (deg): lying in the hand it has no high and low.
HANDOVER_STANDING_DEG = 30.0
#: The giver's retreat after opening (m, along its own side of the table).
HANDOVER_RETREAT = 0.10
#: Clearance lift of a flat object before it is carried (m), and of a tray held by both arms.
FLAT_LIFT = 0.06
TWO_ARM_LIFT = 0.05
#: How far inside a wide object's end its handle is grasped (m).
HANDLE_INSET = 0.025
#: Poses where an arm holding something waits while the other arm works near it (m, yaw).
PARK_POSE = {"left": ((-0.12, 0.72, 0.22), 0.0), "right": ((0.16, 0.42, 0.25), 180.0)}
#: Table-setting convention: utensils lie this far (m) left and right of the plate's centre.
BESIDE_DISTANCE = 0.17
#: Release height above a container's floor or a support's top (m).
RELEASE_CLEARANCE = 0.005
#: Folding a cloth: carry the near corner to this offset from the far corner (m), first high
#: and short of it, then above it; release it this far short of the far corner, this high.
FOLD_LIFT_OFFSET = (0.0, -0.17, 0.10)
FOLD_OVER_OFFSET = (0.0, -0.02, 0.10)
FOLD_PLACE_OFFSET = (0.0, -0.04)
FOLD_RELEASE_HEIGHT = 0.012
#: A pinch of a flat cloth corner: just below the vertex, no lift.
PINCH_DEPTH = 0.002

# --- monitor thresholds -------------------------------------------------------------------

#: Drift of an object that must stay put (m): the larger of this and a fraction of its size.
DRIFT_MIN = 0.02
DRIFT_FRACTION = 0.5
#: Tilt (deg) beyond which an upright object has tipped over.
TIP_DEG = 30.0
#: Persistence window (ticks) of every monitor: 60 ms at 50 Hz.
WINDOW = 3
#: Fewest visible points of a tracked object (RGB-D) before it counts as lost from view.
MIN_POINTS = 30


def words(obj: SceneObject) -> set[str]:
    """The words naming an object: its name's parts and its description."""
    return set(obj.name.lower().replace("_", " ").split()) | set(obj.description.lower().replace(",", " ").split())


def is_container(obj: SceneObject) -> bool:
    """Whether things can be poured or put into the object."""
    return bool(words(obj) & CONTAINER_WORDS)


def is_socket(obj: SceneObject) -> bool:
    """Whether the object is taken by inserting another along its axis (a socket)."""
    return bool(words(obj) & SOCKET_WORDS)


def is_pourable(obj: SceneObject) -> bool:
    """Whether the object is a vessel to pour from."""
    return bool(words(obj) & POURABLE_WORDS)


def is_tall(obj: SceneObject) -> bool:
    """Whether the object stands upright, taller than wide (grasped from the side)."""
    return obj.extent[2] > TALL_RATIO * max(obj.extent[0], obj.extent[1]) or (is_pourable(obj) and obj.extent[2] > obj.extent[0])


def keeps_upright(obj: SceneObject) -> bool:
    """Whether the object must stay upright (it holds liquid or stands on end)."""
    return is_tall(obj) or (is_container(obj) and not is_wide(obj))


def is_flat(obj: SceneObject) -> bool:
    """Whether the object is flat (utensils, plates): top grasp, lifted clear before carrying."""
    return obj.extent[2] < FLAT_HEIGHT


def is_wide(obj: SceneObject) -> bool:
    """Whether one gripper cannot hold the object (it takes both arms, by its ends)."""
    return min(obj.extent[0], obj.extent[1]) > ONE_HAND_WIDTH or max(obj.extent[0], obj.extent[1]) > 2.5 * ONE_HAND_WIDTH


def is_cloth_corner(name: str) -> bool:
    """Whether ``name`` is a cloth's corner point (``towel_bl``)."""
    return "_" in name and name.rsplit("_", 1)[1] in CLOTH_CORNERS


def cloth_names(names: Iterable[str]) -> list[str]:
    """Cloths whose four corner points are all in ``names``."""
    names = set(names)
    stems = sorted({n.rsplit("_", 1)[0] for n in names if is_cloth_corner(n)})
    return [s for s in stems if all(f"{s}_{c}" in names for c in CLOTH_CORNERS)]


def near_arm(obj: SceneObject) -> str:
    """The arm on the object's side of the table (left: x < 0)."""
    return "left" if obj.pos[0] < 0.0 else "right"


def grasp_args(obj: SceneObject) -> dict:
    """Arguments of a one-arm ``grasp`` of ``obj`` by its category."""
    if is_cloth_corner(obj.name):
        return {"obj": obj.name, "mode": "top", "offset": [0.0, 0.0, -PINCH_DEPTH], "lift": 0.0}
    if is_flat(obj) or not (is_tall(obj) or is_container(obj)):
        return {"obj": obj.name, "mode": "top"}
    return {"obj": obj.name}  # auto: from the side when upright and tall, from the top when fallen


def handle_offset(obj: SceneObject, arm: str) -> list[float]:
    """Object-frame offset of the handle an arm takes on a wide object (its end on the arm's side)."""
    half = 0.5 * max(obj.extent[0], obj.extent[1]) - HANDLE_INSET
    return [-half if arm == "left" else half, 0.0, 0.0]


def drift_tolerance(obj: SceneObject) -> float:
    """Drift (m) of ``obj`` that counts as moved: scaled to its footprint."""
    return round(max(DRIFT_MIN, DRIFT_FRACTION * min(obj.extent[0], obj.extent[1])), 3)


# --- the table and its regions (every scene has it) ----------------------------------------

#: The centre (x, y) of the table's reachable workspace (m). x grows to the robot's right;
#: y grows away from the front edge (the near edge, where a cloth's bottom corners lie).
TABLE_CENTER = (0.0, 0.52)
#: Half-sizes (m) of the workspace: a side, an edge or a corner lies this far from the centre.
TABLE_HALF = (0.12, 0.09)
#: Words for the table itself.
TABLE_WORDS = frozenset({"table", "tabletop", "surface", "desk", "counter", "workspace"})
#: Words for a part of something (a region of the table, or a side of an object).
PART_WORDS = frozenset({"side", "half", "edge", "end", "corner", "part", "area", "region", "zone", "spot", "portion", "center", "middle"})
#: Direction words -> unit (dx, dy) on the table.
DIRECTION_WORDS = {
    "left": (-1.0, 0.0), "right": (1.0, 0.0),
    "front": (0.0, -1.0), "near": (0.0, -1.0), "bottom": (0.0, -1.0), "backward": (0.0, -1.0),
    "back": (0.0, 1.0), "far": (0.0, 1.0), "top": (0.0, 1.0), "rear": (0.0, 1.0), "forward": (0.0, 1.0),
    "center": (0.0, 0.0), "middle": (0.0, 0.0),
}
#: Gap (m) between an object placed next to, in front of or behind another and that object.
NEXT_TO_GAP = 0.04
#: How far (m) ``move X forward|left|...`` moves an object when no region names the direction.
NUDGE = 0.10
#: Category synonyms: a word people use -> the word scene descriptions use.
SYNONYMS = {
    "mug": "cup", "glass": "cup", "beaker": "cup", "jug": "bottle", "flask": "bottle", "pitcher": "bottle",
    "cube": "block", "brick": "block", "cloth": "towel", "napkin": "towel", "rag": "towel", "pod": "capsule",
    "platter": "tray", "dish": "plate", "teaspoon": "spoon",
}


def table_point(words: Iterable[str]) -> tuple[float, float] | None:
    """The table position (x, y) a region's words name (``left side``, ``front right corner``, ``centre``); ``None`` if none."""
    dx = dy = 0.0
    named = False
    for word in words:
        if word in DIRECTION_WORDS:
            ux, uy = DIRECTION_WORDS[word]
            dx, dy, named = dx or ux, dy or uy, True
    if not named:
        return None
    return (round(TABLE_CENTER[0] + dx * TABLE_HALF[0], 3), round(TABLE_CENTER[1] + dy * TABLE_HALF[1], 3))


def beside_distance(obj: SceneObject, anchor: SceneObject) -> float:
    """Centre distance (m) of ``obj`` placed beside ``anchor``: the table-setting convention for a
    utensil beside a plate, else the two half-sizes and a gap."""
    if is_flat(obj) and is_flat(anchor):
        return BESIDE_DISTANCE
    return round(0.5 * max(obj.extent[:2]) + 0.5 * max(anchor.extent[:2]) + NEXT_TO_GAP, 3)
