"""Build the offline composer's paraphrase corpus (issue 45): corpus_test.yaml and corpus_dev.yaml.

Each entry is an instruction in one of the seven scenes (the six paper tasks and ``blocks_and_cup``,
seed 0, oracle perception), the classes of phrasing it exercises, and the goal it means as a goal
spec (``agentchord schema goal``), or ``refused`` where the scene cannot do what it asks.

Two sources per part: instructions written by hand (``HAND_TEST``, ``HAND_DEV``: phrased the way
people and public language-conditioned manipulation datasets phrase such tasks, read for their
phrasing, not copied) and instructions generated from templates crossed with lexicons (``_generated``).
The test part's templates, lexicons, cores and typo seed are its own (no test template is a dev
template): the rules are tuned on the development part only; the test part was written before any
rule of issue 45 and is measured, not tuned on.

The labels follow docs/language.md's conventions: ``put X down``/``back`` is ``placed`` with no place
(where it was taken from); ``beside``/``next to`` one object: on the side of the anchor the object is
on (a flat utensil beside a flat plate at 17 cm, turned along y); an object still in hand when the
instruction ends is put back down where it was, by the arm known to hold it; an arm is in a goal
when it is said for that clause or the object was taken or handed over by a said arm.

    .venv/bin/python tests/data/language/build_corpus.py   # rewrites the two YAML files
"""

from __future__ import annotations

import random
from pathlib import Path

import numpy as np
import yaml

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.rules import knowledge as kb
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

HERE = Path(__file__).parent
SCENES = {
    "pour1": "single_arm_pour_water", "pour2": "dual_arm_pour_water", "table": "rearrange_table",
    "hand": "handover_block", "coffee": "setup_coffee_tray", "towel": "fold_towel", "blocks": "blocks_and_cup",
}
#: The classes of phrasing of issue 45.
CLASSES = ("plain", "synonym", "pronoun", "ellipsis", "arm", "state", "temporal", "scene_goal", "reference",
           "politeness", "declarative", "typo")

_objects: dict[str, dict] = {}


def _scene(task: str) -> dict:
    if task not in _objects:
        sim = SIM_TASKS[task]
        scene = observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))
        _objects[task] = {o.name: o for o in scene.objects}
    return _objects[task]


# --- goal helpers (labels) -------------------------------------------------------------------


def _arm(goal: dict, arm: str | None) -> dict:
    if arm:
        goal["arm"] = arm
    return goal


def pour(source="bottle", target="cup", arm=None, hold=False):
    return _arm({"kind": "poured", "source": source, "target": target, **({"hold_target": True} if hold else {})}, arm)


def put(obj, arm=None):
    return _arm({"kind": "placed", "obj": obj}, arm)


def at(obj, words, arm=None):
    return _arm({"kind": "placed", "obj": obj, "at": list(kb.table_point(words.split()))}, arm)


def between(task, obj, a, b, arm=None):
    objs = _scene(task)
    pa, pb = objs[a].pos, objs[b].pos
    return _arm({"kind": "placed", "obj": obj, "at": [round(0.5 * (pa[0] + pb[0]), 3), round(0.5 * (pa[1] + pb[1]), 3)]}, arm)


def rel(task, obj, anchor, where="beside", arm=None):
    """``obj`` placed beside ``anchor``: ``left``, ``right``, ``front``, ``behind`` or ``beside`` (its own side)."""
    objs = _scene(task)
    o, a = objs[obj], objs[anchor]
    if where == "beside":
        where = "left" if o.pos[0] < a.pos[0] else "right"
    dx, dy = {"left": (-1.0, 0.0), "right": (1.0, 0.0), "front": (0.0, -1.0), "behind": (0.0, 1.0)}[where]
    d = kb.beside_distance(o, a)
    goal = {"kind": "placed", "obj": obj, "relative_to": anchor, "offset": [round(dx * d, 4), round(dy * d, 4)]}
    if kb.is_flat(o) and max(o.extent[:2]) > 3 * min(o.extent[:2]) and kb.is_flat(a):
        goal["yaw"] = 90.0
    return _arm(goal, arm)


def nudge(task, obj, direction, arm=None):
    o = _scene(task)[obj]
    ux, uy = kb.DIRECTION_WORDS[direction]
    return _arm({"kind": "placed", "obj": obj, "at": [round(o.pos[0] + ux * kb.NUDGE, 3), round(o.pos[1] + uy * kb.NUDGE, 3)]}, arm)


def into(obj, container, arm=None):
    return _arm({"kind": "inside", "obj": obj, "container": container}, arm)


def on(obj, support, arm=None):
    return _arm({"kind": "on_top_of", "obj": obj, "support": support}, arm)


def hand(obj, giver="left", receiver="right"):
    return {"kind": "handed_over", "obj": obj, "giver": giver, "receiver": receiver}


def region(obj, name, arm=None):
    return _arm({"kind": "placed", "obj": obj, "region": name}, arm)


def fold(cloth="towel"):
    return {"kind": "folded", "cloth": cloth}


REFUSE = "refused"

