"""powertrain.parallel: every scheduler gives the serial results, in order."""

from __future__ import annotations

import pytest

from powertrain.errors import InputError
from powertrain.parallel import check_scheduler, executor, probe_scheduler, run_map


def _square(x):
    return x * x


@pytest.mark.parametrize("scheduler", [None, "serial", "processes"])
def test_local_schedulers_match_serial(scheduler):
    assert run_map(_square, range(7), scheduler, workers=2) == [x * x for x in range(7)]


@pytest.mark.slow
def test_dask_local_cluster_matches_serial():
    pytest.importorskip("distributed")
    assert run_map(_square, range(5), "local", workers=1) == [x * x for x in range(5)]


@pytest.mark.parametrize("bad", ["tcp://nohost", "cluster", "udp://a:1", "tcp://host:notaport",
                                 "tcp://:99", "tcp://h:0", "tcp://h:65536", "tcp://a b:1"])
def test_bad_scheduler_is_one_line_input_error(bad):
    with pytest.raises(InputError) as e:
        check_scheduler(bad)
    assert "--scheduler" in str(e.value) and "\n" not in str(e.value)


def _server(behaviour):
    """A TCP server on a free local port: ``silent`` accepts and never answers, ``http``
    answers like a web server, ``closed`` nothing listens. Returns (address, stop)."""
    import socket
    import threading
    sock = socket.socket()
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    if behaviour == "closed":
        sock.close()
        return f"tcp://127.0.0.1:{port}", lambda: None
    sock.listen(4)
    held = []

    def serve():
        try:
            while True:
                conn, _ = sock.accept()
                held.append(conn)
                if behaviour == "http":
                    conn.sendall(b"HTTP/1.0 400 Bad request\r\nContent-Length: 0\r\n\r\n")
        except OSError:
            pass
    threading.Thread(target=serve, daemon=True).start()

    def stop():
        sock.close()
        for c in held:
            c.close()
    return f"tcp://127.0.0.1:{port}", stop


@pytest.mark.parametrize("behaviour,words", [("silent", "no dask scheduler answered"),
                                             ("http", "not a dask scheduler"),
                                             ("closed", "cannot reach")])
def test_address_where_no_scheduler_answers_is_refused_in_time(behaviour, words):
    """Issue 18: an HTTP server (3 EiB allocation) or a silent one (hang) behind the
    address: a one-line error within the timeout."""
    import time
    address, stop = _server(behaviour)
    t0 = time.perf_counter()
    try:
        with pytest.raises(InputError) as e:
            check_scheduler(address, reach=True) if behaviour != "silent" else \
                probe_scheduler(address, timeout=0.5)
    finally:
        stop()
    assert words in str(e.value) and "--scheduler" in str(e.value)
    assert time.perf_counter() - t0 < 5.0


def test_a_real_scheduler_passes_the_probe():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=0, dashboard_address=None, processes=False,
                                  protocol="tcp://") as cluster:
        probe_scheduler(cluster.scheduler_address)


def test_a_given_executor_is_used_as_is_and_left_running():
    """The factory yields an executor passed in (a dask Client, a concurrent.futures pool)
    and does not shut it down."""
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(max_workers=2) as pool:
        with executor(pool) as ex:
            assert ex is pool
        assert run_map(_square, range(4), pool) == [0, 1, 4, 9]
        assert pool.submit(_square, 3).result() == 9         # still running


def test_auto_runs_one_job_or_one_worker_serially():
    from powertrain.parallel import SerialExecutor
    for kwargs in ({"n_jobs": 1}, {"workers": 1, "n_jobs": 5}, {"n_jobs": 0}):
        with executor(None, **kwargs) as ex:
            assert isinstance(ex, SerialExecutor)


def test_workers_below_one_is_one_line_input_error():
    with pytest.raises(InputError) as e:
        run_map(_square, range(3), "processes", workers=0)
    assert "--workers" in str(e.value) and "\n" not in str(e.value)


def test_a_failing_job_cancels_the_pending_ones():
    """A job that raises ends the map at once: the pool's pending jobs are cancelled, not run
    to the end."""
    import time
    t0 = time.perf_counter()
    with pytest.raises(ZeroDivisionError):
        run_map(_slow_inverse, [0] + [1] * 8, "processes", workers=1)
    assert time.perf_counter() - t0 < 4.0


def _slow_inverse(x):
    import time
    if x:
        time.sleep(1.0)
    return 1 / x


def test_serial_executor_hands_exceptions_to_the_future():
    with executor("serial") as ex:
        fut = ex.submit(int, "x")
    with pytest.raises(ValueError):
        fut.result()


@pytest.mark.slow
def test_diagnosis_candidate_fits_on_a_local_dask_cluster_equal_serial():
    """The candidate fits of one diagnosis on a dask LocalCluster give the serial answer,
    number for number (each fit is a pure function of its problem)."""
    pytest.importorskip("distributed")
    import numpy as np

    from powertrain.analysis.orders import order_label
    from powertrain.diagnosis import diagnose
    from powertrain.effects import predict
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.iotools.measured import MeasuredRunup
    from powertrain.solvers.fast_harmonic import HarmonicModel
    eng = read_engine(DEFAULT_ENGINE_PATH)
    rpm = np.arange(1000.0, 6000.1, 100.0)
    v = predict(HarmonicModel(eng, rpm), {"balancer_error": {"gain": 0.7}}).velocity
    rng = np.random.default_rng(115)
    lev = np.abs(v) / np.sqrt(2) * 10 ** (rng.normal(0, 0.5, v.shape) / 20)
    curves = {(m, d, order_label(o)): (rpm, lev[:, 3 * i + j, int(2 * o) - 1])
              for i, m in enumerate(eng.mount_names) for j, d in enumerate("xyz")
              for o in (0.5, 1.0, 2.0, 4.0)}
    meas = MeasuredRunup(curves, source="SYNTHETIC (test)")
    kw = dict(noise_floor=1e-7, effects=["balancer_error", "mount_stiffness"],
              band_check=False, progress=False)
    a = diagnose(meas, eng, scheduler="serial", **kw).to_dict()
    b = diagnose(meas, eng, scheduler="local", **kw).to_dict()
    assert a["verdict"] == b["verdict"]
    for x, y in zip(a["ranking"], b["ranking"]):
        assert x["effect"] == y["effect"] and x["parameters"] == y["parameters"]
        assert x["heldout_rms_db_after"] == y["heldout_rms_db_after"]
