"""Point clouds from depth images (RGB-D perception): back-projection, down-sampling, axes.

Numpy only, no renderer, no MuJoCo: back-projection of a depth image through a pinhole
camera, voxel down-sampling, PCA, the orientation of a principal axis and quaternions from
axes and matrices. The shape fits to these clouds are in :mod:`agentchord.features.shape_fit`.

Conventions: MuJoCo cameras look along their -z axis with y up and x right;
``cam_rot`` has the camera axes as columns (``data.cam_xmat`` reshaped).
"""

from __future__ import annotations

import math

import numpy as np

from agentchord.features.frame import UP

# --------------------------------------------------------------------------- camera geometry
def focal_length(fovy_deg: float, height: int) -> float:
    """Focal length in pixels of a camera with vertical field of view ``fovy_deg``."""
    return 0.5 * height / np.tan(0.5 * np.radians(fovy_deg))


def backproject(
    depth: np.ndarray,
    fovy_deg: float,
    cam_pos: np.ndarray,
    cam_rot: np.ndarray,
    mask: np.ndarray | None = None,
) -> np.ndarray:
    """World points of the (masked) pixels of a depth image.

    Args:
        depth: (H, W) distance along the camera's viewing axis (m), row 0 at the top.
        fovy_deg: Vertical field of view (``model.cam_fovy``), square pixels.
        cam_pos: Camera position in the world (``data.cam_xpos``).
        cam_rot: (3, 3) camera axes as columns (``data.cam_xmat``).
        mask: Optional (H, W) bool mask of the pixels to keep.

    Returns:
        (N, 3) world points, one per kept pixel, in row-major pixel order.
    """
    height, width = depth.shape
    f = focal_length(fovy_deg, height)
    if mask is None:
        rows, cols = np.indices(depth.shape).reshape(2, -1)
        z = depth.reshape(-1).astype(float)
    else:
        rows, cols = np.nonzero(mask)
        z = depth[rows, cols].astype(float)
    # Pixel centres; image x to the right, image rows downwards = camera -y.
    x = (cols + 0.5 - 0.5 * width) / f * z
    y = -(rows + 0.5 - 0.5 * height) / f * z
    local = np.stack([x, y, -z], axis=1)
    return local @ np.asarray(cam_rot, dtype=float).reshape(3, 3).T + np.asarray(cam_pos, dtype=float)


def voxel_downsample(points: np.ndarray, voxel: float) -> np.ndarray:
    """One point (the mean) per occupied voxel of edge ``voxel`` (m)."""
    if len(points) == 0 or voxel <= 0:
        return points
    keys = np.floor(points / voxel).astype(np.int64)
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    sums = np.zeros((len(counts), 3))
    np.add.at(sums, inverse, points)
    return sums / counts[:, None]


def pca(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centroid, eigenvalues (descending) and eigenvectors (columns) of a cloud."""
    centroid = points.mean(axis=0)
    cov = np.cov((points - centroid).T) if len(points) > 1 else np.zeros((3, 3))
    values, vectors = np.linalg.eigh(cov)
    order = np.argsort(values)[::-1]
    return centroid, values[order], vectors[:, order]


#: Smallest |cos| between a new axis and the last estimate for the last estimate to set its sign.
CONTINUITY_COS = 0.5


def orient(axis: np.ndarray, reference: np.ndarray | None) -> np.ndarray:
    """Flip ``axis`` to point the same way as ``reference`` (the last estimate), else up.

    A cylinder's two ends look alike, so the sign of its axis ("top") follows
    the last estimate while that is informative (within 60 degrees, e.g. a
    bottle tilted past horizontal in a pour); otherwise (first sight, or the
    object turned a lot between frames) the up-pointing end is the top.
    """
    use_ref = reference is not None and np.any(reference) and abs(float(np.dot(axis, reference))) >= CONTINUITY_COS
    ref = reference if use_ref else UP
    return -axis if float(np.dot(axis, ref)) < 0.0 else axis


def quat_from_axis(axis: np.ndarray) -> np.ndarray:
    """Quaternion (w, x, y, z) of the smallest rotation taking world z to ``axis``.

    A cylinder's spin about its own axis is not observable; this picks none.
    """
    axis = axis / np.linalg.norm(axis)
    w = 1.0 + float(axis[2])
    if w < 1e-9:  # upside down: half turn about x
        return np.array([0.0, 1.0, 0.0, 0.0])
    quat = np.array([w, -axis[1], axis[0], 0.0])  # cross(z, axis) = (-a_y, a_x, 0)
    return quat / np.linalg.norm(quat)


def quat_from_matrix(rot: np.ndarray) -> np.ndarray:
    """Quaternion (w, x, y, z) of a rotation matrix.

    MuJoCo's ``mju_mat2Quat``, operation for operation (the same bits): the largest
    component first, the others from it, then normalised.
    """
    m0, m1, m2, m3, m4, m5, m6, m7, m8 = np.asarray(rot, dtype=float).ravel().tolist()
    if m0 + m4 + m8 > 0:
        w = 0.5 * math.sqrt(1 + m0 + m4 + m8)
        q = (w, 0.25 * (m7 - m5) / w, 0.25 * (m2 - m6) / w, 0.25 * (m3 - m1) / w)
    elif m0 > m4 and m0 > m8:
        x = 0.5 * math.sqrt(1 + m0 - m4 - m8)
        q = (0.25 * (m7 - m5) / x, x, 0.25 * (m1 + m3) / x, 0.25 * (m2 + m6) / x)
    elif m4 > m8:
        y = 0.5 * math.sqrt(1 - m0 + m4 - m8)
        q = (0.25 * (m2 - m6) / y, 0.25 * (m1 + m3) / y, y, 0.25 * (m5 + m7) / y)
    else:
        z = 0.5 * math.sqrt(1 - m0 - m4 + m8)
        q = (0.25 * (m3 - m1) / z, 0.25 * (m2 + m6) / z, 0.25 * (m5 + m7) / z, z)
    norm = math.sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    if norm < 1e-15:
        return np.array([1.0, 0.0, 0.0, 0.0])
    if abs(norm - 1.0) > 1e-15:
        inv = 1.0 / norm
        q = tuple(c * inv for c in q)
    return np.array(q)
