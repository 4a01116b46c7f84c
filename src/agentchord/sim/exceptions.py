"""Errors of the MuJoCo world."""

from agentchord.guard.exceptions import InputError



class SimError(Exception):
    """Base class of the simulator's errors."""


class SceneError(SimError):
    """The scene could not be built (missing assets, a model that does not compile)."""


class SceneSpecError(SceneError, InputError):
    """An object of a scene is written wrong (an unknown shape, the wrong number of sizes, a size or
    mass out of range): the scene's author's error, reported as bad input."""


class UnknownObjectError(SimError, KeyError):
    """An action or expression named an object the scene does not have."""


class TaskPluginError(InputError):
    """A task module outside the package (``AGENTCHORD_TASKS``, an ``agentchord.tasks`` entry point)
    cannot be loaded: a missing file, an import that fails, no ``TASK``, or a name already taken."""
