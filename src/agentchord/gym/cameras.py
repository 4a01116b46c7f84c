"""Colour images of the simulated scene's cameras, for observations and datasets.

The simulator's own cameras (``sim/cameras``) render depth and labels for perception; a
policy and a dataset want plain RGB frames: one ``mujoco.Renderer`` per camera here.
"""

from __future__ import annotations

import numpy as np

from agentchord.sim.markers import Shape, add_to_scene
from agentchord.sim.renderers import close_at_exit, closed, open_renderer


class RgbCameras:
    """RGB renderers for some cameras of one simulated world (close when done).

    Args:
        world: The simulated world (it has ``model`` and ``data``).
        cameras: Camera names of its scene.
        size: (height, width) in pixels.

    Raises:
        KeyError: A camera the scene lacks.
    """

    def __init__(self, world, cameras: tuple[str, ...], size: tuple[int, int] = (240, 320)) -> None:
        missing = [c for c in cameras if c not in world.camera_names]
        if missing:
            raise KeyError(f"no camera {missing[0]!r} in the scene (cameras: {', '.join(world.camera_names)})")
        self.world = world
        self.cameras = tuple(cameras)
        self.size = size
        self._renderer = open_renderer(world.model, height=size[0], width=size[1]) if cameras else None
        close_at_exit(self)

    def render(self, shapes: list[Shape] | tuple[Shape, ...] = ()) -> dict[str, np.ndarray]:
        """One (H, W, 3) uint8 image per camera of the state now, ``shapes`` drawn in.

        ``shapes``: disturbance markers (:meth:`agentchord.sim.markers.DisturbanceMarkers.shapes`,
        a Rerun recording's images); observations and datasets pass none.
        """
        out = {}
        for camera in self.cameras:
            self._renderer.update_scene(self.world.data, camera=camera)
            if shapes:
                add_to_scene(self._renderer.scene, list(shapes))
            out[camera] = self._renderer.render().copy()
        return out

    def close(self) -> None:
        """Free the renderer."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        closed(self)
