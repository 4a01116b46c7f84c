"""Measure the offline composer on a labelled paraphrase corpus (``tests/data/language/corpus_*.yaml``).

Each entry is an instruction in a task's seeded scene and the goal it means (or ``expect:
refused``). An entry's outcome is *right* (planned to a graph whose goal equals the label, or
refused where a refusal is expected), *refused* (the composer said why it cannot), or *wrong*
(planned to another goal, or planned where a refusal was expected): a refusal is better than
a wrong plan, and the two are counted apart.

Goals compare as ordered lists, to the centimetre and the degree (as :meth:`GoalSpec.outcome`),
arms included, except that a run of put-backs (``placed`` with no place) compares as a set:
``put both down`` states no order.
"""

from __future__ import annotations

import time
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path

import yaml
from pydantic import ValidationError

from agentchord.agents.exceptions import InfeasibleGoalError, ReasonerError
from agentchord.agents.scene import Scene
from agentchord.agents.rules.composer import compose
from agentchord.agents.rules.feasibility import goal_problems
from agentchord.agents.rules.goals import GoalSpec, Placed
from agentchord.agents.rules.instructions import ground_instruction

#: The classes of phrasing of issue 45 (an entry has one or more).
CLASSES = ("plain", "synonym", "pronoun", "ellipsis", "arm", "state", "temporal", "scene_goal", "reference",
           "politeness", "declarative", "typo")


@dataclass
class Outcome:
    """What became of one entry.

    Attributes:
        entry: The corpus entry.
        verdict: ``right``, ``refused`` or ``wrong``.
        detail: The refusal's message, or the goal planned where it is wrong.
        ground_s: Seconds to read the instruction into a goal (parse and ground).
        plan_s: Seconds to compose its nominal graph (0 when not planned).
    """

    entry: dict
    verdict: str
    detail: str = ""
    ground_s: float = 0.0
    plan_s: float = 0.0


def load(path: Path) -> list[dict]:
    """The entries of a corpus file."""
    return yaml.safe_load(path.read_text(encoding="utf-8"))["entries"]


#: The blind set's writers read while the rules grow (their failures read by kind), and the one held out for the final measurement.
BLIND_DEVELOPMENT = "ABCDEFGHIJK"
BLIND_FINAL = "L"


def load_blind(folder: Path, writers: Iterable[str]) -> list[dict]:
    """The blind evaluation set's entries of ``writers`` (``A`` ...), as corpus entries: each writer's
    instructions (``writer_X.yaml``) with the goal ``labels.yaml`` says it means (or ``expect: refused``),
    and its classes: the kinds of phrasing ``kinds.yaml`` tags it with, if any, else ``plain``."""
    labels = yaml.safe_load((folder / "labels.yaml").read_text(encoding="utf-8"))["labels"]
    kinds_path = folder / "kinds.yaml"
    kinds = yaml.safe_load(kinds_path.read_text(encoding="utf-8"))["kinds"] if kinds_path.exists() else {}
    out = []
    for writer in writers:
        for item in yaml.safe_load((folder / f"writer_{writer}.yaml").read_text(encoding="utf-8"))["entries"]:
            label = labels[item["id"]]
            entry = {"id": item["id"], "task": label["scene"], "instruction": item["instruction"],
                     "classes": list(kinds.get(item["id"]) or ["plain"])}
            if "goal" in label:
                entry["goal"] = label["goal"]
            else:
                entry["expect"] = "refused"
            out.append(entry)
    return out


def _key(goal) -> tuple:
    fields = goal.model_dump()
    return tuple(sorted((k, round(v, 2) if isinstance(v, float) else tuple(round(x, 2) for x in v) if isinstance(v, (tuple, list)) else v)
                        for k, v in fields.items()))


def _put_back(goal) -> bool:
    return isinstance(goal, Placed) and goal.region is None and goal.at is None and goal.relative_to is None


def canonical(spec: GoalSpec) -> list:
    """The goals as comparable keys, each run of put-backs sorted (it states no order)."""
    out: list = []
    run: list = []
    for goal in spec.goals:
        if _put_back(goal):
            run.append(_key(goal))
            continue
        out += sorted(run, key=repr)
        run = []
        out.append(_key(goal))
    return out + sorted(run, key=repr)


def evaluate(entry: dict, where: Scene, plan: bool = True) -> Outcome:
    """Read (and, with ``plan``, compose) one entry in its scene and judge the result against its label.

    Args:
        entry: The corpus entry.
        where: The entry's task's default scene (the first seed's layout, oracle perception): the
            corpus is labelled in these.
        plan: Also compose the nominal graph (else the goal alone is judged).
    """
    expected = GoalSpec(goals=entry["goal"]) if "goal" in entry else None
    start = time.perf_counter()
    try:
        try:
            goal = ground_instruction(entry["instruction"], where)
        except ValidationError as error:
            raise InfeasibleGoalError([d["msg"] for d in error.errors()]) from None
        ground_s = time.perf_counter() - start
        if problems := goal_problems(goal, where):
            raise InfeasibleGoalError(problems)
    except ReasonerError as error:
        ground_s = time.perf_counter() - start
        return Outcome(entry, "right" if expected is None else "refused", str(error), ground_s)
    if expected is None or canonical(goal) != canonical(expected):
        return Outcome(entry, "wrong", str([g.model_dump(exclude_defaults=True) for g in goal.goals]), ground_s)
    if not plan:
        return Outcome(entry, "right", "", ground_s)
    start = time.perf_counter()
    try:
        compose(goal, where, entry["task"], entry["instruction"])
    except ReasonerError as error:
        return Outcome(entry, "refused", f"planning: {error}", ground_s, time.perf_counter() - start)
    return Outcome(entry, "right", "", ground_s, time.perf_counter() - start)


def table(outcomes: Iterable[Outcome]) -> dict[str, dict[str, int]]:
    """Per class of phrasing (and ``all``): how many right, refused, wrong."""
    rows: dict[str, dict[str, int]] = {c: {"right": 0, "refused": 0, "wrong": 0} for c in (*CLASSES, "all")}
    for outcome in outcomes:
        for name in (*outcome.entry["classes"], "all"):
            rows.setdefault(name, {"right": 0, "refused": 0, "wrong": 0})[outcome.verdict] += 1
    return {k: v for k, v in rows.items() if sum(v.values())}
