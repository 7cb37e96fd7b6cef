r"""Cross-point dynamic stiffness of a lumped mount network and its parameter derivatives.

Kernel behind :func:`powertrain.physics.mount_network.cross_point_stiffness_gradient`
(which documents the maths, Kovarik 2016, eq. 39 in general form). Per frequency it
assembles :math:`\mathbf D(\omega) = \mathbf B^T\operatorname{diag}(c + i\omega d)\mathbf B -
\omega^2\mathbf M` and condenses its internal nodes by the one two-port elimination
(:func:`powertrain.kernels.two_port.condense_nodes`), whose back substitution gives the
internal motion for a unit engine-side and a unit ground displacement; then

.. math:: \partial K/\partial c_e = -u_e v_e,\quad \partial K/\partial d_e = -i\omega u_e v_e,
          \quad \partial K/\partial m_j = \omega^2 X_j Y_j .

The networks are small (at most a handful of internal nodes), so a hand-written dense solve
per frequency beats batched LAPACK calls by a wide margin; this matters for parameter
identification, which evaluates the Jacobian thousands of times.
"""

import numpy as np
from numba import njit

from powertrain.kernels.two_port import condense_nodes


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
    D = np.empty((n + 2, n + 2), dtype=np.complex128)
    XY = np.empty((n + 2, 2), dtype=np.complex128)
    order = np.empty(n, np.int64)
    for f in range(omega.shape[0]):
        w = omega[f]
        _incidence_nodal_matrix(1j * w, B, masses, c, d, D)
        if not condense_nodes(D, n, order, XY):
            status = 1
            kcp[f] = np.nan
            for j in range(n):
                dk_dm[f, j] = np.nan
            for e in range(n_el):
                dk_dc[f, e] = np.nan
                dk_dd[f, e] = np.nan
            continue
        total = 0.0 + 0.0j
        for j in range(n):
            g = w * w * XY[j + 1, 0] * XY[j + 1, 1]
            dk_dm[f, j] = g
            total += g * masses[j]
        for e in range(n_el):
            u = 0.0 + 0.0j
            v = 0.0 + 0.0j
            for a in range(n + 2):
                be = B[e, a]
                if be != 0.0:
                    u += be * XY[a, 0]
                    v += be * XY[a, 1]
            g = -u * v
            dk_dc[f, e] = g
            dk_dd[f, e] = 1j * w * g
            total += g * (c[e] + 1j * w * d[e])
        kcp[f] = total
    return status


@njit(cache=True, nogil=True)
def _incidence_nodal_matrix(lam, B, masses, c, d, D):
    r"""Fill ``D`` with :math:`\mathbf B^T\operatorname{diag}(c + \lambda d)\mathbf B +
    \lambda^2\operatorname{diag}(0, \mathbf m, 0)`."""
    size = B.shape[1]
    for i in range(size):
        for j in range(size):
            D[i, j] = 0.0
    for k in range(masses.size):
        D[k + 1, k + 1] = lam * lam * masses[k]
    for e in range(B.shape[0]):
        ke = c[e] + lam * d[e]
        for a in range(size):
            ba = B[e, a]
            if ba != 0.0:
                for b in range(size):
                    if B[e, b] != 0.0:
                        D[a, b] += ke * ba * B[e, b]
