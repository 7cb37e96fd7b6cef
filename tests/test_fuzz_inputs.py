"""Bad input, all of it (issues 10 and 18): property-based campaign over every input kind.

Hypothesis mutates valid seeds of every input kind -- engine TOML, mount TOML, pressure CSV,
stiffness CSV, measured CSV and HDF5, what-if variants TOML, raw time data as CSV, HDF5, UFF
58 and MDF4 (``track``), channel maps, the FRF (measured receptance) chassis, ``diagnose``,
``modes`` on a modal-body engine, and option specs (``--freq``, ``--effect``, ``--scale``,
``--set``, ``--move``, ``--rotate``, ``--target``, speeds, seeds, track options, sweeps),
and the transient manoeuvres of issue 38 -- manoeuvre TOML, ``transient``'s options and
outputs, recordings for ``--compare`` and ``--speed-from`` (CSV and HDF5: cut, shifted,
NaN, held or tacho speed, triggers), ``whatif --manoeuvre`` specs and variants -- and runs
the command that reads it (``tests/fuzz_harness.py``). Every run must end in a
clean one-line error naming the file or option (exit 1, no output file) or in a finite
result; never a traceback, a hang, NaN/inf in an output, a leftover file, or a lost one
(a file that was there before, changed or gone after a failed run).

Examples per kind are bounded here (``FUZZ_EXAMPLES``, default 4) to keep CI short;
``python scripts/fuzz_inputs.py`` runs the long campaign and prints the counts.
Every failure issues 10 and 18 list, and every one the transient campaign found, is
also replayed by name, and data safety is checked
once each: concurrent runs to one path, a SIGKILL mid-write (these three in the slow lane:
about 40 s together).
"""

from __future__ import annotations

import os

import fuzz_harness as fh
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "4"))


@pytest.fixture(scope="module")
def worker(tmp_path_factory):
    w = fh.Worker()
    fh.seeds(w, tmp_path_factory.mktemp("seeds"))
    yield w
    w.close()


@pytest.fixture(scope="module")
def issue_18(worker):
    return fh.issue_18_cases()


@pytest.mark.slow
def test_issue_18_root_causes(worker, issue_18, tmp_path):
    """Each root cause issue 18 lists gives a clean one-line error (or runs, for the short
    sweeps), and no earlier file is lost."""
    wrong = []
    for name, (case, expected) in issue_18.items():
        outcome, detail = fh.run_case(worker, case, tmp_path / "case")
        if outcome != expected:
            wrong.append(f"{name}: {outcome} ({detail[:200]})")
    assert not wrong, "\n".join(wrong)


@pytest.mark.slow
def test_concurrent_runs_leave_one_complete_set(worker, tmp_path):
    outcome, detail = fh.concurrent_runs(tmp_path / "c")
    assert outcome == "ok", detail


@pytest.mark.slow
def test_sigkill_mid_write_leaves_no_temporary_file_after_the_next_run(worker, tmp_path):
    outcome, detail = fh.killed_run(tmp_path / "k", delay=2.5)
    assert outcome == "ok", detail


@pytest.mark.slow
def test_issue_39_last_bad_inputs(worker, tmp_path):
    """Issue 39's last bad inputs: a mount singular at 0 Hz refused at reading (also reached
    through ``whatif --set``), a raw HDF5 file with an empty /time or an array as its
    synthetic flag, and a report folder in the way of a figure (the earlier d.json stays):
    each a clean one-line error, no output, no earlier file lost."""
    cases, _ = fh.issue_39_cases()
    wrong = []
    for name, (case, expected) in cases.items():
        outcome, detail = fh.run_case(worker, case, tmp_path / "case")
        if outcome != expected:
            wrong.append(f"{name}: {outcome} ({detail[:200]})")
    assert not wrong, "\n".join(wrong)


@pytest.mark.slow
def test_issue_39_tiny_level_report_is_finite(worker, tmp_path):
    """A measured level of 1e-300 (a censored point) gives a finite diagnosis: JSON, report
    folder and printout without NaN (its overlay figure once failed on the axis range)."""
    _, slow = fh.issue_39_cases()
    for name, (case, expected) in slow.items():
        outcome, detail = fh.run_case(worker, case, tmp_path / "case")
        assert outcome == expected, f"{name}: {outcome}: {detail}"


def test_issue_38_transient_failures(worker, tmp_path):
    """Each failure the campaign over ``transient`` and ``whatif --manoeuvre`` found (issue
    38's manoeuvres, recordings, options): a clean one-line error, no output."""
    wrong = []
    for name, (case, expected) in fh.issue_38_cases().items():
        outcome, detail = fh.run_case(worker, case, tmp_path / "case")
        if outcome != expected:
            wrong.append(f"{name}: {outcome} ({detail[:200]})")
    assert not wrong, "\n".join(wrong)


@pytest.mark.parametrize("name", sorted(
    ["engine: list where a number belongs", "engine: firing order mixing strings and ints",
     "engine: huge counterweight_fraction", "engine: bore huge", "engine: imep_factors 1e-300",
     "engine: mounts all at the CG", "engine: all-zero mounts", "engine file is a FIFO",
     "measured CSV is a FIFO", "CSV cell over 128 kB", "fit-mount on 1e300 N/mm data",
     "fit-mount --seed -1", "--angle-step 0", "runup --to 9000 names --to",
     "--from 1000 --to 1e12", "--freq 0:1e12:1", "stiffness --freq 1e300",
     "compare --step 0.01", "plot path under a regular file", "HDF5: non-JSON settings",
     "HDF5: integer mount names", "HDF5: wrong-shaped velocity", "HDF5: soft-link loop",
     "HDF5: empty rpm array", "HDF5: flipped bytes #1", "HDF5: flipped bytes #2",
     "HDF5: flipped bytes #3", "HDF5: flipped bytes #4"]))
@pytest.mark.slow
def test_issue_10_failures(worker, tmp_path, name):
    """Each named failure of the issue's campaign is now a clean error (or a finite result,
    e.g. flipped bytes in an unused part of the HDF5 file)."""
    case = fh.issue_cases()[name]
    outcome, detail = fh.run_case(worker, case, tmp_path / "case")
    assert outcome == "clean_error" or (outcome == "ok" and "flipped" in name), \
        f"{outcome}: {detail}"


@pytest.mark.slow
@pytest.mark.parametrize("kind", sorted(fh.KINDS))
def test_mutated_inputs_fail_cleanly_or_give_finite_results(worker, tmp_path, kind):
    @settings(max_examples=EXAMPLES, deadline=None, database=None,
              phases=[Phase.generate], suppress_health_check=list(HealthCheck))
    @given(st.data())
    def run(data):
        case = fh.KINDS[kind](data.draw)
        outcome, detail = fh.run_case(worker, case, tmp_path / "case")
        assert outcome not in fh.FAILURES, f"{case.description} {case.args}: {outcome}: {detail}"
    run()
