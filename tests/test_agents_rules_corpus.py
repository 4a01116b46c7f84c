"""The paraphrase corpus of issue 45 (tests/data/language/corpus_*.yaml): rates that must not fall.

The test part is never tuned on: its rate is a floor measured once (171 of 178 planned to the
labelled goal, 7 refused, none wrong). The default suite grounds every entry (goal only, a few
seconds); composing the graphs of the test part is the slow test.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from functools import cache

import numpy as np

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.scene import Scene
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld
from agentchord.agents.rules import corpus
from agentchord.agents.rules.instructions import ground_instruction


@cache
def scene(task: str) -> Scene:
    """The task's seeded scene (seed 0, oracle perception): the corpus is labelled in these."""
    sim = SIM_TASKS[task]
    return observe(SimWorld(sim.sample_scene(np.random.default_rng([0, 0x5CE7E]))), task_regions(sim))

DATA = Path(__file__).parent / "data" / "language"
TEST = corpus.load(DATA / "corpus_test.yaml")
DEV = corpus.load(DATA / "corpus_dev.yaml")
#: Measured floors (right / all) on each part.
FLOOR = {"test": 0.95, "dev": 0.95}

#: The seven examples of issue 45 and what each must give (None: refused).
ISSUE = [
    ("blocks_and_cup", "take the blue block and set it on the red one"),
    ("single_arm_pour_water", "tip the bottle into the cup"),
    ("single_arm_pour_water", "empty the bottle into the cup"),
    ("single_arm_pour_water", "pour the water from the bottle into the cup and leave the bottle standing on the table"),
    ("rearrange_table", "put the spoon by the plate, and the fork too"),
    ("single_arm_pour_water", "put the bottle down upright after pouring it into the cup"),
    ("fold_towel", "lay the bottom corners of the towel on its top corners"),
]


def test_the_corpus_is_large_and_split():
    assert len(TEST) + len(DEV) >= 300
    assert not {e["instruction"] for e in TEST} & {e["instruction"] for e in DEV}
    for entries in (TEST, DEV):
        assert {c for e in entries for c in e["classes"]} >= set(corpus.CLASSES) - {"plain"}


@pytest.mark.parametrize(("part", "entries"), [("test", TEST), ("dev", DEV)])
def test_grounding_keeps_its_rate_and_never_reads_a_wrong_goal(part, entries):
    outcomes = [corpus.evaluate(e, scene(e["task"]), plan=False) for e in entries]
    wrong = [f"{o.entry['id']}: {o.entry['instruction']} -> {o.detail}" for o in outcomes if o.verdict == "wrong"]
    right = sum(o.verdict == "right" for o in outcomes)
    assert not wrong, "\n".join(wrong)
    assert right / len(entries) >= FLOOR[part], corpus.table(outcomes)


def test_the_issue_examples_read_as_meant():
    goals = {(t, i): ground_instruction(i, scene(t)).goals for t, i in ISSUE}
    kinds = [[g.kind for g in goals[case]] for case in ISSUE]
    assert kinds == [["on_top_of"], ["poured", "placed"], ["poured", "placed"], ["poured", "placed"],
                     ["placed", "placed"], ["poured", "placed"], ["folded"]]
    assert goals[ISSUE[0]][0].obj == "blue_block" and goals[ISSUE[0]][0].support == "red_block"
    spoon, fork = goals[ISSUE[4]]
    assert (spoon.obj, fork.obj) == ("spoon", "fork") and spoon.offset[0] > 0 > fork.offset[0]


def test_a_scene_stated_ambiguously_is_refused_with_the_choices():
    with pytest.raises(Exception, match="is ambiguous: it could be red_block, blue_block"):
        ground_instruction("the block ends up in the cup", scene("blocks_and_cup"))


@pytest.mark.slow
def test_the_test_part_plans_to_its_labels():
    outcomes = [corpus.evaluate(e, scene(e["task"]), plan=True) for e in TEST]
    assert not [o for o in outcomes if o.verdict == "wrong"]
    assert sum(o.verdict == "right" for o in outcomes) / len(TEST) >= FLOOR["test"], corpus.table(outcomes)
