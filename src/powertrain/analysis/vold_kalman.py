r"""Vold–Kalman order filtering (second method of ``powertrain track``).

For each order :math:`o` the complex envelope :math:`a_k` of :math:`x_k \approx a_k
e^{i o \theta_k} + \mathrm{c.c.}` is the solution of the Vold–Kalman least-squares problem
with a two-pole structural equation [1]_:

.. math:: \min_a \sum_k |x_k - a_k c_k|^2 + r^2 \sum_k |a_{k+1} - 2a_k + a_{k-1}|^2,
          \qquad c_k = e^{i o \theta_k},

whose normal equations, since :math:`|c_k| = 1`, are
:math:`(\mathbf I + r^2 \mathbf D^\mathsf T\mathbf D)\,\mathbf a = \bar{\mathbf c}\odot\mathbf x`
with :math:`\mathbf D` the second-difference matrix: one real symmetric positive-definite
pentadiagonal matrix for every order and channel, factored once (banded Cholesky). The
filter's amplitude response to a component at :math:`f` Hz from the order is
:math:`1/(1 + r^2 (2 - 2\cos 2\pi f\Delta t)^2)`; the weight is set from the -3 dB
half-bandwidth :math:`f_b`: :math:`r = \sqrt{\sqrt2 - 1}/(2\pi f_b\Delta t)^2`.

Unlike a block spectrum the envelope follows the order sample by sample, so a
fixed-frequency tone crossing the order disturbs it only while it is within about
:math:`f_b` of the order (``tests/test_order_tracking.py`` shows COT smearing where VKF
holds). Each order is filtered on its own (the "one order at a time" form); closely
crossing orders of the same shaft never meet, so the joint multi-order form is not needed
here. Long records are first decimated (polyphase, Kaiser anti-alias) to about five times
the highest tracked frequency.

References
----------
.. [1] H. Vold, J. Leuridan, "High resolution order tracking at extreme slew rates using
   Kalman tracking filters", SAE Technical Paper 931288, 1993.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.analysis.order_tracking import first_passing

#: Default -3 dB half-bandwidth of the filter [Hz]: holds an order within 0.5 dB while a
#: fixed tone of half its amplitude crosses it at 500 rpm/s (order 2; tests and
#: scripts/verify_order_tracking.py); widen it for envelopes that change faster.
DEFAULT_BANDWIDTH_HZ = 0.5
#: Speeds closer to the record ends than this many 1/bandwidth seconds are not reported:
#: the smoother's end transient (time constant about 1/(2 pi f_b / sqrt 2)) has decayed
#: below 0.01 dB there.
EDGE_TIME_CONSTANTS = 1.5
#: Decimate when the sampling rate exceeds this multiple of the highest tracked frequency.
DECIMATE_ABOVE = 10.0
DECIMATED_RATE_FACTOR = 5.0


def check_bandwidth(bandwidth_hz, duration_s, sample_rate):
    """Refuse a bandwidth [Hz] that is not finite and > 0, above a quarter of the sampling
    rate, or so narrow that the end transients (:data:`EDGE_TIME_CONSTANTS` / bandwidth at
    each end) leave no data of the ``duration_s`` record."""
    from powertrain.errors import InputError
    if not 0 < bandwidth_hz <= 0.25 * sample_rate:
        raise InputError(f"must be > 0 and <= {0.25 * sample_rate:g} Hz (a quarter of the "
                         f"sampling rate), got {bandwidth_hz:g}", key="--bandwidth")
    edge = EDGE_TIME_CONSTANTS / bandwidth_hz
    if not 2 * edge < duration_s:
        raise InputError(f"{bandwidth_hz:g} Hz needs {edge:.3g} s at each end of the record "
                         f"for the filter's end transient; the record is {duration_s:.3g} s "
                         "(a wider bandwidth)", key="--bandwidth")


def weight_from_bandwidth(bandwidth_hz, dt):
    """Structural weight r for a -3 dB half-bandwidth [Hz] at sample interval dt [s]."""
    x = 2 * math.pi * bandwidth_hz * dt
    return math.sqrt(math.sqrt(2.0) - 1.0) / x ** 2


def _factor(n, r):
    """Banded Cholesky factor of I + r^2 D^T D (upper form for scipy)."""
    from scipy.linalg import cholesky_banded
    # D^T D of the second difference: diagonals [1,5,6,...,6,5,1], [-2,-4,...,-4,-2], [1...]
    d0 = np.full(n, 6.0)
    d0[[0, -1]] = 1.0
    d0[[1, -2]] = 5.0
    d1 = np.full(n - 1, -4.0)
    d1[[0, -1]] = -2.0
    d2 = np.ones(n - 2)
    ab = np.zeros((3, n))
    r2 = r * r
    ab[2] = 1.0 + r2 * d0
    ab[1, 1:] = r2 * d1
    ab[0, 2:] = r2 * d2
    return cholesky_banded(ab)


def vkf_amplitudes(X, profile, orders, rpm_centre, *, bandwidth_hz=DEFAULT_BANDWIDTH_HZ,
                   progress=False):
    """Complex order amplitudes at the grid speeds by Vold–Kalman filtering.

    Parameters
    ----------
    X : ndarray (n_ch, n)
        Channels [SI] at ``profile.time``.
    profile : SpeedProfile
    orders : ndarray (n_o,)
    rpm_centre : ndarray (k,)
        Grid speeds [rpm]; each is read at the first instant the speed passes it.
    bandwidth_hz : float
        -3 dB half-bandwidth [Hz].
    progress : bool
        tqdm bar over the orders (hidden when stderr is not a terminal).

    Returns
    -------
    ndarray complex (k, n_ch, n_o)
        Peak complex amplitudes [SI], phase relative to crank angle 0.
    """
    from scipy.linalg import cho_solve_banded
    from scipy.signal import resample_poly
    X = np.asarray(X, float)
    t, angle, rpm = profile.time, profile.angle, profile.rpm
    fs = (t.size - 1) / (t[-1] - t[0])
    f_hi = float(np.max(orders)) * float(np.max(rpm)) / 60.0
    D = int(fs // (DECIMATED_RATE_FACTOR * f_hi)) if fs > DECIMATE_ABOVE * f_hi else 1
    if D >= 2:
        X = resample_poly(X, 1, D, axis=-1, window=("kaiser", 8.0))
        t, angle, rpm = t[::D][:X.shape[1]], angle[::D][:X.shape[1]], rpm[::D][:X.shape[1]]
    times = first_passing(t, rpm, rpm_centre)
    cb = _factor(t.size, weight_from_bandwidth(bandwidth_hz, (t[-1] - t[0]) / (t.size - 1)))
    out = np.empty((len(rpm_centre), X.shape[0], len(orders)), complex)
    iterator = range(len(orders))
    if progress:
        from tqdm import tqdm
        iterator = tqdm(iterator, desc="Vold-Kalman", unit="order", leave=False, disable=None)
    for k in iterator:
        c = np.exp(-1j * orders[k] * angle)
        rhs = (X * c[None, :]).T                                   # (n, n_ch)
        env = cho_solve_banded((cb, False), rhs.real) + 1j * cho_solve_banded((cb, False),
                                                                           rhs.imag)
        for ch in range(X.shape[0]):
            out[:, ch, k] = 2.0 * (np.interp(times, t, env[:, ch].real)
                                   + 1j * np.interp(times, t, env[:, ch].imag))
    return out
