r"""The one noise-floor rule: which measured levels are too close to the floor to be scored.

A measured RMS level :math:`m` is *at the floor* (censored: it only says the true level is
below :math:`\kappa f`) when :math:`m < \kappa f`, with :math:`f` the RMS noise floor and
:math:`\kappa` = :data:`NOISE_FLOOR_MARGIN` = 3 (9.5 dB): noise alone exceeds it with
probability :math:`e^{-\kappa^2}` = 1.2e-4, and a signal there is inflated by the floor by
only 0.46 dB. ``compare`` excludes and counts such points, ``diagnose`` censors them. A
*model* level below the floor itself (:func:`below_floor`) with the measurement above the
censoring level is "measured, not modelled".
"""

from __future__ import annotations

import numpy as np

#: Multiple of the RMS noise floor below which a measured level is censored [1] (9.5 dB:
#: noise alone exceeds it with probability e^-9 = 1.2e-4).
NOISE_FLOOR_MARGIN = 3.0
#: The margin in decibels, 20 log10(NOISE_FLOOR_MARGIN) [dB].
NOISE_FLOOR_MARGIN_DB = float(20.0 * np.log10(NOISE_FLOOR_MARGIN))


def censoring_level(noise_floor):
    """Level below which a measured point is at the floor [unit of ``noise_floor``]."""
    return NOISE_FLOOR_MARGIN * noise_floor


def at_floor(measured, noise_floor):
    """True where a measured level is at or below the censoring level, or not positive
    (NaN stays False: absent points are not 'at the floor')."""
    m = np.asarray(measured, float)
    with np.errstate(invalid="ignore"):
        return (m < censoring_level(noise_floor)) | (m <= 0)


def above_floor(measured, noise_floor):
    """True where a measured level is finite and scoreable (not at the floor)."""
    return np.isfinite(np.asarray(measured, float)) & ~at_floor(measured, noise_floor)


def below_floor(level, noise_floor):
    """True where a (simulated) level is below the noise floor itself, or not positive
    (NaN stays False): a level the measurement could not see at all."""
    v = np.asarray(level, float)
    with np.errstate(invalid="ignore"):
        return (v < noise_floor) | (v <= 0)


#: dB per unit relative amplitude error, 20/ln 10 [dB].
DB_PER_NEPER = float(20.0 / np.log(10.0))


def floor_scatter_db(measured, noise_floor):
    r"""Scatter [dB, 1σ] the noise floor adds to a measured level :math:`m` (RMS).

    Complex Gaussian noise of RMS :math:`f` has a component of RMS :math:`f/\sqrt2` in phase
    with the signal; to first order it moves the level by
    :math:`(20/\ln 10)\,f/(\sqrt2\,m)` dB (2.0 dB at the censoring level 3f, 0.6 dB at 10f,
    0.2 dB at 30f). Infinite where ``measured`` is not positive, NaN where it is NaN."""
    m = np.asarray(measured, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(m > 0, DB_PER_NEPER * noise_floor / (np.sqrt(2.0) * m),
                        np.where(np.isnan(m), np.nan, np.inf))
