"""`agentchord run --rerun`: a Rerun recording of a disturbed episode, read back with rerun's own reader."""

from __future__ import annotations


import numpy as np
import pytest
from click.testing import CliRunner

pytest.importorskip("rerun")
pytest.importorskip("rerun.chunk", reason="reading .rrd files back needs rerun-sdk's RrdReader (0.41+)")

from agentchord.cli import main
from agentchord.data.rerun_log import read_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> dict:
    path = tmp_path_factory.mktemp("rerun") / "episode.rrd"
    # Seed 0 with the cup shifted at the protocol's moment: cup_shifted fires on e3, its recovery runs.
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--protocol", "--disturb", "shift",
                                       "--rerun", str(path)])
    assert result.exit_code == 0, result.output
    assert f"rerun: {path}" in result.output
    return read_recording(path)


def _column(batches: list, name: str) -> list:
    out = []
    for batch in batches:
        if "tick" in batch.schema.names:  # not the static chunks (series names, shapes)
            values = batch.column(name).to_pylist()
            out.extend(v[0] if isinstance(v, list) and len(v) == 1 and isinstance(v[0], str) else v for v in values)
    return out


def _series(recording: dict, entity: str) -> tuple[np.ndarray, np.ndarray]:
    batches = recording[entity]
    ticks = np.array(_column(batches, "tick"))
    values = np.array([v[0] for v in _column(batches, "Scalars:scalars")])
    order = np.argsort(ticks)
    return ticks[order], values[order]


def test_the_scene_cameras_graph_and_status_are_logged(recording: dict) -> None:
    for entity in ("/graph", "/world/robot/left/tcp", "/world/robot/right/tcp", "/world/objects/cup",
                   "/world/objects/bottle", "/cameras/top", "/robot/q/right", "/status/recovery", "/events",
                   "/graph/active"):
        assert entity in recording, entity
    ticks, _ = _series(recording, "/robot/q/right")
    assert ticks[0] >= 1 and ticks[-1] > 500


def test_the_monitor_crosses_its_margin_then_the_switch_follows(recording: dict) -> None:
    ticks, value = _series(recording, "/monitors/e3/cup_shifted/value")
    _, margin = _series(recording, "/monitors/e3/cup_shifted/margin")
    _, window = _series(recording, "/monitors/e3/cup_shifted/window")
    _, streak = _series(recording, "/monitors/e3/cup_shifted/streak")
    over = ticks[value > margin]
    assert len(over) >= 1 and streak[ticks == over[0]][0] == 1
    events = _column(recording["/events"], "TextLog:text")
    event_ticks = _column(recording["/events"], "tick")
    switch = [t for t, e in zip(event_ticks, events, strict=True) if e.startswith("recovery_switch") and "cup_shifted" in e]
    # Above its margin from the onset the detection names, then the switch within the persistence
    # window and the strategy's latency (from then on the recovery edge's monitors are logged).
    detected = [e for e in events if e.startswith("failure_detected") and "cup_shifted" in e]
    assert detected and f"onset_tick={over[0]}," in detected[0]
    assert switch and over[0] + int(window[0]) - 1 <= switch[0] <= over[0] + int(window[0]) + 5
    assert any(e.startswith("disturbance") and "shift" in e for e in events)
    assert any(e.startswith("recovery_merged") for e in events)
    rec_ticks, recovering = _series(recording, "/status/recovery")
    assert recovering[rec_ticks >= switch[0]][0] == 1.0 and recovering[-1] == 0.0


def test_rerun_with_a_remote_world_is_refused() -> None:
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--world", "tcp://127.0.0.1:5555",
                                       "--rerun", "x.rrd"])
    assert result.exit_code == 2 and "--rerun" in result.output


def test_rgbd_mode_logs_the_point_clouds_the_perception_saw(tmp_path) -> None:
    path = tmp_path / "rgbd.rrd"
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--perception", "rgbd", "--rerun", str(path)])
    assert result.exit_code == 0, result.output
    recording = read_recording(path)
    for name in ("bottle", "cup"):
        points = [p for batch in recording[f"/world/points/{name}"] for p in batch.column("Points3D:positions").to_pylist()]
        cloud = np.array(points[0])
        assert cloud.ndim == 2 and len(cloud) > 50
        # Points on the table's objects: above the tabletop, within the workspace.
        assert np.all(np.isfinite(cloud)) and cloud[:, 2].min() > -0.01 and np.abs(cloud[:, 0]).max() < 0.6
    assert "/world/points/bottle" not in _oracle_recording(tmp_path)


def _oracle_recording(tmp_path) -> dict:
    path = tmp_path / "oracle.rrd"
    result = CliRunner().invoke(main, ["run", "single_arm_pour_water", "--rerun", str(path)])
    assert result.exit_code == 0, result.output
    return read_recording(path)


def test_the_push_is_drawn_and_named_while_it_acts(recording: dict) -> None:
    # The protocol's shift pushes the cup: a finger, a hand and an arrow at the cup, named as the trace names it.
    for entity in ("/world/disturbance/cup/hand", "/world/disturbance/cup/fingers", "/world/disturbance/cup/push"):
        assert entity in recording, entity
    texts = _column(recording["/disturbance"], "TextLog:text")
    assert texts[0] == "DISTURBANCE: shift cup (a person pushes it)" and texts[-1] == "disturbance over"
    ticks, shown = _series(recording, "/status/disturbance")
    assert 0 < shown.sum() < len(shown)
    pushes = _column(recording["/world/disturbance/cup/push"], "tick")
    assert min(pushes) == ticks[shown > 0][0]
