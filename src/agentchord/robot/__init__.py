"""The robot's description: the ALOHA bimanual ViperX's arms, joints, gripper and home pose
(:mod:`~agentchord.robot.aloha`, plain numbers), and its MuJoCo kinematic model for the IK
(:mod:`~agentchord.robot.model`).

Both the simulator (``sim/``) and the controller side (``solvers``, ``actions``) read it;
neither owns it. A real robot of the same class (an AgileX CobotMagic) would get a module of
its own beside ``aloha``.
"""
