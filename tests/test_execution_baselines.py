"""The four baselines in the shared executor: what each detects, what it does then, what it is charged."""

import numpy as np
import pytest

from agentchord.harness import DisturbanceSetting
from agentchord.execution.baselines.vqa import SimulatedVqa
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.reasoning import LatencyModel, ReasoningConfig

TASK = "single_arm_pour_water"


class _Const:
    def __init__(self, value: float) -> None:
        self.value = value

    def scalar(self, frame) -> float:
        return self.value


def _events(result, kind: str) -> list[dict]:
    return [e for e in result.trace.events if e["event"] == kind]


def _run(method: str, seed: int, p: float = 0.05):
    return run_episode(EpisodeSpec(TASK, strategy=method, disturbances=DisturbanceSetting(p=p), seed=seed, reasoning=ReasoningConfig()))


def test_simulated_vqa_answers_the_truth_then_flips_with_its_rates():
    holds, violated = [_Const(-1.0)], [_Const(0.5)]
    exact = SimulatedVqa(seed=0)
    assert exact.holds(holds, None) and not exact.holds(violated, None)
    blind = SimulatedVqa(seed=0, miss=1.0)
    assert blind.holds(violated, None)  # every failure missed
    nervous = SimulatedVqa(seed=0, false_alarm=1.0)
    assert not nervous.holds(holds, None)
    half = SimulatedVqa(seed=3, miss=0.5)
    answers = [half.holds(violated, None) for _ in range(400)]
    assert 0.4 < np.mean(answers) < 0.6 and half.errors == sum(answers)
    again = SimulatedVqa(seed=3, miss=0.5)
    assert [again.holds(violated, None) for _ in range(400)] == answers  # seeded


def test_latency_model_parses_and_refuses():
    model = LatencyModel.parse("plan=20, vqa=2")
    assert (model.plan, model.vqa, model.vlm) == (20.0, 2.0, 3.5)
    for bad in ("plan", "think=3", "vqa=-1", "plan=nan", "plan=abc"):
        with pytest.raises(ValueError):
            LatencyModel.parse(bad)
    with pytest.raises(ValueError):
        ReasoningConfig(vqa_miss=1.5)


def test_sequential_agentchord_and_its_ablation_wait_for_the_three_agents():
    flat = ReasoningConfig(latency=LatencyModel())
    runs = {m: run_episode(EpisodeSpec(TASK, strategy=m, disturbances=DisturbanceSetting(p=0.05), seed=0, reasoning=flat))
            for m in ("agentchord-sequential", "agentchord-bt")}
    for result in runs.values():
        # The ablation's monitors are the arranger's failure modes: it is asked too (paper App. E-C).
        assert result.reasoning_calls == {"plan": 3} and result.reasoning_s == pytest.approx(21.0)
        assert result.first_motion_s == pytest.approx(21.0 + result.compute_s)
    seq = runs["agentchord-sequential"]
    assert seq.exec_time_s == pytest.approx(seq.time_s + seq.compute_s + 21.0)
    plain = run_episode(EpisodeSpec(TASK, seed=0))  # `run` and `demo`: robot time only
    assert plain.reasoning_calls == {} and plain.steps == seq.steps


def test_pipelined_agentchord_moves_once_the_first_edge_is_grounded():
    from agentchord.execution.planning import pipelined_schedule
    from agentchord.graph.progress import forward_filter
    from agentchord.library import load_task_graph

    result = _run("agentchord", 0)
    schedule = pipelined_schedule(forward_filter(load_task_graph(TASK)).graph, ReasoningConfig().latency)
    assert result.first_motion_s == pytest.approx(schedule.first_motion_s)
    assert result.reasoning_s == pytest.approx(schedule.first_motion_s)  # the rest arrives while it moves
    assert result.reasoning_calls == {"plan": len(schedule.calls)}
    assert result.first_motion_s < _run("agentchord-sequential", 0).first_motion_s / 10


def test_inner_monologue_queries_at_each_subgoal_and_replans_on_a_no():
    result = _run("inner-monologue", 10)
    assert result.replans >= 1 and _events(result, "replan")
    # One success query per sub-goal reached, never during motion.
    ends = len(_events(result, "edge_end"))
    assert result.reasoning_calls["vqa"] <= ends
    # No compiled monitor is armed: every detection is a VQA "no" or a skill that reported failure.
    assert {e["failure"] for e in _events(result, "failure_detected")} <= {"vqa_failure", "skill_failed"}


def test_doremi_queries_during_motion_and_replans():
    result = _run("doremi", 6)
    im = _run("inner-monologue", 6)
    assert result.success and result.replans == 1
    assert result.reasoning_calls["vqa"] > im.reasoning_calls["vqa"]  # periodic queries on top of the sub-goal ones


def test_rekep_backtracks_and_never_reasons_again():
    result = _run("rekep", 4)
    assert result.success
    assert _events(result, "backtrack")
    assert result.reasoning_calls == {"plan": 1} and result.replans == 0
    (call,) = _events(result, "reasoning")
    # Priced by what it writes: every stage's constraints, fewer tokens than the composer's whole graph.
    assert 100 < call["tokens"] < 400 and call["latency_s"] == pytest.approx(0.45 + call["tokens"] / 120, abs=1e-4)


def test_code_as_monitor_replans_with_the_vlm_on_a_detection():
    result = _run("code-as-monitor", 6)
    assert result.success and result.replans >= 1
    assert set(result.reasoning_calls) == {"vlm"}
    assert _events(result, "failure_detected")  # the compiled monitors fired


def test_step_constraints_follow_the_graph_run_now_whatever_its_address():
    # A re-plan's graph reuses edge ids, and a freed graph's address is reused by a new one: a
    # cache keyed by id(graph) answered a new graph with an old graph's constraints (an episode then
    # depended on memory layout). Each new graph here is allocated where the last was freed.
    import gc
    from types import SimpleNamespace

    from agentchord.execution.baselines.strategies import DoReMiStrategy
    from agentchord.library import load_task_graph

    strategy = DoReMiStrategy()
    executor = SimpleNamespace(graph=load_task_graph(TASK))
    strategy.step_constraints(executor, "e2")
    for k in range(1, 60):
        executor.graph = None
        gc.collect()
        graph = load_task_graph(TASK)
        graph.edge("e2").path_constraints = [f"tilt(bottle) - {k}"]
        executor.graph = graph
        del graph
        assert strategy.step_constraints(executor, "e2")[0].source == f"tilt(bottle) - {k}"
