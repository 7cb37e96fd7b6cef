r"""A transient manoeuvre integrated in time by the run-up's nonlinear stepper.

The load of :mod:`powertrain.solvers.transient_load` drives the model of
:meth:`Engine.assemble` by Newmark average acceleration (port laws by Newton per step, the
Newmark matrix factored sparsely, :mod:`powertrain.kernels.sparse_lu`) in one kernel call
(:func:`~powertrain.kernels.transient.transient_kernel`). The amplitude law and the
networks' centres are updated every :data:`STRETCH` (a linear model without static curves
is one stretch), the static curves every :data:`CURVE_STEP`. Where the laws change the
integration restarts from position and velocity with the acceleration solved from the new
laws (carried over, the trapezoidal rule would keep the jump as an undamped alternating
error).

**Static curves.** Coordinates are measured from the static operating point at zero mean
torque (:func:`~powertrain.solvers.operating_point.operating_point`), network deflections
:math:`\delta_0`. At each curve update, at the state predicted for the middle of the piece,
:math:`\mathbf x_c = \mathbf x + \tfrac T2\dot{\mathbf x}` (:math:`T` the piece's length,
:math:`u_c = \mathbf r^T\mathbf x_c`, :math:`\delta_c = \delta_0 + u_c`; the middle cancels
the first-order lag of the tangent), each network with a static curve :math:`F(\delta)` is
scaled by :math:`\kappa = f\,s` (static factor :math:`f` at :math:`\delta_c`, tangent
:math:`f k_0`; :math:`s` the amplitude law's scale) and loaded by

.. math:: c = F(\delta_c) - F(\delta_0) - f k_0\,(u_c - \bar u) - \kappa k_0\,\bar u ,

where :math:`\bar u`, the network's centre, is its mean deflection over the stretch before
(at first, the starting deflection). Until the next update the static force is

.. math:: F(\delta_c) - F(\delta_0) + f k_0\,(u - u_c) + (\kappa - f)\,k_0\,(u - \bar u):

the curve's tangent at :math:`\delta_c`, the amplitude law acting on the motion about the
centre only; as updates get more frequent it tends to the curve itself
(tests/transient_oracle.py, ``continuous=True``). Mount forces are changes from the
zero-torque static point.

**Start.** At rest from standstill; else the periodic steady state at the first speed and
load (:meth:`Stepper.harmonic_state`), as the run-up and the sweep start.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from powertrain.assembly import NetworkScaling
from powertrain.errors import InputError, PowertrainWarning
from powertrain.kernels.port_forces import NONE
from powertrain.kernels.sparse_lu import compressed
from powertrain.kernels.transient import (
    NEEDS_PIVOTING,
    curve_state,
    network_force_change,
    transient_kernel,
)
from powertrain.solvers.cycle_newmark import no_ports, start_state
from powertrain.solvers.newmark import PORT_MAX_ITER, PORT_TOL
from powertrain.solvers.operating_point import StaticSupport, has_static_curves, operating_point
from powertrain.solvers.steppers import Cycles, DenseNewmarkStepper
from powertrain.solvers.transient_load import (
    N_THETA,
    RPM,
    TorqueLimitWarning,
    driveline_reaction,
    transient_load,
)
from powertrain.solvers.transient_model import motion_model, stretch_kernel_model


class StretchRuleWarning(PowertrainWarning):
    """A mount direction has a static curve and an amplitude law: in a transient the law acts
    per stretch on the motion about the mean deflection (docs/guide/transient.md)."""


#: Length of a stretch [s]: the amplitude law's scales and the networks' centres are updated
#: this often (a rigid-body mode of 12 Hz is 8 stretches per period).
STRETCH = 0.01
#: Interval [s] of the static curves' updates (a whole number per stretch); the error is first
#: order in it (about 0.13 % of the peak force at 2 ms on a 0.12 s flare).
CURVE_STEP = 0.002
#: Most integration steps of a manoeuvre (checked before any work).
MAX_STEPS = 2 ** 21
#: Most memory of a run's time histories [B] (checked before any work).
MAX_BYTES = 2e9
#: A manoeuvre starting below this speed [rpm] starts at rest (the gas load is faded out).
REST_RPM = 5.0
#: Speed below which the step is set as at this speed [rpm]: standstill needs a step too.
FLOOR_RPM = 600.0


@dataclass(frozen=True)
class TransientRun:
    """A manoeuvre's time histories at every step (SI).

    Attributes
    ----------
    load : TransientLoad
    body : ndarray (n_t, 6)
        Body displacement [m] and rotation [rad] at the CG from the zero-torque static point.
    displacement, velocity, acceleration, force : ndarray (n_t, n_ch)
        Channel motion [m, m/s, m/s²] and transmitted force [N].
    deflection : ndarray (n_t, n_net)
        Network deflection (engine side minus base) from the zero-torque static point [m].
    channels : list of (str, str)
    networks : list of str
    method : str
    coordinates, coordinate_velocity : ndarray (n_t, n)
        Every coordinate of the model [m, rad] and its velocity.
    port_law_force : ndarray (n_t, m) or None
        Force of each port law [N], in ``system.port_forces()`` order.
    network_scales : ndarray (n_t, n_net, 2)
        Stiffness and damping scale of every network (amplitude law times static factor).
    curve_load : ndarray (n_t, n_net)
        The static curves' load ``c`` [N] (module docstring; 0 without one).
    stretch_steps, curve_steps : int
        Steps per stretch and per static-curve update (a divisor of ``stretch_steps``).
    """

    load: object
    body: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    force: np.ndarray
    deflection: np.ndarray
    channels: list
    networks: list
    method: str
    coordinates: np.ndarray | None = None
    coordinate_velocity: np.ndarray | None = None
    port_law_force: np.ndarray | None = None
    network_scales: np.ndarray | None = None
    curve_load: np.ndarray | None = None
    stretch_steps: int = 0
    curve_steps: int = 0


def transient_steps(manoeuvre, angle_step_deg) -> int:
    """Integration steps of ``manoeuvre``: ``angle_step_deg`` [deg] of crank angle at the top
    speed (at least :data:`FLOOR_RPM`), at most :data:`MAX_STEPS`."""
    if not (math.isfinite(angle_step_deg) and 0.01 <= angle_step_deg <= 10.0):
        raise InputError("must be 0.01..10 [deg]", key="--angle-step")
    top = max(manoeuvre.max_speed, FLOOR_RPM * RPM)
    n = math.ceil(manoeuvre.duration * top / math.radians(angle_step_deg) - 1e-9)
    if n > MAX_STEPS:
        raise InputError(f"{n} integration steps; at most {MAX_STEPS} (a shorter manoeuvre "
                         "or a larger --angle-step)", file=manoeuvre.file or None, key="speed")
    return max(n, 1)


def simulate_transient(engine, manoeuvre, *, system=None, angle_step_deg=1.0) -> TransientRun:
    """Integrate ``manoeuvre`` on ``engine`` (module docstring).

    Parameters
    ----------
    engine : Engine
    manoeuvre : Manoeuvre
    system : AssembledSystem, optional
        The model (default ``engine.assemble()``).
    angle_step_deg : float
        Crank angle per step at the top speed [deg].
    """
    top = engine.speed_range_rpm()[1]
    if manoeuvre.max_speed / RPM > top + 1e-6:
        raise InputError(f"{manoeuvre.max_speed / RPM:g} rpm is above the engine's combustion "
                         f"model ({top:g} rpm)", file=manoeuvre.file or None, key="speed.speed")
    system = engine.assemble() if system is None else system
    if system.chassis is not None:
        system.chassis.require_time_domain()
    n_steps = transient_steps(manoeuvre, angle_step_deg)
    _check_size(n_steps, system, manoeuvre)
    t = np.linspace(0.0, manoeuvre.duration, n_steps + 1)
    load = transient_load(engine, manoeuvre, t)
    F = np.ascontiguousarray(load.F, float)        # on the body; none on the other coordinates
    ports = system.port_forces() or no_ports(system)
    scaling = NetworkScaling(system)
    curves = _Curves(engine, system) if has_static_curves(engine) else None
    _warn_curve_and_law(engine)
    start = _start(engine, manoeuvre, system, load, ports, (scaling, curves))
    every, sub = _stretch_steps(t[1] - t[0], n_steps, scaling.varying, curves is not None)
    laws = ports.select(ports.kinds != NONE)
    histories = _Histories(*_time_histories(t.size, *_history_shapes(system, laws)))
    _run(system, scaling, ports, curves, F, t[1] - t[0], start, (every, sub), histories)
    _channel_outputs(system, scaling, histories, laws.force_map)
    h = histories
    return TransientRun(load, h.X[:, :6], h.displacement, h.velocity, h.acceleration, h.force,
                        h.deflection, list(system.channels), system.network_names,
                        _method(scaling, ports, curves, every, sub), h.X, h.V,
                        h.Z if h.Z.shape[1] else None, h.scales, h.loads, every, sub)


class _Histories(NamedTuple):
    """A run's time histories, filled by :func:`_run` and :func:`_channel_outputs`."""

    X: np.ndarray
    V: np.ndarray
    Z: np.ndarray
    scales: np.ndarray
    loads: np.ndarray
    acceleration: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    deflection: np.ndarray


