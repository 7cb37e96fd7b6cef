r"""Two-port dynamic stiffness of a lumped mount network (point masses joined by Kelvin–Voigt
elements to its engine-side node E, ground node B and each other).

The nodal matrix :math:`\mathbf D_w = s_w\mathbf K + \lambda_w t_w\mathbf C + \lambda_w^2\mathbf M`
is condensed by eliminating the internal nodes (symmetric pivoting on the largest diagonal)
to :math:`F_E = a x_E + b x_B`, :math:`F_B = b x_E + c x_B` (:math:`a = K_{IP}`,
:math:`b = -K_{CP}`); :func:`kcp_gradient_kernel` gives :math:`K_{CP}`'s parameter
derivatives (:func:`powertrain.physics.mount_network.cross_point_stiffness_gradient`).
"""

import numpy as np
from numba import njit

#: Smallest pivot, relative to the largest entry of the nodal matrix, accepted as regular.
PIVOT_RTOL = 1e-13


@njit(cache=True, nogil=True)
def condense_nodes(D, n, order, X, gone):
    """Eliminate the internal nodes 1..n of ``D`` (n + 2, n + 2) in place, leaving the two-port
    in ``D[0, 0]``, ``D[0, n + 1]``, ``D[n + 1, n + 1]`` and, if ``X`` has n + 2 rows, the
    nodal motion per unit engine-side / ground motion in its columns. ``order`` (n,) and
    ``gone`` (n + 2,) are work space. False if the network is singular."""
    size = n + 2
    big2 = 0.0                    # the largest entry by its squared modulus (no hypot)
    for i in range(size):
        for j in range(size):
            m2 = D[i, j].real * D[i, j].real + D[i, j].imag * D[i, j].imag
            if m2 > big2:
                big2 = m2
    gone[:] = False
    for step in range(n):             # boundary nodes 0 and n + 1 are never eliminated
        k, best2 = -1, -1.0           # squared moduli: the same pivot as by modulus
        for i in range(1, n + 1):
            m2 = D[i, i].real * D[i, i].real + D[i, i].imag * D[i, i].imag
            if not gone[i] and m2 > best2:
                best2, k = m2, i
        if best2 <= PIVOT_RTOL * PIVOT_RTOL * big2:
            return False
        gone[k] = True
        order[step] = k
        p = D[k, k]
        for i in range(size):
            if not gone[i]:
                f = D[i, k] / p
                if f != 0.0:
                    for j in range(size):
                        if not gone[j]:
                            D[i, j] -= f * D[k, j]
    if X.shape[0] == size:
        for col in range(2):
            for i in range(size):
                X[i, col] = 0.0
            X[0 if col == 0 else n + 1, col] = 1.0
            # row k keeps its entries of the nodes still present when k was eliminated
            for step in range(n - 1, -1, -1):
                k = order[step]
                acc = D[k, 0] * X[0, col] + D[k, n + 1] * X[n + 1, col]
                for later in range(step + 1, n):
                    j = order[later]
                    acc += D[k, j] * X[j, col]
                X[k, col] = -acc / D[k, k]
    return True


@njit(cache=True, nogil=True)
def two_port_kernel(lam, spring_scale, damper_scale, masses, elem_nodes, c, d, out_a, out_b,
                    out_c, out_x):
    """Fill ``out_a``, ``out_b``, ``out_c`` (n_w,) complex with the two-port of one network.

    Parameters
    ----------
    lam : ndarray (n_w,) complex
        Laplace variable (:math:`i\\omega` for a harmonic) [1/s].
    spring_scale, damper_scale : ndarray (n_w,) float
        Spring and damper factors [1].
    masses : ndarray (n,) float
        Internal masses [kg] (zero allowed).
    elem_nodes : ndarray (n_el, 2) int
        Node pairs; 0 = engine side, 1..n internal, −1 = ground.
    c, d : ndarray (n_el,) float
        Element stiffness [N/m] and damping [N·s/m].
    out_a, out_b, out_c : ndarray (n_w,) complex
        Output :math:`a = K_{IP}`, :math:`b`, :math:`c` [N/m].
    out_x : ndarray (n_w, n, 2) complex or (0, n, 2)
        Output if not empty: internal motion per unit engine-side and ground motion.

    Returns
    -------
    int
        0, or 1 if singular at some entry (NaN there).
    """
    status, n, size = 0, masses.size, masses.size + 2
    D, order, gone = np.empty((size, size), np.complex128), np.empty(n, np.int64), np.empty(size, np.bool_)
    X = np.empty((size if out_x.shape[0] else 0, 2), np.complex128)
    for w in range(lam.size):
        nodal_matrix(lam[w], spring_scale[w], damper_scale[w], masses, elem_nodes, c, d, D)
        if not condense_nodes(D, n, order, X, gone):
            status = 1
            out_a[w] = out_b[w] = out_c[w] = np.nan
            continue
        out_a[w], out_b[w], out_c[w] = D[0, 0], D[0, n + 1], D[n + 1, n + 1]
        if out_x.shape[0]:
            for i in range(n):
                out_x[w, i, 0], out_x[w, i, 1] = X[i + 1, 0], X[i + 1, 1]
    return status


