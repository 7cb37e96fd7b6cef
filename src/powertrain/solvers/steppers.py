r"""The run-up's per-speed solvers behind one protocol, chosen once per run.

A :class:`Stepper` turns one speed's load over an engine cycle into the order amplitudes of
every channel (:class:`SpeedOrders`), in the frequency domain (:class:`HarmonicStepper`,
:class:`AdmittanceStepper`) or by Newmark average acceleration (:class:`ModalNewmarkStepper`,
:class:`DenseNewmarkStepper`, :class:`ModalPortStepper`); :func:`choose_stepper` picks one.
Nonlinear mount elements: the Newmark steppers integrate the port laws by Newton per step,
the frequency-domain ones solve the equivalent-linear model
(:mod:`powertrain.solvers.equivalent_linear`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.analysis.orders import ORDERS, order_spectrum
from powertrain.assembly import NetworkScaling
from powertrain.kernels import kernel_input
from powertrain.kernels.port_forces import NONE
from powertrain.kernels.small_solve import batched_solve_kernel
from powertrain.physics.condensation import linear_two_ports
from powertrain.solvers.admittance import frf_response, relative_motion
from powertrain.solvers.cycle_newmark import CycleRun, run_cycles, start_state, steady_loop_state
from powertrain.solvers.equivalent_linear import AMPLITUDE_HARMONICS, TOLERANCE, amplitude_fixed_point
from powertrain.solvers.harmonic import harmonic_response
from powertrain.solvers.newmark import ModalNewmark, ModalPortNewmark, newmark

#: Relative tolerance of the equivalent-linear fixed point a nonlinear Newmark run starts
#: from (the time domain's own amplitudes differ by more).
START_TOLERANCE = 1e-4
#: Highest order in the frequency-domain initial state of a Newmark run (harmonics above
#: order 40 are < 2e-5 of the 2nd order for the default engine).
INITIAL_STATE_MAX_ORDER = 40.0


@dataclass(frozen=True)
class Cycles:
    """Time grid of a run-up: samples per engine cycle, cycles simulated and processed."""

    n_cycle: int
    angle_step_deg: float
    cycles: int
    processed_cycles: int

    @property
    def start(self) -> int:
        """First sample of the processed window."""
        return (self.cycles - self.processed_cycles) * self.n_cycle


@dataclass
class SpeedOrders:
    """One speed's complex order amplitudes (n_ch, n_orders) of displacement [m], velocity
    [m/s], acceleration [m/s²] and force [N], the mean force (n_ch,) [N], the processed
    window's cycle-to-cycle periodicity (0 in the frequency domain) and the solver time [s]."""

    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    force: np.ndarray
    mean_force: np.ndarray
    periodicity: float = 0.0
    seconds: float = 0.0


