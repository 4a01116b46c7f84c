"""Offscreen rendering of episodes to video, with the graph state written on the frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from agentchord.worlds.sim.world import CONTROL_HZ, SimWorld


class VideoRecorder:
    """Collect frames of a world every few ticks and write an MP4.

    Args:
        world: The world to film.
        path: Output ``.mp4`` path.
        camera: Scene camera name.
        every: Film every ``every``-th control tick (2 -> 25 fps at 50 Hz).
        size: (width, height) in pixels.
    """

    def __init__(self, world: SimWorld, path: str | Path, camera: str = "front", every: int = 2, size: tuple[int, int] = (640, 480)) -> None:
        import mujoco  # noqa: PLC0415  (MUJOCO_GL is set by the package's __init__)

        self.world = world
        self.path = Path(path)
        self.camera = camera
        self.every = every
        self.renderer = mujoco.Renderer(world.model, height=size[1], width=size[0])
        self.frames: list[np.ndarray] = []
        self.caption = ""
        self.flash = ""
        self._flash_until = -1

    def capture(self, caption: str = "") -> None:
        """Render the current state if this tick is filmed."""
        if self.world.tick % self.every or self.renderer is None:
            return
        self.renderer.update_scene(self.world.data, camera=self.camera)
        image = self.renderer.render()
        self.frames.append(self._annotate(image, caption))

    def announce(self, text: str, ticks: int = 50) -> None:
        """Show a highlighted message (a failure, a recovery switch) for a while."""
        self.flash = text
        self._flash_until = self.world.tick + ticks

    def _annotate(self, image: np.ndarray, caption: str) -> np.ndarray:
        from PIL import Image, ImageDraw  # noqa: PLC0415  (pillow comes with imageio)

        canvas = Image.fromarray(image)
        draw = ImageDraw.Draw(canvas)
        draw.rectangle([0, 0, canvas.width, 22], fill=(0, 0, 0))
        draw.text((6, 5), f"t={self.world.tick / CONTROL_HZ:5.2f}s  {caption}", fill=(255, 255, 255))
        if self.world.tick < self._flash_until:
            draw.rectangle([0, canvas.height - 24, canvas.width, canvas.height], fill=(227, 119, 194))
            draw.text((6, canvas.height - 19), self.flash, fill=(0, 0, 0))
        return np.asarray(canvas)

    def write(self) -> Path:
        """Encode the collected frames as an MP4 (ffmpeg ships with imageio-ffmpeg)."""
        import imageio.v2 as imageio  # noqa: PLC0415

        self.path.parent.mkdir(parents=True, exist_ok=True)
        fps = CONTROL_HZ // self.every
        with imageio.get_writer(self.path, fps=fps, codec="libx264", quality=7, macro_block_size=8) as writer:
            for frame in self.frames:
                writer.append_data(frame)
        self.close()
        return self.path

    def close(self) -> None:
        """Release the renderer (its GL context); a second call does nothing.

        Called on an interrupted episode too: a renderer left to the interpreter's exit can
        fail there, after the command has already said why it stopped.
        """
        renderer, self.renderer = self.renderer, None
        if renderer is not None:
            renderer.close()
