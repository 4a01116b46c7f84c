"""The checks of an agent's reply: ``graph check``, plus what each agent must leave unchanged."""

from __future__ import annotations

from collections.abc import Mapping

from agentchord.agents.reach_check import reach_problems
from agentchord.agents.reasoner import AgentRequest, ArrangeRequest, ComposeRequest, ConductRequest
from agentchord.agents.scene import Scene
from agentchord.graph.models import TaskGraph
from agentchord.graph.validation import Problem, check_graph


def check_reply(request: AgentRequest, graph: TaskGraph) -> list[Problem]:
    """Every problem of ``graph`` as an answer to ``request``; empty means accepted.

    The checks of ``graph check`` (:func:`check_graph`), then the agent's own:

    - composer: a nominal graph only (no failure modes, no recovery nodes or
      edges); every graph object is a scene object; every grasp and place within
      its arm's reach (:mod:`agentchord.agents.reach_check`). The goal it states
      in ``success.goal_spec`` is checked by the reasoner that reads it (an LLM's:
      :func:`agentchord.agents.rules.feasibility.stated_goal_problems`).
    - arranger: start, goal, success and every nominal node and edge of the input
      kept (edge endpoints and actions unchanged); everything added is ``kind:
      recovery``; every graph object is a scene object.
    - conductor: the input's structure kept: the same node ids and kinds, the
      same edges with the same endpoints and kinds, the same failure modes per
      edge with the same recovery entry edges, the same success; every nominal
      grasp and place, as grounded, within its arm's reach.

    Args:
        request: What the agent was asked.
        graph: The graph it answered (schema-valid).
    """
    problems = check_graph(graph)
    if isinstance(request, ComposeRequest):
        problems += _check_nominal_only(graph)
        problems += _check_scene_objects(graph, request.scene)
        problems += reach_problems(graph, request.scene)
    elif isinstance(request, ArrangeRequest):
        problems += _check_keeps_nominal(request.graph, graph)
        problems += _check_keeps_success(request.graph, graph)
        problems += _check_scene_objects(graph, request.scene)
    elif isinstance(request, ConductRequest):
        problems += _check_keeps_structure(request.graph, graph)
        problems += _check_keeps_success(request.graph, graph)
        problems += reach_problems(graph, request.scene)
    else:  # pragma: no cover - guarded by the type
        raise TypeError(f"expected a ComposeRequest, ArrangeRequest or ConductRequest, got {type(request).__name__}")
    return problems