def _history_shapes(system, laws):
    """Each time history's shape but the steps, in :class:`_Histories`' order."""
    n, n_ch, n_net = system.n_dof, len(system.channels), system.port_rows.shape[0]
    return ((n,), (n,), (laws.kinds.size,), (n_net, 2), (n_net,),
            (n_ch,), (n_ch,), (n_ch,), (n_ch,), (n_net,))


def _check_size(n_steps, system, manoeuvre):
    """Refuse, before any work, a run whose time histories exceed :data:`MAX_BYTES`."""
    n, n_ch, n_net = system.n_dof, len(system.channels), system.port_rows.shape[0]
    size = 8.0 * (n_steps + 1) * (6 * n + 5 * n_ch + 4 * n_net)
    if size > MAX_BYTES:
        raise InputError(f"{n_steps} steps of {n} coordinates hold about {size / 1e9:.1f} GB "
                         f"of time histories; at most {MAX_BYTES / 1e9:g} GB (a shorter "
                         "manoeuvre or a larger --angle-step)", file=manoeuvre.file or None,
                         key="speed")


def _stretch_steps(h, n_steps, varying, curves):
    """``(steps per stretch, steps per curve update)`` at the step ``h`` [s]."""
    if curves:
        sub = max(1, round(CURVE_STEP / h))
        return sub * round(STRETCH / CURVE_STEP), sub
    every = max(1, round(STRETCH / h)) if varying else n_steps
    return every, every


