"""``powertrain compare``: simulated vs measured run-up, level gaps and correlation metrics."""

from __future__ import annotations

import click

from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, NOISE_FLOOR_MARGIN_DB
from powertrain.cli import main


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
@click.option("--quiet", is_flag=True, help="No progress bar; print only the summary line.")
def compare(measured, sim_file, engine_file, plot, json_file, noise_floor, solver, rpm_step,
            quiet):
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
    import math
    import time

    from powertrain.errors import InputError
    from powertrain.workflows.comparison import compare_runup

    t0 = time.perf_counter()
    if sim_file and engine_file:
        raise click.UsageError("give --sim or --engine, not both")
    if not (math.isfinite(noise_floor) and noise_floor >= 0):
        raise InputError("must be a finite number >= 0 [mm/s]", key="--noise-floor")
    if rpm_step is not None and not (math.isfinite(rpm_step) and rpm_step > 0):
        raise InputError("must be > 0 [rpm]", key="--step")
    from powertrain.cli.common import check_outputs, write_json
    check_outputs(plot=plot, json=json_file)
    engine = None
    if sim_file:
        simulated = _read_curves(sim_file)
        meas = _read_curves(measured, sorted({m for m, _ in simulated.channels}))
        if meas.signal != simulated.signal:
            raise InputError(f"measured {meas.signal} curves need a simulation of the same "
                             "quantity; run without --sim (the simulation is run here)",
                             file=sim_file)
    else:
        from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
        engine_file = engine_file or str(DEFAULT_ENGINE_PATH)
        engine = read_engine(engine_file)
        meas = _read_curves(measured, list(engine.mount_names))
        simulated = _simulate(engine, engine_file, meas, measured, rpm_step, solver, quiet)
    t_sim = time.perf_counter() - t0
    comp = compare_runup(simulated, meas, noise_floor=noise_floor * 1e-3)
    if not comp.channels and not comp.not_modelled:
        raise InputError("nothing to compare: no channel and quantity has a point above the "
                         f"noise floor ({noise_floor:g} mm/s) inside the simulated speed range",
                         file=measured, key="--noise-floor")
    if plot:
        from powertrain.cli.common import cli_provenance, engine_description, write_plot
        prov = cli_provenance(engine_description(engine, engine_file) + f", {solver} solver"
                              if engine is not None else f"simulation from {sim_file}")
        write_plot(lambda p: comp.plot(path=p, provenance=prov), plot)
    if json_file:
        from powertrain.provenance import provenance
        write_json(json_file, comp.to_json(),
                   provenance(engine, engine_file=engine_file) if engine is not None
                   else dict(provenance(), simulation_file=str(sim_file)))
    summary = _summary(comp, time.perf_counter() - t0)
    if quiet:
        click.echo(summary)
        return
    _print_report(comp, meas, simulated, noise_floor)
    click.echo(summary + f" (simulation {t_sim:.2f} s)"
               + "".join(f"; wrote {p}" for p in (plot, json_file) if p))


def _read_curves(path, mounts=None):
    """Order curves of ``path``; raw time data are refused with a pointer to ``track``."""
    from powertrain.errors import InputError
    from powertrain.iotools.measured import read_measured
    from powertrain.iotools.raw import detect_format
    kind = detect_format(path)
    if kind in ("mdf", "uff"):
        raise InputError(f"raw time data ({kind.upper()}), not order curves: track it first "
                         f"('powertrain track {path} --csv curves.csv'), then compare "
                         "curves.csv", file=path)
    try:
        return read_measured(path, mounts=mounts)
    except InputError as exc:
        if _is_raw_csv(path, exc):
            raise InputError("raw time data (a 'time' column), not order curves: track it "
                             f"first ('powertrain track {path} --csv curves.csv'), then "
                             "compare curves.csv", file=path, line=exc.line,
                             key=exc.key) from None
        raise


def _is_raw_csv(path, exc) -> bool:
    """True if the order-curve reader refused a wide raw CSV (its time column)."""
    from powertrain.iotools.channel_map import split_unit
    return bool(exc.key) and split_unit(str(exc.key))[0].strip().lower() == "time" \
        and exc.message.startswith("unknown column")


def _simulate(engine, engine_file, meas, measured, rpm_step, solver, quiet):
    """Run the engine at the measured speeds (or on a ``rpm_step`` grid over them)."""
    from powertrain.cli.common import checked_runup
    from powertrain.iotools.measured import MeasuredRunup
    from powertrain.workflows.runup import run_runup
    rpm = _simulation_speeds(engine, meas, measured, rpm_step)
    grid = (f"{rpm[0]:g}..{rpm[-1]:g} rpm step {rpm_step:g}, interpolated" if rpm_step
            else f"at the {rpm.size} measured speeds {rpm[0]:g}..{rpm[-1]:g} rpm")
    result = checked_runup(engine, engine_file, run_runup, rpm, solver=solver,
                           progress=not quiet)
    return MeasuredRunup.from_result(result, source=f"{engine_file} ({solver}, {grid})",
                                     signal=meas.signal)


