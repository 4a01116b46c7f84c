"""How large each agent's prompt is: it costs time to first token, so it is measured and reported.

Tokens are estimated as characters / 4 (the usual figure for English and JSON with
OpenAI's tokenizers); an endpoint reports the exact count in each call's usage.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Characters per token of the estimate.
CHARS_PER_TOKEN = 4


def estimate_tokens(text: str) -> int:
    """Estimated tokens of a text: characters / 4, rounded up."""
    return -(-len(text) // CHARS_PER_TOKEN)


@dataclass(frozen=True)
class PromptSize:
    """The size of one request.

    Attributes:
        agent: The agent asked.
        system_chars: Characters of the system prompt (skill notes included).
        notes_chars: Characters of the skill notes in it.
        user_chars: Characters of the user message (the instruction, scene and graph).
    """

    agent: str
    system_chars: int
    notes_chars: int
    user_chars: int

    @property
    def chars(self) -> int:
        """Characters sent in all."""
        return self.system_chars + self.user_chars

    @property
    def tokens(self) -> int:
        """Estimated prompt tokens (characters / 4)."""
        return -(-self.chars // CHARS_PER_TOKEN)


def prompt_size(request: object, mode: str = "json_schema") -> PromptSize:
    """The size of the prompt an LLM reasoner sends for ``request`` (an agent request)."""
    from agentchord.agents.llm.messages import request_message, system_prompt  # avoids a cycle
    from agentchord.agents.llm.skills import skills_section

    agent = request.agent  # type: ignore[attr-defined]
    system = system_prompt(agent, mode, request)  # type: ignore[arg-type]
    notes = skills_section(agent, request)  # type: ignore[arg-type]
    return PromptSize(agent, len(system), len(notes), len(request_message(request)))  # type: ignore[arg-type]
