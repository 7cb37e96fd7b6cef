"""``powertrain track``: order tracking of raw run-up time data (measured or simulated)."""

from __future__ import annotations

import click

from powertrain.cli.common import check_outputs, cli_provenance, quiet_option, write_plot
from powertrain.cli.group import main
from powertrain.errors import InputError
from powertrain.workflows.tracking import track as run_track


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
@click.option("--quantity", type=click.Choice(["acceleration", "velocity", "displacement", "force"]),
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
@click.option("--tdc-offset", type=float, metavar="DEG",
              help="Measure the order phases: crank angle of cylinder-1 firing TDC after the "
                   "tacho's reference pulse [deg] (0..360; 0..720 with --cycle-reference). "
                   "Needs a tacho with one pulse per revolution or a missing-tooth gap.")
@click.option("--cycle-reference", metavar="COLUMN",
              help="Once-per-cycle pulse channel (cam or injection): fixes the 720° cycle, "
                   "so half orders get a phase too; the offset then counts from the first "
                   "tacho reference pulse after its edge.")
@quiet_option
def track(raw, map_file, rpm_column, tacho_column, pulses_per_rev, orders_spec, rpm_step,
          method, bandwidth, quantity, as_quantity, csv_file, out, plot, map_png, map_channel,
          overall, overall_band, spectrum_at, spectrum_out, tdc_offset, cycle_reference, quiet):
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
      powertrain track run.csv --pulses-per-rev 1 --tdc-offset 42 --cycle-reference cam
    """
    if rpm_column and tacho_column:
        raise click.UsageError("give --rpm or --tacho, not both")
    if bool(spectrum_at) != bool(spectrum_out):
        raise InputError("--spectrum-at RPM and --spectrum-out FILE go together",
                         key="--spectrum-out" if spectrum_at else "--spectrum-at")
    check_outputs(csv=csv_file, out=out, plot=plot, map=map_png, spectrum_out=spectrum_out)
    tracked = run_track(raw, orders=orders_spec, rpm_step=rpm_step, method=method,
                        bandwidth=bandwidth, channel_map=map_file, rpm_column=rpm_column,
                        tacho_column=tacho_column, pulses_per_rev=pulses_per_rev,
                        quantity=quantity, as_quantity=as_quantity, overall=overall,
                        overall_band=overall_band, spectrum_at=spectrum_at,
                        map_channel=map_channel, maps=bool(map_png), tdc_offset=tdc_offset,
                        cycle_reference=cycle_reference, progress=not quiet)
    _write(tracked, csv_file, out, spectrum_out)
    _figures(tracked, raw, plot, map_png)
    if not quiet:
        click.echo(tracked.to_text((csv_file, out, plot, map_png, spectrum_out)))


def _write(tracked, csv_file, out, spectrum_out) -> None:
    """The order curves (CSV, HDF5) and the order spectra, if asked for."""
    if csv_file:
        tracked.to_csv(csv_file)
    if out:
        tracked.to_hdf5(out)
    if spectrum_out:
        tracked.write_spectra(spectrum_out)


def _figures(tracked, raw, plot, map_png) -> None:
    """The order curves and the maps, if asked for."""
    prov = cli_provenance(f"none (raw time data {raw})")
    if plot:
        write_plot(lambda p: tracked.plot(path=p, provenance=prov), plot)
    if map_png:
        write_plot(lambda p: tracked.plot_maps(path=p, provenance=prov), map_png)
