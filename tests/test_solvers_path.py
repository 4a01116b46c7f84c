"""The receding-horizon path solver, paper Eq. 10: around obstacles, within step limits, to the goal."""

import numpy as np
import pytest

from agentchord.features.frame import make_static_frame
from agentchord.solvers.constraints import expression_costs
from agentchord.solvers.exceptions import PathNotReachedError, SolverProblemError
from agentchord.solvers.obstacles import Spheres
from agentchord.solvers.path import PathSolution, RecedingHorizonPathSolver, plan_path

CENTRE = np.array([0.0, 0.5, 0.2])
SPHERE = Spheres([CENTRE], [0.05])
START, GOAL = np.array([-0.2, 0.5, 0.2]), np.array([0.2, 0.5, 0.2])


def _steps(points: np.ndarray) -> np.ndarray:
    return np.linalg.norm(np.diff(points, axis=0), axis=1)


@pytest.mark.parametrize("start, goal", [(START, GOAL), (START + [0, -0.03, 0], GOAL + [0, 0.04, 0.01])])
def test_the_tool_goes_around_a_sphere_keeping_the_margin_and_the_step_limit(start, goal):
    solver = RecedingHorizonPathSolver(horizon=20, execute=5, step=0.006, margin=0.02, tool_radius=0.02)
    path = plan_path(start, goal, SPHERE, solver)
    assert path.reached and path.feasible
    assert np.linalg.norm(path.points[-1] - goal) <= 0.002
    clearance = SPHERE.clearance(path.points, 0.02).min()
    assert clearance >= 0.02 - 1e-3
    assert _steps(path.points).max() <= 0.006 + 1e-6
    # It really went around: the straight line runs through the sphere.
    assert np.abs(path.points[:, 1:] - start[1:]).max() > 0.05


def test_a_held_object_keeps_the_margin_too():
    held = Spheres([[0.0, 0.0, -0.08]], [0.03])  # a bottle hanging below the tool
    solver = RecedingHorizonPathSolver(held=held)
    path = plan_path(START, GOAL, SPHERE, solver)
    assert path.reached
    assert SPHERE.clearance(path.points + held.centres[0], 0.03).min() >= 0.02 - 1e-3


def test_a_path_constraint_expression_holds_at_every_waypoint():
    frame = make_static_frame({"cup": {"pos": (0.0, 0.6, 0.05)}}, arms={"right": {"ee": START}})
    above = expression_costs(["0.25 - right.ee[2]"], frame)  # keep the tool at least 25 cm high
    start = np.array([-0.2, 0.5, 0.26])
    solver = RecedingHorizonPathSolver(costs=above)
    path = plan_path(start, np.array([0.2, 0.55, 0.3]), Spheres(), solver)
    assert path.reached
    assert path.points[:, 2].min() >= 0.25 - 1e-3


def test_waypoints_stay_in_the_box_and_a_goal_outside_it_is_never_reached():
    solver = RecedingHorizonPathSolver(high=np.array([0.56, 0.95, 0.3]))
    path = plan_path(START, np.array([-0.2, 0.5, 0.4]), None, solver, max_solves=30)
    assert not path.reached
    assert path.points[:, 2].max() <= 0.3 + 1e-9
    assert path.points[-1] == pytest.approx([-0.2, 0.5, 0.3], abs=2e-3)
    with pytest.raises(PathNotReachedError) as caught:
        plan_path(START, np.array([-0.2, 0.5, 0.4]), None, solver, max_solves=5, require_reached=True)
    assert caught.value.path.solves == 5


def test_a_warm_plan_is_shifted_by_the_executed_ticks():
    solver = RecedingHorizonPathSolver(horizon=6, execute=2)
    plan = PathSolution(waypoints=np.arange(18, dtype=float).reshape(6, 3), cost=0.0, seconds=0.0)
    shifted = solver.shift(plan)
    assert shifted[:4] == pytest.approx(plan.waypoints[2:])
    assert shifted[4:] == pytest.approx(np.repeat(plan.waypoints[-1:], 2, axis=0))
    first = solver.step(START, GOAL, SPHERE)
    second = solver.step(first.waypoints[1], GOAL, SPHERE, warm=first, previous=first.waypoints[0])
    assert second.feasible
    assert second.waypoints.shape == (6, 3)
    assert np.linalg.norm(second.waypoints[0] - first.waypoints[1]) <= 0.006 + 1e-6


def test_malformed_solvers_are_refused():
    with pytest.raises(SolverProblemError):
        RecedingHorizonPathSolver(horizon=5, execute=6)
    with pytest.raises(SolverProblemError):
        RecedingHorizonPathSolver(step=0.0)
    with pytest.raises(SolverProblemError):
        RecedingHorizonPathSolver(low=np.ones(3), high=np.zeros(3))