# Frequently meant goals.
POUR1 = [pour(), put("bottle")]
POUR2 = [pour(hold=True), put("cup"), put("bottle")]
SETTING = [rel("rearrange_table", "fork", "plate", "left"), rel("rearrange_table", "spoon", "plate", "right")]
HANDOVER = [hand("block"), region("block", "target", "right")]
COFFEE = [into("capsule", "tray"), region("tray", "forward")]
FOLD = [fold()]
B = "blocks_and_cup"
T = "rearrange_table"

# --- hand-written: the test part (written before any rule of issue 45) -----------------------

HAND_TEST: list[tuple[str, str, str, object]] = [
    ("pour1", "Could you decant the water from the bottle into the cup, then set the bottle back down?", "synonym politeness", POUR1),
    ("pour1", "With your right hand, fill the cup from the bottle and put it back afterwards.", "arm pronoun", [pour(arm="right"), put("bottle")]),
    ("pour1", "Grab the bottle, pour it into the cup and leave it standing where it was.", "pronoun state", POUR1),
    ("pour1", "Once the cup is filled from the bottle, put the bottle down.", "temporal state", POUR1),
    ("pour1", "Before putting the bottle back, pour water from it into the cup.", "temporal pronoun", POUR1),
    ("pour1", "Pour water from the botle into the cpu, then put the bottle down.", "typo", POUR1),
    ("pour1", "please pour water into the mug with the right gripper and then place the bottle back", "politeness arm synonym", [pour(arm="right"), put("bottle")]),
    ("pour1", "The cup gets filled with water from the bottle, and the bottle goes back on the table.", "scene_goal declarative", POUR1),
    ("pour1", "Slide the cup to the left side of the table.", "synonym reference", [at("cup", "left")]),
    ("pour1", "Set the bottle down to the right of the cup.", "reference", [rel("single_arm_pour_water", "bottle", "cup", "right")]),
    ("pour1", "Pass the bottle to the left hand.", "synonym arm", [hand("bottle", "right", "left"), put("bottle", "left")]),
    ("pour1", "Pour water from the bottle into the cup while the left arm holds the cup.", "temporal arm", [pour(hold=True), put("cup", "left"), put("bottle")]),
    ("pour1", "I'd like the bottle emptied into the cup.", "declarative state", POUR1),
    ("pour1", "Pour the water out of the bottle into the cup using the robot's right arm, then return the bottle.", "arm", [pour(arm="right"), put("bottle")]),
    ("pour1", "Move the bottle in front of the cup.", "reference synonym", [rel("single_arm_pour_water", "bottle", "cup", "front")]),
    ("pour1", "Pour water from the bottle into the bowl.", "plain", REFUSE),
    ("pour2", "Using both arms, pour the water from the bottle into the cup and then put them both down.", "arm pronoun", POUR2),
    ("pour2", "Hold the cup steady with the left hand while the right hand pours the bottle into it, then set both down.", "temporal arm pronoun", [pour(arm="right", hold=True), put("cup", "left"), put("bottle")]),
    ("pour2", "Left arm takes the cup, right arm takes the bottle; pour into the cup, then put both back.", "arm ellipsis declarative", [pour(arm="right", hold=True), put("cup", "left"), put("bottle", "right")]),
    ("pour2", "First the left hand lifts the cup, then the right hand pours the bottle into it; afterwards both go back down.", "arm temporal pronoun declarative", [pour(arm="right", hold=True), put("cup", "left"), put("bottle")]),
    ("pour2", "Pour water into the cup with both arms and set everything back down.", "arm", POUR2),
    ("pour2", "Bimanual pour: bottle into cup, then both down.", "ellipsis arm", POUR2),
    ("table", "Lay the fork to the left of the plate and the spoon to its right.", "synonym reference pronoun", SETTING),
    ("table", "Put the spoon on the right side of the plate, then the fork on the left side.", "ellipsis reference", [SETTING[1], SETTING[0]]),
    ("table", "Place the fork beside the plate, and the spoon as well.", "ellipsis", SETTING),
    ("table", "Arrange the cutlery around the plate.", "synonym", SETTING),
    ("table", "The fork goes left of the plate and the spoon goes right of it.", "declarative reference pronoun", SETTING),
    ("table", "Please move the spoon next to the plate.", "politeness", [SETTING[1]]),
    ("table", "Put the fork on the plate.", "plain", [on("fork", "plate")]),
    ("table", "Put the spoon in front of the plate.", "reference", [rel(T, "spoon", "plate", "front")]),
    ("table", "Place the spon to the rigth of the plate and the frok to its left.", "typo pronoun", [SETTING[1], SETTING[0]]),
    ("table", "Could you put the fork down by the plate's left side?", "politeness reference", [SETTING[0]]),
    ("table", "Put the knife next to the plate.", "plain", REFUSE),
    ("table", "Fork left of the plate, spoon right of the plate.", "ellipsis scene_goal", SETTING),
    ("hand", "Grab the block with your left hand, pass it to your right hand and drop it in the target area.", "arm pronoun synonym", HANDOVER),
    ("hand", "Have the left arm give the block to the right arm, which puts it in the target region.", "arm pronoun", HANDOVER),
    ("hand", "Transfer the block from the left gripper to the right gripper and then place it on the target.", "synonym arm", HANDOVER),
    ("hand", "The block should end up in the target region after being handed from the left arm to the right arm.", "scene_goal temporal state", HANDOVER),
    ("hand", "After handing the block over to the right hand, set it down in the target region.", "temporal pronoun", HANDOVER),
    ("hand", "Move the block to the right half of the table.", "reference", [at("block", "right")]),
    ("hand", "Pick up the block and hand it to the other arm, then put it in the target region.", "pronoun arm", HANDOVER),
    ("hand", "Hand over the blokc to the right arm and place it in the tagret region.", "typo", HANDOVER),
    ("coffee", "Drop the coffee pod into the tray and push the tray forward.", "synonym", COFFEE),
    ("coffee", "Put the capsule in the tray, then slide it forward using both arms.", "pronoun arm", COFFEE),
    ("coffee", "Once the capsule is in the tray, move the tray forward.", "temporal state", COFFEE),
    ("coffee", "I need the capsule inside the tray and the tray pushed forward.", "declarative state ellipsis", COFFEE),
    ("coffee", "Could you please insert the capsule into the tray?", "politeness", [COFFEE[0]]),
    ("coffee", "Place the capsule in the tray before moving the tray forward.", "temporal", COFFEE),
    ("coffee", "Move the tray forward after putting the capsule in it.", "temporal pronoun", COFFEE),
    ("coffee", "Put the capsule on the left side of the table.", "reference", [at("capsule", "left")]),
    ("coffee", "Put the capsul into the trey and move the tray forwrd.", "typo", COFFEE),
    ("towel", "Double the towel over.", "synonym", FOLD),
    ("towel", "Bring the near edge of the towel up to meet the far edge.", "synonym", FOLD),
    ("towel", "Please fold the towel so that the front edge lies on the back edge.", "politeness synonym", FOLD),
    ("towel", "Could you fold the napkin in two?", "politeness synonym", FOLD),
    ("towel", "The towel should be folded in half.", "declarative state", FOLD),
    ("towel", "Fold the towl in hlaf.", "typo", FOLD),
    ("towel", "Take the two near corners of the towel and put them on the two far corners.", "synonym pronoun", FOLD),
    ("towel", "Fold the towel from front to back.", "synonym", FOLD),
    ("blocks", "Put the blue block on top of the red one.", "pronoun", [on("blue_block", "red_block")]),
    ("blocks", "Take the red cube and drop it into the cup.", "synonym pronoun", [into("red_block", "cup")]),
    ("blocks", "Stack the red block onto the blue block with your left hand.", "arm", [on("red_block", "blue_block", "left")]),
    ("blocks", "The red block ends up in the cup.", "scene_goal", [into("red_block", "cup")]),
    ("blocks", "The block ends up on the other block.", "scene_goal", REFUSE),
    ("blocks", "Put the red block in the cup, and the blue one too.", "ellipsis pronoun", [into("red_block", "cup"), into("blue_block", "cup")]),
    ("blocks", "Place the left block next to the cup.", "reference", [rel(B, "red_block", "cup")]),
    ("blocks", "Pick up the blue block and put it behind the cup.", "reference pronoun", [rel(B, "blue_block", "cup", "behind")]),
    ("blocks", "Move the red block to the front right corner of the table.", "reference", [at("red_block", "front right")]),
    ("blocks", "Put the block on the right into the cup.", "reference", [into("blue_block", "cup")]),
    ("blocks", "Once you have the blue block, set it down in the cup.", "temporal pronoun", [into("blue_block", "cup")]),
    ("blocks", "Could you stack the blue block on the red block, please?", "politeness", [on("blue_block", "red_block")]),
    ("blocks", "Put the red blcok in the cup", "typo", [into("red_block", "cup")]),
    ("blocks", "I want the blue block sitting on the red block.", "declarative state", [on("blue_block", "red_block")]),
    ("blocks", "Use the right hand to place the blue block between the red block and the cup.", "arm reference", [between(B, "blue_block", "red_block", "cup", "right")]),
    ("blocks", "Put the green block in the cup.", "plain", REFUSE),
    ("blocks", "Swap the blocks.", "plain", REFUSE),
    ("blocks", "Take the blue block with the left arm and hand it to the right arm, then stack it on the red block.", "arm pronoun",
     [hand("blue_block", "left", "right"), on("blue_block", "red_block", "right")]),
]

