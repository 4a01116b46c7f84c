"""Sweep records on disk: durable appends, a torn tail dropped, another sweep's directory refused."""

import json

import pytest

from agentchord.bench.exceptions import SweepStoreError
from agentchord.bench.store import MANIFEST, RECORDS, RecordStore
from agentchord.bench.sweep import RECORD_VERSION, SweepConfig
from agentchord.execution.reasoning import LatencyModel, ReasoningConfig


def _record(key: str, **extra) -> dict:
    """A valid record of the episode ``key`` names (``task|method|condition|seed``)."""
    task, method, condition, seed = key.split("|")
    kind, _, value = condition.partition("=")
    record = {
        "id": key, "version": RECORD_VERSION, "task": task, "method": method, "condition": condition,
        "p": float(value) if kind == "p" else None, "protocol": value if kind == "protocol" else None,
        "seed": int(seed), "success": True, "reason": "placed", "wall_s": 1.5,
    }
    if "error" in extra:
        record["traceback"] = "Traceback ..."
    else:
        record.update(
            steps=700, exec_time_s=34.7, robot_time_s=13.7, compute_s=0.0, reasoning_s=21.0,
            reasoning_calls={"plan": 3}, replans=0, failures_detected=0, recoveries=0, drops_injected=0,
            drops_detected=0, drops_recovered=0, disturbances={}, reaction_latency_ticks=[], reaction_latency_s=[],
            unrecoverable=False, path=["v0", "e1", "v1"], disturbances_injected=0,
        )
    return {**record, **extra}


K0, K1 = "single_arm_pour_water|agentchord|p=0.1|0", "single_arm_pour_water|agentchord|p=0.1|1"


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
    store.append(_record(K0))
    with open(tmp_path / RECORDS, "ab") as handle:
        handle.write(b'{"id": "k1", "vers')  # killed mid-write
    reopened = RecordStore(tmp_path, SweepConfig())
    assert list(reopened.records) == [K0]
    reopened.append(_record(K1))
    lines = (tmp_path / RECORDS).read_text().splitlines()
    assert [json.loads(line)["id"] for line in lines] == [K0, K1]


def test_a_directory_of_another_sweep_configuration_is_refused(tmp_path):
    RecordStore(tmp_path, SweepConfig())
    other = SweepConfig(reasoning=ReasoningConfig(latency=LatencyModel(plan=20.0)))
    with pytest.raises(SweepStoreError, match="another configuration.*reasoning"):
        RecordStore(tmp_path, other)
    assert json.loads((tmp_path / MANIFEST).read_text()) == SweepConfig().to_dict()


def test_a_corrupt_record_names_the_file_and_line(tmp_path):
    RecordStore(tmp_path, SweepConfig()).append(_record(K0))
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
    store.append(_record(K0, success=False, error="KeyError: 'x'"))
    assert K0 not in store  # not finished: a rerun runs it again
    store.append(_record(K0, steps=700))
    store.append(_record(K0, success=False, error="KeyError: 'x'"))  # finished now: not written again
    reopened = RecordStore(tmp_path, SweepConfig())
    assert K0 in reopened and reopened.records[K0]["steps"] == 700
    assert len((tmp_path / RECORDS).read_text().splitlines()) == 2


@pytest.mark.parametrize(("change", "message"), [
    ({"steps": "700"}, r"steps: Input should be a valid integer \(got '700'\)"),
    ({"success": 1}, "success: Input should be a valid boolean"),
    ({"exec_time_s": float("nan")}, "exec_time_s: Input should be a finite number"),
    ({"compute_s": -1.0}, "compute_s: Input should be greater than or equal to 0"),
    ({"p": 1.5}, "p: Input should be less than or equal to 1"),
    ({"disturbances": {"pull": [1, 1]}}, "disturbances.pull: List should have at least 3 items"),
    ({"replans": None}, "replans: Input should be a valid integer"),
    ({"seed": 3}, "id .* does not name the record's episode"),
    ({"condition": "p=0.2"}, "condition 'p=0.2' does not match p/protocol"),
])
def test_a_record_with_a_bad_field_names_the_file_line_and_field(tmp_path, change, message):
    # Found by fuzzing: such a line (edited by hand, or another build's) ended in a KeyError or
    # TypeError when the tables were made (exit 3); the sweep now refuses it before any episode runs.
    RecordStore(tmp_path, SweepConfig()).append(_record(K0))
    with open(tmp_path / RECORDS, "a") as handle:
        handle.write(json.dumps(_record(K1, **change)) + "\n")
    with pytest.raises(SweepStoreError, match=r"records.jsonl: line 2: .*" + message):
        RecordStore(tmp_path, SweepConfig())


def test_a_record_missing_a_metric_is_refused_and_one_with_a_field_more_is_kept(tmp_path):
    record = _record(K0)
    del record["path"]
    (tmp_path / RECORDS).write_text(json.dumps(record) + "\n")
    with pytest.raises(SweepStoreError, match="line 1: path: Field required"):
        RecordStore(tmp_path, SweepConfig())
    (tmp_path / RECORDS).write_text(json.dumps(_record(K0, added_later=1)) + "\n")
    assert RecordStore(tmp_path, SweepConfig()).records[K0]["added_later"] == 1


# ---------------------------------------------------------------------------- issue 43
_HOLD = """
import sys, time
from agentchord.bench.store import RecordStore
from agentchord.bench.sweep import SweepConfig
store = RecordStore(sys.argv[1], SweepConfig())
print("locked", flush=True)
time.sleep(30)
"""


def test_a_second_sweep_on_the_same_directory_is_refused_naming_the_first(tmp_path):
    import subprocess
    import sys

    holder = subprocess.Popen([sys.executable, "-c", _HOLD, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(SweepStoreError, match=rf"another sweep is running on this directory \(pid {holder.pid}, "
                                                  r"started .*\); wait for it to end, or use another --out"):
            RecordStore(tmp_path, SweepConfig())
    finally:
        holder.kill()
        holder.wait(10)
    RecordStore(tmp_path, SweepConfig()).close()  # the lock went with its process


def test_bench_on_a_directory_another_sweep_holds_exits_2(tmp_path):
    import subprocess
    import sys

    from click.testing import CliRunner

    from agentchord.cli import main

    holder = subprocess.Popen([sys.executable, "-c", _HOLD, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        result = CliRunner().invoke(main, ["bench", "--out", str(tmp_path), "--tasks", "single_arm_pour_water",
                                           "--methods", "agentchord", "--p", "0", "--trials", "1"])
    finally:
        holder.kill()
        holder.wait(10)
    assert result.exit_code == 2, result.output
    assert "another sweep is running on this directory" in result.output


def test_a_records_file_that_cannot_be_read_is_bad_input(tmp_path):
    (tmp_path / RECORDS).mkdir()
    with pytest.raises(SweepStoreError, match="records.jsonl: not a records file"):
        RecordStore(tmp_path, SweepConfig())
