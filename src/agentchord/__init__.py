"""AgentChord: proactive failure recovery through recovery-augmented task graphs."""

import os

# Headless rendering: MuJoCo reads MUJOCO_GL when it is first imported, so set it before
# anything imports mujoco. EGL works without a display (llvmpipe on a plain CPU).
os.environ.setdefault("MUJOCO_GL", "egl")

__version__ = "0.1.0"