# --- generated: events (a clause in its forms, with its goal) crossed with templates ---------

#: scene -> name -> (imperative, gerund, state, goal)
EVENTS: dict[str, dict[str, tuple[str, str, str, list]]] = {
    "coffee": {
        "cap": ("put the capsule in the tray", "putting the capsule in the tray", "the capsule is in the tray", [COFFEE[0]]),
        "fwd": ("move the tray forward", "moving the tray forward", "the tray has been moved forward", [COFFEE[1]]),
    },
    "blocks": {
        "red_cup": ("put the red block into the cup", "putting the red block into the cup", "the red block is in the cup", [into("red_block", "cup")]),
        "blue_cup": ("place the blue block in the cup", "placing the blue block in the cup", "the blue block is inside the cup", [into("blue_block", "cup")]),
        "blue_on_red": ("stack the blue block on the red block", "stacking the blue block on the red block", "the blue block sits on the red block", [on("blue_block", "red_block")]),
        "red_on_blue": ("put the red block on top of the blue block", "putting the red block on top of the blue block", "the red block is on top of the blue block", [on("red_block", "blue_block")]),
        "red_left": ("put the red block on the left side of the table", "putting the red block on the left side of the table", "the red block is on the left side of the table", [at("red_block", "left")]),
        "blue_right": ("move the blue block to the right side of the table", "moving the blue block to the right side of the table", "the blue block is on the right side of the table", [at("blue_block", "right")]),
    },
    "pour1": {
        "pour": ("pour water from the bottle into the cup", "pouring water from the bottle into the cup", "the cup has been filled from the bottle", [pour()]),
        "down": ("put the bottle down", "putting the bottle down", "the bottle is back on the table", [put("bottle")]),
    },
    "hand": {
        "give": ("hand the block from the left arm to the right arm", "handing the block from the left arm to the right arm", "the block has been handed to the right arm", [hand("block")]),
        "target": ("put the block in the target region", "putting the block in the target region", "the block is in the target region", [region("block", "target")]),
    },
    "table": {
        "fork": ("put the fork to the left of the plate", "putting the fork to the left of the plate", "the fork is to the left of the plate", [SETTING[0]]),
        "spoon": ("put the spoon to the right of the plate", "putting the spoon to the right of the plate", "the spoon is to the right of the plate", [SETTING[1]]),
    },
    "towel": {"fold": ("fold the towel in half", "folding the towel in half", "the towel is folded in half", FOLD)},
}
#: Ordered pairs of events whose order matters (or is at least stated).
PAIRS = {
    "test": [("coffee", "cap", "fwd"), ("pour1", "pour", "down"), ("hand", "give", "target"), ("table", "fork", "spoon"), ("blocks", "red_left", "blue_on_red")],
    "dev": [("coffee", "cap", "fwd"), ("pour1", "pour", "down"), ("hand", "give", "target"), ("table", "spoon", "fork"), ("blocks", "blue_right", "red_on_blue"), ("blocks", "red_cup", "blue_right")],
}
#: Events a single arm does (arm templates).
ONE_ARM = {"test": [("coffee", "cap"), ("blocks", "red_cup"), ("blocks", "blue_on_red"), ("table", "fork"), ("blocks", "red_left")],
           "dev": [("blocks", "blue_cup"), ("blocks", "red_on_blue"), ("table", "spoon"), ("blocks", "blue_right"), ("coffee", "cap")]}