def _warn_curve_and_law(engine):
    both = [f"{m.name}.{axis}" for m in engine.mounts for axis, mod in m.directions.items()
            if mod.static_curve is not None and mod.amplitude_law is not None]
    if both:
        warnings.warn(f"{', '.join(both)}: static curve and amplitude law together; in a "
                      f"transient the law's amplitude and centre are each {STRETCH * 1e3:g} ms "
                      "stretch's, a model choice (docs/guide/transient.md)",
                      StretchRuleWarning, stacklevel=3)


def _method(scaling, ports, curves, every, sub):
    parts = ["Newmark average acceleration"]
    if (ports.kinds != NONE).any():
        parts.append("port laws by Newton per step")
    if scaling.varying:
        parts.append(f"amplitude law every {every} steps")
    if curves is not None:
        parts.append(f"static curves' tangents every {sub} steps")
    return "; ".join(parts)


def _run(system, scaling, ports, curves, F, h, start, steps, histories):
    """Fill the kernel's ``histories`` under the body load ``F`` (n_t, 6)."""
    every, sub = steps
    x, v, a, state, amplitudes = start
    laws = ports.select(ports.kinds != NONE)
    n_t, n = F.shape[0], system.n_dof
    X, V, Z, scales, loads = histories[:5]
    X[0], V[0] = x, v
    acceleration = (np.empty((min(sub, n_t - 1) + 1, n)),    # a piece's; channels' at every step
                    compressed(np.array(system.channel_matrix, float), True, True),
                    histories.acceleration)
    kernel_curves = _kernel_curves(system, scaling, curves)
    motion = motion_model(system, scaling, ports)
    for pivoting in (False, True):    # row swaps compiled in only where S needs them
        failed = transient_kernel(
            stretch_kernel_model(system, scaling, pivoting), kernel_curves,
            None if not laws.kinds.size else (
                np.array(laws.rows, float), np.array(laws.kinds, np.int64),
                np.array(laws.parameters, float), None if state is None else state.copy(),
                compressed(np.array(laws.rows, float), True, True),
                np.zeros((7, laws.kinds.size))),
            motion, h, F, (every, sub), np.empty(0) if a is None else np.array(a, float),
            ports.network_amplitudes(amplitudes), system.port_rows @ x, X, V, acceleration, Z,
            scales, loads, PORT_TOL, PORT_MAX_ITER)
        if failed != NEEDS_PIVOTING:
            break
    if failed:
        raise FloatingPointError(f"port laws {', '.join(laws.names)}: Newton did not converge "
                                 f"at {failed} of {n_t - 1} steps")


