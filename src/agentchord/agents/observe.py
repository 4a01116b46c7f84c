"""The first observation of a simulated scene, as the agents see it (a :class:`Scene`).

Objects come from the perception's feature frame (poses, axes, sizes), described in
words by their colour and name so that instructions can say "the red block"; regions
come from the task (a target area); arms from the frame (held objects, tool centres).
"""

from __future__ import annotations

import numpy as np

from agentchord.agents.scene import Region, Scene
from agentchord.features.extractors import make_extractor
from agentchord.worlds.protocol import World

#: Named colours (RGB in [0, 1]) for object descriptions.
COLOURS = {
    "red": (0.85, 0.1, 0.1),
    "orange": (0.95, 0.55, 0.1),
    "yellow": (0.9, 0.85, 0.15),
    "green": (0.15, 0.7, 0.2),
    "blue": (0.15, 0.3, 0.85),
    "purple": (0.55, 0.2, 0.7),
    "brown": (0.45, 0.25, 0.1),
    "white": (0.92, 0.92, 0.92),
    "grey": (0.55, 0.55, 0.55),
    "black": (0.08, 0.08, 0.08),
}


def colour_name(rgba: tuple[float, ...]) -> str:
    """The nearest named colour of an RGB(A) colour."""
    rgb = np.asarray(rgba[:3], dtype=float)
    return min(COLOURS, key=lambda name: float(np.linalg.norm(rgb - np.asarray(COLOURS[name]))))


def task_regions(task: object) -> list[Region]:
    """The named regions a simulated task declares (``regions``: name -> (centre, radius, words))."""
    return [Region(name=name, center=centre, radius=radius, description=words) for name, (centre, radius, words) in getattr(task, "regions", {}).items()]


def observe(world: World, regions: list[Region] | None = None, perception: str = "oracle") -> Scene:
    """The scene as the agents see it now.

    Args:
        world: The world (its objects' colours describe them).
        regions: The task's named regions.
        perception: ``oracle`` or ``rgbd`` features.
    """
    extractor = make_extractor(perception, world, lambda arm: False)
    try:
        frame = extractor.update()
    finally:
        close = getattr(extractor, "close", None)
        if close is not None:
            close()
    descriptions = {}
    for name in frame.objects:
        spec = world.object_spec(name) if name in world.object_names else None
        words = name.replace("_", " ")
        descriptions[name] = f"{colour_name(spec.rgba)} {words}" if spec is not None else words
    # A world may say more of its scene than poses and sizes (gym-aloha's: the socket's bore).
    return Scene.from_frame(frame, descriptions=descriptions, regions=regions or [], notes=getattr(world, "scene_notes", ""))
