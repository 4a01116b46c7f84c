"""gym-aloha's Insertion (LeRobot's ``gym_aloha/AlohaInsertion-v0``), judged by its own reward.

One arm takes a 12 cm peg, the other a socket (four plates around a 3.6 cm bore, a pin inside), and
the peg goes into the socket in mid-air. The environment is gym-aloha's, unmodified
(:mod:`agentchord.sim.gym_aloha`): its sampler (peg x in [0.1, 0.2], socket x in [-0.2, -0.1],
both y in [0.4, 0.6], from the seed) and its reward, 4 when the peg touches the pin. Success is
that within :data:`STEP_LIMIT` steps (its rate within LeRobot's 400 is reported beside it).
"""

from __future__ import annotations

from agentchord.sim.gym_aloha import INSERTION
from agentchord.sim.tasks.gym_aloha_common import GymAlohaSimTask

#: Steps within which its reward must reach 4: twice LeRobot's 8 s evaluation (the rate within 400 is reported too).
STEP_LIMIT = 800

TASK = GymAlohaSimTask(
    name="gym_aloha_insertion",
    description="gym-aloha (LeRobot) Insertion: the peg into the socket, in mid-air",
    instruction="Insert the peg into the socket.",
    world=INSERTION,
    step_limit=STEP_LIMIT,
    what="the peg inserted, touching the pin",
)
