"""The Table III experiment's stage contracts, on tiny datasets (no real training)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("lerobot")
torch = pytest.importorskip("torch")

from agentchord.data.lerobot import DatasetWriter
from agentchord.data.record import features
from agentchord.learning import table3
from agentchord.learning.policy import ChunkMLPPolicy, default_config

ENV_NAMES = [f"{o}_{c}" for o in ("bottle", "cup") for c in ("x", "y", "z", "qw", "qx", "qy", "qz")]


def _write(root: Path, episodes: list[list[tuple[str, bool]]], first_seed: int) -> None:
    """A dataset as ``record`` writes it: per episode a list of (edge, recovery) per frame."""
    writer = DatasetWriter(root, 50, features(ENV_NAMES, (), (48, 64)), exist_ok=True)
    rng = np.random.default_rng(first_seed)
    entries = []
    for i, frames in enumerate(episodes):
        for edge, recovery in frames:
            env = np.tile(np.array([0.1, 0.5, 0.09, 1, 0, 0, 0], np.float32), 2) + 0.01 * rng.standard_normal(14).astype(np.float32)
            writer.add_frame({"observation.state": rng.standard_normal(14).astype(np.float32) * 0.1,
                              "observation.environment_state": env,
                              "action": rng.standard_normal(14).astype(np.float32) * 0.1,
                              "agentchord.node": "v0", "agentchord.edge": edge, "agentchord.node_index": 0,
                              "agentchord.edge_index": 0, "agentchord.edge_kind": "recovery" if recovery else "nominal",
                              "agentchord.recovery": recovery})
        entry = {"seed": first_seed + i, "success": True, "steps": len(frames), "frames": len(frames),
                 "recoveries": int(any(r for _, r in frames)), "recovery_frames": sum(r for _, r in frames),
                 "disturbances": "shift" if any(r for _, r in frames) else ""}
        writer.save_episode("pour", extra=entry)
        entries.append(entry)
    writer.finalize()
    (root / "meta/agentchord.json").write_text(json.dumps({"episodes": entries, "next_seed": first_seed + len(episodes)}))


NOMINAL = [("e1", False)] * 6 + [("e2", False)] * 5
CUP_AFTER_GRASP = [("e1", False)] * 5 + [("e2", False)] * 3 + [("e2_r_cup_shifted", True)] * 4 + [("e3", False)] * 3
BOTTLE_KNOCKED = [("e1", False)] * 5 + [("e6", False)] * 2 + [("e6_r_bottle_knocked", True)] * 3


@pytest.fixture()
def out(tmp_path: Path) -> Path:
    dirs = table3.dataset_dirs(tmp_path)
    _write(dirs["nominal"], [NOMINAL, NOMINAL[:-2], NOMINAL + [("e3", False)] * 2, NOMINAL], 0)
    _write(dirs["recovered"], [BOTTLE_KNOCKED, CUP_AFTER_GRASP, CUP_AFTER_GRASP[:-1]], 1000)
    data = {name: table3.episode_summary(root) for name, root in dirs.items()}
    (tmp_path / "record.json").write_text(json.dumps({"datasets": data}))
    return tmp_path


def test_the_record_summary_counts_episodes_frames_and_cup_recoveries_after_the_grasp(out: Path) -> None:
    rec = json.loads((out / "record.json").read_text())["datasets"]
    assert [e["frames"] for e in rec["nominal"]["episodes"]] == [11, 9, 13, 11]
    assert rec["recovered"]["frames"] == 10 + 15 + 14 and rec["recovered"]["recovery_frames"] == 3 + 4 + 4
    # The knocked-bottle recovery is not the paper's scenario: only the cup-shifted ones count.
    assert rec["recovered"]["cup_recovery_episodes"] == [1, 2]
    assert [e["seed"] for e in rec["recovered"]["episodes"]] == [1000, 1001, 1002]


def test_a_set_reads_exactly_the_episodes_the_record_stage_wrote(out: Path) -> None:
    episodes, info = table3.training_set(out, "A", 4)
    assert [len(e["action"]) for e in episodes] == [11, 9, 13, 11] and info["recovery_frames"] == 0
    episodes, info = table3.training_set(out, "B50", 4)
    assert info["parts"]["nominal"]["episodes"] == [0, 1] and info["parts"]["recovered"]["episodes"] == [1, 2]
    assert info["parts"]["recovered"]["seeds"] == [1001, 1002]
    assert info["frames"] == 11 + 9 + 15 + 14 == sum(len(e["action"]) for e in episodes)
    assert info["recovery_frames"] == 8 == sum(int(e["agentchord.recovery"].sum()) for e in episodes)
    with pytest.raises(ValueError, match="needs 3 cup-recovery episodes"):
        table3.training_set(out, "B75", 4)


def test_a_dataset_changed_after_the_record_stage_is_refused(out: Path) -> None:
    path = out / "record.json"
    rec = json.loads(path.read_text())
    rec["datasets"]["recovered"]["episodes"][1]["recovery_frames"] = 3
    path.write_text(json.dumps(rec))
    with pytest.raises(ValueError, match="record again"):
        table3.training_set(out, "B50", 4)


def test_training_saves_a_lerobot_policy_that_loads_and_acts(out: Path) -> None:
    cfg = table3.TrainConfig(steps=3, batch_size=8, hidden=32, chunk_size=4)
    summary = table3.stage_train(out, "B50", cfg, 4, log=lambda *_: None)
    assert summary["parts"]["recovered"]["recovery_frames"] == 8 and summary["steps"] == 3
    assert (out / "policy_B50/config.json").exists() and not (out / "policy_B50/checkpoint.pt").exists()
    policy = ChunkMLPPolicy.from_pretrained(out / "policy_B50")
    obs = {"observation.state": torch.zeros(1, 14),
           "observation.environment_state": torch.tensor([[0.1, 0.5, 0.09, 1, 0, 0, 0] * 2])}
    assert policy.select_action(obs).shape == (1, 14)
    assert json.loads((out / "stages.json").read_text())["train_B50"]["peak_rss_mb"] > 0


def test_temporal_ensembling_of_constant_chunks_is_that_constant_and_a_reset_forgets() -> None:
    policy = ChunkMLPPolicy(default_config(chunk_size=5, hidden=8, temporal_ensemble_coeff=0.1))
    target = torch.arange(14, dtype=torch.float32)
    policy.predict_action_chunk = lambda batch: target.expand(1, 5, 14).clone()
    obs = {"observation.state": torch.zeros(1, 14),
           "observation.environment_state": torch.tensor([[0, 0, 0, 1, 0, 0, 0] * 2], dtype=torch.float32)}
    for _ in range(8):
        assert torch.allclose(policy.select_action(obs)[0], target)
    policy.reset()
    assert policy._avg is None and policy._max_tilt is None


class _Replay:
    """A stand-in policy that replays AgentChord's own commands of the same seed."""

    def __init__(self, actions: list[np.ndarray]) -> None:
        self.actions = actions
        self.t = 0

    def parameters(self):
        return iter([torch.zeros(1)])

    def reset(self) -> None:
        self.t = 0

    def select_action(self, batch):
        action = self.actions[min(self.t, len(self.actions) - 1)]
        self.t += 1
        return torch.from_numpy(np.asarray(action))[None]


