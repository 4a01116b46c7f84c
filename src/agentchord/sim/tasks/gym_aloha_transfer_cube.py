"""gym-aloha's Transfer Cube (LeRobot's ``gym_aloha/AlohaTransferCube-v0``), judged by its own reward.

The right arm picks up a 4 cm cube and hands it to the left arm. The environment is gym-aloha's,
unmodified (:mod:`agentchord.sim.gym_aloha`): its model, its dynamics, its sampler (cube x in
[0, 0.2], y in [0.4, 0.6], from the seed) and its reward. Success is its reward reaching 4 (the
left arm's finger touches the cube and the cube is off the table) within :data:`STEP_LIMIT` steps,
LeRobot's evaluation length; the episode's own goal judgement (the graph's) is kept beside it.
"""

from __future__ import annotations

from dataclasses import dataclass

from agentchord.sim.gym_aloha import LEROBOT_EVAL_STEPS, TRANSFER_CUBE, GymAlohaWorld
from agentchord.sim.tasks.gym_aloha_judge import RewardTracker

#: Steps within which its reward must reach 4 (LeRobot evaluates 400).
STEP_LIMIT = LEROBOT_EVAL_STEPS


@dataclass
class GymAlohaTransferCube:
    """The task: its world per seed, its reward as the judge."""

    name: str = "gym_aloha_transfer_cube"
    description: str = "gym-aloha (LeRobot) Transfer Cube: the right arm hands a 4 cm cube to the left arm"
    instruction: str = "Pick up the cube with the right arm and hand it to the left arm."
    #: Our actions at twice their speed: its reward counts within 8 s (LeRobot's 400 steps).
    pace: float = 2.0

    @property
    def regions(self) -> dict:
        """No named regions."""
        return {}

    def open_world(self, seed: int) -> GymAlohaWorld:
        """gym-aloha's environment reset with ``seed`` (its own sampler)."""
        return GymAlohaWorld(TRANSFER_CUBE, seed)

    def sample_scene(self, rng):
        raise NotImplementedError(f"{self.name} runs gym-aloha's own scene: open it with open_world(seed)")

    def success_tracker(self) -> RewardTracker:
        """Its reward reaching 4 within :data:`STEP_LIMIT` steps."""
        return RewardTracker(step_limit=STEP_LIMIT, disturbed_step_limit=2 * STEP_LIMIT, what="the cube handed to the left arm, off the table")


TASK = GymAlohaTransferCube()
