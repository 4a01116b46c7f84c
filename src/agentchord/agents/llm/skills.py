"""Skill notes: what a task's skills need that the action table does not say, chosen per request.

The notes live in ``agents/prompts/skills.md``, one ``## name`` section each::

    ## handover
    When: hand over, handover, pass
    Does: handover
    Title: Handing an object from one arm to the other

    Paragraphs every agent reads.

    [arranger] A paragraph only the arranger reads ([composer], [conductor] likewise).

The arranger and the conductor get the notes for what the graph they are given does
(:func:`graph_features`: a hand-over in either direction, a two-arm carry, a place beside or
into another object, a thin object carried, a pour) and what the scene holds (regions, a
cloth): the graph, not the instruction's words, says which skills a plan uses. The composer,
which has no graph yet, gets the notes whose ``When`` terms occur, as whole words, in the
instruction or the scene's object and region names and descriptions, and those the scene
calls for. So a prompt's size grows with the task's skills, not with the library's.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass
from importlib import resources

from agentchord.agents.reasoner import AgentRequest, ComposeRequest
from agentchord.agents.scene import Region, Scene, SceneObject
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import nominal_path

#: The file of the notes, in the prompts package.
SKILLS_FILE = "skills.md"
#: Agents a paragraph may be addressed to.
AGENT_TAGS = ("composer", "arranger", "conductor")
#: What a graph or a scene may do or hold that selects a note (a note's ``Does:`` line).
GRAPH_FEATURES = ("regions", "handover", "two_arm_carry", "cloth", "placed_relative", "thin_flat", "placed_inside", "pouring", "insertion")
#: An object less tall than this (m) and narrower than :data:`THIN_WIDTH` is thin (cutlery); a point
#: (a cloth corner, 8 mm) is not.
THIN_HEIGHT = 0.02
#: See :data:`THIN_HEIGHT` (m): a tray or a plate is flat but wide enough to hold.
THIN_WIDTH = 0.06
#: An object no larger than this (m) along every axis is a point (a cloth's corner).
POINT_SIZE = 0.01


def _is_point(obj: SceneObject) -> bool:
    return max(obj.extent) <= POINT_SIZE


def _is_thin(obj: SceneObject) -> bool:
    return not _is_point(obj) and obj.extent[2] < THIN_HEIGHT and min(obj.extent[:2]) < THIN_WIDTH

_TAG = re.compile(r"^\[(\w+)\]\s*")


class SkillNotesError(ValueError):
    """The skill notes file is malformed (the message names the section and the line)."""


@dataclass(frozen=True)
class SkillNote:
    """One skill note.

    Attributes:
        name: Its section name (``handover``).
        title: Its heading in the prompt.
        when: Terms (lower case) whose occurrence in a composer's request selects it.
        does: What a graph or scene does that selects it (:data:`GRAPH_FEATURES`).
        paragraphs: ``(agent or None, text)``; ``None`` means every agent.
    """

    name: str
    title: str
    when: tuple[str, ...]
    does: tuple[str, ...]
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
        while lines and re.match(r"^(When|Does|Title):", lines[0]):
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
        does = tuple(term.strip() for term in fields.get("Does", "").split(",") if term.strip())
        if unknown := [term for term in does if term not in GRAPH_FEATURES]:
            raise SkillNotesError(f"{source}: section {name!r}: unknown Does: {', '.join(unknown)} (have: {', '.join(GRAPH_FEATURES)})")
        notes.append(SkillNote(name, fields["Title"], when, does, tuple(paragraphs)))
    return tuple(notes)


def request_words(request: AgentRequest) -> str:
    """The text a request's notes are chosen by: instruction, object and region names and descriptions."""
    instruction = request.instruction if isinstance(request, ComposeRequest) else request.graph.instruction or ""
    return " ".join([instruction, *scene_words(request.scene)]).lower().replace("_", " ")


