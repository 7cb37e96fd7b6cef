"""``powertrain track``: order tracking of raw run-up time data (measured or simulated)."""

from __future__ import annotations

import click

from powertrain.cli import main


@main.command()
@click.argument("raw", type=click.Path(dir_okay=False))
@click.option("--channels", "map_file", type=click.Path(dir_okay=False),
              help="Channel map TOML: file channel name -> mount, side, direction, quantity.")
@click.option("--rpm", "rpm_column", metavar="COLUMN",
              help="Speed channel [rpm] (default: the channel named 'rpm').")
@click.option("--tacho", "tacho_column", metavar="COLUMN",
              help="Tacho pulse channel (needs --pulses-per-rev).")
@click.option("--pulses-per-rev", type=int, help="Tacho pulses per revolution.")
@click.option("--orders", "orders_spec", default="0.5:8:0.5", show_default=True,
              metavar="SPEC", help="Orders: start:stop:step and/or a list, e.g. 1,2,4.5.")
@click.option("--rpm-step", type=float, default=50.0, show_default=True,
              help="Speed grid of the order curves [rpm].")
@click.option("--method", type=click.Choice(["cot", "vkf"]), default="cot", show_default=True,
              help="cot: computed order tracking (angle resampling, block spectra); vkf: "
                   "Vold-Kalman order filter (crossing orders, fast sweeps).")
@click.option("--bandwidth", type=float,
              help="Vold-Kalman -3 dB half-bandwidth [Hz] (default: per order and speed, "
                   "1.5 x sqrt(order sweep rate [Hz/s]), at most a quarter of the order "
                   "spacing; 0.5 rejects a crossing fixed tone but flattens fast resonances).")
@click.option("--quantity", type=click.Choice(["acceleration", "velocity", "displacement",
                                                "force"]),
              help="Track only channels of this quantity.")
@click.option("--as", "as_quantity", type=click.Choice(["velocity"]),
              help="Convert order by order to velocity (divide by j*omega of the order).")
@click.option("--csv", "csv_file", type=click.Path(dir_okay=False),
              help="Long-format CSV for compare/diagnose.")
@click.option("--out", type=click.Path(dir_okay=False), help="HDF5 with complex amplitudes.")
@click.option("--plot", type=click.Path(dir_okay=False), help="PNG of the order curves.")
@click.option("--map", "map_png", type=click.Path(dir_okay=False),
              help="PNG: rpm-order (Campbell) and rpm-frequency maps of one channel.")
@click.option("--map-channel", metavar="NAME",
              help="Channel of --map: its name in the file or its MOUNT[.SIDE].DIRECTION "
                   "label (default: the first channel).")
@click.option("--overall", is_flag=True,
              help="Also the overall level of the raw signal per speed (RMS in a band, over "
                   "the block of each speed): 'overall' rows in --csv, /overall_rms in --out.")
@click.option("--overall-band", metavar="LO:HI",
              help="Band of --overall [Hz] (default: half the lowest order's frequency at the "
                   "lowest speed to 0.4 x the sampling rate).")
@click.option("--spectrum-at", "spectrum_at", type=float, multiple=True, metavar="RPM",
              help="Order spectrum (RMS against order, steps of 1/16 order, up to 1.25 x the "
                   "highest --orders) at this speed; repeatable. Needs --spectrum-out.")
@click.option("--spectrum-out", type=click.Path(dir_okay=False),
              help="CSV of the order spectra of --spectrum-at.")
