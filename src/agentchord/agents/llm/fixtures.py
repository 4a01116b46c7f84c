"""Replay fixtures of a prompt evaluation: the replies a model wrote, each with the request it answers.

A case is a folder holding ``case.yaml`` and, per turn of the plan (composer, arranger,
conductor, and any repair turn), the request as it was sent (``01-composer.request.md``) and
the reply written to it (``01-composer.reply.json``)::

    task: handover_block
    instruction: Pick up the block with the left arm, ...
    seed: 0                      # the scene the plan observes
    goal: null                   # optional goal spec: the judge of a task with no check of its own
    turns:
      - {agent: composer, request_sha256: 3f...}

:class:`FixtureBook` answers a plan's requests in order from these files. A request whose hash
is not the stored one (a prompt or a scene changed) is not answered with the old reply:
:class:`FixtureOutdated` is raised and, when recording, the new request is written and the old
reply set aside, so the reply is written again for the request as it now reads.
:class:`FixtureClient` puts a book behind the
``openai`` client interface that :class:`~agentchord.agents.llm.reasoner.LlmReasoner` uses.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from agentchord.agents.llm.sizes import estimate_tokens

#: The file of a case's settings and turns.
CASE_FILE = "case.yaml"
#: Which agent a system prompt belongs to: the words of its role line.
_ROLE_WORDS = {"(the composer)": "composer", "(the arranger)": "arranger", "(the conductor)": "conductor"}


class FixtureError(LookupError):
    """A fixture cannot answer a request (the message names the file to write)."""


class FixtureMissing(FixtureError):
    """No reply is stored for this turn yet."""


class FixtureOutdated(FixtureError):
    """The stored reply answers another request than the one sent now (its hash changed)."""


class FixtureTurn(BaseModel):
    """One request of a plan and the hash of the request its reply answers.

    Attributes:
        agent: ``composer``, ``arranger`` or ``conductor``.
        request_sha256: :func:`request_digest` of the messages the reply answers.
    """

    model_config = ConfigDict(extra="forbid")

    agent: str
    request_sha256: str = Field(pattern=r"^[0-9a-f]{64}$")


class FixtureCase(BaseModel):
    """A case of the prompt evaluation (``case.yaml``).

    Attributes:
        task: The simulated task whose scene is observed.
        instruction: What the plan is asked to do.
        seed: Seed of the observed scene.
        goal: A goal spec (as ``--goal`` reads it) to judge the episodes by, for a task with no
            success check of its own; None keeps the task's check.
        turns: The plan's requests, in order.
    """

    model_config = ConfigDict(extra="forbid")

    task: str
    instruction: str
    seed: int = 0
    goal: dict[str, Any] | None = None
    turns: list[FixtureTurn] = Field(default_factory=list)


def request_digest(messages: list[dict[str, Any]]) -> str:
    """SHA-256 of a request's messages (roles and texts, in order): what its reply answers."""
    plain = [{"role": m.get("role"), "content": m.get("content")} for m in messages]
    return hashlib.sha256(json.dumps(plain, sort_keys=True, ensure_ascii=False).encode()).hexdigest()


def message_agent(messages: list[dict[str, Any]]) -> str:
    """The agent a request is for, read from its system prompt's role line.

    Raises:
        FixtureError: The first message is not an agent's system prompt.
    """
    system = str(messages[0].get("content", "")) if messages else ""
    for words, agent in _ROLE_WORDS.items():
        if words in system[:400]:
            return agent
    raise FixtureError("the request's first message is not the system prompt of an AgentChord agent")


def request_text(messages: list[dict[str, Any]]) -> str:
    """A request as readable Markdown: each message under a heading of its role."""
    return "\n\n".join(f"<!-- message {i}: {m.get('role')} -->\n{m.get('content')}" for i, m in enumerate(messages)) + "\n"


