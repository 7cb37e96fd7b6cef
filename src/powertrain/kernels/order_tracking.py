r"""Angle-domain resampling kernel of computed order tracking.

Each output sample is a low-pass interpolation of the channels at a fractional input index
:math:`p`:

.. math:: y(p) = \frac{\sum_i h\!\left(\frac{i - p}{L}\right) x_i}
                      {\sum_i h\!\left(\frac{i - p}{L}\right)},\qquad
          h(v) = \operatorname{sinc}(K v)\,w_\mathrm{Kaiser}(v),\quad |v| < 1,

a Kaiser-windowed sinc with ``K`` zero crossings per side stretched over ``L = K / c``
input samples, i.e. a low-pass at ``c`` times the input Nyquist frequency (``c = 1``:
plain band-limited interpolation; ``c < 1``: the anti-alias filter of a resampling to a
lower rate, applied only where output samples are wanted). The kernel is tabulated
(``table``, linear interpolation between entries); the weights are computed once per output
sample and applied to every channel.
"""

import math

import numpy as np
from numba import njit, prange

#: Output samples per parallel work item.
CHUNK = 256


@njit(cache=True, nogil=True, parallel=True)
def sinc_resample_kernel(X, pos, cutoff, table, K, out):
    """Low-pass interpolate every channel of ``X`` at the fractional indices ``pos``.

    Parameters
    ----------
    X : ndarray (n_ch, n)
        Channels, uniformly sampled.
    pos : ndarray (m,)
        Fractional sample indices wanted.
    cutoff : ndarray (m,)
        Low-pass cut-off per output sample, fraction of the input Nyquist (0 < c <= 1).
    table : ndarray (n_tab,)
        h(v) tabulated on v = -1 ... 1 (see module docstring).
    K : float
        Zero crossings per side of the tabulated kernel.
    out : ndarray (n_ch, m)
        Output.
    """
    n_ch = X.shape[0]
    n = X.shape[1]
    m = pos.shape[0]
    n_tab = table.shape[0]
    half_tab = 0.5 * (n_tab - 1)
    c_min = 1.0
    for j in range(m):
        c_min = min(c_min, cutoff[j])
    max_width = int(2.0 * K / c_min) + 3
    n_chunks = (m + CHUNK - 1) // CHUNK
    for b in prange(n_chunks):
        w = np.empty(max_width)
        for j in range(b * CHUNK, min(m, (b + 1) * CHUNK)):
            p = pos[j]
            L = K / cutoff[j]
            i_lo = max(int(math.ceil(p - L)), 0)
            i_hi = min(int(math.floor(p + L)), n - 1)
            width = i_hi - i_lo + 1
            wsum = 0.0
            for q in range(width):
                u = ((i_lo + q - p) / L + 1.0) * half_tab
                k = min(int(u), n_tab - 2)
                f = u - k
                c = table[k] + f * (table[k + 1] - table[k])
                w[q] = c
                wsum += c
            for ch in range(n_ch):
                s = 0.0
                for q in range(width):
                    s += w[q] * X[ch, i_lo + q]
                out[ch, j] = s / wsum
