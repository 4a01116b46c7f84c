"""What each baseline's reasoning calls write, for the token-priced latency model.

Each call is priced by its own output (:mod:`agentchord.agents.replies` counts the tokens):

- Inner Monologue and DoReMi: a whole plan at the start and at every re-plan (the composer's
  nominal graph); at each sub-goal the next step, asked with the feedback in context (one edge and
  the sub-goal it reaches); a VQA answer (a yes/no and a short reason, one image).
- ReKep: one call writing every stage's constraints (ReKep's ``stageN_subgoal_constraints``,
  ``stageN_path_constraints``, grasp and release keypoints), here each stage's sub-goal and path
  constraints and what it grasps and releases, in the project's expression language (terser than
  ReKep's Python functions: the price is a lower bound).
- Code-as-Monitor: at each sub-goal's start, the constraint generator (the next sub-goal, its
  constraints during execution and upon completion; front and top views) and the monitor writer
  (the sub-goal's monitors; one annotated view).
"""

from __future__ import annotations

from agentchord.agents.replies import count_tokens, edge_reply
from agentchord.execution.planning import composer_call
from agentchord.execution.reasoning import VQA_REPLY_TOKENS, ModelledCall
from agentchord.graph.models import TaskGraph
from agentchord.graph.progress import nominal_path

__all__ = ["composer_call", "next_step_call", "stages_call", "stages_reply", "subgoal_calls", "vqa_call"]

#: Views the Code-as-Monitor constraint generator reads (front and top, CaM Eq. 1).
GENERATOR_IMAGES = 2
#: Views the Code-as-Monitor monitor writer reads (the view annotated with constraint elements).
MONITOR_IMAGES = 1


def vqa_call() -> ModelledCall:
    """One VQA query: an image in, a yes/no and a short reason out."""
    return ModelledCall("vqa", "vqa", VQA_REPLY_TOKENS, images=1, part="yes/no and a reason")


def next_step_call(graph: TaskGraph, edge_id: str) -> ModelledCall:
    """The planner asked for the next step: one edge and the sub-goal it reaches."""
    edge = graph.edge(edge_id)
    reply = {"step": edge_reply(edge), "subgoal": graph.node(edge.target).model_dump(mode="json", exclude_defaults=True)}
    return ModelledCall("composer", "plan", count_tokens(reply), part=f"next step {edge_id}")


def stages_call(graph: TaskGraph) -> ModelledCall:
    """ReKep's one call: every stage's sub-goal and path constraints, what it grasps and releases."""
    return ModelledCall("composer", "plan", count_tokens(stages_reply(graph)), part="every stage's constraints")


def stages_reply(graph: TaskGraph) -> dict:
    """What ReKep's one call writes, per stage (nominal edge): constraints, grasps, releases."""
    stages = []
    for edge_id in nominal_path(graph):
        edge = graph.edge(edge_id)
        stage = {"subgoal_constraints": graph.node(edge.target).constraints, "path_constraints": edge.path_constraints}
        grasped = sorted({c.args["obj"] for _, c in edge.calls if c.fn == "grasp" and "obj" in c.args})
        released = sorted({c.args["obj"] for _, c in edge.calls if c.fn == "place" and "obj" in c.args})
        stage.update({k: v for k, v in (("grasp", grasped), ("release", released)) if v})
        stages.append(stage)
    return {"stages": stages}


def subgoal_calls(graph: TaskGraph, edge_id: str | None) -> list[ModelledCall]:
    """Code-as-Monitor at a sub-goal's start: the constraint generator, then the monitor writer."""
    if edge_id is None:
        return []
    edge = graph.edge(edge_id)
    target = graph.node(edge.target)
    constraints = {"subgoal": target.semantic, "during": edge.path_constraints, "upon_completion": target.constraints}
    monitors = [{"name": f.name, "monitor": f.monitor, "window": f.window} for f in edge.failures]
    return [
        ModelledCall("composer", "vlm", count_tokens(constraints), images=GENERATOR_IMAGES, part=f"{edge_id} constraints"),
        ModelledCall("arranger", "vlm", count_tokens(monitors), images=MONITOR_IMAGES, part=f"{edge_id} monitor code"),
    ]
