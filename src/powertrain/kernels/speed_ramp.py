r"""The continuous sweep's per-sample loops (:mod:`powertrain.solvers.speed_ramp`): the ramp's
load read from its table, the modal Newmark recurrence and the channel outputs, fused.

Ramp: :math:`n(t) = n_0 + \dot n t`, :math:`\theta(t) = \tfrac{2\pi}{60}(n_0 t +
\tfrac12\dot n t^2)`, :math:`t_k = k h`; the table holds the generalized load at speeds
``speed0 + i speed_step`` [rpm] and ``n_theta`` angles over the cycle plus the periodic wrap.
"""

import math

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def ramp_load(table, speed0, speed_step, rpm_from, rate, h, k, out):
    """Load ``out`` (6,) of the ramp ``rpm_from`` + ``rate`` t [rpm, rpm/s] at step ``k`` of
    ``h`` [s], bilinear in ``table`` (n_speeds, n_theta + 1, 6) of ``speed0``, ``speed_step``."""
    n_speeds, n_theta = table.shape[0], table.shape[1] - 1
    t = k * h
    rpm = rpm_from + rate * t
    theta = (2.0 * np.pi / 60.0) * (rpm_from * t + 0.5 * rate * t * t)
    cycles = theta * (1.0 / (4.0 * np.pi))
    u = (cycles - math.floor(cycles)) * n_theta       # floor: no fmod call per step
    i = min(int(u), n_theta - 1)
    fu = u - i
    v = min(max((rpm - speed0) / speed_step, 0.0), n_speeds - 1 - 1e-12)
    s = int(v)
    fv = v - s
    s1 = min(s + 1, n_speeds - 1)
    for c in range(6):
        a = table[s, i, c] * (1.0 - fu) + table[s, i + 1, c] * fu
        b = table[s1, i, c] * (1.0 - fu) + table[s1, i + 1, c] * fu
        out[c] = a * (1.0 - fv) + b * fv


@njit(cache=True, nogil=True)
def ramp_loads(table, speed0, speed_step, rpm_from, rate, h, k0, out):
    """Loads ``out`` (n, 6) of the ramp at steps ``k0 .. k0 + n - 1`` (:func:`ramp_load`)."""
    for r in range(out.shape[0]):
        ramp_load(table, speed0, speed_step, rpm_from, rate, h, k0 + r, out[r])


@njit(cache=True, nogil=True, fastmath=True)
def modal_ramp_kernel(lam_d, load_map, w, w_load, table, speed0, speed_step, rpm_from, rate,
                      h, k0, x, out):
    r"""Channel outputs ``out`` (n_rows, n_ch) at steps ``k0 ..`` of the modal recurrence
    :math:`\eta_{k+1} = \lambda_d\eta_k + g_k + g_{k+1}`, :math:`g = ` ``load_map``
    :math:`\cdot f` (gain folded in), :math:`y = \mathrm{Re}(W\eta) + W_{load}f`
    (``w``, ``w_load``), the load :func:`ramp_load`'s. Real form: the real parts of the n
    modes, then the imaginary parts of the complex ones, which come first: ``x`` (n_x,),
    ``load_map`` (6, n_x), ``w`` (n_ch, n_x), ``lam_d = (real parts (n,), imaginary parts
    (n_c,))``. ``x`` is the state at step ``k0`` on entry, at ``k0 + n_rows`` on return.
    """
    lr, li = lam_d
    n = lr.shape[0]
    f, f_next = np.empty(6), np.empty(6)
    ramp_load(table, speed0, speed_step, rpm_from, rate, h, k0, f)
    for r in range(out.shape[0]):
        for c in range(out.shape[1]):
            y = 0.0
            for q in range(6):
                y += w_load[c, q] * f[q]
            wc = w[c]
            for j in range(x.shape[0]):
                y += wc[j] * x[j]
            out[r, c] = y
        ramp_load(table, speed0, speed_step, rpm_from, rate, h, k0 + r + 1, f_next)
        for j in range(li.shape[0]):
            a = lr[j] * x[j] - li[j] * x[n + j]
            x[n + j] = lr[j] * x[n + j] + li[j] * x[j]
            x[j] = a
        for j in range(li.shape[0], n):
            x[j] *= lr[j]
        for q in range(6):               # g_k + g_k+1 = map (f_k + f_k+1): one pass per load
            s = f[q] + f_next[q]
            row = load_map[q]
            for j in range(x.shape[0]):
                x[j] += row[j] * s
            f[q] = f_next[q]


@njit(cache=True, nogil=True, fastmath=True)
def fir_decimate(fir, buf_t, m, i_lo, out):
    """Rows ``i_lo ..`` of ``upfirdn(fir, buf_t.T, 1, m, axis=0)`` (scipy) into ``out``
    (n_out, n_ch), ``buf_t`` (n_ch, n)."""
    last = fir.shape[0] - 1
    rev = fir[::-1].copy()
    for r in range(out.shape[0]):
        start = (i_lo + r) * m - last
        for c in range(out.shape[1]):
            row = buf_t[c, start:start + last + 1]
            y = 0.0
            for k in range(last + 1):
                y += rev[k] * row[k]
            out[r, c] = y
