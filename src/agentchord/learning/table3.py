"""The paper's Table III on a CPU: does training on AgentChord recovery episodes make a policy recover?

Stages, each resuming what is on disk (``benchmarks/table3_policy.py`` is the command line):

- ``record``: nominal episodes (seeds from 0 on, undisturbed) and recovery episodes (seeds from 1000 on,
  the cup shifted on the protocol schedule, only episodes whose recovery merged back), no cameras.
  ``record.json`` says per episode its seed, frames, recovery frames and recovery edges, and which
  recovery episodes recover from the cup moved after the grasp (the training sets' recovery demos).
- ``train``: per set a :class:`~agentchord.learning.policy.ChunkMLPPolicy`: set A = ``demos`` nominal
  episodes; set ``B<p>`` = the same number with ``p`` % of them cup-recovery episodes (B50 is the
  paper's set B). The frames are read with lerobot's ``LeRobotDataset``; the policy is saved with
  ``save_pretrained`` (``policy_<set>/``) with ``train.json``; a checkpoint every 1000 steps resumes it.
- ``eval``: per set and condition (``shift``: the cup moved during execution; ``none``: undisturbed),
  ``trials`` held-out seeds (5000 on) in ``agentchord/SingleArmPourWater-v0``; success is the
  environment's ``info["is_success"]``; one JSON line per trial (resumes trial by trial).
- ``report``: ``table3.md``, ``table3.json`` and ``table3.svg`` (success with Wilson 95% intervals).
"""

from __future__ import annotations

import json
import resource
import time
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from agentchord.harness import DisturbanceSetting

TASK = "single_arm_pour_water"
ENV_ID = "agentchord/SingleArmPourWater-v0"
NOMINAL_SEED, RECOVERED_SEED, EVAL_SEED = 0, 1000, 5000
STATE, ENV_STATE, ACTION, RECOVERY = "observation.state", "observation.environment_state", "action", "agentchord.recovery"
CONDITIONS = ("shift", "none")


@dataclass
class TrainConfig:
    """One training configuration, the same for every set."""

    steps: int = 20000
    batch_size: int = 256
    lr: float = 1e-3
    weight_decay: float = 1e-4
    chunk_size: int = 20
    hidden: int = 512
    layers: int = 3
    temporal_ensemble_coeff: float = 0.05
    state_noise: float = 0.01
    noisy_copies: int = 2
    object_noise: float = 0.003
    seed: int = 0
    threads: int = 1
    device: str = "cpu"


def peak_rss_mb() -> float:
    """This process's peak resident memory so far (MiB; Linux reports KiB)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def log_stage(out: Path, name: str, wall_s: float, **extra) -> None:
    """Add a stage's wall time and the peak memory so far to ``stages.json``."""
    path = out / "stages.json"
    stages = json.loads(path.read_text()) if path.exists() else {}
    stages[name] = {"wall_s": round(wall_s, 1), "peak_rss_mb": round(peak_rss_mb(), 1), **extra}
    path.write_text(json.dumps(stages, indent=1))


def progress(iterable=None, **kwargs):
    """A tqdm progress bar (stderr)."""
    from tqdm import tqdm

    return tqdm(iterable, dynamic_ncols=True, mininterval=5.0, **kwargs)


# ----------------------------------------------------------------------------------------- record
def dataset_dirs(out: Path) -> dict[str, Path]:
    return {"nominal": out / "data/nominal", "recovered": out / "data/recovered"}


