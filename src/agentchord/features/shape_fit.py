"""Least-squares fits of the scene's two model families (cylinders and boxes) to a point cloud.

The fits minimise the signed distance of every visible point to the surface of a solid
cylinder / box, with the object's nominal size as a soft prior. Views see only the front
surface of an object, so a centroid of the visible points is biased towards the cameras
(2-4 cm for a bottle); a surface fit is not. The clouds come from
:mod:`agentchord.features.pointcloud`.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from agentchord.features.frame import UP
from agentchord.features.pointcloud import orient, pca

#: Residual scale (m) beyond which a point's weight decays (Huber): guards against mask bleed.
HUBER_M = 0.004
#: Standard deviation (m) of the size prior (the nominal size of the object's category).
SIZE_PRIOR_SIGMA = 0.005
#: Standard deviation (m) assumed for one point's distance to the surface.
POINT_SIGMA = 0.001
#: Mean cost per point (in POINT_SIGMA units, 0.5 * (d / sigma)^2) under which a start is kept
#: without trying the others: an RMS distance to the surface of about 1 mm.
GOOD_START_COST = 0.5


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _perpendicular_basis(axis: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = _cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    return e1, _cross(axis, e1)


def fit_circle(xy: np.ndarray) -> tuple[np.ndarray, float]:
    """Algebraic (Kasa) least-squares circle through 2-D points: centre, radius."""
    a = np.column_stack([xy, np.ones(len(xy))])
    b = (xy**2).sum(axis=1)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    centre = 0.5 * sol[:2]
    radius = float(np.sqrt(max(sol[2] + centre @ centre, 0.0)))
    return centre, radius


# --------------------------------------------------------------------------- fits
@dataclass
class ShapeFit:
    """A fitted object model.

    Attributes:
        pos: Centre (m).
        rot: Orientation; column 2 is the principal axis.
        size: Cylinder (radius, half-height) or box half-sizes (m).
        rms: Root-mean-square distance of the points to the fitted surface (m).
    """

    pos: np.ndarray
    rot: np.ndarray
    size: np.ndarray
    rms: float

    @property
    def axis(self) -> np.ndarray:
        """The principal axis (unit)."""
        return self.rot[:, 2]


def _huber_weights(res: np.ndarray, scale: float = HUBER_M) -> np.ndarray:
    a = np.abs(res)
    return np.where(a <= scale, 1.0, scale / np.maximum(a, 1e-12))


def _facing_sign(toward: np.ndarray | None, local: np.ndarray, inside: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Which of the two faces normal to each direction a point inside the slab is measured to.

    Outside the slab: the face it is beyond (``sign(local)``). Inside: the face
    its camera can see (``toward``: point-to-camera vectors), never the hidden
    one. Without viewpoints: the nearer face, as a plain signed distance does,
    which lets an unseen face (the bottom of a standing object) snap to the
    lowest noisy points.
    """
    if toward is None:
        return np.sign(local)
    facing = np.sign(toward @ directions)
    return np.where(inside, np.where(facing == 0, 1.0, facing), np.sign(local))


def _cylinder_residuals(points, centre, axis, radius, half, jac: bool, toward=None):
    d = points - centre
    s = d @ axis
    q = d - s[:, None] * axis
    rho = np.linalg.norm(q, axis=1)
    u = rho - radius
    sign = _facing_sign(toward, s, np.abs(s) <= half, axis)
    v = sign * s - half
    corner = (u > 0) & (v > 0)
    sdf = np.where(corner, np.hypot(np.maximum(u, 0), np.maximum(v, 0)), np.maximum(u, v))
    if not jac:
        return sdf, None
    e1, e2 = _perpendicular_basis(axis)
    qhat = q / np.maximum(rho, 1e-9)[:, None]
    # Derivatives of u and v wrt (centre[3], tilt[2], radius, half).
    du = np.zeros((len(points), 7))
    du[:, :3] = -qhat
    du[:, 3] = -s * (qhat @ e1)
    du[:, 4] = -s * (qhat @ e2)
    du[:, 5] = -1.0
    dv = np.zeros((len(points), 7))
    dv[:, :3] = -sign[:, None] * axis
    dv[:, 3] = sign * (q @ e1)
    dv[:, 4] = sign * (q @ e2)
    dv[:, 6] = -1.0
    use_u = (u >= v)[:, None]
    j = np.where(use_u, du, dv)
    if corner.any():
        c = corner
        norm = np.maximum(sdf[c], 1e-12)[:, None]
        j[c] = (u[c, None] * du[c] + v[c, None] * dv[c]) / norm
    return sdf, (j, e1, e2)


