"""How long the two rate tests whose length varies run on fresh draws (``--fresh``).

CI runs the rate tests on fixed seeds, so its length is fixed; on fresh draws
(``python -m benchmarks.rates --fresh``) what varies is how many cases the passive-side and
missing-mode rate tests draw before their group-sequential rule decides
(:mod:`benchmarks.sizing`). This script sums the exact distributions of their stopping case counts
(``rates.stopping_counts``: every path of the batches, at the given true rates) over a
linear model of CI's wall time:

    wall = install + overhead × (fixed + (n_passive − n0_passive) × s_passive
                                        + (n_missing − n0_missing) × s_missing)

calibrated on one measured run (defaults: the eleventh round's, docs/validation/diagnosis.md,
"CI's length, estimated"): ``fixed`` the suite's wall time alone in that run's case counts,
``s_*`` the wall seconds a case adds on two busy cores. A crude model; it says where the
length comes from.

    python scripts/ci_length.py --passive 0.93 --missing 0.885

The last line printed: ``P(CI > 15.0 min) = 0.082, mean 13.5 min``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks import sizing as rates  # noqa: E402


def stopping_counts(target, rate) -> dict:
    """``{n: probability}`` of the case count at which the rate test of ``target`` stops
    when the true rate is ``rate`` (:func:`rates.stopping_counts`, its batches and limit)."""
    return rates.stopping_counts(rates.sequential_plan(target), target, True, rate)[0]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--passive", type=float, default=0.93, help="true passive-side rate")
    ap.add_argument("--missing", type=float, default=0.885, help="true missing-mode rate")
    ap.add_argument("--limit-min", type=float, default=15.0)
    ap.add_argument("--install-s", type=float, default=67.0, help="install and lint [s]")
    ap.add_argument("--fixed-s", type=float, default=665.8,
                    help="suite wall time at the calibration counts [s] (rates alone 365.0 s "
                         "+ the rest 300.8 s, eleventh round)")
    ap.add_argument("--overhead", type=float, default=1.1,
                    help="the suite in CI over that sum (738 s / 666 s)")
    ap.add_argument("--calibration", type=int, nargs=2, default=(28, 24),
                    help="passive and missing-mode case counts of the calibration run")
    ap.add_argument("--per-case-s", type=float, nargs=2, default=(2.3, 2.07),
                    help="wall seconds a passive and a missing-mode case add [s]")
    a = ap.parse_args(argv)
    dp = stopping_counts(0.9, a.passive)
    dm = stopping_counts(0.8, a.missing)
    over = mean = 0.0
    for n_p, p_p in dp.items():
        for n_m, p_m in dm.items():
            extra = ((n_p - a.calibration[0]) * a.per_case_s[0]
                     + (n_m - a.calibration[1]) * a.per_case_s[1])
            wall = a.install_s + a.overhead * (a.fixed_s + extra)
            mean += p_p * p_m * wall
            over += p_p * p_m * (wall > 60 * a.limit_min)
    print(f"passive side {a.passive}: mean {sum(n * p for n, p in dp.items()):.1f} cases; "
          f"missing mode {a.missing}: mean {sum(n * p for n, p in dm.items()):.1f} cases")
    print(f"P(CI > {a.limit_min:.1f} min) = {over:.3f}, mean {mean / 60:.1f} min")


if __name__ == "__main__":
    main()