@njit(cache=True, nogil=True)
def two_ports_kernel(lam, spring_scale, damper_scale, mass_ptr, masses, el_ptr, elem_nodes, c,
                     d, out_a, out_b, out_c):
    """:func:`two_port_kernel` of several networks at ``lam``: network k has the masses
    ``masses[mass_ptr[k]:mass_ptr[k + 1]]`` and the elements ``el_ptr[k]:el_ptr[k + 1]`` of
    ``elem_nodes``, ``c``, ``d``; its factors and outputs are row k of ``spring_scale``,
    ``damper_scale``, ``out_a``, ``out_b``, ``out_c`` (n_net, n_w). Returns 0, or 1 if some
    network was singular somewhere (NaN there)."""
    no_x, status = np.empty((0, 0, 2), np.complex128), 0
    for k in range(out_a.shape[0]):
        m0, m1, e0, e1 = mass_ptr[k], mass_ptr[k + 1], el_ptr[k], el_ptr[k + 1]
        status |= two_port_kernel(lam, spring_scale[k], damper_scale[k], masses[m0:m1],
                                  elem_nodes[e0:e1], c[e0:e1], d[e0:e1], out_a[k],
                                  out_b[k], out_c[k], no_x)
    return status


@njit(cache=True, nogil=True)
def nodal_matrix(lam, s, t, masses, elem_nodes, c, d, D):
    """Fill ``D`` (n + 2, n + 2) with :math:`s\\mathbf K + \\lambda t\\mathbf C +
    \\lambda^2\\mathbf M` over the nodes engine side (0), internal (1..n), ground (n + 1)
    (``lam``, ``s``, ``t``; ``masses``, ``elem_nodes``, ``c``, ``d`` as :func:`two_port_kernel`)."""
    n = masses.size
    D[:, :] = 0.0
    for k in range(n):
        D[k + 1, k + 1] = lam * lam * masses[k]
    for e in range(c.size):
        ia, ib = elem_nodes[e, 0], elem_nodes[e, 1]
        if ia < 0:
            ia = n + 1
        if ib < 0:
            ib = n + 1
        if s == t:
            z = s * (c[e] + lam * d[e])
        else:
            z = s * c[e] + lam * t * d[e]
        D[ia, ia] += z
        D[ib, ib] += z
        D[ia, ib] -= z
        D[ib, ia] -= z


@njit(cache=True, nogil=True)
def kcp_gradient_kernel(omega, B, masses, c, d, kcp, dk_dm, dk_dc, dk_dd):
    """Fill the cross-point stiffness and its parameter derivatives at every frequency.

    Parameters
    ----------
    omega : ndarray (n_freq,)
        Angular frequency [rad/s].
    B : ndarray (n_el, n + 2)
        Incidence over engine side (0), internal nodes (1..n), ground (n + 1).
    masses : ndarray (n,)
        Internal masses [kg].
    c, d : ndarray (n_el,)
        Element stiffness [N/m] and damping [N·s/m].
    kcp : ndarray complex (n_freq,)
        Output, cross-point stiffness [N/m].
    dk_dm, dk_dc, dk_dd : ndarray complex (n_freq, n), (n_freq, n_el), (n_freq, n_el)
        Output derivatives [N/(m·kg)], [1], [1/s].

    Returns
    -------
    int
        0, or 1 if singular at some frequency (NaN there).
    """
    n_el, n, status = B.shape[0], B.shape[1] - 2, 0
    D, XY = np.empty((n + 2, n + 2), dtype=np.complex128), np.empty((n + 2, 2), dtype=np.complex128)
    order, gone = np.empty(n, np.int64), np.empty(n + 2, np.bool_)
    for f in range(omega.shape[0]):
        w = omega[f]
        _incidence_nodal_matrix(1j * w, B, masses, c, d, D)
        if not condense_nodes(D, n, order, XY, gone):
            status = 1
            kcp[f] = np.nan
            for j in range(n):
                dk_dm[f, j] = np.nan
            for e in range(n_el):
                dk_dc[f, e] = dk_dd[f, e] = np.nan
            continue
        total = 0.0 + 0.0j
        for j in range(n):
            g = w * w * XY[j + 1, 0] * XY[j + 1, 1]
            dk_dm[f, j] = g
            total += g * masses[j]
        for e in range(n_el):
            u, v = 0.0 + 0.0j, 0.0 + 0.0j
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
    r"""``D`` = :math:`\mathbf B^T\operatorname{diag}(c + \lambda d)\mathbf B + \lambda^2\mathbf M`."""
    size = B.shape[1]
    D[:, :] = 0.0
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
