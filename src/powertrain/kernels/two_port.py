r"""Compiled kernel: two-port dynamic stiffness of a mount network with a scaled elastomer.

The one implementation of the mount two-port condensation (wrapped by
:func:`powertrain.physics.mount_network.two_port`, used by the cached harmonic model and the
truth generator). For one lumped network (internal point masses joined by Kelvin–Voigt
elements to its engine-side node E, its ground node B and each other) and a list of
frequencies :math:`\omega_w` with a spring factor :math:`s_w` and a damper factor
:math:`t_w` each, the kernel forms the nodal dynamic stiffness

.. math:: \mathbf D_w = s_w\mathbf K + i\omega_w t_w\mathbf C - \omega_w^2\mathbf M

(springs and dampers scaled, the masses kept: :meth:`MountModel.scaled`) and condenses the
internal nodes by Gaussian elimination (symmetric pivoting on the largest remaining
diagonal; the pivot is checked: below :data:`PIVOT_RTOL` times the largest entry the
network is singular at that frequency, the outputs are NaN and the status is 1), leaving the
2×2 two-port

.. math:: \begin{pmatrix} F_E \\ F_B \end{pmatrix} =
          \begin{pmatrix} a & b \\ b & c \end{pmatrix}
          \begin{pmatrix} x_E \\ x_B \end{pmatrix}

(:math:`a = K_{IP}` with the ground fixed, :math:`b = -K_{CP}`; checked against the
independent solves of :func:`~powertrain.physics.mount_network.input_point_stiffness` and
:func:`~powertrain.physics.mount_network.cross_point_stiffness` in tests/test_two_port.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Smallest pivot, relative to the largest entry of the nodal matrix, accepted as regular.
PIVOT_RTOL = 1e-13


@njit(cache=True)
def two_port_kernel(omega, spring_scale, damper_scale, masses, elem_nodes, c, d, out_a, out_b,
                    out_c):
    """Fill ``out_a``, ``out_b``, ``out_c`` (n_w,) complex with the two-port of one network.

    Parameters
    ----------
    omega, spring_scale, damper_scale : ndarray (n_w,) float
        Angular frequency [rad/s], spring and damper factors [1] of each entry.
    masses : ndarray (n,) float
        Internal masses [kg] (zero allowed).
    elem_nodes : ndarray (n_el, 2) int
        Node pairs; 0 = engine side, 1..n internal, −1 = ground.
    c, d : ndarray (n_el,) float
        Element stiffness [N/m] and damping [N·s/m].
    out_a, out_b, out_c : ndarray (n_w,) complex
        Filled with :math:`a = K_{IP}`, the coupling :math:`b` and the ground-side
        :math:`c` [N/m].

    Returns
    -------
    int
        0, or 1 if a pivot was below :data:`PIVOT_RTOL` at some frequency (NaN there).
    """
    status = 0
    n = masses.size
    size = n + 2
    D = np.empty((size, size), np.complex128)
    gone = np.zeros(size, np.bool_)          # eliminated internal nodes
    for w in range(omega.size):
        om = omega[w]
        s = spring_scale[w]
        t = damper_scale[w]
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
            if s == t:
                z = s * (c[e] + 1j * om * d[e])
            else:
                z = s * c[e] + 1j * om * t * d[e]
            D[ia, ia] += z
            D[ib, ib] += z
            D[ia, ib] -= z
            D[ib, ia] -= z
        big = 0.0
        for i in range(size):
            for j in range(size):
                if abs(D[i, j]) > big:
                    big = abs(D[i, j])
        singular = False
        for _ in range(n):                  # boundary nodes 0 and n + 1 are never eliminated
            k = -1
            best = -1.0
            for i in range(1, n + 1):
                if not gone[i] and abs(D[i, i]) > best:
                    best = abs(D[i, i])
                    k = i
            if best <= PIVOT_RTOL * big:
                singular = True
                break
            gone[k] = True
            p = D[k, k]
            for i in range(size):
                if not gone[i]:
                    f = D[i, k] / p
                    if f != 0.0:
                        for j in range(size):
                            if not gone[j]:
                                D[i, j] -= f * D[k, j]
        if singular:
            status = 1
            out_a[w] = np.nan
            out_b[w] = np.nan
            out_c[w] = np.nan
            continue
        out_a[w] = D[0, 0]
        out_b[w] = D[0, n + 1]
        out_c[w] = D[n + 1, n + 1]
    return status
