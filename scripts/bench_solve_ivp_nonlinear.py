#!/usr/bin/env python
"""Our Newmark kernel with Berg's friction against ``scipy.integrate.solve_ivp`` on the same
nonlinear system at equal accuracy (issue 20, item 8), in one process.

The system: the default engine with Berg's element (40 N, x2 = 0.05 mm) on every mount
direction, at 3000 rpm, ``--cycles`` engine cycles from the same start (the harmonic fixed
point, the friction on its steady loop, :mod:`powertrain.solvers.cycle_newmark`).

* ours: :func:`powertrain.solvers.newmark.newmark_ports` (Newmark average acceleration,
  Newton per step in the Numba kernel) at the run-up's 1 deg step;
* peer: ``solve_ivp`` (Radau, BDF, LSODA) on the first-order form ``(x, v, F)``, the
  friction forces as states: on a branch from its reversal point ``(x_s, F_s)`` Berg's law
  is ``dF/du = F_max (F_max - d F)^2 / (x2 (F_max - d F_s)^2)`` (d = the direction), a
  reversal (``du/dt = 0``) is a terminal event that starts the element's next branch; the
  load linearly interpolated between the same crank-angle samples as ours.

Accuracy: each against a fine-step reference, our kernel at 1/32 deg (its error falls as the
step squared: ~1000 times below the 1 deg run's); the largest error of the mount-point
velocities over the last cycle relative to their largest value. ``solve_ivp`` at its tightest
tolerance against the same reference is printed too (an independent method agreeing with it).
The peer's tolerance is tightened (rtol 1e-3, 1e-4, ...) until its error is at most ours; the
fastest method that gets there counts. CPU time (``time.process_time``), ours warm.

Last line: ``newmark_s=... solve_ivp_s=... ratio=...`` (solve_ivp over ours).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from bench_nonlinear_runup import BERG, with_laws
from scipy.integrate import solve_ivp

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.solvers.cycle_newmark import steady_loop_state
from powertrain.solvers.newmark import newmark_ports
from powertrain.solvers.steppers import Cycles, DenseNewmarkStepper

RPM = 3000.0


def problem(cycles):
    """Model, load samples, step, start state and the friction laws' start states."""
    engine = with_laws(read_engine(DEFAULT_ENGINE_PATH), port_law=BERG)
    system = engine.assemble()
    grid = Cycles(720, 1.0, cycles, 1)
    stepper = DenseNewmarkStepper(system, grid)
    omega = RPM * np.pi / 30.0
    theta = np.arange(720) * (4 * np.pi / 720)
    load = np.asarray(engine.generalized_load(RPM, theta), float)
    fh, omegas = stepper.harmonics(load, omega, 40.0)
    qh, _ = stepper.harmonic_state(fh, omegas, omega)
    x0 = qh.real.sum(0)
    v0 = (1j * omegas[:, None] * qh).real.sum(0)
    ports = stepper.ports
    state = steady_loop_state(ports, qh @ ports.rows.T, 720)
    F = np.zeros((cycles * 720 + 1, system.n_dof))
    F[:, :6] = np.concatenate([np.tile(load, (cycles, 1)), load[:1]])
    return system, ports, F, np.deg2rad(1.0) / omega, x0, v0, state


def ours(system, ports, F, h, x0, v0, state, refine=1):
    """Mount-model coordinates' velocities at the load samples; ``refine`` sub-steps per
    sample (the load linearly interpolated between the samples, as the peer sees it)."""
    if refine > 1:
        s = np.arange((F.shape[0] - 1) * refine + 1) / refine
        i = np.minimum(s.astype(int), F.shape[0] - 2)
        F = F[i] + (s - i)[:, None] * (F[i + 1] - F[i])
    X, V, A, Z = newmark_ports(system.M, system.C, system.K, F, h / refine, ports, x0, v0,
                               state=state.copy())
    return V[::refine]


