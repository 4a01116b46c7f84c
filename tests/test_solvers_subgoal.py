"""The sub-goal (keyframe) solver, paper Eq. 9: margins, reach, spacing, warm starts, determinism."""

import numpy as np
import pytest

from agentchord.features.frame import make_static_frame
from agentchord.solvers.constraints import UserCost, expression_costs
from agentchord.solvers.exceptions import InfeasibleSubgoalError, SolverProblemError
from agentchord.solvers.obstacles import Spheres, scene_spheres
from agentchord.solvers.reach import REACH
from agentchord.solvers.subgoal import SubgoalSolver
from agentchord.solvers.subgoal_problem import SubgoalProblem, SubgoalWeights

OBSTACLE = np.array([0.05, 0.5, 0.2])


def _pull(arm: str, point, hard: bool = False, slack: float = 0.0) -> UserCost:
    point = np.asarray(point, dtype=float)
    return UserCost(lambda pos: float(np.linalg.norm(pos[arm] - point)) - slack, name=f"{arm}_to", hard=hard)


def _beside_obstacle(hard: bool = False) -> SubgoalProblem:
    # The pull's point lies 6 cm from the sphere's centre: 3 cm inside the kept clearance
    # (0.05 sphere + 0.02 tool + 0.02 margin = 0.09).
    return SubgoalProblem(
        arms=("right",), costs=[_pull("right", OBSTACLE + [0.0, -0.06, 0.0], hard=hard)],
        obstacles=Spheres([OBSTACLE], [0.05]),
    )


def test_a_pull_toward_an_obstacle_stops_at_the_margin_inside_reach():
    solution = SubgoalSolver().solve(_beside_obstacle())
    position = solution.positions["right"]
    assert solution.feasible and solution.method == "dual_annealing+slsqp"
    assert position == pytest.approx(OBSTACLE + [0.0, -0.09, 0.0], abs=2e-3)
    assert np.linalg.norm(position - OBSTACLE) >= 0.09 - 1e-3
    assert REACH["right"].contains(position)
    assert solution.cost == pytest.approx(sum(solution.terms.values()))


def test_conflicting_hard_constraints_are_infeasible_and_raise_on_request():
    solver = SubgoalSolver()
    solution = solver.solve(_beside_obstacle(hard=True))
    assert not solution.feasible
    assert max(solution.violations.values()) > 0.01
    with pytest.raises(InfeasibleSubgoalError) as caught:
        solver.solve(_beside_obstacle(hard=True), require_feasible=True)
    assert not caught.value.solution.feasible


def test_two_tools_keep_their_spacing():
    problem = SubgoalProblem(
        arms=("left", "right"),
        costs=[_pull("left", [-0.02, 0.5, 0.25]), _pull("right", [0.02, 0.5, 0.25])],
        spacing=0.12,
    )
    solution = SubgoalSolver().solve(problem)
    gap = np.linalg.norm(solution.positions["left"] - solution.positions["right"])
    assert solution.feasible
    assert gap == pytest.approx(0.12, abs=1e-3)
    assert solution.positions["left"][0] < solution.positions["right"][0]


def test_a_fixed_arm_keeps_the_decided_one_away():
    problem = SubgoalProblem(arms=("right",), costs=[_pull("right", [0.0, 0.5, 0.25])],
                             fixed={"left": np.array([-0.03, 0.5, 0.25])})
    solution = SubgoalSolver().solve(problem)
    assert np.linalg.norm(solution.positions["right"] - [-0.03, 0.5, 0.25]) >= 0.12 - 1e-3


def test_a_target_out_of_reach_ends_on_the_reach_shell():
    far = np.array([-0.34, 0.5, 0.25])  # 0.81 m from the right shoulder
    solution = SubgoalSolver().solve(SubgoalProblem(arms=("right",), costs=[_pull("right", far)]))
    assert solution.feasible
    assert REACH["right"].slack(solution.positions["right"]) == pytest.approx(0.0, abs=1e-3)


def test_a_warm_start_gives_the_cold_answer_with_fewer_evaluations():
    solver = SubgoalSolver()
    first = solver.solve(_beside_obstacle())
    again = solver.solve(_beside_obstacle(), warm_start=first)
    assert again.method == "slsqp" and again.feasible
    assert again.positions["right"] == pytest.approx(first.positions["right"], abs=1e-4)
    assert again.evaluations < first.evaluations / 10
    # The scene shifts by 1 cm: without the consistency pull, warm and cold agree.
    moved = _beside_obstacle()
    moved.obstacles = moved.obstacles.translated([0.01, 0.0, 0.0])
    moved.weights = SubgoalWeights(consistency=0.0)
    cold = solver.solve(moved)
    warm = solver.solve(moved, warm_start=first)
    assert warm.method == "slsqp" and warm.feasible
    assert warm.positions["right"] == pytest.approx(cold.positions["right"], abs=1e-3)
    assert warm.evaluations < cold.evaluations / 5


