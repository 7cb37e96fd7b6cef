r"""Cross-point dynamic stiffness of a lumped mount network and its parameter derivatives.

Kernel behind :func:`powertrain.physics.mount_network.cross_point_stiffness_gradient`
(which documents the maths, Kovarik 2016, eq. 39 in general form). Per frequency it
assembles the internal block of :math:`\mathbf D(\omega) = \mathbf B^T\operatorname{diag}(c +
i\omega d)\mathbf B - \omega^2\mathbf M`, solves it for two right-hand sides (unit engine-side
and unit ground displacement) by Gaussian elimination with partial pivoting, and forms

.. math:: \partial K/\partial c_e = -u_e v_e,\quad \partial K/\partial d_e = -i\omega u_e v_e,
          \quad \partial K/\partial m_j = \omega^2 X_j Y_j .

The networks are small (at most a handful of internal nodes), so a hand-written dense solve
per frequency beats batched LAPACK calls by a wide margin; this matters for parameter
identification, which evaluates the Jacobian thousands of times.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def kcp_gradient_kernel(omega, B, masses, c, d, kcp, dk_dm, dk_dc, dk_dd):
    """Fill ``kcp``, ``dk_dm``, ``dk_dc``, ``dk_dd`` (complex) for every frequency.

    Parameters
    ----------
    omega : ndarray (n_freq,)
        Angular frequency [rad/s].
    B : ndarray (n_el, n + 2)
        Incidence over engine side (0), internal nodes (1..n), ground (n + 1).
    masses : ndarray (n,)
        [kg]
    c, d : ndarray (n_el,)
        [N/m], [N·s/m]
    kcp : ndarray complex (n_freq,)
        Output, cross-point stiffness [N/m].
    dk_dm, dk_dc, dk_dd : ndarray complex (n_freq, n), (n_freq, n_el), (n_freq, n_el)
        Output derivatives [N/(m·kg)], [1], [1/s].

    Returns
    -------
    int
        0 on success, 1 if the internal block was singular at some frequency (the outputs
        of that frequency are then NaN).
    """
    n_el = B.shape[0]
    n = B.shape[1] - 2
    status = 0
    A = np.empty((n, n), dtype=np.complex128)
    R = np.empty((n, 2), dtype=np.complex128)
    X = np.empty(n + 2, dtype=np.complex128)
    Y = np.empty(n + 2, dtype=np.complex128)
    for f in range(omega.shape[0]):
        w = omega[f]
        # internal block and right-hand sides: A [X Y] = -[D_iE D_iG]
        for i in range(n):
            R[i, 0] = 0.0
            R[i, 1] = 0.0
            for j in range(n):
                A[i, j] = 0.0
            A[i, i] = -w * w * masses[i]
        for e in range(n_el):
            ke = c[e] + 1j * w * d[e]
            for a in range(n):
                ba = B[e, a + 1]
                if ba == 0.0:
                    continue
                R[a, 0] -= ke * ba * B[e, 0]
                R[a, 1] -= ke * ba * B[e, n + 1]
                for b in range(n):
                    bb = B[e, b + 1]
                    if bb != 0.0:
                        A[a, b] += ke * ba * bb
        singular = False
        for k in range(n):
            p = k
            big = abs(A[k, k])
            for i in range(k + 1, n):
                if abs(A[i, k]) > big:
                    big = abs(A[i, k])
                    p = i
            if big == 0.0:
                singular = True
                break
            if p != k:
                for j in range(n):
                    A[k, j], A[p, j] = A[p, j], A[k, j]
                R[k, 0], R[p, 0] = R[p, 0], R[k, 0]
                R[k, 1], R[p, 1] = R[p, 1], R[k, 1]
            for i in range(k + 1, n):
                fac = A[i, k] / A[k, k]
                if fac != 0.0:
                    for j in range(k, n):
                        A[i, j] -= fac * A[k, j]
                    R[i, 0] -= fac * R[k, 0]
                    R[i, 1] -= fac * R[k, 1]
        if singular:
            status = 1
            kcp[f] = np.nan
            for j in range(n):
                dk_dm[f, j] = np.nan
            for e in range(n_el):
                dk_dc[f, e] = np.nan
                dk_dd[f, e] = np.nan
            continue
        for k in range(n - 1, -1, -1):
            s0 = R[k, 0]
            s1 = R[k, 1]
            for j in range(k + 1, n):
                s0 -= A[k, j] * X[j + 1]
                s1 -= A[k, j] * Y[j + 1]
            X[k + 1] = s0 / A[k, k]
            Y[k + 1] = s1 / A[k, k]
        X[0] = 1.0
        Y[0] = 0.0
        X[n + 1] = 0.0
        Y[n + 1] = 1.0
        total = 0.0 + 0.0j
        for j in range(n):
            g = w * w * X[j + 1] * Y[j + 1]
            dk_dm[f, j] = g
            total += g * masses[j]
        for e in range(n_el):
            u = 0.0 + 0.0j
            v = 0.0 + 0.0j
            for a in range(n + 2):
                be = B[e, a]
                if be != 0.0:
                    u += be * X[a]
                    v += be * Y[a]
            g = -u * v
            dk_dc[f, e] = g
            dk_dd[f, e] = 1j * w * g
            total += g * (c[e] + 1j * w * d[e])
        kcp[f] = total
    return status