def _normal_equations(sdf: np.ndarray, j: np.ndarray, point_w: float) -> tuple[np.ndarray, np.ndarray]:
    """The Huber-weighted Gauss-Newton system of the point residuals: (J^T W J, J^T W r)."""
    w = _huber_weights(sdf) * point_w**2
    jw = j * w[:, None]
    return j.T @ jw, jw.T @ sdf


def _damped_step(a: np.ndarray, g: np.ndarray, lam: float, cost: float, candidate):
    """One Levenberg-Marquardt step: the damping raised until a step lowers the cost (six tries).

    Args:
        a, g: The system with its priors.
        lam: The damping to start from.
        cost: The cost now.
        candidate: step -> (the state it leads to, that state's cost).

    Returns:
        (step, state, its cost, the damping for the next step), or None where no try lowered the cost.
    """
    for _ in range(6):
        step = np.linalg.solve(a + lam * np.diag(np.diag(a) + 1e-9), -g)
        state, new_cost = candidate(step)
        if new_cost < cost:
            return step, state, new_cost, max(lam / 3, 1e-7)
        lam *= 4
    return None


def _robust_cost(sdf: np.ndarray, prior: np.ndarray) -> float:
    a = np.abs(sdf)
    huber = np.where(a <= HUBER_M, 0.5 * a**2, HUBER_M * (a - 0.5 * HUBER_M))
    return float(huber.sum() / POINT_SIGMA**2 + 0.5 * (prior**2).sum())


def fit_cylinder(
    points: np.ndarray,
    radius: float,
    half_height: float,
    axis_hint: np.ndarray | None = None,
    viewpoints: np.ndarray | None = None,
    iterations: int = 30,
) -> ShapeFit:
    """Least-squares solid cylinder through surface points.

    The axis is started from the cloud's PCA directions, world up and
    ``axis_hint`` (the last estimate); each start gets a circle fit of the
    points projected on the plane normal to the axis for its centre; the
    best start after a few iterations is refined by Levenberg-Marquardt on the
    points' signed distances to the surface, with the nominal radius and
    half-height as a soft prior.

    Args:
        points: (N, 3) visible surface points (N >= 10).
        radius: Nominal radius (m).
        half_height: Nominal half-height (m).
        axis_hint: Previous axis estimate, if any.
        viewpoints: (N, 3) position of the camera that saw each point (or one
            (3,) position for all): a point is then never matched to a face
            its camera cannot see.
        iterations: Most Levenberg-Marquardt iterations of the refinement.
    """
    toward = None if viewpoints is None else np.asarray(viewpoints, dtype=float) - points
    centroid, _, vectors = pca(points)
    starts: list[np.ndarray] = []
    for cand in ([axis_hint] if axis_hint is not None and np.any(axis_hint) else []) + [vectors[:, 0], UP, vectors[:, 1], vectors[:, 2]]:
        cand = cand / np.linalg.norm(cand)
        if all(abs(float(cand @ s)) < 0.97 for s in starts):
            starts.append(cand)
    best = None
    hinted = axis_hint is not None and np.any(axis_hint)
    for axis in starts:
        state = _cylinder_start(points, centroid, axis, radius, half_height)
        state, cost = _lm_cylinder(points, state, radius, half_height, iterations=4, toward=toward)
        if best is None or cost < best[1]:
            best = (state, cost)
        if hinted and best[1] < GOOD_START_COST * len(points):
            break  # the last estimate's axis still explains the cloud
        hinted = False
    state, _ = _lm_cylinder(points, best[0], radius, half_height, iterations=iterations, toward=toward)
    centre, axis, r, h = state
    sdf, _ = _cylinder_residuals(points, centre, axis, r, h, jac=False, toward=toward)
    axis = orient(axis, axis_hint)
    e1, e2 = _perpendicular_basis(axis)
    return ShapeFit(pos=centre, rot=np.column_stack([e1, e2, axis]), size=np.array([r, h]), rms=float(np.sqrt(np.mean(sdf**2))))


