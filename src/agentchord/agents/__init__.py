"""The agents of AgentChord and the reasoners that answer them.

The composer, arranger and conductor (paper Sec. III-B to III-E) ask a
:class:`Reasoner` for a task graph. Two reasoners implement it: ``rules``, the
offline knowledge-based default, and :class:`~agentchord.agents.llm.LlmReasoner`,
any OpenAI-compatible chat-completions endpoint. The LLM reasoner is imported
lazily (``from agentchord.agents import LlmReasoner`` works) so that the offline
path never loads the ``openai`` client.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from agentchord.agents.checks import check_reply
from agentchord.agents.exceptions import (
    InvalidReplyError,
    ReasonerConfigError,
    ReasonerError,
    ReasonerTransportError,
)
from agentchord.agents.reasoner import (
    AGENTS,
    Agent,
    AgentRequest,
    ArrangeRequest,
    ComposeRequest,
    ConductRequest,
    Reasoner,
    ReasonerAttempt,
    ReasonerCall,
    UnanticipatedFailure,
    total_usage,
)
from agentchord.agents.scene import ArmState, Scene, SceneObject

if TYPE_CHECKING:
    from agentchord.agents.llm import LlmConfig, LlmReasoner

_LAZY = {"LlmConfig": "agentchord.agents.llm", "LlmReasoner": "agentchord.agents.llm"}

__all__ = [
    "AGENTS",
    "Agent",
    "AgentRequest",
    "ArmState",
    "ArrangeRequest",
    "ComposeRequest",
    "ConductRequest",
    "InvalidReplyError",
    "LlmConfig",
    "LlmReasoner",
    "Reasoner",
    "ReasonerAttempt",
    "ReasonerCall",
    "ReasonerConfigError",
    "ReasonerError",
    "ReasonerTransportError",
    "Scene",
    "SceneObject",
    "UnanticipatedFailure",
    "check_reply",
    "total_usage",
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
