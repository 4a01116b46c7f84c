"""Prompt evaluation of the LLM agents: plan each case from its replay fixtures, then run its episodes.

The fixtures (``tests/data/llm/<case>/``) hold, per plan turn, the request as sent and the reply a
model wrote to it (see :mod:`agentchord.agents.llm.fixtures`). Swap the model in by answering the
requests again (``plan --record`` writes each request that has no valid reply yet).

    .venv/bin/python benchmarks/llm_prompt_eval.py plan handover_block --record   # write pending requests
    .venv/bin/python benchmarks/llm_prompt_eval.py episodes handover_block --seeds 0-2            # undisturbed
    .venv/bin/python benchmarks/llm_prompt_eval.py episodes handover_block --seeds 0-19 --protocol real
    .venv/bin/python benchmarks/llm_prompt_eval.py sizes                                          # prompt tokens
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

from agentchord.agents.llm import LlmConfig, LlmReasoner
from agentchord.agents.llm.fixtures import FixtureBook, FixtureClient, FixtureError
from agentchord.agents.llm.sizes import prompt_size
from agentchord.agents.observe import observe, task_regions
from agentchord.agents.pipeline import plan_task
from agentchord.agents.reasoner import ArrangeRequest, ComposeRequest, ConductRequest
from agentchord.episode import planned_success
from agentchord.graph.loader import dump_graph, load_graph
from agentchord.graph.models import Success, TaskGraph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world

#: Where the cases live.
CASES_DIR = Path(__file__).resolve().parents[1] / "tests" / "data" / "llm"
#: Where planned graphs and episode summaries go.
OUT_DIR = Path("/work/out/issue44") if Path("/work/out").is_dir() else Path("out/llm_prompt_eval")


def cases() -> list[str]:
    """Names of the cases, sorted."""
    return sorted(p.name for p in CASES_DIR.iterdir() if (p / "case.yaml").is_file())


def plan_case(name: str, record: bool = False) -> tuple[TaskGraph, list]:
    """The graph planned from a case's fixtures, judged by its goal spec where it has one.

    Raises:
        FixtureError: A request without a valid stored reply.
    """
    book = FixtureBook.load(CASES_DIR / name, record=record)
    case = book.case
    world = open_world(case.task, case.seed)
    scene = observe(world, task_regions(SIM_TASKS[case.task]))
    config = LlmConfig(base_url="http://fixture.invalid/v1", model="fixture", api_key="none", max_repairs=3)
    reasoner = LlmReasoner(config, client=FixtureClient(book))
    result = plan_task(case.instruction, scene, reasoner, task=case.task)
    # Judged as `plan` judges it: by the goal the composer stated, unless the instruction is the task's own.
    graph = planned_success(result.graph, case.task, reasoner.last_goal, scene)
    if case.goal is not None:
        graph = graph.model_copy(update={"success": Success(judge="goal", goal_spec=case.goal)})
    return graph, result.calls


def run_episodes(task: str, graph: TaskGraph, seeds: list[int], protocol: str | None) -> list[dict]:
    """One episode per seed of ``graph`` on ``task``; each summary with its seed."""
    from agentchord.episode import EpisodeSpec, run_episode
    from agentchord.harness import DisturbanceSetting

    setting = DisturbanceSetting.from_options(protocol=protocol)
    out = []
    for seed in seeds:
        spec = EpisodeSpec(task=task, seed=seed, graph=graph, disturbances=setting)
        start = time.perf_counter()
        result = run_episode(spec)
        kinds = [f"{e['kind']} {e['obj']}" for e in result.trace.events if e["event"] == "disturbance"]
        row = {"seed": seed, "success": result.success, "reason": result.reason, "disturbances": kinds,
               "recoveries": result.recoveries, "steps": result.steps, "wall_s": round(time.perf_counter() - start, 1)}
        print(json.dumps(row), flush=True)
        out.append(row)
    return out


def _seeds(text: str) -> list[int]:
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def sizes() -> None:
    """Each agent's prompt per case (tokens = characters / 4): the whole request, the system prompt's
    share (the agent's prompt file and skill notes: what a prompt change moves) and the skill notes'.
    The rest is the user message: the scene and, for the arranger and the conductor, the graph so far."""
    print("tokens: request (system prompt / skill notes)")
    print(f"{'case':24} {'composer':>20} {'arranger':>20} {'conductor':>20}")
    for name in cases():
        try:
            graph, calls = plan_case(name)
        except FixtureError as error:
            print(f"{name:24} (not planned: {error})")
            continue
        book = FixtureBook.load(CASES_DIR / name)
        scene = observe(open_world(book.case.task, book.case.seed), task_regions(SIM_TASKS[book.case.task]))
        requests = [ComposeRequest(instruction=book.case.instruction, scene=scene, task=book.case.task)]
        requests += [ArrangeRequest(graph=TaskGraph.model_validate(calls[0].reply), scene=scene)]
        requests += [ConductRequest(graph=TaskGraph.model_validate(calls[-1].request["graph"]), scene=scene)]
        cells = []
        for request in requests:
            size = prompt_size(request)
            cells.append(f"{size.tokens:>6} ({-(-size.system_chars // 4):>5} / {-(-size.notes_chars // 4):>3})")
        print(f"{name:24} {cells[0]:>20} {cells[1]:>20} {cells[2]:>20}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    plan = sub.add_parser("plan", help="plan a case from its fixtures; write the graph")
    plan.add_argument("case")
    plan.add_argument("--record", action="store_true", help="write each request that has no valid reply")
    episodes = sub.add_parser("episodes", help="run a case's planned graph")
    episodes.add_argument("case")
    episodes.add_argument("--seeds", default="0-2", help="first-last (inclusive)")
    episodes.add_argument("--protocol", choices=("real", "stress"), default=None)
    sub.add_parser("sizes", help="prompt sizes per case and agent")
    args = parser.parse_args(argv)
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    if args.command == "sizes":
        sizes()
        return 0
    graph_path = OUT_DIR / f"{args.case}.yaml"
    if args.command == "plan":
        try:
            graph, _ = plan_case(args.case, record=args.record)
        except FixtureError as error:
            print(f"pending: {error}", file=sys.stderr)
            return 3
        dump_graph(graph, graph_path)
        print(f"graph: {graph_path}")
        return 0
    task = FixtureBook.load(CASES_DIR / args.case).case.task
    rows = run_episodes(task, load_graph(graph_path), _seeds(args.seeds), args.protocol)
    won = sum(r["success"] for r in rows)
    label = args.protocol or "undisturbed"
    print(f"{args.case} {label} seeds {args.seeds}: {won}/{len(rows)}")
    (OUT_DIR / f"{args.case}.{label}.{args.seeds}.json").write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
