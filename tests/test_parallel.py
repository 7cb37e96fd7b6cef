"""powertrain.parallel: every scheduler gives the serial results, in order."""

from __future__ import annotations

import pytest

from powertrain.errors import InputError
from powertrain.parallel import check_scheduler, executor, run_map


def _square(x):
    return x * x


@pytest.mark.parametrize("scheduler", [None, "serial", "processes"])
def test_local_schedulers_match_serial(scheduler):
    assert run_map(_square, range(7), scheduler, workers=2) == [x * x for x in range(7)]


def test_dask_local_cluster_matches_serial():
    pytest.importorskip("distributed")
    assert run_map(_square, range(5), "local", workers=1) == [x * x for x in range(5)]


@pytest.mark.parametrize("bad", ["tcp://nohost", "cluster", "udp://a:1"])
def test_bad_scheduler_is_one_line_input_error(bad):
    with pytest.raises(InputError) as e:
        check_scheduler(bad)
    assert "--scheduler" in str(e.value) and "\n" not in str(e.value)


def test_serial_executor_hands_exceptions_to_the_future():
    with executor("serial") as ex:
        fut = ex.submit(int, "x")
    with pytest.raises(ValueError):
        fut.result()
