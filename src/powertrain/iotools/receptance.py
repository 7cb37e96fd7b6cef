r"""Measured body receptances for ``[chassis] model = "frf"`` (docs/guide/chassis.md): a CSV of
:data:`COLUMNS` with ``response``/``excitation`` = ``NAME.DIR``, or UFF 58 (function type 4,
m/N; points ``rsp_ent_name``/``ref_ent_name``, directions 1/2/3 = x/y/z, negative reversed).
Needed on one grid: every pair of mount directions (reciprocity fills H_ab from H_ba) and each
body point's response to them.
"""

from __future__ import annotations

from itertools import product

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.raw_uff import check_complete
from powertrain.iotools.textfile import check_regular_file, parse_number, read_text
from powertrain.models.chassis import MeasuredReceptance

COLUMNS = ("frequency_hz", "response", "excitation", "receptance_real_m_per_n", "receptance_imag_m_per_n")


class _Names(tuple):
    """The NAMEs a receptance file may use, and the file that defines them (``source``)."""

    def __new__(cls, names, source=""):
        self = super().__new__(cls, names)
        self.source = str(source)
        return self


def _channel(text, names, path, line, column):
    parts = text.strip().split(".")
    if len(parts) != 2 or parts[0] not in names or parts[1].lower() not in ("x", "y", "z"):
        where = f" (the mounts and [chassis] points of {names.source})" if names.source else ""
        raise InputError(f"expected NAME.DIR with NAME one of {', '.join(names)}{where} and "
                         f"DIR x/y/z, got {text.strip()!r}", file=path, line=line, key=column)
    return parts[0], parts[1].lower()


def read_receptance(path, mounts, points, defined_in="") -> MeasuredReceptance:
    """Read a receptance file (``.uff``/``.unv`` as UFF 58, else CSV) and check coverage
    (``defined_in``: the engine file naming the mounts and points, for messages)."""
    path = str(path)
    names = _Names(list(mounts) + list(points), defined_in)
    if path.lower().endswith((".uff", ".unv")):
        freq, values = _read_uff(path, names)
    else:
        freq, values = _read_csv(path, names)
    _check_coverage(values, mounts, points, path)
    return MeasuredReceptance(frequency_hz=freq, values=values, file=path)


def _read_csv(path, names):
    rows = [(i + 1, ln) for i, ln in enumerate(read_text(path, "CSV").splitlines())
            if ln.strip() and not ln.lstrip().startswith("#")]
    if not rows:
        raise InputError("empty receptance file", file=path)
    header = [h.strip() for h in rows[0][1].split(",")]
    if tuple(header) != COLUMNS:
        raise InputError(f"expected the columns {','.join(COLUMNS)}", file=path,
                         line=rows[0][0], key="header")
    data = {}
    for line, text in rows[1:]:
        cells = text.split(",")
        if len(cells) != len(COLUMNS):
            raise InputError(f"expected {len(COLUMNS)} cells", file=path, line=line)
        f = parse_number(cells[0], path, line, COLUMNS[0], nonneg=True)
        r = _channel(cells[1], names, path, line, COLUMNS[1])
        e = _channel(cells[2], names, path, line, COLUMNS[2])
        h = complex(parse_number(cells[3], path, line, COLUMNS[3]),
                    parse_number(cells[4], path, line, COLUMNS[4]))
        data.setdefault(r + e, []).append((f, h, line))
    return _to_grid(data, path)


def _to_grid(data, path):
    grid, values = None, {}
    for key, rows in data.items():
        f = np.array([r[0] for r in rows])
        if np.any(np.diff(f) <= 0):
            raise InputError(f"frequencies of {key[0]}.{key[1]} / {key[2]}.{key[3]} must be "
                             "strictly increasing", file=path, line=rows[0][2], key="frequency_hz")
        if grid is None:
            grid = f
        elif f.shape != grid.shape or not np.allclose(f, grid, rtol=1e-9):
            raise InputError("every pair needs the same frequency grid", file=path,
                             line=rows[0][2], key="frequency_hz")
        values[key] = np.array([r[1] for r in rows], complex)
    if grid is None or grid.size < 2:
        raise InputError("need at least two frequencies", file=path, key="frequency_hz")
    return grid, values


def _read_uff(path, names):
    check_regular_file(path)
    try:
        import pyuff  # deferred: heavy package, loaded only when this format is used
        sets = pyuff.UFF(path).read_sets()
    except Exception as exc:  # pyuff raises bare Exceptions on malformed files
        raise InputError(f"not a readable UFF file ({exc})"[:200], file=path) from None
    sets = [sets] if isinstance(sets, dict) else sets
    check_complete(path, len(sets))
    data = {}
    for k, s in enumerate(sets):
        if s.get("type") != 58:
            continue
        key = f"dataset {k + 1}"
        try:
            r, e, f, h = _uff_record(s, names, path, key)
        except (KeyError, ValueError, TypeError, OverflowError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(f"malformed record ({type(exc).__name__}: {str(exc)[:60]})",
                             file=path, key=key) from None
        data[r + e] = [(fi, hi, None) for fi, hi in zip(f, h)]
    if not data:
        raise InputError("no UFF 58 function records", file=path)
    return _to_grid(data, path)


def _uff_direction(s, field, path, key) -> int:
    d = int(s[field])
    if not 1 <= abs(d) <= 3:
        raise InputError(f"direction {d}: expected 1, 2 or 3 (x, y, z; negative = reversed)",
                         file=path, key=f"{key} {field}")
    return d


def _uff_record(s, names, path, key):
    """(response, excitation, frequencies, receptance) of one UFF 58 record."""
    if int(s.get("func_type", 4)) not in (0, 4):
        raise InputError(f"function type {s.get('func_type')} is not a frequency response "
                         "function (4)", file=path, key=f"{key} func_type")
    if int(s.get("ordinate_spec_data_type", 8)) in (11, 12):
        raise InputError("expected receptance (displacement/force), got mobility or "
                         "accelerance", file=path, key=f"{key} ordinate_spec_data_type")
    rsp = _uff_direction(s, "rsp_dir", path, key)
    ref = _uff_direction(s, "ref_dir", path, key)
    r = _channel(f"{s.get('rsp_ent_name', '')}.{'xyz'[abs(rsp) - 1]}", names, path, None,
                 f"{key} rsp_ent_name")
    e = _channel(f"{s.get('ref_ent_name', '')}.{'xyz'[abs(ref) - 1]}", names, path, None,
                 f"{key} ref_ent_name")
    f = np.asarray(s["x"], float)
    h = np.sign(rsp) * np.sign(ref) * np.asarray(s["data"], complex)
    if f.ndim != 1 or f.shape != h.shape:
        raise InputError(f"{h.size} values at {f.size} frequencies", file=path, key=key)
    if not (np.all(np.isfinite(f)) and np.all(f >= 0) and np.all(np.isfinite(h))):
        raise InputError("frequencies and receptances must be finite (frequencies >= 0)", file=path, key=key)
    return r, e, f, h


def _check_coverage(values, mounts, points, path):
    for a, b, ad, bd in product(mounts, mounts, "xyz", "xyz"):
        if (a, ad, b, bd) not in values and (b, bd, a, ad) not in values:
            raise InputError(f"missing receptance {a}.{ad} / {b}.{bd}", file=path, key="response")
    for p, b, pd, bd in product(points, mounts, "xyz", "xyz"):
        if (p, pd, b, bd) not in values:
            raise InputError(f"missing receptance {p}.{pd} / {b}.{bd}", file=path, key="response")
