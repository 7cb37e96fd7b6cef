#!/usr/bin/env python
"""Time ``powertrain compare`` on the shipped SYNTHETIC example, end to end.

Runs the command line in fresh processes (``REPEAT`` times, after one warm-up run that fills
the Numba JIT cache): reads ``examples/measured-runup.csv``, simulates the default engine
(Newmark, 500-rpm grid covering 1000..6000 rpm), compares, writes the JSON and the PNG.
Prints each wall time and, last, ``compare_seconds_warm=<best>``. Budget: < 10 s warm.

Usage: ``python scripts/time_compare_example.py [--out DIR]``
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPEAT = 3
ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "measured-runup.csv"


def run_once(out: Path) -> float:
    cmd = [sys.executable, "-c", "from powertrain.cli import main; main()", "compare",
           str(EXAMPLE), "--json", str(out / "compare.json"), "--plot",
           str(out / "compare.png"), "--quiet"]
    t0 = time.perf_counter()
    res = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
    elapsed = time.perf_counter() - t0
    if res.returncode != 0:
        sys.exit(f"compare failed:\n{res.stderr}")
    print(f"{elapsed:6.2f} s  {res.stdout.strip()}")
    return elapsed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", help="folder for compare.json/compare.png (default: temporary)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(args.out or tmp)
        out.mkdir(parents=True, exist_ok=True)
        print("warm-up (fills the JIT cache if empty):")
        run_once(out)
        print(f"{REPEAT} warm runs:")
        times = [run_once(out) for _ in range(REPEAT)]
    print(f"compare_seconds_warm={min(times):.2f}")


if __name__ == "__main__":
    main()
