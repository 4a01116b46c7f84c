"""Label the blind evaluation set (issue 59): the goal each instruction means, written to labels.yaml.

The twelve writers' files (writer_A.yaml ... writer_L.yaml) hold 690 instructions, each with the
writer's own ``meaning`` (the intended end state) and ``possible``. This script states, per id, the
goal the instruction means as a goal spec's goals (``agentchord schema goal``), written with the
label helpers of ../build_corpus.py and its conventions (docs/language.md): ``put X down``/``back``
is ``placed`` with no place;
``beside``/``next to`` is ``rel()`` (the side the object is on; a flat utensil beside a flat anchor
at 17 cm, turned along y); ``move X left|right|nearer`` a bit is ``nudge()`` (10 cm), and
``forward`` for the coffee tray is its ``forward`` region; an object still held when the instruction
ends is put back where it was, by the arm that holds it (``complete()``); an arm is in a goal only
when it is said for that clause (an arm addressed as a heading, ``Right arm: a, b, c``, is said for
every step under it) or the object was taken or handed over by a said arm. ``refused`` where the
scene cannot do what is asked (an object, place or action it lacks) or the goal language cannot say
it (the reason is in ``WHY``).

Labelling policy for amounts: ``poured`` states no amount, so a vague amount (``some``, ``a
little``, ``a splash``, ``fill it up``) is a pour; a stated fraction (``about half``, ``till it's
half full``) or quantity (``approx. 50 mL``) cannot be said and is refused.

The labels were written from the instructions and the writers' meanings only: no composer, planner
or benchmark was run on the instructions. Where an instruction and its writer's meaning disagree, the
instruction's words decide (what a reader could know); the entry's comment says so. Each goal list is validated as a ``GoalSpec`` and checked
against its scene (``goal_problems``: the objects and regions exist, things fit).

    .venv/bin/python tests/data/language/blind/build_labels.py   # rewrites labels.yaml
"""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).parent
sys.path.insert(0, str(HERE.parent))

from build_corpus import (
    REFUSE,
    _Dumper,
    _Flow,
    _scene,
    at,
    complete,
    fold,
    hand,
    into,
    nudge,
    on,
    pour,
    put,
    region,
    rel,
)

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules.feasibility import goal_problems
from agentchord.agents.rules.goals import GoalSpec
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

P1, P2, T, H, C, W, B = (
    "single_arm_pour_water",
    "dual_arm_pour_water",
    "rearrange_table",
    "handover_block",
    "setup_coffee_tray",
    "fold_towel",
    "blocks_and_cup",
)


def at_xy(obj: str, x: float, y: float, arm: str | None = None) -> dict:
    """``obj`` placed at a table point (m) that no region word names (another object's spot, beside a region)."""
    goal = {"kind": "placed", "obj": obj, "at": [round(x, 3), round(y, 3)]}
    if arm:
        goal["arm"] = arm
    return goal


def spot(task: str, obj: str) -> tuple[float, float]:
    """Where ``obj`` stands at the start (the scene the labels are written in: seed 0)."""
    pos = _scene(task)[obj].pos
    return round(float(pos[0]), 3), round(float(pos[1]), 3)


def beside_region(task: str, obj: str, name: str, arm: str | None = None) -> dict:
    """``obj`` placed just beside (outside) a named region, on the side the object is on: the
    region's radius, the object's half-size and the 4 cm gap of ``rel()``."""
    reg = next(r for r in task_regions(SIM_TASKS[task]) if r.name == name)
    o = _scene(task)[obj]
    d = reg.radius + 0.5 * max(o.extent[:2]) + 0.04
    side = -1.0 if o.pos[0] < reg.center[0] else 1.0
    return at_xy(obj, reg.center[0] + side * d, reg.center[1], arm)


# Frequently meant goals.
POUR1 = [pour(), put("bottle")]
POUR2 = [pour(hold=True), put("cup"), put("bottle")]
#: The dual pour with the cup lifted by the left arm and the right arm pouring (the bottle's put-down
#: has no arm: it was not taken by a said arm, the pour was; as corpus_test's hand entries).
POUR2_LR = [pour(arm="right", hold=True), put("cup", "left"), put("bottle")]
FORK_L = rel(T, "fork", "plate", "left")
SPOON_R = rel(T, "spoon", "plate", "right")
SETTING = [FORK_L, SPOON_R]
SETTING_ARMS = [rel(T, "fork", "plate", "left", "left"), rel(T, "spoon", "plate", "right", "right")]
HANDOVER = [hand("block"), region("block", "target", "right")]
COFFEE = [into("capsule", "tray"), region("tray", "forward")]
COFFEE_LEFT = [into("capsule", "tray", "left"), region("tray", "forward")]
CAPSULE_HANDOVER = [hand("capsule"), into("capsule", "tray", "right")]
FOLD = [fold()]
TARGET = [region("block", "target")]
TRAY_FWD = [region("tray", "forward")]