@click.option("--quiet", is_flag=True, help="No progress bar and no table.")
def track(raw, map_file, rpm_column, tacho_column, pulses_per_rev, orders_spec, rpm_step,
          method, bandwidth, quantity, as_quantity, csv_file, out, plot, map_png, map_channel,
          overall, overall_band, spectrum_at, spectrum_out, quiet):
    """Order-track raw run-up time data: speed from an rpm or tacho channel, order RMS
    against rpm per channel.

    RAW: wide CSV (time [s], rpm [1/min], tacho [V], MOUNT[.SIDE].DIRECTION [UNIT] columns),
    raw HDF5, UFF dataset 58 or MDF4 file.

    \b
    Examples:
      powertrain track run.csv --csv tracked.csv --plot orders.png
      powertrain track run.mf4 --channels map.toml --tacho Tacho1 --pulses-per-rev 60
      powertrain track run.h5 --orders 1,2,4 --method vkf --as velocity --csv v.csv
      powertrain track run.csv --overall --spectrum-at 3000 --spectrum-out s.csv --csv t.csv
    """
    from powertrain.analysis.order_tracking import parse_orders
    from powertrain.errors import InputError
    from powertrain.iotools.raw import read_raw
    from powertrain.workflows.tracking import track_recording

    if rpm_column and tacho_column:
        raise click.UsageError("give --rpm or --tacho, not both")
    if tacho_column and pulses_per_rev is None:
        raise InputError("--tacho needs --pulses-per-rev N", key="--pulses-per-rev")
    from powertrain.analysis.speed import MAX_PULSES_PER_REV
    if pulses_per_rev is not None and not 1 <= pulses_per_rev <= MAX_PULSES_PER_REV:
        raise InputError(f"must be 1..{MAX_PULSES_PER_REV}", key="--pulses-per-rev")
    orders = parse_orders(orders_spec)
    overall_opts = _overall_options(overall, overall_band, as_quantity)
    if bool(spectrum_at) != bool(spectrum_out):
        raise InputError("--spectrum-at RPM and --spectrum-out FILE go together",
                         key="--spectrum-out" if spectrum_at else "--spectrum-at")
    from powertrain.cli.common import check_outputs
    check_outputs(csv=csv_file, out=out, plot=plot, map=map_png, spectrum_out=spectrum_out)
    cmap = None
    if map_file:
        from powertrain.iotools.channel_map import read_channel_map
        cmap = read_channel_map(map_file)
    rec = read_raw(raw, cmap, rpm=rpm_column, tacho=tacho_column)
    use = "tacho" if tacho_column else "rpm" if rpm_column else "auto"
    tracked = track_recording(rec, orders, rpm_step=rpm_step, method=method, use=use,
                              pulses_per_rev=pulses_per_rev, quantity=quantity,
                              bandwidth_hz=bandwidth, overall=overall_opts,
                              progress=not quiet)
    spectra = _spectra(rec, use, pulses_per_rev, spectrum_at, orders, quantity)
    if as_quantity == "velocity":
        tracked = tracked.as_velocity()
        spectra = spectra and spectra.as_velocity()
    if csv_file:
        _ = tracked.quantity                      # mixed quantities: fail before writing
    if spectra:
        _ = spectra.quantity
    if map_channel and not map_png:
        raise InputError("--map-channel needs --map FILE.png", key="--map-channel")
    maps = _maps(rec, use, pulses_per_rev, rpm_step, _map_channel(rec, map_channel),
                 max(orders)) if map_png else None
    if csv_file:
        tracked.to_csv(csv_file)
    if out:
        tracked.to_hdf5(out)
    if spectra:
        from powertrain.outputs import atomic_write
        text = spectra.spectrum_csv_text()
        with atomic_write(spectrum_out) as fh:
            fh.write(text)
    if plot or map_png:
        from powertrain.cli.common import cli_provenance, write_plot
        prov = cli_provenance(f"none (raw time data {raw})")
    if plot:
        write_plot(lambda p: tracked.plot(path=p, provenance=prov), plot)
    if map_png:
        from powertrain.plotting.orders import plot_maps
        write_plot(lambda p: plot_maps(**maps, path=p, provenance=prov), map_png)
    if not quiet:
        _report(rec, tracked, [p for p in (csv_file, out, plot, map_png, spectrum_out) if p])


def _overall_options(overall, overall_band, as_quantity):
    """The ``overall`` argument of track_recording, or None."""
    if not (overall or overall_band):
        return None
    from powertrain.analysis.overall import parse_band
    band = parse_band(overall_band) if overall_band else None
    return {"band": band, "velocity": as_quantity == "velocity"}


def _spectra(rec, use, pulses_per_rev, speeds, orders, quantity):
    """Order spectra at the speeds of --spectrum-at (one TrackedOrders), or None."""
    if not speeds:
        return None
    import numpy as np

    from powertrain.workflows.tracking import SPECTRUM_EXTENT, order_spectrum, speed_profile
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    parts = [order_spectrum(rec, profile, rpm, SPECTRUM_EXTENT * float(np.max(orders)),
                            quantity=quantity) for rpm in speeds]
    size = min(p.orders.size for p in parts)        # the top order is capped by fs / rpm
    first = parts[0]
    amp = np.concatenate([p.amplitude[:, :, :size] for p in parts])
    from dataclasses import replace
    return replace(first, rpm=np.concatenate([p.rpm for p in parts]),
                   orders=first.orders[:size], amplitude=amp)


