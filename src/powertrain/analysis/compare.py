r"""Correlation of simulated and measured run-up order curves (RMS levels, one unit on both
sides); ``docs/guide/compare.md`` tabulates the measures and what each is blind to.

References
----------
.. [1] W. Heylen, S. Lammens, P. Sas, *Modal Analysis Theory and Testing*, KU Leuven, 1997
   (FRAC).
.. [2] R. J. Allemang, "The modal assurance criterion -- twenty years of use and abuse",
   Sound and Vibration 37(8), 2003, 14--23.
.. [3] C. Zang, H. Grafe, M. Imregun, "Frequency-domain criteria for correlating and
   updating dynamic finite element models", Mechanical Systems and Signal Processing 15(1),
   2001, 139--155 (CSAC, CSF; there also called global shape and amplitude criteria).
.. [4] Lee, Ahn & Kim, "A metric on the similarity between two frequency response
   functions", Journal of Sound and Vibration 436, 2018.
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.phase import wrap_deg

#: Standard deviation of the Gaussian kernel of :func:`frfsm_score` [dB].
FRFSM_SIGMA_DB = 6.0


def interpolate_log(rpm, level, rpm_new):
    r"""Interpolate a level curve linearly in speed and in log level; no extrapolation.

    :math:`\ln v = (1-t)\ln v_a + t\ln v_b`, :math:`t = (n-n_a)/(n_b-n_a)`; linear in
    level where either neighbour is zero.

    Parameters
    ----------
    rpm : array_like, shape (n,)
        Speeds of the curve, strictly increasing [rpm].
    level : array_like, shape (n,)
        Non-negative levels at ``rpm`` [any unit].
    rpm_new : array_like, shape (k,)
        Speeds wanted [rpm].

    Returns
    -------
    values : ndarray, shape (k,)
        Interpolated levels; NaN outside ``[rpm[0], rpm[-1]]``.
    inside : ndarray of bool, shape (k,)
        Where ``rpm_new`` is inside the curve's speed range (within 1e-9 rpm).
    """
    x, y = np.asarray(rpm, float), np.asarray(level, float)
    xn = np.atleast_1d(np.asarray(rpm_new, float))
    if x.ndim != 1 or x.shape != y.shape or x.size == 0:
        raise ValueError("rpm and level must be 1-D arrays of the same non-zero length")
    if np.any(np.diff(x) <= 0):
        raise ValueError("rpm must be strictly increasing")
    if np.any(y < 0) or not np.all(np.isfinite(y)):
        raise ValueError("levels must be finite and >= 0")
    tol = 1e-9
    inside = (xn >= x[0] - tol) & (xn <= x[-1] + tol)
    out = np.full(xn.shape, np.nan)
    if x.size == 1:
        out[inside] = y[0]
        return out, inside
    xi = np.clip(xn[inside], x[0], x[-1])
    j = np.clip(np.searchsorted(x, xi, side="right") - 1, 0, x.size - 2)
    t = (xi - x[j]) / (x[j + 1] - x[j])
    ya, yb = y[j], y[j + 1]
    pos = (ya > 0) & (yb > 0)
    val = (1 - t) * ya + t * yb
    with np.errstate(divide="ignore"):
        val[pos] = np.exp((1 - t[pos]) * np.log(ya[pos]) + t[pos] * np.log(yb[pos]))
    out[inside] = val
    return out, inside


def level_gap_db(simulated, measured):
    r"""Level gap :math:`20\log_{10}(v_\mathrm{sim}/v_\mathrm{meas})` [dB].

    Positive where the simulation is higher.

    Parameters
    ----------
    simulated, measured : array_like
        Positive RMS levels [same unit].
    """
    s, m = np.asarray(simulated, float), np.asarray(measured, float)
    if np.any(s <= 0) or np.any(m <= 0):
        raise ValueError("levels must be > 0 for a gap in dB")
    return 20.0 * np.log10(s / m)


def gap_statistics(rpm, gap_db):
    r"""RMS, mean (bias) and largest absolute value of a level gap over speed.

    Parameters
    ----------
    rpm : array_like, shape (n,)
        Compared speeds [rpm].
    gap_db : array_like, shape (n,)
        Level gap at those speeds [dB].

    Returns
    -------
    dict
        ``rms_db``, ``bias_db``, ``max_abs_db``, ``rpm_at_max_abs_db`` [dB, rpm]; NaN if empty.
    """
    g, r = np.asarray(gap_db, float), np.asarray(rpm, float)
    if g.size == 0:
        return {"rms_db": np.nan, "bias_db": np.nan, "max_abs_db": np.nan, "rpm_at_max_abs_db": np.nan}
    k = int(np.argmax(np.abs(g)))
    return {"rms_db": float(np.sqrt(np.mean(g ** 2))), "bias_db": float(np.mean(g)),
            "max_abs_db": float(abs(g[k])), "rpm_at_max_abs_db": float(r[k])}


def frac(simulated, measured):
    r"""Frequency response assurance criterion of two level curves over speed [1]_ [2]_.

    :math:`(\sum_n s_n m_n)^2 / (\sum_n s_n^2 \sum_n m_n^2)`: the curve's shape, blind to a
    common level error.

    In [0, 1]; 1 for a scaled copy; NaN if either curve is all zero or empty.

    Parameters
    ----------
    simulated, measured : array_like, shape (n,)
        RMS levels at the same speeds [same unit].
    """
    return float(csac(simulated, measured, axis=-1))


def csac(simulated, measured, axis=-1):
    r"""Cross-signature assurance criterion across channels [3]_.

    :math:`(\sum_j s_j m_j)^2 / (\sum_j s_j^2 \sum_j m_j^2)` along ``axis``: the deflection
    shape across the mounts.

    Parameters
    ----------
    simulated, measured : array_like
        RMS levels, channels along ``axis`` [same unit].
    axis : int
        Channel axis.

    Returns
    -------
    ndarray or float
        In [0, 1]; 1 for identical (or proportional) channel vectors.
    """
    s, m = np.asarray(simulated, float), np.asarray(measured, float)
    return _ratio(np.sum(s * m, axis=axis) ** 2, np.sum(s ** 2, axis=axis) * np.sum(m ** 2, axis=axis))


def csf(simulated, measured, axis=-1):
    r"""Cross-signature scale factor across channels [3]_: shape and level.

    :math:`2|\sum_j s_j m_j| / (\sum_j s_j^2 + \sum_j m_j^2)` along ``axis``.

    Parameters
    ----------
    simulated, measured : array_like
        RMS levels, channels along ``axis`` [same unit].
    axis : int
        Channel axis.

    Returns
    -------
    ndarray or float
        In [0, 1]; 1 only for identical vectors; 2a/(1+a²) for a vector scaled by a.
    """
    s, m = np.asarray(simulated, float), np.asarray(measured, float)
    return _ratio(2.0 * np.abs(np.sum(s * m, axis=axis)),
                  np.sum(s ** 2, axis=axis) + np.sum(m ** 2, axis=axis))


def _ratio(num, den):
    """``num / den`` where ``den > 0``, else NaN."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)


