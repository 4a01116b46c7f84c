"""Errors of the MuJoCo world."""


class SimError(Exception):
    """Base class of the simulator's errors."""


class SceneError(SimError):
    """The scene could not be built (missing assets, a model that does not compile)."""


class UnknownObjectError(SimError, KeyError):
    """An action or expression named an object the scene does not have."""
