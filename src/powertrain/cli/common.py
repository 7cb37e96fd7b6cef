"""Shared CLI helpers: parsing of frequency lists and ranges, output of tables."""

from __future__ import annotations

import contextlib
import math

import click
import numpy as np

from powertrain.analysis.text_table import format_table  # noqa: F401 (re-export)
from powertrain.errors import InputError, require_finite, solved  # noqa: F401 (re-export)

#: Names of :mod:`powertrain.workflows.runup` the commands import from here (loaded lazily:
#: ``powertrain --help`` imports no solver).
_RUNUP_NAMES = ("MAX_SPEEDS", "checked_runup", "require_finite", "solved")


def __getattr__(name):
    if name in _RUNUP_NAMES:
        from powertrain.workflows import runup
        return getattr(runup, name)
    raise AttributeError(name)

#: Most frequencies one option may ask for, and the highest frequency [Hz] (a mount model
#: fitted below 1 kHz says nothing at 100 kHz; the limits keep a typo from hanging the run).
MAX_FREQUENCIES = 100_000
MAX_FREQUENCY_HZ = 1e5


def parse_frequencies(text: str, option: str = "--freq") -> np.ndarray:
    """``5,10,12`` or ``start:stop:step`` (inclusive) or a mix, e.g. ``1:10:1,20,40`` [Hz]."""
    arr = _parse_list(text, option, "frequency", "5,10,20 or 1:400:1", MAX_FREQUENCIES)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0) or np.any(arr > MAX_FREQUENCY_HZ):
        raise InputError(f"frequencies must be finite, >= 0 and <= {MAX_FREQUENCY_HZ:g} Hz",
                         key=option)
    if np.any(np.diff(arr) <= 0):
        raise InputError("frequencies must be strictly increasing", key=option)
    return arr


def parse_speeds(text: str, option: str = "--rpm") -> np.ndarray:
    """Speeds [rpm] as a comma list or ``start:stop:step`` (inclusive) or a mix, e.g.
    ``1000:6000:500`` or ``1500,3000``; finite, > 0, strictly increasing."""
    from powertrain.workflows.runup import MAX_SPEEDS
    arr = _parse_list(text, option, "speed", "1000,2000 or 1000:6000:500", MAX_SPEEDS)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise InputError("speeds must be finite and > 0 [rpm]", key=option)
    if np.any(np.diff(arr) <= 0):
        raise InputError("speeds must be strictly increasing", key=option)
    return arr


def _parse_list(text: str, option: str, noun: str, example: str, most: int) -> np.ndarray:
    """Numbers of a comma list whose items may be ``start:stop:step`` ranges (inclusive);
    at most ``most`` of them, at least one."""
    values: list[float] = []
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        try:
            if ":" in part:
                fields = [float(x) for x in part.split(":")]
                if len(fields) != 3 or fields[2] <= 0 or fields[1] < fields[0]:
                    raise ValueError
                start, stop, step = fields
                if not all(math.isfinite(x) for x in fields):
                    raise ValueError
                ratio = (stop - start) / step
                if not math.isfinite(ratio) or ratio + 1 + len(values) > most:
                    raise InputError(f"{part!r} asks for {ratio + 1:.3g} values; at most "
                                     f"{most}", key=option)
                n = math.floor(ratio + 1e-9) + 1
                values.extend(start + step * np.arange(n))
            else:
                values.append(float(part))
        except InputError:
            raise
        except ValueError:
            raise InputError(f"cannot read {noun} {part!r} (use {example})",
                             key=option) from None
    arr = np.array(values, dtype=float)
    if arr.size == 0:
        raise InputError(f"no {noun} given", key=option)
    if arr.size > most:
        raise InputError(f"{arr.size} values; at most {most}", key=option)
    return arr


def speed_options(func):
    """The ``--from/--to/--step`` speed-step options [rpm] shared by the run-up commands."""
    for option in reversed([
        click.option("--from", "rpm_from", type=float, default=1000.0, show_default=True,
                     help="First speed step [rpm]."),
        click.option("--to", "rpm_to", type=float, default=6000.0, show_default=True,
                     help="Last speed step [rpm]."),
        click.option("--step", "rpm_step", type=float, default=500.0, show_default=True,
                     help="Speed step [rpm]."),
    ]):
        func = option(func)
    return func


