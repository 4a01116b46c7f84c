"""What the towel's physics costs, and what a cheaper setting of it costs the fold.

The towel as shipped (:class:`FoldTowel`): a 7 x 7 grid, a 4 ms step (5 substeps a tick), the
conjugate-gradient solver, and the noslip pass (what a corner pinch holds by) only on the ticks after
a finger touched the cloth. Each variant below changes a physics setting of the towel scene only
(the rigid tasks are untouched) and runs whole episodes with the executor, so a variant is judged by
what the fold does with it, not by a replay: success, the failures that ended the others, and the
episode's speed in multiples of real time.

    .venv/bin/python benchmarks/bench_cloth_physics.py [--seeds 0,1,2] [--protocols none,real] [--variants all]

Variants (``--variants`` takes a comma-separated subset):

- ``as-is``: the shipped scene.
- ``before``: the setting shipped before: a 2 ms step, Newton, the noslip pass on every step
  (0.86x real time); ``before-*``: it with one or more changes (``noslip-off``, ``noslip-touch``,
  ``dt-4ms``, ``cg``, ``pyramidal``, ``grid-6-dt-4ms-noslip-touch``).
- ``noslip-off`` / ``noslip-always``: no noslip pass / on every step.
- ``newton``: Newton's solver instead of conjugate gradient.
- ``dt-2ms`` / ``dt-5ms``: another physics step.
- ``grid-5`` / ``grid-6``: a coarser grid (the corner's place offsets are tuned for 7 x 7).
- ``pyramidal``: pyramidal friction cones instead of elliptic ones.

Two cheaper pinches MuJoCo 3.8 does not offer a flex, so they are not variants: an ``adhesion``
actuator on the finger bodies pulls on geom contacts only (on the cloth's it applies no force),
and sleeping islands (``mjENBL_SLEEP``) stop with "flex equality does not yet support sleeping".
``--probes`` checks both on the installed MuJoCo (a pad pressed on a box, then on a cloth, and
lifted with its adhesion on; a resting cloth stepped with sleeping on) and prints what it found.
"""

from __future__ import annotations

import argparse
import os
import statistics
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

os.environ.setdefault("OMP_NUM_THREADS", "1")

import mujoco
from rich.console import Console
from rich.table import Table

import agentchord.sim.world as sim_world
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.harness import DisturbanceSetting
from agentchord.sim.tasks.fold_towel import FoldTowel

TASK = "fold_towel"


@dataclass(frozen=True)
class Variant:
    """One setting of the towel scene's physics (None: as shipped, see :class:`FoldTowel`)."""

    timestep: float | None = None
    noslip: int | None = None
    noslip_on_touch: bool | None = None
    grid: tuple[int, int] | None = None
    cone: str | None = None
    solver: str | None = None


#: The setting shipped before the towel's physics was made cheaper: a 2 ms step, Newton, noslip always.
BEFORE = dict(timestep=0.002, solver="newton", noslip_on_touch=False)

VARIANTS = {
    "as-is": Variant(),
    "before": Variant(**BEFORE),
    "noslip-off": Variant(noslip=0),
    "noslip-always": Variant(noslip_on_touch=False),
    "newton": Variant(solver="newton"),
    "dt-2ms": Variant(timestep=0.002),
    "dt-5ms": Variant(timestep=0.005),
    "grid-5": Variant(grid=(5, 5)),
    "grid-6": Variant(grid=(6, 6)),
    "pyramidal": Variant(cone="pyramidal"),
    "before-noslip-off": Variant(**{**BEFORE, "noslip": 0}),
    "before-noslip-touch": Variant(**{**BEFORE, "noslip_on_touch": True}),
    "before-dt-4ms": Variant(**{**BEFORE, "timestep": 0.004}),
    "before-dt-4ms-noslip-touch": Variant(**{**BEFORE, "timestep": 0.004, "noslip_on_touch": True}),
    "before-cg": Variant(**{**BEFORE, "solver": "cg"}),
    "before-pyramidal": Variant(**{**BEFORE, "cone": "pyramidal"}),
    "before-grid-6-dt-4ms-noslip-touch": Variant(**{**BEFORE, "grid": (6, 6), "timestep": 0.004, "noslip_on_touch": True}),
}


@contextmanager
def towel_physics(variant: Variant) -> Iterator[None]:
    """Worlds built inside take the variant's settings when their scene has a cloth."""
    init, count = sim_world.SimWorld.__init__, FoldTowel.COUNT

    def patched_init(world, scene, *args, **kwargs):
        if scene.cloth is not None:
            if variant.timestep is not None:
                scene.timestep = variant.timestep
            if variant.solver is not None:
                scene.solver = variant.solver
            if variant.noslip_on_touch is not None:
                scene.noslip_while_touching_cloth = variant.noslip_on_touch
            if variant.noslip is not None:
                scene.noslip_while_touching_cloth = False
        init(world, scene, *args, **kwargs)
        if scene.cloth is not None and variant.noslip is not None:
            world.model.opt.noslip_iterations = variant.noslip
        if scene.cloth is not None and variant.cone is not None:
            world.model.opt.cone = getattr(mujoco.mjtCone, f"mjCONE_{variant.cone.upper()}")

    sim_world.SimWorld.__init__ = patched_init
    if variant.grid is not None:
        FoldTowel.COUNT = variant.grid
    try:
        yield
    finally:
        sim_world.SimWorld.__init__, FoldTowel.COUNT = init, count


