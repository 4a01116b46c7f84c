"""Blocks and cup: a scene with no library graph, judged by the goal it is planned for."""

from __future__ import annotations

import numpy as np
import pytest

from agentchord.agents.rules.goals import Folded, GoalSpec, Inside, On, Poured
from agentchord.features.oracle import OracleExtractor
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld

TASK = SIM_TASKS["blocks_and_cup"]


def world_and_frame(seed=0):
    world = SimWorld(TASK.sample_scene(np.random.default_rng(seed)))
    for _ in range(25):  # let everything settle
        world.step()
    return world, OracleExtractor(world).update()


def test_scene_is_seeded_and_the_cup_is_open():
    a, b = TASK.sample_scene(np.random.default_rng(3)), TASK.sample_scene(np.random.default_rng(3))
    assert a == b
    cup = next(o for o in a.objects if o.name == "cup")
    assert len(cup.parts) == 5  # a floor and four walls


def test_without_a_goal_nothing_can_be_judged():
    world, frame = world_and_frame()
    verdict = TASK.success_tracker().verdict(frame, world)
    assert not verdict.success and "no goal" in verdict.reason


@pytest.mark.parametrize("goal", [On(obj="red_block", support="blue_block"), Inside(obj="red_block", container="cup")])
def test_an_unmet_goal_fails_with_the_reason(goal):
    world, frame = world_and_frame()
    tracker = TASK.success_tracker()
    tracker.expect(GoalSpec(goals=[goal]), [])
    verdict = tracker.verdict(frame, world)
    assert not verdict.success and "red_block" in verdict.reason


def test_a_met_goal_passes():
    world, frame = world_and_frame()
    tracker = TASK.success_tracker()
    # The blue block rests released on the table: "placed where it is" holds.
    from agentchord.agents.rules.goals import Placed

    tracker.expect(GoalSpec(goals=[Placed(obj="blue_block")]), [])
    assert tracker.verdict(frame, world).success


def test_a_predicate_it_cannot_judge_falls_back_to_the_graph_constraints():
    world, frame = world_and_frame()
    tracker = TASK.success_tracker()
    # A fold is not judged on the world: the planned graph's goal constraints are.
    tracker.expect(GoalSpec(goals=[Folded(cloth="towel")]), ["70 - tilt(red_block)"])
    verdict = tracker.verdict(frame, world)
    assert not verdict.success and "70 - tilt(red_block)" in verdict.reason


def test_a_pour_is_an_event_that_must_have_been_seen():
    world, frame = world_and_frame()
    tracker = TASK.success_tracker()
    tracker.expect(GoalSpec(goals=[Poured(source="red_block", target="cup")]), [])
    verdict = tracker.verdict(frame, world)
    assert not verdict.success and "the red_block never reached a pouring orientation above the cup" in verdict.reason
