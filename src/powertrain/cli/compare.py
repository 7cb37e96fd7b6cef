"""``powertrain compare``: simulated vs measured run-up, level gaps and correlation metrics."""

from __future__ import annotations

import click

from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, NOISE_FLOOR_MARGIN_DB
from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    say,
    write_json,
    write_plot,
)
from powertrain.cli.group import main
from powertrain.provenance import provenance
from powertrain.workflows.arguments import nonnegative
from powertrain.workflows.comparison import compare as run_compare


@main.command()
@click.argument("measured", type=click.Path(dir_okay=False))
@click.option("--sim", "sim_file", type=click.Path(dir_okay=False),
              help="Simulated run-up to compare (HDF5 from 'powertrain runup --out' or its "
                   "long-format CSV). Default: run the simulation now.")
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file to simulate (default: the shipped engines/default.toml).")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="PNG: measured vs simulated, gap shaded (mount x direction rows; "
                   "one column per quantity: synthesis and every measured order).")
@click.option("--json", "json_file", type=click.Path(dir_okay=False),
              help="JSON with every gap and metric, what was compared and what is missing.")
@click.option("--noise-floor", type=float, default=0.001, show_default=True,
              help="RMS noise floor of the measured order curves [mm/s]; measured points "
                   f"below {NOISE_FLOOR_MARGIN:g}x this (within {NOISE_FLOOR_MARGIN_DB:.1f} dB) "
                   "are excluded and counted; points simulated below it but measured above "
                   "are reported as measured, not modelled.")
@click.option("--solver", type=click.Choice(["newmark", "harmonic"]), default="newmark",
              show_default=True, help="Solver when the simulation is run here.")
@click.option("--step", "rpm_step", type=float, default=None,
              help="Simulate on a grid of this speed step [rpm] covering the measured range "
                   "and interpolate it to the measured speeds. Default: simulate at every "
                   "measured speed (within the engine's range), no interpolation.")
@quiet_option
def compare(measured, sim_file, engine_file, plot, json_file, noise_floor, solver, rpm_step, quiet):
    """Compare a simulated run-up with a measured one.

    For each mount, direction and quantity (synthesis, 2nd, 4th and any other measured
    order): the level gap 20 log10(sim/measured) [dB] at the measured speeds (simulated at
    those speeds; with --step or --sim interpolated linearly in rpm and log level, never
    extrapolated) with its RMS, mean and maximum; FRAC over speed; CSAC and CSF across the
    channels at each speed; an FRFSM-like score (Gaussian kernel, sigma 6 dB). Worst channel
    first. Points measured above the noise floor where the simulation is below it are listed
    apart as measured, not modelled, and not scored.

    MEASURED: long-format CSV (mount,direction,quantity,rpm,velocity_rms_mm_per_s; also
    velocity_rms_m_per_s, velocity_peak_mm_per_s, or the acceleration_rms_m_per_s2,
    displacement_rms_mm, force_rms_n of 'powertrain track', converted per order) or
    run-up HDF5. Raw time data (a time column, MDF, UFF) go through 'powertrain track' first.

    \b
    Examples:
      powertrain compare examples/measured-runup.csv --plot compare.png --json compare.json
      powertrain compare measured.csv --sim runup.h5
    """
    if sim_file and engine_file:
        raise click.UsageError("give --sim or --engine, not both")
    nonnegative(noise_floor, "--noise-floor", "mm/s")
    check_outputs(plot=plot, json=json_file)
    comp = run_compare(measured, engine=engine_file, simulated=sim_file, solver=solver,
                       step=rpm_step, noise_floor=noise_floor * 1e-3, progress=not quiet)
    figure, file = _provenance(comp, sim_file)
    if plot:
        write_plot(lambda p: comp.plot(path=p, provenance=figure), plot)
    if json_file:
        write_json(json_file, comp.to_json(), file)
    say(comp.to_text(written=(plot, json_file)), quiet)


def _provenance(comp, sim_file):
    """Provenance of the figure (what ran, this command) and of the JSON file."""
    engine = comp.run["engine"]
    if engine is None:
        return (cli_provenance(f"simulation from {sim_file}"),
                dict(provenance(), simulation_file=str(sim_file)))
    what = engine_description(engine, comp.run["engine_file"]) + f", {comp.run['solver']} solver"
    return cli_provenance(what), provenance(engine, engine_file=comp.run["engine_file"])
