#!/usr/bin/env python
"""Not slower than before: this checkout against an earlier commit, on the same machine, in
one run (issue 19, "Not slower").

Checks the earlier commit out into a temporary git worktree and runs each version's own
benchmarks with its own code (``PYTHONPATH`` set to that version's ``src``), alternating
old, new, old, new so that both see the same machine load:

* ``scripts/bench_runup.py``: the warm Newmark run-up solver time per speed (its last line,
  ``newmark_s_per_speed=...``), ``--rounds`` times each; the best of each version counts;
* ``scripts/blind_diagnosis.py --cases N --seed S`` (the same seed for both, drawn from
  ``os.urandom`` unless given): the median diagnosis time per case and the rate line.

The last line gives both ratios, new / old (``<= 1.10`` is "within 10 %").

    python scripts/bench_versions.py --ref 9d91fb5 --cases 50
    python scripts/bench_versions.py --ref 9d91fb5 --skip-diagnosis
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _run(tree: Path, args: list[str]) -> str:
    env = {**os.environ, "PYTHONPATH": str(tree / "src")}
    run = subprocess.run([sys.executable, *args], cwd=tree, env=env, capture_output=True,
                         text=True, check=True)
    return run.stdout


def runup_seconds(tree: Path) -> float:
    out = _run(tree, ["scripts/bench_runup.py", "--sample-speeds", "3500"])
    return float(re.search(r"newmark_s_per_speed=([0-9.eE+-]+)", out).group(1))


def diagnosis(tree: Path, cases: int, seed: int) -> tuple[float, str]:
    out = _run(tree, ["scripts/blind_diagnosis.py", "--cases", str(cases), "--seed",
                      str(seed), "--jobs", "2"])
    median = float(re.search(r"diagnosis time per case: median ([0-9.]+) s", out).group(1))
    return median, out.strip().splitlines()[-1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="9d91fb5", help="the earlier commit")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--cases", type=int, default=50)
    ap.add_argument("--seed", type=int, default=None)
    ap.add_argument("--skip-diagnosis", action="store_true")
    args = ap.parse_args()
    seed = args.seed if args.seed is not None else int.from_bytes(os.urandom(4), "little")
    with tempfile.TemporaryDirectory() as tmp:
        old = Path(tmp) / "old"
        subprocess.run(["git", "worktree", "add", "--detach", str(old), args.ref], cwd=ROOT,
                       check=True, capture_output=True)
        try:
            trees = {"old": old, "new": ROOT}
            times = {k: [] for k in trees}
            for _ in range(args.rounds):           # alternating: both see the same load
                for k, t in trees.items():
                    times[k].append(runup_seconds(t))
            best = {k: min(v) for k, v in times.items()}
            for k in trees:
                print(f"{k}: Newmark solver time per speed (best of {args.rounds}) "
                      f"{best[k]:.5f} s")
            ratio_d = None
            if not args.skip_diagnosis:
                med = {}
                for k, t in trees.items():
                    med[k], rates = diagnosis(t, args.cases, seed)
                    print(f"{k}: diagnosis median {med[k]:.1f} s per case ({args.cases} cases, "
                          f"seed {seed}); {rates}")
                ratio_d = med["new"] / med["old"]
        finally:
            subprocess.run(["git", "worktree", "remove", "--force", str(old)], cwd=ROOT,
                           capture_output=True)
    line = f"runup_ratio_new_over_old={best['new'] / best['old']:.3f}"
    if ratio_d is not None:
        line += f" diagnosis_median_ratio_new_over_old={ratio_d:.3f}"
    print(line)


if __name__ == "__main__":
    main()
