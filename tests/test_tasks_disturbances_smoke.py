"""Every task runs under every disturbance kind (slow: one episode per pair)."""

import pytest

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.library import library_tasks
from agentchord.harness import KINDS, DisturbanceSetting
from agentchord.sim.disturbances import ScriptedDisturbance
from agentchord.sim.tasks import SIM_TASKS

TASKS = sorted(set(SIM_TASKS) & set(library_tasks()))


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("task", TASKS)
def test_task_runs_to_a_verdict_under_each_disturbance_kind(task, kind):
    result = run_episode(EpisodeSpec(task, disturbances=DisturbanceSetting(p=0.3, kinds=(kind,)), seed=1))
    # Success is not guaranteed under heavy disturbance; a verdict with a reason is.
    assert result.reason
    assert all(e["kind"] == kind for e in result.trace.of("disturbance"))
    assert result.trace.events[-1]["event"] == "episode_end"


def _recoveries(result) -> list[str]:
    return [e["to"] for e in result.trace.of("recovery_switch")]


@pytest.mark.usefixtures("numerics_before_lean_solves")
def test_a_bottle_pushed_askew_in_its_grasp_is_set_down_and_taken_again():
    # Real-world protocol, seed 10: the bottle is pushed while the fingers close and ends 21 deg askew
    # in the hand; a pour from that hold misses the cup. The anticipated slipped-grasp branch fires.
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=10, disturbances=DisturbanceSetting(kinds=("perturb", "pull"), protocol="custom")))
    assert result.success, result.reason
    assert "e2_r_bottle_slipped" in _recoveries(result)


def test_a_bottle_tipped_askew_in_the_hand_after_a_regrasp_is_set_down_before_the_pour():
    # The bottle drops on its way to the cup and is taken again; on the carry on to the cup a person
    # tips it 4 N m about x for 10 ticks, and it sits askew in the fingers. The carry watches for an
    # askew hold as the nominal carry does, so it is set down and taken again, not poured askew.
    # (Table II's seed 16 did this by itself until the fallen grasp's turn changed.)
    tipped = {"ticks": 0}

    def tip(executor) -> None:
        world = executor.world
        on = executor.program is not None and executor.program.edge_id == "r_bottle_regrasped_to_v2" and tipped["ticks"] < 10
        world.data.xfrc_applied[world.model.body("bottle").id, 3:6] = [4.0, 0.0, 0.0] if on else 0.0
        tipped["ticks"] += on

    drop = ScriptedDisturbance("move_to_obj", "drop", nth=0, after=30)
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=1, disturbance=drop), on_tick=tip)
    assert result.success, result.reason
    assert _recoveries(result) == ["e2_r_bottle_dropped", "r_bottle_regrasped_slipped"]


def test_a_bottle_knocked_over_as_it_is_taken_again_is_taken_as_a_fallen_one():
    # Stress protocol, seed 19: the bottle pulled out of the hand during the pour is set down upright;
    # the regrasp's approach knocks it over and used to close on it lying, carrying it across the
    # fingers to a pour that never came. The grasp now sees it fell and takes it as a fallen one.
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=19, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert result.success, result.reason
    assert _recoveries(result) == ["e4_r_bottle_dropped"]



def test_a_fork_pushed_against_the_plate_is_taken_farther_along_its_length():
    # Stress protocol, seed 86 (seed 2 until the empty hand went home faster and the moments
    # moved): the fork, placed, is pushed against the plate's rim. Taken at its centre, a finger
    # comes down on the rim and the tool stops 1.5 cm above the grasp ("stopped short"); the grasp
    # slides along the fork.
    result = run_episode(EpisodeSpec("rearrange_table", seed=86, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert result.success, result.reason
    assert _recoveries(result) == ["e4_r_fork_moved"]


def test_a_capsule_dropped_against_the_tray_handle_is_taken_with_the_fingers_turned():
    # Stress protocol, seed 13: the capsule drops against the tray's handle; taken with the fingers
    # closing toward the handle, one finger came down on it three times ("fingers closed but capsule
    # is not held") and the right arm could not reach. The fingers now turn off the handle.
    result = run_episode(EpisodeSpec("setup_coffee_tray", seed=13, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert result.success, result.reason
    assert _recoveries(result) == ["e2_r_capsule_dropped"]


HEAVY = {"disturbances": DisturbanceSetting(p=0.3, kinds=KINDS)}


def _pour_node(result, node: str) -> dict:
    return [e for e in result.trace.of("node_reached") if e["node"] == node][-1]


def test_a_bottle_caught_again_near_its_top_after_a_drop_is_taken_again_before_the_pour():
    # p = 0.3, all kinds, seed 8: the bottle drops out of the closed fingers as the grasp lifts and is
    # caught again as they close, at 82 % of its height. The synchronous grasp's recovery kept that
    # hold (skip_if_held) and the pour reached 5.8 cm short of the cup's centre; with reseat asked it
    # now takes the bottle again at the asked height.
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=8, **HEAVY))
    assert result.success, result.reason
    assert _pour_node(result, "v4")["constraints_hold"]


def test_without_the_height_check_that_bottle_pours_beside_the_cup(monkeypatch):
    # (The off-centre carry of a fallen grasp's hold is checked where it acts: tests/test_actions_library.py.)
    monkeypatch.setattr("agentchord.actions.grasp.Grasp.HELD_HEIGHT_TOLERANCE", float("inf"))
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=8, **HEAVY))
    assert not result.success
    assert "never reached a pouring orientation above the" in result.reason


