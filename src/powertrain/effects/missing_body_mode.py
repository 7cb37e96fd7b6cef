r"""``missing_body_mode``: a body mode the engine file's body model lacks.

One more body mode under the mounts, :math:`\mathbf x_B(P) \mathrel{+}=
\boldsymbol\psi(P)\,\eta`, :math:`m(\ddot\eta + 2\zeta\omega_0\dot\eta + \omega_0^2\eta) =
\sum_P \boldsymbol\psi(P)\cdot\mathbf f_P`, with ``frequency_hz``, ``modal_mass_kg``,
``damping_ratio`` and its shape ``shape_<mount>_<x|y|z>`` at each base (engine axes). Only
:math:`\boldsymbol\psi\boldsymbol\psi^T/m` reaches the data, so the shape is normalised to
its largest component and the modal mass belongs to that scaling; at :data:`MASS_OFF` or a
zero shape the mode is absent. A rigid chassis with body-side channels is read as a modal
body without modes (:func:`body_side_engine`).

Starts (:meth:`MissingBodyMode.data_starts`): with order phase, the shape from the rank-1
fit of the body side's complex excess over the model (:func:`signed_shape`) on a frequency
grid (:data:`GRID_STEP`) at :data:`GRID_MASSES`; without phase, from the peaks of the
body-side excess relative to the engine side (:func:`body_gap_peak`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.analysis.channel import split_side
from powertrain.effects.base import Effect, Parameter, mount_labels
from powertrain.effects.chassis_modes import FREQ_RANGE as MOVE
from powertrain.models.chassis import BodyMode, Chassis
from powertrain.solvers.body_coupling import ModalBody

#: Frequency bounds [Hz].
FREQ_RANGE = (5.0, 200.0)
#: Modal-mass bounds [kg]; the upper one is the mode absent (the default).
MASS_RANGE = (0.5, 1.0e4)
MASS_OFF = MASS_RANGE[1]
#: Damping-ratio bounds and default [1].
ZETA_RANGE = (0.005, 0.25)
ZETA_DEFAULT = 0.04
#: Prior standard deviation of ln(damping ratio) about the default [1].
DAMPING_PRIOR = 0.7
#: Modal masses screened at the data's start frequency [kg].
START_MASSES = (3.0, 12.0, 50.0)
#: Start frequencies relative to a peak [1] (the coupled resonance lies above the mode's own).
START_SHIFTS = (0.7, 1.0)
#: Peaks of the body-side excess tried as start frequencies.
START_PEAKS = 3
#: Ratio of neighbouring start frequencies with phase [1].
GRID_STEP = 1.06
#: Modal masses of the frequency-grid starts [kg] (docs/validation/diagnosis.md).
GRID_MASSES = (4.0, 12.0, 36.0)
AXES = "xyz"
#: Modal assurance criterion above which the fitted shape pairs with a file body mode [1]
#: (below Allemang 2003's 0.9 for measured pairs: a stand-in mode pairs less well).
MAC_PAIRED = 0.8


def shape_names(engine) -> list:
    """``shape_<mount>_<axis>`` of every mount (file order) and axis."""
    return [f"shape_{m}_{a}" for m in mount_labels(engine) for a in AXES]


def mode_arrays(params, n_mounts):
    """``(frequency, modal mass, damping, normalised shape (n_mounts, 3))``, or None when the
    mode is absent."""
    shape = np.array([v for k, v in params.items() if k.startswith("shape_")], float)
    peak = float(np.max(np.abs(shape))) if shape.size else 0.0
    if params["modal_mass_kg"] >= MASS_OFF or peak == 0.0:
        return None
    return (float(params["frequency_hz"]), float(params["modal_mass_kg"]),
            float(params["damping_ratio"]), (shape / peak).reshape(n_mounts, 3))


def body_side_engine(engine):
    """``engine`` with a rigid (or absent) chassis read as a modal body without modes."""
    ch = getattr(engine, "chassis", None)
    if ch is not None and not ch.is_rigid:
        return engine
    return engine.replace(chassis=Chassis(model="modal", modes=(), points=(),
                                          file=getattr(ch, "file", "")))


class MissingBodyMode(Effect):
    name = "missing_body_mode"
    kind = "structure"
    withhold_orders = True
    basin_parameter = "frequency_hz"
    model_floor = ("frequency_hz", "modal_mass_kg")
    locations = ("body",)
    description = ("one body mode the body model lacks: frequency, modal mass, damping and "
                   "its shape at each mount base (normalised to its largest component)")

    def parameters(self, engine=None):
        out = [Parameter("frequency_hz", "Hz", *FREQ_RANGE, 30.0, True,
                         "natural frequency of the missing body mode"),
               Parameter("modal_mass_kg", "kg", *MASS_RANGE, MASS_OFF, True,
                         "modal mass for the shape normalised to its largest component "
                         f"(the upper bound {MASS_OFF:g} kg: no mode)"),
               Parameter("damping_ratio", "1", *ZETA_RANGE, ZETA_DEFAULT, True,
                         "damping ratio of the missing body mode", DAMPING_PRIOR)]
        out += [Parameter(n, "1", -1.0, 1.0, 0.0, False,
                          f"shape of the mode at the base of {n[6:-2]}, {n[-1]} (engine axes)")
                for n in shape_names(engine)]
        return tuple(out)

    def signed(self, engine=None) -> list:
        return shape_names(engine)

    def applicable(self, engine) -> bool:
        return ModalBody.of(engine) is not None

    def apply(self, engine, **params):
        p = {**self.defaults(engine), **params}
        mode = mode_arrays(p, len(engine.mounts))
        if mode is None:
            return engine
        f, m, z, shape = mode
        ch = body_side_engine(engine).chassis
        shapes = {mt.name: shape[i] for i, mt in enumerate(engine.mounts)}
        shapes.update({pt: np.zeros(3) for pt in ch.points})
        new = BodyMode(frequency=f, damping_ratio=z, modal_mass=m, shapes=shapes)
        return engine.replace(chassis=Chassis(
            model="modal", modes=tuple(ch.modes) + (new,), points=ch.points,
            receptance=None, file=ch.file, notes=dict(ch.notes)))

    def body_change(self, hm, p, body):
        mode = mode_arrays(p, body.mount_shapes.shape[0])
        return body if mode is None else body.with_extra_mode(*mode)

    def summary(self, params) -> str:
        """'a body mode missing from the model near f Hz, m kg, moving mostly X's z'."""
        shape = {k: v for k, v in params.items() if k.startswith("shape_")}
        if not shape or params["modal_mass_kg"] >= MASS_OFF:
            return ""
        top = max(shape, key=lambda k: abs(shape[k]))
        return (f"a body mode missing from the model near {params['frequency_hz']:.1f} Hz, "
                f"{params['modal_mass_kg']:.3g} kg, moving mostly {top[6:-2]}'s {top[-1]}")

    def alternative_text(self, params, other, delta_chi2) -> str:
        """'the missing mode lies near 55 or 24 Hz ... the data prefer 55 Hz ...'."""
        f, g = params["frequency_hz"], other["frequency_hz"]
        return (f"the missing mode lies near {f:.3g} or {g:.3g} Hz ({params['modal_mass_kg']:.3g}"
                f" or {other['modal_mass_kg']:.3g} kg): both explain the data alike (training "
                f"chi2 differs by {delta_chi2:.1f} < 10); the data prefer {f:.3g} Hz")

    def interval_text(self, interval) -> str:
        """'95 % intervals: frequency 70.1-79.3 Hz, modal mass 9.8-12.6 kg' ("" without
        finite intervals)."""
        f, m = interval.get("frequency_hz"), interval.get("modal_mass_kg")
        if not f or not m or None in f + m:
            return ""
        return (f"95 % intervals of the missing mode: frequency {f[0]:.3g}-{f[1]:.3g} Hz, "
                f"modal mass {m[0]:.3g}-{m[1]:.3g} kg")

    def bound_warnings(self, params) -> list:
        """The damping ratio or the frequency at its bound (within 1 % of it)."""
        out = []
        z, f = params["damping_ratio"], params["frequency_hz"]
        if params["modal_mass_kg"] >= MASS_OFF:
            return out
        if z <= ZETA_RANGE[0] * 1.01 or z >= ZETA_RANGE[1] * 0.99:
            out.append(f"warning: the missing mode's damping ratio stopped at its bound "
                       f"({z:.3g}): the data do not resolve the resonance's width, so its "
                       f"frequency and modal mass are less certain than their 1 sigma says")
        if f <= FREQ_RANGE[0] * 1.01 or f >= FREQ_RANGE[1] * 0.99:
            out.append(f"warning: the missing mode's frequency stopped at its bound "
                       f"({f:.3g} Hz): the measured orders see only its mass or spring line, "
                       f"not the mode itself")
        return out

    def restates(self, params, engine=None, band=None):
        """``("chassis_modes", reason)`` when the fitted shape pairs (MAC >= :data:`MAC_PAIRED`)
        with a file body mode at a frequency ``chassis_modes`` can move it to, or outside the
        measured ``band`` (a mass or spring line on that mode)."""
        ch = getattr(engine, "chassis", None)
        modes = () if ch is None else ch.body_modes
        mode = mode_arrays(params, len(engine.mounts)) if modes else None
        if mode is None:
            return None
        f, _, _, shape = mode
        psi = shape.ravel()
        best = None
        for k, m in enumerate(modes):
            phi = np.concatenate([np.asarray(m.shapes[mt.name], float) for mt in engine.mounts])
            mac = float(phi @ psi) ** 2 / max(float(phi @ phi) * float(psi @ psi), 1e-300)
            ratio = f / m.frequency
            outside = band is not None and not band[0] <= f <= band[1]
            if mac >= MAC_PAIRED and (MOVE[0] <= ratio <= MOVE[1] or outside) and (
                    best is None or mac > best[1]):
                best = (k, mac, ratio)
        if best is None:
            return None
        k, mac, ratio = best
        where = (f"at {ratio:.2f}x its frequency" if MOVE[0] <= ratio <= MOVE[1] else
                 f"at {f:.1f} Hz, outside the measured {band[0]:.0f}-{band[1]:.0f} Hz (a "
                 f"{'mass' if f < band[0] else 'spring'} line on that mode's shape)")
        return ("chassis_modes", f"its shape pairs with body mode {k + 1} of the engine file "
                                 f"(MAC {mac:.2f}) {where}")

    def data_starts(self, engine, gaps):
        """Start parameter sets from the body-side :class:`BodyGaps` ``gaps`` ([] without)."""
        names = [m.name for m in engine.mounts]
        shape = signed_shape(gaps, names)
        if shape is not None:
            out = []
            for f in frequency_grid(gaps, names):
                local = signed_shape(gaps, names, f0=f)
                for sh in [shape] + ([] if local is None else [local]):
                    base = {"damping_ratio": ZETA_DEFAULT,
                            **dict(zip(shape_names(engine), sh.ravel().tolist()))}
                    out += [dict(base, frequency_hz=float(f), modal_mass_kg=m)
                            for m in GRID_MASSES]
            return out
        out = _magnitude_grid_starts(engine, gaps, names)
        for f0, shape in body_gap_peak(gaps, [m.name for m in engine.mounts],
                                       n_peaks=START_PEAKS):
            base = {"frequency_hz": float(np.clip(f0, *FREQ_RANGE)),
                    "damping_ratio": ZETA_DEFAULT}
            base.update(dict(zip(shape_names(engine), shape.ravel().tolist())))
            out += [dict(base, modal_mass_kg=m, frequency_hz=float(np.clip(s * f0, *FREQ_RANGE)))
                    for m in START_MASSES for s in START_SHIFTS]
        return out


