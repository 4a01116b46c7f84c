"""Seeded disturbances: every kind happens, and schedules are the same for two strategies."""

import numpy as np
import pytest

from agentchord.actions.library import make_action
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.harness import KINDS, DisturbanceSetting, parse_kinds
from agentchord.sim.disturbances import ProtocolDisturbances, RandomDisturbances, ScriptedDisturbance

TASK = "single_arm_pour_water"


def _draws(schedule, n=50):
    action = make_action("move_to_obj", "right", {"obj": "cup"})
    due = []
    for k in range(n):
        schedule.action_started("right", action, 100, tick=1000 * k)
        pending = schedule._pending.get("right")
        due.append(None if pending is None else pending[:2])
    return due


def test_same_seed_same_schedule_other_seed_other_schedule():
    assert _draws(RandomDisturbances(0.3, seed=4)) == _draws(RandomDisturbances(0.3, seed=4))
    assert _draws(RandomDisturbances(0.3, seed=4)) != _draws(RandomDisturbances(0.3, seed=5))


def test_probability_zero_never_disturbs_and_bad_input_is_refused():
    assert all(d is None for d in _draws(RandomDisturbances(0.0, seed=1)))
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        RandomDisturbances(1.5, seed=1)
    with pytest.raises(ValueError, match="unknown disturbance kind"):
        parse_kinds("drop,earthquake")


@pytest.mark.parametrize("kind,action,after,moved", [
    ("drop", "move_to_obj", 30, "bottle"),
    ("pull", "move_to_obj", 30, "bottle"),
    ("perturb", "grasp", 40, "bottle"),
    ("shift", "move_to_obj", 20, "cup"),
    ("knock", "move_to_obj", 20, "cup"),
])
def test_every_kind_happens_and_is_the_same_for_both_strategies(kind, action, after, moved):
    firsts = []
    for strategy in ("agentchord", "agentchord-bt"):
        disturbance = ScriptedDisturbance(action, kind, after=after, seed=3)
        result = run_episode(EpisodeSpec(TASK, strategy=strategy, seed=2, disturbance=disturbance,
                                         config=None))
        events = result.trace.of("disturbance")
        assert events and events[0]["kind"] == kind and events[0]["obj"] == moved
        firsts.append(events[0])
    assert firsts[0] == firsts[1]


def test_knock_tips_the_object_over():
    result = run_episode(EpisodeSpec(TASK, seed=2, disturbance=ScriptedDisturbance("move_to_obj", "knock", after=5)))
    knocked = result.trace.of("disturbance")[0]["obj"]
    assert knocked == "cup"


def test_protocol_injects_one_or_two_disturbances_identically_for_both_strategies():
    counts = []
    for seed in range(4):
        schedule = ProtocolDisturbances(seed)
        assert 1 <= len(schedule._due) <= 2
        counts.append(len(schedule._due))
    assert ProtocolDisturbances(7)._due == ProtocolDisturbances(7)._due
    firsts = [run_episode(EpisodeSpec(TASK, strategy=s, seed=1, disturbances=DisturbanceSetting(kinds=KINDS, protocol="custom"))).trace.of("disturbance")[:1]
              for s in ("agentchord", "agentchord-bt")]
    assert firsts[0] == firsts[1] and firsts[0]


def test_presets_name_the_papers_protocols():
    from agentchord.harness import PRESETS

    assert PRESETS["real"] == ("perturb", "pull") and PRESETS["stress"] == KINDS


@pytest.mark.parametrize("kind,low,high,upright", [
    ("pull", 0.04, 0.30, None),      # set down 6-25 cm away, upright or on its side
    ("perturb", 0.01, 0.08, None),   # pushed 2-5 cm
    ("shift", 0.03, 0.12, True),     # slid 5-8 cm, still standing
    ("drop", 0.0, 0.25, None),       # falls from where it was held
    ("knock", 0.0, 0.20, False),     # tipped over where it stood
])
def test_landings_stay_in_the_stated_ranges(kind, low, high, upright):
    from agentchord.bench.landing import landing

    landings = [x for x in (landing(kind, seed) for seed in range(3)) if x is not None]
    assert len(landings) >= 2
    for x in landings:
        assert not x.off_table
        assert low <= x.moved <= high, (x.seed, x.moved)
        assert any(x.reachable.values())
        if upright is not None:
            assert x.upright is upright


def test_a_push_or_a_knock_never_takes_an_object_in_the_air(pour_scene):
    from agentchord.features.oracle import OracleExtractor
    from agentchord.sim.disturbances import _free_objects
    from agentchord.sim.world import SimWorld

    world = SimWorld(pour_scene)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: False)
    for _ in range(30):
        world.step()
    extractor.update()
    # Lift the cup 20 cm, as if just dropped from a hand.
    joint = world.model.body("cup").jntadr[0]
    world.data.qpos[world.model.jnt_qposadr[joint] + 2] += 0.2
    world.step()
    extractor.update()
    assert _free_objects(extractor.frame, world) == ["bottle"]  # the cup is in the air: no one pushes it
    for _ in range(150):  # it lands and comes to rest: then it can be pushed again
        world.step()
    extractor.update()
    assert _free_objects(extractor.frame, world) == ["bottle", "cup"]


