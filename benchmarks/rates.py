"""The ten diagnosis rate tests from the command line, one line each.

    python -m benchmarks.rates                  # the fixed seeds CI runs (tests/test_*rates.py)
    python -m benchmarks.rates --fresh          # new seeds (os.urandom), new cases
    python -m benchmarks.rates --seed 424243 passive_side_named missing_body_mode

Each test (:data:`benchmarks.rate_tests.RATE_TESTS`) prints the line its pytest test prints
(:meth:`benchmarks.rate_tests.RateOutcome.line`): name, seed, ``k/n``, the rate, its 95 %
Wilson interval, the target and pass or FAIL; with ``--misses`` the rows that were not
successes follow it. Run from the top of the repository. Exit status 1 when a test fails.
"""

from __future__ import annotations

import argparse
import os
import sys

from benchmarks.rate_tests import RATE_TESTS, run


def fresh_seed() -> int:
    """A new seed from ``os.urandom`` (32 bits)."""
    return int.from_bytes(os.urandom(4), "little")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tests", nargs="*", metavar="NAME",
                    help=f"rate tests to run (default: all ten): {', '.join(RATE_TESTS)}")
    how = ap.add_mutually_exclusive_group()
    how.add_argument("--fresh", action="store_true",
                     help="draw a new seed for each test (default: each test's fixed seed)")
    how.add_argument("--seed", type=int, help="one seed for every test")
    ap.add_argument("--misses", action="store_true", help="print the rows that failed")
    a = ap.parse_args(argv)
    unknown = [t for t in a.tests if t not in RATE_TESTS]
    if unknown:
        ap.error(f"unknown rate test(s) {', '.join(unknown)}; known: {', '.join(RATE_TESTS)}")
    ok = True
    for name in a.tests or RATE_TESTS:
        seed = fresh_seed() if a.fresh else a.seed
        outcome = run(RATE_TESTS[name], seed)
        print(outcome.line(), flush=True)
        if a.misses:
            for row in outcome.misses():
                print(f"  miss: {row}", flush=True)
        ok = ok and outcome.passed
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
