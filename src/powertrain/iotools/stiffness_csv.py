"""Measured dynamic stiffness tables K*(f) (``fit-mount`` input, docs/reference/csv-formats.md):
CSV in datasheet units into SI, optionally one block of rows per test amplitude (Kovarik 2016
Fig. 14).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.textfile import parse_number, read_text
from powertrain.units import to_si

FREQUENCY = "frequency_hz"
AMPLITUDE = "amplitude_mm"
REAL, IMAG = "k_real_n_per_mm", "k_imag_n_per_mm"
ABS, PHASE = "k_abs_n_per_mm", "phase_deg"


@dataclass(frozen=True)
class MeasuredStiffness:
    """A measured cross-point dynamic stiffness curve: ``frequency_hz`` [Hz], strictly
    increasing; ``kcp`` the complex stiffness [N/m]; ``source`` the file read."""

    frequency_hz: np.ndarray
    kcp: np.ndarray
    source: str = ""
    #: Test amplitude of each point [m] (multi-amplitude data), None without that column.
    amplitude_m: np.ndarray | None = None
    #: A comment line of the file says the data are synthetic (figures mark them SYNTHETIC).
    synthetic: bool = False

    def select(self, fmin=None, fmax=None) -> MeasuredStiffness:
        """The points with ``fmin <= f <= fmax`` [Hz] (either bound optional)."""
        keep = np.ones(self.frequency_hz.size, bool)
        if fmin is not None:
            keep &= self.frequency_hz >= fmin
        if fmax is not None:
            keep &= self.frequency_hz <= fmax
        amp = None if self.amplitude_m is None else self.amplitude_m[keep]
        return MeasuredStiffness(self.frequency_hz[keep], self.kcp[keep], self.source, amp, self.synthetic)

    @property
    def amplitudes(self) -> np.ndarray:
        """The distinct test amplitudes [m], increasing (empty without the column)."""
        return np.zeros(0) if self.amplitude_m is None else np.unique(self.amplitude_m)

    def at(self, amplitude) -> MeasuredStiffness:
        """The curve measured at one test ``amplitude`` [m] (one of :attr:`amplitudes`)."""
        keep = self.amplitude_m == amplitude
        return MeasuredStiffness(self.frequency_hz[keep], self.kcp[keep], self.source,
                                 self.amplitude_m[keep], self.synthetic)


#: Plausible magnitudes: frequency [Hz], stiffness [N/mm] (a steel bar is ~1e6 N/mm), phase
#: [deg]; beyond them a value is a unit or export error.
LIMITS = {FREQUENCY: 1e5, REAL: 1e9, IMAG: 1e9, ABS: 1e9, PHASE: 360.0, AMPLITUDE: 1e3}


def _open_rows(path):
    """The data rows (line number, fields) and whether a comment says "synthetic"."""
    text = read_text(path, "CSV")
    rows, synthetic = [], False
    try:
        parsed = list(csv.reader(text.splitlines()))
    except csv.Error as exc:
        raise InputError(f"not a CSV table ({exc})", file=path) from None
    for lineno, fields in zip(range(1, 10**9), parsed):
        if fields and fields[0].lstrip().startswith("#"):
            synthetic = synthetic or "synthetic" in ",".join(fields).lower()
            continue
        if not fields or all(not f.strip() for f in fields):
            continue
        rows.append((lineno, [f.strip() for f in fields]))
    return rows, synthetic


def read_stiffness_csv(path) -> MeasuredStiffness:
    """Read a measured K*(f) table (docs/reference/csv-formats.md) into SI.

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
        Naming file, column and line of the first problem.
    """
    path = str(path)
    rows, synthetic = _open_rows(path)
    if not rows:
        raise InputError("empty file, expected a header line", file=path, key=FREQUENCY)
    header_line, header = rows[0]
    pair, polar = _columns(header, header_line, path)
    amp = [AMPLITUDE] if AMPLITUDE in header else []
    data = _values(rows[1:], header, [*amp, FREQUENCY, *pair], path)
    f, a, b = (np.array(data[name]) for name in (FREQUENCY, *pair))
    if polar:
        mag = to_si(a, "N/mm", "stiffness")
        kcp = mag * np.exp(1j * to_si(b, "deg", "angle"))
    else:
        kcp = to_si(a, "N/mm", "stiffness") + 1j * to_si(b, "N/mm", "stiffness")
    amplitude = to_si(np.array(data[AMPLITUDE]), "mm", "length") if amp else None
    return MeasuredStiffness(f, kcp, path, amplitude, synthetic)


def _columns(header, header_line, path):
    """``(pair, polar)``: the two stiffness columns and whether they are magnitude, phase."""
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
    blocks = _Blocks(path)
    for lineno, fields in rows:
        if len(fields) != len(header):
            raise InputError(f"expected {len(header)} fields, got {len(fields)}",
                             file=path, key=FREQUENCY, line=lineno)
        for name in cols:
            raw = fields[index[name]]
            value = parse_number(raw, path, lineno, name, nonneg=name in (FREQUENCY, ABS))
            if name == AMPLITUDE:
                blocks.start(value, lineno)
            elif name == FREQUENCY:
                blocks.check(value, raw, lineno)
            limit = LIMITS.get(name)
            if limit is not None and abs(value) > limit:
                raise InputError(f"|{raw}| above the plausible {limit:g}", file=path, key=name, line=lineno)
            data[name].append(value)
    if not data[FREQUENCY]:
        raise InputError("no data rows", file=path, key=FREQUENCY)
    return data


class _Blocks:
    """Frequencies strictly increasing within each block of one amplitude (> 0)."""

    def __init__(self, path):
        self.path, self.seen, self.last = path, [], None

    def start(self, amplitude, lineno) -> None:
        if amplitude <= 0:
            raise InputError(f"amplitude must be > 0, got {amplitude:g}", file=self.path,
                             key=AMPLITUDE, line=lineno)
        if self.seen and amplitude == self.seen[-1]:
            return
        if amplitude in self.seen:
            raise InputError(f"amplitude {amplitude:g} mm again after other amplitudes "
                             "(one block of rows per amplitude)", file=self.path, key=AMPLITUDE, line=lineno)
        self.seen.append(amplitude)
        self.last = None

    def check(self, frequency, raw, lineno) -> None:
        if self.last is not None and frequency <= self.last:
            raise InputError(f"frequencies must be strictly increasing ({raw} after "
                             f"{self.last:g})", file=self.path, key=FREQUENCY, line=lineno)
        self.last = frequency
