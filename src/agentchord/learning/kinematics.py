"""Forward kinematics of the ALOHA arms from the 14-dim joint state: the tool centres' poses.

The policy's grasp features (objects in the gripper's frame) need where the tool is; the recorded
state holds only joint angles, so the tool pose is computed from them on the robot's own model
(``agentchord.robot.model``, the model the IK solver plans on).
"""

from __future__ import annotations

import mujoco
import numpy as np

from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX, ARMS
from agentchord.robot.model import build_robot_model


class ToolKinematics:
    """Tool-centre poses of both arms for joint states (one at a time or a whole episode)."""

    def __init__(self) -> None:
        self.model = build_robot_model()
        self.data = mujoco.MjData(self.model)
        self._qadr = {arm: np.array([self.model.joint(f"{ARM_PREFIX[arm]}/{j}").qposadr[0] for j in ARM_JOINTS])
                      for arm in ARMS}
        self._site = {arm: self.model.site(f"{arm}_tcp").id for arm in ARMS}

    def tool_poses(self, states: np.ndarray) -> np.ndarray:
        """(N, 14) joint states -> (N, 2, 12): per arm the tool position and its rotation matrix (row-major)."""
        states = np.atleast_2d(np.asarray(states, dtype=np.float64))
        out = np.empty((len(states), len(ARMS), 12), dtype=np.float32)
        for n, s in enumerate(states):
            for i, arm in enumerate(ARMS):
                self.data.qpos[self._qadr[arm]] = s[7 * i: 7 * i + 6]
            mujoco.mj_kinematics(self.model, self.data)
            for i, arm in enumerate(ARMS):
                out[n, i, :3] = self.data.site_xpos[self._site[arm]]
                out[n, i, 3:] = self.data.site_xmat[self._site[arm]]
        return out