def episode_summary(root: Path) -> dict:
    """Per episode of a recorded dataset: seed, frames, recovery frames, recovery edges, whether its
    first recovery frame comes after the grasp edge ``e1`` ended, and the cup-recovery episodes."""
    import pandas as pd

    files = sorted((root / "data").glob("chunk-*/file-*.parquet"))
    frames = pd.concat([pd.read_parquet(f) for f in files]) if files else pd.DataFrame()
    meta = json.loads((root / "meta/agentchord.json").read_text())
    out = []
    groups = list(frames.groupby("episode_index")) if len(frames) else []
    for (index, group), entry in zip(groups, meta["episodes"], strict=True):
        rec = group[group[RECOVERY]]
        edges = sorted(set(rec["agentchord.edge"]) - {""})
        after_grasp = None
        if len(rec):
            first = int(rec["frame_index"].min())
            e1 = group.loc[group["agentchord.edge"] == "e1", "frame_index"]
            later = group[(group["agentchord.edge"] != "e1") & (group["agentchord.edge"] != "")
                          & (group["frame_index"] > (e1.min() if len(e1) else -1))]
            after_grasp = bool(len(later)) and first > int(later["frame_index"].min())
        out.append({"episode": int(index), "seed": entry["seed"], "frames": len(group), "recovery_frames": len(rec),
                    "recovery_edges": edges, "disturbances": entry["disturbances"],
                    "recovery_after_grasp": after_grasp})
    cup = [e["episode"] for e in out
           if e["recovery_after_grasp"] and any("cup_shifted" in edge for edge in e["recovery_edges"])]
    return {"episodes": out, "frames": len(frames), "cup_recovery_episodes": cup,
            "recovery_frames": int(frames[RECOVERY].sum()) if len(frames) else 0}


def stage_record(out: Path, n_nominal: int, n_cup: int, log=print) -> dict:
    """Record ``n_nominal`` nominal episodes and recovery episodes until ``n_cup`` recover from the
    cup moved after the grasp; write ``record.json``."""
    from agentchord.data.record import record

    dirs = dataset_dirs(out)
    path = out / "record.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    timings = dict(old.get("timings_s", {}))
    t0 = time.perf_counter()

    def run(name: str, episodes: int, **kwargs) -> None:
        root = dirs[name]
        meta = root / "meta/agentchord.json"
        have = len(json.loads(meta.read_text())["episodes"]) if meta.exists() else 0
        if have >= episodes:
            return
        t = time.perf_counter()
        bar = progress(total=episodes, initial=have, desc=f"record {name}", unit="ep")
        record(TASK, episodes, root, cameras=(), max_tries=20 * episodes, **kwargs,
               progress=lambda s, e, why: bar.update(1 if e else 0))
        bar.close()
        timings[name] = timings.get(name, 0.0) + time.perf_counter() - t

    run("nominal", n_nominal, seed=NOMINAL_SEED)
    recovered = {"seed": RECOVERED_SEED, "disturbances": DisturbanceSetting(kinds=("shift",), protocol="custom"), "only_recovered": True}
    summary = episode_summary(dirs["recovered"]) if (dirs["recovered"] / "meta/agentchord.json").exists() else None
    while summary is None or len(summary["cup_recovery_episodes"]) < n_cup:
        have = len(summary["episodes"]) if summary else 0
        cup = len(summary["cup_recovery_episodes"]) if summary else 0
        # About 3 in 4 recovered episodes recover from the cup moved after the grasp.
        run("recovered", have + max(1, int(np.ceil((n_cup - cup) * 1.4))), **recovered)
        summary = episode_summary(dirs["recovered"])
    data = {"nominal": episode_summary(dirs["nominal"]), "recovered": summary}
    rec = data["recovered"]
    log(f"[record] nominal: {len(data['nominal']['episodes'])} episodes, {data['nominal']['frames']} frames; "
        f"recovered: {len(rec['episodes'])} episodes, {rec['frames']} frames ({rec['recovery_frames']} in recovery "
        f"segments), {len(rec['cup_recovery_episodes'])} recover from the cup moved after the grasp")
    path.write_text(json.dumps({"timings_s": timings, "datasets": data}, indent=1))
    log_stage(out, "record", time.perf_counter() - t0)
    return data


# ------------------------------------------------------------------------------------------ train
def set_names(dose: tuple[int, ...]) -> list[str]:
    """``(0, 25, 50)`` -> ``["A", "B25", "B50"]`` (0 % recovery is set A)."""
    return ["A" if p == 0 else f"B{p}" for p in dose]


