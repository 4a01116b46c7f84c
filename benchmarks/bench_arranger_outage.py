"""The arranger failing mid-episode: is any disturbance left undetected, and does every episode recover or say why?

    .venv/bin/python benchmarks/bench_arranger_outage.py                  # six tasks, real protocol, seeds 0-4
    .venv/bin/python benchmarks/bench_arranger_outage.py --seeds 0-9 --protocol stress --fail-at 1.0

Each episode starts on the composer's graph (the library graph's nominal part) with the rest of a
pipelined plan in the background, which fails ``--fail-at`` seconds after the first motion with an
outage (the endpoint answered HTTP 500 to every retry). Two ways on:

- ``derived``: no fallback: each edge keeps the monitors derived from its own constraints; a failure
  that needs a branch ends the episode with the plan's error as its reason.
- ``fallback``: the offline arranger and conductor write the branches instead (``run --reasoner llm``'s
  default), arriving when the LLM's plan failed.
- ``arrives`` (for comparison): the plan does not fail; the library graph's modes and branches arrive then.

A drop or pull counts as undetected when no failure was detected after it: in a successful episode
the skill absorbed it (a corner pulled as the grasp closed: the grasp tracks it), in a failed one it
was missed.

Per task: disturbances injected and detected by kind, successes, and each failure's reason.
"""

from __future__ import annotations

import argparse
from collections import Counter

from agentchord.agents.observe import observe, task_regions
from agentchord.agents.pipeline import augment_task
from agentchord.agents.prompts import nominal_part
from agentchord.agents.rules import RulesReasoner
from agentchord.episode import EpisodeSpec, run_episode
from agentchord.execution.background import ScriptedPlan
from agentchord.execution.reasoning import ReasoningConfig
from agentchord.harness import DisturbanceSetting
from agentchord.library import load_task_graph
from agentchord.sim.tasks import SIM_TASKS
from agentchord.sim.trial import open_world

TASKS = ("single_arm_pour_water", "dual_arm_pour_water", "rearrange_table", "handover_block", "setup_coffee_tray", "fold_towel")
OUTAGE = "ReasonerTransportError: the arranger's endpoint answered HTTP 500 after 3 tries"


def seeds(text: str) -> list[int]:
    """``0-4`` or ``0,3,7``."""
    if "-" in text:
        a, b = text.split("-")
        return list(range(int(a), int(b) + 1))
    return [int(s) for s in text.split(",")]


def episode(task: str, seed: int, mode: str, protocol: str, fail_at: float):
    """One episode with the plan failing at ``fail_at`` s."""
    composed = nominal_part(load_task_graph(task))
    if mode == "arrives":
        plan = ScriptedPlan(fail_at, load_task_graph(task))
    elif mode == "fallback":
        scene = observe(open_world(task, seed), task_regions(SIM_TASKS[task]))
        offline = augment_task(composed, scene, RulesReasoner()).graph
        plan = ScriptedPlan(fail_at, offline, error=OUTAGE, outage=True, fallback="rules")
    else:
        plan = ScriptedPlan(fail_at, None, error=OUTAGE, outage=True)
    setting = DisturbanceSetting.from_options(protocol=protocol)
    return run_episode(EpisodeSpec(task, seed=seed, graph=composed, reasoning=ReasoningConfig(), disturbances=setting,
                                   background=plan))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-4")
    parser.add_argument("--protocol", default="real")
    parser.add_argument("--fail-at", type=float, default=2.0, help="seconds after the first motion the plan fails")
    parser.add_argument("--modes", default="arrives,derived,fallback")
    parser.add_argument("--tasks", default=",".join(TASKS))
    args = parser.parse_args()
    print(f"arranger outage at {args.fail_at:g} s, protocol {args.protocol}, seeds {args.seeds}\n")
    print("| way on | task | episodes | success | injected (kind: n) | drops and pulls undetected: missed (in a failed episode) "
          "| absorbed (in a successful one) | other kinds undetected | failures, each with its reason |")
    print("|---|---|---:|---:|---|---:|---:|---:|---|")
    for mode in args.modes.split(","):
        for task in args.tasks.split(","):
            injected, missed, ok, n = Counter(), Counter(), 0, 0
            reasons = []
            for seed in seeds(args.seeds):
                result = episode(task, seed, mode, args.protocol, args.fail_at)
                n += 1
                ok += result.success
                for kind, (inj, det, _rec) in result.disturbances.items():
                    injected[kind] += inj
                    hold = "missed" if not result.success else "absorbed"
                    missed[hold if kind in ("drop", "pull") else "other"] += max(0, inj - det)
                if not result.success:
                    reasons.append(f"seed {seed}: {result.reason}")
            kinds = ", ".join(f"{k}: {v}" for k, v in sorted(injected.items()))
            print(f"| {mode} | {task} | {n} | {ok}/{n} | {kinds} | {missed['missed']} | {missed['absorbed']} | {missed['other']} "
                  f"| {'; '.join(reasons) or '-'} |", flush=True)


if __name__ == "__main__":
    main()
