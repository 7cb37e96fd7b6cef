"""Significance of a held-out improvement: t of the per-speed log ratios of mean squared gaps."""

from __future__ import annotations

import math

import numpy as np


def improvement_t(base, cand, noise_mse=0.0):
    r"""t statistic of the held-out improvement per speed of ``cand`` over ``base``.

    :math:`d_r = \ln\frac{E_{0,r} + E_n}{E_{c,r} + E_n}` (``noise_mse`` :math:`E_n` [dB²]), a
    relative improvement whose scatter over speeds measures chance (a difference would be
    dominated by the speeds near a resonance); t = :math:`\bar d/(s_d/\sqrt{n_r})`.
    """
    return log_ratio_t(base.heldout_per_rpm, cand.heldout_per_rpm, noise_mse)


def crossfit_t(base, cand, noise_mse=0.0):
    """:func:`improvement_t` over every speed when both carry ``crossfit``, else held-out."""
    if base.crossfit is None or cand.crossfit is None:
        return improvement_t(base, cand, noise_mse)
    return log_ratio_t(base.crossfit, cand.crossfit, noise_mse)


def log_ratio_t(per_0, per_c, noise_mse=0.0):
    """t of the per-speed ln((per_0 + E_n)/(per_c + E_n)), ``noise_mse`` E_n (NaN dropped)."""
    en = max(float(noise_mse), 1e-12)
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.log((np.asarray(per_0, float) + en) / (np.asarray(per_c, float) + en))
    d = d[np.isfinite(d)]
    if d.size < 2:
        return float("nan")
    sd = float(np.std(d, ddof=1))
    if sd > 0:
        return float(np.mean(d)) / (sd / math.sqrt(d.size))
    return float("inf") if np.mean(d) > 0 else 0.0
