"""Command-line plumbing: exit statuses, the top-level error handler, output checks, number options,
and what several commands share (reasoner and perception names, the task check, goal files).

Exit statuses of every ``agentchord`` command:

====  ==========================================================================
0     success (the task succeeded, the file is valid, the output was written)
1     the task failed (``run``: the episode ended without success)
2     bad input: a usage error, an unreadable or invalid file, an output path that
      cannot be written, an instruction that cannot be planned
3     internal error: anything unexpected; one line on stderr, the traceback in a
      log file that the line names
130   interrupted (Ctrl-C)
143   terminated (SIGTERM, in the commands that catch it: ``run``, ``demo``, ``record``, ``serve``, ``plan``)
====  ==========================================================================
"""

from __future__ import annotations

import contextlib
import datetime
import functools
import math
import os
import signal
import sys
import tempfile
import traceback
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any

import click

from agentchord.guard.exceptions import InputError
from agentchord.guard.outputs import check_output_path

EXIT_OK = 0
EXIT_TASK_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3
EXIT_INTERRUPTED = 130  # the shell's convention for Ctrl-C (128 + SIGINT)
EXIT_TERMINATED = 143  # 128 + SIGTERM

#: Where internal-error logs go; default ``$XDG_CACHE_HOME/agentchord`` (``~/.cache/agentchord``).
ENV_LOG_DIR = "AGENTCHORD_LOG_DIR"


class BadInput(click.ClickException):
    """Bad input found by a command: its message, exit status 2."""

    exit_code = EXIT_BAD_INPUT

    def show(self, file: Any = None) -> None:
        """Print the message as is (it already names the file, field and problem)."""
        click.echo(self.format_message(), file=file or sys.stderr)


class InternalError(click.ClickException):
    """Anything unexpected: one line naming the log file with the details, exit status 3.

    Attributes:
        log: The log file holding the traceback, ``None`` if it could not be written.
    """

    exit_code = EXIT_INTERNAL

    def __init__(self, error: BaseException, log: Path | None) -> None:
        self.log = log
        first = (str(error).strip().splitlines() or [""])[0][:200]
        where = f"details in {log}" if log else "no log could be written"
        super().__init__(f"internal error: {type(error).__name__}{': ' if first else ''}{first} ({where})")

    def show(self, file: Any = None) -> None:
        """One line on stderr."""
        click.echo(f"agentchord: {self.format_message()}", file=file or sys.stderr)


