"""Choose a feature extractor by name: ``oracle`` or ``rgbd``."""

from __future__ import annotations

from collections.abc import Callable

from agentchord.worlds.protocol import World

#: Names accepted by ``--perception``.
PERCEPTION_MODES = ("oracle", "rgbd")


def make_extractor(mode: str, world: World, grasp_signal: Callable[[str], bool]):
    """The feature extractor for a perception mode.

    Raises:
        ValueError: Unknown mode.
        GroundTruthUnavailableError: ``oracle`` on a world without ground truth.
    """
    if mode == "oracle":
        from agentchord.features.oracle import OracleExtractor

        return OracleExtractor(world, grasp_signal=grasp_signal)
    if mode == "rgbd":
        from agentchord.features.rgbd import RgbdExtractor  # imports the renderer

        return RgbdExtractor(world, grasp_signal=grasp_signal)
    raise ValueError(f"unknown perception mode {mode!r} (choose from: {', '.join(PERCEPTION_MODES)})")
