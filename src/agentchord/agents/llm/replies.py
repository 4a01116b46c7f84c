"""A model's reply: read from the completion, JSON extracted, checked against the graph schema."""

from __future__ import annotations

import copy
import functools
import json
import math
import re
from typing import Any

from pydantic import ValidationError

from agentchord.agents.llm.config import ENV_MAX_REPLY
from agentchord.agents.checks import check_reply
from agentchord.agents.reasoner import AgentRequest, ComposeRequest, ReasonerAttempt
from agentchord.agents.rules.feasibility import stated_goal_problems
from agentchord.graph.loader import validation_messages
from agentchord.graph.models import TaskGraph
from agentchord.guard.documents import check_shape
from agentchord.guard.exceptions import DocumentError

#: How much of a refused over-long reply is kept in the record and the conversation.
REPLY_EXCERPT = 2000


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
    surrogate = lone_surrogate(data)
    if surrogate is not None:
        where, char = surrogate
        return None, [f"{where}: the text holds a lone surrogate (\\u{ord(char):04x}), which is not Unicode text: write plain characters"]
    data = _fill_from_request(data, request)
    try:
        graph = TaskGraph.model_validate(data)
    except ValidationError as error:
        return None, validation_messages(error, data)
    problems = check_reply(request, graph)
    if isinstance(request, ComposeRequest):
        problems += stated_goal_problems(graph, request.scene)
    return graph, [str(problem) for problem in problems]


def lone_surrogate(value: Any, where: str = "reply") -> tuple[str, str] | None:
    """The first lone surrogate (``"\\ud800"`` in JSON: no character, cannot be written as UTF-8) in a
    parsed reply's keys or strings, with where it is; None when every string is text."""
    if isinstance(value, str):
        bad = next((c for c in value if "\ud800" <= c <= "\udfff"), None)
        return (where, bad) if bad is not None else None
    if isinstance(value, dict):
        for key, item in value.items():
            found = lone_surrogate(key, where) or lone_surrogate(item, f"{where}.{key}" if where != "reply" else str(key))
            if found is not None:
                return found
    if isinstance(value, list):
        for k, item in enumerate(value):
            found = lone_surrogate(item, f"{where}[{k}]")
            if found is not None:
                return found
    return None


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
        # The arranger and the conductor keep the composer's goal: one that leaves it out keeps it.
        graph = request.graph
        defaults = {"task": graph.task, "instruction": graph.instruction, "objects": list(graph.objects),
                    "success": graph.success.model_dump(mode="json")}
    return {**{k: v for k, v in defaults.items() if k not in data}, **data}


def read_completion(
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
        if isinstance(content, str):
            # A lone surrogate sent raw (JSON "\ud800" in the response body) is no character: kept as its
            # escape text, so that the reply can be sent back for repair and written to a trace; the
            # reply's own JSON then reads it as a lone surrogate, a problem it is told.
            content = content.encode("utf-8", "backslashreplace").decode("utf-8")
        raw_refusal = getattr(message, "refusal", None)
        refusal = raw_refusal if isinstance(raw_refusal, str) else None
        finish = getattr(choice, "finish_reason", None)
        attempt.finish_reason = finish if isinstance(finish, str) else None
        if content is not None and not isinstance(content, str):
            problem = f"the reply's content is a JSON {_json_type(content)}; expected a string holding the task graph"
        elif content is not None and len(content) > max_chars:
            attempt.reply = f"{content[:REPLY_EXCERPT]}... [cut: {len(content):,} characters in all]"
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


_JSON_TYPES = {dict: "object", list: "array", str: "string", bool: "boolean", int: "number", float: "number", type(None): "null"}


def _json_type(value: Any) -> str:
    return _JSON_TYPES.get(type(value), type(value).__name__)

