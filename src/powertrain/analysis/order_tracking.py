r"""Computed order tracking (COT) of run-up time data (``docs/guide/track.md``, step 3).

For each grid speed, a block of ``B`` revolutions centred where the speed is passed is
resampled to ``S`` samples per revolution (low-pass at the local angular Nyquist frequency
:math:`S\,n/120` [Hz], :mod:`powertrain.kernels.order_tracking`) and its Hann-windowed
spectrum evaluated at exactly the orders asked for:

.. math:: \hat S_o = \frac{2}{\sum_j w_j}\sum_j w_j\,x(\theta_j)\,e^{-i o \theta_j},
          \qquad \mathrm{RMS}_o = |\hat S_o|/\sqrt2.

At least 4 bins between neighbouring orders (:func:`block_revolutions`) keep one order's
Hann side lobes below -50 dB at the next.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.errors import InputError
from powertrain.kernels.order_tracking import sinc_resample_kernel

#: Angle samples per revolution: at least this many per unit of the highest order.
SAMPLES_PER_ORDER = 6
#: Anti-alias cut-off as a fraction of the angular Nyquist frequency S/2: only content above
#: 5S/6 folds onto the tracked orders (<= S/6), beyond the kernel's transition band.
ANTI_ALIAS_FRACTION = 1.0
#: Zero crossings per side and Kaiser beta of the resampling kernel (0.004 dB on a sweep
#: under 5x stronger orders 8.25..200, tests/test_order_tracking.py).
KERNEL_ZERO_CROSSINGS = 8
KERNEL_BETA = 7.0
#: Block length bounds [revolutions].
MIN_BLOCK_REVS = 8
MAX_BLOCK_REVS = 64
#: Most speeds of a tracked speed grid (1 rpm steps over 20 000 rpm).
MAX_GRID_SPEEDS = 20_000
#: Most orders one ``--orders`` may ask for, and the highest order (200 at 6000 rpm: 20 kHz).
MAX_ORDERS = 2000
MAX_ORDER = 200.0


def parse_orders(text: str, option: str = "--orders") -> np.ndarray:
    """Orders from ``text``: ``0.5:8:0.5`` (start:stop:step, inclusive), a list
    ``1,0.5,1.41421356``, or a mix; ``option`` names errors."""
    values = []
    for part in str(text).split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if ":" in part:
                a, b, c = (float(x) for x in part.split(":"))
                if not (math.isfinite(a + b + c) and c > 0 and b >= a):
                    raise ValueError
                n = (b - a) / c + 1
                if not n <= MAX_ORDERS - len(values):
                    raise InputError(f"{part!r} asks for {n:.3g} orders; at most "
                                     f"{MAX_ORDERS}", key=option)
                values.extend(a + c * np.arange(int(math.floor(n - 1 + 1e-9)) + 1))
            else:
                values.append(float(part))
        except InputError:
            raise
        except ValueError:
            raise InputError(f"cannot read orders {part!r} (use 0.5:8:0.5 or 1,2,4)", key=option) from None
    arr = np.unique(np.round(np.array(values, float), 12))
    if arr.size == 0 or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError("orders must be finite and > 0", key=option)
    if arr.size > MAX_ORDERS or arr[-1] > MAX_ORDER:
        raise InputError(f"{arr.size} orders up to {arr[-1]:g}; at most {MAX_ORDERS} orders "
                         f"up to order {MAX_ORDER:g}", key=option)
    return arr


def block_revolutions(orders) -> int:
    """Block length [rev]: at least 4 Hann bins between neighbouring ``orders`` and from 0."""
    o = np.sort(np.asarray(orders, float))
    spacing = min(o[0], np.min(np.diff(o)) if o.size > 1 else o[0])
    return int(min(MAX_BLOCK_REVS, max(MIN_BLOCK_REVS, math.ceil(4.0 / spacing - 1e-9))))


def samples_per_rev(orders) -> int:
    """Angle samples per revolution: power of two >= SAMPLES_PER_ORDER * max(``orders``)."""
    need = max(16.0, SAMPLES_PER_ORDER * float(np.max(orders)))
    return int(2 ** math.ceil(math.log2(need)))


def kernel_table(K, beta, n_tab=16385):
    """Kaiser-windowed (``beta``) sinc with ``K`` zero crossings per side, ``n_tab`` points on
    v = -1 ... 1."""
    v = np.linspace(-1.0, 1.0, n_tab)
    return np.sinc(K * v) * np.kaiser(n_tab, beta)


def speed_grid(profile, rpm_step, block_revs, *, margin_s=0.0, file=None, key="rpm"):
    """Grid speeds [rpm], multiples of ``rpm_step``, that ``profile`` passes with a block of
    ``block_revs`` [rev] and ``margin_s`` [s] (or ``(start, end)``) inside the measured range;
    ``file``, ``key`` name errors.

    Returns
    -------
    rpm : ndarray (k,)
        Grid speeds (multiples of ``rpm_step``).
    centre : ndarray (k,)
        Crank angle at which the speed passes each [rad].
    """
    i0, i1 = profile.valid
    t, n, th = profile.time[i0:i1 + 1], profile.rpm[i0:i1 + 1], profile.angle[i0:i1 + 1]
    if not (math.isfinite(rpm_step) and rpm_step > 0):
        raise InputError("must be > 0 [rpm]", key="--rpm-step")
    n_grid = (n.max() - n.min()) / rpm_step
    if not n_grid <= MAX_GRID_SPEEDS:
        raise InputError(f"{n_grid:.3g} grid speeds over {n.min():.0f}..{n.max():.0f} rpm; "
                         f"at most {MAX_GRID_SPEEDS} (choose a larger step)", key="--rpm-step")
    m0, m1 = np.broadcast_to(np.asarray(margin_s, float), (2,))
    lo_ok = np.interp(th[0] + np.pi * block_revs, th, t) + m0
    hi_ok = np.interp(th[-1] - np.pi * block_revs, th, t) - m1
    grid = rpm_step * np.arange(math.ceil(n.min() / rpm_step), math.floor(n.max() / rpm_step) + 1)
    if grid.size == 0:
        raise InputError(f"no multiple of {rpm_step:g} rpm between the record's speeds "
                         f"{n.min():.0f}..{n.max():.0f} rpm (a smaller step)", file=file, key="--rpm-step")
    tc, thc = first_passing(t, n, grid, th)
    keep = (tc >= lo_ok) & (tc <= hi_ok)
    rpm, centre = list(grid[keep]), thc[keep]
    if not rpm:
        raise InputError(f"speed never passes a multiple of {rpm_step:g} rpm with "
                         f"{block_revs / 2:g} revolutions (+ {max(m0, m1):.3g} s) of data either "
                         "side (speed "
                         f"{n.min():.0f}..{n.max():.0f} rpm over {t[-1] - t[0]:.3g} s)", file=file, key=key)
    return np.array(rpm, float), np.array(centre, float)


def first_passing(t, rpm, targets, *others):
    """Time [s] at which ``rpm`` over ``t`` first reaches each of ``targets`` [rpm] (and
    ``others`` interpolated there); NaN where it never does. Bisection in the running
    maximum (from below) or minimum (from above)."""
    t, rpm, targets = np.asarray(t, float), np.asarray(rpm, float), np.asarray(targets, float)
    up = np.searchsorted(np.maximum.accumulate(rpm), targets, side="left")
    down = np.searchsorted(-np.minimum.accumulate(rpm), -targets, side="left")
    idx = np.where(rpm[0] < targets, up, down)
    found = idx < rpm.size
    i1 = np.clip(idx, 1, rpm.size - 1)
    i0 = i1 - 1
    d0, d1 = rpm[i0] - targets, rpm[i1] - targets
    f = np.where(d0 != d1, d0 / np.where(d0 != d1, d0 - d1, 1.0), 0.0)
    f = np.where(idx == 0, 0.0, np.clip(f, 0.0, 1.0))
    out = [np.where(found, t[i0] + f * (t[i1] - t[i0]), np.nan)]
    for arr in others:
        arr = np.asarray(arr, float)
        out.append(np.where(found, arr[i0] + f * (arr[i1] - arr[i0]), np.nan))
    return out[0] if not others else tuple(out)


def cot_amplitudes(X, profile, orders, rpm_centre, angle_centre, block_revs=None):
    """Complex order amplitudes per grid speed by computed order tracking.

    Parameters
    ----------
    X : ndarray (n_ch, n)
        Channels [SI], uniformly sampled at ``profile.time``.
    profile : SpeedProfile
    orders : ndarray (n_o,)
    rpm_centre, angle_centre : ndarray (k,)
        From :func:`speed_grid`.
    block_revs : int, optional
        Block length [rev] (default :func:`block_revolutions`).

    Returns
    -------
    ndarray complex (k, n_ch, n_o)
        Peak complex amplitudes [SI], phase relative to crank angle 0.
    """
    X, orders = np.ascontiguousarray(X, float), np.asarray(orders, float)
    B, S = block_revs or block_revolutions(orders), samples_per_rev(orders)
    N = B * S
    fs = (profile.time.size - 1) / (profile.time[-1] - profile.time[0])
    j = np.arange(N)
    theta = angle_centre[:, None] + (j[None, :] - N / 2) * (2 * np.pi / S)
    idx = np.arange(profile.time.size, dtype=float)
    pos = np.interp(theta.ravel(), profile.angle, idx)
    rpm_at = np.interp(pos, idx, profile.rpm)
    cutoff = np.minimum(1.0, ANTI_ALIAS_FRACTION * S * rpm_at / 60.0 / fs)
    out = np.empty((X.shape[0], pos.size))
    sinc_resample_kernel(X, pos, cutoff, kernel_table(KERNEL_ZERO_CROSSINGS, KERNEL_BETA),
                         float(KERNEL_ZERO_CROSSINGS), out)
    w = 0.5 - 0.5 * np.cos(2 * np.pi * j / N)
    E = (w[:, None] * np.exp(-1j * np.outer((j - N / 2) * (2 * np.pi / S), orders)))
    E *= 2.0 / w.sum()
    spec = out.reshape(X.shape[0], len(rpm_centre), N) @ E              # (n_ch, k, n_o)
    spec *= np.exp(-1j * np.outer(angle_centre, orders))[None]
    return np.transpose(spec, (1, 0, 2))
