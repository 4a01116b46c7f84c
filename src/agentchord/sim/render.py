"""Offscreen rendering of episodes to video, with the graph state and the disturbances shown on the frames.

A disturbance is drawn where it acts (:mod:`agentchord.sim.markers`: a person's hand
carrying a pulled object, a finger pushing or knocking one), into the renderer's scene only,
and named in an orange banner while it acts.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from agentchord.sim.markers import KIND, WHAT, DisturbanceMarkers, add_to_scene
from agentchord.sim.renderers import open_renderer
from agentchord.sim.world import CONTROL_HZ, SimWorld

#: The disturbance announcements of ``agentchord run --video`` (``DISTURBANCE: kind obj``): they name the kind.
_ANNOUNCED = re.compile(r"DISTURBANCE: (?P<kind>\S+) (?P<obj>\S+)")
DISTURBANCE_RGBA = (255, 140, 0)


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
        self.world = world
        self.path = Path(path)
        self.camera = camera
        self.every = every
        self.renderer = open_renderer(world.model, height=size[1], width=size[0])
        self.frames: list[np.ndarray] = []
        self.caption = ""
        self.flash = ""
        self._flash_until = -1
        self.markers = DisturbanceMarkers(world)
        self._named: dict[str, str] = {}  # object -> the kind of disturbance announced on it

    def capture(self, caption: str = "") -> None:
        """Render the current state if this tick is filmed (call every tick: disturbances are followed)."""
        self.markers.update()
        if self.world.tick % self.every or self.renderer is None:
            return
        self.renderer.update_scene(self.world.data, camera=self.camera)
        add_to_scene(self.renderer.scene, self.markers.shapes())
        image = self.renderer.render()
        self.frames.append(self._annotate(image, caption))

    def final(self, caption: str, outcome: str, seconds: float = 1.5) -> None:
        """The last frame, whatever the tick: the node the episode ended at and its outcome, held for
        ``seconds`` (the frames filmed before it show the node the arms were leaving)."""
        if self.renderer is None:
            return
        self.markers.update()
        self.renderer.update_scene(self.world.data, camera=self.camera)
        add_to_scene(self.renderer.scene, self.markers.shapes())
        self.flash, self._flash_until = outcome, self.world.tick + 1
        frame = self._annotate(self.renderer.render(), caption)
        self.frames += [frame] * max(1, round(seconds * CONTROL_HZ / self.every))

    def announce(self, text: str, ticks: int = 50) -> None:
        """Show a highlighted message (a failure, a recovery switch) for a while.

        A disturbance's announcement (``DISTURBANCE: kind obj``) also names the disturbance
        whose marker the frames show while it acts.
        """
        self.flash = text
        self._flash_until = self.world.tick + ticks
        if match := _ANNOUNCED.match(text):
            self.disturbed(match["kind"], match["obj"])

    def disturbed(self, kind: str, obj: str) -> None:
        """Name the disturbance on ``obj`` (``pull``, ``perturb``, ...) for the banner while it acts."""
        self._named[obj] = kind

    def disturbance_banner(self) -> str:
        """What the disturbance banner says now ("" when no disturbance is shown).

        As long as its marker shows: while it acts, and the moment after (a push of 0.1 s
        would be named on two or three frames).
        """
        return "   ".join(
            f"DISTURBANCE: {self._named.get(m.obj, KIND[m.kind])} {m.obj} ({WHAT[m.kind]})" for m in self.markers.markers
        )

    def _annotate(self, image: np.ndarray, caption: str) -> np.ndarray:
        from PIL import Image, ImageDraw  # pillow comes with imageio

        canvas = Image.fromarray(image)
        draw = ImageDraw.Draw(canvas)
        draw.rectangle([0, 0, canvas.width, 22], fill=(0, 0, 0))
        draw.text((6, 5), f"t={self.world.tick / CONTROL_HZ:5.2f}s  {caption}", fill=(255, 255, 255))
        if banner := self.disturbance_banner():
            draw.rectangle([0, 22, canvas.width, 44], fill=DISTURBANCE_RGBA)
            draw.text((6, 27), banner, fill=(0, 0, 0))
        if self.world.tick < self._flash_until:
            draw.rectangle([0, canvas.height - 24, canvas.width, canvas.height], fill=(227, 119, 194))
            draw.text((6, canvas.height - 19), self.flash, fill=(0, 0, 0))
        return np.asarray(canvas)

    def write(self) -> Path:
        """Encode the collected frames as an MP4 (ffmpeg ships with imageio-ffmpeg)."""
        import imageio.v2 as imageio

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
