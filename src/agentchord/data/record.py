"""Record AgentChord episodes as a LeRobot v3.0 dataset (``agentchord record``).

Each frame: the ALOHA joint state before the tick (``observation.state``), the objects' true poses
(``observation.environment_state``), camera images (``observation.images.<camera>``), the
joint-position command of the tick (``action``), and what the executor was doing: the active graph
node and edge (names and indices into ``meta/agentchord.json``'s lists), the edge's kind, and
whether the frame lies in a recovery segment (from the switch to a recovery edge until it merges
back into the nominal path). The instruction is the task text.

Each episode is on disk as soon as it is reported written (the dataset's files are rewritten
after it, ``meta/agentchord.json`` last: it lists the episodes kept and the next seed). An
interrupted recording (Ctrl-C, SIGTERM) leaves the dataset of the episodes it finished, and the
same call resumes it (:func:`recorded_state`); the episode it was writing is dropped.
"""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from agentchord.data.lerobot import DatasetWriter
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.guard.outputs import atomic_write_text
from agentchord.gym.aloha import JOINT_NAMES, environment_names, environment_state, joint_action, joint_state
from agentchord.gym.cameras import RgbCameras
from agentchord.library import load_task_graph
from agentchord.harness import UNDISTURBED, DisturbanceSetting
from agentchord.worlds.protocol import CONTROL_HZ

#: Cameras recorded by default (ALOHA's high camera and the right wrist).
DEFAULT_CAMERAS = ("top", "right_wrist")
#: The file that says what a recording is, which episodes it kept and where it goes on.
META_PATH = "meta/agentchord.json"


class ResumeError(ValueError):
    """A folder that ``record`` cannot go on with: not its dataset, unreadable, or recorded otherwise."""


