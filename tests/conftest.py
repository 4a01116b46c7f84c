"""Shared fixtures: one small pour-water scene, built once per test that needs it."""

from __future__ import annotations

import numpy as np
import pytest

from agentchord.sim.tasks import SIM_TASKS


@pytest.fixture
def pour_scene():
    """A seeded single-arm pour-water scene."""
    return SIM_TASKS["single_arm_pour_water"].sample_scene(np.random.default_rng(7))


@pytest.fixture
def straight_carry(monkeypatch):
    """A person's pull carried in a straight line, as before carries went over what stands in the way:
    the scene some regression tests were met in (the lifted carry no longer knocks the cup there)."""
    import agentchord.sim.disturbances as disturbances

    monkeypatch.setattr(disturbances, "_carry_height", lambda *args, **kwargs: None)


@pytest.fixture
def numerics_before_lean_solves(monkeypatch):
    """The live IK's two whole QPs every tick, and the towel's 2 ms Newton step with the noslip pass
    always on: the numerics the scenes pinned by the older regression tests were recorded with (the
    lean IK and the cheaper towel move the arms and the cloth by millimetres, and a pinned scene's
    failure may not happen there)."""
    import agentchord.solvers.ik as ik
    from agentchord.sim.tasks.fold_towel import FoldTowel

    monkeypatch.setattr(ik, "LEAN_SOLVES", False)
    monkeypatch.setattr(FoldTowel, "TIMESTEP", 0.002)
    monkeypatch.setattr(FoldTowel, "SOLVER", "newton")
    monkeypatch.setattr(FoldTowel, "NOSLIP_WHILE_TOUCHING", False)
