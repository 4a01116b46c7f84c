"""What is sent to the model: the system prompt of each agent, the request, a repair turn.

The system prompt is the agent's prompt file plus the skill notes the request calls for
(:mod:`~agentchord.agents.llm.skills`); the user message carries the whole scene the offline
reasoner sees (objects, arms, regions, notes), so both reason over the same facts.
"""

from __future__ import annotations

import json

from agentchord.agents.llm.replies import task_graph_schema
from agentchord.agents.llm.skills import skills_section
from agentchord.agents.prompts import graph_json, render_prompt
from agentchord.agents.reasoner import AgentRequest, ArrangeRequest, ComposeRequest, ConductRequest
from agentchord.agents.scene import Scene

#: How to read the scene's numbers; the same words head every agent's scene.
SCENE_LEGEND = (
    "world frame, metres; quat = w, x, y, z; extent = full size along the object's principal axes; "
    "axis = its bottom-to-top direction; reachable_by = the arms that can grasp it where it lies; "
    "an arm's base = where it stands (x, y), reach_top / reach_side = how far from its base it reaches "
    "on the table from above / with a side grasp of a tall object; regions = named discs on the table "
    "(centre x, y and radius) that an instruction may name"
)


def system_prompt(agent: str, mode: str = "json_schema", request: AgentRequest | None = None) -> str:
    """The system message of an agent; without ``json_schema`` output, the schema is appended.

    Args:
        agent: ``composer``, ``arranger`` or ``conductor``.
        mode: The structured-output mode of the request.
        request: The request it answers: its instruction and scene choose the skill notes
            appended to the prompt (none without a request).
    """
    prompt = render_prompt(agent)
    if request is not None:
        prompt += skills_section(agent, request)
    if mode == "json_schema":
        return prompt
    schema = json.dumps(task_graph_schema(), separators=(",", ":"))
    return f"{prompt}\n\n# Reply format\n\nThe reply is one JSON object that matches this JSON Schema:\n\n{schema}\n"


def request_message(request: AgentRequest) -> str:
    """The user message that carries a request's data (the task itself is in the system prompt)."""
    scene = scene_json(request.scene)
    if isinstance(request, ComposeRequest):
        return "\n".join(
            [
                f"Instruction: {request.instruction}",
                f"Task name: {request.task or '(choose a short snake_case name)'}",
                f"First observation ({SCENE_LEGEND}):",
                scene,
                "",
                "Write the nominal task graph.",
            ]
        )
    if isinstance(request, ArrangeRequest):
        lines = [
            f"Instruction: {request.graph.instruction or '(not given)'}",
            f"Scene ({SCENE_LEGEND}):",
            scene,
            "",
        ]
        if request.failure is None:
            lines += [
                "Nominal task graph:",
                graph_json(request.graph),
                "",
                "Return the recovery-augmented graph.",
            ]
        else:
            failure = request.failure
            lines += [
                "Current task graph:",
                graph_json(request.graph),
                "",
                f"Online repair: edge {failure.edge!r} ended without reaching its target's sub-goal and no "
                f"monitor fired. Failure context (last completed sub-goal): {failure.context!r}.",
                f"Observation: {failure.observation or '(none)'}",
                f"Return the whole graph with one new failure mode on edge {failure.edge!r} and its recovery branch.",
            ]
        return "\n".join(lines)
    if isinstance(request, ConductRequest):
        return "\n".join(
            [
                f"Instruction: {request.graph.instruction or '(not given)'}",
                f"Scene ({SCENE_LEGEND}):",
                scene,
                "",
                "Recovery-augmented task graph:",
                graph_json(request.graph),
                "",
                "Return the graph with its parameters grounded in this scene.",
            ]
        )
    raise TypeError(f"expected a ComposeRequest, ArrangeRequest or ConductRequest, got {type(request).__name__}")


def scene_json(scene: Scene) -> str:
    """A scene as JSON, every field of it (objects, arms, regions, notes), one item per line.

    Every field of :class:`~agentchord.agents.scene.Scene` is written, so a field added to the
    scene reaches the model too: it reads what the offline reasoner reads.
    """
    data = scene.model_dump(mode="json")
    entries = []
    for key, value in data.items():
        if isinstance(value, list) and value:
            items = ",\n".join(f"    {json.dumps(item)}" for item in value)
            entries.append(f'  "{key}": [\n{items}\n  ]')
        else:
            entries.append(f'  "{key}": {json.dumps(value)}')
    return "{\n" + ",\n".join(entries) + "\n}"


def repair_message(problems: list[str]) -> str:
    """The follow-up user message that asks the model to fix an invalid reply."""
    listed = "\n".join(f"- {problem}" for problem in problems)
    return (
        "Your reply is not a valid task graph. Problems (field path: what is wrong):\n"
        f"{listed}\n\n"
        "Reply again with the complete corrected task graph as one JSON object, no prose; "
        "keep everything that was right."
    )
