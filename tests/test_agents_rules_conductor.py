"""The conductor: free keyframes solved clear of other objects, warm starts, structure kept."""

from __future__ import annotations

from agentchord.agents.checks import check_reply
from agentchord.agents.reasoner import ConductRequest
from agentchord.agents.scene import Scene, SceneObject
from agentchord.agents.rules.conductor import Conductor
from agentchord.graph.models import ActionCall, Edge, Node, TaskGraph


def _graph(target):
    return TaskGraph(
        task="t", start="v0", goal="v2", objects=["bottle", "cup"],
        nodes=[Node(id="v0", semantic="start"), Node(id="v1", semantic="held"), Node(id="v2", semantic="placed")],
        edges=[
            Edge(id="e1", source="v0", target="v1", actions={"right": ActionCall(fn="grasp", args={"obj": "bottle"})}),
            Edge(id="e2", source="v1", target="v2", actions={"right": ActionCall(fn="place", args={"obj": "bottle", "target": target})},
                 path_constraints=["tilt(bottle) - 20"]),
        ],
    )


SCENE = Scene(objects=[
    SceneObject(name="bottle", pos=(0.10, 0.45, 0.09), extent=(0.05, 0.05, 0.18)),
    SceneObject(name="cup", pos=(0.0, 0.55, 0.05), extent=(0.06, 0.06, 0.1)),
])


def test_a_clear_spot_stays_and_a_blocked_one_moves_off_the_obstacle():
    conductor = Conductor()
    clear = conductor.conduct(_graph([0.10, 0.45]), SCENE)
    assert clear.edge("e2").steps[0]["right"].args["target"] == [0.10, 0.45]
    blocked = conductor.conduct(_graph([0.02, 0.55]), SCENE)  # 2 cm from the cup's centre
    spot = blocked.edge("e2").steps[0]["right"].args["target"]
    assert ((spot[0] - 0.0) ** 2 + (spot[1] - 0.55) ** 2) ** 0.5 > 0.05
    assert conductor.report[-1].feasible and conductor.report[-1].after == spot


def test_the_same_keyframe_again_is_warm_started():
    conductor = Conductor()
    conductor.conduct(_graph([0.02, 0.55]), SCENE)
    conductor.conduct(_graph([0.02, 0.55]), SCENE)
    assert [k.method for k in conductor.report] == ["warm"]


def test_structure_is_kept_and_carried_motions_under_path_constraints_are_solved():
    graph = _graph([0.10, 0.45])
    graph.edges[1].actions = [{"right": ActionCall(fn="move_to_obj", args={"obj": "cup", "offset": [0, -0.09, 0.08]})}]
    request = ConductRequest(graph=graph, scene=SCENE)
    out = Conductor().conduct(graph, SCENE)
    assert check_reply(request, out) == []
    assert out.edge("e2").steps[0]["right"].args["path"] == "solved"
    assert "path" not in graph.edge("e2").steps[0]["right"].args  # the input is not changed
