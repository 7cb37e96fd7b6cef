r"""Start of the amplitude fixed point for a fit's next evaluation (:mod:`powertrain.diagnosis.fit`).

The converged amplitudes of the last *base* point and the slopes
:math:`\partial\ln A/\partial v_j` of the last finite-difference column of each parameter
predict the next start to first order,

.. math:: \ln A_0 = \ln A_{base} + \sum_j \frac{\partial\ln A}{\partial v_j}\,(v_j - v_{base,j});

only the start changes, every evaluation still iterates to tolerance.
"""

from __future__ import annotations

import numpy as np

#: A point differing from the base in one parameter by at most this (relative to
#: max(1, |v|)) is a finite-difference column (the fits' steps are 1e-4).
COLUMN_STEP = 1e-3
#: Largest predicted change of ln A from the base (a long step may overshoot).
MAX_LOG_CHANGE = 1.0


def scenario_vector(scenario) -> np.ndarray:
    """``scenario``'s parameter values in a fixed order (effect, then parameter name)."""
    return np.array([float(v) for e in sorted(scenario) for _, v in sorted(scenario[e].items())])


class AmplitudeStart:
    """First-order prediction of the converged amplitudes from the last base point."""

    def __init__(self):
        self.base = None                  # (v, ln A, A > 0)
        self.slope = {}                   # parameter index -> d ln A / d v

    def start(self, v):
        """Predicted amplitudes (n_r, n_net) at parameter values ``v`` (None before any)."""
        if self.base is None:
            return None
        vb, lb, on = self.base
        if v.shape != vb.shape:
            return np.where(on, np.exp(lb), 0.0)
        change = np.zeros_like(lb)
        for j in np.flatnonzero(v != vb):
            if j in self.slope:
                change += self.slope[j] * (v[j] - vb[j])
        pred = lb + np.clip(change, -MAX_LOG_CHANGE, MAX_LOG_CHANGE)
        return np.where(on, np.exp(pred), 0.0)

    def record(self, v, amplitudes):
        """Note the converged ``amplitudes`` at ``v``: a column's slope, or the new base."""
        on = amplitudes > 0.0
        la = np.log(np.where(on, amplitudes, 1.0))
        if self.base is not None and v.shape == self.base[0].shape:
            d = v - self.base[0]
            moved = np.flatnonzero(d)
            if moved.size == 1:
                j = int(moved[0])
                if abs(d[j]) <= COLUMN_STEP * max(1.0, abs(self.base[0][j])):
                    self.slope[j] = (la - self.base[1]) / d[j]
                    return
        self.base = (np.array(v, float), la, on)
