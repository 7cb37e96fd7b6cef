"""``powertrain excitation``: what drives the powertrain at one engine speed."""

from __future__ import annotations

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    say,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.workflows.excitation import excitation as run


@main.command()
@click.option("--rpm", type=float, required=True, help="Engine speed [rpm].")
@click.option("--engine", "engine_file", default=None,
              help="Engine file (TOML) [default: the shipped engines/default.toml].")
@click.option("--load", "load", type=float, default=1.0, show_default=True,
              help="Fraction of the full-load torque [-] (single-zone model).")
@click.option("--no-balancers", is_flag=True, help="Switch the balancer shafts off.")
@click.option("--step", type=float, default=0.5, show_default=True,
              help="Crank-angle step [deg]; must divide 720.")
@click.option("--csv", "csv_path", default=None,
              help="Write one row per crank angle: total load, then per-cylinder columns.")
@click.option("--plot", default=None, help="Write a summary figure (PNG).")
@quiet_option
def excitation(rpm, engine_file, load, no_balancers, step, csv_path, plot, quiet):
    """Cylinder pressures, gas and inertia forces, crank torque and the total load on the
    powertrain over one engine cycle at --rpm, with the load's order spectrum (0.5..8).

    The load is [Fx, Fy, Fz, Mx, My, Mz] on the powertrain about its centre of gravity in
    engine axes (origin at the 3rd main bearing, X rearwards along the crank, Y right, Z up),
    against the crank angle of cylinder 1 (0..720 deg, 0 = firing TDC of cylinder 1).

    \b
    CSV columns (first seven fixed):
      crank_angle_deg, fx_n, fy_n, fz_n, mx_nm, my_nm, mz_nm,
      then per cylinder i: p{i}_bar, gas_force{i}_n, inertia_force{i}_n, torque{i}_nm
      (gas force on the piston, reciprocating inertia force along the cylinder axis,
      crank torque of that cylinder).

    \b
    Examples:
      powertrain excitation --rpm 3000
      powertrain excitation --rpm 3000 --csv out/load-3000.csv --plot out/load-3000.png
      powertrain excitation --rpm 2000 --engine engines/default.toml --no-balancers
    """
    check_outputs(csv=csv_path, plot=plot)
    result = run(engine_file, rpm, load=load, balancers=not no_balancers, angle_step_deg=step)
    if csv_path:
        result.to_csv(csv_path)
    if plot:
        prov = cli_provenance(engine_description(result.engine, result.engine.file,
                                                 no_balancers=no_balancers))
        write_plot(lambda p: result.plot(path=p, provenance=prov), plot)
    say(result.to_text(), quiet)
    if csv_path or plot:
        say(wrote(csv_path, plot), quiet)
