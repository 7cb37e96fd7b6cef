r"""Time-domain run of a model with nonlinear mount elements, one engine cycle at a time.

Port laws (Berg's friction, the Jenkins element) are integrated exactly, Newton per step
(:func:`powertrain.kernels.port_forces.newmark_port_kernel`), their memory carried across
steps and cycles. After each engine cycle the amplitude of every nonlinear element,
:math:`A = \sqrt 2\,` RMS of its relative displacement over the cycle, rescales its network
for the next (:class:`powertrain.assembly.NetworkScaling`), times its static factor
(:meth:`MountElement.at_operating_point`). A run starts from the harmonic fixed point
(:meth:`Stepper.harmonic_state`) with the port laws on their steady loop
(:func:`steady_loop_state`; Berg's loop started unloaded settles only slowly).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.kernels.port_forces import NONE, port_force_loop
from powertrain.physics.mount_elements import PortForces
from powertrain.solvers.newmark import newmark, newmark_ports

#: Engine cycles of prescribed harmonic motion that settle the port laws' minor loops.
LOOP_CYCLES = 2


def cycle_signal(harmonics, n_cycle) -> np.ndarray:
    """Samples (n_cycle, m) over one engine cycle of the ``harmonics`` (n_h, m), index j =
    order j/2: ``Re sum_j c_j exp(i j theta / 2)``."""
    n_h = harmonics.shape[0]
    if 2 * n_h > n_cycle:                 # up to the Nyquist harmonic: the full transform
        spectrum = np.zeros((n_cycle,) + harmonics.shape[1:], complex)
        spectrum[:n_h] = harmonics
        return (n_cycle * np.fft.ifft(spectrum, axis=0)).real
    half = np.zeros((n_cycle // 2 + 1,) + harmonics.shape[1:], complex)
    half[:n_h] = harmonics                # the real transform doubles every harmonic but 0
    half[1:n_h] *= 0.5
    return n_cycle * np.fft.irfft(half, n_cycle, axis=0)


def cycle_amplitudes(u) -> np.ndarray:
    """:math:`\\sqrt 2\\,` RMS (mean removed) over the rows of ``u`` (n, m) [m]."""
    return np.sqrt(2.0) * np.std(u, axis=0)


def steady_loop_state(ports, relative, n_cycle, cycles=LOOP_CYCLES) -> np.ndarray:
    """States (m, n_state) at t = 0 of the ``ports``' laws on their steady loop along the
    harmonic relative motion ``relative`` (n_h, m), ``n_cycle`` samples per cycle: each starts
    at the lower tip of its loop centred on the mean (no mean force) and follows the motion
    for ``cycles`` cycles (:func:`powertrain.kernels.port_forces.port_force_loop`)."""
    u = cycle_signal(relative, n_cycle)
    low = np.argmin(u, axis=0)
    m = u.shape[1]
    u_low = u[low, np.arange(m)]
    centre = u.mean(axis=0)
    state = ports.steady_states(centre - u_low, centre)
    U = np.concatenate([np.tile(u, (cycles + 1, 1)), u[:1]])
    for e in range(m):
        U[:low[e], e] = u_low[e]
    port_force_loop(ports.kinds, ports.parameters, state, U, np.zeros_like(U), np.empty_like(U))
    return state


def no_ports(system):
    """A :class:`PortForces` of ``system`` holding no element."""
    n_net = len(system.networks)
    return PortForces(np.zeros((0, system.n_dof)), np.zeros(0, np.int64), np.zeros((0, 1)),
                      [], np.zeros((len(system.channels), 0)), [], np.zeros(0, int), n_net)


def start_state(ports, qh, n_cycle):
    """The ``ports``' law states at t = 0 along the harmonic response ``qh`` (n_h, n), with
    ``n_cycle`` samples per cycle (:func:`steady_loop_state`); None without port laws."""
    laws = ports.select(ports.kinds != NONE)
    return steady_loop_state(laws, qh @ laws.rows.T, n_cycle) if laws.kinds.size else None


@dataclasses.dataclass
class CycleRun:
    """A time-domain run: states (n_t, n) ``X``, ``V``, ``A``, the port forces ``Z``
    (n_t, m; None without port laws) and the force rows the run used, ``(rows,
    force_matrix_k, force_matrix_d, offset)``: the transmitted force over ``rows`` is
    ``X Fk^T + V Fd^T - offset`` (offset (n_ch,) or None)."""

    X: np.ndarray
    V: np.ndarray
    A: np.ndarray
    Z: np.ndarray | None
    segments: list


class CycleIntegrator:
    """Integrates the nonlinear model one stretch (engine cycle) at a time at the network
    scales of the stretch before's amplitudes. The networks scale about the static deflection
    ``mean``: a stretch whose stiffness differs by dK is loaded by dK times it, so a change of
    scale does not move the static equilibrium.

    Parameters
    ----------
    scaling : NetworkScaling
    ports : PortForces
        The nonlinear elements (their rows make the amplitudes; those with a port law are
        integrated by Newton per step).
    h : float
        Time step [s].
    mean : ndarray (n,)
        Static deflection [m].
    """

    def __init__(self, scaling, ports, h, mean):
        self.scaling, self.ports, self.h, self.mean = scaling, ports, h, mean
        self.laws = ports.select(ports.kinds != NONE)
        self.varying = scaling.varying
        self._first = None

    def run(self, F, start, amplitudes, state, factors=None, scales=None):
        """States ``(X, V, A, Z)`` over the loads ``F`` (k + 1, n) [N] from ``start`` = (x, v,
        a), the port-law ``state`` updated in place, and the force rows ``(Fk, Fd, offset)``;
        the networks scaled at ``amplitudes`` [m] and static ``factors``, or by ``scales``
        (n_net, 2) if given."""
        s = self.scaling
        scales = s.scales(self.ports.network_amplitudes(amplitudes), factors) if scales is None else scales
        C, K, Fk, Fd = s.matrices(scales)
        self._first = self._first or (K, Fk)
        shifted = K is not self._first[0]
        load = F + (K - self._first[0]) @ self.mean if shifted else F
        if self.laws.kinds.size:
            X, V, A, Z = newmark_ports(s.system.M, C, K, load, self.h, self.laws, *start, state=state)
        else:
            (X, V, A), Z = newmark(s.system.M, C, K, load, self.h, *start), None
        return (X, V, A, Z), (Fk, Fd, (Fk - self._first[1]) @ self.mean if shifted else None)


def run_cycles(scaling, ports, F, h, n_cycle, start, amplitudes, factors=None) -> CycleRun:
    """Integrate the model of ``scaling`` with the nonlinear elements ``ports`` under ``F``
    (n_t, n) [N] at step ``h`` [s] from ``start`` = (x0, v0, a0, port-law states, static
    deflection [m]), the amplitude law updated every ``n_cycle`` steps from ``amplitudes``
    (m,) [m], static ``factors`` applied."""
    x0, v0, a0, state, mean = start
    integrator = CycleIntegrator(scaling, ports, h, mean)
    n_t = F.shape[0]
    bounds = list(range(0, n_t - 1, n_cycle)) + [n_t - 1] if integrator.varying else [0, n_t - 1]
    out = [np.empty((n_t, F.shape[1])) for _ in range(3)]
    out.append(np.empty((n_t, integrator.laws.kinds.size)) if integrator.laws.kinds.size else None)
    out[0][0], out[1][0], out[2][0] = x0, v0, a0
    segments = []
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        rows = slice(lo, hi + 1)
        states, forces = integrator.run(F[rows], [o[lo] for o in out[:3]], amplitudes, state, factors)
        for o, value in zip(out, states):
            if o is not None:
                o[rows] = value
        segments.append((slice(lo, hi if hi < n_t - 1 else n_t),) + forces)
        amplitudes = cycle_amplitudes(out[0][lo:hi] @ ports.rows.T)
    return CycleRun(*out, segments)
