"""Prompt files of the agents, with their reference tables filled in at run time.

Each agent has one Markdown file beside this module (``composer.md``,
``arranger.md``, ``conductor.md``). They contain ``{{placeholder}}`` marks
that :func:`render_prompt` replaces with tables generated from the code, so a
prompt can never list an action, argument, function or template the code does
not have:

========================  ===========================================================
``{{actions}}``           the atomic action catalogue (``agentchord.actions.catalog.ACTIONS``)
``{{arms}}``              the arm names
``{{features}}``          what an expression may read on an object or an arm
``{{functions}}``         the function library (``agentchord.expr.FUNCTIONS``)
``{{templates}}``         the monitor templates, Eq. 14-19 (``agentchord.expr.TEMPLATES``)
``{{expression_rules}}``  syntax of the expression language
``{{trigger_defaults}}``  default margin and window of a failure mode
``{{goal_language}}``     the goal predicates a composer states its goal in (``agents.rules.goals``)
``{{example_*}}``         the worked example: the library single-arm pour graph
========================  ===========================================================

``skills.md`` beside them holds the skill notes that
:mod:`agentchord.agents.llm.skills` appends to a prompt when a request calls for them.
"""

from __future__ import annotations

import functools
import inspect
import json
import re
import types
import typing
from importlib import resources
from typing import Any

from pydantic.fields import FieldInfo

from agentchord.actions.catalog import ACTIONS
from agentchord.expr import FUNCTIONS, MAX_SOURCE_LENGTH, TEMPLATES
from agentchord.features.frame import ARM_ATTRIBUTES, ARMS, OBJECT_ATTRIBUTES, ArmFeatures, ObjectFeatures
from agentchord.graph.models import FailureMode, TaskGraph

#: The task whose library graph is the worked example of every prompt.
EXAMPLE_TASK = "single_arm_pour_water"
#: The goal its composer states (``success.goal_spec``), as the offline composer reads its instruction.
EXAMPLE_GOAL = {"goals": [{"kind": "poured", "source": "bottle", "target": "cup", "arm": "right"},
                          {"kind": "placed", "obj": "bottle"}], "home": True}
#: How many of the example's nominal edges keep their failure modes and branches in the arranger's
#: and the conductor's prompts: the grasp and the carry show every kind of mode; the whole graph
#: would cost 3,000 tokens more per request.
EXAMPLE_EDGES_SHOWN = 2

_PLACEHOLDER = re.compile(r"\{\{\s*([a-z_]+)\s*\}\}")


#: Markdown files beside the agents' prompts that are not an agent's prompt.
NOT_AGENTS = ("skills.md",)


def prompt_names() -> list[str]:
    """Names of the prompt files (without ``.md``): one per agent (``skills.md`` holds skill notes)."""
    folder = resources.files(__name__)
    return sorted(p.name[: -len(".md")] for p in folder.iterdir() if p.name.endswith(".md") and p.name not in NOT_AGENTS)


def prompt_template(agent: str) -> str:
    """The raw text of an agent's prompt file, placeholders unfilled.

    Raises:
        KeyError: No prompt file for that agent.
    """
    path = resources.files(__name__) / f"{agent}.md"
    if not path.is_file():
        raise KeyError(f"no prompt for agent {agent!r} (have: {', '.join(prompt_names())})")
    return path.read_text(encoding="utf-8")


@functools.cache
def render_prompt(agent: str) -> str:
    """An agent's system prompt with every placeholder filled in.

    Raises:
        KeyError: No prompt file for that agent, or the file names an unknown placeholder.
    """
    text = prompt_template(agent)
    values = placeholders()

    def fill(match: re.Match[str]) -> str:
        name = match.group(1)
        if name not in values:
            raise KeyError(f"prompt {agent!r} names unknown placeholder {{{{{name}}}}} (known: {', '.join(values)})")
        return values[name]

    return _PLACEHOLDER.sub(fill, text)


@functools.lru_cache(maxsize=1)
def placeholders() -> dict[str, str]:
    """Every placeholder's generated text, by name."""
    example = _example_graph()
    return {
        "actions": action_table(),
        "arms": ", ".join(f"`{arm}`" for arm in ARMS),
        "features": feature_table(),
        "functions": function_table(),
        "templates": template_table(),
        "expression_rules": expression_rules(),
        "trigger_defaults": trigger_defaults(),
        "goal_language": goal_language(),
        "example_task": example.task,
        "example_instruction": example.instruction,
        "example_objects": ", ".join(example.objects),
        "example_nominal": graph_json(nominal_part(example)),
        "example_edges_shown": str(EXAMPLE_EDGES_SHOWN),
        "example_augmented": graph_json(example_excerpt(example, EXAMPLE_EDGES_SHOWN)),
    }


