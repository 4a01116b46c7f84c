"""The atomic action catalogue, re-exported: it lives in :mod:`agentchord.graph.catalog`,
the graph's vocabulary, below both the graph's checks and the action programs."""

from agentchord.graph.catalog import (  # noqa: F401
    ACTIONS,
    ActionSpec,
    GraspArgs,
    InsertArgs,
    MoveByOffsetArgs,
    MoveToObjArgs,
    MoveToTargetArgs,
    NoArgs,
    PlaceArgs,
    RotateEefArgs,
)