def test_the_consistency_pull_damps_a_jump_toward_the_new_answer():
    solver = SubgoalSolver()
    first = solver.solve(_beside_obstacle())
    moved = _beside_obstacle()
    moved.obstacles = moved.obstacles.translated([0.01, 0.0, 0.0])
    moved.weights = SubgoalWeights(consistency=0.0)
    target = solver.solve(moved).positions["right"]
    moved.weights = SubgoalWeights()
    damped = solver.solve(moved, warm_start=first)
    assert damped.feasible
    start = first.positions["right"]
    assert 0.0 < np.linalg.norm(damped.positions["right"] - start) < np.linalg.norm(target - start)
    assert damped.terms["consistency"] > 0.0


def test_same_seed_same_answer():
    problem = SubgoalProblem(arms=("left", "right"), decide_yaw=True,
                             costs=[_pull("left", [-0.1, 0.55, 0.2]), _pull("right", [0.1, 0.45, 0.3])],
                             obstacles=Spheres([[0.0, 0.5, 0.25]], [0.04]))
    a = SubgoalSolver(seed=3).solve(problem)
    b = SubgoalSolver(seed=3).solve(problem)
    assert np.array_equal(a.x, b.x)
    assert a.yaw == b.yaw


def test_a_node_constraint_expression_drives_the_tool_to_its_point():
    frame = make_static_frame(
        {"cup": {"pos": (-0.1, 0.55, 0.05), "extent": (0.08, 0.08, 0.1)},
         "bottle": {"pos": (0.12, 0.55, 0.09), "extent": (0.06, 0.06, 0.18)}},
        arms={"right": {"ee": (0.2, 0.45, 0.25)}, "left": {"ee": (-0.3, 0.45, 0.25)}},
    )
    costs = expression_costs(["dist(right.ee, cup.top + [0, -0.09, 0.08]) - 0.01"], frame)
    problem = SubgoalProblem(
        arms=("right",), costs=costs, obstacles=scene_spheres(frame, round_objects={"cup", "bottle"}),
        preferred={"right": frame.arms["right"].ee}, fixed={"left": frame.arms["left"].ee},
    )
    solution = SubgoalSolver(verify_ik=True).solve(problem)
    target = frame.objects["cup"].top + np.array([0.0, -0.09, 0.08])
    assert solution.feasible
    assert np.linalg.norm(solution.positions["right"] - target) <= 0.01 + 1e-3
    assert solution.ik_residual["right"] < 0.005


def test_a_held_object_turns_with_the_yaw_to_clear_an_obstacle():
    point = np.array([0.1, 0.5, 0.25])
    problem = SubgoalProblem(
        arms=("right",), decide_yaw=True,
        costs=[_pull("right", point, hard=True, slack=0.002)],
        held={"right": Spheres([[0.12, 0.0, 0.0]], [0.03])},  # measured at yaw 0
        obstacles=Spheres([point + [0.12, 0.0, 0.0]], [0.03]),  # where the held object is at yaw 0
    )
    solution = SubgoalSolver().solve(problem)
    assert solution.feasible
    yaw = solution.yaw["right"]
    turned = solution.positions["right"] + 0.12 * np.array([np.cos(yaw), np.sin(yaw), 0.0])
    assert np.linalg.norm(turned - (point + [0.12, 0.0, 0.0])) >= 0.08 - 1e-3


def test_a_warm_start_for_other_arms_is_refused():
    solver = SubgoalSolver()
    left = solver.solve(SubgoalProblem(arms=("left",)))
    with pytest.raises(SolverProblemError, match="warm start"):
        solver.solve(SubgoalProblem(arms=("right",)), warm_start=left)


def test_costs_with_the_same_name_are_reported_apart():
    pull = _pull("right", [0.1, 0.5, 0.25], hard=True, slack=0.01)
    costs = [pull, pull, _pull("right", [0.1, 0.5, 0.3])]
    solution = SubgoalSolver().solve(SubgoalProblem(arms=("right",), costs=costs))
    assert solution.feasible
    assert {"user:right_to", "user:right_to#1", "user:right_to#2"} <= set(solution.terms)
    assert {"user:right_to", "user:right_to#1"} <= set(solution.violations)
