"""``powertrain fit-mount``: identify mount model parameters from a measured K*(f)."""

from __future__ import annotations

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    plot_form_options,
    quiet_option,
    say,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.iotools.mount_file import write_mount
from powertrain.models.mount import TOPOLOGIES
from powertrain.progress import activity
from powertrain.units import to_si
from powertrain.workflows.amplitude_fit import fit_mount_csv
from powertrain.workflows.fitting import DEFAULT_SEED, DEFAULT_STARTS

_MODELS = tuple(TOPOLOGIES)


@main.command("fit-mount")
@click.argument("measured")
@click.option("--model", default="triple-parallel", show_default=True, metavar="[" + "|".join(_MODELS) + "]",
              help="Mount model preset (thesis Table 2).")
@click.option("--out", required=True, type=click.Path(dir_okay=False),
              help="Fitted mount file to write (TOML, datasheet units).")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Write a measured-vs-fitted K*(f) plot (PNG); the path is printed.")
@plot_form_options
@click.option("--starts", type=int, default=DEFAULT_STARTS, show_default=True,
              help="Random starting points screened.")
@click.option("--seed", type=int, default=DEFAULT_SEED, show_default=True,
              help="Seed of the starting points.")
@click.option("--fmin", type=float, help="Fit only frequencies >= FMIN [Hz].")
@click.option("--fmax", type=float, help="Fit only frequencies <= FMAX [Hz].")
@click.option("--max-mass", type=float,
              help="Upper bound of every internal mass [kg]. K_CP alone does not identify the "
                   "internal masses, but the engine feels them (input-point stiffness).")
@click.option("--friction", is_flag=True,
              help="With data at several amplitudes: fit Berg's friction element too.")
@click.option("--reference", type=float,
              help="With data at several amplitudes: the reference amplitude of the network "
                   "and the amplitude law [mm], one of the data's (default the smallest).")
@quiet_option
def fit_mount(measured, model, out, plot, form, freq_axis, starts, seed, fmin, fmax, max_mass,
              friction, reference, quiet):
    """Fit a lumped mount model to the measured dynamic stiffness in MEASURED (CSV).

    MEASURED has a header line and the columns frequency_hz plus either k_real_n_per_mm,
    k_imag_n_per_mm or k_abs_n_per_mm, phase_deg (N/mm, degrees); other columns are ignored,
    so the output of `powertrain stiffness --format csv` is valid input. The parameters
    (all >= 0) minimise the thesis objective f_obj = ||k_t - k_m|| in N/mm times 1 mm
    (Kovarik 2016, eq. 19): the Euclidean norm over the frequencies of the complex stiffness
    error. Printed: f_obj [N] and the relative RMS error sqrt(sum|K-K_m|^2 / sum|K_m|^2).

    With a column amplitude_mm (K*(f) at several amplitudes, from `stiffness --amplitude`)
    the network at the reference amplitude, a power amplitude law (exponent fitted, limits
    fixed) and, with --friction, Berg's friction element are fitted together; the error is
    printed per amplitude.

    \b
    Examples:
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --format csv > k.csv
      powertrain fit-mount k.csv --model triple-parallel --out fitted.toml --plot fit.png
      powertrain stiffness fitted.toml --freq 5,10,20,50,100,200,400
      powertrain fit-mount multi-amplitude.csv --friction --out fitted.toml
    """
    check_outputs(out=out, plot=plot)
    ref = _reference(reference)
    with activity(f"fit-mount ({model}, {starts} starts)", enabled=not quiet):
        result = fit_mount_csv(measured, model, friction=friction, reference=ref,
                               starts=starts, seed=seed, max_mass=max_mass, fmin=fmin, fmax=fmax)
    write_mount(result.model, out, comment=result.file_comment())
    _plot(result, plot, form, freq_axis)
    say(result.to_text(), quiet)
    if not result.success:
        say("warning: the best local solve stopped at its evaluation limit", quiet, err=True)
    say(wrote(out, plot), quiet)


def _plot(result, plot, form, freq_axis) -> None:
    """The measured-vs-fitted figure, when asked."""
    if plot:
        prov = cli_provenance()
        write_plot(lambda p: result.plot(path=p, form=form, freq_axis=freq_axis, provenance=prov), plot)


def _reference(reference_mm):
    """``--reference`` [mm] in [m] (None when not given)."""
    return None if reference_mm is None else to_si(reference_mm, "mm", "length")
