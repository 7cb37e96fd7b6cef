"""The sweep engine: run-up variants (picklable :class:`SweepTask`) on any executor
(:func:`powertrain.parallel.executor`), results in task order. docs/guide/parallel.md.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from powertrain.parallel import run_map
from powertrain.workflows.runup import run_runup, runup_with_effects


@dataclass(frozen=True)
class SweepTask:
    """One run-up of one variant: its ``engine`` at the speeds ``rpm`` [rpm], further
    ``options`` of :func:`powertrain.workflows.runup.run_runup` and response-level
    ``effects`` ``{effect: {parameter: value}}``."""

    name: str
    engine: object
    rpm: np.ndarray = field(default_factory=lambda: np.zeros(0))
    solver: str = "harmonic"
    options: dict = field(default_factory=dict)
    effects: dict = field(default_factory=dict)


def run_task(task: SweepTask):
    """The task's run-up (with its effects), ``meta["variant"]`` the task name."""
    if task.effects:
        result = runup_with_effects(task.engine, task.rpm, task.effects, solver=task.solver, **task.options)
    else:
        result = run_runup(task.engine, task.rpm, solver=task.solver, **task.options)
    return replace(result, meta={**result.meta, "variant": task.name})


def run_sweep(tasks, executor=None, *, workers: int | None = None, progress: bool = False):
    """Run the tasks, return their results in task order.

    Parameters
    ----------
    tasks : sequence of SweepTask
        The run-ups.
    executor : str, object with ``submit``, or None
        Where they run (:func:`powertrain.parallel.executor`): a scheduler name or address,
        or an executor, used as is and left running.
    workers : int, optional
        Local processes (default: the usable cores).
    progress : bool
        Progress bar over the tasks.
    """
    return run_map(run_task, tasks, executor, workers=workers,
                   progress="variants" if progress else None, unit="run-up")