def test_a_long_object_pulled_out_of_a_top_grasp_leaves_the_fingers_and_lands_flat():
    from agentchord.features.frame import tilt_deg
    from agentchord.sim.disturbances import ScriptedDisturbance

    seen = {}

    def watch(executor):
        events = executor.disturbance.events
        if events and executor.world.tick == events[0].tick + 60:
            event = events[0]
            seen["held"] = executor.frame.is_holding(event.arm, event.obj)
            seen["tilt"] = tilt_deg(executor.frame.objects[event.obj].axis)

    pull = ScriptedDisturbance("place", "pull", after=10, seed=3)
    run_episode(EpisodeSpec("rearrange_table", seed=1, disturbance=pull), on_tick=watch)
    # Taken out along its length (18 cm: more than the usual 10 cm slide), it is not caught again as
    # the fingers close after the fault, and it lies flat, not on its edge.
    assert seen == {"held": False, "tilt": seen["tilt"]} and seen["tilt"] < 20


@pytest.mark.parametrize("spot_seed", [0, 3])
def test_a_person_takes_the_object_out_of_a_gripper_that_keeps_moving(spot_seed):
    # Inner Monologue does not stop for a pull until its sub-goal check: the arm carries on towards the cup
    # while the person takes the bottle. The person still gets it (a moving arm used to catch it again).
    held = {}

    def watch(executor):
        held[executor.world.tick] = ("right", "bottle") in set(executor.frame.holding)

    pull = ScriptedDisturbance("move_to_obj", "pull", after=26, seed=spot_seed)
    result = run_episode(EpisodeSpec(TASK, strategy="inner-monologue", seed=16, disturbance=pull), on_tick=watch)
    pulled = result.trace.of("disturbance")[0]["tick"]
    assert not held[pulled + 75] and not held[pulled + 150]
    assert result.trace.of("replan")  # its sub-goal check saw the bottle gone


def test_a_perturb_pushes_an_object_at_rest_or_in_the_other_hand_never_one_in_the_air(pour_scene):
    # Real protocol, single-arm pour, seed 32: a pull set the bottle down across the closed fingers,
    # and the push of a later grasp, with no table friction to hold it, flung it off the table.
    import numpy as np

    from agentchord.features.oracle import OracleExtractor
    from agentchord.sim.disturbances import inject
    from agentchord.sim.world import SimWorld

    world = SimWorld(pour_scene)
    extractor = OracleExtractor(world, grasp_signal=lambda arm: False)
    for _ in range(30):
        world.step()
    grasp = make_action("grasp", "right", {"obj": "bottle"})
    rng = np.random.default_rng(0)
    assert inject("perturb", world, extractor.update(), rng, "right", grasp) is not None  # at rest: pushed
    for _ in range(200):
        world.step()
    joint = world.model.body("bottle").jntadr[0]
    world.data.qpos[world.model.jnt_qposadr[joint] + 2] += 0.2  # in the air
    world.step()
    assert inject("perturb", world, extractor.update(), rng, "right", grasp) is None
    frame = extractor.update()
    frame.holding = {("left", "bottle")}  # ... unless the other hand holds it (a hand-over)
    assert inject("perturb", world, frame, rng, "right", grasp) is not None


def test_a_pulled_bottle_is_carried_over_the_cup_and_the_regrasp_reaches_over_it_too():
    # Set down beyond the cup: a straight carry swept the bottle through the cup (stress, p = 0.3,
    # single-arm pour seed 4), and the right hand's straight reach for it struck the cup's rim.
    cup_moved = []

    def watch(executor):
        pos, rotation = executor.world.object_pose("cup")
        if not cup_moved:
            cup_moved.append(pos.copy())
        elif rotation[2, 2] < 0.95 or np.linalg.norm(pos[:2] - cup_moved[0][:2]) > 0.01:
            cup_moved.append(executor.world.tick)

    pull = ScriptedDisturbance("move_to_obj", "pull", after=15, seed=1, spot=(-0.25, 0.7), lying=False)
    result = run_episode(EpisodeSpec(TASK, seed=1, disturbance=pull), on_tick=watch)
    assert result.trace.of("disturbance")[0]["kind"] == "pull"
    assert result.success, result.reason
    assert cup_moved[1:] == []  # the cup never moved or tipped


def test_a_carry_lifts_over_what_stands_in_its_way_but_not_over_its_own_load():
    # Lifted over the capsule in it, a tray pulled out of the hand threw the capsule off the table
    # (planned coffee tray, real protocol, seed 2): what rests in or on the carried object goes with it.
    from types import SimpleNamespace

    from agentchord.sim.disturbances import _carry_height
    from agentchord.sim.tasks import SIM_TASKS

    specs = {o.name: o for o in SIM_TASKS["setup_coffee_tray"].sample_scene(np.random.default_rng(0)).objects}
    on_table = 0.5 * specs["capsule"].height

    def world(x, y, z=on_table):
        poses = {"tray": np.array([0.0, 0.5, 0.5 * specs["tray"].height]), "capsule": np.array([x, y, z])}
        return SimpleNamespace(object_names=["tray", "capsule"], object_spec=specs.__getitem__,
                               object_pose=lambda name: (poses[name], np.eye(3)))

    frame = SimpleNamespace(holding=[])
    start, spot = np.array([0.0, 0.5]), np.array([0.35, 0.5])
    assert _carry_height(world(0.03, 0.5, on_table + 0.005), frame, "tray", start, spot) is None  # on the tray's base
    for x in (0.15, 0.26):  # on the table in the way, beside the tray's centre or beyond its end
        over = _carry_height(world(x, 0.5), frame, "tray", start, spot)
        assert over is not None and over > 2 * on_table
    assert _carry_height(world(0.26, 0.75), frame, "tray", start, spot) is None  # well off the way
    frame.holding = [("left", "capsule")]
    assert _carry_height(world(0.26, 0.5), frame, "tray", start, spot) is None  # up in a hand