def speed_steps(rpm_from: float, rpm_to: float, rpm_step: float) -> np.ndarray:
    """Validated speed steps [rpm] from the ``--from/--to/--step`` options."""
    from powertrain.workflows.runup import MAX_SPEEDS, default_rpm
    for value, key in ((rpm_from, "--from"), (rpm_to, "--to"), (rpm_step, "--step")):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"must be a finite speed > 0 [rpm], got {value:g}", key=key)
    if rpm_to < rpm_from:
        raise InputError(f"{rpm_to:g} rpm is below --from {rpm_from:g} rpm", key="--to")
    ratio = (rpm_to - rpm_from) / rpm_step
    if not math.isfinite(ratio) or ratio + 1 > MAX_SPEEDS:
        raise InputError(f"{ratio + 1:.3g} speed steps from --from/--to/--step; at most {MAX_SPEEDS}",
                         key="--step")
    return default_rpm(rpm_from, rpm_to, rpm_step)


def check_outputs(**targets) -> None:
    """Refuse, before any work, output paths that cannot be written (``--name=path``)."""
    from powertrain.outputs import check_writable
    for name, path in targets.items():
        if path:
            check_writable(path, key=f"--{name.replace('_', '-')}")


def runup_settings(engine, rpm: np.ndarray, angle_step: float) -> None:
    """:func:`powertrain.workflows.runup.check_runup_settings` (speeds, crank-angle step)."""
    from powertrain.workflows.runup import check_runup_settings
    check_runup_settings(engine, rpm, angle_step)


def checked_runup(engine, engine_path, run, *args, **kwargs):
    """:func:`powertrain.workflows.runup.checked_runup` (a run-up, checked finite)."""
    from powertrain.workflows.runup import checked_runup as checked
    return checked(engine, engine_path, run, *args, **kwargs)


def write_json(path, text: str, provenance: dict, key: str = "--json") -> None:
    """Write a result's JSON ``text`` with a ``provenance`` key added, atomically; a result
    with a non-finite number is refused (no NaN in an output file)."""
    import json

    from powertrain.outputs import atomic_write
    doc = json.loads(text)
    doc["provenance"] = provenance
    try:
        out = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    except ValueError:
        raise InputError("the result holds a non-finite number (NaN or inf); not written",
                         file=path, key=key) from None
    with atomic_write(path) as fh:
        fh.write(out)


# ------------------------------------------------------------------ figures
def use_agg() -> None:
    """Select matplotlib's file-only Agg backend: the CLI draws no windows. Only the CLI
    does this; the library never switches the backend."""
    import matplotlib
    matplotlib.use("Agg")


def cli_provenance(engine: str = ""):
    """:class:`~powertrain.provenance.Provenance` of this command: the command line as given,
    ``engine`` (what ran), version and time."""
    from powertrain.provenance import Provenance, command_line
    return Provenance.now(command=command_line(), engine=engine)


def engine_description(engine, path, *, no_balancers=False, effects=()) -> str:
    """``name (file)`` plus what the command line changed (balancers off, effects)."""
    import os
    try:
        rel = os.path.relpath(str(path))
    except ValueError:          # another drive (Windows)
        rel = ".."
    shown = rel if not rel.startswith("..") else os.path.basename(str(path))
    text = f"{engine.name} ({shown})"
    if no_balancers:
        text += ", balancers off"
    if effects:
        text += ", effects " + " ".join(effects)
    return text


def write_plot(draw, path) -> None:
    """Draw a figure with ``draw(path)`` (a result's ``plot``) under the Agg backend, then
    release it."""
    use_agg()
    from powertrain.plotting.style import close_figure
    close_figure(draw(path))


def plot_form_options(func):
    """``--form`` and ``--freq-axis`` of the dynamic-stiffness plots."""
    for option in reversed([
        click.option("--form", type=click.Choice(["magnitude-phase", "real-imag"]),
                     default="magnitude-phase", show_default=True,
                     help="Plot form: |K*| and loss angle (datasheets, ISO 10846) or real "
                          "and imaginary part (the thesis)."),
        click.option("--freq-axis", type=click.Choice(["log", "linear"]), default="log",
                     show_default=True, help="Frequency axis of the plot."),
    ]):
        func = option(func)
    return func


@contextlib.contextmanager
def terminate_as_exit():
    """Turn SIGTERM (``kill PID``) into ``SystemExit(143)`` while a command runs, so that its
    staged outputs and temporary files are removed as on any other failure (main thread
    only; other signals keep their handlers)."""
    import signal
    import threading
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def stop(signum, frame):
        raise SystemExit(128 + signum)
    old = signal.signal(signal.SIGTERM, stop)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)