def _bad_input_types() -> tuple[type[BaseException], ...]:
    # Imported late: the handler must not make every command import the agents.
    from agentchord.agents.exceptions import ReasonerError
    from agentchord.graph.exceptions import GraphFileError, GraphNotRunnableError, RenderError

    return (InputError, GraphFileError, GraphNotRunnableError, RenderError, ReasonerError)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command is, so that its ``finally`` blocks (temporary files,
    renderers, half-written episodes) run as they do for Ctrl-C."""


@contextlib.contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """While inside, SIGTERM raises :class:`Terminated` in this process (exit status 143).

    A child process forked meanwhile (a worker pool) inherits the handler; there it dies of
    SIGTERM as it would have without it.
    """
    owner = os.getpid()

    def handler(signum: int, frame: Any) -> None:
        if os.getpid() != owner:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise Terminated

    try:
        previous = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread (a test's runner): nothing to catch
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def catches_sigterm(command: Callable[..., Any]) -> Callable[..., Any]:
    """A command function run inside :func:`sigterm_as_interrupt` (put it under ``@click.command``)."""

    @functools.wraps(command)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with sigterm_as_interrupt():
            return command(*args, **kwargs)

    return wrapper


class GuardedGroup(click.Group):
    """A click group whose commands never end in a traceback.

    Known bad input that a command did not catch becomes its message with exit status 2;
    anything else becomes :class:`InternalError` (exit status 3), its traceback in a log file.
    """

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        """Refuse an argument that is not valid UTF-8 (exit 2) before any command reads it."""
        for position, arg in enumerate(args, start=1):
            bad = undecodable(arg)
            if bad is not None:
                shown = arg.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
                raise BadInput(f"argument {position} ('{shown}') is not valid UTF-8: byte {bad} cannot be read as text")
        return super().parse_args(ctx, args)

    def invoke(self, ctx: click.Context) -> Any:
        """Run the command, translating what escapes it."""
        try:
            return super().invoke(ctx)
        except (click.exceptions.ClickException, click.exceptions.Exit, click.exceptions.Abort, SystemExit):
            raise
        except Terminated:
            click.echo("agentchord: terminated", err=True)
            raise click.exceptions.Exit(EXIT_TERMINATED) from None
        except KeyboardInterrupt:
            # click would say "Aborted!" and exit 1, which means "the task failed".
            click.echo("agentchord: interrupted", err=True)
            raise click.exceptions.Exit(EXIT_INTERRUPTED) from None
        except Exception as error:
            if isinstance(error, _bad_input_types()):
                raise BadInput(str(error)) from error
            raise InternalError(error, write_error_log(error)) from error


def undecodable(text: str) -> str | None:
    """The first byte of ``text`` that was not valid UTF-8 (as Python passes such argv bytes: a lone
    surrogate, ``surrogateescape``), as ``0xFF``; None when every character is text."""
    for char in text:
        if "\udc80" <= char <= "\udcff":
            return f"0x{ord(char) - 0xDC00:02X}"
        if "\ud800" <= char <= "\udfff":
            return f"U+{ord(char):04X}"
    return None


def log_dir() -> Path:
    """The folder of internal-error logs (see :data:`ENV_LOG_DIR`)."""
    configured = os.environ.get(ENV_LOG_DIR)
    if configured:
        return Path(configured)
    cache = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(cache) / "agentchord"


def write_error_log(error: BaseException) -> Path | None:
    """Write the traceback of ``error``, the command line and the version to a new log file.

    Returns:
        The log file, or ``None`` when neither the log folder nor the temporary folder takes it.
    """
    from agentchord import __version__

    stamp = datetime.datetime.now().strftime("%Y%m%d-%H%M%S")
    text = (
        f"agentchord {__version__}, python {sys.version.split()[0]}\n"
        f"command: {' '.join(sys.argv)}\n\n"
        + "".join(traceback.format_exception(type(error), error, error.__traceback__))
    )
    for folder in (log_dir(), Path(tempfile.gettempdir())):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / f"error-{stamp}-{os.getpid()}.log"
            path.write_text(text, encoding="utf-8", errors="backslashreplace")  # argv may hold undecodable bytes
            return path
        except OSError:
            continue
    return None


def check_outputs(*outputs: tuple[str, str | Path | None, Iterable[str]],
                  inputs: Iterable[tuple[str, str | Path | None]] = ()) -> None:
    """Check every output path before any work starts (missing folders are created).

    Two outputs that name one file (``--trace out.json --json out.json``, or two spellings of
    it, or a symlink and its target) are refused: the second would overwrite the first. So is an
    output that names an input file (``--graph g.yaml --json g.yaml``). A device such as
    ``/dev/null`` may be shared.

    Args:
        outputs: ``(option, path or None, accepted suffixes)``; ``None`` paths are skipped,
            an empty suffix list accepts any.
        inputs: ``(option, path or None)`` of the files the command reads.

    Raises:
        BadInput: Every path that cannot be written, one line each.
    """
    problems = []
    given = [(option, path) for option, path, _ in outputs if path is not None]
    problems.extend(_shared_paths(given, [(option, path) for option, path in inputs if path is not None]))
    for option, path, suffixes in outputs:
        if path is None:
            continue
        try:
            check_output_path(path, suffixes, option)
        except InputError as error:
            problems.append(str(error))
    if problems:
        raise BadInput("\n".join(problems))


def _file_key(path: str | Path) -> tuple | None:
    """What identifies the file ``path`` names (None for a device or FIFO, which many outputs may share)."""
    if os.path.exists(path):
        if not os.path.isfile(path):
            return None
        stat = os.stat(path)
        return ("inode", stat.st_dev, stat.st_ino)  # hard links and symlinks included
    return ("path", os.path.realpath(path))


def _shared_paths(outputs: list[tuple[str, Any]], inputs: list[tuple[str, Any]]) -> list[str]:
    seen: dict[tuple, str] = {}
    problems = []
    for option, path in inputs:
        key = _file_key(path)
        if key is not None:
            seen.setdefault(key, f"the {option} input")
    for option, path in outputs:
        key = _file_key(path)
        if key is None:
            continue
        if key in seen:
            problems.append(f"cannot write {option} {path}: it is the same file as {seen[key]}; give each output its own path")
        else:
            seen[key] = option
    return problems


class FiniteFloatRange(click.FloatRange):
    """A float option within bounds that refuses NaN (``FloatRange`` lets NaN through: every comparison is false)."""

    name = "finite float range"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The number, or a usage error naming NaN."""
        number = super().convert(value, param, ctx)
        if isinstance(number, float) and math.isnan(number):
            self.fail("NaN is not a number: give a finite value", param, ctx)
        return number


