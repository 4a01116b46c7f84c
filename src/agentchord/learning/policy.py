"""A small CPU policy for low-dimensional ALOHA state: an MLP that predicts a chunk of joint targets.

A lerobot 0.4.x policy (``PreTrainedPolicy``, registered as ``agentchord_chunk_mlp``): it saves
and loads with ``save_pretrained`` / ``from_pretrained``, and its normalisation statistics are
buffers of the model, so no pre/post-processor is needed to run it.

Inputs, from the environment's observation (``observation.state``, the 14 joint positions and
grippers, and ``observation.environment_state``, each object's position and quaternion):

- the joint state; each object's position and its axis (the quaternion's z column);
- the first object's position relative to the second (bottle minus cup, for pour water);
- the first object's tilt and the **largest tilt it has had so far in the episode**. The pour
  needs that memory: the bottle held upright beside the cup is the same state before the pour and
  after it, and a memoryless policy cannot tell whether to tilt it or to put it down.

Output: the next ``chunk_size`` actions. Arm joints are predicted relative to the current joint
positions (the target minus the measured position), grippers as they are; at run time the
overlapping chunks are blended with ACT's temporal ensembling (weights ``exp(-m * i)``, oldest
first) or executed ``n_action_steps`` at a time.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch
from lerobot.configs.policies import PreTrainedConfig
from lerobot.configs.types import FeatureType, NormalizationMode, PolicyFeature
from lerobot.optim.optimizers import AdamWConfig
from lerobot.policies.pretrained import PreTrainedPolicy
from torch import Tensor, nn

STATE, ENV_STATE, ACTION = "observation.state", "observation.environment_state", "action"
#: The policy's memory of the episode in a training batch: the first object's largest tilt so far (deg).
MAX_TILT = "observation.max_tilt"
#: The arms' tool poses from the joint state (forward kinematics), (B, 24): per arm position and rotation.
TOOL = "observation.tool_pose"
#: Entries of the 14-dim ALOHA state and action that are grippers (the rest are arm joints).
GRIPPERS = (6, 13)


def quat_axis(quat: Tensor) -> Tensor:
    """The body's z axis in the world of (..., 4) quaternions (w, x, y, z)."""
    w, x, y, z = quat.unbind(-1)
    return torch.stack([2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y)], -1)


def tilt_deg(env_state: Tensor) -> Tensor:
    """The first object's tilt from upright (deg), (...,) of (..., 7 n) environment states."""
    axis = quat_axis(env_state[..., 3:7])
    return torch.rad2deg(torch.arccos(axis[..., 2].clamp(-1.0, 1.0)))


def running_max_tilt(env_states: np.ndarray) -> np.ndarray:
    """Per frame of one episode, the first object's largest tilt up to it (deg): the training input
    that the policy keeps itself at run time."""
    tilt = tilt_deg(torch.from_numpy(np.asarray(env_states, np.float32))).numpy()
    return np.maximum.accumulate(tilt).astype(np.float32)


def features(state: Tensor, env_state: Tensor, max_tilt: Tensor, tool: Tensor) -> Tensor:
    """The policy's raw input features (before normalisation), (B, F)."""
    n_obj = env_state.shape[-1] // 7
    parts = [state, tool]
    tool = tool.reshape(len(tool), -1, 12)
    for k in range(n_obj):
        pos = env_state[:, 7 * k: 7 * k + 3]
        parts += [pos, quat_axis(env_state[:, 7 * k + 3: 7 * k + 7])]
        for arm in range(tool.shape[1]):
            rel = pos - tool[:, arm, :3]
            rot = tool[:, arm, 3:].reshape(-1, 3, 3)
            parts += [rel, torch.einsum("bji,bj->bi", rot, rel)]  # in the world and in the tool's frame
    if n_obj >= 2:
        parts.append(env_state[:, 0:3] - env_state[:, 7:10])
    parts.append(tilt_deg(env_state)[:, None] / 90.0)
    parts.append(max_tilt.reshape(-1, 1) / 90.0)
    return torch.cat(parts, -1)


