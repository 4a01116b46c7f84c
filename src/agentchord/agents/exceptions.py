"""Exceptions of the agents package.

Every error a reasoner raises is a :class:`ReasonerError`; its message says what
was expected and what came, and, when the call got that far, the
:class:`~agentchord.agents.reasoner.ReasonerCall` record of the failed call is
attached (it is also in the reasoner's ``calls`` list).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from agentchord.agents.reasoner import ReasonerCall


class ReasonerError(Exception):
    """A reasoner could not produce a valid result.

    Attributes:
        agent: The agent whose call failed (``composer``, ``arranger``, ``conductor``), if known.
        headline: The message without the list of problems.
        problems: One line per problem, the last ones seen.
        call: The record of the failed call, if one was made.
        calls: Every call of the plan that failed, the failed one last (set by
            :func:`~agentchord.agents.pipeline.plan_task`), so that the replies are kept.
    """

    def __init__(
        self,
        message: str,
        *,
        agent: str | None = None,
        problems: Sequence[str] = (),
        call: ReasonerCall | None = None,
    ) -> None:
        self.agent = agent
        self.headline = message
        self.problems = list(problems)
        self.call = call
        self.calls: list[ReasonerCall] = [call] if call is not None else []
        lines = [message, *(f"  - {problem}" for problem in self.problems)]
        super().__init__("\n".join(lines))

    def __reduce__(self) -> tuple[object, ...]:
        # Subclasses take other arguments than the message: rebuild from the state, so
        # that an error raised in a bench worker process reaches the parent intact.
        return (_rebuild, (type(self), self.args, self.__dict__))


def _rebuild(cls: type[ReasonerError], args: tuple, state: dict) -> ReasonerError:
    error = cls.__new__(cls)
    Exception.__init__(error, *args)
    error.__dict__.update(state)
    return error


class ReasonerConfigError(ReasonerError):
    """A reasoner is missing a setting (endpoint, model, key) or has an invalid one.

    Attributes:
        missing: Names of the environment variables that were needed and unset.
    """

    def __init__(self, message: str, *, missing: Sequence[str] = (), problems: Sequence[str] = ()) -> None:
        self.missing = list(missing)
        super().__init__(message, problems=problems)


class ReasonerTransportError(ReasonerError):
    """The endpoint could not be reached, or refused the request, after every retry.

    Attributes:
        status: HTTP status of the last response, ``None`` for a connection error or timeout.
    """

    def __init__(
        self,
        message: str,
        *,
        agent: str | None = None,
        status: int | None = None,
        problems: Sequence[str] = (),
        call: ReasonerCall | None = None,
    ) -> None:
        self.status = status
        super().__init__(message, agent=agent, problems=problems, call=call)


class InvalidReplyError(ReasonerError):
    """Every reply, repairs included, failed the schema or the semantic checks.

    ``problems`` lists the problems of the last reply.
    """


class InstructionNotGroundedError(ReasonerError):
    """The offline composer cannot read an instruction, or its words name no scene object.

    Attributes:
        instruction: The instruction as given.
        reason: Which words failed and why.
    """

    def __init__(self, instruction: str, reason: str) -> None:
        self.instruction = instruction
        self.reason = reason
        super().__init__(
            f"cannot ground the instruction {_shorten(instruction)!r}: {_shorten(reason, 300)}. Give the goal as a goal spec "
            "(`--goal goal.yaml`, see `agentchord schema goal`) or use an LLM (`--reasoner llm`).",
            agent="composer",
        )


class InfeasibleGoalError(ReasonerError):
    """A goal that no plan can achieve in the scene: the reasons (size, containment, a cycle) are the problems."""

    def __init__(self, problems: Sequence[str]) -> None:
        super().__init__("the goal cannot be achieved in this scene:", agent="composer", problems=problems)


def _shorten(text: str, limit: int = 200) -> str:
    # An instruction can be any length; the message quotes enough of it to recognise it.
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text):,} characters)"


class PlanningError(ReasonerError):
    """No sequence of skills reaches the goal from the scene."""

    def __init__(self, message: str) -> None:
        super().__init__(message, agent="composer")
