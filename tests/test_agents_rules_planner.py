"""The STRIPS planner and the two-arm schedule."""

from __future__ import annotations

import pytest

from agentchord.agents.exceptions import PlanningError
from agentchord.agents.rules.planner import Operator, plan, schedule


def _op(name, arm, pre, add, delete=(), cost=10, objects=()):
    return Operator(name=name, arms=(arm,), objects=tuple(objects), pre=frozenset(pre), add=frozenset(add),
                    delete=frozenset(delete), cost=cost, steps=({arm: {"fn": "back"}},))


def test_cheapest_plan_and_wildcard_delete():
    ops = [
        _op("grasp", "right", {("free", "right")}, {("holding", "right", "b")}, {("free", "right"), ("at", "b", "*")}, objects=["b"]),
        _op("place", "right", {("holding", "right", "b")}, {("at", "b", "spot"), ("free", "right")}, {("holding", "right", "b")}, objects=["b"]),
        _op("expensive", "right", {("free", "right")}, {("at", "b", "spot")}, cost=1000),
    ]
    result = plan({("free", "right"), ("at", "b", "start")}, {("at", "b", "spot")}, ops)
    assert [op.name for op in result.operators] == ["grasp", "place"]
    assert ("at", "b", "start") not in result.states[-1]


def test_unreachable_goal_names_the_missing_facts():
    with pytest.raises(PlanningError, match="poured bottle cup"):
        plan({("free", "right")}, {("poured", "bottle", "cup")}, [])


def test_independent_operators_of_two_arms_share_a_round():
    ops = [
        _op("grasp_fork", "left", {("free", "left")}, {("holding", "left", "fork")}, {("free", "left")}, objects=["fork"]),
        _op("grasp_spoon", "right", {("free", "right")}, {("holding", "right", "spoon")}, {("free", "right")}, objects=["spoon"]),
    ]
    initial = frozenset({("free", "left"), ("free", "right")})
    result = plan(initial, {("holding", "left", "fork"), ("holding", "right", "spoon")}, ops)
    rounds, states = schedule(result, initial)
    assert len(rounds) == 1 and rounds[0].arms == {"left", "right"}
    assert rounds[0].steps == [{"left": {"fn": "back"}, "right": {"fn": "back"}}]
    assert states[-1] >= {("holding", "left", "fork"), ("holding", "right", "spoon")}


def test_an_operator_that_deletes_anothers_precondition_runs_after_it():
    ops = [
        _op("approach", "right", {("on_table", "cup")}, {("ready", "right")}, objects=["bottle"]),
        _op("take_cup", "left", {("on_table", "cup")}, {("holding", "left", "cup")}, {("on_table", "cup")}, objects=["cup"]),
    ]
    initial = frozenset({("on_table", "cup")})
    result = plan(initial, {("ready", "right"), ("holding", "left", "cup")}, ops)
    rounds, _ = schedule(result, initial)
    assert len(rounds) == 2