def scene_words(scene: Scene) -> list[str]:
    """Names and descriptions of a scene's objects and regions."""
    words = []
    items: list[SceneObject | Region] = [*scene.objects, *scene.regions]
    for item in items:
        words += [item.name, item.description]
    return words


def scene_features(scene: Scene) -> set[str]:
    """What a scene holds that calls for a note whatever the plan: named regions, a cloth."""
    features = {"regions"} if scene.regions else set()
    if any(obj.name.rsplit("_", 1)[-1] in ("bl", "br", "tl", "tr") and _is_point(obj) for obj in scene.objects):
        features.add("cloth")
    return features


def graph_features(graph: TaskGraph, scene: Scene) -> set[str]:
    """What a graph's nominal path does (:data:`GRAPH_FEATURES`), read from its actions in order.

    A hand-over is a grasp of an object that the other arm holds, whichever arm gives; a two-arm
    carry, one step in which both arms grasp the same object; a place relative to another object
    at an offset is a placement beside it (in front, behind ...), at its centre a placement into
    or onto it; a thin object is one less than :data:`THIN_HEIGHT` tall that an arm grasps; a pour,
    a ``rotate_eef``; an insertion, an ``insert``.
    """
    try:
        path = nominal_path(graph)
    except Exception:  # an unsound graph is the checks' to report
        path = [e.id for e in graph.nominal_edges()]
    objects = {obj.name: obj for obj in scene.objects}
    features = scene_features(scene)
    held: dict[str, set[str]] = {}  # arm -> objects it holds
    for edge_id in path:
        for step in graph.edge(edge_id).steps:
            grasped = {arm: call.args.get("obj") for arm, call in step.items() if call is not None and call.fn == "grasp"}
            if len(grasped) == 2 and len(set(grasped.values())) == 1:
                features.add("two_arm_carry")
            for arm, call in step.items():
                if call is None:
                    continue
                obj = call.args.get("obj")
                if call.fn == "grasp" and isinstance(obj, str):
                    together = len(grasped) == 2 and len(set(grasped.values())) == 1
                    if not together and any(obj in objs for other, objs in held.items() if other != arm):
                        features.add("handover")
                    if obj in objects and _is_thin(objects[obj]):
                        features.add("thin_flat")
                    held.setdefault(arm, set()).add(obj)
                elif call.fn == "place":
                    held.get(arm, set()).discard(obj)
                    anchor, target = call.args.get("relative_to"), call.args.get("target") or (0.0, 0.0)
                    if anchor is not None and not (obj in objects and _is_point(objects[obj])):
                        near = all(abs(float(v)) < 0.03 for v in list(target)[:2])
                        features.add("placed_inside" if near else "placed_relative")
                elif call.fn in ("open_gripper", "back"):
                    held.pop(arm, None)
                elif call.fn == "rotate_eef":
                    features.add("pouring")
                elif call.fn == "insert":
                    features.add("insertion")
    return features


def select_notes(request: AgentRequest) -> list[SkillNote]:
    """The notes a request calls for, in file order: by the graph it carries (arranger, conductor),
    else by the instruction's words (composer); and by what its scene holds."""
    if isinstance(request, ComposeRequest):
        text = request_words(request)
        features = scene_features(request.scene)
        return [note for note in skill_notes() if any(_occurs(term, text) for term in note.when) or features & set(note.does)]
    features = graph_features(request.graph, request.scene)
    return [note for note in skill_notes() if features & set(note.does)]


def skills_section(agent: str, request: AgentRequest) -> str:
    """The prompt section of the notes chosen for ``request``, as ``agent`` reads them ('' if none)."""
    texts = [note.text(agent) for note in select_notes(request)]
    texts = [t for t in texts if t]
    if not texts:
        return ""
    return "\n\n# Skill notes for this task\n\n" + "\n\n".join(texts) + "\n"


def _occurs(term: str, text: str) -> bool:
    return re.search(rf"(?<![a-z]){re.escape(term)}(?![a-z])", text) is not None
