"""Wide CSV of raw run-up time data: a ``time [s]`` column, optional ``rpm``, ``tacho`` and
``cycle`` columns, one column per channel ``MOUNT[.SIDE].DIRECTION [UNIT]``
(docs/reference/raw-data.md); ``#`` comment lines are kept (a SYNTHETIC label)."""

from __future__ import annotations

import io

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.channel_map import split_unit
from powertrain.iotools.raw_signals import FileSignals, written_signals
from powertrain.iotools.textfile import read_text
from powertrain.outputs import atomic_write
from powertrain.units import to_si


def read_csv_signals(path, channel_map=None) -> FileSignals:
    """Signals of a wide CSV file (docs/reference/raw-data.md)."""
    text = read_text(path, "CSV")
    comments, header, start = [], None, 0
    lines = text.splitlines()
    for i, raw in enumerate(lines):
        s = raw.strip()
        if not s:
            continue
        if s.startswith("#"):
            comments.append(s[1:].strip())
            continue
        header = [h.strip() for h in s.split(",")]
        start = i + 1
        break
    if header is None:
        raise InputError("no header line (expected 'time [s],...')", file=path)
    for name in header:
        if header.count(name) > 1:
            raise InputError("column appears twice", file=path, line=start, key=name)
    time_name = (channel_map.time if channel_map is not None and channel_map.time else "time")
    tcol = [k for k, h in enumerate(header) if split_unit(h)[0].lower() == time_name.lower()
            or h == time_name]
    if not tcol:
        raise InputError(f"header lacks a '{time_name} [s]' column (is this a wide raw CSV? "
                         "order curves go to 'compare', not 'track')", file=path, line=start, key="time")
    data = _numbers(lines, start, len(header), path)
    tname = header[tcol[0]]
    time = to_si(data[:, tcol[0]], split_unit(tname)[1] or "s", "time", file=path, key=tname)
    signals = [(h, data[:, k], split_unit(h)[1]) for k, h in enumerate(header) if k != tcol[0]]
    return FileSignals(time, signals, str(path), tname, comments)


def _numbers(lines, start, n_cols, path):
    body = "\n".join(ln for ln in lines[start:] if ln.strip() and not ln.lstrip().startswith("#"))
    if not body:
        raise InputError("no data rows", file=path)
    try:
        data = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, dtype=float)
    except ValueError:
        data = None
    if data is None or data.shape[1] != n_cols:
        for lineno, raw in enumerate(lines[start:], start=start + 1):
            s = raw.strip()
            if not s or s.startswith("#"):
                continue
            fields = s.split(",")
            if len(fields) != n_cols:
                raise InputError(f"{len(fields)} fields, header has {n_cols}", file=path, line=lineno)
            for k, f in enumerate(fields):
                try:
                    float(f)
                except ValueError:
                    raise InputError(f"not a number: {f.strip()!r}", file=path, line=lineno,
                                     key=f"column {k + 1}") from None
        raise InputError("cannot read the data rows", file=path)
    return data


def write_raw_csv(path, recording, *, comment: str = "") -> None:
    """Write a :class:`RawRecording` as a wide CSV in its channels' file units (time to 15
    significant digits, to stay uniform however late it starts; values to 9)."""
    signals = written_signals(recording)
    names = ["time [s]"] + [f"{name} [{'1/min' if name == 'rpm' else unit}]" for name, _, unit, _ in signals]
    with atomic_write(path) as fh:
        for line in (comment.splitlines() if comment else []):
            fh.write(f"# {line}\n")
        fh.write(",".join(names) + "\n")
        np.savetxt(fh, np.column_stack([recording.time] + [v for _, v, _, _ in signals]),
                   delimiter=",", fmt=["%.15g"] + ["%.9g"] * len(signals))
