r"""Noise model of the measured order levels, per channel and level.

A point's scatter is :math:`\sigma(c, m) = \sqrt{\sigma_c^2 + \sigma_f(m)^2}`: the channel's
repeatability :math:`\sigma_c` (log-normal; from second differences of its dB levels at least
:data:`CLEAN_MULTIPLE` × the floor, :math:`1.4826\,\mathrm{MAD}/\sqrt6`, pooled over channels
below :data:`MIN_DIFFS` differences) and the floor's
(:func:`powertrain.analysis.noise_floor.floor_scatter_db`: 2.0 dB at 3f, 0.6 dB at 10f).
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.analysis.noise_floor import floor_scatter_db

#: Levels at least this multiple of the floor estimate a channel's own scatter [1].
CLEAN_MULTIPLE = 30.0
#: Fewest second differences for a channel's own estimate.
MIN_DIFFS = 10
#: Scatter when no channel has enough clean points [dB, 1σ] (a lab's 0.5-1 dB).
FALLBACK_DB = 0.7


def second_differences(level_db):
    """Finite second differences along speed (axis 0) of dB levels ``level_db``, flattened."""
    d2 = level_db[2:] - 2 * level_db[1:-1] + level_db[:-2]
    return d2[np.isfinite(d2)]


def mad_sigma(d2) -> float:
    """1σ of independent scatter from second differences ``d2``: 1.4826 MAD/√6."""
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0))


def channel_scatter_db(data) -> np.ndarray:
    """Repeatability scatter σ_c [dB, 1σ] of every channel of ``data`` (GapData), (n_ch,)."""
    lv = data.level[:, :, data.order_mask]
    with np.errstate(divide="ignore", invalid="ignore"):
        clean = np.where(lv >= CLEAN_MULTIPLE * data.floor, 20 * np.log10(lv), np.nan)
    per = [second_differences(clean[:, c]) for c in range(lv.shape[1])]
    pooled = np.concatenate(per) if per else np.empty(0)
    common = mad_sigma(pooled) if pooled.size >= MIN_DIFFS else FALLBACK_DB
    return np.array([mad_sigma(d) if d.size >= MIN_DIFFS else common for d in per])


def point_sigma_db(data, scatter_db=None) -> np.ndarray:
    """σ(c, m) [dB, 1σ] of every point of ``data``, like ``data.level``; ``scatter_db``: the
    channels' σ_c (default :func:`channel_scatter_db`) or one number."""
    sc = channel_scatter_db(data) if scatter_db is None else scatter_db
    sc = np.broadcast_to(np.asarray(sc, float), (len(data.channels),))
    fl = floor_scatter_db(data.level, data.floor)
    return np.sqrt(sc[None, :, None] ** 2 + fl ** 2)
