"""Property: every graph file that ``graph check`` accepts loads, dumps and loads back to the same
graph, and runs to a verdict (success, or failure with a reason) without an exception.

The graphs are chains over the single-arm pour-water scene whose action arguments, margins,
costs, constraint constants and object names are drawn at random, hostile values included
(NaN, infinities, huge magnitudes, names that are not identifiers, arms, functions, objects
the scene lacks). A file ``graph check`` refuses must be refused with exit status 2 and no
exception; one it accepts but that names objects the scene lacks is refused before the first
tick (a verdict with the reason).
"""

from __future__ import annotations

import json
import math

import pytest
import yaml
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import ExecutorConfig
from agentchord.graph.exceptions import GraphFileError, GraphNotRunnableError
from agentchord.graph.loader import dump_graph, load_graph
from agentchord.graph.validation import check_graph

TASK = "single_arm_pour_water"
SCENE = ("bottle", "cup")

finite = st.one_of(st.floats(min_value=-0.3, max_value=0.3, allow_nan=False), st.integers(min_value=-5, max_value=5))
hostile_numbers = st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e12, 10**400])
valid_names = st.sampled_from(SCENE + ("jug", "cup2"))  # identifiers; two of them not in the scene
hostile_names = st.one_of(
    st.sampled_from(["my bottle", "__import__", "right", "dist", "if", ""]),
    st.text(alphabet="ab _-1é", min_size=1, max_size=6),
)
constants = st.sampled_from(["0.03", "0.5", "2 ** 3"])
hostile_constants = st.sampled_from(["0/0", "1e400", "-1e400", "1/0"])


@st.composite
def graph_documents(draw) -> dict:
    """A chain graph v0 -> ... -> vN of grasp / move / rotate / place calls, numbers and names drawn.

    Half the graphs mix hostile values into every kind of field; the others are well formed,
    so that accepted graphs are common too.
    """
    hostile = draw(st.booleans())
    numbers = st.one_of(finite, finite, hostile_numbers) if hostile else finite
    names = st.one_of(valid_names, hostile_names) if hostile else valid_names
    objects = draw(st.lists(names, min_size=1, max_size=3, unique=True))
    obj = objects[0]
    calls = [
        {"fn": "grasp", "args": {"obj": obj, "lift": draw(numbers)}},
        {"fn": "move_to_obj", "args": {"obj": objects[-1], "offset": [draw(numbers), draw(numbers), draw(numbers)]}},
        {"fn": "move_to_target", "args": {"pos": [draw(numbers), draw(numbers), draw(numbers)]}},
        {"fn": "rotate_eef", "args": {"angle": draw(st.one_of(numbers, st.floats(-180, 180)))}},
        {"fn": "place", "args": {"obj": obj, "target": [draw(numbers), draw(numbers)]}},
    ]
    chosen = draw(st.lists(st.sampled_from(range(len(calls))), min_size=1, max_size=3))
    nodes = [{"id": "v0", "semantic": "start"}]
    edges = []
    for i, index in enumerate(chosen, start=1):
        node = {"id": f"v{i}", "semantic": f"after step {i}"}
        if draw(st.booleans()):
            constant = draw(st.one_of(constants, hostile_constants) if hostile else constants)
            node["constraints"] = [f"dist({obj}.pos, {objects[-1]}.top) - {constant}"]
        nodes.append(node)
        edge = {"id": f"e{i}", "source": f"v{i - 1}", "target": f"v{i}", "actions": {"right": calls[index]}}
        if draw(st.booleans()):
            edge["cost"] = draw(numbers)
        edges.append(edge)
    return {"task": TASK, "start": "v0", "goal": f"v{len(chosen)}", "objects": objects, "nodes": nodes, "edges": edges}


def _write(tmp_path, data: dict, suffix: str):
    path = tmp_path / f"g{suffix}"
    # JSON with NaN literals, or YAML with .nan / .inf: what a careless tool would write.
    path.write_text(json.dumps(data) if suffix == ".json" else yaml.safe_dump(data, sort_keys=False))
    return path


def _accepted(path):
    """The graph if ``graph check`` accepts the file, else ``None`` (never an exception)."""
    try:
        graph = load_graph(path)
    except GraphFileError as error:
        assert error.problems and all(line.startswith(f"{path}: ") for line in error.problems)
        event("refused when loaded")
        return None
    if check_graph(graph):
        event("refused by the checks")
        return None
    event("accepted")
    return graph


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=graph_documents(), suffix=st.sampled_from([".yaml", ".json"]))
def test_every_accepted_file_round_trips(tmp_path, data, suffix):
    graph = _accepted(_write(tmp_path, data, suffix))
    if graph is None:
        return
    for out_suffix in (".yaml", ".json"):
        again = load_graph(dump_graph(graph, tmp_path / f"again{out_suffix}"))
        assert again == graph
        assert check_graph(again) == []


def _run_to_verdict(tmp_path, data, suffix, ticks: int) -> None:
    graph = _accepted(_write(tmp_path, data, suffix))
    if graph is None:
        return
    spec = EpisodeSpec(task=TASK, graph=graph, seed=0, config=ExecutorConfig(tick_limit=ticks))
    try:
        result = run_episode(spec)
    except GraphNotRunnableError as error:  # refused before the first tick, with the reason
        event("refused before the first tick")
        assert not set(graph.objects) <= set(SCENE)
        assert "scene has no object" in str(error)
        return
    event(f"ran: {'success' if result.success else 'failure'}")
    assert isinstance(result.success, bool)
    assert result.success or result.reason


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=graph_documents(), suffix=st.sampled_from([".yaml", ".json"]))
def test_every_accepted_file_runs_to_a_verdict(tmp_path, data, suffix):
    _run_to_verdict(tmp_path, data, suffix, ticks=40)


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(data=graph_documents(), suffix=st.sampled_from([".yaml", ".json"]))
def test_every_accepted_file_runs_to_a_verdict_long(tmp_path, data, suffix):
    _run_to_verdict(tmp_path, data, suffix, ticks=600)
