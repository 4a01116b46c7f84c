"""``run`` as a process with an LLM that hangs: it exits when its episode ends, and promptly on a signal.

Issue 58: the background arranger's thread was joined at exit, so a process whose episode had ended
lived on until the call did (the LLM deadline: 600 s), and Ctrl-C while a call was in flight printed
"interrupted" and kept running (a second Ctrl-C: a traceback from ``threading._shutdown``). A local
replay server (127.0.0.1) plays the LLM.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import pytest
from replay_server import Completion, ReplayServer, composer_first


TASK = "single_arm_pour_water"
NEVER_S = 120.0  # a reply that never comes within the test


def _server(composer_hangs: bool) -> tuple[str, ReplayServer]:
    return composer_first(TASK, Completion("{}", delay_s=NEVER_S), first=not composer_hangs)


def _run(server: ReplayServer, instruction: str, *extra: str) -> subprocess.Popen:
    env = {**os.environ, "AGENTCHORD_LLM_BASE_URL": server.base_url, "AGENTCHORD_LLM_MODEL": "replay-model",
           "AGENTCHORD_LLM_API_KEY": "test-key", "AGENTCHORD_LLM_TIMEOUT_S": "300", "AGENTCHORD_LLM_DEADLINE_S": "600"}
    return subprocess.Popen([sys.executable, "-m", "agentchord.cli", "run", TASK, "--reasoner", "llm", "--instruction",
                             instruction, *extra], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


@pytest.mark.slow
def test_run_exits_when_its_episode_ends_though_the_arranger_never_answers(tmp_path):
    instruction, server = _server(composer_hangs=False)
    summary = tmp_path / "episode.json"
    with server:
        process = _run(server, instruction, "--json", str(summary))
        try:
            out, err = process.communicate(timeout=90)
        finally:
            process.kill()
        ended = time.time()
    assert summary.exists(), err
    assert ended - summary.stat().st_mtime < 5.0, "the process lived on after its episode's summary was written"
    assert process.returncode in (0, 1), err
    assert "Traceback" not in err


@pytest.mark.slow
@pytest.mark.parametrize(("composer_hangs", "sig", "code"), [(True, signal.SIGINT, 130), (False, signal.SIGINT, 130),
                                                              (False, signal.SIGTERM, 143)])
def test_a_signal_while_a_call_is_in_flight_exits_at_once(composer_hangs, sig, code):
    instruction, server = _server(composer_hangs)
    with server:
        process = _run(server, instruction)
        try:
            deadline = time.time() + 60
            while len(server.requests) < (1 if composer_hangs else 2) and time.time() < deadline:
                time.sleep(0.1)  # the call that hangs is in flight
            assert process.poll() is None
            sent = time.time()
            process.send_signal(sig)
            out, err = process.communicate(timeout=30)
            took = time.time() - sent
        finally:
            process.kill()
    assert process.returncode == code, err
    assert took < 5.0, f"exited {took:.1f} s after the signal"
    assert "Traceback" not in err
