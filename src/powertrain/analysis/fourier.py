r"""Fourier coefficients of sampled periodic signals.

For :math:`N` samples over whole periods, :math:`s(t) \approx \mathrm{Re}\sum_j \hat S_j
e^{i j \Omega t}` with :math:`\hat S_j = \frac{2}{N}\sum_k s_k e^{-2\pi i jk/N}`
(:math:`j \ge 1`), :math:`\hat S_0 = \frac1N\sum_k s_k`; RMS :math:`|\hat S_j|/\sqrt2`.
"""

from __future__ import annotations

import numpy as np


def harmonic_amplitudes(samples, axis=0):
    """Complex amplitudes of all harmonics of a signal sampled over one window.

    Parameters
    ----------
    samples : ndarray
        Equally spaced samples over the window, end point excluded, along ``axis``.
    axis : int
        Time axis of ``samples``.

    Returns
    -------
    ndarray of complex
        Harmonic j of the window's fundamental at index j (0 = mean).
    """
    samples = np.asarray(samples, dtype=float)
    N = samples.shape[axis]
    spec = np.fft.rfft(samples, axis=axis) / N
    idx = [slice(None)] * spec.ndim
    idx[axis] = slice(1, None)
    spec[tuple(idx)] *= 2.0
    return spec
