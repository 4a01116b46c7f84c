"""AgentChord as the expert of its Gymnasium environments (``agentchord.gym.expert``)."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

import agentchord.gym
from agentchord.gym.expert import AgentChordExpert, ExpertError


def _roll_out(env, expert, seed: int) -> tuple[dict, int]:
    env.reset(seed=seed)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(expert.act())
        steps += 1
        if terminated or truncated:
            return info, steps


def test_the_expert_completes_the_task_in_the_environment():
    env = gymnasium.make("agentchord/SingleArmPourWater-v0", max_steps=2000)
    expert = agentchord.gym.AgentChordExpert(env)
    info, steps = _roll_out(env, expert, seed=0)
    assert info["is_success"] and steps < 2000
    expert.close()


def test_the_expert_recovers_from_what_the_environment_injects():
    """Closed loop: the environment's own protocol pulls the bottle out of the hand; the expert sees it."""
    env = gymnasium.make("agentchord/SingleArmPourWater-v0", disturb="real", max_steps=3000)
    expert = AgentChordExpert(env)
    info, _ = _roll_out(env, expert, seed=3)
    assert [d["kind"] for d in info["disturbances"]] == ["pull"]
    assert info["is_success"]
    expert.close()


def test_asking_twice_before_a_step_gives_the_same_action_and_a_new_trial_restarts_the_expert():
    env = gymnasium.make("agentchord/SingleArmPourWater-v0")
    expert = AgentChordExpert(env)
    env.reset(seed=1)
    first = expert.act()
    assert first.shape == (14,) and np.array_equal(first, expert.act())
    for _ in range(30):
        env.step(expert.act())
    thread = expert._thread
    env.reset(seed=2)
    expert.act()
    assert thread is not None and not thread.is_alive() and expert._thread is not thread
    expert.close()
    assert expert._thread is None


def test_an_expert_that_cannot_plan_says_why():
    env = gymnasium.make("agentchord/BlocksAndCup-v0")
    env.reset(seed=0)
    with pytest.raises(ExpertError, match="library graph"):
        AgentChordExpert(env).act()
    expert = AgentChordExpert(env, instruction="put the red block into the cup")
    env.reset(seed=0)
    for _ in range(1500):  # an open scene: the environment has no goal to judge, the expert's episode does
        env.step(expert.act())
        if expert.result is not None:
            break
    assert expert.result is not None and expert.result.success, expert.result
    expert.close()


def test_the_expert_wants_an_agentchord_environment():
    with pytest.raises(TypeError, match="agentchord/<Task>-v0"):
        AgentChordExpert(gymnasium.make("CartPole-v1"))
