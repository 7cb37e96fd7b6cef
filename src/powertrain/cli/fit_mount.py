"""``powertrain fit-mount``: identify mount model parameters from a measured K*(f)."""

from __future__ import annotations

import click

from powertrain.cli import main
from powertrain.cli.common import plot_form_options
from powertrain.models.mount import TOPOLOGIES
from powertrain.workflows.fitting import DEFAULT_SEED, DEFAULT_STARTS

_MODELS = tuple(TOPOLOGIES)


@main.command("fit-mount")
@click.argument("measured")
@click.option("--model", default="triple-parallel", show_default=True,
              metavar="[" + "|".join(_MODELS) + "]",
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
@click.option("--quiet", is_flag=True, help="No progress indicator on stderr.")
def fit_mount(measured, model, out, plot, form, freq_axis, starts, seed, fmin, fmax, max_mass, quiet):
    """Fit a lumped mount model to the measured dynamic stiffness in MEASURED (CSV).

    MEASURED has a header line and the columns frequency_hz plus either k_real_n_per_mm,
    k_imag_n_per_mm or k_abs_n_per_mm, phase_deg (N/mm, degrees); other columns are ignored,
    so the output of `powertrain stiffness --format csv` is valid input. The parameters
    (all >= 0) minimise the thesis objective f_obj = ||k_t - k_m|| in N/mm times 1 mm
    (Kovarik 2016, eq. 19): the Euclidean norm over the frequencies of the complex stiffness
    error. Printed: f_obj [N] and the relative RMS error sqrt(sum|K-K_m|^2 / sum|K_m|^2).

    \b
    Examples:
      powertrain stiffness mounts/hydraulic-engine-mount-z.toml --format csv > k.csv
      powertrain fit-mount k.csv --model triple-parallel --out fitted.toml --plot fit.png
      powertrain stiffness fitted.toml --freq 5,10,20,50,100,200,400
    """
    from pathlib import Path

    from powertrain.errors import InputError
    from powertrain.iotools.mount_file import write_mount
    from powertrain.iotools.stiffness_csv import FREQUENCY, read_stiffness_csv
    from powertrain.units import from_si
    from powertrain.workflows.fitting import fit_mount as fit

    if model not in TOPOLOGIES:
        raise InputError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})",
                         file=measured, key="--model")
    if max_mass is not None and not max_mass > 0:
        raise InputError(f"must be positive, got {max_mass}", key="--max-mass")
    if not 1 <= starts <= 10_000:
        raise InputError(f"must be 1..10000, got {starts}", key="--starts")
    if not 0 <= seed < 2 ** 63:
        raise InputError(f"must be an integer 0..2^63-1, got {seed}", key="--seed")
    import math
    for name, value in (("--fmin", fmin), ("--fmax", fmax), ("--max-mass", max_mass)):
        if value is not None and not math.isfinite(value):
            raise InputError(f"must be a finite number, got {value}", key=name)
    if fmin is not None and fmax is not None and not fmin < fmax:
        raise InputError(f"--fmin {fmin:g} must be below --fmax {fmax:g}", key="--fmin")
    data = read_stiffness_csv(measured).select(fmin, fmax)
    topo = TOPOLOGIES[model]
    need = (len(topo.parameters) + 1) // 2
    if data.frequency_hz.size < need:
        limits = "/".join(n for n, v in (("--fmin", fmin), ("--fmax", fmax)) if v is not None)
        raise InputError(f"{data.frequency_hz.size} frequencies in range"
                         + (f" of {limits}" if limits else "") + f", the "
                         f"{len(topo.parameters)} parameters of {model} need at least {need}",
                         file=measured, key=limits or FREQUENCY)
    if not (abs(data.kcp) > 0).any():
        raise InputError("stiffness is zero everywhere", file=measured, key=FREQUENCY)

    from powertrain.cli.common import check_outputs
    from powertrain.progress import activity
    check_outputs(out=out, plot=plot)
    with activity(f"fit-mount ({model}, {starts} starts)", enabled=not quiet):
        result = fit(data.frequency_hz, data.kcp, model, starts=starts, seed=seed,
                     max_mass=max_mass, name=f"{topo.description} fitted to {Path(measured).name}",
                     source=f"powertrain fit-mount {Path(measured).name} --model {model}")
    f = data.frequency_hz
    comment = (f"Fitted by powertrain fit-mount (Kovarik 2016 sec. 2.2, eq. 19) to "
               f"{Path(measured).name}: {f.size} frequencies, {f[0]:g}-{f[-1]:g} Hz.\n"
               f"f_obj = {result.objective_n:.6g} N, relative RMS error = "
               f"{100 * result.rel_rms:.4g} %, starts = {starts}, seed = {seed}.")
    write_mount(result.model, out, comment=comment)
    if plot:
        from powertrain.cli.common import cli_provenance, write_plot
        prov = cli_provenance()
        write_plot(lambda p: result.plot(path=p, form=form, freq_axis=freq_axis,
                                         provenance=prov), plot)

    units = {"c": "N/mm", "d": "N*s/mm", "m": "kg"}
    click.echo(result.summary())
    if not result.success:
        click.echo("warning: the best local solve stopped at its evaluation limit", err=True)
    click.echo("parameters:")
    for p in topo.parameters:
        click.echo(f"  {p:>3s} = {from_si(result.model.params[p], units[p[0]]):.6g} {units[p[0]]}")
    click.echo("wrote " + ", ".join(p for p in (out, plot) if p))
