r"""Time-domain verification of a mount model: Newmark integration processed by FFT.

The thesis verified its triple mass oscillator in AVL Excite by integrating the model in time
under a harmonic load and processing the result into the frequency domain with an FFT
(Kovarik 2016, sec. 3.2). These functions do the same with our Newmark kernel, starting from
the exactly periodic state of the discrete recurrence (:func:`~powertrain.solvers.newmark.periodic_state`)
so that no transient contaminates the window, and report the cycle-to-cycle periodicity.

Two set-ups:

* :func:`time_cross_point_stiffness` — the rate-machine test (sec. 1.8): the engine-side
  node follows :math:`x_1 = X\cos\omega t` with the base grounded, the force transmitted to
  ground is recorded, :math:`K_{CP} = \hat F_T/X`.
* :func:`time_forced_response` — the verification set-up (sec. 3.2, Appendix A): a force
  :math:`F\cos\omega t` on an engine mass carried by the mount; records :math:`\hat X_1` and
  :math:`\hat F_T`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.physics.mount_network import ground_force_rows
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
    """Cross-point stiffness by imposing x1 = X cos(ωt) and integrating the internal masses.

    Parameters
    ----------
    model : MountModel
    frequency_hz : array_like
        [Hz], > 0.
    amplitude : float
        Engine-side displacement amplitude X [m] (default 0.1 mm, the thesis's test amplitude;
        the model is linear so it cancels).
    steps_per_period : int
    """
    freqs = np.atleast_1d(np.asarray(frequency_hz, float))
    if np.any(freqs <= 0):
        raise ValueError("time-domain method needs frequencies > 0 Hz")
    masses, elem_nodes, c, d = model.network()
    M, C, K = model.matrices()
    kg, dg = ground_force_rows(masses.size, elem_nodes, c, d)
    n = M.shape[0]
    out_k, out_p = [], []
    for f in freqs:
        w = 2 * np.pi * f
        N = int(steps_per_period)
        h = 1.0 / (f * N)
        t = np.arange(2 * N + 1) * h
        x1 = amplitude * np.cos(w * t)
        v1 = -amplitude * w * np.sin(w * t)
        if n > 1:
            Mi, Ci, Ki = M[1:, 1:], C[1:, 1:], K[1:, 1:]
            # load on the internal masses from the prescribed engine-side motion
            Fi = -(np.outer(x1[:N + 1], K[1:, 0]) + np.outer(v1[:N + 1], C[1:, 0]))
            Xi, Vi, _ = _run_periodic(Mi, Ci, Ki, Fi, h)
            X = np.column_stack([x1, Xi])
            V = np.column_stack([v1, Vi])
        else:
            X, V = x1[:, None], v1[:, None]
        ft = X @ kg + V @ dg
        spec = harmonic_amplitudes(ft[N:2 * N])
        out_k.append(spec[1] / amplitude)
        out_p.append(_periodicity(ft, N))
    kcp = np.array(out_k)
    return TimeDomainResult(freqs, kcp, np.full(freqs.size, amplitude, complex),
                            kcp * amplitude, np.array(out_p))


def time_forced_response(model, frequency_hz, engine_mass, force,
                         steps_per_period=STEPS_PER_PERIOD) -> TimeDomainResult:
    """Engine mass [kg] on the mount under F cos(ωt) [N]: Newmark + FFT (thesis sec. 3.2)."""
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