def _cylinder_start(points, centroid, axis, radius, half_height):
    e1, e2 = _perpendicular_basis(axis)
    d = points - centroid
    xy = np.column_stack([d @ e1, d @ e2])
    s = d @ axis
    try:
        c2, r_fit = fit_circle(xy)
        if not np.isfinite(r_fit) or r_fit > 3 * radius or np.linalg.norm(c2) > 3 * radius:
            raise np.linalg.LinAlgError
    except np.linalg.LinAlgError:
        c2 = np.zeros(2)
    mid = 0.5 * (s.min() + s.max())
    centre = centroid + c2[0] * e1 + c2[1] * e2 + mid * axis
    return centre, axis, float(radius), float(half_height)


def _lm_cylinder(points, state, radius0, half0, iterations, toward=None):
    centre, axis, r, h = state
    lam = 1e-3
    prior_w = 1.0 / SIZE_PRIOR_SIGMA
    point_w = 1.0 / POINT_SIGMA

    def prior(r_, h_):
        return np.array([(r_ - radius0) * prior_w, (h_ - half0) * prior_w])

    sdf, (j, e1, e2) = _cylinder_residuals(points, centre, axis, r, h, jac=True, toward=toward)
    cost = _robust_cost(sdf, prior(r, h))
    for _ in range(iterations):
        a, g = _normal_equations(sdf, j, point_w)
        pr = prior(r, h)
        a[5, 5] += prior_w**2
        a[6, 6] += prior_w**2
        g[5] += prior_w * pr[0]
        g[6] += prior_w * pr[1]

        def candidate(step, centre=centre, axis=axis, r=r, h=h, e1=e1, e2=e2):
            new_axis = axis + step[3] * e1 + step[4] * e2
            new_axis /= np.linalg.norm(new_axis)
            cand = (centre + step[:3], new_axis, max(r + step[5], 1e-3), max(h + step[6], 1e-3))
            sdf_new, _ = _cylinder_residuals(points, *cand, jac=False, toward=toward)
            return cand, _robust_cost(sdf_new, prior(cand[2], cand[3]))

        found = _damped_step(a, g, lam, cost, candidate)
        if found is None:
            break
        step, cand, new_cost, lam = found
        converged = cost - new_cost < 1e-5 * cost
        centre, axis, r, h = cand
        cost = new_cost
        sdf, (j, e1, e2) = _cylinder_residuals(points, centre, axis, r, h, jac=True, toward=toward)
        if converged or np.linalg.norm(step[:5]) < 1e-6:
            break
    return (centre, axis, r, h), cost


