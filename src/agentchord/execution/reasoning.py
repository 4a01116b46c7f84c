"""What reasoning costs: the per-call latency model and the simulated VQA's error rates.

Every method compared in the benchmark calls a reasoner (a planning LLM) or a VQA model
(a VLM answering yes/no about an image) at some moments. Offline, the rules reasoner and
the ground-truth VQA answer in milliseconds, so each call is charged a modelled latency:
by default priced by what it writes (time to first token + output tokens / decode rate + image
encoding, :class:`TokenLatencyModel`), or a flat constant per kind (:class:`LatencyModel`), the
medians of published measurements of GPT-4o-class calls (docs/results.md, "Reasoning latency",
cites them). With ``--reasoner llm`` a planning call that is actually made is charged what it
measured.

Execution time = robot time (control ticks at 50 Hz) + measured compute (the planner's
own work in this process) + the reasoning latency the robot waited for. A blocking call holds
the robot still (the world is not stepped while it answers); the calls of AgentChord's pipelined
plan that arrive while the robot moves (:mod:`agentchord.execution.planning`) cost only the
ticks the robot waits for one of them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, fields
from typing import TYPE_CHECKING, Any, ClassVar

if TYPE_CHECKING:
    from agentchord.agents.reasoner import ReasonerCall

#: Call kinds and what each stands for.
CALL_KINDS = {
    "plan": "a text planning call (task plan or re-plan as JSON, ~600-1000 output tokens)",
    "vqa": "a VQA success/constraint query (one image, yes/no and a short reason)",
    "vlm": "a VLM call with images writing constraints or monitor code (CoT/JSON, ~250 output tokens)",
}
#: Output tokens of a VQA answer: a yes/no and a short reason (``{"answer":"no","reason":"..."}``).
VQA_REPLY_TOKENS = 20
#: Output tokens of the reference planning call of the flat model's ``plan`` (0.45 s + 800 / 120 tokens/s).
REFERENCE_PLAN_TOKENS = 800


@dataclass(frozen=True)
class ModelledCall:
    """One reasoning call as the latency model prices it: who asks, what kind, what it writes.

    Attributes:
        agent: Who asks (``composer``, ``arranger``, ``conductor``, ``vqa``, ...).
        kind: A key of :data:`CALL_KINDS`.
        tokens: Output tokens of its reply (:mod:`agentchord.agents.replies`).
        images: Camera images it sends (each one encoded before the first token).
        part: What it writes, for the trace (``nominal graph``, ``e2 branches``).
    """

    agent: str
    kind: str
    tokens: int = 0
    images: int = 0
    part: str = ""


@dataclass(frozen=True)
class LatencyModel:
    """Seconds charged per reasoning call, by kind, whatever it writes (the flat model).

    Defaults are medians from published measurements (docs/results.md cites them):
    ``plan`` 7.0 s = 0.45 s to first token + 800 tokens at 120 tokens/s (GPT-4o, Artificial
    Analysis medians); ``vqa`` 1.5 s (one image, a yes/no answer: GPT-4o-mini/4o time to first
    token 0.4-0.65 s plus image encoding); ``vlm`` 3.5 s (one image and a chain-of-thought JSON
    reply: PragmaBot's published traces, 3.42 s and 4.11 s per call). ``--latency plan=7,...``
    selects it: the tables before the token-priced model are reproduced with it.
    """

    plan: float = 7.0
    vqa: float = 1.5
    vlm: float = 3.5
    #: A reply arrives whole: nothing can be read from it before its call ends.
    streams: ClassVar[bool] = False
    #: Calls the model serves at once (a pipelined plan's per-edge calls overlap up to this many).
    concurrency: ClassVar[int] = 4

    def of(self, kind: str) -> float:
        """The latency of one call of ``kind``."""
        return float(getattr(self, kind))

    def price(self, call: ModelledCall) -> float:
        """Seconds ``call`` takes: its kind's constant."""
        return self.of(call.kind)

    def first_token_s(self, call: ModelledCall) -> float:
        """Seconds before the first output token (a flat call has none before its end)."""
        return self.price(call)

    def decode_s(self, tokens: int) -> float:
        """Seconds to write ``tokens`` once the first token is out (nothing: the reply comes whole)."""
        return 0.0

    @property
    def reference_plan_s(self) -> float:
        """The latency of a reference planning call (the crossings of ``tables/latency.md`` are in it)."""
        return self.plan

    def describe(self) -> str:
        """One line for a table's caption."""
        return ", ".join(f"{f.name} {getattr(self, f.name):g} s" for f in fields(self))

    def to_dict(self) -> dict:
        """JSON-ready (a sweep's manifest): the fields and the model's name."""
        return {"model": "flat", **asdict(self)}

    @classmethod
    def parse(cls, text: str) -> LatencyModel:
        """``plan=7,vqa=1.5`` (kinds not named keep their defaults).

        Raises:
            ValueError: An unknown kind, a value that is not a finite number >= 0.
        """
        return cls(**_parse_pairs(text, {name: (0.0, 1e6) for name in CALL_KINDS}))


@dataclass(frozen=True)
class TokenLatencyModel:
    """Seconds per call priced by what it writes: time to first token + output tokens / decode rate.

    ``+ image_s`` per image the call sends (encoded before the first token). Defaults: GPT-4o medians
    (Artificial Analysis: 0.39-0.45 s to first token, 81-131 tokens/s; 120 tokens/s is the rate the
    flat ``plan`` 7 s assumes); an image costs 0.9 s, which puts a VQA answer (20 tokens) at the flat
    model's 1.5 s and a 250-token chain-of-thought VLM reply at 3.5 s (PragmaBot's 3.42-4.11 s).
    A reply streams: a part of it can be read as soon as the tokens before its end are written.

    Attributes:
        ttft_s: Seconds to the first output token.
        tokens_per_s: Output tokens per second once the reply streams.
        image_s: Seconds per image sent (encoding, before the first token).
        concurrency: Calls the model serves at once; more wait for a free one.
    """

    ttft_s: float = 0.45
    tokens_per_s: float = 120.0
    image_s: float = 0.9
    concurrency: int = 4
    streams: ClassVar[bool] = True

    def __post_init__(self) -> None:
        if not (math.isfinite(self.tokens_per_s) and self.tokens_per_s > 0):
            raise ValueError(f"tokens_per_s must be a finite number > 0, got {self.tokens_per_s!r}")
        if not 1 <= self.concurrency <= 1000:
            raise ValueError(f"concurrency must be a whole number from 1 to 1000, got {self.concurrency!r}")

    def first_token_s(self, call: ModelledCall) -> float:
        """Seconds before ``call``'s first output token: time to first token and its images."""
        return self.ttft_s + self.image_s * call.images

    def decode_s(self, tokens: int) -> float:
        """Seconds to write ``tokens`` once the first token is out."""
        return tokens / self.tokens_per_s

    def price(self, call: ModelledCall) -> float:
        """Seconds ``call`` takes, first token to last."""
        return self.first_token_s(call) + self.decode_s(call.tokens)

    def of(self, kind: str) -> float:
        """A typical call of ``kind`` (a reference plan, a VQA answer, a 250-token VLM reply)."""
        tokens = {"plan": REFERENCE_PLAN_TOKENS, "vqa": VQA_REPLY_TOKENS, "vlm": 250}[kind]
        return self.price(ModelledCall(kind, kind, tokens, images=0 if kind == "plan" else 1))

    @property
    def reference_plan_s(self) -> float:
        """The latency of a reference planning call (800 output tokens, no image)."""
        return self.of("plan")

    def describe(self) -> str:
        """One line for a table's caption."""
        return (f"token-priced: {self.ttft_s:g} s to first token + output tokens / {self.tokens_per_s:g} per s "
                f"+ {self.image_s:g} s per image, {self.concurrency} calls at once")

    def to_dict(self) -> dict:
        """JSON-ready (a sweep's manifest): the fields and the model's name."""
        return {"model": "tokens", **asdict(self)}

    @classmethod
    def parse(cls, text: str) -> TokenLatencyModel:
        """``tokens`` or ``ttft=0.45,rate=120,image=0.9,concurrency=4`` (names not given keep their defaults).

        Raises:
            ValueError: An unknown name, a value that is not a finite number in range.
        """
        text = text.strip()
        if text == "tokens" or text.startswith("tokens,"):
            text = text[len("tokens"):].lstrip(",")
        values = _parse_pairs(text, {"ttft": (0.0, 1e4), "rate": (1e-3, 1e7), "image": (0.0, 1e4), "concurrency": (1, 1000)})
        renamed = {"ttft": "ttft_s", "rate": "tokens_per_s", "image": "image_s"}
        out: dict[str, Any] = {renamed.get(k, k): v for k, v in values.items()}
        if "concurrency" in out:
            if out["concurrency"] != int(out["concurrency"]):
                raise ValueError(f"concurrency: {out['concurrency']!r} is not a whole number")
            out["concurrency"] = int(out["concurrency"])
        return cls(**out)


AnyLatencyModel = LatencyModel | TokenLatencyModel


def parse_latency(text: str) -> AnyLatencyModel:
    """The latency model ``--latency`` names: flat (``plan=7,vqa=1.5,vlm=3.5``) or token-priced
    (``tokens``, ``ttft=0.45,rate=120,image=0.9,concurrency=4``).

    Raises:
        ValueError: Names of both models, an unknown name, a value out of range.
    """
    names = {part.partition("=")[0].strip() for part in text.split(",") if part.strip()}
    flat = names & set(CALL_KINDS)
    if flat and names - set(CALL_KINDS):
        raise ValueError(f"either per-kind seconds ({', '.join(CALL_KINDS)}) or the token-priced model's "
                         f"tokens, ttft, rate, image, concurrency, not both: {text!r}")
    return LatencyModel.parse(text) if flat else TokenLatencyModel.parse(text)


def latency_from_dict(data: dict) -> AnyLatencyModel:
    """The latency model a manifest holds (one written before the token model is flat)."""
    data = dict(data)
    model = data.pop("model", "flat")
    return TokenLatencyModel(**data) if model == "tokens" else LatencyModel(**data)


def _parse_pairs(text: str, ranges: dict[str, tuple[float, float]]) -> dict[str, float]:
    """``NAME=NUMBER,...`` with each name one of ``ranges`` and its value finite and in range."""
    values: dict[str, float] = {}
    for part in (p.strip() for p in text.split(",") if p.strip()):
        name, sep, value = part.partition("=")
        name = name.strip()
        if not sep or name not in ranges:
            raise ValueError(f"expected NAME=NUMBER with NAME one of {', '.join(ranges)}, got {part!r}")
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"{name}: {value!r} is not a number") from None
        low, high = ranges[name]
        if not (math.isfinite(number) and low <= number < high):
            raise ValueError(f"{name}: {value!r} is out of range ({low:g} to {high:g})")
        values[name] = number
    return values


