"""``powertrain diagnose`` and ``powertrain synth``: where the sim-to-real gap lies, which
unmodelled effect explains it, how far it shrinks; and synthetic measurements to test it."""

from __future__ import annotations

from pathlib import Path

import click

from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN
from powertrain.cli.common import (
    check_outputs,
    cli_provenance,
    engine_description,
    quiet_option,
    say,
    use_agg,
    write_json,
    wrote,
)
from powertrain.cli.group import main
from powertrain.diagnosis import diagnose as run_diagnosis
from powertrain.diagnosis.report import REPORT_FILES
from powertrain.effects import EFFECTS
from powertrain.errors import InputError
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH
from powertrain.outputs import check_writable
from powertrain.parallel import check_scheduler
from powertrain.progress import activity
from powertrain.provenance import provenance
from powertrain.units import to_si
from powertrain.workflows.arguments import nonnegative
from powertrain.workflows.synth import TRUTH_ALIASES, TRUTH_EFFECTS
from powertrain.workflows.synth import synth as run_synth


class _ListedOption(click.Option):
    """An option whose help ends with the names ``names()`` returns when it is shown."""

    def __init__(self, *args, names, **kwargs):
        super().__init__(*args, **kwargs)
        self._names = names
        self._base_help = self.help

    def get_help_record(self, ctx):
        self.help = f"{self._base_help} {self._names()}"
        return super().get_help_record(ctx)


def _library_names() -> str:
    return f"Known: {', '.join(EFFECTS)}."


def _truth_names() -> str:
    old = ", ".join(f"{a} (= {n})" for a, n in TRUTH_ALIASES.items())
    return f"Known: {', '.join(TRUTH_EFFECTS)}; or 'none'. Former names still accepted: {old}."


@main.command()
@click.argument("measured", type=click.Path(dir_okay=False), required=False)
@click.option("--plan", "plan_file", type=click.Path(dir_okay=False),
              help="Test plan (TOML, [[runs]] with file and load or traces; paths relative "
                   "to the plan): all its run-ups diagnosed together, one set of effect "
                   "parameters. Instead of MEASURED.")
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Baseline engine file (default: the shipped engines/default.toml).")
@click.option("--report", "report_dir", type=click.Path(file_okay=False),
              help="Folder for summary.txt, diagnosis.json and the figures (gap map, gap vs "
                   "frequency, before/after overlays).")
@click.option("--json", "json_file", type=click.Path(dir_okay=False),
              help="JSON: where (gap map, regions, decomposition), ranking (effect, "
                   "parameters, heldout_rms_db_before/after, verdict), verdict.")
@click.option("--noise-floor", type=float, default=0.001, show_default=True,
              help="RMS noise floor of the measured order curves [mm/s]; measured points "
                   f"below {NOISE_FLOOR_MARGIN:g}x this are treated as 'below "
                   f"{NOISE_FLOOR_MARGIN:g}x floor' (censored).")
@click.option("--effects", "effects", default="", cls=_ListedOption, names=_library_names,
              help="Comma-separated candidates (default: all of the library).")
@click.option("--no-pairs", is_flag=True, help="Do not try pairs of effects.")
@quiet_option
@click.option("--scheduler", default=None, metavar="local|tcp://HOST:PORT",
              help="Run the candidate fits on dask.distributed: 'local' (a LocalCluster on "
                   "this machine's cores) or an existing scheduler's address; also "
                   "'processes' or 'serial'. Default: serial (starts fastest). Same result "
                   "on every scheduler.")
