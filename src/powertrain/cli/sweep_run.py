"""``powertrain runup --sweep``: continuous run-up, raw data out, tracked like a measurement."""

from __future__ import annotations

import click

#: Speed grid of the tracked curves [rpm] (the ``track`` default).
TRACK_RPM_STEP = 50.0


def run_sweep(engine, rpm_from, rpm_to, rate, sample_rate, raw_file, out, csv_file, plot,
              effect, quiet):
    """Simulate the sweep, write the raw HDF5, track it (COT, orders 0.5..8, as velocity)."""
    from powertrain.errors import InputError
    from powertrain.iotools.raw_hdf5 import write_raw_hdf5
    from powertrain.solvers.speed_ramp import simulate_sweep
    from powertrain.workflows.tracking import track_recording
    if rate is None:
        raise InputError("--raw needs --sweep RPM_PER_S", key="--sweep")
    if effect:
        raise InputError("effects are not simulated in a sweep (use stepped run-ups)",
                         key="--effect")
    from powertrain.cli.common import check_outputs
    check_outputs(raw=raw_file)
    rec = simulate_sweep(engine, rpm_from, rpm_to, rate, sample_rate, progress=not quiet)
    tracked = track_recording(rec, rpm_step=TRACK_RPM_STEP, progress=not quiet).as_velocity()
    if raw_file:
        write_raw_hdf5(raw_file, rec, description=rec.comments[0], synthetic=True)
    if csv_file:
        tracked.to_csv(csv_file)
    if out:
        tracked.to_hdf5(out)
    if plot:
        from powertrain.cli.common import cli_provenance, engine_description, write_plot
        prov = cli_provenance(engine_description(engine, engine.file)
                              + f", sweep {rate:g} rpm/s")
        write_plot(lambda p: tracked.plot(path=p, provenance=prov), plot)
    if quiet:
        return
    from powertrain.cli.common import format_table
    syn = tracked.synthesis_rms() * 1e3
    click.echo(rec.comments[0])
    click.echo("tracked synthesis RMS velocity (orders 0.5-8) [mm/s]:")
    labels = [f"{c.mount}.{c.direction}" for c in tracked.channels]
    step = max(1, len(tracked.rpm) // 12)
    rows = [[f"{r:g}"] + [float(v) for v in syn[i]]
            for i, r in list(enumerate(tracked.rpm))[::step]]
    click.echo(format_table(["rpm"] + labels, rows, "{:.3f}"))
    click.echo("wrote " + ", ".join(p for p in (raw_file, out, csv_file, plot) if p))
