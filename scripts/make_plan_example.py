#!/usr/bin/env python
"""Write the shipped SYNTHETIC two-run test plan: ``examples/plan.toml`` with its runs
``examples/plan-full-load.csv`` (load 1.0) and ``examples/plan-part-load.csv`` (load 0.4), one
hidden truth effect measured at both loads by the independent truth generator
(:func:`benchmarks.plans.make_plan_case`), with the order phase a lab records (every
order's, as with a cycle reference; column ``phase_deg``, empty where the level is below the
noise floor). ``powertrain examples DIR`` copies them with the other shipped files.

Usage: ``python scripts/make_plan_example.py [--out DIR] [--effect KIND] [--seed S]``
(default: the repository's ``examples/``; KIND a truth kind of :mod:`benchmarks.kinds`,
default ``mount_temperature``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks.plans import make_plan_case  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
#: File names of the runs, by load.
RUN_FILES = ("plan-full-load.csv", "plan-part-load.csv")


def plan_files(effect="mount_temperature", seed=1) -> dict:
    """``{file name: text}`` of the plan and its runs."""
    case = make_plan_case(0, [effect], seed, phase="all")
    files, runs = {}, []
    for name, run, load in zip(RUN_FILES, case.runs, case.loads):
        body = run.csv_text().split("\n", 1)[1]          # the generator's own header dropped
        files[name] = (f"# SYNTHETIC measured run-up (load {load:g}) of a two-run test plan: "
                       f"made by scripts/make_plan_example.py (truth generator of benchmarks/, "
                       f"seed {seed}), NOT measured; the hidden effect is not stated here\n"
                       + body)
        runs += ["[[runs]]", f'file = "{name}"', f"load = {load:g}", ""]
    files["plan.toml"] = "\n".join(
        ["# SYNTHETIC two-run test plan (one car, one hidden effect, two loads): made by",
         "# scripts/make_plan_example.py, NOT measured. Paths are relative to this file.", ""]
        + runs)
    return files


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(ROOT / "examples"), help="folder written")
    ap.add_argument("--effect", default="mount_temperature")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, text in plan_files(args.effect, args.seed).items():
        (out / name).write_text(text)
    print(f"wrote {out}/plan.toml with {len(RUN_FILES)} runs (loads 1, 0.4); the hidden "
          "effect is not written")


if __name__ == "__main__":
    main()
