r"""``cylinder_imbalance``: cylinder i delivers (1 + e_i) times its nominal combustion.

Single-zone combustion: the IMEP target times (1 + e_i). Measured traces: the combustion part
times (1 + e_i), :math:`p_i' = p_{m,i} + (1 + e_i)(p_i - p_{m,i})`, with :math:`p_{m,i}` the
motored (polytropic, :data:`N_MOTORED`) pressure through the trace at :data:`REF_ANGLE` over
the closed cycle. The load is linear in the e_i, so one forward difference per cylinder
(:data:`STEP`) is exact to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.effects.base import Effect, Parameter
from powertrain.physics.combustion import indicated_work

#: Polytropic exponent of the motored pressure [1].
N_MOTORED = 1.32
#: Cycle angle where the motored pressure meets the trace (before combustion, after IVC) [rad].
REF_ANGLE = -np.deg2rad(60.0)
#: Forward-difference step of the load derivatives [1].
STEP = 0.05


def motored_pressure(theta, pressure, crank):
    """Motored pressure of each cylinder's trace [Pa] (the trace outside −π..π)."""
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
        theta, p, info = self.base.cycle_pressures(crank, omega, load)
        pm = motored_pressure(theta, p, crank)
        p_new = pm + np.asarray(self.factors, float)[:, None] * (p - pm)
        _, dV = crank.volume(theta)
        imep = indicated_work(np.atleast_2d(p_new), dV, theta[1] - theta[0])
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
                out[k] = (hm.load_of(up) - hm.load) / STEP
            hm._extra["cylinder_imbalance"] = out
        return hm._extra["cylinder_imbalance"]

    def alternatives(self, params, engine=None):
        """The same pattern with another reference (strongest, weakest or mean cylinder
        nominal) and single weak or strong cylinders."""
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

    def finding(self, params, engine=None, phase="none"):
        """The cylinder furthest from the median, weak or strong, and its equivalents."""
        f = 1.0 + np.array([params.get(f"e{i + 1}", 0.0) for i in range(len(params))])
        rel = f / np.median(f) - 1.0
        j = int(np.argmax(np.abs(rel)))
        word = "weak" if rel[j] < 0 else "strong"
        same = equivalent_cylinders(engine, j, rel[j] < 0, phase)
        named = " or ".join(_cylinder_words(same))
        text = f"{named} ({rel[j]:+.1%} against the median cylinder)"
        if phase == "none":
            text = (f"one cylinder {abs(rel[j]):.1%} off the median cylinder; which one, and "
                    "whether weak or strong, needs the order phases")
        elif phase == "whole":
            text += ("; without half-order phases (no cycle reference) cylinders sharing a "
                     f"crank pin ({_pin_text(engine)}) cannot be told apart, nor a weak "
                     "cylinder on one pin from a strong one on the other")
        return {"cylinder": j + 1, "sign": word, "deviation": float(rel[j]),
                "could_be": [{"cylinder": c + 1, "sign": "weak" if w else "strong"}
                             for c, w in same], "phase": phase, "text": text}

    def load_terms(self, hm, p):
        d = self.warm(hm)
        return self.name, np.array([p.get(f"e{i + 1}", 0.0) for i in range(d.shape[0])]), d


def equivalent_cylinders(engine, j, weak, phase) -> list:
    r"""``[(cylinder, weak)]`` (0-based) the measured orders cannot tell from cylinder ``j``
    weak/strong: all without phase; with whole-order phases those with the same phasor
    :math:`\pm e^{-ik\alpha}` at every non-firing whole order k; itself with half orders."""
    n = len(engine.crank.firing_angles)
    if phase == "all":
        return [(j, weak)]
    every = [(c, w) for c in range(n) for w in (True, False)]
    if phase == "none":
        return sorted(every, key=lambda cw: (cw != (j, weak), not cw[1], cw[0]))
    alpha = np.asarray(engine.crank.firing_angles, float)
    ks = [k for k in range(1, 9) if abs(np.sum(np.exp(-1j * k * alpha))) < 1e-6]

    def phasor(c, w):
        return (-1.0 if w else 1.0) * np.exp(-1j * np.array(ks) * alpha[c])
    mine = phasor(j, weak)
    same = [(c, w) for c, w in every if np.allclose(phasor(c, w), mine, atol=1e-6)]
    return sorted(same, key=lambda cw: (cw != (j, weak), not cw[1], cw[0]))


def _cylinder_words(cyls) -> list:
    """``["cylinder 2 or 3 weak", ...]``."""
    out = []
    for weak in dict.fromkeys(w for _, w in cyls):
        nums = [str(c + 1) for c, w in cyls if w == weak]
        out.append(f"cylinder {' or '.join(nums)} {'weak' if weak else 'strong'}")
    return out


def _pin_text(engine) -> str:
    """``"1 and 4, 2 and 3"``: cylinders on the same crank pin angle."""
    pins = np.round(np.mod(np.asarray(engine.crank.crank_pin_angles, float), 2 * np.pi), 6)
    groups = [np.flatnonzero(pins == a) + 1 for a in dict.fromkeys(pins)]
    return ", ".join(" and ".join(str(c) for c in g) for g in groups if g.size > 1) or "none"


__all__ = ["CylinderImbalance", "ScaledCombustion", "motored_pressure",
           "with_cylinder_imbalance"]
