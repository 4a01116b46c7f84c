"""What each agent call writes: the graph's parts as replies, and their size in tokens."""

import json

from agentchord.agents.replies import (
    STREAM_HEADER,
    alternatives_reply,
    branch_alternatives,
    branch_edges,
    branch_entry,
    branch_owners,
    branch_reply,
    count_tokens,
    grounding_patch,
    modes_reply,
    nominal_reply,
    stream_order,
    streamed_tokens,
)
from agentchord.library import load_task_graph


def _graph(task="single_arm_pour_water"):
    return load_task_graph(task)


def test_tokens_are_characters_of_compact_json_over_four():
    assert count_tokens("abcd") == 1 and count_tokens("abcde") == 2
    assert count_tokens({"a": [1, 2]}) == count_tokens('{"a":[1,2]}') == 3


def test_the_nominal_reply_streams_in_execution_order_each_edge_before_the_node_it_reaches():
    graph = _graph()
    reply = nominal_reply(graph)
    assert [k for k in reply] == [k for k in STREAM_HEADER if k in reply] + ["graph"]
    edges = [item for item in reply["graph"] if "source" in item]
    assert all(not e.get("failures") and e.get("kind", "nominal") == "nominal" for e in edges)
    assert {i["id"] for i in reply["graph"] if "source" not in i} == {n.id for n in graph.nodes if not n.is_recovery}
    assert stream_order(graph)[:5] == ["e1", graph.start, graph.edge("e1").target, "e2", graph.edge("e2").target]
    ends = streamed_tokens(graph)
    assert [i for i in ends if i.startswith("e")] == ["e1", "e2", "e3", "e4", "e5", "e6"]
    assert list(ends.values()) == sorted(ends.values())
    # The first edge is readable long before the whole reply, and every edge comes before the node it reaches.
    assert ends["e1"] < count_tokens(reply) / 5 and ends["e6"] < count_tokens(reply)
    assert all(ends[e.id] < ends[e.target] for e in graph.nominal_edges())


def test_every_recovery_edge_comes_with_the_first_failure_mode_that_leads_to_it():
    graph = _graph()
    owners = branch_owners(graph)
    assert set(owners) == {e.id for e in graph.recovery_edges()} | {n.id for n in graph.recovery_nodes()}
    assert owners["e1_r_bottle_dropped"] == ("e1", "bottle_dropped")
    # A second drop while the first regrasp carries the bottle on: part of the same branch.
    assert owners["r_bottle_regrasped_again"] == ("e2", "bottle_dropped")
    reply = branch_reply(graph, "e2", "bottle_dropped", owners)
    assert reply["recovery"] == "e2_r_bottle_dropped"
    assert "r_bottle_regrasped_again" in [e["id"] for e in reply["edges"]]
    assert [f["name"] for f in modes_reply(graph.edge("e2"))] == ["bottle_dropped", "cup_tipped", "cup_shifted", "bottle_slipped"]


def test_a_branch_is_written_without_the_other_arms_way_which_comes_in_a_reply_of_its_own():
    graph = _graph()
    owners = branch_owners(graph)
    # The entry the robot needs when the mode fires: the regrasp alone, not the left arm's way to it.
    assert branch_entry(graph, "e2", "bottle_dropped", owners) == ["e2_r_bottle_dropped", "r_bottle_regrasped"]
    reply = branch_reply(graph, "e2", "bottle_dropped", owners)
    written = [item["id"] for part in ("entry", "nodes", "edges") for item in reply[part]]
    assert "e2_r_bottle_dropped_via_left" not in written
    assert all(e.alternative_to is None for e in branch_edges(graph, "e2", "bottle_dropped", owners))
    # The branch's alternatives: the entry's, and that of the regrasp again on a second drop.
    alternatives = branch_alternatives(graph, "e2", "bottle_dropped", owners)
    assert {(e.id, e.alternative_to) for e in alternatives} == {
        ("e2_r_bottle_dropped_via_left", "e2_r_bottle_dropped"), ("r_bottle_regrasped_again_via_left", "r_bottle_regrasped_again")}
    assert [a["id"] for a in alternatives_reply(graph, "e2", "bottle_dropped", owners)["alternatives"]] == [e.id for e in alternatives]
    # Every recovery edge is written exactly once, in a branch or in an alternatives reply.
    once = []
    for edge_id, failure in [(e.id, f.name) for e in graph.nominal_edges() for f in e.failures]:
        once += [e.id for e in branch_edges(graph, edge_id, failure, owners) + branch_alternatives(graph, edge_id, failure, owners)]
    assert sorted(once) == sorted(e.id for e in graph.recovery_edges())


def test_the_conductor_writes_the_values_it_grounds_not_the_structure():
    graph = _graph()
    patch = grounding_patch([graph.edge("e2")])
    assert patch["e2"]["0.right.offset"] == [0.0, -0.09, 0.08] and patch["e2"]["0.right.yaw"] == 180
    assert patch["e2"]["bottle_dropped"] == [0.0, 3]
    assert "obj" not in json.dumps(patch)  # an object's name is structure, kept as the composer wrote it
    grasp = graph.edge("e1").model_copy(update={"failures": []})
    assert grounding_patch([grasp]) == {}  # nothing numeric to ground in a plain grasp
