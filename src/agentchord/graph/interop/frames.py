"""Frames: the rigid map from the release's robot frame to our world."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass


def round6(x: float) -> float:
    value = round(x, 6)
    return 0.0 if value == 0 else value




@dataclass(frozen=True)
class FrameMap:
    """A rigid map from the release's robot frame to our world: a turn about z, then a shift.

    Attributes:
        yaw_deg: Turn about z (deg).
        shift: Translation (m) added after the turn.
    """

    yaw_deg: float = 90.0
    shift: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def vector(self, v: Sequence[float]) -> tuple[float, float, float]:
        """A displacement in our frame (turned, not shifted)."""
        c, s = math.cos(math.radians(self.yaw_deg)), math.sin(math.radians(self.yaw_deg))
        x, y, z = (float(a) for a in v)
        return (round6(c * x - s * y), round6(s * x + c * y), round6(z))

    def point(self, p: Sequence[float]) -> tuple[float, float, float]:
        """A position in our frame."""
        x, y, z = self.vector(p)
        return (round6(x + self.shift[0]), round6(y + self.shift[1]), round6(z + self.shift[2]))

    @classmethod
    def parse(cls, text: str) -> FrameMap:
        """``aloha``, ``identity`` or ``yaw=DEG[,dx=M][,dy=M][,dz=M]``.

        Raises:
            ValueError: Anything else.
        """
        if text in FRAMES:
            return FRAMES[text]
        values = {"yaw": 0.0, "dx": 0.0, "dy": 0.0, "dz": 0.0}
        for part in filter(None, (p.strip() for p in text.split(","))):
            key, sep, value = part.partition("=")
            if not sep or key.strip() not in values:
                raise ValueError(
                    f"bad frame {text!r}: use {', '.join(FRAMES)} or yaw=DEG,dx=M,dy=M,dz=M (got {part!r})"
                )
            try:
                values[key.strip()] = float(value)
            except ValueError:
                raise ValueError(f"bad frame {text!r}: {key.strip()} is not a number ({value!r})") from None
        return cls(values["yaw"], (values["dx"], values["dy"], values["dz"]))


#: Named frames: ``aloha`` (release x forward, y left -> our +y, -x) and ``identity``.
FRAMES = {"aloha": FrameMap(90.0), "identity": FrameMap(0.0)}
