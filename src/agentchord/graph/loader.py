"""Reading and writing task-graph files (YAML or JSON).

Every failure to load is a :class:`GraphFileError` whose lines read
``FILE: where: what is wrong``; all pydantic errors are reported, not the first.
Reading is bounded (:mod:`agentchord.guard.documents`: regular files only, a size,
depth and value-count limit) and every number must be finite; writing is atomic.
"""

from __future__ import annotations

import contextlib
import gc
import json
import typing
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from agentchord.graph._hints import did_you_mean
from agentchord.graph.exceptions import GraphFileError
from agentchord.graph.models import ActionCall, Edge, FailureMode, Node, TaskGraph
from agentchord.guard.documents import check_shape, read_text
from agentchord.guard.exceptions import DocumentError, NonFiniteNumberError
from agentchord.guard.numbers import MAX_MAGNITUDE, describe, non_finite
from agentchord.guard.outputs import atomic_write_text

YAML_SUFFIXES = (".yaml", ".yml")
JSON_SUFFIXES = (".json",)


def load_graph(path: str | Path) -> TaskGraph:
    """Load and validate a task graph from a ``.yaml``, ``.yml`` or ``.json`` file.

    Args:
        path: The graph file.

    Returns:
        The validated graph (types and ranges; see ``check_graph`` for the rest).

    Raises:
        GraphFileError: The file cannot be read or parsed, or does not match the schema.
    """
    path = Path(path)
    with collector_paused():
        data = _read(path)
        if not isinstance(data, dict):
            found = "an empty file" if data is None else f"a {_kind(data)}"
            raise GraphFileError(
                path, [f"expected a task graph (a mapping with task, start, goal, nodes, edges), found {found}"]
            )
        try:
            return TaskGraph.model_validate(data)
        except ValidationError as error:
            raise GraphFileError(path, validation_messages(error, data)) from None


def load_model(path: str | Path, model: type[BaseModel]) -> BaseModel:
    """Load any pydantic model (a goal spec, ...) from a YAML or JSON file, with the same error lines.

    Raises:
        GraphFileError: The file cannot be read or parsed, or does not match the model.
    """
    path = Path(path)
    with collector_paused():
        data = _read(path)
        if not isinstance(data, dict):
            found = "an empty file" if data is None else f"a {_kind(data)}"
            raise GraphFileError(path, [f"expected a mapping ({model.__name__}), found {found}"])
        try:
            return model.model_validate(data)
        except ValidationError as error:
            raise GraphFileError(path, validation_messages(error, data, model)) from None


def dump_graph(graph: TaskGraph, path: str | Path) -> Path:
    """Write ``graph`` as YAML or JSON, chosen by the suffix of ``path``.

    Fields at their default value are left out; a single-step edge is written in
    the compact ``{arm: call}`` form. ``load_graph`` gives back an equal graph.

    Args:
        graph: The graph to write.
        path: Destination, ``.yaml``/``.yml`` or ``.json``.

    Returns:
        The path written.

    Raises:
        GraphFileError: Unsupported suffix.
        OutputPathError: The file cannot be written (the previous file, if any, is left intact).
    """
    path = Path(path)
    data = graph.model_dump(mode="json", exclude_defaults=True)
    suffix = path.suffix.lower()
    if suffix in YAML_SUFFIXES:
        for edge in data["edges"]:
            edge["actions"] = _inline_steps(edge["actions"])
        text = yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)
    elif suffix in JSON_SUFFIXES:
        text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    else:
        raise GraphFileError(path, [_unsupported_suffix(path)])
    atomic_write_text(path, text)
    return path


def format_loc(loc: Sequence[str | int], data: Any = None) -> str:
    """Format a pydantic error location as a field path, e.g. ``edges[1].failures[0].window``.

    Edges store their steps as a list; when ``data`` (the raw file content) shows
    the compact single-step mapping form, the step index is left out so that the
    path names what is in the file.

    Args:
        loc: The location tuple of a pydantic error.
        data: The raw document the location refers to, if known.
    """
    parts: list[str] = []
    node = data
    skip_step_index = False
    for item in loc:
        if skip_step_index and item == 0:
            skip_step_index = False
            continue  # compact form: the file has no step index here
        skip_step_index = False
        if isinstance(node, dict) and isinstance(item, str) and item not in node and node.get("kind") == item:
            continue  # pydantic's tag of a discriminated union (goals[0].placed.at): not in the file
        if isinstance(item, int):
            parts.append(f"[{item}]")
        else:
            parts.append(f".{item}" if parts else str(item))
        node = _child(node, item)
        if item == "actions" and isinstance(node, dict):
            skip_step_index = True
    return "".join(parts)


