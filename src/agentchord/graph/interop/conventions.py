"""The release's names and our numbers the import maps them to (arms, slots, workspace, tasks)."""

from __future__ import annotations

#: Release arm names -> ours.
ARM_NAMES = {"left_arm": "left", "right_arm": "right"}
#: Arm slots of a release edge or ``action`` step -> our arm.
SLOTS = {"left_arm_action": "left", "right_arm_action": "right"}
#: Tool height (m) for ``move_to_absolute_position`` with ``z: null`` (the release keeps the
#: current height): the carrying height of our library graphs.
CARRY_Z = 0.15
#: Our workspace (m), as ``agentchord.actions.motion`` clips every pose target (kept in
#: step by a test: the graph layer sits below the actions and does not import them).
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
#: The persistence window (ticks) of the monitors of an imported graph.
PERSISTENCE_WINDOW = 3
