"""Top grasps whose open fingers would come down on a neighbour slide along the object or turn about it;
a side grasp's open fingers are followed along their way in."""

from types import SimpleNamespace

import numpy as np
import pytest

from agentchord.actions.grasping.finger_clearance import (
    END_MARGIN,
    FINGER_ACROSS,
    TopGraspChoice,
    blocking,
    clear_top_grasp,
    crossing_over,
    finger_points,
    horizontal_sizes,
    open_finger_points,
    side_approach_blocking,
    swept_hits,
)
from scipy.spatial.transform import Rotation

from agentchord.actions.library import make_action
from agentchord.features.frame import make_static_frame

#: A yaw of 90 deg: the fork's own x axis (its length) along world y.
ALONG_Y = (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4))
#: The rearrange scene of the stress protocol's seed 2: a fork pushed against the plate's rim.
PLATE = {"pos": (0.03, 0.604, 0.011), "extent": (0.184, 0.184, 0.022)}
GRASP_Z = 0.043  # the tool centre of a top grasp of the flat fork: finger tips 4 mm over the table


def _fork(x: float = -0.075, y: float = 0.662) -> dict:
    return {"pos": (x, y, 0.005), "quat": ALONG_Y, "extent": (0.165, 0.016, 0.011)}


def _frame(**objects):
    return make_static_frame(objects=objects)


def _plain(frame, obj: str = "fork", long_dir=(0.0, 1.0, 0.0)):
    pos = frame.objects[obj].pos
    return np.array([pos[0], pos[1], GRASP_Z]), np.asarray(long_dir, dtype=float)


def test_the_open_fingers_lie_across_the_long_direction_on_both_sides():
    points = finger_points(np.zeros(3), np.array([0.0, 1.0, 0.0]))
    across = np.abs(points[:, 0])
    assert across.min() == pytest.approx(FINGER_ACROSS[0]) and across.max() == pytest.approx(FINGER_ACROSS[1])
    assert (points[:, 0] > 0).sum() == (points[:, 0] < 0).sum()  # both fingers
    assert points[:, 2].min() == pytest.approx(-0.0387)  # the tips, the tool's reach below its centre


def test_a_fork_alone_is_grasped_at_its_centre():
    frame = _frame(fork=_fork())
    assert clear_top_grasp(frame, "fork", *_plain(frame)) == TopGraspChoice()


def test_a_fork_against_the_plate_rim_is_grasped_farther_along_its_length():
    frame = _frame(plate=PLATE, fork=_fork())
    point, long_dir = _plain(frame)
    plain_hits = blocking(frame, "fork", point, long_dir)
    assert set(plain_hits) == {"plate"}
    choice = clear_top_grasp(frame, "fork", point, long_dir)
    assert choice.turn_deg == 0.0  # a long object is slid, never turned off its narrow side
    assert 0.0 < choice.slide <= 0.5 * 0.165 - END_MARGIN  # away from the plate, still on the fork
    turned, moved = choice.apply(long_dir, point)
    assert sum(blocking(frame, "fork", moved, turned).values()) < sum(plain_hits.values())


def test_a_fork_a_little_off_the_rim_is_slid_until_its_fingers_clear():
    frame = _frame(plate=PLATE, fork=_fork(x=-0.085))
    point, long_dir = _plain(frame)
    assert blocking(frame, "fork", point, long_dir)
    choice = clear_top_grasp(frame, "fork", point, long_dir)
    assert choice.blocked_by == ()
    turned, moved = choice.apply(long_dir, point)
    assert blocking(frame, "fork", moved, turned) == {}
    # The nearest clear slide: one step less is still blocked.
    shorter = TopGraspChoice(slide=choice.slide - 0.005).apply(long_dir, point)
    assert blocking(frame, "fork", shorter[1], shorter[0])


