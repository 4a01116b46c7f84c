"""Atomic actions on the real physics: grasps hold through contact, programs are interruptible."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from agentchord.harness import DisturbanceSetting
from agentchord.actions.base import Status
from agentchord.actions.controller import RobotController
from agentchord.actions.grasping.finger_clearance import swept_hits
from agentchord.actions.grasp import GraspMissed
from agentchord.actions.joint_path import joint_path
from agentchord.actions.library import make_action
from agentchord.actions import motion
from agentchord.actions.motion import EMPTY_HAND_JOINT_SPEED
from agentchord.actions.move import BACK_OPEN_WIDTH
from agentchord.features.frame import make_static_frame, tilt_deg
from agentchord.features.oracle import OracleExtractor
from agentchord.robot.aloha import HOME_Q
from agentchord.sim.world import SimWorld


def _setup(scene):
    world = SimWorld(scene)
    robot = RobotController(world)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: robot.targets[arm].grip_closed_settled)
    robot.frame = extractor.frame
    return world, robot, extractor


def _run(robot, extractor, action, max_ticks=1500):
    action.initialise(robot)
    for tick in range(max_ticks):
        status = action.update(robot)
        if status != Status.RUNNING:
            return status, tick
        robot.step()
        extractor.update()
    raise AssertionError("action did not finish")


def test_grasp_lifts_the_bottle_only_through_finger_contact(pour_scene):
    world, robot, extractor = _setup(pour_scene)
    z0 = world.object_pose("bottle")[0][2]
    status, _ = _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle"}))
    assert status == Status.SUCCESS
    assert world.holding("right", "bottle")
    assert world.object_pose("bottle")[0][2] > z0 + 0.04
    # Open the fingers: the bottle falls back to the table.
    status, _ = _run(robot, extractor, make_action("open_gripper", "right", {}))
    for _ in range(60):
        robot.step()
    assert not world.holding("right", "bottle")
    assert world.on_table("bottle")


def test_interrupted_action_leaves_the_arm_holding_still(pour_scene):
    world, robot, extractor = _setup(pour_scene)
    action = make_action("grasp", "right", {"obj": "bottle"})
    action.initialise(robot)
    for _ in range(40):
        action.update(robot)
        robot.step()
        extractor.update()
    action.terminate(Status.INVALID)
    assert action.status == Status.INVALID
    held = robot.commanded_pose("right").pos
    for _ in range(40):
        robot.step()
    # The target froze where the action was interrupted and the arm settles there.
    assert np.array_equal(robot.commanded_pose("right").pos, held)
    assert np.linalg.norm(world.tcp_pose("right")[0] - held) < 0.005


def _lay_bottle_down(world, scene, extractor, at=(0.08, 0.5), yaw=1.2) -> None:
    """The bottle lying on the table at ``at``, its top turned ``yaw`` rad about z, at rest."""
    adr = world.model.joint("bottle_free").qposadr[0]
    radius = scene.objects[0].size[0]
    x, y, z, w = (Rotation.from_euler("z", yaw) * Rotation.from_euler("y", 90, degrees=True)).as_quat()
    world.data.qpos[adr : adr + 7] = [*at, radius + 0.001, w, x, y, z]
    for _ in range(40):
        world.step()
    extractor.update()


def test_grasp_of_a_fallen_bottle_sets_it_upright_in_hand(pour_scene):
    world, robot, extractor = _setup(pour_scene)
    _lay_bottle_down(world, pour_scene, extractor)
    assert extractor.frame.objects["bottle"].axis[2] < 0.2  # lying down
    status, _ = _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle"}))
    assert status == Status.SUCCESS, make_action
    assert world.holding("right", "bottle")
    assert extractor.frame.objects["bottle"].axis[2] > np.cos(np.radians(20))


ARM_LINKS = ("shoulder_link", "upper_arm_link", "upper_forearm_link", "lower_forearm_link", "wrist_link")


def _arm_struck(world, arm: str = "vx300s_right") -> set[str]:
    """Which of the arm's links (not its gripper) touch the bottle or another of its own links now."""
    model, data = world.model, world.data
    struck = set()
    for contact in data.contact[: data.ncon]:
        a, b = (model.body(model.geom_bodyid[g]).name for g in (contact.geom1, contact.geom2))
        links = [n for n in (a, b) if n.startswith(arm) and n.split("/")[1] in ARM_LINKS]
        if links and ("bottle" in (a, b) or (a.startswith(arm) and b.startswith(arm))):
            struck.update(links)
    return struck


