"""Skill notes: what a task's skills need that the action table does not say, chosen per request.

The notes live in ``agents/prompts/skills.md``, one ``## name`` section each::

    ## handover
    When: hand over, handover, pass
    Title: Handing an object from one arm to the other

    Paragraphs every agent reads.

    [arranger] A paragraph only the arranger reads ([composer], [conductor] likewise).

A note is appended to an agent's system prompt when one of its ``When`` terms occurs, as
whole words, in the request's instruction, its scene's object names and descriptions or its
region names and descriptions. So a prompt carries the hand-over note only for a hand-over,
and its size grows with the task's skills, not with the library's.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from importlib import resources

from agentchord.agents.reasoner import AgentRequest, ComposeRequest
from agentchord.agents.scene import Scene

#: The file of the notes, in the prompts package.
SKILLS_FILE = "skills.md"
#: Agents a paragraph may be addressed to.
AGENT_TAGS = ("composer", "arranger", "conductor")

_TAG = re.compile(r"^\[(\w+)\]\s*")


class SkillNotesError(ValueError):
    """The skill notes file is malformed (the message names the section and the line)."""


@dataclass(frozen=True)
class SkillNote:
    """One skill note.

    Attributes:
        name: Its section name (``handover``).
        title: Its heading in the prompt.
        when: Terms (lower case) whose occurrence in a request selects it.
        paragraphs: ``(agent or None, text)``; ``None`` means every agent.
    """

    name: str
    title: str
    when: tuple[str, ...]
    paragraphs: tuple[tuple[str | None, str], ...]

    def text(self, agent: str) -> str:
        """The note as ``agent`` reads it (empty when no paragraph is for it)."""
        body = [text for who, text in self.paragraphs if who in (None, agent)]
        return f"## {self.title}\n\n" + "\n\n".join(body) if body else ""


@functools.lru_cache(maxsize=1)
def skill_notes() -> tuple[SkillNote, ...]:
    """Every note of ``skills.md``, in file order.

    Raises:
        SkillNotesError: A section lacks its ``When:`` or ``Title:`` line, or tags a paragraph
            with an unknown agent.
    """
    text = (resources.files("agentchord.agents.prompts") / SKILLS_FILE).read_text(encoding="utf-8")
    return parse_skill_notes(text)


def parse_skill_notes(text: str, source: str = SKILLS_FILE) -> tuple[SkillNote, ...]:
    """The notes in the text of a skills file (see the module docstring for the format).

    Raises:
        SkillNotesError: A malformed section (the message names ``source`` and the section).
    """
    notes = []
    for section in re.split(r"^## ", text, flags=re.MULTILINE)[1:]:
        head, _, rest = section.partition("\n")
        name = head.strip()
        fields: dict[str, str] = {}
        lines = rest.strip("\n").splitlines()
        while lines and re.match(r"^(When|Title):", lines[0]):
            key, _, value = lines.pop(0).partition(":")
            fields[key] = value.strip()
        for key in ("When", "Title"):
            if not fields.get(key):
                raise SkillNotesError(f"{source}: section {name!r}: expected a {key}: line under its heading")
        paragraphs = []
        for block in re.split(r"\n\s*\n", "\n".join(lines).strip()):
            match = _TAG.match(block)
            who = match.group(1) if match else None
            if who is not None and who not in AGENT_TAGS:
                raise SkillNotesError(f"{source}: section {name!r}: unknown agent tag [{who}] (have: {', '.join(AGENT_TAGS)})")
            paragraphs.append((who, block[match.end():] if match else block))
        when = tuple(term.strip().lower() for term in fields["When"].split(",") if term.strip())
        notes.append(SkillNote(name, fields["Title"], when, tuple(paragraphs)))
    return tuple(notes)


def request_words(request: AgentRequest) -> str:
    """The text a request's notes are chosen by: instruction, object and region names and descriptions."""
    instruction = request.instruction if isinstance(request, ComposeRequest) else request.graph.instruction or ""
    return " ".join([instruction, *scene_words(request.scene)]).lower().replace("_", " ")


def scene_words(scene: Scene) -> list[str]:
    """Names and descriptions of a scene's objects and regions."""
    words = []
    for item in [*scene.objects, *scene.regions]:
        words += [item.name, item.description]
    return words


def select_notes(request: AgentRequest) -> list[SkillNote]:
    """The notes whose terms occur in the request, in file order."""
    text = request_words(request)
    return [note for note in skill_notes() if any(_occurs(term, text) for term in note.when)]


def skills_section(agent: str, request: AgentRequest) -> str:
    """The prompt section of the notes chosen for ``request``, as ``agent`` reads them ('' if none)."""
    texts = [note.text(agent) for note in select_notes(request)]
    texts = [t for t in texts if t]
    if not texts:
        return ""
    return "\n\n# Skill notes for this task\n\n" + "\n\n".join(texts) + "\n"


def _occurs(term: str, text: str) -> bool:
    return re.search(rf"(?<![a-z]){re.escape(term)}(?![a-z])", text) is not None