def _map_channel(rec, name):
    """Index of the --map-channel NAME (file name or MOUNT[.SIDE].DIRECTION label)."""
    if not name:
        return 0
    for i, ch in enumerate(rec.channels):
        if name in (ch.name, ch.label):
            return i
    from powertrain.errors import InputError
    known = ", ".join(ch.label for ch in rec.channels)
    raise InputError(f"no channel {name!r} in the file (channels: {known})",
                     key="--map-channel")


def _maps(rec, use, pulses_per_rev, rpm_step, channel, max_order):
    """Campbell and rpm-frequency maps of one channel (arguments of plot_maps), both
    reaching 25 % above the highest tracked order."""
    import numpy as np
    from scipy.signal import spectrogram

    from powertrain.plotting.orders import DISPLAY, MAP_MARGIN
    from powertrain.workflows.tracking import order_map, speed_profile
    profile = speed_profile(rec, use=use, pulses_per_rev=pulses_per_rev)
    rpm, fine, rms = order_map(rec, profile, channel, rpm_step=rpm_step,
                               max_order=MAP_MARGIN * max_order)
    fs = rec.sample_rate
    nper = min(int(2 ** np.ceil(np.log2(max(64, fs / 2.0)))), rec.time.size)   # ~2 Hz
    f, tt, p = spectrogram(rec.channels[channel].values, fs, nperseg=nper,
                           noverlap=nper * 7 // 8)
    rpm_t = np.interp(tt + rec.time[0], rec.time, profile.rpm)
    ch = rec.channels[channel]
    from pathlib import Path
    return dict(rpm=rpm, orders=fine, order_rms=rms, times=tt, freqs=f, rpm_t=rpm_t, psd=p.T,
                title=f"{ch.label} ({ch.quantity}) of {Path(str(rec.source)).name}",
                unit=DISPLAY[ch.quantity][0], factor=DISPLAY[ch.quantity][1],
                max_order=max_order)


def _report(rec, tracked, written):
    import numpy as np

    from powertrain.cli.common import format_table
    from powertrain.plotting.orders import DISPLAY
    tag = " [SYNTHETIC]" if rec.synthetic else ""
    click.echo(f"raw: {rec.source}{tag}: {len(rec.channels)} channel(s), "
               f"{rec.sample_rate:g} Hz, {rec.time[-1] - rec.time[0]:.3g} s")
    s = tracked.settings
    click.echo(f"speed: {s['speed_source']}; tracked ({tracked.method}) at "
               f"{tracked.rpm.size} speeds {tracked.rpm[0]:g}..{tracked.rpm[-1]:g} rpm "
               f"(step {s['rpm_step']:g}) of the measured {s['measured_rpm'][0]:.0f}.."
               f"{s['measured_rpm'][1]:.0f} rpm")
    if "ends_dropped_s" in s:
        lo, hi = s["bandwidth_hz_range"]
        start, end = s["ends_dropped_s"]
        span = rec.time[-1] - rec.time[0]
        click.echo(f"Vold-Kalman bandwidth {lo:.3g}..{hi:.3g} Hz ({s['bandwidth_rule']}); "
                   f"not reported: the first {start:.3g} s and the last {end:.3g} s "
                   f"({100 * (start + end) / span:.1f} % of the record, filter end transient)")
    rows = []
    rms = tracked.order_rms()
    syn = tracked.synthesis_rms()
    for c, ch in enumerate(tracked.channels):
        unit, f = DISPLAY[ch.quantity]
        label = ch.mount + ("" if ch.side == "active" else f".{ch.side}") + f".{ch.direction}"
        for k, o in enumerate(tracked.orders):
            v = rms[:, c, k] * f
            rows.append([label, ch.quantity, f"{o:.6g}", float(np.median(v)),
                         float(v.min()), float(v.max()), unit])
        v = syn[:, c] * f
        rows.append([label, ch.quantity, "synthesis", float(np.median(v)), float(v.min()),
                     float(v.max()), unit])
        if tracked.overall is not None:
            v = tracked.overall[:, c] * f
            rows.append([label, ch.quantity, "overall", float(np.median(v)),
                         float(v.min()), float(v.max()), unit])
    click.echo("tracked RMS over the speed grid:")
    click.echo(format_table(["channel", "quantity", "order", "median", "min", "max", "unit"],
                            rows, "{:.6g}"))
    if written:
        click.echo("wrote " + ", ".join(written))
