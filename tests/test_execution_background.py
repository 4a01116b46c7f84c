"""A pipelined plan answered by an LLM in a thread: the robot moves before the arranger replies, and the
episode equals the offline one with the same latencies (a local replay server, 127.0.0.1 only)."""

import json

import pytest
from replay_server import Completion, ReplayServer

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.pipeline import plan_task
from agentchord.agents.rules import RulesReasoner
from agentchord.execution.background import ScriptedPlan, ThreadedPlan
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.reasoning import ReasoningConfig
from agentchord.graph.models import TaskGraph
from agentchord.library import load_task_graph
from agentchord.sim.disturbances import ScriptedDrop
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world

TASK = "single_arm_pour_water"
DELAY_S = 2.0


def _physical(result) -> list[tuple]:
    """What happened in the world and the executor, not what was charged."""
    kept = ("edge_start", "node_reached", "disturbance", "failure_detected", "recovery_switch", "failure_before_branch",
            "branch_arrived", "modes_listed", "monitors_armed", "recovery_bound", "episode_end")
    return [(e["tick"], e["event"], e.get("edge"), e.get("failure"), e.get("to"), e.get("node")) for e in result.trace.events
            if e["event"] in kept]


def test_the_robot_moves_before_the_arranger_replies_and_the_episode_equals_the_offline_one(monkeypatch):
    instruction = load_task_graph(TASK).instruction
    rules = RulesReasoner()
    plan_task(instruction, observe(open_world(TASK, 0), task_regions(SIM_TASKS[TASK])), rules, TASK)
    drop = ScriptedDrop("move_to_obj", after=5)  # on the second edge, before the plan's rest can be there
    with ReplayServer() as server:
        for call in rules.calls:  # composer, arranger, conductor: each answers after DELAY_S
            server.push(Completion(json.dumps(call.reply), delay_s=DELAY_S))
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "replay-model")
        monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "test-key")
        live = run_episode(EpisodeSpec(TASK, seed=0, instruction=instruction, reasoner="llm", repair=False,
                                       reasoning=ReasoningConfig(), disturbance=drop))
        assert len(server.requests) == 3
    assert live.success, live.reason
    (asked,) = live.trace.of("plan_asked")
    (replied,) = live.trace.of("plan_replied")
    first_edge = live.trace.of("edge_start")[0]
    # The first motion came before the arranger's reply: the robot ran while the agents thought.
    assert asked["tick"] == first_edge["tick"] == 0 and replied["arrives_tick"] > 0
    assert 2 * DELAY_S <= replied["latency_s"] < 2 * DELAY_S + 1.0
    assert replied["arrives_tick"] == pytest.approx(replied["latency_s"] * 50, abs=1)
    assert live.first_motion_s == pytest.approx(DELAY_S, abs=0.5)  # the composer's measured call only
    # The drop came before the modes: it waited for them, then recovered.
    assert live.early_failures and live.early_failures[0]["then"] == "recovery for bottle_dropped"

    # The same episode offline, the plan's rest arriving after the latency the live one measured.
    calls = [e for e in live.trace.events if e["event"] == "reasoner_call"]
    composed = TaskGraph.model_validate(calls[0]["reply"])
    conducted = TaskGraph.model_validate(replied["calls"][-1]["reply"])
    offline = run_episode(EpisodeSpec(TASK, seed=0, graph=composed, reasoning=ReasoningConfig(), disturbance=ScriptedDrop("move_to_obj", after=5),
                                      background=ScriptedPlan(replied["latency_s"], conducted)))
    assert _physical(offline) == _physical(live)
    assert offline.steps == live.steps and offline.success


def test_a_failed_background_plan_is_survived_with_its_reason_in_the_trace():
    graph = load_task_graph(TASK)
    from agentchord.agents.prompts import nominal_part

    result = run_episode(EpisodeSpec(TASK, seed=0, graph=nominal_part(graph), reasoning=ReasoningConfig(),
                                     background=ScriptedPlan(1.0, None, error="ReasonerError: no valid reply")))
    assert result.success, result.reason  # undisturbed: the composed graph is enough
    (replied,) = result.trace.of("plan_replied")
    assert replied["error"] == "ReasonerError: no valid reply" and not result.trace.of("plan_arrived")


def test_the_control_loop_does_not_run_ahead_of_a_pending_reply():
    import time

    clock = [0.0]
    plan = ThreadedPlan(lambda: (time.sleep(0.3), (None, []))[1], clock=time.perf_counter)
    plan.start()
    started = time.perf_counter()
    assert plan.poll(0.0) is None  # nothing to wait for at the first motion
    arrival = plan.poll(5.0)  # the loop would be 5 s ahead: it waits for the reply instead
    assert arrival is not None and 0.25 < time.perf_counter() - started < 2.0
    assert arrival.latency_s == pytest.approx(0.3, abs=0.15) and clock == [0.0]


def _composer_then(server_reply, monkeypatch):
    """A replay server whose first answer is the rules composer's reply for TASK, every later one ``server_reply``."""
    from replay_server import composer_first

    monkeypatch.setenv("AGENTCHORD_LLM_MODEL", "replay-model")
    monkeypatch.setenv("AGENTCHORD_LLM_API_KEY", "test-key")
    return composer_first(TASK, server_reply)


