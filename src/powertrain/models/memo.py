"""The memo a frozen model keeps of values computed from its own fields.

A frozen model (:class:`~powertrain.models.engine.Engine`,
:class:`~powertrain.models.crank_train.CrankTrain`,
:class:`~powertrain.models.combustion.SingleZoneCombustion`) holds one :class:`Memo` as a
field (``init=False``: every new or replaced model starts with an empty one). The memo is
not part of the model's value: it is never compared nor printed, and a copy
(``copy.copy``, ``copy.deepcopy``, ``pickle``: a model sent to another process) starts
empty and fills again where it is used.
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
    """Values computed from the fields of the model that holds it, by key; a copy is
    empty."""

    def __reduce__(self):
        return (Memo, ())

    def __copy__(self) -> Memo:
        return Memo()

    def __deepcopy__(self, memo) -> Memo:
        return Memo()

    def __repr__(self) -> str:
        return f"Memo({len(self)} entries)"

    def last_grid(self, key: str, theta, compute):
        """``compute(theta)`` for the crank-angle grid ``theta`` [rad], kept under ``key``
        for the last grid asked (a run-up asks for the same cycle grid at every speed); its
        arrays are made read-only, as every caller shares them."""
        theta = np.asarray(theta, float)
        kept = self.get(key)
        if kept is not None and kept[0].shape == theta.shape and np.array_equal(kept[0], theta):
            return kept[1]
        out = _read_only(compute(theta))
        self[key] = (theta.copy(), out)
        return out
