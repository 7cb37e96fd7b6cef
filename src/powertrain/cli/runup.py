"""``powertrain runup``: the main job — a run-up on the default (or given) engine."""

from __future__ import annotations

import click

from powertrain.cli import main
from powertrain.cli.common import speed_options, speed_steps


@main.command()
@speed_options
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@click.option("--solver", type=click.Choice(["newmark", "harmonic"]), default="newmark",
              show_default=True,
              help="newmark: time integration, 6 cycles, last 2 processed; harmonic: "
                   "frequency-domain steady state order by order.")
@click.option("--stepper", type=click.Choice(["auto", "modal", "dense"]), default="auto",
              show_default=True,
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
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Thesis figure set (Figs 45-71) as PNG.")
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
              help="With --sweep: write the raw mount-point accelerations (raw HDF5 layout).")
@click.option("--sample-rate", type=float, default=8192.0, show_default=True,
              help="With --sweep: sampling rate of the raw data [Hz].")
@click.option("--quiet", is_flag=True, help="No progress bar and no table.")
def runup(rpm_from, rpm_to, rpm_step, engine_file, solver, stepper, angle_step, out, csv_file,
          plot, path_plot, path_order, no_balancers, effect, sweep, raw_file, sample_rate, quiet):
    """Run-up: steady-state mount-point velocities at each speed, order analysed.

    Prints the rigid-body modes (undamped, at the mounts' static stiffness; 'powertrain modes'
    gives the damped ones at dynamic stiffness) and the synthesis (RMS sum of orders 0.5..8)
    velocity of the
    channels (every mount × engine X/Y/Z) per speed; writes HDF5, CSV and PNG only on request
    (--out, --csv, --plot) and names the files written.

    \b
    Examples:
      powertrain runup --from 1000 --to 6000 --step 500
      powertrain runup --out runup.h5 --no-balancers
      powertrain runup --solver harmonic --csv runup.csv --plot runup.png
      powertrain runup --effect amplitude_stiffness:kappa=1,a_c=0.02mm
      powertrain runup --engine engines/default-modal-body.toml --path-plot paths.png
      powertrain runup --from 2000 --to 3000 --sweep 200 --raw sweep.h5 --csv sweep.csv
    """
    from powertrain.cli.common import check_outputs, checked_runup, runup_settings
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.workflows.runup import run_runup

    rpm = speed_steps(rpm_from, rpm_to, rpm_step)
    check_outputs(out=out, csv=csv_file, plot=plot, path_plot=path_plot)
    engine_path = engine_file or DEFAULT_ENGINE_PATH
    engine = read_engine(engine_path)
    engine.require_excitation()
    if path_plot:
        _check_path_plot(engine, path_order)
    modifications = []
    if no_balancers:
        engine = engine.with_balancers(enabled=False)
        modifications.append("balancer shafts switched off (--no-balancers)")
    if sweep is not None or raw_file:
        from powertrain.cli.sweep_run import run_sweep
        return run_sweep(engine, rpm_from, rpm_to, sweep, sample_rate, raw_file, out, csv_file,
                         plot, effect, quiet)
    from powertrain.workflows.variants import effect_scenario, parse_operations
    scenario = effect_scenario(parse_operations({"effect": effect}, engine=engine))
    runup_settings(engine, rpm, angle_step)
    if scenario:
        from powertrain.progress import activity
        from powertrain.workflows.effect_runup import runup_with_effects
        with activity(f"run-up with effects ({solver})", enabled=not quiet):
            result = checked_runup(engine, engine_path, runup_with_effects, rpm, scenario,
                                   solver=solver, angle_step_deg=angle_step, stepper=stepper)
    else:
        result = checked_runup(engine, engine_path, run_runup, rpm, solver=solver,
                               angle_step_deg=angle_step, progress=not quiet,
                               stepper=stepper)
    written = []
    if out:
        from powertrain.provenance import provenance
        prov = provenance(engine, engine_file=engine_path, modifications=modifications,
                          effects=scenario)
        import json
        from pathlib import Path
        mounts = {f"{m.name}.{a}": {"model": mdl.topology.name, "params_si": mdl.params,
                                     "source": mdl.source}
                  for m in engine.mounts for a, mdl in m.directions.items()}
        result.to_hdf5(out, engine_snapshot=Path(engine_path).read_text(encoding="utf-8"),
                       mount_snapshots={"mounts": json.dumps(mounts)}, provenance=prov,
                       description=f"run-up {rpm_from:g}-{rpm_to:g} rpm, {engine.name}")
        written.append(out)
    from powertrain.cli.common import cli_provenance, engine_description, write_plot
    fig_prov = cli_provenance(engine_description(engine, engine_path, no_balancers=no_balancers,
                                                 effects=effect))
    if csv_file:
        result.to_csv(csv_file, _csv_comments(scenario, fig_prov))
        written.append(csv_file)
    if plot:
        write_plot(lambda p: result.plot(path=p, provenance=fig_prov), plot)
        written.append(plot)
    if path_plot:
        write_plot(lambda p: result.plot_paths(path=p, order=path_order, provenance=fig_prov),
                   path_plot)
        written.append(path_plot)
    if quiet:
        return
    _print_table(result, engine, engine_path, solver, scenario)
    click.echo(f"solver time: {result.solver_seconds:.3f} s; "
               + (f"wrote {', '.join(map(str, written))}" if written else
                  "no file written (ask with --out, --csv or --plot)"))


