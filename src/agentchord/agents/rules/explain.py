"""``agentchord plan --explain``: what the offline composer read, as text.

clauses (the grammar's parse) -> goal predicates (each clause's, in the scene) -> skills
(the ground operators the planner chose, in order) -> graph (the nominal nodes and edges).
A pure function of the instruction (or goal spec) and the scene: it plans again, cheaply,
and says where reading or planning stopped when it does.
"""

from __future__ import annotations

from agentchord.agents.exceptions import ReasonerError
from agentchord.agents.scene import Scene
from agentchord.agents.rules.discourse import NotAGoalError
from agentchord.agents.rules.composer import compose
from agentchord.agents.rules.goals import GoalSpec
from agentchord.agents.rules.instructions import Reading, read_instruction, vocabulary
from agentchord.agents.rules.language import Clause, ParseError, normalise, parse_prepared, prepare


def _goal_text(goal) -> str:
    fields = goal.model_dump(exclude_none=True)
    fields.pop("kind", None)
    if fields.get("offset") in ((0.0, 0.0), [0.0, 0.0]):
        fields.pop("offset")
    if fields.get("hold_target") is False:
        fields.pop("hold_target")
    args = ", ".join(f"{k}={tuple(v) if isinstance(v, list) else v}" for k, v in fields.items())
    return f"{goal.kind}({args})"


def _clause_text(clause: Clause) -> str:
    parts = [clause.verb]
    if clause.source is not None:
        parts.append(f"from={clause.source.text!r}")
    if clause.target is not None:
        parts.append(f"into={clause.target.text!r}")
    elif clause.objects:
        parts.append("objects=" + ", ".join(repr(o.text) for o in clause.objects))
    if clause.where is not None:
        parts.append(f"where={clause.where.relation}" + (f" {clause.where.side}" if clause.where.side else "")
                     + (" " + " & ".join(repr(p.text) for p in clause.where.phrases) if clause.where.phrases else ""))
    for name in ("arm", "giver", "receiver", "direction"):
        if getattr(clause, name):
            parts.append(f"{name}={getattr(clause, name)}")
    if clause.arms and any(clause.arms):
        parts.append("arms=" + ", ".join(str(a) for a in clause.arms))
    if clause.back:
        parts.append("back")
    return " ".join(parts)


def _words(reading: Reading) -> list[str]:
    """How each word was read: the rewrites, the typos corrected, then verb, object, arm and place of each phrase."""
    lines = ["words:"]
    if reading.prepared is not None:
        for typo, word in reading.prepared.corrected.items():
            lines.append(f"  {typo!r} -> typo of {word!r}")
        if reading.prepared.steps:
            lines.append(f"  rewritten ({', '.join(dict.fromkeys(reading.prepared.steps))}): {reading.prepared.text!r}")
    for clause in reading.clauses:
        if clause.text and not clause.text.startswith("("):
            lines.append(f"  {clause.text.split()[0]!r} -> verb {clause.verb}")
        if clause.where is not None:
            phrases = " & ".join(repr(p.text) for p in clause.where.phrases)
            lines.append(f"  {phrases or repr(clause.where.relation)} -> place ({clause.where.relation}{' ' + clause.where.side if clause.where.side else ''})")
        for arm in {a for a in (clause.arm, clause.giver, clause.receiver, *clause.arms) if a}:
            lines.append(f"  {arm + ' arm'!r} -> arm {arm}")
        if clause.direction:
            lines.append(f"  {clause.direction!r} -> place (direction)")
    for words, role, what in reading.words:
        lines.append(f"  {words!r} -> {role} {what}")
    return lines


def explain_plan(instruction: str, scene: Scene, goal: GoalSpec | None = None) -> str:
    """The parse of ``instruction`` in ``scene`` as lines of text: clauses -> goal predicates -> skills -> graph."""
    lines: list[str] = []
    if goal is None:
        lines.append(f"instruction: {instruction!r}")
        lines.append(f"normalised:  {normalise(instruction)!r}")
        known, objects = vocabulary(scene)
        try:
            prepared = prepare(instruction, known, objects)
        except NotAGoalError as error:
            lines.append(f"refused: {error}")
            return "\n".join(lines)
        if prepared.text != normalise(instruction):
            lines.append(f"rewritten:   {prepared.text!r}" + (f" (typos: {prepared.corrected})" if prepared.corrected else ""))
        try:
            clauses = parse_prepared(prepared.text)
        except ParseError as error:
            lines.append(f"clauses: the grammar stops at {error.words!r}")
            return "\n".join(lines)
        lines.append("clauses -> goal predicates:")
        try:
            reading = read_instruction(instruction, scene)
        except ReasonerError as error:
            for i, clause in enumerate(clauses, start=1):
                lines.append(f"  {i}. {clause.text!r}: {_clause_text(clause)}")
            lines.append(f"  refused: {error}")
            return "\n".join(lines)
        for i, (clause, goals) in enumerate(zip(reading.clauses, reading.goals, strict=True), start=1):
            lines.append(f"  {i}. {clause.text!r}: {_clause_text(clause)}")
            lines.append("       -> " + ("; ".join(_goal_text(g) for g in goals) if goals else "(no goal: who holds what, for later clauses)"))
        lines += _words(reading)
        goal = reading.goal
    else:
        lines.append("goal spec (given):")
        lines += [f"  - {_goal_text(g)}" for g in goal.goals]
    try:
        composition = compose(goal, scene, instruction=instruction)
    except ReasonerError as error:
        lines.append(f"skills: planning stops: {error}")
        return "\n".join(lines)
    lines.append(f"skills ({sum(len(r.operators) for r in composition.rounds)} operators, {composition.expanded} states expanded):")
    for i, rnd in enumerate(composition.rounds, start=1):
        lines.append(f"  e{i}: " + " | ".join(f"{op.skill}: {op.name}" for op in rnd.operators))
    graph = composition.graph
    lines.append(f"graph ({len(graph.nodes)} nodes, {len(graph.edges)} edges, nominal):")
    for node in graph.nodes:
        lines.append(f"  {node.id}: {node.semantic}")
    for edge in graph.edges:
        calls = "; ".join(f"{arm}.{step['fn']}" for phase in edge.actions for arm, step in _phase_items(phase))
        lines.append(f"  {edge.id}: {edge.source} -> {edge.target}  [{calls}]")
    return "\n".join(lines)


def _phase_items(phase) -> list[tuple[str, dict]]:
    if isinstance(phase, dict):
        return [(arm, step if isinstance(step, dict) else getattr(step, "model_dump", lambda step=step: {"fn": str(step)})()) for arm, step in phase.items()]
    dumped = phase.model_dump() if hasattr(phase, "model_dump") else {}
    return [(arm, step) for arm, step in dumped.items() if isinstance(step, dict) and "fn" in step]
