"""Object segmentation of camera frames: the interface, the world's own labels, and noise.

RGB-D perception needs, per camera frame, one pixel mask per named object. On a
real robot an open-vocabulary segmenter (SAM3, Grounded-SAM) prompted with the
object names provides them from ``frame.rgb``; a world that segments its own
frames (the simulator renders instance labels) fills ``frame.labels``, which
:class:`LabelSegmenter` reads. :class:`NoisySegmenter` degrades any segmenter's
masks (eroded borders, dropped pixels, missed detections) for robustness tests.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from agentchord.worlds.protocol import CameraFrame, World


@runtime_checkable
class Segmenter(Protocol):
    """Per-object pixel masks of one camera frame."""

    def masks(self, image: CameraFrame) -> dict[str, np.ndarray]:
        """Masks of the objects seen in ``image`` (``image.camera`` names its camera).

        Returns:
            ``{object name: (H, W) bool mask}``; an object not seen may be absent
            or have an empty mask.
        """
        ...


class SegmentationUnavailableError(ValueError):
    """A camera frame has no labels of its own, and no segmenter was given for it."""


class LabelSegmenter:
    """The world's own instance segmentation (``frame.labels``): label k is ``object_names[k]``.

    In simulation these are exact: every geom of an object's body counts as that object
    (a compound one, such as a tray, has several).

    Args:
        object_names: The world's object names, in its order.
    """

    def __init__(self, object_names: list[str] | tuple[str, ...]) -> None:
        self.object_names = list(object_names)

    @classmethod
    def for_world(cls, world: World) -> LabelSegmenter:
        """The segmenter of a world's objects."""
        return cls(world.object_names)

    def labels(self, image: CameraFrame) -> np.ndarray:
        """(H, W) object index per pixel (-1: no object).

        Raises:
            SegmentationUnavailableError: The frame carries no labels (a real camera).
        """
        if image.labels is None:
            raise SegmentationUnavailableError(
                f"camera {image.camera!r} gives no segmentation of its own: give the RGB-D extractor a segmenter"
            )
        return image.labels

    def masks(self, image: CameraFrame) -> dict[str, np.ndarray]:
        """One mask per object, containing exactly that object's pixels."""
        labels = self.labels(image)
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

    def masks(self, image: CameraFrame) -> dict[str, np.ndarray]:
        """The base masks, eroded, thinned and sometimes missing."""
        out = {}
        for name, mask in self.base.masks(image).items():
            if self.miss > 0 and self.rng.random() < self.miss:
                out[name] = np.zeros_like(mask)
                continue
            if self.erode_px > 0:
                mask = erode(mask, self.erode_px)
            if self.drop > 0:
                mask = mask & (self.rng.random(mask.shape) >= self.drop)
            out[name] = mask
        return out
