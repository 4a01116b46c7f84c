"""Oracle feature extraction: the feature frame read from the world's ground truth.

What a perfect perception stack would report (the paper's simulation setting,
Sec. IV-B): object poses from the physics, the grasp from finger contacts. It
needs a :class:`~agentchord.worlds.protocol.GroundTruthWorld` (a simulator); on a
world without ground truth it says so (:class:`~agentchord.worlds.protocol.GroundTruthUnavailableError`).
"""

from __future__ import annotations

import numpy as np

from agentchord.features.frame import ARMS, ArmFeatures, FeatureFrame, ObjectFeatures
from agentchord.features.pointcloud import quat_from_matrix
from agentchord.worlds.protocol import World, require_ground_truth


class OracleExtractor:
    """Builds a :class:`FeatureFrame` from a world's ground truth every tick.

    The same frame object is updated in place, so the references captured with
    ``capture_refs`` survive between ticks.

    Args:
        world: The world to read; it must have ground truth.
        grasp_signal: Callable ``arm -> bool``: the robot's latched "grasp done"
            signal (the controller knows it, the world does not).

    Raises:
        GroundTruthUnavailableError: ``world`` has no ground truth (a real robot).
    """

    #: What this extractor reads of the world besides the robot's signals.
    needs_ground_truth = True

    def __init__(self, world: World, grasp_signal=None) -> None:
        self.world = require_ground_truth(world, "oracle perception")
        self.grasp_signal = grasp_signal or (lambda arm: False)
        self.frame = FeatureFrame(objects={}, arms={})
        self._half_heights = {}
        for name in world.object_names:
            spec = world.object_spec(name)
            if spec.shape == "cylinder":
                extent = np.array([2 * spec.size[0], 2 * spec.size[0], 2 * spec.size[1]])
            else:
                extent = 2 * np.asarray(spec.size, dtype=float)
            self._half_heights[name] = 0.5 * extent[2]
            self.frame.objects[name] = ObjectFeatures(
                pos=np.zeros(3), quat=np.zeros(4), axis=np.zeros(3), extent=extent, top=np.zeros(3), bottom=np.zeros(3)
            )
        # A cloth's named points (its corners) are point-like objects: ``pos`` is the vertex, ``top`` and
        # ``bottom`` are half a cloth thickness above and below it, ``axis`` is up, and the local x axis of
        # ``quat`` is the corner's horizontal outward diagonal (a top grasp closes across it).
        self._cloth_radius = self.world.cloth_radius
        self._cloth_points = list(world.cloth_point_names)
        for name in self._cloth_points:
            self.frame.objects[name] = ObjectFeatures(
                pos=np.zeros(3), quat=np.zeros(4), axis=np.zeros(3), extent=np.full(3, 2 * self._cloth_radius),
                top=np.zeros(3), bottom=np.zeros(3),
            )
        for arm in ARMS:
            self.frame.arms[arm] = ArmFeatures(ee=np.zeros(3), ee_quat=np.zeros(4), q=np.zeros(6), width=0.0, closed=0.0)
        self.update()
        self.frame.capture_refs()

    def update(self) -> FeatureFrame:
        """Refresh the frame from the current simulator state."""
        world, frame = self.world, self.frame
        for name in self._cloth_points:
            feats = frame.objects[name]
            pos, out = world.cloth_point(name)
            if not out.any():
                out = np.array([1.0, 0.0, 0.0])
            up = np.array([0.0, 0.0, 1.0])
            feats.pos = pos
            feats.quat = quat_from_matrix(np.column_stack([out, np.cross(up, out), up]))
            feats.axis = up
            feats.top = pos + self._cloth_radius * up
            feats.bottom = pos - self._cloth_radius * up
        for name, feats in frame.objects.items():
            if name in self._cloth_points:
                continue
            pos, rot = world.object_pose(name)
            axis = rot[:, 2]
            half = self._half_heights[name] * axis
            feats.pos = pos
            feats.quat = world.object_quat(name)
            feats.axis = axis
            feats.top = pos + half
            feats.bottom = pos - half
        update_robot_signals(frame, world, self.grasp_signal)
        return frame


def update_robot_signals(frame: FeatureFrame, world: World, grasp_signal) -> None:
    """The robot's own signals, read every tick in every perception mode: tool poses, joints,
    gripper widths, the grasp-done signal, contact-based holding, the tick."""
    holding = set()
    for arm, feats in frame.arms.items():
        ee, rot = world.tcp_pose(arm)
        feats.ee = ee
        feats.ee_quat = quat_from_matrix(rot)
        feats.q = world.arm_q(arm)
        feats.width = world.gripper_width(arm)
        feats.closed = 1.0 if grasp_signal(arm) else 0.0
        for name in frame.objects:
            if world.holding(arm, name):
                holding.add((arm, name))
    frame.holding = holding
    frame.tick = world.tick
