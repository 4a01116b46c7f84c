"""Every task runs under every disturbance kind (slow: one episode per pair)."""

import pytest

from agentchord.execution.episode import EpisodeSpec, run_episode
from agentchord.tasks import library_tasks
from agentchord.worlds.sim.disturbances import KINDS
from agentchord.worlds.sim.tasks import SIM_TASKS

TASKS = sorted(set(SIM_TASKS) & set(library_tasks()))


@pytest.mark.slow
@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("task", TASKS)
def test_task_runs_to_a_verdict_under_each_disturbance_kind(task, kind):
    result = run_episode(EpisodeSpec(task, p=0.3, seed=1, disturb=(kind,)))
    # Success is not guaranteed under heavy disturbance; a verdict with a reason is.
    assert result.reason
    assert all(e["kind"] == kind for e in result.trace.of("disturbance"))
    assert result.trace.events[-1]["event"] == "episode_end"
