"""The paper's Table III on CPU: a policy trained on nominal demonstrations against one trained with
AgentChord recovery demonstrations, both evaluated with the cup moved during execution.

Training sets (single-arm pour water, low-dim: no cameras):

- A: 40 successful nominal episodes (seeds 0..39, undisturbed).
- B: the first 20 of them plus 20 AgentChord episodes in which the cup was moved after the grasp and
  the recovery from it merged back: 40 episodes are recorded with ``--protocol --disturb shift
  --only-recovered`` (seeds from 1000 on) and the first 20 whose recovery segments include a
  cup-shifted recovery edge (``e2_r_cup_shifted``, ``e3_r_cup_shifted``: after the grasp edge e1) are
  kept (a shift can also move the bottle after it is put down; those episodes are left out).

Both train the same lerobot ACT policy (inputs ``observation.state`` + ``observation.environment_state``,
no images) for the same number of steps, and each is evaluated over 50 trials (seeds 5000..5049,
disjoint from the training seeds) in ``agentchord/SingleArmPourWater-v0`` with ``disturb="shift"``.

Needs the learning stack (``make install-test``: torch and lerobot 0.4.x in ``.venv``; docs/data.md,
"The Table III experiment"); stage by stage, each stage skipping what is already on disk:

    python benchmarks/table3_policy.py record --out OUT
    python benchmarks/table3_policy.py train --set A --out OUT      (and --set B)
    python benchmarks/table3_policy.py eval --set A --out OUT       (and --set B)
    python benchmarks/table3_policy.py report --out OUT
    python benchmarks/table3_policy.py all --out OUT                (all of the above)
    python benchmarks/table3_policy.py probe --out OUT              (time one train step, one episode)
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import asdict, dataclass
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("HF_DATASETS_OFFLINE", "1")

import numpy as np  # noqa: E402

TASK = "single_arm_pour_water"
ENV_ID = "agentchord/SingleArmPourWater-v0"
NOMINAL_SEED, RECOVERED_SEED, EVAL_SEED = 0, 1000, 5000
STATE, ENV_STATE, ACTION = "observation.state", "observation.environment_state", "action"


@dataclass
class Config:
    """One training configuration, the same for both policies."""

    steps: int = 10000
    batch_size: int = 32
    lr: float = 1e-4
    lr_schedule: str = "constant"  # or "cosine" (to 0 over the steps)
    weight_decay: float = 1e-4
    grad_clip: float = 10.0
    chunk_size: int = 50
    n_action_steps: int = 10
    dim_model: int = 128
    n_heads: int = 4
    dim_feedforward: int = 512
    n_encoder_layers: int = 2
    n_decoder_layers: int = 1
    n_vae_encoder_layers: int = 2
    use_vae: bool = False
    latent_dim: int = 32
    kl_weight: float = 10.0
    dropout: float = 0.1
    std_floor: float = 1e-2
    seed: int = 0
    threads: int = 1


# ----------------------------------------------------------------------------------------- record
def dataset_dirs(out: Path) -> dict[str, Path]:
    return {"nominal": out / "data/pour_nominal40", "recovered": out / "data/pour_recovered"}


def recovery_summary(root: Path) -> dict:
    """Per episode of a recorded dataset: recovery frames, the recovery edges, and whether the first
    recovery frame comes after the grasp (the bottle's grasp edge e1 ended before it)."""
    import pandas as pd

    frames = pd.read_parquet(root / "data/chunk-000/file-000.parquet")
    meta = json.loads((root / "meta/agentchord.json").read_text())
    out = []
    for (index, group), entry in zip(frames.groupby("episode_index"), meta["episodes"], strict=True):
        rec = group[group["agentchord.recovery"]]
        edges = sorted(set(rec["agentchord.edge"]) - {""})
        after_grasp = None
        if len(rec):
            first = int(rec["frame_index"].min())
            past_e1 = group[(group["agentchord.edge"] != "e1") & (group["agentchord.edge"] != "")
                            & (group["frame_index"] > group.loc[group["agentchord.edge"] == "e1", "frame_index"].min())]
            after_grasp = bool(len(past_e1)) and first > int(past_e1["frame_index"].min())
        out.append({"episode": int(index), "seed": entry["seed"], "frames": len(group), "recovery_frames": len(rec),
                    "recovery_edges": edges, "disturbances": entry["disturbances"], "recovery_after_grasp": after_grasp})
    return {"episodes": out, "frames": int(len(frames)), "cup_recovery_episodes": cup_recovery_episodes(out),
            "recovery_frames": int(frames["agentchord.recovery"].sum())}


def cup_recovery_episodes(episodes: list[dict]) -> list[int]:
    """Episodes whose recovery segments include a recovery from the cup shifted, after the grasp."""
    return [e["episode"] for e in episodes
            if e["recovery_after_grasp"] and any("cup_shifted" in edge for edge in e["recovery_edges"])]


def stage_record(out: Path, n_nominal: int, n_recovered: int) -> dict:
    from agentchord.data.record import record

    dirs = dataset_dirs(out)
    timings, skipped = {}, {}
    for name, kwargs in (("nominal", {"episodes": n_nominal, "seed": NOMINAL_SEED}),
                         ("recovered", {"episodes": n_recovered, "seed": RECOVERED_SEED, "protocol": True,
                                        "disturb": ("shift",), "only_recovered": True})):
        root = dirs[name]
        meta = root / "meta/agentchord.json"
        if meta.exists() and json.loads(meta.read_text()).get("complete", True):
            print(f"[record] {name}: {root} exists, kept")
            continue
        # An interrupted recording is resumed by the same call (record keeps each finished episode).
        t0 = time.perf_counter()
        report = record(TASK, kwargs.pop("episodes"), root, cameras=(), **kwargs,
                        progress=lambda s, e, why, n=name: print(f"[record] {n} seed {s}: {'written' if e else why}",
                                                                 flush=True))
        timings[name] = time.perf_counter() - t0
        skipped[name] = [[seed, why] for seed, why in report.skipped]
        print(f"[record] {name}: {len(report.written)} episodes, {len(report.skipped)} seeds skipped, "
              f"{timings[name]:.0f} s")
    summary = {name: recovery_summary(root) for name, root in dirs.items()}
    rec = summary["recovered"]
    print(f"[record] recovered set: {len(rec['cup_recovery_episodes'])} episodes with a cup-shifted recovery "
          f"after the grasp; {rec['recovery_frames']} recovery frames of {rec['frames']}; "
          f"recovery after the grasp in {sum(bool(e['recovery_after_grasp']) for e in rec['episodes'])}"
          f"/{len(rec['episodes'])} episodes; edges: "
          f"{sorted({x for e in rec['episodes'] for x in e['recovery_edges']})}")
    path = out / "record.json"
    old = json.loads(path.read_text()) if path.exists() else {}
    path.write_text(json.dumps({"timings_s": {**old.get("timings_s", {}), **timings},
                                "skipped_seeds": {**old.get("skipped_seeds", {}), **skipped}, "datasets": summary},
                               indent=1))
    return summary


# ------------------------------------------------------------------------------------------ train
def load_episodes(root: Path, episodes: list[int] | None = None) -> list[dict]:
    """The episodes of a dataset, loaded through lerobot's ``LeRobotDataset``, as numpy arrays."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    ds = LeRobotDataset(f"local/{root.name}", root=root, episodes=episodes)
    table = ds.hf_dataset.with_format("numpy")
    state, env, action, ep = (np.asarray(table[k]) for k in (STATE, ENV_STATE, ACTION, "episode_index"))
    out = []
    for index in np.unique(ep):
        m = ep == index
        out.append({STATE: state[m].astype(np.float32), ENV_STATE: env[m].astype(np.float32),
                    ACTION: action[m].astype(np.float32)})
    return out


def training_set(out: Path, which: str, n_total: int) -> list[dict]:
    dirs = dataset_dirs(out)
    if which == "A":
        return load_episodes(dirs["nominal"], list(range(n_total)))
    half = n_total // 2
    cup = json.loads((out / "record.json").read_text())["datasets"]["recovered"]["cup_recovery_episodes"]
    if len(cup) < half:
        raise SystemExit(f"only {len(cup)} recorded episodes recover from the cup shifted; record more")
    return load_episodes(dirs["nominal"], list(range(half))) + load_episodes(dirs["recovered"], cup[:half])


def make_policy(cfg: Config, dims: dict[str, int]):
    from lerobot.configs.types import FeatureType, PolicyFeature
    from lerobot.policies.act.configuration_act import ACTConfig
    from lerobot.policies.act.modeling_act import ACTPolicy

    config = ACTConfig(
        input_features={STATE: PolicyFeature(FeatureType.STATE, (dims[STATE],)),
                        ENV_STATE: PolicyFeature(FeatureType.ENV, (dims[ENV_STATE],))},
        output_features={ACTION: PolicyFeature(FeatureType.ACTION, (dims[ACTION],))},
        chunk_size=cfg.chunk_size, n_action_steps=cfg.n_action_steps, dim_model=cfg.dim_model, n_heads=cfg.n_heads,
        dim_feedforward=cfg.dim_feedforward, n_encoder_layers=cfg.n_encoder_layers,
        n_decoder_layers=cfg.n_decoder_layers, n_vae_encoder_layers=cfg.n_vae_encoder_layers,
        use_vae=cfg.use_vae, latent_dim=cfg.latent_dim, kl_weight=cfg.kl_weight, dropout=cfg.dropout, optimizer_lr=cfg.lr,
        optimizer_weight_decay=cfg.weight_decay, pretrained_backbone_weights=None, device="cpu", push_to_hub=False,
    )
    return ACTPolicy(config)


def stats_of(episodes: list[dict], floor: float) -> dict:
    stats = {}
    for key in (STATE, ENV_STATE, ACTION):
        x = np.concatenate([e[key] for e in episodes])
        stats[key] = {"mean": x.mean(0), "std": np.maximum(x.std(0), floor), "min": x.min(0), "max": x.max(0)}
    return stats


class ChunkSampler:
    """Random frames with their action chunks (padded past the episode's end, as lerobot pads them)."""

    def __init__(self, episodes: list[dict], chunk: int, rng: np.random.Generator) -> None:
        self.episodes = episodes
        self.chunk = chunk
        self.rng = rng
        self.index = np.array([(i, t) for i, e in enumerate(episodes) for t in range(len(e[ACTION]))])

    def batch(self, size: int) -> dict:
        import torch

        rows = self.index[self.rng.integers(len(self.index), size=size)]
        state, env, action, pad = [], [], [], []
        for i, t in rows:
            e = self.episodes[i]
            n = len(e[ACTION])
            idx = np.arange(t, t + self.chunk)
            pad.append(idx >= n)
            idx = np.minimum(idx, n - 1)
            state.append(e[STATE][t])
            env.append(e[ENV_STATE][t])
            action.append(e[ACTION][idx])
        return {STATE: torch.from_numpy(np.stack(state)), ENV_STATE: torch.from_numpy(np.stack(env)),
                ACTION: torch.from_numpy(np.stack(action)), "action_is_pad": torch.from_numpy(np.stack(pad))}


def stage_train(out: Path, which: str, cfg: Config, n_total: int, steps: int | None = None) -> dict:
    import torch
    from lerobot.policies.factory import make_pre_post_processors

    target = out / f"policy_{which}"
    if (target / "train.json").exists() and steps is None:
        print(f"[train] {which}: {target} exists, kept")
        return json.loads((target / "train.json").read_text())
    torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    episodes = training_set(out, which, n_total)
    dims = {k: episodes[0][k].shape[1] for k in (STATE, ENV_STATE, ACTION)}
    policy = make_policy(cfg, dims)
    stats = stats_of(episodes, cfg.std_floor)
    pre, post = make_pre_post_processors(policy.config, dataset_stats=stats)
    sampler = ChunkSampler(episodes, cfg.chunk_size, np.random.default_rng(cfg.seed))
    optimizer = torch.optim.AdamW(policy.parameters(), lr=cfg.lr, weight_decay=cfg.weight_decay)
    n_steps = steps if steps is not None else cfg.steps
    schedule = None
    if cfg.lr_schedule == "cosine":
        schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, T_max=n_steps)
    elif cfg.lr_schedule != "constant":
        raise SystemExit(f"unknown --lr-schedule {cfg.lr_schedule!r} (constant, cosine)")
    params = sum(p.numel() for p in policy.parameters())
    frames = len(sampler.index)
    print(f"[train] {which}: {len(episodes)} episodes, {frames} frames, {params / 1e6:.2f} M parameters, "
          f"{n_steps} steps", flush=True)
    policy.train()
    losses = []
    t0 = time.perf_counter()
    for step in range(1, n_steps + 1):
        batch = pre(sampler.batch(cfg.batch_size))
        loss, parts = policy.forward(batch)
        optimizer.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(policy.parameters(), cfg.grad_clip)
        optimizer.step()
        if schedule is not None:
            schedule.step()
        losses.append(float(loss.detach()))
        if step % 250 == 0 or step == n_steps:
            recent = np.mean(losses[-250:])
            print(f"[train] {which} step {step}: loss {recent:.4f} (l1 {parts['l1_loss']:.4f}) "
                  f"{time.perf_counter() - t0:.0f} s", flush=True)
    train_s = time.perf_counter() - t0
    summary = {"set": which, "episodes": len(episodes), "frames": frames, "parameters": params, "steps": n_steps,
               "train_s": train_s, "s_per_step": train_s / n_steps, "final_loss": float(np.mean(losses[-250:])),
               "loss_every_250": [float(np.mean(losses[i:i + 250])) for i in range(0, len(losses), 250)],
               "config": asdict(cfg)}
    if steps is None:
        target.mkdir(parents=True, exist_ok=True)
        policy.save_pretrained(target)
        pre.save_pretrained(target)
        post.save_pretrained(target)
        (target / "train.json").write_text(json.dumps(summary, indent=1))
    return summary


# ------------------------------------------------------------------------------------------- eval
def load_policy(target: Path):
    from lerobot.policies.act.modeling_act import ACTPolicy
    from lerobot.policies.factory import make_pre_post_processors

    policy = ACTPolicy.from_pretrained(target)
    policy.eval()
    pre, post = make_pre_post_processors(policy.config, pretrained_path=str(target))
    return policy, pre, post


def run_trial(env, policy, pre, post, seed: int) -> dict:
    import torch

    obs, info = env.reset(seed=seed)
    policy.reset()
    low, high = env.action_space.low, env.action_space.high
    terminated = truncated = False
    t0 = time.perf_counter()
    while not (terminated or truncated):
        batch = pre({STATE: torch.from_numpy(obs["agent_pos"])[None],
                     ENV_STATE: torch.from_numpy(obs["environment_state"])[None]})
        with torch.no_grad():
            action = post(policy.select_action(batch))
        action = np.clip(action[0].numpy(), low, high)
        obs, _, terminated, truncated, info = env.step(action)
    return {"seed": seed, "success": bool(info["is_success"]), "ticks": int(info["tick"]),
            "disturbances": info["disturbances"], "wall_s": time.perf_counter() - t0}


def stage_eval(out: Path, which: str, trials: int, disturb: str | None, threads: int) -> dict:
    import gymnasium
    import torch

    import agentchord.gym  # noqa: F401  (registers the environments)

    torch.set_num_threads(threads)
    tag = f"eval_{which}" + ("" if disturb == "shift" else f"_{disturb or 'none'}")
    path = out / f"{tag}.jsonl"
    done = [json.loads(line) for line in path.read_text().splitlines()] if path.exists() else []
    seen = {r["seed"] for r in done}
    policy, pre, post = load_policy(out / f"policy_{which}")
    env = gymnasium.make(ENV_ID, disturb=disturb)
    with path.open("a") as f:
        for seed in range(EVAL_SEED, EVAL_SEED + trials):
            if seed in seen:
                continue
            r = run_trial(env, policy, pre, post, seed)
            done.append(r)
            f.write(json.dumps(r) + "\n")
            f.flush()
            moved = ",".join(f"{d['kind']}:{d['obj']}@{d['tick']}" for d in r["disturbances"]) or "-"
            print(f"[eval] {which} seed {seed}: {'success' if r['success'] else 'fail'} {r['ticks']} ticks "
                  f"({moved}) {r['wall_s']:.1f} s", flush=True)
    env.close()
    done = [r for r in done if EVAL_SEED <= r["seed"] < EVAL_SEED + trials]
    k = sum(r["success"] for r in done)
    print(f"[eval] {which}: {k}/{len(done)}")
    return {"trials": done}


# ----------------------------------------------------------------------------------------- report
def stage_report(out: Path, trials: int) -> str:
    from agentchord.bench.report import wilson_interval  # noqa: PLC0415

    rows, data = [], {}
    names = {"A": "ACT, nominal demos only", "B": "ACT, nominal + AgentChord recovery demos"}
    demos = {"A": "40 nominal", "B": "20 nominal + 20 recovery"}
    for which in ("A", "B"):
        train_path, eval_path = out / f"policy_{which}/train.json", out / f"eval_{which}.jsonl"
        if not (train_path.exists() and eval_path.exists()):
            continue
        train = json.loads(train_path.read_text())
        results = [json.loads(line) for line in eval_path.read_text().splitlines()]
        results = [r for r in results if EVAL_SEED <= r["seed"] < EVAL_SEED + trials]
        n, k = len(results), sum(r["success"] for r in results)
        lo, hi = wilson_interval(k, n)
        eval_s = sum(r["wall_s"] for r in results)
        cup_moved = sum(any(d["obj"] == "cup" for d in r["disturbances"]) for r in results)
        other = sorted({d["obj"] for r in results for d in r["disturbances"] if d["obj"] != "cup"})
        data[which] = {"policy": names[which], "demos": demos[which], "successes": k, "trials": n,
                       "success_rate": k / n if n else None, "wilson95": [lo, hi], "train_s": train["train_s"],
                       "train_steps": train["steps"], "eval_s": eval_s, "trials_cup_moved": cup_moved,
                       "other_objects_moved": other, "mean_ticks": float(np.mean([r["ticks"] for r in results])),
                       "config": train["config"]}
        rows.append(f"| {names[which]} | {demos[which]} | {k}/{n} ({100 * k / n:.0f}%) | "
                    f"[{100 * lo:.1f}%, {100 * hi:.1f}%] | {train['train_s'] / 60:.1f} min ({train['steps']} steps) | "
                    f"{eval_s / 60:.1f} min | {cup_moved}/{n} |")
    table = ("| policy | demos | success | Wilson 95% CI | train time | eval time | trials with the cup moved |\n"
             "| --- | --- | --- | --- | --- | --- | --- |\n" + "\n".join(rows))
    print(table)
    (out / "table3.md").write_text(table + "\n")
    record_path = out / "record.json"
    if record_path.exists():
        data["record"] = json.loads(record_path.read_text())
    (out / "table3.json").write_text(json.dumps(data, indent=1))
    return table


# ------------------------------------------------------------------------------------------ probe
def stage_probe(out: Path, cfg: Config, n_total: int) -> None:
    """Time a few training steps and one evaluation episode of an untrained policy (sizing)."""
    import gymnasium
    import torch

    import agentchord.gym  # noqa: F401

    summary = stage_train(out, "A", cfg, n_total, steps=20)
    print(f"[probe] {summary['s_per_step'] * 1000:.0f} ms per training step (batch {cfg.batch_size})")
    episodes = training_set(out, "A", 2)
    dims = {k: episodes[0][k].shape[1] for k in (STATE, ENV_STATE, ACTION)}
    from lerobot.policies.factory import make_pre_post_processors

    policy = make_policy(cfg, dims)
    pre, post = make_pre_post_processors(policy.config, dataset_stats=stats_of(episodes, cfg.std_floor))
    env = gymnasium.make(ENV_ID, disturb="shift")
    torch.set_num_threads(cfg.threads)
    r = run_trial(env, policy, pre, post, EVAL_SEED)
    print(f"[probe] one evaluation episode of an untrained policy: {r['ticks']} ticks, {r['wall_s']:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stage", choices=("record", "train", "eval", "report", "all", "probe"))
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--set", choices=("A", "B"), action="append", help="training set(s); default both")
    parser.add_argument("--demos", type=int, default=40, help="demonstrations per training set")
    parser.add_argument("--trials", type=int, default=50)
    parser.add_argument("--disturb", default="shift", help="evaluation disturbance ('none': undisturbed)")
    for field, value in asdict(Config()).items():
        kind = (lambda text: text.lower() in ("1", "true", "yes")) if isinstance(value, bool) else type(value)
        parser.add_argument(f"--{field.replace('_', '-')}", type=kind, default=value)
    args = parser.parse_args()
    cfg = Config(**{f: getattr(args, f) for f in asdict(Config())})
    args.out.mkdir(parents=True, exist_ok=True)
    sets = args.set or ["A", "B"]
    disturb = None if args.disturb == "none" else args.disturb
    stages = ("record", "train", "eval", "report") if args.stage == "all" else (args.stage,)
    if "record" in stages or args.stage == "probe":
        stage_record(args.out, args.demos, args.demos)
    if args.stage == "probe":
        stage_probe(args.out, cfg, args.demos)
        return
    if "train" in stages:
        for which in sets:
            stage_train(args.out, which, cfg, args.demos)
    if "eval" in stages:
        for which in sets:
            stage_eval(args.out, which, args.trials, disturb, cfg.threads)
    if "report" in stages:
        stage_report(args.out, args.trials)


if __name__ == "__main__":
    sys.exit(main())