def _magnitude_grid_starts(engine, gaps, names) -> list:
    """Without phase: a start at every grid frequency, the shape the excess near it."""
    cols = _body_columns(gaps, names)
    if not cols:
        return []
    ex = _excess(gaps, cols)
    f = gaps.order_hz[:, None, :] * np.ones((1, len(cols), 1))
    places = [cols[c][:2] for c in cols]
    out = []
    for f0 in frequency_grid(gaps, names):
        shape = _shape_near(f, ex, f0, places, len(names))
        if shape is None:
            continue
        base = {"damping_ratio": ZETA_DEFAULT, "frequency_hz": float(f0),
                **dict(zip(shape_names(engine), shape.ravel().tolist()))}
        out += [dict(base, modal_mass_kg=m) for m in GRID_MASSES]
    return out


def _excess(g, cols):
    """Excess velocity [m/s RMS] of the body-side points over the model, (n_r, n_cols, n_o)."""
    meas = g.measured[:, list(cols)]
    with np.errstate(invalid="ignore", over="ignore"):
        model = meas * 10 ** (g.gap[:, list(cols)] / 20)
        return np.sqrt(np.maximum(meas ** 2 - model ** 2, 0.0))


@dataclasses.dataclass
class BodyGaps:
    """Gaps of measured order levels against a model: ``rpm`` (n_r,), ``channels``
    [(mount, direction)], ``orders`` (n_o,), ``gap`` [dB] and ``measured`` [m/s RMS], each
    (n_r, n_ch, n_o), NaN where not scored; ``excess`` measured minus model complex amplitude
    [m/s RMS] (None without phase)."""

    rpm: np.ndarray
    channels: list
    orders: np.ndarray
    gap: np.ndarray
    measured: np.ndarray
    excess: np.ndarray | None = None

    @property
    def order_hz(self) -> np.ndarray:
        """Order frequency of every speed and order [Hz], (n_r, n_o)."""
        return self.rpm[:, None] * self.orders[None, :] / 60.0


