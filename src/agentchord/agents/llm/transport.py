"""One request's transport: the client, a wall-clock limit, retries with back-off, error lines."""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import openai

from agentchord.agents.llm.config import ENV_API_KEY, ENV_BASE_URL, ENV_MODEL, LlmConfig

#: HTTP statuses worth retrying: timeout, conflict, rate limit, server errors.
RETRYABLE_STATUS = frozenset({408, 409, 429})


class WallClockTimeout(Exception):
    """A request did not finish within its wall-clock limit."""


def within(seconds: float, request: Callable[[], Any]) -> Any:
    """``request()``, or :class:`WallClockTimeout` after ``seconds`` of wall time.

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
        raise WallClockTimeout(f"no complete reply within {seconds:g} s")
    if "error" in box:
        raise box["error"]
    return box["value"]


def backoff_delay(retry: int, base_s: float, max_s: float) -> float:
    """Delay before retry ``retry + 1``: ``base_s * 2**retry``, at most ``max_s``."""
    return min(max_s, base_s * 2.0**retry)


def retryable(status: int) -> bool:
    return status in RETRYABLE_STATUS or status >= 500


def retry_after(response: Any, max_s: float) -> float | None:
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


def error_text(error: openai.APIStatusError) -> str:
    body = error.body
    if isinstance(body, dict):
        inner = body.get("error", body)
        if isinstance(inner, dict) and inner.get("message"):
            return str(inner["message"])
        if isinstance(inner, str):
            return inner
    return str(getattr(error, "message", "") or error)


def status_message(agent: str, config: LlmConfig, status: int, retries: int) -> str:
    hint = {
        401: f" (check {ENV_API_KEY})",
        403: f" (check {ENV_API_KEY} and the model's access)",
        404: f" (check {ENV_BASE_URL}, which usually ends in /v1, and {ENV_MODEL})",
    }.get(status, "")
    tries = f" after {retries + 1} tries" if retries else ""
    return f"{agent}: {config.endpoint} answered HTTP {status}{tries}{hint}:"


def make_client(config: LlmConfig) -> openai.OpenAI:
    return openai.OpenAI(
        base_url=config.base_url, api_key=config.api_key, timeout=config.timeout_s, max_retries=0
    )
