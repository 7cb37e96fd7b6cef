r"""Noise model of the measured order levels, per channel and level.

A measured order level scatters by the test's own repeatability (log-normal, σ_c per
channel: sensors, mountings and cable runs differ) and by the noise floor, which adds a
scatter that grows as the level nears the floor
(:func:`powertrain.analysis.noise_floor.floor_scatter_db`: 2.0 dB at the censoring level
3f, 0.6 dB at 10f). One σ for every channel and level under-states the scatter near the
floor and over-states it high above; the point's own

.. math:: \sigma(c, m) = \sqrt{\sigma_c^2 + \sigma_f(m)^2}

is used instead. :math:`\sigma_c` comes from the second differences of the channel's dB
level along speed at the points at least :data:`CLEAN_MULTIPLE` × the floor (there the
floor adds ≤ 0.2 dB), :math:`\hat\sigma = 1.4826\,\mathrm{MAD}/\sqrt6`; a channel with fewer
than :data:`MIN_DIFFS` such differences takes the estimate pooled over all channels.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.analysis.noise_floor import floor_scatter_db

#: Levels at least this multiple of the floor estimate a channel's own scatter [1].
CLEAN_MULTIPLE = 30.0
#: Fewest second differences for a channel's own estimate.
MIN_DIFFS = 10
#: Scatter assumed when no channel has enough clean points [dB, 1σ] (the middle of the
#: 0.5-1 dB a test lab's order levels scatter by).
FALLBACK_DB = 0.7


def _second_differences(level_db):
    """Second differences along speed (axis 0) of dB levels, finite ones, flattened."""
    d2 = level_db[2:] - 2 * level_db[1:-1] + level_db[:-2]
    return d2[np.isfinite(d2)]


def _mad_sigma(d2) -> float:
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0))


def channel_scatter_db(data) -> np.ndarray:
    """Repeatability scatter σ_c [dB, 1σ] of every channel, (n_ch,) (module docstring)."""
    lv = data.level[:, :, data.order_mask]
    with np.errstate(divide="ignore", invalid="ignore"):
        clean = np.where(lv >= CLEAN_MULTIPLE * data.floor, 20 * np.log10(lv), np.nan)
    per = [_second_differences(clean[:, c]) for c in range(lv.shape[1])]
    pooled = np.concatenate(per) if per else np.empty(0)
    common = _mad_sigma(pooled) if pooled.size >= MIN_DIFFS else FALLBACK_DB
    return np.array([_mad_sigma(d) if d.size >= MIN_DIFFS else common for d in per])


def point_sigma_db(data, scatter_db=None) -> np.ndarray:
    r"""σ(c, m) [dB, 1σ] of every measured point, like ``data.level`` (NaN where absent).

    ``scatter_db``: the channels' σ_c (default :func:`channel_scatter_db`), or one number
    for all."""
    sc = channel_scatter_db(data) if scatter_db is None else scatter_db
    sc = np.broadcast_to(np.asarray(sc, float), (len(data.channels),))
    fl = floor_scatter_db(data.level, data.floor)
    return np.sqrt(sc[None, :, None] ** 2 + fl ** 2)