@dataclass
class FixtureBook:
    """A case's replies, answered in the order of the plan's requests.

    Attributes:
        folder: The case's folder.
        case: Its ``case.yaml``.
        record: Write a request that has no valid reply into the folder, and set an outdated
            reply aside as ``NN-agent.reply.stale.json`` (the reply still has to be written
            before the book answers the request).
        answered: How many requests it has answered.
        problems: Why each request it could not answer was refused.
    """

    folder: Path
    case: FixtureCase
    record: bool = False
    answered: int = 0
    problems: list[str] = field(default_factory=list)

    @classmethod
    def load(cls, folder: str | Path, record: bool = False) -> FixtureBook:
        """The book of the case in ``folder``.

        Raises:
            FixtureError: No ``case.yaml`` there, or one that is not a valid case (file and field named).
        """
        folder = Path(folder)
        path = folder / CASE_FILE
        if not path.is_file():
            raise FixtureError(f"{path}: no such case file")
        try:
            case = FixtureCase.model_validate(yaml.safe_load(path.read_text(encoding="utf-8")) or {})
        except (ValidationError, yaml.YAMLError) as error:
            raise FixtureError(f"{path}: not a fixture case: {error}") from None
        return cls(folder, case, record)

    def stem(self, index: int, agent: str) -> str:
        """The file stem of turn ``index`` (0-based): ``01-composer``."""
        return f"{index + 1:02d}-{agent}"

    def answer(self, messages: list[dict[str, Any]]) -> str:
        """The stored reply to the next request.

        Raises:
            FixtureMissing: No reply stored for this turn (with ``record``, the request is written).
            FixtureOutdated: The request differs from the one the stored reply answers.
        """
        index, self.answered = self.answered, self.answered + 1
        agent = message_agent(messages)
        digest = request_digest(messages)
        stem = self.stem(index, agent)
        reply = self.folder / f"{stem}.reply.json"
        turn = self.case.turns[index] if index < len(self.case.turns) else None
        if turn is not None and turn.agent == agent and turn.request_sha256 == digest and reply.is_file():
            return reply.read_text(encoding="utf-8")
        if turn is None or not reply.is_file():
            error: FixtureError = FixtureMissing(f"{reply}: no reply to turn {index + 1} ({agent}) yet")
        else:
            error = FixtureOutdated(
                f"{reply}: answers another request (stored sha256 {turn.request_sha256[:12]}, "
                f"sent {digest[:12]}: the prompt or the scene changed); answer {stem}.request.md again"
            )
        if self.record:
            if isinstance(error, FixtureOutdated):
                # Kept for reference, never answered with: the request has to be answered again.
                reply.replace(reply.with_name(f"{stem}.reply.stale.json"))
            self._write_request(index, agent, digest, messages)
        self.problems.append(str(error))
        raise error

    def _write_request(self, index: int, agent: str, digest: str, messages: list[dict[str, Any]]) -> None:
        (self.folder / f"{self.stem(index, agent)}.request.md").write_text(request_text(messages), encoding="utf-8")
        turns = self.case.turns[:index] + [FixtureTurn(agent=agent, request_sha256=digest)]
        self.case = self.case.model_copy(update={"turns": turns})
        data = self.case.model_dump(mode="json")
        (self.folder / CASE_FILE).write_text(yaml.safe_dump(data, sort_keys=False, width=120), encoding="utf-8")


def completion_body(content: str, messages: list[dict[str, Any]], model: str = "fixture") -> dict[str, Any]:
    """A chat-completion response body for a stored reply (tokens estimated, characters / 4)."""
    prompt = sum(estimate_tokens(str(m.get("content", ""))) for m in messages)
    tokens = estimate_tokens(content)
    return {
        "id": "chatcmpl-fixture",
        "object": "chat.completion",
        "created": int(time.time()),
        "model": model,
        "choices": [{"index": 0, "message": {"role": "assistant", "content": content}, "finish_reason": "stop"}],
        "usage": {"prompt_tokens": prompt, "completion_tokens": tokens, "total_tokens": prompt + tokens},
    }


class FixtureClient:
    """An ``openai.OpenAI`` stand-in whose ``chat.completions.create`` answers from a :class:`FixtureBook`.

    Args:
        book: The replies.
    """

    def __init__(self, book: FixtureBook) -> None:
        self.book = book
        self.chat = self
        self.completions = self

    def create(self, *, model: str, messages: list[dict[str, Any]], **_: Any) -> Any:
        """The stored reply as an ``openai`` ChatCompletion.

        Raises:
            FixtureError: No valid stored reply (see :meth:`FixtureBook.answer`).
        """
        from openai.types.chat import ChatCompletion  # only a fixture run needs it

        return ChatCompletion.model_validate(completion_body(self.book.answer(messages), messages, model))
