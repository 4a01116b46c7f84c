"""The offline composer: goal spec + scene -> nominal task graph (paper Sec. III-B).

Plan each goal predicate in order with the STRIPS planner over the scene's skills
(keeping what earlier goals achieved), schedule the plan into rounds where the two arms
work at once, and write one node per round: its semantic from the skills, its
constraints from the facts that hold there (:func:`~agentchord.agents.rules.constraints.fact_constraints`).
"""

from __future__ import annotations

from dataclasses import dataclass

from agentchord.agents.scene import Scene
from agentchord.agents.rules import constraints, facts, skills
from agentchord.agents.rules.goals import GoalSpec
from agentchord.agents.rules.planner import Operator, Plan, Round, State, plan, schedule
from agentchord.graph.models import Edge, Node, TaskGraph


@dataclass
class Composition:
    """What the composer decided, beside the graph.

    Attributes:
        graph: The nominal graph.
        rounds: The scheduled operators, one round per edge.
        states: The symbolic state at each node (``states[i]`` at node ``v{i}``).
        expanded: States the planner expanded, over all goals.
    """

    graph: TaskGraph
    rounds: list[Round]
    states: list[State]
    expanded: int


def compose(goal: GoalSpec, scene: Scene, task: str = "", instruction: str = "") -> Composition:
    """The nominal graph that achieves ``goal`` in ``scene``.

    Raises:
        PlanningError: A goal cannot be reached with the scene's skills.
    """
    operators = skills.ground(scene, goal)
    state = facts.initial_state(scene, goal)
    initial = state
    ops: list[Operator] = []
    states = [state]
    expanded = 0
    for wanted in facts.goal_facts(goal, scene):
        part: Plan = plan(state, wanted, operators)
        ops += part.operators
        states += part.states[1:]
        expanded += part.expanded
        state = part.states[-1]
    rounds, round_states = schedule(Plan(ops, states, expanded), initial)
    return Composition(_graph(rounds, round_states, goal, scene, task, instruction), rounds, round_states, expanded)


def _graph(rounds: list[Round], states: list[State], goal: GoalSpec, scene: Scene, task: str, instruction: str) -> TaskGraph:
    # Only objects the goal or the plan touch are constrained: the rest of the table is not the task's.
    relevant = set(goal.objects()) | {name for rnd in rounds for op in rnd.operators for name in op.objects}
    states = [frozenset(f for f in state if f[0] not in ("upright", "on_table") or f[1] in relevant) for state in states]
    nodes = [Node(id="v0", semantic=_initial_semantic(scene, goal), constraints=_constraints(states[0], frozenset(), scene, initial=True))]
    edges = []
    for i, rnd in enumerate(rounds, start=1):
        added = states[i] - states[i - 1]
        nodes.append(Node(id=f"v{i}", semantic=" ".join(op.semantic for op in rnd.operators), constraints=_constraints(states[i], added, scene)))
        path = _path_constraints(rnd, states[i - 1], scene)
        edges.append(Edge(id=f"e{i}", source=f"v{i - 1}", target=f"v{i}", actions=rnd.steps, path_constraints=path))
    if rounds:
        nodes[-1] = nodes[-1].model_copy(update={"semantic": nodes[-1].semantic + " Task complete."})
    return TaskGraph(
        task=task or "planned_task",
        instruction=instruction,
        start="v0",
        goal=f"v{len(rounds)}",
        objects=[o.name for o in scene.objects if o.name in relevant],
        nodes=nodes,
        edges=edges,
    )


def _initial_semantic(scene: Scene, goal: GoalSpec) -> str:
    names = ", ".join(goal.objects())
    return f"Both arms home; {names} as first observed."


def _constraints(state: State, added: frozenset, scene: Scene, initial: bool = False) -> list[str]:
    out: list[str] = []
    for fact in sorted(state):
        if fact[0] in facts.EVENT_FACTS and fact not in added:
            continue
        if initial and fact[0] == "on_table":
            continue
        for expr in constraints.fact_constraints(fact, scene):
            if expr not in out:
                out.append(expr)
    return out + [c for c in constraints.upright_constraints(state) if c not in out]


def _path_constraints(rnd: Round, before: State, scene: Scene) -> list[str]:
    # A held vessel or container carried by a motion stays upright on the way.
    upright = {f[1] for f in before if f[0] == "upright"}
    out = []
    for op in rnd.operators:
        if op.skill in ("approach", "present", "offer"):
            for arm in op.arms:
                for fact in sorted(before):
                    if fact[0] == "holding" and fact[1] == arm and fact[2] in upright:
                        out.append(f"tilt({fact[2]}) - 20")
    return out
