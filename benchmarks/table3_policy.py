"""The paper's Table III on a CPU: a policy trained on nominal demonstrations against one trained
with AgentChord recovery demonstrations, evaluated with the cup moved during execution and undisturbed.

    python benchmarks/table3_policy.py all --out OUT          # record, train, eval, report (resumes)
    python benchmarks/table3_policy.py record --out OUT
    python benchmarks/table3_policy.py train --set A --out OUT
    python benchmarks/table3_policy.py eval --set A --condition none --trials 10 --out OUT
    python benchmarks/table3_policy.py report --out OUT

Sets: A (``--demos`` nominal episodes) and B<p> (the same number, p % of them AgentChord episodes that
recover from the cup moved after the grasp); ``--dose 0,50`` trains A and B50 (the paper's pair),
``--dose 0,25,50`` adds B25. ``--device cuda`` trains and evaluates there (nothing needs it).
What each stage does and writes: ``agentchord.learning.table3``; the results: docs/data.md,
"The Table III experiment".
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import asdict
from pathlib import Path

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("HF_DATASETS_OFFLINE", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

from agentchord.learning.table3 import (
    CONDITIONS,
    TrainConfig,
    log_stage,
    set_names,
    stage_eval,
    stage_record,
    stage_report,
    stage_train,
)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("stage", choices=("record", "train", "eval", "report", "all"))
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--demos", type=int, default=150, help="demonstrations per training set")
    parser.add_argument("--dose", default="0,50", help="recovery shares (%%) of the sets: 0 is set A")
    parser.add_argument("--set", action="append", help="only these sets (A, B25, B50 ...); default: --dose's")
    parser.add_argument("--condition", action="append", choices=CONDITIONS,
                        help="evaluation: shift (the cup moved) and/or none (undisturbed); default both")
    parser.add_argument("--trials", type=int, default=50)
    for name, value in asdict(TrainConfig()).items():
        parser.add_argument(f"--{name.replace('_', '-')}", type=type(value), default=value)
    args = parser.parse_args(argv)
    cfg = TrainConfig(**{f: getattr(args, f) for f in asdict(TrainConfig())})
    dose = tuple(int(x) for x in args.dose.split(","))
    sets = args.set or set_names(dose)
    conditions = args.condition or list(CONDITIONS)
    args.out.mkdir(parents=True, exist_ok=True)
    stages = ("record", "train", "eval", "report") if args.stage == "all" else (args.stage,)
    t0 = time.perf_counter()
    if "record" in stages:
        shares = [0 if s == "A" else int(s[1:]) for s in sets]
        stage_record(args.out, args.demos, round(args.demos * max(shares) / 100))
    if "train" in stages:
        for which in sets:
            stage_train(args.out, which, cfg, args.demos)
    if "eval" in stages:
        for which in sets:
            for condition in conditions:
                stage_eval(args.out, which, condition, args.trials, cfg.threads, cfg.device)
    if "report" in stages:
        stage_report(args.out, sets, args.trials, args.demos)
    if args.stage == "all":
        log_stage(args.out, "all", time.perf_counter() - t0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
