"""The steps a study may include (``[compare]``, ``[diagnose]``, ``[whatif]``, ``[modes]``,
``[transient]``), each run through the library's own function and shown as a report section;
each kind is one :class:`Step` in :data:`STEPS`.
"""

from __future__ import annotations

import os
import shlex
from collections.abc import Callable
from dataclasses import dataclass

from powertrain.diagnosis import diagnose
from powertrain.diagnosis.html import diagnosis_html
from powertrain.effects import EFFECTS
from powertrain.errors import InputError
from powertrain.plotting.diagnosis import plot_diagnosis_overlay, plot_gap_frequency
from powertrain.reporting import keys as k
from powertrain.results.html_tables import comparison_html, modes_html, transient_html, whatif_html
from powertrain.solvers.steppers import SOLVERS
from powertrain.workflows.arguments import speed_steps
from powertrain.workflows.comparison import compare
from powertrain.workflows.modes import modes
from powertrain.workflows.transient import transient
from powertrain.workflows.whatif import command_variants, whatif

#: What-if operations a study may list (the command's repeatable options), in their order.
WHATIF_OPERATIONS = ("scale", "set", "swap", "move", "rotate", "effect")


@dataclass(frozen=True)
class Step:
    """One kind of report section.

    Attributes
    ----------
    title : str
        Section heading.
    options : callable
        ``options(table, where)``: the step's table checked, as ``run`` and ``commands`` take.
    run : callable
        ``run(study, options, progress)``: ``[(label, result)]``, one per measured run for a
        comparing step, else one with an empty label.
    figures : callable
        ``figures(result, provenance)``: ``[(caption, draw)]``, ``draw()`` returning a figure.
    html : callable
        ``html(result)``: the result's tables.
    commands : callable
        ``commands(study, options)``: command (or Python) lines that repeat the step.
    needs_measured : bool
        The step needs a measurement.
    cost : int
        Run order, cheapest first.
    """

    title: str
    options: Callable
    run: Callable
    figures: Callable
    html: Callable
    commands: Callable
    needs_measured: bool = False
    cost: int = 0


def shown(path) -> str:
    """``path`` as the commands name it: relative to the current folder when inside it."""
    try:
        rel = os.path.relpath(path)
    except ValueError:                  # another drive (Windows)
        return str(path)
    return rel if not rel.startswith("..") else os.path.abspath(path)


def _own_plot(caption: str) -> Callable:
    """``figures`` of a step whose one figure is its result's own ``plot``."""
    return lambda result, provenance: [(caption, lambda: result.plot(provenance=provenance))]


def _line(words) -> str:
    return shlex.join(str(w) for w in words)


def _engine_words(study) -> list:
    return ["--engine", shown(study.engine_file)] if study.engine_file else []


def _noise_words(study) -> list:
    default = 1e-6
    return [] if study.noise_floor == default else ["--noise-floor", f"{study.noise_floor * 1e3:g}"]


def _compare_options(table, where) -> dict:
    k.check_keys(table, ("solver", "step"), where, "compare")
    return {"solver": k.choice(table, "solver", where, "compare", tuple(SOLVERS), "newmark"),
            "step": k.positive(table, "step", where, "compare")}


def _compare_run(study, opts, progress) -> list:
    return [(label, compare(measured, engine=engine, noise_floor=study.noise_floor,
                            progress=progress, **opts))
            for label, measured, engine, _ in study.runs()]


def _compare_commands(study, opts) -> list:
    extra = ["--solver", opts["solver"]] + (["--step", f"{opts['step']:g}"] if opts["step"] else [])
    lines = []
    for i, (label, measured, _, run) in enumerate(study.runs()):
        if run is not None and (run.traces or run.load != 1.0):
            lines.append(f"# {label}: no command line runs the engine at a load; in Python: "
                         f"run = pt.read_plan({shown(study.plan.source)!r}, engine).runs[{i}]; "
                         f"pt.compare(run.measured, engine=run.engine(engine), "
                         f"solver={opts['solver']!r})")
            continue
        lines.append(_line(["powertrain", "compare", shown(measured.source), *_engine_words(study),
                            *extra, *_noise_words(study)]))
    return lines