def _spied_env(max_steps: int):
    """The pour environment, with the ``is_success`` of every step it returned kept in ``env.seen``."""
    import gymnasium

    import agentchord.gym  # noqa: F401

    env = gymnasium.make(table3.ENV_ID, max_steps=max_steps)
    env.seen = []
    step = env.step

    def spy(action):
        result = step(action)
        env.seen.append(result[-1]["is_success"])
        return result

    env.step = spy
    return env


def test_a_failed_trial_is_the_environment_s_own_failure() -> None:
    env = _spied_env(30)
    home = np.asarray(env.unwrapped.reset(seed=0)[0]["agent_pos"])
    idle = table3.run_trial(env, _Replay([home]), 0)
    assert idle["success"] is False and env.seen == [False] * 30 and idle["ticks"] == 30 and idle["grasps"] == 0
    env.close()


def test_a_trial_s_success_is_the_environment_s_own_is_success() -> None:
    from agentchord.episode import EpisodeSpec, run_episode
    from agentchord.gym.aloha import joint_action

    actions = []
    assert run_episode(EpisodeSpec(task=table3.TASK, seed=0),
                       on_tick=lambda ex: actions.append(joint_action(ex.world.commands))).success
    env = _spied_env(len(actions) + 50)
    good = table3.run_trial(env, _Replay(actions), 0)
    assert good["success"] is True and env.seen[-1] is True and not any(env.seen[:-1])
    assert good["ticks"] == len(env.seen) and good["grasps"] >= 1 and good["poured"] and not good["cup_moved"]
    env.close()


@pytest.mark.slow
def test_the_record_stage_writes_what_the_train_stage_reads(tmp_path: Path) -> None:
    """Recorded for real: one nominal episode, one that recovers from the cup moved after the grasp."""
    data = table3.stage_record(tmp_path, 1, 1, log=lambda *_: None)
    assert len(data["nominal"]["episodes"]) == 1 and len(data["recovered"]["cup_recovery_episodes"]) >= 1
    episodes, info = table3.training_set(tmp_path, "B50", 2)
    rec = data["recovered"]["episodes"][data["recovered"]["cup_recovery_episodes"][0]]
    assert info["parts"]["recovered"]["frames"] == rec["frames"] == len(episodes[1]["action"])
    assert info["recovery_frames"] == rec["recovery_frames"] == int(episodes[1]["agentchord.recovery"].sum()) > 0
    assert info["parts"]["nominal"]["frames"] == data["nominal"]["episodes"][0]["frames"]
