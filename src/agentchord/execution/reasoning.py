"""What reasoning costs: the per-call latency model and the simulated VQA's error rates.

Every method compared in the benchmark calls a reasoner (a planning LLM) or a VQA model
(a VLM answering yes/no about an image) at some moments. Offline, the rules reasoner and
the ground-truth VQA answer in milliseconds, so each call is charged a stated latency:
the median of published measurements of GPT-4o-class calls of that kind (see
docs/results.md, "Reasoning latency", for the sources). With ``--reasoner llm`` a
planning call that is actually made is charged what it measured.

Execution time = robot time (control ticks at 50 Hz) + measured compute (the planner's
own work in this process) + reasoning latency (modelled, or measured for a real LLM).
Calls block: the robot holds still while a model answers (the world is not stepped).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields

#: Call kinds and what each stands for.
CALL_KINDS = {
    "plan": "a text planning call (task plan or re-plan as JSON, ~600-1000 output tokens)",
    "vqa": "a VQA success/constraint query (one image, yes/no and a short reason)",
    "vlm": "a VLM call with images writing constraints or monitor code (CoT/JSON, ~250 output tokens)",
}


@dataclass(frozen=True)
class LatencyModel:
    """Seconds charged per reasoning call, by kind.

    Defaults are medians from published measurements (docs/results.md cites them):
    ``plan`` 7.0 s = 0.45 s to first token + 800 tokens at 120 tokens/s (GPT-4o, Artificial
    Analysis medians); ``vqa`` 1.5 s (one image, a yes/no answer: GPT-4o-mini/4o time to first
    token 0.4-0.65 s plus image encoding); ``vlm`` 3.5 s (one image and a chain-of-thought JSON
    reply: PragmaBot's published traces, 3.42 s and 4.11 s per call).
    """

    plan: float = 7.0
    vqa: float = 1.5
    vlm: float = 3.5

    def of(self, kind: str) -> float:
        """The latency of one call of ``kind``."""
        return float(getattr(self, kind))

    def describe(self) -> str:
        """One line for a table's caption."""
        return ", ".join(f"{f.name} {getattr(self, f.name):g} s" for f in fields(self))

    @classmethod
    def parse(cls, text: str) -> LatencyModel:
        """``plan=7,vqa=1.5`` (kinds not named keep their defaults).

        Raises:
            ValueError: An unknown kind, a value that is not a finite number >= 0.
        """
        values: dict[str, float] = {}
        for part in (p.strip() for p in text.split(",") if p.strip()):
            name, sep, value = part.partition("=")
            name = name.strip()
            if not sep or name not in CALL_KINDS:
                raise ValueError(f"expected KIND=SECONDS with KIND one of {', '.join(CALL_KINDS)}, got {part!r}")
            try:
                seconds = float(value)
            except ValueError:
                raise ValueError(f"{name}: {value!r} is not a number") from None
            if not 0.0 <= seconds < 1e6:
                raise ValueError(f"{name}: {value!r} is not a latency in seconds (0 to 1e6)")
            values[name] = seconds
        return cls(**values)


@dataclass(frozen=True)
class ReasoningConfig:
    """How the compared methods reason: latencies, the simulated VQA, DoReMi's query period.

    Attributes:
        latency: Seconds per call, by kind.
        vqa_miss: Probability that a VQA query answers "succeeded / holds" about a failure
            (a false negative of the failure detector).
        vqa_false_alarm: Probability that it answers "failed / violated" about a success
            (a false positive).
        doremi_every: DoReMi's query period in control ticks during motion (75 ticks = 1.5 s at
            50 Hz: a blocking query cannot be issued more often than it takes to answer; the
            DoReMi paper states no period).
        max_replans: Re-plans one episode may make before it ends as a failure.
    """

    latency: LatencyModel = field(default_factory=LatencyModel)
    vqa_miss: float = 0.0
    vqa_false_alarm: float = 0.0
    doremi_every: int = 75
    max_replans: int = 8

    def __post_init__(self) -> None:
        for name in ("vqa_miss", "vqa_false_alarm"):
            value = getattr(self, name)
            if not 0.0 <= value <= 1.0:
                raise ValueError(f"{name} must be a probability in [0, 1], got {value!r}")
        if self.doremi_every < 1:
            raise ValueError(f"doremi_every must be >= 1 tick, got {self.doremi_every!r}")

    def to_dict(self) -> dict:
        """JSON-ready (records and table captions)."""
        return asdict(self)


def charge_calls(executor, config: ReasoningConfig, roles: dict[str, str], calls=(), wall_s: float | None = None) -> None:
    """Charge the calls a method makes for one planning step, by the roles it has.

    Args:
        executor: Where to charge (:meth:`~agentchord.execution.executor.Executor.charge`).
        config: The latency model.
        roles: Agent -> call kind, the calls this method makes (``{"composer": "plan"}`` for a
            planner that writes the plan and its constraints in one call).
        calls: The reasoner calls actually made (:class:`~agentchord.agents.reasoner.ReasonerCall`);
            an LLM call of a role is charged what it measured, any other role its modelled latency.
        wall_s: Wall time of the whole planning step, if measured here: what the LLM calls did not
            take of it is compute (the offline planner's work, the conductor's solver).
    """
    made: dict[str, object] = {}
    for call in calls:
        made.setdefault(call.agent, call)
    llm_s = sum(c.latency_s for c in calls if c.reasoner != "rules")
    rules_s = sum(c.latency_s for c in calls if c.reasoner == "rules")
    compute = max(wall_s - llm_s, 0.0) if wall_s is not None else rules_s
    for k, (agent, kind) in enumerate(roles.items()):
        call = made.get(agent)
        measured = call is not None and call.reasoner != "rules"
        latency = call.latency_s if measured else config.latency.of(kind)
        executor.charge(kind, agent, latency, measured=measured, compute_s=compute if k == 0 else 0.0)