@pytest.mark.parametrize("yaw", [0.0, 1.6, 3.0])
def test_a_fallen_bottle_beside_the_arms_own_base_is_turned_upright_clear_of_the_arm(pour_scene, yaw):
    # Lying 21 cm from the right arm's shoulder (Table II, single-arm pour, seed 4): turned upright where
    # it was picked up, the arm folds its forearm onto its own upper arm and flings the bottle off the
    # table. It is carried out to 30 cm from the shoulder first.
    world, robot, extractor = _setup(pour_scene)
    _lay_bottle_down(world, pour_scene, extractor, at=(0.26, 0.476), yaw=yaw)
    grasp = make_action("grasp", "right", {"obj": "bottle"})
    grasp.initialise(robot)
    struck: set[str] = set()
    for _ in range(1500):
        if grasp.update(robot) != Status.RUNNING:
            break
        robot.step()
        extractor.update()
        struck |= _arm_struck(world)
    assert grasp.status == Status.SUCCESS, grasp.failure_reason
    assert world.holding("right", "bottle")
    assert extractor.frame.objects["bottle"].axis[2] > np.cos(np.radians(20))
    assert not struck


@pytest.mark.usefixtures("numerics_before_lean_solves")
@pytest.mark.parametrize("crosses_over", [True, False])
def test_a_fallen_grasp_goes_over_a_neighbour_its_straight_approach_would_strike(crosses_over, monkeypatch, straight_carry):
    # Stress protocol, single-arm pour, seed 38: the bottle pulled out of the hand lies beyond the cup
    # from where the hand let it go. The straight move to the fallen grasp's pre-grasp crossed the cup's
    # rim; the fingers struck it and the cup went off the table. The hand now goes over it.
    from agentchord.actions import grasp as grasp_module
    from agentchord.episode import EpisodeSpec, run_episode

    if not crosses_over:
        monkeypatch.setattr(grasp_module, "crossing_over", lambda *args: None)
        # The straight move also loses the live IK's line on the way, and the approach's detour
        # through home (motion.LINE_LOST) would then go round the cup: keep to the line, as before.
        monkeypatch.setattr(motion, "LINE_LOST", np.inf)
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=38, disturbances=DisturbanceSetting.from_options(protocol="stress")))
    if crosses_over:
        assert result.success, result.reason
    else:
        assert not result.success and "cup fell off the table" in result.reason


@pytest.mark.usefixtures("numerics_before_lean_solves")
@pytest.mark.parametrize("slides", [True, False])
def test_a_fallen_grasp_slides_along_the_object_where_a_finger_would_come_down_on_a_neighbour(slides, monkeypatch, straight_carry):
    # Real-world protocol, single-arm pour, seed 58: the bottle pulled out of the hand lies against the
    # cup. At its centre a finger came down on the cup's rim and the tool stopped 6 cm above the grasp,
    # three times, for the right arm; the left arm's alternative could not reach past it. Slid 2.5 cm
    # along the bottle, clear of the cup, the right arm takes it.
    from agentchord.actions import grasp as grasp_module
    from agentchord.actions.grasping.finger_clearance import TopGraspChoice
    from agentchord.episode import EpisodeSpec, run_episode

    if not slides:
        monkeypatch.setattr(grasp_module, "clear_top_grasp", lambda *args: TopGraspChoice())
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=58, disturbances=DisturbanceSetting.from_options(protocol="real")))
    if slides:
        assert result.success, result.reason
    else:
        assert not result.success and "bottle_dropped_via_left" in result.reason


def test_a_side_grasp_refuses_an_object_knocked_over_meanwhile(pour_scene):
    # A side grasp closing on a bottle that now lies would carry it lying across the fingers; the
    # grasp's retry takes it the way a fallen one is taken instead.
    world, robot, extractor = _setup(pour_scene)
    grasp = make_action("grasp", "right", {"obj": "bottle"})
    grasp._still_standing(robot, "during the approach")  # upright: goes on
    _lay_bottle_down(world, pour_scene, extractor)
    with pytest.raises(GraspMissed, match="fell over during the approach"):
        grasp._still_standing(robot, "during the approach")


