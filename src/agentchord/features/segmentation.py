"""Object segmentation of camera images: the interface and the simulator's segmenter.

RGB-D perception needs, per camera image, one pixel mask per named object. On a
real robot an open-vocabulary segmenter (SAM3, Grounded-SAM) prompted with the
object names provides them; in simulation :class:`SimSegmenter` reads MuJoCo's
segmentation rendering (geom id and object type per pixel) and maps geoms to
objects. :class:`NoisySegmenter` degrades any segmenter's masks (eroded
borders, dropped pixels, missed detections) for robustness tests.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import mujoco
import numpy as np


@runtime_checkable
class Segmenter(Protocol):
    """Per-object pixel masks of one camera image."""

    def masks(self, seg_image: np.ndarray, camera: str) -> dict[str, np.ndarray]:
        """Masks of the objects seen by ``camera``.

        Args:
            seg_image: (H, W, 2) int image of (object id, object type) per pixel,
                as ``mujoco.Renderer`` gives with segmentation rendering; -1 is
                background. A learned segmenter would take the RGB image instead.
            camera: Name of the camera the image comes from.

        Returns:
            ``{object name: (H, W) bool mask}``; an object not seen may be absent
            or have an empty mask.
        """
        ...


class SimSegmenter:
    """The simulator's ground-truth segmentation: geom id -> object name.

    Every geom attached to an object's body counts as that object (most objects
    have one geom, named like the object; a compound one, such as a tray, has several).

    Args:
        model: The compiled MuJoCo model.
        object_names: Names of the object bodies to segment.
    """

    def __init__(self, model: mujoco.MjModel, object_names: list[str] | tuple[str, ...]) -> None:
        self.object_names = list(object_names)
        self._lut = np.full(model.ngeom + 1, -1, dtype=np.int32)  # index geom id + 1 (-1 -> background)
        for index, name in enumerate(self.object_names):
            body = model.body(name).id
            for geom in np.nonzero(model.geom_bodyid == body)[0]:
                self._lut[geom + 1] = index

    @classmethod
    def for_world(cls, world) -> SimSegmenter:
        """The segmenter of a :class:`~agentchord.worlds.sim.world.SimWorld`'s objects."""
        return cls(world.model, world.object_names)

    def labels(self, seg_image: np.ndarray) -> np.ndarray:
        """(H, W) object index per pixel (-1: no object)."""
        ids = seg_image[..., 0]
        is_geom = seg_image[..., 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
        ids = np.where(is_geom & (ids >= 0) & (ids < len(self._lut) - 1), ids, -1)
        return self._lut[ids + 1]

    def masks(self, seg_image: np.ndarray, camera: str) -> dict[str, np.ndarray]:
        """One mask per object, containing exactly that object's geom pixels."""
        labels = self.labels(seg_image)
        return {name: labels == index for index, name in enumerate(self.object_names)}


def erode(mask: np.ndarray, pixels: int = 1) -> np.ndarray:
    """Binary erosion with a 3x3 cross, ``pixels`` times (the border counts as outside)."""
    out = mask.copy()
    for _ in range(pixels):
        inner = out.copy()
        inner[1:, :] &= out[:-1, :]
        inner[:-1, :] &= out[1:, :]
        inner[:, 1:] &= out[:, :-1]
        inner[:, :-1] &= out[:, 1:]
        inner[0, :] = inner[-1, :] = False
        inner[:, 0] = inner[:, -1] = False
        out = inner
    return out


class NoisySegmenter:
    """Degrade another segmenter's masks, as a learned segmenter would.

    Args:
        base: The segmenter whose masks are degraded.
        erode_px: Pixels eroded off every mask border.
        drop: Fraction of mask pixels dropped at random.
        miss: Probability that an object is not detected at all in one image.
        seed: Seed of the noise.
    """

    def __init__(self, base: Segmenter, erode_px: int = 1, drop: float = 0.0, miss: float = 0.0, seed: int = 0) -> None:
        self.base = base
        self.erode_px = erode_px
        self.drop = drop
        self.miss = miss
        self.rng = np.random.default_rng(seed)

    def masks(self, seg_image: np.ndarray, camera: str) -> dict[str, np.ndarray]:
        """The base masks, eroded, thinned and sometimes missing."""
        out = {}
        for name, mask in self.base.masks(seg_image, camera).items():
            if self.miss > 0 and self.rng.random() < self.miss:
                out[name] = np.zeros_like(mask)
                continue
            if self.erode_px > 0:
                mask = erode(mask, self.erode_px)
            if self.drop > 0:
                mask = mask & (self.rng.random(mask.shape) >= self.drop)
            out[name] = mask
        return out
