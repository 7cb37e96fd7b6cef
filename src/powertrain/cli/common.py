"""Shared CLI helpers: parsing of frequency lists and ranges, output of tables."""

from __future__ import annotations

import math

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
