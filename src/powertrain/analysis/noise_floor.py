r"""The one noise-floor rule: which measured levels are too close to the floor to be scored.

A measured RMS level :math:`m` is *at the floor* (censored) when :math:`m < \kappa f`,
:math:`f` the RMS noise floor, :math:`\kappa` = :data:`NOISE_FLOOR_MARGIN` = 3 (9.5 dB: noise
alone exceeds it with probability :math:`e^{-\kappa^2}` = 1.2e-4; a signal there is inflated
by 0.46 dB). A model level below the floor itself (:func:`below_floor`) with the measurement
above the censoring level is "measured, not modelled".
"""

from __future__ import annotations

import numpy as np

#: Multiple of the RMS noise floor below which a measured level is censored [1].
NOISE_FLOOR_MARGIN = 3.0
#: The margin in decibels, 20 log10(NOISE_FLOOR_MARGIN) [dB].
NOISE_FLOOR_MARGIN_DB = float(20.0 * np.log10(NOISE_FLOOR_MARGIN))


def censoring_level(noise_floor):
    """Level below which a measured point is at the ``noise_floor`` [its unit]."""
    return NOISE_FLOOR_MARGIN * noise_floor


def at_floor(measured, noise_floor):
    """True where ``measured`` is below the censoring level of ``noise_floor`` or not
    positive (NaN: False)."""
    m = np.asarray(measured, float)
    with np.errstate(invalid="ignore"):
        return (m < censoring_level(noise_floor)) | (m <= 0)


def above_floor(measured, noise_floor):
    """True where ``measured`` is finite and not at ``noise_floor``."""
    return np.isfinite(np.asarray(measured, float)) & ~at_floor(measured, noise_floor)


def below_floor(level, noise_floor):
    """True where a simulated ``level`` is below ``noise_floor`` itself or not positive
    (NaN: False)."""
    v = np.asarray(level, float)
    with np.errstate(invalid="ignore"):
        return (v < noise_floor) | (v <= 0)


#: dB per unit relative amplitude error, 20/ln 10 [dB].
DB_PER_NEPER = float(20.0 / np.log(10.0))


def floor_scatter_db(measured, noise_floor):
    r"""Scatter [dB, 1σ] the ``noise_floor`` :math:`f` adds to a ``measured`` level :math:`m`.

    The noise's in-phase component (RMS :math:`f/\sqrt2`) moves the level by
    :math:`(20/\ln 10)\,f/(\sqrt2\,m)` dB (2.0 dB at 3f, 0.6 dB at 10f); inf where
    :math:`m \le 0`, NaN where NaN."""
    m = np.asarray(measured, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(m > 0, DB_PER_NEPER * noise_floor / (np.sqrt(2.0) * m),
                        np.where(np.isnan(m), np.nan, np.inf))
