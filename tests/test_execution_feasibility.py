"""Feasibility before motion: first grasps, off-table objects, reach and IK checks."""

import numpy as np

from agentchord.actions.catalog import GraspArgs
from agentchord.actions.controller import RobotController
from agentchord.actions.library import Grasp
from agentchord.execution.edge_program import EdgeProgram
from agentchord.execution.feasibility import FeasibilityChecker, first_grasps, off_table
from agentchord.features.extractors import make_extractor
from agentchord.library import load_task_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.world import SimWorld


def _robot() -> RobotController:
    world = SimWorld(SIM_TASKS["single_arm_pour_water"].sample_scene(np.random.default_rng([1, 0x5CE7E])))
    robot = RobotController(world)
    robot.frame = make_extractor("oracle", world, lambda arm: False).update()
    return robot


def _move(robot: RobotController, obj: str, xyz) -> None:
    feats = robot.frame.objects[obj]
    shift = np.asarray(xyz, dtype=float) - feats.pos
    for name in ("pos", "top", "bottom"):
        setattr(feats, name, getattr(feats, name) + shift)


def test_an_alternative_checks_the_hand_off_grasp_not_the_grasp_after_it():
    graph = load_task_graph("single_arm_pour_water")
    alt = next(e for e in graph.edges if e.alternative_to == "e2_r_bottle_dropped")
    grasps = first_grasps(EdgeProgram.from_edge(alt))
    assert [(g.arm, g.args.obj) for g in grasps] == [("left", "bottle")]


def test_a_busy_arm_that_sets_its_object_down_first_is_checked_for_the_hand_off_with_its_hand_freed():
    from agentchord.execution.feasibility import places_first

    graph = load_task_graph("dual_arm_pour_water")
    alt = next(e for e in graph.edges if e.alternative_to == "e3_r_bottle_dropped")
    program = EdgeProgram.from_edge(alt)
    grasps = first_grasps(program)
    # The left arm sets the cup down, then takes the bottle: that grasp is checked, with its hand counted free.
    assert [(g.arm, g.args.obj) for g in grasps] == [("left", "bottle")]
    assert places_first(program, grasps[0])


def test_an_object_below_the_table_top_is_off_the_table():
    robot = _robot()
    assert off_table(robot.frame, ["bottle", "cup"]) == []
    _move(robot, "bottle", (0.0, 1.2, -0.6))
    assert off_table(robot.frame, ["bottle", "cup"]) == ["bottle"]
    assert FeasibilityChecker(robot).unreachable("bottle")


def test_the_arm_near_the_object_can_take_it_and_an_object_beyond_both_shells_is_unreachable():
    robot = _robot()
    checker = FeasibilityChecker(robot)
    assert checker.check_grasp(Grasp("right", GraspArgs(obj="bottle"))).feasible  # where the scene put it
    _move(robot, "bottle", (-0.3, 0.8, robot.frame.objects["bottle"].pos[2]))
    right = checker.check_grasp(Grasp("right", GraspArgs(obj="bottle")))
    assert not right.feasible and "right arm" in right.reason
    assert checker.check_grasp(Grasp("left", GraspArgs(obj="bottle"))).feasible
    _move(robot, "bottle", (0.0, 1.3, robot.frame.objects["bottle"].pos[2]))
    assert len(checker.unreachable("bottle")) == 2


def test_a_busy_hand_cannot_take_another_object():
    robot = _robot()
    robot.frame.holding = {("left", "cup")}
    check = FeasibilityChecker(robot).check_grasp(Grasp("left", GraspArgs(obj="bottle")))
    assert not check.feasible and "holds cup" in check.reason


def test_a_hand_pinching_one_corner_of_the_cloth_is_free_for_another_and_a_rigid_object_keeps_it_busy():
    # Fold towel, real protocol seed 47: a bottom corner that slipped onto its top corner is re-pinched
    # with it; the grasp of the bottom corner opens the hand first, so the pinched top corner does not
    # make the arm busy (the episode ended "no feasible recovery: the left arm holds towel_tl").
    world = SimWorld(SIM_TASKS["fold_towel"].sample_scene(np.random.default_rng([0, 0x5CE7E])))
    robot = RobotController(world)
    robot.frame = make_extractor("oracle", world, lambda arm: False).update()
    robot.frame.holding = {("left", "towel_tl")}
    assert FeasibilityChecker(robot).check_grasp(Grasp("left", GraspArgs(obj="towel_bl", mode="top"))).feasible
    robot = _robot()
    robot.frame.holding = {("left", "cup")}
    assert not FeasibilityChecker(robot).check_grasp(Grasp("left", GraspArgs(obj="cup"))).reason  # its own object: free
    assert "holds cup" in FeasibilityChecker(robot).check_grasp(Grasp("left", GraspArgs(obj="bottle"))).reason


def test_an_arm_holding_the_object_does_not_make_way_for_its_grasp_unless_it_lets_go_first():
    # Single-arm pour under drops, DoReMi's seed 6: the bottle rode home on the right arm's open
    # fingers; a left-arm grasp of it there, beside the right hand, is checked clear of the right arm,
    # even though the right arm moves in the same step (it takes the bottle along).
    from types import SimpleNamespace

    from agentchord.actions.library import make_action
    from agentchord.execution.feasibility import releases_first

    robot = _robot()
    checker = FeasibilityChecker(robot)
    grasp = make_action("grasp", "left", {"obj": "bottle"})
    together = SimpleNamespace(steps=[[grasp, make_action("back", "right", {})]])
    let_go = SimpleNamespace(steps=[[make_action("open_gripper", "right", {})], [grasp, make_action("back", "right", {})]])
    alone = SimpleNamespace(steps=[[grasp]])
    assert not releases_first(together, grasp, "right") and releases_first(let_go, grasp, "right")
    robot.frame.holding = set()
    assert not checker._other_arm_stays(together, grasp)  # the right arm, empty-handed, may move away
    assert checker._other_arm_stays(alone, grasp)
    robot.frame.holding = {("right", "bottle")}
    assert checker._other_arm_stays(together, grasp)
    assert not checker._other_arm_stays(let_go, grasp)
    robot.frame.holding = {("right", "cup")}
    assert not checker._other_arm_stays(together, grasp)  # it holds something else: it moves away with it