def frfsm_score(gap_db, sigma_db=FRFSM_SIGMA_DB):
    r"""FRFSM-like similarity: mean over points of :math:`\exp(-\Delta L^2/(2\sigma^2))`.

    After the idea of Lee, Ahn & Kim's FRF similarity metric [4]_, not their formula: a
    uniform 6 dB gap scores 0.61, 3 dB 0.88, 12 dB 0.14.

    Parameters
    ----------
    gap_db : array_like, shape (n,)
        Level gaps [dB].
    sigma_db : float
        Kernel width [dB] (default 6 dB).

    Returns
    -------
    float
        In (0, 1]; 1 for identical curves; NaN if ``n = 0``.
    """
    g = np.asarray(gap_db, float)
    if g.size == 0:
        return float("nan")
    return float(np.mean(np.exp(-g ** 2 / (2.0 * sigma_db ** 2))))


def interpolate_phase(rpm, phase_deg, rpm_new):
    """Phase [deg] at ``rpm_new`` [rpm] from ``phase_deg`` at ``rpm``: linear in rpm on the
    unwrapped phase, wrapped to (-180°, 180°]; NaN outside the given speeds."""
    rpm, phase = np.asarray(rpm, float), np.asarray(phase_deg, float)
    ok = np.isfinite(phase)
    rpm_new = np.asarray(rpm_new, float)
    if not ok.any():
        return np.full(rpm_new.shape, np.nan)
    r, p = rpm[ok], np.degrees(np.unwrap(np.radians(phase[ok])))
    out = np.interp(rpm_new, r, p)
    out[(rpm_new < r[0] - 1e-9) | (rpm_new > r[-1] + 1e-9)] = np.nan
    return wrap_deg(out)


def phase_statistics(simulated, measured, sim_phase_deg, meas_phase_deg) -> dict:
    r"""Phase gap :math:`\varphi_\mathrm{sim} - \varphi_\mathrm{meas}` [deg] of the levels
    ``simulated``, ``measured`` at phases ``sim_phase_deg``, ``meas_phase_deg`` [deg]:
    ``phase_gap_deg`` (wrapped; NaN where a phase is), ``n_phase_compared``,
    ``phase_rms_deg``, ``phase_bias_deg`` (angle of the mean phasor), and ``complex_gap_db``,
    ``complex_gap_deg``: :math:`20\log_{10}|a|`, :math:`\arg a` of the least-squares ratio
    :math:`a = \sum_n S_n \bar M_n / \sum_n |M_n|^2`."""
    gap = wrap_deg(np.asarray(sim_phase_deg, float) - np.asarray(meas_phase_deg, float))
    ok = np.isfinite(gap)
    out = {"phase_gap_deg": gap, "n_phase_compared": int(ok.sum())}
    if not ok.any():
        return out
    S = np.asarray(simulated, float)[ok] * np.exp(1j * np.radians(sim_phase_deg[ok]))
    M = np.asarray(measured, float)[ok] * np.exp(1j * np.radians(meas_phase_deg[ok]))
    ratio = np.sum(S * np.conj(M)) / np.sum(np.abs(M) ** 2)
    out.update({"phase_rms_deg": float(np.sqrt(np.mean(gap[ok] ** 2))),
                "phase_bias_deg": float(np.degrees(np.angle(np.mean(np.exp(
                    1j * np.radians(gap[ok])))))),
                "complex_gap_db": float(20 * np.log10(max(abs(ratio), 1e-300))),
                "complex_gap_deg": float(np.degrees(np.angle(ratio)))})
    return out
