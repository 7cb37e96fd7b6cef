r"""Vold–Kalman order filtering (second method of ``powertrain track``).

For each order :math:`o` the complex envelope :math:`a_k` of :math:`x_k \approx a_k
e^{i o \theta_k} + \mathrm{c.c.}` is the solution of the Vold–Kalman least-squares problem
with a two-pole structural equation [1]_:

.. math:: \min_a \sum_k |x_k - a_k c_k|^2 + r^2 \sum_k |a_{k+1} - 2a_k + a_{k-1}|^2,
          \qquad c_k = e^{i o \theta_k},

with normal equations (:math:`|c_k| = 1`)
:math:`(\mathbf I + r^2 \mathbf D^\mathsf T\mathbf D)\,\mathbf a = \bar{\mathbf c}\odot\mathbf x`,
:math:`\mathbf D` the second-difference matrix: one pentadiagonal SPD matrix per order,
factored once (banded Cholesky). The amplitude response at :math:`f` Hz from the order is
:math:`1/(1 + r^2 (2 - 2\cos 2\pi f\Delta t)^2)`, so the -3 dB half-bandwidth :math:`f_b`
gives :math:`r = \sqrt{\sqrt2 - 1}/(2\pi f_b\Delta t)^2`.

The default bandwidth (:func:`default_bandwidth`; ``docs/guide/track.md``) is the narrowest
of: *sweep* :math:`f_b = 1.5\sqrt{\dot f_o}` [Hz/s] (a linear chirp's time-frequency limit,
A. Brandt, *Noise and Vibration Analysis*, Wiley 2011, ch. 12); *record* at least
:math:`1.5/(0.05\,T)`; capped by *spacing*, a quarter of the distance to the nearest other
order. Long records are first decimated (polyphase, Kaiser) to about five times the highest
tracked frequency.

References
----------
.. [1] H. Vold, J. Leuridan, "High resolution order tracking at extreme slew rates using
   Kalman tracking filters", SAE Technical Paper 931288, 1993.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import cho_solve_banded, cholesky_banded
from scipy.ndimage import uniform_filter1d
from scipy.signal import resample_poly

from powertrain.analysis.order_tracking import first_passing
from powertrain.errors import InputError

#: Sweep rule: f_b = SWEEP_FACTOR * sqrt(order frequency rate [Hz/s]) (module docstring).
SWEEP_FACTOR = 1.5
#: Spacing rule: f_b <= distance to the nearest other order / SPACING_RATIO (-40.6 dB there).
SPACING_RATIO = 4.0
#: Record rule: at most this fraction of the record is dropped at each end.
EDGE_FRACTION = 0.05
#: Window [s] over which the speed's rate of change is averaged for the sweep rule.
SWEEP_RATE_WINDOW_S = 0.5
#: Speeds within this many 1/bandwidth seconds of the record ends are not reported (the end
#: transient has decayed below 0.01 dB beyond).
EDGE_TIME_CONSTANTS = 1.5
#: Decimate when the sampling rate exceeds this multiple of the highest tracked frequency.
DECIMATE_ABOVE = 10.0
DECIMATED_RATE_FACTOR = 5.0


def check_bandwidth(bandwidth_hz, duration_s, sample_rate):
    """Refuse a ``bandwidth_hz`` [Hz] not in (0, ``sample_rate``/4] [Hz], or whose end
    transients (:data:`EDGE_TIME_CONSTANTS` / bandwidth) fill the ``duration_s`` [s] record."""
    if not 0 < bandwidth_hz <= 0.25 * sample_rate:
        raise InputError(f"must be > 0 and <= {0.25 * sample_rate:g} Hz (a quarter of the "
                         f"sampling rate), got {bandwidth_hz:g}", key="--bandwidth")
    edge = EDGE_TIME_CONSTANTS / bandwidth_hz
    if not 2 * edge < duration_s:
        raise InputError(f"{bandwidth_hz:g} Hz needs {edge:.3g} s at each end of the record "
                         f"for the filter's end transient; the record is {duration_s:.3g} s "
                         "(a wider bandwidth)", key="--bandwidth")


def weight_from_bandwidth(bandwidth_hz, dt):
    """Structural weight r for a -3 dB half-bandwidth ``bandwidth_hz`` [Hz] at ``dt`` [s]."""
    x = 2 * np.pi * np.asarray(bandwidth_hz, float) * dt
    return math.sqrt(math.sqrt(2.0) - 1.0) / x ** 2


def default_bandwidth(profile, orders):
    """Default -3 dB half-bandwidth [Hz] per ``orders`` and sample of ``profile`` (module
    docstring).

    Returns
    -------
    ndarray (n_o, n)
        Bandwidth of each order at each sample of ``profile.time``.
    """
    t, rpm = profile.time, profile.rpm
    dt = (t[-1] - t[0]) / (t.size - 1)
    i0, i1 = profile.valid
    rate = np.abs(np.gradient(rpm, dt))                                  # [rpm/s]
    rate = uniform_filter1d(rate, max(1, int(round(SWEEP_RATE_WINDOW_S / dt))), mode="nearest")
    o = np.sort(np.asarray(orders, float))
    spacing = np.minimum(o, np.diff(o, prepend=-np.inf))
    spacing = np.minimum(spacing, np.diff(o, append=np.inf))
    sweep = SWEEP_FACTOR * np.sqrt(o[:, None] * rate[None, :] / 60.0)
    record = EDGE_TIME_CONSTANTS / (EDGE_FRACTION * (t[i1] - t[i0]))
    speed = np.maximum(np.abs(rpm), np.min(rpm[i0:i1 + 1]))     # tacho: extrapolated ends
    cap = spacing[:, None] * speed[None, :] / (60.0 * SPACING_RATIO)
    width = np.minimum(np.maximum(sweep, record), cap)
    return width[np.argsort(np.argsort(np.asarray(orders, float)))]


def _factor(r):
    """Banded Cholesky factor (upper) of I + D^T diag(r^2) D; r (n-2,)."""
    w = np.asarray(r, float) ** 2
    n = w.size + 2
    ab = np.zeros((3, n))
    ab[2] = 1.0
    ab[2, :-2] += w
    ab[2, 1:-1] += 4.0 * w
    ab[2, 2:] += w
    ab[1, 1:-1] -= 2.0 * w
    ab[1, 2:] -= 2.0 * w
    ab[0, 2:] = w
    return cholesky_banded(ab)


def vkf_amplitudes(X, profile, orders, rpm_centre, *, bandwidth_hz, progress=False):
    """Complex order amplitudes at the grid speeds by Vold–Kalman filtering.

    Parameters
    ----------
    X : ndarray (n_ch, n)
        Channels [SI] at ``profile.time``.
    profile : SpeedProfile
    orders : ndarray (n_o,)
    rpm_centre : ndarray (k,)
        Grid speeds [rpm]; each is read at the first instant the speed passes it.
    bandwidth_hz : float or ndarray (n_o, n)
        -3 dB half-bandwidth [Hz] (per order and sample: :func:`default_bandwidth`).
    progress : bool
        tqdm bar over the orders (hidden when stderr is not a terminal).

    Returns
    -------
    ndarray complex (k, n_ch, n_o)
        Peak complex amplitudes [SI], phase relative to crank angle 0.
    """
    X = np.asarray(X, float)
    t, angle, rpm = profile.time, profile.angle, profile.rpm
    width = np.broadcast_to(np.asarray(bandwidth_hz, float), (len(orders), t.size))
    fs = (t.size - 1) / (t[-1] - t[0])
    f_hi = float(np.max(orders)) * float(np.max(rpm)) / 60.0
    D = int(fs // (DECIMATED_RATE_FACTOR * f_hi)) if fs > DECIMATE_ABOVE * f_hi else 1
    if D >= 2:
        X = resample_poly(X, 1, D, axis=-1, window=("kaiser", 8.0))
        keep = slice(None, D * X.shape[1], D)
        t, angle, rpm, width = t[keep], angle[keep], rpm[keep], width[:, keep]
    times = first_passing(t, rpm, rpm_centre)
    dt = (t[-1] - t[0]) / (t.size - 1)
    out = np.empty((len(rpm_centre), X.shape[0], len(orders)), complex)
    iterator = range(len(orders))
    if progress:
        from tqdm import tqdm  # deferred: heavy optional package
        iterator = tqdm(iterator, desc="Vold-Kalman", unit="order", leave=False, disable=None)
    for k in iterator:
        cb = _factor(weight_from_bandwidth(width[k, 1:-1], dt))
        c = np.exp(-1j * orders[k] * angle)
        rhs = (X * c[None, :]).T                                   # (n, n_ch)
        env = cho_solve_banded((cb, False), rhs.real) + 1j * cho_solve_banded((cb, False), rhs.imag)
        for ch in range(X.shape[0]):
            out[:, ch, k] = 2.0 * (np.interp(times, t, env[:, ch].real)
                                   + 1j * np.interp(times, t, env[:, ch].imag))
    return out
