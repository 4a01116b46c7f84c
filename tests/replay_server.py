"""A local OpenAI-compatible chat-completions server that replays recorded replies.

Used by the LLM reasoner's tests: it listens on 127.0.0.1 on an ephemeral port
in a thread, answers ``POST /v1/chat/completions`` with the next item of its
queue (a :class:`Completion`, or an :class:`HttpError` to simulate a transport
failure) and records every request it got. Nothing leaves the machine.

A ``responder`` (a callable from the request body to a reply) answers instead of the queue:
the prompt evaluation answers each request from its replay fixtures that way.

Example:
    with ReplayServer() as server:
        server.push(Completion('{"task": ...}'), HttpError(500))
        client = openai.OpenAI(base_url=server.base_url, api_key="test")
"""

from __future__ import annotations

import json
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass
class Completion:
    """A chat completion to answer with.

    Attributes:
        content: The assistant message's text (``None``: no content).
        prompt_tokens: Reported prompt tokens.
        completion_tokens: Reported completion tokens.
        finish_reason: Reported finish reason.
        delay_s: Wait this long before answering (latency, or a client timeout).
        usage: Whether to report usage at all.
        refusal: A refusal message instead of content.
    """

    content: str | None
    prompt_tokens: int = 120
    completion_tokens: int = 80
    finish_reason: str = "stop"
    delay_s: float = 0.0
    usage: bool = True
    refusal: str | None = None


@dataclass
class HttpError:
    """An HTTP error response (OpenAI's error body).

    Attributes:
        status: HTTP status.
        message: The error message.
        headers: Extra response headers (e.g. ``retry-after``).
    """

    status: int
    message: str = "replayed error"
    headers: dict[str, str] = field(default_factory=dict)


@dataclass
class Received:
    """A request the server got.

    Attributes:
        path: Request path.
        headers: Request headers, names lower-cased.
        body: The JSON body.
        at: ``time.monotonic()`` when it arrived.
    """

    path: str
    headers: dict[str, str]
    body: Any
    at: float


class ReplayServer:
    """The server; a context manager that starts and stops it.

    Args:
        responder: Answers each request from its JSON body (default: the queue).

    Attributes:
        requests: Every request received, in order.
        queue: Replies still to give, in order.
    """

    def __init__(self, responder: Callable[[Any], Completion | HttpError] | None = None) -> None:
        self.responder = responder
        self.requests: list[Received] = []
        self.queue: deque[Completion | HttpError] = deque()
        self._lock = threading.Lock()
        self._server = ThreadingHTTPServer(("127.0.0.1", 0), self._handler_class())
        self._server.daemon_threads = True
        self._thread = threading.Thread(
            target=self._server.serve_forever, kwargs={"poll_interval": 0.02}, name="replay-server", daemon=True
        )

    @property
    def port(self) -> int:
        """The ephemeral port it listens on."""
        return self._server.server_address[1]

    @property
    def base_url(self) -> str:
        """Base URL for an OpenAI client: ``http://127.0.0.1:PORT/v1``."""
        return f"http://127.0.0.1:{self.port}/v1"

    def push(self, *items: Completion | HttpError) -> None:
        """Queue replies, answered in order."""
        with self._lock:
            self.queue.extend(items)

    def bodies(self) -> list[Any]:
        """The JSON bodies of the chat-completion requests received."""
        return [r.body for r in self.requests if r.path.endswith("/chat/completions")]

    def start(self) -> ReplayServer:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=5)

    def __enter__(self) -> ReplayServer:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _next(self, received: Received) -> Completion | HttpError | None:
        with self._lock:
            self.requests.append(received)
            if self.responder is not None:
                return self.responder(received.body)
            return self.queue.popleft() if self.queue else None

    def _handler_class(self) -> type[BaseHTTPRequestHandler]:
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:  # stdlib signature
                pass  # keep test output clean

            def do_POST(self) -> None:  # stdlib name
                length = int(self.headers.get("content-length", 0))
                raw = self.rfile.read(length)
                try:
                    body = json.loads(raw)
                except json.JSONDecodeError:
                    body = raw.decode("utf-8", "replace")
                received = Received(
                    path=self.path,
                    headers={k.lower(): v for k, v in self.headers.items()},
                    body=body,
                    at=time.monotonic(),
                )
                if not self.path.endswith("/chat/completions"):
                    self._send(404, {"error": {"message": f"no route {self.path}", "type": "not_found"}})
                    return
                item = server._next(received)
                if item is None:
                    # 418 is not retried: an exhausted queue fails the test at once.
                    self._send(418, {"error": {"message": "replay queue is empty", "type": "replay"}})
                elif isinstance(item, HttpError):
                    self._send(item.status, {"error": {"message": item.message, "type": "replay"}}, item.headers)
                else:
                    if item.delay_s:
                        time.sleep(item.delay_s)
                    self._send(200, _completion_body(item, body))

            def _send(self, status: int, payload: Any, headers: dict[str, str] | None = None) -> None:
                data = json.dumps(payload).encode()
                try:
                    self.send_response(status)
                    self.send_header("content-type", "application/json")
                    self.send_header("content-length", str(len(data)))
                    for name, value in (headers or {}).items():
                        self.send_header(name, value)
                    self.end_headers()
                    self.wfile.write(data)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the client gave up (a timeout test)

        return Handler


def _completion_body(item: Completion, request: Any) -> dict[str, Any]:
    model = request.get("model", "replay") if isinstance(request, dict) else "replay"
    message: dict[str, Any] = {"role": "assistant", "content": item.content}
    if item.refusal is not None:
        message["refusal"] = item.refusal
    body: dict[str, Any] = {
        "id": "chatcmpl-replay",
        "object": "chat.completion",
        "created": int(time.time()),
        "model": model,
        "choices": [{"index": 0, "message": message, "finish_reason": item.finish_reason, "logprobs": None}],
    }
    if item.usage:
        body["usage"] = {
            "prompt_tokens": item.prompt_tokens,
            "completion_tokens": item.completion_tokens,
            "total_tokens": item.prompt_tokens + item.completion_tokens,
        }
    return body


def composer_first(task: str, later: Completion | HttpError, first: bool = True) -> tuple[str, ReplayServer]:
    """The task's library instruction and a server whose first answer is the rules composer's reply for it
    (unless ``first`` is False) and every later one ``later``: an LLM whose arranger misbehaves."""
    from agentchord.agents.observe import observe, task_regions
    from agentchord.agents.pipeline import plan_task
    from agentchord.agents.rules import RulesReasoner
    from agentchord.library import load_task_graph
    from agentchord.sim.tasks import SIM_TASKS
    from agentchord.sim.trial import open_world

    instruction = load_task_graph(task).instruction
    rules = RulesReasoner()
    plan_task(instruction, observe(open_world(task, 0), task_regions(SIM_TASKS[task])), rules, task)
    composed = json.dumps(rules.calls[0].reply)
    answered: list[Any] = []

    def respond(body: Any) -> Completion | HttpError:
        answered.append(body)
        return Completion(composed) if first and len(answered) == 1 else later

    return instruction, ReplayServer(respond)
