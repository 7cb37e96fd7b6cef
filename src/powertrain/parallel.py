"""Where independent jobs run: serially, in local processes, or on a dask.distributed
cluster. :func:`executor` gives a ``concurrent.futures`` executor for a ``scheduler``
(docs/guide/parallel.md); :func:`run_map` returns results in submission order whatever the
choice.
"""

from __future__ import annotations

import functools
import os
import socket
import struct
from concurrent.futures import Future, ProcessPoolExecutor
from contextlib import contextmanager

from threadpoolctl import ThreadpoolController

from powertrain.errors import InputError
from powertrain.progress import progress_bar


@functools.cache
def _threadpools():
    return ThreadpoolController()


def single_blas_thread():
    """Context manager limiting BLAS to one thread: on the models' small (~33×33) matrices
    BLAS threads cost more than they give."""
    return _threadpools().limit(limits=1, user_api="blas")


class SerialExecutor:
    """``concurrent.futures``-like executor running every job at submission."""

    def submit(self, fn, *args, **kwargs) -> Future:
        fut = Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except BaseException as exc:  # noqa: BLE001 (handed to the caller via the future)
            fut.set_exception(exc)
        return fut

    def map(self, fn, *iterables):
        return [fn(*a) for a in zip(*iterables)]

    def shutdown(self, wait=True):
        return None


def cpu_count() -> int:
    """Cores this process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:              # pragma: no cover (not Linux)
        return os.cpu_count() or 1


def check_scheduler(scheduler, *, reach: bool = False) -> str:
    """Normalised scheduler name; InputError (key ``--scheduler``) if not understood.
    ``reach``: also check that a dask scheduler answers (:func:`probe_scheduler`)."""
    s = "auto" if scheduler in (None, "") else str(scheduler).strip()
    if s in ("auto", "serial", "processes", "local"):
        return s
    if s.startswith("tcp://"):
        scheduler_host_port(s)
        if reach:
            probe_scheduler(s)
        return s
    raise InputError(f"{s!r}: expected 'local', 'serial', 'processes' or tcp://HOST:PORT",
                     key="--scheduler")


def scheduler_host_port(address: str) -> tuple[str, int]:
    """(host, port) of ``tcp://HOST:PORT`` (``[IPv6]:PORT`` too)."""
    host, sep, port = address[len("tcp://"):].rpartition(":")
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    if not (sep and host and port.isdigit() and 1 <= int(port) <= 65535
            and len(host) <= 253 and not any(c in host for c in "/@ ")):
        raise InputError(f"{address!r}: expected tcp://HOST:PORT with a port 1..65535",
                         key="--scheduler")
    return host, int(port)


#: Seconds to wait for a dask scheduler to connect and greet.
CONNECT_TIMEOUT_S = 10.0


def probe_scheduler(address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
    """Raise InputError unless a dask scheduler answers at ``address`` within ``timeout``
    [s]: a dask scheduler greets every connection first with a frame header (total length,
    number of frames: unsigned 64-bit little-endian)."""
    host, port = scheduler_host_port(address)
    try:
        with socket.create_connection((host, port), timeout=timeout) as sock:
            sock.settimeout(timeout)
            head = b""
            while len(head) < 16:
                chunk = sock.recv(16 - len(head))
                if not chunk:
                    break
                head += chunk
    except TimeoutError:
        raise InputError(f"no dask scheduler answered at {address} within {timeout:g} s",
                         key="--scheduler") from None
    except OSError as exc:
        raise InputError(f"cannot reach the dask scheduler at {address} "
                         f"({exc.strerror or exc})", key="--scheduler") from None
    total, frames = struct.unpack("<QQ", head) if len(head) == 16 else (0, 0)
    if not (16 < total < 2 ** 26 and 1 <= frames <= 64):
        raise InputError(f"what answers at {address} is not a dask scheduler",
                         key="--scheduler")


@contextmanager
def executor(scheduler=None, *, workers=None, n_jobs=None):
    """The executor for ``scheduler``; one opened here is shut down on exit, pending jobs
    cancelled if the block raised.

    Parameters
    ----------
    scheduler : str, executor or None
        ``None``/``"auto"``, ``"serial"``, ``"processes"``, ``"local"``,
        ``"tcp://HOST:PORT"``, or an object with ``submit`` (yielded as it is).
    workers : int, optional
        Local processes (default :func:`cpu_count`, at most ``n_jobs``).
    n_jobs : int, optional
        Jobs about to be submitted (``auto`` runs one job serially).

    Raises
    ------
    InputError
        ``scheduler`` not understood, or ``workers`` < 1.
    """
    if hasattr(scheduler, "submit"):
        yield scheduler
        return
    s = check_scheduler(scheduler)
    if workers is not None and workers < 1:
        raise InputError("must be >= 1", key="--workers")
    n = workers or cpu_count()
    if n_jobs is not None:
        n = max(1, min(n, n_jobs))
    if s == "auto":
        s = "serial" if n <= 1 else "processes"
    if s == "serial":
        yield SerialExecutor()
    elif s == "processes":
        pool = ProcessPoolExecutor(max_workers=n)
        try:
            yield pool
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
    else:
        with _dask_client(s, n) as client:
            yield client


@contextmanager
def _dask_client(address, n):
    try:
        from distributed import Client, LocalCluster  # deferred: heavy optional package
    except ImportError as exc:          # pragma: no cover (declared dependency)
        raise InputError("dask.distributed is not installed (pip install 'dask[distributed]')",
                         key="--scheduler") from exc
    if address == "local":
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            yield client
        return
    probe_scheduler(address)
    try:
        client = Client(address, timeout=f"{CONNECT_TIMEOUT_S:g}s")
    except OSError as exc:
        raise InputError(f"cannot reach the dask scheduler at {address} ({exc})",
                         key="--scheduler") from exc
    try:
        yield client
    finally:
        client.close()


def run_map(fn, items, scheduler=None, *, workers=None, progress=None, unit="job"):
    """``[fn(x) for x in items]`` on the executor of ``scheduler`` (:func:`executor`), in the
    order of ``items``; ``progress``: description of a tqdm bar on stderr (terminal only)
    counting ``unit``."""
    items = list(items)
    with executor(scheduler, workers=workers, n_jobs=len(items)) as ex:
        futures = [ex.submit(fn, x) for x in items]
        out = []
        with progress_bar(enabled=bool(progress), total=len(futures), desc=progress,
                          unit=unit) as bar:
            for f in futures:
                out.append(f.result())
                bar.update(1)
    return out
