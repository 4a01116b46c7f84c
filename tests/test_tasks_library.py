"""The task library's graphs are valid and forward-moving."""

import pytest

from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.graph.validation import check_graph
from agentchord.tasks import library_tasks, load_task_graph


@pytest.mark.parametrize("task", library_tasks())
def test_library_graph_checks_clean(task):
    graph = load_task_graph(task)
    assert check_graph(graph) == []
    assert forward_filter(graph).removed == []


def test_pour_water_graph_has_drop_failures_on_every_edge_that_holds_the_bottle():
    graph = load_task_graph("single_arm_pour_water")
    assert nominal_path(graph) == ["e1", "e2", "e3", "e4", "e5", "e6"]
    # Every edge that holds the bottle -- nominal and recovery -- watches for a drop.
    holding = {e.id for e in graph.edges if e.id != "e6"}
    with_drop = {e.id for e in graph.edges if any(f.name == "bottle_dropped" for f in e.failures)}
    assert with_drop == holding
    with_shift = {e.id for e in graph.edges if any(f.name == "cup_shifted" for f in e.failures)}
    assert {"e2", "e3"} <= with_shift


def test_unknown_task_is_a_clear_error():
    with pytest.raises(KeyError, match="no library graph"):
        load_task_graph("make_coffee")