# --- tables ------------------------------------------------------------------------------


def action_table() -> str:
    """The atomic actions: signature, cost, what it does, and each argument."""
    blocks = []
    for spec in ACTIONS.values():
        fields = spec.args.model_fields
        doc = inspect.cleandoc(spec.args.__doc__ or "").splitlines()
        summary = doc[0].replace("``", "`") if doc and doc[0] != "No arguments." else ""
        flags = [f"about {spec.expected_ticks} ticks at 50 Hz"]
        if spec.holds_object:
            flags.append("runs with the object held")
        head = f"- `{spec.name}`({', '.join(fields)})" + (f": {summary}" if summary else "") + f" [{'; '.join(flags)}]"
        lines = [head]
        for name, field in fields.items():
            lines.append(f"    - `{name}`: {_describe_field(name, field, name in spec.object_fields)}")
        blocks.append("\n".join(lines))
    return "\n".join(blocks)


def _describe_field(name: str, field: FieldInfo, is_object: bool) -> str:
    parts = ["object name" if is_object and field.annotation is str else _type_name(field.annotation)]
    if is_object and field.annotation is not str:
        parts[0] += " (an object name)"
    if field.is_required():
        parts.append("required")
    else:
        parts.append(f"default {json.dumps(_plain(field.get_default(call_default_factory=True)))}")
    bounds = []
    for item in field.metadata:
        for attr, symbol in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            value = getattr(item, attr, None)
            if value is not None:
                bounds.append(f"{symbol} {value}")
    if bounds:
        parts.append(" and ".join(bounds))
    text = ", ".join(parts)
    if field.description:
        text += f". {field.description.replace('``', '`')}"
    return text


def _type_name(annotation: Any) -> str:
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if annotation is type(None):
        return "null"
    if origin is typing.Literal:
        return " | ".join(json.dumps(a) for a in args)
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_type_name(a) for a in args)
    if origin is tuple:
        return f"[{', '.join(_type_name(a) for a in args)}]"
    if origin is list:
        return f"list of {_type_name(args[0])}" if args else "list"
    if isinstance(annotation, type):
        return {"float": "number", "int": "integer", "str": "string", "bool": "boolean"}.get(
            annotation.__name__, annotation.__name__
        )
    return str(annotation).replace("typing.", "")


