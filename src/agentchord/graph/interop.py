"""Import the AgentChord reference release's format into our augmented task graph (issue 4 item 6).

The release publishes a task as two JSON files (their format is summarised in
``shared/interop/agentchord-release-examples/NOTICE.md``):

- ``agent_task_graph.json``: ``task, start, goal, nodes[{id, semantic}],
  edges[{id, source, target, left_arm_action, right_arm_action}]``, optional
  ``max_transitions``; one deterministic start-to-goal chain.
- ``agent_recovery_spec.json``: ``task, recovery_bindings[{edge_id, failure_name,
  monitors[], recovery[], merge, repeat_until_success}]``.

:func:`import_release` turns the pair into one :class:`~agentchord.graph.models.TaskGraph`:
the chain becomes the nominal edges, every binding a failure mode of its edge plus
one recovery entry edge. Anything it cannot map is an error naming the file, the
JSON path and the problem (:class:`ReleaseImportError`); everything it drops or
approximates is reported as a note with the same file and path.

Actions (one ``{fn, kwargs}`` per arm slot -> one step ``{left: ..., right: ...}``)
====================================================================================

``frame(p)`` maps a position and ``R v`` turns a displacement from the release's frame to
ours (see *Frames*).

===============================  ==========================================================
release                          ours
===============================  ==========================================================
``left_arm`` / ``right_arm``     arm ``left`` / ``right``; ``kwargs.robot_name`` must name
                                 the slot's arm and is then dropped
``grasp``                        ``grasp(obj=obj_name, pre_grasp_dis)``; ``mode`` is set
                                 to ``top`` (``side``) when the release orients the tool
                                 ``down`` (``front``) right after grasping (see orient_eef)
``move_relative_to_object``      ``move_to_obj(obj=obj_name, offset=R (x_offset, y_offset,
                                 z_offset))``; the release keeps the tool's orientation:
                                 ``keep_orientation: true``, except before a roll
                                 (``rotate_eef`` next on that arm), see *pouring* below,
                                 and before an ``open_gripper`` while holding: offset
                                 z -> ``PRE_PLACE_DIS``, see *placing by release*
``move_to_absolute_position``    ``move_to_target(pos=frame(x, y, z))``, clipped to our
                                 workspace; ``z: null`` (keep the height) -> ``CARRY_Z``;
                                 ``x``/``y`` null cannot be mapped (error)
``move_by_relative_offset``      ``move_by_offset(offset=R (dx, dy, dz), frame=extrinsic)``;
                                 ``mode: intrinsic`` -> ``frame: intrinsic`` with the
                                 release's tool z (its approach) as our tool x;
                                 a lateral intrinsic ``dx``/``dy`` is an error
``rotate_eef``                   ``rotate_eef(angle=degree)`` (same sign, see *pouring*)
``place_on_table``               ``place(obj=obj_name, target=frame(x, y))``, clipped to
                                 the table; both null -> ``target`` omitted (straight
                                 down); ``pre_place_dis`` dropped; ``yaw`` after
                                 ``orient_eef`` down, see *placing by release*
``back_to_initial_pose``         ``back``
``open_gripper``                 ``open_gripper``; right after ``move_relative_to_object``
                                 while holding: ``place``, see *placing by release*
``close_gripper``                ``close_gripper``
``orient_eef``                   no absolute-orientation action in our catalogue. Right
                                 after a grasp of that arm: the grasp gets ``mode: top``
                                 (``down``) / ``side`` (``front``) and the orient step
                                 becomes a zero ``move_by_offset`` (hold, settle).
                                 Otherwise ``move_by_offset(angles=(0, 90, 0))`` (down)
                                 / ``(0, -90, 0)`` (front), ``frame: intrinsic``: a pitch
                                 that assumes a level (down) / top-down (front) tool
===============================  ==========================================================

Dropped everywhere, with a note: ``force_valid`` (the release's "accept the nearest
valid IK pose"; our motion always clips to the workspace and tracks best-effort),
``sample_num`` (trajectory sampling of the release's planner), ``max_transitions``
(our executor's tick limit bounds an episode). Any other kwarg is an error.

Frames
------
The release's coordinates are in its own robot frame: x forward (away from the robot),
y to the robot's left, z up, both arms reaching forward side by side. Our ALOHA arms
face each other across the table (left arm at -x, right at +x; the front camera at
-y). ``--frame aloha`` (default) maps release ``(x, y, z)`` to ours ``(-y, x, z)``: a
+90 deg turn about z, so each arm's side is kept (the release's right, -y, becomes our
+x where our right arm stands) and its forward becomes our +y, away from the front
camera. Absolute positions map to table positions near the library graphs' (the
release's bottle place ``(0.7, -0.1)`` -> ``(0.1, 0.7)``, its cup pose ``(0.55, 0.05)``
-> ``(-0.05, 0.55)``); offsets turn with it (rearrangement's ``y_offset: +-0.16`` from
the plate -> ``x: -+0.16``, our library's fork/spoon sides). ``--frame identity`` takes
the numbers as ours; ``--frame yaw=DEG,dx=M,dy=M,dz=M`` is any other such transform.
The release's object offsets are from an object's base-pose origin and ours from its
top point: the numbers are kept (the release's pour then holds the bottle 2-5 cm
higher above the cup's rim than its own robot did).

Pouring: the release rolls its wrist joint with the tool still pointing forward, as
left after its grasp, so the roll tips the bottle sideways over the cup. Our arms'
approach points across the table instead, so that orientation cannot carry over. A
``move_relative_to_object`` followed on the same arm by ``rotate_eef`` (next step of
the chain or of the recovery) therefore gets ``yaw``: the approach axis is set
perpendicular to the horizontal offset, turned so that the roll (sign kept: negative
tips the top toward the tool's +y, ours as the release's) tips the held object's top
toward the object. With the release's pour offset the bottle's mouth ends within
1-3 cm of the cup's axis. The angle is kept: it is a roll of the release's wrist joint
(its tool frame), and our tool rolls by exactly that; nothing in the release says the
held object should turn further. (Our tool reaches the release's dual-arm -70 deg, but
the bottle lags 0.2-0.5 deg in the fingers, just short of the 70 deg that
``dual_arm_pour_water`` counts as pouring; that gap is our simulation's, not a convention.)

Placing by release: the release has no place relative to an object; it moves what it holds
to an offset from the object's base-pose origin (its centre; ``z_offset: 0`` is the table
for an object resting on it) and then opens the gripper. ``move_relative_to_object``
followed on the same arm by ``open_gripper`` while the arm holds an object is therefore a
place: the move becomes a carry to the offset ``PRE_PLACE_DIS`` (0.08 m, the release's own
``place_on_table`` stand-off) above the object's top point (lowered there, the held object
would be dragged into the table), and the open becomes ``place(obj=held, target=R (x_offset,
y_offset), relative_to=obj)``, with ``z_offset`` (our release height) from a non-zero
release ``z_offset``. The release's ``orient_eef`` sets an absolute orientation: ``down``
is its tool x forward, tool z down, fingers closing along its y. A thin object grasped
across its narrow side (ours, like any parallel gripper's) is then carried with its long
axis along the release's x; our top grasp keeps the object's own yaw and only ``place``
can set it, so a place of an object grasped ``mode: top`` (orient ``down``) gets ``yaw``:
the release's x in our frame (90 with ``aloha``), unless the tool rolled since.

Monitors
--------
- ``object_moved {objects, threshold}`` -> ``drift(obj, threshold)``, a ``max(...)`` over
  the objects. An object the edge grasps, or that an arm holds at the edge's start,
  moves with the hand on purpose: its term is gated ``(1 - arm.closed) * drift(...)``.
- ``hold_lost {robot_name, obj_name, threshold}`` -> ``0.5 - holding(arm, obj)``, gated
  ``arm.closed * (...)`` on edges that grasp, place, open or close that gripper on
  purpose (our grasp-done gating). ``threshold`` is dropped (the release's own hold-check
  tolerance; ours is contact-based, debounced by the persistence window).
- Several monitors of one binding -> one failure mode, ``max(...)`` of them. Margin 0,
  window 3 (the shared defaults).

Recovery steps and merge
------------------------
- ``regrasp {robot_name, obj_name, pre_grasp_dis}`` -> a ``grasp`` step of that arm.
- ``regrasp_both {arms: {left_arm: a, right_arm: b}, pre_grasp_dis}`` -> one synchronous
  step of both grasps, with ``skip_if_held: true`` (the half still held is not redone).
- ``retry_failed_edge`` -> the failed edge's own steps; ``replay_edge {edge_id}`` -> that
  edge's steps (a ``pre_grasp_dis`` on the step overrides their grasps'); ``action
  {left_arm_action, right_arm_action}`` -> one step.
- ``merge: target``: the recovery entry edge goes from the failed edge's source (the
  failure context) to its target. ``merge: source``: it goes from the failed edge's
  source back to it (a loop that restores the precondition), so the failed edge runs
  again. Both are forward-moving: ``D(merge node) <= D(failure context)``.
- ``repeat_until_success: true`` -> the recovery edges of the failed edge carry the
  binding's monitor again, re-entering its recovery, bounded by our per-mode failure
  budget (``ExecutorConfig.failure_budget``, 3 per edge and mode) instead of unbounded
  repetition. ``false`` -> one attempt (no re-entry).

Nodes keep their ids and semantics; their constraints are derived from the chain
(``0.5 - holding(arm, obj)`` for what an arm holds there, ``holding(arm, obj) - 0.5``
for what the edge into the node released). The graph's ``objects`` are the names
used in kwargs (``obj_name``, ``objects``, ``regrasp_both.arms``), in first-use order.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from agentchord.actions.catalog import ACTIONS
from agentchord.expr.names import name_problem
from agentchord.graph.exceptions import GraphError
from agentchord.graph.loader import format_loc
from agentchord.graph.models import ActionCall, Edge, FailureMode, Node, TaskGraph
from agentchord.graph.validation import check_graph
from agentchord.guard.documents import check_shape, read_text
from agentchord.guard.exceptions import DocumentError
from agentchord.guard.numbers import describe, non_finite

#: Release arm names -> ours.
ARM_NAMES = {"left_arm": "left", "right_arm": "right"}
#: Arm slots of a release edge or ``action`` step -> our arm.
SLOTS = {"left_arm_action": "left", "right_arm_action": "right"}
#: Tool height (m) for ``move_to_absolute_position`` with ``z: null`` (the release keeps the
#: current height): the carrying height of our library graphs.
CARRY_Z = 0.15
#: Our workspace (m), as ``agentchord.actions.motion`` clips every pose target (kept in
#: step by a test; that module imports the simulator).
WORKSPACE = ((-0.56, 0.22, 0.015), (0.56, 0.95, 0.55))
#: Stand-off (m) above the spot where the release lets go of what it holds (its ``place_on_table``
#: default ``pre_place_dis``): our carry stops there, our place lowers the object.
PRE_PLACE_DIS = 0.08
#: Range (m) of our place's ``z_offset`` (``PlaceArgs``).
PLACE_Z = (-0.05, 0.2)
#: Table positions a place may target (m): the table top less a 5 cm margin.
TABLE_XY = ((-0.56, 0.27), (0.56, 0.93))
#: Kwargs dropped from every release call, and why.
DROPPED_KWARGS = {
    "force_valid": "the release's 'accept the nearest valid IK pose' flag; our motion clips to the workspace",
    "sample_num": "trajectory sampling of the release's planner",
}
#: Release task strings and example folder names (normalised) -> our simulated task names.
RELEASE_TASKS = {
    "singlepourwater": "single_arm_pour_water",
    "pourfrombottleintocupandplacebottle": "single_arm_pour_water",
    "dualpourwater": "dual_arm_pour_water",
    "pourwaterintocup": "dual_arm_pour_water",
    "rearrangement": "rearrange_table",
    "rearrangeforkspoonoppositesidesplate": "rearrange_table",
}
#: Actions that open or close a gripper on purpose: a hold monitor is gated on them.
GRIPPING = frozenset({"grasp", "place", "open_gripper", "close_gripper"})
_WINDOW = 3


class ReleaseImportError(GraphError):
    """The release files cannot be imported.

    Attributes:
        problems: One line per problem, ``FILE: json.path: what is wrong``.
    """

    def __init__(self, problems: Sequence[str]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))


@dataclass(frozen=True)
class FrameMap:
    """A rigid map from the release's robot frame to our world: a turn about z, then a shift.

    Attributes:
        yaw_deg: Turn about z (deg).
        shift: Translation (m) added after the turn.
    """

    yaw_deg: float = 90.0
    shift: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def vector(self, v: Sequence[float]) -> tuple[float, float, float]:
        """A displacement in our frame (turned, not shifted)."""
        c, s = math.cos(math.radians(self.yaw_deg)), math.sin(math.radians(self.yaw_deg))
        x, y, z = (float(a) for a in v)
        return (_round(c * x - s * y), _round(s * x + c * y), _round(z))

    def point(self, p: Sequence[float]) -> tuple[float, float, float]:
        """A position in our frame."""
        x, y, z = self.vector(p)
        return (_round(x + self.shift[0]), _round(y + self.shift[1]), _round(z + self.shift[2]))

    @classmethod
    def parse(cls, text: str) -> FrameMap:
        """``aloha``, ``identity`` or ``yaw=DEG[,dx=M][,dy=M][,dz=M]``.

        Raises:
            ValueError: Anything else.
        """
        if text in FRAMES:
            return FRAMES[text]
        values = {"yaw": 0.0, "dx": 0.0, "dy": 0.0, "dz": 0.0}
        for part in filter(None, (p.strip() for p in text.split(","))):
            key, sep, value = part.partition("=")
            if not sep or key.strip() not in values:
                raise ValueError(
                    f"bad frame {text!r}: use {', '.join(FRAMES)} or yaw=DEG,dx=M,dy=M,dz=M (got {part!r})"
                )
            try:
                values[key.strip()] = float(value)
            except ValueError:
                raise ValueError(f"bad frame {text!r}: {key.strip()} is not a number ({value!r})") from None
        return cls(values["yaw"], (values["dx"], values["dy"], values["dz"]))


#: Named frames: ``aloha`` (release x forward, y left -> our +y, -x) and ``identity``.
FRAMES = {"aloha": FrameMap(90.0), "identity": FrameMap(0.0)}


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
    graph_data = _read_json(task_graph, problems)
    spec_data = _read_json(recovery_spec, problems)
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


# ----------------------------------------------------------------------------- internals


def _round(x: float) -> float:
    value = round(x, 6)
    return 0.0 if value == 0 else value


def _fmt(x: float) -> str:
    return f"{x:g}"


def _read_json(path: Path, problems: list[str]) -> Any:
    # Bounded like every input (agentchord.guard): regular files, size, depth, finite numbers.
    try:
        text = read_text(path)
    except (OSError, UnicodeDecodeError, DocumentError) as error:
        reason = error.strerror if isinstance(error, OSError) and error.strerror else str(error)
        problems.append(f"{path}: (file): cannot read the file: {reason}")
        return None
    try:
        data = json.loads(text)
    except RecursionError:
        problems.append(f"{path}: (file): the JSON is nested too deeply to read")
        return None
    except json.JSONDecodeError as error:
        problems.append(f"{path}: (file): line {error.lineno}, column {error.colno}: invalid JSON: {error.msg}")
        return None
    try:
        check_shape(data)
    except DocumentError as error:
        problems.append(f"{path}: {error.where or '(file)'}: {error}")
        return None
    bad = [f"{path}: {where or '(top level)'}: {describe(number)}" for where, number in non_finite(data)]
    if bad:
        problems += bad
        return None
    return data


def _slug(text: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", text.lower()).strip("_") or "imported_task"


def _norm(text: str) -> str:
    return re.sub(r"[^a-z0-9]", "", text.lower())


@dataclass
class _Raw:
    """A release arm call (``{fn, kwargs}``), where it is, and recovery-step extras."""

    call: dict[str, Any]
    file: str
    path: str
    extra: dict[str, Any] = field(default_factory=dict)


#: One step: our arm -> release call (None: idle).
_RawStep = dict[str, "_Raw | None"]


@dataclass
class _Track:
    """Each arm's history along a translation.

    Attributes:
        before: The arm's last release call.
        previous: Our last action on the arm.
        turned: Arms whose tool turned (a roll, a pitch) since they last grasped.
    """

    before: dict[str, _Raw] = field(default_factory=dict)
    previous: dict[str, str] = field(default_factory=dict)
    turned: set[str] = field(default_factory=set)

    def update(self, arm: str, call: ActionCall) -> None:
        self.previous[arm] = call.fn
        if call.fn == "grasp":
            self.turned.discard(arm)
        elif call.fn == "rotate_eef" or any(call.args.get("angles", ())):
            self.turned.add(arm)

    def copy(self) -> _Track:
        return _Track(dict(self.before), dict(self.previous), set(self.turned))


@dataclass
class _Ctx:
    """What one release call is translated in view of.

    Attributes:
        arm: The call's arm.
        nxt: The arm's next release call (later in the steps, then in the continuation).
        before: The arm's previous release call.
        previous: Our previous action on the arm.
        holds: What each arm holds.
        turned: Whether the arm's tool turned since it last grasped.
    """

    arm: str
    nxt: _Raw | None
    before: _Raw | None
    previous: str | None
    holds: dict[str, str]
    turned: bool


@dataclass
class _Binding:
    index: int
    edge_id: str
    name: str
    monitors: list[tuple[str, dict[str, Any]]]
    steps: list[_RawStep]
    merge: str
    repeat: bool
    intent: str


class _Importer:
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
        track = _Track()
        track_before: dict[str, _Track] = {}
        released_into: dict[str, list[tuple[str, str]]] = {}
        nominal: dict[str, list[dict[str, ActionCall | None]]] = {}
        for k, edge_id in enumerate(order):
            holds_before[edge_id] = dict(holds)
            track_before[edge_id] = track.copy()
            continuation = [s for later in order[k + 1:] for s in steps[later]]
            nominal[edge_id] = self._translate(steps[edge_id], continuation, holds, track)
            released_into[edge_id] = _released(holds_before[edge_id], nominal[edge_id])
            holds = _after(holds, nominal[edge_id])

        graph_edges: dict[str, Edge] = {}
        for edge in edges_raw:
            graph_edges[edge["id"]] = Edge(
                id=edge["id"], source=edge["source"], target=edge["target"], actions=nominal[edge["id"]] or [{}]
            )

        # Recovery entry edges, one per binding.
        recovery_edges: list[Edge] = []
        entry_of: dict[int, str] = {}
        by_edge: dict[str, list[_Binding]] = {}
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
            rec_id = f"{binding.edge_id}_r_{_slug(binding.name)}"
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
                after = _after(holds_before[edge_id], nominal[edge_id])
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

    # ------------------------------------------------------------ task graph
    def _chain(self, data: Any) -> tuple[list[dict], list[dict], str, str, str] | None:
        f = self.gfile
        if not isinstance(data, dict):
            self.error(f, "(top level)", f"expected a task graph object, found {type(data).__name__}")
            return None
        self._unknown_keys(f, "", data, ("task", "start", "goal", "nodes", "edges", "max_transitions"))
        for key in ("task", "start", "goal"):
            if not isinstance(data.get(key), str) or not data.get(key):
                self.error(f, key, f"missing or not a non-empty string: {data.get(key)!r}")
        if "max_transitions" in data:
            self.note(f, "max_transitions", "dropped: our executor's tick limit and failure budgets bound an episode")
        nodes, edges = data.get("nodes"), data.get("edges")
        if not isinstance(nodes, list) or not nodes:
            self.error(f, "nodes", "missing or not a non-empty list")
            nodes = []
        if not isinstance(edges, list) or not edges:
            self.error(f, "edges", "missing or not a non-empty list")
            edges = []
        node_ids: list[str] = []
        for i, node in enumerate(nodes):
            if not isinstance(node, dict) or not isinstance(node.get("id"), str):
                self.error(f, f"nodes[{i}]", "expected an object with a string id")
                continue
            self._unknown_keys(f, f"nodes[{i}]", node, ("id", "semantic"))
            if node["id"] in node_ids:
                self.error(f, f"nodes[{i}].id", f"duplicate node id {node['id']!r}")
            node_ids.append(node["id"])
            if not isinstance(node.get("semantic", ""), str):
                self.error(f, f"nodes[{i}].semantic", "not a string")
        out: dict[str, dict] = {}
        edge_ids: set[str] = set()
        for i, edge in enumerate(edges):
            if not isinstance(edge, dict):
                self.error(f, f"edges[{i}]", f"expected an edge object, found {type(edge).__name__}")
                continue
            self._unknown_keys(f, f"edges[{i}]", edge, ("id", "source", "target", *SLOTS))
            for key in ("id", "source", "target"):
                if not isinstance(edge.get(key), str):
                    self.error(f, f"edges[{i}].{key}", f"missing or not a string: {edge.get(key)!r}")
            if not all(isinstance(edge.get(k), str) for k in ("id", "source", "target")):
                continue
            if edge["id"] in edge_ids:
                self.error(f, f"edges[{i}].id", f"duplicate edge id {edge['id']!r}")
            edge_ids.add(edge["id"])
            for key in ("source", "target"):
                if edge[key] not in node_ids:
                    self.error(f, f"edges[{i}].{key}", f"unknown node {edge[key]!r}")
            if edge["source"] in out:
                self.error(f, f"edges[{i}].source",
                           f"a second edge leaves {edge['source']!r}: the release format is one start-to-goal chain")
            out[edge["source"]] = edge
        if self.problems:
            return None
        # Follow the chain from start to goal; every edge must be on it.
        order, node, seen = [], data["start"], {data["start"]}
        if data["start"] not in node_ids:
            self.error(f, "start", f"unknown node {data['start']!r}")
        if data["goal"] not in node_ids:
            self.error(f, "goal", f"unknown node {data['goal']!r}")
        while node != data["goal"] and node in out:
            edge = out[node]
            order.append(edge)
            node = edge["target"]
            if node in seen:
                self.error(f, f"edges[{edges.index(edge)}].target", f"the chain loops back to {node!r}")
                return None
            seen.add(node)
        if node != data["goal"]:
            self.error(f, "goal", f"the chain from {data['start']!r} stops at {node!r} and never reaches the goal")
        for i, edge in enumerate(edges):
            if edge not in order:
                self.error(f, f"edges[{i}]", f"edge {edge['id']!r} is not on the start-to-goal chain")
        if self.problems:
            return None
        return nodes, order, data["start"], data["goal"], data["task"]

    def _edge_steps(self, edge: dict, index: int) -> list[_RawStep]:
        step = self._slots(self.gfile, f"edges[{index}]", edge)
        if all(v is None for v in step.values()):
            self.error(self.gfile, f"edges[{index}]", "both left_arm_action and right_arm_action are null")
            return []
        return [step]

    def _slots(self, file: str, path: str, holder: dict) -> _RawStep:
        step: _RawStep = {}
        for slot, arm in SLOTS.items():
            call = holder.get(slot)
            if call is None:
                continue
            if not isinstance(call, dict):
                self.error(file, f"{path}.{slot}", f"expected {{fn, kwargs}} or null, found {type(call).__name__}")
                continue
            step[arm] = _Raw(call, file, f"{path}.{slot}")
        return step

    # --------------------------------------------------------- recovery spec
    def _bindings(self, data: Any, steps: dict[str, list[_RawStep]], release_task: str) -> list[_Binding]:
        f = self.sfile
        if not isinstance(data, dict):
            self.error(f, "(top level)", f"expected a recovery spec object, found {type(data).__name__}")
            return []
        self._unknown_keys(f, "", data, ("task", "recovery_bindings"))
        if data.get("task") not in (None, release_task):
            self.note(f, "task", f"{data.get('task')!r} differs from the task graph's {release_task!r}")
        raw = data.get("recovery_bindings")
        if not isinstance(raw, list):
            self.error(f, "recovery_bindings", "missing or not a list")
            return []
        bindings, names = [], set()
        for i, b in enumerate(raw):
            path = f"recovery_bindings[{i}]"
            if not isinstance(b, dict):
                self.error(f, path, f"expected a binding object, found {type(b).__name__}")
                continue
            self._unknown_keys(f, path, b, ("edge_id", "failure_name", "monitors", "recovery", "merge",
                                            "repeat_until_success"))
            edge_id, name = b.get("edge_id"), b.get("failure_name")
            if edge_id not in steps:
                self.error(f, f"{path}.edge_id", f"unknown edge {edge_id!r}; the task graph has {', '.join(steps)}")
                continue
            if not isinstance(name, str) or not name:
                self.error(f, f"{path}.failure_name", f"missing or not a non-empty string: {name!r}")
                continue
            if (edge_id, name) in names:
                self.error(f, f"{path}.failure_name", f"duplicate failure {name!r} on edge {edge_id!r}")
                continue
            names.add((edge_id, name))
            merge = b.get("merge", "target")
            if merge not in ("target", "source"):
                self.error(f, f"{path}.merge", f"expected 'target' or 'source', got {merge!r}")
            repeat = b.get("repeat_until_success", False)
            if not isinstance(repeat, bool):
                self.error(f, f"{path}.repeat_until_success", f"expected true or false, got {repeat!r}")
            elif repeat:
                self.note(f, f"{path}.repeat_until_success",
                          "mapped to re-entry monitors on the recovery edge, bounded by the failure budget "
                          "(3 fires per edge and mode), not unbounded repetition")
            monitors = self._monitors(b.get("monitors"), f"{path}.monitors")
            rec_steps, intent = self._recovery_steps(b.get("recovery"), f"{path}.recovery", edge_id, steps)
            bindings.append(_Binding(i, edge_id, name, monitors, rec_steps, merge, repeat is True, intent))
        return bindings

    def _monitors(self, raw: Any, path: str) -> list[tuple[str, dict[str, Any]]]:
        f = self.sfile
        if not isinstance(raw, list) or not raw:
            self.error(f, path, "missing or not a non-empty list of monitors")
            return []
        out = []
        for j, m in enumerate(raw):
            where = f"{path}[{j}]"
            if not isinstance(m, dict):
                self.error(f, where, f"expected a monitor object, found {type(m).__name__}")
                continue
            kind = m.get("type")
            if kind == "object_moved":
                self._unknown_keys(f, where, m, ("type", "objects", "threshold"))
                objs = m.get("objects")
                if not isinstance(objs, list) or not objs or not all(isinstance(o, str) for o in objs):
                    self.error(f, f"{where}.objects", f"expected a non-empty list of object names, got {objs!r}")
                    continue
                threshold = m.get("threshold")
                if threshold is None:
                    threshold = 0.02
                    self.note(f, where, "no threshold: drift tolerance 0.02 m (the library graphs')")
                elif not _number(threshold) or threshold <= 0:
                    self.error(f, f"{where}.threshold", f"expected a positive number (m), got {threshold!r}")
                    continue
                names = [self._object(o, f, f"{where}.objects[{k}]") for k, o in enumerate(objs)]
                out.append(("object_moved", {"objects": names, "threshold": float(threshold)}))
            elif kind == "hold_lost":
                self._unknown_keys(f, where, m, ("type", "robot_name", "obj_name", "threshold"))
                arm = self._arm(m.get("robot_name"), f, f"{where}.robot_name")
                obj = m.get("obj_name")
                if not isinstance(obj, str):
                    self.error(f, f"{where}.obj_name", f"missing or not a string: {obj!r}")
                    continue
                if "threshold" in m:
                    self.note(f, f"{where}.threshold",
                              "dropped: our hold monitor is contact-based (holding), debounced by the 3-tick window")
                if arm is not None:
                    out.append(("hold_lost", {"arm": arm, "obj": self._object(obj, f, f"{where}.obj_name")}))
            else:
                self.error(f, f"{where}.type", f"unknown monitor type {kind!r}; known: object_moved, hold_lost")
        return out

    def _recovery_steps(
        self, raw: Any, path: str, failed: str, steps: dict[str, list[_RawStep]]
    ) -> tuple[list[_RawStep], str]:
        f = self.sfile
        if not isinstance(raw, list) or not raw:
            self.error(f, path, "missing or not a non-empty list of recovery steps")
            return [], ""
        out: list[_RawStep] = []
        intents = []
        for j, s in enumerate(raw):
            where = f"{path}[{j}]"
            if not isinstance(s, dict):
                self.error(f, where, f"expected a recovery step object, found {type(s).__name__}")
                continue
            kind = s.get("type")
            if s.get("force_valid") is not None:
                self.note(f, f"{where}.force_valid", f"dropped: {DROPPED_KWARGS['force_valid']}")
            pre = s.get("pre_grasp_dis")
            if pre is not None and not _number(pre):
                self.error(f, f"{where}.pre_grasp_dis", f"expected a number (m), got {pre!r}")
                continue
            extra = {"pre_grasp_dis": pre} if pre is not None else {}
            common = ("type", "force_valid", "pre_grasp_dis")
            if kind == "regrasp":
                self._unknown_keys(f, where, s, (*common, "robot_name", "obj_name"))
                arm = self._arm(s.get("robot_name"), f, f"{where}.robot_name")
                if not isinstance(s.get("obj_name"), str):
                    self.error(f, f"{where}.obj_name", f"missing or not a string: {s.get('obj_name')!r}")
                    continue
                if arm is not None:
                    call = {"fn": "grasp", "kwargs": {"obj_name": s["obj_name"], **extra}}
                    out.append({arm: _Raw(call, f, where)})
                    intents.append("regrasp")
            elif kind == "regrasp_both":
                self._unknown_keys(f, where, s, (*common, "arms"))
                arms = s.get("arms")
                if not isinstance(arms, dict) or not arms:
                    self.error(f, f"{where}.arms", f"expected {{left_arm: obj, right_arm: obj}}, got {arms!r}")
                    continue
                step: _RawStep = {}
                for release_arm, obj in arms.items():
                    arm = self._arm(release_arm, f, f"{where}.arms.{release_arm}")
                    if not isinstance(obj, str):
                        self.error(f, f"{where}.arms.{release_arm}", f"expected an object name, got {obj!r}")
                    elif arm is not None:
                        call = {"fn": "grasp", "kwargs": {"obj_name": obj, **extra}}
                        step[arm] = _Raw(call, f, f"{where}.arms.{release_arm}", {"skip_if_held": True})
                if step:
                    out.append(step)
                    intents.append("regrasp both")
                    self.note(f, where, "synchronous grasp of both arms with skip_if_held: true "
                                        "(an arm still holding its object keeps it)")
            elif kind in ("retry_failed_edge", "replay_edge"):
                self._unknown_keys(f, where, s, (*common, "edge_id") if kind == "replay_edge" else common)
                edge_id = failed if kind == "retry_failed_edge" else s.get("edge_id")
                if edge_id not in steps:
                    known = ", ".join(steps)
                    self.error(f, f"{where}.edge_id", f"unknown edge {edge_id!r}; the task graph has {known}")
                    continue
                for replayed in steps[edge_id]:
                    out.append({arm: None if raw_call is None else _Raw(raw_call.call, raw_call.file, raw_call.path,
                                                                          dict(extra))
                                for arm, raw_call in replayed.items()})
                intents.append("retry" if kind == "retry_failed_edge" else f"replay {edge_id}")
            elif kind == "action":
                self._unknown_keys(f, where, s, (*common, *SLOTS))
                step = self._slots(f, where, s)
                if not step:
                    self.error(f, where, "both left_arm_action and right_arm_action are missing or null")
                    continue
                out.append(step)
                intents.append("action")
            else:
                known = "regrasp, regrasp_both, retry_failed_edge, replay_edge, action"
                self.error(f, f"{where}.type", f"unknown recovery step type {kind!r}; known: {known}")
        return out, ", then ".join(intents)

    # ------------------------------------------------------------- actions
    def _scan_orient(self, order: list[str], steps: dict[str, list[_RawStep]]) -> None:
        """Grasp modes implied by ``orient_eef`` right after a grasp of the same arm."""
        last: dict[str, _Raw] = {}
        for edge_id in order:
            for step in steps[edge_id]:
                for arm, raw in step.items():
                    if raw is None or not isinstance(raw.call, dict):
                        continue
                    prev = last.get(arm)
                    kwargs = raw.call.get("kwargs") or {}
                    if raw.call.get("fn") == "orient_eef" and prev is not None and prev.call.get("fn") == "grasp":
                        obj = (prev.call.get("kwargs") or {}).get("obj_name")
                        mode = {"down": "top", "front": "side"}.get(kwargs.get("direction", "front"))
                        if isinstance(obj, str) and mode is not None:
                            self.grasp_modes[(arm, self.renames.get(obj, obj))] = mode
                    last[arm] = raw

    def _translate(
        self, steps: list[_RawStep], continuation: list[_RawStep], holds: dict[str, str],
        track: _Track | None = None,
    ) -> list[dict[str, ActionCall | None]]:
        """Our steps for ``steps``; ``continuation`` is what runs after them.

        ``track`` (each arm's history before ``steps``) is brought up to date in place.
        """
        out: list[dict[str, ActionCall | None]] = []
        holds = dict(holds)
        track = track if track is not None else _Track()
        for k, step in enumerate(steps):
            ours: dict[str, ActionCall | None] = {}
            for arm, raw in step.items():
                if raw is None:
                    continue
                after = steps[k + 1:] + continuation
                nxt = next((s[arm] for s in after if s.get(arm) is not None), None)
                ctx = _Ctx(arm, nxt, track.before.get(arm), track.previous.get(arm), holds, arm in track.turned)
                call = self._call(raw, ctx)
                track.before[arm] = raw
                if call is not None:
                    ours[arm] = call
                    track.update(arm, call)
            if ours:
                out.append(ours)
                holds = _after(holds, [ours])
        return out

    def _call(self, raw: _Raw, ctx: _Ctx) -> ActionCall | None:
        arm = ctx.arm
        f, path = raw.file, raw.path
        call = raw.call
        fn = call.get("fn")
        self._unknown_keys(f, path, call, ("fn", "kwargs"))
        kwargs = call.get("kwargs", {})
        if kwargs is None:
            kwargs = {}
        if not isinstance(fn, str) or not isinstance(kwargs, dict):
            self.error(f, path, f"expected {{fn: NAME, kwargs: {{...}}}}, got {call!r}")
            return None
        kwargs = dict(kwargs)
        kpath = f"{path}.kwargs"
        robot = kwargs.pop("robot_name", None)
        if robot is not None:
            mapped = self._arm(robot, f, f"{kpath}.robot_name")
            if mapped is not None and mapped != arm:
                self.error(f, f"{kpath}.robot_name", f"{robot!r} in the {arm} arm's slot")
                return None
        for key, why in DROPPED_KWARGS.items():
            if key in kwargs:
                kwargs.pop(key)
                self.note(f, f"{kpath}.{key}", f"dropped: {why}")
        handler = getattr(self, f"_fn_{fn}", None)
        if handler is None:
            known = ", ".join(sorted(n[4:] for n in dir(self) if n.startswith("_fn_")))
            self.error(f, f"{path}.fn", f"cannot map release action {fn!r}; mapped actions: {known}")
            return None
        before = len(self.problems)
        result = handler(kwargs, raw, ctx)
        if len(self.problems) > before or result is None:
            return None
        for key in kwargs:  # the handlers pop what they map
            self.error(f, f"{kpath}.{key}", f"cannot map kwarg {key!r} of {fn}")
        if kwargs:
            return None
        ours_fn, args = result
        try:
            ACTIONS[ours_fn].args.model_validate(args)
        except ValidationError as error:
            for detail in error.errors(include_url=False):
                self.error(f, kpath, f"{ours_fn}.{format_loc(detail['loc'])}: {detail['msg']} (mapped from {fn})")
            return None
        return ActionCall(fn=ours_fn, args=args)

    def _obj_kwarg(self, kwargs: dict, raw: _Raw, fn: str) -> str | None:
        obj = kwargs.pop("obj_name", None)
        if not isinstance(obj, str) or not obj:
            self.error(raw.file, f"{raw.path}.kwargs.obj_name", f"{fn} needs obj_name (a string), got {obj!r}")
            return None
        return self._object(obj, raw.file, f"{raw.path}.kwargs.obj_name")

    def _numbers(self, kwargs: dict, raw: _Raw, names: Iterable[str], default: float | None = 0.0,
                 ) -> dict[str, float | None] | None:
        """Pop numeric kwargs (``None`` where absent and no default); ``None`` if one is not a number."""
        out: dict[str, float | None] = {}
        ok = True
        for name in names:
            value = kwargs.pop(name, default)
            if value is not None and not _number(value):
                self.error(raw.file, f"{raw.path}.kwargs.{name}", f"expected a number, got {value!r}")
                ok = False
            out[name] = None if value is None or not ok else float(value)
        return out if ok else None

    def _fn_grasp(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "grasp")
        pre = kwargs.pop("pre_grasp_dis", None)
        if raw.extra.get("pre_grasp_dis") is not None:  # a recovery step's own pre_grasp_dis wins
            pre = raw.extra["pre_grasp_dis"]
        if obj is None:
            return None
        args: dict[str, Any] = {"obj": obj}
        if pre is not None:
            if not _number(pre):
                self.error(raw.file, f"{raw.path}.kwargs.pre_grasp_dis", f"expected a number (m), got {pre!r}")
                return None
            args["pre_grasp_dis"] = float(pre)
        mode = self.grasp_modes.get((ctx.arm, obj))
        if mode is not None:
            args["mode"] = mode
            self.note(raw.file, raw.path, f"grasp mode {mode!r}: the release orients this arm's tool "
                                          f"{'down' if mode == 'top' else 'front'} right after grasping {obj}")
        if raw.extra.get("skip_if_held"):
            args["skip_if_held"] = True
        return "grasp", args

    def _fn_move_relative_to_object(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "move_relative_to_object")
        d = self._numbers(kwargs, raw, ("x_offset", "y_offset", "z_offset"))
        if obj is None or d is None:
            return None
        offset = self.frame.vector((d["x_offset"], d["y_offset"], d["z_offset"]))
        held = ctx.holds.get(ctx.arm)
        if held is not None and _fn_of(ctx.nxt) == "open_gripper":
            # The release lowers what it holds to this offset and lets go there: a place. Ours
            # carries it above the spot; the open_gripper after it becomes our place.
            carry = [offset[0], offset[1], PRE_PLACE_DIS]
            self.note(raw.file, raw.path,
                      f"offset {_fmt_vec(offset)} then open_gripper: the release sets {held} down there; our "
                      f"move_to_obj carries it to {_fmt_vec(carry)} from {obj}'s top point (the release's "
                      f"pre_place_dis stand-off) and the open_gripper becomes our place")
            return "move_to_obj", {"obj": obj, "offset": carry, "keep_orientation": True}
        args: dict[str, Any] = {"obj": obj, "offset": list(offset)}
        roll = _roll_of(ctx.nxt)
        horizontal = math.hypot(offset[0], offset[1])
        if roll and horizontal > 1e-6:
            ox, oy = offset[0] / horizontal, offset[1] / horizontal
            # Negative roll tips the top toward the tool's +y, positive toward -y; tool y = z x approach.
            approach = (-oy, ox) if roll < 0 else (oy, -ox)
            args["yaw"] = round(math.degrees(math.atan2(approach[1], approach[0])), 1)
            self.note(raw.file, raw.path,
                      f"yaw {args['yaw']:g}: approach perpendicular to the offset so that the next "
                      f"rotate_eef ({_fmt(roll)} deg) tips the held object toward {obj}")
        else:
            args["keep_orientation"] = True
        self.note(raw.file, raw.path, f"offset {_fmt_vec(offset)} in our frame, measured from {obj}'s top point "
                                      "(the release's: from its base-pose origin)")
        return "move_to_obj", args

    def _fn_move_to_absolute_position(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("x", "y", "z"), default=None)
        if d is None:
            return None
        for key in ("x", "y"):
            if d[key] is None:
                self.error(raw.file, f"{raw.path}.kwargs.{key}", f"{key}: null or missing (keep the current {key}) "
                           "cannot be mapped: our move_to_target needs a full position")
        if d["x"] is None or d["y"] is None:
            return None
        if d["z"] is None:
            d["z"] = CARRY_Z
            self.note(raw.file, f"{raw.path}.kwargs.z", f"null (keep the current height) -> z = {CARRY_Z} m, "
                                                        "our carrying height")
        pos = self.frame.point((d["x"], d["y"], d["z"]))
        clipped = tuple(_round(min(max(v, lo), hi)) for v, lo, hi in zip(pos, *WORKSPACE))
        if clipped != pos:
            self.note(raw.file, raw.path, f"position {_fmt_vec(pos)} clipped to our workspace: {_fmt_vec(clipped)}")
        self.note(raw.file, raw.path, f"({_fmt(d['x'])}, {_fmt(d['y'])}, {_fmt(d['z'])}) in the release's frame "
                                      f"-> {_fmt_vec(clipped)} in ours")
        return "move_to_target", {"pos": list(clipped)}

    def _fn_move_by_relative_offset(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("dx", "dy", "dz"))
        mode = kwargs.pop("mode", "extrinsic")
        if d is None:
            return None
        if mode == "extrinsic":
            return "move_by_offset", {"offset": list(self.frame.vector((d["dx"], d["dy"], d["dz"])))}
        if mode == "intrinsic":
            if d["dx"] or d["dy"]:
                self.error(raw.file, f"{raw.path}.kwargs",
                           "an intrinsic dx/dy cannot be mapped: the release's tool x/y axes are not ours "
                           "(only dz, along the approach, is)")
                return None
            self.note(raw.file, raw.path, "intrinsic dz (the release's approach axis, tool z) -> our tool x")
            return "move_by_offset", {"offset": [d["dz"], 0.0, 0.0], "frame": "intrinsic"}
        self.error(raw.file, f"{raw.path}.kwargs.mode", f"expected 'extrinsic' or 'intrinsic', got {mode!r}")
        return None

    def _fn_rotate_eef(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        d = self._numbers(kwargs, raw, ("degree",))
        if d is None:
            return None
        return "rotate_eef", {"angle": d["degree"]}

    def _fn_place_on_table(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        obj = self._obj_kwarg(kwargs, raw, "place_on_table")
        d = self._numbers(kwargs, raw, ("x", "y"), default=None)
        if "pre_place_dis" in kwargs:
            kwargs.pop("pre_place_dis")
            self.note(raw.file, f"{raw.path}.kwargs.pre_place_dis",
                      "dropped: our place lowers from the carrying height, no stand-off parameter")
        if obj is None or d is None:
            return None
        args: dict[str, Any] = {"obj": obj, **self._place_yaw(raw, ctx, obj)}
        if d["x"] is None and d["y"] is None:
            return "place", args
        if d["x"] is None or d["y"] is None:
            self.error(raw.file, f"{raw.path}.kwargs", "only one of x, y is given: our place needs both or neither")
            return None
        x, y, _ = self.frame.point((d["x"], d["y"], 0.0))
        (x_lo, y_lo), (x_hi, y_hi) = TABLE_XY
        target = (_round(min(max(x, x_lo), x_hi)), _round(min(max(y, y_lo), y_hi)))
        if target != (x, y):
            self.note(raw.file, raw.path, f"place target ({_fmt(x)}, {_fmt(y)}) clipped to our table: "
                                          f"({_fmt(target[0])}, {_fmt(target[1])})")
        self.note(raw.file, raw.path, f"place ({_fmt(d['x'])}, {_fmt(d['y'])}) in the release's frame -> "
                                      f"({_fmt(target[0])}, {_fmt(target[1])}) in ours (the object's centre)")
        args["target"] = list(target)
        return "place", args

    def _fn_back_to_initial_pose(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        return "back", {}

    def _fn_open_gripper(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        held = ctx.holds.get(ctx.arm)
        if held is None or _fn_of(ctx.before) != "move_relative_to_object":
            return "open_gripper", {}
        # The move before it took what the arm holds to its release point: place it there.
        move = ctx.before.call.get("kwargs") or {}
        ref = self.renames.get(move.get("obj_name"), move.get("obj_name"))
        d = {k: move.get(k, 0.0) for k in ("x_offset", "y_offset", "z_offset")}
        if not isinstance(ref, str) or not all(_number(v) for v in d.values()):
            return "open_gripper", {}  # the move itself reports what is wrong with it
        dx, dy, _ = self.frame.vector((d["x_offset"], d["y_offset"], 0.0))
        args: dict[str, Any] = {"obj": held, "target": [dx, dy], "relative_to": ref}
        z = _round(min(max(float(d["z_offset"]), PLACE_Z[0]), PLACE_Z[1]))
        if z:
            args["z_offset"] = z
        args.update(self._place_yaw(raw, ctx, held))
        self.note(raw.file, raw.path,
                  f"open_gripper after move_relative_to_object({ref}) while holding {held}: the release's place by "
                  f"release -> place({held}, target ({_fmt(dx)}, {_fmt(dy)}) from {ref}'s centre"
                  f"{f', z_offset {_fmt(z)}' if z else ''}): ours lowers {held} onto the table, opens, backs off")
        return "place", args

    def _fn_close_gripper(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        return "close_gripper", {}

    def _fn_orient_eef(self, kwargs: dict, raw: _Raw, ctx: _Ctx) -> tuple[str, dict] | None:
        direction = kwargs.pop("direction", "front")
        if direction not in ("down", "front"):
            self.error(raw.file, f"{raw.path}.kwargs.direction", f"expected 'down' or 'front', got {direction!r}")
            return None
        held = ctx.holds.get(ctx.arm)
        if ctx.previous == "grasp" and held is not None and (ctx.arm, held) in self.grasp_modes:
            self.note(raw.file, raw.path, f"orient_eef {direction!r} -> zero move_by_offset (hold): the grasp before "
                                          f"it takes {held} with mode {self.grasp_modes[(ctx.arm, held)]!r}")
            return "move_by_offset", {}
        pitch = 90.0 if direction == "down" else -90.0
        self.note(raw.file, raw.path, f"orient_eef {direction!r} -> move_by_offset angles (0, {_fmt(pitch)}, 0) "
                                      f"intrinsic: assumes a {'level' if direction == 'down' else 'top-down'} tool")
        return "move_by_offset", {"angles": [0.0, pitch, 0.0], "frame": "intrinsic"}

    def _place_yaw(self, raw: _Raw, ctx: _Ctx, obj: str) -> dict[str, float]:
        """``{"yaw": ...}`` for a place of ``obj`` held as the release's ``orient_eef 'down'`` left it, else ``{}``.

        That orientation is absolute (tool x along the release's x, fingers closing along its y), so a
        thin object grasped across its narrow side is carried with its long axis along the release's
        x; our top grasp keeps the object's own yaw and only a place can set it.
        """
        if self.grasp_modes.get((ctx.arm, obj)) != "top" or ctx.turned:
            return {}
        ax, ay, _ = self.frame.vector((1.0, 0.0, 0.0))
        yaw = _round((math.degrees(math.atan2(ay, ax)) + 90.0) % 180.0 - 90.0)  # a long axis: mod 180
        yaw = 90.0 if yaw == -90.0 else yaw
        self.note(raw.file, raw.path,
                  f"place yaw {_fmt(yaw)}: the release's orient_eef 'down' is absolute (its tool x forward, fingers "
                  f"closing along its y), so {obj}, grasped across its narrow side, lies along the release's x")
        return {"yaw": yaw}

    # ------------------------------------------------------------ monitors
    def _failure(self, binding: _Binding, edge: Edge, holds: dict[str, str], entry: str) -> FailureMode:
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
                    term = f"drift({obj}, {_fmt(m['threshold'])})"
                    arm = grasped.get(obj) or holder.get(obj)
                    terms.append(f"(1 - {arm}.closed) * {term}" if arm else term)
        monitor = terms[0] if len(terms) == 1 else f"max({', '.join(terms)})"
        return FailureMode(name=binding.name, monitor=monitor, window=_WINDOW, intent=binding.intent or "recover",
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
            name = RELEASE_TASKS.get(_norm(key))
            if name is not None:
                return name
        name = _slug(release_task)
        self.note(self.gfile, "task", f"no simulated task matches {release_task!r}: task name {name!r} (use --task)")
        return name

    def _unknown_keys(self, file: str, path: str, data: dict, known: Iterable[str]) -> None:
        known = tuple(known)
        for key in data:
            if key not in known:
                where = f"{path}.{key}" if path else str(key)
                self.error(file, where, f"cannot map field {key!r} (known here: {', '.join(known)})")


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _fmt_vec(v: Sequence[float]) -> str:
    return "(" + ", ".join(_fmt(x) for x in v) + ")"


def _roll_of(raw: _Raw | None) -> float:
    """The roll (deg) of a release ``rotate_eef`` call, 0 for anything else."""
    if raw is None or not isinstance(raw.call, dict) or raw.call.get("fn") != "rotate_eef":
        return 0.0
    degree = (raw.call.get("kwargs") or {}).get("degree", 0)
    return float(degree) if _number(degree) else 0.0


def _fn_of(raw: _Raw | None) -> str | None:
    """The release action name of a call, None for none."""
    return raw.call.get("fn") if raw is not None and isinstance(raw.call, dict) else None


def _after(holds: dict[str, str], steps: list[dict[str, ActionCall | None]]) -> dict[str, str]:
    """What each arm holds after ``steps``: a grasp takes its object, a place or opening lets go."""
    holds = dict(holds)
    for step in steps:
        for arm, call in step.items():
            if call is None:
                continue
            if call.fn == "grasp":
                holds[arm] = call.args["obj"]
            elif call.fn in ("place", "open_gripper"):
                holds.pop(arm, None)
    return holds


def _released(before: dict[str, str], steps: list[dict[str, ActionCall | None]]) -> list[tuple[str, str]]:
    """``(arm, obj)`` pairs that ``steps`` let go of on purpose."""
    holds, out = dict(before), []
    for step in steps:
        for arm, call in step.items():
            if call is None:
                continue
            if call.fn == "grasp":
                holds[arm] = call.args["obj"]
            elif call.fn in ("place", "open_gripper") and arm in holds:
                out.append((arm, holds.pop(arm)))
    return sorted(out)