class Stepper:
    """Protocol: ``solve(load, omega)`` -> :class:`SpeedOrders`; ``settings()`` for the
    result file; ``setup_seconds`` spent once per model."""

    solver = ""
    setup_seconds = 0.0
    #: Hook ``static_factors(rpm) -> (n_net,)``: every network's static-curve factor at a
    #: speed; None: each element's own ``static_factor``.
    static_factors = None
    #: Relative change of the amplitudes at which the equivalent-linear fixed point stops.
    fixed_point_tolerance = TOLERANCE

    def __init__(self, system, grid: Cycles):
        self.system = system
        self.grid = grid
        self.ports = system.port_forces()
        #: the last speed's equivalent-linear amplitudes (the next speed's first guess)
        self.amplitudes = None
        self._scaling = None

    @property
    def scaling(self) -> NetworkScaling:
        """The model's networks rescalable (built on first use)."""
        if self._scaling is None:
            self._scaling = NetworkScaling(self.system)
        return self._scaling

    def factors_at(self, omega):
        """The hook's static factors (n_net,) at the speed ``omega`` [rad/s], or None."""
        return None if self.static_factors is None else \
            np.asarray(self.static_factors(omega * 30.0 / np.pi), float)

    def system_at(self, factors):
        """The model at the operating point of the static ``factors`` (None: as assembled)."""
        return self.system if factors is None else self.scaling.at_operating_point(factors)

    def on_system(self, system) -> Stepper:
        """A stepper of this kind on ``system``, warm-started from this one's amplitudes."""
        new = type(self)(system, self.grid)
        new.amplitudes = self.amplitudes
        return new

    def equivalent_linear(self, solve, relative_motion, omega):
        """``(amplitudes, solve(amplitudes))`` at the equivalent-linear fixed point
        (:func:`amplitude_fixed_point` of ``relative_motion``) at ``omega`` [rad/s],
        warm-started from the last speed; a linear model is solved once (amplitudes None)."""
        if self.ports is None:
            return None, solve(None)
        A, solution = amplitude_fixed_point(solve, relative_motion, self.ports,
                                            omega * 30.0 / np.pi, self.amplitudes,
                                            self.fixed_point_tolerance)
        self.amplitudes = A
        return A, solution

    def harmonic_state(self, fh, omegas, omega, system=None):
        """Harmonic response (n_h, n_dof) of the equivalent-linear ``system`` (default the
        stepper's) to the load harmonics ``fh`` at ``omegas`` [rad/s], and the nonlinear
        elements' amplitudes (None: linear), at the speed ``omega`` [rad/s]."""
        s = self.system if system is None else system
        if self.ports is None:
            return harmonic_response(s, fh, omegas), None
        k = AMPLITUDE_HARMONICS.stop
        linear = linear_two_ports(s.ports(), 1j * np.asarray(omegas, float))
        first = None if linear is None else linear.first(k)
        internal = bool(np.any(np.delete(self.ports.rows, s.ports().retained, axis=1)))
        A = self.equivalent_linear(lambda a: harmonic_response(s, fh[:k], omegas[:k], a,
                                                               first, internal),
                                   lambda q: q @ self.ports.rows.T, omega)[0]
        return harmonic_response(s, fh, omegas, self.ports.network_amplitudes(A), linear), A

    def harmonics(self, load, omega, max_order=None):
        """Harmonics of the cycle's ``load`` (index j is order j/2, up to ``max_order``) and
        their frequencies [rad/s] at ``omega`` [rad/s]."""
        n_h = self.grid.n_cycle // 2
        if max_order is not None:
            n_h = min(n_h, int(2 * max_order) + 1)
        fh = harmonic_amplitudes(load, axis=0)[:n_h]
        return fh, 0.5 * omega * np.arange(fh.shape[0])

    def settings(self) -> dict:
        return {"solver": self.solver, "angle_step_deg": self.grid.angle_step_deg,
                "cycles": 0, "processed_cycles": 0,
                "integrator": "harmonic steady state per order", "initial_state": ""}


class HarmonicStepper(Stepper):
    """Frequency-domain steady state per order (rigid or modal body,
    :func:`powertrain.solvers.harmonic.harmonic_response`)."""

    solver = "harmonic"

    def solve(self, load, omega) -> SpeedOrders:
        t0 = time.perf_counter()
        fh, omegas = self.harmonics(load, omega)
        qh, A = self.harmonic_state(fh, omegas, omega)
        j = np.round(ORDERS * 2).astype(int)
        w = omegas[j][:, None]
        q_o = qh[j]                                       # (n_orders, n)
        s = self.system
        Fk, Fd = s.force_matrix_k, s.force_matrix_d
        if A is not None:        # the force rows of the networks at their amplitudes
            Fk, Fd = self.scaling.matrices(self.scaling.scales(self.ports.network_amplitudes(A)))[2:]
        x = (q_o @ s.channel_matrix.T).T
        force = ((q_o @ Fk.T) + 1j * w * (q_o @ Fd.T)).T
        mean = Fk @ qh[0].real
        if A is not None:
            z = self.ports.describing_forces(A, qh @ self.ports.rows.T) @ self.ports.force_map.T
            force, mean = force + z[j].T, mean + z[0].real
        return SpeedOrders(x, 1j * w.T * x, -(w.T ** 2) * x, force, mean, 0.0, time.perf_counter() - t0)


class AdmittanceStepper(Stepper):
    """Frequency-domain steady state per order with a measured-receptance body
    (:func:`powertrain.solvers.admittance.frf_response`)."""

    solver = "harmonic"

    def solve(self, load, omega) -> SpeedOrders:
        t0 = time.perf_counter()
        fh, omegas = self.harmonics(load, omega)
        s = self.system
        j = np.round(ORDERS * 2).astype(int)
        sel = np.r_[j, 0]                     # the orders (harmonics 1..16), then the mean
        q, body, fb = self.equivalent_linear(
            lambda a: frf_response(s, fh[sel], omegas[sel], a),
            lambda r: relative_motion(s, self.ports.index, *r[:2])[np.r_[-1, :len(j)]],
            omega)[1]
        n_a = s.n_mount_channels
        x = np.hstack([q[:-1] @ s.channel_matrix[:n_a].T, body[:-1]])      # (n_orders, n_ch)
        w = omegas[j][:, None]
        n_rest = x.shape[1] - 2 * n_a
        force = np.hstack([fb[:-1], fb[:-1], np.zeros((len(j), n_rest))])
        f0 = fb[-1].real
        return SpeedOrders(x.T, (1j * w * x).T, (-(w ** 2) * x).T, force.T,
                           np.hstack([f0, f0, np.zeros(n_rest)]), 0.0,
                           time.perf_counter() - t0)


