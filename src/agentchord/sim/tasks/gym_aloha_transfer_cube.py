"""gym-aloha's Transfer Cube (LeRobot's ``gym_aloha/AlohaTransferCube-v0``), judged by its own reward.

The right arm picks up a 4 cm cube and hands it to the left arm. The environment is gym-aloha's,
unmodified (:mod:`agentchord.sim.gym_aloha`): its model, its dynamics, its sampler (cube x in
[0, 0.2], y in [0.4, 0.6], from the seed) and its reward. Success is its reward reaching 4 (the
left arm's finger touches the cube and the cube is off the table) within :data:`STEP_LIMIT` steps,
LeRobot's evaluation length; the episode's own goal judgement (the graph's) is kept beside it.
"""

from __future__ import annotations

from agentchord.sim.gym_aloha import LEROBOT_EVAL_STEPS, TRANSFER_CUBE
from agentchord.sim.tasks.gym_aloha_common import GymAlohaSimTask

#: Steps within which its reward must reach 4 (LeRobot evaluates 400).
STEP_LIMIT = LEROBOT_EVAL_STEPS

TASK = GymAlohaSimTask(
    name="gym_aloha_transfer_cube",
    description="gym-aloha (LeRobot) Transfer Cube: the right arm hands a 4 cm cube to the left arm",
    instruction="Pick up the cube with the right arm and hand it to the left arm.",
    world=TRANSFER_CUBE,
    step_limit=STEP_LIMIT,
    what="the cube handed to the left arm, off the table",
)
