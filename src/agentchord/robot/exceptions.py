"""Errors of the robot's description."""


class RobotModelError(Exception):
    """The robot's kinematic model could not be built (missing assets, a model that does not compile)."""