def recorded_state(out: str | Path, settings: dict) -> dict | None:
    """What a recording at ``out`` made with ``settings`` has done so far, to go on with it.

    Args:
        out: The dataset directory.
        settings: The recording's settings (:func:`record_settings`).

    Returns:
        ``None`` when ``out`` is missing or an empty folder (a new recording), else the recording's
        ``meta/agentchord.json``: ``episodes`` (those kept), ``skipped``, ``next_seed``.

    Raises:
        ResumeError: ``out`` is a file, a folder that holds something else, an unreadable or
            damaged recording, or one made with other settings (the first differing one named).
    """
    root = Path(out)
    if not root.exists():
        return None
    if not root.is_dir():
        raise ResumeError("it exists and is not a directory")
    meta_path = root / META_PATH
    try:
        if not meta_path.exists():
            if not any(p.name not in ("tmp", ".record.lock") for p in root.iterdir()):
                return None  # empty, or interrupted before the first checkpoint
            raise ResumeError("it exists and holds no dataset that `record` wrote (no meta/agentchord.json): "
                              "give a new directory")
        meta = json.loads(meta_path.read_text())
    except OSError as exc:
        raise ResumeError(f"cannot read it: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise ResumeError(f"{META_PATH} is damaged ({exc}): give a new directory") from None
    recorded = meta.get("settings") if isinstance(meta, dict) else None
    if not isinstance(recorded, dict) or not isinstance(meta.get("episodes"), list) \
            or not isinstance(meta.get("next_seed"), int):
        raise ResumeError(f"{META_PATH} does not say how it was recorded (written by an older agentchord?): "
                          "give a new directory")
    for key, value in settings.items():
        if recorded.get(key) != value:
            raise ResumeError(f"it was recorded with {key} = {recorded.get(key)!r}, not {value!r}: rerun with the "
                              "same options to resume it, or give a new directory")
    return meta


def record_settings(task: str, disturbances: DisturbanceSetting, only_recovered: bool,
                    keep_failed: bool, seed: int, cameras: tuple[str, ...], image_size: tuple[int, int],
                    strategy: str) -> dict:
    """What decides a recording's episodes: a resumed recording must have the same."""
    return {"task": task, "p": float(disturbances.p), "disturb": list(disturbances.kinds), "protocol": disturbances.protocol is not None,
            "only_recovered": bool(only_recovered), "keep_failed": bool(keep_failed), "first_seed": int(seed),
            "cameras": list(cameras), "image_size": list(image_size), "strategy": strategy}


@dataclass
class RecordReport:
    """What ``record`` did.

    Attributes:
        root: The dataset's directory.
        written: Per written episode: its seed, steps, recoveries and recovery frames.
        skipped: Seeds run but not written, with why (failed, not recovered).
    """

    root: Path
    written: list[dict] = field(default_factory=list)
    skipped: list[tuple[int, str]] = field(default_factory=list)


def features(env_names: list[str], cameras: tuple[str, ...], image_size: tuple[int, int]) -> dict:
    """The dataset's user features."""
    h, w = image_size
    out = {
        "observation.state": {"dtype": "float32", "shape": [len(JOINT_NAMES)], "names": list(JOINT_NAMES)},
        "observation.environment_state": {"dtype": "float32", "shape": [len(env_names)], "names": env_names},
        "action": {"dtype": "float32", "shape": [len(JOINT_NAMES)], "names": list(JOINT_NAMES)},
        "agentchord.node": {"dtype": "string", "shape": [1], "names": None},
        "agentchord.edge": {"dtype": "string", "shape": [1], "names": None},
        "agentchord.node_index": {"dtype": "int64", "shape": [1], "names": None},
        "agentchord.edge_index": {"dtype": "int64", "shape": [1], "names": None},
        "agentchord.edge_kind": {"dtype": "string", "shape": [1], "names": None},
        "agentchord.recovery": {"dtype": "bool", "shape": [1], "names": None},
    }
    for camera in cameras:
        out[f"observation.images.{camera}"] = {
            "dtype": "video", "shape": [h, w, 3], "names": ["height", "width", "channels"],
            "info": {"video.height": h, "video.width": w, "video.codec": "h264", "video.pix_fmt": "yuv420p",
                     "video.is_depth_map": False, "video.fps": CONTROL_HZ, "video.channels": 3, "has_audio": False},
        }
    return out


class EpisodeRecorder:
    """The ``on_tick`` callback of one episode: frames into the writer, annotated with the executor's state.

    A frame pairs the state after tick k (and its images) with the command of tick k + 1 and the
    executor's node, edge and recovery flag at tick k + 1 (what decided that command).
    """

    def __init__(self, writer: DatasetWriter, cameras: tuple[str, ...], image_size: tuple[int, int],
                 nodes: list[str], edges: list[str]) -> None:
        self.writer = writer
        self.cameras = cameras
        self.image_size = image_size
        self.nodes = nodes
        self.edges = edges
        self._pending: dict | None = None
        self._renderer: RgbCameras | None = None
        self.recovery_frames = 0

    def __call__(self, executor) -> None:
        world = executor.world
        if self._pending is not None:
            program = executor.program
            edge = program.edge_id if program is not None else ""
            node = executor.node
            recovery = executor.recovering_from is not None or executor.binding is not None
            self.writer.add_frame({
                **self._pending,
                "action": joint_action(world.commands),
                "agentchord.node": node,
                "agentchord.edge": edge,
                "agentchord.node_index": self._index(self.nodes, node),
                "agentchord.edge_index": self._index(self.edges, edge) if edge else -1,
                "agentchord.edge_kind": program.kind if program is not None else "",
                "agentchord.recovery": bool(recovery),
            })
            self.recovery_frames += bool(recovery)
        if self._renderer is None and self.cameras:
            self._renderer = RgbCameras(world, self.cameras, self.image_size)
        images = self._renderer.render() if self._renderer is not None else {}
        self._pending = {
            "observation.state": joint_state(world),
            "observation.environment_state": environment_state(world),
            **{f"observation.images.{c}": image for c, image in images.items()},
        }

    @staticmethod
    def _index(names: list[str], name: str) -> int:
        if name not in names:  # an online repair added it
            names.append(name)
        return names.index(name)

    def close(self) -> None:
        """Free the renderer."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


def record(task: str, episodes: int, out: str | Path, *, disturbances: DisturbanceSetting = UNDISTURBED,
           only_recovered: bool = False, keep_failed: bool = False, seed: int = 0,
           max_tries: int | None = None, cameras: tuple[str, ...] = DEFAULT_CAMERAS,
           image_size: tuple[int, int] = (240, 320), strategy: str = "agentchord",
           progress: Callable[[int, dict | None, str], None] | None = None) -> RecordReport:
    """Run seeds ``seed``, ``seed + 1`` ... until ``episodes`` episodes are written (or ``max_tries``
    seeds were run, default 10 x ``episodes``), and write them as a LeRobot v3.0 dataset at ``out``.

    Args:
        task: A simulated task with a library graph.
        episodes: Episodes to write.
        out: The dataset directory: new, empty, or a recording of the same settings to go on with
            (its episodes kept, the seeds after the last one tried run).
        disturbances: How the episodes are disturbed (``agentchord run``'s ``--p``, ``--disturb``, ``--protocol``).
        only_recovered: Write only episodes with at least one recovery that merged back.
        keep_failed: Write failed episodes too.
        cameras: Scene cameras recorded.
        image_size: (height, width) of the images.
        progress: Called after each seed with (seed, the written episode's entry or None, why not).

    Raises:
        ResumeError: ``out`` holds something else, or a recording made with other settings.
        KeyError: Unknown task.
    """
    graph = load_task_graph(task)
    nodes = [n.id for n in graph.nodes]
    edges = [e.id for e in graph.edges]
    instruction = graph.instruction or task.replace("_", " ")
    from agentchord.sim.trial import open_world  # the scene's object names

    settings = record_settings(task, disturbances, only_recovered, keep_failed, seed, cameras, image_size, strategy)
    state = recorded_state(out, settings)
    env_names = environment_names(open_world(task, seed))
    frames_features = features(env_names, cameras, image_size)
    report = RecordReport(root=Path(out))
    current = seed
    if state is None:
        writer = DatasetWriter(out, CONTROL_HZ, frames_features, robot_type="aloha", exist_ok=True)
    else:
        try:
            writer = DatasetWriter.resume(out, CONTROL_HZ, frames_features, len(state["episodes"]), robot_type="aloha")
        except (OSError, ValueError, KeyError) as exc:
            raise ResumeError(f"its dataset cannot be taken up again ({exc}): give a new directory") from None
        report.written = list(state["episodes"])
        report.skipped = [tuple(s) for s in state.get("skipped", [])]
        nodes = list(state.get("nodes", nodes))
        edges = list(state.get("edges", edges))
        current = state["next_seed"]

    def save(complete: bool = False) -> None:
        writer.checkpoint()
        meta = {"task": task, "instruction": instruction, "nodes": nodes, "edges": edges,
                "disturbances": {"p": disturbances.p, "kinds": list(disturbances.kinds), "protocol": disturbances.protocol is not None}, "strategy": strategy,
                "settings": settings, "next_seed": current, "complete": complete,
                "skipped": [list(s) for s in report.skipped],
                "episodes": report.written}
        atomic_write_text(Path(out) / META_PATH, json.dumps(meta, indent=2) + "\n")

    tries = max_tries if max_tries is not None else 10 * episodes
    try:
        if state is None:
            save()  # a dataset of no episode yet: from here on, the folder can always be resumed
        while len(report.written) < episodes and current < seed + tries:
            recorder = EpisodeRecorder(writer, cameras, image_size, nodes, edges)
            spec = EpisodeSpec(task=task, strategy=strategy, seed=current, disturbances=disturbances)
            try:
                result = run_episode(spec, on_tick=recorder)
            finally:
                recorder.close()
            why = ""
            if not result.success and not keep_failed:
                why = f"failed: {result.reason}"
            elif only_recovered and not result.trace.of("recovery_merged"):
                why = "no recovery"
            elif writer.episode_frames == 0:
                why = "no frames"
            entry = None
            if why:
                writer.discard_episode()
                report.skipped.append((current, why))
            else:
                entry = {"seed": current, "success": result.success, "steps": result.steps, "frames": writer.episode_frames,
                         "recoveries": result.recoveries,
                         "recovery_frames": recorder.recovery_frames,
                         "disturbances": ",".join(e["kind"] for e in result.trace.of("disturbance"))}
                writer.save_episode(instruction, extra=entry)
                report.written.append(entry)
            current += 1
            save()  # on disk before it is reported
            if progress is not None:
                progress(current - 1, entry, why)
    except BaseException:
        # Interrupted: the episode being written goes; the saved ones stay, as last checkpointed.
        writer.discard_episode()
        shutil.rmtree(Path(out) / "tmp", ignore_errors=True)
        raise
    writer.finalize()
    save(complete=True)
    return report


__all__ = ["DEFAULT_CAMERAS", "META_PATH", "EpisodeRecorder", "RecordReport", "ResumeError", "features", "record",
           "record_settings", "recorded_state", "np"]