def test_a_capsule_beside_a_cup_is_taken_with_the_fingers_turned_away_from_the_cup():
    capsule = {"pos": (0.0, 0.5, 0.014), "extent": (0.037, 0.037, 0.027)}
    cup = {"pos": (0.0, 0.57, 0.05), "extent": (0.06, 0.06, 0.1)}
    frame = _frame(capsule=capsule, cup=cup)
    point, long_dir = _plain(frame, "capsule", long_dir=(1.0, 0.0, 0.0))  # fingers close along y, onto the cup
    assert set(blocking(frame, "capsule", point, long_dir)) == {"cup"}
    choice = clear_top_grasp(frame, "capsule", point, long_dir)
    assert choice.slide == 0.0 and choice.turn_deg != 0.0 and choice.blocked_by == ()
    turned, moved = choice.apply(long_dir, point)
    assert np.allclose(moved, point)  # turned about its centre


def test_an_object_lying_along_its_axis_is_slid_along_it_not_turned():
    # A 19 cm bottle lying along world y (its own axis, the quat's z, horizontal), a cup beside it
    # where the plain grasp's finger comes down: the bottle's length is along y, not in extent[:2].
    lying = (np.cos(np.pi / 4), -np.sin(np.pi / 4), 0.0, 0.0)  # its z axis turned onto world y
    bottle = {"pos": (0.0, 0.5, 0.025), "quat": lying, "axis": (0.0, 1.0, 0.0), "extent": (0.05, 0.05, 0.19)}
    cup = {"pos": (0.075, 0.47, 0.05), "extent": (0.06, 0.06, 0.1)}
    frame = _frame(bottle=bottle, cup=cup)
    along, across = horizontal_sizes(frame.objects["bottle"], np.array([0.0, 1.0, 0.0]))
    assert (along, across) == (pytest.approx(0.19), pytest.approx(0.05))
    point, long_dir = _plain(frame, "bottle")
    assert set(blocking(frame, "bottle", point, long_dir)) == {"cup"}
    choice = clear_top_grasp(frame, "bottle", point, long_dir)
    assert choice.turn_deg == 0.0 and choice.slide > 0.0 and choice.blocked_by == ()


def test_an_object_resting_in_a_container_is_reached_into():
    # A capsule on the tray's floor: the fingers go down inside the tray's box, as they must.
    tray = {"pos": (0.0, 0.55, 0.014), "extent": (0.33, 0.135, 0.027)}
    capsule = {"pos": (0.05, 0.55, 0.016), "extent": (0.037, 0.037, 0.027)}
    frame = _frame(tray=tray, capsule=capsule)
    assert clear_top_grasp(frame, "capsule", *_plain(frame, "capsule")) == TopGraspChoice()


def test_point_features_and_things_below_the_finger_tips_are_not_in_the_way():
    corner = {"pos": (-0.035, 0.662, 0.002), "extent": (0.005, 0.005, 0.004)}  # a cloth corner under a finger
    mat = {"pos": (-0.2, 0.662, -0.004), "extent": (0.2, 0.3, 0.002)}  # sunk in the table top, beside the fork
    frame = _frame(fork=_fork(), corner=corner, mat=mat)
    assert blocking(frame, "fork", *_plain(frame)) == {}


def _robot(frame, base=(-0.469, 0.5, 0.079)):
    return SimpleNamespace(
        frame=frame,
        world=SimpleNamespace(arm_base=lambda arm: np.asarray(base, dtype=float)),
        rotation=lambda arm: np.eye(3),  # a level tool: no wrist-rotate preference
    )


def test_the_grasp_aims_at_the_clear_point_and_keeps_it_when_it_looks_again():
    frame = _frame(plate=PLATE, fork=_fork(x=-0.085))
    grasp = make_action("grasp", "left", {"obj": "fork", "mode": "top"})
    robot = _robot(frame)
    _, point = grasp._top_frame(robot)
    assert point[1] > 0.662 + 0.01  # slid along the fork, away from the plate
    # The plate is nudged (the approach touched it): the choice made at the first look is kept,
    # where a fresh look would slide the grasp farther.
    frame.objects["plate"].pos = np.array([0.03, 0.625, 0.011])
    _, again = grasp._top_frame(robot, keep_choice=True)
    assert again[1] == pytest.approx(point[1])
    _, fresh = grasp._top_frame(robot)
    assert fresh[1] > point[1] + 0.004


