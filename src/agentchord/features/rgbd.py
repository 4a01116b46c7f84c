"""RGB-D feature extraction: object features from rendered depth + segmentation.

The alternative to :class:`~agentchord.features.oracle.OracleExtractor`
(``--perception rgbd``): the scene cameras render depth and segmentation at the
camera rate (10 Hz, every 5th control tick at 50 Hz), a :class:`Segmenter`
gives one mask per object and camera, the masked depth pixels are
back-projected into world points, the views are fused, and a cylinder or box is
fitted to the fused cloud (:mod:`agentchord.features.shape_fit`). Between
camera frames the last estimate is kept. The robot's own signals (end
effectors, joints, gripper width, the grasp signal) and the contact-based
``holding`` relation come from the robot every tick, as in oracle mode: they are
proprioception and contact sensing, not vision.

The object's category (``object_spec(name).shape`` and its nominal size) only
chooses the model family and a soft size prior; its pose is never read.
"""

from __future__ import annotations

import time
from collections import deque

import numpy as np

from agentchord.features.frame import ARMS, ArmFeatures, FeatureFrame, ObjectFeatures
from agentchord.features.oracle import update_robot_signals
from agentchord.features.pointcloud import backproject, quat_from_axis, quat_from_matrix, voxel_downsample
from agentchord.features.shape_fit import ShapeFit, fit_box, fit_cylinder
from agentchord.features.segmentation import LabelSegmenter, Segmenter
from agentchord.worlds.protocol import CONTROL_HZ, Camera, CameraFrame, World

#: Cameras used for perception (the simulated scene's are defined in :mod:`agentchord.sim.scene`).
PERCEPTION_CAMERAS = ("front", "side")
#: Camera frame rate (Hz) of the paper's RGB-D setting.
CAMERA_RATE_HZ = 10
#: Fewer fused points than this: the object counts as not seen, its last estimate is kept.
MIN_POINTS = 30
#: Voxel edge (m) of the down-sampling of the fused cloud before fitting (equalises view densities).
VOXEL_M = 0.003


def frame_points(image: CameraFrame, mask: np.ndarray | None = None) -> np.ndarray:
    """World points of the (masked) pixels of a camera frame."""
    return backproject(image.depth, image.fovy, image.pos, image.rot, mask)


