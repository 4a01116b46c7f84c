"""Settings of the LLM reasoner: arguments, or ``AGENTCHORD_LLM_*`` environment variables."""

from __future__ import annotations

import dataclasses
import math
import os
import urllib.parse
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Literal, get_args

from agentchord.agents.exceptions import ReasonerConfigError

ENV_BASE_URL = "AGENTCHORD_LLM_BASE_URL"
ENV_MODEL = "AGENTCHORD_LLM_MODEL"
ENV_API_KEY = "AGENTCHORD_LLM_API_KEY"
ENV_STRUCTURED_OUTPUT = "AGENTCHORD_LLM_STRUCTURED_OUTPUT"
ENV_TIMEOUT = "AGENTCHORD_LLM_TIMEOUT_S"
ENV_TEMPERATURE = "AGENTCHORD_LLM_TEMPERATURE"
ENV_MAX_TOKENS = "AGENTCHORD_LLM_MAX_TOKENS"
ENV_DEADLINE = "AGENTCHORD_LLM_DEADLINE_S"
ENV_MAX_REPLY = "AGENTCHORD_LLM_MAX_REPLY_CHARS"

#: How the reply's JSON is asked for. ``json_schema``: ``response_format`` with the
#: graph's JSON Schema (OpenAI, Gemini, vLLM, recent Ollama and llama.cpp);
#: ``json_object``: plain JSON mode; ``text``: no ``response_format``, the JSON is
#: taken from the text. The schema is written into the system prompt for the last
#: two. ``auto`` starts with ``json_schema`` and falls back, in that order, when the
#: endpoint refuses the request (HTTP 400/422), then keeps the first mode that answered.
StructuredOutput = Literal["auto", "json_schema", "json_object", "text"]
STRUCTURED_OUTPUT_MODES: tuple[str, ...] = ("json_schema", "json_object", "text")

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


#: The longest wait a setting may ask for (a timeout, a deadline, a back-off): beyond it a clock overflows.
MAX_WAIT_S = 86_400.0


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
        for name in ("timeout_s", "deadline_s", "backoff_base_s", "backoff_max_s"):
            if _finite_number(getattr(self, name)) and getattr(self, name) > MAX_WAIT_S:
                problems.append(f"{name}: at most {MAX_WAIT_S:g} s (a day), got {getattr(self, name)!r}")
        for name, _, _ in _REQUIRED:
            value = getattr(self, name)
            if isinstance(value, str) and not value.isascii():
                # A header or a URL must be ASCII: a byte the shell passed undecoded, or a stray non-ASCII letter.
                shown = value.encode("utf-8", "surrogateescape").decode("ascii", "backslashreplace")
                problems.append(f"{name}: expected ASCII text, got {redact_url(shown) if name == 'base_url' else shown!r}"[:300])
        if isinstance(self.base_url, str) and self.base_url.strip() and self.base_url.isascii():
            try:
                url = urllib.parse.urlsplit(self.base_url.strip())
                url.port  # noqa: B018 -- read for its check: a port out of range raises here
                ok = url.scheme in ("http", "https") and bool(url.hostname)
            except ValueError as error:  # "http://[::1": an invalid IPv6 address; a port out of range
                ok = False
                problems.append(f"base_url: not a URL ({error}): {redact_url(self.base_url)!r}")
            else:
                if not ok:
                    problems.append(f"base_url: expected an http:// or https:// URL with a host, got {redact_url(self.base_url)!r}")
        if self.temperature is not None and not (_finite_number(self.temperature) and 0 <= self.temperature <= 2):
            problems.append(f"temperature: expected a number from 0 to 2 or None, got {self.temperature!r}")
        if self.max_tokens is not None and self.max_tokens < 1:
            problems.append(f"max_tokens: expected a positive integer or None, got {self.max_tokens!r}")
        if problems:
            raise ReasonerConfigError("invalid LLM reasoner settings:", problems=problems)

    @property
    def endpoint(self) -> str:
        """The base URL as it may be shown and recorded: credentials in it (``user:pw@``) masked."""
        return redact_url(self.base_url)

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


def _finite_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def redact_url(url: str) -> str:
    """``url`` with any credentials in it (``http://user:pw@host/...``) masked as ``***``: safe to print and record."""
    try:
        parts = urllib.parse.urlsplit(url)
    except ValueError:
        return url
    if parts.username is None and parts.password is None:
        return url
    host = parts.netloc.rsplit("@", 1)[-1]
    return urllib.parse.urlunsplit(parts._replace(netloc=f"***@{host}"))
