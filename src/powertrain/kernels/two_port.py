r"""Compiled kernel: two-port dynamic stiffness of a mount network with a scaled elastomer.

For one lumped network (internal point masses joined by Kelvin–Voigt elements to its
engine-side node E, its ground node B and each other) and a list of frequencies
:math:`\omega_w` with an elastomer factor :math:`s_w` each, the kernel forms the nodal
dynamic stiffness

.. math:: \mathbf D_w = s_w(\mathbf K + i\omega_w\mathbf C) - \omega_w^2\mathbf M

(every spring and damper scaled, the masses kept: :meth:`MountModel.scaled` with
``stiffness = damping = s``) and condenses the internal nodes by Gaussian elimination
(symmetric pivoting on the largest remaining diagonal), leaving the 2×2 two-port

.. math:: \begin{pmatrix} F_E \\ F_B \end{pmatrix} =
          \begin{pmatrix} a & b \\ b & c \end{pmatrix}
          \begin{pmatrix} x_E \\ x_B \end{pmatrix}

of :func:`powertrain.solvers.fast_harmonic.two_port` (which does the same with batched
LAPACK solves and no scaling; the two agree to round-off, tests/test_diagnose.py). Used where
the scale changes with every speed and iteration (amplitude-dependent mounts), where the
batched NumPy path spends its time in call overhead on 2×2–3×3 systems.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def two_port_kernel(omega, scale, masses, elem_nodes, c, d, out_a, out_b, out_c):
    """Fill ``out_a``, ``out_b``, ``out_c`` (n_w,) complex with the two-port of one network.

    Parameters
    ----------
    omega, scale : ndarray (n_w,) float
        Angular frequency [rad/s] and elastomer factor [1] of each entry.
    masses : ndarray (n,) float
        Internal masses [kg] (zero allowed).
    elem_nodes : ndarray (n_el, 2) int
        Node pairs; 0 = engine side, 1..n internal, −1 = ground.
    c, d : ndarray (n_el,) float
        Element stiffness [N/m] and damping [N·s/m].
    out_a, out_b, out_c : ndarray (n_w,) complex
        Filled with :math:`a = K_{IP}`, the coupling :math:`b` and the ground-side
        :math:`c` [N/m].
    """
    n = masses.size
    size = n + 2
    D = np.empty((size, size), np.complex128)
    gone = np.zeros(size, np.bool_)          # eliminated internal nodes
    for w in range(omega.size):
        om = omega[w]
        s = scale[w]
        for i in range(size):
            gone[i] = False
            for j in range(size):
                D[i, j] = 0.0
        for k in range(n):
            D[k + 1, k + 1] = -om * om * masses[k]
        for e in range(c.size):
            ia = elem_nodes[e, 0]
            ib = elem_nodes[e, 1]
            if ia < 0:
                ia = n + 1
            if ib < 0:
                ib = n + 1
            z = s * (c[e] + 1j * om * d[e])
            D[ia, ia] += z
            D[ib, ib] += z
            D[ia, ib] -= z
            D[ib, ia] -= z
        for _ in range(n):                  # boundary nodes 0 and n + 1 are never eliminated
            k = -1
            best = -1.0
            for i in range(1, n + 1):
                if not gone[i] and abs(D[i, i]) > best:
                    best = abs(D[i, i])
                    k = i
            gone[k] = True
            p = D[k, k]
            for i in range(size):
                if not gone[i]:
                    f = D[i, k] / p
                    if f != 0.0:
                        for j in range(size):
                            if not gone[j]:
                                D[i, j] -= f * D[k, j]
        out_a[w] = D[0, 0]
        out_b[w] = D[0, n + 1]
        out_c[w] = D[n + 1, n + 1]