def _channel_outputs(system, scaling, histories, laws_map):
    """Fill the ``histories``' channel outputs and network deflection from the states."""
    h = histories
    Cm = system.channel_matrix
    n_t, n_ch, n_net = h.X.shape[0], Cm.shape[0], system.port_rows.shape[0]
    work, net, net_v = _time_histories(n_t, (n_ch,), (n_net,), (n_net,))
    np.matmul(h.X, Cm.T, out=h.displacement)
    np.matmul(h.V, Cm.T, out=h.velocity)
    np.matmul(h.X, system.port_rows.T, out=h.deflection)
    force = np.matmul(h.X, system.force_matrix_k.T, out=h.force)
    force += np.matmul(h.V, system.force_matrix_d.T, out=work)
    network_force_change(np.matmul(h.X, scaling.gk.T, out=net),
                         np.matmul(h.V, scaling.gd.T, out=net_v), h.scales, scaling.assembled,
                         h.loads)
    force += np.matmul(net, system.port_force_map.T, out=work)
    if h.Z.shape[1]:
        force += np.matmul(h.Z, laws_map.T, out=work)


def _time_histories(n_t, *shapes):
    r"""Zeroed C-contiguous arrays (n_t, \*shape) for each of ``shapes``, in one buffer."""
    sizes = [n_t * math.prod(shape) for shape in shapes]
    buffer = np.zeros(sum(sizes))
    edges = np.cumsum([0, *sizes])
    return [buffer[a:b].reshape((n_t, *shape)) for a, b, shape in zip(edges, edges[1:], shapes)]


def _kernel_curves(system, scaling, curves):
    """The kernel's ``curves`` tuple (:func:`~powertrain.kernels.transient.curve_state`)."""
    rows = np.array(system.port_rows, float)
    n_net = rows.shape[0]
    if curves is None:
        zero = np.zeros(n_net)
        return (rows, zero, zero, np.zeros((n_net, 2)), np.zeros((n_net, 1, 4)),
                np.full(n_net, 2, np.int64), np.ones(n_net), np.zeros(n_net, bool),
                np.array(scaling.static_factors, float), zero)
    return (rows, *curves.kernel_tuple(), np.ones(n_net), np.array(curves.stiffness, float))


def _start(engine, manoeuvre, system, load, ports, model):
    """``(x0, v0, a0, port-law states, amplitudes)`` at the start (module docstring)."""
    scaling, curves = model
    laws = ports.select(ports.kinds != NONE)
    n = system.n_dof
    omega = abs(float(load.omega[0]))
    if omega < REST_RPM * RPM:  # at rest where the driveline holds the block (none: at zero)
        held = driveline_reaction(engine, manoeuvre, load.driveline_torque[0])
        x0 = (_static_state(system, scaling, curves, held, manoeuvre.file) if held.any() else np.zeros(n))
        state = laws.initial_state(x0) if laws.kinds.size else None
        return x0, np.zeros(n), None, state, np.zeros(ports.kinds.size)
    grid = Cycles(N_THETA, 720.0 / N_THETA, 1, 1)
    stepper = DenseNewmarkStepper(system, grid)
    theta = float(load.theta[0]) + np.arange(N_THETA) * (4 * np.pi / N_THETA)
    fh, omegas = stepper.harmonics(_cycle_load(engine, manoeuvre, theta), omega, 40.0)
    factors, mean = None, None
    if curves is not None:       # the mean on the curves, the vibration on their tangents
        mean = _static_state(system, scaling, curves, fh[0].real, manoeuvre.file)
        factors, fh = curves.factors(mean), np.concatenate([0 * fh[:1], fh[1:]])
    qh, A = stepper.harmonic_state(fh, omegas, omega, stepper.system_at(factors))
    if mean is not None:
        qh[0] += mean
    x0 = qh.real.sum(0)
    v0 = (1j * omegas[:, None] * qh).real.sum(0)
    a0 = (-(omegas ** 2)[:, None] * qh).real.sum(0)
    state = start_state(ports, qh, N_THETA) if ports.kinds.size else None
    return x0, v0, a0, state, (np.zeros(ports.kinds.size) if A is None else A)


