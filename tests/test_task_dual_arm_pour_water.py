"""Dual-arm pour water: scene ranges, success check both ways, library graph, a recovered drop."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.harness import DisturbanceSetting
from agentchord.actions.base import Status
from agentchord.actions.controller import RobotController
from agentchord.actions.library import make_action
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.features.frame import make_static_frame, tilt_deg
from agentchord.features.oracle import OracleExtractor
from agentchord.graph.progress import forward_filter, nominal_path
from agentchord.graph.validation import check_graph
from agentchord.library import load_task_graph
from agentchord.sim.disturbances import ScriptedDrop
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.tasks.dual_arm_pour_water import DualPourTracker
from agentchord.sim.world import SimWorld

TASK = "dual_arm_pour_water"


def _scene(seed=3):
    return SIM_TASKS[TASK].sample_scene(np.random.default_rng([seed, 0x5CE7E]))


def test_scenes_vary_within_the_stated_ranges():
    task = SIM_TASKS[TASK]
    for seed in range(10):
        bottle, cup = _scene(seed).objects
        assert task.CUP_RADIUS[0] <= cup.size[0] <= task.CUP_RADIUS[1]
        # The cup is grasped from the side: it must fit the 6.9 cm finger gap with room to spare.
        assert 2 * cup.size[0] <= 0.056
        assert task.CUP_XY[0][0] <= cup.pos[0] <= task.CUP_XY[0][1] < 0.0  # left half of the table
        assert 0.0 < task.BOTTLE_XY[0][0] <= bottle.pos[0] <= task.BOTTLE_XY[0][1]  # right half
        assert task.BOTTLE_MASS[0] <= bottle.mass <= task.BOTTLE_MASS[1]
    assert _scene(1).objects[0].size != _scene(2).objects[0].size


def _pour_frame(*, cup_held=True, tilt=95.0, lateral=0.0):
    cup_top = np.array([0.0, 0.62, 0.20])
    axis = Rotation.from_euler("x", -tilt, degrees=True).apply([0.0, 0.0, 1.0])
    bottle_top = cup_top + np.array([lateral, 0.0, 0.07])
    holding = {("right", "bottle")} | ({("left", "cup")} if cup_held else set())
    return make_static_frame(
        objects={
            "cup": {"pos": cup_top - [0, 0, 0.05], "extent": (0.052, 0.052, 0.10), "top": cup_top},
            "bottle": {"pos": bottle_top - 0.09 * axis, "axis": axis, "extent": (0.05, 0.05, 0.18), "top": bottle_top},
        },
        holding=holding,
    )


def test_pour_event_needs_tilt_position_and_the_cup_held():
    for frame, expected in [
        (_pour_frame(), True),
        (_pour_frame(cup_held=False), False),  # the cup must be held by the other arm
        (_pour_frame(tilt=50.0), False),  # not tilted enough
        (_pour_frame(lateral=0.05), False),  # mouth beside the cup
    ]:
        tracker = DualPourTracker()
        tracker.observe(frame)
        assert tracker.poured is expected


def test_verdict_needs_the_pour_and_both_objects_upright_and_released():
    world = SimWorld(_scene())
    extractor = OracleExtractor(world)
    frame = extractor.update()
    tracker = DualPourTracker()
    assert not tracker.verdict(frame, world).success  # never poured
    tracker.poured = True
    assert tracker.verdict(frame, world).success  # both stand upright on the table
    # Lay the cup on its side: the end state no longer counts.
    adr = world.model.joint("cup_free").qposadr[0]
    radius = world.object_spec("cup").size[0]
    x, y, z, w = Rotation.from_euler("y", 90, degrees=True).as_quat()
    world.data.qpos[adr : adr + 7] = [-0.1, 0.55, radius + 0.001, w, x, y, z]
    for _ in range(40):
        world.step()
    verdict = tracker.verdict(extractor.update(), world)
    assert not verdict.success and "cup is not upright" in verdict.reason


def test_library_graph_checks_clean_and_watches_every_held_object():
    graph = load_task_graph(TASK)
    assert check_graph(graph) == []
    assert forward_filter(graph).removed == []
    assert nominal_path(graph) == ["e1", "e2", "e3", "e4", "e5", "e6", "e7"]
    # Every edge that holds the cup or the bottle -- nominal and recovery -- watches for its drop;
    # an arm-switch alternative watches the object it hands over (the other is set down on purpose).
    # Once both are put down (v6), the arms going home watch both for a knock, and a knock's
    # recovery watches the drop of the one object it stands up again.
    for edge in graph.edges:
        names = {f.name for f in edge.failures}
        if edge.alternative_to:
            assert names == {f.name for f in graph.edge(edge.alternative_to).failures if f.recovery == edge.alternative_to}, edge.id
        elif edge.id == "e7":
            assert names == {"cup_knocked", "bottle_knocked"}
        elif edge.source == "v6":
            taken = {call.args["obj"] for _, call in edge.calls if call.fn == "grasp"}
            assert names == {f"{obj}_dropped" for obj in taken}, edge.id
        else:
            assert {"cup_dropped", "bottle_dropped"} <= names, edge.id
    # Synchronous grasp and place: both arms in one step.
    assert set(graph.edge("e1").steps[0]) == {"left", "right"}
    assert set(graph.edge("e6").steps[0]) == {"left", "right"}


def test_stopping_before_the_pour_fails_the_success_check():
    graph = load_task_graph(TASK)
    # Skip the pour (nominal edges only): e3 goes straight to v5 (bottle beside the cup, upright), then place.
    edges = [e.model_copy(update={"failures": []}) for e in graph.edges if e.kind == "nominal" and e.id not in ("e4", "e5")]
    edges = [e.model_copy(update={"target": "v5"}) if e.id == "e3" else e for e in edges]
    short = graph.model_copy(update={"edges": edges})
    result = run_episode(EpisodeSpec(TASK, seed=1, graph=short))
    assert not result.success
    assert "never reached a pouring orientation" in result.reason


def test_nominal_episode_pours_and_places_both():
    result = run_episode(EpisodeSpec(TASK, seed=1))
    assert result.success, result.reason
    assert [p for p in result.path if p.startswith("e")] == ["e1", "e2", "e3", "e4", "e5", "e6", "e7"]
    assert result.recoveries == 0


@pytest.mark.parametrize(("action", "nth", "after", "edge", "failure", "entry"), [
    ("move_to_target", 0, 20, "e2", "cup_dropped", "e2_r_cup_dropped"),
    ("place", 1, 60, "e6", "bottle_dropped", "e6_r_bottle_dropped"),
])
def test_forced_drop_is_recovered_forward(action, nth, after, edge, failure, entry):
    result = run_episode(EpisodeSpec(TASK, seed=1, disturbance=ScriptedDrop(action, nth, after)))
    assert result.success, result.reason
    assert result.drops_injected == result.drops_detected == result.drops_recovered == 1
    switch = result.trace.of("recovery_switch")[0]
    assert (switch["edge"], switch["failure"], switch["to"]) == (edge, failure, entry)
    # Forward-moving: neither the failure context nor any node before it is revisited.
    before = {"e2": {"v0", "v1"}, "e6": {"v0", "v1", "v2", "v3", "v4", "v5"}}[edge]
    assert not before & set(result.path[result.path.index(entry):])

def _robot(scene):
    world = SimWorld(scene)
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame
    return world, robot, extractor


def _run(robot, extractor, action, max_ticks=1500):
    action.initialise(robot)
    for tick in range(max_ticks):
        if action.update(robot) != Status.RUNNING:
            return action.status, tick
        robot.step()
        extractor.update()
    raise AssertionError("action did not finish")


def test_skip_if_held_keeps_a_finished_grasp_and_skip_if_placed_only_retreats():
    world, robot, extractor = _robot(_scene())
    assert _run(robot, extractor, make_action("grasp", "left", {"obj": "cup"}))[0] == Status.SUCCESS
    status, ticks = _run(robot, extractor, make_action("grasp", "left", {"obj": "cup", "skip_if_held": True}))
    assert status == Status.SUCCESS and ticks == 0 and world.holding("left", "cup")
    # The bottle stands on the table, never grasped: a plain place refuses, skip_if_placed retreats.
    assert _run(robot, extractor, make_action("place", "right", {"obj": "bottle"}))[0] == Status.FAILURE
    before = robot.commanded_pose("right").pos
    status, _ = _run(robot, extractor, make_action("place", "right", {"obj": "bottle", "skip_if_placed": True}))
    assert status == Status.SUCCESS
    assert robot.commanded_pose("right").pos[2] > before[2]
    # free_hand (an arm-switch emptying the busy hand): the bottle is not held, so the hand is free already.
    before = robot.commanded_pose("right").pos
    status, _ = _run(robot, extractor, make_action("place", "right", {"obj": "bottle", "free_hand": True}))
    assert status == Status.SUCCESS and robot.targets["right"].grip == 0.0
    assert robot.commanded_pose("right").pos[2] > before[2]


@pytest.mark.parametrize(("x", "y", "yaw", "reseated"), [
    (0.2, 0.45, 2.0, True),    # left more than 5 deg askew by the turn: put down and taken again
    (0.05, 0.5, 0.3, False),   # left within 5 deg of upright by the turn: the fallen-grasp hold is kept
])
def test_reseat_turns_a_fallen_bottle_left_askew_into_a_nominal_side_grasp(x, y, yaw, reseated, monkeypatch):
    import agentchord.actions.grasp as grasp_module
    from agentchord.actions.grasp import Grasp
    from agentchord.actions.grasping.wrist_branch import is_wound
    from agentchord.robot.aloha import HOME_Q

    # The straight turn upright (the unflipped branch's joint-space turn leaves a bottle within
    # 3 deg: tests/test_actions_grasping_wrist_branch.py): this one leaves the first bottle askew.
    monkeypatch.setattr(grasp_module, "plan_unflipped_fallen_grasp", lambda *args, **kwargs: None)
    calls, wound, homed = [], [], []
    reseat, move_joints = Grasp._reseat, grasp_module.move_joints

    def counted(self, robot):
        calls.append(tilt_deg(robot.frame.objects[self.args.obj].axis))
        wound.append(is_wound(robot.ik.arm_q(self.arm)))
        return (yield from reseat(self, robot))

    def recorded(robot, arm, q_goal, speed=1.0):
        homed.append(np.allclose(q_goal, HOME_Q))
        return (yield from move_joints(robot, arm, q_goal, speed))

    monkeypatch.setattr(Grasp, "_reseat", counted)
    monkeypatch.setattr(grasp_module, "move_joints", recorded)
    scene = _scene(0)
    world, robot, extractor = _robot(scene)
    bottle = scene.objects[0]
    adr = world.model.joint("bottle_free").qposadr[0]
    qx, qy, qz, qw = (Rotation.from_euler("z", yaw) * Rotation.from_euler("y", 90, degrees=True)).as_quat()
    world.data.qpos[adr : adr + 7] = [x, y, bottle.size[0] + 0.001, qw, qx, qy, qz]
    for _ in range(40):
        world.step()
    assert extractor.update().objects["bottle"].axis[2] < 0.2  # lying down
    status, _ = _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle", "reseat": True}), max_ticks=2500)
    assert status == Status.SUCCESS
    assert bool(calls) is reseated and all(t > Grasp.RESEAT_TILT_DEG for t in calls)
    # The hand goes home between set-down and grasp only to unwind a wound wrist.
    assert any(homed) is any(wound)
    frame = extractor.frame
    feats, tool = frame.objects["bottle"], frame.arms["right"].ee
    assert frame.is_holding("right", "bottle") and tilt_deg(feats.axis) <= Grasp.RESEAT_TILT_DEG
    # Re-seated: held at mid-height on its axis, as a side grasp of a standing bottle is. Kept: the
    # fallen-object hold, off the axis.
    offset = feats.pos - tool
    off_axis = np.linalg.norm(offset - np.dot(offset, feats.axis) * feats.axis)
    assert bool(off_axis < 0.01) is reseated


@pytest.mark.parametrize("kept_clear", [True, False])
def test_a_hand_off_is_not_set_down_where_the_cup_is_held_next(kept_clear, monkeypatch):
    # Real-world protocol, seed 54: the bottle pulled out of the right hand after the pour was handed
    # over by the left arm at (-0.10, 0.72); the left arm then took the cup and held it at (-0.12, 0.72),
    # knocking the bottle over, out of the right arm's reach.
    from agentchord.execution import edge_program

    if not kept_clear:
        monkeypatch.setattr(edge_program, "_link_handoffs_to_later_moves", lambda steps: None)
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=54, disturbances=DisturbanceSetting.from_options(protocol="real")))
    assert result.trace.of("recovery_bound")[0]["edge"] == "e5_r_bottle_dropped_via_left"
    assert result.success == kept_clear, result.reason


@pytest.mark.parametrize("watched", [True, pytest.param(False, marks=pytest.mark.slow)])
def test_a_bottle_that_turns_in_the_hand_while_brought_to_the_cup_again_is_reseated(watched):
    # Stress protocol, seed 89: the cup knocked in the hand shifts as the bottle approaches it; the
    # re-approach (e3_r_cup_shifted) brings the bottle to it again, and the bottle turns 24 deg in
    # the hand on the way. Watched for the slip as e3 is, it is set down and taken again before the
    # pour; unwatched, the pour starts from the tilted hold and misses the cup.

    graph = load_task_graph("dual_arm_pour_water")
    if not watched:
        edge = graph.edge("e3_r_cup_shifted")
        edge.failures = [f for f in edge.failures if f.name != "bottle_slipped"]
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=89, disturbances=DisturbanceSetting.from_options(protocol="stress"), graph=graph))
    assert result.success is watched, result.reason
    if not watched:
        assert "never reached a pouring orientation" in result.reason
