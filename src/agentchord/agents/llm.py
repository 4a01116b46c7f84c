"""A reasoner over any OpenAI-compatible chat-completions endpoint.

:class:`LlmReasoner` talks to OpenAI, Gemini's OpenAI-compatible endpoint, vLLM,
Ollama or a llama.cpp server through the official ``openai`` client. It asks
for the task graph as structured output (the JSON Schema of
:class:`~agentchord.graph.models.TaskGraph`), validates every reply (the schema,
then :func:`~agentchord.agents.reasoner.check_reply`: the semantic checks of
``graph check`` and the agent's own), and sends the problems of an invalid reply
back to the model for repair, at most ``max_repairs`` times. Transport failures
(connection errors, timeouts, HTTP 408/409/429/5xx) are retried with exponential
back-off by its own loop (the client's retries are off). Every call is recorded
as a :class:`~agentchord.agents.reasoner.ReasonerCall`.

Nothing an endpoint does can hang a plan: each request has a wall-clock limit
(``timeout_s``; the HTTP client's own timeout is per read, so a server that drips
its reply byte by byte would never trip it), each agent call a total deadline
(``deadline_s``: retries, back-off and repairs included), and a reply longer than
``max_reply_chars`` is refused without being copied into the repair request.

Configuration comes from the environment or from arguments::

    AGENTCHORD_LLM_BASE_URL=http://127.0.0.1:11434/v1  # Ollama; vLLM: http://HOST:8000/v1
    AGENTCHORD_LLM_MODEL=qwen2.5:14b
    AGENTCHORD_LLM_API_KEY=none                         # local servers accept any value
    AGENTCHORD_LLM_TIMEOUT_S=120                        # optional: wall-clock limit of one request
    AGENTCHORD_LLM_DEADLINE_S=600                       # optional: limit of one agent call, repairs included
    AGENTCHORD_LLM_MAX_REPLY_CHARS=1000000              # optional: longest reply accepted

    reasoner = LlmReasoner()                            # or LlmReasoner(LlmConfig(...))
    graph = reasoner.compose(ComposeRequest(instruction=..., scene=...))
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import json
import math
import os
import re
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal, get_args

import openai
from pydantic import ValidationError

from agentchord.agents.exceptions import (
    InvalidReplyError,
    ReasonerConfigError,
    ReasonerError,
    ReasonerTransportError,
)
from agentchord.agents.prompts import graph_json, render_prompt
from agentchord.agents.reasoner import (
    AgentRequest,
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    ReasonerAttempt,
    ReasonerCall,
    Scene,
    check_reply,
)
from agentchord.graph.loader import validation_messages
from agentchord.graph.models import TaskGraph
from agentchord.guard.documents import check_shape
from agentchord.guard.exceptions import DocumentError

ENV_BASE_URL = "AGENTCHORD_LLM_BASE_URL"
ENV_MODEL = "AGENTCHORD_LLM_MODEL"
ENV_API_KEY = "AGENTCHORD_LLM_API_KEY"
ENV_STRUCTURED_OUTPUT = "AGENTCHORD_LLM_STRUCTURED_OUTPUT"
ENV_TIMEOUT = "AGENTCHORD_LLM_TIMEOUT_S"
ENV_TEMPERATURE = "AGENTCHORD_LLM_TEMPERATURE"
ENV_MAX_TOKENS = "AGENTCHORD_LLM_MAX_TOKENS"
ENV_DEADLINE = "AGENTCHORD_LLM_DEADLINE_S"
ENV_MAX_REPLY = "AGENTCHORD_LLM_MAX_REPLY_CHARS"

#: How much of a refused over-long reply is kept in the record and the conversation.
_REPLY_EXCERPT = 2000

#: How the reply's JSON is asked for. ``json_schema``: ``response_format`` with the
#: graph's JSON Schema (OpenAI, Gemini, vLLM, recent Ollama and llama.cpp);
#: ``json_object``: plain JSON mode; ``text``: no ``response_format``, the JSON is
#: taken from the text. The schema is written into the system prompt for the last
#: two. ``auto`` starts with ``json_schema`` and falls back, in that order, when the
#: endpoint refuses the request (HTTP 400/422), then keeps the first mode that answered.
StructuredOutput = Literal["auto", "json_schema", "json_object", "text"]
_MODES: tuple[str, ...] = ("json_schema", "json_object", "text")

#: HTTP statuses worth retrying: timeout, conflict, rate limit, server errors.
RETRYABLE_STATUS = frozenset({408, 409, 429})

_REQUIRED = (
    ("base_url", ENV_BASE_URL, "the endpoint's base URL, e.g. https://api.openai.com/v1 or http://127.0.0.1:8000/v1"),
    ("model", ENV_MODEL, "the model name the endpoint serves, e.g. gpt-4o-mini, gemini-2.5-flash, qwen2.5:14b"),
    ("api_key", ENV_API_KEY, "the API key; local servers (vLLM, Ollama, llama.cpp) accept any value, e.g. none"),
)
_OPTIONAL: tuple[tuple[str, str, Callable[[str], Any]], ...] = (
    ("structured_output", ENV_STRUCTURED_OUTPUT, str),
    ("timeout_s", ENV_TIMEOUT, float),
    ("temperature", ENV_TEMPERATURE, float),
    ("max_tokens", ENV_MAX_TOKENS, int),
    ("deadline_s", ENV_DEADLINE, float),
    ("max_reply_chars", ENV_MAX_REPLY, int),
)


@dataclass(frozen=True)
class LlmConfig:
    """Settings of an :class:`LlmReasoner`.

    Attributes:
        base_url: Base URL of the OpenAI-compatible API (ends in ``/v1`` for most servers).
        model: Model name.
        api_key: API key (any non-empty value for a local server).
        structured_output: How JSON is asked for; see :data:`StructuredOutput`.
        temperature: Sampling temperature; ``None`` leaves the server's default
            (reasoning models accept only their default).
        max_tokens: Reply token limit (sent as ``max_tokens``); ``None`` sends none.
        seed: Sampling seed, for the servers that honour it.
        timeout_s: Wall-clock limit of one HTTP request, however the reply trickles in.
        deadline_s: Wall-clock limit of one agent call: every request, retry,
            back-off and repair turn together.
        max_reply_chars: Longest reply accepted; a longer one is refused (and
            only its start kept) so that it is not sent back in every repair.
        max_repairs: Repair turns after an invalid reply before giving up.
        max_retries: Transport retries of one request before giving up.
        backoff_base_s: First back-off delay; the n-th retry waits ``base * 2**n``.
        backoff_max_s: Longest back-off delay (also the longest ``Retry-After`` honoured).
        extra_body: Extra JSON fields for the request body (server-specific options).
    """

    base_url: str
    model: str
    api_key: str = dataclasses.field(repr=False)
    structured_output: StructuredOutput = "auto"
    temperature: float | None = None
    max_tokens: int | None = None
    seed: int | None = None
    timeout_s: float = 120.0
    deadline_s: float = 600.0
    max_reply_chars: int = 1_000_000
    max_repairs: int = 3
    max_retries: int = 4
    backoff_base_s: float = 1.0
    backoff_max_s: float = 30.0
    extra_body: Mapping[str, Any] | None = None

    def __post_init__(self) -> None:
        problems = [
            f"{name}: expected a non-empty string, got {getattr(self, name)!r}"
            for name, _, _ in _REQUIRED
            if not isinstance(getattr(self, name), str) or not getattr(self, name).strip()
        ]
        if self.structured_output not in get_args(StructuredOutput):
            problems.append(
                f"structured_output: expected one of {', '.join(get_args(StructuredOutput))}, "
                f"got {self.structured_output!r}"
            )
        for name in ("timeout_s", "deadline_s", "max_reply_chars"):
            if not _finite_number(getattr(self, name)) or not getattr(self, name) > 0:
                problems.append(f"{name}: expected a finite positive number, got {getattr(self, name)!r}")
        for name in ("max_repairs", "max_retries", "backoff_base_s", "backoff_max_s"):
            if not _finite_number(getattr(self, name)) or not getattr(self, name) >= 0:
                problems.append(f"{name}: expected a finite number >= 0, got {getattr(self, name)!r}")
        if self.temperature is not None and not (_finite_number(self.temperature) and 0 <= self.temperature <= 2):
            problems.append(f"temperature: expected a number from 0 to 2 or None, got {self.temperature!r}")
        if self.max_tokens is not None and self.max_tokens < 1:
            problems.append(f"max_tokens: expected a positive integer or None, got {self.max_tokens!r}")
        if problems:
            raise ReasonerConfigError("invalid LLM reasoner settings:", problems=problems)

    @classmethod
    def from_env(cls, env: Mapping[str, str] | None = None, **overrides: Any) -> LlmConfig:
        """Settings from the environment; arguments that are not ``None`` take precedence.

        Reads ``AGENTCHORD_LLM_BASE_URL``, ``AGENTCHORD_LLM_MODEL``,
        ``AGENTCHORD_LLM_API_KEY`` (required), and ``AGENTCHORD_LLM_STRUCTURED_OUTPUT``,
        ``AGENTCHORD_LLM_TIMEOUT_S``, ``AGENTCHORD_LLM_DEADLINE_S``, ``AGENTCHORD_LLM_TEMPERATURE``,
        ``AGENTCHORD_LLM_MAX_TOKENS``, ``AGENTCHORD_LLM_MAX_REPLY_CHARS`` (optional).

        Args:
            env: The environment (default ``os.environ``).
            **overrides: Any :class:`LlmConfig` field, e.g. from command-line flags;
                ``None`` means "not given".

        Raises:
            ReasonerConfigError: A required setting is neither given nor in the
                environment (every missing variable is named), or a value is invalid.
            TypeError: An override names no field.
        """
        env = os.environ if env is None else env
        fields = {f.name for f in dataclasses.fields(cls)}
        if unknown := sorted(set(overrides) - fields):
            raise TypeError(f"LlmConfig has no field {', '.join(unknown)} (fields: {', '.join(sorted(fields))})")
        values = {name: value for name, value in overrides.items() if value is not None}
        missing = []
        for name, var, what in _REQUIRED:
            if name in values:
                continue
            raw = env.get(var, "").strip()
            if raw:
                values[name] = raw
            else:
                missing.append((var, name, what))
        if missing:
            raise ReasonerConfigError(
                "the LLM reasoner is not configured: "
                + ", ".join(var for var, _, _ in missing)
                + (" is" if len(missing) == 1 else " are")
                + " not set",
                missing=[var for var, _, _ in missing],
                problems=[f"{var} (or {name}=...): {what}" for var, name, what in missing],
            )
        bad = []
        for name, var, parse in _OPTIONAL:
            raw = env.get(var, "").strip()
            if name in values or not raw:
                continue
            try:
                values[name] = parse(raw)
            except ValueError:
                bad.append(f"{var}={raw!r}: expected {'an integer' if parse is int else 'a number'}")
        if bad:
            raise ReasonerConfigError("invalid LLM reasoner settings in the environment:", problems=bad)
        return cls(**values)

    def settings(self) -> dict[str, Any]:
        """The settings worth recording with a call (the key left out)."""
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if f.name not in ("api_key", "base_url", "model", "extra_body")
        } | ({"extra_body": dict(self.extra_body)} if self.extra_body else {})


class LlmReasoner:
    """The three agents answered by an LLM behind an OpenAI-compatible endpoint.

    Args:
        config: Settings; default :meth:`LlmConfig.from_env`.
        client: An ``openai.OpenAI``-like client (default: one built from ``config``
            with the client's own retries off).
        sleep: Called with each back-off delay (tests pass a recorder).
        clock: Monotonic clock for latencies, in seconds.

    Attributes:
        name: ``llm``.
        config: The settings.
        calls: Every call made so far, failed ones included.
    """

    name = "llm"

    def __init__(
        self,
        config: LlmConfig | None = None,
        *,
        client: Any | None = None,
        sleep: Callable[[float], None] = time.sleep,
        clock: Callable[[], float] = time.perf_counter,
    ) -> None:
        self.config = config if config is not None else LlmConfig.from_env()
        self.calls: list[ReasonerCall] = []
        self._client = client if client is not None else _make_client(self.config)
        self._sleep = sleep
        self._clock = clock
        mode = self.config.structured_output
        self._modes = list(_MODES) if mode == "auto" else [mode]
        self._mode_settled = mode != "auto"

    @classmethod
    def from_env(cls, env: Mapping[str, str] | None = None, **overrides: Any) -> LlmReasoner:
        """A reasoner configured by :meth:`LlmConfig.from_env`."""
        return cls(LlmConfig.from_env(env, **overrides))

    @property
    def response_format(self) -> str:
        """The structured-output mode the next request will use."""
        return self._modes[0]

    def compose(self, request: ComposeRequest) -> TaskGraph:
        """The nominal task graph (see :class:`~agentchord.agents.reasoner.Reasoner`)."""
        return self._ask(_expect(request, ComposeRequest))

    def arrange(self, request: ArrangeRequest) -> TaskGraph:
        """The recovery-augmented graph (see :class:`~agentchord.agents.reasoner.Reasoner`)."""
        return self._ask(_expect(request, ArrangeRequest))

    def conduct(self, request: ConductRequest) -> TaskGraph:
        """The graph grounded in the scene (see :class:`~agentchord.agents.reasoner.Reasoner`)."""
        return self._ask(_expect(request, ConductRequest))

    # --- one call: ask, validate, repair ----------------------------------------------------

    def _ask(self, request: AgentRequest) -> TaskGraph:
        config = self.config
        agent = request.agent
        call = ReasonerCall(
            agent=agent,
            reasoner=self.name,
            model=config.model,
            endpoint=config.base_url,
            request=request.model_dump(mode="json"),
            settings=config.settings(),
        )
        messages: list[dict[str, Any]] = [
            {"role": "system", "content": ""},  # filled per request: it depends on the structured-output mode
            {"role": "user", "content": request_message(request)},
        ]
        start = self._clock()
        deadline = time.monotonic() + config.deadline_s
        try:
            problems: list[str] = []
            for turn in range(config.max_repairs + 1):
                if turn:
                    messages.append({"role": "user", "content": repair_message(problems)})
                attempt = ReasonerAttempt()
                call.attempts.append(attempt)
                begun = self._clock()
                try:
                    completion = self._complete(agent, messages, attempt, deadline)
                finally:
                    attempt.latency_s = self._clock() - begun
                refusal, unreadable = _read_completion(completion, attempt, config.max_reply_chars)
                messages.append({"role": "assistant", "content": attempt.reply or ""})
                if unreadable:
                    graph, problems = None, [unreadable]
                else:
                    graph, problems = parse_reply(
                        attempt.reply, request, finish_reason=attempt.finish_reason, refusal=refusal
                    )
                attempt.problems = problems
                if graph is not None and not problems:
                    call.reply = graph.model_dump(mode="json", exclude_defaults=True)
                    return graph
            raise InvalidReplyError(
                f"{agent}: no valid task graph from {config.model} after {config.max_repairs} "
                f"repair{'s' if config.max_repairs != 1 else ''}; problems of the last reply:",
                problems=problems,
            )
        except ReasonerError as error:
            error.agent = error.agent or agent
            error.call = call
            call.error = error.headline
            raise
        finally:
            call.latency_s = self._clock() - start
            call.add_usage()
            call.messages = copy.deepcopy(messages)
            self.calls.append(call)

    def _complete(
        self, agent: str, messages: list[dict[str, Any]], attempt: ReasonerAttempt, deadline: float | None = None
    ) -> Any:
        """One chat completion, with transport retries and the structured-output fallback.

        Each request is bounded by ``timeout_s`` of wall time and all of them by ``deadline``
        (a ``time.monotonic()`` instant).
        """
        config = self.config
        if deadline is None:
            deadline = time.monotonic() + config.deadline_s
        retries = 0
        while True:
            mode = self._modes[0]
            messages[0]["content"] = system_prompt(agent, mode)
            left = deadline - time.monotonic()
            if left <= 0:
                raise ReasonerTransportError(
                    f"{agent}: no valid reply from {config.base_url} within the deadline of "
                    f"{config.deadline_s:g} s ({ENV_DEADLINE}):",
                    problems=attempt.transport_errors or ["the deadline passed before a request could be sent"],
                )
            limit = min(config.timeout_s, left)
            try:
                completion = _within(
                    limit,
                    lambda: self._client.chat.completions.create(
                        model=config.model, messages=messages, timeout=limit, **self._params(mode)
                    ),
                )
            except openai.APIStatusError as error:
                status = error.status_code
                line = f"HTTP {status}: {_error_text(error)}"
                if status in (400, 422) and not self._mode_settled and len(self._modes) > 1:
                    self._modes.pop(0)
                    attempt.transport_errors.append(
                        f"{line}; the endpoint refused response_format {mode!r}: falling back to {self._modes[0]!r}"
                    )
                    continue
                if not _retryable(status) or retries >= config.max_retries:
                    attempt.transport_errors.append(line)
                    message = _status_message(agent, config, status, retries)
                    raise ReasonerTransportError(message, status=status, problems=attempt.transport_errors) from None
                delay = _retry_after(error.response, config.backoff_max_s)
                if delay is None:
                    delay = backoff_delay(retries, config.backoff_base_s, config.backoff_max_s)
            except (openai.APIConnectionError, _WallClockTimeout) as error:  # also a timeout
                if isinstance(error, (openai.APITimeoutError, _WallClockTimeout)):
                    line = f"timed out after {limit:g} s"
                else:
                    cause = error.__cause__
                    line = f"connection error: {cause or error}"
                if retries >= config.max_retries:
                    attempt.transport_errors.append(line)
                    raise ReasonerTransportError(
                        f"{agent}: no reply from {config.base_url} after {retries + 1} "
                        f"tr{'ies' if retries else 'y'}:",
                        problems=attempt.transport_errors,
                    ) from None
                delay = backoff_delay(retries, config.backoff_base_s, config.backoff_max_s)
            except openai.OpenAIError as error:  # e.g. a response the client cannot read: not worth retrying
                attempt.transport_errors.append(f"{type(error).__name__}: {error}")
                raise ReasonerTransportError(
                    f"{agent}: the request to {config.base_url} failed:", problems=attempt.transport_errors
                ) from error
            else:
                attempt.response_format = mode
                self._mode_settled = True
                return completion
            retries += 1
            attempt.retries = retries
            delay = max(0.0, min(delay, deadline - time.monotonic()))  # never sleep past the deadline
            attempt.transport_errors.append(f"{line}; retry {retries}/{config.max_retries} in {delay:.3g} s")
            self._sleep(delay)

    def _params(self, mode: str) -> dict[str, Any]:
        config = self.config
        params: dict[str, Any] = {}
        if mode == "json_schema":
            params["response_format"] = {
                "type": "json_schema",
                "json_schema": {
                    "name": "task_graph",
                    "description": "A recovery-augmented task graph of AgentChord.",
                    "schema": task_graph_schema(),
                    "strict": False,  # the graph has free-form mappings (action args), which strict mode refuses
                },
            }
        elif mode == "json_object":
            params["response_format"] = {"type": "json_object"}
        if config.temperature is not None:
            params["temperature"] = config.temperature
        if config.max_tokens is not None:
            params["max_tokens"] = config.max_tokens
        if config.seed is not None:
            params["seed"] = config.seed
        if config.extra_body:
            params["extra_body"] = dict(config.extra_body)
        return params


# --- messages ----------------------------------------------------------------------------


def system_prompt(agent: str, mode: str = "json_schema") -> str:
    """The system message of an agent; without ``json_schema`` output, the schema is appended."""
    prompt = render_prompt(agent)
    if mode == "json_schema":
        return prompt
    schema = json.dumps(task_graph_schema(), separators=(",", ":"))
    return f"{prompt}\n\n# Reply format\n\nThe reply is one JSON object that matches this JSON Schema:\n\n{schema}\n"


def request_message(request: AgentRequest) -> str:
    """The user message that carries a request's data (the task itself is in the system prompt)."""
    scene = scene_json(request.scene)
    if isinstance(request, ComposeRequest):
        return "\n".join(
            [
                f"Instruction: {request.instruction}",
                f"Task name: {request.task or '(choose a short snake_case name)'}",
                "First observation (world frame, metres; quat = w, x, y, z; extent = full size along the "
                "object's principal axes; axis = its bottom-to-top direction):",
                scene,
                "",
                "Write the nominal task graph.",
            ]
        )
    if isinstance(request, ArrangeRequest):
        lines = [
            f"Instruction: {request.graph.instruction or '(not given)'}",
            "Scene (world frame, metres; quat = w, x, y, z; extent = full size along the object's principal axes):",
            scene,
            "",
        ]
        if request.failure is None:
            lines += [
                "Nominal task graph:",
                graph_json(request.graph),
                "",
                "Return the recovery-augmented graph.",
            ]
        else:
            failure = request.failure
            lines += [
                "Current task graph:",
                graph_json(request.graph),
                "",
                f"Online repair: edge {failure.edge!r} ended without reaching its target's sub-goal and no "
                f"monitor fired. Failure context (last completed sub-goal): {failure.context!r}.",
                f"Observation: {failure.observation or '(none)'}",
                f"Return the whole graph with one new failure mode on edge {failure.edge!r} and its recovery branch.",
            ]
        return "\n".join(lines)
    if isinstance(request, ConductRequest):
        return "\n".join(
            [
                f"Instruction: {request.graph.instruction or '(not given)'}",
                "Scene (world frame, metres; quat = w, x, y, z; extent = full size along the object's principal axes):",
                scene,
                "",
                "Recovery-augmented task graph:",
                graph_json(request.graph),
                "",
                "Return the graph with its parameters grounded in this scene.",
            ]
        )
    raise TypeError(f"expected a ComposeRequest, ArrangeRequest or ConductRequest, got {type(request).__name__}")


def scene_json(scene: Scene) -> str:
    """A scene as JSON, one object or arm per line."""
    data = scene.model_dump(mode="json")
    lines = ["{"]
    for key in ("objects", "arms"):
        items = [f"    {json.dumps(item)}" for item in data[key]]
        lines += [f'  "{key}": [', ",\n".join(items), "  ],"] if items else [f'  "{key}": [],']
    lines += [f'  "notes": {json.dumps(data["notes"])}', "}"]
    return "\n".join(lines)


def repair_message(problems: list[str]) -> str:
    """The follow-up user message that asks the model to fix an invalid reply."""
    listed = "\n".join(f"- {problem}" for problem in problems)
    return (
        "Your reply is not a valid task graph. Problems (field path: what is wrong):\n"
        f"{listed}\n\n"
        "Reply again with the complete corrected task graph as one JSON object, no prose; "
        "keep everything that was right."
    )


# --- replies -----------------------------------------------------------------------------


def parse_reply(
    text: str | None,
    request: AgentRequest,
    *,
    finish_reason: str | None = None,
    refusal: str | None = None,
) -> tuple[TaskGraph | None, list[str]]:
    """Validate a reply: JSON, then the graph schema, then :func:`check_reply`.

    Keys the reply leaves out that the request determines (``task``,
    ``instruction``, ``objects``) are taken from the request.

    Returns:
        The graph (``None`` if the reply is not even schema-valid) and the
        problems; the reply is accepted when the problems are empty.
    """
    if refusal and not (text and text.strip()):
        return None, [f"the model refused: {refusal}"]
    if text is None or not text.strip():
        return None, ["the reply is empty: expected one JSON object, the task graph"]
    try:
        data = extract_json(text)
    except ValueError as error:
        problem = f"the reply is not valid JSON: {error}"
        if finish_reason == "length":
            problem += " (the reply was cut off at the token limit: write it more compactly)"
        return None, [problem]
    if not isinstance(data, dict):
        return None, [f"expected one JSON object (the task graph), got a JSON {_json_type(data)}"]
    try:
        check_shape(data)  # a validator must not recurse into a 10,000-level list
    except DocumentError as error:
        return None, [f"{error.where}: {error}" if error.where else str(error)]
    data = _fill_from_request(data, request)
    try:
        graph = TaskGraph.model_validate(data)
    except ValidationError as error:
        return None, validation_messages(error, data)
    return graph, [str(problem) for problem in check_reply(request, graph)]


_FENCE = re.compile(r"```(?:json|JSON)?[ \t]*\n(.*?)```", re.DOTALL)
_THINK = re.compile(r"<think>.*?</think>", re.DOTALL)


def extract_json(text: str) -> Any:
    """The JSON value in a reply: the whole text, a fenced block, or the first ``{...}`` in it.

    A leading ``<think>...</think>`` block (reasoning models) is ignored.

    Raises:
        ValueError: No JSON value could be read; the message says where parsing failed.
    """
    text = _THINK.sub("", text).strip()
    try:
        return json.loads(text)
    except RecursionError:
        raise ValueError("the JSON is nested too deeply") from None
    except json.JSONDecodeError as error:
        first = error
    candidates = [m.group(1) for m in _FENCE.finditer(text)]
    for candidate in candidates:
        try:
            return json.loads(candidate)
        except (json.JSONDecodeError, RecursionError):
            continue
    start = text.find("{")
    if start >= 0:  # prose around the object, or trailing text after it
        try:
            value, _ = json.JSONDecoder().raw_decode(text, start)
            return value
        except (json.JSONDecodeError, ValueError, RecursionError):
            pass
    raise ValueError(f"line {first.lineno}, column {first.colno}: {first.msg}")


@functools.lru_cache(maxsize=1)
def _schema() -> dict[str, Any]:
    schema = TaskGraph.model_json_schema()
    definitions = schema.pop("$defs", {})
    return _inline_refs(schema, definitions)


def task_graph_schema() -> dict[str, Any]:
    """The JSON Schema of :class:`TaskGraph` with every ``$ref`` inlined (for the widest server support)."""
    return copy.deepcopy(_schema())


def _inline_refs(node: Any, definitions: dict[str, Any]) -> Any:
    if isinstance(node, dict):
        if "$ref" in node:
            name = node["$ref"].rsplit("/", 1)[-1]
            resolved = _inline_refs(definitions[name], definitions)
            extra = {k: _inline_refs(v, definitions) for k, v in node.items() if k != "$ref"}
            return {**resolved, **extra}
        return {k: _inline_refs(v, definitions) for k, v in node.items()}
    if isinstance(node, list):
        return [_inline_refs(item, definitions) for item in node]
    return node


def _fill_from_request(data: dict[str, Any], request: AgentRequest) -> dict[str, Any]:
    if isinstance(request, ComposeRequest):
        defaults: dict[str, Any] = {"instruction": request.instruction, "objects": request.scene.object_names}
        if request.task:
            defaults["task"] = request.task
    else:
        graph = request.graph
        defaults = {"task": graph.task, "instruction": graph.instruction, "objects": list(graph.objects)}
    return {**{k: v for k, v in defaults.items() if k not in data}, **data}


def _read_completion(
    completion: Any, attempt: ReasonerAttempt, max_chars: int = 1_000_000
) -> tuple[str | None, str | None]:
    """Copy text, finish reason and usage of a completion into the attempt.

    Whatever the endpoint sent is taken defensively: a ``content`` that is not a string,
    a reply over ``max_chars`` (kept only in part) and non-numeric usage are problems or
    unknowns, never crashes.

    Returns:
        ``(refusal, problem)``: any refusal, and why the reply cannot be read (``None`` if it can).
    """
    choices = getattr(completion, "choices", None)
    refusal = problem = None
    if isinstance(choices, list) and choices:
        choice = choices[0]
        message = getattr(choice, "message", None)
        content = getattr(message, "content", None)
        raw_refusal = getattr(message, "refusal", None)
        refusal = raw_refusal if isinstance(raw_refusal, str) else None
        finish = getattr(choice, "finish_reason", None)
        attempt.finish_reason = finish if isinstance(finish, str) else None
        if content is not None and not isinstance(content, str):
            problem = f"the reply's content is a JSON {_json_type(content)}; expected a string holding the task graph"
        elif content is not None and len(content) > max_chars:
            attempt.reply = f"{content[:_REPLY_EXCERPT]}... [cut: {len(content):,} characters in all]"
            problem = (
                f"the reply is {len(content):,} characters long, more than the limit of {max_chars:,} "
                f"({ENV_MAX_REPLY}): reply with the task graph only, compactly"
            )
        else:
            attempt.reply = content
    usage = getattr(completion, "usage", None)
    if usage is not None:
        attempt.tokens_in = _token_count(getattr(usage, "prompt_tokens", None))
        attempt.tokens_out = _token_count(getattr(usage, "completion_tokens", None))
    return refusal, problem


def _token_count(value: Any) -> int | None:
    # Usage is informational: a count that is not a non-negative integer is unknown.
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    if isinstance(value, float) and not (math.isfinite(value) and value.is_integer()):
        return None
    return int(value) if 0 <= value < 2**53 else None


def _finite_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


class _WallClockTimeout(Exception):
    """A request did not finish within its wall-clock limit."""


def _within(seconds: float, request: Callable[[], Any]) -> Any:
    """``request()``, or :class:`_WallClockTimeout` after ``seconds`` of wall time.

    The HTTP client's timeout applies per read; a reply that trickles in a byte at a time
    never trips it. The request runs in a daemon thread that is abandoned on timeout (it
    ends with its connection and never keeps the process alive).
    """
    box: dict[str, Any] = {}

    def run() -> None:
        try:
            box["value"] = request()
        except BaseException as error:  # re-raised in the caller's thread
            box["error"] = error

    worker = threading.Thread(target=run, name="agentchord-llm-request", daemon=True)
    worker.start()
    worker.join(seconds)
    if worker.is_alive():
        raise _WallClockTimeout(f"no complete reply within {seconds:g} s")
    if "error" in box:
        raise box["error"]
    return box["value"]


# --- transport helpers -------------------------------------------------------------------


def backoff_delay(retry: int, base_s: float, max_s: float) -> float:
    """Delay before retry ``retry + 1``: ``base_s * 2**retry``, at most ``max_s``."""
    return min(max_s, base_s * 2.0**retry)


def _retryable(status: int) -> bool:
    return status in RETRYABLE_STATUS or status >= 500


def _retry_after(response: Any, max_s: float) -> float | None:
    headers = getattr(response, "headers", None)
    if not headers:
        return None
    for name, scale in (("retry-after-ms", 0.001), ("retry-after", 1.0)):
        raw = headers.get(name)
        if raw is None:
            continue
        try:
            seconds = float(raw) * scale
        except ValueError:
            return None  # an HTTP date: use the back-off
        return seconds if 0.0 <= seconds <= max_s else None
    return None


def _error_text(error: openai.APIStatusError) -> str:
    body = error.body
    if isinstance(body, dict):
        inner = body.get("error", body)
        if isinstance(inner, dict) and inner.get("message"):
            return str(inner["message"])
        if isinstance(inner, str):
            return inner
    return str(getattr(error, "message", "") or error)


def _status_message(agent: str, config: LlmConfig, status: int, retries: int) -> str:
    hint = {
        401: f" (check {ENV_API_KEY})",
        403: f" (check {ENV_API_KEY} and the model's access)",
        404: f" (check {ENV_BASE_URL}, which usually ends in /v1, and {ENV_MODEL})",
    }.get(status, "")
    tries = f" after {retries + 1} tries" if retries else ""
    return f"{agent}: {config.base_url} answered HTTP {status}{tries}{hint}:"


def _json_type(value: Any) -> str:
    return {dict: "object", list: "array", str: "string", bool: "boolean", int: "number", float: "number", type(None): "null"}.get(
        type(value), type(value).__name__
    )


def _expect(request: Any, cls: type) -> Any:
    if not isinstance(request, cls):
        raise TypeError(f"expected {cls.__name__}, got {type(request).__name__}")
    return request


def _make_client(config: LlmConfig) -> openai.OpenAI:
    return openai.OpenAI(
        base_url=config.base_url, api_key=config.api_key, timeout=config.timeout_s, max_retries=0
    )
