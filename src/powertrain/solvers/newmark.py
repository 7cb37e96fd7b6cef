r"""Public Newmark average-acceleration integrator and its periodic steady state.

:func:`newmark` validates, allocates and calls :func:`powertrain.kernels.newmark.newmark_kernel`.
:func:`periodic_state` finds the exactly periodic steady state of the *discrete* Newmark
recurrence under a periodic load (shooting: the one-period map :math:`z \mapsto \Phi z + g`
is affine, so :math:`z_0 = (I-\Phi)^{-1} g`), so time-domain results need no transient to die
out and do not borrow anything from the frequency-domain solution.
"""

from __future__ import annotations

import numpy as np

from powertrain.kernels.newmark import newmark_kernel


def _prepare(M, C, K, h):
    M = np.ascontiguousarray(M, dtype=float)
    C = np.ascontiguousarray(C, dtype=float)
    K = np.ascontiguousarray(K, dtype=float)
    n = M.shape[0]
    if M.shape != (n, n) or C.shape != (n, n) or K.shape != (n, n):
        raise ValueError("M, C, K must be square and of equal size")
    if not (np.isfinite(h) and h > 0):
        raise ValueError("time step must be positive")
    S = M + 0.5 * h * C + 0.25 * h * h * K
    Sinv = np.linalg.inv(S)
    return Sinv, np.ascontiguousarray(Sinv @ C), np.ascontiguousarray(Sinv @ K)


def newmark(M, C, K, F, h, x0=None, v0=None, a0=None):
    """Integrate M x'' + C x' + K x = f(t) with constant step ``h`` [s].

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m] (or consistent generalized units).
    F : ndarray (n_steps + 1, n)
        Load at every time point t_k = k h [N].
    h : float
        Time step [s].
    x0, v0, a0 : ndarray (n,), optional
        Initial state; zeros by default. When ``a0`` is omitted and M is regular it is made
        consistent: a0 = M^-1 (f0 - C v0 - K x0).

    Returns
    -------
    X, V, A : ndarray (n_steps + 1, n)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    F = np.asarray(F, dtype=float)
    n = G.shape[0]
    if F.ndim != 2 or F.shape[1] != n:
        raise ValueError("F must have shape (n_steps + 1, n)")
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float).copy()
    v0 = np.zeros(n) if v0 is None else np.asarray(v0, float).copy()
    if a0 is None:
        try:
            a0 = np.linalg.solve(M, F[0] - C @ v0 - K @ x0)
        except np.linalg.LinAlgError:
            a0 = np.zeros(n)
    a0 = np.asarray(a0, float).copy()
    Fs = np.ascontiguousarray(F @ Sinv.T)
    X = np.empty_like(Fs)
    V = np.empty_like(Fs)
    A = np.empty_like(Fs)
    newmark_kernel(G, H, Fs, float(h), x0, v0, a0, X, V, A)
    return X, V, A


def periodic_state(M, C, K, F_period, h):
    """Initial state (x0, v0, a0) of the periodic steady state of the Newmark recurrence.

    Parameters
    ----------
    F_period : ndarray (N + 1, n)
        Load over exactly one period, ``F_period[N] == F_period[0]``.
    h : float
        Time step [s]; N h is the period.

    Returns
    -------
    x0, v0, a0 : ndarray (n,)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    F_period = np.asarray(F_period, float)
    n = G.shape[0]
    N = F_period.shape[0] - 1
    zero = np.zeros((N + 1, n))
    Fs = np.ascontiguousarray(F_period @ Sinv.T)
    X = np.empty_like(Fs)
    V = np.empty_like(Fs)
    A = np.empty_like(Fs)
    # forced response from rest -> g
    newmark_kernel(G, H, Fs, float(h), np.zeros(n), np.zeros(n), np.zeros(n), X, V, A)
    g = np.concatenate([X[-1], V[-1], A[-1]])
    # free response of each unit state -> columns of Phi
    Phi = np.empty((3 * n, 3 * n))
    e = np.zeros(3 * n)
    for col in range(3 * n):
        e[:] = 0.0
        e[col] = 1.0
        newmark_kernel(G, H, zero, float(h), e[:n].copy(), e[n:2 * n].copy(), e[2 * n:].copy(),
                       X, V, A)
        Phi[:, col] = np.concatenate([X[-1], V[-1], A[-1]])
    z0 = np.linalg.lstsq(np.eye(3 * n) - Phi, g, rcond=None)[0]
    return z0[:n], z0[n:2 * n], z0[2 * n:]
