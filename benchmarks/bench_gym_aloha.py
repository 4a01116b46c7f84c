"""AgentChord in LeRobot's gym-aloha: success by its own reward, and what one control tick costs.

    .venv/bin/python benchmarks/bench_gym_aloha.py                 # both tables, seeds 0-49
    .venv/bin/python benchmarks/bench_gym_aloha.py --seeds 0-9 --protocols none
    .venv/bin/python benchmarks/bench_gym_aloha.py --timing-only

Success: the library graph of each task (``gym_aloha_transfer_cube``, ``gym_aloha_insertion``) run
per seed of gym-aloha's own sampler, judged by its reward reaching 4 (400 steps undisturbed, 800
where a disturbance acted), with the share within LeRobot's 400 steps beside it. Timing: one
episode's actions sent through our World (its physics stepped as its ``env.step`` steps it, no
rendering) and through its own ``env.step`` (which renders three cameras every step), in one run.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

os.environ.setdefault("MUJOCO_GL", "egl")

from agentchord.episode import EpisodeSpec, run_episode
from agentchord.harness import DisturbanceSetting
from agentchord.library import load_task_graph
from agentchord.sim.gym_aloha import INSERTION, LEROBOT_EVAL_STEPS, TRANSFER_CUBE, GymAlohaWorld

TASKS = {"gym_aloha_transfer_cube": TRANSFER_CUBE, "gym_aloha_insertion": INSERTION}
#: Published rates to set beside ours (undisturbed; ACT arXiv 2304.13705 Table I, LeRobot's model card).
PUBLISHED = {
    "gym_aloha_transfer_cube": "ACT 86 % (scripted data) / 50 % (human); LeRobot act_aloha_sim_transfer_cube_human 87.6 %",
    "gym_aloha_insertion": "ACT 32 % (scripted data) / 20 % (human)",
}


def sweep(task: str, seeds: range, protocol: str | None) -> dict:
    """Every seed's episode: success, steps, and why each failure failed."""
    graph = load_task_graph(task)
    rows = []
    for seed in seeds:
        result = run_episode(EpisodeSpec(task=task, seed=seed, graph=graph, disturbances=DisturbanceSetting.from_options(protocol=protocol)))
        rows.append((seed, result.success, result.steps, result.reason))
    won = [r for r in rows if r[1]]
    return {
        "n": len(rows), "success": len(won), "within_400": sum(r[2] <= LEROBOT_EVAL_STEPS for r in won),
        "median_steps": statistics.median(r[2] for r in won) if won else None,
        "failures": [(seed, reason) for seed, ok, _, reason in rows if not ok],
    }


def timing(task: str, seed: int = 0) -> tuple[float, float]:
    """Mean wall time (ms) per control tick of our World and of its ``env.step``, on one episode's actions."""
    import gymnasium
    import gym_aloha  # noqa: F401  (registers its environments)

    worlds: list[GymAlohaWorld] = []
    run_episode(EpisodeSpec(task=task, seed=seed, graph=load_task_graph(task)),
                on_tick=lambda ex: worlds.append(ex.world) if not worlds else None)
    actions = worlds[0].actions
    world = GymAlohaWorld(TASKS[task], seed)
    start = time.perf_counter()
    for action in actions:
        world.action = action
        world._apply_commands = lambda: None  # the recorded action as it is
        world.step()
    ours = (time.perf_counter() - start) / len(actions)
    env = gymnasium.make(TASKS[task].gym_id, max_episode_steps=10_000)
    env.reset(seed=seed)
    start = time.perf_counter()
    for action in actions:
        env.step(action)
    theirs = (time.perf_counter() - start) / len(actions)
    env.close()
    return 1000 * ours, 1000 * theirs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--seeds", default="0-49", help="first-last of gym-aloha's seeds")
    parser.add_argument("--protocols", default="none,real", help="comma-separated: none, real, stress")
    parser.add_argument("--timing-only", action="store_true")
    args = parser.parse_args()
    first, _, last = args.seeds.partition("-")
    seeds = range(int(first), int(last or first) + 1)
    if not args.timing_only:
        print("| task | protocol | success (its reward 4) | within 400 steps | median steps | published (undisturbed) |")
        print("|---|---|---|---|---|---|")
        failures = []
        for task in TASKS:
            for protocol in args.protocols.split(","):
                row = sweep(task, seeds, None if protocol == "none" else protocol)
                n = row["n"]
                print(f"| {task} | {protocol} | {row['success']}/{n} ({100 * row['success'] / n:.0f} %) | "
                      f"{row['within_400']}/{n} ({100 * row['within_400'] / n:.0f} %) | {row['median_steps']} | "
                      f"{PUBLISHED[task] if protocol == 'none' else ''} |", flush=True)
                failures += [(task, protocol, *f) for f in row["failures"]]
        for task, protocol, seed, reason in failures:
            print(f"  {task} {protocol} seed {seed}: {reason}")
    print()
    print("| task | our World, ms/tick (no rendering) | its env.step, ms/tick (three cameras) | ratio |")
    print("|---|---|---|---|")
    for task in TASKS:
        ours, theirs = timing(task)
        print(f"| {task} | {ours:.2f} | {theirs:.1f} | {theirs / ours:.0f}x |", flush=True)


if __name__ == "__main__":
    main()