def _simulation_speeds(engine, meas, measured, rpm_step):
    """Speeds to simulate: every measured speed inside the engine's range, or a
    ``rpm_step`` grid covering the measured range [rpm]."""
    import math

    import numpy as np

    from powertrain.cli.common import MAX_SPEEDS
    from powertrain.errors import InputError
    lo, hi = meas.rpm_range()
    e_lo, e_hi = engine.speed_range_rpm()
    if hi < e_lo or lo > e_hi:
        raise InputError(f"measured speeds {lo:g}..{hi:g} rpm outside the engine's range "
                         f"{e_lo:g}..{e_hi:g} rpm", file=measured, key="rpm")
    if rpm_step is None:
        rpm = np.unique(np.concatenate([r for r, _ in meas.curves.values()]))
        rpm = rpm[(rpm >= e_lo - 1e-6) & (rpm <= e_hi + 1e-6)]
        if rpm.size > MAX_SPEEDS:
            raise InputError(f"{rpm.size} distinct measured speeds; at most {MAX_SPEEDS} are "
                             "simulated one by one: give --step to simulate a grid",
                             file=measured, key="rpm")
        return rpm
    start = max(math.floor(lo / rpm_step + 1e-9) * rpm_step,
                math.ceil(e_lo / rpm_step - 1e-9) * rpm_step)
    stop = min(math.ceil(hi / rpm_step - 1e-9) * rpm_step,
               math.floor(e_hi / rpm_step + 1e-9) * rpm_step)
    if stop < start or start <= 0:
        raise InputError(f"{rpm_step:g} rpm leaves no speed step inside both the measured "
                         f"({lo:g}..{hi:g}) and the engine's ({e_lo:g}..{e_hi:g}) range",
                         key="--step")
    if (stop - start) / rpm_step + 1 > MAX_SPEEDS:
        raise InputError(f"{(stop - start) / rpm_step + 1:.3g} speed steps over the "
                         f"measured range; at most {MAX_SPEEDS}", key="--step")
    from powertrain.workflows.runup import default_rpm
    return default_rpm(start, stop, rpm_step)


def _summary(comp, elapsed) -> str:
    """The one-line result (``--quiet`` prints only this)."""
    c = comp.to_dict()["compared"]
    return (f"overall RMS gap {comp.overall_rms_db:.2f} dB over {c['n_points_compared']} "
            f"points ({c['n_channel_quantities']} channel-quantities); "
            f"{c['n_points_excluded_noise_floor']} at the noise floor, "
            f"{comp.n_not_modelled} measured but not modelled, "
            f"{c['n_points_outside_simulated_range']} outside the simulated range; "
            f"{len(comp.missing)} missing; {elapsed:.2f} s")


def _print_report(comp, meas, simulated, noise_floor) -> None:
    """Sources, rules, the per-channel table, per-quantity lines and what was not compared."""
    tag = " [SYNTHETIC]" if meas.synthetic else ""
    click.echo(f"measured: {meas.source}{tag}")
    click.echo(f"simulated: {simulated.source}")
    for note in meas.notes:
        click.echo(f"note: {note}")
    how = ("simulated at the measured speeds" if comp.n_interpolated == 0 else
           f"simulation interpolated linearly in rpm and log level at {comp.n_interpolated} "
           "of them, never extrapolated")
    click.echo(f"gap = 20 log10(sim/measured) [dB] at the measured speeds; {how}; noise floor "
               f"{noise_floor:g} mm/s (measured points below {comp.exclusion_limit * 1e3:g} "
               "mm/s excluded)")
    click.echo("")
    click.echo("per channel, worst first:")
    click.echo(comp.table())
    click.echo("")
    click.echo("per quantity (CSAC/CSF across the channels at each speed, RMS magnitudes):")
    for pq in comp.per_quantity():
        line = (f"  {pq['quantity']:<10} rms {pq['rms_db']:.2f} dB, bias {pq['bias_db']:+.2f} dB")
        if pq["n_rpm_with_csac"]:
            line += (f"; CSAC mean {pq['csac_mean']:.3f} (min {pq['csac_min']:.3f} at "
                     f"{pq['rpm_at_csac_min']:g} rpm); CSF mean {pq['csf_mean']:.3f} (min "
                     f"{pq['csf_min']:.3f} at {pq['rpm_at_csf_min']:g} rpm)")
        else:
            line += "; CSAC/CSF: fewer than 3 channels at every speed"
        click.echo(line)
    _print_not_modelled(comp, noise_floor)
    if comp.missing:
        click.echo("")
        click.echo("not compared:")
        for line in _missing_lines(comp.missing):
            click.echo(f"  {line}")
    click.echo("")


def _missing_lines(missing) -> list:
    """``MOUNT DIRS: QUANTITIES: reason``, one line per mount and reason: the directions with
    the same quantities and reason share a line (every entry stays in the JSON)."""
    from powertrain.iotools.measured import quantity_sort_key
    groups = {}                                     # (mount, reason, direction) -> quantities
    for m in missing:
        groups.setdefault((m["mount"], m["reason"], m["direction"]), []).append(m["quantity"])
    merged = {}                                     # (mount, reason, quantities) -> directions
    for (mount, reason, direction), qs in groups.items():
        key = (mount, reason, tuple(sorted(qs, key=quantity_sort_key)))
        merged.setdefault(key, []).append(direction)
    return [f"{mount} {', '.join(sorted(dirs))}: {', '.join(qs)}: {reason}"
            for (mount, reason, qs), dirs in merged.items()]


def _print_not_modelled(comp, noise_floor) -> None:
    """The measured-not-modelled points, per channel and quantity (not in any dB gap)."""
    if not comp.not_modelled:
        return
    click.echo("")
    click.echo(f"measured, not modelled (simulation below the {noise_floor:g} mm/s floor, "
               "measurement above the exclusion limit; not in any dB gap):")
    for e in comp.not_modelled:
        r, m = e["rpm"], e["measured_m_per_s"]
        click.echo(f"  {e['mount']} {e['direction']} {e['quantity']}: {len(r)} points "
                   f"{min(r):g}..{max(r):g} rpm, measured up to {max(m) * 1e3:.3g} mm/s")
