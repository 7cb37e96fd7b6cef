"""Long malformed-input campaign (issues 10, 18, 38 and 39): every input kind, many examples.

Runs the hypothesis strategies of ``tests/fuzz_harness.py`` (the same as the CI suite
``tests/test_fuzz_inputs.py``, more examples), the failures issues 10, 18 and 39 listed, and the
data-safety trials (concurrent runs to one path, SIGKILL mid-write at random moments);
classifies every run and prints the counts, last line::

    tracebacks=0 hangs=0 nan_outputs=0 leftovers=0 lost_files=0 clean_errors=N ok=M

Failing cases are copied to ``--keep`` (default ``fuzz-failures/``) with the command in
``ARGS`` so they can be replayed. Usage::

    python scripts/fuzz_inputs.py --examples 100          # ~100 per input kind
    python scripts/fuzz_inputs.py --examples 5 --kinds engine,options --safety 2
    python scripts/fuzz_inputs.py --examples 300 --kinds transient --safety 0 --no-named

``--kinds transient`` stands for the transient manoeuvre kinds (``fh.TRANSIENT_KINDS``);
``--no-named`` skips the named failures of the issues (about a minute).
"""

from __future__ import annotations

import argparse
import collections
import shutil
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

import fuzz_harness as fh  # noqa: E402
from hypothesis import HealthCheck, Phase, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--examples", type=int, default=100, help="examples per input kind")
    ap.add_argument("--kinds", default=",".join(fh.KINDS),
                    help=f"comma-separated input kinds ({', '.join(fh.KINDS)}; 'transient' "
                         "for the transient ones)")
    ap.add_argument("--seed", type=int, default=None, help="hypothesis seed (default random)")
    ap.add_argument("--keep", default="fuzz-failures", help="folder for failing cases")
    ap.add_argument("--safety", type=int, default=10,
                    help="concurrent-run and SIGKILL trials (each)")
    ap.add_argument("--no-named", action="store_true",
                    help="skip the named failures of issues 10, 18, 38 and 39")
    args = ap.parse_args()
    kinds = [k.strip() for k in args.kinds.split(",") if k.strip()]
    if "transient" in kinds:
        i = kinds.index("transient")
        kinds[i:i + 1] = fh.TRANSIENT_KINDS
    unknown = [k for k in kinds if k not in fh.KINDS]
    if unknown:
        ap.error(f"unknown kind {unknown[0]!r}")
    worker = fh.Worker()
    tmp = Path(tempfile.mkdtemp(prefix="fuzz-"))
    counts: dict = collections.Counter()
    per_kind: dict = collections.defaultdict(collections.Counter)
    failures = []
    t0 = time.perf_counter()

    def record(kind, case, outcome, detail):
        counts[outcome] += 1
        per_kind[kind][outcome] += 1
        if outcome in fh.FAILURES:
            keep = Path(args.keep) / f"{len(failures) + 1:03d}-{kind}"
            shutil.rmtree(keep, ignore_errors=True)
            keep.mkdir(parents=True)
            fh.write_case(case, keep)
            (keep / "ARGS").write_text("powertrain " + " ".join(case.args) + "\n")
            failures.append(f"{kind}: {case.description}: {outcome}: {detail[-200:]}")
            print(f"  FAIL {failures[-1]}", flush=True)

    try:
        fh.seeds(worker, tmp / "seeds")
        if not args.no_named:
            _named(worker, tmp, record)
        _safety(args, tmp, counts, per_kind, failures)
        for kind in kinds:
            run = _campaign(kind, args, worker, tmp, record)
            run()
            print(f"{kind}: {dict(per_kind[kind])}", flush=True)
    finally:
        worker.close()
        shutil.rmtree(tmp, ignore_errors=True)
    print(f"issue-10 named cases: {dict(per_kind['issue-10'])}")
    print(f"issue-18 named cases: {dict(per_kind['issue-18'])}")
    print(f"issue-39 named cases: {dict(per_kind['issue-39'])}")
    print(f"issue-38 (transient) named cases: {dict(per_kind['issue-38'])}")
    print(f"data safety (concurrent runs, SIGKILL): {dict(per_kind['safety'])}; "
          f"{sum(n > 0 for n in fh.KILL_TEMPS)} of {len(fh.KILL_TEMPS)} kills left "
          f"{sum(fh.KILL_TEMPS)} temporary files, all swept by the next run unless counted "
          "as leftovers")
    print(f"runs: {sum(counts.values())} in {time.perf_counter() - t0:.0f} s; "
          f"unclear errors (exit 1 not naming the file/option): {counts['unclear_error']}")
    print(f"tracebacks={counts['traceback']} hangs={counts['hang']} "
          f"nan_outputs={counts['nan_output']} leftovers={counts['leftover']} "
          f"lost_files={counts['lost_file']} clean_errors={counts['clean_error']} "
          f"ok={counts['ok']}")
    return 1 if failures else 0


def _named(worker, tmp, record):
    """The failures issues 10, 18, 38 and 39 list, each run once."""
    for name, case in fh.issue_cases().items():
        case.description = name
        outcome, detail = fh.run_case(worker, case, tmp / "case")
        record("issue-10", case, outcome, detail)
    cases_39, slow_39 = fh.issue_39_cases()
    for issue, named in (("issue-18", fh.issue_18_cases()),
                         ("issue-39", {**cases_39, **slow_39}),
                         ("issue-38", fh.issue_38_cases())):
        for name, (case, expected) in named.items():
            case.description = name
            outcome, detail = fh.run_case(worker, case, tmp / "case")
            if outcome != expected and outcome not in fh.FAILURES:
                outcome, detail = "unclear_error", f"expected {expected}: {detail}"
            record(issue, case, outcome, detail)


def _safety(args, tmp, counts, per_kind, failures):
    """Concurrent runs to one path and SIGKILLs at random moments (1.5..4.5 s: the run-up
    killed writes its outputs about 2..4.5 s after its start)."""
    import random
    rng = random.Random(args.seed)
    trials = [("concurrent", lambda: fh.concurrent_runs(tmp / "safety", n=rng.choice([2, 3])))
              for _ in range(args.safety)]
    trials += [("sigkill", lambda: fh.killed_run(tmp / "safety", rng.uniform(1.5, 4.5)))
               for _ in range(args.safety)]
    for name, trial in trials:
        outcome, detail = trial()
        counts[outcome] += 1
        per_kind["safety"][outcome] += 1
        if outcome in fh.FAILURES:
            failures.append(f"safety {name}: {outcome}: {detail[-200:]}")
            print(f"  FAIL {failures[-1]}", flush=True)


def _campaign(kind, args, worker, tmp, record):
    deco = settings(max_examples=args.examples, deadline=None, database=None,
                    phases=[Phase.generate], suppress_health_check=list(HealthCheck),
                    derandomize=False)

    @deco
    @given(st.data())
    def run(data):
        case = fh.KINDS[kind](data.draw)
        outcome, detail = fh.run_case(worker, case, tmp / "case")
        record(kind, case, outcome, detail)
    if args.seed is not None:
        from hypothesis import seed
        run = seed(args.seed)(run)
    return run


if __name__ == "__main__":
    sys.exit(main())
