"""The sweep engine: run many run-up variants on any executor.

A :class:`SweepTask` is a small picklable description of one variant's run-up;
:func:`run_task` turns it into a :class:`~powertrain.results.runup.RunupResult` in whatever
process runs it; :func:`run_sweep` runs the tasks on :func:`powertrain.parallel.executor`
(a local process pool by default, a scheduler name or address, or an executor passed in,
e.g. a Dask client, left running), results in task order. docs/guide/parallel.md.
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
