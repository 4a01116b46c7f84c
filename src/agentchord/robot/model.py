"""The robot's MuJoCo model: the ALOHA XML and meshes from the installed ``gym-aloha``
package (loaded by path: we neither import its environments nor copy its files), edited
through ``mujoco.MjSpec`` -- a tool-centre site between the fingers, gravity compensation,
lighter joint friction, our own position actuators.

The simulator builds its scene on it (``sim/scene.py``); the IK works on the robot
alone with capsule collision proxies (:func:`build_robot_model`).
"""

from __future__ import annotations

import os

import mujoco

from agentchord.robot.aloha import ARM_JOINTS, ARM_PREFIX, COLLISION_PROXIES, FINGER_RANGE, TCP_OFFSET
from agentchord.robot.exceptions import RobotModelError

#: Position gains of the arm joint actuators (N m / rad). Higher than gym-aloha's
#: so that a 0.4 kg bottle does not sag the wrist during a pour.
ARM_KP = (800.0, 1600.0, 800.0, 300.0, 300.0, 200.0)
ARM_FORCE = (150.0, 300.0, 150.0, 60.0, 60.0, 40.0)
FINGER_KP = 400.0
FINGER_FORCE = 12.0


def aloha_assets_dir() -> str:
    """The folder of the ALOHA model files inside the installed gym-aloha package.

    Raises:
        RobotModelError: gym-aloha is not installed, or its model files are missing.
    """
    try:
        import gym_aloha  # imported for its data files only
    except ImportError as exc:  # pragma: no cover - install problem
        raise RobotModelError("gym-aloha is not installed: run `make install` (it ships the ALOHA model)") from exc
    path = os.path.join(os.path.dirname(gym_aloha.__file__), "assets")
    if not os.path.isfile(os.path.join(path, "vx300s_right.xml")):
        raise RobotModelError(f"{path}: the ALOHA model files are missing from the gym-aloha package")
    return path


#: Iterations of MuJoCo's noslip pass: the friction of a grasp (a pinch of cloth) held without creep.
NOSLIP_ITERATIONS = 3


def robot_xml(timestep: float = 0.002, extra_worldbody: str = "") -> str:
    """The MJCF document of both arms (``extra_worldbody``: more elements of the world body)."""
    assets = aloha_assets_dir()
    return f"""<mujoco model="agentchord_aloha">
  <compiler meshdir="{assets}" angle="radian"/>
  <option timestep="{timestep}" integrator="implicitfast" cone="elliptic" noslip_iterations="{NOSLIP_ITERATIONS}"/>
  <include file="{assets}/vx300s_dependencies.xml"/>
  <worldbody>
    <include file="{assets}/vx300s_left.xml"/>
    <include file="{assets}/vx300s_right.xml"/>
    {extra_worldbody}
  </worldbody>
</mujoco>"""


def edit_robot(spec: mujoco.MjSpec) -> None:
    """Our edits of the ALOHA model: gravity compensation, joint friction, tool sites, actuators, finger pads."""
    for arm, prefix in ARM_PREFIX.items():
        for body in spec.bodies:
            if body.name.startswith(prefix + "/"):
                # Gravity compensation: hold error 2.4 mm -> 0.5 mm in the prototype.
                body.gravcomp = 1.0
        for joint_name in ARM_JOINTS:
            joint = spec.joint(f"{prefix}/{joint_name}")
            # gym-aloha's 30-60 N m of friction loss made the arm lag and knock objects over.
            joint.frictionloss = 1.0
            joint.damping = [2.0, 0.0, 0.0]
            joint.armature = 0.01
        for finger in ("left_finger", "right_finger"):
            joint = spec.joint(f"{prefix}/{finger}")
            joint.frictionloss = 0.2
            joint.damping = [5.0, 0.0, 0.0]
        gripper = spec.body(f"{prefix}/gripper_link")
        gripper.add_site(name=f"{arm}_tcp", pos=[TCP_OFFSET, 0.0, 0.0], size=[0.004, 0.004, 0.004], rgba=[1, 0, 0, 0])
        for joint_name, kp, force in zip(ARM_JOINTS, ARM_KP, ARM_FORCE):
            joint = spec.joint(f"{prefix}/{joint_name}")
            spec.add_actuator(
                name=f"{arm}_{joint_name}",
                target=joint.name,
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
                gaintype=mujoco.mjtGain.mjGAIN_FIXED,
                biastype=mujoco.mjtBias.mjBIAS_AFFINE,
                gainprm=[kp] + [0] * 9,
                biasprm=[0, -kp, -0.05 * kp] + [0] * 7,
                ctrlrange=list(joint.range),
                ctrllimited=True,
                forcerange=[-force, force],
                forcelimited=True,
            )
        for finger, sign in (("left_finger", 1.0), ("right_finger", -1.0)):
            lo, hi = FINGER_RANGE
            spec.add_actuator(
                name=f"{arm}_{finger}",
                target=f"{prefix}/{finger}",
                trntype=mujoco.mjtTrn.mjTRN_JOINT,
                gaintype=mujoco.mjtGain.mjGAIN_FIXED,
                biastype=mujoco.mjtBias.mjBIAS_AFFINE,
                gainprm=[FINGER_KP] + [0] * 9,
                biasprm=[0, -FINGER_KP, -0.1 * FINGER_KP] + [0] * 7,
                ctrlrange=[lo, hi] if sign > 0 else [-hi, -lo],
                ctrllimited=True,
                forcerange=[-FINGER_FORCE, FINGER_FORCE],
                forcelimited=True,
            )
            # Friction high enough to hold a 0.4 kg bottle with a 12 N squeeze.
            geom = spec.geom(f"{prefix}/10_{finger.split('_')[0]}_gripper_finger")
            geom.friction = [1.5, 0.01, 0.001]
            geom.condim = 4
            geom.solimp = [0.95, 0.99, 0.001, 0.5, 2.0]
            geom.solref = [0.01, 1.0]


def add_collision_proxies(spec: mujoco.MjSpec) -> None:
    """The capsules of :data:`~agentchord.robot.aloha.COLLISION_PROXIES` on both arms (group 5, own collision bits)."""
    for arm, prefix in ARM_PREFIX.items():
        for k, (body, start, end, radius) in enumerate(COLLISION_PROXIES):
            spec.body(f"{prefix}/{body}").add_geom(
                name=f"{arm}_proxy_{k}",
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                fromto=[*start, *end],
                size=[radius, 0.0, 0.0],
                group=5,
                # Own collision bits: proxies only ever meet the other arm's proxies.
                contype=2,
                conaffinity=2,
                mass=0.0,
                rgba=[1, 0, 0, 0.2],
            )


def build_robot_model() -> mujoco.MjModel:
    """The robot alone, with collision proxies: what the IK solver works on.

    Raises:
        RobotModelError: If the ALOHA assets are missing or the model does not compile.
    """
    try:
        spec = mujoco.MjSpec.from_string(robot_xml())
        edit_robot(spec)
        add_collision_proxies(spec)
        return spec.compile()
    except ValueError as exc:
        raise RobotModelError(f"the robot model does not compile: {exc}") from exc