LABELS: dict[str, object] = {
    # --- writer A ----------------------------------------------------------------------------
    # "right arm:" heads the whole instruction: said for the put-down too.
    "A-001": [pour(arm="right"), put("bottle", "right")],
    "A-002": POUR1,  # "some water": no amount to state (policy above)
    "A-003": POUR1,
    "A-004": POUR1,  # "fill the cup up a little": a vague amount, a pour
    "A-005": REFUSE,
    "A-006": REFUSE,
    # The left arm picks the bottle up (said), pours, and stands it beside the cup (on the side it is on: right).
    "A-007": [pour(arm="left"), rel(P1, "bottle", "cup", "beside", "left")],
    "A-008": POUR2_LR,
    "A-009": POUR2_LR,
    "A-010": POUR2,
    "A-011": POUR2,  # "do the pour with the cup held up": hold_target, arms unsaid
    "A-012": POUR2,
    "A-013": POUR2_LR,
    "A-014": [pour(arm="left", hold=True), put("cup", "right"), put("bottle")],
    "A-015": SETTING,
    "A-016": SETTING_ARMS,
    "A-017": SETTING,
    "A-018": [SPOON_R],
    "A-019": SETTING,
    "A-020": [on("spoon", "plate")],
    "A-021": REFUSE,
    "A-022": HANDOVER,
    "A-023": HANDOVER,
    "A-024": HANDOVER,  # "via handover": left to right (the block is on the left, the target on the right)
    "A-025": HANDOVER,
    # "then just hold it there": the end state (the block held in the air) cannot be said: every
    # goal spec ends with the arms at home and the convention puts a held object back down.
    "A-026": REFUSE,
    "A-027": TARGET,
    "A-028": REFUSE,
    "A-029": COFFEE,
    "A-030": COFFEE_LEFT,
    "A-031": COFFEE,  # "farther back" = away from the robot (the writer's meaning): the forward spot
    "A-032": COFFEE,
    "A-033": [into("capsule", "tray")],
    # "forward about 10 cm": the scene's forward spot (12 cm away; the direction names the region).
    "A-034": TRAY_FWD,
    "A-035": CAPSULE_HANDOVER,
    "A-036": FOLD,
    "A-037": FOLD,
    "A-038": FOLD,  # the natural fold: near corners onto far corners
    "A-039": FOLD,
    "A-040": FOLD,
    "A-041": FOLD,
    "A-042": REFUSE,
    "A-043": REFUSE,
    "A-044": [into("red_block", "cup")],
    "A-045": [on("blue_block", "red_block")],
    "A-046": [into("red_block", "cup"), into("blue_block", "cup")],
    # Handed right -> left, then the left arm puts it beside the red cube (on its right, the side it is on).
    "A-047": [hand("blue_block", "right", "left"), rel(B, "blue_block", "red_block", "beside", "left")],
    "A-048": [on("red_block", "blue_block"), nudge(B, "cup", "right")],  # "over to the right a bit": a nudge
    "A-049": [into("blue_block", "cup")],
    # "way over to the left" / "over to the right side": the table's side points (the red block is
    # already near the left side point; no farther place is sayable without inventing coordinates).
    "A-050": [at("red_block", "left"), at("blue_block", "right")],
    # --- writer B ----------------------------------------------------------------------------
    "B-001": POUR1,
    "B-002": [pour(arm="right"), put("bottle", "right")],  # the right hand takes the bottle
    "B-003": [pour(arm="right"), put("bottle", "right")],  # "right arm:" heads grab, pour, set down
    "B-004": POUR1,  # "just a little ... don't overflow": a vague amount, a pour
    "B-005": [rel(P1, "cup", "bottle")],  # next to the bottle, on its left (where the cup is)
    "B-006": REFUSE,
    "B-007": [rel(P1, "bottle", "cup", "left")],
    # "pour water into it with the bottle in your right hand": the right arm pours; the bottle's
    # put-down has no arm (it was not taken in a clause of its own).
    "B-008": POUR2_LR,
    "B-009": POUR2_LR,
    # "You can hold the cup up ... if that's easier": optional, so no hold_target; the cup never
    # moves, the bottle goes back.
    "B-010": POUR1,
    "B-011": [hand("cup", "left", "right"), rel(P2, "cup", "bottle", "beside", "right")],
    # Swap the two places: absolute points (each the other's start). Expressible as the end state,
    # though the planner has to clear the cup's spot first.
    "B-012": [at_xy("bottle", *spot(P2, "cup")), at_xy("cup", *spot(P2, "bottle"))],
    "B-013": POUR2,  # "one in each hand": no arm named for which
    # Held cup, a little water (a pour), then the cup put down "a bit more to the left" (a nudge
    # from where it stood) and the bottle back.
    "B-014": [pour(hold=True), nudge(P2, "cup", "left"), put("bottle")],
    "B-015": SETTING,
    "B-016": SETTING_ARMS,
    "B-017": SETTING,
    "B-018": [on("spoon", "plate"), on("fork", "plate")],
    # "to the left side, near to the fork": beside the fork (its right side, where the spoon comes
    # from); by the helper's flat-anchor rule that is 17 cm and turned along y.
    "B-019": [rel(T, "spoon", "fork")],
    # "a bit closer to the plate": the writer means near (left of) the plate: beside it.
    "B-020": [FORK_L],
    "B-021": REFUSE,
    "B-022": HANDOVER,
    "B-023": HANDOVER,
    "B-024": TARGET,
    "B-025": REFUSE,
    "B-026": [hand("block"), put("block", "right")],  # back where it was, by the right arm
    # "next to the target, not on it": the target is a region, not an object, so beside it is an
    # absolute point just outside its radius, on the side the block comes from (the left).
    "B-027": [hand("block"), beside_region(H, "block", "target", "right")],
    "B-028": REFUSE,
    "B-029": COFFEE,
    "B-030": COFFEE_LEFT,
    "B-031": [into("capsule", "tray")],
    "B-032": TRAY_FWD,
    "B-033": COFFEE,
    "B-034": CAPSULE_HANDOVER,
    "B-035": REFUSE,
    "B-036": FOLD,
    "B-037": FOLD,
    "B-038": FOLD,
    "B-039": FOLD,
    "B-040": FOLD,
    "B-041": REFUSE,
    "B-042": REFUSE,
    "B-043": [into("red_block", "cup")],
    "B-044": [into("red_block", "cup"), into("blue_block", "cup")],
    "B-045": [on("red_block", "blue_block")],
    "B-046": [rel(B, "red_block", "cup", "left", "left"), rel(B, "blue_block", "cup", "right", "right")],
    "B-047": [nudge(B, "blue_block", "right")],  # "to the right a bit, maybe 10 cm": the 10 cm nudge
    # The blue block into the cup, then the cup (with it) onto the red block: expressible; the writer
    # means it (a 9 cm bowl on a 4 cm cube is precarious).
    "B-048": [into("blue_block", "cup"), on("cup", "red_block")],
    "B-049": [hand("red_block"), into("red_block", "cup", "right")],
    "B-050": [rel(B, "red_block", "blue_block", "behind")],
    # --- writer C ----------------------------------------------------------------------------
    "C-001": [pour(arm="right"), put("bottle", "right")],  # "Right arm, grab the bottle, ...": said for every step
    "C-002": POUR1,
    "C-003": REFUSE,
    "C-004": [pour(arm="left"), put("bottle")],  # "use the left arm to pour ..., and leave the bottle ...": the pour's arm
    # "a bit closer to the bottle": a nudge towards it (the bottle is to the cup's right), not beside it.
    "C-005": [nudge(P1, "cup", "right"), pour(arm="right"), put("bottle")],
    "C-006": POUR1,
    "C-007": REFUSE,
    "C-008": [hand("bottle", "right", "left"), pour(arm="left"), put("bottle", "left")],
    # "Then both of you set them back down": each arm its own object (the writer's meaning).
    "C-009": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "C-010": POUR2,
    # Nothing said about putting down: by the convention the held cup and bottle go back, each by
    # the arm holding it (the writer's meaning would end with the cup still held: not sayable).
    "C-011": POUR2_LR,
    "C-012": POUR2,
    # Both taken by said arms: the right arm pours, each puts its own back.
    "C-013": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "C-014": REFUSE,
    # End state only; "back standing in the same spot" could hint the cup was lifted, but the writer
    # says holding is not specified: the plain pour, the bottle back.
    "C-015": POUR1,
    "C-016": SETTING_ARMS,
    "C-017": SETTING,
    "C-018": SETTING,
    "C-019": SETTING,
    "C-020": [on("spoon", "plate")],
    "C-021": [rel(T, "fork", "plate", "right"), rel(T, "spoon", "plate", "left")],
    "C-022": REFUSE,
    "C-023": HANDOVER,
    "C-024": HANDOVER,
    "C-025": HANDOVER,
    "C-026": TARGET,
    "C-027": HANDOVER,
    "C-028": [region("block", "target", "right")],  # right arm only, no handover
    "C-029": HANDOVER,  # "pull the right arm back": the arms end at home (home: true)
    "C-030": COFFEE_LEFT,
    "C-031": COFFEE,
    "C-032": COFFEE,  # "forward about ten centimetres": the forward spot (12 cm)
    "C-033": COFFEE,
    "C-034": TRAY_FWD,
    "C-035": CAPSULE_HANDOVER,
    "C-036": REFUSE,
    "C-037": FOLD,
    "C-038": FOLD,
    "C-039": FOLD,
    "C-040": FOLD,
    "C-041": FOLD,
    "C-042": REFUSE,
    "C-043": FOLD,
    "C-044": [into("red_block", "cup")],
    "C-045": [into("blue_block", "cup", "right"), into("red_block", "cup", "left")],
    "C-046": [on("red_block", "blue_block")],
    "C-047": [hand("blue_block", "right", "left"), rel(B, "blue_block", "red_block", "beside", "left")],
    "C-048": [into("red_block", "cup"), into("blue_block", "cup")],  # "the bowl": the bowl-like white cup
    "C-049": REFUSE,
    "C-050": [nudge(B, "cup", "left"), into("blue_block", "cup")],
    # --- writer D ----------------------------------------------------------------------------
    "D-001": [pour(arm="right"), put("bottle")],  # "Using your right arm, pour ..., then stand ...": the pour's arm
    "D-002": POUR1,
    "D-003": [pour(arm="right"), put("bottle", "right")],  # "R arm:" heads grab, pour, put back
    "D-004": POUR1,
    "D-005": POUR1,
    "D-006": REFUSE,
    "D-007": [rel(P1, "cup", "bottle")],
    "D-008": REFUSE,
    "D-009": POUR2_LR,
    "D-010": POUR2,
    "D-011": POUR2_LR,
    "D-012": POUR2,
    # Both taken by said arms; "fill the cup up": a pour (no amount); "put them down side by side":
    # the cup back by the left arm, the bottle beside it (on its right, the side it is on) by the right.
    "D-014": [pour(arm="right", hold=True), put("cup", "left"), rel(P2, "bottle", "cup", "beside", "right")],
    "D-013": POUR2_LR,
    "D-015": [pour(arm="right"), hand("bottle", "right", "left"), at("bottle", "left", "left")],
    "D-016": [rel(P2, "bottle", "cup")],  # moved left to be right beside the cup: on the cup's right
    "D-017": SETTING,
    "D-018": SETTING_ARMS,
    "D-019": SETTING,
    "D-020": SETTING,
    "D-021": [on("spoon", "plate")],
    "D-022": SETTING,  # orientation unsaid: the setting convention (turned along y) still applies
    "D-023": [hand("spoon", "right", "left"), rel(T, "spoon", "plate", "left", "left")],
    "D-024": REFUSE,
    "D-025": HANDOVER,
    "D-026": HANDOVER,
    "D-027": TARGET,
    "D-028": HANDOVER,
    "D-029": TARGET,
    "D-030": HANDOVER,
    "D-031": [nudge(H, "block", "front")],  # "a little closer to you": 10 cm towards the robot
    "D-032": REFUSE,
    "D-033": COFFEE,
    "D-034": COFFEE_LEFT,
    "D-035": COFFEE,
    "D-036": [into("capsule", "tray")],
    "D-037": TRAY_FWD,
    "D-038": COFFEE,
    "D-039": COFFEE_LEFT,
    "D-040": REFUSE,
    "D-041": FOLD,
    "D-042": FOLD,
    "D-043": FOLD,
    "D-044": FOLD,
    "D-045": FOLD,
    "D-046": FOLD,
    "D-047": REFUSE,
    "D-048": REFUSE,
    "D-049": [into("red_block", "cup")],
    "D-050": [into("blue_block", "cup"), into("red_block", "cup")],
    "D-051": [on("red_block", "blue_block")],
    "D-052": [on("blue_block", "red_block")],
    "D-053": [rel(B, "red_block", "cup", "left")],
    # The left side point of the table is close to the red block (4 cm): the convention's point all the same.
    "D-054": [hand("blue_block", "right", "left"), at("blue_block", "left", "left")],
    "D-055": [into("red_block", "cup"), into("blue_block", "cup")],  # order unsaid: as named ("both blocks")
    "D-056": REFUSE,
    "D-057": [into("red_block", "cup"), rel(B, "blue_block", "cup", "right")],
    # The blue block already stands in front of the cup: the red one to its left makes the two side
    # by side in front of the cup, red on the left (moving both to new points would say the same less simply).
    "D-058": [rel(B, "red_block", "blue_block", "left")],
    "D-059": [nudge(B, "cup", "front"), into("blue_block", "cup")],
    "D-060": REFUSE,
    # --- writer E ----------------------------------------------------------------------------
    "E-001": POUR1,  # "some water": a vague amount, a pour
    # "use your right hand to pour ...": the pour's arm; the bottle was not taken in a clause of its own (as D-001).
    "E-002": [pour(arm="right"), put("bottle")],
    "E-003": [pour(arm="right"), put("bottle", "right")],  # "right arm:" heads grab, pour, set it back down
    "E-004": POUR1,  # end state: water in the cup, the bottle standing back where it was
    # "take the bottle with right hand": taken by a said arm, so its put-back is the right arm's too (as B-002).
    "E-005": [pour(arm="right"), put("bottle", "right")],
    "E-006": REFUSE,
    "E-007": [rel(P1, "cup", "bottle")],  # right beside the bottle, on its left (where the cup is; as B-005)
    "E-008": REFUSE,
    "E-009": POUR2_LR,
    "E-010": POUR2_LR,  # "tip the bottle into it with your right": the pour's arm; the bottle's put-down has none
    "E-011": POUR2,  # held cup, arms unsaid (the writer's "presumably left" is not in the words)
    "E-012": POUR2_LR,  # "First ... left arm. Second, pour ... using the right arm. Finally, put ... back"
    # "End state: cup has water, both ... upright on the table": no hold said (as C-015): the plain pour,
    # the bottle back.
    "E-013": POUR1,
    "E-014": POUR2_LR,  # "lift up the red cup with left and pour it some water by the right arm"
    # Picked up by the right arm (it is handed to the left) and handed over; nothing said about putting it
    # down: by the convention the left arm that holds it puts it back (the writer's meaning, the bottle
    # still held at the end, is not sayable; the instruction does not ask for it, unlike A-026/B-025).
    "E-015": [hand("bottle", "right", "left"), put("bottle", "left")],
    # Swap the two places: absolute points, each the other's start (as B-012), in the order said (the cup first).
    "E-016": [at_xy("cup", *spot(P2, "bottle")), at_xy("bottle", *spot(P2, "cup"))],
    "E-017": SETTING,  # "next to the plate": each on the side it is on (fork left, spoon right)
    "E-018": SETTING_ARMS,  # "both pointing away from you": the setting convention (turned along y)
    "E-019": SETTING,
    "E-020": [on("spoon", "plate")],
    # "line them both up beside the plate, handles toward you": beside on their own sides, turned along y
    # (the yaw of the long axis; which end is the handle is not sayable and no more than the setting).
    "E-021": SETTING,
    "E-022": SETTING,  # "by the plate", "do the same with the spoon": each beside it, on its own side
    "E-023": REFUSE,
    # "pass the spoon over to your left hand": from the right arm; the left lays it left of the plate (as D-023).
    "E-024": [hand("spoon", "right", "left"), rel(T, "spoon", "plate", "left", "left")],
    "E-025": [on("fork", "plate"), on("spoon", "plate")],  # in the order said
    "E-026": HANDOVER,
    "E-027": HANDOVER,
    "E-028": TARGET,
    "E-029": TARGET,  # "standing up like it is now": placed stands it upright anyway
    "E-030": HANDOVER,
    # "with your left arm, don't bother handing it over": the left arm alone (as C-028 for the right arm).
    "E-031": [region("block", "target", "left")],
    "E-032": REFUSE,
    # "Lift the block up a bit with your left hand and then just put it back down where it was": put back
    # is placed with no place (where it was taken from), by the said arm. The lift's height is manner, not
    # an end state. (Unlike D-056 no achieved goal is undone: nothing but the put-back is stated.)
    "E-033": [put("block", "left")],
    "E-034": COFFEE,  # "carry the tray forward with both hands": the tray's carry is two-handed anyway
    "E-035": COFFEE_LEFT,  # capsule "with your left hand"; "a bit further away from you": the forward spot
    "E-036": COFFEE,
    "E-037": COFFEE,  # "a little farther back" = away from the robot (the writer's meaning; as A-031)
    "E-038": COFFEE,  # "put it down a little further away": the forward spot
    "E-039": COFFEE,  # "bring it more far": the forward spot
    "E-040": [into("capsule", "tray")],  # "leave the tray where it is": no goal for the tray
    "E-041": REFUSE,
    "E-042": FOLD,
    "E-043": FOLD,
    "E-044": FOLD,  # near corners "toward the back": onto the far corners
    "E-045": FOLD,
    "E-046": FOLD,  # "half as deep, with the folded edge facing me": near corners onto far corners, crease near
    "E-047": REFUSE,
    "E-048": REFUSE,
    # "fold it in half the long way round... well you know, front to back": the words settle on front to
    # back (front corners onto the back ones): the fold.
    "E-049": FOLD,
    "E-050": REFUSE,
    "E-051": [into("red_block", "cup")],
    "E-052": [on("blue_block", "red_block")],
    "E-053": [into("red_block", "cup"), into("blue_block", "cup")],  # "Red one first, then the blue one"
    # Side unsaid: beside it on the side the blue block is on (its right).
    "E-054": [rel(B, "blue_block", "red_block")],
    # "the bowl": the bowl-like white cup (as C-048); the blue block just left of it.
    "E-055": [into("red_block", "cup"), rel(B, "blue_block", "cup", "left")],
    "E-056": [hand("red_block"), into("red_block", "cup", "right")],  # as B-049
    "E-057": [rel(B, "blue_block", "cup", "right"), into("red_block", "cup")],
    "E-058": [into("blue_block", "cup"), rel(B, "red_block", "cup", "front")],  # "right in front of": directly in front
    # Each block's arm said; order unsaid: as named (blue first; as C-045).
    "E-059": [into("blue_block", "cup", "right"), into("red_block", "cup", "left")],
    "E-060": [nudge(B, "cup", "right"), into("blue_block", "cup")],  # "over a bit to the right": a nudge (as C-050)
    # --- writer F ----------------------------------------------------------------------------
    # "... using your right hand, then stand the bottle back up": the pour's arm; the bottle was not
    # taken in a clause of its own (as D-001, E-002).
    "F-001": [pour(arm="right"), put("bottle")],
    "F-002": POUR1,  # "fill the cup up a bit": a vague amount, a pour (as A-004)
    "F-003": [pour(arm="right"), put("bottle", "right")],  # "right arm:" heads grab, pour, put it back
    "F-004": POUR1,  # "give water in the red cup": a pour; "put the bottle again on the table standing": back
    "F-005": POUR1,  # "a little water, just a splash": a vague amount; "don't leave the bottle lying": put back upright
    "F-006": POUR1,  # end state: water in the cup, the bottle standing about where it is now (as E-004)
    # The left arm picks the cup up (said) and sets it down beside the bottle, on its left (the side it is on).
    "F-007": [rel(P1, "cup", "bottle", "beside", "left")],
    "F-008": REFUSE,
    "F-009": REFUSE,
    "F-010": POUR2_LR,  # "Left hand holds the cup up, right hand pours ..., then put both back down"
    "F-011": POUR2_LR,
    "F-012": POUR2,  # "pour ... while holding it up": hold_target, arms unsaid
    "F-013": POUR2,  # "pick up the cup, ... pour ... with the other hand": held cup, no arm named
    # "Only a little bit of water, maybe a third of a cup": the vague amount is then stated as a fraction,
    # which poured cannot say (policy above; the held pour alone would be sayable, not the amount).
    "F-014": REFUSE,
    # Both taken by said arms ("cup in your left and bottle in your right"): the right arm pours with the
    # cup held; "at once" is manner. Putting them down is not asked: by the convention each arm puts its
    # own back (as C-011, C-013; the writer's end with both still held is not sayable).
    "F-015": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "F-016": [hand("cup", "left", "right"), rel(P2, "cup", "bottle", "beside", "right")],  # as B-011
    "F-017": [rel(P2, "bottle", "cup", "left")],
    "F-018": REFUSE,
    "F-019": SETTING,  # "both pointing away from me": the setting convention (turned along y)
    "F-020": SETTING_ARMS,  # "both should point forward": the setting convention
    "F-021": SETTING,  # "like a proper place setting": fork left, spoon right
    "F-022": [SPOON_R],  # "pointing straight ahead": the setting convention
    # "a bit closer to the plate": the writer means near (left of) the plate: beside it (as B-020, the same
    # words in the same scene).
    "F-023": [FORK_L],
    "F-024": SETTING,  # "lying up-and-down instead of sideways": turned along y, the setting convention
    "F-025": [on("spoon", "plate")],
    # No arm named: "pass it to your other hand", so the giver is the arm that picks it up, the left (the
    # fork lies on the left; as A-024); the right arm, which receives it, lays it right of the plate.
    "F-026": [hand("fork", "left", "right"), rel(T, "fork", "plate", "right", "right")],
    "F-027": REFUSE,
    "F-028": HANDOVER,
    "F-029": TARGET,
    "F-030": HANDOVER,  # "it": the block (the scene's only block)
    "F-031": TARGET,  # "the marked spot on the right": the target region
    # "from one hand to the other": left to right (the block is on the left, the target on the right; as
    # A-024); "inside the circle": the target; "keep it standing up": placed stands it upright anyway.
    "F-032": HANDOVER,
    # "lift the block up a little and put it back down where it was": the put-back, no arm (as E-033).
    "F-033": [put("block")],
    # "right beside the target, not on it": a point just outside its radius, on the side the block is on (as B-027).
    "F-034": [beside_region(H, "block", "target")],
    "F-035": REFUSE,
    "F-036": COFFEE_LEFT,  # "with your left hand", then "both hands ... a bit further forward": the forward spot
    "F-037": COFFEE,  # "pod": the capsule; "a little farther away": the forward spot
    "F-038": COFFEE,  # "pick the tray up by its handles and move it forward a bit": the forward spot
    "F-039": COFFEE,  # "about ten centimetres forward": the forward spot (12 cm; as C-032)
    "F-040": COFFEE,  # "the tray sitting a little further from you with the capsule in it" (as A-031)
    "F-041": COFFEE_LEFT,  # "set it down further away": the forward spot
    "F-042": COFFEE,  # "carry tray with two hand to the front": the forward spot
    "F-043": TRAY_FWD,  # "leave the capsule where it is": no goal for the capsule
    "F-044": REFUSE,
    "F-045": FOLD,
    "F-046": FOLD,
    "F-047": FOLD,  # "bottom" corners (near) folded up to the "top" edge (far); each arm a near corner
    "F-048": FOLD,  # the near edge onto the far edge
    "F-049": FOLD,
    "F-050": REFUSE,
    "F-051": FOLD,  # "half as deep, with the fold nearest to you": near corners onto far corners, crease near (as E-046)
    "F-052": REFUSE,
    "F-053": [into("red_block", "cup")],
    "F-054": [on("blue_block", "red_block")],
    # "the white bowl": the bowl-like white cup (as C-048); "next to the bowl", side unsaid: the side the
    # blue block is on (it stands almost straight in front of the cup, 1.5 cm to its right: right).
    "F-055": [into("red_block", "cup"), rel(B, "blue_block", "cup")],
    "F-056": [into("blue_block", "cup", "right"), into("red_block", "cup", "left")],  # "Right arm, ... Left arm, after that"
    "F-057": [into("red_block", "cup"), into("blue_block", "cup")],  # "doesn't matter which one goes first": as D-055
    # "side by side on the left of the cup": a row left of the cup (neither block is there now: the red one
    # is left and in front of it), keeping their present order (red on the left of blue): the blue block
    # just left of the cup, the red one just left of the blue one.
    "F-058": [rel(B, "blue_block", "cup", "left"), rel(B, "red_block", "blue_block", "left")],
    "F-059": [hand("red_block", "left", "right"), rel(B, "red_block", "cup", "right", "right")],
    "F-060": REFUSE,
    # --- writer G ----------------------------------------------------------------------------
    # "pour water into cup w/ right arm, bottle back upright after": the pour's arm; the bottle was not taken
    # in a clause of its own and its put-back names no arm (as D-001, E-002).
    "G-001": [pour(arm="right"), put("bottle")],
    # "use your right hand to pour some water into the red cup": the pour's arm; "some": a vague amount; the
    # put-down is unsaid and the bottle was not taken in a clause of its own: no arm (as E-002, J-005).
    "G-002": [pour(arm="right"), put("bottle")],
    "G-003": REFUSE,
    # "take the bottle with the right arm and pour ..., after put the bottle back standing": taken by a said
    # arm, so the pour and the put-back are the right arm's (as E-005).
    "G-004": [pour(arm="right"), put("bottle", "right")],
    "G-005": POUR1,  # end state: water in the red cup, the bottle still standing (as E-004)
    "G-006": POUR1,  # "pour a little into the cup, then set it back down": a vague amount; "it": the bottle
    # "First grab the bottle with your right arm. Second, tip it over the cup ... Third, stand the bottle back
    # up": taken by a said arm, so the pour and the put-back are the right arm's (as E-005).
    "G-007": [pour(arm="right"), put("bottle", "right")],
    # "use your left hand to pick up the cup and put it down right next to the bottle": the left arm takes it
    # and sets it beside the bottle, on its left (the side it is on; as F-007).
    "G-008": [rel(P1, "cup", "bottle", "beside", "left")],
    "G-009": REFUSE,
    # "Left arm lift the cup. Right arm pour into it. Then put both down.": the put-down is a sentence of its
    # own with no arm; the cup was taken by the said left arm, the bottle not in a clause of its own (as D-009).
    "G-010": POUR2_LR,
    "G-011": POUR2_LR,  # "hold the cup up with your left hand while your right hand pours ... Afterwards, set them both back"
    "G-012": POUR2,  # "hold the cup up in the air while u do it ... put everything back after": held cup, arms unsaid
    # "Left hand take the cup up, right hand take the bottle and pour ...": both taken by said arms; the right
    # arm pours with the cup held, each puts its own down (as C-013).
    "G-013": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    # "Just a splash": a vague amount; "Keep the cup off the table with one arm while you pour with the other
    # one": held cup, no arm named (as B-013, F-013).
    "G-014": POUR2,
    # "Pick the cup up with your left hand and pass it over to the right one": nothing said about putting it
    # down, so by the convention the right arm that holds it puts it back (as E-015; the writer's meaning,
    # the cup still held at the end, is not sayable, and the instruction does not ask for it).
    "G-015": [hand("cup", "left", "right"), put("cup", "right")],
    # "right in front of the bottle": directly in front, nearer the robot (as E-058).
    "G-016": [rel(P2, "cup", "bottle", "front")],
    # End state and "Do the pouring with the cup held up, not on the table": held cup, arms unsaid; both back
    # "roughly where they started": put back.
    "G-017": POUR2,
    "G-018": SETTING,  # "set the table - fork and spoon next to the plate": each on the side it is on
    "G-019": SETTING,  # "Both pointing away from you": the setting convention (turned along y)
    # "Left arm: move the fork next to the plate, facing forward. Right arm: same thing with the spoon on the
    # other side": each heading said for its step; "facing forward": the setting convention.
    "G-020": SETTING_ARMS,
    "G-021": SETTING,  # "near the plate, like when we are eating dinner": a place setting, fork left, spoon right
    "G-022": SETTING,  # "a proper place setting ... both pointing straight out away from you" (as F-021)
    "G-023": [on("spoon", "plate")],
    # "right next to the fork": beside it on the side the spoon is on (its right; as B-019), 17 cm and turned
    # along y by the helper's flat-anchor rule (still on the table's left, as the writer's meaning says).
    "G-024": [rel(T, "spoon", "fork")],
    # Swap the two places: absolute points, each the other's start (as B-012), in the order said (the fork first).
    "G-025": [at_xy("fork", *spot(T, "spoon")), at_xy("spoon", *spot(T, "fork"))],
    "G-026": REFUSE,
    "G-027": HANDOVER,  # "block left to right hand, then onto the target"
    "G-028": HANDOVER,  # "the target circle": the target region
    "G-029": TARGET,  # "standing inside the marked area on the right": the target; placed stands it upright anyway
    "G-030": TARGET,
    # "Take the orange block, give it to the other hand": no giver said, the arm that picks it up, the left
    # (the block is on the left; as A-024, F-026).
    "G-031": HANDOVER,
    # "you'll probably have to pass it between your hands": the speaker says how it is to be done (a
    # hand-over, left to right: the block is on the left, the target on the right), not an optional offer
    # like B-010's "you can ... if that's easier"; the writer's meaning agrees.
    "G-032": HANDOVER,
    "G-033": HANDOVER,
    "G-034": REFUSE,
    "G-035": COFFEE,  # "carry tray forward w both hands": the forward spot
    "G-036": COFFEE,  # "moving the tray a little further away from you using both arms": the forward spot
    "G-037": COFFEE_LEFT,  # "Left arm," heads the capsule sentence only; "move the tray forward a bit": the forward spot
    # End state: "the tray pushed back a little on the table, still centred": back = away from the robot (as
    # A-031); the forward spot is centred (x 0.00).
    "G-038": COFFEE,
    "G-039": COFFEE,  # "then lift it with both hands and move it forward": "it" is the tray
    # "shift the tray back a few centimetres, away from you": the forward spot (the direction names the region;
    # as A-034); "Leave the capsule where it is": no goal for it.
    "G-040": TRAY_FWD,
    "G-041": [into("capsule", "tray", "left")],  # "coffee pod": the capsule; "with your left hand"; the tray stays
    "G-042": REFUSE,
    "G-043": FOLD,
    "G-044": FOLD,  # "the edge closest to you lines up with the far edge": the near edge onto the far edge (as F-048)
    "G-045": FOLD,  # each arm a near corner, onto the far corners
    "G-046": FOLD,  # "fold it over once, bottom to top": near onto far (as F-047)
    "G-047": FOLD,  # "take the two corners near you and put them on the two corners far away"
    "G-048": FOLD,  # "with the folded edge closest to me": crease near (as E-046, F-051)
    "G-049": REFUSE,
    "G-050": REFUSE,
    "G-051": [into("red_block", "cup")],
    "G-052": [into("blue_block", "cup")],
    "G-053": [on("red_block", "blue_block")],
    "G-054": [into("red_block", "cup"), into("blue_block", "cup")],  # "both blocks", order unsaid: as D-055
    # "next of the blue cube", side unsaid: the side the red cube is on (its left; as E-054).
    "G-055": [rel(B, "red_block", "blue_block")],
    # "a little bit to the left, just a few cm": a vague distance, the convention's nudge (as B-047).
    "G-056": [nudge(B, "blue_block", "left")],
    # "Use your left hand for the red block and your right hand for the blue one, and put them both in the
    # bowl": each by its arm, in the order named (red first; as C-045); "the bowl": the white cup (as C-048).
    "G-057": [into("red_block", "cup", "left"), into("blue_block", "cup", "right")],
    "G-058": [into("blue_block", "cup"), into("red_block", "cup")],  # "First ... the blue block ..., then ... the red one"
    # Left to right, then the right arm that holds it puts it just right of the cup (as F-059).
    "G-059": [hand("red_block", "left", "right"), rel(B, "red_block", "cup", "right", "right")],
    # End state: the blue block on the red one; "the cup moved over to the far right side": "far" is how far
    # over (the writer's meaning: the table's right side), not away from the robot: the table's right side
    # point (as A-050).
    "G-060": [on("blue_block", "red_block"), at("cup", "right")],
    # --- writer H ----------------------------------------------------------------------------
    "H-001": POUR1,
    "H-002": POUR1,  # "a little water": a vague amount, a pour; "stand the bottle back up": put back
    "H-003": [pour(arm="right"), put("bottle", "right")],  # "Right arm:" heads grasp, pour, return
    "H-004": POUR1,  # end state: water in the cup, the bottle standing where it is now (as F-006)
    # "Use your left hand to pick up the bottle and fill the cup with it, then put it back": the bottle is
    # taken by the said arm, so the pour and the put-back are the left arm's (as A-007); "fill": no amount.
    "H-005": [pour(arm="left"), put("bottle", "left")],
    # The cup beside the bottle on its left (the side it is on), then the pour into it ("it": the cup) and
    # the bottle back (as C-005).
    "H-006": [rel(P1, "cup", "bottle"), pour(), put("bottle")],
    "H-007": REFUSE,
    "H-008": [pour(arm="right"), put("bottle", "right")],  # "Take the bottle with right hand": as E-005
    "H-009": POUR1,  # "give the cup a drink from the bottle": a pour
    # "Left arm, lift the cup. Right arm, pour ..., then put both back down": the address heads its
    # sentence, so the put-down is said for the right arm (as C-001), which holds only the bottle; the
    # cup goes down by the left arm that lifted it (each by the arm holding it, as C-009). Unlike D-009
    # and F-010, the put-down is in the addressed sentence.
    "H-010": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "H-011": POUR2,  # "Hold the cup up ... a little water": held cup, a vague amount, arms unsaid
    "H-012": POUR2,  # "grab the cup with one hand and pour ... with the other": no arm named (as B-013, F-013)
    # Both taken by said arms (cup left, bottle right): the right arm pours with the cup held, each puts
    # its own down (as C-013).
    "H-013": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "H-014": [hand("cup", "left", "right"), rel(P2, "cup", "bottle", "beside", "right")],  # as B-011
    "H-015": REFUSE,
    "H-016": POUR2_LR,  # "the cup you lift with left, and right hand pour ..., after both put on table" (as A-013)
    "H-017": POUR2,  # end state and "pour while the cup's off the table": held cup, arms unsaid
    "H-018": SETTING,  # "like a proper table setting" (as F-021)
    "H-019": SETTING,  # "both pointing away from you": the setting convention (turned along y)
    # "tines facing away", "same orientation": turned along y; which end is which is not sayable (as E-021).
    "H-020": SETTING_ARMS,
    "H-021": [SPOON_R],  # "next to the plate": on the side the spoon is on (its right)
    "H-022": [on("spoon", "plate")],
    # Swap the two places: absolute points, each the other's start (as B-012, E-016), in the order said
    # (the spoon first); no yaw is said.
    "H-023": [at_xy("spoon", *spot(T, "fork")), at_xy("fork", *spot(T, "spoon"))],
    # No giver said: the arm that picks it up, the left (the fork lies on the left); the right arm, which
    # receives it, lays it right of the plate (as F-026).
    "H-024": [hand("fork", "left", "right"), rel(T, "fork", "plate", "right", "right")],
    "H-025": REFUSE,
    "H-026": SETTING,  # "tidy up the cutlery ... fork on the plate's left and the spoon on its right"
    "H-027": HANDOVER,  # "with ur left hand, pass it to the right one and drop it on the target"
    "H-028": TARGET,  # "standing up inside the marked target circle": placed stands it upright anyway
    "H-029": HANDOVER,
    # "don't use your left arm": with two arms, the right arm alone, no handover (as C-028 "use right arm only").
    "H-030": [region("block", "target", "right")],
    "H-031": HANDOVER,
    "H-032": TARGET,  # "the circle thing": the scene's one region (as F-031)
    "H-033": REFUSE,
    # "lift the block up high" (manner), "switch it into your other hand": left to right (the block is on
    # the left; as A-024, F-032); "set it down standing up in the target zone".
    "H-034": HANDOVER,
    "H-035": COFFEE,  # "carry the tray forward a bit with both hands": the forward spot
    "H-036": [into("capsule", "tray")],  # "pod": the capsule; the tray stays
    "H-037": TRAY_FWD,  # "scoot it back a little, away from you": the forward spot (as A-031)
    "H-038": COFFEE,  # end state: capsule in the tray, the tray "a bit further away from me": the forward spot
    # "Left hand:" heads the capsule step only; "about ten centimetres farther out": the forward spot (12 cm; as C-032).
    "H-039": COFFEE_LEFT,
    "H-040": COFFEE,  # "a touch further back" = away from the robot: the forward spot (as A-031, E-037)
    # The order said: the tray carried to the forward spot first, then the capsule into it there.
    "H-041": [region("tray", "forward"), into("capsule", "tray")],
    "H-042": COFFEE_LEFT,  # capsule "with left arm"; "two arms take tray and bring more far": the forward spot (as E-039)
    "H-043": FOLD,
    # "half as deep, with the fold along the side furthest from me": the crease on the far side is the far
    # half laid over onto the near half (near corners onto far corners leave the crease near: E-046, F-051).
    # The writer's meaning says near corners onto far corners; the instruction's words decide: refused.
    "H-044": REFUSE,
    "H-045": FOLD,  # each arm a near corner, onto the far corners
    "H-046": FOLD,  # "like a sandwich": in half, direction unsaid: the natural fold (as A-038)
    "H-047": REFUSE,
    "H-048": FOLD,  # "bring the bottom corners up to the top ones" (as F-047)
    "H-049": FOLD,  # the two near corners onto the two far corners
    "H-050": REFUSE,
    "H-051": [into("red_block", "cup")],
    "H-052": [on("red_block", "blue_block")],
    # "the bigger block on top of the smaller one": blue (4.5 cm) on red (4 cm), the sizes the scene states.
    "H-053": [on("blue_block", "red_block")],
    "H-054": [hand("red_block"), into("red_block", "cup", "right")],  # as B-049
    # "the block that's closest to me": the blue one (y 0.41; the red one is at 0.48).
    "H-055": [rel(B, "blue_block", "cup", "right")],
    "H-056": [into("blue_block", "cup"), rel(B, "red_block", "cup", "left")],
    "H-057": [into("red_block", "cup")],  # "the bowl": the bowl-like white cup (as C-048)
    # "a little closer to me": a 10 cm nudge towards the robot (as D-031); then the red block beside the cup
    # where it now stands, side unsaid: the side the red block is on (its left).
    "H-058": [nudge(B, "cup", "front"), rel(B, "red_block", "cup")],
    # Into the cup and out again onto the blue block: the put-in is undone later (as D-056): refused.
    "H-059": REFUSE,
    # Each block taken by a said arm; swap: absolute points, each the other's start (as B-012), in the order
    # named (red first), each put by the arm that holds it.
    "H-060": [at_xy("red_block", *spot(B, "blue_block"), "left"), at_xy("blue_block", *spot(B, "red_block"), "right")],
    # --- writer I ----------------------------------------------------------------------------
    "I-001": POUR1,  # "some water": a vague amount, a pour; "put the bottle back": placed with no place
    # "use your right hand to pick up the grey bottle and pour a little water": the bottle is taken by the
    # said arm, so the pour and the put-back are the right arm's (as H-005); "a little": a vague amount.
    "I-002": [pour(arm="right"), put("bottle", "right")],
    "I-003": REFUSE,
    "I-004": POUR1,  # "put it back down where it was": placed with no place
    # "take the bottle with right hand and fill the cup": taken by a said arm (as E-005); "fill": no amount.
    "I-005": [pour(arm="right"), put("bottle", "right")],
    "I-006": POUR1,  # end state: water in the cup, the bottle standing where it was (as E-004)
    # "Use the left arm to pour — no wait, the right one — pour ...": the words correct themselves, the
    # right arm pours (a reader hears the correction; as E-049 settles on its last words). The put-down is
    # unsaid and the bottle was not taken in a clause of its own: no arm (as E-002).
    "I-007": [pour(arm="right"), put("bottle")],
    "I-008": REFUSE,
    "I-009": REFUSE,
    # "Left arm: ... hold it up. Right arm: pour ... Then both of you put things back down": each arm its
    # own object (as C-009).
    "I-010": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],
    "I-011": POUR2,  # "hold the cup up and pour into it": held cup, arms unsaid
    # "the cup to have water in it and both ... standing on the table again": no hold said (as C-015, E-013):
    # the plain pour, the bottle back.
    "I-012": POUR1,
    # Cup taken by the said left hand; "pour the bottle into it with the other one": the right arm pours; the
    # bottle was not taken in a clause of its own (as A-013, F-011).
    "I-013": POUR2_LR,
    # Both taken by said arms ("lift the red cup ... with the left arm", "take the bottle in the right arm");
    # the put-downs in the order said: the bottle first, then the cup.
    "I-014": [pour(arm="right", hold=True), put("bottle", "right"), put("cup", "left")],
    "I-015": POUR2,  # "Pick the cup up, fill it up from the bottle": held cup, arms unsaid (as A-012)
    "I-016": POUR2_LR,  # "Left hand lift cup in the air, right hand pour ..., then both put down" (as A-013, B-009)
    # "Hold the bottle in the left hand and — sorry, I mean hold the cup in the left hand — and pour with the
    # right": the correction decides: the cup held by the left, the right arm pours. Nothing said about
    # putting down: each goes back by the convention (the cup by the left that holds it; as C-011).
    "I-017": POUR2_LR,
    "I-018": SETTING,
    "I-019": SETTING_ARMS,  # "Left arm, ... Right arm, do the same with the spoon": pointing away is the setting convention
    "I-020": SETTING,  # "oriented perpendicular to the table edge": turned along y, the setting convention
    "I-021": SETTING,  # "on either side like a normal place setting": fork left, spoon right
    "I-022": SETTING,  # "plate in the middle" is already so: no goal for the plate
    # The swapped setting, in the order said (the spoon first): each beside the plate on the side named.
    "I-023": [rel(T, "spoon", "plate", "left"), rel(T, "fork", "plate", "right")],
    "I-024": [on("fork", "plate")],  # "leave the spoon": no goal for it
    "I-025": REFUSE,
    "I-026": SETTING,  # "both straight, pointing to far side": the setting convention
    "I-027": HANDOVER,
    "I-028": TARGET,  # "the marked circle": the scene's one region; "standing": placed stands it upright anyway
    "I-029": HANDOVER,
    "I-030": HANDOVER,  # "give it to the other one, and have it drop it off on the target": left to right
    "I-031": HANDOVER,  # "handing it over to your right hand": the giver is the other, the left
    # "Put the block on the target with your right hand — actually, pick it up with the left first and hand
    # it across, then the right one puts it down": the correction decides: the hand-over, left to right.
    "I-032": HANDOVER,
    # "swap hands": left to right (the block is on the left; as A-024); "the mark on the right": the target (as F-031).
    "I-033": HANDOVER,
    "I-034": REFUSE,
    # "shove the tray back a bit": back = away from the robot (the writer's meaning; as A-031, H-037): the forward spot.
    "I-035": COFFEE,
    # "Left arm:" heads the capsule step only (both arms carry the tray); "forward about 10 cm": the forward
    # spot (12 cm; as A-034, H-039).
    "I-036": COFFEE_LEFT,
    "I-037": COFFEE,  # "set it down a little farther away": the forward spot
    "I-038": COFFEE,  # end state: the tray "a bit further from you than it is now": the forward spot
    "I-039": COFFEE_LEFT,  # capsule "with left hand"; "two hands take tray ... and bring more far" (as E-039, H-042)
    "I-040": COFFEE,  # "the little coffee pod thing": the capsule; "move it forward a bit": the forward spot
    "I-041": TRAY_FWD,  # "don't touch the capsule": a negation states no goal
    "I-042": COFFEE,  # "lift that up by the handles": the tray; "a bit further out": the forward spot
    "I-043": FOLD,
    "I-044": FOLD,
    "I-045": FOLD,  # bottom (near) corners onto the top (far) ones, one arm each (as F-047)
    "I-046": FOLD,  # "front to back"
    "I-047": FOLD,  # "half as deep, with the fold on the side closest to you": crease near (as E-046, F-051)
    # "Fold the towel left to right — no, sorry, fold it front to back, near corners onto the far ones": the
    # correction decides (as E-049): the fold.
    "I-048": FOLD,
    "I-049": FOLD,  # "take the corners near you and put on the corners far"
    "I-050": FOLD,
    "I-051": REFUSE,
    "I-052": [into("red_block", "cup")],
    "I-053": [on("blue_block", "red_block")],
    "I-054": [into("red_block", "cup"), into("blue_block", "cup")],  # "the bowl": the white cup; order unsaid: as D-055
    # "put the red cube into the white cup, then put the blue cube on top of it": "it" is the red cube (the
    # object of the clause before; the writer's meaning agrees): the blue cube stacked on it, in the cup.
    "I-055": [into("red_block", "cup"), on("blue_block", "red_block")],
    # "side by side in front of the cup", order unsaid: the blue block already stands in front of the cup, so
    # the red one beside it on the side it is on (its left) makes the pair, keeping their order (as D-058).
    "I-056": [rel(B, "red_block", "blue_block")],
    # Each block taken by a said arm; "Drop them both in the cup": each by its arm, in the order named (as C-045).
    "I-057": [into("red_block", "cup", "left"), into("blue_block", "cup", "right")],
    "I-058": [hand("blue_block", "right", "left"), rel(B, "blue_block", "cup", "left", "left")],
    # "Put the blue block in the cup, no, the red one": the correction decides; "leave the other one": no goal.
    "I-059": [into("red_block", "cup")],
    "I-060": REFUSE,
    # --- writer J ----------------------------------------------------------------------------
    "J-001": [pour(arm="right"), put("bottle", "right")],  # "Right arm:" heads grab, pour, stand it back up
    "J-002": POUR1,  # "pour me some water into the cup": the bottle goes back by the convention
    "J-003": POUR1,  # "a little water": a vague amount; "put the bottle back upright"
    "J-004": REFUSE,
    # "Use your left hand to pour ...": the pour's arm; the bottle was not taken in a clause of its own, and
    # its put-down is unsaid: no arm (as C-004, E-002; the writer's meaning has the left arm put it back).
    # "not the right one": a negation states no goal.
    "J-005": [pour(arm="left"), put("bottle")],
    "J-006": [rel(P1, "cup", "bottle")],  # next to the bottle, on its left (where the cup is; as D-007); "Don't pour": no goal
    # "on the other side of the cup": the bottle is on the cup's right, so beside it on its left (as B-007).
    "J-007": [rel(P1, "bottle", "cup", "left")],
    "J-008": REFUSE,
    "J-009": POUR1,  # "tip it over the cup till there's a bit of water in it": a vague amount, a pour
    "J-010": [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")],  # "both of you put your things back": as C-009
    "J-011": POUR2,  # held cup, arms unsaid
    # "left hand holding and right hand pouring": the cup held by the said left arm, the right pours; "both
    # ... standing back on the table" (as A-013).
    "J-012": POUR2_LR,
    "J-013": POUR1,  # "Don't lift the cup": no hold; the bottle back by the convention
    # "Take the cup with your left and lift it up, then pour ... with your right": putting down unsaid, each
    # goes back by the convention (as C-011).
    "J-014": POUR2_LR,
    "J-015": [rel(P2, "bottle", "cup", "right")],  # "right up against its right side": beside it, on its right
    "J-016": POUR2_LR,  # "take the cup up with left hand, ... pour ... with right hand, after put down both" (as A-013)
    # Swap the two places: absolute points, each the other's start (as B-012), in the order said (the bottle first).
    "J-017": [at_xy("bottle", *spot(P2, "cup")), at_xy("cup", *spot(P2, "bottle"))],
    "J-018": REFUSE,
    "J-019": SETTING,  # "both pointing away from you": the setting convention
    "J-020": SETTING_ARMS,  # "Both should point forward, away from the robot": the setting convention
    "J-021": SETTING,  # "by the plate like a normal table setting": fork left, spoon right
    "J-022": [on("spoon", "plate")],
    "J-023": [FORK_L],  # "pointed toward the far end": the setting convention; "Leave the spoon alone": no goal
    # "bring the cutlery in closer to the plate": each beside it on its own side (as B-020, F-023).
    "J-024": SETTING,
    # "First the spoon, then the fork": in the order said; "turned so the handle is toward you": turned along y
    # (which end is the handle is not sayable; as E-021).
    "J-025": [SPOON_R, FORK_L],
    "J-026": [hand("spoon", "right", "left"), rel(T, "spoon", "plate", "left", "left")],  # as D-023
    "J-027": REFUSE,
    "J-028": HANDOVER,
    # "the orange thing": the block; "use both arms, pass it across mid air": left to right (the block is on
    # the left; as A-024).
    "J-029": HANDOVER,
    "J-030": TARGET,  # "standing in the target area": placed stands it upright anyway; method open
    "J-031": HANDOVER,  # "from one gripper to the other": left to right (as F-032); "the marked spot": the target
    "J-032": REFUSE,
    # "a bit closer to the target, but not onto it": a nudge towards it (the target lies to the block's right;
    # as C-005), which leaves it well outside the target.
    "J-033": [nudge(H, "block", "right")],
    "J-034": [region("block", "target", "right")],  # "only the right arm": no handover (as C-028)
    "J-035": REFUSE,
    "J-036": COFFEE,  # "carry the tray forward with both hands": the forward spot
    "J-037": COFFEE_LEFT,  # "left arm:" heads the capsule step only; "a bit further away": the forward spot (as I-036)
    "J-038": COFFEE,  # "move the tray back a little so I've got room in front": away from the robot (as A-031)
    "J-039": [into("capsule", "tray")],  # "the brown pod": the capsule; "Don't move the tray": no goal
    "J-040": TRAY_FWD,  # "forward to the marked spot": the forward region; the capsule stays
    "J-041": [region("tray", "forward"), into("capsule", "tray")],  # the order said: the tray first (as H-041)
    "J-042": COFFEE,  # "both hand take the tray and move to far": the forward spot
    "J-043": REFUSE,
    "J-044": FOLD,
    "J-045": FOLD,  # direction unsaid: the natural fold (as A-038)
    "J-046": FOLD,  # bottom (near) corners onto the top (far) ones, one arm each (as F-047)
    "J-047": FOLD,  # "with the fold closest to the robot": crease near (as E-046, F-051)
    "J-048": REFUSE,
    "J-049": FOLD,
    "J-050": REFUSE,
    "J-051": REFUSE,
    "J-052": REFUSE,
    "J-053": [into("red_block", "cup")],
    "J-054": [on("blue_block", "red_block")],
    "J-055": [into("blue_block", "cup"), into("red_block", "cup")],  # "the blue one first and then the red one"
    "J-056": [hand("red_block", "left", "right"), rel(B, "red_block", "blue_block", "right", "right")],
    # The red cube on the blue one, then the cup beside the stack (anchored on its base, the blue cube); side
    # unsaid: the side the cup is on (it stands almost straight behind the blue cube, 1 cm to its left: left;
    # as F-055).
    "J-057": [on("red_block", "blue_block"), rel(B, "cup", "blue_block")],
    "J-058": REFUSE,
    "J-059": [into("blue_block", "cup")],  # "the bowl": the white cup; "don't touch the red one": no goal
    "J-060": REFUSE,
    # --- writer K ----------------------------------------------------------------------------
    # "pour some water ... with the right arm then put the bottle back": the pour's arm; the put-back names
    # no arm and the bottle was not taken in a clause of its own (as D-001, G-001).
    "K-001": [pour(arm="right"), put("bottle")],
    "K-002": POUR1,  # "fill up the cup with a bit of water": a vague amount, a pour
    "K-003": [pour(arm="right"), put("bottle", "right")],  # "right hand:" heads grab, pour, set it back upright
    "K-004": POUR1,  # end state: water in the cup, the bottle standing where it was (as E-004)
    "K-005": POUR1,  # "after put it down again": the bottle back
    "K-006": POUR1,  # "tip a little into the cup, and then stand it back up": a vague amount; "it": the bottle
    "K-007": [rel(P1, "cup", "bottle")],  # "Slide the cup over so it's right next to the bottle": on its left (as D-007)
    "K-008": REFUSE,
    # "Left arm, ... hold it up. Right arm, pour ... Then put both of them down.": the put-down is a sentence of
    # its own with no arm (as D-009, the same words).
    "K-009": POUR2_LR,
    # "hold the cup up ... with your left hand while the right one pours water in, then set them both back
    # down": the cup by the left that holds it, the right arm pours; the put-down names no arm (as F-010).
    "K-010": POUR2_LR,
    # "a cup with water in it, but don't pour while the cup's sitting on the table, lift it up first": held
    # cup, arms unsaid; "put everything back upright".
    "K-011": POUR2,
    "K-012": POUR2_LR,  # "lift cup w/ left, pour w/ right, put both down"
    "K-013": POUR2,  # "pour water in the cup while you are holding it": held cup, arms unsaid; "place them on the table"
    # "First pick up the cup, second grab the bottle, third pour into the cup, and last set them both down":
    # the cup is not put down before the pour: held (as A-012, I-015), arms unsaid.
    "K-014": POUR2,
    "K-015": [rel(P2, "bottle", "cup")],  # "right beside the cup": on its right, the side the bottle is on (as D-016)
    # "Use your right hand to pick up the cup, then pass it over to your left hand": nothing said about putting
    # it down, so the left arm that holds it puts it back (as E-015; the writer's meaning, the cup still held
    # at the end, is not sayable, and the instruction does not ask for it).
    "K-016": [hand("cup", "right", "left"), put("cup", "left")],
    "K-017": SETTING,  # "both pointing away from you": the setting convention
    # "left arm take the fork, right arm the spoon, put them next to the plate facing forward": each taken by
    # a said arm, each on its own side.
    "K-018": SETTING_ARMS,
    "K-019": SETTING,  # "tidy up the cutlery ... either side of the plate, like a proper place setting"
    "K-020": SETTING,  # "fork L of plate, spoon R, tips pointing to the far end": the setting convention
    "K-021": [on("spoon", "plate")],
    "K-022": SETTING,  # "the fork next to the plate, and then ... the spoon on the other side": fork first, on its own side
    "K-023": REFUSE,
    "K-024": [rel(T, "spoon", "fork")],  # "next to the fork": on its right, the side the spoon is on (as B-019, G-024)
    "K-025": HANDOVER,
    "K-026": HANDOVER,  # "hand it across between arms, don't just drag it": left to right (the block is on the left)
    "K-027": HANDOVER,  # "left grabs block -> handover -> right drops it on the mark": "the mark": the target
    "K-028": TARGET,  # "the target spot on the right": the target; method open
    "K-029": TARGET,  # "standing up inside the target circle": placed stands it upright anyway
    "K-030": REFUSE,
    "K-031": REFUSE,
    "K-032": [region("block", "target", "right")],  # "Just use your right arm ..., no need to pass it": as C-028
    "K-033": COFFEE,
    "K-034": COFFEE,  # "pod": the capsule; "a bit further away": the forward spot
    # "Left hand:" heads the capsule step only; "both hands on the handles and take it forward to the spot":
    # the forward region (as J-040).
    "K-035": COFFEE_LEFT,
    "K-036": COFFEE,  # end state: "capsule in and the tray a little further away from me": the forward spot
    "K-037": COFFEE,  # "after that both arm lift tray and bring forward"
    "K-038": TRAY_FWD,  # "Leave the capsule where it is": no goal for it
    "K-039": [into("capsule", "tray")],  # the tray stays
    "K-040": REFUSE,
    "K-041": FOLD,  # "bottom edge up to the top edge" (as F-047)
    "K-042": FOLD,
    "K-043": FOLD,  # "in half ..., away from you": the near half laid away, onto the far half
    "K-044": FOLD,  # each arm a near corner, onto the far corners
    "K-045": FOLD,  # "with the fold on my side": crease near (as E-046, F-051)
    "K-046": FOLD,  # "fold it": the towel, the scene's only object; direction unsaid: the natural fold (as A-038)
    "K-047": REFUSE,
    "K-048": REFUSE,
    "K-049": [into("red_block", "cup")],
    "K-050": [into("red_block", "cup"), into("blue_block", "cup")],  # "both blocks", order unsaid: as D-055
    "K-051": [on("red_block", "blue_block")],
    "K-052": [on("blue_block", "red_block")],  # "blue on red"
    "K-053": [into("blue_block", "cup"), into("red_block", "cup")],  # "the blue block ... first, and then the red one"
    # Taken by the said left arm, handed to the right, which puts it in the cup (as B-049).
    "K-054": [hand("red_block", "left", "right"), into("red_block", "cup", "right")],
    "K-055": [rel(B, "red_block", "blue_block")],  # side unsaid: the side the red block is on (its left; as E-054)
    # End state: the blue block in the cup, the red one "just beside the cup", side unsaid: the side it is on
    # (its left; as E-055).
    "K-056": [into("blue_block", "cup"), rel(B, "red_block", "cup")],
    # "put it on top of... actually no, just put it next to the cup": the correction decides (as I-059); side
    # unsaid: the side the blue block is on (1.5 cm right of the cup: right; as F-055).
    "K-057": [into("red_block", "cup"), rel(B, "blue_block", "cup")],
    # "the blue cube put it beside of the red one": the red cube is then in the cup, so beside it is beside the
    # cup that holds it (anchored on the container, as J-057 anchors on a stack's base; the writer's meaning
    # says so); side unsaid: the side the blue cube is on (right, as K-057).
    "K-058": [into("red_block", "cup"), rel(B, "blue_block", "cup")],
    "K-059": REFUSE,
    # "right arm, grab the blue block and set it down to the left of the red block": the address heads the
    # sentence, said for both steps.
    "K-060": [rel(B, "blue_block", "red_block", "left", "right")],
    # --- writer L ----------------------------------------------------------------------------
    "L-001": POUR1,  # "Pour some water ..., then stand the bottle back up where it was": no arm said (the meaning's "natural" right is not in the words)
    "L-002": REFUSE,
    # "take the bottle with right hand and make water go in the cup, after put bottle standing again": taken by a
    # said arm, so the pour and the put-back are the right arm's (as E-005).
    "L-003": [pour(arm="right"), put("bottle", "right")],
    "L-004": POUR1,  # "give the cup a drink of water ... pour it in": a pour (as H-009); the bottle back by the convention
    # End state: "a bit of water" (a vague amount) and "the bottle standing up next to it again": "again" restores the
    # bottle's own place (it stood next to the cup at the start; the writer's meaning agrees), not rel() beside the
    # cup, which would move it ~10 cm: the bottle put back (as E-004).
    "L-005": POUR1,
    "L-006": REFUSE,
    "L-007": REFUSE,
    # "Use whichever arm is closest to the bottle": an arm said by a description the scene resolves (the bottle is
    # right of centre, the right arm's corner; as H-055 resolves "closest to me"): the right arm pours. The put-down
    # is unsaid and the bottle was not taken in a clause of its own: no arm (as G-002).
    "L-008": [pour(arm="right"), put("bottle")],
    # "Left hand, lift the cup up. Right hand, pour ... Then put them both back down.": the put-down is a sentence
    # of its own with no arm (as D-009, K-009).
    "L-009": POUR2_LR,
    # "Raise the red cup with the left arm ... With the right arm, pour ..., and afterwards set both down": the
    # fronted "With the right arm" is the pour's arm (as D-001 "Using your right arm, pour ..., then stand ..."),
    # not a vocative heading (H-010); the cup goes down by the left arm that lifted it, the bottle with no arm.
    "L-010": POUR2_LR,
    "L-011": POUR2,  # "just hold the cup up and pour some water in it, then put everything down": held cup, arms unsaid
    "L-012": POUR2_LR,  # "Left arm take cup up in the air, right arm pour water to it. Then both down" (as G-010)
    # "Step 1: left arm picks up cup. Step 2: right arm picks up bottle and pours ...": both taken by said arms, the
    # cup not put down before the pour: held (as K-014); the put-downs in the order said, bottle first (as I-014).
    "L-013": [pour(arm="right", hold=True), put("bottle", "right"), put("cup", "left")],
    # End state plus "Don't pour with the cup sitting on the table": held cup, arms unsaid (as H-017, K-011).
    "L-014": POUR2,
    "L-015": POUR2_LR,  # "Hold the cup up with your left hand ..., and pour into it with the right. Put them down ...": as F-010
    # "pour me a little water? Hold the cup for it yourself": a vague amount; held cup, arms unsaid (the meaning's
    # "natural" left/right is not in the words); the put-downs by the convention.
    "L-016": POUR2,
    "L-017": SETTING,  # "both pointing away from you": the setting convention (turned along y)
    "L-018": SETTING,  # "next to the plate": each on the side it is on (as E-017)
    "L-019": SETTING_ARMS,  # "Left arm, bring the fork ... Right arm, do the same with the spoon"
    "L-020": SETTING,  # "make it look like a restaurant! fork and spoon go by the plate": a place setting (as G-021)
    # "to the left of the plate, about three centimetres from the rim, tines pointing away ... do the same for the
    # spoon on the right": the stated gap is sayable as the offset (plate radius 8.1 cm + 3 cm + the utensil's half
    # width 1 cm = 12.1 cm from the plate's centre), not the setting convention's 17 cm (5 cm farther, beyond
    # rearrange's 3 cm tolerance); turned along y. The writer's meaning ("just left of the plate") drops the
    # distance; the instruction's words decide. Which end points away is not sayable (as E-021).
    "L-021": [{**FORK_L, "offset": [-0.121, 0.0]}, {**SPOON_R, "offset": [0.121, 0.0]}],
    "L-022": SETTING,  # "Turn them so they point to far": the setting convention
    "L-023": [SPOON_R],  # "Leave the fork alone": no goal; the meaning's "natural" right arm is not in the words
    "L-024": REFUSE,
    # "First the fork, then the spoon - line each one up beside the plate with the handle towards you": each on its own
    # side, turned along y (which end is the handle is not sayable; as E-021).
    "L-025": SETTING,
    "L-026": HANDOVER,
    "L-027": TARGET,  # "the marked circle on the right": the target; method open (the meaning's "natural" handover is not in the words)
    "L-028": HANDOVER,  # "hand it across in the air": left to right (the block is on the left, the target on the right; as A-024)
    # "lift it roughly fifteen centimetres", "above the middle of the table": how high and where the hand-over happens
    # are manner, not an end state (as E-033, H-034); "Left arm: ... Right arm: lower it ... onto the target".
    "L-029": HANDOVER,
    "L-030": HANDOVER,  # "from one hand to your other hand": left to right (as F-032); "the circle spot": the target
    "L-031": HANDOVER,  # "have the left one pick it up and hand it over. Then the right one can put it on the target"
    "L-032": HANDOVER,  # "hand it off to the right": the giver is the other, the left (as I-031)
    "L-033": REFUSE,
    "L-034": COFFEE,  # "carry the tray a bit further away with both hands": the forward spot
    "L-035": COFFEE_LEFT,  # "Left arm," heads the capsule sentence only; "move the tray forward a little": the forward spot (as G-037)
    "L-036": COFFEE,  # "pod": the capsule; "tray back a bit": back = away from the robot, the forward spot (as A-031, I-035)
    "L-037": COFFEE,  # "with two hands move the tray more far from you": the forward spot (as E-039)
    "L-038": COFFEE,  # end state: "a few inches further up the table": the forward spot (as G-040's "a few centimetres")
    # "using the left gripper"; "about twelve centimetres farther from you, still centred": the forward spot (12 cm
    # farther, x 0.00; as A-034); "lift it level so the capsule doesn't slide": manner.
    "L-039": COFFEE_LEFT,
    # "Use both hands on the tray ... before you move it, pop the capsule in": where the tray goes is unsaid; the scene
    # has one place for it, its forward spot (as H-032 takes "the circle thing" for the scene's one region; the
    # writer's meaning agrees): the capsule first, then the tray there.
    "L-040": COFFEE,
    "L-041": REFUSE,
    "L-042": FOLD,  # "the near edge over to the far edge"
    "L-043": FOLD,  # direction unsaid: the natural fold (as A-038)
    "L-044": FOLD,  # bottom (near) corners up to the top (far) ones, one arm each (as F-047)
    # "lay them exactly on the two far corners, ... about 28 by 11 centimetres": what folded is (near corners on far
    # corners) and the size a fold in half of the 28 x 23 cm towel has: nothing beyond the fold.
    "L-045": FOLD,
    "L-046": FOLD,  # "bring the close side on top of the far side"
    "L-047": FOLD,  # "like a taco": in half, direction unsaid: the natural fold (as H-046 "like a sandwich")
    "L-048": FOLD,  # "fold in half towards the back, corners lined up": near corners onto far corners (as I-050)
    "L-049": REFUSE,
    "L-050": [into("red_block", "cup")],
    "L-051": [on("red_block", "blue_block")],
    "L-052": [into("red_block", "cup"), into("blue_block", "cup")],  # "red first and then blue"
    "L-053": [rel(B, "blue_block", "red_block", "left")],
    "L-054": [into("blue_block", "cup")],  # "the bowl thing": the bowl-like white cup (as C-048)
    # Picked up by the said right hand, passed to the left, which puts it in the cup (as B-049, right to left).
    "L-055": [hand("blue_block", "right", "left"), into("blue_block", "cup", "left")],
    "L-056": [on("red_block", "blue_block")],  # "leave the cup where it is": no goal
    # "the little red box": the red cube; "the bowl": the white cup (as C-048); "the blue one next to it": beside the
    # cup (or the red cube in it: anchored on the container, as K-058); side unsaid: the side the blue block is on
    # (1.5 cm right of the cup: right; as F-055).
    "L-057": [into("red_block", "cup"), rel(B, "blue_block", "cup")],
    # "over to the right side": the table's right side point (as A-050), not a nudge ("a bit"); it leaves the space
    # in front of the cup clear.
    "L-058": [at("blue_block", "right")],
    "L-059": REFUSE,
    "L-060": REFUSE,
}

