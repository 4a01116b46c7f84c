"""Sweep records on disk: durable appends, a torn tail dropped, another sweep's directory refused."""

import json

import pytest

from agentchord.bench.exceptions import SweepStoreError
from agentchord.bench.store import MANIFEST, RECORDS, RecordStore
from agentchord.bench.sweep import RECORD_VERSION, SweepConfig
from agentchord.execution.reasoning import LatencyModel, ReasoningConfig


def _record(key: str, **extra) -> dict:
    return {"id": key, "version": RECORD_VERSION, "success": True, **extra}


def test_records_survive_reopening_and_are_not_written_twice(tmp_path):
    store = RecordStore(tmp_path / "sweep", SweepConfig())
    store.append(_record("a|m|p=0.1|0"))
    store.append(_record("a|m|p=0.1|1"))
    store.append(_record("a|m|p=0.1|1"))  # a key already stored
    again = RecordStore(tmp_path / "sweep", SweepConfig())
    assert len(again) == 2 and "a|m|p=0.1|1" in again
    assert len((tmp_path / "sweep" / RECORDS).read_text().splitlines()) == 2


def test_a_torn_last_line_is_dropped_and_its_episode_runs_again(tmp_path):
    store = RecordStore(tmp_path, SweepConfig())
    store.append(_record("k0"))
    with open(tmp_path / RECORDS, "ab") as handle:
        handle.write(b'{"id": "k1", "vers')  # killed mid-write
    reopened = RecordStore(tmp_path, SweepConfig())
    assert list(reopened.records) == ["k0"]
    reopened.append(_record("k1"))
    lines = (tmp_path / RECORDS).read_text().splitlines()
    assert [json.loads(line)["id"] for line in lines] == ["k0", "k1"]


def test_a_directory_of_another_sweep_configuration_is_refused(tmp_path):
    RecordStore(tmp_path, SweepConfig())
    other = SweepConfig(reasoning=ReasoningConfig(latency=LatencyModel(plan=20.0)))
    with pytest.raises(SweepStoreError, match="another configuration.*reasoning"):
        RecordStore(tmp_path, other)
    assert json.loads((tmp_path / MANIFEST).read_text()) == SweepConfig().to_dict()


def test_a_corrupt_record_names_the_file_and_line(tmp_path):
    RecordStore(tmp_path, SweepConfig()).append(_record("k0"))
    with open(tmp_path / RECORDS, "a") as handle:
        handle.write("not json\n")
    with pytest.raises(SweepStoreError, match=r"records.jsonl: line 2: not a JSON record"):
        RecordStore(tmp_path, SweepConfig())


def test_an_output_that_is_a_file_is_refused(tmp_path):
    path = tmp_path / "file"
    path.write_text("x")
    with pytest.raises(SweepStoreError, match="not a directory"):
        RecordStore(path, SweepConfig())


def test_an_episode_stopped_on_an_internal_error_runs_again_and_its_verdict_counts(tmp_path):
    store = RecordStore(tmp_path, SweepConfig())
    store.append(_record("k0", success=False, error="KeyError: 'x'", traceback="..."))
    assert "k0" not in store  # not finished: a rerun runs it again
    store.append(_record("k0", steps=700))
    store.append(_record("k0", success=False, error="KeyError: 'x'"))  # finished now: not written again
    reopened = RecordStore(tmp_path, SweepConfig())
    assert "k0" in reopened and reopened.records["k0"]["steps"] == 700
    assert len((tmp_path / RECORDS).read_text().splitlines()) == 2
