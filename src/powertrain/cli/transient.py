"""``powertrain transient``: an engine start, stop, tip-in or back-out on the mounts."""

from __future__ import annotations

import json

import click

from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    say,
    write_json,
    write_plot,
    wrote,
)
from powertrain.cli.group import main
from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.iotools.manoeuvre_file import read_manoeuvre
from powertrain.iotools.raw import write_raw
from powertrain.workflows import transient as workflow
from powertrain.workflows import transient_recording as recording


@main.command()
@click.argument("manoeuvre_file", metavar="MANOEUVRE", type=click.Path(dir_okay=False))
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Engine file (default: the shipped engines/default.toml).")
@click.option("--angle-step", type=float, default=workflow.ANGLE_STEP_DEG, show_default=True,
              help="Crank angle per integration step at the top speed [deg].")
@click.option("--speed-from", type=click.Path(dir_okay=False),
              help="Raw recording (CSV, HDF5, UFF, MDF4) whose rpm channel or tacho drives "
                   "the crank instead of the file's speed table, lined up with the "
                   "manoeuvre as for --compare; it must cover the whole manoeuvre.")
@click.option("--speed-average", is_flag=True,
              help="With --speed-from: the recorded speed's mean over each firing interval "
                   "of crank angle (a speed resolved within the cycle, an encoder's: its "
                   "firing orders' fluctuation is in the gas and inertia torques already).")
@click.option("--seat", help="Body point for the ISO 2631-1 values (default: a body point named seat...).")
@click.option("--channels", help="Channels of the figure, comma separated (e.g. "
                                 "left.z,right.z; default: the seat's, else each mount's z).")
@click.option("--quantity", type=click.Choice(["acceleration", "displacement", "force"]),
              default="acceleration", show_default=True, help="What the figure's channel panels show.")
@click.option("--out", type=click.Path(dir_okay=False), help="Write the HDF5 time histories.")
@click.option("--csv", "csv_file", type=click.Path(dir_okay=False),
              help="Write the time histories as CSV, one row per step.")
@click.option("--json", "json_file", type=click.Path(dir_okay=False),
              help="Write the peaks and the seat's values as JSON.")
@click.option("--plot", type=click.Path(dir_okay=False),
              help="Speed and torque above the channels' accelerations (PNG).")
@click.option("--raw", "raw_out", type=click.Path(dir_okay=False),
              help="Write every channel's acceleration, the crank speed and the trigger as "
                   "raw time data, labelled SYNTHETIC, in the format of the suffix (.csv, "
                   ".uff, .mf4, else raw HDF5), e.g. to try --compare.")
@click.option("--compare", "raw_file", type=click.Path(dir_okay=False),
              help="A recording of the manoeuvre (raw CSV, HDF5, UFF, MDF4): lined up on its "
                   "crank speed (or --trigger), every acceleration channel of the model "
                   "compared over the span it covers (peaks, RMS of the difference); in "
                   "--json under 'compare'.")
@click.option("--compare-plot", type=click.Path(dir_okay=False),
              help="With --compare: measured and simulated accelerations overlaid (PNG).")
@click.option("--trigger", metavar="CHANNEL",
              help="Trigger channel of the --compare/--speed-from recording ('trigger' in "
                   "--raw's files): the manoeuvre's trigger_time (default 0) at its first "
                   "rising crossing of the mid level between its low and high levels "
                   "(default: lined up on the crank speed).")
@click.option("--channel-map", type=click.Path(dir_okay=False),
              help="Channel map TOML of the --compare/--speed-from recording (the format of "
                   "'powertrain track --channels'): file channel name -> mount, side, direction, quantity.")
@click.option("--trigger-edge", type=click.Choice(["rising", "falling"]), default="rising",
              show_default=True, help="The edge the --trigger channel marks (falling: an "
                                      "active-low trigger).")
@click.option("--pulses-per-rev", type=int, default=1, show_default=True,
              help="Tacho pulses per revolution of the --compare/--speed-from recording, "
                   "where its speed is a tacho's (a missing-tooth wheel's gap is counted).")
