"""Where disturbed objects end up: the landing statistics of each disturbance kind.

One scripted disturbance per episode (the same action, moment and seeds for every
kind), the object's pose read when it has come to rest (when the recovery binds its
arm, or a fixed time after the event), and at that moment whether each arm could take
it (reach model confirmed by the IK, ``execution.feasibility``). The figures say
whether a kind behaves like the person it models: a pull sets the object down on
the table, a perturbation pushes it a few centimetres, nothing is thrown off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from agentchord.actions.catalog import GraspArgs
from agentchord.actions.library import Grasp
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.executor import Executor, ExecutorConfig
from agentchord.execution.feasibility import off_table
from agentchord.features.frame import ARMS, tilt_deg
from agentchord.sim.disturbances import ScriptedDisturbance

#: Ticks after the event at which an object that no recovery bound is measured.
SETTLE_TICKS = 110
#: Tilt (deg) under which a tall object counts as upright.
UPRIGHT_DEG = 25.0

#: (task, object, action, ticks into it) each kind is injected at: the object is held, approached or nearby.
SCENARIOS: dict[str, tuple[str, str, str, int]] = {
    "drop": ("single_arm_pour_water", "bottle", "move_to_obj", 15),
    "pull": ("single_arm_pour_water", "bottle", "move_to_obj", 15),
    "perturb": ("single_arm_pour_water", "bottle", "grasp", 40),
    "shift": ("single_arm_pour_water", "cup", "move_to_obj", 20),
    "knock": ("single_arm_pour_water", "cup", "move_to_obj", 20),
}


@dataclass(frozen=True)
class Landing:
    """Where one disturbed object came to rest.

    Attributes:
        kind: The disturbance kind.
        seed: The episode's seed.
        moved: Horizontal distance (m) from where it was at the event.
        upright: Whether it stands upright.
        off_table: Whether it left the table.
        reachable: Per arm, whether that arm could take it there.
    """

    kind: str
    seed: int
    moved: float
    upright: bool
    off_table: bool
    reachable: dict[str, bool]


def landing(kind: str, seed: int) -> Landing | None:
    """Inject ``kind`` in its scenario with ``seed`` and measure where the object comes to rest.

    Returns:
        The landing, or None when the disturbance did not apply (nothing to drop at that moment).
    """
    task, obj, action, after = SCENARIOS[kind]
    # (tick, position) at the event, and the landing once measured.
    start: tuple[int, np.ndarray] | None = None
    done: Landing | None = None

    def on_tick(executor: Executor) -> None:
        nonlocal start, done
        if done is not None:
            return
        frame = executor.frame
        events = executor.trace.of("disturbance")
        if events and start is None:
            start = (events[0]["tick"], frame.objects[obj].pos.copy())
        if start is None:
            return
        bound = executor.trace.of("recovery_bound")
        if bound or executor.world.tick - start[0] >= SETTLE_TICKS:
            checker = executor.feasibility
            done = Landing(
                kind=kind,
                seed=seed,
                moved=float(np.linalg.norm(frame.objects[obj].pos[:2] - start[1][:2])),
                upright=tilt_deg(frame.objects[obj].axis) < UPRIGHT_DEG,
                off_table=bool(off_table(frame, [obj])),
                # Reach alone: the other arm's pose and what the hands hold are not the object's doing.
                # (model_validate, not GraspArgs(obj=obj): mypy takes the positional Field defaults for required.)
                reachable={arm: checker.check_grasp(Grasp(arm, GraspArgs.model_validate({"obj": obj})), hand_free=False,
                                                    avoid_other_arm=False).feasible for arm in ARMS},
            )

    disturbance = ScriptedDisturbance(action, kind, after=after, seed=seed)
    # Long enough for the event and the settling after it; the rest of the episode does not matter here.
    config = ExecutorConfig(tick_limit=700)
    run_episode(EpisodeSpec(task, seed=seed, disturbance=disturbance, config=config), on_tick=on_tick)
    return done


def summarise(landings: list[Landing]) -> dict[str, float]:
    """Shares and distance percentiles of one kind's landings."""
    n = len(landings)
    moved = np.array([x.moved for x in landings]) if n else np.zeros(1)
    return {
        "n": n,
        "moved_median_m": float(np.median(moved)),
        "moved_p5_m": float(np.percentile(moved, 5)),
        "moved_p95_m": float(np.percentile(moved, 95)),
        "upright": sum(x.upright for x in landings) / max(n, 1),
        "reach_left": sum(x.reachable["left"] for x in landings) / max(n, 1),
        "reach_right": sum(x.reachable["right"] for x in landings) / max(n, 1),
        "reach_any": sum(any(x.reachable.values()) for x in landings) / max(n, 1),
        "off_table": sum(x.off_table for x in landings) / max(n, 1),
    }
