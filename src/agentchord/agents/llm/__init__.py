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

The package, one concept per module: ``config`` (settings), ``messages`` (what is sent),
``skills`` (the skill notes a request's prompt carries), ``sizes`` (how large each prompt is),
``replies`` (what comes back, checked), ``transport`` (timeouts, retries, back-off),
``reasoner`` (the ask-validate-repair loop) and ``fixtures`` (replayed replies of the prompt
evaluation, each checked against the request it answers). docs/llm.md has the set-up.
"""

from __future__ import annotations

from agentchord.agents.llm.config import (
    ENV_API_KEY,
    ENV_BASE_URL,
    ENV_DEADLINE,
    ENV_MAX_REPLY,
    ENV_MAX_TOKENS,
    ENV_MODEL,
    ENV_STRUCTURED_OUTPUT,
    ENV_TEMPERATURE,
    ENV_TIMEOUT,
    LlmConfig,
    StructuredOutput,
)
from agentchord.agents.llm.messages import repair_message, request_message, scene_json, system_prompt
from agentchord.agents.llm.reasoner import LlmReasoner
from agentchord.agents.llm.replies import extract_json, parse_reply, task_graph_schema
from agentchord.agents.llm.transport import RETRYABLE_STATUS, backoff_delay

__all__ = [
    "ENV_API_KEY",
    "ENV_BASE_URL",
    "ENV_DEADLINE",
    "ENV_MAX_REPLY",
    "ENV_MAX_TOKENS",
    "ENV_MODEL",
    "ENV_STRUCTURED_OUTPUT",
    "ENV_TEMPERATURE",
    "ENV_TIMEOUT",
    "RETRYABLE_STATUS",
    "LlmConfig",
    "LlmReasoner",
    "StructuredOutput",
    "backoff_delay",
    "extract_json",
    "parse_reply",
    "repair_message",
    "request_message",
    "scene_json",
    "system_prompt",
    "task_graph_schema",
]
