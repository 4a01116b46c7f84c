"""An object pressed against a neighbour is dragged away by one finger's tip until a top grasp's
fingers fit beside it."""

import dataclasses

import numpy as np
import pytest

from agentchord.actions.base import Status
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.drag_clear import EDGE_MARGIN, FINGER_ACROSS, TIP_THICKNESS, DragPlan, plan_drag
from agentchord.actions.grasping.finger_clearance import clear_top_grasp
from agentchord.actions.grasp import Grasp
from agentchord.actions.library import make_action
from agentchord.actions.grasping.top_grasp import plain_top_grasp
from agentchord.features.frame import make_static_frame
from agentchord.features.oracle import OracleExtractor
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import scene_rng
from agentchord.sim.world import SimWorld

#: A yaw of 90 deg: the fork's own x axis (its length) along world y.
ALONG_Y = (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4))
PLATE = {"pos": (0.03, 0.604, 0.011), "extent": (0.184, 0.184, 0.022)}
#: The fork's left side 1 mm off the plate's rim, along it (where it touches, the rim is along y).
FLUSH_X = 0.03 - 0.092 - 0.001 - 0.008


def _fork(x: float = FLUSH_X, y: float = 0.604) -> dict:
    return {"pos": (x, y, 0.0055), "quat": ALONG_Y, "extent": (0.165, 0.016, 0.011)}


def _clears(frame, plan: DragPlan, length: float) -> bool:
    objects = dict(frame.objects)
    objects["fork"] = dataclasses.replace(objects["fork"], pos=objects["fork"].pos + length * plan.away)
    moved = dataclasses.replace(frame, objects=objects)
    long_dir, point = plain_top_grasp(moved.objects["fork"])
    return not clear_top_grasp(moved, "fork", point, long_dir).blocked_by


def test_a_fork_against_the_plate_is_dragged_square_to_its_length_away_from_the_plate():
    frame = make_static_frame(objects={"plate": PLATE, "fork": _fork()})
    long_dir, point = plain_top_grasp(frame.objects["fork"])
    assert clear_top_grasp(frame, "fork", point, long_dir).blocked_by == ("plate",)  # why it is dragged
    plan = plan_drag(frame, "fork", ("plate",))
    assert plan is not None
    assert plan.away == pytest.approx([-1.0, 0.0, 0.0], abs=1e-6)
    # The pressing tip (the finger's inner edge, nearer the plate) lies on the fork, just inside its
    # plate-side edge; the tool centre is beyond the fork, away from the plate.
    tip_x = plan.press[0] + FINGER_ACROSS[0] + 0.5 * TIP_THICKNESS
    fork_edge = FLUSH_X + 0.008
    assert fork_edge - 0.5 * TIP_THICKNESS - tip_x == pytest.approx(EDGE_MARGIN, abs=1e-6)
    assert plan.press[2] - 0.0387 < 0.011  # the tip below the fork's top: it presses
    # The shortest drag after which the fingers of a top grasp clear the plate.
    assert _clears(frame, plan, plan.length)
    assert not _clears(frame, plan, plan.length - 0.01)


def test_no_drag_without_a_way_out():
    fork = _fork(x=0.0, y=0.604)
    # Between two boxes pressing on it from either side: no direction leads away from both.
    walls = {"left": {"pos": (-0.02, 0.604, 0.02), "extent": (0.02, 0.2, 0.04)},
             "right": {"pos": (0.02, 0.604, 0.02), "extent": (0.02, 0.2, 0.04)}}
    assert plan_drag(make_static_frame(objects={"fork": fork, **walls}), "fork", ("left", "right")) is None
    # A cup standing where the hand would drag it.
    cup = {"pos": (FLUSH_X - 0.1, 0.604, 0.045), "extent": (0.07, 0.07, 0.09)}
    assert plan_drag(make_static_frame(objects={"plate": PLATE, "fork": _fork(), "cup": cup}), "fork", ("plate",)) is None
    # Nothing named to drag it from.
    assert plan_drag(make_static_frame(objects={"plate": PLATE, "fork": _fork()}), "fork", ()) is None


def _grasp_fork_against_the_plate(drags: int, monkeypatch) -> tuple[Status, SimWorld, str]:
    scene = SIM_TASKS["rearrange_table"].sample_scene(scene_rng(5))
    plate = next(o for o in scene.objects if o.name == "plate")
    fork = next(o for o in scene.objects if o.name == "fork")
    flush = (plate.pos[0] - plate.size[0] - fork.size[1] - 0.0005, plate.pos[1])
    scene = dataclasses.replace(scene, objects=[plate, dataclasses.replace(fork, pos=flush, yaw=np.pi / 2)])
    world = SimWorld(scene)
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame
    monkeypatch.setattr(Grasp, "DRAGS", drags)
    action = make_action("grasp", "left", {"obj": "fork", "mode": "top"})
    action.initialise(robot)
    for _ in range(2500):
        status = action.update(robot)
        if status != Status.RUNNING:
            return status, world, action.failure_reason or ""
        robot.step()
        extractor.update()
    raise AssertionError("the grasp did not finish")


def test_a_fork_pushed_against_the_plate_is_dragged_clear_and_taken(monkeypatch):
    status, world, _ = _grasp_fork_against_the_plate(Grasp.DRAGS, monkeypatch)
    assert status == Status.SUCCESS
    assert world.holding("left", "fork")
    # Without the drag the fingers come down on the plate's rim.
    status, world, reason = _grasp_fork_against_the_plate(0, monkeypatch)
    assert status == Status.FAILURE
    assert "the open fingers came down on plate beside fork" in reason
    assert not world.holding("left", "fork")
