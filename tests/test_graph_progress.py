"""Tests of agentchord.graph.progress: cost-to-go and the forward-moving filter (Eq. 8)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from agentchord.actions.catalog import ACTIONS
from agentchord.graph import (
    Edge,
    NoPathError,
    TaskGraph,
    UnknownActionError,
    augmented_digraph,
    cost_to_go,
    edge_cost,
    forward_filter,
    load_graph,
    nominal_path,
    recovery_reach,
)

POUR = Path(__file__).parent / "data" / "graphs" / "pour_water.yaml"
BACK = {"right": {"fn": "back"}}


def _edge(edge_id: str, source: str, target: str, cost: float | None = None, **extra: Any) -> dict[str, Any]:
    return {"id": edge_id, "source": source, "target": target, "actions": BACK, "cost": cost, **extra}


def _failure(name: str, recovery: str) -> dict[str, Any]:
    return {"name": name, "monitor": "0.5 - holding(right, bottle)", "intent": "recover", "recovery": recovery}


def _chain() -> dict[str, Any]:
    """v0 -> v1 -> v2 -> v3 -> v4 (goal), 100 ticks each: D(v1) = 300."""
    return {
        "task": "chain",
        "start": "v0",
        "goal": "v4",
        "objects": ["bottle"],
        "nodes": [{"id": f"v{i}", "semantic": f"sub-goal {i}"} for i in range(5)],
        "edges": [_edge(f"e{i + 1}", f"v{i}", f"v{i + 1}", 100) for i in range(4)],
    }


def _with_branches() -> TaskGraph:
    """A regressive branch r_x (D = 50 + 300 = 350) and an admissible one back to v1 itself, both on e2."""
    data = _chain()
    data["nodes"].append({"id": "r_x", "kind": "recovery", "semantic": "bottle at the home pose"})
    data["edges"][1]["failures"] = [_failure("bottle_dropped", "e2_r_x"), _failure("bottle_slipped", "e2_r_self")]
    data["edges"] += [
        _edge("e2_r_x", "v1", "r_x", 10, kind="recovery"),
        _edge("r_x_to_v1", "r_x", "v1", 50, kind="recovery"),
        _edge("e2_r_self", "v1", "v1", 120, kind="recovery"),
    ]
    return TaskGraph.model_validate(data)


def test_edge_cost_sums_steps_and_takes_the_slowest_arm() -> None:
    grasp, move, back = (ACTIONS[n].expected_ticks for n in ("grasp", "move_to_obj", "back"))
    sync = Edge.model_validate(
        {
            "id": "e",
            "source": "a",
            "target": "b",
            "actions": {"left": {"fn": "back"}, "right": {"fn": "grasp", "args": {"obj": "x"}}},
        }
    )
    assert edge_cost(sync) == max(grasp, back)
    seq = Edge.model_validate(
        {
            "id": "e",
            "source": "a",
            "target": "b",
            "actions": [{"right": {"fn": "grasp"}}, {"left": None, "right": {"fn": "move_to_obj"}}],
        }
    )
    assert edge_cost(seq) == grasp + move
    assert edge_cost(seq.model_copy(update={"cost": 7.5})) == 7.5


def test_edge_cost_of_unknown_action_raises() -> None:
    edge = Edge.model_validate({"id": "e", "source": "a", "target": "b", "actions": {"right": {"fn": "jump"}}})
    with pytest.raises(UnknownActionError, match="edge 'e' calls unknown action 'jump'"):
        edge_cost(edge)


def test_cost_to_go_of_pour_water() -> None:
    graph = load_graph(POUR)
    d = cost_to_go(graph)
    assert d == {"v0": 630, "v1": 440, "v2": 330, "v3": 250, "v4": 170, "v5": 0, "r_bottle_regrasped": 440}
    assert nominal_path(graph) == ["e1", "e2", "e3", "e4", "e5"]


def test_cost_to_go_is_inf_where_goal_unreachable() -> None:
    data = _chain()
    data["nodes"].append({"id": "island", "semantic": "cut off"})
    assert cost_to_go(TaskGraph.model_validate(data))["island"] == math.inf


def test_parallel_edges_keep_the_cheapest() -> None:
    data = _chain()
    data["edges"].append(_edge("e1_fast", "v0", "v1", 30))
    graph = TaskGraph.model_validate(data)
    assert augmented_digraph(graph).edges["v0", "v1"] == {"weight": 30, "edge": "e1_fast"}
    assert cost_to_go(graph)["v0"] == 330
    assert nominal_path(graph) == ["e1_fast", "e2", "e3", "e4"]


def test_nominal_path_ignores_recovery_shortcuts() -> None:
    data = _chain()
    data["edges"].append(_edge("shortcut", "v0", "v4", 1, kind="recovery"))
    graph = TaskGraph.model_validate(data)
    assert cost_to_go(graph)["v0"] == 1
    assert nominal_path(graph) == ["e1", "e2", "e3", "e4"]
    data["edges"][2]["kind"] = "recovery"
    with pytest.raises(NoPathError, match="goal 'v4' is not reachable from start 'v0' over nominal edges"):
        nominal_path(TaskGraph.model_validate(data))


def test_forward_filter_removes_the_regressive_branch_and_says_why() -> None:
    graph = _with_branches()
    result = forward_filter(graph)
    [removed] = result.removed
    assert removed.reason == "D(r_x, goal)=350  >  D(v1, goal)=300"
    assert (removed.failure, removed.edge, removed.recovery_edge, removed.recovery_node, removed.context) == (
        "bottle_dropped",
        "e2",
        "e2_r_x",
        "r_x",
        "v1",
    )
    assert (removed.recovery_cost, removed.context_cost) == (350, 300)
    # Routed back to the failure context itself: admissible with equality.
    [kept] = result.kept
    assert (kept.failure, kept.recovery_node, kept.context) == ("bottle_slipped", "v1", "v1")
    assert kept.admissible and kept.reason == "D(v1, goal)=300  <=  D(v1, goal)=300"

    filtered = result.graph
    assert [f.name for f in filtered.edge("e2").failures] == ["bottle_slipped"]
    assert result.removed_edges == ["e2_r_x", "r_x_to_v1"]
    assert result.removed_nodes == ["r_x"]
    assert [e.id for e in filtered.edges] == ["e1", "e2", "e3", "e4", "e2_r_self"]
    assert "r_x" not in {n.id for n in filtered.nodes}
    # The input graph is left as it was.
    assert len(graph.edge("e2").failures) == 2 and len(graph.edges) == 7


def test_forward_filter_keeps_recovery_nodes_that_a_kept_branch_still_reaches() -> None:
    data = _chain()
    data["nodes"] += [{"id": r, "kind": "recovery", "semantic": r} for r in ("r_x", "r_y")]
    data["edges"][1]["failures"] = [_failure("bottle_dropped", "e2_r")]  # v1, D = 300
    data["edges"][2]["failures"] = [_failure("bottle_dropped", "e3_r")]  # v2, D = 200
    data["edges"] += [
        _edge("e2_r", "v1", "r_x", 10, kind="recovery"),
        _edge("r_x_to_r_y", "r_x", "r_y", 300, kind="recovery"),  # D(r_x) = 450: regressive
        _edge("e3_r", "v2", "r_y", 100, kind="recovery"),
        _edge("r_y_to_v3", "r_y", "v3", 50, kind="recovery"),  # D(r_y) = 150: forward
    ]
    result = forward_filter(TaskGraph.model_validate(data))
    assert [b.reason for b in result.removed] == ["D(r_x, goal)=450  >  D(v1, goal)=300"]
    assert [b.reason for b in result.kept] == ["D(r_y, goal)=150  <=  D(v2, goal)=200"]
    assert (result.removed_edges, result.removed_nodes) == (["e2_r", "r_x_to_r_y"], ["r_x"])
    assert [e.id for e in result.graph.recovery_edges()] == ["e3_r", "r_y_to_v3"]


def test_forward_filter_on_pour_water_removes_nothing() -> None:
    graph = load_graph(POUR)
    result = forward_filter(graph)
    assert result.removed == [] and result.graph == graph
    assert len(result.kept) == 3


def test_recovery_reach_stops_at_merge_nodes() -> None:
    graph = load_graph(POUR)
    edges, nodes = recovery_reach(graph, ["e2_r_bottle_dropped"])
    assert edges == {"e2_r_bottle_dropped", "r_bottle_regrasped_to_v2"}
    assert nodes == {"r_bottle_regrasped", "v2"}


def _bellman_ford_to_goal(graph: TaskGraph) -> dict[str, float]:
    """An independent cost-to-go: relax every edge until nothing changes."""
    d = {n.id: math.inf for n in graph.nodes}
    d[graph.goal] = 0.0
    for _ in range(len(d)):
        for edge in graph.edges:
            d[edge.source] = min(d[edge.source], edge_cost(edge) + d[edge.target])
    return d


@st.composite
def random_graphs(draw: st.DrawFn) -> TaskGraph:
    """A nominal chain with random forward skips, plus recovery branches from random contexts."""
    costs = st.one_of(st.none(), st.integers(1, 400).map(float), st.floats(0.5, 400.0))
    n = draw(st.integers(2, 7))
    data = _chain()
    data.update(goal=f"v{n - 1}", nodes=[{"id": f"v{i}", "semantic": "s"} for i in range(n)], edges=[])
    data["edges"] = [_edge(f"e{i}", f"v{i}", f"v{i + 1}", draw(costs)) for i in range(n - 1)]
    for k in range(draw(st.integers(0, 3))):
        i = draw(st.integers(0, n - 2))
        j = draw(st.integers(i + 1, n - 1))
        data["edges"].append(_edge(f"skip{k}", f"v{i}", f"v{j}", draw(costs)))
    nominal_nodes = [f"v{i}" for i in range(n)]
    recovery_nodes = [f"r{k}" for k in range(draw(st.integers(0, 3)))]
    for r in recovery_nodes:
        data["nodes"].append({"id": r, "kind": "recovery", "semantic": "s"})
        data["edges"].append(_edge(f"{r}_exit", r, draw(st.sampled_from(nominal_nodes)), draw(costs), kind="recovery"))
    nominal = [e for e in data["edges"] if e.get("kind") != "recovery"]
    for b in range(draw(st.integers(0, 6))):
        failing = draw(st.sampled_from(nominal))
        target = draw(st.sampled_from(nominal_nodes + recovery_nodes))
        data["edges"].append(_edge(f"entry{b}", failing["source"], target, draw(costs), kind="recovery"))
        failing.setdefault("failures", []).append(_failure(f"f{b}", f"entry{b}"))
    return TaskGraph.model_validate(data)


@settings(max_examples=150, deadline=None)
@given(random_graphs())
def test_forward_filter_keeps_exactly_the_forward_moving_branches(graph: TaskGraph) -> None:
    d = cost_to_go(graph)
    assert d == pytest.approx(_bellman_ford_to_goal(graph))
    result = forward_filter(graph)

    for branch in result.kept:
        assert d[branch.recovery_node] <= d[branch.context] + 1e-9
    for branch in result.removed:
        assert d[branch.recovery_node] > d[branch.context] + 1e-9
    # Every failure mode is judged once, and exactly the kept ones remain.
    judged = sorted((b.edge, b.failure) for b in result.kept + result.removed)
    assert judged == sorted((e.id, f.name) for e, f in graph.failures())
    assert sorted((e.id, f.name) for e, f in result.graph.failures()) == sorted(
        (b.edge, b.failure) for b in result.kept
    )
    # Nothing dangles: every remaining recovery edge or node is on a remaining branch, or already was on none.
    entries = [f.recovery for _, f in result.graph.failures()]
    edges, nodes = recovery_reach(result.graph, entries)
    before_edges, before_nodes = recovery_reach(graph, [f.recovery for _, f in graph.failures()])
    for edge in result.graph.recovery_edges():
        assert edge.id in edges or edge.id not in before_edges
    for node in result.graph.recovery_nodes():
        assert node.id in nodes or node.id not in before_nodes
    ids = {n.id for n in result.graph.nodes}
    assert all(e.source in ids and e.target in ids for e in result.graph.edges)
    # Nominal structure is untouched.
    assert [e.id for e in result.graph.nominal_edges()] == [e.id for e in graph.nominal_edges()]
