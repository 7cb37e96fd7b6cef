r"""Overall level of the raw signal per speed (``powertrain track --overall``).

At each grid speed: the Hann-weighted RMS of the channel band-limited to
:math:`[f_\mathrm{lo}, f_\mathrm{hi}]` (ideal FFT filter over the whole record) over the COT
block, :math:`L = \sqrt{\sum_j w_j\,x_j^2 / \sum_j w_j}`. On tracked orders alone it equals
the synthesis; :math:`L^2 - \mathrm{synthesis}^2` is the in-band power of the rest.
"""

from __future__ import annotations

import numpy as np
from scipy.fft import irfft, next_fast_len, rfft, rfftfreq

from powertrain.analysis.order_tracking import first_passing
from powertrain.errors import InputError


def parse_band(text: str, option: str = "--overall-band"):
    """``text`` ``LO:HI`` [Hz] -> (lo, hi) with 0 <= lo < hi; ``option`` names errors."""
    try:
        lo, hi = (float(v) for v in str(text).split(":"))
    except ValueError:
        raise InputError(f"cannot read band {text!r} (use LO:HI in Hz, e.g. 5:1000)", key=option) from None
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 <= lo < hi):
        raise InputError("band must be LO:HI with 0 <= LO < HI [Hz]", key=option)
    return lo, hi


def band_limited(x, fs, band, derivative=None):
    r"""Channels ``x`` (n_ch, n) at ``fs`` [Hz] with every FFT bin outside ``band`` [Hz]
    zeroed; ``derivative`` (n_ch,) -1/0/1 integrates (:math:`/i\omega`) or differentiates."""
    n = x.shape[-1]
    m = next_fast_len(n, real=True)
    f = rfftfreq(m, 1.0 / fs)
    out = np.empty_like(x, dtype=float)
    for c in range(x.shape[0]):                        # one at a time: bounded memory
        spec = rfft(x[c], m)
        spec[(f < band[0]) | (f > band[1]) | (f == 0)] = 0.0
        if derivative is not None and derivative[c]:
            jw = 2j * np.pi * np.where(f > 0, f, 1.0)
            spec *= jw if derivative[c] > 0 else 1.0 / jw
        out[c] = irfft(spec, m)[:n]
    return out


def overall_rms(X, profile, rpm, block_revs, band, derivative=None):
    """Overall level [SI RMS] per grid speed and channel (module docstring).

    Parameters
    ----------
    X : ndarray (n_ch, n)
        Channels [SI] at ``profile.time``.
    profile : SpeedProfile
    rpm : ndarray (k,)
        Grid speeds [rpm] (each read where the speed first passes it).
    block_revs : int
        Span of each level [revolutions], centred on the passing instant.
    band : (float, float)
        Band [Hz].
    derivative : sequence of int, optional
        Per channel: -1 integrate, 1 differentiate, 0 keep (:func:`band_limited`).

    Returns
    -------
    ndarray (k, n_ch)
    """
    t, angle = profile.time, profile.angle
    fs = (t.size - 1) / (t[-1] - t[0])
    y = band_limited(np.asarray(X, float), fs, band, derivative)
    _, centre = first_passing(t, profile.rpm, rpm, angle)
    lo = np.searchsorted(t, np.interp(centre - np.pi * block_revs, angle, t))
    hi = np.searchsorted(t, np.interp(centre + np.pi * block_revs, angle, t))
    out = np.empty((len(rpm), y.shape[0]))
    for i, (a, b) in enumerate(zip(lo, hi)):
        w = np.hanning(b - a + 2)[1:-1]
        out[i] = np.sqrt((y[:, a:b] ** 2) @ w / w.sum())
    return out