#: Why each refused entry is refused.
WHY = {
    "A-005": "'pour about half into cup': a stated fraction of the water; poured states no amount",
    "A-006": "no milk in the scene (only a bottle of water)",
    "A-021": "no knife in the scene",
    "A-026": "'then just hold it there': an end with the block held in the air cannot be said (a goal spec ends at home, a held object is put back)",
    "A-028": "no cup in the handover scene",
    "A-042": "a side fold (left half onto right half): folded is only near corners onto far corners",
    "A-043": "no laundry basket in the scene",
    "B-006": "no glass jug in the scene (the writer means a second vessel, not the bottle)",
    "B-021": "no knife in the scene",
    "B-025": "'hold it in the air ... don't put it anywhere': an end with the block held cannot be said",
    "B-028": "no green block in the scene",
    "B-035": "brewing coffee: no coffee machine, not a goal",
    "B-041": "moving the whole towel flat to the left: the cloth is only its corner points and folded; no goal moves a cloth",
    "B-042": "folding twice (quarters) and a drawer: neither in the scene nor sayable",
    "C-003": "'till it's about half full': a stated amount; poured states no amount",
    "C-007": "no fridge in the scene",
    "C-014": "no orange juice or carton in the scene",
    "C-022": "no knife in the scene",
    "C-036": "no coffee machine in the scene",
    "C-042": "a side fold (left to right): folded is only near corners onto far corners",
    "C-049": "no green block in the scene",
    "D-006": "'till it's about half full': a stated amount; poured states no amount",
    "D-008": "no bowl in the pouring scene",
    "D-024": "no knife in the scene",
    "D-032": "no green block in the scene",
    "D-040": "no coffee machine; brewing is not a goal",
    "D-047": "one corner laid on another by one arm (a partial fold): folded is both near corners onto the far corners",
    "D-048": "no drawer in the scene",
    "D-056": "into the cup and out again: goals are kept once achieved, so a put-in undone later cannot be said (the end state is the start)",
    "D-060": "no water in this scene",
    "E-006": "'fill the cup about halfway': a stated amount; poured states no amount",
    "E-008": "no glass jug in the scene (only the bottle and the cup)",
    "E-023": "no knife in the scene",
    "E-032": "no cup in the handover scene",
    "E-041": "making coffee: no coffee machine, water or cup in the scene; brewing is not a goal",
    "E-047": "a side fold (left edge onto right edge): folded is only near corners onto far corners",
    "E-048": "moving the whole towel to the right side: the cloth is only its corner points and folded; no goal moves a cloth",
    "E-050": "ironing the towel: no iron in the scene and ironing is not a goal (the fold alone would be sayable, not the whole)",
    "F-008": "'pour about half of it into the cup': a stated fraction of the water; poured states no amount",
    "F-009": "no blue cup in the scene (only the red cup)",
    "F-014": "'maybe a third of a cup': a stated amount; poured states no amount",
    "F-018": "'pick the cup up ... and hold it there': an end with the cup held in the air cannot be said "
    "(a goal spec ends at home, a held object is put back)",
    "F-027": "no knife in the scene",
    "F-035": "no cup in the handover scene",
    "F-044": "no coffee machine in the scene; making an espresso is not a goal",
    "F-050": "picking the folded towel up and putting it down to the right: the cloth is only its corner points and folded; "
    "no goal moves a cloth (the fold alone would be sayable, not the whole)",
    "F-052": "no drawer in the scene",
    "F-060": "no green block in the scene (only a red and a blue block)",
    "G-003": "'fill the cup up about halfway': a stated amount; poured states no amount (the bottle put back alone would be sayable, not the whole)",
    "G-009": "no bowl in the pouring scene (only the bottle and the red cup)",
    "G-026": "no knife in the scene",
    "G-034": "no green block in the scene (only the orange block)",
    "G-042": "no coffee machine in the scene; making an espresso is not a goal",
    "G-049": "one corner laid on another by one arm, the rest left flat (a partial fold): folded is both near corners onto the far corners",
    "G-050": "ironing the towel: no iron in the scene and ironing is not a goal (the fold alone would be sayable, not the whole)",
    "H-007": "no orange juice in the scene (the only bottle holds water)",
    "H-015": "the bottle (5 cm wide, 17 cm tall) does not fit inside the cup (5 cm wide, 9.5 cm tall)",
    "H-025": "no knife in the scene",
    "H-033": "no green block in the scene (the block on the target alone would be sayable, not the whole)",
    "H-044": "a fold with the crease along the far side (the far half laid onto the near half): folded is only near corners "
    "onto far corners, which leaves the crease near",
    "H-047": "a side fold (left side onto right side): folded is only near corners onto far corners",
    "H-050": "no cup in the towel scene (the fold alone would be sayable, not the whole)",
    "H-059": "into the cup and then out onto the blue block: goals are kept once achieved, so a put-in undone later cannot be "
    "said (the end state alone, red on blue, would be sayable, not the whole)",
    "I-003": "'approx. 50 mL': a stated amount of water; poured states no amount",
    "I-008": "'fill it about halfway': a stated amount; poured states no amount (the cup beside the bottle alone would be sayable, not the whole)",
    "I-009": "no kettle in the scene (only a bottle of water)",
    "I-025": "no knife in the scene",
    "I-034": "no green block in the scene",
    "I-051": "no sink in the scene, and hanging a cloth is not a goal (the fold alone would be sayable, not the whole)",
    "I-060": "no yellow block in the scene (only a red and a blue block)",
    "J-004": "'fill the cup about halfway': a stated amount; poured states no amount",
    "J-008": "no kettle in the scene, and switching an appliance on is not a goal",
    "J-018": "heating the water: nothing in the scene heats and heating is not a goal (the pour alone would be sayable, not the whole)",
    "J-027": "no knife in the scene",
    "J-032": "'just hold it up in the air. Don't put it anywhere': an end with the block held cannot be said (a goal spec "
    "ends at home, a held object is put back)",
    "J-035": "onto the target and then back where it was: goals are kept once achieved, so a placement undone later cannot "
    "be said (the end state is the start)",
    "J-043": "no coffee machine or water in the scene; making an espresso is not a goal",
    "J-048": "a side fold (left half onto right half): folded is only near corners onto far corners",
    "J-050": "one corner laid diagonally on the opposite one by one arm (a triangle): folded is both near corners onto the far corners",
    "J-051": "folding twice (in half and in half again): folded is one fold, near corners onto far corners",
    "J-052": "sliding the whole towel flat to the left: the cloth is only its corner points and folded; no goal moves a cloth",
    "J-058": "no green block in the scene (only a red and a blue block)",
    "J-060": "turning the cup upside down over the red block: no goal turns an object over or covers one with another (placed stands it upright)",
    "K-008": "no milk carton in the scene (only a bottle of water)",
    "K-023": "no knife in the scene",
    "K-030": "'then just hold it there': an end with the block held in the air cannot be said (a goal spec ends at home, "
    "a held object is put back)",
    "K-031": "no green block in the scene (only the orange block)",
    "K-040": "brewing coffee: no coffee machine, not a goal",
    "K-047": "lifting the towel by its near corners and holding it there: no goal lifts a cloth (folded is its only goal), "
    "and an end with something held in the air cannot be said",
    "K-048": "one corner laid on another by one arm (a partial fold): folded is both near corners onto the far corners",
    "K-059": "no yellow block in the scene (only a red and a blue block)",
    "L-002": "'fill the cup about halfway': a stated amount; poured states no amount",
    "L-006": "'until roughly a third of the water has gone in': a stated fraction of the water; poured states no amount",
    "L-007": "no teapot in the scene (only the bottle and the red cup)",
    "L-024": "no knife in the scene",
    "L-033": "no green block in the scene (only the orange block)",
    "L-041": "no coffee machine in the scene; pressing start is not a goal",
    "L-049": "no drawer in the scene (the fold alone would be sayable, not the whole)",
    "L-059": "'set it squarely on the red cube, edges aligned': on_top_of states no yaw, so the alignment of the edges "
    "(the cubes stand 7 degrees apart) cannot be said (the stack alone would be sayable, not the whole)",
    "L-060": "no green block in the scene (only a red and a blue block)",
}

