"""``powertrain runup``: the main job — a run-up on the default (or given) engine."""

from __future__ import annotations

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    speed_options,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.iotools.raw import write_raw
from powertrain.workflows import runup as workflow
from powertrain.workflows.arguments import speed_steps
from powertrain.workflows.runup import check_path_plot


@main.command()
@speed_options
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@click.option("--solver", type=click.Choice(["newmark", "harmonic"]), default="newmark", show_default=True,
              help="newmark: time integration, 6 cycles, last 2 processed; harmonic: "
                   "frequency-domain steady state order by order.")
@click.option("--stepper", type=click.Choice(["auto", "modal", "dense"]), default="auto", show_default=True,
              help="Newmark implementation: modal (diagonalised recurrence), dense "
                   "(physical coordinates); auto = modal when the mass matrix is regular.")
@click.option("--angle-step", type=float, default=1.0, show_default=True,
              help="Crank-angle increment of the Newmark stepper [deg].")
@click.option("--out", type=click.Path(dir_okay=False),
              help="Write the HDF5 result file (e.g. runup.h5); nothing is written unless "
                   "--out, --csv or --plot is given.")
@click.option("--csv", "csv_file", type=click.Path(dir_okay=False),
              help="Write the long-format CSV (columns mount, direction, quantity, rpm, "
                   "velocity_rms_mm_per_s).")
@click.option("--plot", type=click.Path(dir_okay=False), help="Thesis figure set (Figs 45-71) as PNG.")
@click.option("--path-plot", type=click.Path(dir_okay=False),
              help="Path contributions at the body points of a modal or measured chassis "
                   "(PNG), at --path-order.")
@click.option("--path-order", type=float, default=2.0, show_default=True,
              help="Engine order of the path-contribution plot.")
@click.option("--no-balancers", is_flag=True, help="Switch the balancer shafts off.")
@click.option("--effect", multiple=True, metavar="NAME[:PARAM=VALUE,...]",
              help="Add an unmodelled effect of the diagnosis library (as in `whatif`), e.g. "
                   "base_compliance:c_base=400N/mm,m_base=8kg. Repeatable.")
@click.option("--sweep", type=float, metavar="RPM_PER_S",
              help="Continuous run-up at this rate [rpm/s] (time integration of one speed "
                   "ramp) instead of steady states; tracked like measured data.")
@click.option("--raw", "raw_file", type=click.Path(dir_okay=False),
              help="With --sweep: write the raw mount-point accelerations (format of the "
                   "suffix: .csv, .uff, .mf4, else raw HDF5).")
@click.option("--sample-rate", type=float, default=8192.0, show_default=True,
              help="With --sweep: sampling rate of the raw data [Hz].")
@quiet_option
def runup(rpm_from, rpm_to, rpm_step, engine_file, solver, stepper, angle_step, out, csv_file,
          plot, path_plot, path_order, no_balancers, effect, sweep, raw_file, sample_rate, quiet):
    """Run-up: steady-state mount-point velocities at each speed, order analysed.

    Prints the rigid-body modes (undamped, at the mounts' static stiffness; 'powertrain modes'
    gives the damped ones at dynamic stiffness) and the synthesis (RMS sum of orders 0.5..8)
    velocity of the channels (every mount × engine X/Y/Z) per speed; writes HDF5, CSV and PNG
    only on request (--out, --csv, --plot) and names the files written.

    \b
    Examples:
      powertrain runup --from 1000 --to 6000 --step 500
      powertrain runup --out runup.h5 --no-balancers
      powertrain runup --solver harmonic --csv runup.csv --plot runup.png
      powertrain runup --effect amplitude_stiffness:exponent=0.2
      powertrain runup --engine engines/default-modal-body.toml --path-plot paths.png
      powertrain runup --from 2000 --to 3000 --sweep 200 --raw sweep.h5 --csv sweep.csv
    """
    rpm = speed_steps(rpm_from, rpm_to, rpm_step)
    check_outputs(out=out, csv=csv_file, plot=plot, path_plot=path_plot, raw=raw_file)
    engine = engine_or_default(engine_file)
    _check_options(engine, path_order if path_plot else None, raw_file, sweep)
    result = workflow.runup(
        engine, rpm if sweep is None else [rpm_from, rpm_to], solver=solver, stepper=stepper,
        angle_step_deg=angle_step, balancers=not no_balancers, effects=effect, sweep=sweep,
        sample_rate=sample_rate, progress=not quiet)
    files = dict(out=out, csv=csv_file, plot=plot, path_plot=path_plot, raw=raw_file)
    written = (_write_runup(result, files, engine_description(
        engine, engine.file, effects=effect, no_balancers=no_balancers), path_order)
        if sweep is None else _write_sweep(result, files, engine_description(
            engine, engine.file) + f", sweep {sweep:g} rpm/s"))
    if not quiet:
        click.echo(result.to_text())
        click.echo(_files_line(result, written, sweep))


def _check_options(engine, path_order, raw_file, sweep) -> None:
    """The path plot's body points and order (None: no path plot); --raw with --sweep."""
    if path_order is not None:
        check_path_plot(engine, path_order)
    if raw_file and sweep is None:
        raise InputError("--raw needs --sweep RPM_PER_S", key="--sweep")


def _write_runup(result, files, engine, path_order) -> list:
    """The stepped run-up's HDF5, CSV (SYNTHETIC with effects), figure and path figure."""
    prov = cli_provenance(engine)
    if files["out"]:
        result.to_hdf5(files["out"])
    if files["csv"]:
        result.to_csv(files["csv"], result.synthetic_comments(prov))
    plots = {}
    if files["plot"]:
        plots["plot"] = write_plot(lambda p: result.plot(path=p, provenance=prov), files["plot"])
    if files["path_plot"]:
        write_plot(lambda p: result.plot_paths(path=p, order=path_order, provenance=prov), files["path_plot"])
    return [f for k in ("out", "csv", "plot", "path_plot") if files[k] for f in plots.get(k, [files[k]])]


def _write_sweep(result, files, engine) -> list:
    """The continuous run-up's raw HDF5 and tracked HDF5, CSV and figure."""
    prov = cli_provenance(engine)
    if files["raw"]:
        write_raw(files["raw"], result.recording)
    if files["csv"]:
        result.to_csv(files["csv"])
    if files["out"]:
        result.to_hdf5(files["out"])
    if files["plot"]:
        write_plot(lambda p: result.plot(path=p, provenance=prov), files["plot"])
    return [files[k] for k in ("raw", "out", "csv", "plot") if files[k]]


def _files_line(result, written, sweep) -> str:
    """The solver time and the files written (a sweep: the files)."""
    if sweep is not None:
        return wrote(*written)
    return (f"solver time: {result.solver_seconds:.3f} s; "
            + (wrote(*written) if written else "no file written (ask with --out, --csv or --plot)"))
