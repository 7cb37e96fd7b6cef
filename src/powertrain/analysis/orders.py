r"""Order analysis of engine-synchronous signals.

Signals at a constant crank-angle increment over W revolutions (whole engine cycles) are
Fourier analysed: harmonic j is order j/W. Orders 0.5..8 are reported as RMS
:math:`|\hat S|/\sqrt 2`; the synthesis is :math:`\sqrt{\sum_o S_{o,\mathrm{rms}}^2}`
(Kovarik 2016, sec. 4.4).
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes

#: Orders reported: 0.5 ... 8 in steps of 0.5.
ORDERS = np.arange(1, 17) * 0.5


def order_label(order: float) -> str:
    """Label of ``order``: ``order_0.5``, ``order_1`` ... (no trailing ``.0``)."""
    return f"order_{order:g}"


def quantity_sort_key(quantity: str):
    """Sort key of a ``quantity`` label: ``synthesis`` first, then orders ascending."""
    if quantity == "synthesis":
        return (0, 0.0)
    return (1, float(quantity.split("_", 1)[1]))


def order_spectrum(samples, revolutions, orders=ORDERS, axis=0):
    """Complex amplitudes of the given orders [unit of ``samples``].

    Parameters
    ----------
    samples : ndarray
        Samples over exactly ``revolutions`` crank revolutions (end point excluded), along
        ``axis``; constant crank-angle increment.
    revolutions : int
        Window length in crank revolutions (4 for two four-stroke cycles).
    orders : array_like
        Orders wanted; each times ``revolutions`` must be an integer.
    axis : int
        Time axis of ``samples``.

    Returns
    -------
    ndarray complex, the ``axis`` replaced by one entry per order.
    """
    spec = harmonic_amplitudes(samples, axis=axis)
    idx = np.asarray(orders, float) * revolutions
    if not np.allclose(idx, np.round(idx)):
        raise ValueError("orders must fall on FFT bins of the window")
    idx = np.round(idx).astype(int)
    if idx.max() >= spec.shape[axis]:
        raise ValueError("window too coarsely sampled for the highest order")
    return np.take(spec, idx, axis=axis)


def order_rms(amplitudes):
    """RMS value of each order from complex ``amplitudes``."""
    return np.abs(amplitudes) / np.sqrt(2.0)


def synthesis_rms(amplitudes, axis=-1):
    """RMS sum of ``amplitudes`` over orders, sqrt(sum of order RMS^2), along ``axis``."""
    return np.sqrt(np.sum(order_rms(amplitudes) ** 2, axis=axis))
