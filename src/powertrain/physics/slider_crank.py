r"""Exact slider-crank kinematics and the forces of one cylinder on the engine block.

In the cylinder plane :math:`u` is the cylinder axis (crank axis to head) and :math:`s` the
lateral direction the crank pin moves into just after TDC; the crank angle :math:`\theta`
[rad] is measured from :math:`u` in the sense of rotation. The piston pin moves on
:math:`s = e` (pin offset [m]; the usual offset towards the major thrust side is
:math:`e < 0`). With crank radius :math:`r`, rod length :math:`l` and rod angle
:math:`\sin\beta = (r\sin\theta - e)/l`, exactly (no series expansion):

.. math::

    y = r\cos\theta + l\cos\beta, \qquad
    \frac{dy}{d\theta} = -\frac{r\sin(\theta+\beta)}{\cos\beta}, \qquad
    \frac{d^2y}{d\theta^2} = -r\cos\theta - l\cos\beta\,\beta'^2 - l\sin\beta\,\beta''

(Heywood 1988, sec. 2.2). Forces (Taylor 1985, vol. 2, ch. 8; rod mass split into
reciprocating and rotating parts): with gas force :math:`F_g` and reciprocating mass
:math:`m`, rod force :math:`F_r = (F_g + m a)/\cos\beta`, side thrust
:math:`N = F_r\sin\beta`, crank torque :math:`T = -(F_g + m a)\,dy/d\theta`. On the block
they sum to the shaking force :math:`-m a\,u` plus the torque reaction :math:`-T`.
"""

from __future__ import annotations

import numpy as np


def piston_kinematics(theta, r, l, e=0.0):
    r"""Exact piston position and its first two derivatives with respect to crank angle.

    Parameters
    ----------
    theta : array_like
        Crank angle from the cylinder axis [rad].
    r, l, e : float
        Crank radius, connecting-rod length, piston-pin offset [m].

    Returns
    -------
    y, dy, d2y, beta : ndarray
        Piston-pin distance from the crank axis [m], :math:`dy/d\theta` [m/rad],
        :math:`d^2y/d\theta^2` [m/rad²] and the rod angle [rad].
    """
    theta = np.asarray(theta, dtype=float)
    beta = np.arcsin((r * np.sin(theta) - e) / l)
    cb, sb = np.cos(beta), np.sin(beta)
    y = r * np.cos(theta) + l * cb
    b1 = r * np.cos(theta) / (l * cb)
    b2 = (l * sb * b1**2 - r * np.sin(theta)) / (l * cb)
    dy = -r * np.sin(theta + beta) / cb
    d2y = -r * np.cos(theta) - l * cb * b1**2 - l * sb * b2
    return y, dy, d2y, beta


def stroke_limits(r, l, e=0.0):
    r"""Piston-pin positions at TDC and BDC [m] and their crank angles [rad]:
    ``(y_tdc, y_bdc, theta_tdc, theta_bdc)``, :math:`y_{TDC} = \sqrt{(l+r)^2 - e^2}`,
    :math:`\sin\theta_{TDC} = e/(l+r)`."""
    y_tdc = float(np.sqrt((l + r) ** 2 - e**2))
    y_bdc = float(np.sqrt((l - r) ** 2 - e**2))
    theta_tdc = float(np.arcsin(e / (l + r)))
    theta_bdc = float(np.pi + np.arcsin(e / (l - r)))
    return y_tdc, y_bdc, theta_tdc, theta_bdc


def cylinder_volume(theta, bore, r, l, e, compression_ratio):
    r"""Cylinder volume :math:`V = V_c + A\,(y_{TDC} - y)`, :math:`V_c = V_d/(\varepsilon - 1)`
    [m³], from the exact kinematics.

    Parameters
    ----------
    theta : array_like
        Crank angle from the cylinder axis [rad].
    bore : float
        Bore [m].
    r, l, e : float
        Crank radius, rod length, piston-pin offset [m].
    compression_ratio : float
        Geometric compression ratio :math:`\varepsilon` [-].

    Returns
    -------
    V, dV : ndarray
        Volume [m³] and :math:`dV/d\theta` [m³/rad].
    """
    area = np.pi * bore**2 / 4.0
    y_tdc, y_bdc, _, _ = stroke_limits(r, l, e)
    vd = area * (y_tdc - y_bdc)
    vc = vd / (compression_ratio - 1.0)
    y, dy, _, _ = piston_kinematics(theta, r, l, e)
    return vc + area * (y_tdc - y), -area * dy


def swept_volume(bore, r, l, e=0.0):
    """Swept volume of one cylinder [m³] from the exact dead-centre positions."""
    y_tdc, y_bdc, _, _ = stroke_limits(r, l, e)
    return np.pi * bore**2 / 4.0 * (y_tdc - y_bdc)


def crank_forces(theta, omega, gas_force, r, l, e, m_rec, alpha=0.0):
    r"""Rod force, side thrust and crank torque of one cylinder (exact kinematics).

    Parameters
    ----------
    theta : array_like
        Crank angle of this cylinder from its cylinder axis [rad].
    omega : float
        Crank angular speed [rad/s] (constant).
    gas_force : array_like
        :math:`F_g = (p - p_{cc})A` on the piston crown, towards the crank [N].
    r, l, e : float
        Crank radius, rod length, piston-pin offset [m].
    m_rec : float
        Reciprocating mass (piston group plus the rod's small-end share) [kg].
    alpha : float or array_like
        Crank angular acceleration [rad/s²]: piston acceleration :math:`\omega^2 y'' + \alpha y'`.

    Returns
    -------
    dict of ndarray
        ``y`` [m], ``dy`` [m/rad], ``acc`` piston acceleration along :math:`u` [m/s²],
        ``beta`` [rad], ``rod`` rod force :math:`F_r` (compression > 0) [N], ``side`` wall
        force on the piston :math:`N` along :math:`s` [N], ``inertia`` reciprocating inertia
        force :math:`-m a` along :math:`u` [N], ``torque`` crank torque :math:`T` [N·m],
        ``torque_gas`` and ``torque_inertia`` its gas and inertia parts [N·m].
    """
    y, dy, d2y, beta = piston_kinematics(theta, r, l, e)
    acc = omega**2 * d2y + alpha * dy
    fg = np.asarray(gas_force, dtype=float)
    rod = (fg + m_rec * acc) / np.cos(beta)
    return {
        "y": y, "dy": dy, "acc": acc, "beta": beta, "rod": rod,
        "side": rod * np.sin(beta), "inertia": -m_rec * acc,
        "torque": -(fg + m_rec * acc) * dy,
        "torque_gas": -fg * dy, "torque_inertia": -m_rec * acc * dy,
    }


def second_order_coefficient(lam, terms=3):
    r"""Coefficient :math:`A_2 = \lambda + \lambda^3/4 + 15\lambda^5/128 + \dots` of
    :math:`\cos 2\theta` in :math:`-a/(r\omega^2)` for :math:`e = 0` (Taylor 1985, vol. 2, ch. 8).

    Parameters
    ----------
    lam : float
        Crank-radius to rod-length ratio :math:`\lambda = r/l` [-].
    terms : int
        Number of terms of the series kept (1 to 3).
    """
    coeffs = [1.0, 1.0 / 4.0, 15.0 / 128.0]
    return float(sum(c * lam ** (2 * k + 1) for k, c in enumerate(coeffs[:terms])))