def test_a_grasp_point_the_graph_asked_for_is_not_moved():
    # A handle given by an offset stays where the graph put it, whatever stands beside it.
    frame = _frame(plate=PLATE, fork=_fork(x=-0.085))
    grasp = make_action("grasp", "left", {"obj": "fork", "mode": "top", "offset": [0.0, 0.01, 0.0]})
    _, point = grasp._top_frame(_robot(frame))
    assert point[:2] == pytest.approx([-0.085, 0.672])


# Stress protocol, dual-arm pour, seed 8: the cup beside a bottle lying on the table, the left arm's
# side grasp approaching the cup along +x.
CUP = {"pos": (-0.081, 0.405, 0.0535), "extent": (0.048, 0.048, 0.107)}


def _lying_bottle(at=(-0.118, 0.478), yaw=-2.69) -> dict:
    x, y, z, w = (Rotation.from_euler("z", yaw) * Rotation.from_euler("y", 90, degrees=True)).as_quat()
    axis = Rotation.from_quat([x, y, z, w]).apply([0.0, 0.0, 1.0])
    return {"pos": (*at, 0.0245), "quat": (w, x, y, z), "axis": tuple(axis), "extent": (0.049, 0.049, 0.187)}


def _side_way_in(height: float, approach=(1.0, 0.0, 0.0)):
    approach = np.asarray(approach, dtype=float)
    rotation = np.column_stack([approach, np.cross((0.0, 0.0, 1.0), approach), (0.0, 0.0, 1.0)])
    point = np.array([CUP["pos"][0], CUP["pos"][1], height])
    return point - 0.08 * approach, point, rotation


def test_the_open_fingers_of_a_side_grasp_close_across_the_approach_and_stand_upright():
    _, point, rotation = _side_way_in(0.05)
    points = open_finger_points(point, rotation) - point
    assert np.abs(points[:, 1]).min() == pytest.approx(FINGER_ACROSS[0])  # across the approach (y)
    assert points[:, 2].max() == pytest.approx(-points[:, 2].min())  # their width is vertical
    assert points[:, 0].max() == pytest.approx(0.0387)  # the tips reach past the tool centre


def test_a_side_grasp_with_nothing_beside_its_way_in_is_clear():
    frame = _frame(cup=CUP, bottle=_lying_bottle(at=(0.2, 0.6)))
    assert side_approach_blocking(frame, "cup", *_side_way_in(0.0535)) == {}


def test_a_side_grasp_sweeping_into_a_lying_bottle_is_blocked_and_a_higher_one_passes_over_it():
    frame = _frame(cup=CUP, bottle=_lying_bottle())
    assert set(side_approach_blocking(frame, "cup", *_side_way_in(0.0535))) == {"bottle"}
    assert side_approach_blocking(frame, "cup", *_side_way_in(0.8 * 0.107)) == {}


def test_only_the_way_in_is_swept_not_what_lies_beyond_the_object():
    # The bottle lying past the cup, ahead of the fingers' tips at the grasp: not in the way.
    frame = _frame(cup=CUP, bottle=_lying_bottle(at=(0.02, 0.405), yaw=np.pi / 2))
    assert side_approach_blocking(frame, "cup", *_side_way_in(0.0535)) == {}