#: Relative half-width of the frequency window read for the shape [1].
PEAK_WINDOW = 0.08


def body_gap_peak(g: BodyGaps, mount_names, n_bins=32, n_peaks=1):
    r"""``(f0, shape (n_mounts, 3))`` of the body side's excess over the model, or None (a
    list for ``n_peaks`` > 1). The excess :math:`e = \sqrt{\max(0, m^2 - s^2)}` relative to
    the measured engine side peaks at a resonance; f0 is its weighted mean frequency in the
    log bin (of ``n_bins``) with the largest mean :math:`(e/m_\mathrm{engine})^2`, the shape
    the RMS excess within ± :data:`PEAK_WINDOW` of f0, normalised."""
    cols = _body_columns(g, mount_names)
    if not cols:
        return None
    idx = list(cols)
    f = g.order_hz[:, None, :] * np.ones((1, len(idx), 1))
    ex = _excess(g, cols)
    engine_side = g.measured[:, [cols[c][2] for c in idx]]
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        w = (ex / engine_side) ** 2
    w = np.where(np.isfinite(w), w, 0.0)
    if not np.any(w > 0):
        return None
    edges = np.geomspace(f.min(), f.max() * 1.0001, n_bins + 1)
    k = np.clip(np.searchsorted(edges, f, side="right") - 1, 0, n_bins - 1)
    n_in = np.bincount(k.ravel(), (w > 0).ravel(), n_bins)
    sums = np.bincount(k.ravel(), w.ravel(), n_bins) / np.maximum(n_in, 1)
    out = []
    for top in np.argsort(sums)[::-1][:n_peaks]:
        sel = k == top
        if sums[top] <= 0:
            break
        f0 = float(np.sum(f[sel] * w[sel]) / np.sum(w[sel]))
        shape = _shape_near(f, ex, f0, [cols[c][:2] for c in idx], len(mount_names))
        if shape is not None:
            out.append((f0, shape))
    if n_peaks == 1:
        return out[0] if out else None
    return out


