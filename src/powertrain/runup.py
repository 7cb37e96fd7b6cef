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
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.analysis.orders import ORDERS, order_spectrum
from powertrain.assembly import assemble
from powertrain.progress import progress_bar
from powertrain.results import RunupResult
from powertrain.solvers.harmonic import harmonic_response
from powertrain.solvers.newmark import ModalNewmark, newmark

#: Default crank-angle increment [deg]; halving it moves the results < 0.1 % (see tests).
ANGLE_STEP_DEG = 1.0
#: Cycles simulated per speed step and cycles processed (thesis sec. 4.4).
CYCLES = 6
PROCESSED_CYCLES = 2
#: Periodicity above which a warning is raised.
PERIODICITY_LIMIT = 1e-3
#: Highest order in the frequency-domain initial-state estimate of the Newmark run (the
#: stepper itself sees the full sampled load): load harmonics above order 40 are < 2e-5 of
#: the 2nd order for the default engine, and their response is smaller still.
INITIAL_STATE_MAX_ORDER = 40.0
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


def _outputs(system, q, v, a):
    """Channel displacement, velocity, acceleration and mount forces from states (n_t, n)."""
    Cm = system.channel_matrix
    return (q @ Cm.T, v @ Cm.T, a @ Cm.T,
            q @ system.force_matrix_k.T + v @ system.force_matrix_d.T)


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
    if solver not in ("newmark", "harmonic"):
        raise ValueError(f"unknown solver {solver!r}")
    rpm = default_rpm() if rpm is None else np.atleast_1d(np.asarray(rpm, float))
    if np.any(rpm <= 0):
        raise ValueError("speeds must be positive")
    n_cycle = 720.0 / angle_step_deg
    if abs(n_cycle - round(n_cycle)) > 1e-9 or round(n_cycle) % 2:
        raise ValueError("angle step must divide 720 deg into an even number of steps")
    n_cycle = int(round(n_cycle))
    if processed_cycles < 1 or cycles < processed_cycles:
        raise ValueError("need cycles >= processed_cycles >= 1")
    if system is None:
        b = engine.body
        system = assemble(b.mass, b.cg, b.inertia, engine.mounts,
                          getattr(engine, "chassis", None))
    chassis = getattr(system, "chassis", None)
    if solver == "newmark" and chassis is not None and chassis.model == "frf":
        from powertrain.errors import InputError
        raise InputError("a measured-receptance chassis (model = \"frf\") is coupled in the "
                         "frequency domain only: use the harmonic solver",
                         file=chassis.file or None, key="chassis.model")
    n_ch = len(system.channels)
    shape = (rpm.size, n_ch, ORDERS.size)
    disp = np.zeros(shape, complex)
    vel = np.zeros(shape, complex)
    acc = np.zeros(shape, complex)
    force = np.zeros(shape, complex)
    mean_force = np.zeros((rpm.size, n_ch))
    periodicity = np.zeros(rpm.size)
    bar = {"desc": f"run-up ({solver})", "unit": "speed", "enabled": bool(progress)}
    loads = [_cycle_load(engine, n_rpm, n_cycle) for n_rpm in rpm]
    timings = np.zeros(rpm.size)
    modal = None
    t_setup = time.perf_counter()
    if solver == "newmark" and stepper in ("auto", "modal"):
        try:
            modal = ModalNewmark(system.M, system.C, system.K, load_dofs=6)
        except np.linalg.LinAlgError:
            if stepper == "modal":
                raise
        if modal is not None:
            Z = np.zeros_like(system.channel_matrix)
            W_modal, W_load = modal.output_map(
                np.vstack([system.channel_matrix, Z, Z, system.force_matrix_k]),
                np.vstack([Z, system.channel_matrix, Z, system.force_matrix_d]),
                np.vstack([Z, Z, system.channel_matrix, Z]))
    elif stepper not in ("auto", "modal", "dense"):
        raise ValueError(f"unknown stepper {stepper!r}")
    t_setup = time.perf_counter() - t_setup

    def solve_speed(i):
        n_rpm = rpm[i]
        omega = n_rpm * 2 * np.pi / 60.0
        load = loads[i]
        t0 = time.perf_counter()
        # harmonics of the cycle: index j is order j/2
        n_h = n_cycle // 2 if solver == "harmonic" else \
            min(n_cycle // 2, int(2 * INITIAL_STATE_MAX_ORDER) + 1)
        fh = harmonic_amplitudes(load, axis=0)[:n_h]
        omegas = 0.5 * omega * np.arange(fh.shape[0])
        if modal is not None:
            h = np.deg2rad(angle_step_deg) / omega
            x0, v0 = modal.harmonic_state(fh, omegas)
            start = (cycles - processed_cycles) * n_cycle
            Y = modal.run_outputs(load, cycles, h, x0, v0, start, W_modal, W_load)
            timings[i] = time.perf_counter() - t0
            d_c, v_c, a_c, f_c = (Y[:-1, k * n_ch:(k + 1) * n_ch] for k in range(4))
            _post(i, d_c, v_c, a_c, f_c, None)
            return
        if chassis is not None and chassis.model == "frf":
            disp[i], vel[i], acc[i], force[i], mean_force[i] = frf_orders(system, fh, omegas)
            return
        qh = harmonic_response(system, fh, omegas)
        if solver == "harmonic":
            j = np.round(ORDERS * 2).astype(int)
            w = omegas[j][:, None]
            q_o = qh[j]                                   # (n_orders, n)
            disp[i] = (q_o @ system.channel_matrix.T).T
            vel[i] = (1j * w * q_o @ system.channel_matrix.T).T
            acc[i] = (-(w ** 2) * q_o @ system.channel_matrix.T).T
            force[i] = ((q_o @ system.force_matrix_k.T)
                        + 1j * w * (q_o @ system.force_matrix_d.T)).T
            mean_force[i] = system.force_matrix_k @ qh[0].real
            timings[i] = time.perf_counter() - t0
            return
        h = np.deg2rad(angle_step_deg) / omega
        # periodic steady-state estimate at t = 0: static preload + harmonic solution
        x0 = qh.real.sum(axis=0)
        v0 = (1j * omegas[:, None] * qh).real.sum(axis=0)
        a0 = (-(omegas ** 2)[:, None] * qh).real.sum(axis=0)
        n_steps = cycles * n_cycle
        F = np.zeros((n_steps + 1, system.n_dof))
        F[:, :6] = np.concatenate([np.tile(load, (cycles, 1)), load[:1]])
        X, V, A = newmark(system.M, system.C, system.K, F, h, x0, v0, a0)
        timings[i] = time.perf_counter() - t0
        start = (cycles - processed_cycles) * n_cycle
        win = slice(start, start + processed_cycles * n_cycle)
        d_c, v_c, a_c, f_c = _outputs(system, X[win], V[win], A[win])
        _post(i, d_c, v_c, a_c, f_c, (X, V, A, start))

    def _post(i, d_c, v_c, a_c, f_c, states):
        """Order analysis and periodicity of the processed window (Newmark)."""
        revs = 2 * processed_cycles
        disp[i] = order_spectrum(d_c, revs).T
        vel[i] = order_spectrum(v_c, revs).T
        acc[i] = order_spectrum(a_c, revs).T
        force[i] = order_spectrum(f_c, revs).T
        mean_force[i] = f_c.mean(axis=0)
        # cycle-to-cycle periodicity of the processed window (velocity channels)
        if processed_cycles >= 2:
            prev = v_c[:n_cycle]
            last = v_c[-n_cycle:]
        elif states is not None:
            X, V, A, start = states
            _, vp, _, _ = _outputs(system, X[start - n_cycle:start], V[start - n_cycle:start],
                                   A[start - n_cycle:start])
            prev, last = vp, v_c
        else:
            raise ValueError("the modal stepper needs processed_cycles >= 2; use "
                             "stepper='dense'")
        scale = np.max(np.abs(last)) or 1.0
        periodicity[i] = np.max(np.abs(last - prev)) / scale

    wall0 = time.perf_counter()
    if workers > 1 and rpm.size > 1:
        from concurrent.futures import ThreadPoolExecutor
        with ThreadPoolExecutor(max_workers=workers) as pool:
            futures = [pool.submit(solve_speed, i) for i in range(rpm.size)]
            for fut in progress_bar(futures, **bar):
                fut.result()
    else:
        for i in progress_bar(range(rpm.size), **bar):
            solve_speed(i)
    wall = time.perf_counter() - wall0
    # solver time: summed per-speed solver times (serial); wall-clock if run concurrently
    solver_seconds = t_setup + (float(timings.sum()) if workers <= 1
                                else min(wall, float(timings.sum())))
    for n_rpm, p in zip(rpm, periodicity):
        if p > PERIODICITY_LIMIT:
            warnings.warn(f"{n_rpm:g} rpm: processed window periodic only to "
                          f"{100 * p:.3g} % (> 0.1 %)", PeriodicityWarning, stacklevel=3)
    settings = {"solver": solver, "angle_step_deg": angle_step_deg,
                "cycles": cycles if solver == "newmark" else 0,
                "processed_cycles": processed_cycles if solver == "newmark" else 0,
                "integrator": "Newmark average acceleration (beta=1/4, gamma=1/2), "
                + ("modal (diagonalised recurrence)" if modal is not None else "dense")
                if solver == "newmark" else "harmonic steady state per order",
                "initial_state": "static preload + frequency-domain steady state at t=0 "
                f"(orders <= {INITIAL_STATE_MAX_ORDER:g})"
                if solver == "newmark" else ""}
    modes_hz, _ = system.rigid_body_modes()
    paths = None
    if chassis is not None and not chassis.is_rigid and chassis.points:
        paths = path_contributions(system, rpm, force)
    return RunupResult(rpm=rpm, orders=ORDERS.copy(), channels=list(system.channels),
                       displacement=disp, velocity=vel, acceleration=acc, mount_force=force,
                       mean_mount_force=mean_force, periodicity=periodicity,
                       settings=settings, solver_seconds=solver_seconds,
                       rigid_body_modes_hz=modes_hz, path_contribution=paths,
                       meta={"engine": getattr(engine, "name", ""),
                             "chassis": "rigid" if chassis is None else chassis.model,
                             "points": list(chassis.points) if chassis is not None else []})


def frf_orders(system, fh, omegas):
    """One speed's order amplitudes with a measured-receptance body (admittance coupling,
    :func:`powertrain.solvers.admittance.frf_response`): displacement, velocity,
    acceleration, transmitted force, each (n_ch, n_orders) complex, and the mean force (n_ch,).
    """
    from powertrain.solvers.admittance import frf_response
    j = np.round(ORDERS * 2).astype(int)
    q, body, fb = frf_response(system, fh[j], omegas[j])
    n_a = system.n_mount_channels
    x = np.hstack([q @ system.channel_matrix[:n_a].T, body])          # (n_orders, n_ch)
    w = omegas[j][:, None]
    n_rest = x.shape[1] - 2 * n_a
    force = np.hstack([fb, fb, np.zeros((len(j), n_rest))])
    _, _, f0 = frf_response(system, fh[:1], omegas[:1])
    mean_force = np.hstack([f0[0].real, f0[0].real, np.zeros(n_rest)])
    return x.T, (1j * w * x).T, (-(w ** 2) * x).T, force.T, mean_force


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