def test_a_swept_path_reports_what_the_fingers_and_a_held_object_pass_through():
    # A tool pointing down with one open finger over the cup (the fingers lie 3.5-5.9 cm either side
    # of the tool centre, their tips 3.9 cm below it): clear 9 cm over the cup's top, in it at 3 cm.
    frame = _frame(cup=CUP, bottle=_lying_bottle())
    down = np.column_stack([(0.0, 0.0, -1.0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)])
    finger_over_cup = np.array([CUP["pos"][0], CUP["pos"][1] - 0.045, 0.107])
    assert swept_hits(frame, "bottle", [(finger_over_cup + (0.0, 0.0, 0.09), down)]) == {}
    assert set(swept_hits(frame, "bottle", [(finger_over_cup + (0.0, 0.0, 0.03), down)])) == {"cup"}
    # An object held 10 cm down the tool's approach, beside the finger, reaches into the cup from 9 cm.
    held = np.array([[0.0, 0.045, 0.0], [0.1, 0.045, 0.0]])
    assert set(swept_hits(frame, "bottle", [(finger_over_cup + (0.0, 0.0, 0.09), down)], held, 0.02)) == {"cup"}
    # The object being grasped is never in its own way.
    assert "bottle" not in swept_hits(frame, "bottle", [(np.array([-0.118, 0.478, 0.06]), down)])


def _top_down(at, long_dir=(-0.4, 0.92, 0.0)):
    """A top-down tool pose at ``at``, fingers closing across ``long_dir`` (the lying bottle's axis)."""
    from agentchord.solvers.poses import top_down_rotation
    from agentchord.actions.motion import pose_from_matrix

    long_dir = np.asarray(long_dir, dtype=float)
    return pose_from_matrix(np.asarray(at, dtype=float), top_down_rotation(long_dir / np.linalg.norm(long_dir)))


def _leg_hits(frame, obj, start, end):
    from agentchord.actions.grasping.finger_clearance import _sweeps

    return _sweeps(frame, obj, start, end)


# Single-arm pour, stress seed 38: the hand let the bottle go at (0.03, 0.50, 0.21); the bottle lies
# beyond the cup, whose rim the straight line to the fallen grasp's pre-grasp crossed.
POUR_CUP = {"pos": (-0.091, 0.594, 0.047), "extent": (0.053, 0.053, 0.094)}
FALLEN_BOTTLE = {"pos": (-0.169, 0.629, 0.027), "extent": (0.055, 0.055, 0.192), "axis": (-0.4, 0.92, 0.0)}


def test_a_move_whose_straight_line_crosses_a_neighbour_goes_over_it():
    frame = make_static_frame({"cup": POUR_CUP, "bottle": FALLEN_BOTTLE})
    start, goal = _top_down((0.03, 0.503, 0.14)), _top_down((-0.169, 0.629, 0.125))
    assert set(_leg_hits(frame, "bottle", start, goal)) == {"cup"}
    waypoints = crossing_over(frame, "bottle", start, goal)
    assert waypoints is not None and len(waypoints) == 2
    up, over = waypoints
    np.testing.assert_allclose(up.pos[:2], start.pos[:2])
    np.testing.assert_allclose(over.pos[:2], goal.pos[:2])
    assert up.pos[2] == over.pos[2] >= goal.pos[2]
    legs = [(start, up), (up, over), (over, goal)]
    assert not any(_leg_hits(frame, "bottle", a, b) for a, b in legs)


def test_a_clear_straight_move_or_one_no_crossing_clears_is_left_as_it_is():
    frame = make_static_frame({"cup": POUR_CUP, "bottle": FALLEN_BOTTLE})
    start, goal = _top_down((-0.3, 0.45, 0.2)), _top_down((-0.169, 0.629, 0.125))
    assert not _leg_hits(frame, "bottle", start, goal)
    assert crossing_over(frame, "bottle", start, goal) is None
    # A finger of the pre-grasp itself in the cup: no height helps.
    from agentchord.solvers.poses import quat_to_rotation

    across = quat_to_rotation(_top_down((0.0, 0.0, 0.0)).quat).as_matrix()[:, 1]
    inside = _top_down(np.array([-0.091, 0.594, 0.1]) - 0.047 * across)
    assert set(_leg_hits(frame, "bottle", inside, inside)) == {"cup"}
    assert crossing_over(frame, "bottle", start, inside) is None
