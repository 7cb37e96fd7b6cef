"""Shared CLI helpers: the speed-step options, output checks, JSON and figure writing
(the speed and frequency parsers are :mod:`powertrain.workflows.arguments`)."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import threading
import warnings
from pathlib import Path

import click

from powertrain.errors import InputError, PowertrainWarning
from powertrain.outputs import check_writable, json_text
from powertrain.plotting.style import close_figure
from powertrain.provenance import Provenance, command_line


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


#: What ``--quiet`` means on every command.
QUIET_HELP = "Print nothing but errors (on stderr): no progress, no table, no warnings, no " \
             "list of files written."


def _silence_warnings(ctx, param, quiet):
    """While the command runs: ``--quiet`` ignores warnings; else the package's own print as
    one line ``warning: ...``."""
    ctx.with_resource(warnings.catch_warnings())
    if quiet:
        warnings.simplefilter("ignore")
    else:
        warnings.simplefilter("default", PowertrainWarning)
        warnings.showwarning = _one_line(warnings.showwarning)
    return quiet


def _one_line(default):
    """A ``warnings.showwarning`` that prints the package's warnings as one line."""
    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, PowertrainWarning):
            click.echo(f"warning: {message}", err=True)
        else:
            default(message, category, filename, lineno, file, line)
    return show


def quiet_option(func):
    """The ``--quiet`` flag of every command (:data:`QUIET_HELP`)."""
    return click.option("--quiet", is_flag=True, help=QUIET_HELP, callback=_silence_warnings)(func)


def say(text: str, quiet: bool, **kwargs) -> None:
    """Print ``text`` (``click.echo``) unless ``quiet``."""
    if not quiet:
        click.echo(text, **kwargs)


def wrote(*paths) -> str:
    """``wrote A, B``: the line naming the files a command wrote (empty paths skipped)."""
    return "wrote " + ", ".join(str(p) for p in paths if p)


def check_outputs(**targets) -> None:
    """Refuse, before any work, unwritable output paths (``--name=path``) and two options naming
    the same file."""
    seen = {}
    for name, path in targets.items():
        if path:
            key = f"--{name.replace('_', '-')}"
            check_writable(path, key=key)
            same = seen.setdefault(Path(path).resolve(), key)
            if same != key:
                raise InputError(f"{path} is also the {same} file (one file per output)", key=key)


def write_json(path, text: str, provenance: dict, key: str = "--json") -> None:
    """Write a result's JSON ``text`` with a ``provenance`` key added, atomically (NaN refused)."""
    doc = json.loads(text)
    doc["provenance"] = provenance
    json_text(doc, path, key=key)


# ------------------------------------------------------------------ figures
def use_agg() -> None:
    """Select matplotlib's file-only Agg backend (the CLI only; the library never switches it)."""
    import matplotlib  # deferred: heavy package, loaded only when a figure is drawn
    matplotlib.use("Agg")


def cli_provenance(engine: str = ""):
    """:class:`~powertrain.provenance.Provenance` of this command line and ``engine`` (what ran)."""
    return Provenance.now(command=command_line(), engine=engine)


def engine_description(engine, path, *, no_balancers=False, effects=()) -> str:
    """``name (file)`` plus what the command line changed (balancers off, effects)."""
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


def write_plot(draw, path) -> list:
    """Draw a figure with ``draw(path)`` under the Agg backend and release it; returns the files
    written (``path`` and any further ``pages``)."""
    use_agg()
    fig = draw(path)
    close_figure(fig)
    return list(getattr(fig, "pages", None) or [path])


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
    """Turn SIGTERM into ``SystemExit(143)`` while a command runs (main thread only), so that
    its staged outputs are removed as on any other failure."""
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
