"""A benchmark sweep: tasks x methods x conditions x seeds, one record per episode.

A condition is either a drop probability (``p=0.05``, the paper's Table I) or a disturbance
protocol (``protocol=real``, Table II). Every episode of a sweep is named by its key
``task|method|condition|seed``; records are written under that key, so a sweep that is
run again skips what it already has (:mod:`agentchord.bench.store`).
"""

from __future__ import annotations

import time
import traceback
from dataclasses import dataclass, field

from agentchord.agents.exceptions import ReasonerTransportError
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.reasoning import ReasoningConfig
from agentchord.harness import DisturbanceSetting

#: Version of the record layout (a record names it; a reader refuses another).
RECORD_VERSION = 1


@dataclass(frozen=True)
class Condition:
    """How an episode is disturbed: random drops with probability ``p``, or a protocol preset.

    Attributes:
        p: Drop probability per atomic action (ignored under a protocol).
        protocol: ``real`` or ``stress`` (1-2 disturbances per trial), or None.
    """

    p: float = 0.0
    protocol: str | None = None

    def __post_init__(self) -> None:
        # One value, one condition: -0 is 0 (a label "p=-0" would be a sweep of its own).
        object.__setattr__(self, "p", float(self.p) + 0.0)

    @property
    def label(self) -> str:
        """``p=0.05`` or ``protocol=real``: the condition part of a record's key.

        Short (``%g``) where that names the value exactly, its full repr where not: two
        probabilities that differ in the seventh digit never share a label.
        """
        if self.protocol:
            return f"protocol={self.protocol}"
        short = f"{self.p:g}"
        return f"p={short}" if float(short) == self.p else f"p={self.p!r}"

    @property
    def setting(self) -> DisturbanceSetting:
        """The disturbance setting it stands for (drops at ``p``, or the protocol preset's kinds)."""
        return DisturbanceSetting.from_options(p=0.0 if self.protocol else self.p, protocol=self.protocol)

    @classmethod
    def from_label(cls, label: str) -> Condition:
        """The condition a label names (the inverse of :attr:`label`)."""
        kind, _, value = label.partition("=")
        return cls(protocol=value) if kind == "protocol" else cls(p=float(value))


@dataclass(frozen=True)
class EpisodeKey:
    """One episode of a sweep."""

    task: str
    method: str
    condition: Condition
    seed: int

    @property
    def id(self) -> str:
        """``task|method|condition|seed``: unique within a sweep."""
        return f"{self.task}|{self.method}|{self.condition.label}|{self.seed}"


@dataclass(frozen=True)
class SweepConfig:
    """What a sweep's records depend on besides their keys: a resumed sweep must match it.

    Attributes:
        reasoning: The latency model, the simulated VQA's error rates, DoReMi's period.
        perception: ``oracle`` or ``rgbd`` features.
        reasoner: ``rules``: every method runs the task library's graph and each planning call is
            charged the modelled latency; ``llm``: every method plans from the task's instruction
            with the LLM of ``AGENTCHORD_LLM_*`` at the episode's start (re-plans too), and each
            planning call is charged the latency it measured.
        llm: With ``reasoner`` ``llm``: the model and the endpoint (credentials masked) that answer, so that
            a sweep resumed with another model is refused and every caption names the model.
    """

    reasoning: ReasoningConfig = field(default_factory=ReasoningConfig)
    perception: str = "oracle"
    reasoner: str = "rules"
    llm: dict[str, str] | None = None

    def to_dict(self) -> dict:
        """JSON-ready (the sweep's manifest)."""
        out = {"record_version": RECORD_VERSION, "reasoning": self.reasoning.to_dict(), "perception": self.perception,
               "reasoner": self.reasoner}
        if self.llm is not None:
            out["llm"] = dict(self.llm)
        return out

    @classmethod
    def from_dict(cls, data: dict) -> SweepConfig:
        """The config a manifest holds."""
        return cls(reasoning=ReasoningConfig.from_dict(data["reasoning"]), perception=data["perception"],
                   reasoner=data.get("reasoner", "rules"), llm=data.get("llm"))


def sweep_keys(tasks: list[str], methods: list[str], conditions: list[Condition], trials: int, first_seed: int = 0) -> list[EpisodeKey]:
    """Every episode of a sweep, seeds innermost (the same seeds for every method: paired).

    A task, method or condition named twice is run, and counted, once.
    """
    tasks, methods, conditions = list(dict.fromkeys(tasks)), list(dict.fromkeys(methods)), list(dict.fromkeys(conditions))
    return [
        EpisodeKey(task, method, condition, seed)
        for condition in conditions for task in tasks for method in methods
        for seed in range(first_seed, first_seed + trials)
    ]


