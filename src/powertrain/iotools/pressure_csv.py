"""Measured cylinder-pressure traces (``[combustion] model = "measured"``): a CSV with units
(docs/reference/csv-formats.md), each trace one 720° cycle resampled by periodic linear
interpolation onto a common grid on [-π, 3π). Errors name the file, line and column.
"""

from __future__ import annotations

import csv
import math
import re

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.textfile import parse_number, read_text
from powertrain.models.combustion import MeasuredPressure
from powertrain.units import to_si

#: Largest allowed gap between crank angles of one trace [deg].
MAX_GAP_DEG = 10.0
#: Highest plausible cylinder pressure [Pa] (1000 bar; peak firing pressures are ~200 bar).
MAX_PRESSURE_PA = 1e8
#: Points per cycle of the common grid.
GRID_POINTS = 2880

_COLUMNS = (("speed", "angular_speed"), ("cylinder", None), ("crank_angle", "angle"),
            ("pressure", "pressure"))
_HEADER = re.compile(r"^\s*([a-z_]+)\s*(?:\[\s*([^\]]+?)\s*\])?\s*$")


def read_pressure_traces(path, n_cylinders: int):
    """Read a pressure-trace CSV into a :class:`~powertrain.models.combustion.MeasuredPressure`.

    Parameters
    ----------
    path : str or Path
    n_cylinders : int
        Number of cylinders the engine has.
    """
    path = str(path)
    lines = list(enumerate(read_text(path, "CSV").splitlines(), start=1))
    body = [(n, s) for n, s in lines if s.strip() and not s.lstrip().startswith("#")]
    if not body:
        raise InputError("no header line", file=path)
    units = _header_units(*body[0], path)
    rows = [_row(n, s, path, n_cylinders) for n, s in body[1:]]
    if not rows:
        raise InputError("no data rows", file=path)
    data = np.array([r[1:] for r in rows], dtype=float)
    line_no = np.array([r[0] for r in rows])
    speed = to_si(data[:, 0], units[0], "angular_speed", file=path, key="speed")
    angle = to_si(data[:, 2], units[2], "angle", file=path, key="crank_angle")
    pressure = to_si(data[:, 3], units[3], "pressure", file=path, key="pressure")
    _check_ranges(speed, pressure, line_no, path)
    speeds = np.unique(speed)
    grid = -np.pi + 4 * np.pi * np.arange(GRID_POINTS) / GRID_POINTS
    out = np.empty((speeds.size, n_cylinders, GRID_POINTS))
    for i, w in enumerate(speeds):
        for c in range(1, n_cylinders + 1):
            sel = (speed == w) & (data[:, 1] == c)
            if not np.any(sel):
                raise InputError(f"no trace for cylinder {c} at {w * 60 / (2 * np.pi):.6g} rpm",
                                 file=path, key="cylinder")
            _check_trace(angle[sel], line_no[sel], c, w, path)
            out[i, c - 1] = np.interp(grid, angle[sel], pressure[sel], period=4 * np.pi)
    return MeasuredPressure(file=path, speed=speeds, pressure=out, theta=grid)


def _header_units(hline, header, path) -> list:
    """Units of the four columns (None for ``cylinder``)."""
    names = next(csv.reader([header]))
    if len(names) != 4:
        raise InputError("expected 4 columns: speed [unit], cylinder, crank_angle [unit], "
                         "pressure [unit]", file=path, line=hline)
    units = []
    for (want, dim), cell in zip(_COLUMNS, names):
        m = _HEADER.match(cell)
        if not m or m.group(1) != want:
            raise InputError(f"expected column {want!r}, got {cell.strip()!r}", file=path,
                             line=hline, key=want)
        if dim is not None and not m.group(2):
            raise InputError("column must declare its unit in brackets, e.g. "
                             f"'{want} [..]'", file=path, line=hline, key=want)
        units.append(m.group(2))
    return units


def _row(n, text, path, n_cylinders) -> tuple:
    """``(line, speed, cylinder, crank_angle, pressure)`` of a data line (file units)."""
    cells = next(csv.reader([text]))
    if len(cells) != 4:
        raise InputError(f"expected 4 values, got {len(cells)}", file=path, line=n)
    vals = [parse_number(c, path, n, name) for (name, _), c in zip(_COLUMNS, cells)]
    if vals[1] != int(vals[1]) or not 1 <= vals[1] <= n_cylinders:
        raise InputError(f"cylinder must be 1..{n_cylinders}", file=path, line=n, key="cylinder")
    if vals[3] < 0:
        raise InputError("absolute pressure must not be negative", file=path, line=n, key="pressure")
    return (n, *vals)


def _check_ranges(speed, pressure, line_no, path) -> None:
    """Speeds 1..1e5 rpm, pressures below :data:`MAX_PRESSURE_PA` (SI inputs)."""
    rpm = speed * 60 / (2 * np.pi)
    bad_speed = (rpm < 1.0) | (rpm > 1e5)
    if np.any(bad_speed):
        raise InputError("speeds must be 1..1e5 rpm", file=path, key="speed",
                         line=int(line_no[np.argmax(bad_speed)]))
    if np.any(pressure > MAX_PRESSURE_PA):
        raise InputError(f"pressure above the plausible {MAX_PRESSURE_PA / 1e5:g} bar",
                         file=path, key="pressure", line=int(line_no[np.argmax(pressure > MAX_PRESSURE_PA)]))


def _check_trace(a, ln, c, w, path) -> None:
    """Trace angles ``a`` [rad] increasing within one cycle, gaps <= :data:`MAX_GAP_DEG`."""
    bad = np.nonzero(np.diff(a) <= 0)[0]
    if bad.size:
        raise InputError("crank angles must increase within a trace", file=path,
                         line=int(ln[bad[0] + 1]), key="crank_angle")
    if a[-1] - a[0] >= 4 * np.pi - 1e-9:
        raise InputError("trace covers more than one 720° cycle", file=path,
                         line=int(ln[-1]), key="crank_angle")
    gaps = np.append(np.diff(a), a[0] + 4 * np.pi - a[-1])
    if gaps.max() > math.radians(MAX_GAP_DEG) + 1e-12:
        raise InputError(f"trace has a gap over {MAX_GAP_DEG:g}° (cylinder {c}, "
                         f"{w * 60 / (2 * np.pi):.6g} rpm)", file=path, line=int(ln[0]), key="crank_angle")

