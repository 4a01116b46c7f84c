"""Renderers opened by the package: a process that renders and then imports torch's Triton lives."""

from __future__ import annotations

import importlib.util
import subprocess
import sys

import pytest

# Render with a package renderer, then import Triton as torch does when a policy trains.
# Mesa's llvmpipe (headless EGL on a CPU) and Triton each bring an LLVM; Triton loaded second
# segfaulted the process (exit -11) until open_renderer loaded it first.
RENDER_THEN_TRITON = """
import agentchord  # sets MUJOCO_GL
import mujoco
from agentchord.sim.renderers import open_renderer
model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
data = mujoco.MjData(model)
renderer = open_renderer(model, 32, 32)
renderer.update_scene(data)
image = renderer.render()
renderer.close()
import triton
print("rendered", image.shape)
"""


@pytest.mark.skipif(importlib.util.find_spec("triton") is None, reason="Triton is not installed")
def test_rendering_then_importing_triton_does_not_crash():
    done = subprocess.run([sys.executable, "-c", RENDER_THEN_TRITON], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "rendered (32, 32, 3)" in done.stdout


def test_open_renderer_renders_the_model():
    import mujoco

    from agentchord.sim.renderers import open_renderer

    model = mujoco.MjModel.from_xml_string("<mujoco><worldbody><geom size='0.1'/></worldbody></mujoco>")
    renderer = open_renderer(model, 24, 40)
    try:
        renderer.update_scene(mujoco.MjData(model))
        assert renderer.render().shape == (24, 40, 3)
    finally:
        renderer.close()
