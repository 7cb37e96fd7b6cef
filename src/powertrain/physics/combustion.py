r"""Single-zone cylinder pressure: polytropic compression and expansion, Wiebe heat release.

:math:`\theta` [rad] is one cylinder's crank angle from firing TDC on
:math:`-\pi \le \theta < 3\pi`; the volume comes from the exact kinematics. Intake valve closes
at BDC at the intake pressure :math:`p_i`; compression :math:`p = p_i (V_{BDC}/V)^{n_c}` up
to :math:`\theta_s`; then :math:`pV^{n_e} = p_sV_s^{n_e} + (n_e-1)\int V^{n_e-1}dQ` with Wiebe
heat release :math:`Q = Q_{tot}\,x_b`; blow-down and valve overlap are cosine ramps to the
exhaust pressure :math:`p_e` and back to :math:`p_i` (Heywood 1988, sec. 9.2 and 14.4;
Wiebe 1970). The pressure is linear in :math:`Q_{tot}`, so :func:`calibrate_heat` is exact.
"""

from __future__ import annotations

import numpy as np

#: Specific gas constant of air [J/(kg K)].
R_AIR = 287.05


def wiebe(theta, theta_start, duration, a=6.908, m=2.0):
    r"""Wiebe mass fraction burned
    :math:`x_b = 1 - \exp[-a((\theta-\theta_s)/\Delta\theta)^{m+1}]` and its derivative.

    Parameters
    ----------
    theta : array_like
        Crank angle [rad].
    theta_start : float
        Start of combustion :math:`\theta_s` [rad].
    duration : float
        Combustion duration :math:`\Delta\theta` [rad].
    a : float
        Efficiency parameter [-] (6.908: 99.9 % burned after :math:`\Delta\theta`).
    m : float
        Form factor [-].

    Returns
    -------
    xb, dxb : ndarray
        Burned fraction [-] and :math:`dx_b/d\theta` [1/rad].
    """
    z = np.clip((np.asarray(theta, dtype=float) - theta_start) / duration, 0.0, None)
    e = np.exp(-a * z ** (m + 1.0))
    return 1.0 - e, a * (m + 1.0) / duration * z**m * e


def _ramp(theta, start, end):
    """Smooth 0 -> 1 cosine ramp between ``start`` and ``end`` [rad]."""
    t = np.clip((theta - start) / (end - start), 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * t)


def pressure_basis(theta, volume, n_c, n_e, theta_start, duration, a, m, theta_evo, theta_evc,
                   overlap):
    r"""Cylinder pressure split as :math:`p = p_i\,b_i + p_e\,b_e + Q_{tot}\,p_1`.

    Parameters
    ----------
    theta : ndarray
        Uniform grid of cycle angles on :math:`[-\pi, 3\pi)` [rad], from BDC.
    volume : ndarray
        Cylinder volume on the grid [m³].
    n_c, n_e : float
        Polytropic exponents of compression and of combustion/expansion [-].
    theta_start, duration : float
        Wiebe start and duration [rad].
    a, m : float
        Wiebe parameters [-].
    theta_evo, theta_evc : float
        Blow-down ramp: exhaust valve opening to end of blow-down [rad].
    overlap : float
        Half-width of the valve-overlap ramp around :math:`2\pi` [rad].

    Returns
    -------
    b_i, b_e, p1 : ndarray
        Pressure without heat release per unit intake and exhaust pressure [-], and per
        joule of heat released [Pa/J].
    """
    theta = np.asarray(theta, dtype=float)
    V = np.asarray(volume, dtype=float)
    v_bdc = V[0]
    comp = (v_bdc / V) ** n_c
    i_s = np.searchsorted(theta, theta_start)
    v_s = np.interp(theta_start, theta, V)
    p_s = (v_bdc / v_s) ** n_c
    xb, _ = wiebe(theta, theta_start, duration, a, m)
    integrand = V ** (n_e - 1.0)
    inc = 0.5 * (integrand[1:] + integrand[:-1]) * np.diff(xb)
    cum = np.concatenate([[0.0], np.cumsum(inc)])
    closed = theta >= theta_start
    b0 = np.where(closed, p_s * v_s**n_e / V**n_e, comp)
    p1 = np.where(closed, (n_e - 1.0) * cum / V**n_e, 0.0)
    if i_s == 0:
        raise ValueError("start of combustion must lie after bottom dead centre")
    w_bd = _ramp(theta, theta_evo, theta_evc)
    w_ov = _ramp(theta, 2 * np.pi - overlap, 2 * np.pi + overlap)
    return b0 * (1 - w_bd) + w_ov * w_bd, (1 - w_ov) * w_bd, p1 * (1 - w_bd)


def indicated_work(pressure, dvolume, dtheta):
    r"""Net indicated work per cycle :math:`W = \Delta\theta\sum_k p_k\,(dV/d\theta)_k` [J]
    (periodic rectangle rule over one cycle).

    Parameters
    ----------
    pressure : ndarray (..., n)
        Pressure [Pa] on the grid (one row per cylinder: the work of each).
    dvolume : ndarray (n,)
        :math:`dV/d\theta` [m³/rad] on the grid.
    dtheta : float
        Grid step [rad].
    """
    work = np.sum(np.asarray(pressure, float) * dvolume, axis=-1) * dtheta
    return float(work) if np.ndim(work) == 0 else work


def calibrate_heat(p0, p1, dvolume, dtheta, swept_volume, imep_target):
    r"""Heat released per cycle :math:`Q_{tot} = (\mathrm{IMEP}\,V_d - W_0)/W_1` [J] that
    gives the target net IMEP.

    Raises
    ------
    ValueError
        The target is below the IMEP of the motored cycle (no negative heat release).
    """
    w0 = indicated_work(p0, dvolume, dtheta)
    w1 = indicated_work(p1, dvolume, dtheta)
    q = (imep_target * swept_volume - w0) / w1
    if q < 0:
        raise ValueError(f"IMEP {imep_target / 1e5:.3g} bar is below the motored cycle's "
                         f"{w0 / swept_volume / 1e5:.3g} bar")
    return float(q)


def boost_pressure(imep, swept_volume, trapped_volume, *, indicated_efficiency,
                   air_fuel_ratio, heating_value, intake_temperature,
                   volumetric_efficiency):
    r"""Intake-manifold pressure [Pa] that supplies the air for a given IMEP:
    :math:`p_i = \mathrm{IMEP}\,V_d\,\mathrm{AFR}\,R\,T_i/(\eta_i H_u \eta_v V_{BDC})`
    (Heywood 1988, eq. 2.27 and 2.38).

    Parameters
    ----------
    imep : float
        Net indicated mean effective pressure [Pa].
    swept_volume, trapped_volume : float
        :math:`V_d` and the volume at intake-valve closing [m³].
    indicated_efficiency : float
        Assumed indicated efficiency :math:`\eta_i` [-].
    air_fuel_ratio : float
        Air-fuel mass ratio [-].
    heating_value : float
        Lower heating value of the fuel [J/kg].
    intake_temperature : float
        Intake-manifold temperature [K].
    volumetric_efficiency : float
        [-].
    """
    q_fuel = imep * swept_volume / indicated_efficiency
    m_air = air_fuel_ratio * q_fuel / heating_value
    return m_air * R_AIR * intake_temperature / (volumetric_efficiency * trapped_volume)
