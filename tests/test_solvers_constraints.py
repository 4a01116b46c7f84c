"""User constraints of the solvers and task-graph expressions evaluated at candidate tool positions."""

import numpy as np
import pytest

from agentchord.expr import ExprNameError
from agentchord.features.frame import make_static_frame
from agentchord.solvers.constraints import HypotheticalFrame, UserCost, expression_costs
from agentchord.solvers.exceptions import SolverProblemError


def _frame():
    return make_static_frame(
        {"bottle": {"pos": (0.1, 0.5, 0.1), "extent": (0.06, 0.06, 0.2)}, "cup": {"pos": (-0.1, 0.6, 0.05)}},
        arms={"right": {"ee": (0.1, 0.5, 0.12)}, "left": {"ee": (-0.3, 0.5, 0.2)}},
        holding={("right", "bottle")},
    )


def test_the_held_object_moves_rigidly_with_the_tool_and_the_original_frame_stays():
    frame = _frame()
    hypothetical = HypotheticalFrame(frame)
    moved = hypothetical.place({"right": np.array([0.0, 0.6, 0.3])})
    assert moved.arms["right"].ee == pytest.approx([0.0, 0.6, 0.3])
    assert moved.objects["bottle"].pos == pytest.approx([0.0, 0.6, 0.28])
    assert moved.objects["bottle"].top == pytest.approx([0.0, 0.6, 0.38])
    assert moved.objects["cup"].pos == pytest.approx(frame.objects["cup"].pos)
    assert frame.arms["right"].ee == pytest.approx([0.1, 0.5, 0.12])
    assert frame.objects["bottle"].pos == pytest.approx([0.1, 0.5, 0.1])
    # Every place starts from the original: moving back restores it exactly.
    back = hypothetical.place({"right": np.array([0.1, 0.5, 0.12])})
    assert back.objects["bottle"].bottom == pytest.approx(frame.objects["bottle"].bottom)


def test_expression_costs_read_the_candidate_positions():
    frame = _frame()
    (reach_cup,) = expression_costs(["dist(right.ee, cup.top + [0, -0.09, 0.08]) - 0.01"], frame)
    target = frame.objects["cup"].top + np.array([0.0, -0.09, 0.08])
    assert reach_cup.fn({"right": target}) == pytest.approx(-0.01)
    assert reach_cup.fn({"right": target + [0.0, 0.0, 0.05]}) == pytest.approx(0.04)
    assert reach_cup.hard and reach_cup.name.startswith("dist(")
    (over_cup,) = expression_costs(["dist(bottle.top, cup.top + [0, 0, 0.1]) - 0.005"], frame, weight=3.0, hard=False)
    tool = frame.objects["cup"].top + np.array([0.0, 0.0, 0.1]) - (frame.objects["bottle"].top - frame.arms["right"].ee)
    assert over_cup.fn({"right": tool}) == pytest.approx(-0.005)
    assert over_cup.weight == 3.0 and not over_cup.hard


def test_attached_overrides_what_the_frame_holds():
    frame = _frame()
    (cost,) = expression_costs(["bottle.pos[2] - 0.2"], frame, attached={})
    assert cost.fn({"right": np.array([0.1, 0.5, 0.4])}) == pytest.approx(-0.1)  # the bottle stayed
    with pytest.raises(SolverProblemError, match="spoon"):
        expression_costs(["bottle.pos[2]"], frame, attached={"right": ["spoon"]})


def test_bad_expressions_and_costs_are_refused():
    with pytest.raises(ExprNameError):
        expression_costs(["dist(right.ee, mug.top)"], _frame())
    with pytest.raises(SolverProblemError):
        UserCost(fn=3.0)
    with pytest.raises(SolverProblemError):
        UserCost(fn=lambda p: 0.0, weight=-1.0)