@PreTrainedConfig.register_subclass("agentchord_chunk_mlp")
@dataclass
class ChunkMLPConfig(PreTrainedConfig):
    """The MLP chunk policy's configuration (saved as ``config.json``)."""

    chunk_size: int = 20
    n_action_steps: int = 1
    temporal_ensemble_coeff: float | None = 0.05
    hidden: int = 512
    layers: int = 3
    dropout: float = 0.0
    # Training-time input noise (joint positions rad, object positions m): the labels stay the
    # demonstration's absolute targets, so the policy learns to steer back onto them. The joint
    # noise is drawn once per frame copy when the training arrays are made (the tool poses are
    # computed for the noisy joints there); the object noise afresh in every batch.
    state_noise: float = 0.01
    object_noise: float = 0.003
    n_features: int = 0  # set from the training data
    normalization_mapping: dict[str, NormalizationMode] = field(default_factory=lambda: {
        "STATE": NormalizationMode.MEAN_STD, "ENV": NormalizationMode.MEAN_STD, "ACTION": NormalizationMode.MEAN_STD})
    optimizer_lr: float = 1e-3
    optimizer_weight_decay: float = 1e-4

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.n_action_steps > self.chunk_size:
            raise ValueError("n_action_steps must be at most chunk_size")

    @property
    def observation_delta_indices(self) -> None:
        return None

    @property
    def action_delta_indices(self) -> list[int]:
        return list(range(self.chunk_size))

    @property
    def reward_delta_indices(self) -> None:
        return None

    def get_optimizer_preset(self) -> AdamWConfig:
        return AdamWConfig(lr=self.optimizer_lr, weight_decay=self.optimizer_weight_decay)

    def get_scheduler_preset(self) -> None:
        return None

    def validate_features(self) -> None:
        if STATE not in self.input_features or ENV_STATE not in self.input_features:
            raise ValueError(f"the chunk MLP needs {STATE} and {ENV_STATE} inputs")


def default_config(state_dim: int = 14, env_dim: int = 14, action_dim: int = 14, **kwargs) -> ChunkMLPConfig:
    """A configuration for ALOHA state, object poses and joint actions."""
    return ChunkMLPConfig(
        input_features={STATE: PolicyFeature(FeatureType.STATE, (state_dim,)),
                        ENV_STATE: PolicyFeature(FeatureType.ENV, (env_dim,))},
        output_features={ACTION: PolicyFeature(FeatureType.ACTION, (action_dim,))},
        device=kwargs.pop("device", "cpu"), push_to_hub=False, **kwargs)


