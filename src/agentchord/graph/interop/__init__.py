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

from agentchord.graph.interop.conventions import (
    ARM_NAMES,
    CARRY_Z,
    DROPPED_KWARGS,
    GRIPPING,
    PLACE_Z,
    PRE_PLACE_DIS,
    RELEASE_TASKS,
    SLOTS,
    TABLE_XY,
    WORKSPACE,
)
from agentchord.graph.interop.converter import (
    ImportResult,
    import_release,
    import_release_data,
)
from agentchord.graph.interop.exceptions import ReleaseImportError
from agentchord.graph.interop.frames import FRAMES, FrameMap

__all__ = [
    "ARM_NAMES",
    "CARRY_Z",
    "DROPPED_KWARGS",
    "FRAMES",
    "GRIPPING",
    "PLACE_Z",
    "PRE_PLACE_DIS",
    "RELEASE_TASKS",
    "SLOTS",
    "TABLE_XY",
    "WORKSPACE",
    "FrameMap",
    "ImportResult",
    "ReleaseImportError",
    "import_release",
    "import_release_data",
]