class _NewmarkStepper(Stepper):
    """Shared part of the two Newmark steppers: the processed window's order analysis."""

    solver = "newmark"
    implementation = ""

    def settings(self) -> dict:
        g = self.grid
        return {"solver": self.solver, "angle_step_deg": g.angle_step_deg,
                "cycles": g.cycles, "processed_cycles": g.processed_cycles,
                "integrator": "Newmark average acceleration (beta=1/4, gamma=1/2), "
                + self.implementation,
                "initial_state": "static preload + frequency-domain steady state at t=0 "
                f"(orders <= {INITIAL_STATE_MAX_ORDER:g})"}

    def window_orders(self, d_c, v_c, a_c, f_c, v_prev, seconds) -> SpeedOrders:
        """Orders of the window's channel signals, periodicity against ``v_prev``."""
        revs = 2 * self.grid.processed_cycles
        last = v_c[-self.grid.n_cycle:]
        scale = np.max(np.abs(last)) or 1.0
        return SpeedOrders(order_spectrum(d_c, revs).T, order_spectrum(v_c, revs).T,
                           order_spectrum(a_c, revs).T, order_spectrum(f_c, revs).T,
                           f_c.mean(axis=0), float(np.max(np.abs(last - v_prev)) / scale),
                           seconds)


class ModalNewmarkStepper(_NewmarkStepper):
    """Newmark recurrence diagonalised once per model
    (:class:`powertrain.solvers.newmark.ModalNewmark`); linear models with a regular mass
    matrix and two processed cycles."""

    implementation = "modal (diagonalised recurrence)"

    def __init__(self, system, grid: Cycles):
        super().__init__(system, grid)
        if grid.processed_cycles < 2:
            raise ValueError("the modal stepper needs processed_cycles >= 2; use "
                             "stepper='dense'")
        if self.ports is not None:
            raise ValueError(f"the modal stepper integrates linear models only "
                             f"({', '.join(self.ports.names)} nonlinear); use stepper='dense'")
        t0 = time.perf_counter()
        self.modal = ModalNewmark(system.M, system.C, system.K, load_dofs=6)
        Cm, Z = system.channel_matrix, np.zeros_like(system.channel_matrix)
        self.maps = self.modal.output_map(np.vstack([Cm, Z, Z, system.force_matrix_k]),
                                          np.vstack([Z, Cm, Z, system.force_matrix_d]),
                                          np.vstack([Z, Z, Cm, Z]))
        self.setup_seconds = time.perf_counter() - t0

    def solve(self, load, omega) -> SpeedOrders:
        t0 = time.perf_counter()
        g = self.grid
        fh, omegas = self.harmonics(load, omega, INITIAL_STATE_MAX_ORDER)
        x0, v0 = self.modal.harmonic_state(fh, omegas)
        Y = self.modal.run_outputs(load, g.cycles, np.deg2rad(g.angle_step_deg) / omega,
                                   x0, v0, g.start, *self.maps)
        seconds = time.perf_counter() - t0
        n_ch = len(self.system.channels)
        d_c, v_c, a_c, f_c = (Y[:-1, k * n_ch:(k + 1) * n_ch] for k in range(4))
        return self.window_orders(d_c, v_c, a_c, f_c, v_c[:g.n_cycle], seconds)


