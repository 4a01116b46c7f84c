"""Tests of agentchord.graph.interop and ``agentchord import-release`` (issue 4 item 6)."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

import pytest
from click.testing import CliRunner

from agentchord.actions.catalog import PlaceArgs
from agentchord.cli import main
from agentchord.graph import check_graph, load_graph
from agentchord.graph.interop import (
    CARRY_Z,
    PLACE_Z,
    PRE_PLACE_DIS,
    TABLE_XY,
    WORKSPACE,
    FrameMap,
    ReleaseImportError,
    import_release,
    import_release_data,
)
from agentchord.graph.progress import cost_to_go, recovery_branches

#: The release's example pairs, in the shared folder beside the checkout (or inside it).
EXAMPLES = next(
    (p / "shared" / "interop" / "agentchord-release-examples" for p in Path(__file__).resolve().parents[1:3]
     if (p / "shared" / "interop" / "agentchord-release-examples").is_dir()),
    Path("/work/shared/interop/agentchord-release-examples"),
)
PAIRS = {
    "SinglePourWater": ("single_arm_pour_water", ["bottle", "cup"]),
    "DualPourWater": ("dual_arm_pour_water", ["cup", "bottle"]),
    "Rearrangement": ("rearrange_table", ["fork", "spoon", "plate"]),
}
needs_examples = pytest.mark.skipif(not EXAMPLES.is_dir(), reason="release examples not available")


def _pair(name: str) -> tuple[Path, Path]:
    return EXAMPLES / name / "agent_task_graph.json", EXAMPLES / name / "agent_recovery_spec.json"


def _call(arm: str, fn: str, **kwargs) -> dict:
    return {"fn": fn, "kwargs": {"robot_name": f"{arm}_arm", **kwargs}}


def _graph(*edges: tuple[dict | None, dict | None]) -> dict:
    """A release task graph: a chain v0 -> v1 -> ... with one edge per (left, right) pair."""
    n = len(edges)
    return {
        "task": "test task",
        "start": "v0",
        "goal": f"v{n}",
        "nodes": [{"id": f"v{i}", "semantic": f"node {i}"} for i in range(n + 1)],
        "edges": [
            {"id": f"e{i + 1}", "source": f"v{i}", "target": f"v{i + 1}", "left_arm_action": left,
             "right_arm_action": right}
            for i, (left, right) in enumerate(edges)
        ],
    }


def _spec(*bindings: dict) -> dict:
    return {"task": "test task", "recovery_bindings": list(bindings)}


def _binding(edge_id: str, name: str, monitors: list[dict], recovery: list[dict], merge: str = "target",
             repeat: bool = True) -> dict:
    return {"edge_id": edge_id, "failure_name": name, "monitors": monitors, "recovery": recovery, "merge": merge,
            "repeat_until_success": repeat}


def _hold(arm: str, obj: str) -> dict:
    return {"type": "hold_lost", "robot_name": f"{arm}_arm", "obj_name": obj, "threshold": 0.05}


#: A pour chain: grasp, move beside the cup, tilt, untilt, place, home.
POUR = _graph(
    (None, _call("right", "grasp", obj_name="bottle", pre_grasp_dis=0.1)),
    (None, _call("right", "move_relative_to_object", obj_name="cup", x_offset=0.05, y_offset=-0.1, z_offset=0.125)),
    (None, _call("right", "rotate_eef", degree=-90)),
    (None, _call("right", "rotate_eef", degree=90)),
    (None, _call("right", "place_on_table", obj_name="bottle", x=0.7, y=-0.1, pre_place_dis=0.08)),
    (_call("left", "back_to_initial_pose"), _call("right", "back_to_initial_pose")),
)


def _import(graph: dict, spec: dict | None = None, **options):
    return import_release_data(graph, spec if spec is not None else _spec(), **options)


def _args(result, edge_id: str, arm: str = "right", step: int = 0) -> tuple[str, dict]:
    call = result.graph.edge(edge_id).steps[step][arm]
    return call.fn, call.args


def _problems(graph: dict, spec: dict | None = None, **options) -> list[str]:
    with pytest.raises(ReleaseImportError) as info:
        _import(graph, spec, **options)
    return info.value.problems


# ------------------------------------------------------------------------- examples


@needs_examples
@pytest.mark.parametrize("name", PAIRS)
def test_example_pair_imports_and_checks_clean(name: str) -> None:
    result = import_release(*_pair(name))
    graph = result.graph
    task, objects = PAIRS[name]
    assert graph.task == task
    assert sorted(graph.objects) == sorted(objects)
    assert check_graph(graph) == []
    # Forward-moving: every recovery branch is admissible (D(merge) <= D(failure context)).
    branches = recovery_branches(graph, cost_to_go(graph))
    assert branches and all(b.admissible for b in branches)
    spec = json.loads(_pair(name)[1].read_text())
    assert len(graph.recovery_edges()) == len(spec["recovery_bindings"])
    assert {(b["edge_id"], b["failure_name"]) for b in spec["recovery_bindings"]} <= set(graph.failure_entries())
    # The chain is kept: same nodes, nominal edges in order.
    release = json.loads(_pair(name)[0].read_text())
    assert [n.id for n in graph.nodes] == [n["id"] for n in release["nodes"]]
    assert [e.id for e in graph.nominal_edges()] == [e["id"] for e in release["edges"]]


@needs_examples
def test_single_arm_example_maps_the_pour() -> None:
    graph = import_release(*_pair("SinglePourWater")).graph
    move = graph.edge("e02_move_to_pour_offset").steps[0]["right"]
    assert move.fn == "move_to_obj"
    assert move.args["offset"] == [0.1, 0.05, 0.125]
    assert move.args["yaw"] == pytest.approx(116.6)
    assert graph.edge("e03_tilt_to_pour").steps[0]["right"].args == {"angle": -90.0}
    assert graph.edge("e05_place_bottle_target").steps[0]["right"].args == {"obj": "bottle", "target": [0.1, 0.7]}
    # merge: source -> a loop at the failed edge's source; merge: target -> source to target.
    assert (graph.edge("e02_move_to_pour_offset_r_bottle_hold_lost_during_move").source,
            graph.edge("e02_move_to_pour_offset_r_bottle_hold_lost_during_move").target) == ("v1_bottle_grasped",) * 2
    entry = graph.edge("e01_grasp_bottle_r_bottle_shifted_during_grasp")
    assert (entry.source, entry.target) == ("v0_start", "v1_bottle_grasped")


@needs_examples
def test_rearrangement_example_places_by_release_along_the_release_x() -> None:
    result = import_release(*_pair("Rearrangement"))
    graph = result.graph
    # The move before the release's open_gripper carries each utensil above its spot ...
    carry = graph.edge("e03_move_to_plate_offsets").steps[0]
    assert carry["left"].args == {"obj": "plate", "offset": [-0.16, 0.0, PRE_PLACE_DIS], "keep_orientation": True}
    assert carry["right"].args["offset"] == [0.16, 0.0, PRE_PLACE_DIS]
    # ... and the open_gripper is a place there, the long axis along the release's x (our y).
    release = graph.edge("e04_release").steps[0]
    assert (release["left"].fn, release["left"].args) == (
        "place", {"obj": "fork", "target": [-0.16, 0.0], "relative_to": "plate", "yaw": 90.0})
    assert release["right"].args == {"obj": "spoon", "target": [0.16, 0.0], "relative_to": "plate", "yaw": 90.0}
    # The recovery that retries the move carries to the same stand-off before merging at v3.
    retry = graph.edge("e03_move_to_plate_offsets_r_hold_lost_during_move").steps[-1]
    assert retry["left"].args["offset"] == [-0.16, 0.0, PRE_PLACE_DIS]
    assert graph.node("v4_placed").constraints == ["holding(left, fork) - 0.5", "holding(right, spoon) - 0.5"]
    assert any("edges[3].left_arm_action" in n and "place by release" in n for n in result.notes)
    assert any("edges[3].left_arm_action" in n and "place yaw 90" in n and "orient_eef 'down' is absolute" in n
               for n in result.notes)


def test_task_override_and_unknown_task_slug() -> None:
    assert _import(POUR, task="my_task").graph.task == "my_task"
    result = _import(POUR)
    assert result.graph.task == "test_task"
    assert any("no simulated task matches" in note for note in result.notes)
    assert _import(POUR, folder="SinglePourWater").graph.task == "single_arm_pour_water"


# -------------------------------------------------------------------------- actions


def test_grasp_keeps_pre_grasp_dis_and_drops_robot_name_and_force_valid() -> None:
    graph = _graph((None, {"fn": "grasp", "kwargs": {"robot_name": "right_arm", "obj_name": "bottle",
                                                      "pre_grasp_dis": 0.12, "force_valid": True}}))
    result = _import(graph)
    assert _args(result, "e1") == ("grasp", {"obj": "bottle", "pre_grasp_dis": 0.12})
    assert any("force_valid" in note and "dropped" in note for note in result.notes)
    assert result.graph.objects == ["bottle"]


def test_move_relative_to_object_turns_the_offset_and_keeps_orientation() -> None:
    graph = _graph(
        (_call("left", "grasp", obj_name="fork"), None),
        (_call("left", "move_relative_to_object", obj_name="plate", x_offset=0.0, y_offset=0.16, z_offset=0.02), None),
    )
    fn, args = _args(_import(graph), "e2", "left")
    assert fn == "move_to_obj"
    assert args == {"obj": "plate", "offset": [-0.16, 0.0, 0.02], "keep_orientation": True}


def test_move_relative_to_object_before_a_roll_gets_a_yaw_that_tips_toward_the_object() -> None:
    result = _import(POUR)
    fn, args = _args(result, "e2")
    assert fn == "move_to_obj" and "keep_orientation" not in args
    assert args["offset"] == [0.1, 0.05, 0.125]
    # Approach perpendicular to the horizontal offset ...
    yaw = args["yaw"]
    approach = (math.cos(math.radians(yaw)), math.sin(math.radians(yaw)))
    assert approach[0] * 0.1 + approach[1] * 0.05 == pytest.approx(0.0, abs=1e-3)
    # ... with the tool's +y (z x approach) toward the cup: a negative roll tips the top there.
    tool_y = (-approach[1], approach[0])
    assert tool_y[0] * -0.1 + tool_y[1] * -0.05 > 0
    # A positive roll turns the approach round.
    flipped = copy.deepcopy(POUR)
    flipped["edges"][2]["right_arm_action"]["kwargs"]["degree"] = 90
    other = _args(_import(flipped), "e2")[1]["yaw"]
    assert abs((other - yaw) % 360 - 180) < 0.2


def test_move_to_absolute_position_maps_the_frame_fills_z_and_clips() -> None:
    graph = _graph(
        (_call("left", "move_to_absolute_position", x=0.55, y=0.05, z=None), None),
        (_call("left", "move_to_absolute_position", x=0.6, y=0.1, z=0.2), None),
        (_call("left", "move_to_absolute_position", x=2.0, y=0.0, z=0.2), None),
    )
    result = _import(graph)
    assert _args(result, "e1", "left") == ("move_to_target", {"pos": [-0.05, 0.55, CARRY_Z]})
    assert _args(result, "e2", "left") == ("move_to_target", {"pos": [-0.1, 0.6, 0.2]})
    assert _args(result, "e3", "left")[1]["pos"] == [0.0, WORKSPACE[1][1], 0.2]
    assert any("clipped to our workspace" in note for note in result.notes)
    assert any("our carrying height" in note for note in result.notes)


def test_move_by_relative_offset_extrinsic_and_intrinsic() -> None:
    graph = _graph(
        (_call("left", "move_by_relative_offset", dx=0.1, dy=0.0, dz=0.05, mode="extrinsic"), None),
        (_call("left", "move_by_relative_offset", dz=-0.03, mode="intrinsic"), None),
    )
    result = _import(graph)
    assert _args(result, "e1", "left") == ("move_by_offset", {"offset": [0.0, 0.1, 0.05]})
    assert _args(result, "e2", "left") == ("move_by_offset", {"offset": [-0.03, 0.0, 0.0], "frame": "intrinsic"})


def test_rotate_eef_degree_becomes_angle() -> None:
    assert _args(_import(POUR), "e3") == ("rotate_eef", {"angle": -90.0})
    assert _args(_import(POUR), "e4") == ("rotate_eef", {"angle": 90.0})


def test_place_on_table_maps_target_and_drops_pre_place_dis() -> None:
    result = _import(POUR)
    assert _args(result, "e5") == ("place", {"obj": "bottle", "target": [0.1, 0.7]})
    assert any("pre_place_dis" in note and "dropped" in note for note in result.notes)
    far = _graph((None, _call("right", "place_on_table", obj_name="bottle", x=0.0, y=-1.0)))
    assert _args(_import(far), "e1")[1]["target"] == [TABLE_XY[1][0], TABLE_XY[0][1]]
    down = _graph((None, _call("right", "place_on_table", obj_name="bottle")))
    assert _args(_import(down), "e1") == ("place", {"obj": "bottle"})


def test_back_open_close_map_by_name() -> None:
    graph = _graph(
        (_call("left", "open_gripper"), _call("right", "close_gripper")),
        (_call("left", "back_to_initial_pose"), None),
    )
    result = _import(graph)
    steps = result.graph.edge("e1").steps[0]
    assert (steps["left"].fn, steps["right"].fn) == ("open_gripper", "close_gripper")
    assert result.graph.edge("e2").steps[0] == {"left": result.graph.edge("e2").steps[0]["left"]}
    assert result.graph.edge("e2").steps[0]["left"].fn == "back"


def test_orient_eef_after_a_grasp_sets_the_grasp_mode() -> None:
    graph = _graph(
        (_call("left", "grasp", obj_name="fork"), None),
        (_call("left", "orient_eef", direction="down"), None),
    )
    result = _import(graph)
    assert _args(result, "e1", "left") == ("grasp", {"obj": "fork", "mode": "top"})
    assert _args(result, "e2", "left") == ("move_by_offset", {})


def test_orient_eef_without_a_grasp_pitches_the_tool() -> None:
    down = _import(_graph((_call("left", "orient_eef", direction="down"), None)))
    assert _args(down, "e1", "left") == ("move_by_offset", {"angles": [0.0, 90.0, 0.0], "frame": "intrinsic"})
    front = _import(_graph((_call("left", "orient_eef", direction="front"), None)))
    assert _args(front, "e1", "left")[1]["angles"] == [0.0, -90.0, 0.0]


#: Rearrangement-like chain: grasp, orient down, move beside the plate, open.
SET_DOWN = _graph(
    (_call("left", "grasp", obj_name="fork"), None),
    (_call("left", "orient_eef", direction="down"), None),
    (_call("left", "move_relative_to_object", obj_name="plate", x_offset=0.0, y_offset=0.16, z_offset=0.0), None),
    (_call("left", "open_gripper"), None),
)


def test_move_then_open_while_holding_is_a_place_at_the_offset() -> None:
    result = _import(SET_DOWN)
    assert _args(result, "e3", "left") == (
        "move_to_obj", {"obj": "plate", "offset": [-0.16, 0.0, PRE_PLACE_DIS], "keep_orientation": True})
    assert _args(result, "e4", "left") == (
        "place", {"obj": "fork", "target": [-0.16, 0.0], "relative_to": "plate", "yaw": 90.0})
    # A release height above the reference becomes our place's release height.
    high = copy.deepcopy(SET_DOWN)
    high["edges"][2]["left_arm_action"]["kwargs"]["z_offset"] = 0.05
    assert _args(_import(high), "e4", "left")[1]["z_offset"] == 0.05
    bounds = PlaceArgs.model_fields["z_offset"].metadata
    assert PLACE_Z == (bounds[0].ge, bounds[1].le)  # kept in step with the catalogue
    # Without an object in hand an open is an open, and the move keeps the release's offset.
    empty = _graph(
        (_call("left", "move_relative_to_object", obj_name="plate", x_offset=0.0, y_offset=0.16, z_offset=0.0), None),
        (_call("left", "open_gripper"), None),
    )
    result = _import(empty)
    assert _args(result, "e1", "left")[1]["offset"] == [-0.16, 0.0, 0.0]
    assert _args(result, "e2", "left") == ("open_gripper", {})


def test_an_open_after_a_move_whose_object_is_not_a_name_reports_the_move() -> None:
    # Found by fuzzing: a list for the move's obj_name ended in a TypeError (exit 3), not exit 2.
    bad = copy.deepcopy(SET_DOWN)
    bad["edges"][2]["left_arm_action"]["kwargs"]["obj_name"] = []
    problems = _problems(bad, graph_name="g.json")
    assert any(p.startswith("g.json: edges[2].left_arm_action.kwargs.obj_name: ") and "needs obj_name" in p
               for p in problems), problems


def test_place_yaw_follows_the_release_x_and_only_an_unturned_down_tool() -> None:
    # The release's x in our frame: 90 deg with the aloha frame, 0 with identity, 30 for yaw=-60.
    assert _args(_import(SET_DOWN, frame="identity"), "e4", "left")[1]["yaw"] == 0.0
    assert _args(_import(SET_DOWN, frame="yaw=-60"), "e4", "left")[1]["yaw"] == pytest.approx(-60.0)
    # place_on_table after orient 'down' gets it too.
    table = _graph(
        (_call("left", "grasp", obj_name="fork"), None),
        (_call("left", "orient_eef", direction="down"), None),
        (_call("left", "place_on_table", obj_name="fork", x=0.6, y=0.1), None),
    )
    assert _args(_import(table), "e3", "left")[1]["yaw"] == 90.0
    # A roll after the orient turns the object: no fixed yaw. No orient: no yaw either.
    rolled = copy.deepcopy(table)
    rolled["edges"].insert(2, {"id": "e2b", "source": "v2", "target": "v2b", "left_arm_action": _call(
        "left", "rotate_eef", degree=30), "right_arm_action": None})
    rolled["nodes"].append({"id": "v2b", "semantic": "rolled"})
    rolled["edges"][3]["source"] = "v2b"
    assert "yaw" not in _args(_import(rolled), "e3", "left")[1]
    plain = _graph(
        (_call("left", "grasp", obj_name="fork"), None),
        (_call("left", "move_relative_to_object", obj_name="plate", x_offset=0.0, y_offset=0.16, z_offset=0.0), None),
        (_call("left", "open_gripper"), None),
    )
    assert _args(_import(plain), "e3", "left") == ("place", {"obj": "fork", "target": [-0.16, 0.0],
                                                             "relative_to": "plate"})


def test_frame_parse_and_identity() -> None:
    assert FrameMap.parse("aloha").point((0.7, -0.1, 0.2)) == (0.1, 0.7, 0.2)
    assert FrameMap.parse("identity").point((0.7, -0.1, 0.2)) == (0.7, -0.1, 0.2)
    custom = FrameMap.parse("yaw=180,dx=0.1,dy=0.5")
    assert custom.point((0.1, 0.1, 0.0)) == (0.0, 0.4, 0.0)
    assert custom.vector((0.1, 0.0, 0.0)) == (-0.1, 0.0, 0.0)
    with pytest.raises(ValueError, match="bad frame"):
        FrameMap.parse("tilt=3")
    graph = _graph((None, _call("right", "place_on_table", obj_name="bottle", x=0.1, y=0.5)))
    assert _args(_import(graph, frame="identity"), "e1")[1]["target"] == [0.1, 0.5]


def test_workspace_constants_match_the_motion_module() -> None:
    from agentchord.actions.motion import WORKSPACE_HIGH, WORKSPACE_LOW
    from agentchord.robot.aloha import TABLE_CENTER, TABLE_HALF

    assert WORKSPACE[0] == pytest.approx(tuple(WORKSPACE_LOW))
    assert WORKSPACE[1] == pytest.approx(tuple(WORKSPACE_HIGH))
    assert TABLE_XY[0][1] > TABLE_CENTER[1] - TABLE_HALF[1]
    assert TABLE_XY[1][1] < TABLE_CENTER[1] + TABLE_HALF[1]
    assert TABLE_XY[1][0] < TABLE_HALF[0]


# ------------------------------------------------------------------------- monitors


def test_object_moved_is_drift_gated_for_the_grasped_object() -> None:
    graph = _graph((_call("left", "grasp", obj_name="cup"), _call("right", "grasp", obj_name="bottle")))
    spec = _spec(
        _binding("e1", "shifted", [{"type": "object_moved", "objects": ["bottle", "cup", "plate"], "threshold": 0.03}],
                 [{"type": "retry_failed_edge"}]),
    )
    monitor = _import(graph, spec).graph.edge("e1").failures[0].monitor
    assert monitor == (
        "max((1 - right.closed) * drift(bottle, 0.03), (1 - left.closed) * drift(cup, 0.03), drift(plate, 0.03))"
    )


def test_object_moved_single_object_is_a_bare_drift() -> None:
    spec = _spec(_binding("e2", "cup_moved", [{"type": "object_moved", "objects": ["cup"], "threshold": 0.02}],
                          [{"type": "retry_failed_edge"}]))
    assert _import(POUR, spec).graph.edge("e2").failures[0].monitor == "drift(cup, 0.02)"


def test_hold_lost_is_holding_based_and_gated_where_the_gripper_moves_on_purpose() -> None:
    spec = _spec(
        _binding("e1", "lost", [_hold("right", "bottle")], [{"type": "regrasp", "robot_name": "right_arm",
                                                              "obj_name": "bottle"}]),
        _binding("e2", "lost", [_hold("right", "bottle")], [{"type": "regrasp", "robot_name": "right_arm",
                                                              "obj_name": "bottle"}], merge="source"),
        _binding("e5", "lost", [_hold("right", "bottle")], [{"type": "regrasp", "robot_name": "right_arm",
                                                              "obj_name": "bottle"}], merge="source"),
    )
    result = _import(POUR, spec)
    graph = result.graph
    assert graph.edge("e1").failures[0].monitor == "right.closed * (0.5 - holding(right, bottle))"
    assert graph.edge("e2").failures[0].monitor == "0.5 - holding(right, bottle)"
    assert graph.edge("e5").failures[0].monitor == "right.closed * (0.5 - holding(right, bottle))"
    # The recovery edge grasps: its re-entry monitor is gated too.
    assert graph.edge("e2_r_lost").failures[0].monitor == "right.closed * (0.5 - holding(right, bottle))"
    assert any("threshold" in note and "dropped" in note for note in result.notes)


def test_several_monitors_of_a_binding_are_one_failure_mode() -> None:
    graph = _graph(
        (_call("left", "grasp", obj_name="fork"), _call("right", "grasp", obj_name="spoon")),
        (_call("left", "move_by_relative_offset", dz=0.05), _call("right", "move_by_relative_offset", dz=0.05)),
    )
    spec = _spec(_binding("e2", "lost", [_hold("left", "fork"), _hold("right", "spoon")],
                          [{"type": "regrasp_both", "arms": {"left_arm": "fork", "right_arm": "spoon"}},
                           {"type": "retry_failed_edge"}]))
    failures = _import(graph, spec).graph.edge("e2").failures
    assert [f.name for f in failures] == ["lost"]
    assert failures[0].monitor == "max(0.5 - holding(left, fork), 0.5 - holding(right, spoon))"


# ----------------------------------------------------------------- recovery steps


def test_regrasp_becomes_a_grasp_step_keeping_pre_grasp_dis() -> None:
    spec = _spec(_binding("e2", "lost", [_hold("right", "bottle")],
                          [{"type": "regrasp", "robot_name": "right_arm", "obj_name": "bottle", "pre_grasp_dis": 0.1,
                            "force_valid": True}], merge="source"))
    entry = _import(POUR, spec).graph.edge("e2_r_lost")
    assert entry.is_recovery and (entry.source, entry.target) == ("v1", "v1")
    assert [(a, c.fn, c.args) for a, c in entry.calls] == [("right", "grasp", {"obj": "bottle", "pre_grasp_dis": 0.1})]


def test_regrasp_both_is_one_synchronous_step() -> None:
    graph = _graph((_call("left", "grasp", obj_name="cup"), _call("right", "grasp", obj_name="bottle")))
    spec = _spec(_binding("e1", "shifted", [{"type": "object_moved", "objects": ["cup"], "threshold": 0.02}],
                          [{"type": "regrasp_both", "arms": {"left_arm": "cup", "right_arm": "bottle"},
                            "pre_grasp_dis": 0.1}]))
    entry = _import(graph, spec).graph.edge("e1_r_shifted")
    assert len(entry.steps) == 1
    step = entry.steps[0]
    assert step["left"].args == {"obj": "cup", "pre_grasp_dis": 0.1, "skip_if_held": True}
    assert step["right"].args == {"obj": "bottle", "pre_grasp_dis": 0.1, "skip_if_held": True}
    assert (entry.source, entry.target) == ("v0", "v1")


def test_retry_replay_and_action_steps() -> None:
    spec = _spec(_binding("e3", "lost", [_hold("right", "bottle")], [
        {"type": "regrasp", "robot_name": "right_arm", "obj_name": "bottle"},
        {"type": "replay_edge", "edge_id": "e2"},
        {"type": "action", "right_arm_action": _call("right", "rotate_eef", degree=-10)},
        {"type": "retry_failed_edge"},
    ]))
    result = _import(POUR, spec)
    entry = result.graph.edge("e3_r_lost")
    assert [c.fn for _, c in entry.calls] == ["grasp", "move_to_obj", "rotate_eef", "rotate_eef"]
    assert entry.steps[1] == result.graph.edge("e2").steps[0]
    assert entry.steps[3] == result.graph.edge("e3").steps[0]
    assert entry.steps[2]["right"].args == {"angle": -10.0}
    assert (entry.source, entry.target) == ("v2", "v3")
    assert result.graph.edge("e3").failures[0].intent == "regrasp, then replay e2, then action, then retry"


def test_repeat_until_success_adds_re_entry_and_false_does_not() -> None:
    recovery = [{"type": "regrasp", "robot_name": "right_arm", "obj_name": "bottle"}]
    again = _import(POUR, _spec(_binding("e4", "lost", [_hold("right", "bottle")], recovery))).graph
    entry = again.edge("e4_r_lost")
    assert [(f.name, f.recovery) for f in entry.failures] == [("lost", "e4_r_lost")]
    once = _import(POUR, _spec(_binding("e4", "lost", [_hold("right", "bottle")], recovery, repeat=False))).graph
    assert once.edge("e4_r_lost").failures == []


def test_node_constraints_follow_what_is_held() -> None:
    graph = _import(POUR).graph
    assert graph.node("v0").constraints == []
    assert graph.node("v1").constraints == ["0.5 - holding(right, bottle)"]
    assert graph.node("v5").constraints == ["holding(right, bottle) - 0.5"]


def test_objects_option_renames_and_requires_every_object() -> None:
    result = _import(POUR, objects=["bottle=jug", "cup", "plate"])
    assert result.graph.objects == ["jug", "cup", "plate"]
    assert _args(result, "e1")[1]["obj"] == "jug"
    problems = _problems(POUR, objects=["bottle"])
    assert any("object 'cup' is not among --objects" in p and "edges[1].right_arm_action.kwargs.obj_name" in p
               for p in problems)


# ------------------------------------------------------------------------- errors


@pytest.mark.parametrize(
    ("mutate", "path", "message"),
    [
        (lambda g, s: g["edges"][2]["right_arm_action"].update(fn="pour"), "edges[2].right_arm_action.fn",
         "cannot map release action 'pour'"),
        (lambda g, s: g["edges"][2]["right_arm_action"]["kwargs"].update(speed=2),
         "edges[2].right_arm_action.kwargs.speed", "cannot map kwarg 'speed'"),
        (lambda g, s: g["edges"][2]["right_arm_action"]["kwargs"].update(degree="a lot"),
         "edges[2].right_arm_action.kwargs.degree", "expected a number"),
        (lambda g, s: g["edges"][2]["right_arm_action"]["kwargs"].update(degree=270),
         "edges[2].right_arm_action.kwargs", "rotate_eef.angle"),
        (lambda g, s: g["edges"][0]["right_arm_action"]["kwargs"].update(robot_name="left_arm"),
         "edges[0].right_arm_action.kwargs.robot_name", "in the right arm's slot"),
        (lambda g, s: g["edges"][0]["right_arm_action"]["kwargs"].update(robot_name="third_arm"),
         "edges[0].right_arm_action.kwargs.robot_name", "unknown arm 'third_arm'"),
        (lambda g, s: g["edges"][1]["right_arm_action"].update(fn="move_to_absolute_position", kwargs={"x": 0.5}),
         "edges[1].right_arm_action.kwargs.y", "cannot be mapped"),
        (lambda g, s: g["edges"][1].update(source="v0"), "edges[1].source", "one start-to-goal chain"),
        (lambda g, s: g.update(goal="v9"), "goal", "unknown node 'v9'"),
        (lambda g, s: g["nodes"][0].update(pose=[0, 0]), "nodes[0].pose", "cannot map field 'pose'"),
        (lambda g, s: s["recovery_bindings"][0].update(edge_id="e9"), "recovery_bindings[0].edge_id",
         "unknown edge 'e9'"),
        (lambda g, s: s["recovery_bindings"][0]["monitors"][0].update(type="slipped"),
         "recovery_bindings[0].monitors[0].type", "unknown monitor type 'slipped'"),
        (lambda g, s: s["recovery_bindings"][0]["recovery"][0].update(type="wiggle"),
         "recovery_bindings[0].recovery[0].type", "unknown recovery step type 'wiggle'"),
        (lambda g, s: s["recovery_bindings"][0].update(merge="middle"), "recovery_bindings[0].merge",
         "expected 'target' or 'source'"),
        (lambda g, s: s["recovery_bindings"][0]["recovery"].append({"type": "replay_edge", "edge_id": "e7"}),
         "recovery_bindings[0].recovery[1].edge_id", "unknown edge 'e7'"),
    ],
)
def test_malformed_input_names_file_path_and_problem(mutate, path: str, message: str) -> None:
    graph, spec = copy.deepcopy(POUR), _spec(_binding("e2", "lost", [_hold("right", "bottle")],
                                                      [{"type": "regrasp", "robot_name": "right_arm",
                                                        "obj_name": "bottle"}]))
    mutate(graph, spec)
    problems = _problems(graph, spec, graph_name="g.json", spec_name="s.json")
    hits = [p for p in problems if p.startswith(("g.json: ", "s.json: ")) and f": {path}: " in p and message in p]
    assert hits, problems


def test_unreadable_and_invalid_json_name_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "agent_task_graph.json"
    bad.write_text('{"task": "x",\n "nodes": [}')
    with pytest.raises(ReleaseImportError) as info:
        import_release(bad, tmp_path / "missing.json")
    text = str(info.value)
    assert f"{bad}: (file): line 2" in text and "invalid JSON" in text
    assert f"{tmp_path / 'missing.json'}: (file): cannot read the file" in text


# ---------------------------------------------------------------------------- CLI


def _write_pair(tmp_path: Path, graph: dict, spec: dict) -> tuple[Path, Path]:
    g, s = tmp_path / "agent_task_graph.json", tmp_path / "agent_recovery_spec.json"
    g.write_text(json.dumps(graph))
    s.write_text(json.dumps(spec))
    return g, s


def test_cli_writes_a_yaml_that_reloads(tmp_path: Path) -> None:
    spec = _spec(_binding("e2", "lost", [_hold("right", "bottle")],
                          [{"type": "regrasp", "robot_name": "right_arm", "obj_name": "bottle"}], merge="source"))
    g, s = _write_pair(tmp_path, POUR, spec)
    out = tmp_path / "imported.yaml"
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(out), "--task",
                                       "single_arm_pour_water"])
    assert result.exit_code == 0, result.output
    assert f"wrote {out}: task single_arm_pour_water, 7 nodes, 7 edges, 2 failure modes" in result.output
    assert "note: " in result.output and "pre_place_dis" in result.output
    assert out.read_text().startswith("# Imported by `agentchord import-release`")
    reloaded = load_graph(out)
    assert reloaded == import_release(g, s, task="single_arm_pour_water").graph
    check = CliRunner().invoke(main, ["graph", "check", str(out)])
    assert check.exit_code == 0, check.output


def test_cli_json_output_and_objects_option(tmp_path: Path) -> None:
    g, s = _write_pair(tmp_path, POUR, _spec())
    out = tmp_path / "imported.json"
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(out), "--objects",
                                       "bottle=jug,cup", "--task", "single_arm_pour_water", "--quiet"])
    assert result.exit_code == 0, result.output
    assert "note: " not in result.output
    assert "has no jug" in result.output
    assert load_graph(out).objects == ["jug", "cup"]


def test_cli_reports_an_unmappable_file_with_exit_2(tmp_path: Path) -> None:
    graph = copy.deepcopy(POUR)
    graph["edges"][3]["right_arm_action"]["fn"] = "wave"
    g, s = _write_pair(tmp_path, graph, _spec())
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(tmp_path / "x.yaml")])
    assert result.exit_code == 2
    assert f"{g}: edges[3].right_arm_action.fn: cannot map release action 'wave'" in result.output
    assert not (tmp_path / "x.yaml").exists()


def test_cli_rejects_a_bad_frame(tmp_path: Path) -> None:
    g, s = _write_pair(tmp_path, POUR, _spec())
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(tmp_path / "x.yaml"),
                                       "--frame", "sideways"])
    assert result.exit_code == 2
    assert "bad frame" in result.output


# ------------------------------------------------------------------------ sim run


@needs_examples
def test_single_arm_imported_graph_runs_one_episode(tmp_path: Path) -> None:
    g, s = _pair("SinglePourWater")
    out = tmp_path / "imported.yaml"
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    run = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--graph", str(out), "--seed", "1"])
    assert run.exit_code == 0, run.output
    assert "SUCCESS" in run.output


@needs_examples
@pytest.mark.slow
def test_rearrangement_imported_graph_succeeds_on_one_seed(tmp_path: Path) -> None:
    g, s = _pair("Rearrangement")
    out = tmp_path / "imported.yaml"
    result = CliRunner().invoke(main, ["import-release", str(g), str(s), "-o", str(out), "--quiet"])
    assert result.exit_code == 0, result.output
    run = CliRunner().invoke(main, ["run", "rearrange_table", "--graph", str(out), "--seed", "1"])
    assert run.exit_code == 0, run.output
    assert "SUCCESS" in run.output


#: Values a mutated release file gets where it had something else (types an importer must not trip on).
_WRONG = [None, "", "x", -1, 0, 1e308, float("nan"), float("inf"), [], {}, [1, 2], {"a": 1}, True, [None], "e1", "left_arm"]


def _paths(value, at=()):
    yield at
    children = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, child in children:
        yield from _paths(child, (*at, key))


def _mutated(document, rng):
    """``document`` with 1-3 values deleted, duplicated or replaced by one of :data:`_WRONG`."""
    document = copy.deepcopy(document)
    for _ in range(rng.randint(1, 3)):
        paths = [p for p in _paths(document) if p]
        if not paths:
            break
        *parent_path, key = rng.choice(paths)
        parent = document
        for step in parent_path:
            parent = parent[step]
        roll = rng.random()
        if roll < 0.25:
            del parent[key]
        elif roll < 0.35 and isinstance(parent, list):
            parent.append(copy.deepcopy(parent[key]))
        else:
            parent[key] = copy.deepcopy(rng.choice(_WRONG))
    return document


@needs_examples
@pytest.mark.parametrize("name", PAIRS)
def test_mutated_release_files_are_reported_never_crashed_on(name: str) -> None:
    # Fuzzing found eight places where a wrongly typed value (a list for an obj_name or an edge_id,
    # a string for kwargs, a null offset) ended in a TypeError or AttributeError: exit 3, not 2.
    import random

    rng = random.Random(f"interop-{name}")
    graph_path, spec_path = _pair(name)
    graph, spec = json.loads(graph_path.read_text()), json.loads(spec_path.read_text())
    for _ in range(400):
        which = rng.random()
        pair = (_mutated(graph, rng), spec) if which < 0.45 else (graph, _mutated(spec, rng)) if which < 0.9 \
            else (_mutated(graph, rng), _mutated(spec, rng))
        try:
            import_release_data(*pair, folder=name)
        except ReleaseImportError as error:
            assert error.problems and all(isinstance(p, str) and p for p in error.problems)