def run_variant(variant: Variant, seeds: list[int], protocol: str | None) -> dict:
    """Episodes of one variant: successes, the reasons of the others, the median speed (x real time)."""
    setting = DisturbanceSetting.from_options(protocol=protocol) if protocol else DisturbanceSetting.from_options()
    speeds, failed = [], []
    with towel_physics(variant):
        for seed in seeds:
            result = run_episode(EpisodeSpec(TASK, seed=seed, disturbances=setting))
            speeds.append(result.time_s / result.wall_s)
            if not result.success:
                failed.append(f"{seed}: {result.reason[:70]}")
    return {"success": len(seeds) - len(failed), "speed": statistics.median(speeds), "failed": failed}


#: A pad on a vertical slide, pressed down and lifted, with an adhesion actuator on its body; under
#: it either a thin box or a small flex cloth (with the towel's contact dimension and friction).
_PROBE_XML = """<mujoco><option timestep="0.002" cone="elliptic"/>
<worldbody><geom type="plane" size="1 1 .1"/>
<body name="pad" pos="0 0 0.03"><joint name="z" type="slide" axis="0 0 1"/>
<geom type="box" size=".02 .02 .005" mass=".1"/></body>{under}</worldbody>
<actuator><position joint="z" kp="400" kv="40"/><adhesion body="pad" ctrlrange="0 1" gain="5"/></actuator></mujoco>"""
_PROBE_BOX = '<body name="box" pos="0 0 0.006"><freejoint/><geom type="box" size=".03 .03 .005" mass=".02"/></body>'
_PROBE_CLOTH = """<flexcomp name="cloth" type="grid" count="5 5 1" spacing=".03 .03 .03" pos="0 0 0.005" radius="0.004"
dim="2" mass="0.02"><contact condim="3" friction="1.5 0.005 0.0001" selfcollide="none"/>
<edge equality="true" damping="0.01"/></flexcomp>"""


def probe_adhesion(under: str, adhesion: float = 1.0) -> float:
    """How high (m) the pad lifts what lies under it (``box`` or ``cloth``): its centre's height after the lift."""
    model = mujoco.MjModel.from_xml_string(_PROBE_XML.format(under=_PROBE_BOX if under == "box" else _PROBE_CLOTH))
    data = mujoco.MjData(model)
    data.ctrl[:] = (-0.02, adhesion)  # pressed on it
    for _ in range(400):
        mujoco.mj_step(model, data)
    data.ctrl[0] = 0.06  # lifted 8 cm
    for _ in range(400):
        mujoco.mj_step(model, data)
    if under == "box":
        return float(data.xpos[model.body("box").id][2])
    return float(data.flexvert_xpos[12][2])  # the cloth's centre vertex


def probe_sleep() -> str:
    """What stepping a resting flex cloth with sleeping enabled does: ``sleeps`` or MuJoCo's error."""
    model = mujoco.MjModel.from_xml_string(_PROBE_XML.format(under=_PROBE_CLOTH))
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_SLEEP
    data = mujoco.MjData(model)
    try:
        for _ in range(200):
            mujoco.mj_step(model, data)
    except mujoco.FatalError as error:
        return str(error)
    return "sleeps"


def print_probes() -> None:
    """Whether the installed MuJoCo offers a pinch that holds a cloth without the noslip pass."""
    table = Table(title=f"MuJoCo {mujoco.__version__}: a cloth pinch without the noslip pass")
    for column in ("probe", "found"):
        table.add_column(column)
    for under in ("box", "cloth"):
        for adhesion in (0.0, 1.0):
            found = f"{100 * probe_adhesion(under, adhesion):.1f} cm"
            table.add_row(f"pad lifted 8 cm, adhesion {'on' if adhesion else 'off'}: height of the {under}", found)
    table.add_row("a resting flex with sleeping on", probe_sleep())
    Console().print(table)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="0,1,2", help="comma-separated seeds")
    parser.add_argument("--protocols", default="none,real", help="comma-separated: none, real, stress")
    parser.add_argument("--variants", default="all", help=f"comma-separated: {', '.join(VARIANTS)}")
    parser.add_argument("--probes", action="store_true", help="only check MuJoCo's adhesion and sleeping on a flex")
    args = parser.parse_args()
    if args.probes:
        print_probes()
        return
    seeds = [int(s) for s in args.seeds.split(",")]
    names = list(VARIANTS) if args.variants == "all" else args.variants.split(",")
    unknown = [n for n in names if n not in VARIANTS]
    if unknown:
        parser.error(f"--variants: unknown {', '.join(unknown)} (known: {', '.join(VARIANTS)})")
    table = Table(title=f"fold towel, seeds {args.seeds}: the towel's physics against the fold")
    for column in ("variant", "protocol", "success", "x real time (median)", "failures"):
        table.add_column(column)
    for name in names:
        for protocol in args.protocols.split(","):
            row = run_variant(VARIANTS[name], seeds, None if protocol == "none" else protocol)
            table.add_row(name, protocol, f"{row['success']}/{len(seeds)}", f"{row['speed']:.2f}", "\n".join(row["failed"]))
    Console().print(table)


if __name__ == "__main__":
    main()
