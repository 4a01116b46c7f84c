"""``agentchord bench``: bad input exits 2; a sweep killed midway resumes without losing or repeating an episode."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from click.testing import CliRunner

from agentchord.cli import main


def test_bad_options_exit_2(tmp_path):
    runner = CliRunner()
    out = str(tmp_path / "sweep")
    for args in (["--p", "0.1,1.5"], ["--p", "nan"], ["--p", "0.1", "--protocol", "real"], ["--methods", "magic"],
                 ["--tasks", "no_such_task"], ["--latency", "plan=-1"], ["--ray-address", "auto"]):
        result = runner.invoke(main, ["bench", *args, "--out", out])
        assert result.exit_code == 2, (args, result.output)
    blocked = tmp_path / "file"
    blocked.write_text("x")
    result = runner.invoke(main, ["bench", "--p", "0", "--out", str(blocked)])
    assert result.exit_code == 2


def _ids(directory: Path) -> list[str]:
    lines = (directory / "records.jsonl").read_bytes().split(b"\n")
    return [json.loads(line)["id"] for line in lines if line.strip()]


def test_a_sweep_killed_midway_loses_and_repeats_nothing(tmp_path):
    out = tmp_path / "sweep"
    args = [sys.executable, "-m", "agentchord.cli", "bench", "--tasks", "single_arm_pour_water", "--methods", "agentchord",
            "--p", "0", "--trials", "3", "--workers", "1", "--out", str(out)]
    process = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.time() + 120
    while time.time() < deadline and not ((out / "records.jsonl").exists() and len(_ids(out)) >= 1):
        time.sleep(0.2)
    os.killpg(process.pid, signal.SIGKILL)  # kill -9, mid-sweep
    process.wait()
    before = _ids(out)
    assert 1 <= len(before) < 3
    result = subprocess.run(args, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    after = _ids(out)
    assert after[: len(before)] == before  # nothing lost
    assert sorted(after) == sorted(set(after)) and len(after) == 3  # nothing repeated
    assert f"{len(before)} already in" in " ".join(result.stdout.split())
    assert (out / "tables" / "table1.md").exists()
