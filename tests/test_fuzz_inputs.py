"""Bad input, all of it (issue 10, item 6): property-based campaign over every input kind.

Hypothesis mutates valid seeds of every input kind -- engine TOML, mount TOML, pressure CSV,
stiffness CSV, measured CSV and HDF5, what-if variants TOML, raw time-data CSV (``track``)
and option specs (``--freq``, ``--effect``, ``--scale``, ``--set``, ``--move``,
``--rotate``, ``--target``, speeds, seeds)
-- and runs the command that reads it (``tests/fuzz_harness.py``). Every run must end in a
clean one-line error naming the file or option (exit 1, no output file) or in a finite
result; never a traceback, a hang, NaN/inf in an output, or a leftover file.

Examples per kind are bounded here (``FUZZ_EXAMPLES``, default 6) to keep CI short;
``python scripts/fuzz_inputs.py`` runs the long campaign and prints the counts.
Every failure issue 10 lists is also replayed by name (``test_issue_10_failures``).
"""

from __future__ import annotations

import os

import fuzz_harness as fh
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

EXAMPLES = int(os.environ.get("FUZZ_EXAMPLES", "6"))


@pytest.fixture(scope="module")
def worker(tmp_path_factory):
    w = fh.Worker()
    fh.seeds(w, tmp_path_factory.mktemp("seeds"))
    yield w
    w.close()


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
def test_issue_10_failures(worker, tmp_path, name):
    """Each named failure of the issue's campaign is now a clean error (or a finite result,
    e.g. flipped bytes in an unused part of the HDF5 file)."""
    case = fh.issue_cases()[name]
    outcome, detail = fh.run_case(worker, case, tmp_path / "case")
    assert outcome == "clean_error" or (outcome == "ok" and "flipped" in name), \
        f"{outcome}: {detail}"


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
