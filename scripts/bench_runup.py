#!/usr/bin/env python
"""Benchmark the run-up solvers on the same model at equal accuracy, in one process.

Runs, on the default engine (or ``--engine``):

* our Newmark stepper (Numba kernel, warm JIT), the whole run-up, as ``powertrain runup``
  runs it: the average-acceleration recurrence diagonalised once per model
  (:class:`powertrain.solvers.newmark.ModalNewmark`; identical to the physical-coordinate
  kernel to round-off, tests/test_runup.py) — the dense physical-coordinate kernel's time is
  printed too;
* a plain NumPy Newmark loop (the same recurrence, one Python iteration per step);
* ``scipy.integrate.solve_ivp`` with each stiff method (Radau, BDF, LSODA) on the first-order
  form of the same assembled model, from the same initial state, over the same six cycles,
  with the load linearly interpolated between the same crank-angle samples; the tolerance
  is tightened until its synthesis values agree with the harmonic solution to <= 0.5 %;
  the fastest method that reaches that accuracy counts.

Every solver's synthesis values are checked against the harmonic (frequency-domain) solution
(accuracy criterion <= 0.5 %). Timings are wall-clock per speed step (solver only: load
sampling and assembly excluded for all alike). The NumPy loop and solve_ivp run on a subset of
speeds (``--sample-speeds``) because they are slow; per-speed times are comparable.

Last line: ``newmark_s_per_speed=... numpy_s_per_speed=... solve_ivp_s_per_speed=...
ratio_vs_solve_ivp=...``
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.analysis.orders import order_spectrum, synthesis_rms
from powertrain.assembly import assemble
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.solvers.harmonic import harmonic_response
from powertrain.workflows.arguments import default_rpm
from powertrain.workflows.runup import run_runup

ACCURACY = 5e-3   # synthesis agreement with the harmonic solution, relative


def prepare(system, engine, rpm, angle_step_deg):
    n_cycle = int(round(720 / angle_step_deg))
    omega = rpm * 2 * np.pi / 60
    theta = np.arange(n_cycle) * 4 * np.pi / n_cycle
    load = engine.generalized_load(rpm, theta)
    fh = harmonic_amplitudes(load, axis=0)[: n_cycle // 2]
    omegas = 0.5 * omega * np.arange(fh.shape[0])
    qh = harmonic_response(system, fh, omegas)
    x0 = qh.real.sum(0)
    v0 = (1j * omegas[:, None] * qh).real.sum(0)
    a0 = (-(omegas ** 2)[:, None] * qh).real.sum(0)
    h = np.deg2rad(angle_step_deg) / omega
    return n_cycle, load, h, x0, v0, a0


def synthesis_from_velocity(system, V, n_cycle):
    v_ch = V[-2 * n_cycle:] @ system.channel_matrix.T
    return synthesis_rms(order_spectrum(v_ch, 4).T, axis=-1)


def numpy_newmark(M, C, K, F, h, x0, v0, a0):
    """The same average-acceleration recurrence as the kernel, in a NumPy loop."""
    S = M + 0.5 * h * C + 0.25 * h * h * K
    Sinv = np.linalg.inv(S)
    G, H = Sinv @ C, Sinv @ K
    Fs = F @ Sinv.T
    x, v, a = x0.copy(), v0.copy(), a0.copy()
    V = np.empty_like(F)
    V[0] = v
    for k in range(1, F.shape[0]):
        xt = x + h * v + 0.25 * h * h * a
        vt = v + 0.5 * h * a
        a = Fs[k] - G @ vt - H @ xt
        x = xt + 0.25 * h * h * a
        v = vt + 0.5 * h * a
        V[k] = v
    return V


def ivp_run(system, load, h, x0, v0, n_cycle, method, rtol):
    from scipy.integrate import solve_ivp
    n = system.n_dof
    Minv = np.linalg.inv(system.M)
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Minv @ system.K
    A[n:, n:] = -Minv @ system.C
    B6 = Minv[:, :6]
    n_steps = 6 * n_cycle
    t_grid = np.arange(n_steps + 1) * h
    L = np.concatenate([np.tile(load, (6, 1)), load[:1]])

    def rhs(t, z):
        k = min(int(t / h), n_steps - 1)
        s = t / h - k
        f = (1 - s) * L[k] + s * L[k + 1]
        dz = A @ z
        dz[n:] += B6 @ f
        return dz

    sol = solve_ivp(rhs, (0, t_grid[-1]), np.concatenate([x0, v0]), method=method,
                    t_eval=t_grid, rtol=rtol, atol=rtol * 1e-6, jac=lambda t, z: A)
    if not sol.success:
        raise RuntimeError(sol.message)
    return sol.y[n:].T, sol.nfev


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--engine", default=str(DEFAULT_ENGINE_PATH))
    ap.add_argument("--angle-step", type=float, default=1.0)
    ap.add_argument("--sample-speeds", default="1000,3500,6000",
                    help="speeds [rpm] for the slow solvers")
    ap.add_argument("--repeat", type=int, default=5, help="repeats of the warm Newmark run-up")
    args = ap.parse_args(argv)

    engine = read_engine(args.engine)
    b = engine.body
    system = assemble(b.mass, b.cg, b.inertia, engine.mounts)
    rpms = default_rpm()
    sample = np.array([float(s) for s in args.sample_speeds.split(",")])

    # cold start: first call in a fresh process (JIT compile or cache load)
    code = ("import time; t=time.perf_counter();"
            "from powertrain.iotools.engine_file import read_engine;"
            "from powertrain.workflows.runup import run_runup;"
            f"r=run_runup(read_engine({args.engine!r}));"
            "print(time.perf_counter()-t, r.solver_seconds)")
    cold = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    cold_total, cold_solver = (float(x) for x in cold.stdout.split())

    ref = run_runup(engine, rpms, solver="harmonic", system=system)
    ref_syn = ref.synthesis_rms()
    run_runup(engine, rpms, system=system, angle_step_deg=args.angle_step)   # warm the JIT
    best = np.inf
    for _ in range(args.repeat):
        t0 = time.perf_counter()
        res = run_runup(engine, rpms, system=system, angle_step_deg=args.angle_step)
        best = min(best, res.solver_seconds)
        wall = time.perf_counter() - t0
    err_nm = np.max(np.abs(res.synthesis_rms() / ref_syn - 1))
    newmark_s = best / rpms.size
    dense = min(run_runup(engine, rpms, system=system, angle_step_deg=args.angle_step,
                          stepper="dense").solver_seconds for _ in range(3))
    err_dense = np.max(np.abs(run_runup(engine, rpms, system=system, stepper="dense")
                              .synthesis_rms() / ref_syn - 1))
    print(f"dense physical-coordinate Newmark kernel: run-up solver time {dense:.4f} s "
          f"({dense / rpms.size:.5f} s per speed), max synthesis deviation vs harmonic "
          f"{100 * err_dense:.3f} %")
    print(f"Newmark (Numba): run-up of {rpms.size} speeds, "
          f"solver time {best:.4f} s warm "
          f"(best of {args.repeat}; wall incl. load sampling {wall:.3f} s), cold first run in a "
          f"fresh process {cold_total:.2f} s (solver {cold_solver:.2f} s); "
          f"max synthesis deviation vs harmonic {100 * err_nm:.3f} %")

    np_times, ivp_times, np_err, ivp_err, ivp_choice = [], [], [], [], []
    with threadpool_limits(limits=1, user_api="blas"):
        for rpm in sample:
            i_ref = int(np.argmin(np.abs(rpms - rpm)))
            r_ref = run_runup(engine, [rpm], solver="harmonic", system=system).synthesis_rms()[0]
            n_cycle, load, h, x0, v0, a0 = prepare(system, engine, rpm, args.angle_step)
            F = np.zeros((6 * n_cycle + 1, system.n_dof))
            F[:, :6] = np.concatenate([np.tile(load, (6, 1)), load[:1]])
            t0 = time.perf_counter()
            V = numpy_newmark(system.M, system.C, system.K, F, h, x0, v0, a0)
            np_times.append(time.perf_counter() - t0)
            np_err.append(np.max(np.abs(synthesis_from_velocity(system, V, n_cycle) / r_ref - 1)))
            best_ivp = (np.inf, None, None)
            for method in ("Radau", "BDF", "LSODA"):
                for rtol in (1e-4, 1e-5, 1e-6, 1e-7):
                    t0 = time.perf_counter()
                    try:
                        Vi, nfev = ivp_run(system, load, h, x0, v0, n_cycle, method, rtol)
                    except RuntimeError:
                        continue
                    dt = time.perf_counter() - t0
                    err = np.max(np.abs(synthesis_from_velocity(system, Vi, n_cycle) / r_ref - 1))
                    if err <= ACCURACY:
                        if dt < best_ivp[0]:
                            best_ivp = (dt, f"{method} rtol={rtol:g}", err)
                        break
            ivp_times.append(best_ivp[0])
            ivp_err.append(best_ivp[2])
            ivp_choice.append(best_ivp[1])
            print(f"{rpm:6.0f} rpm: numpy loop {np_times[-1]:.3f} s (dev {100 * np_err[-1]:.3f} %),"
                  f" solve_ivp best {best_ivp[1]} {best_ivp[0]:.3f} s "
                  f"(dev {100 * (best_ivp[2] or np.nan):.3f} %)", flush=True)
            del i_ref
    numpy_s = float(np.mean(np_times))
    ivp_s = float(np.mean(ivp_times))
    ok = err_nm <= ACCURACY and max(np_err) <= ACCURACY and np.all(np.isfinite(ivp_times))
    print(f"accuracy criterion (<= {100 * ACCURACY:.1f} % on synthesis vs harmonic) met by all: {ok}")
    print(f"targets: ratio_vs_solve_ivp >= 200: {ivp_s / newmark_s >= 200}; "
          f"run-up solver time <= 0.1 s: {best <= 0.1}")
    print(f"newmark_s_per_speed={newmark_s:.5f} numpy_s_per_speed={numpy_s:.4f} "
          f"solve_ivp_s_per_speed={ivp_s:.3f} ratio_vs_solve_ivp={ivp_s / newmark_s:.0f}")


if __name__ == "__main__":
    main()
