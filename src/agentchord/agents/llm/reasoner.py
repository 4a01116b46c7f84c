"""The three agents answered by an LLM: ask, validate, repair; retry the transport."""

from __future__ import annotations

import copy
import time
from collections.abc import Callable, Mapping
from typing import Any, cast

import openai
from openai.types.chat import ChatCompletionMessageParam

from agentchord.agents.exceptions import InvalidReplyError, ReasonerError, ReasonerTransportError
from agentchord.agents.llm.config import ENV_DEADLINE, STRUCTURED_OUTPUT_MODES, LlmConfig
from agentchord.agents.llm.messages import repair_message, request_message, system_prompt
from agentchord.agents.llm.replies import parse_reply, read_completion, task_graph_schema
from agentchord.agents.llm.transport import (
    WallClockTimeout,
    backoff_delay,
    error_text,
    make_client,
    retry_after,
    retryable,
    status_message,
    within,
)
from agentchord.agents.reasoner import (
    AgentRequest,
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    ReasonerAttempt,
    ReasonerCall,
)
from agentchord.agents.rules.feasibility import stated_goal
from agentchord.agents.rules.goals import GoalSpec
from agentchord.graph.models import TaskGraph


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
        last_goal: The goal the last composer reply stated.
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
        #: The goal the last composer reply stated (``success.goal_spec``).
        self.last_goal: GoalSpec | None = None
        self._client = client if client is not None else make_client(self.config)
        self._sleep = sleep
        self._clock = clock
        mode = self.config.structured_output
        self._modes = list(STRUCTURED_OUTPUT_MODES) if mode == "auto" else [mode]
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
        """The nominal task graph (see :class:`~agentchord.agents.reasoner.Reasoner`), its goal in ``success``.

        The goal it states is kept as ``last_goal``: the episode is judged by it.
        """
        graph = self._ask(_expect(request, ComposeRequest))
        self.last_goal = stated_goal(graph)
        return graph

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
            endpoint=config.endpoint,
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
                    completion = self._complete(agent, messages, attempt, deadline, request)
                finally:
                    attempt.latency_s = self._clock() - begun
                refusal, unreadable = read_completion(completion, attempt, config.max_reply_chars)
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
        self,
        agent: str,
        messages: list[dict[str, Any]],
        attempt: ReasonerAttempt,
        deadline: float | None = None,
        request: AgentRequest | None = None,
    ) -> Any:
        """One chat completion, with transport retries and the structured-output fallback.

        Each request is bounded by ``timeout_s`` of wall time and all of them by ``deadline``
        (a ``time.monotonic()`` instant); ``request`` chooses the system prompt's skill notes.
        """
        config = self.config
        if deadline is None:
            deadline = time.monotonic() + config.deadline_s
        retries = 0
        while True:
            mode = self._modes[0]
            messages[0]["content"] = system_prompt(agent, mode, request)
            left = deadline - time.monotonic()
            if left <= 0:
                raise ReasonerTransportError(
                    f"{agent}: no valid reply from {config.endpoint} within the deadline of "
                    f"{config.deadline_s:g} s ({ENV_DEADLINE}):",
                    problems=attempt.transport_errors or ["the deadline passed before a request could be sent"],
                )
            limit = min(config.timeout_s, left)

            def send(limit: float = limit, mode: str = mode) -> Any:
                # The conversation's plain dicts are the role/content messages the chat API takes.
                chat = cast("list[ChatCompletionMessageParam]", messages)
                return self._client.chat.completions.create(model=config.model, messages=chat, timeout=limit, **self._params(mode))

            try:
                completion = within(limit, send)
            except openai.APIStatusError as error:
                status = error.status_code
                line = f"HTTP {status}: {error_text(error)}"
                if status in (400, 422) and not self._mode_settled and len(self._modes) > 1:
                    self._modes.pop(0)
                    attempt.transport_errors.append(
                        f"{line}; the endpoint refused response_format {mode!r}: falling back to {self._modes[0]!r}"
                    )
                    continue
                if not retryable(status) or retries >= config.max_retries:
                    attempt.transport_errors.append(line)
                    message = status_message(agent, config, status, retries)
                    raise ReasonerTransportError(message, status=status, problems=attempt.transport_errors) from None
                delay = retry_after(error.response, config.backoff_max_s)
                if delay is None:
                    delay = backoff_delay(retries, config.backoff_base_s, config.backoff_max_s)
            except (openai.APIConnectionError, WallClockTimeout, ValueError, RecursionError) as error:  # also a timeout
                if isinstance(error, (openai.APITimeoutError, WallClockTimeout)):
                    line = f"timed out after {limit:g} s"
                elif isinstance(error, (ValueError, RecursionError)):
                    # An HTTP 200 whose body the client cannot read (cut short, not UTF-8, nested past the parser's
                    # depth): as a dropped connection, retried, then a transport error (issue 58).
                    line = f"an unreadable response body ({type(error).__name__}: {str(error)[:120]})"
                else:
                    cause = error.__cause__
                    line = f"connection error: {cause or error}"
                if retries >= config.max_retries:
                    attempt.transport_errors.append(line)
                    raise ReasonerTransportError(
                        f"{agent}: no reply from {config.endpoint} after {retries + 1} "
                        f"tr{'ies' if retries else 'y'}:",
                        problems=attempt.transport_errors,
                    ) from None
                delay = backoff_delay(retries, config.backoff_base_s, config.backoff_max_s)
            except openai.OpenAIError as error:  # e.g. a response the client cannot read: not worth retrying
                attempt.transport_errors.append(f"{type(error).__name__}: {error}")
                raise ReasonerTransportError(
                    f"{agent}: the request to {config.endpoint} failed:", problems=attempt.transport_errors
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


def _expect(request: Any, cls: type) -> Any:
    if not isinstance(request, cls):
        raise TypeError(f"expected {cls.__name__}, got {type(request).__name__}")
    return request