def _diagnose_options(table, where) -> dict:
    k.check_keys(table, ("effects", "pairs"), where, "diagnose")
    effects = [e.strip() for item in k.strings(table, "effects", where, "diagnose")
               for e in item.split(",") if e.strip()]
    for e in effects:
        if e not in EFFECTS:
            raise where.error(f"unknown effect {e!r} (known: {', '.join(EFFECTS)})",
                              "diagnose.effects")
    return {"effects": effects or None,
            "pairs": k.boolean(table, "pairs", where, "diagnose", True)}


def _diagnose_run(study, opts, progress) -> list:
    measured = study.plan if study.plan is not None else study.measured
    return [("", diagnose(measured, study.engine, noise_floor=study.noise_floor,
                          progress=progress, **opts))]


def _diagnose_figures(result, provenance) -> list:
    return [("Gap map: the gap 20 log10(sim/measured) per channel and speed, one panel per "
             "quantity.", lambda: result.plot(provenance=provenance)),
            ("The order gaps against frequency (structure) and, averaged over the channels, "
             "against speed (excitation).",
             lambda: plot_gap_frequency(result, None, provenance=provenance)),
            ("Measured, baseline and baseline with the chosen effect for the largest gaps; "
             "held-out speeds circled.",
             lambda: plot_diagnosis_overlay(result, None, provenance=provenance))]


def _diagnose_commands(study, opts) -> list:
    what = (["--plan", shown(study.plan.source)] if study.plan is not None
            else [shown(study.measured.source)])
    extra = (["--effects", ",".join(opts["effects"])] if opts["effects"] else []) \
        + ([] if opts["pairs"] else ["--no-pairs"])
    return [_line(["powertrain", "diagnose", *what, *_engine_words(study), *extra,
                   *_noise_words(study)])]


def _whatif_options(table, where) -> dict:
    allowed = ("variants", *WHATIF_OPERATIONS, "target", "from", "to", "step", "solver",
               "workers", "measured")
    k.check_keys(table, allowed, where, "whatif")
    ops = {op: k.strings(table, op, where, "whatif") for op in WHATIF_OPERATIONS}
    ops["swap"] = [_swap_relative(s, where) for s in ops["swap"]]
    opts = {"ops": ops, "targets": k.strings(table, "target", where, "whatif"),
            "variants": k.file_path(table, "variants", where, "whatif"),
            "solver": k.choice(table, "solver", where, "whatif", tuple(SOLVERS), "harmonic"),
            "workers": k.positive(table, "workers", where, "whatif", integer=True),
            "measured": k.boolean(table, "measured", where, "whatif", True),
            "rpm": tuple(float(k.positive(table, key, where, "whatif", default))
                         for key, default in (("from", 1000.0), ("to", 6000.0),
                                              ("step", 500.0)))}
    try:
        speed_steps(*opts["rpm"])
        command_variants(where.engine, ops, opts["targets"], opts["variants"])
    except InputError as exc:
        raise k.restated(exc, where, "whatif") from None
    return opts


def _swap_relative(spec: str, where) -> str:
    """``MOUNT.DIR=FILE`` with FILE taken relative to the study file."""
    node, eq, name = spec.partition("=")
    if not eq or not name.strip():
        return spec                       # malformed: the what-if parser names it
    return f"{node}={k.existing(name.strip(), where, 'whatif.swap')}"


def _whatif_run(study, opts, progress) -> list:
    measured = study.measured if opts["measured"] else None
    ops = opts["ops"]
    return [("", whatif(study.engine, scale=ops["scale"], set=ops["set"], swap=ops["swap"],
                        move=ops["move"], rotate=ops["rotate"], effects=ops["effect"],
                        targets=opts["targets"], variants=opts["variants"],
                        rpm=speed_steps(*opts["rpm"]), solver=opts["solver"],
                        workers=opts["workers"], measured=measured, progress=progress,
                        rpm_step=opts["rpm"][2]))]


