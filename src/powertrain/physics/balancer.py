r"""Balancer shafts (Lanchester balancer): rotating unbalance at a multiple of crank speed.

A shaft at :math:`\rho\,\omega` with unbalance :math:`m_b r_b` [kg·m] has its mass centre at
:math:`\alpha = \sigma_b\,\rho\,\theta + \phi_b` from the cylinder axis :math:`u` towards
:math:`s` (:mod:`powertrain.physics.slider_crank`; :math:`\sigma_b = \pm 1` with/against the
crank) and loads the block with
:math:`\mathbf F_b = m_b r_b(\rho\omega)^2(\cos\alpha\,\mathbf u + \sin\alpha\,\mathbf s)`
(Taylor 1985, vol. 2, ch. 8).
"""

from __future__ import annotations

import numpy as np


def shaft_force(theta, omega, mass_radius, phase, sense=1, ratio=2.0):
    r"""Force of one balancer shaft on the block, in the cylinder plane.

    Parameters
    ----------
    theta : array_like
        Crank angle of cylinder 1 [rad].
    omega : float
        Crank angular speed [rad/s].
    mass_radius : float
        Unbalance :math:`m_b r_b` [kg·m].
    phase : float
        :math:`\phi_b` [rad].
    sense : {+1, -1}
        Direction of rotation relative to the crank.
    ratio : float
        Shaft speed over crank speed :math:`\rho` [-].

    Returns
    -------
    f_u, f_s : ndarray
        Components along the cylinder axis :math:`u` and the lateral direction :math:`s` [N].
    """
    alpha = sense * ratio * np.asarray(theta, dtype=float) + phase
    f = mass_radius * (ratio * omega) ** 2
    return f * np.cos(alpha), f * np.sin(alpha)


def matching_mass_radius(m_rec, r, a2, n_cylinders=4, n_shafts=2, ratio=2.0):
    r"""Unbalance per shaft [kg·m] that cancels the second-order shaking force:
    :math:`m_b r_b = n_{cyl}\,m\,r\,A_2/(n_{sh}\,\rho^2)`.

    Parameters
    ----------
    m_rec : float
        Reciprocating mass per cylinder [kg].
    r : float
        Crank radius [m].
    a2 : float
        Second-order coefficient :math:`A_2` [-]
        (:func:`powertrain.physics.slider_crank.second_order_coefficient`).
    n_cylinders : int
        Cylinders of the inline engine [-].
    n_shafts : int
        Balancer shafts sharing the force [-].
    ratio : float
        Shaft speed over crank speed ρ [-].
    """
    return n_cylinders * m_rec * r * a2 / (n_shafts * ratio**2)