TEMPLATES = {
    "test": {
        "temporal": ["After {g1}, {i2}.", "{I1} before {g2}.", "Once {s1}, {i2}.", "{I2}, but only after {g1}.", "{I1}. Once that's done, {i2}."],
        "politeness": (["Please {i}.", "Could you please {i}?", "Would you {i}?", "Kindly {i}.", "Can you {i}, thanks?", "Would you mind {g}?", "{I} for me, please."]),
        "arm": ["{I} with your {s} hand.", "{I} using the {s} gripper.", "{S} arm: {i}.", "The robot's {s} arm should {i}.", "Use your {s} hand to {i}."],
        "scene_goal": ["In the end, {s}.", "Make sure {s}.", "Goal: {s}."],
        "declarative": ["You should {i}.", "Your job is to {i}.", "I want you to {i}."],
    },
    "dev": {
        "temporal": ["{I2} after {g1}.", "Before {g2}, {i1}.", "{I1}; when that is done, {i2}.", "First {i1}, then {i2}.", "{I1} and, once done, {i2}.", "{I2} once {s1}."],
        "politeness": ["Please {i}.", "Could you {i}?", "Can you please {i}?", "I'd like you to {i}.", "Would you be so kind as to {i}?", "Hey robot, {i}.", "{I}, thank you.", "{I} when you get a chance."],
        "arm": ["{I} with the {s} arm.", "{I} using the {s} hand.", "Let the {s} gripper {i}.", "{S}-hand gripper, {i}.", "With its {s} arm, {i}.", "{S} hand: {i}."],
        "scene_goal": ["The end state: {s}.", "{S} at the end.", "Get to a state where {s}.", "At the end, {s}."],
        "declarative": ["You need to {i}.", "The task is to {i}.", "Robot, {i}.", "We want to {i}.", "Your task: {i}."],
    },
}

#: Verb synonyms, crossed with object words (the test and the dev part draw different verbs).
LEXICON = {
    "test": {
        "into": (["drop", "deposit", "pop", "stick", "place"], ["block", "cube"], ["into", "in", "inside"], ["cup", "mug"]),
        "stack": ["pile", "stack", "set", "rest"],
        "pour": ["tip", "decant", "empty", "pour out"],
        "give": ["pass", "give", "hand", "transfer"],
        "push": ["push", "slide", "shove"],
        "pick": ["grab", "lift", "take"],
        "place": ["put", "drop", "set"],
    },
    "dev": {
        "into": (["put", "place", "insert", "toss", "set", "get"], ["block", "cube", "brick"], ["into", "in"], ["cup", "mug", "glass"]),
        "stack": ["stack", "put", "place", "pile up"],
        "pour": ["pour", "empty", "tip", "dump", "tilt"],
        "give": ["pass", "hand over", "transfer", "switch"],
        "push": ["push", "nudge", "move", "slide", "shift"],
        "pick": ["pick up", "grasp", "grab", "get"],
        "place": ["place", "put", "lay", "leave"],
    },
}


def _cap(text: str) -> str:
    return text[0].upper() + text[1:]