def _plain(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value


def _attribute_docs(cls: type) -> dict[str, str]:
    # The "Attributes:" section of a Google-style docstring, name -> description.
    docs: dict[str, str] = {}
    current = None
    in_section = False
    for line in inspect.cleandoc(cls.__doc__ or "").splitlines():
        if line.strip() == "Attributes:":
            in_section = True
            continue
        if not in_section:
            continue
        match = re.match(r"^\s{4}(\w+): (.*)$", line)
        if match:
            current = match.group(1)
            docs[current] = match.group(2).strip()
        elif current and line.startswith(" " * 8):
            docs[current] += " " + line.strip()
        elif line.strip():
            break
    return docs


def feature_table() -> str:
    """What an expression may read: ``obj.attr`` and ``arm.attr``."""
    object_docs = _attribute_docs(ObjectFeatures)
    arm_docs = _attribute_docs(ArmFeatures)
    lines = ["Object features (`bottle.pos`; any object listed under `objects`):"]
    lines += [f"- `obj.{name}`: {object_docs.get(name, '')}" for name in OBJECT_ATTRIBUTES]
    lines.append(f"Arm features (`right.ee`; arms: {', '.join(ARMS)}):")
    lines += [f"- `arm.{name}`: {arm_docs.get(name, '')}" for name in ARM_ATTRIBUTES]
    return "\n".join(lines)


def function_table() -> str:
    """The function library, templates left out (they have their own table)."""
    lines = []
    for name, description in FUNCTIONS.items():
        if name in TEMPLATES:
            continue
        signature, _, summary = description.partition(": ")
        lines.append(f"- `{signature}`: {summary}")
    return "\n".join(lines)


def template_table() -> str:
    """The monitor templates of the paper (Eq. 14-19), each with an example monitor."""
    return "\n".join(
        f"- `{info.signature}` (Eq. {info.equation}): {info.description}. Example: `\"{info.example}\"`"
        for info in TEMPLATES.values()
    )


def expression_rules() -> str:
    """The syntax of the expression language."""
    return "\n".join(
        [
            "- An expression is a string that evaluates to one number. Constraints: <= 0 when satisfied. "
            "Monitors: <= 0 during normal execution, > 0 when the failure is present.",
            "- Numbers, `+ - * / **` and unary `-`; vectors are written `[x, y, z]` and support "
            "`+ -` with vectors and `* /` with numbers; index one component as `v[0]`.",
            "- Names: the graph's `objects`, the arms, their features (`cup.top`, `right.width`), "
            "and the functions and templates below. Nothing else: no comparisons (`<`, `>=`), no "
            "`and`/`or`/`not`, no `if`, no variables, no strings.",
            "- \"Both must hold\" is `max(a, b)`; \"either holds\" is `min(a, b)`. A condition is gated "
            "by a 0/1 feature as in `right.closed * (0.5 - holding(right, bottle))`.",
            f"- Distances in metres, angles in degrees; at most {MAX_SOURCE_LENGTH} characters.",
            "- Write a constraint `lhs <= rhs` as `lhs - rhs`, e.g. \"within 3 cm of the cup's top\": "
            "`dist(bottle.pos, cup.top) - 0.03`; \"holds the bottle\": `0.5 - holding(right, bottle)`.",
        ]
    )


def goal_language() -> str:
    """The goal predicates (``kind`` and fields), each with what it means: the composer's ``success.goal_spec``."""
    from agentchord.agents.rules.goals import GOAL_KINDS

    lines = []
    for cls in GOAL_KINDS:
        fields = cls.model_fields
        kind = fields["kind"].get_default()
        doc = inspect.cleandoc(cls.__doc__ or "").splitlines()
        summary = doc[0].replace("``", "`") if doc else ""
        names = []
        for name, field in fields.items():
            if name == "kind":
                continue
            text = f"`{name}`" if field.is_required() else f"`{name}` (default {json.dumps(_plain(field.get_default()))})"
            names.append(text)
        lines.append(f"- `{kind}`: {summary} Fields: {', '.join(names)}.")
        attributes = _attribute_docs(cls)
        lines += [f"    - `{name}`: {text.replace('``None``', 'null').replace('``', '`')}" for name, text in attributes.items() if name in fields]
    return "\n".join(lines)


def trigger_defaults() -> str:
    """The default margin and window of a failure mode (Eq. 12)."""
    fields = FailureMode.model_fields
    margin = fields["margin"].get_default()
    window = fields["window"].get_default()
    return (
        f"`margin` (delta of Eq. 12) defaults to {margin} and `window` (tau, ticks at 50 Hz) to {window}: "
        f"a mode fires once its monitor stays above the margin for `window` consecutive ticks."
    )


# --- graphs as prompt text ---------------------------------------------------------------


def graph_json(graph: TaskGraph) -> str:
    """A graph as JSON, one node or edge per line (defaults left out): compact and readable."""
    data = graph.model_dump(mode="json", exclude_defaults=True)
    lines = ["{"]
    keys = list(data)
    for index, key in enumerate(keys):
        comma = "," if index < len(keys) - 1 else ""
        value = data[key]
        if key in ("nodes", "edges") and isinstance(value, list):
            lines.append(f'  "{key}": [')
            lines += [
                f"    {json.dumps(item, ensure_ascii=False)}{',' if i < len(value) - 1 else ''}"
                for i, item in enumerate(value)
            ]
            lines.append(f"  ]{comma}")
        else:
            lines.append(f'  "{key}": {json.dumps(value, ensure_ascii=False)}{comma}')
    lines.append("}")
    return "\n".join(lines)


def nominal_part(graph: TaskGraph) -> TaskGraph:
    """The nominal graph inside an augmented one: recovery nodes and edges and failure modes removed."""
    return graph.model_copy(
        update={
            "nodes": [n for n in graph.nodes if not n.is_recovery],
            "edges": [e.model_copy(update={"failures": []}) for e in graph.edges if not e.is_recovery],
        }
    )


def example_excerpt(graph: TaskGraph, edges: int) -> TaskGraph:
    """The augmented ``graph`` with failure modes on its first ``edges`` nominal edges only, and the
    recovery nodes and edges their branches bring (a worked example the size of a few edges)."""
    from agentchord.agents.replies import branch_reach
    from agentchord.graph.progress import nominal_path

    shown = nominal_path(graph)[:edges]
    kept: set[str] = set()
    for edge_id in shown:
        for failure in graph.edge(edge_id).failures:
            kept |= set(branch_reach(graph, edge_id, failure.name))
    nodes = [n for n in graph.nodes if not n.is_recovery or n.id in kept]
    kept_edges = []
    for edge in graph.edges:
        if edge.is_recovery and edge.id not in kept:
            continue
        if not edge.is_recovery and edge.id not in shown:
            edge = edge.model_copy(update={"failures": []})
        kept_edges.append(edge)
    return graph.model_copy(update={"nodes": nodes, "edges": kept_edges})


def _example_graph() -> TaskGraph:
    from agentchord.graph.models import Success
    from agentchord.library import load_task_graph  # the task library imports the graph loader only

    return load_task_graph(EXAMPLE_TASK).model_copy(update={"success": Success(judge="goal", goal_spec=EXAMPLE_GOAL)})