def _top_grasps_at_the_centre(monkeypatch, report_blocked: bool) -> None:
    """Make every top grasp the plain one (the behaviour before the fingers' clearance was checked)."""
    from agentchord.actions import grasp
    from agentchord.actions.grasping import finger_clearance

    def plain(frame, obj, point, long_dir):
        hits = finger_clearance.blocking(frame, obj, point, long_dir)
        return finger_clearance.TopGraspChoice(blocked_by=tuple(sorted(hits)) if report_blocked else ())

    monkeypatch.setattr(grasp, "clear_top_grasp", plain)


def test_an_arm_that_falls_short_of_a_pushed_object_is_not_blamed_on_the_other_arm(monkeypatch):
    # Seed 86 again with the fork taken at its centre and nothing known of what the fingers land on:
    # the arm stops short with its links 5 cm clear of the other arm's; the reason used to say "the
    # other arm was in the way".
    _top_grasps_at_the_centre(monkeypatch, report_blocked=False)
    result = run_episode(EpisodeSpec("rearrange_table", seed=86, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert not result.success
    assert "stopped short of the grasp of fork" in result.reason
    assert "in the way" not in result.reason


def test_fingers_that_come_down_on_a_neighbour_are_named_in_the_reason(monkeypatch):
    # The same grasp, its fingers known to overlap the plate and no clear one chosen, nor a drag of
    # the fork away from the plate: the reason says what they came down on.
    _top_grasps_at_the_centre(monkeypatch, report_blocked=True)
    monkeypatch.setattr("agentchord.actions.grasp.Grasp.DRAGS", 0)
    result = run_episode(EpisodeSpec("rearrange_table", seed=86, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert not result.success
    assert "the open fingers came down on plate beside fork" in result.reason


def test_a_fork_the_fingers_come_down_beside_is_dragged_off_the_plate_and_taken(monkeypatch):
    # The same again with the drag (actions/grasping/drag_clear.py): the fork is dragged clear and taken.
    _top_grasps_at_the_centre(monkeypatch, report_blocked=True)
    result = run_episode(EpisodeSpec("rearrange_table", seed=86, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert result.success, result.reason


class _Both:
    """Two scripted disturbances in one episode (each keeps its own schedule)."""

    def __init__(self, *parts: ScriptedDisturbance) -> None:
        self.parts = parts

    @property
    def events(self) -> list:
        return [event for part in self.parts for event in part.events]

    def action_started(self, arm, action, expected_ticks, tick) -> None:
        for part in self.parts:
            part.action_started(arm, action, expected_ticks, tick)

    def action_ended(self, arm) -> None:
        for part in self.parts:
            part.action_ended(arm)

    def apply(self, world, frame):
        for part in self.parts:
            event = part.apply(world, frame)
            if event is not None:
                return event
        return None


@pytest.mark.parametrize("crosses_over", [False, True])
def test_an_arm_switch_whose_busy_hand_already_lost_its_object_goes_on(crosses_over, straight_carry, monkeypatch):
    # Both arms lose their objects: the right arm drops the bottle on its way to the cup, then, as the
    # recovery starts, a person takes the cup out of the left hand and sets it down far on the right,
    # beyond the bottle lying there. Reaching straight in, the left arm's grasp sweeps into the bottle
    # and pushes the cup away. The cup's recovery passes to the right arm, whose bottle already fell:
    # its hand is free already (place free_hand), it takes the cup over the lying bottle, and takes
    # the fallen bottle again before the pour. A grasp that crosses over the bottle (as side grasps
    # now do) takes the cup with the left arm itself.
    from agentchord.actions import grasp as grasp_module

    if not crosses_over:
        monkeypatch.setattr(grasp_module, "crossing_over", lambda *args: None)
    both = _Both(ScriptedDisturbance("move_to_obj", "drop", nth=0, after=36),
                 ScriptedDisturbance("move_to_target", "pull", nth=1, after=1, seed=1, spot=(0.25, 0.35), lying=False))
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=8, disturbance=both))
    assert [(e["kind"], e["obj"], e["arm"]) for e in result.trace.of("disturbance")] == [("drop", "bottle", "right"), ("pull", "cup", "left")]
    assert result.success, result.reason
    assert ("e3_r_cup_dropped_via_right" in result.path) is not crosses_over


def test_a_recovery_whose_scene_changed_under_it_is_bound_once_more():
    # Stress protocol, seed 2: the cup drops at its spot and lands placed (the regrasp only opens the
    # hand); then it is knocked over before the place step, which finds it neither held nor placed.
    # The recovery is bound again from there and this time takes the cup again.
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=2, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom")))
    assert result.success, result.reason
    failed = result.trace.of("recovery_failed")
    assert [f["edge"] for f in failed] == ["e6_r_cup_dropped"]
    assert result.path.count("e6_r_cup_dropped") == 2


@pytest.mark.parametrize(("disturbance_seed", "victim"), [(0, "bottle"), (3, "cup")])
def test_a_cup_or_bottle_knocked_over_as_the_arms_go_home_is_stood_up_again(disturbance_seed, victim):
    # The task's last edge sends both arms home; a person knocking the cup or the bottle over then
    # left it lying, and the goal (both upright) failed with no recovery to run.
    knock = ScriptedDisturbance("back", "knock", nth=0, after=20, seed=disturbance_seed)
    result = run_episode(EpisodeSpec("dual_arm_pour_water", seed=disturbance_seed, disturbance=knock))
    assert [e["obj"] for e in result.trace.of("disturbance")] == [victim]
    assert result.success, result.reason
    assert _recoveries(result) == [f"e7_r_{victim}_knocked"]


def test_a_tray_pushed_off_its_spot_as_the_arms_go_home_is_carried_back():
    # The right arm's return home (the third `back`) is when a person slides the released tray 5-8 cm.
    shift = ScriptedDisturbance("back", "shift", nth=2, after=20, seed=0)
    result = run_episode(EpisodeSpec("setup_coffee_tray", seed=0, disturbance=shift))
    assert [e["obj"] for e in result.trace.of("disturbance")] == ["tray"]
    assert result.success, result.reason
    assert _recoveries(result) == ["e5_r_tray_moved"]


def test_a_bottle_knocked_over_just_before_the_arm_gets_home_is_caught_as_it_falls():
    # Knocked 6 ticks before the last edge ends, the bottle is still falling (about 30 deg) when the
    # goal is first judged: the verdict waits for the scene to come to rest, the last edge's monitor
    # sees the bottle go over, and its recovery stands it up again (the verdict on the falling
    # bottle used to end the episode).
    clean = run_episode(EpisodeSpec("single_arm_pour_water", seed=0))
    back_start = [e["tick"] for e in clean.trace.of("action_start") if ".back" in e["action"]][-1]
    knock = ScriptedDisturbance("back", "knock", nth=0, after=clean.steps - back_start - 6, seed=0)
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=0, disturbance=knock))
    assert [e["obj"] for e in result.trace.of("disturbance")] == ["bottle"]
    assert [e["tick"] for e in result.trace.of("goal_settling")] == [clean.steps]
    assert result.success, result.reason
    assert _recoveries(result) == ["e6_r_bottle_knocked"]


def test_a_bottle_knocked_over_again_on_the_recoverys_way_home_is_stood_up_once_more():
    # The knock recovery ends by sending the arm home, where no monitor watches the bottle; a second
    # knock then left it lying and the goal failed. The goal's failure is one the edge into it
    # watches for (bottle_knocked), so that recovery runs again.
    twice = _Both(ScriptedDisturbance("back", "knock", nth=0, after=20, seed=0),
                  ScriptedDisturbance("back", "knock", nth=1, after=20, seed=2))
    result = run_episode(EpisodeSpec("single_arm_pour_water", seed=0, disturbance=twice))
    assert [e["obj"] for e in result.trace.of("disturbance")] == ["bottle", "bottle"]
    assert [e["failure"] for e in result.trace.of("violation_at_goal")] == ["bottle_knocked"]
    assert result.success, result.reason
    assert _recoveries(result) == ["e6_r_bottle_knocked", "e6_r_bottle_knocked"]
