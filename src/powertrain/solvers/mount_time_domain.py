r"""Time-domain verification of a mount model: Newmark integration processed by FFT.

As the thesis's verification in AVL Excite (Kovarik 2016, sec. 3.2), from the exactly periodic
state of the discrete recurrence (:func:`~powertrain.solvers.newmark.periodic_state`), with
the cycle-to-cycle periodicity reported. :func:`time_cross_point_stiffness` is the
rate-machine test (sec. 1.8, Fig. 13: :math:`x_1 = X\sin\omega t`, base grounded,
:math:`K_{CP} = \hat F_T/X`); :func:`time_forced_response` the verification set-up (sec. 3.2,
Appendix A: :math:`F\cos\omega t` on an engine mass on the mount).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.kernels.port_forces import port_force_loop
from powertrain.physics.mount_network import ground_force_rows, network_matrices
from powertrain.solvers.newmark import newmark, periodic_state

#: Default number of Newmark steps per excitation period: period error (2π/N)²/12 ≈ 3e-6.
STEPS_PER_PERIOD = 1024


@dataclass
class TimeDomainResult:
    """Per-frequency harmonic results of a time-domain run."""

    frequency_hz: np.ndarray
    kcp: np.ndarray            #: cross-point stiffness [N/m] (F_T / X_1)
    x1: np.ndarray             #: engine-side displacement amplitude [m]
    ft: np.ndarray             #: transmitted force amplitude [N]
    periodicity: np.ndarray    #: max |s(t+T) - s(t)| / max |s| over the window


def _run_periodic(M, C, K, F_one_period, h):
    x0, v0, a0 = periodic_state(M, C, K, F_one_period, h)
    N = F_one_period.shape[0] - 1
    F_two = np.concatenate([F_one_period, F_one_period[1:]])  # two periods
    X, V, _ = newmark(M, C, K, F_two, h, x0, v0, a0)
    return X, V, N


def _periodicity(sig, N):
    scale = np.max(np.abs(sig)) or 1.0
    return float(np.max(np.abs(sig[N:2 * N] - sig[:N])) / scale)


def time_cross_point_stiffness(model, frequency_hz, amplitude=1e-4,
                               steps_per_period=STEPS_PER_PERIOD) -> TimeDomainResult:
    r"""Cross-point stiffness: first harmonic of the base force over that of the imposed
    :math:`x_1 = X\sin\omega t` (base grounded; Kovarik 2016 Fig. 13).

    A mount element's network is scaled by its amplitude law at :math:`A = X`, its port law
    integrated along the motion from its steady loop
    (:func:`powertrain.kernels.port_forces.port_force_loop`). The second of two periods is
    transformed; ``periodicity`` is max |F(t+T) - F(t)| over max |F|.

    Parameters
    ----------
    model : MountModel or MountElement
    frequency_hz : array_like
        [Hz], > 0.
    amplitude : float
        Engine-side displacement amplitude X [m] (default 0.1 mm, the thesis's).
    steps_per_period : int
        Newmark steps per period.
    """
    element = model.element() if hasattr(model, "element") else model
    freqs = np.atleast_1d(np.asarray(frequency_hz, float))
    if np.any(freqs <= 0):
        raise ValueError("time-domain method needs frequencies > 0 Hz")
    N = int(steps_per_period)
    phase = 2 * np.pi * np.arange(2 * N + 1) / N
    x1 = amplitude * np.sin(phase)
    law_amplitude = np.sqrt(2 * np.mean(x1[N:2 * N] ** 2))
    masses, elem_nodes, c, d = element.network(law_amplitude)
    M, C, K = network_matrices(masses, elem_nodes, c, d)
    kg, dg = ground_force_rows(masses.size, elem_nodes, c, d)
    out_k, out_p = [], []
    for f in freqs:
        w = 2 * np.pi * f
        h = 1.0 / (f * N)
        v1 = amplitude * w * np.cos(phase)
        X, V = _driven(M, C, K, x1, v1, h, N)
        ft = X @ kg + V @ dg + _port_force(element.port_law, x1, v1, amplitude)
        out_k.append(harmonic_amplitudes(ft[N:2 * N])[1] / harmonic_amplitudes(x1[N:2 * N])[1])
        out_p.append(_periodicity(ft, N))
    kcp = np.array(out_k)
    return TimeDomainResult(freqs, kcp, np.full(freqs.size, amplitude, complex),
                            kcp * amplitude, np.array(out_p))


def _driven(M, C, K, x1, v1, h, N):
    """Motion ``(X, V)`` of the network, engine-side node prescribed (``x1``, ``v1``)."""
    if M.shape[0] == 1:
        return x1[:, None], v1[:, None]
    Mi, Ci, Ki = M[1:, 1:], C[1:, 1:], K[1:, 1:]
    Fi = -(np.outer(x1[:N + 1], K[1:, 0]) + np.outer(v1[:N + 1], C[1:, 0]))
    Xi, Vi, _ = _run_periodic(Mi, Ci, Ki, Fi, h)
    return np.column_stack([x1, Xi]), np.column_stack([v1, Vi])


def _port_force(law, x1, v1, amplitude):
    """Force [N] of the port ``law`` (None: zero) along ``x1``, ``v1`` from its steady loop."""
    if law is None:
        return 0.0
    U = np.ascontiguousarray(x1[:, None])
    F = np.zeros_like(U)
    state = np.atleast_2d(law.steady_state(amplitude)).astype(float)
    port_force_loop(np.array([law.kind], np.int64), np.atleast_2d(law.parameters()), state,
                    U, np.ascontiguousarray(v1[:, None]), F)
    return F[:, 0]


def time_forced_response(model, frequency_hz, engine_mass, force,
                         steps_per_period=STEPS_PER_PERIOD) -> TimeDomainResult:
    """An ``engine_mass`` [kg] on the mount ``model`` under ``force`` cos(ωt) [N] at
    ``frequency_hz`` [Hz], ``steps_per_period`` Newmark steps per period, by FFT (thesis
    sec. 3.2)."""
    freqs = np.atleast_1d(np.asarray(frequency_hz, float))
    if np.any(freqs <= 0):
        raise ValueError("time-domain method needs frequencies > 0 Hz")
    masses, elem_nodes, c, d = model.network()
    M, C, K = model.matrices()
    M = M.copy()
    M[0, 0] += engine_mass
    kg, dg = ground_force_rows(masses.size, elem_nodes, c, d)
    n = M.shape[0]
    res_x, res_f, res_p = [], [], []
    for f in freqs:
        N = int(steps_per_period)
        h = 1.0 / (f * N)
        t = np.arange(N + 1) * h
        F = np.zeros((N + 1, n))
        F[:, 0] = force * np.cos(2 * np.pi * f * t)
        X, V, N = _run_periodic(M, C, K, F, h)
        ft = X @ kg + V @ dg
        res_x.append(harmonic_amplitudes(X[N:2 * N, 0])[1])
        res_f.append(harmonic_amplitudes(ft[N:2 * N])[1])
        res_p.append(max(_periodicity(X[:, 0], N), _periodicity(ft, N)))
    x1 = np.array(res_x)
    ft = np.array(res_f)
    return TimeDomainResult(freqs, ft / x1, x1, ft, np.array(res_p))