def _check_path_plot(engine, path_order):
    """--path-plot needs body points; --path-order must be an analysed order."""
    import numpy as np

    from powertrain.analysis.orders import ORDERS
    from powertrain.errors import InputError
    if not getattr(engine.chassis, "points", ()):
        raise InputError("needs body points ([chassis.points.NAME] with a modal or frf "
                         "chassis)", file=engine.file, key="--path-plot")
    if not np.any(np.isclose(ORDERS, path_order)):
        raise InputError(f"order {path_order:g} not analysed (0.5 to 8 in steps of 0.5)",
                         key="--path-order")


def _csv_comments(scenario, prov) -> list:
    """``#`` lines of the run-up CSV with added effects (a stand-in for a measurement, as
    `synth` writes): the SYNTHETIC label and the provenance. A plain run-up CSV starts with
    its header, as before."""
    if not scenario:
        return []
    return [f"SYNTHETIC: simulated run-up with added effects {_effects_text(scenario)}; not "
            "measured", f"provenance: {prov.line()}"]


def _effects_text(scenario) -> str:
    """``name(param=value, ...); ...`` of the effects added [SI]."""
    return "; ".join(f"{name}(" + ", ".join(f"{k}={v:g}" for k, v in p.items()) + ")"
                     for name, p in scenario.items())


def _labelled_modes(engine, frequencies_hz) -> str:
    """``5.9 (y), 6.7 (z), ...``: each static-stiffness mode with its dominant coordinate
    (largest kinetic-energy share), from the same eigenproblem as the run-up's
    (:meth:`~powertrain.assembly.AssembledSystem.rigid_body_modes`), matched by frequency."""
    import numpy as np

    from powertrain.assembly import assemble
    from powertrain.solvers.modes import COORDINATES, kinetic_energy_percent
    b = engine.body
    system = assemble(b.mass, b.cg, b.inertia, engine.mounts, getattr(engine, "chassis", None))
    f_sys, shapes = system.rigid_body_modes()
    out = []
    for f in frequencies_hz:
        k = int(np.argmin(np.abs(f_sys - f)))
        dom = COORDINATES[int(np.argmax(kinetic_energy_percent(system.M[:6, :6],
                                                               shapes[:, k])))]
        out.append(f"{f:.1f} ({dom})" if abs(f_sys[k] - f) <= 1e-6 * max(f, 1.0)
                   else f"{f:.1f}")
    return ", ".join(out)


def _print_table(result, engine, engine_path, solver, scenario):
    """Rigid-body modes and the synthesis velocity table."""
    import numpy as np

    from powertrain.cli.common import format_table
    click.echo(f"engine: {engine.name} ({engine_path})")
    click.echo("rigid-body modes, undamped, mounts at their static stiffness [Hz]: "
               f"{_labelled_modes(engine, result.rigid_body_modes_hz)} (damped, at the "
               "mounts' dynamic stiffness: 'powertrain modes')")
    if scenario:
        click.echo("effects: " + _effects_text(result.settings["effects"]))
    syn = result.synthesis_rms("velocity") * 1e3
    header = ["rpm"] + [f"{m}.{d}" for m, d in result.channels]
    rows = [[f"{r:g}"] + [float(v) for v in syn[i]] for i, r in enumerate(result.rpm)]
    click.echo("synthesis RMS velocity (orders 0.5-8) [mm/s]:")
    click.echo(format_table(header, rows, "{:.3f}"))
    if solver == "newmark":
        click.echo(f"periodicity of processed windows: max {100 * np.max(result.periodicity):.2g} %")
