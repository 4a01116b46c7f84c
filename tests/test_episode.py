"""One seeded episode, end to end: what it writes of its own trial."""

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.harness import DisturbanceSetting


def test_the_trace_opens_with_the_seed_and_the_disturbance_setting_it_ran():
    setting = DisturbanceSetting.from_options(protocol="real")
    result = run_episode(EpisodeSpec("handover_block", seed=3, disturbances=setting))
    (start,) = result.trace.of("episode_start")
    assert start["seed"] == 3 and start["p"] == 0.0
    assert start["disturbances"] == {"p": 0.0, "kinds": ["perturb", "pull"], "protocol": "real"}
    undisturbed = run_episode(EpisodeSpec("handover_block", seed=4)).trace.of("episode_start")[0]
    assert undisturbed["seed"] == 4 and undisturbed["disturbances"] == {"p": 0.0, "kinds": ["drop"], "protocol": None}
