"""The sweep engine: run many run-up variants on any executor.

A :class:`SweepTask` is a small picklable description -- the variant's engine (its operations
already applied), its response-level effects, speeds, solver -- and :func:`run_task` turns it
into a :class:`~powertrain.results.runup.RunupResult` in whatever process runs it.
:func:`run_sweep` runs the tasks on the one executor factory,
:func:`powertrain.parallel.executor` (through :func:`powertrain.parallel.run_map`): by default
a process pool on the local cores (serial for one task or ``workers=1``), or the scheduler
named (``serial``, ``processes``, ``local``, ``tcp://HOST:PORT``), or an executor passed in,
e.g. a Dask client::

      from distributed import Client
      client = Client("tcp://scheduler:8786")    # or Client() for a local cluster
      results = run_sweep(tasks, executor=client)

Only ``submit`` and the futures' ``result`` are used; results come back in task order; the
workers must have ``powertrain`` installed; an executor passed in is not shut down. Nothing in
the model knows which executor runs it.

BLAS inside :func:`powertrain.workflows.runup.run_runup` is limited to one thread, so one
process per core does not oversubscribe.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from powertrain.parallel import run_map
from powertrain.workflows.runup import run_runup, runup_with_effects


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
        result = runup_with_effects(task.engine, task.rpm, task.effects, solver=task.solver,
                                    **task.options)
    else:
        result = run_runup(task.engine, task.rpm, solver=task.solver, **task.options)
    return replace(result, meta={**result.meta, "variant": task.name})


def run_sweep(tasks, executor=None, *, workers: int | None = None, progress: bool = False):
    """Run the tasks, return their results in task order.

    Parameters
    ----------
    tasks : sequence of SweepTask
    executor : str, object with ``submit``, or None
        Where the tasks run (:func:`powertrain.parallel.executor`): None, a scheduler name
        or address, or an executor (a Dask ``distributed.Client``, a
        ``concurrent.futures`` executor...), used as is and left running.
    workers : int, optional
        Local processes (default: the usable cores; serial for one).
    progress : bool
        Progress bar over the tasks.

    Returns
    -------
    list of RunupResult
    """
    return run_map(run_task, tasks, executor, workers=workers,
                   progress="variants" if progress else None, unit="run-up")