def validation_messages(error: ValidationError, data: Any = None, root: type[BaseModel] = TaskGraph) -> list[str]:
    """Turn every error of a pydantic ``ValidationError`` into ``path: message``.

    Args:
        error: The validation error.
        data: The raw document that was validated (to name fields as written).
        root: The model the document was validated as (a graph, a goal spec): where an unknown
            field's "did you mean" looks for the fields it could have been.
    """
    lines = []
    for detail in error.errors(include_url=False):
        loc = detail["loc"]
        message = detail["msg"].removeprefix("Value error, ")  # our validators' messages read as they are
        if detail["type"] == "extra_forbidden" and loc:
            message += _field_hint(loc, root)
        cause = (detail.get("ctx") or {}).get("error")
        if isinstance(cause, NonFiniteNumberError) and cause.where:
            # The number's own path inside the field (args.offset[1]), not just the field.
            loc, message = (*loc, *_split_path(cause.where)), describe(cause.value, MAX_MAGNITUDE)
        where = format_loc(loc, data)
        lines.append(f"{where}: {message}" if where else message)
    return lines


def _split_path(path: str) -> list[str | int]:
    # "offset[1].x" -> ["offset", 1, "x"]
    parts: list[str | int] = []
    for piece in path.replace("]", "").replace("[", ".").split("."):
        if piece:
            parts.append(int(piece) if piece.isdigit() else piece)
    return parts


def _child(node: Any, item: str | int) -> Any:
    if isinstance(node, dict):
        return node.get(item)
    if isinstance(node, list) and isinstance(item, int) and 0 <= item < len(node):
        return node[item]
    return None


def _model_at(parent: Sequence[str | int], root: type[BaseModel] = TaskGraph) -> type[BaseModel] | None:
    # Which model a location's parent is, from the shape of the path.
    if not parent:
        return root
    if root is not TaskGraph:
        return _walk(root, parent)
    if len(parent) >= 2 and isinstance(parent[-1], int):
        return {"nodes": Node, "edges": Edge, "failures": FailureMode}.get(str(parent[-2]))
    if "actions" in parent:
        return ActionCall
    return None