def diagnose(measured, plan_file, engine_file, report_dir, json_file, noise_floor, effects,
             no_pairs, quiet, scheduler):
    """Diagnose the gap between the simulated and a measured run-up.

    1. Where: the gap map per channel, quantity and speed, the regions beyond +-3 dB and
    the gap against frequency, split into structure (frequency), excitation (order/speed)
    and sensor (channel constant) parts. 2. Which: every candidate effect of the library
    (and pairs of the best three) fitted on training speeds, ranked on held-out speeds.
    3. How far: held-out RMS gap before and after the chosen effect.

    MEASURED: long-format CSV (mount,direction,quantity,rpm,velocity_rms_mm_per_s, and
    phase_deg where measured) or run-up HDF5, as for 'powertrain compare'; or --plan.

    \b
    Examples:
      powertrain synth --effect balancer_error --seed 3 --out case.csv
      powertrain diagnose case.csv --report out/diag --json out/diag.json
      powertrain diagnose --plan plan.toml --json out/plan.json
    """
    measured = _measured_or_plan(measured, plan_file)
    noise_floor = _noise_floor(noise_floor)
    names = [e.strip() for e in effects.split(",") if e.strip()] or None
    scheduler = check_scheduler(scheduler or "serial", reach=True)
    check_outputs(json=json_file)
    _check_report(report_dir)
    with activity("diagnose (fitting the effect library)", enabled=not quiet):
        res = run_diagnosis(measured, engine_file, noise_floor=noise_floor, effects=names,
                            pairs=not no_pairs, scheduler=scheduler, progress=False)
    say(res.to_text(), quiet)
    if json_file:
        _write_json(res, json_file, engine_file)
        say(wrote(json_file), quiet)
    if report_dir:
        files = _write_report(res, report_dir)
        say(f"wrote {len(files)} files to {report_dir}", quiet)


def _write_report(res, report_dir) -> list:
    use_agg()
    return res.report(report_dir, provenance=cli_provenance(engine_description(res.engine, res.engine.file)))


def _measured_or_plan(measured, plan_file):
    """MEASURED or ``--plan``, exactly one of them."""
    if (measured is None) == (plan_file is None):
        raise InputError("give either a MEASURED file or --plan PLAN.toml (not both)"
                         if measured else "missing MEASURED file or --plan PLAN.toml", key="--plan")
    if plan_file is not None and not plan_file.lower().endswith(".toml"):
        raise InputError("a plan is a TOML file (PLAN.toml)", file=plan_file, key="--plan")
    return measured or plan_file


def _noise_floor(value: float) -> float:
    """``--noise-floor`` [mm/s] checked, in SI [m/s]."""
    return to_si(nonnegative(value, "--noise-floor", "mm/s"), "mm/s", "velocity")


def _check_report(report_dir) -> None:
    """Every file of the report folder can be written (checked before any work)."""
    if report_dir:
        for name in REPORT_FILES:
            check_writable(Path(report_dir) / name, key="--report")


def _write_json(res, json_file, engine_file) -> None:
    write_json(json_file, res.to_json(),
               provenance(res.engine, engine_file=engine_file or DEFAULT_ENGINE_PATH))


@main.command()
@click.option("--effect", "effect_names", default="none", show_default=True,
              cls=_ListedOption, names=_truth_names, help="Hidden truth effect(s), comma-separated.")
@click.option("--seed", type=int, default=0, show_default=True)
@click.option("--out", required=True, type=click.Path(dir_okay=False),
              help="CSV written (long format; the hidden effect is not written).")
@click.option("--truth", "truth_file", type=click.Path(dir_okay=False),
              help="JSON with the hidden effect and its parameters (keep it away from the diagnosis).")
@click.option("--engine", "engine_file", type=click.Path(dir_okay=False),
              help="Baseline engine file (default: engines/default.toml).")
@quiet_option
def synth(effect_names, seed, out, truth_file, engine_file, quiet):
    """Make a SYNTHETIC measured run-up with hidden effects and noise (truth generator).

    \b
    Examples:
      powertrain synth --effect mount_temperature --seed 1 --out m.csv --truth t.json
      powertrain synth --effect none --out clean.csv
    """
    names = [] if effect_names.strip() == "none" else [
        e.strip() for e in effect_names.split(",") if e.strip()]
    check_outputs(out=out, truth=truth_file)
    with activity("synth (simulating the hidden truth)", enabled=not quiet):
        case = run_synth(names, seed, engine=engine_file)
    case.to_csv(out)
    if truth_file:
        case.to_truth_json(truth_file)
    say(f"{wrote(out, truth_file)}: {case.to_text()}", quiet)
