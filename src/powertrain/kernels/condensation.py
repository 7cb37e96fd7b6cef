r"""Compiled kernel: the assembled system's dynamic stiffness with its mount networks
condensed to two-ports, at many values of the Laplace variable.

For each :math:`s_w` it fills

.. math:: \mathbf D_w = s_w^2\mathbf M_0 + s_w\mathbf C_0 + \mathbf K_0
          + \sum_n a_{wn}\,\mathbf e_n\mathbf e_n^T
          + b_{wn}\,(\mathbf e_n\boldsymbol\beta_n^T + \boldsymbol\beta_n\mathbf e_n^T)
          + c_{wn}\,\boldsymbol\beta_n\boldsymbol\beta_n^T

(:math:`\mathbf e_n` network n's engine-side row, :math:`\boldsymbol\beta_n` its base row;
the maths is in :mod:`powertrain.physics.condensation`, whose
:func:`~powertrain.physics.condensation.condensed_matrix` is the one caller). The networks'
terms are symmetric and a row moves only some coordinates (the rigid body, or the body
modes): the kernel lists each network's nonzero upper-triangle entries once and sums over
them in real arithmetic (real rows times complex two-ports), with no temporary of the size
of the result. Checked against the dense NumPy sum in tests/test_two_port.py.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from powertrain.kernels.small_solve import solve_in_place


@njit(cache=True, nogil=True)
def condensed_matrix_kernel(s, M0, C0, K0, E, B, a, b, c, D):
    """Fill ``D`` (n_w, n, n) complex.

    Parameters
    ----------
    s : ndarray (n_w,) complex
        Laplace variable [1/s].
    M0, C0, K0 : ndarray (n, n) float
        The frame's mass, damping and stiffness (the networks not in them).
    E, B : ndarray (n_net, n) float
        Engine-side and base rows; ``B`` with no rows: every base grounded (``b``, ``c``
        unused).
    a, b, c : ndarray (n_w, n_net) complex
        The networks' two-ports.
    D : ndarray (n_w, n, n) complex
        Filled.
    """
    terms = _all_terms(E, B)
    U = np.empty((2, M0.shape[0] ** 2))          # real, imaginary upper triangle
    for w in range(s.size):
        _fill(w, s[w], M0, C0, K0, terms, a, b, c, U, D[w])


@njit(cache=True, nogil=True)
def condensed_solve_kernel(s, M0, C0, K0, E, B, a, b, c, load, x):
    r"""Fill ``x`` (n_w, n) complex with the solutions of :math:`\mathbf D_w\mathbf x_w =
    [\mathbf f_w; \mathbf 0]`, ``load`` (n_w, n_f) complex the first n_f entries of the
    right-hand side (the other arguments as :func:`condensed_matrix_kernel`): each matrix
    filled as that kernel fills it and solved as
    :func:`~powertrain.kernels.small_solve.batched_solve_kernel` solves it, without
    keeping the matrices. Returns 0, or 1 when some matrix has an exactly zero pivot (its
    solution NaN)."""
    n = M0.shape[0]
    terms = _all_terms(E, B)
    U = np.empty((2, n * n))
    A = np.empty((n, n), np.complex128)
    status = 0
    y = np.empty(n, np.complex128)
    n_f = load.shape[1]
    for w in range(s.size):
        _fill(w, s[w], M0, C0, K0, terms, a, b, c, U, A)
        for i in range(n):
            y[i] = 0.0
        for i in range(n_f):
            y[i] = load[w, i]
        status |= solve_in_place(A, y)
        for i in range(n):
            x[w, i] = y[i]
    return status


@njit(cache=True, nogil=True)
def _all_terms(E, B):
    """The networks' terms ``[E E, E B, B B]`` (:func:`_outer_terms`; ``[E E]`` when ``B``
    has no rows)."""
    terms = [_outer_terms(E, E, True)]
    if B.shape[0]:
        terms += [_outer_terms(E, B, False), _outer_terms(B, B, True)]
    return terms


@njit(cache=True, nogil=True, inline="always")
def _fill(w, sw, M0, C0, K0, terms, a, b, c, U, Dw):
    r"""Fill ``Dw`` (n, n) with :math:`\mathbf D_w` (``U`` (2, n²) work space)."""
    n = M0.shape[0]
    U[:] = 0.0
    for kind in range(len(terms)):
        z = (a, b, c)[kind]
        net, pos, val = terms[kind]
        for t in range(net.size):
            zt = z[w, net[t]]
            U[0, pos[t]] += zt.real * val[t]
            U[1, pos[t]] += zt.imag * val[t]
    s2 = sw * sw
    for i in range(n):
        for j in range(n):
            u = min(i, j) * n + max(i, j)
            Dw[i, j] = s2 * M0[i, j] + sw * C0[i, j] + K0[i, j] + (U[0, u] + 1j * U[1, u])


@njit(cache=True, nogil=True)
def _outer_terms(R, S, same):
    """The nonzero upper-triangle entries of each network's ``r sᵀ`` (``same``: ``R`` is
    ``S``) or ``r sᵀ + s rᵀ``: ``(network, flat position i·n + j with i <= j, value)``."""
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
