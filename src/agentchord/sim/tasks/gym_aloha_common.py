"""What gym-aloha's tasks share: their world per seed, and their judge, its own reward as its world records it."""

from __future__ import annotations

from dataclasses import dataclass

from agentchord.features.frame import FeatureFrame
from agentchord.harness import Verdict
from agentchord.sim.gym_aloha import SUCCESS_REWARD, GymAlohaTask, GymAlohaWorld


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


@dataclass
class GymAlohaSimTask:
    """One of gym-aloha's tasks as a task of ours: its own world per seed, its reward as the judge.

    Attributes:
        name: Our name of the task.
        description: One line.
        instruction: Its instruction in words.
        world: Which of its tasks (``sim.gym_aloha``).
        step_limit: Steps within which its reward must reach 4, undisturbed (twice as many disturbed).
        what: What reward 4 means, in words.
        pace: Our actions' speed on it (its reward counts within LeRobot's 8 s).
    """

    name: str
    description: str
    instruction: str
    world: GymAlohaTask
    step_limit: int
    what: str
    pace: float = 2.0

    @property
    def regions(self) -> dict:
        """No named regions."""
        return {}

    def open_world(self, seed: int) -> GymAlohaWorld:
        """Its environment reset with ``seed`` (its own sampler)."""
        return GymAlohaWorld(self.world, seed)

    def sample_scene(self, rng):
        """Not a scene of ours: its world is gym-aloha's (:meth:`open_world`)."""
        raise NotImplementedError(f"{self.name} runs gym-aloha's own scene: open it with open_world(seed)")

    def success_tracker(self) -> RewardTracker:
        """Its reward reaching 4 within :attr:`step_limit` steps (twice that where a disturbance acted)."""
        return RewardTracker(step_limit=self.step_limit, disturbed_step_limit=2 * self.step_limit, what=self.what)