def _models_in(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models an annotation holds (``list[Goal]``, a union of goal kinds, ``X | None``)."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    return [m for arg in typing.get_args(annotation) for m in _models_in(arg)]


def _walk(model: type[BaseModel], path: Sequence[str | int]) -> type[BaseModel] | None:
    """The model at ``path`` below ``model``: fields by name, list items by index, a union's member by
    the tag pydantic puts in the path (``goals[0].inside`` is the goal whose kind is ``inside``)."""
    candidates: list[type[BaseModel]] = [model]
    for item in path:
        if isinstance(item, int):
            continue  # a list's item: the models the list holds
        field_models = [m for c in candidates if item in c.model_fields for m in _models_in(c.model_fields[item].annotation)]
        tagged = [c for c in candidates if getattr(c.model_fields.get("kind"), "default", None) == item]
        candidates = field_models or tagged
        if not candidates:
            return None
    return candidates[0] if len(candidates) == 1 else None


def _field_hint(loc: Sequence[str | int], root: type[BaseModel] = TaskGraph) -> str:
    model = _model_at(loc[:-1], root)
    if model is None:
        return ""
    fields = list(model.model_fields)
    return did_you_mean(str(loc[-1]), fields) or f" (fields: {', '.join(fields)})"


def _kind(data: Any) -> str:
    return {list: "list", str: "string", int: "number", float: "number", bool: "boolean"}.get(
        type(data), type(data).__name__
    )


def read_document(path: str | Path) -> Any:
    """The parsed content of a YAML or JSON file, within the limits of :mod:`agentchord.guard.documents`.

    Raises:
        GraphFileError: Unsupported suffix; not a regular file, too large, not UTF-8; invalid
            YAML/JSON; nested too deep; or a number that is NaN or infinite (each with its path).
    """
    path = Path(path)
    with collector_paused():
        return _checked(path, _parse(path))


def _checked(path: Path, data: Any) -> Any:
    try:
        check_shape(data)
    except DocumentError as error:
        raise GraphFileError(path, [f"{error.where}: {error}" if error.where else str(error)]) from None
    bad = [f"{where or '(top)'}: {describe(number)}" for where, number in non_finite(data)]
    if bad:
        raise GraphFileError(path, bad)
    return data


@contextlib.contextmanager
def collector_paused() -> Iterator[None]:
    """Pause Python's cyclic garbage collector while a document is parsed, checked and validated.

    Reading a large graph allocates about a million objects (parser nodes, values, models), none
    of them garbage yet; the collector would walk them all again and again as they come: two thirds
    of the time of loading a 10,000-node YAML graph. Nothing is lost: whatever became unreachable
    meanwhile is freed by reference counting or, for cycles, by the next collection once resumed.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _read(path: Path) -> Any:
    return read_document(path)


def _parse(path: Path) -> Any:
    suffix = path.suffix.lower()
    if suffix not in YAML_SUFFIXES + JSON_SUFFIXES:
        raise GraphFileError(path, [_unsupported_suffix(path)])
    try:
        text = read_text(path)
    except DocumentError as error:
        raise GraphFileError(path, [f"cannot read the file: {error}"]) from None
    except (OSError, UnicodeDecodeError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
        raise GraphFileError(path, [f"cannot read the file: {reason}"]) from None
    try:
        return _parse_text(path, text, suffix)
    except RecursionError:
        # The parser recursed past Python's limit: far deeper than the depth limit.
        raise GraphFileError(path, ["the document is nested too deeply to read"]) from None


def _parse_text(path: Path, text: str, suffix: str) -> Any:
    if suffix in JSON_SUFFIXES:
        try:
            return json.loads(text, object_pairs_hook=_no_duplicate_pairs)
        except json.JSONDecodeError as error:
            raise GraphFileError(
                path, [f"line {error.lineno}, column {error.colno}: invalid JSON: {error.msg}"]
            ) from None
        except _DuplicateKeyError as error:
            raise GraphFileError(path, [f"invalid JSON: {error}"]) from None
    try:
        return yaml.load(text, Loader=_Loader)  # _Loader is a SafeLoader
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        what = " ".join(part for part in (error.context, error.problem) if part)
        raise GraphFileError(path, [f"{where}invalid YAML: {what}"]) from None
    except yaml.YAMLError as error:
        raise GraphFileError(path, [f"invalid YAML: {error}"]) from None


def _unsupported_suffix(path: Path) -> str:
    return f"unsupported file type {path.suffix or '(none)'!r}; use .yaml, .yml or .json"


class _DuplicateKeyError(ValueError):
    pass


def _no_duplicate_pairs(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    # A repeated key would silently replace the first one (e.g. two `failures:`).
    result: dict[str, Any] = {}
    for key, value in pairs:
        if key in result:
            raise _DuplicateKeyError(f"duplicate key {key!r}")
        result[key] = value
    return result


_SafeBase = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml parses ~10x faster (large graphs)


_TAG = "tag:yaml.org,2002:"
_STR, _SEQ, _MAP, _MERGE = _TAG + "str", _TAG + "seq", _TAG + "map", _TAG + "merge"
_MISSING = object()


class _Loader(_SafeBase):  # type: ignore[misc,valid-type]
    """A safe YAML loader (libyaml when available) that rejects duplicate mapping keys.

    Documents of plain mappings, sequences and scalars (every graph file) are built by an
    iterative constructor, several times faster than PyYAML's recursive one on large graphs;
    any other node (timestamps, merge keys, explicit tags) is built the standard way.
    """

    def construct_document(self, node: yaml.Node) -> Any:
        data = self._build(node)
        self.constructed_objects = {}
        self.recursive_objects = {}
        return data

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        self._refuse_duplicate_keys(node)
        return super().construct_mapping(node, deep=deep)

    def _refuse_duplicate_keys(self, node: yaml.MappingNode) -> None:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            if key_node.tag == _MERGE:
                continue  # `<<: *defaults` is merged by the base constructor
            if isinstance(key_node, yaml.ScalarNode) and key_node.tag == _STR:
                key = key_node.value  # a plain string key: no need to construct it (large graphs)
            else:
                key = self.construct_object(key_node, deep=True)
            if not isinstance(key, (str, int, float, bool)) and key is not None:
                continue  # unhashable or exotic keys: SafeLoader reports them itself
            if key in seen:
                raise self._duplicate(node, key_node, key)
            seen.add(key)

    @staticmethod
    def _duplicate(node: yaml.Node, key_node: yaml.Node, key: Any) -> yaml.constructor.ConstructorError:
        return yaml.constructor.ConstructorError(
            "while constructing a mapping", node.start_mark, f"found duplicate key {key!r}", key_node.start_mark
        )

    def _scalar(self, node: yaml.Node) -> Any:
        tag = node.tag
        if tag == _STR:
            return node.value
        if tag == _TAG + "null":
            return None
        if tag == _TAG + "int":
            return self.construct_yaml_int(node)
        if tag == _TAG + "float":
            return self.construct_yaml_float(node)
        if tag == _TAG + "bool":
            return self.construct_yaml_bool(node)
        return self.construct_object(node, deep=True)

    def _build(self, root: yaml.Node) -> Any:
        # Containers are created first and filled as their children come off the stack, so an
        # alias gets the very object its anchor made (a cycle is caught by the depth limit).
        # Scalars are immutable: one aliased twice is simply built twice.
        built: dict[int, Any] = {}
        holder: list[Any] = [None]
        stack: list[tuple[yaml.Node, Any, Any]] = [(root, holder, 0)]
        pop, scalar_node = stack.pop, yaml.ScalarNode
        while stack:
            node, parent, key = pop()
            if node.__class__ is scalar_node:
                parent[key] = node.value if node.tag == _STR else self._scalar(node)
                continue
            value = built.get(id(node), _MISSING)
            if value is _MISSING:
                value = built[id(node)] = self._collection(node, stack)
            parent[key] = value
        return holder[0]

    def _collection(self, node: yaml.Node, stack: list[tuple[yaml.Node, Any, Any]]) -> Any:
        # An empty list or mapping to be filled from ``stack``, or a node built the standard way.
        if node.__class__ is yaml.SequenceNode and node.tag == _SEQ:
            items: list[Any] = [None] * len(node.value)
            stack += [(child, items, i) for i, child in enumerate(node.value)]
            return items
        if node.__class__ is not yaml.MappingNode or node.tag != _MAP:
            return self.construct_object(node, deep=True)
        mapping: dict[Any, Any] = {}
        children = []
        for key_node, value_node in node.value:
            tag = key_node.tag
            if tag == _STR and key_node.__class__ is yaml.ScalarNode:
                name = key_node.value
            elif tag == _MERGE:
                return self.construct_object(node, deep=True)  # `<<: *defaults`: merged the standard way
            elif key_node.__class__ is yaml.ScalarNode:
                name = self._scalar(key_node)
            else:
                name = self.construct_object(key_node, deep=True)
            try:
                if name in mapping:
                    raise self._duplicate(node, key_node, name)
                mapping[name] = None
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    "while constructing a mapping", node.start_mark, "found unhashable key", key_node.start_mark
                ) from None
            children.append((value_node, mapping, name))
        stack += children
        return mapping


class _Dumper(yaml.SafeDumper):
    """A YAML dumper that writes steps and short lists of scalars inline.

    ``actions: {right: {fn: grasp, args: {obj: bottle}}}`` and ``offset: [0.05, -0.1, 0.1]``
    read as in DESIGN section 3.
    """


class _InlineStep(dict):
    """A step mapping that the dumper writes in flow style."""


def _inline_steps(actions: Any) -> Any:
    if isinstance(actions, dict):
        return _InlineStep(actions)
    return [_InlineStep(step) for step in actions]


def _represent_inline_step(dumper: yaml.SafeDumper, data: _InlineStep) -> yaml.Node:
    return dumper.represent_mapping("tag:yaml.org,2002:map", data, flow_style=True)


def _represent_list(dumper: yaml.SafeDumper, data: list[Any]) -> yaml.Node:
    inline = all(isinstance(item, (int, float, bool)) or item is None for item in data)
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=inline and bool(data))


_Dumper.add_representer(list, _represent_list)
_Dumper.add_representer(_InlineStep, _represent_inline_step)
