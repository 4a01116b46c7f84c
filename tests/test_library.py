"""The task library's graphs are valid and forward-moving."""

import pytest

from agentchord.agents.rules.in_hand import redone_slips
from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.graph.validation import check_graph
from agentchord.library import library_tasks, load_task_graph


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


@pytest.mark.parametrize("task", library_tasks())
def test_a_recovery_that_redoes_a_carry_watches_its_slip_as_the_arranger_would(task):
    graph = load_task_graph(task)
    for edge in graph.recovery_edges():
        have = {(f.name, f.monitor, f.recovery) for f in edge.failures}
        for mode in redone_slips(graph, edge):
            assert (mode.name, mode.monitor, mode.recovery) in have, f"{task}: {edge.id} does not watch {mode.name}"


def test_the_redone_carries_of_the_pours_are_the_re_approaches_and_the_offer_beside_a_regrasp():
    single, dual = load_task_graph("single_arm_pour_water"), load_task_graph("dual_arm_pour_water")
    watched = {(e.id, f.name) for g in (single, dual) for e in g.recovery_edges() for f in e.failures if f.intent == "reseat"}
    assert {("e2_r_cup_shifted", "bottle_slipped"), ("e3_r_cup_shifted", "bottle_slipped"), ("e2_r_bottle_dropped", "cup_slipped")} <= watched
    # A recovery that sets the object down on purpose (the slip's own recovery) or parks it does not.
    assert not {("e2_r_bottle_slipped", "bottle_slipped"), ("e3_r_bottle_slipped", "bottle_slipped"), ("e2_r_cup_tipped", "bottle_slipped")} & watched


def test_unknown_task_is_a_clear_error():
    with pytest.raises(KeyError, match="no library graph"):
        load_task_graph("make_coffee")