def set_composition(record_json: dict, which: str, demos: int) -> dict[str, list[int]]:
    """Which episodes of which dataset a set takes: ``{"nominal": [...], "recovered": [...]}``."""
    share = 0 if which == "A" else int(which[1:])
    n_rec = round(demos * share / 100)
    cup = record_json["datasets"]["recovered"]["cup_recovery_episodes"]
    nominal = record_json["datasets"]["nominal"]["episodes"]
    if len(cup) < n_rec:
        raise ValueError(f"set {which} needs {n_rec} cup-recovery episodes, the recording has {len(cup)}")
    if len(nominal) < demos - n_rec:
        raise ValueError(f"set {which} needs {demos - n_rec} nominal episodes, the recording has {len(nominal)}")
    return {"nominal": list(range(demos - n_rec)), "recovered": list(cup[:n_rec])}


def load_episodes(root: Path, episodes: list[int]) -> list[dict]:
    """Episodes of a dataset read through lerobot's ``LeRobotDataset``, as numpy arrays (with the
    recovery flag), in the order asked."""
    if not episodes:
        return []
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    ds = LeRobotDataset(f"local/{root.name}", root=root, episodes=sorted(episodes))
    table = ds.hf_dataset.with_format("arrow")[:]  # the episodes' rows (numpy format is minutes slower)

    def column(key: str) -> np.ndarray:
        col = table.column(key).combine_chunks()
        if str(col.type).startswith(("list", "fixed_size_list")):
            return col.flatten().to_numpy(zero_copy_only=False).reshape(len(col), -1)
        return col.to_numpy(zero_copy_only=False)

    cols = {k: column(k) for k in (STATE, ENV_STATE, ACTION, RECOVERY, "episode_index", "frame_index")}
    out = {}
    for index in np.unique(cols["episode_index"]):
        m = cols["episode_index"] == index
        order = np.argsort(cols["frame_index"][m])
        out[int(index)] = {"episode": int(index), STATE: cols[STATE][m][order].astype(np.float32),
                           ENV_STATE: cols[ENV_STATE][m][order].astype(np.float32),
                           ACTION: cols[ACTION][m][order].astype(np.float32),
                           RECOVERY: cols[RECOVERY][m][order].reshape(-1).astype(bool)}
    return [out[i] for i in episodes]


def training_set(out: Path, which: str, demos: int) -> tuple[list[dict], dict]:
    """A set's episodes and what it is made of (checked against ``record.json``: the frames and
    recovery frames of every episode must be what the record stage wrote).

    Raises:
        ValueError: The datasets on disk are not the ones ``record.json`` describes.
    """
    record_json = json.loads((out / "record.json").read_text())
    comp = set_composition(record_json, which, demos)
    dirs = dataset_dirs(out)
    episodes, info = [], {"set": which, "episodes": 0, "frames": 0, "recovery_frames": 0, "parts": {}}
    for name, wanted in comp.items():
        written = {e["episode"]: e for e in record_json["datasets"][name]["episodes"]}
        loaded = load_episodes(dirs[name], wanted)
        for ep in loaded:
            entry = written[ep["episode"]]
            if len(ep[ACTION]) != entry["frames"] or int(ep[RECOVERY].sum()) != entry["recovery_frames"]:
                raise ValueError(f"{name} episode {ep['episode']}: {len(ep[ACTION])} frames, {int(ep[RECOVERY].sum())} "
                                 f"in recovery, but the record stage wrote {entry['frames']} and "
                                 f"{entry['recovery_frames']}: record again")
        episodes += loaded
        info["parts"][name] = {"episodes": wanted, "seeds": [written[i]["seed"] for i in wanted],
                               "frames": int(sum(len(e[ACTION]) for e in loaded)),
                               "recovery_frames": int(sum(e[RECOVERY].sum() for e in loaded))}
    info["episodes"] = len(episodes)
    info["frames"] = sum(p["frames"] for p in info["parts"].values())
    info["recovery_frames"] = sum(p["recovery_frames"] for p in info["parts"].values())
    return episodes, info