@quiet_option
def transient(manoeuvre_file, engine_file, angle_step, speed_from, speed_average, seat,
              channels, quantity, out, csv_file, json_file, plot, raw_out, raw_file,
              compare_plot, trigger, channel_map, trigger_edge, pulses_per_rev, quiet):
    """Transient manoeuvre: time histories of body, mounts and seat over a start, stop,
    tip-in or back-out.

    MANOEUVRE is a TOML file with the crank speed and load over time
    (docs/guide/transient.md); it is checked before any work.

    \b
    Examples:
      powertrain transient examples/start.toml
      powertrain transient examples/tip-in.toml --engine engines/default-nonlinear.toml
      powertrain transient examples/start.toml --engine engines/default-modal-body.toml \\
          --plot start.png --json start.json
      powertrain transient examples/start.toml --compare start-raw.h5 --compare-plot o.png
      powertrain transient examples/tip-in.toml --compare rec.mf4 --trigger trig \\
          --channel-map map.toml
      powertrain transient examples/start.toml --speed-from rec.mf4 --pulses-per-rev 60 \\
          --speed-average
    """
    files = dict(out=out, csv=csv_file, json=json_file, plot=plot, raw=raw_out, compare_plot=compare_plot)
    reading = dict(trigger=trigger, channel_map=channel_map, pulses_per_rev=pulses_per_rev,
                   trigger_edge=trigger_edge)
    _check_options(files, raw_file, speed_from, reading, speed_average)
    manoeuvre, engine = read_manoeuvre(manoeuvre_file), engine_or_default(engine_file)
    system = engine.assemble()
    figure = workflow.figure_channels(system, channels)
    firing = engine.crank.firing_interval if speed_average else None
    recorded = _recordings(raw_file, speed_from, reading, system, manoeuvre, firing)
    result = workflow.transient(manoeuvre, engine, angle_step_deg=angle_step, seat=seat,
                                system=system, speed_from=recorded.get("speed"), speed_average=speed_average)
    comparison = recording.compare_transient(result, recorded["compare"]) if raw_file else None
    written = _write(result, comparison, files, cli_provenance(engine_description(
        engine, engine.file)), figure, quantity)
    _say(result, comparison, written, quiet)


def _say(result, comparison, written, quiet) -> None:
    """The run's text, the comparison's and what was written."""
    say(result.to_text(), quiet)
    if comparison is not None:
        say(comparison.to_text(), quiet)
    say(f"solver time: {result.solver_seconds:.3f} s; "
        + (wrote(*written) if written else "no file written (ask with --out, --csv, --json or --plot)"),
        quiet)


def _check_options(files, raw_file, speed_from, reading, speed_average) -> None:
    """The output paths and the options that need another, before any work (``reading``:
    the recordings' trigger, channel map and pulses per revolution)."""
    check_outputs(**files)
    if speed_average and not speed_from:
        raise InputError("goes with --speed-from RAW", key="--speed-average")
    if files["compare_plot"] and not raw_file:
        raise InputError("--compare-plot needs --compare RAW", key="--compare-plot")
    for key, given in (("--trigger", reading["trigger"] is not None),
                       ("--channel-map", reading["channel_map"] is not None),
                       ("--pulses-per-rev", reading["pulses_per_rev"] != 1),
                       ("--trigger-edge", reading["trigger_edge"] != "rising")):
        if given and not (raw_file or speed_from):
            raise InputError("goes with --compare RAW or --speed-from RAW", key=key)


def _recordings(raw_file, speed_from, reading, system, manoeuvre, firing_interval) -> dict:
    """The recordings of --compare and --speed-from read and checked before the run (the
    compared channels against the model's, the alignment and the span covered); one read
    where both name the same file."""
    out = {}
    for kind, path in (("compare", raw_file), ("speed", speed_from)):
        if path:
            same = out.get("compare") if kind == "speed" and path == raw_file else None
            out[kind] = same or recording.read_recording(path, **reading)
    recording.check_recordings(manoeuvre, [f"{c}.{d}" for c, d in system.channels],
                               firing_interval=firing_interval,
                               compare=out.get("compare"), speed=out.get("speed"))
    return out


def _write(result, comparison, files, prov, channels, quantity) -> list:
    """The files asked for, each atomically; returns their paths."""
    doc = result.to_dict()
    if comparison is not None:
        doc["compare"] = comparison.to_dict()
    writers = {"out": result.to_hdf5, "csv": result.to_csv,
               "json": lambda p: write_json(p, json.dumps(doc), prov.to_dict()),
               "plot": lambda p: write_plot(lambda q: result.plot(
                   path=q, channels=channels, quantity=quantity, provenance=prov), p),
               "raw": lambda p: write_raw(p, result.recording()),
               "compare_plot": lambda p: write_plot(lambda q: comparison.plot(
                   path=q, provenance=prov), p)}
    written = []
    for key, path in files.items():
        if path:
            writers[key](path)
            written.append(path)
    return written