@pytest.mark.parametrize("fallback", [True, False])
def test_an_arranger_outage_never_leaves_the_robot_blind(monkeypatch, fallback):
    """Issue 58: the arranger answering HTTP 500 until it gives up. Before, from that moment no monitor was
    armed and a bottle dropped during the pour was never detected (the episode ended later, "bottle is not
    held", 0 failures detected). Now the offline arranger writes the branches and the robot recovers; or,
    without that fallback, the derived monitors catch the drop and the reason names the plan's failure."""
    from replay_server import HttpError

    instruction, server = _composer_then(HttpError(500, "upstream down"), monkeypatch)
    with server:
        monkeypatch.setenv("AGENTCHORD_LLM_BASE_URL", server.base_url)
        result = run_episode(EpisodeSpec(TASK, seed=0, instruction=instruction, reasoner="llm", repair=False,
                                         reasoning=ReasoningConfig(), disturbance=ScriptedDrop("rotate_eef", after=20),
                                         arranger_fallback=fallback))
    (replied,) = result.trace.of("plan_replied")
    assert "500" in replied["error"] and replied["outage"]
    assert result.drops_injected == 1 and result.drops_detected == 1, result.reason
    if fallback:
        assert replied["fallback"] == "rules" and result.trace.of("plan_arrived")[0]["written_by"] == "rules"
        assert result.success and result.recoveries >= 1, result.reason
    else:
        assert not result.success and "the arranger's plan failed" in result.reason and "500" in result.reason
        assert result.trace.of("unrecovered") and not result.trace.of("plan_arrived")


def test_a_plan_that_fails_while_a_failure_waits_for_its_branch_ends_with_the_reason():
    """Issue 58: a derived monitor caught the drop, the arms waited for the branch, then the arranger failed:
    the trace said "no failure mode of the edge is violated: the edge goes on" with the bottle on the table.
    Now the wait ends with the failure unrecovered and the plan's error as the reason."""
    from agentchord.agents.prompts import nominal_part

    error = "ReasonerTransportError: the arranger's endpoint answered HTTP 500 after 3 tries"
    result = run_episode(EpisodeSpec(TASK, seed=0, graph=nominal_part(load_task_graph(TASK)), reasoning=ReasoningConfig(),
                                     disturbance=ScriptedDrop("move_to_obj", after=5),
                                     background=ScriptedPlan(6.0, None, error=error, outage=True)))
    (arrived,) = result.trace.of("branch_arrived")
    assert "edge goes on" not in arrived["then"] and "plan failed" in arrived["then"]
    assert not result.success and "HTTP 500" in result.reason
    assert result.failures_detected == 1 and result.drops_detected == 1


def test_after_a_failed_plan_every_nominal_edge_keeps_its_derived_monitors():
    from agentchord.agents.prompts import nominal_part

    result = run_episode(EpisodeSpec(TASK, seed=0, graph=nominal_part(load_task_graph(TASK)), reasoning=ReasoningConfig(),
                                     background=ScriptedPlan(0.5, None, error="ReasonerError: no valid reply")))
    assert result.success, result.reason  # undisturbed: the composed graph is enough
    (failed,) = result.trace.of("plan_failed")
    assert failed["tick"] == 25 and not failed["outage"]  # taken at the tick it arrives, not when polled
    armed = [e for e in result.trace.of("monitors_armed") if e["tick"] >= failed["tick"]]
    assert armed and all(all(m.startswith("keeps: ") for m in e["monitors"]) for e in armed)


def test_run_says_when_the_offline_arranger_stood_in_or_the_plan_failed():
    """An adversarial pass (issue 58): the trace said the LLM's plan failed and the rules wrote the branches,
    but ``run``'s output said nothing of it."""
    import io

    from rich.console import Console

    from agentchord.agents.prompts import nominal_part
    from agentchord.cli.episode import _print_episode

    graph = load_task_graph(TASK)
    for plan, words in ((ScriptedPlan(0.5, graph, error="ReasonerTransportError: HTTP 500", outage=True, fallback="rules"),
                         "the rules arranger and conductor wrote the recovery branches instead"),
                        (ScriptedPlan(0.5, None, error="ReasonerTransportError: HTTP 500", outage=True),
                         "each edge keeps the monitors derived from its constraints")):
        result = run_episode(EpisodeSpec(TASK, seed=0, graph=nominal_part(graph), reasoning=ReasoningConfig(), background=plan))
        out = io.StringIO()
        _print_episode(Console(file=out, width=300), result)
        assert "the LLM's plan failed (ReasonerTransportError: HTTP 500)" in out.getvalue() and words in out.getvalue()


def test_a_late_reply_that_is_refused_is_written_by_the_offline_arranger(monkeypatch):
    """Issue 58: a background reply refused before it runs (an object the scene lacks) left the robot with no
    monitor. Now the offline arranger writes the branches (the trace names the refusal)."""
    import agentchord.episode as episode_module
    from agentchord.execution.background import FallbackPlan
    from agentchord.graph.exceptions import GraphNotRunnableError

    scene = observe(open_world(TASK, 0), task_regions(SIM_TASKS[TASK]))
    from agentchord.agents.prompts import nominal_part

    composed = nominal_part(load_task_graph(TASK))
    real = episode_module.require_runnable
    refused = []

    def refuse_the_llms(graph, names, task, source):
        if not refused:  # the LLM's reply: it names a ghost
            refused.append(graph)
            raise GraphNotRunnableError(source, ["edge 'e3': names 'ghost', which the scene lacks"])
        return real(graph, names, task, source)

    monkeypatch.setattr(episode_module, "require_runnable", refuse_the_llms)
    work = episode_module._augmenting(composed, scene, RulesReasoner(), open_world(TASK, 0), TASK)
    with pytest.raises(FallbackPlan) as raised:
        work()
    assert "ghost" in str(raised.value.cause) and raised.value.by == "rules" and raised.value.graph.failures()
    without = episode_module._augmenting(composed, scene, RulesReasoner(), open_world(TASK, 0), TASK, fallback=False)
    refused.clear()
    with pytest.raises(GraphNotRunnableError):
        without()
