"""The paraphrase suite (tests/data/paraphrases.yaml): instructions grounded, planned, checked, some executed.

Each case is read in its task's seeded scene (seed 0, oracle perception). At least 95% must
ground to the expected goal; each expected goal must plan into a graph that passes
`graph check`; every refusal must name the words; the paraphrases quoted in issue 12 and the
new combinations it asks for plan end to end (compose, arrange, conduct) and, marked slow, run.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path

import numpy as np
import pytest
import yaml

from agentchord.agents.exceptions import InstructionNotGroundedError, ReasonerError
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.pipeline import make_reasoner, plan_task
from agentchord.agents.scene import Scene
from agentchord.agents.rules.composer import compose
from agentchord.agents.rules.feasibility import goal_problems
from agentchord.agents.rules.goals import GoalSpec
from agentchord.agents.rules.instructions import ground_instruction
from agentchord.graph.validation import check_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

CASES = yaml.safe_load((Path(__file__).parent / "data" / "paraphrases.yaml").read_text())["cases"]
PAPER_TASKS = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "setup_coffee_tray", "fold_towel")
GOALS = [c for c in CASES if "goal" in c]
REFUSALS = [c for c in CASES if "refused" in c]

#: The four paraphrases quoted in issue 12, and the new combinations it asks for.
ISSUE = [
    ("single_arm_pour_water", "Pour water from the bottle into the cup using the right arm, then place the bottle on the table."),
    ("dual_arm_pour_water", "Grasp the cup with the left arm and the bottle with the right arm, pour water into the cup, then put both back."),
    ("handover_block", "Hand the block over from the left arm to the right arm and place it in the target region."),
    ("setup_coffee_tray", "Put the coffee capsule into the tray, then move the tray forward with both arms."),
    ("single_arm_pour_water", "Take the bottle with the left arm, hand it over to the right arm, pour water into the cup, then set the bottle down."),
    ("blocks_and_cup", "Put the red block on the left side of the table."),
    ("handover_block", "Pick up the block with the left arm, hand it to the right arm and put it on the right side of the table."),
]


@cache
def scene(task: str, seed: int = 0) -> Scene:
    sim = SIM_TASKS[task]
    return observe(SimWorld(sim.sample_scene(np.random.default_rng([seed, 0x5CE7E]))), task_regions(sim))


def _label(case: dict) -> str:
    return f"{case['task']}: {case['instruction'][:60]}"


def test_the_suite_covers_every_paper_task_and_new_combinations():
    for task in PAPER_TASKS:
        assert sum(c["task"] == task and c["kind"] == "paraphrase" for c in CASES) >= 10, task
    assert sum(c["kind"] == "combination" and "goal" in c for c in CASES) >= 20


def test_at_least_95_percent_ground_to_the_expected_goal():
    misses = []
    for case in GOALS:
        try:
            got = ground_instruction(case["instruction"], scene(case["task"])).goals
        except ReasonerError as error:
            misses.append(f"{_label(case)}: refused: {error}")
            continue
        if got != GoalSpec(goals=case["goal"]).goals:
            misses.append(f"{_label(case)}: {[g.model_dump(exclude_defaults=True) for g in got]}")
    rate = 1.0 - len(misses) / len(GOALS)
    print(f"grounded to the expected goal: {len(GOALS) - len(misses)}/{len(GOALS)} ({100 * rate:.1f}%)")
    assert rate >= 0.95, "\n".join(misses)


@pytest.mark.parametrize("case", GOALS, ids=_label)
def test_each_expected_goal_plans_and_passes_graph_check(case):
    where = scene(case["task"])
    goal = GoalSpec(goals=case["goal"])
    assert goal_problems(goal, where) == []
    graph = compose(goal, where, case["task"], case["instruction"]).graph
    assert check_graph(graph) == []
    assert set(graph.objects) <= set(where.object_names)


@pytest.mark.parametrize("case", REFUSALS, ids=_label)
def test_each_refusal_is_a_clear_one(case):
    where = scene(case["task"])
    with pytest.raises(ReasonerError) as info:
        goal = ground_instruction(case["instruction"], where)
        if problems := goal_problems(goal, where):
            raise InstructionNotGroundedError(case["instruction"], "; ".join(problems))
    message = str(info.value)
    assert case["refused"] in message
    assert "--goal" in message and "agentchord schema goal" in message


def test_a_refusal_names_the_words_and_the_closest_understood():
    with pytest.raises(InstructionNotGroundedError) as info:
        ground_instruction("Pour water from the bottle into the cup, then juggle the cup.", scene("single_arm_pour_water"))
    message = str(info.value)
    assert "not understood: 'juggle the cup'" in message
    assert "closest understood:" in message


@pytest.mark.parametrize(("task", "instruction"), ISSUE, ids=[f"{t}: {i[:40]}" for t, i in ISSUE])
def test_the_issue_instructions_plan_end_to_end(task, instruction):
    result = plan_task(instruction, scene(task), make_reasoner("rules"), task=task)
    assert check_graph(result.graph) == []
    assert result.graph.recovery_edges()


@pytest.mark.slow
@pytest.mark.parametrize(("task", "instruction"), ISSUE, ids=[f"{t}: {i[:40]}" for t, i in ISSUE])
def test_a_sample_succeeds_when_run(task, instruction):
    from agentchord.episode import EpisodeSpec, run_episode

    result = run_episode(EpisodeSpec(task=task, seed=0, instruction=instruction))
    assert result.success, result.reason


def test_explain_prints_clauses_goals_skills_and_graph():
    from agentchord.agents.rules.explain import explain_plan

    text = explain_plan(ISSUE[2][1], scene("handover_block"))
    assert "clauses -> goal predicates:" in text
    assert "handed_over(obj=block, giver=left, receiver=right)" in text
    assert "handover: handover(left->right, block)" in text
    assert "graph (" in text and "e1: v0 -> v1" in text
    assert "the grammar stops at 'juggle'" in explain_plan("pour water into the cup then juggle", scene("single_arm_pour_water"))