def _typo(text: str, rng: random.Random) -> str:
    """One edit a spell checker would fix, in one content word of four letters or more."""
    words = text.split(" ")
    spots = [i for i, w in enumerate(words) if len(w.strip(".,?")) >= 4 and w.strip(".,?").isalpha()
             and w.strip(".,?").lower() not in ("left", "right", "with", "from", "into", "then", "down", "side")]
    i = rng.choice(spots)
    w = words[i].strip(".,?")
    k = rng.randrange(1, len(w) - 1)
    edit = rng.choice(("swap", "drop", "double", "sub"))
    if edit == "swap":
        new = w[:k] + w[k + 1] + w[k] + w[k + 2:]
    elif edit == "drop":
        new = w[:k] + w[k + 1:]
    elif edit == "double":
        new = w[:k] + w[k] + w[k:]
    else:
        keys = "qwertyuiopasdfghjklzxcvbnm"
        new = w[:k] + rng.choice([c for c in keys if c != w[k]]) + w[k + 1:]
    words[i] = words[i].replace(w, new)
    return " ".join(words)


def _generated(part: str) -> list[tuple[str, str, str, object]]:
    rng = random.Random(45 if part == "test" else 4545)
    out: list[tuple[str, str, str, object]] = []
    templates, lex = TEMPLATES[part], LEXICON[part]
    for (scene, a, b), template in zip(PAIRS[part] * 3, templates["temporal"] * 3, strict=False):
        (i1, g1, s1, goal1), (i2, g2, s2, goal2) = EVENTS[scene][a], EVENTS[scene][b]
        text = template.format(i1=i1, g1=g1, s1=s1, i2=i2, g2=g2, s2=s2, I1=_cap(i1), I2=_cap(i2))
        out.append((scene, _cap(text), "temporal", HANDOVER if (a, b) == ("give", "target") else goal1 + goal2))
    singles = [(scene, name) for scene in EVENTS for name in EVENTS[scene]]
    singles = singles[::2] if part == "test" else singles[1::2] + singles[::4]
    for n, template in enumerate(templates["politeness"] * 2):
        scene, name = singles[n % len(singles)]
        i, g, s, goal = EVENTS[scene][name]
        out.append((scene, template.format(i=i, g=g, I=_cap(i)), "politeness", goal))
    for n, template in enumerate(templates["arm"] * 2):
        scene, name = ONE_ARM[part][n % len(ONE_ARM[part])]
        side = ("left", "right")[n % 2]
        i, g, s, goal = EVENTS[scene][name]
        goal = [{**goal[0], "arm": side}]
        out.append((scene, template.format(i=i, I=_cap(i), s=side, S=_cap(side)), "arm", goal))
    for n, template in enumerate(templates["scene_goal"] * 3):
        scene, name = singles[(n + 3) % len(singles)]
        i, g, s, goal = EVENTS[scene][name]
        out.append((scene, template.format(s=s, S=_cap(s)), "scene_goal", goal))
    for n, template in enumerate(templates["declarative"] * 2):
        scene, name = singles[(n + 5) % len(singles)]
        i, g, s, goal = EVENTS[scene][name]
        out.append((scene, template.format(i=i, I=_cap(i)), "declarative", goal))
    # Synonyms: verbs crossed with object words.
    verbs, nouns, preps, cups = lex["into"]
    for n in range(8):
        colour = ("red", "blue")[n % 2]
        text = f"{_cap(rng.choice(verbs))} the {colour} {rng.choice(nouns)} {rng.choice(preps)} the {rng.choice(cups)}."
        out.append(("blocks", text, "synonym", [into(f"{colour}_block", "cup")]))
    for n, verb in enumerate(lex["stack"]):
        top, bottom = (("blue", "red"), ("red", "blue"))[n % 2]
        out.append(("blocks", f"{_cap(verb)} the {top} block on{' top of' if n % 2 else ''} the {bottom} block.", "synonym", [on(f"{top}_block", f"{bottom}_block")]))
    for verb in lex["pour"]:
        out.append(("pour1", f"{_cap(verb)} the bottle into the {rng.choice(['cup', 'mug', 'glass'])}.", "synonym", POUR1))
    for verb in lex["give"]:
        out.append(("hand", f"{_cap(verb)} the block to the right arm.", "synonym", [hand("block"), put("block", "right")]))
    for verb in lex["push"]:
        out.append(("coffee", f"Put the capsule in the tray and {verb} the tray forward.", "synonym", COFFEE))
    # Pronouns and "one".
    for n, (pick_verb, place_verb) in enumerate(zip(lex["pick"], lex["place"] * 2, strict=False)):
        colour, other = (("red", "blue"), ("blue", "red"))[n % 2]
        if part == "test":
            text = f"{_cap(pick_verb)} the {colour} block and {place_verb} it on the {other} one."
        else:
            text = f"{_cap(pick_verb)} the {colour} block, then {place_verb} it on top of the {other} one."
        out.append(("blocks", text, "pronoun", [on(f"{colour}_block", f"{other}_block")]))
    # Ellipsis and coordination.
    ellipsis = {"test": ["{V} the {a} {w}, and the {b} as well.", "{V} the {a} {w} and do the same with the {b}.", "{V} the {a}, and then the {b}, {w}."],
                "dev": ["{V} the {a} {w}, and the {b} too.", "{V} the {a} {w}, the {b} also.", "Both the {a} and the {b} go {w}.", "{V} the {a} {w}; same for the {b}."]}[part]
    for template in ellipsis:
        for scene, a, b, w, goal in (("blocks", "red block", "blue block", "in the cup", [into("red_block", "cup"), into("blue_block", "cup")]),
                                     ("table", "fork", "spoon", "beside the plate", SETTING)):
            if part == "dev" and scene == "table":
                a, b, goal = "spoon", "fork", [SETTING[1], SETTING[0]]
            out.append((scene, template.format(V=_cap(rng.choice(lex["place"])), a=a, b=b, w=w), "ellipsis", goal))
    # Spatial references.
    spatial = {"test": [("to the left of", "left"), ("in front of", "front"), ("behind", "behind"), ("to the right of", "right"), ("next to", "beside")],
               "dev": [("left of", "left"), ("on the right of", "right"), ("in back of", "behind"), ("beside", "beside"), ("near", "beside"), ("at the front of", "front")]}[part]
    for n, (words, where) in enumerate(spatial):
        colour = ("red", "blue")[n % 2]
        out.append(("blocks", f"{_cap(rng.choice(lex['place']))} the {colour} block {words} the cup.", "reference", [rel(B, f"{colour}_block", "cup", where)]))
    corners = {"test": ["back left corner", "middle", "front edge"], "dev": ["front left corner", "center", "back right corner", "right edge"]}[part]
    for words in corners:
        out.append(("coffee", f"Put the capsule {'at' if 'edge' in words else 'in'} the {words} of the table.", "reference", [at("capsule", words)]))
    refs = {"test": [("the block on the left", "red_block"), ("the front block", "blue_block"), ("the rightmost block", "blue_block")],
            "dev": [("the left block", "red_block"), ("the block on the right", "blue_block"), ("the leftmost block", "red_block"), ("the block nearer the front", "blue_block"), ("the block at the back", "red_block")]}[part]
    for words, name in refs:
        out.append(("blocks", f"Put {words} into the cup.", "reference", [into(name, "cup")]))
    # States and participles.
    states = {"test": ["Leave the {o} sitting {w}.", "Get the {o} placed {w}.", "Have the {o} resting {w}."],
              "dev": ["Leave the {o} lying {w}.", "Set the {o} down so it is standing {w}.", "Get the {o} positioned {w}.", "The {o} should be left {w}."]}[part]
    for n, template in enumerate(states):
        o, w, goal = (("red block", "in the cup", [into("red_block", "cup")]), ("blue block", "on the red block", [on("blue_block", "red_block")]))[n % 2]
        out.append(("blocks", template.format(o=o, w=w), "state", goal))
    # Typos: cores of this part with one edit.
    cores = [(scene, _cap(EVENTS[scene][a][0]) + ", then " + EVENTS[scene][b][0] + ".",
               HANDOVER if (a, b) == ("give", "target") else EVENTS[scene][a][3] + EVENTS[scene][b][3]) for scene, a, b in PAIRS[part]]
    cores += [(scene, _cap(EVENTS[scene][name][0]) + ".", EVENTS[scene][name][3]) for scene, name in singles]
    for n in range(12 if part == "test" else 16):
        scene, text, goal = cores[n % len(cores)]
        out.append((scene, _typo(text, rng), "typo", goal))
    return out


