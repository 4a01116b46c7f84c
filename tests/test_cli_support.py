"""Command-line plumbing (``cli/support.py``): outputs that name one file, SIGTERM as an interruption."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap

import click
import pytest
from click.testing import CliRunner

from agentchord.cli import main
from agentchord.cli.support import EXIT_TERMINATED, BadInput, Terminated, check_outputs, sigterm_as_interrupt

POUR = "single_arm_pour_water"


def test_two_outputs_on_one_path_are_refused_before_any_work(tmp_path):
    same = tmp_path / "out.json"
    with pytest.raises(BadInput, match=r"cannot write --json .*out.json: it is the same file as --trace; give each output its own path"):
        check_outputs(("--trace", same, ()), ("--json", same, ()))
    assert not same.exists()


def test_another_spelling_or_a_symlink_of_one_output_is_the_same_file(tmp_path):
    target = tmp_path / "out.json"
    link = tmp_path / "link.json"
    link.symlink_to(target)  # dangling: nothing written yet
    with pytest.raises(BadInput, match="same file as -o"):
        check_outputs(("-o", target, ()), ("--trace", link, ()))
    with pytest.raises(BadInput, match="same file as -o"):
        check_outputs(("-o", tmp_path / "sub" / ".." / "out.json", ()), ("--trace", target, ()))
    target.write_text("{}")
    hard = tmp_path / "hard.json"
    os.link(target, hard)
    with pytest.raises(BadInput, match="same file as -o"):
        check_outputs(("-o", target, ()), ("--trace", hard, ()))


def test_an_output_that_is_an_input_is_refused(tmp_path):
    graph = tmp_path / "g.yaml"
    graph.write_text("task: t\n")
    with pytest.raises(BadInput, match=r"cannot write --json .*g.yaml: it is the same file as the --graph input"):
        check_outputs(("--json", graph, ()), inputs=(("--graph", graph),))
    assert graph.read_text() == "task: t\n"


def test_a_device_may_take_several_outputs(tmp_path):
    check_outputs(("--trace", "/dev/null", ()), ("--json", "/dev/null", ()))


@pytest.mark.parametrize("args", [
    ["run", POUR, "--trace", "{d}/o.json", "--json", "{d}/o.json"],
    ["run", POUR, "--json", "{d}/o.json", "--video", "{d}/./o.json"],
    ["plan", "pour water into the cup", "--task", POUR, "-o", "{d}/g.yaml", "--trace", "{d}/g.yaml"],
])
def test_the_commands_refuse_two_outputs_on_one_path(tmp_path, args):
    result = CliRunner().invoke(main, [a.format(d=tmp_path) for a in args])
    assert result.exit_code == 2, result.output
    assert "it is the same file as" in result.output
    assert "Traceback" not in result.output
    assert list(tmp_path.iterdir()) == []


def test_run_refuses_to_write_over_its_graph(tmp_path):
    from agentchord.library import library_path

    graph = tmp_path / "g.yaml"
    graph.write_text(library_path(POUR).read_text())
    before = graph.read_text()
    result = CliRunner().invoke(main, ["run", POUR, "--graph", str(graph), "--json", str(graph)])
    assert result.exit_code == 2, result.output
    assert "same file as the --graph input" in result.output
    assert graph.read_text() == before


def test_sigterm_inside_raises_terminated_and_the_handler_is_restored():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Terminated), sigterm_as_interrupt():
        os.kill(os.getpid(), signal.SIGTERM)
    assert signal.getsignal(signal.SIGTERM) == before


def test_a_terminated_command_exits_143_with_one_line():
    @click.command()
    def stub() -> None:
        raise Terminated

    from agentchord.cli.support import GuardedGroup

    group = GuardedGroup(commands={"stub": stub})
    result = CliRunner().invoke(group, ["stub"])
    assert result.exit_code == EXIT_TERMINATED
    assert result.output.strip() == "agentchord: terminated"


SIGTERM_DURING_VIDEO = textwrap.dedent("""
    import os, signal, sys, time
    from agentchord.cli import episode
    from agentchord.cli import main

    class Executor:  # what run's video hook reads of the executor
        def __init__(self):
            from agentchord.sim.trial import open_world
            self.world = open_world("single_arm_pour_water", 0)
            self.trace = type("T", (), {"events": []})()
            self.program = None
            self.node = "v0"
            from agentchord.library import load_task_graph
            self.graph = load_task_graph("single_arm_pour_water")

    def terminated(spec, on_tick, *args):
        on_tick(Executor())  # the renderer is open and a frame taken
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(5)
        print("SIGTERM was not delivered")

    episode._run_or_explain = terminated
    main(["run", "single_arm_pour_water", "--video", sys.argv[1]], prog_name="agentchord")
""")


def test_sigterm_during_run_video_exits_143_without_traceback_or_temporary_file(tmp_path):
    video = tmp_path / "v.mp4"
    done = subprocess.run([sys.executable, "-c", SIGTERM_DURING_VIDEO, str(video)], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path)
    assert done.returncode == EXIT_TERMINATED, (done.returncode, done.stderr)
    assert done.stderr.strip() == "agentchord: terminated"
    assert list(tmp_path.iterdir()) == []


def test_an_argument_that_is_not_utf8_is_refused_before_any_command_reads_it():
    """Issue 58: non-UTF-8 bytes in argv (Python hands them over as lone surrogates) made the error
    handler itself crash writing its log: two tracebacks, exit 1, an empty log."""
    from click.testing import CliRunner

    from agentchord.cli import main

    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--instruction", "pour \udcff the bottle"])
    assert result.exit_code == 2
    assert "argument 4 ('pour \\xff the bottle') is not valid UTF-8: byte 0xFF" in result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)


def test_the_error_log_is_written_whatever_argv_holds(tmp_path, monkeypatch):
    from agentchord.cli.support import write_error_log

    monkeypatch.setenv("AGENTCHORD_LOG_DIR", str(tmp_path))
    monkeypatch.setattr("sys.argv", ["agentchord", "plan", "\udcff\ud800"])
    try:
        raise RuntimeError("boom")
    except RuntimeError as error:
        log = write_error_log(error)
    assert log is not None and "RuntimeError: boom" in log.read_text() and "\\udcff" in log.read_text()
