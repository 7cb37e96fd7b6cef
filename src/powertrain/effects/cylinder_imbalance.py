r"""``cylinder_imbalance``: cylinder i delivers (1 + e_i) times its nominal combustion.

* single-zone combustion: cylinder i's IMEP target times (1 + e_i) (the heat release is
  recalibrated to it);
* measured pressure traces: cylinder i's *combustion part* of its trace times (1 + e_i),
  :math:`p_i' = p_{m,i} + (1 + e_i)(p_i - p_{m,i})`, with :math:`p_{m,i}` the motored
  (polytropic, n = :data:`N_MOTORED`) pressure through the trace's value at
  :data:`REF_ANGLE` before firing TDC, over the closed cycle (−180…180°); the gas-exchange
  strokes are kept. The IMEP changes by about e_i times the combustion part's share.

On the cached path the load is linearised in the e_i (central differences of the load
harmonics, step :data:`STEP`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.effects.base import Effect, Parameter

#: Polytropic exponent of the motored pressure [1].
N_MOTORED = 1.32
#: Crank angle (cylinder cycle, before firing TDC) where the motored pressure is matched to
#: the trace: well before any start of combustion, after intake valve closing [rad].
REF_ANGLE = -np.deg2rad(60.0)
#: Central-difference step of the linearised load [1].
STEP = 0.05


def motored_pressure(theta, pressure, crank):
    """Motored (no combustion) pressure of each cylinder's trace, same shape; equal to the
    trace outside the closed cycle (−π..π)."""
    V, _ = crank.volume(theta)
    j = int(np.argmin(np.abs(theta - REF_ANGLE)))
    closed = (theta > -np.pi) & (theta < np.pi)
    pm = np.array(pressure, float, copy=True)
    pm[:, closed] = pressure[:, j:j + 1] * (V[j] / V[closed]) ** N_MOTORED
    return np.where(closed[None, :], np.minimum(pm, pressure), pressure)


@dataclass(frozen=True, eq=False)
class ScaledCombustion:
    """Combustion model whose cylinders' combustion parts are scaled (measured traces)."""

    base: object
    factors: np.ndarray

    @property
    def model(self):
        return self.base.model

    @property
    def speed_key(self):
        return getattr(self.base, "speed_key", "combustion.traces")

    def speed_range(self):
        return self.base.speed_range()

    def cycle_pressures(self, crank, omega, load=1.0):
        from powertrain.physics.combustion import indicated_work
        theta, p, info = self.base.cycle_pressures(crank, omega, load)
        pm = motored_pressure(theta, p, crank)
        p_new = pm + np.asarray(self.factors, float)[:, None] * (p - pm)
        _, dV = crank.volume(theta)
        imep = np.array([indicated_work(pc, dV, theta[1] - theta[0]) for pc in p_new])
        return theta, p_new, dict(info, imep_target=imep / crank.swept_volume)


def with_cylinder_imbalance(engine, **e):
    """Cylinder i's combustion times (1 + e<i>) [1] (``e1=...``; missing ones 0)."""
    n = engine.crank.n_cylinders
    eps = np.array([float(e.get(f"e{i + 1}", 0.0)) for i in range(n)])
    scale = getattr(engine.combustion, "with_cylinder_factors", None)
    if scale is not None:                  # a model of its own cylinders' combustion
        return engine.replace(combustion=scale(1.0 + eps))
    return engine.replace(combustion=ScaledCombustion(engine.combustion, 1.0 + eps))


class CylinderImbalance(Effect):
    name = "cylinder_imbalance"
    kind = "excitation"
    description = ("cylinder-to-cylinder combustion differences (IMEP, or the combustion part "
                   "of measured traces; half and first orders); linearised load")

    def _n(self, engine):
        return 4 if engine is None else engine.crank.n_cylinders

    def parameters(self, engine=None):
        return tuple(Parameter(f"e{i}", "1", -0.25, 0.25, 0.0, False,
                               f"relative combustion (IMEP) deviation of cylinder {i}")
                     for i in range(1, self._n(engine) + 1))

    def start_grid(self, engine=None):
        return ((-0.06, 0.06),) * self._n(engine)

    def applicable(self, engine):
        return getattr(engine.combustion, "model", "") in ("single-zone", "measured") \
            and engine.crank.n_cylinders > 1

    def apply(self, engine, **params):
        return with_cylinder_imbalance(engine, **params)

    def warm(self, hm):
        if "cylinder_imbalance" not in hm._extra:
            eng, n = hm.engine, hm.engine.crank.n_cylinders
            out = np.zeros((n, hm.rpm.size) + hm.load.shape[1:], complex)
            for k in range(n):
                up = self.apply(eng, **{f"e{k + 1}": STEP})
                dn = self.apply(eng, **{f"e{k + 1}": -STEP})
                out[k] = (hm.load_of(up) - hm.load_of(dn)) / (2 * STEP)
            hm._extra["cylinder_imbalance"] = out
        return hm._extra["cylinder_imbalance"]

    def alternatives(self, params, engine=None):
        """The same cylinder-to-cylinder pattern with another reference: the strongest
        cylinder nominal (the others weak), the weakest nominal (the others strong), the mean
        nominal. Orders 0.5, 1, 1.5 see only the deviations from the mean, so these differ
        mainly in the firing orders' level, often below the noise."""
        n = len(params)
        f = 1.0 + np.array([params.get(f"e{i + 1}", 0.0) for i in range(n)])
        out = []
        dev = float(np.max(np.abs(f / np.median(f) - 1.0)))
        for j in range(n):                   # one cylinder weak / strong (magnitudes only)
            for sign, word in ((-1.0, "weak"), (1.0, "strong")):
                g = np.zeros(n)
                g[j] = sign * dev
                out.append((f"cylinder {j + 1} {word}", {f"e{i + 1}": float(x)
                                                        for i, x in enumerate(g)}))
        for label, ref in (("strongest cylinder nominal, the others weak", f.max()),
                           ("weakest cylinder nominal, the others strong", f.min()),
                           ("mean nominal", f.mean())):
            g = np.clip(f / ref - 1.0, -0.25, 0.25)
            if np.max(np.abs(g - (f - 1.0))) > 1e-3:
                out.append((f"{label}: " + ", ".join(f"e{i + 1}={x:+.3f}"
                                                     for i, x in enumerate(g)),
                            {f"e{i + 1}": float(x) for i, x in enumerate(g)}))
        return out

    def load_delta(self, hm, p):
        d = self.warm(hm)
        eps = np.array([p.get(f"e{i + 1}", 0.0) for i in range(d.shape[0])])
        return None if not eps.any() else np.tensordot(eps, d, axes=1)


__all__ = ["CylinderImbalance", "ScaledCombustion", "motored_pressure",
           "with_cylinder_imbalance"]