def test_place_without_the_object_in_hand_fails_with_a_reason(pour_scene):
    _, robot, extractor = _setup(pour_scene)
    action = make_action("place", "right", {"obj": "bottle", "target": [0.1, 0.42]})
    status, _ = _run(robot, extractor, action)
    assert status == Status.FAILURE
    assert "not held" in action.failure_reason


def test_unknown_action_arguments_are_refused():
    with pytest.raises(Exception, match="angle"):
        make_action("rotate_eef", "right", {"angel": 90})


def test_a_side_grasp_beside_the_arms_own_base_backs_off_less_and_still_holds(pour_scene):
    import dataclasses

    # The cup set down low beside the left arm's base: the usual 8 cm pre-grasp folds the elbow past its limit.
    objects = [dataclasses.replace(o, pos=(-0.1, 0.57)) if o.name == "cup" else o for o in pour_scene.objects]
    world, robot, extractor = _setup(dataclasses.replace(pour_scene, objects=objects))
    for _ in range(20):
        robot.step()
        extractor.update()
    grasp = make_action("grasp", "left", {"obj": "cup"})
    pre, point = (pose.pos for pose in grasp.target_poses(robot))
    backed_off = float(np.linalg.norm((pre - point)[:2]))
    assert backed_off < 0.079 or pre[2] > point[2] + 0.02  # a shorter or a higher pre-grasp than the asked one
    status, _ = _run(robot, extractor, grasp)
    assert status == Status.SUCCESS and world.holding("left", "cup")


#: A spoon as the frame sees one lying flat: its axis (the thinnest side) up, its 15 cm length
#: (local x) turned to world y.
FLAT_SPOON_ALONG_Y = {"quat": (np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)), "axis": (0.0, 0.0, 1.0), "extent": (0.15, 0.03, 0.01)}


def _placing(frame_objects, **args):
    from types import SimpleNamespace

    place = make_action("place", "right", {"obj": "spoon", "target": [0.17, 0.0], "relative_to": "plate", "yaw": 90, **args})
    frame = make_static_frame(objects={"plate": {"pos": (0.0, 0.5, 0.01), "extent": (0.2, 0.2, 0.02)}, **frame_objects})
    return place, SimpleNamespace(frame=frame)


@pytest.mark.parametrize("spoon,placed", [
    ({"pos": (0.18, 0.51, 0.01)}, True),                            # 1.4 cm off, along y: placed
    ({"pos": (0.22, 0.5, 0.01)}, False),                            # 5 cm off
    ({"pos": (0.17, 0.5, 0.15)}, False),                            # over the spot, in mid-air
    ({"pos": (0.17, 0.5, 0.01), "quat": (1.0, 0.0, 0.0, 0.0)}, False),  # on the spot, along x: wrong yaw
])
def test_a_place_knows_when_its_object_already_lies_at_the_target(spoon, placed):
    spoon = {**FLAT_SPOON_ALONG_Y, **spoon}
    place, robot = _placing({"spoon": spoon})
    assert place.lies_at_target(robot) is placed
    robot.frame.holding = {("right", "spoon")}
    assert place.lies_at_target(robot) is False  # still in the hand: not placed yet


def test_a_place_with_a_sub_goal_check_takes_an_object_released_where_it_holds_as_placed():
    # 5 cm off the place's own target, but where the recovery's merge node wants it.
    spoon = {**FLAT_SPOON_ALONG_Y, "pos": (0.22, 0.5, 0.01)}
    place, robot = _placing({"spoon": spoon})
    assert place.lies_at_target(robot) is False
    place.meets_subgoal = lambda frame: frame.objects["spoon"].pos[0] > 0.2
    assert place.lies_at_target(robot) is True
    robot.frame.holding = {("right", "spoon")}
    assert place.lies_at_target(robot) is False  # in the hand: never placed, whatever the check says


