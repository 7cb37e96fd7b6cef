r"""Frequency-domain coupling of the powertrain to a body given by measured receptances.

Each mount network is condensed to a two-port between its engine-side node E (moving with
the powertrain along :math:`\mathbf r`) and its base node G (moving with the body's
attachment point along the mount's local axis :math:`\mathbf e`):
:math:`[F_E; F_G] = [[k_{11}, k_{12}]; [k_{21}, k_{22}]]\,[x_E; x_G]` (forces applied to the
nodes). The body answers the forces the mounts put on it, :math:`\mathbf f_B = -(k_{21}x_E +
k_{22}x_G)\mathbf e` summed per attachment point, through its receptance
:math:`\mathbf x_A = \mathbf G_{AA}(\omega)\,\mathbf f_B` (admittance coupling; no inversion
of the measured matrix):

.. math:: \begin{bmatrix}\mathbf D_{rr} & \mathbf D_{ra}\\ \mathbf G\mathbf D_{ar} &
          \mathbf I + \mathbf G\mathbf D_{aa}\end{bmatrix}
          \begin{bmatrix}\hat{\mathbf q}\\ \hat{\mathbf x}_A\end{bmatrix} =
          \begin{bmatrix}\hat{\mathbf f}\\ 0\end{bmatrix},

:math:`\mathbf D_{rr} = -\omega^2\mathbf M_6 + \sum k_{11}\mathbf r\mathbf r^T`, and body
points follow as :math:`\mathbf x_P = \mathbf G_{PA}\mathbf f_B`. With receptances taken from
a modal body this reproduces the modal assembly exactly (tests/test_chassis.py).
"""

from __future__ import annotations

import numpy as np

from powertrain.physics.mount_network import network_matrices

DIRECTIONS = ("x", "y", "z")


def _two_port(model, omega):
    """(2×2 two-port [E, G], internal response per unit x_E and per unit x_G)."""
    M, C, K = network_matrices(*model.network(), include_ground=True)
    D = K + 1j * omega * C - omega**2 * M
    n = D.shape[0]
    ends = [0, n - 1]
    inner = list(range(1, n - 1))
    if not inner:
        return D[np.ix_(ends, ends)], np.zeros((0, 2), complex)
    X = -np.linalg.solve(D[np.ix_(inner, inner)], D[np.ix_(inner, ends)])   # (ni, 2)
    return D[np.ix_(ends, ends)] + D[np.ix_(ends, inner)] @ X, X


def frf_response(system, load_harmonics, omegas):
    """Harmonic response with a measured-receptance body.

    Returns
    -------
    q : ndarray (n_h, n_dof) complex
        Powertrain and network-internal amplitudes [m, rad].
    body : ndarray (n_h, 3 (n_mounts + n_points)) complex
        Body-side displacement of every attachment point, then of every body point [m].
    force : ndarray (n_h, 3 n_mounts) complex
        Force each mount puts on the body, engine axes [N].
    """
    chassis = system.chassis
    mounts = system.mount_names
    nm = len(mounts)
    n_a = 3 * nm
    out_q = np.zeros((len(omegas), system.n_dof), complex)
    out_b = np.zeros((len(omegas), n_a + 3 * len(chassis.points)), complex)
    out_f = np.zeros((len(omegas), n_a), complex)
    nets = [(k, row, start, ni, model) for k, (row, start, ni, model)
            in enumerate(system.networks)]
    for h, (w, f6) in enumerate(zip(omegas, np.asarray(load_harmonics, complex))):
        D = np.zeros((6 + n_a, 6 + n_a), complex)
        D[:6, :6] = -(w**2) * system.M[:6, :6]
        ports = []
        for k, row, start, ni, model in nets:
            m, d = divmod(k, 3)
            e = system.mount_axes[m][:, d]
            T, X = _two_port(model, w)
            a = slice(6 + 3 * m, 9 + 3 * m)
            D[:6, :6] += T[0, 0] * np.outer(row, row)
            D[:6, a] += T[0, 1] * np.outer(row, e)
            D[a, :6] += T[1, 0] * np.outer(e, row)
            D[a, a] += T[1, 1] * np.outer(e, e)
            ports.append((row, start, ni, e, a, T, X))
        G = chassis.receptance_at(w, mounts, mounts)
        A = D.copy()
        A[6:] = G @ D[6:]
        A[6:, 6:] += np.eye(n_a)
        rhs = np.zeros(6 + n_a, complex)
        rhs[:6] = f6
        sol = np.linalg.solve(A, rhs)
        q, xa = sol[:6], sol[6:]
        fb = -(D[6:, :6] @ q + D[6:, 6:] @ xa)
        out_q[h, :6] = q
        for row, start, ni, e, a, _t, X in ports:
            if ni:
                out_q[h, start:start + ni] = X @ np.array([row @ q, e @ xa[a.start - 6:a.stop - 6]])
        out_b[h, :n_a] = xa
        if chassis.points:
            out_b[h, n_a:] = chassis.receptance_at(w, list(chassis.points), mounts) @ fb
        out_f[h] = fb
    return out_q, out_b, out_f