@dataclass(frozen=True)
class ReasoningConfig:
    """How the compared methods reason: latencies, the simulated VQA, DoReMi's query period.

    Attributes:
        latency: Seconds per call: token-priced (the default) or flat per kind.
        vqa_miss: Probability that a VQA query answers "succeeded / holds" about a failure
            (a false negative of the failure detector).
        vqa_false_alarm: Probability that it answers "failed / violated" about a success
            (a false positive).
        doremi_every: DoReMi's query period in control ticks during motion (75 ticks = 1.5 s at
            50 Hz: a blocking query cannot be issued more often than it takes to answer; the
            DoReMi paper states no period).
        max_replans: Re-plans one episode may make before it ends as a failure.
    """

    latency: AnyLatencyModel = field(default_factory=TokenLatencyModel)
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
        return {**asdict(self), "latency": self.latency.to_dict()}

    @classmethod
    def from_dict(cls, data: dict) -> ReasoningConfig:
        """The config :meth:`to_dict` wrote."""
        return cls(**{**data, "latency": latency_from_dict(data["latency"])})


def charge_calls(executor, config: ReasoningConfig, modelled: list[ModelledCall], calls: Sequence[ReasonerCall] = (),
                 wall_s: float | None = None) -> None:
    """Charge the calls a method makes for one planning step; the robot holds still meanwhile.

    Args:
        executor: Where to charge (:meth:`~agentchord.execution.executor.Executor.charge`).
        config: The latency model.
        modelled: The calls this method makes, each with what it writes (a planner that writes the
            plan and its constraints in one call makes one).
        calls: The reasoner calls actually made (:class:`~agentchord.agents.reasoner.ReasonerCall`);
            an LLM call of an agent is charged what it measured, any other its modelled latency.
        wall_s: Wall time of the whole planning step, if measured here: what the LLM calls did not
            take of it is compute (the offline planner's work, the conductor's solver).
    """
    made: dict[str, ReasonerCall] = {}
    for made_call in calls:
        made.setdefault(made_call.agent, made_call)
    llm_s = sum(c.latency_s for c in calls if c.reasoner != "rules")
    rules_s = sum(c.latency_s for c in calls if c.reasoner == "rules")
    compute = max(wall_s - llm_s, 0.0) if wall_s is not None else rules_s
    for k, call in enumerate(modelled):
        found = made.get(call.agent)
        measured = found is not None and found.reasoner != "rules"
        latency = found.latency_s if found is not None and measured else config.latency.price(call)
        executor.charge(call.kind, call.agent, latency, measured=measured, compute_s=compute if k == 0 else 0.0,
                        tokens=None if measured else call.tokens)