HEADER = """# Labels of the blind evaluation set (issue 59). Built by build_labels.py; do not edit by hand.
#
# For each instruction of writer_A.yaml ... writer_L.yaml (twelve writers, 690): its scene, and the
# goal it means as a goal spec's goals (`agentchord schema goal`), or expect: refused with why (the
# scene cannot do it, or the goal language cannot say it). Written from the instruction and the writer's `meaning` by a labeller who
# did not write them, following build_corpus.py's label conventions (docs/language.md), without
# running the composer on them. Each goal is a valid GoalSpec and names only its scene's objects and
# regions (the seed-0 scene).
"""


def _scene_obs(task: str):
    sim = SIM_TASKS[task]
    return observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))


def main() -> None:
    entries = []
    for name in ("A", "B", "C", "D", "E", "F", "G", "H", "I", "J", "K", "L"):
        entries += yaml.safe_load((HERE / f"writer_{name}.yaml").read_text(encoding="utf-8"))["entries"]
    ids = [e["id"] for e in entries]
    assert len(ids) == len(set(ids)) == 690, len(ids)
    assert set(LABELS) == set(ids), (set(ids) - set(LABELS), set(LABELS) - set(ids))
    assert set(WHY) == {k for k, v in LABELS.items() if v == REFUSE}, set(WHY) ^ {k for k, v in LABELS.items() if v == REFUSE}
    scenes: dict = {}
    labels: dict[str, dict] = {}
    counts: Counter = Counter()
    for entry in entries:
        eid, task, label = entry["id"], entry["scene"], LABELS[entry["id"]]
        if label == REFUSE:
            labels[eid] = {"scene": task, "expect": "refused", "why": WHY[eid]}
            counts[eid[0], "refused"] += 1
            continue
        if not entry["possible"]:
            print(f"note: {eid} labelled though the writer marked it impossible")
        goals = complete([dict(g) for g in label])
        spec = GoalSpec(goals=goals)  # raises on an invalid goal
        if task not in scenes:
            scenes[task] = _scene_obs(task)
        problems = goal_problems(spec, scenes[task])
        assert not problems, (eid, problems)
        labels[eid] = {"scene": task, "goal": [_Flow(g) for g in goals]}
        counts[eid[0], "labelled"] += 1
    text = yaml.dump({"labels": labels}, Dumper=_Dumper, sort_keys=False, width=200, allow_unicode=True)
    (HERE / "labels.yaml").write_text(HEADER + text, encoding="utf-8")
    for name in "ABCDEFGHIJKL":
        print(f"writer {name}: {counts[name, 'labelled']} labelled, {counts[name, 'refused']} refused")
    print(f"labels.yaml: {len(labels)} entries")


if __name__ == "__main__":
    main()