def complete(goal: list[dict]) -> list[dict]:
    """``goal`` with what is still in hand at the end put back down (the label convention)."""
    held: dict[str, str | None] = {}
    for g in goal:
        if g["kind"] == "poured":
            if g.get("hold_target"):
                held.setdefault(g["target"], None)
            held.setdefault(g["source"], None)
        elif g["kind"] == "handed_over":
            held.pop(g["obj"], None)
            held[g["obj"]] = g["receiver"]
        elif "obj" in g:
            held.pop(g["obj"], None)
    return goal + [put(obj, arm) for obj, arm in held.items()]


def _entry(part: str, source: str, n: int, scene: str, instruction: str, classes: str, goal: object) -> dict:
    entry = {"id": f"{part}-{source[0]}{n:03d}", "task": SCENES[scene], "instruction": instruction, "classes": classes.split(), "source": source}
    if goal == REFUSE:
        entry["expect"] = "refused"
    else:
        entry["goal"] = [_Flow(g) for g in complete([dict(g) for g in goal])]
    return entry


def build(part: str, hand_written: list, taken: frozenset[str] = frozenset()) -> dict:
    """One part; ``taken``: the other part's instructions (a generated one of them is left out)."""
    entries = [_entry(part, "hand", n, *row) for n, row in enumerate(hand_written)]
    seen = {e["instruction"] for e in entries} | set(taken)
    for n, row in enumerate(_generated(part)):
        if row[1] not in seen:
            seen.add(row[1])
            entries.append(_entry(part, "generated", n, *row))
    for entry in entries:
        assert set(entry["classes"]) <= set(CLASSES), entry
    return {"part": part, "entries": entries}


