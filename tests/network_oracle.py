"""Plain NumPy oracles of the condensations (issue 19: the library has one implementation,
the compiled elimination of kernels/two_port.py; these dense LAPACK solves of the assembled
matrices check it)."""

from __future__ import annotations

import numpy as np

from powertrain.physics.mount_network import incidence_matrix, network_matrices


def dense_two_port(s, masses, elem_nodes, c, d):
    """``(T (n_s, 2, 2), X (n_s, n, 2))``: the two-port [engine side, ground] of the network
    at Laplace variables ``s`` and the internal motion per unit boundary motion, by a dense
    solve of the nodal matrix with the ground node kept."""
    s = np.atleast_1d(np.asarray(s, complex))
    M, C, K = network_matrices(masses, elem_nodes, c, d, include_ground=True)
    D = K[None] + s[:, None, None] * C[None] + (s ** 2)[:, None, None] * M[None]
    n = D.shape[1] - 2
    ends, inner = [0, n + 1], list(range(1, n + 1))
    T = D[:, ends][:, :, ends]
    if not inner:
        return T, np.zeros((s.size, 0, 2), complex)
    X = -np.linalg.solve(D[:, inner][:, :, inner], D[:, inner][:, :, ends])
    return T + np.einsum("wij,wjk->wik", D[:, ends][:, :, inner], X), X


def dense_condense(system, keep, s):
    """Schur complement of ``K + sC + s^2 M`` of an assembled system on ``keep``."""
    keep = np.asarray(keep, int)
    rest = np.setdiff1d(np.arange(system.n_dof), keep)
    D = system.K + s * system.C + s * s * system.M
    out = D[np.ix_(keep, keep)]
    if rest.size:
        out = out - D[np.ix_(keep, rest)] @ np.linalg.solve(D[np.ix_(rest, rest)],
                                                             D[np.ix_(rest, keep)])
    return out


def numpy_kcp_gradient(omega, masses, elem_nodes, c, d):
    """Cross-point stiffness and its derivatives (as
    :func:`powertrain.physics.mount_network.cross_point_stiffness_gradient`) by batched
    LAPACK solves."""
    omega = np.atleast_1d(np.asarray(omega, float))
    masses, c, d = (np.asarray(x, float) for x in (masses, c, d))
    n = masses.size
    B = incidence_matrix(n, elem_nodes)
    _, X = dense_two_port(1j * omega, masses, elem_nodes, c, d)
    XY = np.zeros((omega.size, n + 2, 2), complex)
    XY[:, 0, 0] = 1.0
    XY[:, n + 1, 1] = 1.0
    XY[:, 1:n + 1] = X
    uv = np.einsum("ea,fas->fes", B, XY)
    dk_dc = -uv[..., 0] * uv[..., 1]
    dk_dd = 1j * omega[:, None] * dk_dc
    dk_dm = omega[:, None] ** 2 * XY[:, 1:n + 1, 0] * XY[:, 1:n + 1, 1]
    kcp = dk_dc @ c + dk_dd @ d + dk_dm @ masses
    return kcp, dk_dm, dk_dc, dk_dd


def dense_harmonic_response(system, load_harmonics, omegas):
    """Harmonic amplitudes of every coordinate by a dense solve of the assembled matrices."""
    omegas = np.asarray(omegas, float)
    w = omegas[:, None, None]
    D = system.K[None] + 1j * w * system.C[None] - w * w * system.M[None]
    rhs = np.zeros((omegas.size, system.n_dof, 1), dtype=complex)
    rhs[:, :6, 0] = load_harmonics
    return np.linalg.solve(D, rhs)[..., 0]
