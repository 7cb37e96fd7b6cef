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
    for value, key in ((rpm_from, "--from"), (rpm_to, "--to"), (rpm_step, "--step")):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"must be a finite speed > 0 [rpm], got {value:g}", key=key)
    if rpm_to < rpm_from:
        raise InputError(f"{rpm_to:g} rpm is below --from {rpm_from:g} rpm", key="--to")
    n = math.floor((rpm_to - rpm_from) / rpm_step + 1e-9) + 1
    if n > MAX_SPEEDS:
        raise InputError(f"{n:.3g} speed steps from --from/--to/--step; at most {MAX_SPEEDS}",
                         key="--step")
    return default_rpm(rpm_from, rpm_to, rpm_step)


#: Largest speed grid a run-up command accepts (about 0.1 s per speed step).
MAX_SPEEDS = 2000
#: Finest crank-angle step [deg] of the Newmark stepper (720 / 0.05 = 14 400 steps a cycle).
MIN_ANGLE_STEP_DEG = 0.05


def check_outputs(**targets) -> None:
    """Refuse, before any work, output paths that cannot be written (``--name=path``)."""
    from powertrain.iotools.atomic import check_writable
    for name, path in targets.items():
        if path:
            check_writable(path, key=f"--{name.replace('_', '-')}")


def runup_settings(engine, rpm: np.ndarray, angle_step: float) -> None:
    """Check a run-up's speeds against the engine's range and the crank-angle step, naming
    the option at fault."""
    lo, hi = engine.speed_range_rpm()
    if rpm[0] < lo - 1e-6:
        raise InputError(f"{rpm[0]:g} rpm is below the engine's range {lo:g}..{hi:g} rpm",
                         key="--from")
    if rpm[-1] > hi + 1e-6:
        raise InputError(f"{rpm[-1]:g} rpm is above the engine's range {lo:g}..{hi:g} rpm",
                         key="--to")
    n_cycle = 720.0 / angle_step if math.isfinite(angle_step) and angle_step > 0 else 0.0
    if not (angle_step >= MIN_ANGLE_STEP_DEG and abs(n_cycle - round(n_cycle)) < 1e-9
            and round(n_cycle) % 2 == 0):
        raise InputError(f"{angle_step:g} deg: must divide 720 deg into an even number of "
                         f"steps and be >= {MIN_ANGLE_STEP_DEG:g} deg (e.g. 0.5, 1, 2)",
                         key="--angle-step")


def write_json(path, text: str, provenance: dict, key: str = "--json") -> None:
    """Write a result's JSON ``text`` with a ``provenance`` key added, atomically; a result
    with a non-finite number is refused (no NaN in an output file)."""
    import json

    from powertrain.iotools.atomic import atomic_write
    doc = json.loads(text)
    doc["provenance"] = provenance
    try:
        out = json.dumps(doc, indent=1, allow_nan=False) + "\n"
    except ValueError:
        raise InputError("the result holds a non-finite number (NaN or inf); not written",
                         file=path, key=key) from None
    with atomic_write(path) as fh:
        fh.write(out)