def training_arrays(episodes: list[dict], chunk: int, noisy_copies: int = 0, state_noise: float = 0.0, seed: int = 0,
                    kinematics=None) -> dict[str, np.ndarray]:
    """Every frame with its inputs (tilt memory, tool poses) and its ``chunk`` next actions (past the
    episode's end, its last action repeated: the robot rests at home there); then ``noisy_copies``
    more copies of every frame with its arm joints perturbed by ``state_noise`` (rad) and the tool
    poses of the perturbed joints (the actions stay: the policy learns to steer back)."""
    from agentchord.learning.kinematics import ToolKinematics
    from agentchord.learning.policy import MAX_TILT, TOOL, running_max_tilt

    kin = kinematics or ToolKinematics()
    parts = {STATE: [], ENV_STATE: [], MAX_TILT: [], TOOL: [], ACTION: []}
    for e in episodes:
        n = len(e[ACTION])
        parts[STATE].append(e[STATE])
        parts[ENV_STATE].append(e[ENV_STATE])
        parts[MAX_TILT].append(running_max_tilt(e[ENV_STATE]))
        parts[TOOL].append(kin.tool_poses(e[STATE]).reshape(n, -1))
        idx = np.minimum(np.arange(n)[:, None] + np.arange(chunk)[None, :], n - 1)
        parts[ACTION].append(e[ACTION][idx])
    clean = {k: np.concatenate(v).astype(np.float32) for k, v in parts.items()}
    rng = np.random.default_rng(seed)
    arm = np.ones(clean[STATE].shape[1], bool)
    arm[[6, 13]] = False  # grippers stay as measured
    copies = [clean]
    for _ in range(noisy_copies):
        state = clean[STATE] + (state_noise * rng.standard_normal(clean[STATE].shape) * arm).astype(np.float32)
        copies.append({**clean, STATE: state, TOOL: kin.tool_poses(state).reshape(len(state), -1)})
    return {k: np.concatenate([c[k] for c in copies]) for k in clean}


