r"""Frequency-domain steady state of the assembled model, order by order.

A load periodic over the engine cycle (two crank revolutions) has orders
:math:`k/2`, :math:`k = 0, 1, 2, \dots` of the crank speed :math:`\Omega`. For each order the
steady-state amplitude solves

.. math:: \left(\mathbf K + i\omega_k\mathbf C - \omega_k^2\mathbf M\right)\hat{\mathbf q}_k
          = \mathbf B\hat{\mathbf f}_k, \qquad \omega_k = \tfrac{k}{2}\Omega,

and :math:`\mathbf q(t) = \mathrm{Re}\sum_k \hat{\mathbf q}_k e^{i\omega_k t}`. Exact for the
linear model; the time-domain Newmark stepper must agree with it.

:func:`harmonic_response` solves it by the one condensation
(:func:`powertrain.physics.condensation.harmonic_solve`): the internal masses of each mount
network are eliminated exactly through its two-port, so the retained coordinates (rigid body,
body modes) feel each network through :math:`\mathbf P_n^T\mathbf T_n(i\omega)\mathbf P_n`
(for a rigid ground, its input-point dynamic stiffness :math:`K_{IP}(\omega)` along the row
:math:`\mathbf r_n`), a small solve per order; the internal amplitudes follow from the
networks' own condensation. tests/test_runup.py checks it against a dense solve of the
assembled matrices.
"""

from __future__ import annotations

from powertrain.physics.condensation import harmonic_solve


def harmonic_response(system, load_harmonics, omegas, amplitudes=None):
    """Complex amplitudes of q for each load harmonic (condensed solve).

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

    Returns
    -------
    ndarray (n_h, n_dof) complex
    """
    return harmonic_solve(system, load_harmonics, omegas, amplitudes)
