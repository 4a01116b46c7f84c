"""Tool poses: quaternion conventions and the side-grasp frame.

Quaternions are (w, x, y, z), as MuJoCo and mink write them; scipy's ``Rotation``
takes (x, y, z, w).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from agentchord.solvers.ik import PoseTarget

UP = np.array([0.0, 0.0, 1.0])


def quat_to_rotation(quat: np.ndarray) -> Rotation:
    """A (w, x, y, z) quaternion as a scipy rotation."""
    w, x, y, z = quat
    return Rotation.from_quat([x, y, z, w])


def rotation_to_quat(rotation: Rotation) -> np.ndarray:
    """A scipy rotation as a (w, x, y, z) quaternion."""
    x, y, z, w = rotation.as_quat()
    return np.array([w, x, y, z])


def pose_from_matrix(pos: np.ndarray, matrix: np.ndarray) -> PoseTarget:
    """Pose target from a position and a rotation matrix."""
    return PoseTarget(pos=np.asarray(pos, dtype=float), quat=rotation_to_quat(Rotation.from_matrix(matrix)))


def grasp_frame(approach: np.ndarray) -> np.ndarray:
    """Tool rotation for a side grasp: x along the horizontal approach, z up."""
    x = np.array([approach[0], approach[1], 0.0])
    norm = np.linalg.norm(x)
    if norm < 1e-6:
        raise ValueError("a side grasp needs a horizontal approach direction, got a vertical one")
    x /= norm
    y = np.cross(UP, x)
    return np.column_stack([x, y, UP])


def top_down_rotation(long_dir: np.ndarray) -> np.ndarray:
    """Tool rotation for a top grasp: approach straight down, fingers closing across ``long_dir``
    (horizontal, unit)."""
    down = np.array([0.0, 0.0, -1.0])
    return np.column_stack([down, np.cross(long_dir, down), long_dir])