class DenseNewmarkStepper(_NewmarkStepper):
    """Newmark recurrence in physical coordinates (any mass matrix); nonlinear elements
    cycle by cycle (:func:`powertrain.solvers.cycle_newmark.run_cycles`)."""

    implementation = "dense"
    #: the start's fixed point: the run goes on to its own steady state from it
    fixed_point_tolerance = START_TOLERANCE

    def solve(self, load, omega) -> SpeedOrders:
        t0 = time.perf_counter()
        factors = self.factors_at(omega)
        s = self.system_at(factors)
        fh, omegas = self.harmonics(load, omega, INITIAL_STATE_MAX_ORDER)
        qh, amplitudes = self.harmonic_state(fh, omegas, omega, s)
        x0 = qh.real.sum(axis=0)
        v0 = (1j * omegas[:, None] * qh).real.sum(axis=0)
        a0 = (-(omegas ** 2)[:, None] * qh).real.sum(axis=0)
        h = np.deg2rad(self.grid.angle_step_deg) / omega
        out = self.channels(s, load, h, (x0, v0, a0, qh), amplitudes, factors)
        seconds = time.perf_counter() - t0
        return self.window_orders(*out, seconds)

    def channels(self, s, load, h, start, amplitudes, factors):
        """Channel signals over the processed window and the velocity of the cycle before
        its last: model ``s`` at step ``h`` [s] from ``start`` = (x0, v0, a0, harmonic
        response), nonlinear elements cycle by cycle from the ``amplitudes``."""
        g = self.grid
        x0, v0, a0, qh = start
        F = np.zeros((g.cycles * g.n_cycle + 1, s.n_dof))
        F[:, :6] = np.concatenate([np.tile(load, (g.cycles, 1)), load[:1]])
        if self.ports is None:
            run = CycleRun(*newmark(s.M, s.C, s.K, F, h, x0, v0, a0), None,
                           [(slice(0, F.shape[0]), s.force_matrix_k, s.force_matrix_d, None)])
        else:
            begin = (x0, v0, a0, start_state(self.ports, qh, g.n_cycle), qh[0].real)
            run = run_cycles(self.scaling, self.ports, F, h, g.n_cycle, begin, amplitudes, factors)
        n = g.n_cycle
        d_c, v_c, a_c, f_c = self._outputs(run, slice(g.start, g.start + g.processed_cycles * n))
        v_prev = v_c[:n] if g.processed_cycles >= 2 else self._outputs(run, slice(g.start - n, g.start))[1]
        return d_c, v_c, a_c, f_c, v_prev

    def _outputs(self, run, win):
        """Channel displacement, velocity, acceleration and force of ``run`` over ``win``."""
        Cm = self.system.channel_matrix
        q, v, a = run.X[win], run.V[win], run.A[win]
        force = [run.X[lo:hi] @ Fk.T + run.V[lo:hi] @ Fd.T - (0.0 if off is None else off)
                 for lo, hi, Fk, Fd, off in
                 ((max(r.start, win.start), min(r.stop, win.stop), Fk, Fd, off)
                  for r, Fk, Fd, off in run.segments) if lo < hi]
        force = force[0] if len(force) == 1 else np.concatenate(force)
        if run.Z is not None:
            force += run.Z[win] @ self.ports.select(self.ports.kinds != NONE).force_map.T
        return q @ Cm.T, v @ Cm.T, a @ Cm.T, force


