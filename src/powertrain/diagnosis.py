r"""Diagnosis of the sim-to-real gap: where it lies, which unmodelled effect causes it, how far
it shrinks.

Input: a measured run-up (:class:`~powertrain.iotools.measured.MeasuredRunup`, order curves
per mount channel) and the baseline engine model. Levels are compared as the gap
:math:`\Delta L = 20\log_{10}(s/m)` [dB] (+ = simulation higher).

**Data.** The simulation is the harmonic steady state (:mod:`powertrain.solvers.fast_harmonic`,
identical to ``run_runup(solver="harmonic")``) at every measured speed inside the engine's
range. The measured noise floor :math:`f` (RMS per order) is added to the model in power,
:math:`s' = \sqrt{s^2 + f^2}` (for the synthesis :math:`\sqrt{s^2 + 16 f^2}`). A measured
point below :math:`3f` is *censored*: it only says the level is below :math:`3f`, so its
residual is :math:`\max(0, 20\log_{10}(s'/3f))` — a model predicting an order where none was
measured is penalised, noise is never scored as a gap.

**1. Where.** The gap map per mount, direction, quantity and speed; the regions beyond
±3 dB; and a decomposition of all order gaps (not the synthesis) into smooth parts,

.. math:: \Delta L_{c,o}(n) \approx g_c + \Delta H_c\!\big(f = o\,n/60\big)
          + \Delta F_o(n),

fitted by penalised least squares (piecewise-linear bases: ΔH on 16 knots in log f, ΔF on
8 knots in rpm, second-difference smoothing and a small ridge): :math:`g_c` a constant per
channel (sensor gain), :math:`\Delta H_c` tied to a fixed *frequency* (transfer path,
structure), :math:`\Delta F_o` tied to a fixed *order and speed* (excitation). The share of
the gap's sum of squares each part carries alone, and the residual, are reported. A region
is labelled by the part that carries most of its sum of squares. Finally the gap outside the
span of rigid-body motion: at each speed and order the nine measured magnitudes, given the
simulated phases, are projected on the 6-dimensional space of rigid-body mount-point motions;
what is left (in dB) cannot come from a rigid powertrain (powertrain flexibility, sensor
position/orientation error, or phases far from the model's).

**2. Which.** The speeds are split into 12 contiguous blocks; blocks 2, 5, 8, 11 are held
out (one third of the speeds, spread over the range), the rest is for fitting. Each candidate
of :data:`powertrain.effects.EFFECTS`, and the pairs of the three best, is fitted on (at most
:data:`N_FIT_RPM` evenly chosen) training speeds by bounded least squares in dB
(``scipy.optimize.least_squares``, multi-start on a coarse grid) and scored on the held-out
speeds. Decision rule, with :math:`E_0, E_c` the held-out mean squared gaps (dB²) of the
baseline and the candidate, :math:`\hat\sigma` the noise estimated from the measured
curves (second differences along speed, robust) and :math:`E_n = \hat\sigma^2 u` the held-out
mean squared gap a perfect model would leave, :math:`u` the fraction of scored held-out
points that are not censored (:func:`noise_mse`; a censored point leaves no noise):

* a candidate is **supported** when it lowers the training BIC,
  :math:`n\ln(\mathrm{RSS}/n) + p\ln n`, by more than :data:`BIC_MARGIN`, and the held-out
  improvement is significant: the per-speed improvements :math:`d_r` have
  :math:`\bar d/(s_d/\sqrt{n_r}) >` :data:`T_MIN` and :math:`\bar d > 0`;
* a pair is preferred to its better member only if it is supported against that member
  in the same way and explains at least :data:`PAIR_GAIN_MIN` of the held-out excess that
  member leaves;
* the **answer** is the best (lowest held-out gap) supported candidate, among the first
  :data:`N_CHECKED` supported ones, that passes all of

  - *size*: it explains at least :data:`EXPLAINED_MIN` of the held-out excess gap over
    noise, :math:`(E_0 - E_c)/(E_0 - E_n)`;
  - *residual consistent with noise*: its held-out residual, averaged per channel and order
    over groups of about 4 adjacent held-out speeds (:func:`structured_residual`; noise
    averages out, structure does not), keeps a structured RMS beyond noise of at most
    :math:`\max(` :data:`STRUCT_ABS_DB`, :data:`STRUCT_REL` × the baseline's :math:`)`;
  - *held-out cells* (:func:`heldout_cells_check`): refitted without some (channel, order)
    cells, it must predict them at the held-out speeds — explain at least
    :data:`XV_EXPLAINED_MIN` of their excess with t > :data:`T_MIN` (skipped when their
    excess is below :data:`EXCESS_MIN_DB`). Physical effects withhold channels (three
    folds, one channel of every mount triad each: the rigid body carries the effect to a
    channel it was not fitted on); candidates with sensor errors withhold orders
    (orders ≤ 2 vs > 2, both ways: a gain or a triad rotation is the same on every order of
    its channels, a frequency-tied gap is not). Free gains thus cannot absorb a structural
    gap;
* otherwise: **"no effect"** when the excess RMS gap :math:`\sqrt{\max(E_0 - E_n,
  0)}` is below :data:`EXCESS_MIN_DB` (the model agrees within noise), else
  **"unexplained"** (a supported candidate that failed a check is named as partial, with
  the rule it failed).

Parameter uncertainties are the 1σ of the Gauss–Newton covariance
:math:`\hat s^2 (J^TJ)^{-1}` (residual correlation along speed ignored: optimistic). A
confounding check refits the chosen effect on four speed bands: a parameter believed
constant that trends with speed (e.g. a mount-stiffness factor that grows with speed, i.e.
with falling amplitude) points to a different effect.

**3. How far.** The held-out RMS gap before and after the chosen effect, per channel and
overall, with overlay plots (:meth:`DiagnosisResult.report`).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import dataclass, field
from itertools import combinations

import numpy as np

from powertrain.effects import EFFECTS, apply_sensor_error, predict
from powertrain.errors import InputError
from powertrain.solvers.fast_harmonic import HarmonicModel

#: Gap beyond which a region is listed [dB].
REGION_DB = 3.0
#: Held-out significance (t statistic over held-out speeds).
T_MIN = 4.0
#: Training BIC improvement a candidate must reach.
BIC_MARGIN = 10.0
#: Fraction of the held-out excess gap the answer must explain.
EXPLAINED_MIN = 0.6
#: A pair must also explain this fraction of what its better member leaves over noise.
PAIR_GAIN_MIN = 0.5
#: Excess gap over noise below which the model counts as agreeing [dB RMS].
EXCESS_MIN_DB = 0.5
#: Training speeds used for fitting (evenly chosen among the training blocks).
N_FIT_RPM = 24
#: Held-out speeds scored (evenly chosen among the held-out blocks).
N_TEST_RPM = 36
#: Blocks of the speed split and those held out (0-based).
N_BLOCKS = 12
HELDOUT_BLOCKS = (1, 4, 7, 10)
#: Residual structure: the answer's held-out residual, averaged over short runs of adjacent
#: held-out speeds per channel and order (noise averages out, structure does not), may keep
#: at most this structured RMS beyond noise [dB] ...
STRUCT_ABS_DB = 0.6
#: ... or this fraction of the baseline's structured held-out gap, whichever is larger.
STRUCT_REL = 0.35
#: Held-out cells: the answer refitted without some (channel, order) cells must explain at
#: least this fraction of the held-out excess on the withheld cells (at the held-out speeds).
XV_EXPLAINED_MIN = 0.5
#: Channel folds for physical effects (each holds out one channel of every mount triad).
CHANNEL_FOLDS = ((0, 4, 8), (1, 5, 6), (2, 3, 7))
#: Orders up to this one form the "low" fold of the order split (sensor gains) [order].
ORDER_SPLIT = 2.0
#: Supported candidates (best first) put through the structure and held-out-cell checks.
N_CHECKED = 3
#: Smallest data set that can be split: speeds in total.
MIN_RPM = 12
DEFAULT_NOISE_FLOOR = 1.0e-6
#: Measured points below this multiple of the noise floor are censored (9.5 dB; noise alone
#: exceeds it with probability e^-9 = 1e-4 for complex Gaussian noise of that RMS).
CENSOR_MARGIN = 3.0


# ============================================================================ data
@dataclass
class GapData:
    """Measured levels on a speed grid, arranged for fast comparison.

    Attributes
    ----------
    rpm : ndarray (n_r,)
    channels : list of (mount, direction)
    quantities : list of str
        Orders (``order_2``...) then ``synthesis`` if measured.
    harmonic : ndarray (n_q,) int
        Index into the 16 orders 0.5..8 (−1 for the synthesis).
    level : ndarray (n_r, n_ch, n_q)
        Measured RMS velocity [m/s]; NaN where absent.
    floor : float
        Noise floor [m/s RMS].
    """

    rpm: np.ndarray
    channels: list
    quantities: list
    harmonic: np.ndarray
    level: np.ndarray
    floor: float

    @property
    def order_mask(self):
        return self.harmonic >= 0


def gap_data(measured, engine, noise_floor=DEFAULT_NOISE_FLOOR) -> GapData:
    """Arrange a :class:`MeasuredRunup` on the union of its speeds inside the engine range."""
    from powertrain.iotools.measured import quantity_sort_key
    lo, hi = engine.speed_range_rpm()
    rpm = np.unique(np.concatenate([r for r, _ in measured.curves.values()]))
    rpm = rpm[(rpm >= lo - 1e-9) & (rpm <= hi + 1e-9)]
    channels = [(m.name, a) for m in engine.mounts for a in ("x", "y", "z")]
    quantities = []
    for q in sorted({q for _, _, q in measured.curves}, key=quantity_sort_key):
        if q == "synthesis":
            continue
        o = float(q.split("_", 1)[1])
        if abs(2 * o - round(2 * o)) < 1e-9 and 0.5 <= o <= 8.0:
            quantities.append(q)
    if any(q == "synthesis" for _, _, q in measured.curves):
        quantities.append("synthesis")
    harmonic = np.array([-1 if q == "synthesis" else int(round(2 * float(q[6:]))) - 1
                         for q in quantities])
    level = np.full((rpm.size, len(channels), len(quantities)), np.nan)
    for (m, d, q), (r, v) in measured.curves.items():
        if (m, d) not in channels or q not in quantities:
            continue
        c, k = channels.index((m, d)), quantities.index(q)
        idx = np.searchsorted(rpm, r)
        ok = (idx < rpm.size) & (rpm[np.minimum(idx, rpm.size - 1)] == r)
        level[idx[ok], c, k] = v[ok]
    return GapData(rpm, channels, quantities, harmonic, level, float(noise_floor))


def model_levels(velocity, data: GapData):
    """Model RMS levels (n_r, n_ch, n_q) with the noise floor added in power [m/s]."""
    rms = np.abs(velocity) / np.sqrt(2.0)                      # (n_r, n_ch, 16)
    out = np.empty(velocity.shape[:2] + (data.harmonic.size,))
    f2 = data.floor ** 2
    for k, h in enumerate(data.harmonic):
        if h < 0:
            out[..., k] = np.sqrt(np.sum(rms ** 2, axis=-1) + 16 * f2)
        else:
            out[..., k] = np.sqrt(rms[..., h] ** 2 + f2)
    return out


def residuals_db(sim, meas, floor):
    """Gap [dB] with censoring at CENSOR_MARGIN × the floor; NaN where nothing was measured."""
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = 20 * np.log10(sim / meas)
        cens = meas < CENSOR_MARGIN * floor
        gap = np.where(cens, np.maximum(0.0, 20 * np.log10(sim / (CENSOR_MARGIN * floor))), gap)
    return np.where(np.isfinite(meas), gap, np.nan)


def noise_sigma_db(data: GapData) -> float:
    r"""Measurement scatter [dB, 1σ] from the measured order curves: second differences of
    the dB level along speed, :math:`\hat\sigma = 1.4826\,\mathrm{MAD}/\sqrt6` (exact for
    independent scatter on a locally linear curve)."""
    lv = data.level[:, :, data.order_mask]
    ok = np.isfinite(lv) & (lv >= CENSOR_MARGIN * data.floor)
    with np.errstate(divide="ignore", invalid="ignore"):
        L = np.where(ok, 20 * np.log10(lv), np.nan)
    d2 = L[2:] - 2 * L[1:-1] + L[:-2]
    d2 = d2[np.isfinite(d2)]
    if d2.size < 10:
        return float("nan")
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0))


def split_rpm(rpm):
    """Training and held-out speed indices (12 contiguous blocks, blocks 2, 5, 8, 11 held
    out)."""
    n = rpm.size
    block = np.minimum((np.arange(n) * N_BLOCKS) // n, N_BLOCKS - 1)
    test = np.isin(block, HELDOUT_BLOCKS)
    return np.flatnonzero(~test), np.flatnonzero(test)


def _even(idx, n_max):
    if idx.size <= n_max:
        return idx
    return idx[np.unique(np.round(np.linspace(0, idx.size - 1, n_max)).astype(int))]


# ============================================================================ where
def _hat_basis(x, knots):
    """Piecewise-linear (hat) basis on ``knots``, (n, n_knots); x clipped to the range."""
    x = np.clip(x, knots[0], knots[-1])
    B = np.zeros((x.size, knots.size))
    j = np.clip(np.searchsorted(knots, x) - 1, 0, knots.size - 2)
    t = (x - knots[j]) / (knots[j + 1] - knots[j])
    B[np.arange(x.size), j] = 1 - t
    B[np.arange(x.size), j + 1] = t
    return B


def decompose_gap(gap, data: GapData, mask):
    r"""Fit :math:`g_c + \Delta H_c(f) + \Delta F_o(n)` to the order gaps [dB].

    Parameters
    ----------
    gap : ndarray (n_r, n_ch, n_q)
    mask : ndarray bool, same shape
        Points used (finite, not censored, orders only).

    Returns
    -------
    dict with the fitted parts at every point (``const``, ``structure``, ``excitation``,
    ``residual``; arrays like ``gap``, NaN outside ``mask``), the share of the sum of squares
    each part alone carries (R²), the full-model R² and residual RMS [dB].
    """
    r_i, c_i, q_i = np.nonzero(mask)
    y = gap[mask]
    n_ch, n_q = gap.shape[1], gap.shape[2]
    order = np.array([(data.harmonic[k] + 1) / 2.0 for k in range(n_q)])
    f = order[q_i] * data.rpm[r_i] / 60.0
    fk = np.geomspace(max(f.min(), 1.0), f.max() * 1.0001, 16)
    rk = np.linspace(data.rpm.min(), data.rpm.max() * 1.0001 + 1e-6, 8)
    Bf = _hat_basis(np.log(f), np.log(fk))
    Br = _hat_basis(data.rpm[r_i], rk)
    nf, nr = fk.size, rk.size
    p_c = n_ch
    p_h = n_ch * nf
    p_f = n_q * nr
    X = np.zeros((y.size, p_c + p_h + p_f))
    X[np.arange(y.size), c_i] = 1.0
    for j in range(nf):
        X[np.arange(y.size), p_c + c_i * nf + j] = Bf[:, j]
    for j in range(nr):
        X[np.arange(y.size), p_c + p_h + q_i * nr + j] = Br[:, j]
    # penalties: second differences (smoothness), small ridge (identifiability)
    pen = []
    lam_s, lam_r = 3.0, 0.3
    for c in range(n_ch):
        for j in range(1, nf - 1):
            row = np.zeros(X.shape[1])
            row[p_c + c * nf + j - 1:p_c + c * nf + j + 2] = lam_s * np.array([1, -2, 1])
            pen.append(row)
    for k in range(n_q):
        for j in range(1, nr - 1):
            row = np.zeros(X.shape[1])
            row[p_c + p_h + k * nr + j - 1:p_c + p_h + k * nr + j + 2] = lam_s * np.array(
                [1, -2, 1])
            pen.append(row)
    ridge = np.zeros((X.shape[1], X.shape[1]))
    ridge[np.arange(p_c, X.shape[1]), np.arange(p_c, X.shape[1])] = lam_r
    A = np.vstack([X, np.array(pen), ridge])
    b = np.concatenate([y, np.zeros(A.shape[0] - y.size)])
    beta = np.linalg.lstsq(A, b, rcond=None)[0]
    parts = {"const": X[:, :p_c] @ beta[:p_c],
             "structure": X[:, p_c:p_c + p_h] @ beta[p_c:p_c + p_h],
             "excitation": X[:, p_c + p_h:] @ beta[p_c + p_h:]}
    fit = sum(parts.values())
    ss = float(np.sum(y ** 2)) or 1.0
    out = {}
    for k, v in parts.items():
        arr = np.full(gap.shape, np.nan)
        arr[mask] = v
        out[k] = arr
    res = np.full(gap.shape, np.nan)
    res[mask] = y - fit
    out["residual"] = res
    share = {}
    for k, v in parts.items():
        # sum of squares this part carries alone: best scale of it alone
        den = float(np.sum(v ** 2)) or 1.0
        s = float(np.dot(v, y)) / den
        share[k] = max(0.0, 1.0 - float(np.sum((y - s * v) ** 2)) / ss)
    out["share_alone"] = share
    out["r2_full"] = 1.0 - float(np.sum((y - fit) ** 2)) / ss
    out["residual_rms_db"] = float(np.sqrt(np.mean((y - fit) ** 2)))
    out["structure_curves"] = {"frequency_hz": fk.tolist(),
                               "by_channel": beta[p_c:p_c + p_h].reshape(n_ch, nf).tolist()}
    out["excitation_curves"] = {"rpm": rk.tolist(),
                                "by_quantity": beta[p_c + p_h:].reshape(n_q, nr).tolist()}
    out["channel_const_db"] = beta[:p_c].tolist()
    return out


def rigid_span_gap(velocity, data: GapData, channel_matrix):
    r"""Gap left outside the rigid-body span [dB], (n_r, n_q_orders) RMS over channels.

    Measured magnitudes with the simulated phases,
    :math:`\tilde v_c = m_c\,e^{i\angle s_c}`, projected (least squares) on the span of the
    channel matrix :math:`\mathbf C` (9×6); the RMS over channels of
    :math:`20\log_{10}(|P\tilde v|_c/m_c)` is returned where all channels are measured.
    """
    qs = np.flatnonzero(data.order_mask)
    out = np.full((data.rpm.size, qs.size), np.nan)
    pinv = channel_matrix @ np.linalg.pinv(channel_matrix)
    for j, k in enumerate(qs):
        h = data.harmonic[k]
        m = data.level[:, :, k]
        ok = np.all(np.isfinite(m) & (m >= CENSOR_MARGIN * data.floor), axis=1)
        if not ok.any():
            continue
        ph = np.exp(1j * np.angle(velocity[ok][:, :, h]))
        vt = m[ok] * ph
        proj = vt @ pinv.T
        out[ok, j] = np.sqrt(np.mean((20 * np.log10(np.abs(proj) / m[ok])) ** 2, axis=1))
    return out


def _regions(gap, data: GapData, parts):
    """Contiguous speed ranges with |gap| > REGION_DB per channel and quantity."""
    regions = []
    for c, (mount, direction) in enumerate(data.channels):
        for k, q in enumerate(data.quantities):
            g = gap[:, c, k]
            over = np.isfinite(g) & (np.abs(g) > REGION_DB)
            i = 0
            while i < over.size:
                if not over[i]:
                    i += 1
                    continue
                j = i
                while j + 1 < over.size and over[j + 1]:
                    j += 1
                sl = slice(i, j + 1)
                seg = g[sl]
                kind = "synthesis (see orders)" if data.harmonic[k] < 0 else _region_kind(
                    parts, sl, c, k)
                worst = i + int(np.nanargmax(np.abs(seg)))
                regions.append({"mount": mount, "direction": direction, "quantity": q,
                                "rpm_from": float(data.rpm[i]), "rpm_to": float(data.rpm[j]),
                                "n_points": int(j - i + 1),
                                "max_abs_db": float(np.nanmax(np.abs(seg))),
                                "gap_at_max_db": float(g[worst]),
                                "frequency_hz_at_max": float(
                                    data.rpm[worst] * (data.harmonic[k] + 1) / 120.0)
                                if data.harmonic[k] >= 0 else None,
                                "kind": kind})
                i = j + 1
    regions.sort(key=lambda r: -r["max_abs_db"])
    return regions


def _region_kind(parts, sl, c, k):
    ss = {}
    for name, label in (("structure", "structural (tied to frequency)"),
                        ("excitation", "excitation (tied to order/speed)"),
                        ("const", "sensor gain (constant per channel)"),
                        ("residual", "local/unexplained by smooth parts")):
        v = parts[name][sl, c, k]
        ss[label] = float(np.nansum(v ** 2))
    return max(ss, key=ss.get)


# ============================================================================ which
@dataclass
class FitOutcome:
    """A fitted candidate (one effect or a pair)."""

    effects: tuple
    params: dict
    sigma: dict
    rss_train: float
    n_train: int
    n_params: int
    bic: float
    heldout_mse: float
    heldout_rms_db: float
    heldout_per_rpm: np.ndarray
    heldout_channel_rms: list
    nfev: int
    seconds: float
    t_stat: float = float("nan")
    bic_gain: float = float("nan")
    explained: float = float("nan")
    status: str = ""
    struct_db: float = float("nan")
    chi2_ratio: float = float("nan")
    cells_check: dict | None = None

    @property
    def label(self) -> str:
        return "+".join(self.effects)


class _Problem:
    """Residual functions on the training and held-out speeds."""

    def __init__(self, hm_train, hm_test, data, train_idx, test_idx, train_cells=None,
                 test_cells=None):
        self.hm = {"train": hm_train, "test": hm_test}
        self.data = data
        self.idx = {"train": train_idx, "test": test_idx}
        om = data.order_mask
        self.meas = {k: data.level[v][:, :, om] for k, v in self.idx.items()}
        self.sub = GapData(data.rpm, data.channels,
                           [q for q, o in zip(data.quantities, om) if o],
                           data.harmonic[om], data.level[:, :, om], data.floor)
        self.valid = {k: np.isfinite(v) for k, v in self.meas.items()}
        self._last = {}
        # optional (channel, order) cells used for fitting / scoring (held-out channels or
        # orders): bool (n_ch, n_orders)
        for part, cells in (("train", train_cells), ("test", test_cells)):
            if cells is not None:
                self.valid[part] = self.valid[part] & np.asarray(cells, bool)[None]

    def gaps(self, scenario, part="train"):
        # the physical part of the scenario is solved once per distinct value: a sensor
        # error only re-reads the same velocities (cheap finite-difference columns)
        phys = {k: v for k, v in scenario.items() if k != "sensor_error"}
        key = repr(sorted((k, sorted(v.items())) for k, v in phys.items()))
        last = self._last.get(part)
        if last is not None and last[0] == key:
            vel = last[1]
        else:
            vel = predict(self.hm[part], phys).velocity
            self._last[part] = (key, vel)
        if "sensor_error" in scenario:
            vel = apply_sensor_error(vel, scenario["sensor_error"])
        sim = model_levels(vel, self.sub)
        g = residuals_db(sim, self.meas[part], self.data.floor)
        return np.where(self.valid[part], g, np.nan)

    def vector(self, scenario, part="train"):
        g = self.gaps(scenario, part)
        return g[self.valid[part]]


def _pack(effects):
    names, lo, hi, logs, x0 = [], [], [], [], []
    for e in effects:
        for p in EFFECTS[e].parameters:
            names.append((e, p.name))
            lo.append(math.log(p.lower) if p.log else p.lower)
            hi.append(math.log(p.upper) if p.log else p.upper)
            logs.append(p.log)
            x0.append(math.log(p.default) if p.log else p.default)
    return names, np.array(lo), np.array(hi), np.array(logs), np.array(x0)


def _scenario(names, logs, x):
    sc = {}
    for (e, p), lg, v in zip(names, logs, x):
        sc.setdefault(e, {})[p] = float(math.exp(v) if lg else v)
    return sc


def _applicable(engine, effect):
    if effect == "cylinder_imbalance":
        return getattr(engine.combustion, "model", "") == "single-zone"
    if effect == "balancer_error":
        return len(engine.balancer.shafts) > 0
    if effect == "mount_stiffness":
        return len(engine.mounts) <= 3
    return True


def fit_candidate(problem: _Problem, effects, starts=None, grid=True) -> FitOutcome:
    """Fit one effect or a combination on the training speeds, score on the held-out ones."""
    from scipy.optimize import least_squares
    t0 = time.perf_counter()
    names, lo, hi, logs, x0 = _pack(effects)
    span = hi - lo
    inner_lo, inner_hi = lo + 1e-9 * span, hi - 1e-9 * span
    cands = [np.clip(x0, inner_lo, inner_hi)]
    for s in starts or []:
        cands.append(np.clip(s, inner_lo, inner_hi))
    # coarse grid of start points for effects that declare one (the cylinder IMEP factors
    # need one: at e = 0 the half orders vanish and the gradient of their level with them)
    if grid and len(effects) == 1 and EFFECTS[effects[0]].start_grid:
        grid = EFFECTS[effects[0]].start_grid
        mesh = np.meshgrid(*grid, indexing="ij")
        pts = np.stack([m.ravel() for m in mesh], axis=1).astype(float)
        pts[:, logs] = np.log(pts[:, logs])
        costs = [np.sum(problem.vector(_scenario(names, logs, p)) ** 2) for p in pts]
        for i in np.argsort(costs)[:2]:
            cands.append(np.clip(pts[i], inner_lo, inner_hi))
    best, nfev = None, 0

    def fun(x):
        return problem.vector(_scenario(names, logs, x))

    for x_start in cands:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = least_squares(fun, x_start, bounds=(lo, hi), x_scale=np.maximum(span / 8, 1e-3),
                                method="trf", max_nfev=60 * len(x_start), diff_step=1e-4)
        nfev += res.nfev
        if best is None or res.cost < best.cost:
            best = res
    r = best.fun
    n, p = r.size, len(names)
    rss = float(np.sum(r ** 2))
    # Gauss-Newton covariance in the fitted coordinates
    J = best.jac
    s2 = rss / max(n - p, 1)
    try:
        cov = s2 * np.linalg.pinv(J.T @ J)
        sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        sd = np.full(p, np.nan)
    params, sigma = {}, {}
    for (e, pn), lg, v, s in zip(names, logs, best.x, sd):
        val = math.exp(v) if lg else v
        params.setdefault(e, {})[pn] = float(val)
        sigma.setdefault(e, {})[pn] = float(val * s if lg else s)
    sc = _scenario(names, logs, best.x)
    return _score(problem, effects, sc, params, sigma, rss, n, p, nfev,
                  time.perf_counter() - t0, best.x)


def _score(problem, effects, sc, params, sigma, rss, n, p, nfev, seconds, x=None):
    g = problem.gaps(sc, "test")
    valid = np.isfinite(g)
    per_rpm = np.array([np.mean(g[i][valid[i]] ** 2) if valid[i].any() else np.nan
                        for i in range(g.shape[0])])
    mse = float(np.mean(g[valid] ** 2))
    ch = []
    for c in range(g.shape[1]):
        v = g[:, c][valid[:, c]]
        ch.append(float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan"))
    bic = n * math.log(max(rss, 1e-300) / n) + p * math.log(n)
    out = FitOutcome(tuple(effects), params, sigma, rss, n, p, bic, mse, math.sqrt(mse),
                     per_rpm, ch, nfev, seconds)
    out.x = x
    out.heldout_gaps = g
    return out


def _compare(base: FitOutcome, cand: FitOutcome):
    """t statistic of the held-out improvement per speed, and the BIC gain."""
    d = base.heldout_per_rpm - cand.heldout_per_rpm
    d = d[np.isfinite(d)]
    if d.size < 2:
        return float("nan"), base.bic - cand.bic
    sd = float(np.std(d, ddof=1))
    t = float(np.mean(d)) / (sd / math.sqrt(d.size)) if sd > 0 else (
        float("inf") if np.mean(d) > 0 else 0.0)
    return t, base.bic - cand.bic


def _speed_groups(test_idx, size=4):
    """Runs of adjacent held-out speeds, cut into groups of about ``size`` speeds."""
    runs, start = [], 0
    for i in range(1, test_idx.size + 1):
        if i == test_idx.size or test_idx[i] != test_idx[i - 1] + 1:
            runs.append(np.arange(start, i))
            start = i
    groups = []
    for r in runs:
        k = max(1, int(round(r.size / size)))
        groups += [g for g in np.array_split(r, k) if g.size >= 2]
    return groups


def structured_residual(g, censored, groups, sigma, cells=None):
    r"""Structured part of held-out residuals [dB RMS beyond noise] and its χ² ratio.

    For every group of adjacent held-out speeds and every (channel, order) the mean
    residual :math:`\bar g` of the :math:`n` uncensored points is formed; pure noise of
    scatter :math:`\sigma` gives :math:`E[\bar g^2] = \sigma^2/n`. Returned:
    :math:`\sqrt{\max(0,\ \overline{\bar g^2 - \sigma^2/n})}` and the ratio
    :math:`\overline{n\bar g^2/\sigma^2}` (≈ 1 for noise).

    Parameters
    ----------
    g : ndarray (n_test, n_ch, n_o)
        Held-out residuals [dB] (NaN where not scored).
    censored : ndarray bool, same shape
    groups : list of index arrays into the first axis
    sigma : float
        Noise [dB, 1σ].
    cells : ndarray bool (n_ch, n_o), optional
        Cells included (default all).
    """
    ok = np.isfinite(g) & ~censored
    if cells is not None:
        ok &= np.asarray(cells, bool)[None]
    z, chi = [], []
    s2 = sigma ** 2 if np.isfinite(sigma) and sigma > 0 else 0.0
    for grp in groups:
        n = ok[grp].sum(axis=0)
        sm = np.where(ok[grp], g[grp], 0.0).sum(axis=0)
        use = n >= 2
        m = sm[use] / n[use]
        z.append(m ** 2 - s2 / n[use])
        if s2 > 0:
            chi.append(n[use] * m ** 2 / s2)
    if not z:
        return float("nan"), float("nan")
    z = np.concatenate(z)
    chi_r = float(np.mean(np.concatenate(chi))) if chi else float("nan")
    return float(math.sqrt(max(float(np.mean(z)), 0.0))), chi_r


def _cells_mse(o: FitOutcome, cells):
    g = o.heldout_gaps
    ok = np.isfinite(g) & np.asarray(cells, bool)[None]
    per = np.array([np.mean(g[i][ok[i]] ** 2) if ok[i].any() else np.nan
                    for i in range(g.shape[0])])
    return float(np.mean(g[ok] ** 2)) if ok.any() else float("nan"), per


def noise_mse(problem, sigma, cells=None) -> float:
    r"""Expected held-out mean squared gap of a perfect model [dB²]: :math:`\hat\sigma^2`
    times the fraction of scored held-out points that are not censored (a censored point's
    residual, :math:`\max(0, 20\log_{10}(s'/3f))`, is 0 for a model below the censoring
    level, whatever the noise).

    Parameters
    ----------
    problem : _Problem
    sigma : float
        Noise [dB, 1σ] (NaN: 0 returned).
    cells : ndarray bool (n_ch, n_o), optional
        Restrict to these (channel, order) cells.
    """
    if not (np.isfinite(sigma) and sigma > 0):
        return 0.0
    valid = problem.valid["test"]
    if cells is not None:
        valid = valid & np.asarray(cells, bool)[None]
    unc = valid & (problem.meas["test"] >= CENSOR_MARGIN * problem.data.floor)
    n = int(valid.sum())
    return float(sigma ** 2 * unc.sum() / n) if n else 0.0


def heldout_cells_check(problem, o: FitOutcome, baseline: FitOutcome, sigma):
    """Refit ``o``'s effects without some (channel, order) cells and score the withheld
    cells at the held-out speeds (cross-validation over cells as well as speeds).

    Physical effects (no ``sensor_error``) withhold channels (:data:`CHANNEL_FOLDS`): a
    physical effect predicts a channel it was not fitted on through the rigid-body
    kinematics, a channel gain cannot. Candidates with ``sensor_error`` withhold orders
    (orders up to :data:`ORDER_SPLIT` vs the others, both ways): a true gain is the same on
    every order of its channel, a frequency-dependent gap is not.

    Returns
    -------
    dict
        ``kind``, ``explained`` (fraction of the withheld cells' held-out excess over noise
        removed), ``t`` (per-speed significance), ``baseline_excess_db`` and ``seconds``.
    """
    t0 = time.perf_counter()
    n_ch, n_o = problem.valid["test"].shape[1:]
    if "sensor_error" in o.effects:
        kind = "orders"
        order = (problem.sub.harmonic + 1) / 2.0
        low = np.broadcast_to(order <= ORDER_SPLIT + 1e-9, (n_ch, n_o))
        folds = [low, ~low]
    else:
        kind = "channels"
        folds = []
        for f in CHANNEL_FOLDS:
            m = np.zeros((n_ch, n_o), bool)
            m[[c for c in f if c < n_ch]] = True
            folds.append(m)
    g_all = np.full(problem.valid["test"].shape, np.nan)
    for held in folds:
        if not held.any() or held.all():
            continue
        prob = _Problem(problem.hm["train"], problem.hm["test"], problem.data,
                        problem.idx["train"], problem.idx["test"], train_cells=~held,
                        test_cells=held)
        fo = fit_candidate(prob, o.effects, starts=[o.x], grid=False)
        g_all = np.where(np.isfinite(fo.heldout_gaps), fo.heldout_gaps, g_all)
    ok = np.isfinite(g_all)
    per_c = np.array([np.mean(g_all[i][ok[i]] ** 2) if ok[i].any() else np.nan
                      for i in range(g_all.shape[0])])
    cells = ok.any(axis=0)
    e0, per_0 = _cells_mse(baseline, cells)
    ec = float(np.mean(g_all[ok] ** 2)) if ok.any() else float("nan")
    excess = max(e0 - noise_mse(problem, sigma, cells), 0.0)
    d = per_0 - per_c
    d = d[np.isfinite(d)]
    sd = float(np.std(d, ddof=1)) if d.size > 1 else 0.0
    t = float(np.mean(d)) / (sd / math.sqrt(d.size)) if sd > 0 else 0.0
    return {"kind": kind, "explained": (e0 - ec) / excess if excess > 0 else float("nan"),
            "t": t, "baseline_excess_db": math.sqrt(excess), "heldout_rms_db": math.sqrt(ec),
            "seconds": time.perf_counter() - t0}


def _band_check(problem_factory, effect, data, train_idx, n_bands=4):
    """Refit one effect on speed bands of the training data: parameter trend with speed."""
    out = []
    edges = np.linspace(0, train_idx.size, n_bands + 1).astype(int)
    for b in range(n_bands):
        idx = train_idx[edges[b]:edges[b + 1]]
        if idx.size < 3:
            continue
        prob = problem_factory(idx)
        fo = fit_candidate(prob, (effect,))
        out.append({"rpm_from": float(data.rpm[idx[0]]), "rpm_to": float(data.rpm[idx[-1]]),
                    "parameters": fo.params[effect], "sigma": fo.sigma[effect]})
    return out


# ============================================================================ result
@dataclass
class DiagnosisResult:
    """Everything the diagnosis found; ``.to_json()``, ``.summary()``, ``.report(dir)``."""

    data: GapData
    source: str
    engine_name: str
    gap: np.ndarray
    gap_after: np.ndarray | None
    parts: dict
    rigid_gap: np.ndarray
    regions: list
    noise_db: float
    split: dict
    baseline: FitOutcome
    outcomes: list
    chosen: FitOutcome | None
    verdict: str
    verdict_text: str
    band_check: list
    seconds: float
    synthetic: bool = False
    notes: list = field(default_factory=list)
    #: E_n: held-out mean squared gap a perfect model would leave [dB²] (:func:`noise_mse`).
    noise_mse_heldout: float = 0.0
    #: Labels of candidates that pass the decision rule but cannot be told apart.
    ambiguous: list = field(default_factory=list)

    # ------------------------------------------------------------------ dicts
    def where(self) -> dict:
        d = self.data
        chans = []
        for c, (m, di) in enumerate(d.channels):
            for k, q in enumerate(d.quantities):
                g = self.gap[:, c, k]
                ok = np.isfinite(g)
                if not ok.any():
                    continue
                chans.append({"mount": m, "direction": di, "quantity": q,
                              "rms_db": float(np.sqrt(np.mean(g[ok] ** 2))),
                              "bias_db": float(np.mean(g[ok])),
                              "max_abs_db": float(np.max(np.abs(g[ok])))})
        p = self.parts
        rg = self.rigid_gap[np.isfinite(self.rigid_gap)]
        return {
            "gap_definition": "20 log10(sim/measured) dB, + = simulation higher; noise floor "
                              "added to the model in power; censored below 3x floor",
            "rpm": d.rpm.tolist(),
            "channels": [list(c) for c in d.channels],
            "quantities": list(d.quantities),
            "gap_db": [[[None if not np.isfinite(x) else round(float(x), 3) for x in row]
                        for row in mat] for mat in self.gap],
            "gap_db_after": None if self.gap_after is None else
            [[[None if not np.isfinite(x) else round(float(x), 3) for x in row]
              for row in mat] for mat in self.gap_after],
            "per_channel": chans,
            "regions_beyond_3db": self.regions,
            "decomposition": {
                "model": "gap = g_channel + dH_channel(f = order*rpm/60) + dF_order(rpm)",
                "share_alone": p["share_alone"], "r2_full": p["r2_full"],
                "residual_rms_db": p["residual_rms_db"],
                "channel_const_db": p["channel_const_db"],
                "structure_curves": p["structure_curves"],
                "excitation_curves": p["excitation_curves"]},
            "outside_rigid_span_rms_db": {
                "median": float(np.median(rg)) if rg.size else None,
                "p90": float(np.percentile(rg, 90)) if rg.size else None},
            "noise_sigma_db": self.noise_db,
        }

    def _outcome_dict(self, o: FitOutcome) -> dict:
        return {"effect": o.label, "effects": list(o.effects), "parameters": o.params,
                "parameter_sigma": o.sigma, "n_parameters": o.n_params,
                "heldout_rms_db_before": self.baseline.heldout_rms_db,
                "heldout_rms_db_after": o.heldout_rms_db,
                "heldout_channel_rms_db_before": self.baseline.heldout_channel_rms,
                "heldout_channel_rms_db_after": o.heldout_channel_rms,
                "train_bic_gain": o.bic_gain, "heldout_t": o.t_stat,
                "explained_fraction_of_excess": o.explained, "verdict": o.status,
                "heldout_structured_residual_db": o.struct_db,
                "heldout_block_chi2_ratio": o.chi2_ratio,
                "heldout_cells_check": o.cells_check,
                "nfev": o.nfev, "seconds": o.seconds}

    def to_dict(self) -> dict:
        b = self.baseline
        excess = math.sqrt(max(b.heldout_mse - self.noise_mse_heldout, 0.0))
        return {
            "source": self.source, "synthetic": self.synthetic, "engine": self.engine_name,
            "where": self.where(),
            "ranking": [self._outcome_dict(o) for o in self.outcomes],
            "verdict": self.verdict, "verdict_text": self.verdict_text,
            "chosen": None if self.chosen is None else self._outcome_dict(self.chosen),
            "heldout_rms_db_before": b.heldout_rms_db,
            "heldout_rms_db_after": (self.chosen or b).heldout_rms_db,
            "heldout_excess_rms_db_before": excess,
            "heldout_noise_mse_db2": self.noise_mse_heldout,
            "ambiguous_between": self.ambiguous,
            "split": self.split,
            "confounding_check": self.band_check,
            "decision_rule": {"T_MIN": T_MIN, "BIC_MARGIN": BIC_MARGIN,
                              "EXPLAINED_MIN": EXPLAINED_MIN, "EXCESS_MIN_DB": EXCESS_MIN_DB,
                              "PAIR_GAIN_MIN": PAIR_GAIN_MIN, "STRUCT_ABS_DB": STRUCT_ABS_DB,
                              "STRUCT_REL": STRUCT_REL, "XV_EXPLAINED_MIN": XV_EXPLAINED_MIN,
                              "CHANNEL_FOLDS": CHANNEL_FOLDS, "ORDER_SPLIT": ORDER_SPLIT},
            "baseline_heldout_structured_db": b.struct_db,
            "effects_library": [e.to_dict() for e in EFFECTS.values()],
            "seconds": self.seconds, "notes": self.notes,
        }

    def to_json(self, path=None) -> str:
        text = json.dumps(self.to_dict(), indent=1, allow_nan=False, default=_jsonable)
        if path is not None:
            from powertrain.iotools.atomic import atomic_write
            with atomic_write(path) as fh:
                fh.write(text)
        return text

    # ------------------------------------------------------------------ text
    def summary(self) -> str:
        b = self.baseline
        d = self.data
        lines = [f"measured: {self.source}{' [SYNTHETIC]' if self.synthetic else ''}",
                 f"engine: {self.engine_name}",
                 f"data: {d.rpm.size} speeds {d.rpm[0]:g}..{d.rpm[-1]:g} rpm, "
                 f"{len(d.channels)} channels, quantities {', '.join(d.quantities)}; "
                 f"noise estimate {self.noise_db:.2f} dB (1 sigma)",
                 f"split: {self.split['description']}", "",
                 "1. WHERE",
                 f"  decomposition of the order gaps (share of sum of squares, each part "
                 f"alone): structure/frequency {self.parts['share_alone']['structure']:.0%}, "
                 f"excitation/order {self.parts['share_alone']['excitation']:.0%}, "
                 f"channel constant {self.parts['share_alone']['const']:.0%}; all together "
                 f"{self.parts['r2_full']:.0%}, residual {self.parts['residual_rms_db']:.2f} "
                 f"dB RMS"]
        rg = self.rigid_gap[np.isfinite(self.rigid_gap)]
        if rg.size:
            lines.append(f"  outside the rigid-body span: median {np.median(rg):.2f} dB RMS "
                         f"over channels (90 % {np.percentile(rg, 90):.2f} dB)")
        lines.append(f"  regions beyond +-{REGION_DB:g} dB: {len(self.regions)}")
        for r in self.regions[:12]:
            fq = (f" ({r['frequency_hz_at_max']:.0f} Hz)" if r["frequency_hz_at_max"]
                  else "")
            lines.append(f"    {r['mount']:>7} {r['direction']} {r['quantity']:<10} "
                         f"{r['rpm_from']:>6g}-{r['rpm_to']:<6g} rpm  max {r['gap_at_max_db']:+.1f} "
                         f"dB{fq}  {r['kind']}")
        if len(self.regions) > 12:
            lines.append(f"    ... {len(self.regions) - 12} more in the JSON")
        lines += ["", "2. WHICH (fitted on the training speeds, scored on the held-out ones)",
                  f"  {'candidate':<40} {'p':>2} {'held-out dB':>11} {'t':>6} {'dBIC':>8} "
                  f"{'expl.':>6} {'struct dB':>9}  status"]
        lines.append(f"  {'(baseline)':<40} {0:>2} {b.heldout_rms_db:>11.2f} {'':>6} {'':>8} "
                     f"{'':>6} {b.struct_db:>9.2f}")
        for o in self.outcomes:
            lines.append(f"  {o.label:<40} {o.n_params:>2} {o.heldout_rms_db:>11.2f} "
                         f"{o.t_stat:>6.1f} {o.bic_gain:>8.1f} {o.explained:>6.0%} "
                         f"{o.struct_db:>9.2f}  {o.status}")
        if self.chosen is not None:
            lines.append("  parameters (1 sigma, Gauss-Newton, optimistic):")
            for e, ps in self.chosen.params.items():
                spec = {p.name: p for p in EFFECTS[e].parameters}
                txt = ", ".join(f"{k} = {v:.4g} +- {self.chosen.sigma[e][k]:.2g} "
                                f"{spec[k].unit}" for k, v in ps.items())
                lines.append(f"    {e}: {txt}")
        if self.band_check:
            lines.append("  confounding check (refit on speed bands):")
            for bnd in self.band_check:
                txt = ", ".join(f"{k}={v:.3g}" for k, v in bnd["parameters"].items())
                lines.append(f"    {bnd['rpm_from']:g}-{bnd['rpm_to']:g} rpm: {txt}")
        lines += ["", "3. HOW FAR (held-out speeds)"]
        after = self.chosen or b
        lines.append(f"  {'mount':>7} {'dir':>3} {'before dB':>9} {'after dB':>8}")
        for c, (m, di) in enumerate(d.channels):
            lines.append(f"  {m:>7} {di:>3} {b.heldout_channel_rms[c]:>9.2f} "
                         f"{after.heldout_channel_rms[c]:>8.2f}")
        lines.append(f"  overall {b.heldout_rms_db:.2f} -> {after.heldout_rms_db:.2f} dB RMS")
        lines += ["", f"VERDICT: {self.verdict_text}", f"({self.seconds:.1f} s)"]
        return "\n".join(lines)

    # ------------------------------------------------------------------ figures
    def plot(self, path=None):
        """Gap map figure (see :func:`powertrain.plotting.plot_gap_map`)."""
        from powertrain.plotting import plot_gap_map
        return plot_gap_map(self, path)

    def report(self, directory) -> list:
        """Write ``summary.txt``, ``diagnosis.json`` and the figures into ``directory``."""
        from pathlib import Path

        from powertrain.iotools.atomic import atomic_write
        from powertrain.plotting import plot_diagnosis_overlay, plot_gap_frequency, plot_gap_map
        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        files = []
        with atomic_write(out / "summary.txt") as fh:
            fh.write(self.summary() + "\n")
        files.append(out / "summary.txt")
        self.to_json(out / "diagnosis.json")
        files.append(out / "diagnosis.json")
        for name, fn in (("gap_map.png", plot_gap_map), ("gap_vs_frequency.png",
                                                           plot_gap_frequency),
                         ("overlay.png", plot_diagnosis_overlay)):
            fn(self, out / name)
            files.append(out / name)
        return files


def _jsonable(x):
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    raise TypeError(type(x))


# ============================================================================ driver
def diagnose(measured, engine, *, noise_floor=DEFAULT_NOISE_FLOOR, effects=None,
             pairs=True, band_check=True) -> DiagnosisResult:
    """Diagnose the gap between ``engine``'s simulated run-up and ``measured``.

    Parameters
    ----------
    measured : MeasuredRunup
        Measured order curves [m/s RMS].
    engine : Engine
        Baseline model.
    noise_floor : float
        RMS noise floor of the measured order curves [m/s].
    effects : sequence of str, optional
        Candidates (default: all of :data:`powertrain.effects.EFFECTS` that apply).
    pairs : bool
        Also fit the pairs of the three best single candidates.

    Returns
    -------
    DiagnosisResult

    Raises
    ------
    InputError
        Too few speeds to split, or nothing comparable.
    """
    from threadpoolctl import threadpool_limits
    with threadpool_limits(limits=1, user_api="blas"):
        return _diagnose(measured, engine, noise_floor, effects, pairs, band_check)


def _diagnose(measured, engine, noise_floor, effects, pairs, band_check):
    t0 = time.perf_counter()
    data = gap_data(measured, engine, noise_floor)
    src = getattr(measured, "source", "")
    if data.rpm.size < MIN_RPM:
        raise InputError(f"only {data.rpm.size} measured speeds inside the engine's range: "
                         f"too few to split into training and held-out speeds (need at least "
                         f"{MIN_RPM})", file=src or None, key="rpm")
    om = data.order_mask
    usable = np.isfinite(data.level[:, :, om]) & (data.level[:, :, om] >= CENSOR_MARGIN * data.floor)
    if not om.any() or usable.sum() < 20:
        raise InputError("fewer than 20 measured order points above twice the noise floor: "
                         "nothing to diagnose", file=src or None)
    train_all, test_all = split_rpm(data.rpm)
    train_idx, test_idx = _even(train_all, N_FIT_RPM), _even(test_all, N_TEST_RPM)
    effects = [e for e in (effects or EFFECTS) if _applicable(engine, e)]
    # one cached model over all speeds; sub-models share its load harmonics
    hm = HarmonicModel(engine, data.rpm)
    hm.two_ports()
    need = np.union1d(train_all, test_idx)
    hm_need = hm.subset(need)
    hm_need.two_ports()
    _ = hm_need.load
    if "balancer_error" in effects:
        hm_need.shaft_loads()
    if "cylinder_imbalance" in effects:
        hm_need.imep_derivatives()
    pos = {int(r): i for i, r in enumerate(need)}

    def sub(idx):
        return hm_need.subset([pos[int(i)] for i in idx])

    problem = _Problem(sub(train_idx), sub(test_idx), data, train_idx, test_idx)
    # ---- where
    vel0 = predict(hm, {}).velocity
    gap = residuals_db(model_levels(vel0, data), data.level, data.floor)
    cens = data.level < CENSOR_MARGIN * data.floor
    gap_map = np.where(cens, np.nan, gap)
    mask = np.isfinite(gap_map) & om[None, None, :]
    parts = decompose_gap(gap_map, data, mask)
    rigid = rigid_span_gap(vel0, data, hm.channel_matrix)
    regions = _regions(gap_map, data, parts)
    sigma = noise_sigma_db(data)
    # ---- which
    n0 = int(problem.valid["train"].sum())
    r0 = problem.vector({})
    baseline = _score(problem, (), {}, {}, {}, float(np.sum(r0 ** 2)), n0, 0, 1, 0.0)
    outcomes = []
    for e in effects:
        fo = fit_candidate(problem, (e,))
        outcomes.append(fo)
    for o in outcomes:
        o.t_stat, o.bic_gain = _compare(baseline, o)
    singles = sorted(outcomes, key=lambda o: o.heldout_mse)
    if pairs:
        for a, b in combinations(singles[:3], 2):
            effs = (a.effects[0], b.effects[0])
            names, _, _, logs, x0 = _pack(effs)
            xa = a.x
            xb = b.x
            starts = [np.concatenate([xa, xb])]
            fo = fit_candidate(problem, effs, starts=starts)
            fo.t_stat, fo.bic_gain = _compare(baseline, fo)
            outcomes.append(fo)
    e0 = baseline.heldout_mse
    s2_heldout = noise_mse(problem, sigma)
    excess0 = max(e0 - s2_heldout, 0.0)
    for o in outcomes:
        o.explained = (e0 - o.heldout_mse) / excess0 if excess0 > 0 else float("nan")
        supported = (o.bic_gain > BIC_MARGIN and o.t_stat > T_MIN
                     and o.heldout_mse < e0)
        o.status = "supported" if supported else "not supported"
    # pairs must beat their better member
    by_label = {o.label: o for o in outcomes}
    for o in outcomes:
        if len(o.effects) == 2 and o.status == "supported":
            members = [by_label[e] for e in o.effects]
            best_m = min(members, key=lambda m: m.heldout_mse)
            t, dbic = _compare(best_m, o)
            left = best_m.heldout_mse - s2_heldout
            gain = (best_m.heldout_mse - o.heldout_mse) / left if left > 0 else 0.0
            if not (t > T_MIN and dbic > BIC_MARGIN and gain >= PAIR_GAIN_MIN):
                o.status = f"not better than {best_m.label} alone"
    outcomes.sort(key=lambda o: o.heldout_mse)
    # residual structure on the held-out speeds (all outcomes; cheap)
    groups = _speed_groups(test_idx)
    cens_t = ~(problem.meas["test"] >= CENSOR_MARGIN * data.floor)
    baseline.struct_db, baseline.chi2_ratio = structured_residual(
        baseline.heldout_gaps, cens_t, groups, sigma)
    for o in outcomes:
        o.struct_db, o.chi2_ratio = structured_residual(o.heldout_gaps, cens_t, groups, sigma)
    struct_max = max(STRUCT_ABS_DB, STRUCT_REL * baseline.struct_db)
    supported = [o for o in outcomes if o.status == "supported"]
    chosen = None
    excess_db = math.sqrt(excess0)
    big = [o for o in supported if np.isfinite(o.explained) and o.explained >= EXPLAINED_MIN]
    for o in big[:N_CHECKED]:
        if not o.struct_db <= struct_max:
            o.status = (f"residual structured ({o.struct_db:.2f} dB > {struct_max:.2f} dB "
                        f"beyond noise)")
            continue
        o.cells_check = heldout_cells_check(problem, o, baseline, sigma)
        xv = o.cells_check
        if xv["baseline_excess_db"] >= EXCESS_MIN_DB and not (
                xv["explained"] >= XV_EXPLAINED_MIN and xv["t"] > T_MIN):
            o.status = (f"fails held-out {xv['kind']} (explains {xv['explained']:.0%}, "
                        f"t {xv['t']:.1f})")
            continue
        chosen = o
        break
    # confounding: an admissible rival from another effect family that the held-out data
    # cannot tell apart from the answer makes the answer ambiguous, not a claim
    rivals = []
    if chosen is not None:
        mine = set(chosen.effects)
        for o in outcomes:
            theirs = set(o.effects)
            if (o is chosen or o.status != "supported" or theirs <= mine or mine <= theirs
                    or not (np.isfinite(o.explained) and o.explained >= EXPLAINED_MIN)
                    or not o.struct_db <= struct_max):
                continue
            t_rival = _compare(o, chosen)[0]
            if not t_rival > T_MIN:
                rivals.append((o, t_rival))
    ambiguous = []
    if rivals:
        ambiguous = [chosen.label] + [o.label for o, _ in rivals]
        chosen.status = "indistinguishable from " + ", ".join(o.label for o, _ in rivals)
        for o, t_rival in rivals:
            o.status = f"indistinguishable from {chosen.label} (t {t_rival:.1f})"
        verdict = "ambiguous"
        verdict_text = (
            "ambiguous: " + " or ".join(f"{o.label} (explains {o.explained:.0%})"
                                        for o in [chosen] + [r for r, _ in rivals])
            + f"; each passes the decision rule but the held-out speeds do not tell them "
              f"apart (t {max(t for _, t in rivals):.1f} <= {T_MIN:g}); data at other "
              f"amplitudes, loads or channels are needed to decide")
        chosen = None
    elif chosen is not None:
        best = chosen
        best.status = "chosen"
        verdict = best.label
        verdict_text = (f"{best.label}: explains {best.explained:.0%} of the held-out "
                        f"excess gap over noise; held-out RMS gap {e0 ** 0.5:.2f} -> "
                        f"{best.heldout_rms_db:.2f} dB; structured residual "
                        f"{best.struct_db:.2f} dB (baseline {baseline.struct_db:.2f} dB); "
                        f"withheld {best.cells_check['kind']}: explains "
                        f"{best.cells_check['explained']:.0%}")
    elif supported:
        best = supported[0]
        if best.status == "supported":
            best.status = "partial"
        verdict = "unexplained"
        verdict_text = (f"unexplained: the best candidate, {best.label}, explains "
                        f"{best.explained:.0%} of the held-out excess gap "
                        f"({excess_db:.2f} dB RMS over noise) but fails the decision rule "
                        f"({best.status}); " + _where_text(regions, parts))
    elif excess_db < EXCESS_MIN_DB:
        verdict = "no effect"
        verdict_text = (f"no effect: the held-out gap ({e0 ** 0.5:.2f} dB RMS) is within "
                        f"noise ({sigma:.2f} dB; excess {excess_db:.2f} dB < "
                        f"{EXCESS_MIN_DB:g} dB) and no candidate improves it significantly")
    else:
        verdict = "unexplained"
        verdict_text = (f"unexplained: no candidate improves the held-out gap "
                        f"significantly; excess over noise {excess_db:.2f} dB RMS; "
                        + _where_text(regions, parts))
    # ---- how far: the chosen effect on every speed (for the map and overlays)
    gap_after = None
    if chosen is not None:
        sc = {e: chosen.params[e] for e in chosen.effects}
        vel1 = predict(hm, sc).velocity
        g1 = residuals_db(model_levels(vel1, data), data.level, data.floor)
        gap_after = np.where(cens, np.nan, g1)
    bands = []
    if band_check and chosen is not None and len(chosen.effects) == 1:
        def factory(idx):
            return _Problem(sub(idx), problem.hm["test"], data, idx, test_idx)
        bands = _band_check(factory, chosen.effects[0], data, train_all[::max(
            1, train_all.size // 48)])
    split = {"description": f"{N_BLOCKS} contiguous speed blocks, blocks "
                            f"{', '.join(str(b + 1) for b in HELDOUT_BLOCKS)} held out: "
                            f"{test_all.size} held-out speeds ({test_idx.size} scored), "
                            f"{train_all.size} training speeds ({train_idx.size} fitted); "
                            f"all channels and measured orders; synthesis not fitted",
             "train_rpm": data.rpm[train_idx].tolist(),
             "heldout_rpm": data.rpm[test_idx].tolist()}
    return DiagnosisResult(data, src, getattr(engine, "name", ""), gap_map, gap_after, parts,
                           rigid, regions, sigma, split, baseline, outcomes, chosen, verdict,
                           verdict_text, bands, time.perf_counter() - t0,
                           synthetic=bool(getattr(measured, "synthetic", False)),
                           noise_mse_heldout=s2_heldout, ambiguous=ambiguous)


def _where_text(regions, parts):
    share = parts["share_alone"]
    kind = max(("structure", "excitation", "const"), key=lambda k: share[k])
    label = {"structure": "a structural (frequency-tied)",
             "excitation": "an excitation (order/speed-tied)",
             "const": "a channel-constant (sensor-like)"}[kind]
    txt = f"the gap looks mostly like {label} error ({share[kind]:.0%} of it)"
    if regions:
        r = regions[0]
        txt += (f"; worst at {r['mount']} {r['direction']} {r['quantity']} "
                f"{r['rpm_from']:g}-{r['rpm_to']:g} rpm ({r['gap_at_max_db']:+.1f} dB)")
    return txt
