r"""Frequency-domain steady state of the assembled model, order by order.

A load periodic over the engine cycle (two crank revolutions) has orders
:math:`k/2`, :math:`k = 0, 1, 2, \dots` of the crank speed :math:`\Omega`. For each order the
steady-state amplitude solves

.. math:: \left(\mathbf K + i\omega_k\mathbf C - \omega_k^2\mathbf M\right)\hat{\mathbf q}_k
          = \mathbf B\hat{\mathbf f}_k, \qquad \omega_k = \tfrac{k}{2}\Omega,

and :math:`\mathbf q(t) = \mathrm{Re}\sum_k \hat{\mathbf q}_k e^{i\omega_k t}`. Exact for the
linear model; the time-domain Newmark stepper must agree with it.

:func:`harmonic_response` solves it by condensation: the internal masses of each mount network
are eliminated exactly, so the body feels each network through its *input-point* dynamic
stiffness :math:`K_{IP}(\omega)` along the row :math:`\mathbf r` that maps the body motion to
the network's engine-side node (the ground feels the cross-point stiffness):

.. math:: \Big(-\omega^2\mathbf M_{rb} + \sum_n K_{IP,n}(\omega)\,\mathbf r_n\mathbf r_n^T\Big)
          \hat{\mathbf q}_{rb} = \hat{\mathbf f},

a 6×6 solve per order; the internal amplitudes follow from the network's own condensation.
:func:`harmonic_response_full` solves the assembled matrices directly (a check of the first).
"""

from __future__ import annotations

import numpy as np

from powertrain.physics import mount_network as net


def harmonic_response(system, load_harmonics, omegas):
    """Complex amplitudes of q for each load harmonic (condensed 6×6 solve).

    Parameters
    ----------
    system : AssembledSystem
    load_harmonics : ndarray (n_h, 6) complex
        Amplitudes of the 6-vector load [N, N·m] (index 0 = mean).
    omegas : ndarray (n_h,)
        Angular frequency of each harmonic [rad/s].

    Returns
    -------
    ndarray (n_h, n_dof) complex
    """
    omegas = np.asarray(omegas, float)
    if not system.networks or system.body_start < system.n_dof:
        # no networks, or a modal body under them: solve the assembled matrices
        return harmonic_response_full(system, load_harmonics, omegas)
    w = omegas[:, None, None]
    # the body's own mass; every spring and damper acting on it comes from the networks
    D = -(w ** 2) * system.M[None, :6, :6].astype(complex)
    shapes = []
    for row, start, ni, model in system.networks:
        network = model.network()
        X, kip = net.condensed_network(omegas, *network)   # (n_h, ni + 1), (n_h,)
        D = D + kip[:, None, None] * np.outer(row, row)[None]
        shapes.append((row, start, ni, X))
    q_rb = np.linalg.solve(D, np.asarray(load_harmonics, complex)[..., None])[..., 0]
    out = np.zeros((omegas.size, system.n_dof), dtype=complex)
    out[:, :6] = q_rb
    for row, start, ni, X in shapes:
        xe = q_rb @ row
        out[:, start:start + ni] = X[:, 1:] * xe[:, None]
    return out


def harmonic_response_full(system, load_harmonics, omegas):
    """Same as :func:`harmonic_response` by a direct solve of the assembled matrices."""
    omegas = np.asarray(omegas, float)
    w = omegas[:, None, None]
    D = system.K[None] + 1j * w * system.C[None] - w * w * system.M[None]
    rhs = np.zeros((omegas.size, system.n_dof, 1), dtype=complex)
    rhs[:, :6, 0] = load_harmonics
    return np.linalg.solve(D, rhs)[..., 0]
