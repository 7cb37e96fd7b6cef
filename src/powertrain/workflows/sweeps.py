"""The sweep engine: run many run-up variants on any executor.

A :class:`SweepTask` is a small picklable description -- the variant's engine (its operations
already applied), its response-level effects, speeds, solver -- and :func:`run_task` turns it
into a :class:`~powertrain.results.runup.RunupResult` in whatever process runs it.
:func:`run_sweep` hands the tasks to an *executor*: anything with the
:class:`concurrent.futures.Executor` method ``submit(fn, *args) -> future`` whose futures have
``result()``. Only ``submit`` and ``result`` are used (not ``map``, whose return type differs
between libraries), results come back in task order.

* default: :class:`concurrent.futures.ProcessPoolExecutor` on the local cores
  (``workers`` processes, default ``os.cpu_count()``), created and shut down here;
* ``workers=1`` (or a single task): :class:`SerialExecutor`, in this process;
* a distributed engine: pass its client, e.g. Dask::

      from distributed import Client
      client = Client("tcp://scheduler:8786")    # or Client() for a local cluster
      results = run_sweep(tasks, executor=client)

  ``distributed.Client.submit(fn, *args)`` returns a future with ``.result()``, which is all
  :func:`run_sweep` needs; the workers must have ``powertrain`` installed. An executor passed
  in is not shut down. Nothing in the model knows which executor runs it.

BLAS inside :func:`powertrain.workflows.runup.run_runup` is limited to one thread, so one process per
core does not oversubscribe.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace

import numpy as np

from powertrain.parallel import SerialExecutor  # noqa: F401 (one serial executor)


@dataclass(frozen=True)
class SweepTask:
    """One run-up of one variant.

    Attributes
    ----------
    name : str
        Variant name (``baseline`` for no operation).
    engine : Engine
        The variant's engine (its operations applied,
        :func:`powertrain.workflows.whatif.variant_engine`).
    rpm : ndarray
        Speed steps [rpm].
    solver : {"harmonic", "newmark"}
    options : dict
        Further keyword arguments of :func:`powertrain.workflows.runup.run_runup`
        (``angle_step_deg``...).
    effects : dict
        Response-level effects ``{effect: {parameter: value}}`` (amplitude-dependent mounts,
        sensor errors) run by :func:`powertrain.workflows.runup.runup_with_effects`.
    """

    name: str
    engine: object
    rpm: np.ndarray = field(default_factory=lambda: np.zeros(0))
    solver: str = "harmonic"
    options: dict = field(default_factory=dict)
    effects: dict = field(default_factory=dict)


def run_task(task: SweepTask):
    """Run the task's run-up (with its response-level effects, if any).

    Returns
    -------
    RunupResult
        ``meta["variant"]`` holds the task name.
    """
    if task.effects:
        from powertrain.workflows.runup import runup_with_effects
        result = runup_with_effects(task.engine, task.rpm, task.effects, solver=task.solver,
                                    **task.options)
    else:
        from powertrain.workflows.runup import run_runup
        result = run_runup(task.engine, task.rpm, solver=task.solver, **task.options)
    return replace(result, meta={**result.meta, "variant": task.name})


def default_workers() -> int:
    """Local cores (``os.cpu_count()``, at least 1)."""
    return max(1, os.cpu_count() or 1)


def run_sweep(tasks, executor=None, *, workers: int | None = None, progress: bool = False):
    """Run the tasks, return their results in task order.

    Parameters
    ----------
    tasks : sequence of SweepTask
    executor : object with ``submit``, optional
        Default: a process pool of ``workers`` processes (serial when ``workers == 1`` or
        one task), shut down on return. Any given executor (a Dask ``distributed.Client``,
        a ``ThreadPoolExecutor``...) is used as is and left running.
    workers : int, optional
        Processes of the default pool (default :func:`default_workers`).
    progress : bool
        Progress bar over the tasks.

    Returns
    -------
    list of RunupResult
    """
    tasks = list(tasks)
    if workers is not None and workers < 1:
        raise ValueError("workers must be >= 1")
    own = None
    if executor is None:
        n = min(workers or default_workers(), len(tasks))
        if n <= 1:
            executor = SerialExecutor()
        else:
            from concurrent.futures import ProcessPoolExecutor
            executor = own = ProcessPoolExecutor(max_workers=n)
    try:
        futures = [executor.submit(run_task, t) for t in tasks]
        from powertrain.progress import progress_bar
        bar = progress_bar(futures, enabled=progress, desc="variants", unit="run-up")
        return [f.result() for f in bar]
    finally:
        if own is not None:
            own.shutdown(cancel_futures=True)