def stage_train(out: Path, which: str, cfg: TrainConfig, demos: int, log=print) -> dict:
    """Train one set's policy (resumes from ``policy_<set>/checkpoint.pt``)."""
    import torch

    from agentchord.learning.policy import ChunkMLPPolicy, default_config

    target = out / f"policy_{which}"
    if (target / "train.json").exists():
        log(f"[train] {which}: {target} exists, kept")
        return json.loads((target / "train.json").read_text())
    t0 = time.perf_counter()
    torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    episodes, info = training_set(out, which, demos)
    arrays = training_arrays(episodes, cfg.chunk_size, cfg.noisy_copies, cfg.state_noise, cfg.seed)
    device = torch.device(cfg.device)
    data = {k: torch.from_numpy(v).to(device) for k, v in arrays.items()}
    config = default_config(chunk_size=cfg.chunk_size, hidden=cfg.hidden, layers=cfg.layers,
                            temporal_ensemble_coeff=cfg.temporal_ensemble_coeff, state_noise=cfg.state_noise,
                            object_noise=cfg.object_noise, optimizer_lr=cfg.lr,
                            optimizer_weight_decay=cfg.weight_decay, device=cfg.device)
    policy = ChunkMLPPolicy(config).to(device)
    from agentchord.learning.policy import MAX_TILT, TOOL

    clean = len(data[ACTION]) // (cfg.noisy_copies + 1)  # the statistics of the demonstrations themselves
    policy.fit_normalization(*(data[k][:clean] for k in (STATE, ENV_STATE, MAX_TILT, TOOL, ACTION)))
    optimizer = torch.optim.AdamW(policy.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, T_max=cfg.steps)
    generator = torch.Generator().manual_seed(cfg.seed)
    losses: list[float] = []
    start = 0
    checkpoint = target / "checkpoint.pt"
    if checkpoint.exists():
        state = torch.load(checkpoint, weights_only=False)
        policy.load_state_dict(state["model"])
        optimizer.load_state_dict(state["optimizer"])
        schedule.load_state_dict(state["schedule"])
        generator.set_state(state["generator"])
        torch.set_rng_state(state["torch_rng"])
        losses, start = state["losses"], state["step"]
        log(f"[train] {which}: resumed at step {start}")
    n = len(data[ACTION])
    log(f"[train] {which}: {info['episodes']} episodes ({info['parts']['nominal']['frames']} nominal frames, "
        f"{info['parts']['recovered']['frames']} from recovery episodes, {info['recovery_frames']} in recovery "
        f"segments), {sum(p.numel() for p in policy.parameters()) / 1e6:.2f} M parameters, {cfg.steps} steps")
    policy.train()
    target.mkdir(parents=True, exist_ok=True)
    bar = progress(range(start + 1, cfg.steps + 1), desc=f"train {which}", unit="step", initial=start, total=cfg.steps)
    for step in bar:
        idx = torch.randint(n, (cfg.batch_size,), generator=generator).to(device)
        loss, _ = policy.forward({k: v[idx] for k, v in data.items()})
        optimizer.zero_grad()
        loss.backward()
        optimizer.step()
        schedule.step()
        losses.append(float(loss.detach()))
        if step % 250 == 0:
            bar.set_postfix(loss=f"{np.mean(losses[-250:]):.4f}")
        if step % 1000 == 0 and step < cfg.steps:
            torch.save({"model": policy.state_dict(), "optimizer": optimizer.state_dict(),
                        "schedule": schedule.state_dict(), "generator": generator.get_state(),
                        "torch_rng": torch.get_rng_state(), "losses": losses, "step": step}, checkpoint)
    bar.close()
    policy.eval()
    policy.save_pretrained(target)
    train_s = time.perf_counter() - t0
    summary = {**info, "parameters": sum(p.numel() for p in policy.parameters()), "steps": cfg.steps,
               "train_s": train_s, "final_loss": float(np.mean(losses[-250:])),
               "loss_every_250": [float(np.mean(losses[i:i + 250])) for i in range(0, len(losses), 250)],
               "config": asdict(cfg)}
    (target / "train.json").write_text(json.dumps(summary, indent=1))
    checkpoint.unlink(missing_ok=True)
    log(f"[train] {which}: final loss {summary['final_loss']:.4f}, {train_s / 60:.1f} min")
    log_stage(out, f"train_{which}", train_s)
    return summary


# ------------------------------------------------------------------------------------------- eval
def run_trial(env, policy, seed: int) -> dict:
    """One trial: the policy acts every tick until the environment ends it. ``success`` is the
    environment's ``info["is_success"]``; the rest says what happened (grasps, pour, the cup's moves)."""
    import torch

    obs, info = env.reset(seed=seed)
    policy.reset()
    world = env.unwrapped.world
    device = next(policy.parameters()).device
    low, high = env.action_space.low, env.action_space.high
    terminated = truncated = False
    holding, grasps, first_grasp = False, 0, None
    t0 = time.perf_counter()
    while not (terminated or truncated):
        batch = {STATE: torch.from_numpy(obs["agent_pos"])[None].to(device),
                 ENV_STATE: torch.from_numpy(obs["environment_state"])[None].to(device)}
        action = policy.select_action(batch)[0].cpu().numpy()
        obs, _, terminated, truncated, info = env.step(np.clip(action, low, high))
        now = bool(world.holding("right", "bottle"))
        if now and not holding:
            grasps += 1
            first_grasp = first_grasp if first_grasp is not None else int(info["tick"])
        holding = now
    tracker = env.unwrapped.tracker
    cup_moves = [d for d in info["disturbances"] if d["obj"] == "cup"]
    return {"seed": seed, "success": bool(info["is_success"]), "ticks": int(info["tick"]),
            "disturbances": info["disturbances"], "cup_moved": bool(cup_moves),
            "cup_moved_after_grasp": bool(cup_moves) and first_grasp is not None and cup_moves[0]["tick"] > first_grasp,
            "grasps": grasps, "first_grasp_tick": first_grasp, "poured": bool(tracker.poured),
            "poured_tick": tracker.poured_tick, "wall_s": time.perf_counter() - t0}


