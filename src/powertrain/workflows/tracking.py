"""The tracking orchestrator: raw recording -> speed profile -> order curves.

``powertrain track`` and ``runup --sweep`` both call :func:`track_recording`.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.signal import spectrogram

from powertrain.analysis import order_tracking as cot
from powertrain.analysis import vold_kalman as vk
from powertrain.analysis.orders import ORDERS
from powertrain.analysis.overall import overall_rms, parse_band
from powertrain.analysis.phase import tdc_origin, to_tdc
from powertrain.analysis.speed import MAX_PULSES_PER_REV, speed_from_rpm, speed_from_tacho, tacho_edges
from powertrain.errors import InputError
from powertrain.iotools.raw import read_raw
from powertrain.models.recording import RawRecording
from powertrain.plotting.orders import DISPLAY, MAP_MARGIN
from powertrain.progress import progress_bar
from powertrain.results.tracked import TrackedChannel, TrackedOrders
from powertrain.workflows import arguments as args

#: Highest tracked frequency allowed, as a fraction of the sampling rate (Nyquist 0.5).
MAX_FREQUENCY_FRACTION = 0.4
#: Grid speeds per COT call (progress granularity).
CHUNK = 16
#: Order spectrum block length [rev]: orders in steps of 1/16, no scalloping at half orders.
SPECTRUM_REVS = 16
#: ... up to this multiple of the highest tracked order.
SPECTRUM_EXTENT = 1.25


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
    return speed_from_tacho(rec.time, rec.tacho, pulses_per_rev, smooth_s=smooth_s, file=rec.source)


def track(raw, *, orders=None, rpm_step=50.0, method="cot", bandwidth=None, channel_map=None,
          rpm_column=None, tacho_column=None, pulses_per_rev=None, quantity=None,
          as_quantity=None, overall=False, overall_band=None, spectrum_at=(),
          map_channel=None, maps=False, tdc_offset=None, cycle_reference=None,
          progress=False) -> TrackedOrders:
    """Order-track raw run-up time data (``powertrain track``).

    Parameters
    ----------
    raw : str, Path or RawRecording
        Wide CSV, raw HDF5, UFF 58 or MDF4 file, or a recording.
    orders : str or array_like, optional
        ``start:stop:step`` and/or a list (``"1,2,4.5"``), or numbers (default 0.5..8).
    rpm_step, method, bandwidth, quantity, progress
        See :func:`track_recording` (``bandwidth`` [Hz]).
    channel_map : str, Path or ChannelMap, optional
        File channel name -> mount, side, direction, quantity.
    rpm_column, tacho_column : str, optional
        Speed channel [rpm] or tacho channel (needs ``pulses_per_rev``).
    as_quantity : {"velocity"}, optional
        Convert order by order (spectra and overall level too).
    overall : bool
        Also the overall level per speed, in ``overall_band`` (``"LO:HI"`` or (lo, hi) [Hz]).
    spectrum_at : sequence of float
        Speeds [rpm] of order spectra (:func:`order_spectrum`).
    map_channel : str, optional
        Channel of the maps, name or label (default the first).
    maps : bool
        Campbell and rpm-frequency maps of that channel.
    tdc_offset, cycle_reference : float, str, optional
        Phase reference [deg] (:func:`track_recording`) and the cycle reference channel.

    Returns
    -------
    TrackedOrders
        With ``spectra`` and ``maps`` when asked; ``to_text()`` is the command's report.
    """
    rpm_step, bandwidth, pulses_per_rev, tdc_offset, spectrum_at = _numbers(
        rpm_step, bandwidth, pulses_per_rev, tdc_offset, spectrum_at)
    _check_options(tacho_column, pulses_per_rev, map_channel, maps, tdc_offset, cycle_reference)
    orders = _orders(orders)
    overall_opts = _overall_options(overall, overall_band, as_quantity)
    rec = _recording(raw, channel_map, rpm_column, tacho_column, cycle_reference)
    use = "tacho" if tacho_column else "rpm" if rpm_column else "auto"
    tracked = track_recording(rec, orders, rpm_step=rpm_step, method=method, use=use,
                              pulses_per_rev=pulses_per_rev, quantity=quantity,
                              bandwidth_hz=bandwidth, overall=overall_opts,
                              tdc_offset_deg=tdc_offset, progress=progress)
    spectra = _spectra(rec, use, pulses_per_rev, spectrum_at, tracked.orders, quantity)
    if as_quantity == "velocity":
        tracked = tracked.as_velocity()
        spectra = spectra and spectra.as_velocity()
    if spectra:
        _ = spectra.quantity                      # mixed quantities fail here
    drawn = _maps(rec, use, pulses_per_rev, rpm_step, _map_channel(rec, map_channel),
                  float(np.max(tracked.orders)),
                  (float(np.min(tracked.rpm)), float(np.max(tracked.rpm)))) if maps else None
    return replace(tracked, spectra=spectra, maps=drawn)


def _numbers(rpm_step, bandwidth, pulses_per_rev, tdc_offset, spectrum_at):
    """The numeric options of :func:`track` as numbers (ranges checked later)."""
    return (args.real(rpm_step, "--rpm-step", unit="rpm"),
            args.real(bandwidth, "--bandwidth", unit="Hz", optional=True),
            args.integer(pulses_per_rev, "--pulses-per-rev", optional=True),
            args.real(tdc_offset, "--tdc-offset", unit="deg", optional=True),
            [args.real(r, "--spectrum-at", unit="rpm") for r in
             ([spectrum_at] if args.is_number(spectrum_at) or isinstance(spectrum_at, str)
              else spectrum_at or ())])


def _orders(orders):
    """``--orders`` as written (``0.5:8:0.5``, ``1,2,4.5``) or numbers, checked (None: default)."""
    if orders is None:
        return None
    if isinstance(orders, str):
        return cot.parse_orders(orders)
    values = args.floats(orders, "--orders", "orders", "0.5:8:0.5 or 1,2,4", cot.MAX_ORDERS)
    return cot.parse_orders(",".join(repr(float(v)) for v in values))


def _check_options(tacho_column, pulses_per_rev, map_channel, maps, tdc_offset, cycle_reference) -> None:
    """Refuse options that need another one, or out of range."""
    if tacho_column and pulses_per_rev is None:
        raise InputError("--tacho needs --pulses-per-rev N", key="--pulses-per-rev")
    if pulses_per_rev is not None and not 1 <= pulses_per_rev <= MAX_PULSES_PER_REV:
        raise InputError(f"must be 1..{MAX_PULSES_PER_REV}", key="--pulses-per-rev")
    if map_channel and not maps:
        raise InputError("--map-channel needs --map FILE.png", key="--map-channel")
    if cycle_reference and tdc_offset is None:
        raise InputError("needs --tdc-offset DEG (where cylinder-1 firing TDC lies)", key="--cycle-reference")


def _recording(raw, channel_map, rpm_column, tacho_column, cycle_reference=None):
    """The recording of ``raw`` (read through ``channel_map`` if a path)."""
    if isinstance(raw, RawRecording):
        return raw
    args.path_or(raw, (), "RAW", "a raw recording or its file")
    return read_raw(raw, channel_map, rpm=rpm_column, tacho=tacho_column, cycle_reference=cycle_reference)


def _overall_options(overall, overall_band, as_quantity):
    """The ``overall`` argument of track_recording, or None."""
    if not (overall or overall_band):
        return None
    band = parse_band(overall_band) if isinstance(overall_band, str) else overall_band
    return {"band": band, "velocity": as_quantity == "velocity"}


def _spectra(rec, use, pulses_per_rev, speeds, orders, quantity):
    """Order spectra at ``speeds`` (one TrackedOrders), or None."""
    if not len(speeds):
        return None
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    parts = [order_spectrum(rec, profile, rpm, SPECTRUM_EXTENT * float(np.max(orders)),
                            quantity=quantity) for rpm in speeds]
    size = min(p.orders.size for p in parts)        # top order capped by fs / rpm
    first = parts[0]
    amp = np.concatenate([p.amplitude[:, :, :size] for p in parts])
    return replace(first, rpm=np.concatenate([p.rpm for p in parts]),
                   orders=first.orders[:size], amplitude=amp)


def _map_channel(rec, name):
    """Index of the map channel ``name`` (file name or MOUNT[.SIDE].DIRECTION label)."""
    if not name:
        return 0
    for i, ch in enumerate(rec.channels):
        if name in (ch.name, ch.label):
            return i
    known = ", ".join(ch.label for ch in rec.channels)
    raise InputError(f"no channel {name!r} in the file (channels: {known})", key="--map-channel")


def _maps(rec, use, pulses_per_rev, rpm_step, channel, max_order, tracked_rpm):
    """Campbell and rpm-frequency maps of one channel (:func:`~powertrain.plotting.orders.
    plot_maps`'s arguments), reaching 25 % above the highest tracked order."""
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    rpm, fine, rms = order_map(rec, profile, channel, rpm_step=rpm_step, max_order=MAP_MARGIN * max_order)
    fs = rec.sample_rate
    nper = min(int(2 ** np.ceil(np.log2(max(64, round(fs / 2.0))))), rec.time.size)  # ~2 Hz
    f, tt, p = spectrogram(rec.channels[channel].values, fs, nperseg=nper, noverlap=nper * 7 // 8)
    rpm_t = np.interp(tt + rec.time[0], rec.time, profile.rpm)
    ch = rec.channels[channel]
    return dict(rpm=rpm, orders=fine, order_rms=rms, times=tt, freqs=f, rpm_t=rpm_t, psd=p.T,
                title=f"{ch.label} ({ch.quantity}) of {Path(str(rec.source)).name}",
                unit=DISPLAY[ch.quantity][0], factor=DISPLAY[ch.quantity][1],
                max_order=max_order, tracked_rpm=tracked_rpm,
                block_revs=cot.MIN_BLOCK_REVS * 2, window_s=nper / fs)


def track_recording(rec, orders=None, *, rpm_step=50.0, method="cot", use="auto",
                    pulses_per_rev=None, quantity=None, bandwidth_hz=None, block_revs=None,
                    overall=None, tdc_offset_deg=None, progress=False) -> TrackedOrders:
    """Order-track every channel of a recording.

    Parameters
    ----------
    rec : RawRecording
        The recording.
    orders : array_like, optional
        Orders (default 0.5 ... 8 step 0.5).
    rpm_step : float
        Output speed grid [rpm].
    method : {"cot", "vkf"}
        Computed order tracking or Vold–Kalman filtering.
    use, pulses_per_rev : {"auto", "rpm", "tacho"}, int
        Speed source; tacho pulses per revolution.
    quantity : str, optional
        Track only channels of this quantity.
    bandwidth_hz : float, optional
        Vold–Kalman -3 dB half-bandwidth [Hz] (default
        :func:`~powertrain.analysis.vold_kalman.default_bandwidth`).
    block_revs : int, optional
        COT block length [rev].
    overall : dict, optional
        Overall level too: ``band`` (lo, hi) [Hz] or None (:func:`overall_band`), ``velocity``.
    tdc_offset_deg : float, optional
        Crank angle of cylinder-1 firing TDC after the tacho reference pulse [deg]: measure
        the phases (:func:`~powertrain.analysis.phase.tdc_origin`).
    progress : bool
        Progress bar on stderr.

    Returns
    -------
    TrackedOrders
        Amplitudes re cylinder-1 firing TDC when ``tdc_offset_deg`` is given.
    """
    orders = np.asarray(ORDERS if orders is None else orders, float)
    if method not in ("cot", "vkf"):
        raise InputError(f"unknown method {method!r} (cot or vkf)", key="--method")
    chans = [c for c in rec.channels if quantity is None or c.quantity == quantity]
    if not chans:
        raise InputError(f"no {quantity} channel", file=rec.source, key="--quantity")
    profile, origin = _profile_and_origin(rec, use, pulses_per_rev, tdc_offset_deg)
    amp, rpm, settings = _track_channels(rec, chans, profile, orders, method, rpm_step,
                                         block_revs if method == "cot" else bandwidth_hz, progress)
    if origin is not None:
        amp = to_tdc(amp, orders, origin[0])
        settings["phase"] = _phase_settings(orders, tdc_offset_deg, origin[1])
    level = None if overall is None else _overall(rec, chans, profile, orders, rpm, settings,
                                                  overall.get("band"), overall.get("velocity"))
    return TrackedOrders(rpm, orders, _tracked(chans), amp, method, rec.source, settings,
                         list(rec.comments), level, recording=_summary(rec))


def _tracked(chans) -> list:
    return [TrackedChannel(c.name, c.mount, c.side, c.direction, c.quantity) for c in chans]


def _track_channels(rec, chans, profile, orders, method, rpm_step, block_or_bandwidth, progress):
    """``(amplitudes, rpm, settings)`` of COT or VKF, with the speed grid and source."""
    track_with = _track_cot if method == "cot" else _track_vkf
    amp, rpm, settings = track_with(rec, chans, profile, orders, rpm_step, block_or_bandwidth, progress)
    i0, i1 = profile.valid
    settings.update({"rpm_step": float(rpm_step), "speed_source": profile.source,
                     "speed_notes": profile.notes, "sample_rate_hz": rec.sample_rate,
                     "measured_rpm": [float(np.min(profile.rpm[i0:i1 + 1])),
                                      float(np.max(profile.rpm[i0:i1 + 1]))]})
    return amp, rpm, settings


def _profile_and_origin(rec, use, pulses_per_rev, tdc_offset_deg):
    """The speed profile (the tacho's when measuring phase) and :func:`_tdc_origin`."""
    if tdc_offset_deg is not None and use == "auto" and rec.tacho is not None:
        use = "tacho"
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    origin = None if tdc_offset_deg is None else _tdc_origin(rec, profile, tdc_offset_deg)
    return profile, origin


def _tdc_origin(rec, profile, tdc_offset_deg):
    """``(origin [rad], per_cycle)`` of :func:`powertrain.analysis.phase.tdc_origin`."""
    edges = None
    if rec.cycle_reference is not None:
        edges = tacho_edges(rec.time, rec.cycle_reference, file=rec.source,
                            key="--cycle-reference", what="cycle reference")
    return tdc_origin(profile, float(tdc_offset_deg), edges, file=rec.source)


def _phase_settings(orders, tdc_offset_deg, per_cycle) -> dict:
    """The phase reference and the orders with a phase (half orders with a cycle reference)."""
    step = 0.5 if per_cycle else 1.0
    defined = [float(o) for o in orders if abs(o / step - round(o / step)) < 1e-9]
    return {"tdc_offset_deg": float(tdc_offset_deg), "cycle_reference": bool(per_cycle), "orders": defined}


def _summary(rec) -> dict:
    """What the report says of a recording."""
    return {"synthetic": bool(rec.synthetic), "n_channels": len(rec.channels),
            "sample_rate_hz": float(rec.sample_rate), "seconds": float(rec.time[-1] - rec.time[0])}


def overall_band(orders, rpm, sample_rate):
    """Default band of the overall level [Hz]: half the lowest order at the lowest speed to
    MAX_FREQUENCY_FRACTION x the sampling rate."""
    return 0.5 * float(np.min(orders)) * float(np.min(rpm)) / 60.0, MAX_FREQUENCY_FRACTION * sample_rate


def _overall(rec, chans, profile, orders, rpm, settings, band, velocity):
    """Overall level per speed and channel (SI RMS; velocity if asked), noted in ``settings``."""
    band = band or overall_band(orders, rpm, rec.sample_rate)
    turn = {"acceleration": -1, "velocity": 0, "displacement": 1}
    if velocity and any(c.quantity not in turn for c in chans):
        raise InputError("a force cannot be converted to velocity", file=rec.source, key="--as")
    derivative = [turn[c.quantity] for c in chans] if velocity else None
    B = int(settings.get("block_revolutions") or cot.block_revolutions(orders))
    level = overall_rms(rec.channel_matrix(chans), profile, rpm, B, band, derivative)
    settings.update({"overall_band_hz": [float(band[0]), float(band[1])], "overall_revolutions": B,
                     "overall_quantity": "velocity" if velocity else "channel"})
    return level


def order_spectrum(rec, profile, rpm, top_order, *, quantity=None) -> TrackedOrders:
    """Order spectrum (RMS at orders k/SPECTRUM_REVS up to ``top_order``, Hann) of every
    channel at one speed, as a one-speed TrackedOrders."""
    if not (np.isfinite(rpm) and rpm > 0):
        raise InputError("must be a speed > 0 [rpm]", key="--spectrum-at")
    chans = [c for c in rec.channels if quantity is None or c.quantity == quantity]
    B = SPECTRUM_REVS
    top = min(float(top_order), MAX_FREQUENCY_FRACTION * rec.sample_rate * 60.0 / rpm)
    fine = np.arange(1, int(np.floor(top * B + 1e-9)) + 1) / B
    S = cot.samples_per_rev(fine)
    i0, i1 = profile.valid
    t, n, th = (a[i0:i1 + 1] for a in (profile.time, profile.rpm, profile.angle))
    _, centre = cot.first_passing(t, n, [float(rpm)], th)
    reach = np.pi * B + 2 * np.pi * cot.KERNEL_ZERO_CROSSINGS / S
    if fine.size == 0 or not (th[0] + reach <= centre[0] <= th[-1] - reach):
        raise InputError(f"speed does not pass {rpm:g} rpm with {B / 2:g} revolutions of data "
                         f"either side (speed {n.min():.0f}..{n.max():.0f} rpm)",
                         file=rec.source, key="--spectrum-at")
    amp = cot.cot_amplitudes(rec.channel_matrix(chans), profile, fine, np.array([rpm]), centre, B)
    return TrackedOrders(np.array([float(rpm)]), fine, _tracked(chans), amp, "cot", rec.source,
                         {"block_revolutions": B, "window": "hann",
                          "order_resolution": 1.0 / B}, list(rec.comments))


def _check_rate(rec, orders, rpm):
    f_top = orders.max() * rpm.max() / 60.0
    fs = rec.sample_rate
    if f_top > MAX_FREQUENCY_FRACTION * fs:
        raise InputError(f"order {orders.max():g} at {rpm.max():g} rpm is {f_top:.0f} Hz, "
                         f"above {MAX_FREQUENCY_FRACTION:g} x the sampling rate {fs:g} Hz",
                         file=rec.source, key="--orders")


def _track_cot(rec, chans, profile, orders, rpm_step, block_revs, progress):
    """Computed order tracking over the speed grid: (amplitudes, rpm, settings)."""
    B = int(block_revs or cot.block_revolutions(orders))
    S = cot.samples_per_rev(orders)
    rpm, centre = cot.speed_grid(profile, rpm_step, B, margin_s=_kernel_margin(profile, S),
                                 file=rec.source, key=profile.source)
    _check_rate(rec, orders, rpm)
    X = rec.channel_matrix(chans)
    amp = np.empty((rpm.size, X.shape[0], orders.size), complex)
    for s in progress_bar(range(0, rpm.size, CHUNK), enabled=progress, desc="order tracking", unit="block"):
        amp[s:s + CHUNK] = cot.cot_amplitudes(X, profile, orders, rpm[s:s + CHUNK], centre[s:s + CHUNK], B)
    return amp, rpm, {"block_revolutions": B, "samples_per_revolution": S, "window": "hann",
                      "kernel": f"Kaiser-windowed sinc, {cot.KERNEL_ZERO_CROSSINGS} zero "
                      f"crossings, beta {cot.KERNEL_BETA:g}"}


def _track_vkf(rec, chans, profile, orders, rpm_step, bandwidth_hz, progress):
    """Vold–Kalman filtering over the speed grid, the record's transient ends dropped:
    (amplitudes, rpm, settings)."""
    if bandwidth_hz is None:
        width = vk.default_bandwidth(profile, orders)
        rule = (f"per order and speed: {vk.SWEEP_FACTOR:g} x sqrt(order sweep rate), at "
                f"least {vk.EDGE_TIME_CONSTANTS:g} / ({vk.EDGE_FRACTION:g} x record length), "
                f"at most order spacing / {vk.SPACING_RATIO:g}")
    else:
        vk.check_bandwidth(float(bandwidth_hz), rec.time[-1] - rec.time[0], rec.sample_rate)
        width = np.full((orders.size, profile.time.size), float(bandwidth_hz))
        rule = "given (--bandwidth)"
    i0, i1 = profile.valid
    ends = [vk.EDGE_TIME_CONSTANTS / float(np.min(width[:, i])) for i in (i0, i1)]
    rpm, _ = cot.speed_grid(profile, rpm_step, 0, margin_s=ends, file=rec.source, key=profile.source)
    _check_rate(rec, orders, rpm)
    amp = vk.vkf_amplitudes(rec.channel_matrix(chans), profile, orders, rpm,
                            bandwidth_hz=width, progress=progress)
    inside = width[:, i0:i1 + 1]
    return amp, rpm, {"bandwidth_hz": float(np.max(inside)),
                      "bandwidth_hz_range": [float(np.min(inside)), float(np.max(inside))],
                      "bandwidth_rule": rule, "ends_dropped_s": ends, "structural_equation": "two-pole"}


def _kernel_margin(profile, samples_per_rev) -> float:
    """Time [s] the resampling kernel reaches beyond a block at the lowest valid speed."""
    i0, i1 = profile.valid
    n_min = float(np.min(profile.rpm[i0:i1 + 1]))
    return cot.KERNEL_ZERO_CROSSINGS / (cot.ANTI_ALIAS_FRACTION * samples_per_rev * n_min / 60.0)


def order_map(rec, profile, channel=0, *, rpm_step=50.0, max_order=None):
    """Campbell map of one channel: ``(rpm (k,), orders (m,), RMS (k, m) [SI])``."""
    top = float(max_order or 10.0)
    B = cot.MIN_BLOCK_REVS * 2
    fine = np.arange(1, int(top * B) + 1) / B
    rpm, centre = cot.speed_grid(profile, rpm_step, B,
                                 margin_s=_kernel_margin(profile, cot.samples_per_rev(fine)), file=rec.source)
    X = rec.channels[channel].values[None, :]
    amp = cot.cot_amplitudes(X, profile, fine, rpm, centre, B)[:, 0, :]
    return rpm, fine, np.abs(amp) / np.sqrt(2.0)