@pytest.mark.parametrize("offset", [(0.03, 0.026), (0.02, -0.04)])
def test_a_side_grasp_from_a_hand_right_over_the_object_goes_round_its_top(pour_scene, offset):
    # The bottle set upright under the hand (Table II, dual-arm pour, seed 1): the straight line down
    # to the pre-grasp drove the open fingers into its top and knocked it over.
    world, robot, extractor = _setup(pour_scene)
    bottle = extractor.frame.objects["bottle"]
    over = [bottle.pos[0] + offset[0], bottle.pos[1] + offset[1], bottle.top[2] + 0.065]
    status, _ = _run(robot, extractor, make_action("move_to_target", "right", {"pos": over, "yaw": 180.0}))
    assert status == Status.SUCCESS
    grasp = make_action("grasp", "right", {"obj": "bottle"})
    grasp.initialise(robot)
    tilt = 0.0
    while grasp.update(robot) == Status.RUNNING:
        robot.step()
        extractor.update()
        tilt = max(tilt, tilt_deg(extractor.frame.objects["bottle"].axis))
    assert grasp.status == Status.SUCCESS, grasp.failure_reason
    assert world.holding("right", "bottle")
    assert tilt < 5.0


@pytest.mark.parametrize("holding", [False, True])
def test_back_opens_a_hand_closed_on_nothing_and_keeps_a_held_object(pour_scene, holding):
    # A towel corner that slipped out of the pinch as its place ended rests in the closed fingers;
    # going home with them closed dragged it off its top corner (Table II, fold towel, seed 6).
    world, robot, extractor = _setup(pour_scene)
    if holding:
        assert _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle"}))[0] == Status.SUCCESS
    else:
        away = make_action("move_to_target", "right", {"pos": [0.2, 0.45, 0.2], "yaw": 180.0})
        assert _run(robot, extractor, away)[0] == Status.SUCCESS
        assert _run(robot, extractor, make_action("close_gripper", "right", {}))[0] == Status.SUCCESS
    back = make_action("back", "right", {})
    back.initialise(robot)
    start = robot.commanded_pose("right").pos.copy()
    span = float(np.max(np.abs(HOME_Q - robot.ik.arm_q("right"))))
    grip_when_moving = width_when_moving = None
    moving_ticks = 0
    while back.update(robot) == Status.RUNNING:
        if grip_when_moving is None and np.linalg.norm(robot.commanded_pose("right").pos - start) > 0.001:
            grip_when_moving, width_when_moving = robot.targets["right"].grip, world.gripper_width("right")
        moving_ticks += grip_when_moving is not None
        robot.step()
        extractor.update()
    assert back.status == Status.SUCCESS
    # An empty hand goes home twice as fast as one that holds something (the min-jerk move's
    # first ticks, before the tool has gone 1 mm, are not counted).
    expected = int(np.ceil(1.875 * span / (1.0 if holding else EMPTY_HAND_JOINT_SPEED) * 50))
    assert expected - 8 <= moving_ticks <= expected + 1
    if holding:
        assert grip_when_moving == 1.0 and world.holding("right", "bottle")
    else:
        # The fingers opened before the arm set off.
        assert grip_when_moving == 0.0 and width_when_moving >= BACK_OPEN_WIDTH


@pytest.mark.parametrize("rising", [True, False])
def test_an_empty_hand_rises_before_going_home_where_the_way_home_passes_its_fingers_through_an_object(
    pour_scene, rising, monkeypatch
):
    # A side place's retreat leaves the fingers 8 cm back from the bottle's side; the joint-space
    # move home from there can swing them through its top (stress protocol: the handover's block,
    # seeds 30 and 32, knocked off its spot). The hand goes straight up first; without that, this
    # bottle is knocked over.
    if not rising:
        monkeypatch.setattr("agentchord.actions.move.BACK_RISES", ())
    world, robot, extractor = _setup(pour_scene)
    assert _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle"}))[0] == Status.SUCCESS
    place = make_action("place", "right", {"obj": "bottle", "target": [0.2, 0.4]})
    assert _run(robot, extractor, place)[0] == Status.SUCCESS
    assert swept_hits(robot.frame, None, list(joint_path(robot, "right", HOME_Q).tool_poses))
    at = world.object_pose("bottle")[0].copy()
    assert _run(robot, extractor, make_action("back", "right", {}))[0] == Status.SUCCESS
    for _ in range(50):
        robot.step()
    extractor.update()
    moved = float(np.linalg.norm(world.object_pose("bottle")[0] - at))
    if rising:
        assert moved < 0.005 and tilt_deg(robot.frame.objects["bottle"].axis) < 2.0
    else:
        assert moved > 0.05