#: The reasoners ``plan``, ``run`` and ``demo`` plan with.
REASONER_NAMES = ("rules", "llm")
#: How the agents see the scene: the simulator's ground truth, or RGB-D cameras.
PERCEPTION_NAMES = ("oracle", "rgbd")


def check_task_name(task: str, param_hint: str) -> None:
    """Refuse a task that is not simulated, naming the ones that are (a usage error on ``param_hint``)."""
    from agentchord.sim.tasks import SIM_TASKS

    if task not in SIM_TASKS:
        raise click.BadParameter(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})", param_hint=param_hint)


def check_graph_source(task: str, param_hint: str, *given: object) -> None:
    """Refuse a task with no library graph when no graph, instruction or goal is given to run instead
    (``blocks_and_cup``: its goal is whatever it is asked), naming what to give."""
    from agentchord.library import library_tasks

    if not any(g is not None for g in given) and task not in library_tasks():
        raise click.BadParameter(f"{task!r} has no library graph: give --instruction or --goal (or --graph) to plan what to do in it",
                                 param_hint=param_hint)


def check_served(task: str, what: str) -> None:
    """Refuse to serve, or to drive over the world protocol, a task judged by its environment's own reward
    (gym-aloha's): the protocol does not carry that reward yet, and a remote episode could not be judged."""
    from agentchord.sim.tasks import SIM_TASKS

    if hasattr(SIM_TASKS.get(task), "open_world"):
        raise click.UsageError(f"{task} is judged by gym-aloha's own reward, read in this process; {what} cannot carry it "
                               "yet: run it without a served world")


def check_rendered(task: str, what: str) -> None:
    """Refuse to render a task run in gym-aloha's own physics (videos, RGB-D, datasets): rendering its
    cameras through ours is not done yet (its dm_control physics keeps its own GL context)."""
    from agentchord.sim.tasks import SIM_TASKS

    if hasattr(SIM_TASKS.get(task), "open_world"):
        raise click.UsageError(f"{task} runs in gym-aloha's own physics, whose cameras {what} cannot render yet: "
                               "run it with the oracle features and without a video")


def load_goal_option(goal_path: str | None):
    """The goal spec of ``--goal`` (None without the option); an unreadable or invalid file is a usage error."""
    if goal_path is None:
        return None
    from agentchord.agents.rules.goals import GoalSpec
    from agentchord.graph.exceptions import GraphFileError
    from agentchord.graph.loader import load_model

    try:
        return load_model(goal_path, GoalSpec)
    except GraphFileError as exc:
        raise BadInput(str(exc)) from exc


def failed_calls_trace(error, trace_path) -> str:
    """Write the agents' calls of a failed plan (the replies that were refused) to the trace; say where."""
    from agentchord.execution.trace import Trace

    calls = list(getattr(error, "calls", None) or ([error.call] if getattr(error, "call", None) else []))
    if not trace_path or not calls:
        return ""
    trace = Trace()
    for call in calls:
        trace.add(0, "reasoner_call", **call.to_trace_event())
    try:
        return f"\n(the agents' calls, refused replies included: {trace.write(trace_path)})"
    except OSError as exc:
        return f"\n(the agents' calls could not be written to {trace_path}: {exc})"


def disturbance_setting(p: float, disturb: tuple[str, ...], protocol: str | None):
    """The :class:`~agentchord.harness.DisturbanceSetting` of ``--p``, ``--disturb`` and ``--protocol``."""
    from agentchord.harness import DisturbanceSetting

    try:
        return DisturbanceSetting.from_options(p, disturb, protocol)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from exc
