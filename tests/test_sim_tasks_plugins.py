"""Tasks from outside the package: ``AGENTCHORD_TASKS`` files and ``agentchord.tasks`` entry points."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from pathlib import Path

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.sim import tasks as task_registry
from agentchord.sim.exceptions import SceneSpecError, TaskPluginError

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "fruit_and_bowl.py"

SCENE = textwrap.dedent('''
    """Two blocks and a cup, under another name: a scene a user writes outside the package."""
    from agentchord.sim.tasks.blocks_and_cup import BlocksAndCup


    class MyBlocks(BlocksAndCup):
        name = "my_blocks"
        description = "The blocks scene, registered from a file."


    TASK = MyBlocks()
''')


def _registered(monkeypatch, value: str) -> dict:
    monkeypatch.setenv(task_registry.TASKS_VARIABLE, value)
    return task_registry._plugins({})


def test_a_file_and_a_folder_of_task_modules_are_registered(tmp_path, monkeypatch):
    (tmp_path / "my_blocks.py").write_text(SCENE)
    (tmp_path / "_helpers.py").write_text("raise RuntimeError('not a task module: never imported')\n")
    assert list(_registered(monkeypatch, str(tmp_path / "my_blocks.py"))) == ["my_blocks"]
    assert list(_registered(monkeypatch, str(tmp_path))) == ["my_blocks"]


@pytest.mark.parametrize(("content", "message"), [
    (None, "is neither a .py file nor a folder"),
    ("x = 1\n", "defines no TASK"),
    ("raise RuntimeError('boom')\n", "importing it raised RuntimeError: boom"),
    ("TASK = object()\n", "its TASK has no name, description, sample_scene, success_tracker"),
    (SCENE.replace("TASK = MyBlocks()", "TASK = MyBlocks"), "its TASK is the class MyBlocks, not a task: make one, TASK = MyBlocks()"),
    (SCENE.replace('"my_blocks"', '"blocks_and_cup"'), "a task named 'blocks_and_cup' exists already"),
    (SCENE.replace('"my_blocks"', '"my blocks!"'), "is not a plain identifier"),
], ids=["missing", "no TASK", "raises", "not a task", "a class", "name taken", "bad name"])
def test_a_bad_task_module_is_refused_naming_the_variable_the_file_and_the_problem(tmp_path, monkeypatch, content, message):
    path = tmp_path / "scene.py"
    if content is not None:
        path.write_text(content)
    registry = dict(task_registry.SIM_TASKS)
    monkeypatch.setenv(task_registry.TASKS_VARIABLE, str(path))
    with pytest.raises(TaskPluginError, match="AGENTCHORD_TASKS") as caught:
        task_registry._plugins(registry)
    assert message in str(caught.value)


def test_the_command_line_runs_a_task_from_a_file_and_refuses_a_bad_one_with_exit_2(tmp_path):
    (tmp_path / "my_blocks.py").write_text(SCENE)
    env = {**os.environ, "AGENTCHORD_TASKS": str(tmp_path / "my_blocks.py")}
    run = [sys.executable, "-m", "agentchord.cli", "run", "my_blocks", "--instruction", "put the red block into the cup"]
    done = subprocess.run(run, env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "SUCCESS" in done.stdout, done.stdout + done.stderr
    env["AGENTCHORD_TASKS"] = str(tmp_path / "nope.py")
    done = subprocess.run([sys.executable, "-m", "agentchord.cli", "tasks"], env=env, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and "nope.py' is neither a .py file" in done.stdout + done.stderr
    assert "Traceback" not in done.stderr


def test_an_installed_packages_entry_point_is_registered(tmp_path, monkeypatch):
    from importlib.metadata import EntryPoint

    (tmp_path / "my_scene_pkg.py").write_text(SCENE)
    monkeypatch.syspath_prepend(str(tmp_path))
    points = [EntryPoint(name="my_blocks", value="my_scene_pkg:TASK", group=task_registry.ENTRY_POINT_GROUP)]
    monkeypatch.setattr(task_registry.importlib.metadata, "entry_points", lambda group: points if group == task_registry.ENTRY_POINT_GROUP else [])
    monkeypatch.delenv(task_registry.TASKS_VARIABLE, raising=False)
    assert list(task_registry._plugins({})) == ["my_blocks"]
    points[0] = EntryPoint(name="gone", value="no_such_module_here:TASK", group=task_registry.ENTRY_POINT_GROUP)
    with pytest.raises(TaskPluginError, match="entry point gone = no_such_module_here:TASK .* ModuleNotFoundError"):
        task_registry._plugins({})


def test_the_guides_worked_example_registers_and_its_instruction_succeeds(monkeypatch):
    """docs/scenes.md's example scene, as a user registers it: the guide stays true."""
    monkeypatch.setenv(task_registry.TASKS_VARIABLE, str(EXAMPLE))
    found = task_registry._plugins({})
    assert list(found) == ["fruit_and_bowl"]
    monkeypatch.setitem(task_registry.SIM_TASKS, "fruit_and_bowl", found["fruit_and_bowl"])
    result = run_episode(EpisodeSpec("fruit_and_bowl", seed=0, instruction="put the apple into the bowl, then the lime on the board"))
    assert result.success, result.reason


@pytest.mark.parametrize(("change", "message"), [
    ({"shape": "sphere", "size": (0.03,)}, "shape 'sphere' is not one the simulator builds"),
    ({"shape": "cylinder", "size": (0.03, 0.02, 0.01)}, "a cylinder takes 2 sizes (radius, half-height), got 3"),
    ({"size": (0.02, 0.02, float("nan"))}, "must be finite"),
    ({"size": (0.02, 0.02, 2.0)}, "each size must be from 0.002 to 1 m"),
    ({"mass": 0.0}, "mass must be from 0.001 to 20 kg"),
], ids=["unknown shape", "wrong size count", "nan", "too big", "no mass"])
def test_an_object_written_wrong_is_refused_naming_it(change, message):
    from agentchord.sim.scene import ObjectSpec

    fields = {"name": "apple", "shape": "box", "size": (0.02, 0.02, 0.02), "mass": 0.1, "pos": (0.0, 0.5)} | change
    with pytest.raises(SceneSpecError, match="object 'apple'") as caught:
        ObjectSpec(**fields)
    assert message in str(caught.value)