def eval_path(out: Path, which: str, condition: str) -> Path:
    return out / f"eval_{which}_{condition}.jsonl"


def stage_eval(out: Path, which: str, condition: str, trials: int, threads: int = 1, device: str = "cpu",
               log=print) -> list[dict]:
    """Evaluate one set's policy over ``trials`` held-out seeds (resumes trial by trial)."""
    import gymnasium
    import torch

    import agentchord.gym  # noqa: F401  (registers the environments)
    from agentchord.learning.policy import ChunkMLPPolicy

    torch.set_num_threads(threads)
    path = eval_path(out, which, condition)
    done = [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []
    seen = {r["seed"] for r in done}
    todo = [s for s in range(EVAL_SEED, EVAL_SEED + trials) if s not in seen]
    if todo:
        t0 = time.perf_counter()
        policy = ChunkMLPPolicy.from_pretrained(out / f"policy_{which}")
        policy.config.device = device
        policy.to(device)
        env = gymnasium.make(ENV_ID, disturb=None if condition == "none" else condition)
        bar = progress(todo, desc=f"eval {which} {condition}", unit="trial")
        with path.open("a") as f:
            for seed in bar:
                r = run_trial(env, policy, seed)
                done.append(r)
                f.write(json.dumps(r) + "\n")
                f.flush()
                bar.set_postfix(success=f"{sum(x['success'] for x in done)}/{len(done)}")
        bar.close()
        env.close()
        log_stage(out, f"eval_{which}_{condition}", time.perf_counter() - t0, trials=len(todo))
    done = sorted((r for r in done if EVAL_SEED <= r["seed"] < EVAL_SEED + trials), key=lambda r: r["seed"])
    log(f"[eval] {which} {condition}: {sum(r['success'] for r in done)}/{len(done)}")
    return done


# ----------------------------------------------------------------------------------------- report
def summarize(results: list[dict]) -> dict:
    """Successes, Wilson 95% interval and what the trials did."""
    from agentchord.bench.report import wilson_interval

    n, k = len(results), sum(r["success"] for r in results)
    lo, hi = wilson_interval(k, n)
    moved = [r for r in results if r["cup_moved_after_grasp"]]
    return {"successes": k, "trials": n, "rate": k / n if n else None, "wilson95": [lo, hi],
            "cup_moved": sum(r["cup_moved"] for r in results), "cup_moved_after_grasp": len(moved),
            "success_when_cup_moved_after_grasp": sum(r["success"] for r in moved),
            "poured_when_cup_moved_after_grasp": sum(bool(r["poured"] and r["poured_tick"] is not None
                                                          and r["poured_tick"] > first_cup_tick(r)) for r in moved),
            "regrasped": sum(r["grasps"] > 1 for r in results), "never_grasped": sum(r["grasps"] == 0 for r in results),
            "poured": sum(r["poured"] for r in results), "eval_s": sum(r["wall_s"] for r in results)}


def first_cup_tick(trial: dict) -> int:
    return min((d["tick"] for d in trial["disturbances"] if d["obj"] == "cup"), default=-1)


def svg_figure(rows: list[tuple[str, str, dict]]) -> str:
    """A bar chart: success per set and condition with Wilson 95% intervals (plain SVG, no plotting library)."""
    width, height, left, bottom, top = 120 + 90 * len(rows), 300, 60, 60, 20
    plot_h = height - bottom - top
    colours = {"shift": "#d95f02", "none": "#1b9e77"}
    out = [(f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" '
            'font-size="11">'), f'<rect width="{width}" height="{height}" fill="white"/>']
    for pct in (0, 25, 50, 75, 100):
        y = top + plot_h * (1 - pct / 100)
        out.append(f'<line x1="{left}" x2="{width - 10}" y1="{y:.1f}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{pct}%</text>')
    for i, (which, condition, s) in enumerate(rows):
        x = left + 20 + 90 * i
        y = top + plot_h * (1 - (s["rate"] or 0))
        out.append(f'<rect x="{x}" y="{y:.1f}" width="50" height="{top + plot_h - y:.1f}" fill="{colours[condition]}"/>')
        lo, hi = (top + plot_h * (1 - v) for v in s["wilson95"])
        cx = x + 25
        out.append(f'<path d="M{cx},{lo:.1f}V{hi:.1f}M{cx - 6},{lo:.1f}h12M{cx - 6},{hi:.1f}h12" stroke="black"/>')
        out.append(f'<text x="{cx}" y="{hi - 4:.1f}" text-anchor="middle">{s["successes"]}/{s["trials"]}</text>')
        label = "cup moved" if condition == "shift" else "undisturbed"
        out.append(f'<text x="{cx}" y="{height - bottom + 16}" text-anchor="middle">{which}</text>')
        out.append(f'<text x="{cx}" y="{height - bottom + 30}" text-anchor="middle">{label}</text>')
    out.append(f'<text x="{left}" y="{height - 8}">success, Wilson 95% interval '
               '(single-arm pour water, held-out seeds)</text>')
    out.append("</svg>")
    return "\n".join(out) + "\n"


def stage_report(out: Path, sets: list[str], trials: int, demos: int, log=print) -> str:
    """``table3.md``, ``table3.json`` and ``table3.svg`` from what the other stages wrote."""
    rows, data, figure = [], {"demos": demos, "trials": trials, "sets": {}}, []
    for which in sets:
        train_path = out / f"policy_{which}/train.json"
        if not train_path.exists():
            continue
        train = json.loads(train_path.read_text())
        entry = {"train": {k: train[k] for k in ("episodes", "frames", "recovery_frames", "parts", "steps", "train_s",
                                                  "final_loss", "parameters")}}
        for condition in CONDITIONS:
            path = eval_path(out, which, condition)
            if not path.exists():
                continue
            results = [json.loads(line) for line in path.read_text().splitlines()]
            results = [r for r in results if EVAL_SEED <= r["seed"] < EVAL_SEED + trials]
            s = summarize(results)
            entry[condition] = s
            figure.append((which, condition, s))
            lo, hi = s["wilson95"]
            parts = train["parts"]
            demo_text = f"{len(parts['nominal']['episodes'])} nominal + {len(parts['recovered']['episodes'])} recovery"
            moved = (f"{s['success_when_cup_moved_after_grasp']}/{s['cup_moved_after_grasp']}"
                     if condition == "shift" else "-")
            rows.append(f"| {which} | {demo_text} | {'cup moved' if condition == 'shift' else 'undisturbed'} | "
                        f"{s['successes']}/{s['trials']} ({100 * s['rate']:.0f}%) | [{100 * lo:.1f}%, {100 * hi:.1f}%] | "
                        f"{moved} | {s['regrasped']} | {train['train_s'] / 60:.1f} min | {s['eval_s'] / 60:.1f} min |")
        data["sets"][which] = entry
    table = ("| set | demos | evaluation | success | Wilson 95% CI | success when the cup moved after the grasp | "
             "trials where the grasp contact broke and re-formed | train time | eval time |\n"
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n" + "\n".join(rows))
    log(table)
    (out / "table3.md").write_text(table + "\n")
    (out / "table3.svg").write_text(svg_figure(figure))
    for name in ("record.json", "stages.json"):
        if (out / name).exists():
            data[name.removesuffix(".json")] = json.loads((out / name).read_text())
    if "record" in data:  # the per-episode lists are in record.json
        data["record"] = {k: {"episodes": len(v["episodes"]), "frames": v["frames"],
                              "recovery_frames": v["recovery_frames"],
                              "cup_recovery_episodes": len(v["cup_recovery_episodes"])}
                          for k, v in data["record"]["datasets"].items()}
    (out / "table3.json").write_text(json.dumps(data, indent=1))
    return table