class ChunkMLPPolicy(PreTrainedPolicy):
    """An MLP from state features to a chunk of actions (see the module's docstring)."""

    config_class = ChunkMLPConfig
    name = "agentchord_chunk_mlp"

    def __init__(self, config: ChunkMLPConfig, **kwargs) -> None:
        super().__init__(config)
        self.action_dim = config.output_features[ACTION].shape[0]
        n_in = config.n_features or self._n_features()
        config.n_features = n_in
        out = config.chunk_size * self.action_dim
        layers, width = [], n_in
        for _ in range(config.layers):
            layers += [nn.Linear(width, config.hidden), nn.GELU()]
            if config.dropout:
                layers.append(nn.Dropout(config.dropout))
            width = config.hidden
        layers.append(nn.Linear(width, out))
        self.net = nn.Sequential(*layers)
        self.register_buffer("in_mean", torch.zeros(n_in))
        self.register_buffer("in_std", torch.ones(n_in))
        self.register_buffer("out_mean", torch.zeros(config.chunk_size, self.action_dim))
        self.register_buffer("out_std", torch.ones(config.chunk_size, self.action_dim))
        mask = torch.ones(self.action_dim, dtype=torch.bool)
        mask[[g for g in GRIPPERS if g < self.action_dim]] = False
        self.register_buffer("relative", mask)  # arm joints relative to the measured state
        self.reset()

    def _n_features(self) -> int:
        s = self.config.input_features[STATE].shape[0]
        e = self.config.input_features[ENV_STATE].shape[0]
        return features(torch.zeros(1, s), torch.zeros(1, e) + torch.tensor([0, 0, 0, 1, 0, 0, 0] * (e // 7)),
                        torch.zeros(1), torch.zeros(1, 24)).shape[-1]

    def tool_pose(self, state: Tensor) -> Tensor:
        """(B, 24) tool poses of (B, 14) joint states (forward kinematics on the robot's model)."""
        if getattr(self, "_kinematics", None) is None:
            from agentchord.learning.kinematics import ToolKinematics

            self._kinematics = ToolKinematics()
        poses = self._kinematics.tool_poses(state.detach().cpu().numpy())
        return torch.from_numpy(poses.reshape(len(poses), -1)).to(state.device)

    # ------------------------------------------------------------------ normalisation
    def targets(self, state: Tensor, chunk: Tensor) -> Tensor:
        """(B, K, A) absolute actions -> the predicted representation (arm joints minus the state)."""
        return torch.where(self.relative, chunk - state[:, None, :], chunk)

    def absolute(self, state: Tensor, pred: Tensor) -> Tensor:
        return torch.where(self.relative, pred + state[:, None, :], pred)

    @torch.no_grad()
    def fit_normalization(self, state: Tensor, env_state: Tensor, max_tilt: Tensor, tool: Tensor, chunk: Tensor,
                          floor: float = 1e-2) -> None:
        """Set the input and output statistics from a sample of training frames."""
        x = features(state, env_state, max_tilt, tool)
        self.in_mean.copy_(x.mean(0))
        self.in_std.copy_(x.std(0).clamp_min(floor))
        y = self.targets(state, chunk)
        self.out_mean.copy_(y.mean(0))
        self.out_std.copy_(y.std(0).clamp_min(floor * 0.1))

    # ------------------------------------------------------------------ model
    def predict_action_chunk(self, batch: dict[str, Tensor], **kwargs) -> Tensor:
        """(B, K, A) absolute actions for a batch of observations (``MAX_TILT`` in it, or the current tilt)."""
        state, env = batch[STATE].float(), batch[ENV_STATE].float()
        max_tilt = batch.get(MAX_TILT)
        if max_tilt is None:
            max_tilt = tilt_deg(env)
        tool = batch.get(TOOL)
        if tool is None:
            tool = self.tool_pose(state)
        x = (features(state, env, max_tilt.float(), tool.float()) - self.in_mean) / self.in_std
        y = self.net(x).view(-1, self.config.chunk_size, self.action_dim) * self.out_std + self.out_mean
        return self.absolute(state, y)

    def forward(self, batch: dict[str, Tensor]) -> tuple[Tensor, dict]:
        """L1 loss on the normalised chunk; input noise in training mode."""
        state, env, max_tilt, chunk = (batch[k].float() for k in (STATE, ENV_STATE, MAX_TILT, ACTION))
        tool = batch.get(TOOL)
        if tool is None:
            tool = self.tool_pose(state)
        if self.training:
            noise = torch.zeros_like(env)
            for k in range(env.shape[-1] // 7):
                noise[:, 7 * k: 7 * k + 3] = self.config.object_noise * torch.randn_like(env[:, :3])
            env = env + noise
        x = (features(state, env, max_tilt, tool) - self.in_mean) / self.in_std
        pred = self.net(x).view(-1, self.config.chunk_size, self.action_dim)
        target = (self.targets(state, chunk) - self.out_mean) / self.out_std
        loss = (pred - target).abs().mean()
        return loss, {"l1_loss": float(loss.detach())}

    def get_optim_params(self) -> dict:
        return self.parameters()

    # ------------------------------------------------------------------ acting
    def reset(self) -> None:
        """Forget the episode: the tilt memory and the chunks in flight."""
        self._max_tilt: Tensor | None = None
        self._queue: list[Tensor] = []
        self._avg: Tensor | None = None  # (K-1, A): per future tick, the weighted mean of its predictions
        self._count: Tensor | None = None  # (K-1,): how many predictions each holds

    @torch.no_grad()
    def select_action(self, batch: dict[str, Tensor], **kwargs) -> Tensor:
        """The action (1, A) for this tick's observation (one environment, batch of one)."""
        env = batch[ENV_STATE].float()
        tilt = tilt_deg(env)
        self._max_tilt = tilt if self._max_tilt is None else torch.maximum(self._max_tilt, tilt)
        obs = {STATE: batch[STATE], ENV_STATE: env, MAX_TILT: self._max_tilt}
        coeff = self.config.temporal_ensemble_coeff
        if coeff is None:
            if not self._queue:
                self._queue = list(self.predict_action_chunk(obs)[0][: self.config.n_action_steps])
            return self._queue.pop(0)[None]
        chunk = self.predict_action_chunk(obs)[0]  # (K, A)
        if self._avg is None:
            avg, count = chunk, torch.ones(len(chunk), dtype=torch.long, device=chunk.device)
        else:
            # ACT's temporal ensembling: the i-th prediction of a tick weighs exp(-m * i), the oldest i = 0.
            w = torch.exp(-coeff * torch.arange(len(chunk), dtype=torch.float32, device=chunk.device))
            cum = torch.cumsum(w, 0)
            c = self._count
            mean = (self._avg * cum[c - 1, None] + chunk[:-1] * w[c, None]) / cum[c, None]
            avg = torch.cat([mean, chunk[-1:]])
            count = torch.cat([c + 1, torch.ones(1, dtype=torch.long, device=chunk.device)])
        self._avg, self._count = avg[1:], count[1:]
        return avg[:1]