class ModalPortStepper(DenseNewmarkStepper):
    """Modal recurrence with the port laws, Newton per step
    (:class:`~powertrain.solvers.newmark.ModalPortNewmark`), for networks of constant scale.
    Needs a regular mass matrix, two processed cycles and no static-factor hook."""

    implementation = "modal with the port laws (Newton per step)"

    def __init__(self, system, grid: Cycles):
        super().__init__(system, grid)
        if grid.processed_cycles < 2 or self.ports is None or self.scaling.varying:
            raise ValueError("the modal port stepper needs processed_cycles >= 2 and port "
                             "laws on networks of constant scale")
        t0 = time.perf_counter()
        self.laws = self.ports.select(self.ports.kinds != NONE)
        self.modal = ModalNewmark(system.M, system.C, system.K, load_dofs=6)
        Cm, Z = system.channel_matrix, np.zeros_like(system.channel_matrix)
        zf = np.zeros_like(self.laws.force_map)
        self.rows = (np.vstack([Cm, Z, Z, system.force_matrix_k]),
                     np.vstack([Z, Cm, Z, system.force_matrix_d]), np.vstack([Z, Z, Cm, Z]),
                     np.vstack([zf, zf, zf, self.laws.force_map]))
        self._runner = None
        self.port_modes = self.modal.port_modes(self.ports.rows)
        groups = {}
        for e, law in enumerate(self.ports.laws):
            if law is not None:
                groups.setdefault(law, []).append(e)
        #: the port laws, each with the ports it acts at
        self.law_groups = [(law, np.array(index)) for law, index in groups.items()]
        self.setup_seconds = time.perf_counter() - t0

    def harmonic_state(self, fh, omegas, omega, system=None):
        """:meth:`Stepper.harmonic_state` through the stepper's modes: the port laws'
        describing stiffnesses fed back along the port rows
        (:meth:`ModalNewmark.port_harmonics`); the condensation for another ``system`` or
        an amplitude law."""
        s = self.system if system is None else system
        elements = s.ports().elements
        if s is not self.system or len(elements) != self.ports.n_networks or any(
                el.amplitude_law is not None for el in elements):
            return super().harmonic_state(fh, omegas, omega, system)
        g, ef, uf, Hp = self.modal.port_harmonics(self.port_modes, fh, omegas)
        eye = np.eye(self.ports.kinds.size)

        def relative(amplitudes, n_h=AMPLITUDE_HARMONICS.stop):
            """Relative motions (n_h, m) along the port rows and describing stiffnesses."""
            a, kd = amplitudes[self.ports.index], np.zeros(eye.shape[0], complex)
            for law, index in self.law_groups:      # one call per distinct law
                kd[index] = law.describing_stiffness(a[index])
            kd = np.where(omegas[:n_h, None] == 0, 0.0, kd[None, :])
            u = np.empty((n_h, kd.shape[1]), complex)
            if batched_solve_kernel(kernel_input(eye + Hp[:n_h] * kd[:, None, :], complex),
                                    kernel_input(uf[:n_h], complex), u):
                raise np.linalg.LinAlgError("singular equivalent-linear port feedback")
            return u, kd

        A = self.equivalent_linear(lambda a: relative(a)[0], lambda u: u, omega)[0]
        u, kd = relative(self.ports.network_amplitudes(A), omegas.size)
        eta = ef - g * ((kd * u) @ self.port_modes[1].T)
        return eta @ self.modal.Psi[:self.modal.n].T, A

    def runner(self, h) -> ModalPortNewmark:
        """The modal recurrence with the port laws at the step ``h`` [s]."""
        if self._runner is None:
            self._runner = ModalPortNewmark(self.modal, self.laws, h, *self.rows)
        return self._runner.at_step(h)

    def channels(self, s, load, h, start, amplitudes, factors):
        if factors is not None:              # a static-factor hook: networks rescaled
            return super().channels(s, load, h, start, amplitudes, factors)
        g = self.grid
        x0, v0, _, qh = start
        run = self.runner(h)
        state = steady_loop_state(self.laws, qh @ self.laws.rows.T, g.n_cycle)
        z = self.laws.forces(self.laws.rows @ x0, self.laws.rows @ v0, state)
        eta = run.modal_state(x0, v0)
        F = np.concatenate([np.tile(load, (g.cycles, 1)), load[:1]])
        run.run(F[:g.start + 1], eta, z, state, outputs=False)
        Y = run.run(F[g.start:], eta, z, state)
        n_ch = len(self.system.channels)
        d_c, v_c, a_c, f_c = (Y[:, k * n_ch:(k + 1) * n_ch] for k in range(4))
        return d_c, v_c, a_c, f_c, v_c[:g.n_cycle]


def _auto_newmark(system, grid):
    kinds = [ModalNewmarkStepper, DenseNewmarkStepper]
    if system.port_forces() is not None:
        kinds[0] = ModalPortStepper
    for kind in kinds:
        try:
            return kind(system, grid)
        except (ValueError, np.linalg.LinAlgError):
            pass
    return DenseNewmarkStepper(system, grid)


#: Newmark implementations by their ``--stepper`` name.
NEWMARK_STEPPERS = {"auto": _auto_newmark, "modal": ModalNewmarkStepper, "dense": DenseNewmarkStepper}


def _newmark(system, grid, stepper):
    chassis = system.chassis
    if chassis is not None:
        chassis.require_time_domain()
    if stepper not in NEWMARK_STEPPERS:
        raise ValueError(f"unknown stepper {stepper!r}")
    return NEWMARK_STEPPERS[stepper](system, grid)


def _harmonic(system, grid, stepper):
    if stepper not in NEWMARK_STEPPERS:
        raise ValueError(f"unknown stepper {stepper!r}")
    chassis = system.chassis
    if chassis is not None and chassis.coupled_by_admittance:
        return AdmittanceStepper(system, grid)
    return HarmonicStepper(system, grid)


#: Solvers by their ``--solver`` name.
SOLVERS = {"newmark": _newmark, "harmonic": _harmonic}


def choose_stepper(system, solver, stepper, grid: Cycles) -> Stepper:
    """The stepper for ``system`` on the time ``grid``: ``solver`` (``newmark`` or
    ``harmonic``), ``stepper`` (``auto``, ``modal``, ``dense``) and the chassis decide."""
    if solver not in SOLVERS:
        raise ValueError(f"unknown solver {solver!r}")
    return SOLVERS[solver](system, grid, stepper)