def _check_keeps_success(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    if after.success == before.success:
        return []
    return [Problem("success", "must stay as the input states it (the composer's goal); copy it unchanged")]


def _check_nominal_only(graph: TaskGraph) -> list[Problem]:
    why = "the composer writes the nominal graph only; failure modes and recovery branches are the arranger's"
    problems = [Problem(f"nodes[{i}].kind", why) for i, n in enumerate(graph.nodes) if n.is_recovery]
    for i, edge in enumerate(graph.edges):
        if edge.is_recovery:
            problems.append(Problem(f"edges[{i}].kind", why))
        if edge.failures:
            problems.append(Problem(f"edges[{i}].failures", why))
    return problems


def _check_scene_objects(graph: TaskGraph, scene: Scene) -> list[Problem]:
    names = scene.object_names
    if not names:
        return []
    return [
        Problem(f"objects[{i}]", f"{name!r} is not a scene object; the scene has {', '.join(names)}")
        for i, name in enumerate(graph.objects)
        if name not in names
    ]


def _check_keeps_nominal(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    problems = _check_ends(before, after)
    nodes = {n.id: n for n in after.nodes}
    for node in before.nodes:
        if node.is_recovery:
            continue
        if node.id not in nodes:
            message = f"nominal node {node.id!r} of the input is missing; keep every nominal node"
            problems.append(Problem("nodes", message))
        elif nodes[node.id].is_recovery:
            problems.append(Problem("nodes", f"nominal node {node.id!r} of the input became kind: recovery"))
    edges = {e.id: e for e in after.edges}
    for edge in before.nominal_edges():
        new = edges.get(edge.id)
        if new is None:
            message = f"nominal edge {edge.id!r} of the input is missing; keep every nominal edge"
            problems.append(Problem("edges", message))
            continue
        i = after.edges.index(new)
        if new.is_recovery:
            problems.append(Problem(f"edges[{i}].kind", f"nominal edge {edge.id!r} of the input became kind: recovery"))
        if (new.source, new.target) != (edge.source, edge.target):
            problems.append(
                Problem(
                    f"edges[{i}]",
                    f"nominal edge {edge.id!r} must keep {edge.source!r} -> {edge.target!r}, "
                    f"got {new.source!r} -> {new.target!r}",
                )
            )
        if new.actions != edge.actions:
            problems.append(Problem(f"edges[{i}].actions", f"nominal edge {edge.id!r} must keep its actions"))
    old_nodes = {n.id for n in before.nodes}
    old_edges = {e.id for e in before.edges}
    problems += [
        Problem(f"nodes[{i}].kind", f"node {n.id!r} is new: nodes the arranger adds are kind: recovery")
        for i, n in enumerate(after.nodes)
        if n.id not in old_nodes and not n.is_recovery
    ]
    problems += [
        Problem(f"edges[{i}].kind", f"edge {e.id!r} is new: edges the arranger adds are kind: recovery")
        for i, e in enumerate(after.edges)
        if e.id not in old_edges and not e.is_recovery
    ]
    return problems


def _check_keeps_structure(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    problems = _check_ends(before, after)
    old_nodes = {n.id: n.kind for n in before.nodes}
    new_nodes = {n.id: n.kind for n in after.nodes}
    if old_nodes != new_nodes:
        missing = sorted(old_nodes.keys() - new_nodes.keys())
        added = sorted(new_nodes.keys() - old_nodes.keys())
        changed = sorted(k for k in old_nodes.keys() & new_nodes.keys() if old_nodes[k] != new_nodes[k])
        groups = (("missing", missing), ("added", added), ("kind changed", changed))
        detail = "; ".join(f"{what}: {', '.join(ids)}" for what, ids in groups if ids)
        problems.append(Problem("nodes", f"the conductor must keep the nodes of its input ({detail})"))
    old_edges = {e.id: e for e in before.edges}
    new_ids = {e.id for e in after.edges}
    missing_edges = [e for e in before.edges if e.id not in new_ids]
    if missing_edges:
        ids = ", ".join(e.id for e in missing_edges)
        problems.append(Problem("edges", f"the conductor must keep every edge of its input (missing: {ids})"))
    for i, edge in enumerate(after.edges):
        old = old_edges.get(edge.id)
        if old is None:
            problems.append(Problem(f"edges[{i}].id", f"edge {edge.id!r} is new; the conductor must not add edges"))
            continue
        if (edge.source, edge.target, edge.kind) != (old.source, old.target, old.kind):
            problems.append(
                Problem(
                    f"edges[{i}]",
                    f"edge {edge.id!r} must keep {old.source!r} -> {old.target!r} ({old.kind}), "
                    f"got {edge.source!r} -> {edge.target!r} ({edge.kind})",
                )
            )
        old_map = {f.name: f.recovery for f in old.failures}
        new_map = {f.name: f.recovery for f in edge.failures}
        if old_map != new_map:
            problems.append(
                Problem(
                    f"edges[{i}].failures",
                    f"edge {edge.id!r} must keep its failure modes and their recovery edges "
                    f"({_mapping(old_map)}), got ({_mapping(new_map)})",
                )
            )
    return problems


def _check_ends(before: TaskGraph, after: TaskGraph) -> list[Problem]:
    return [
        Problem(field, f"must stay {getattr(before, field)!r}, got {getattr(after, field)!r}")
        for field in ("start", "goal")
        if getattr(before, field) != getattr(after, field)
    ]


def _mapping(mapping: Mapping[str, str]) -> str:
    return ", ".join(f"{name} -> {entry}" for name, entry in mapping.items()) or "none"