def _box_residuals(points, centre, rot, half, jac: bool, toward=None):
    local = (points - centre) @ rot
    sign = _facing_sign(toward, local, np.abs(local) <= half, rot)
    q = sign * local - half
    pos_q = np.maximum(q, 0.0)
    outside = np.linalg.norm(pos_q, axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    sdf = outside + inside
    if not jac:
        return sdf, None
    # d sdf / d q: outside the box the direction to the nearest surface point, inside the nearest face.
    gq = pos_q / np.maximum(outside, 1e-12)[:, None]
    inner = outside <= 0
    if inner.any():
        gq[inner] = 0.0
        gq[inner, np.argmax(q[inner], axis=1)] = 1.0
    gl = gq * sign
    j = np.empty((len(points), 9))
    j[:, :3] = -gl @ rot.T  # centre
    # rotation increment R <- R exp([w]): d local = local x w, so d sdf / d w = gl x local.
    j[:, 3] = gl[:, 1] * local[:, 2] - gl[:, 2] * local[:, 1]
    j[:, 4] = gl[:, 2] * local[:, 0] - gl[:, 0] * local[:, 2]
    j[:, 5] = gl[:, 0] * local[:, 1] - gl[:, 1] * local[:, 0]
    j[:, 6:] = -gq  # half sizes
    return sdf, j


def _rodrigues(w: np.ndarray) -> np.ndarray:
    theta = float(np.linalg.norm(w))
    if theta < 1e-12:
        return np.eye(3)
    k = w / theta
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(theta) * kx + (1 - np.cos(theta)) * kx @ kx


_QUARTER_TURN_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def fit_box(
    points: np.ndarray,
    half_sizes: np.ndarray,
    rot_hint: np.ndarray | None = None,
    viewpoints: np.ndarray | None = None,
    iterations: int = 30,
) -> ShapeFit:
    """Least-squares box through surface points.

    Starts: the PCA axes (each assigned to the nominal half-size it best
    matches), the upright box turned to the horizontal PCA direction of the
    cloud, each also turned a quarter about its z axis, and ``rot_hint`` (the
    last estimate); each start's centre is the middle of the extremal
    projections on its axes (not the centroid of the visible faces). The best
    start is refined by Levenberg-Marquardt on the points' signed distances to
    the surface, nominal half-sizes as a soft prior (``viewpoints``: as for
    :func:`fit_cylinder`).
    """
    toward = None if viewpoints is None else np.asarray(viewpoints, dtype=float) - points
    half_sizes = np.asarray(half_sizes, dtype=float)
    centroid, _, vectors = pca(points)
    candidates = []
    if rot_hint is not None:
        candidates.append(np.asarray(rot_hint, dtype=float))
    order = np.argsort(half_sizes)[::-1]  # the largest spread goes with the largest nominal size
    rot = np.zeros((3, 3))
    for k, idx in enumerate(order):
        rot[:, idx] = vectors[:, k]
    flat = (points - centroid)[:, :2]
    _, vec2 = np.linalg.eigh(np.cov(flat.T))
    x = np.array([vec2[0, -1], vec2[1, -1], 0.0])
    upright = np.column_stack([x, _cross(UP, x), UP])
    for base in (upright, rot):
        candidates += [base, base @ _QUARTER_TURN_Z]
    best = None
    hinted = rot_hint is not None
    for rot in candidates:
        if np.linalg.det(rot) < 0:
            rot = rot.copy()
            rot[:, 0] *= -1
        proj = (points - centroid) @ rot
        centre = centroid + rot @ (0.5 * (proj.min(axis=0) + proj.max(axis=0)))
        state, cost = _lm_box(points, (centre, rot, half_sizes.copy()), half_sizes, iterations=4, toward=toward)
        if best is None or cost < best[1]:
            best = (state, cost)
        if hinted and best[1] < GOOD_START_COST * len(points):
            break  # the last estimate still explains the cloud
        hinted = False
    (centre, rot, half), _ = _lm_box(points, best[0], half_sizes, iterations=iterations, toward=toward)
    rot, half = _match_axes(rot, half, half_sizes)
    # Sign of the principal (z) axis: consistent with the last estimate, else up (see orient).
    if float(rot[:, 2] @ orient(rot[:, 2], None if rot_hint is None else rot_hint[:, 2])) < 0:
        rot = rot @ np.diag([-1.0, 1.0, -1.0])
    if rot_hint is not None and float(rot[:, 0] @ rot_hint[:, 0]) < 0:
        rot = rot @ np.diag([-1.0, -1.0, 1.0])  # the same box, turned like the last estimate
    sdf, _ = _box_residuals(points, centre, rot, half, jac=False, toward=toward)
    return ShapeFit(pos=centre, rot=rot, size=half, rms=float(np.sqrt(np.mean(sdf**2))))


def _match_axes(rot: np.ndarray, half: np.ndarray, half0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Relabel the fitted axes so the half-sizes match the nominal ones (the same solid)."""
    best = min(itertools.permutations(range(3)), key=lambda p: float(np.abs(half[list(p)] - half0).sum()))
    perm = list(best)
    rot, half = rot[:, perm].copy(), half[perm].copy()
    if np.linalg.det(rot) < 0:
        rot[:, 0] *= -1
    return rot, half


def _lm_box(points, state, half0, iterations, toward=None):
    centre, rot, half = state
    prior_w = 1.0 / SIZE_PRIOR_SIGMA
    point_w = 1.0 / POINT_SIGMA
    lam = 1e-3
    sdf, j = _box_residuals(points, centre, rot, half, jac=True, toward=toward)
    cost = _robust_cost(sdf, (half - half0) * prior_w)
    for _ in range(iterations):
        a, g = _normal_equations(sdf, j, point_w)
        a[6:, 6:] += np.eye(3) * prior_w**2
        g[6:] += prior_w**2 * (half - half0)

        def candidate(step, centre=centre, rot=rot, half=half):
            cand = (centre + step[:3], rot @ _rodrigues(step[3:6]), np.maximum(half + step[6:], 1e-3))
            sdf_new, _ = _box_residuals(points, *cand, jac=False, toward=toward)
            return cand, _robust_cost(sdf_new, (cand[2] - half0) * prior_w)

        found = _damped_step(a, g, lam, cost, candidate)
        if found is None:
            break
        step, cand, new_cost, lam = found
        converged = cost - new_cost < 1e-5 * cost
        centre, rot, half = cand
        cost = new_cost
        sdf, j = _box_residuals(points, centre, rot, half, jac=True, toward=toward)
        if converged or np.linalg.norm(step[:6]) < 1e-7:
            break
    return (centre, rot, half), cost
