"""Shared CLI helpers: parsing of frequency lists and ranges, output of tables."""

from __future__ import annotations

import math

import click
import numpy as np

from powertrain.errors import InputError


def parse_frequencies(text: str, option: str = "--freq") -> np.ndarray:
    """``5,10,12`` or ``start:stop:step`` (inclusive) or a mix, e.g. ``1:10:1,20,40`` [Hz]."""
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
                n = int(math.floor((stop - start) / step + 1e-9)) + 1
                values.extend(start + step * np.arange(n))
            else:
                values.append(float(part))
        except ValueError:
            raise InputError(f"cannot read frequency {part!r} (use 5,10,20 or 1:400:1)",
                             key=option) from None
    arr = np.array(values, dtype=float)
    if arr.size == 0:
        raise InputError("no frequency given", key=option)
    if not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise InputError("frequencies must be finite and >= 0", key=option)
    if np.any(np.diff(arr) <= 0):
        raise InputError("frequencies must be strictly increasing", key=option)
    return arr


def format_table(header: list[str], rows: list[list], floatfmt: str = "{:.4g}") -> str:
    """Fixed-width text table."""
    cells = [[floatfmt.format(v) if isinstance(v, float) else str(v) for v in row]
             for row in rows]
    widths = [max(len(h), *(len(r[i]) for r in cells)) if cells else len(h)
              for i, h in enumerate(header)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths)),
             "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)


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
    from powertrain.runup import default_rpm
    if not (math.isfinite(rpm_from + rpm_to + rpm_step) and rpm_from > 0
            and rpm_to >= rpm_from and rpm_step > 0):
        raise InputError("need 0 < --from <= --to and --step > 0", key="--from/--to/--step")
    return default_rpm(rpm_from, rpm_to, rpm_step)


# ------------------------------------------------------------------ figures
def use_agg() -> None:
    """Select matplotlib's file-only Agg backend: the CLI draws no windows. Only the CLI
    does this; the library never switches the backend."""
    import matplotlib
    matplotlib.use("Agg")


def cli_provenance(engine: str = ""):
    """:class:`~powertrain.provenance.Provenance` of this command: the command line as given,
    ``engine`` (what ran), version and time."""
    import shlex
    import sys

    from powertrain.cli import ARGV_KEY
    from powertrain.provenance import Provenance
    ctx = click.get_current_context(silent=True)
    argv = ctx.meta.get(ARGV_KEY) if ctx is not None else None
    if argv is None:
        argv = sys.argv[1:]
    return Provenance.now(command="powertrain " + shlex.join(str(a) for a in argv),
                          engine=engine)


def engine_description(engine, path, *, no_balancers=False, effects=()) -> str:
    """``name (file)`` plus what the command line changed (balancers off, effects)."""
    import os
    rel = os.path.relpath(str(path))
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
