"""AgentChord: proactive failure recovery through recovery-augmented task graphs."""

import os

# Headless rendering: MuJoCo reads MUJOCO_GL when it is first imported, so set it before
# anything imports mujoco. EGL works without a display (llvmpipe on a plain CPU).
os.environ.setdefault("MUJOCO_GL", "egl")
# One BLAS thread: the solvers' small SLSQP problems run 20-40x slower with a BLAS thread pool
# on a busy machine, and episodes already run one per core. Read when numpy is first imported.
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.1.0"
