r"""Single-zone cylinder pressure: polytropic compression and expansion, Wiebe heat release.

Cycle angle
-----------
:math:`\theta` [rad] is the crank angle of one cylinder measured from its cylinder axis at
the firing top dead centre, on the window :math:`-\pi \le \theta < 3\pi` (compression from
bottom dead centre, firing TDC at 0, expansion, exhaust from :math:`\pi`, gas-exchange TDC at
:math:`2\pi`, intake to :math:`3\pi \equiv -\pi`). With a piston-pin offset the kinematic TDC
lies at :math:`\arcsin(e/(l+r))` (about −0.15° for the default engine); the volume is always
taken from the exact kinematics.

Model (Heywood 1988, sec. 9.2 and 14.4; Wiebe 1970)
---------------------------------------------------
* intake valve closes at BDC with the cylinder at the intake (boost) pressure :math:`p_i`;
* compression :math:`p = p_i (V_{BDC}/V)^{n_c}` up to the start of combustion
  :math:`\theta_s`;
* from :math:`\theta_s` the first law with a polytropic exponent :math:`n_e` standing for
  the ratio of specific heats less the wall heat loss,

  .. math:: \frac{dp}{d\theta} = \frac{n_e-1}{V}\frac{dQ}{d\theta}
            - n_e\frac{p}{V}\frac{dV}{d\theta}
            \;\Longleftrightarrow\;
            \frac{d(pV^{n_e})}{d\theta} = (n_e-1)\,V^{n_e-1}\frac{dQ}{d\theta},

  integrated exactly as :math:`pV^{n_e} = p_sV_s^{n_e} + (n_e-1)\int V^{n_e-1}dQ`;
* Wiebe heat release :math:`Q = Q_{tot}\,x_b`,
  :math:`x_b = 1 - \exp\{-a[(\theta-\theta_s)/\Delta\theta]^{m+1}\}`;
* blow-down: from exhaust-valve opening the pressure blends smoothly (cosine ramp) into the
  exhaust back-pressure :math:`p_e`; valve overlap: a cosine ramp from :math:`p_e` to
  :math:`p_i` centred on gas-exchange TDC.

Because the pressure is linear in :math:`Q_{tot}`, the heat that gives a prescribed IMEP
is found exactly (:func:`calibrate_heat`).
"""

from __future__ import annotations

import numpy as np

#: Specific gas constant of air [J/(kg K)].
R_AIR = 287.05


def wiebe(theta, theta_start, duration, a=6.908, m=2.0):
    r"""Wiebe mass fraction burned and its derivative.

    .. math:: x_b = 1 - \exp\left[-a\left(\frac{\theta-\theta_s}{\Delta\theta}\right)^{m+1}
              \right], \quad \theta \ge \theta_s

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
    xb : ndarray
        Burned fraction [-].
    dxb : ndarray
        :math:`dx_b/d\theta` [1/rad].
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
    r"""Cylinder pressure split as :math:`p = p_i\,b_i + p_e\,b_e + Q_{tot}\,p_1`: the
    pressure is linear in the intake pressure :math:`p_i`, the exhaust back-pressure
    :math:`p_e` and the heat released :math:`Q_{tot}`, so the three traces do not depend on
    the operating point.

    Parameters
    ----------
    theta : ndarray
        Uniform grid of cycle angles on :math:`[-\pi, 3\pi)` [rad], starting at
        :math:`-\pi` (bottom dead centre before compression).
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
    b_i, b_e : ndarray
        Pressure without heat release per unit intake and exhaust pressure [-].
    p1 : ndarray
        Pressure per joule of heat released [Pa/J].
    """
    theta = np.asarray(theta, dtype=float)
    V = np.asarray(volume, dtype=float)
    v_bdc = V[0]
    comp = (v_bdc / V) ** n_c
    i_s = np.searchsorted(theta, theta_start)
    v_s = np.interp(theta_start, theta, V)
    p_s = (v_bdc / v_s) ** n_c
    # p V^ne after the start of combustion, without and with (unit) heat release
    xb, _ = wiebe(theta, theta_start, duration, a, m)
    integrand = V ** (n_e - 1.0)
    # cumulative trapezoid of V^(ne-1) dxb
    inc = 0.5 * (integrand[1:] + integrand[:-1]) * np.diff(xb)
    cum = np.concatenate([[0.0], np.cumsum(inc)])
    closed = theta >= theta_start
    b0 = np.where(closed, p_s * v_s**n_e / V**n_e, comp)
    p1 = np.where(closed, (n_e - 1.0) * cum / V**n_e, 0.0)
    if i_s == 0:
        raise ValueError("start of combustion must lie after bottom dead centre")
    # blow-down into the exhaust pressure (cosine ramp, may extend past BDC), exhaust stroke,
    # valve overlap around gas-exchange TDC, intake stroke
    w_bd = _ramp(theta, theta_evo, theta_evc)
    w_ov = _ramp(theta, 2 * np.pi - overlap, 2 * np.pi + overlap)
    return b0 * (1 - w_bd) + w_ov * w_bd, (1 - w_ov) * w_bd, p1 * (1 - w_bd)


def indicated_work(pressure, dvolume, dtheta):
    r"""Net indicated work per cycle :math:`W = \oint p\,dV` [J].

    Periodic rectangle rule over a uniform grid covering one cycle once
    (:math:`W = \Delta\theta\sum_k p_k\,(dV/d\theta)_k`).

    Parameters
    ----------
    pressure : ndarray (..., n)
        Pressure [Pa] on the grid (one row per cylinder: the work of each).
    dvolume : ndarray (n,)
        :math:`dV/d\theta` [m³/rad] on the grid.
    dtheta : float
        Grid step [rad].

    Returns
    -------
    float or ndarray (...)
        [J]
    """
    work = np.sum(np.asarray(pressure, float) * dvolume, axis=-1) * dtheta
    return float(work) if np.ndim(work) == 0 else work


def calibrate_heat(p0, p1, dvolume, dtheta, swept_volume, imep_target):
    r"""Heat released per cycle :math:`Q_{tot}` [J] that gives the target net IMEP.

    .. math:: \mathrm{IMEP} = \frac{\oint p\,dV}{V_d}
              = \frac{W_0 + Q_{tot}W_1}{V_d}
              \;\Rightarrow\; Q_{tot} = \frac{\mathrm{IMEP}\,V_d - W_0}{W_1}

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
    r"""Intake-manifold pressure [Pa] that supplies the air for a given IMEP.

    Fuel energy :math:`Q_f = \mathrm{IMEP}\,V_d/\eta_i`, air mass
    :math:`m_a = \mathrm{AFR}\,Q_f/H_u`, and the ideal-gas filling of the trapped volume
    :math:`m_a = \eta_v\,p_i V_{BDC}/(R T_i)` (Heywood 1988, eq. 2.27 and 2.38):

    .. math:: p_i = \frac{\mathrm{IMEP}\,V_d\,\mathrm{AFR}\,R\,T_i}
              {\eta_i H_u \eta_v V_{BDC}}

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