def _whatif_commands(study, opts) -> list:
    words = ["powertrain", "whatif", *_engine_words(study)]
    for op in WHATIF_OPERATIONS:
        for spec in opts["ops"][op]:
            words += [f"--{op}", _shown_swap(spec) if op == "swap" else spec]
    for t in opts["targets"]:
        words += ["--target", t]
    if opts["variants"]:
        words += ["--variants", shown(opts["variants"])]
    lo, hi, step = opts["rpm"]
    words += ["--from", f"{lo:g}", "--to", f"{hi:g}", "--step", f"{step:g}", "--solver",
              opts["solver"]]
    if opts["measured"] and study.measured is not None:
        words += ["--measured", shown(study.measured.source)]
    if opts["workers"]:
        words += ["--workers", str(opts["workers"])]
    return [_line(words)]


def _shown_swap(spec: str) -> str:
    node, _, path = spec.partition("=")
    return f"{node}={shown(path)}"


def _modes_options(table, where) -> dict:
    k.check_keys(table, ("static",), where, "modes")
    return {"static": k.boolean(table, "static", where, "modes", False)}


def _modes_run(study, opts, progress) -> list:
    return [("", modes(study.engine, **opts))]


def _modes_commands(study, opts) -> list:
    return [_line(["powertrain", "modes", *_engine_words(study),
                   *(["--static"] if opts["static"] else [])])]


def _transient_options(table, where) -> dict:
    k.check_keys(table, ("manoeuvres", "seat"), where, "transient")
    files = k.strings(table, "manoeuvres", where, "transient")
    if not files:
        raise where.error("expected at least one manoeuvre file", "transient.manoeuvres")
    return {"files": [k.existing(f, where, "transient.manoeuvres") for f in files],
            "seat": k.string(table, "seat", where, "transient")}


def _transient_run(study, opts, progress) -> list:
    results = [transient(f, study.engine, seat=opts["seat"]) for f in opts["files"]]
    return [(r.name, r) for r in results]


def _transient_commands(study, opts) -> list:
    seat = ["--seat", opts["seat"]] if opts["seat"] else []
    return [_line(["powertrain", "transient", shown(f), *_engine_words(study), *seat])
            for f in opts["files"]]


#: The steps a study may include, in the order of the report's sections.
STEPS = {
    "compare": Step("Compare: simulated against measured", _compare_options, _compare_run,
                    _own_plot("Measured (black) against simulated (blue) order curves per "
                              "channel, the gap shaded; over each panel its RMS gap and bias."),
                    comparison_html, _compare_commands, needs_measured=True, cost=2),
    "diagnose": Step("Diagnose: where the gap lies, which effect explains it, how far it "
                     "shrinks", _diagnose_options, _diagnose_run, _diagnose_figures,
                     diagnosis_html, _diagnose_commands, needs_measured=True, cost=3),
    "whatif": Step("What if: mount retuning variants", _whatif_options, _whatif_run,
                   _own_plot("Levels of the baseline (black), the variants and the measurement "
                             "(grey), every channel (the table gives every change in dB)."),
                   whatif_html, _whatif_commands, cost=1),
    "modes": Step("Rigid-body modes", _modes_options, _modes_run,
                  _own_plot("Kinetic-energy distribution of each mode over the six "
                            "coordinates."), modes_html, _modes_commands, cost=0),
    "transient": Step("Transient manoeuvres: starts, stops, tip-ins", _transient_options,
                      _transient_run,
                      _own_plot("Crank speed and torque over the manoeuvre above the seat's "
                                "(else the mounts') accelerations, peaks marked."),
                      transient_html, _transient_commands, cost=1),
}
