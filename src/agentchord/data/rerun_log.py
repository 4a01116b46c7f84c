"""Rerun recordings of episodes (``agentchord run ... --rerun out.rrd``).

One timeline, ``tick`` (50 Hz; ``time`` alongside in seconds), with:

- ``world/robot/{arm}/tcp``: the tool-centre pose of each arm (a transform and a point);
  ``robot/q/{arm}``: its 6 joint positions and gripper opening (0 closed, 1 open);
- ``world/objects/{name}``: each object's pose (a transform) and its box (static);
- ``cameras/{camera}``: RGB images (JPEG) every few ticks;
- ``world/points/{name}``: in RGB-D mode (``--perception rgbd``), each object's fused point cloud
  from the depth cameras, as the perception saw it, every few ticks;
- ``monitors/{edge}/{failure}/value`` against ``.../margin`` while its edge is armed, and
  ``.../streak`` against ``.../window`` (the persistence window of Eq. 12), at the tick of the
  frame they were evaluated on;
- ``graph``: the graph's nodes and edges (static) and ``graph/active``: the active node and edge;
  ``status/recovery``: 1 in a recovery segment;
- ``events``: disturbances, detected failures, recovery switches and merges, repairs (text log);
- ``world/disturbance``: what a disturbance looks like while it acts (and a moment after): a
  person's hand on a pulled object with the trail of its carry, a finger pushing or knocking one,
  an arrow along the push (:mod:`agentchord.sim.markers`), labelled with the disturbance's
  name; the camera images show them too; ``status/disturbance``: 1 while one shows, and
  ``disturbance``: its name in a text log when it starts and ends.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from agentchord.gym.aloha import ARMS, gripper_open
from agentchord.gym.cameras import RgbCameras
from agentchord.worlds.protocol import CONTROL_HZ
from agentchord.sim.markers import KIND, WHAT, DisturbanceMarkers, Shape

#: Trace events logged to ``events``, with their level.
EVENT_LEVELS = {
    "disturbance": "WARN",
    "failure_detected": "ERROR",
    "recovery_switch": "WARN",
    "recovery_merged": "INFO",
    "failure_cleared": "INFO",
    "subgoal_met": "INFO",
    "merged_ahead": "INFO",
    "recovery_failed": "ERROR",
    "repair": "INFO",
    "unrecoverable": "CRITICAL",
    "action_failed": "ERROR",
    "episode_end": "INFO",
}


def _describe(event: dict) -> str:
    skip = {"tick", "event"}
    return f"{event['event']}: " + ", ".join(f"{k}={v}" for k, v in event.items() if k not in skip)


class RerunLogger:
    """The ``on_tick`` callback that logs an episode to a ``.rrd`` file (call :meth:`close` at the end).

    Args:
        path: The ``.rrd`` file.
        task: The task name (the recording's name).
        cameras: Scene cameras logged as images (empty: none).
        image_every: Log images every this many ticks.
        image_size: (height, width) of the images.
    """

    def __init__(self, path: str | Path, task: str, cameras: tuple[str, ...] = ("top",), image_every: int = 5,
                 image_size: tuple[int, int] = (240, 320)) -> None:
        import rerun as rr

        self.rr = rr
        self.path = Path(path)
        self.task = task
        self.cameras = cameras
        self.image_every = image_every
        self.image_size = image_size
        self.rec = rr.RecordingStream(f"agentchord-{task}")
        self.rec.save(str(self.path))
        self._seen = 0
        self._started = False
        self._active: tuple[str, str] | None = None
        self._renderer: RgbCameras | None = None
        self._markers: DisturbanceMarkers | None = None
        self._shown = ""  # the disturbances shown at the last tick, as the text log says them
        self.ticks = 0

    # ------------------------------------------------------------------ static
    def _start(self, executor) -> None:
        rr, rec = self.rr, self.rec
        graph = executor.graph
        ids = [n.id for n in graph.nodes]
        colors = [(120, 160, 220) if n.kind == "nominal" else (230, 140, 60) for n in graph.nodes]
        rec.log("graph", rr.GraphNodes(ids, labels=ids, colors=colors), static=True)
        rec.log("graph", rr.GraphEdges([(e.source, e.target) for e in graph.edges], graph_type="directed"), static=True)
        world = executor.world
        for name in world.object_names:
            spec = world.object_spec(name)
            size = tuple(spec.size)
            half = (size[0], size[0], size[1]) if spec.shape == "cylinder" else size[:3]
            rec.log(f"world/objects/{name}", rr.Boxes3D(half_sizes=[half], labels=[name]), static=True)
        for arm in ARMS:
            rec.log(f"robot/q/{arm}", rr.SeriesLines(names=[*(f"j{i}" for i in range(6)), "gripper"]), static=True)
        self._started = True

    # ------------------------------------------------------------------ per tick
    def __call__(self, executor) -> None:
        rr, rec = self.rr, self.rec
        if not self._started:
            self._start(executor)
        world = executor.world
        tick = world.tick
        rec.set_time("tick", sequence=tick)
        rec.set_time("time", duration=tick / CONTROL_HZ)
        self.ticks += 1
        for arm in ARMS:
            pos, rot = world.tcp_pose(arm)
            rec.log(f"world/robot/{arm}/tcp", rr.Transform3D(translation=pos, mat3x3=rot), rr.Points3D([[0, 0, 0]], radii=0.01))
            rec.log(f"robot/q/{arm}", rr.Scalars(np.append(world.arm_q(arm), gripper_open(world, arm))))
        for name in world.object_names:
            pos, rot = world.object_pose(name)
            rec.log(f"world/objects/{name}", rr.Transform3D(translation=pos, mat3x3=rot))
        self._log_monitors(executor)
        rec.set_time("tick", sequence=tick)
        rec.set_time("time", duration=tick / CONTROL_HZ)
        program = executor.program
        active = (executor.node, program.edge_id if program is not None else "")
        if active != self._active:
            self._active = active
            rec.log("graph/active", rr.TextLog(f"node {active[0]}, edge {active[1] or '-'}"
                                              f" ({program.kind if program is not None else 'idle'})", level="INFO"))
        recovering = executor.recovering_from is not None or executor.binding is not None
        rec.log("status/recovery", rr.Scalars(1.0 if recovering else 0.0))
        for event in executor.trace.events[self._seen:]:
            level = EVENT_LEVELS.get(event["event"])
            if level is not None:
                rec.log("events", rr.TextLog(_describe(event), level=level))
        self._seen = len(executor.trace.events)
        shapes = self._log_disturbances(executor)
        if self.cameras and tick % self.image_every == 0:
            if self._renderer is None:
                self._renderer = RgbCameras(world, self.cameras, self.image_size)
            for camera, image in self._renderer.render(shapes).items():
                rec.log(f"cameras/{camera}", rr.Image(image).compress(jpeg_quality=80))
        if tick % self.image_every == 0:
            for name, cloud in getattr(executor.extractor, "clouds", {}).items():
                rec.log(f"world/points/{name}", rr.Points3D(cloud, radii=0.002))

    def _log_disturbances(self, executor) -> list[Shape]:
        """Log the disturbance markers of this tick; return their shapes (the camera images draw them)."""
        rr, rec = self.rr, self.rec
        if self._markers is None:
            self._markers = DisturbanceMarkers(executor.world)
        markers = self._markers.update()
        named = {e["obj"]: e["kind"] for e in executor.trace.events if e["event"] == "disturbance"}
        names = [f"{named.get(m.obj, KIND[m.kind])} {m.obj}" for m in markers]
        shown = "; ".join(f"{name} ({WHAT[m.kind]})" for name, m in zip(names, markers, strict=True))
        rec.log("status/disturbance", rr.Scalars(1.0 if markers else 0.0))
        if shown != self._shown:
            rec.log("disturbance", rr.TextLog(f"DISTURBANCE: {shown}" if shown else "disturbance over", level="WARN"))
            if not markers:
                rec.log("world/disturbance", rr.Clear(recursive=True))
            self._shown = shown
        if not markers:
            return []
        for name, marker in zip(names, markers, strict=True):
            _log_shapes(rr, rec, f"world/disturbance/{marker.obj}", marker.shapes(), name)
        for obj, trail in self._markers.trails.items():
            if len(trail) > 1:
                rec.log(f"world/disturbance/{obj}/carry", rr.LineStrips3D([np.array(trail)], radii=0.003,
                                                                        colors=[(255, 128, 0)]))
        return self._markers.shapes()

    def _log_monitors(self, executor) -> None:
        armed = executor.armed
        if armed is None:
            return
        rr, rec = self.rr, self.rec
        frame = executor.frame
        # At the tick of the frame the executor evaluated them on (the one before this step).
        rec.set_time("tick", sequence=frame.tick)
        rec.set_time("time", duration=frame.tick / CONTROL_HZ)
        for monitor in armed.monitors:
            base = f"monitors/{monitor.edge_id}/{monitor.failure.name}"
            value = float(monitor.expr.scalar(frame))
            if not np.isfinite(value):
                continue
            rec.log(f"{base}/value", rr.Scalars(value))
            rec.log(f"{base}/margin", rr.Scalars(float(monitor.trigger.margin)))
            rec.log(f"{base}/streak", rr.Scalars(float(monitor.trigger.streak)))
            rec.log(f"{base}/window", rr.Scalars(float(monitor.trigger.window)))

    def close(self, result=None) -> Path:
        """Log the episode's end (and the events after the last tick); flush and close the file."""
        if result is not None:
            for event in result.trace.events[self._seen:]:
                level = EVENT_LEVELS.get(event["event"])
                if level is not None:
                    self.rec.log("events", self.rr.TextLog(_describe(event), level=level))
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self.rec.flush()
        disconnect = getattr(self.rec, "disconnect", None)
        if disconnect is not None:
            disconnect()
        return self.path


def _rgba(shape: Shape) -> tuple[int, int, int, int]:
    r, g, b, a = (round(255 * c) for c in shape.rgba)
    return r, g, b, a


def _log_shapes(rr, rec, path: str, shapes: list[Shape], label: str) -> None:
    """A marker's shapes as Rerun's ellipsoids, capsules (along +z, turned onto each segment) and arrows."""
    from scipy.spatial.transform import Rotation

    ellipsoids = [s for s in shapes if s.kind == "ellipsoid"]
    capsules = [s for s in shapes if s.kind == "capsule"]
    arrows = [s for s in shapes if s.kind == "arrow"]
    rec.log(f"{path}/hand", rr.Ellipsoids3D(
        centers=[s.a for s in ellipsoids], half_sizes=[s.size for s in ellipsoids],
        quaternions=[rr.Quaternion(xyzw=Rotation.from_matrix(s.rotation).as_quat()) for s in ellipsoids],
        colors=[_rgba(s) for s in ellipsoids], fill_mode="solid", labels=[label] + [""] * (len(ellipsoids) - 1)))
    turns = [Rotation.align_vectors([s.b - s.a], [[0.0, 0.0, 1.0]])[0].as_quat() for s in capsules]
    rec.log(f"{path}/fingers", rr.Capsules3D(
        lengths=[float(np.linalg.norm(s.b - s.a)) for s in capsules], radii=[float(s.size[0]) for s in capsules],
        translations=[s.a for s in capsules], quaternions=[rr.Quaternion(xyzw=q) for q in turns],
        colors=[_rgba(s) for s in capsules]))
    if arrows:
        rec.log(f"{path}/push", rr.Arrows3D(origins=[s.a for s in arrows], vectors=[s.b - s.a for s in arrows],
                                            radii=[float(s.size[0]) / 2 for s in arrows],
                                            colors=[_rgba(s) for s in arrows]))


def read_recording(path: str | Path) -> dict[str, list]:
    """The entity paths of a ``.rrd`` file with their chunks' record batches (rerun's own reader)."""
    from rerun.chunk import RrdReader

    out: dict[str, list] = {}
    for chunk in RrdReader(path).stream().to_chunks():
        out.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return out