def _place_cup(world, at) -> None:
    adr = world.model.joint("cup_free").qposadr[0]
    world.data.qpos[adr : adr + 2] = at


@pytest.mark.parametrize("clearing", [True, False])
def test_a_side_grasp_does_not_sweep_its_fingers_into_a_bottle_lying_beside_the_cup(pour_scene, clearing, monkeypatch):
    # Stress protocol, dual-arm pour, seed 8: the cup pulled out of the left hand rests beside the bottle
    # lying on the table; the plain side grasp's open fingers swept into the bottle, pushed it, and the
    # cup was caught 3.9 cm off the grasp point, three times. The clearing grasp passes over it.
    import dataclasses

    from agentchord.actions.grasping import side_plan

    if not clearing:
        monkeypatch.setattr(side_plan, "CLEAR_TURNS_DEG", ())
        monkeypatch.setattr(side_plan, "CLEAR_HEIGHT", 0.0)
    sizes = {"bottle": (0.0245, 0.0935), "cup": (0.024, 0.0535)}  # that episode's (radius, half height)
    scene = dataclasses.replace(pour_scene, objects=[dataclasses.replace(o, size=sizes[o.name]) for o in pour_scene.objects])
    world, robot, extractor = _setup(scene)
    _place_cup(world, (-0.081, 0.405))
    _lay_bottle_down(world, scene, extractor, at=(-0.118, 0.478), yaw=-2.69)
    bottle_before = extractor.frame.objects["bottle"].pos.copy()
    grasp = make_action("grasp", "left", {"obj": "cup"})
    status, _ = _run(robot, extractor, grasp, max_ticks=2500)
    pushed = float(np.linalg.norm(extractor.frame.objects["bottle"].pos[:2] - bottle_before[:2]))
    if clearing:
        assert status == Status.SUCCESS, grasp.failure_reason
        assert world.holding("left", "cup")
        assert pushed < 0.01
    else:
        assert status == Status.FAILURE or pushed > 0.02


def test_a_side_grasp_is_not_raised_over_a_neighbour_standing_in_its_way(pour_scene):
    # Table I, dual-arm pour seed 6 (AgentChord-BT's backtrack): the cup stands just behind the bottle
    # and the bottle's grasp sweeps 1.8 cm into it; no turn clears. A standing neighbour is nudged
    # and slides, so the bottle is taken at the asked height, not raised over the cup as over a
    # lying one (a pour follows, which needs the asked hold).
    import dataclasses

    from agentchord.actions.grasping.side_plan import REACH_VARIANTS, SidePlanner

    sizes = {"bottle": (0.0295, 0.0945), "cup": (0.0245, 0.042)}
    scene = dataclasses.replace(pour_scene, objects=[dataclasses.replace(o, size=sizes[o.name]) for o in pour_scene.objects])
    world, robot, extractor = _setup(scene)
    for name, at in (("bottle", (0.0, 0.556)), ("cup", (0.002, 0.621))):
        adr = world.model.joint(f"{name}_free").qposadr[0]
        world.data.qpos[adr : adr + 2] = at
    for _ in range(40):
        world.step()
    extractor.update()
    grasp = make_action("grasp", "right", {"obj": "bottle"})
    planner = SidePlanner(robot, "right", grasp.args, np.zeros(3))
    assert planner.blocked(planner.variant(REACH_VARIANTS[0]))  # the asked grasp sweeps into the cup
    point = grasp.target_poses(robot)[1].pos
    assert grasp._height_fraction is None
    assert point[2] == pytest.approx(grasp._side_point(robot)[2])


