"""A local OpenAI-compatible endpoint that misbehaves on purpose (hostile-input tests).

Each request is answered by a function of the request body that returns a :class:`Reply`:
any JSON body (a ``content`` that is not a string, a ``usage`` that is not numeric, NaN
arguments), or a body dripped a few bytes at a time so that no single read ever times out.
Nothing leaves the machine (127.0.0.1, ephemeral port).
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any


@dataclass
class Reply:
    """What to answer.

    Attributes:
        body: The JSON body (serialised with NaN allowed, as a careless server would), or raw bytes.
        status: HTTP status.
        drip_s: Pause between chunks of ``chunk`` bytes (0: send at once).
        chunk: Bytes per chunk when dripping.
    """

    body: Any
    status: int = 200
    drip_s: float = 0.0
    chunk: int = 4


def completion(content: Any, usage: Any = None) -> dict[str, Any]:
    """A chat-completion body whose message content is ``content`` (any JSON value)."""
    body: dict[str, Any] = {
        "id": "chatcmpl-hostile",
        "object": "chat.completion",
        "created": 0,
        "model": "hostile",
        "choices": [{"index": 0, "message": {"role": "assistant", "content": content}, "finish_reason": "stop"}],
    }
    if usage is not None:
        body["usage"] = usage
    return body


class HostileServer:
    """The server, as a context manager.

    Args:
        answer: Request body -> :class:`Reply`.

    Attributes:
        requests: The JSON bodies received, in order.
    """

    def __init__(self, answer: Callable[[Any], Reply]) -> None:
        self.answer = answer
        self.requests: list[Any] = []
        self.stopping = threading.Event()
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, format: str, *args: Any) -> None:  # stdlib signature
                pass

            def do_POST(self) -> None:  # stdlib name
                raw = self.rfile.read(int(self.headers.get("content-length", 0)))
                body = json.loads(raw)
                server.requests.append(body)
                reply = server.answer(body)
                data = reply.body if isinstance(reply.body, bytes) else json.dumps(reply.body).encode()
                try:
                    self.send_response(reply.status)
                    self.send_header("content-type", "application/json")
                    self.send_header("content-length", str(len(data)))
                    self.end_headers()
                    if not reply.drip_s:
                        self.wfile.write(data)
                        return
                    for start in range(0, len(data), reply.chunk):
                        if server.stopping.is_set():
                            return
                        self.wfile.write(data[start : start + reply.chunk])
                        self.wfile.flush()
                        time.sleep(reply.drip_s)
                except (BrokenPipeError, ConnectionResetError):
                    pass

        self._server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self._server.daemon_threads = True
        self._thread = threading.Thread(target=self._server.serve_forever, kwargs={"poll_interval": 0.02}, daemon=True)

    @property
    def base_url(self) -> str:
        """``http://127.0.0.1:PORT/v1``."""
        return f"http://127.0.0.1:{self._server.server_address[1]}/v1"

    def __enter__(self) -> HostileServer:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stopping.set()
        self._server.shutdown()
        self._server.server_close()
        self._thread.join(timeout=5)
