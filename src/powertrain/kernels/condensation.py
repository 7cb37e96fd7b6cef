r"""The assembled dynamic stiffness with the mount networks condensed to two-ports
(maths in :mod:`powertrain.physics.condensation`):

.. math:: \mathbf D_w = s_w^2\mathbf M_0 + s_w\mathbf C_0 + \mathbf K_0
          + \sum_n a_{wn}\,\mathbf e_n\mathbf e_n^T
          + b_{wn}\,(\mathbf e_n\boldsymbol\beta_n^T + \boldsymbol\beta_n\mathbf e_n^T)
          + c_{wn}\,\boldsymbol\beta_n\boldsymbol\beta_n^T,

:math:`\mathbf e_n`, :math:`\boldsymbol\beta_n` network n's engine-side and base rows.
"""

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def condensed_matrix_kernel(s, M0, C0, K0, E, B, a, b, c, D):
    """Fill ``D`` (n_w, n, n) complex.

    Parameters
    ----------
    s : ndarray (n_w,) complex
        Laplace variable [1/s].
    M0, C0, K0 : ndarray (n, n) float
        The frame's mass, damping and stiffness, networks excluded.
    E, B : ndarray (n_net, n) float
        Engine-side and base rows; ``B`` with no rows: every base grounded.
    a, b, c : ndarray (n_w, n_net) complex
        The networks' two-ports (``b``, ``c`` unused when ``B`` is empty).
    D : ndarray (n_w, n, n) complex
        Output.
    """
    n = M0.shape[0]
    terms = [_outer_terms(E, E, True)]
    if B.shape[0]:
        terms += [_outer_terms(E, B, False), _outer_terms(B, B, True)]
    U = np.empty((2, n * n))                     # real, imaginary upper triangle
    for w in range(s.size):
        U[:] = 0.0
        for kind in range(len(terms)):
            z = (a, b, c)[kind]
            net, pos, val = terms[kind]
            for t in range(net.size):
                zt = z[w, net[t]]
                U[0, pos[t]] += zt.real * val[t]
                U[1, pos[t]] += zt.imag * val[t]
        sw = s[w]
        s2 = sw * sw
        for i in range(n):
            for j in range(n):
                u = min(i, j) * n + max(i, j)
                D[w, i, j] = s2 * M0[i, j] + sw * C0[i, j] + K0[i, j] + (U[0, u] + 1j * U[1, u])


@njit(cache=True, nogil=True)
def _outer_terms(R, S, same):
    """``(network, flat position i·n + j, value)`` of each network's nonzero upper-triangle terms."""
    n_net, n = R.shape
    net = np.empty(n_net * n * n, np.int64)
    pos = np.empty(n_net * n * n, np.int64)
    val = np.zeros(n_net * n * n)
    m = 0
    for k in range(n_net):
        for i in range(n):
            for j in range(i, n):
                v = R[k, i] * S[k, j] if same else R[k, i] * S[k, j] + S[k, i] * R[k, j]
                if v != 0.0:
                    net[m], pos[m], val[m] = k, i * n + j, v
                    m += 1
    return net[:m], pos[:m], val[:m]
