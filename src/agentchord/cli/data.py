"""``agentchord record``: AgentChord episodes as a LeRobot v3.0 dataset (docs/data.md)."""

from __future__ import annotations


import click
from rich.console import Console

from agentchord.cli.support import BadInput, FiniteFloatRange, catches_sigterm


def _kinds(ctx, param, value: str) -> tuple[str, ...]:
    from agentchord.harness import parse_kinds

    try:
        return parse_kinds(value)
    except ValueError as exc:
        raise click.BadParameter(str(exc)) from exc


def _size(ctx, param, value: str) -> tuple[int, int]:
    try:
        width, height = (int(v) for v in value.lower().split("x"))
    except ValueError:
        raise click.BadParameter(f"{value!r} is not WIDTHxHEIGHT (e.g. 320x240)") from None
    if not (16 <= width <= 1920 and 16 <= height <= 1080) or width % 8 or height % 8:
        raise click.BadParameter(f"{value!r}: width and height must be multiples of 8 within 16..1920 x 16..1080")
    return height, width


@click.command("record")
@click.argument("task")
@click.option("--episodes", type=click.IntRange(1), default=10, show_default=True, help="Episodes to write.")
@click.option("--out", "out", type=click.Path(file_okay=False), required=True,
              help="Dataset directory: a new one, or one this command was interrupted writing (rerun it to resume).")
@click.option("--p", "p", type=FiniteFloatRange(0.0, 1.0), default=0.0, show_default=True, help="Disturbance probability per atomic action.")
@click.option("--disturb", default="drop", show_default=True, callback=_kinds, help="Disturbance kinds, comma-separated: drop, pull, perturb, shift, knock.")
@click.option("--protocol", type=click.Choice(("real", "stress", "custom")), is_flag=False, flag_value="custom", default=None,
              help="1-2 disturbances at random moments of each trial (ignores --p): 'real', 'stress' or bare --protocol (--disturb).")
@click.option("--only-recovered", is_flag=True, help="Write only episodes in which a recovery merged back.")
@click.option("--keep-failed", is_flag=True, help="Write failed episodes too.")
@click.option("--seed", type=click.IntRange(0), default=0, show_default=True, help="First seed; the next episodes take the next seeds.")
@click.option("--max-tries", type=click.IntRange(1), default=None, help="Seeds to run at most (default 10 x --episodes).")
@click.option("--camera", "cameras", multiple=True, default=("top", "right_wrist"), show_default=True,
              help="Scene camera recorded (repeat for more; 'none' for no images).")
@click.option("--size", default="320x240", show_default=True, callback=_size, help="Image size WIDTHxHEIGHT.")
@catches_sigterm
def record_command(task, episodes, out, p, disturb, protocol, only_recovered, keep_failed, seed, max_tries, cameras, size) -> None:
    """Run TASK's seeded episodes and write them as a LeRobot v3.0 dataset at --out.

    Each frame has the 14-dim ALOHA joint state and action, the objects' poses, camera images
    (videos), the instruction as its task, and columns marking the active graph node and edge and
    whether it lies in a recovery segment. Failed episodes are not written unless --keep-failed.
    Each episode is on disk once it is reported written: interrupted (Ctrl-C, SIGTERM), the same
    command resumes the dataset with the next seed. Exit status 0 when --episodes episodes were
    written, 1 when fewer were.
    """
    import sys

    from agentchord.cli.support import check_rendered, disturbance_setting
    from agentchord.library import library_tasks
    from agentchord.sim.tasks import SIM_TASKS

    if task not in SIM_TASKS:
        raise click.BadParameter(f"unknown task {task!r} (tasks: {', '.join(SIM_TASKS)})", param_hint="TASK")
    if task not in library_tasks():
        raise click.BadParameter(f"{task!r} has no library graph to record", param_hint="TASK")
    check_rendered(task, "a recorded dataset")
    from agentchord.guard import OutputPathError
    from agentchord.guard.outputs import check_output_folder

    try:
        check_output_folder(out, "--out")
    except OutputPathError as error:
        raise BadInput(str(error)) from None
    cameras = () if tuple(cameras) == ("none",) else tuple(cameras)
    from agentchord.data.record import ResumeError, record_settings, recorded_state

    from agentchord.guard.locks import FolderBusyError, lock_folder

    disturbances = disturbance_setting(p, disturb, protocol)
    try:
        state = recorded_state(out, record_settings(task, disturbances, only_recovered, keep_failed, seed,
                                                    cameras, size, "agentchord"))
    except ResumeError as exc:
        raise BadInput(f"--out {out}: {exc}") from None
    from agentchord.sim.trial import open_world

    known = open_world(task, seed).camera_names
    unknown = [c for c in cameras if c not in known]
    if unknown:
        raise click.BadParameter(f"no camera {unknown[0]!r} in the {task} scene (cameras: {', '.join(known)})", param_hint="--camera")
    from agentchord.data.record import record

    try:  # one recording per folder, held until the process ends; then what is there is read again
        lock_folder(out, ".record.lock", "recording")
        state = recorded_state(out, record_settings(task, disturbances, only_recovered, keep_failed, seed,
                                                    cameras, size, "agentchord"))
    except FolderBusyError as exc:
        raise BadInput(str(exc)) from None
    except ResumeError as exc:
        raise BadInput(f"--out {out}: {exc}") from None
    console = Console()
    if state is not None:
        console.print(f"resuming {out}: {len(state['episodes'])} episodes written, going on from seed {state['next_seed']}")

    def progress(s: int, entry: dict | None, why: str) -> None:
        if entry is None:
            console.print(f"  seed {s}: not written ({why})")
        else:
            console.print(f"  seed {s}: written, {entry['steps']} ticks, {entry['recoveries']} recoveries, "
                          f"{entry['recovery_frames']} recovery frames")

    try:
        report = record(task, episodes, out, disturbances=disturbances, only_recovered=only_recovered,
                        keep_failed=keep_failed, seed=seed, max_tries=max_tries, cameras=cameras, image_size=size,
                        progress=progress)
    except ResumeError as exc:
        raise BadInput(f"--out {out}: {exc}") from None
    except OSError as exc:
        raise BadInput(f"--out {out}: {exc.strerror or exc}") from exc
    frames = sum(e["frames"] for e in report.written)
    console.print(f"dataset: {report.root} ({len(report.written)} episodes, {frames} frames, "
                  f"{len(report.skipped)} seeds not written)")
    sys.exit(0 if len(report.written) >= episodes else 1)