class FrictionODE:
    """The first-order form with the friction forces as states and reversal events."""

    def __init__(self, system, ports, F, h):
        self.Minv = np.linalg.inv(system.M)
        self.C, self.K, self.P = system.C, system.K, ports.rows
        self.F, self.h = F, h
        self.fm, self.x2 = BERG.max_force, BERG.half_displacement
        self.n = system.n_dof
        self.Fs = np.zeros(ports.rows.shape[0])        # reversal forces
        self.d = np.ones(ports.rows.shape[0])          # directions

    def load(self, t):
        u = t / self.h
        i = min(int(u), self.F.shape[0] - 2)
        return self.F[i] + (u - i) * (self.F[i + 1] - self.F[i])

    def __call__(self, t, y):
        n = self.n
        x, v, z = y[:n], y[n:2 * n], y[2 * n:]
        a = self.Minv @ (self.load(t) - self.C @ v - self.K @ x - self.P.T @ z)
        du = self.P @ v
        kt = self.fm * (self.fm - self.d * z) ** 2 / (self.x2 * (self.fm - self.d * self.Fs) ** 2)
        return np.concatenate([v, a, kt * du])

    def events(self):
        """Reversal of each element: its relative velocity turning against its direction."""
        def make(e):
            def reversal(t, y):
                return self.P[e] @ y[self.n:2 * self.n]
            reversal.terminal = True
            reversal.direction = -self.d[e]
            return reversal
        return [make(e) for e in range(self.P.shape[0])]


def peer(system, ports, F, h, x0, v0, state, method, rtol):
    """solve_ivp from the same start; velocities at the same time points."""
    ode = FrictionODE(system, ports, F, h)
    u0 = ports.rows @ x0
    z0 = ports.forces(u0, ports.rows @ v0, state.copy())
    ode.d = np.sign(ports.rows @ v0) + (ports.rows @ v0 == 0)
    ode.Fs = np.where(ode.d == state[:, 2], state[:, 1], state[:, 4])
    t_eval = np.arange(F.shape[0]) * h
    y, t, out = np.concatenate([x0, v0, z0]), 0.0, []
    while True:
        sol = solve_ivp(ode, (t, t_eval[-1]), y, method=method, rtol=rtol, atol=rtol * 1e-6,
                        t_eval=t_eval[(t_eval > t) | (t == 0) & (t_eval == 0)],
                        events=ode.events())
        if len(sol.t):
            out.append(np.asarray(sol.y).T)
        if sol.status != 1:
            break
        e = next(k for k, te in enumerate(sol.t_events) if te.size)
        t, y = sol.t_events[e][0], sol.y_events[e][0]
        du = ode.P @ y[ode.n:2 * ode.n]
        turned = ode.d * du <= 1e-9 * np.abs(du).max()      # this one and any at that instant
        turned[e] = True                                    # (symmetric mounts reverse together)
        ode.Fs[turned] = y[2 * ode.n:][turned]
        ode.d[turned] = -ode.d[turned]
    Y = np.concatenate(out)
    return Y[:, ode.n:2 * ode.n]


def error(V, V_ref, system):
    """Largest error of the mount-point velocities over the last cycle, relative."""
    Cm = system.channel_matrix
    a, b = V[-721:] @ Cm.T, V_ref[-721:] @ Cm.T
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--cycles", type=int, default=2)
    args = p.parse_args()
    case = problem(args.cycles)
    system = case[0]
    ours(*case)                                                   # warm
    t0 = time.process_time()
    V = ours(*case)
    ours_s = time.process_time() - t0
    V_ref = ours(*case, refine=32)
    target = error(V, V_ref, system)
    print(f"ours (Newmark, 1 deg): {ours_s:.4f} s, error {target:.2e}")
    best = np.inf
    for method in ("Radau", "BDF", "LSODA"):
        for rtol in 10.0 ** -np.arange(3, 9):
            t0 = time.process_time()
            Vp = peer(*case, method, rtol)
            seconds = time.process_time() - t0
            err = error(Vp, V_ref, system)
            if err <= target:
                print(f"solve_ivp {method} rtol {rtol:.0e}: {seconds:.3f} s, error {err:.2e}")
                best = min(best, seconds)
                break
        else:
            print(f"solve_ivp {method}: error {err:.2e} above ours down to rtol 1e-8")
    print(f"newmark_s={ours_s:.4f} solve_ivp_s={best:.3f} ratio={best / ours_s:.0f}")


if __name__ == "__main__":
    main()
