"""The success check of a gym-aloha task: its own reward, as its world records it every step."""

from __future__ import annotations

from dataclasses import dataclass

from agentchord.features.frame import FeatureFrame
from agentchord.harness import Verdict
from agentchord.sim.gym_aloha import SUCCESS_REWARD


@dataclass
class RewardTracker:
    """Success = gym-aloha's reward reached :data:`~agentchord.sim.gym_aloha.SUCCESS_REWARD` within ``step_limit`` steps.

    The reward is the environment's own (``task.get_reward(physics)`` after each step), read from
    :class:`~agentchord.sim.gym_aloha.GymAlohaWorld`, which keeps the first step it was 4 at.

    Attributes:
        step_limit: Steps within which it must (LeRobot evaluates 400).
        what: What reward 4 means, in words.
        disturbed_step_limit: The limit of an episode a disturbance acted on: a person's pull alone
            holds the object up to 3.3 s (165 steps) before it is back on the table.
    """

    step_limit: int
    what: str
    disturbed_step_limit: int = 0

    def limit(self, world) -> int:
        """The step limit of this episode: longer where a disturbance acted."""
        return max(self.step_limit, self.disturbed_step_limit) if getattr(world, "disturbed", False) else self.step_limit

    def observe(self, frame: FeatureFrame) -> None:
        """Nothing to read in the features: the reward is the world's."""

    def terminated(self, world) -> Verdict | None:
        """The episode's end as its environment ends it: on the step its reward reaches 4 (``terminated``
        in its ``env.step``; LeRobot's evaluation stops there). None while it has not."""
        first = getattr(world, "first_success_tick", None)
        return None if first is None else self.verdict(None, world)  # type: ignore[arg-type]

    def verdict(self, frame: FeatureFrame, world) -> Verdict:
        """Its verdict: reward 4 at a step within the limit."""
        first = getattr(world, "first_success_tick", None)
        best = getattr(world, "best_reward", 0)
        if first is None:
            return Verdict(False, f"gym-aloha's reward never reached {SUCCESS_REWARD} (best {best}): not {self.what}")
        limit = self.limit(world)
        if first > limit:
            return Verdict(False, f"gym-aloha's reward reached {SUCCESS_REWARD} at step {first}, after its limit of {limit}")
        return Verdict(True, f"gym-aloha's reward {SUCCESS_REWARD} at step {first} (limit {limit}): {self.what}")