@pytest.mark.parametrize("centred_within", [0.01, float("inf")])
def test_a_bottle_held_off_centre_by_a_fallen_grasp_is_carried_to_where_a_centred_one_would_be(pour_scene, centred_within, monkeypatch):
    # A fallen grasp sets the bottle upright in the hand ~2 cm out along the approach. Carried to the
    # usual tool pose beside the cup, its mouth came down that far from where the pour aims (p = 0.3,
    # single-arm seed 4 once missed the cup by 4.2 cm): move_to_obj carries the object there instead.
    from agentchord.actions.grasping.in_hand import axis_offset_in_tool
    from agentchord.actions.move import MoveToObj

    monkeypatch.setattr(MoveToObj, "CENTRED_WITHIN", centred_within)
    world, robot, extractor = _setup(pour_scene)
    _lay_bottle_down(world, pour_scene, extractor, at=(0.2, 0.45), yaw=2.0)
    assert _run(robot, extractor, make_action("grasp", "right", {"obj": "bottle"}), max_ticks=2500)[0] == Status.SUCCESS
    frame = extractor.frame
    held_out = axis_offset_in_tool(frame, "right", "bottle", Rotation.from_quat(np.roll(frame.arms["right"].ee_quat, -1)).as_matrix())
    assert np.linalg.norm(held_out) > 0.015
    offset = np.array([0.0, -0.09, 0.08])
    move = make_action("move_to_obj", "right", {"obj": "cup", "offset": offset.tolist(), "yaw": 180})
    assert _run(robot, extractor, move)[0] == Status.SUCCESS
    frame = extractor.frame
    aimed = frame.objects["cup"].top + offset
    miss = float(np.linalg.norm((frame.objects["bottle"].pos - aimed)[:2]))
    if centred_within < 1.0:
        assert miss < 0.01
    else:
        assert miss > 0.015


@pytest.mark.parametrize("confirmed", [True, False])
def test_a_hand_off_spot_is_one_the_taker_reaches_with_the_top_down_grasp_it_will_make(confirmed, monkeypatch):
    """Coffee tray stress seed 22: the capsule, dropped 0.60 m from the left shoulder, is inside the
    side-grasp reach shell, so the right arm set it down where it lay, where the left arm's top-down
    grasp ends 2 cm short. The IK-confirmed spot is 2 cm nearer the left arm, and the left arm takes it."""
    from agentchord.actions import place
    from agentchord.sim.tasks import SIM_TASKS

    if not confirmed:
        monkeypatch.setattr(place, "_top_grasp_reaches", lambda *args: True)
    world, robot, extractor = _setup(SIM_TASKS["setup_coffee_tray"].sample_scene(np.random.default_rng([0, 0x5CE7E])))
    adr = world.model.joint("capsule_free").qposadr[0]
    world.data.qpos[adr : adr + 2] = (0.10, 0.32)
    for _ in range(60):
        world.step()
    extractor.update()
    assert _run(robot, extractor, make_action("grasp", "right", {"obj": "capsule", "mode": "top"}))[0] == Status.SUCCESS
    hand_off = make_action("place", "right", {"obj": "capsule", "within_reach": "left"})
    assert _run(robot, extractor, hand_off)[0] == Status.SUCCESS
    assert _run(robot, extractor, make_action("back", "right", {}))[0] == Status.SUCCESS
    set_down = world.object_pose("capsule")[0]
    status, _ = _run(robot, extractor, make_action("grasp", "left", {"obj": "capsule", "mode": "top"}))
    if confirmed:
        assert set_down[0] < 0.09  # moved towards the left arm
        assert status == Status.SUCCESS and robot.frame.is_holding("left", "capsule")
    else:
        assert abs(set_down[0] - 0.10) < 0.01  # where it lay
        assert status == Status.FAILURE


@pytest.mark.slow
@pytest.mark.parametrize("seed", [25, 33])
def test_a_cloth_corner_pinched_off_its_point_is_held(seed):
    # Real-world protocol, fold towel, seeds 25 and 33: a corner re-taken from the folded towel (it
    # lies on the cloth) is pinched 2.6-2.8 cm from its point. The hold is a hold (the frame reports
    # it: the fingers touch the cloth near the point); before, the off-centre check let go of it
    # three times and the episode failed ("towel_bl is held 2.8 cm off the grasp point").
    from agentchord.episode import EpisodeSpec, run_episode

    result = run_episode(EpisodeSpec("fold_towel", seed=seed, disturbances=DisturbanceSetting.from_options(protocol="real")))
    assert result.success, result.reason