HEADERS = {
    "test": """# The offline composer's paraphrase corpus, TEST part (issue 45). Built by build_corpus.py.
#
# Written before any rule of issue 45, and never tuned on: the rules are tuned on corpus_dev.yaml
# only; this part is measured (benchmarks/bench_language.py, tests/test_agents_rules_corpus.py).
# Each entry: task (its seeded scene, seed 0), instruction, classes of phrasing, source (hand or
# generated from templates x lexicons), and the goal it means (a goal spec's goals, as
# `agentchord schema goal` writes them) or expect: refused (the scene cannot do what it asks).
""",
    "dev": """# The offline composer's paraphrase corpus, DEVELOPMENT part (issue 45). Built by build_corpus.py.
#
# The rules are tuned on this part (the test part, corpus_test.yaml, is not tuned on). It holds
# the seven examples of issue 45 and hand-written and generated instructions of its own templates.
# Each entry: task (its seeded scene, seed 0), instruction, classes of phrasing, source (hand or
# generated), and the goal it means (a goal spec's goals) or expect: refused.
""",
}


class _Flow(dict):
    """A goal predicate, written on one line."""


class _Dumper(yaml.SafeDumper):
    def ignore_aliases(self, data: object) -> bool:
        return True


_Dumper.add_representer(_Flow, lambda d, data: d.represent_mapping("tag:yaml.org,2002:map", data.items(), flow_style=True))
_Dumper.add_representer(list, lambda d, data: d.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=all(isinstance(x, (int, float, str)) for x in data) and len(data) <= 3 and not all(isinstance(x, str) for x in data)))


def main() -> None:
    taken: frozenset[str] = frozenset()
    for part, hand_written in (("test", HAND_TEST), ("dev", HAND_DEV)):
        data = build(part, hand_written, taken)
        taken = frozenset(e["instruction"] for e in data["entries"])
        text = yaml.dump(data, Dumper=_Dumper, sort_keys=False, width=200, allow_unicode=True)
        (HERE / f"corpus_{part}.yaml").write_text(HEADERS[part] + text, encoding="utf-8")
        hand_n = sum(e["source"] == "hand" for e in data["entries"])
        print(f"corpus_{part}.yaml: {len(data['entries'])} entries ({hand_n} hand-written, {len(data['entries']) - hand_n} generated)")


# --- hand-written: the development part (the seven examples of issue 45 first) -------------

