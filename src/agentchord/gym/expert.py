"""AgentChord as the expert of a Gymnasium environment: the action it would command this tick.

A user collecting demonstrations in ``agentchord/<Task>-v0`` steps the environment with their own
loop; the expert answers each step with the 14-dim joint-position action AgentChord's executor
commands there, closed loop: it plans on the trial ``reset`` opened, watches the same world the
environment steps (so a disturbance the environment injects is seen and recovered from, as in
``agentchord run``), and switches to its pre-compiled recoveries as it would on its own.

    env = gymnasium.make("agentchord/SingleArmPourWater-v0", disturb="real")
    expert = AgentChordExpert(env)
    obs, info = env.reset(seed=3)
    while True:
        obs, reward, terminated, truncated, info = env.step(expert.act())
        if terminated or truncated:
            break
    expert.close()

It is a privileged expert, as gym-aloha's scripted ones are: it reads the simulator's state
(oracle perception), not ``obs``. The executor runs in a thread of its own over a world whose
``step`` hands the commands to :meth:`AgentChordExpert.act` and waits for the environment's
``step``: the two never touch the world at once.
"""

from __future__ import annotations

import queue
import threading
from typing import Any

import numpy as np

from agentchord.episode import EpisodeSpec, run_episode_on
from agentchord.execution.result import EpisodeResult
from agentchord.gym.aloha import joint_action
from agentchord.robot.aloha import ARMS
from agentchord.worlds.protocol import ArmCommand

#: Seconds :meth:`AgentChordExpert.act` waits for the executor's next command (planning included).
ANSWER_TIMEOUT_S = 60.0


class ExpertError(RuntimeError):
    """The expert cannot answer: its executor failed, or the environment was stepped past it."""


class _Stopped(BaseException):
    """Raised in the executor's thread when the expert is closed or reset: ends the episode there."""


class LockstepWorld:
    """A world the executor drives while another loop steps it.

    Every call but ``command`` and ``step`` goes to the wrapped world. ``command`` keeps the arm's
    command for the expert; ``step`` hands the tick's commands over and returns once the
    environment has stepped the real world (its tick advanced).
    """

    def __init__(self, world: Any) -> None:
        self._world = world
        self.pending: dict[str, ArmCommand] = {}
        self.answers: queue.Queue[dict[str, ArmCommand] | None] = queue.Queue(maxsize=1)
        self.stepped = threading.Semaphore(0)
        self.stopped = False

    def __getattr__(self, name: str) -> Any:
        return getattr(self._world, name)

    def command(self, arm: str, command: ArmCommand) -> None:
        """Keep ``command`` for this tick's answer (the environment applies it)."""
        self.pending[arm] = command

    def step(self) -> None:
        """Hand the tick's commands to the expert; wait for the environment's step."""
        if self.stopped:
            raise _Stopped
        held = {arm: self.pending.get(arm) or ArmCommand(q=np.asarray(self._world.arm_q(arm), float), grip=0.0)
                for arm in ARMS}
        self.answers.put(held)
        self.stepped.acquire()
        if self.stopped:
            raise _Stopped


class AgentChordExpert:
    """The action AgentChord commands at each step of an ``agentchord/<Task>-v0`` environment.

    Args:
        env: The environment (wrappers are looked through to the :class:`AgentChordEnv`).
        strategy: The executing method (``agentchord``, or a baseline's name: its recovery behaviour).
        instruction: Plan from this instruction with the offline agents instead of the library graph.
        goal: Plan for this goal spec (a :class:`GoalSpec`) instead of the library graph.

    Attributes:
        result: The executor's episode once it has ended (success, reason, path, recoveries), else None.
            In an open scene (``blocks_and_cup``) the environment has no goal of its own to judge:
            ``result.success`` says whether the planned goal holds.
    """

    def __init__(self, env: Any, strategy: str = "agentchord", instruction: str | None = None, goal: Any = None) -> None:
        self.env = env.unwrapped
        if not hasattr(self.env, "world") or not hasattr(self.env, "task"):
            raise TypeError(f"AgentChordExpert needs an agentchord/<Task>-v0 environment, got {type(self.env).__name__}")
        self.strategy = strategy
        self.instruction = instruction
        self.goal = goal
        self.result: EpisodeResult | None = None
        self._error: BaseException | None = None
        self._world: LockstepWorld | None = None
        self._thread: threading.Thread | None = None
        self._answered_at: int | None = None
        self._last: dict[str, ArmCommand] | None = None

    # ------------------------------------------------------------------ public
    def reset(self) -> None:
        """Start on the trial the environment's ``reset`` opened (``act`` does it when it sees a new trial)."""
        self._stop()
        world = self.env.world
        if world.tick != 0:
            raise ExpertError(f"the expert starts on a fresh trial: the environment is at tick {world.tick}; "
                              "call env.reset() first")
        spec = EpisodeSpec(self.env.task, strategy=self.strategy, seed=self.env.world_seed, instruction=self.instruction,
                           goal=self.goal)
        self._world = lockstep = LockstepWorld(world)
        self.result, self._error, self._answered_at, self._last = None, None, None, None

        def episode() -> None:
            try:
                self.result = run_episode_on(lockstep, spec)
            except _Stopped:
                return
            except BaseException as error:  # handed to the caller's thread by act()
                self._error = error
            finally:
                if lockstep.answers.empty():
                    lockstep.answers.put(None)  # act() stops waiting: the episode has ended

        self._thread = threading.Thread(target=episode, name="agentchord-expert", daemon=True)
        self._thread.start()

    def act(self, observation: Any = None) -> np.ndarray:
        """The 14-dim action for the environment's next ``step`` (``observation`` is not read: the
        expert watches the world itself). After its episode has ended it holds the last pose.

        Raises:
            ExpertError: The executor raised, or took longer than ``ANSWER_TIMEOUT_S`` to answer.
        """
        world = self.env.world
        if self._world is None or self._world._world is not world:
            self.reset()
        lockstep = self._world
        assert lockstep is not None
        if self._answered_at is not None:
            if world.tick == self._answered_at:
                return self._action()  # asked twice before a step: the same answer
            lockstep.stepped.release()  # the environment stepped: the executor's tick goes on
        if self.result is not None or self._error is not None:
            return self._finished(world)
        try:
            answer = lockstep.answers.get(timeout=ANSWER_TIMEOUT_S)
        except queue.Empty:
            raise ExpertError(f"the expert did not answer within {ANSWER_TIMEOUT_S:.0f} s at tick {world.tick}") from None
        if answer is None:
            return self._finished(world)
        self._answered_at, self._last = world.tick, answer
        return self._action()

    __call__ = act

    def close(self) -> None:
        """End the executor's thread (the environment stays open)."""
        self._stop()

    # ------------------------------------------------------------------ inside
    def _action(self) -> np.ndarray:
        assert self._last is not None
        return joint_action(self._last)

    def _finished(self, world: Any) -> np.ndarray:
        if self._error is not None:
            raise ExpertError(f"the expert's executor failed: {type(self._error).__name__}: {self._error}") from self._error
        self._answered_at = None
        if self._last is None:
            self._last = {arm: ArmCommand(q=np.asarray(world.arm_q(arm), float), grip=world.commands[arm].grip) for arm in ARMS}
        return self._action()

    def _stop(self) -> None:
        lockstep, thread = self._world, self._thread
        self._world = self._thread = None
        if lockstep is None or thread is None:
            return
        lockstep.stopped = True
        lockstep.stepped.release()
        thread.join(timeout=5.0)
