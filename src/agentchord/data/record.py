"""Record AgentChord episodes as a LeRobot v3.0 dataset (``agentchord record``).

Each frame: the ALOHA joint state before the tick (``observation.state``), the objects' true poses
(``observation.environment_state``), camera images (``observation.images.<camera>``), the
joint-position command of the tick (``action``), and what the executor was doing: the active graph
node and edge (names and indices into ``meta/agentchord.json``'s lists), the edge's kind, and
whether the frame lies in a recovery segment (from the switch to a recovery edge until it merges
back into the nominal path). The instruction is the task text.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from agentchord.data.lerobot import DatasetWriter
from agentchord.execution.episode import EpisodeSpec, run_episode
from agentchord.gym.aloha import JOINT_NAMES, environment_names, environment_state, joint_action, joint_state
from agentchord.gym.cameras import RgbCameras
from agentchord.tasks import load_task_graph
from agentchord.worlds.protocol import CONTROL_HZ

#: Cameras recorded by default (ALOHA's high camera and the right wrist).
DEFAULT_CAMERAS = ("top", "right_wrist")


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


def record(task: str, episodes: int, out: str | Path, *, p: float = 0.0, disturb: tuple[str, ...] = ("drop",),
           protocol: bool = False, only_recovered: bool = False, keep_failed: bool = False, seed: int = 0,
           max_tries: int | None = None, cameras: tuple[str, ...] = DEFAULT_CAMERAS,
           image_size: tuple[int, int] = (240, 320), strategy: str = "agentchord",
           progress: Callable[[int, dict | None, str], None] | None = None) -> RecordReport:
    """Run seeds ``seed``, ``seed + 1`` ... until ``episodes`` episodes are written (or ``max_tries``
    seeds were run, default 10 x ``episodes``), and write them as a LeRobot v3.0 dataset at ``out``.

    Args:
        task: A simulated task with a library graph.
        episodes: Episodes to write.
        out: The dataset directory (must not exist).
        p, disturb, protocol: The disturbances, as ``agentchord run`` takes them.
        only_recovered: Write only episodes with at least one recovery that merged back.
        keep_failed: Write failed episodes too.
        cameras: Scene cameras recorded.
        image_size: (height, width) of the images.
        progress: Called after each seed with (seed, the written episode's entry or None, why not).

    Raises:
        FileExistsError: ``out`` exists.
        KeyError: Unknown task.
    """
    graph = load_task_graph(task)
    nodes = [n.id for n in graph.nodes]
    edges = [e.id for e in graph.edges]
    instruction = graph.instruction or task.replace("_", " ")
    from agentchord.worlds.sim.trial import open_world  # noqa: PLC0415  (the scene's object names)

    env_names = environment_names(open_world(task, seed))
    writer = DatasetWriter(out, CONTROL_HZ, features(env_names, cameras, image_size), robot_type="aloha")
    report = RecordReport(root=Path(out))
    tries = max_tries if max_tries is not None else 10 * episodes
    current = seed
    while len(report.written) < episodes and current < seed + tries:
        recorder = EpisodeRecorder(writer, cameras, image_size, nodes, edges)
        spec = EpisodeSpec(task=task, strategy=strategy, p=p, seed=current, disturb=disturb, protocol=protocol)
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
        if progress is not None:
            progress(current, entry, why)
        current += 1
    writer.finalize()
    meta = {"task": task, "instruction": instruction, "nodes": nodes, "edges": edges,
            "disturbances": {"p": p, "kinds": list(disturb), "protocol": protocol}, "strategy": strategy,
            "episodes": report.written}
    (Path(out) / "meta/agentchord.json").write_text(json.dumps(meta, indent=2) + "\n")
    return report


__all__ = ["DEFAULT_CAMERAS", "EpisodeRecorder", "RecordReport", "features", "record", "np"]
