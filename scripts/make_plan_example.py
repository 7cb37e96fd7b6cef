#!/usr/bin/env python
"""Write a SYNTHETIC two-run test plan: ``DIR/full.csv`` (load 1.0), ``DIR/part.csv`` (load
0.4) and ``DIR/plan.toml``, one hidden truth effect measured at both loads by the
independent truth generator (:func:`benchmarks.plans.make_plan_case`), with
the order phase a lab records (every order's, as with a cycle reference; column
``phase_deg``, empty where the level is below the noise floor).

Usage: ``python scripts/make_plan_example.py --out DIR [--effect KIND] [--seed S]``
(KIND a truth kind of :mod:`benchmarks.kinds`, default ``mount_temperature``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="folder written")
    ap.add_argument("--effect", default="mount_temperature")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args(argv)
    from benchmarks.plans import make_plan_case
    case = make_plan_case(0, [args.effect], args.seed, phase="all")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    lines = []
    for name, run, load in zip(("full", "part"), case.runs, case.loads):
        (out / f"{name}.csv").write_text(run.csv_text())
        lines += ["[[runs]]", f'file = "{name}.csv"', f"load = {load:g}", ""]
    (out / "plan.toml").write_text("\n".join(lines))
    print(f"wrote {out}/plan.toml with {len(case.runs)} runs (loads "
          f"{', '.join(f'{x:g}' for x in case.loads)}); the hidden effect is not written")


if __name__ == "__main__":
    main()
