"""The conversion: a release task graph and recovery spec -> one augmented task graph."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from agentchord.expr.names import name_problem
from agentchord.graph.interop.actions import ActionTranslator
from agentchord.graph.interop.conventions import (
    PERSISTENCE_WINDOW,
    ARM_NAMES,
    GRIPPING,
    RELEASE_TASKS,
)
from agentchord.graph.interop.exceptions import ReleaseImportError
from agentchord.graph.interop.frames import FrameMap
from agentchord.graph.interop.reader import ReleaseReader, read_json
from agentchord.graph.interop.release import (
    holds_after,
    Binding,
    fmt,
    norm,
    released_by,
    slug,
    Track,
)
from agentchord.graph.loader import format_loc
from agentchord.graph.models import ActionCall, Edge, FailureMode, Node, TaskGraph
from agentchord.graph.validation import check_graph


@dataclass
class ImportResult:
    """An imported graph and what the import dropped or approximated.

    Attributes:
        graph: The augmented task graph; it passes :func:`check_graph`.
        notes: One line per drop or approximation, ``FILE: json.path: what``.
    """

    graph: TaskGraph
    notes: list[str] = field(default_factory=list)


def import_release(
    task_graph: str | Path,
    recovery_spec: str | Path,
    *,
    task: str | None = None,
    objects: Sequence[str] | None = None,
    frame: FrameMap | str = "aloha",
) -> ImportResult:
    """Import a release task graph and recovery spec.

    Args:
        task_graph: The release's ``agent_task_graph.json``.
        recovery_spec: The release's ``agent_recovery_spec.json``.
        task: Our task name; default: the sim task matching the release's task string
            or folder name (:data:`RELEASE_TASKS`), else a slug of the task string.
        objects: The graph's objects, each ``name`` or ``release_name=name`` (a rename);
            every object the release names must be among them. Default: the names
            the release uses.
        frame: A :class:`FrameMap` or its text form (see :meth:`FrameMap.parse`).

    Raises:
        ReleaseImportError: A file cannot be read, or something in it cannot be mapped.
    """
    task_graph, recovery_spec = Path(task_graph), Path(recovery_spec)
    problems: list[str] = []
    graph_data = read_json(task_graph, problems)
    spec_data = read_json(recovery_spec, problems)
    if problems:
        raise ReleaseImportError(problems)
    return import_release_data(
        graph_data,
        spec_data,
        graph_name=str(task_graph),
        spec_name=str(recovery_spec),
        task=task,
        objects=objects,
        frame=frame,
        folder=task_graph.resolve().parent.name,
    )


def import_release_data(
    graph_data: Any,
    spec_data: Any,
    *,
    graph_name: str = "agent_task_graph.json",
    spec_name: str = "agent_recovery_spec.json",
    task: str | None = None,
    objects: Sequence[str] | None = None,
    frame: FrameMap | str = "aloha",
    folder: str = "",
) -> ImportResult:
    """:func:`import_release` on already parsed JSON documents (``*_name`` label the messages).

    Raises:
        ReleaseImportError: Something cannot be mapped.
    """
    frame_map = FrameMap.parse(frame) if isinstance(frame, str) else frame
    importer = _Importer(graph_name, spec_name, frame_map, objects)
    try:
        graph = importer.run(graph_data, spec_data, task, folder)
    except ValidationError as error:  # a value that passed the mapping but not our models
        raise ReleaseImportError(
            [f"{graph_name}: (imported graph) {format_loc(d['loc'])}: {d['msg']}" for d in error.errors()]
        ) from None
    if importer.problems:
        raise ReleaseImportError(importer.problems)
    assert graph is not None
    problems = check_graph(graph)
    if problems:  # a mapping this module got wrong, not the input's fault
        raise ReleaseImportError([f"{graph_name}: (imported graph) {p}" for p in problems])
    return ImportResult(graph, importer.notes)




class _Importer(ReleaseReader, ActionTranslator):
    def __init__(self, graph_name: str, spec_name: str, frame: FrameMap, objects: Sequence[str] | None) -> None:
        self.gfile, self.sfile = graph_name, spec_name
        self.frame = frame
        self.problems: list[str] = []
        self._notes: dict[tuple[str, str], list[str]] = {}
        self.renames: dict[str, str] = {}
        self.declared: list[str] | None = None
        if objects is not None:
            self.declared = []
            for entry in objects:
                old, sep, new = entry.partition("=")
                name = (new if sep else old).strip()
                if sep:
                    self.renames[old.strip()] = name
                if name and (problem := name_problem(name)) is not None:
                    self.problems.append(f"--objects: {problem}")
                elif name and name not in self.declared:
                    self.declared.append(name)
        self.used: dict[str, str] = {}  # object -> where first named
        self.grasp_modes: dict[tuple[str, str], str] = {}

    # --------------------------------------------------------------- messages
    def error(self, file: str, path: str, message: str) -> None:
        line = f"{file}: {path}: {message}"
        if line not in self.problems:  # a replayed edge's calls are translated again
            self.problems.append(line)

    def note(self, file: str, path: str, message: str) -> None:
        paths = self._notes.setdefault((file, message), [])
        if path not in paths:
            paths.append(path)

    @property
    def notes(self) -> list[str]:
        """One line per drop or approximation, the same one at several paths on one line."""
        return [f"{file}: {', '.join(paths)}: {message}" for (file, message), paths in self._notes.items()]

    # ------------------------------------------------------------------- run
    def run(self, graph_data: Any, spec_data: Any, task: str | None, folder: str) -> TaskGraph | None:
        chain = self._chain(graph_data)
        if chain is None:
            return None
        nodes_raw, edges_raw, start, goal, release_task = chain
        steps = {e["id"]: self._edge_steps(e, i) for i, e in enumerate(edges_raw)}
        order = [e["id"] for e in edges_raw]
        bindings = self._bindings(spec_data, steps, release_task)
        self._scan_orient(order, steps)

        # Nominal edges, with what each arm holds before each edge.
        holds_before: dict[str, dict[str, str]] = {}
        holds: dict[str, str] = {}
        track = Track()
        track_before: dict[str, Track] = {}
        released_into: dict[str, list[tuple[str, str]]] = {}
        nominal: dict[str, list[dict[str, ActionCall | None]]] = {}
        for k, edge_id in enumerate(order):
            holds_before[edge_id] = dict(holds)
            track_before[edge_id] = track.copy()
            continuation = [s for later in order[k + 1:] for s in steps[later]]
            nominal[edge_id] = self._translate(steps[edge_id], continuation, holds, track)
            released_into[edge_id] = released_by(holds_before[edge_id], nominal[edge_id])
            holds = holds_after(holds, nominal[edge_id])

        graph_edges: dict[str, Edge] = {}
        for edge in edges_raw:
            graph_edges[edge["id"]] = Edge(
                id=edge["id"], source=edge["source"], target=edge["target"], actions=nominal[edge["id"]] or [{}]
            )

        # Recovery entry edges, one per binding.
        recovery_edges: list[Edge] = []
        entry_of: dict[int, str] = {}
        by_edge: dict[str, list[Binding]] = {}
        for binding in bindings:
            by_edge.setdefault(binding.edge_id, []).append(binding)
        existing = set(order)
        for binding in bindings:
            failed = graph_edges[binding.edge_id]
            k = order.index(binding.edge_id)
            if binding.merge == "source":
                target, continuation = failed.source, [s for later in order[k:] for s in steps[later]]
            else:
                target, continuation = failed.target, [s for later in order[k + 1:] for s in steps[later]]
            rec_id = f"{binding.edge_id}_r_{slug(binding.name)}"
            if rec_id in existing:
                self.error(self.sfile, f"recovery_bindings[{binding.index}].failure_name",
                           f"recovery edge id {rec_id!r} is already taken")
                continue
            existing.add(rec_id)
            actions = self._translate(binding.steps, continuation, holds_before[binding.edge_id],
                                      track_before[binding.edge_id].copy())
            entry_of[binding.index] = rec_id
            recovery_edges.append(
                Edge(id=rec_id, kind="recovery", source=failed.source, target=target, actions=actions or [{}])
            )
        if self.problems:
            return None

        # Failure modes: on the failed edge, and again on its recovery edges (repeat_until_success).
        for edge_id, group in by_edge.items():
            edge = graph_edges[edge_id]
            edge.failures = [self._failure(b, edge, holds_before[edge_id], entry_of[b.index]) for b in group]
            entries = {entry_of[b.index] for b in group}
            for rec in recovery_edges:
                if rec.id in entries:  # a recovery of this edge: it leaves the same failure context
                    rec.failures = [
                        self._failure(b, rec, holds_before[edge_id], entry_of[b.index]) for b in group if b.repeat
                    ]

        # Nodes: ids and semantics kept; constraints from what is held / was released there.
        into = {e["target"]: e["id"] for e in edges_raw}
        nodes = []
        for node in nodes_raw:
            constraints: list[str] = []
            edge_id = into.get(node["id"])
            if edge_id is not None:
                after = holds_after(holds_before[edge_id], nominal[edge_id])
                constraints += [f"0.5 - holding({arm}, {obj})" for arm, obj in sorted(after.items())]
                constraints += [f"holding({arm}, {obj}) - 0.5" for arm, obj in released_into[edge_id]]
            nodes.append(Node(id=node["id"], semantic=node.get("semantic", ""), constraints=constraints))

        objects = self._objects()
        if self.problems:
            return None
        name = self._task_name(task, release_task, folder)
        return TaskGraph(
            task=name,
            instruction=release_task,
            start=start,
            goal=goal,
            objects=objects,
            nodes=nodes,
            edges=[graph_edges[e] for e in order] + recovery_edges,
        )


    # ------------------------------------------------------------ monitors
    def _failure(self, binding: Binding, edge: Edge, holds: dict[str, str], entry: str) -> FailureMode:
        terms = []
        gripping = {arm for arm, call in edge.calls if call.fn in GRIPPING}
        grasped = {call.args.get("obj"): arm for arm, call in edge.calls if call.fn == "grasp"}
        holder = {obj: arm for arm, obj in holds.items()}
        for kind, m in binding.monitors:
            if kind == "hold_lost":
                term = f"0.5 - holding({m['arm']}, {m['obj']})"
                terms.append(f"{m['arm']}.closed * ({term})" if m["arm"] in gripping else term)
            else:
                for obj in m["objects"]:
                    term = f"drift({obj}, {fmt(m['threshold'])})"
                    arm = grasped.get(obj) or holder.get(obj)
                    terms.append(f"(1 - {arm}.closed) * {term}" if arm else term)
        monitor = terms[0] if len(terms) == 1 else f"max({', '.join(terms)})"
        return FailureMode(name=binding.name, monitor=monitor, window=PERSISTENCE_WINDOW, intent=binding.intent or "recover",
                           recovery=entry)


    # ------------------------------------------------------------- helpers
    def _arm(self, name: Any, file: str, path: str) -> str | None:
        arm = ARM_NAMES.get(name) if isinstance(name, str) else None
        if arm is None:
            self.error(file, path, f"unknown arm {name!r}; the release's arms are {', '.join(ARM_NAMES)}")
        return arm

    def _object(self, name: str, file: str, path: str) -> str:
        ours = self.renames.get(name, name)
        if ours not in self.used and (problem := name_problem(ours)) is not None:
            hint = f" (rename it: --objects '{name}=NEW_NAME')" if isinstance(name, str) else ""
            self.error(file, path, problem + hint)
        self.used.setdefault(ours, f"{file}: {path}")
        return ours

    def _objects(self) -> list[str]:
        if self.declared is None:
            return list(self.used)
        for obj, where in self.used.items():
            if obj not in self.declared:
                self.problems.append(f"{where}: object {obj!r} is not among --objects ({', '.join(self.declared)})")
        return list(self.declared)

    def _task_name(self, task: str | None, release_task: str, folder: str) -> str:
        if task:
            return task
        for key in (release_task, folder):
            name = RELEASE_TASKS.get(norm(key))
            if name is not None:
                return name
        name = slug(release_task)
        self.note(self.gfile, "task", f"no simulated task matches {release_task!r}: task name {name!r} (use --task)")
        return name

    def _unknown_keys(self, file: str, path: str, data: dict, known: Iterable[str]) -> None:
        known = tuple(known)
        for key in data:
            if key not in known:
                where = f"{path}.{key}" if path else str(key)
                self.error(file, where, f"cannot map field {key!r} (known here: {', '.join(known)})")
