"""Coverage of the reported 95 % intervals of a missing body mode's frequency and modal mass.

    python -m benchmarks.sigma_coverage                    # the rate test's fixed seed, 20 cases
    python -m benchmarks.sigma_coverage --seed 7 --cases 40
    python -m benchmarks.sigma_coverage --fresh --cases 40

Cases ``0..cases-1`` of the ``missing_body_mode`` rate test (:func:`benchmarks.rate_tests.
mode_row`, the same draws for the same seed) are diagnosed; of those where
``missing_body_mode`` is named, the share whose true frequency, modal mass and both lie
within the reported 95 % interval (``parameter_interval_95`` of the JSON; without it,
± 1.96 ``parameter_sigma``) is printed with its
95 % Wilson interval, and the same for the cases found (frequency within 5 %, modal mass
within 30 %). ``--json FILE`` writes the rows. The last line is the joint coverage over the
named cases.
"""

from __future__ import annotations

import argparse
import json
import sys

from benchmarks.rate_tests import RATE_TESTS, mode_row
from benchmarks.rates import fresh_seed
from benchmarks.scoring import mode_found, wilson_interval
from powertrain.parallel import executor

#: Parameters whose coverage is measured.
KEYS = ("frequency_hz", "modal_mass_kg")


def covered(row, key) -> bool | None:
    """Whether the truth of ``key`` lies within the reported 95 % interval (None: not named,
    or no interval reported)."""
    if row["claimed"] != ["missing_body_mode"]:
        return None
    iv = interval(row, key)
    if iv is None or None in iv:
        return None
    return bool(iv[0] <= row["truth_mode"][key] <= iv[1])


def interval(row, key):
    """The reported 95 % interval ``[lo, hi]`` of ``key``: ``parameter_interval_95``, or
    without it (older code) the value ± 1.96 ``parameter_sigma``."""
    e = "missing_body_mode"
    if row.get("interval_95"):
        return row["interval_95"][e][key]
    v, s = row["parameters"][e][key], row["sigma"][e][key]
    return [v - 1.96 * s, v + 1.96 * s]


def line(label, flags) -> str:
    """``label: k/n = rate (95% Wilson lo-hi)``."""
    k, n = sum(flags), len(flags)
    if not n:
        return f"{label}: no cases"
    lo, hi = wilson_interval(k, n)
    return f"{label}: {k}/{n} = {k / n:.3f} (95% Wilson {lo:.2f}-{hi:.2f})"


def report(rows) -> list:
    """The coverage lines, joint coverage over the named cases last."""
    named = [r for r in rows if covered(r, KEYS[0]) is not None]
    found = [r for r in named if mode_found(r)]
    out = [f"cases {len(rows)}, named {len(named)}, found {len(found)}"]
    for label, group in (("found", found), ("named", named)):
        for key in KEYS:
            out.append(line(f"{label} {key}", [covered(r, key) for r in group]))
    out.append(line("found joint", [all(covered(r, k) for k in KEYS) for r in found]))
    out.append(line("named joint", [all(covered(r, k) for k in KEYS) for r in named]))
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    how = ap.add_mutually_exclusive_group()
    how.add_argument("--seed", type=int, help="the cases' seed (default: the rate test's)")
    how.add_argument("--fresh", action="store_true", help="a new seed (os.urandom)")
    ap.add_argument("--cases", type=int, default=20, help="cases drawn (default 20)")
    ap.add_argument("--json", help="write the rows to this file")
    a = ap.parse_args(argv)
    seed = fresh_seed() if a.fresh else RATE_TESTS["missing_body_mode"].seed \
        if a.seed is None else a.seed
    with executor(None, n_jobs=a.cases) as ex:
        rows = list(ex.map(mode_row, [(i, seed) for i in range(a.cases)]))
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1, default=float)
    print(f"seed {seed}")
    print("\n".join(report(rows)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
