r"""Whole-body vibration at a seat: ISO 2631-1 frequency weighting, weighted RMS and VDV.

The weightings are the standard's analogue filters [1]_ (Annex A, Table A.1): band
limiting (2nd-order Butterworth high pass at :math:`f_1` and low pass at :math:`f_2`,
:math:`Q = 1/\sqrt2`), acceleration-velocity transition and upward step,

.. math::
   H_h = \frac{s^2}{s^2 + \omega_1 s/Q_1 + \omega_1^2},\quad
   H_l = \frac{\omega_2^2}{s^2 + \omega_2 s/Q_2 + \omega_2^2},\quad
   H_t = \frac{1 + s/\omega_3}{1 + s/(\omega_4 Q_4) + s^2/\omega_4^2},\quad
   H_s = \frac{1 + s/(\omega_5 Q_5) + s^2/\omega_5^2}{1 + s/(\omega_6 Q_6) + s^2/\omega_6^2}
   \left(\frac{\omega_5}{\omega_6}\right)^2,

with :math:`W_k` (vertical, z) :math:`f_3 = f_4 = 12.5` Hz, :math:`Q_4 = 0.63`,
:math:`f_5 = 2.37` Hz, :math:`Q_5 = 0.91`, :math:`f_6 = 3.35` Hz, :math:`Q_6 = 0.91`, and
:math:`W_d` (horizontal, x and y) :math:`f_3 = f_4 = 2` Hz, :math:`Q_4 = 0.63`, no step;
:math:`f_1 = 0.4` Hz, :math:`f_2 = 100` Hz for both; made digital by the bilinear transform
and run from rest in second-order sections. Weighted RMS
:math:`a_w = (\frac1T\int a_w^2 dt)^{1/2}`, vibration dose value
:math:`VDV = (\int a_w^4 dt)^{1/4}` [m/s^1.75] (eqs. 1 and 9).

.. [1] ISO 2631-1:1997, Mechanical vibration and shock — Evaluation of human exposure to
   whole-body vibration — Part 1: General requirements, Annex A.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import bilinear_zpk, sosfilt, zpk2sos

#: Filter parameters per weighting: (f1, f2, f3, f4, Q4, f5, Q5, f6, Q6) [Hz, -];
#: f5 None: no upward step.
WEIGHTINGS = {
    "Wk": (0.4, 100.0, 12.5, 12.5, 0.63, 2.37, 0.91, 3.35, 0.91),
    "Wd": (0.4, 100.0, 2.0, 2.0, 0.63, None, None, None, None),
}
#: The weighting of each seat axis (ISO 2631-1, Table 1: seated, comfort).
AXIS_WEIGHTING = {"x": "Wd", "y": "Wd", "z": "Wk"}
_Q = 1.0 / np.sqrt(2.0)


def weighting_analog(name):
    """Numerator and denominator (descending powers of s) of the weighting ``name`` (Wk, Wd)."""
    f1, f2, f3, f4, q4, f5, q5, f6, q6 = WEIGHTINGS[name]
    w1, w2, w3, w4 = (2 * np.pi * f for f in (f1, f2, f3, f4))
    num = np.polymul([1.0, 0.0, 0.0], [w2 ** 2])
    den = np.polymul([1.0, w1 / _Q, w1 ** 2], [1.0, w2 / _Q, w2 ** 2])
    num = np.polymul(num, [1.0 / w3, 1.0])
    den = np.polymul(den, [1.0 / w4 ** 2, 1.0 / (w4 * q4), 1.0])
    if f5 is not None:
        w5, w6 = 2 * np.pi * f5, 2 * np.pi * f6
        num = np.polymul(num, np.array([1.0 / w5 ** 2, 1.0 / (w5 * q5), 1.0]) * (w5 / w6) ** 2)
        den = np.polymul(den, [1.0 / w6 ** 2, 1.0 / (w6 * q6), 1.0])
    return num, den


def weighted(acceleration, sample_rate, name) -> np.ndarray:
    """``acceleration`` (n,) [m/s²] sampled at ``sample_rate`` [Hz] through the digital
    weighting ``name`` (module docstring)."""
    num, den = weighting_analog(name)
    z, p = np.roots(num), np.roots(den)
    k = num[np.flatnonzero(num)[0]] / den[0]
    zd, pd, kd = bilinear_zpk(z, p, k, sample_rate)
    return sosfilt(zpk2sos(zd, pd, kd.real), np.asarray(acceleration, float))


def weighted_rms(aw, sample_rate) -> float:
    """Weighted RMS acceleration [m/s²] of the weighted signal ``aw`` (``sample_rate`` [Hz])."""
    return float(np.sqrt(np.mean(np.square(aw)))) if len(aw) else 0.0


def vibration_dose_value(aw, sample_rate) -> float:
    """Vibration dose value [m/s^1.75] of the weighted signal ``aw`` at ``sample_rate`` [Hz]."""
    return float(np.sum(np.asarray(aw) ** 4) / sample_rate) ** 0.25