def episode_spec(key: EpisodeKey, config: SweepConfig) -> EpisodeSpec:
    """The episode a key names, under the sweep's config."""
    from agentchord.library import load_task_graph

    condition = key.condition
    # With an LLM the plan is made (and timed) in the episode, from the instruction of the graph
    # the rules run; the rules' graph is the task library's (their calls are modelled).
    instruction = load_task_graph(key.task).instruction if config.reasoner == "llm" else None
    # An outage is an error to rerun, for every method alike: no offline arranger stands in for the LLM.
    return EpisodeSpec(
        task=key.task, strategy=key.method, seed=key.seed, disturbances=condition.setting,
        perception=config.perception, reasoning=config.reasoning,
        instruction=instruction, reasoner=config.reasoner, arranger_fallback=False,
    )


def _key_fields(key: EpisodeKey) -> dict:
    """The fields every record starts with: what episode it is."""
    return {
        "id": key.id,
        "version": RECORD_VERSION,
        "task": key.task,
        "method": key.method,
        "condition": key.condition.label,
        "p": key.condition.p if key.condition.protocol is None else None,
        "protocol": key.condition.protocol,
        "seed": key.seed,
    }


def run_record(key: EpisodeKey, config: SweepConfig) -> dict:
    """Run one episode and return its record (DESIGN section 7's metrics and the reasoning calls).

    An episode that stops on an unexpected exception returns an :func:`error_record` instead:
    one bug must not end a sweep of hundreds of episodes (records are rows, not crashes).
    """
    started = time.perf_counter()
    try:
        result = run_episode(episode_spec(key, config))
    except ReasonerTransportError as error:  # the plan before the first motion met an outage
        return outage_record(key, f"{type(error).__name__}: {error.headline}", time.perf_counter() - started)
    except Exception as error:  # recorded with its traceback; the sweep goes on
        return error_record(key, error, time.perf_counter() - started)
    outage = next((e["error"] for e in result.trace.of("plan_replied") if e.get("outage")), None)
    if outage is not None:  # the plan in the background met one while the robot moved
        return outage_record(key, outage, time.perf_counter() - started)
    summary = result.summary()
    injected = sum(counts[0] for counts in summary["disturbances"].values())
    return {
        **_key_fields(key),
        **{name: summary[name] for name in (
            "success", "reason", "steps", "exec_time_s", "robot_time_s", "compute_s", "reasoning_s", "reasoning_calls",
            "replans", "failures_detected", "recoveries", "drops_injected", "drops_detected", "drops_recovered",
            "disturbances", "reaction_latency_ticks", "reaction_latency_s", "unrecoverable", "path",
            "first_motion_s", "critical_reasoning_s", "plan_wait_s", "early_failures")},
        "disturbances_injected": injected,
        "wall_s": round(time.perf_counter() - started, 3),
    }


def error_record(key: EpisodeKey, error: BaseException, wall_s: float) -> dict:
    """The record of an episode that stopped on an internal error: a bug to fix, not a result.

    It has no metrics: the tables leave it out (neither a success nor a failure of the method),
    the sweep says how many there were, and a rerun with the same ``--out`` runs it again.
    """
    message = f"{type(error).__name__}: {error}"
    return {
        **_key_fields(key),
        "success": False,
        "reason": f"internal error: {message}",
        "error": message,
        "traceback": "".join(traceback.format_exception(type(error), error, error.__traceback__)),
        "wall_s": round(wall_s, 3),
    }


def outage_record(key: EpisodeKey, error: str, wall_s: float) -> dict:
    """The record of an episode whose LLM could not be reached (an outage): neither a success nor a failure
    of the method. Every method's outage is this record, whether it met it before the first motion (a
    sequential plan) or while the robot moved (a pipelined one); the tables leave it out and a rerun with
    the same ``--out`` runs it again."""
    return {
        **_key_fields(key),
        "success": False,
        "reason": f"LLM outage: {error}",
        "error": f"LLM outage: {error}",
        "outage": True,
        "wall_s": round(wall_s, 3),
    }


def is_outage(record: dict) -> bool:
    """Whether a record is an :func:`outage_record`."""
    return bool(record.get("outage"))


def is_error(record: dict) -> bool:
    """Whether a record is an :func:`error_record` (the episode did not run to a verdict)."""
    return "error" in record


def describe(config: SweepConfig) -> str:
    """One line for every table's caption: the latency model and the VQA's error rates."""
    reasoning = config.reasoning
    if config.reasoner == "llm":
        model = f" {config.llm['model']} at {config.llm['endpoint']}" if config.llm else ""
        latency = (f"planning calls measured (LLM reasoner{model}), VQA {reasoning.latency.of('vqa'):g} s and VLM "
                   f"{reasoning.latency.of('vlm'):g} s per call modelled (see docs/results.md)")
    else:
        latency = f"reasoning latency per call: {reasoning.latency.describe()} (modelled; see docs/results.md)"
    return (f"{latency}; "
            f"VQA miss {reasoning.vqa_miss:g}, false alarm {reasoning.vqa_false_alarm:g}; "
            f"DoReMi query every {reasoning.doremi_every} ticks; perception {config.perception}")
