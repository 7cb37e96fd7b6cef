r"""Frequency-domain steady state of the assembled model, order by order.

A load periodic over the engine cycle has orders :math:`k/2` of the crank speed
:math:`\Omega`; each order's steady-state amplitude solves

.. math:: \left(\mathbf K + i\omega_k\mathbf C - \omega_k^2\mathbf M\right)\hat{\mathbf q}_k
          = \mathbf B\hat{\mathbf f}_k, \qquad \omega_k = \tfrac{k}{2}\Omega,

and :math:`\mathbf q(t) = \mathrm{Re}\sum_k \hat{\mathbf q}_k e^{i\omega_k t}`, exact for the
linear model. Each network's internal masses are eliminated exactly through its two-port
(:func:`powertrain.physics.condensation.harmonic_solve`): the retained coordinates feel it as
:math:`\mathbf P_n^T\mathbf T_n(i\omega)\mathbf P_n` (on a rigid ground :math:`K_{IP}(\omega)`
along :math:`\mathbf r_n`); tests/test_runup.py checks it against a dense solve.
"""

from __future__ import annotations

import numpy as np

from powertrain.physics.condensation import harmonic_solve, two_ports


def harmonic_response(system, load_harmonics, omegas, amplitudes=None, linear=None, internal=True):
    """Complex amplitudes of every coordinate for each load harmonic (module docstring).

    Parameters
    ----------
    system : AssembledSystem
    load_harmonics : ndarray (n_h, 6) complex
        Amplitudes of the 6-vector load [N, N·m] (index 0 = mean).
    omegas : ndarray (n_h,)
        Angular frequency of each harmonic [rad/s].
    amplitudes : ndarray (n_net,), optional
        Relative-displacement amplitude of every network [m]: nonlinear elements act
        through their equivalent-linear two-port there.
    linear : LinearTwoPorts, optional
        The networks' linear two-ports at ``1j * omegas`` with their internal motions
        (:func:`~powertrain.physics.condensation.linear_two_ports`), reused.
    internal : bool
        False: the networks' internal coordinates are left zero.

    Returns
    -------
    ndarray (n_h, n_dof) complex
    """
    ports = system.ports()
    s = 1j * np.asarray(omegas, float)
    abc, shapes = two_ports(ports, s, internal=True, amplitudes=amplitudes, linear=linear) \
        if internal else (two_ports(ports, s, amplitudes=amplitudes, linear=linear), [])
    q_r = harmonic_solve(ports.frame, ports.engine_rows,
                         None if ports.grounded else ports.base_rows, abc, s, load_harmonics)
    out = np.zeros((s.size, system.n_dof), complex)
    out[:, ports.retained] = q_r
    x_e = q_r @ ports.engine_rows.T
    x_b = q_r @ ports.base_rows.T
    for k, ((start, ni), X) in enumerate(zip(ports.internal, shapes)):
        out[:, start:start + ni] = X[..., 0] * x_e[:, k, None] + X[..., 1] * x_b[:, k, None]
    return out
