r"""The run-up orchestrator: engine -> assembled model -> solver -> order results.

For each speed step the load over one engine cycle is sampled at a constant crank-angle
increment. Two solvers give the periodic steady state of the same assembled linear model:

* ``newmark`` (default, the thesis's way): Newmark average-acceleration time integration in
  the Numba kernel over ``cycles`` engine cycles (6), processing the last ``processed_cycles``
  (2) by FFT. Every speed step starts from the periodic steady-state estimate (static preload
  plus the frequency-domain solution at t = 0), so the lightly damped rigid-body modes and
  the step of the mean torque do not pollute the window; the cycle-to-cycle periodicity of
  the processed window is reported and a warning raised above 0.1 %.
* ``harmonic``: the frequency-domain solve order by order
  (:mod:`powertrain.solvers.harmonic`), exact for the linear model and used as a cross-check.

The solver is chosen once per run (:func:`powertrain.solvers.steppers.choose_stepper`); a
run-up is then: speeds and time grid, the assembled model, the stepper, the cycle loads, one
solve per speed, the periodicity check, the result.
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np

from powertrain.analysis.orders import ORDERS
from powertrain.assembly import assemble
from powertrain.errors import InputError
from powertrain.progress import progress_bar
from powertrain.results.runup import RunupResult
from powertrain.solvers.steppers import Cycles, choose_stepper

#: Largest speed grid a run-up command accepts (about 0.1 s per speed step).
MAX_SPEEDS = 2000
#: Default crank-angle increment [deg]; halving it moves the results < 0.1 % (see tests).
ANGLE_STEP_DEG = 1.0
#: Cycles simulated per speed step and cycles processed (thesis sec. 4.4).
CYCLES = 6
PROCESSED_CYCLES = 2
#: Periodicity above which a warning is raised.
PERIODICITY_LIMIT = 1e-3
#: Speed steps run concurrently in threads (the Newmark kernel releases the GIL); serial by
#: default: on a busy 2-core machine threads were measured slower.
WORKERS = 1


class PeriodicityWarning(UserWarning):
    """The processed window is not periodic to the stated limit."""


def default_rpm(start=1000.0, stop=6000.0, step=500.0) -> np.ndarray:
    """Speed steps ``start, start + step, ... <= stop`` [rpm] (default: the thesis's 1000 to
    6000 rpm in 500 rpm steps, sec. 4.4)."""
    n = int(np.floor((stop - start) / step + 1e-9)) + 1
    return start + step * np.arange(n)


def _cycle_load(engine, rpm, n_per_cycle):
    theta = np.arange(n_per_cycle) * (4 * np.pi / n_per_cycle)
    load = np.asarray(engine.generalized_load(rpm, theta), float)
    if load.shape != (n_per_cycle, 6) or not np.all(np.isfinite(load)):
        raise ValueError("engine.generalized_load must return finite (n, 6) values")
    return load


def run_runup(*args, **kwargs) -> RunupResult:
    """Simulate a run-up (see :func:`_run_runup` for the parameters).

    BLAS is limited to one thread meanwhile: the model's matrices are small (~33×33), and
    OpenBLAS threads cost more than they give (5× slower on a busy 2-core machine).
    """
    from threadpoolctl import threadpool_limits
    with threadpool_limits(limits=1, user_api="blas"):
        return _run_runup(*args, **kwargs)


def _run_runup(engine, rpm=None, *, solver="newmark", angle_step_deg=ANGLE_STEP_DEG,
              cycles=CYCLES, processed_cycles=PROCESSED_CYCLES, progress=False,
              system=None, workers=WORKERS, stepper="auto") -> RunupResult:
    """Simulate a run-up: steady state at each speed, order analysis of the mount points.

    Parameters
    ----------
    engine : Engine
        Provides ``body`` (mass, cg, inertia), ``mounts`` and ``generalized_load``.
    rpm : array_like, optional
        Speed steps [rpm]; default 1000..6000 step 500.
    solver : {"newmark", "harmonic"}
    angle_step_deg : float
        Constant crank-angle increment [deg]; must divide 720 into an even number of steps.
    cycles, processed_cycles : int
        Engine cycles simulated and processed (Newmark only).
    progress : bool
        Show a progress bar over the speed steps.
    system : AssembledSystem, optional
        Pre-assembled model (default: assembled from ``engine``).
    workers : int
        Speed steps solved concurrently (threads; 1 = serial).
    stepper : {"auto", "modal", "dense"}
        Newmark implementation: ``modal`` (the same recurrence diagonalised once per model,
        :class:`~powertrain.solvers.newmark.ModalNewmark`; needs a regular mass matrix),
        ``dense`` (the physical-coordinate kernel) or ``auto`` (modal when possible).

    Returns
    -------
    RunupResult
    """
    rpm = _speeds(rpm)
    grid = _cycles(angle_step_deg, cycles, processed_cycles)
    if system is None:
        b = engine.body
        system = assemble(b.mass, b.cg, b.inertia, engine.mounts,
                          getattr(engine, "chassis", None))
    step = choose_stepper(system, solver, stepper, grid)
    loads = [_cycle_load(engine, n_rpm, grid.n_cycle) for n_rpm in rpm]
    speeds, seconds = _solve_speeds(step, rpm, loads, workers,
                                    {"desc": f"run-up ({solver})", "unit": "speed",
                                     "enabled": bool(progress)})
    _warn_periodicity(rpm, [o.periodicity for o in speeds])
    return _result(engine, system, step, rpm, speeds, step.setup_seconds + seconds)


def _speeds(rpm) -> np.ndarray:
    rpm = default_rpm() if rpm is None else np.atleast_1d(np.asarray(rpm, float))
    if np.any(rpm <= 0):
        raise ValueError("speeds must be positive")
    return rpm


def _cycles(angle_step_deg, cycles, processed_cycles) -> Cycles:
    n_cycle = 720.0 / angle_step_deg
    if abs(n_cycle - round(n_cycle)) > 1e-9 or round(n_cycle) % 2:
        raise ValueError("angle step must divide 720 deg into an even number of steps")
    if processed_cycles < 1 or cycles < processed_cycles:
        raise ValueError("need cycles >= processed_cycles >= 1")
    return Cycles(int(round(n_cycle)), angle_step_deg, cycles, processed_cycles)


def _solve_speeds(step, rpm, loads, workers, bar):
    """Every speed's :class:`SpeedOrders` and the solver time: summed per-speed solver
    times (serial), wall-clock if run concurrently."""
    omegas = rpm * 2 * np.pi / 60.0
    wall0 = time.perf_counter()
    if workers > 1 and rpm.size > 1:
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(step.solve, load, w) for load, w in zip(loads, omegas)]
            speeds = [fut.result() for fut in progress_bar(futures, **bar)]
    else:
        speeds = [step.solve(loads[i], omegas[i]) for i in progress_bar(range(rpm.size), **bar)]
    total = float(sum(o.seconds for o in speeds))
    if workers > 1:
        total = min(time.perf_counter() - wall0, total)
    return speeds, total


def _warn_periodicity(rpm, periodicity):
    for n_rpm, p in zip(rpm, periodicity):
        if p > PERIODICITY_LIMIT:
            warnings.warn(f"{n_rpm:g} rpm: processed window periodic only to "
                          f"{100 * p:.3g} % (> 0.1 %)", PeriodicityWarning, stacklevel=4)


def _result(engine, system, step, rpm, speeds, solver_seconds) -> RunupResult:
    def stack(name):
        return np.array([getattr(o, name) for o in speeds])

    chassis = system.chassis
    modes_hz, _ = system.rigid_body_modes()
    force = stack("force")
    paths = None
    if chassis is not None and not chassis.is_rigid and chassis.points:
        paths = path_contributions(system, rpm, force)
    return RunupResult(rpm=rpm, orders=ORDERS.copy(), channels=list(system.channels),
                       displacement=stack("displacement"), velocity=stack("velocity"),
                       acceleration=stack("acceleration"), mount_force=force,
                       mean_mount_force=stack("mean_force"),
                       periodicity=stack("periodicity"), settings=step.settings(),
                       solver_seconds=solver_seconds, rigid_body_modes_hz=modes_hz,
                       path_contribution=paths,
                       meta={"engine": getattr(engine, "name", ""),
                             "chassis": "rigid" if chassis is None else chassis.model,
                             "points": list(chassis.points) if chassis is not None else []})


def path_contributions(system, rpm, force) -> np.ndarray:
    r"""Velocity at every body-point channel carried by each mount path (mount × local
    direction), complex, per speed and order [m/s]:
    :math:`\hat v_{P,(m,d)} = i\omega\,\mathbf G_{Pm}(\omega)\,\mathbf e_d\,
    (\mathbf e_d\cdot\hat{\mathbf f}_m)`, :math:`\hat{\mathbf f}_m` the force mount m puts on
    the body (engine axes) and :math:`\mathbf G_{Pm}` the body's receptance. The paths of a
    point sum to its velocity (the body is loaded through the mounts only).

    Returns
    -------
    ndarray complex (n_rpm, 3 n_points, 3 n_mounts, n_orders)
    """
    ch = system.chassis
    mounts = system.mount_names
    n_a = system.n_mount_channels
    out = np.zeros((len(rpm), 3 * len(ch.points), n_a, ORDERS.size), complex)
    from scipy.linalg import block_diag
    E = block_diag(*system.mount_axes)          # column p: local axis of path p, at its mount
    w = np.outer(np.asarray(rpm, float) * 2 * np.pi / 60.0, ORDERS)      # (n_rpm, n_orders)
    G = ch.receptances(w, list(ch.points), mounts).reshape(w.shape + (3 * len(ch.points), n_a))
    GE = G @ E                                                     # (n_rpm, n_o, 3 n_p, n_a)
    f_local = np.einsum("ap,ika->ikp", E, np.moveaxis(force[:, :n_a, :], 1, 2))   # e_p . f
    out[:] = np.moveaxis(1j * w[..., None, None] * GE * f_local[:, :, None, :], 1, 3)
    return out


def engine_and_file(engine=None):
    """The engine to run and the file it came from: an Engine as it is (its ``file``), a
    path read, None the shipped ``engines/default.toml``."""
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    if engine is None or isinstance(engine, (str, os.PathLike)):
        path = str(engine or DEFAULT_ENGINE_PATH)
        return read_engine(path), path
    return engine, engine.file


def solved(solve, file, key):
    """``solve()``, with a model that cannot be solved (singular, overflow) reported as bad
    input naming ``file`` and ``key`` (the last guard: the checks at load catch the known
    causes first)."""
    try:
        with np.errstate(all="ignore"):
            return solve()
    except InputError:
        raise
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        raise InputError(f"the model cannot be solved ({type(exc).__name__}: "
                         f"{str(exc)[:120]})", file=file, key=key) from None


def require_finite(values: dict, file, key) -> None:
    """Refuse results holding NaN or inf (``values``: name -> array), naming the input."""
    for name, value in values.items():
        if value is not None and not np.all(np.isfinite(value)):
            raise InputError(f"the computed {name} is not finite (NaN or "
                             "inf): values out of any physical range", file=file, key=key)


def checked_runup(engine, engine_path, run, *args, **kwargs):
    """``run(engine, *args, **kwargs)`` (a run-up) through :func:`solved`, its result
    checked finite (errors name the engine file)."""
    result = solved(lambda: run(engine, *args, **kwargs), engine_path, "engine")
    require_finite({name.replace("_", " "): getattr(result, name) for name in (
        "displacement", "velocity", "acceleration", "mount_force", "mean_mount_force")},
        engine_path, "engine")
    return result