class RgbdExtractor:
    """Builds a :class:`FeatureFrame` from rendered depth + segmentation of scene cameras.

    Same interface as :class:`~agentchord.features.oracle.OracleExtractor`: the
    frame is updated in place (``frame.refs`` survive), ``update()`` is called
    every control tick. Objects are re-perceived every ``round(50 / rate_hz)``-th
    tick; in between the last estimate is kept. An object with fewer than
    ``min_points`` fused points keeps its last estimate, and its ``points`` is
    the count seen (so a ``lost_view`` monitor fires).

    Args:
        world: The world (its cameras are read, its object poses never).
        grasp_signal: Callable ``arm -> bool``: the controller's latched grasp signal.
        cameras: Names of the scene cameras to fuse.
        rate_hz: Camera rate (Hz).
        width: Image width (px).
        height: Image height (px).
        segmenter: Object masks per image; default :class:`LabelSegmenter` (the world's own
            labels: a simulator has them, a real camera needs a segmenter).
        min_points: Fewest fused points for a new estimate.
        voxel: Voxel edge (m) of the fused cloud's down-sampling (0: none).
        depth_noise: Standard deviation (m) of Gaussian depth noise at 1 m, growing
            with the square of the distance as for stereo / structured-light
            sensors (0: the renderer's exact depth).
        seed: Seed of the depth noise.

    Attributes:
        last_perceived_tick: Tick of the last camera frame.
        perceptions: Number of camera frames processed.
        costs_ms: Wall-clock cost of the recent camera frames (all cameras, all objects).
        estimated: Per object, whether it has been seen at least once.
    """

    #: Objects are read from the cameras only, never from the world's ground truth.
    needs_ground_truth = False

    def __init__(
        self,
        world: World,
        grasp_signal=None,
        cameras: tuple[str, ...] = PERCEPTION_CAMERAS,
        rate_hz: float = CAMERA_RATE_HZ,
        width: int = 320,
        height: int = 240,
        segmenter: Segmenter | None = None,
        min_points: int = MIN_POINTS,
        voxel: float = VOXEL_M,
        depth_noise: float = 0.0,
        seed: int = 0,
    ) -> None:
        self.world = world
        self.grasp_signal = grasp_signal or (lambda arm: False)
        self.period = max(1, round(CONTROL_HZ / rate_hz))
        self.min_points = min_points
        self.voxel = voxel
        self.depth_noise = depth_noise
        self.rng = np.random.default_rng(seed)
        self.segmenter = segmenter if segmenter is not None else LabelSegmenter.for_world(world)
        self.cameras: list[Camera] = []
        try:
            for name in cameras:
                self.cameras.append(world.open_camera(name, width, height))
        except Exception:
            self.close()
            raise
        self.frame = FeatureFrame(objects={}, arms={})
        #: Each object's fused point cloud (world frame, m) from the last camera frame that saw it
        #: (for viewers: ``run --perception rgbd --rerun``).
        self.clouds: dict[str, np.ndarray] = {}
        self._priors: dict[str, tuple[str, np.ndarray]] = {}
        self._rot: dict[str, np.ndarray] = {}
        self.estimated: dict[str, bool] = {}
        for name in world.object_names:
            spec = world.object_spec(name)
            if spec.shape == "cylinder":
                extent = np.array([2 * spec.size[0], 2 * spec.size[0], 2 * spec.size[1]])
            else:
                extent = 2 * np.asarray(spec.size, dtype=float)
            self._priors[name] = (spec.shape, np.asarray(spec.size, dtype=float))
            self.estimated[name] = False
            half = np.array([0.0, 0.0, 0.5 * extent[2]])
            self.frame.objects[name] = ObjectFeatures(
                pos=np.zeros(3), quat=np.array([1.0, 0.0, 0.0, 0.0]), axis=np.array([0.0, 0.0, 1.0]),
                extent=extent, top=half.copy(), bottom=-half, points=0.0,
            )  # fmt: skip
        for arm in ARMS:
            self.frame.arms[arm] = ArmFeatures(ee=np.zeros(3), ee_quat=np.zeros(4), q=np.zeros(6), width=0.0, closed=0.0)
        self.last_perceived_tick: int | None = None
        self.perceptions = 0
        self.costs_ms: deque[float] = deque(maxlen=1000)
        self.update()
        self.frame.capture_refs()

    # ------------------------------------------------------------------ life cycle
    def close(self) -> None:
        """Free the cameras' renderers (call before the interpreter exits)."""
        for camera in self.cameras:
            camera.close()

    def __enter__(self) -> RgbdExtractor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ------------------------------------------------------------------ per tick
    def due(self) -> bool:
        """Whether this tick gets a camera frame."""
        last = self.last_perceived_tick
        tick = self.world.tick
        return last is None or tick < last or tick - last >= self.period

    def update(self) -> FeatureFrame:
        """Refresh the frame: objects at the camera rate, the robot every tick."""
        world, frame = self.world, self.frame
        if self.due():
            self.perceive()
        update_robot_signals(frame, world, self.grasp_signal)
        return frame

    # ------------------------------------------------------------------ perception
    def capture(self) -> list[CameraFrame]:
        """A frame of every perception camera at the current state."""
        images = [camera.capture() for camera in self.cameras]
        if self.depth_noise > 0:
            for image in images:
                noise = self.rng.standard_normal(image.depth.shape, dtype=np.float32)
                image.depth = image.depth + noise * np.float32(self.depth_noise) * image.depth**2
        return images

    def object_clouds(self, images: list[CameraFrame]) -> dict[str, list[np.ndarray]]:
        """Per object, the world points of its mask in each image (in camera order)."""
        clouds: dict[str, list[np.ndarray]] = {name: [] for name in self.frame.objects}
        for image in images:
            masks = self.segmenter.masks(image)
            for name in clouds:
                mask = masks.get(name)
                if mask is None or not mask.any():
                    clouds[name].append(np.empty((0, 3)))
                else:
                    clouds[name].append(frame_points(image, mask & (image.depth < 0.99 * image.far)))
        return clouds

    def fuse(self, views: list[np.ndarray], origins: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Fuse per-camera clouds: each voxel-downsampled, then concatenated.

        Returns:
            The points and, per point, the position of the camera that saw it.
        """
        points, viewpoints = [], []
        for cloud, origin in zip(views, origins):
            if len(cloud) == 0:
                continue
            if self.voxel > 0:
                cloud = voxel_downsample(cloud, self.voxel)
            points.append(cloud)
            viewpoints.append(np.broadcast_to(np.asarray(origin, dtype=float), cloud.shape))
        if not points:
            return np.empty((0, 3)), np.empty((0, 3))
        return np.concatenate(points), np.concatenate(viewpoints)

    def fit(self, name: str, views: list[np.ndarray], origins: list[np.ndarray], hint: bool = True) -> ShapeFit:
        """Fit the object's model family to its fused views.

        Args:
            name: The object.
            views: Its points as seen by each camera.
            origins: The position of each of those cameras.
            hint: Start from the last estimate (if any).
        """
        shape, size = self._priors[name]
        points, viewpoints = self.fuse(views, origins)
        known = hint and self.estimated[name]
        if shape == "cylinder":
            axis = self.frame.objects[name].axis if known else None
            return fit_cylinder(points, radius=size[0], half_height=size[1], axis_hint=axis, viewpoints=viewpoints)
        return fit_box(points, size, rot_hint=self._rot.get(name) if known else None, viewpoints=viewpoints)

    def perceive(self) -> None:
        """Take one camera frame and re-estimate every object seen."""
        t0 = time.perf_counter()
        images = self.capture()
        origins = [image.pos for image in images]
        for name, views in self.object_clouds(images).items():
            count = sum(len(v) for v in views)
            feats = self.frame.objects[name]
            feats.points = float(count)
            if count < self.min_points:
                continue  # occluded or out of view: keep the last estimate
            self.clouds[name] = self.fuse(views, origins)[0]
            try:
                fit = self.fit(name, views, origins)
            except np.linalg.LinAlgError:
                continue  # a degenerate cloud (a sliver): keep the last estimate
            if np.all(np.isfinite(fit.pos)) and np.all(np.isfinite(fit.rot)):
                self._write(name, fit)
        self.last_perceived_tick = self.world.tick
        self.perceptions += 1
        self.costs_ms.append((time.perf_counter() - t0) * 1e3)

    def _write(self, name: str, fit: ShapeFit) -> None:
        feats = self.frame.objects[name]
        shape, _ = self._priors[name]
        axis = fit.axis.copy()
        if shape == "cylinder":
            radius, half = fit.size
            feats.extent = np.array([2 * radius, 2 * radius, 2 * half])
            feats.quat = quat_from_axis(axis)
        else:
            half = fit.size[2]
            feats.extent = 2 * fit.size.copy()
            feats.quat = quat_from_matrix(fit.rot)
        self._rot[name] = fit.rot.copy()
        feats.pos = fit.pos.copy()
        feats.axis = axis
        feats.top = fit.pos + half * axis
        feats.bottom = fit.pos - half * axis
        self.estimated[name] = True
