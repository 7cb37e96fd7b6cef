"""The memo a frozen model keeps of values computed from its own fields.

A frozen model holds one :class:`Memo` as an ``init=False`` field; it is not part of the
model's value (never compared nor printed) and any copy or pickle starts empty.
"""

from __future__ import annotations

import numpy as np


def _read_only(value):
    if isinstance(value, np.ndarray):
        value.setflags(write=False)
    elif isinstance(value, (tuple, list)):
        for v in value:
            _read_only(v)
    return value


class Memo(dict):
    """Values computed from the holding model's fields, by key; a copy is empty."""

    def __reduce__(self):
        return (Memo, ())

    def __copy__(self) -> Memo:
        return Memo()

    def __deepcopy__(self, memo) -> Memo:
        return Memo()

    def __repr__(self) -> str:
        return f"Memo({len(self)} entries)"

    def last_grid(self, key: str, theta, compute):
        """``compute(theta)`` for the grid ``theta`` [rad], kept read-only under ``key`` for the
        last grid asked."""
        theta = np.asarray(theta, float)
        kept = self.get(key)
        if kept is not None and kept[0].shape == theta.shape and np.array_equal(kept[0], theta):
            return kept[1]
        out = _read_only(compute(theta))
        self[key] = (theta.copy(), out)
        return out
