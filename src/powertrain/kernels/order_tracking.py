r"""Angle-domain resampling of computed order tracking: each output sample is a low-pass
interpolation of the channels at a fractional input index :math:`p`,

.. math:: y(p) = \frac{\sum_i h\!\left(\frac{i - p}{L}\right) x_i}
                      {\sum_i h\!\left(\frac{i - p}{L}\right)},\qquad
          h(v) = \operatorname{sinc}(K v)\,w_\mathrm{Kaiser}(v),\quad |v| < 1,

with ``L = K / c``: a low-pass at ``c`` times the input Nyquist frequency.
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
    n_ch, n = X.shape
    m, n_tab = pos.shape[0], table.shape[0]
    half_tab = 0.5 * (n_tab - 1)
    c_min = 1.0
    for j in range(m):
        c_min = min(c_min, cutoff[j])
    max_width = int(2.0 * K / c_min) + 3
    n_chunks = (m + CHUNK - 1) // CHUNK
    for b in prange(n_chunks):
        w = np.empty(max_width)
        for j in range(b * CHUNK, min(m, (b + 1) * CHUNK)):
            p, L = pos[j], K / cutoff[j]
            i_lo = max(int(math.ceil(p - L)), 0)
            i_hi = min(int(math.floor(p + L)), n - 1)
            width = i_hi - i_lo + 1
            wsum = 0.0
            for q in range(width):
                u = ((i_lo + q - p) / L + 1.0) * half_tab
                k = min(int(u), n_tab - 2)
                c = table[k] + (u - k) * (table[k + 1] - table[k])
                w[q] = c
                wsum += c
            for ch in range(n_ch):
                s = 0.0
                for q in range(width):
                    s += w[q] * X[ch, i_lo + q]
                out[ch, j] = s / wsum
