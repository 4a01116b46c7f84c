"""The schema of one sweep record (a line of ``records.jsonl``), checked when a sweep is resumed.

A record file is input like any other: a line edited by hand, or left by another build with the
same record version, must not end in a traceback when the tables are made from it. Each line is
checked against :class:`EpisodeRecord` (an episode that ran to a verdict) or :class:`ErrorRecord`
(one that stopped on an internal error): types are strict (``"3"`` is not a step count, ``1`` is
not ``true``), numbers finite and in range, and the id must name the episode its fields describe.
Fields this build does not know are kept (a later build's additions).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, Strict, StrictBool, StrictInt, StrictStr, ValidationError, model_validator

from agentchord.bench.sweep import RECORD_VERSION, Condition, is_error

#: A count (steps, calls, detections): a JSON integer, not below 0.
Count = Annotated[StrictInt, Field(ge=0)]
#: A duration (s): a finite JSON number, not below 0.
Seconds = Annotated[float, Strict(), Field(ge=0.0, allow_inf_nan=False)]
#: A disturbance probability: a finite JSON number in [0, 1].
Probability = Annotated[float, Strict(), Field(ge=0.0, le=1.0, allow_inf_nan=False)]


class _RecordKey(BaseModel):
    """The fields every record starts with: which episode it is, and how it ended."""

    model_config = ConfigDict(extra="allow", frozen=True)

    id: StrictStr
    version: Annotated[StrictInt, Field(ge=RECORD_VERSION, le=RECORD_VERSION)]
    task: StrictStr
    method: StrictStr
    condition: StrictStr
    p: Probability | None
    protocol: StrictStr | None
    seed: Count
    success: StrictBool
    reason: StrictStr
    wall_s: Seconds

    @model_validator(mode="after")
    def _names_its_episode(self) -> _RecordKey:
        if (self.p is None) == (self.protocol is None):
            raise ValueError("a record has either p (a drop sweep) or protocol (a protocol sweep), not both or neither")
        label = Condition(p=self.p or 0.0, protocol=self.protocol).label
        if self.condition != label:
            raise ValueError(f"condition {self.condition!r} does not match p/protocol ({label!r})")
        expected = f"{self.task}|{self.method}|{self.condition}|{self.seed}"
        if self.id != expected:
            raise ValueError(f"id {self.id!r} does not name the record's episode ({expected!r})")
        return self


class EpisodeRecord(_RecordKey):
    """An episode that ran to a verdict: DESIGN section 7's metrics and the reasoning calls."""

    steps: Count
    exec_time_s: Seconds
    robot_time_s: Seconds
    compute_s: Seconds
    reasoning_s: Seconds
    reasoning_calls: dict[StrictStr, Count]
    replans: Count
    failures_detected: Count
    recoveries: Count
    drops_injected: Count
    drops_detected: Count
    drops_recovered: Count
    #: Per disturbance kind: injected, detected, recovered.
    disturbances: dict[StrictStr, Annotated[list[Count], Field(min_length=3, max_length=3)]]
    reaction_latency_ticks: list[Count]
    reaction_latency_s: list[Seconds]
    unrecoverable: StrictBool
    path: list[StrictStr]
    disturbances_injected: Count
    # Pipelined planning (absent from records written before it: read as a robot that waited for every call).
    first_motion_s: Seconds | None = None
    critical_reasoning_s: Seconds | None = None
    plan_wait_s: Seconds = 0.0
    early_failures: list[dict[StrictStr, Any]] = Field(default_factory=list)


class ErrorRecord(_RecordKey):
    """An episode that stopped on an internal error (it runs again when the sweep is resumed)."""

    error: StrictStr
    traceback: StrictStr


class OutageRecord(_RecordKey):
    """An episode whose LLM could not be reached (it runs again when the sweep is resumed)."""

    error: StrictStr
    outage: Literal[True]


def check_record(record: Any) -> list[str]:
    """What is wrong with one parsed line of ``records.jsonl`` (empty when it is a valid record).

    Each problem names the field (``steps: Input should be a valid integer``).
    """
    if not isinstance(record, dict):
        return [f"expected a record object, found {type(record).__name__}"]
    model = (OutageRecord if record.get("outage") else ErrorRecord) if is_error(record) else EpisodeRecord
    try:
        model.model_validate(record)
    except ValidationError as error:
        return [_describe(detail) for detail in error.errors(include_url=False)]
    return []


def _describe(detail: Any) -> str:
    """``field: problem (got value)`` for one pydantic error."""
    where = ".".join(str(part) for part in detail["loc"]) or "(record)"
    if detail["type"] == "missing" or not detail["loc"]:
        return f"{where}: {detail['msg']}"
    return f"{where}: {detail['msg']} (got {str(repr(detail['input']))[:60]})"