#: Newton on the curves' static point: most iterations, and the converged step relative to
#: the state or to :data:`STATIC_SCALE` [m] where the state is smaller.
STATIC_MAX_ITER, STATIC_TOL, STATIC_SCALE = 100, 1e-12, 1e-3


def _static_state(system, scaling, curves, load, file=None):
    r"""State (n,) at rest under the body load ``load`` (6,) [N, N m] on the static curves:
    :math:`\mathbf K(f)\,\mathbf x + \mathbf R^T \mathbf c = \mathbf F` by Newton on the
    tangent stiffness (:func:`~powertrain.kernels.transient.curve_state`; port laws carry no
    mean force); an InputError naming ``file`` where there is none."""
    kc = _kernel_curves(system, scaling, curves)
    rows, n_net = kc[0], kc[0].shape[0]
    F = np.zeros(system.n_dof)
    F[:load.shape[0]] = load
    x, law = np.zeros(system.n_dof), np.ones((n_net, 2))
    f, c = np.empty(n_net), np.empty(n_net)
    for _ in range(STATIC_MAX_ITER):
        curve_state(x, kc, law, rows @ x, f, c)
        K = system.K + np.tensordot(f - scaling.assembled[:, 0], scaling.K_parts, 1)
        dx = np.linalg.solve(K, F - K @ x - rows.T @ c)
        x += dx
        if np.max(np.abs(dx)) <= STATIC_TOL * max(np.max(np.abs(x)), STATIC_SCALE):
            _check_within_curves(curves, rows @ x, system.network_names, file)
            return x
    raise InputError("no static point of the first load on the mounts' static curves (not "
                     f"converged in {STATIC_MAX_ITER} iterations): a mean torque or gear ratio "
                     "beyond what they carry?", file=file or None, key="load")


def _check_within_curves(curves, u, names, file):
    """Refuse a static point farther beyond a static curve's points than they span."""
    for r in np.flatnonzero(curves.has):
        breaks, _, count = curves.support.cubics
        lo, hi = breaks[r, 0], breaks[r, count[r] - 1]
        d = curves.d0[r] + u[r]
        if not lo - (hi - lo) <= d <= hi + (hi - lo):
            raise InputError(f"the static point of the first load deflects {names[r]} "
                             f"{d * 1e3:.4g} mm, beyond its static curve's points "
                             f"({lo * 1e3:.4g} to {hi * 1e3:.4g} mm) by more than they span: "
                             "a mean torque or gear ratio beyond what the mounts carry?",
                             file=file or None, key="load")


def _cycle_load(engine, manoeuvre, theta):
    """Load (N_THETA, 6) at ``theta`` [rad] of the manoeuvre held at its first speed and load."""
    w0 = float(manoeuvre.speed[0])
    T = 4 * np.pi / abs(w0)
    held = dataclasses.replace(manoeuvre, time=np.array([0.0, T]), speed=np.full(2, w0),
                               load_time=np.array([0.0, T]),
                               load=np.full(2, float(manoeuvre.load_at(0.0))), starter=None,
                               trigger_time=0.0)
    with warnings.catch_warnings():     # the manoeuvre's own load says it once
        warnings.simplefilter("ignore", TorqueLimitWarning)
        return transient_load(engine, held, (theta - theta[0]) / abs(w0)).F


class _Curves:
    """The networks' static curves about the zero-torque static point."""

    def __init__(self, engine, system):
        self.support = support = StaticSupport.of(engine)
        self.stiffness = support.stiffness
        rpm = engine.speed_range_rpm()[0]
        self.d0 = operating_point(engine, rpm, support, mean_torque=0.0).deflection.ravel()
        self.rows = system.port_rows
        self.has = np.array([c is not None for c in support.curves])
        self.f0 = support.forces(self.d0)

    def kernel_tuple(self):
        """``(d0, f0, breaks, coefficients, count, reference tangent, has)``."""
        return (self.d0, self.f0, *self.support.cubics, self.support.reference_tangent, self.has)

    def factors(self, x):
        """Static factor of every network at the state ``x`` (1 without a curve)."""
        return self.support.factors(self.d0 + self.rows @ x)