HAND_DEV: list[tuple[str, str, str, object]] = [
    ("blocks", "take the blue block and set it on the red one", "pronoun synonym", [on("blue_block", "red_block")]),
    ("pour1", "tip the bottle into the cup", "synonym", POUR1),
    ("pour1", "empty the bottle into the cup", "synonym", POUR1),
    ("pour1", "pour the water from the bottle into the cup and leave the bottle standing on the table", "state", POUR1),
    ("table", "put the spoon by the plate, and the fork too", "ellipsis", [SETTING[1], SETTING[0]]),
    ("pour1", "put the bottle down upright after pouring it into the cup", "temporal pronoun", POUR1),
    ("towel", "lay the bottom corners of the towel on its top corners", "synonym pronoun", FOLD),
    ("blocks", "the block ends up in the cup", "scene_goal", REFUSE),
    ("blocks", "the red block ends up on the blue one", "scene_goal pronoun", [on("red_block", "blue_block")]),
    ("pour2", "tip the bottle into the cup", "synonym", POUR1),
    ("pour2", "Hold the cup with your left hand and tip the bottle into it with your right hand.", "arm pronoun synonym", [pour(arm="right", hold=True), put("cup", "left"), put("bottle")]),
    ("pour2", "With both hands: pour the bottle into the cup, then put the two of them down.", "arm pronoun", POUR2),
    ("pour2", "The left arm holds the cup while the right arm empties the bottle into it.", "temporal arm declarative", [pour(arm="right", hold=True), put("cup", "left"), put("bottle")]),
    ("pour2", "Could you fill the cup from the bottle using both arms?", "politeness arm", POUR2),
    # Added after the test part was measured (issue 45's report): a holding clause after "while".
    ("pour2", "Tip the bottle into the cup while the left hand keeps the cup steady.", "temporal arm synonym", [pour(hold=True), put("cup", "left"), put("bottle")]),
    ("pour1", "Pour the water into the cup while the left gripper holds it.", "temporal arm pronoun", [pour(hold=True), put("cup", "left"), put("bottle")]),
    ("pour1", "Fill the cup with water from the bottle and then put the bottle back where it was.", "reference", POUR1),
    ("pour1", "Get the bottle, empty it into the cup, and leave it on the table.", "pronoun synonym state", POUR1),
    ("pour1", "After pouring the bottle into the cup, stand it back on the table.", "temporal pronoun", POUR1),
    ("pour1", "Before you put the bottle down, tip it into the cup.", "temporal pronoun", POUR1),
    ("pour1", "Make sure there is water in the cup from the bottle.", "scene_goal", POUR1),
    ("pour1", "Pur water from the bottel into the cup and put the bottle down", "typo", POUR1),
    ("pour1", "Push the cup to the right.", "synonym reference", [nudge("single_arm_pour_water", "cup", "right")]),
    ("pour1", "Place the cup next to the bottle.", "reference", [rel("single_arm_pour_water", "cup", "bottle")]),
    ("pour1", "Put the bottle behind the cup.", "reference", [rel("single_arm_pour_water", "bottle", "cup", "behind")]),
    ("pour1", "Give the bottle to the left arm.", "synonym arm", [hand("bottle", "right", "left"), put("bottle", "left")]),
    ("pour1", "Pour the cup into the bottle.", "plain", REFUSE),
    ("pour1", "Drink the water.", "plain", REFUSE),
    ("table", "Set the fork on the left of the plate and the spoon on the right.", "reference ellipsis", SETTING),
    ("table", "Put the spoon right of the plate and the fork left of it.", "reference pronoun", [SETTING[1], SETTING[0]]),
    ("table", "Place the cutlery beside the plate.", "synonym", SETTING),
    ("table", "Lay the utensils next to the plate.", "synonym", SETTING),
    ("table", "The spoon goes on the right of the plate and the fork goes on the left.", "declarative ellipsis", [SETTING[1], SETTING[0]]),
    ("table", "Spoon to the right of the plate, fork to the left of the plate.", "ellipsis scene_goal", [SETTING[1], SETTING[0]]),
    ("table", "Could you please put the spoon next to the plate?", "politeness", [SETTING[1]]),
    ("table", "Put the spoon on the plate.", "plain", [on("spoon", "plate")]),
    ("table", "Move the fork behind the plate.", "reference", [rel(T, "fork", "plate", "behind")]),
    ("table", "Put the fork and the spoon on either side of the plate.", "reference ellipsis", SETTING),
    ("table", "Stack the plate on the cup.", "plain", REFUSE),
    ("hand", "Pass the block from your left hand to your right hand, then drop it in the target region.", "arm pronoun synonym", HANDOVER),
    ("hand", "Pick the block up with the left gripper, give it to the right gripper, and put it on the target.", "arm pronoun synonym", HANDOVER),
    ("hand", "Once the right hand has the block from the left hand, place it in the target zone.", "temporal arm pronoun", HANDOVER),
    ("hand", "The block goes to the target region, handed over from the left arm to the right arm first.", "scene_goal temporal", HANDOVER),
    ("hand", "Put the block in the target region after handing it over from the left arm to the right arm.", "temporal pronoun", HANDOVER),
    ("hand", "Switch the block to the right hand and leave it in the target region.", "synonym state", HANDOVER),
    ("hand", "Move the block to the left side of the table.", "reference", [at("block", "left")]),
    ("hand", "Put the block on the front left corner of the table.", "reference", [at("block", "front left corner")]),
    ("hand", "Hnad the blcok over to the rigth arm, then palce it in the target region.", "typo", HANDOVER),
    ("coffee", "Insert the pod in the tray, then push the tray forward with both hands.", "synonym arm", COFFEE),
    ("coffee", "The capsule goes into the tray and the tray goes forward.", "declarative scene_goal", COFFEE),
    ("coffee", "Slide the tray forward once the capsule is inside it.", "temporal pronoun state", COFFEE),
    ("coffee", "Before pushing the tray forward, drop the capsule into it.", "temporal pronoun", COFFEE),
    ("coffee", "Put the coffee capsule in the tray, and then move it forward.", "pronoun", COFFEE),
    ("coffee", "Place the capsule next to the tray.", "reference", [rel("setup_coffee_tray", "capsule", "tray")]),
    ("coffee", "Put the capsule into the cup.", "plain", REFUSE),
    ("towel", "Fold the towel in half from bottom to top.", "synonym", FOLD),
    ("towel", "Take the near corners of the cloth and lay them on the far corners.", "synonym pronoun", FOLD),
    ("towel", "Bring the bottom edge of the towel onto the top edge.", "synonym", FOLD),
    ("towel", "Fold the towel over, please.", "politeness", FOLD),
    ("towel", "I want the towel folded.", "declarative state", FOLD),
    ("towel", "Fold the towell in half.", "typo", FOLD),
    ("towel", "Fold the towel into quarters.", "plain", REFUSE),
    ("blocks", "Put the blue block on the red one, please.", "pronoun politeness", [on("blue_block", "red_block")]),
    ("blocks", "Put the red block in the cup, and the blue block too.", "ellipsis", [into("red_block", "cup"), into("blue_block", "cup")]),
    ("blocks", "Put both blocks in the cup.", "ellipsis", [into("red_block", "cup"), into("blue_block", "cup")]),
    ("blocks", "Place the right block on the left one.", "reference pronoun", [on("blue_block", "red_block")]),
    ("blocks", "Put the block closest to the cup into it.", "reference pronoun", [into("red_block", "cup")]),
    ("blocks", "Put the red block to the left of the blue block.", "reference", [rel(B, "red_block", "blue_block", "left")]),
    ("blocks", "The blue block should be in the cup.", "declarative", [into("blue_block", "cup")]),
    ("blocks", "Red block on blue block.", "scene_goal", [on("red_block", "blue_block")]),
    ("blocks", "Grab the red block with your right hand and drop it into the cup.", "arm pronoun synonym", [into("red_block", "cup", "right")]),
    ("blocks", "Using the left gripper, put the blue block on the red block.", "arm", [on("blue_block", "red_block", "left")]),
    ("blocks", "Stack the bleu block on the red blcok.", "typo", [on("blue_block", "red_block")]),
    ("blocks", "Move the red block back where it was.", "reference", [put("red_block")]),
]


if __name__ == "__main__":
    main()
