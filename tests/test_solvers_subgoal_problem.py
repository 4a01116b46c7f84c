"""A sub-goal problem as posed: malformed ones are refused; a tool's yaw read from its quaternion."""

import numpy as np
import pytest

from agentchord.solvers.exceptions import SolverProblemError
from agentchord.solvers.obstacles import Spheres
from agentchord.solvers.subgoal_problem import WORKSPACE_HIGH, WORKSPACE_LOW, SubgoalProblem, tool_yaw


def test_tool_yaw_reads_the_approach_axis():
    half = np.pi / 8
    assert tool_yaw(np.array([np.cos(half), 0.0, 0.0, np.sin(half)])) == pytest.approx(np.pi / 4)
    assert tool_yaw(np.array([1.0, 0.0, 0.0, 0.0])) == pytest.approx(0.0)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"arms": ("middle",)}, "unknown arm"),
        ({"arms": ()}, "one or two distinct arms"),
        ({"arms": ("left", "left")}, "one or two distinct arms"),
        ({"arms": ("right",), "fixed": {"right": np.zeros(3)}}, "both decided and fixed"),
        ({"low": np.ones(3), "high": np.zeros(3)}, "empty box"),
        ({"arms": ("right",), "held": {"left": Spheres()}}, "not decided"),
        ({"arms": ("right",), "reach": {}}, "no reach model"),
    ],
)
def test_malformed_problems_are_refused(kwargs, message):
    with pytest.raises(SolverProblemError, match=message):
        SubgoalProblem(**kwargs)


def test_a_problem_defaults_to_the_workspace_box_as_arrays_of_its_own():
    problem = SubgoalProblem(low=[-0.1, 0.3, 0.1], high=(0.1, 0.7, 0.3))
    assert isinstance(problem.low, np.ndarray) and problem.low.shape == (3,)
    default = SubgoalProblem()
    np.testing.assert_array_equal(default.low, WORKSPACE_LOW)
    default.low[0] = 9.0
    np.testing.assert_array_equal(WORKSPACE_LOW, [-0.35, 0.25, 0.05])  # the default was a copy
    np.testing.assert_array_equal(default.high, WORKSPACE_HIGH)
