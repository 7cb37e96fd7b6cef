"""Measured dynamic stiffness tables: CSV in datasheet units, converted to SI here.

Format (comma-separated, one header line, ``#`` comment lines and blank lines ignored,
extra columns ignored)::

    frequency_hz,k_real_n_per_mm,k_imag_n_per_mm
    1,241.7,13.2
    ...

or, instead of the real and imaginary parts, magnitude and phase (loss angle)::

    frequency_hz,k_abs_n_per_mm,phase_deg

``frequency_hz`` [Hz] must be finite, non-negative and strictly increasing; stiffness in
N/mm, phase in degrees. When both pairs are present the real/imaginary pair is used. The
output of ``powertrain stiffness --format csv`` is a valid input. Every problem raises
:class:`powertrain.errors.InputError` naming the file, the column and (for values) the line.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.textfile import parse_number, read_text
from powertrain.units import to_si

FREQUENCY = "frequency_hz"
REAL, IMAG = "k_real_n_per_mm", "k_imag_n_per_mm"
ABS, PHASE = "k_abs_n_per_mm", "phase_deg"


@dataclass(frozen=True)
class MeasuredStiffness:
    """A measured cross-point dynamic stiffness curve.

    Attributes
    ----------
    frequency_hz : ndarray
        [Hz], strictly increasing.
    kcp : ndarray of complex
        Cross-point dynamic stiffness [N/m].
    source : str
        File it was read from.
    """

    frequency_hz: np.ndarray
    kcp: np.ndarray
    source: str = ""

    def select(self, fmin=None, fmax=None) -> MeasuredStiffness:
        """The points with ``fmin <= f <= fmax`` [Hz] (either bound optional)."""
        keep = np.ones(self.frequency_hz.size, bool)
        if fmin is not None:
            keep &= self.frequency_hz >= fmin
        if fmax is not None:
            keep &= self.frequency_hz <= fmax
        return MeasuredStiffness(self.frequency_hz[keep], self.kcp[keep], self.source)


#: Plausible magnitudes: frequency [Hz], stiffness [N/mm] (a steel bar is ~1e6 N/mm), phase
#: [deg]; beyond them a value is a unit or export error.
LIMITS = {FREQUENCY: 1e5, REAL: 1e9, IMAG: 1e9, ABS: 1e9, PHASE: 360.0}


def _open_rows(path):
    text = read_text(path, "CSV")
    rows = []
    try:
        parsed = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise InputError(f"not a CSV table ({exc})", file=path) from None
    for lineno, fields in zip(range(1, 10**9), parsed):
        if not fields or all(not f.strip() for f in fields) or fields[0].lstrip().startswith("#"):
            continue
        rows.append((lineno, [f.strip() for f in fields]))
    return rows


def read_stiffness_csv(path) -> MeasuredStiffness:
    """Read a measured K*(f) table (see the module docstring) into SI.

    Parameters
    ----------
    path : str or path-like
        CSV file.

    Returns
    -------
    MeasuredStiffness
        Frequencies [Hz] and complex stiffness [N/m].

    Raises
    ------
    InputError
        Unreadable file, missing or duplicated column, wrong number of fields, a value that
        is not a finite number, negative frequency or magnitude, frequencies not strictly
        increasing, no data rows.
    """
    path = str(path)
    rows = _open_rows(path)
    if not rows:
        raise InputError("empty file, expected a header line", file=path, key=FREQUENCY)
    header_line, header = rows[0]
    pair, polar = _columns(header, header_line, path)
    data = _values(rows[1:], header, [FREQUENCY, *pair], path)
    f = np.array(data[FREQUENCY])
    a = np.array(data[pair[0]])
    b = np.array(data[pair[1]])
    if polar:
        mag = to_si(a, "N/mm", "stiffness")
        kcp = mag * np.exp(1j * to_si(b, "deg", "angle"))
    else:
        kcp = to_si(a, "N/mm", "stiffness") + 1j * to_si(b, "N/mm", "stiffness")
    return MeasuredStiffness(f, kcp, path)


def _columns(header, header_line, path):
    """``(pair, polar)``: the two stiffness columns of the header and whether they are
    magnitude and phase."""
    seen = set()
    for name in header:
        if name in seen:
            raise InputError("duplicated column", file=path, key=name, line=header_line)
        seen.add(name)
    if FREQUENCY not in header:
        raise InputError("missing column", file=path, key=FREQUENCY, line=header_line)
    if REAL in header or IMAG in header:
        pair, polar = (REAL, IMAG), False
    elif ABS in header or PHASE in header:
        pair, polar = (ABS, PHASE), True
    else:
        raise InputError(f"missing column (give {REAL},{IMAG} or {ABS},{PHASE})",
                         file=path, key=REAL, line=header_line)
    for name in pair:
        if name not in header:
            raise InputError("missing column", file=path, key=name, line=header_line)
    return pair, polar


def _values(rows, header, cols, path) -> dict:
    """Column name -> list of numbers (file units) of the data ``rows``, checked."""
    index = {name: header.index(name) for name in cols}
    data = {name: [] for name in cols}
    for lineno, fields in rows:
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields, got {len(fields)}",
                             file=path, key=FREQUENCY, line=lineno)
        for name in cols:
            raw = fields[index[name]]
            value = parse_number(raw, path, lineno, name, nonneg=name in (FREQUENCY, ABS))
            if data[FREQUENCY] and name == FREQUENCY and value <= data[FREQUENCY][-1]:
                raise InputError(f"frequencies must be strictly increasing ({raw} after "
                                 f"{data[FREQUENCY][-1]:g})", file=path, key=name,
                                 line=lineno)
            limit = LIMITS.get(name)
            if limit is not None and abs(value) > limit:
                raise InputError(f"|{raw}| above the plausible {limit:g}", file=path,
                                 key=name, line=lineno)
            data[name].append(value)
    if not data[FREQUENCY]:
        raise InputError("no data rows", file=path, key=FREQUENCY)
    return data
