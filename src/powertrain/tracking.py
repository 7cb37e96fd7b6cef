"""The tracking orchestrator: raw recording -> speed profile -> order curves.

``powertrain track`` and the continuous run-up simulation (``runup --sweep``) both call
:func:`track_recording`, so a measured sweep and a simulated one pass through the same
analysis.
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis import order_tracking as cot
from powertrain.analysis.orders import ORDERS
from powertrain.analysis.speed import speed_from_rpm, speed_from_tacho
from powertrain.errors import InputError
from powertrain.tracked import TrackedChannel, TrackedOrders

#: Highest tracked frequency allowed, as a fraction of the sampling rate (Nyquist 0.5).
MAX_FREQUENCY_FRACTION = 0.4
#: Grid speeds per COT call (progress granularity).
CHUNK = 16


def speed_profile(rec, *, use="auto", pulses_per_rev=None, smooth_s=0.1):
    """Speed profile of a recording from its rpm channel or tacho (``use``: auto/rpm/tacho)."""
    if use == "auto":
        use = "rpm" if rec.rpm is not None else "tacho" if rec.tacho is not None else None
    if use is None:
        raise InputError("no speed: the file has neither an rpm nor a tacho channel (name "
                         "them 'rpm [1/min]' / 'tacho [V]', or give --rpm/--tacho)",
                         file=rec.source, key="rpm")
    if use == "rpm":
        if rec.rpm is None:
            raise InputError("no rpm channel", file=rec.source, key="rpm")
        return speed_from_rpm(rec.time, rec.rpm, smooth_s=smooth_s, file=rec.source)
    if rec.tacho is None:
        raise InputError("no tacho channel", file=rec.source, key="tacho")
    if pulses_per_rev is None:
        raise InputError("a tacho needs --pulses-per-rev N", file=rec.source, key="tacho")
    return speed_from_tacho(rec.time, rec.tacho, pulses_per_rev, smooth_s=smooth_s,
                            file=rec.source)


def track_recording(rec, orders=None, *, rpm_step=50.0, method="cot", use="auto",
                    pulses_per_rev=None, quantity=None, bandwidth_hz=None, block_revs=None,
                    progress=False) -> TrackedOrders:
    """Order-track every channel of a recording.

    Parameters
    ----------
    rec : RawRecording
    orders : array_like, optional
        Orders (default 0.5 ... 8 step 0.5).
    rpm_step : float
        Output speed grid [rpm].
    method : {"cot", "vkf"}
    use : {"auto", "rpm", "tacho"}
        Speed source.
    pulses_per_rev : int, optional
        Tacho pulses per revolution.
    quantity : str, optional
        Track only channels of this quantity.
    bandwidth_hz : float, optional
        Vold–Kalman -3 dB half-bandwidth [Hz].
    block_revs : int, optional
        COT block length [rev].
    progress : bool
        tqdm bar on stderr (hidden when stderr is not a terminal).

    Returns
    -------
    TrackedOrders
    """
    orders = np.asarray(ORDERS if orders is None else orders, float)
    if method not in ("cot", "vkf"):
        raise InputError(f"unknown method {method!r} (cot or vkf)", key="--method")
    chans = [c for c in rec.channels if quantity is None or c.quantity == quantity]
    if not chans:
        raise InputError(f"no {quantity} channel", file=rec.source, key="--quantity")
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    B = int(block_revs or cot.block_revolutions(orders))
    S = cot.samples_per_rev(orders)
    i0, i1 = profile.valid
    n_min = float(np.min(profile.rpm[i0:i1 + 1]))
    margin = cot.KERNEL_ZERO_CROSSINGS / (cot.ANTI_ALIAS_FRACTION * S * n_min / 60.0)
    if method == "vkf":
        from powertrain.analysis.vold_kalman import (
            DEFAULT_BANDWIDTH_HZ,
            EDGE_TIME_CONSTANTS,
            check_bandwidth,
        )
        bandwidth_hz = float(DEFAULT_BANDWIDTH_HZ if bandwidth_hz is None else bandwidth_hz)
        check_bandwidth(bandwidth_hz, rec.time[-1] - rec.time[0], rec.sample_rate)
        margin = max(margin, EDGE_TIME_CONSTANTS / bandwidth_hz)
    rpm, centre = cot.speed_grid(profile, rpm_step, B, margin_s=margin, file=rec.source,
                                 key=profile.source)
    fs = rec.sample_rate
    f_top = orders.max() * rpm.max() / 60.0
    if f_top > MAX_FREQUENCY_FRACTION * fs:
        raise InputError(f"order {orders.max():g} at {rpm.max():g} rpm is {f_top:.0f} Hz, "
                         f"above {MAX_FREQUENCY_FRACTION:g} x the sampling rate {fs:g} Hz",
                         file=rec.source, key="--orders")
    X = rec.channel_matrix(chans)
    if method == "cot":
        amp = np.empty((rpm.size, X.shape[0], orders.size), complex)
        steps = range(0, rpm.size, CHUNK)
        if progress:
            from tqdm import tqdm
            steps = tqdm(steps, desc="order tracking", unit="block", leave=False,
                         disable=None, total=len(steps))
        for s in steps:
            amp[s:s + CHUNK] = cot.cot_amplitudes(X, profile, orders, rpm[s:s + CHUNK],
                                                  centre[s:s + CHUNK], B)
        settings = {"block_revolutions": B, "samples_per_revolution": S,
                    "window": "hann", "kernel": f"Kaiser-windowed sinc, "
                    f"{cot.KERNEL_ZERO_CROSSINGS} zero crossings, beta {cot.KERNEL_BETA:g}"}
    else:
        from powertrain.analysis.vold_kalman import vkf_amplitudes
        amp = vkf_amplitudes(X, profile, orders, rpm, bandwidth_hz=bandwidth_hz,
                             progress=progress)
        settings = {"bandwidth_hz": bandwidth_hz, "structural_equation": "two-pole"}
    settings.update({"rpm_step": float(rpm_step), "speed_source": profile.source,
                     "speed_notes": profile.notes, "sample_rate_hz": fs})
    tracked = [TrackedChannel(c.name, c.mount, c.side, c.direction, c.quantity) for c in chans]
    return TrackedOrders(rpm, orders, tracked, amp, method, rec.source, settings,
                         list(rec.comments))


def order_map(rec, profile, channel=0, *, rpm_step=50.0, max_order=None, resolution=None):
    """Campbell (rpm-order) map of one channel: RMS over a fine order grid per speed.

    Returns
    -------
    rpm : ndarray (k,), orders : ndarray (m,), rms : ndarray (k, m) [SI]
    """
    top = float(max_order or 10.0)
    B = cot.MIN_BLOCK_REVS * 2
    fine = np.arange(1, int(top * B) + 1) / B
    S = cot.samples_per_rev(fine)
    i0, i1 = profile.valid
    n_min = float(np.min(profile.rpm[i0:i1 + 1]))
    margin = cot.KERNEL_ZERO_CROSSINGS / (cot.ANTI_ALIAS_FRACTION * S * n_min / 60.0)
    rpm, centre = cot.speed_grid(profile, rpm_step, B, margin_s=margin, file=rec.source)
    X = rec.channels[channel].values[None, :]
    amp = cot.cot_amplitudes(X, profile, fine, rpm, centre, B)[:, 0, :]
    return rpm, fine, np.abs(amp) / np.sqrt(2.0)
