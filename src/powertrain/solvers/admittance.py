r"""Frequency-domain coupling of the powertrain to a body given by measured receptances.

Each network is a two-port between its engine-side node E (along :math:`\mathbf r`) and its
base node G (the body's attachment point along the mount axis :math:`\mathbf e`),
:math:`[F_E; F_G] = [[k_{11}, k_{12}]; [k_{21}, k_{22}]]\,[x_E; x_G]`. The body answers the
mount forces :math:`\mathbf f_B = -(k_{21}x_E + k_{22}x_G)\mathbf e` through its receptance,
:math:`\mathbf x_A = \mathbf G_{AA}(\omega)\,\mathbf f_B` (no inversion of the measured matrix):

.. math:: \begin{bmatrix}\mathbf D_{rr} & \mathbf D_{ra}\\ \mathbf G\mathbf D_{ar} &
          \mathbf I + \mathbf G\mathbf D_{aa}\end{bmatrix}
          \begin{bmatrix}\hat{\mathbf q}\\ \hat{\mathbf x}_A\end{bmatrix} =
          \begin{bmatrix}\hat{\mathbf f}\\ 0\end{bmatrix},

:math:`\mathbf D_{rr} = -\omega^2\mathbf M_6 + \sum k_{11}\mathbf r\mathbf r^T`; body points
follow as :math:`\mathbf x_P = \mathbf G_{PA}\mathbf f_B` (exact against the modal assembly,
tests/test_chassis.py).
"""

from __future__ import annotations

import numpy as np

from powertrain.physics.condensation import condensed_matrix, two_ports

DIRECTIONS = ("x", "y", "z")


def _attachment_ports(system):
    """Frame and engine/base port rows on the coordinates [q (6), x_A (3 per mount)]."""
    n_a = system.n_mount_channels
    n = 6 + n_a
    frame = (np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)))
    frame[0][:6, :6] = system.M[:6, :6]
    E = np.zeros((len(system.networks), n))
    B = np.zeros((len(system.networks), n))
    for k, (row, *_rest) in enumerate(system.networks):
        m, d = divmod(k, 3)
        E[k, :6] = row
        B[k, 6 + 3 * m:9 + 3 * m] = system.mount_axes[m][:, d]
    return frame, E, B


def frf_response(system, load_harmonics, omegas, amplitudes=None):
    """Harmonic response of ``system`` on its measured-receptance body to ``load_harmonics``
    (n_h, 6) [N, N·m] at ``omegas`` [rad/s]; nonlinear elements at their equivalent-linear
    two-port at ``amplitudes`` (n_net,) [m].

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
    n_a = system.n_mount_channels
    omegas = np.asarray(omegas, float)
    s = 1j * omegas
    frame, E, B = _attachment_ports(system)
    abc, shapes = two_ports(system.ports(), s, internal=True, amplitudes=amplitudes)
    D = condensed_matrix(frame, E, B, abc, s)                  # (n_h, 6 + n_a, 6 + n_a)
    G = chassis.receptances(omegas, mounts, mounts)
    A = D.copy()
    A[:, 6:] = G @ D[:, 6:]
    A[:, 6:, 6:] += np.eye(n_a)
    rhs = np.zeros((omegas.size, 6 + n_a), complex)
    rhs[:, :6] = load_harmonics
    sol = np.linalg.solve(A, rhs[..., None])[..., 0]
    fb = -np.einsum("hij,hj->hi", D[:, 6:], sol)
    out_q = np.zeros((omegas.size, system.n_dof), complex)
    out_q[:, :6] = sol[:, :6]
    x_e, x_b = sol @ E.T, sol @ B.T
    for k, (_row, start, ni, _model) in enumerate(system.networks):
        X = shapes[k]
        out_q[:, start:start + ni] = X[..., 0] * x_e[:, k, None] + X[..., 1] * x_b[:, k, None]
    body = np.hstack([sol[:, 6:], np.einsum("hij,hj->hi", chassis.receptances(
        omegas, list(chassis.points), mounts), fb)]) if chassis.points else sol[:, 6:]
    return out_q, body, fb


def relative_motion(system, index, q, body):
    """Relative displacement (n_h, len(index)), engine side minus body side, across the
    networks ``index`` of ``system`` in an :func:`frf_response` solution ``q``, ``body``."""
    axes = np.array([system.mount_axes[k // 3][:, k % 3] for k in index])
    rows = np.array([system.networks[k][0] for k in index])
    attach = np.stack([body[:, 3 * (k // 3):3 * (k // 3) + 3] for k in index], axis=1)
    return q[:, :6] @ rows.T - np.einsum("hki,ki->hk", attach, axes)