def _body_columns(g: BodyGaps, mount_names) -> dict:
    """``{channel: (mount index, axis index, engine-side channel)}`` of the body-side channels
    whose engine side is measured too."""
    where = {c: i for i, c in enumerate(g.channels)}
    cols = {}
    for c, (m, d) in enumerate(g.channels):
        base, side = split_side(m)
        if side == "passive" and base in mount_names and (base, d) in where:
            cols[c] = (mount_names.index(base), "xyz".index(d), where[(base, d)])
    return cols


def signed_shape(g: BodyGaps, mount_names, f0=None):
    r"""Signed, normalised shape (n_mounts, 3) from the complex excess, or None without phase:
    the leading eigenvector of :math:`E^HE` turned real (a missing mode adds
    :math:`a_{ro}\,\boldsymbol\psi`); with ``f0`` [Hz] only points within ± :data:`PEAK_WINDOW`."""
    cols = _body_columns(g, mount_names)
    if g.excess is None or not cols:
        return None
    idx = list(cols)
    E = np.moveaxis(g.excess[:, idx], 1, -1)
    if f0 is not None:
        E = E[np.abs(g.order_hz / f0 - 1) <= PEAK_WINDOW]
    E = E.reshape(-1, len(idx))
    E = np.where(np.isfinite(E), E, 0.0)
    if not np.any(E):
        return None
    v = np.linalg.eigh(E.conj().T @ E)[1][:, -1]
    psi = np.real(v * np.exp(-0.5j * np.angle(np.sum(v ** 2))))
    shape = np.zeros((len(mount_names), 3))
    for j, c in enumerate(idx):
        shape[cols[c][:2]] = psi[j]
    peak = np.max(np.abs(shape))
    return shape / peak if peak > 0 else None


def frequency_grid(g: BodyGaps, mount_names) -> np.ndarray:
    """Start frequencies [Hz] in steps of :data:`GRID_STEP` over the scored body-side points."""
    idx = list(_body_columns(g, mount_names))
    ok = np.isfinite(g.gap[:, idx] if g.excess is None else g.excess[:, idx])
    f = (g.order_hz[:, None, :] * np.ones(ok.shape))[ok]
    if not f.size:
        return np.empty(0)
    lo, hi = np.clip([f.min(), f.max()], *FREQ_RANGE)
    n = int(np.ceil(np.log(hi / lo) / np.log(GRID_STEP))) + 1
    return np.geomspace(lo, hi, max(n, 1))


def _shape_near(f, ex, f0, places, n_mounts):
    """RMS excess per base and direction within ± PEAK_WINDOW of f0, normalised."""
    near = np.abs(f / f0 - 1) <= PEAK_WINDOW
    shape = np.zeros((n_mounts, 3))
    for j, place in enumerate(places):
        e = ex[:, j][near[:, j] & np.isfinite(ex[:, j])]
        if e.size:
            shape[place] = np.sqrt(np.mean(e ** 2))
    peak = shape.max()
    return shape / peak if peak > 0 else None
