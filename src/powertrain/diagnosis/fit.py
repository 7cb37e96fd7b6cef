r"""Step 3 of the diagnosis: fit candidate effects on the training speeds, score them on the
held-out ones.

Each candidate (one effect or a pair) is fitted by bounded least squares in dB (trust region
reflective, multi-start: :mod:`.starts`, :mod:`.search`) within :data:`EVAL_BUDGET` residual
evaluations (reached: the best point so far, ``budget_hit``). A parameter with a prior
(``Parameter.prior_sd``) adds the residual :math:`\hat\sigma\,(x - x_0)/s_p` (a MAP fit); the
BIC and held-out scores use the data residuals only. Uncertainties: :mod:`.uncertainty`. A
trial point without a steady state scores
:data:`~powertrain.diagnosis.search.NO_STEADY_STATE_RESIDUAL`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from powertrain.diagnosis import phase as ph
from powertrain.diagnosis.data import GapData, ScoredLevels, model_levels, noise_sigma_db, residuals_db
from powertrain.diagnosis.packing import Packing
from powertrain.diagnosis.search import Counted, Exhausted, jacobian, trust_region
from powertrain.diagnosis.starts import BASIN_RATIO, start_points
from powertrain.diagnosis.uncertainty import cluster_ids, intervals, parameter_sd, with_model_floor
from powertrain.diagnosis.warm_start import AmplitudeStart, scenario_vector
from powertrain.effects import EFFECTS, predict
from powertrain.solvers.fast_harmonic import N_HARMONICS

#: Orders 0.5..8 of the model velocities (harmonics 1..16).
N_ORDERS = N_HARMONICS - 1

#: Evaluation budget per fit [residual evaluations]: every point of every start, grid and
#: Jacobian column counts 1, cached or solved, so where a fit stops depends on its points only.
EVAL_BUDGET = 2500


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
    #: mean squared gap per speed over all speed folds (:func:`checks.crossfit`)
    crossfit: np.ndarray | None = field(default=None, repr=False)
    t_crossfit: float = float("nan")
    budget_hit: bool = False
    x: np.ndarray | None = None
    heldout_gaps: np.ndarray | None = field(default=None, repr=False)
    status_code: object = None
    units: dict = field(default_factory=dict)
    n_eval: int = 0
    #: candidates whose finding this fit restates (:func:`candidates.restatements`)
    restates: tuple = ()
    #: second minimum explaining the data alike (:func:`second_minimum`)
    alternatives: list = field(default_factory=list)
    #: 95 % interval ``{effect: {parameter: [lo, hi]}}`` (SI)
    interval: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        return "+".join(self.effects)


def _physical(scenario) -> tuple:
    """``(physical part, its key)`` of a scenario: its effects that are not response-only."""
    phys = {k: v for k, v in scenario.items() if not EFFECTS[k].response_only}
    return phys, tuple(sorted((k, tuple(sorted(v.items()))) for k, v in phys.items()))


class Problem:
    """Residual functions on the training and held-out speeds; ``train_cells`` /
    ``test_cells`` (bool (n_ch, n_orders)) restrict the cells fitted / scored."""

    def __init__(self, hm_train, hm_test, data: GapData, train_idx, test_idx,
                 train_cells=None, test_cells=None):
        self.hm = {"train": hm_train, "test": hm_test}
        self.engine = hm_train.engine
        self.data = data
        self.idx = {"train": train_idx, "test": test_idx}
        om = data.order_mask
        self.meas = {k: data.level[v][:, :, om] for k, v in self.idx.items()}
        self.sub = data.orders_only()
        #: velocity indices scored (None: all, for the synthesis)
        self.orders = np.unique(self.sub.harmonic) if np.all(self.sub.harmonic >= 0) else None
        self.valid = {k: np.isfinite(v) for k, v in self.meas.items()}
        sig = noise_sigma_db(data)
        #: measured scatter [dB, 1σ] weighting the priors (1 dB if unknown)
        self.sigma_db = sig if np.isfinite(sig) and sig > 0 else 1.0
        self.reset_warm()
        for part, cells in (("train", train_cells), ("test", test_cells)):
            if cells is not None:
                self.valid[part] = self.valid[part] & np.asarray(cells, bool)[None]
        self._level_at = {k: self._flat(on) for k, on in self.valid.items()}
        self._scored = {k: ScoredLevels(self.meas[k][on], data.floor) for k, on in self.valid.items()}
        self._phase_setup()

    def _flat(self, on):
        """Flat indices into the velocities (n_r, n_ch, N_ORDERS) of ``array[on]``."""
        r, c, q = np.nonzero(on)
        return (r * on.shape[1] + c) * N_ORDERS + self.sub.harmonic[q]

    def clusters(self) -> np.ndarray:
        """(channel, order) cell of each training residual of :meth:`vector`."""
        return cluster_ids(self.valid["train"], None if self.phase_w is None else self.phase_on["train"])

    def _phase_setup(self):
        """Measured phases and their weights per part; ``phase_w`` None without phase."""
        self.order = (self.sub.harmonic + 1) / 2.0
        self.phase_w = None
        if not self.data.has_phase:
            return
        self.phase = {k: self.sub.phase[v] for k, v in self.idx.items()}
        self.phase_w = {k: np.where(self.valid[k], ph.phase_weights(
            self.meas[k], self.phase[k], self.data.floor, self.sigma_db), np.nan)
            for k in self.idx}
        self.phase_on = {k: np.isfinite(w) for k, w in self.phase_w.items()}
        self._phase_rad = {k: np.deg2rad(v[self.phase_on[k]]) for k, v in self.phase.items()}
        self._phase_at = {k: self._flat(on) for k, on in self.phase_on.items()}
        self._order_on = {k: np.broadcast_to(self.order, on.shape)[on] for k, on in self.phase_on.items()}
        self._w_on = {k: self.phase_w[k][on] for k, on in self.phase_on.items()}
        self._offset = ph.OffsetProfile(self._order_on["train"], self._w_on["train"], self.sigma_db)

    def reset_warm(self):
        """Forget cached velocities and amplitude starts (a fit must not depend on the last)."""
        self._last, self._warm = {}, {}

    def restricted(self, train_cells=None, test_cells=None) -> Problem:
        """The same problem with (channel, order) cells withheld from fitting / scoring."""
        return Problem(self.hm["train"], self.hm["test"], self.data, self.idx["train"],
                       self.idx["test"], train_cells, test_cells)

    def velocity(self, scenario, part="train"):
        """Complex model velocities of the measured orders (n_r, n_ch, 16) [m/s peak]."""
        # a sensor error only re-reads the physical part's velocities
        phys, key = _physical(scenario)
        last = self._last.get(part)
        if last is not None and last[0] == key:
            vel = last[1]
        else:
            warm = self._warm.setdefault(part, AmplitudeStart())
            v = scenario_vector(phys)
            pred = predict(self.hm[part], phys, warm_amplitudes=warm.start(v), orders=self.orders)
            vel = pred.velocity
            if pred.amplitudes is not None:
                warm.record(v, pred.amplitudes)
            self._last[part] = (key, vel)
        for k, v in scenario.items():
            if EFFECTS[k].response_only:
                vel = EFFECTS[k].reading(vel, v)
        return vel

    def gaps(self, scenario, part="train", vel=None):
        """Level gaps [dB] (n_r, n_ch, n_q), NaN where not scored."""
        vel = self.velocity(scenario, part) if vel is None else vel
        g = residuals_db(model_levels(vel, self.sub), self.meas[part], self.data.floor)
        return np.where(self.valid[part], g, np.nan)

    def crank_offset(self, scenario, vel=None) -> float:
        """The run's crank-angle offset [rad] profiled on the training speeds."""
        vel = self.velocity(scenario, "train") if vel is None else vel
        return self._offset(self._phase_diff(vel, "train"))

    def _phase_diff(self, vel, part):
        """Model minus measured phase [rad] at the scored phase points of ``part``."""
        return np.angle(np.take(vel, self._phase_at[part])) - self._phase_rad[part]

    def crank_offsets(self, scenario) -> list:
        """``[offset [rad]]`` (``[None]`` without phase); one per run, as for a plan."""
        return [None if self.phase_w is None else self.crank_offset(scenario)]

    def _order_velocity(self, scenario, part):
        return self.velocity(scenario, part)[..., self.sub.harmonic]

    def phase_gaps(self, scenario, part="train", delta=None):
        """Phase residuals [dB] (n_r, n_ch, n_q), NaN where not scored; None without phase.
        ``delta``: crank offset [rad] (default: profiled on the training speeds)."""
        if self.phase_w is None:
            return None
        delta = self.crank_offset(scenario) if delta is None else delta
        return ph.phase_gaps(self._order_velocity(scenario, part), self.phase[part],
                             self.phase_w[part], self.order, delta)

    def complex_excess(self, scenario):
        r"""Measured (:math:`L\,e^{i(\varphi + k\delta)}`) minus model complex order amplitude
        [m/s RMS] on the training speeds; NaN where no phase is scored, None without phase."""
        if self.phase_w is None:
            return None
        vel = self.velocity(scenario)
        meas = self.meas["train"] * np.exp(1j * (np.deg2rad(self.phase["train"]) + self.order
                                                 * self.crank_offset(scenario, vel)))
        return np.where(self.phase_on["train"], meas - vel[..., self.sub.harmonic] / math.sqrt(2.0), np.nan)

    def vector(self, scenario, part="train"):
        """Residuals of ``part`` [dB]: ``gaps[valid]``, then any phase gaps and offset prior."""
        vel = self.velocity(scenario, part)
        g = self._scored[part](np.take(vel, self._level_at[part]))
        return g if self.phase_w is None else self._with_phase(g, vel, scenario, part)

    def read_vectors(self, scenarios) -> list | None:
        """:meth:`vector` on the training speeds of ``scenarios`` differing in response-only
        effects only, read at once from the cached velocities; None when the cache holds
        another physical part."""
        last = self._last.get("train")
        if last is None or last[0] != _physical(scenarios[0])[1]:
            return None
        vel = np.broadcast_to(last[1], (len(scenarios),) + last[1].shape)
        for k in scenarios[0]:
            if EFFECTS[k].response_only:
                vel = EFFECTS[k].readings(vel, [sc[k] for sc in scenarios])
        at = self._level_at["train"]
        g = self._scored["train"](np.take(vel.reshape(len(scenarios), -1), at, axis=1))
        if self.phase_w is None:
            return list(g)
        d = np.angle(np.take(vel.reshape(len(scenarios), -1), self._phase_at["train"], axis=1))
        return ph.rows_with_phase(g, d - self._phase_rad["train"], self._offset,
                                  self._w_on["train"], self.sigma_db)

    def _with_phase(self, g, vel, scenario, part):
        """``g`` followed by the phase gaps and the crank offset's prior."""
        d = self._phase_diff(vel, part)
        delta = self._offset(d) if part == "train" else self.crank_offset(scenario)
        gp = self._w_on[part] * ph.wrap(d - self._order_on[part] * delta)
        return np.concatenate([g, gp, [ph.offset_prior(delta, self.sigma_db)]])


def fit_candidate(problem: Problem, effects, starts=None, grid=True,
                  budget=EVAL_BUDGET, defaults=True) -> FitOutcome:
    """Fit one effect or a combination on the training speeds, score on the held-out ones.

    Parameters
    ----------
    problem : Problem or JointProblem
    effects : tuple of str
    starts : list of ndarray, optional
        Extra start vectors (fitted coordinates).
    grid : bool
        Also the start grid and the data starts.
    budget : int
        Residual evaluations.
    defaults : bool
        False with ``starts``: skip the defaults' start (a refit from a known optimum).
    """
    t0 = time.perf_counter()
    problem.reset_warm()
    pack = Packing.of(effects, problem.engine)
    fun = Counted(problem, pack, budget)
    try:
        cands = start_points(problem, pack, effects, starts, grid, fun, defaults)
        best, nfev, hit = trust_region(fun, pack, cands)
    except Exhausted:                      # spent on the start grid already
        cands, best, nfev, hit = [pack.x0], None, 0, True
    if best is None:                       # budget spent or stalled: the best point so far
        x = fun.best[1] if fun.best[1] is not None else cands[0]
        r, J = jacobian(fun, x, pack)
        nfev = int(fun.n)
    else:
        x, r, J = best.x, best.fun, best.jac
    n, p = r.size - pack.n_prior, len(pack.names)
    rss = float(np.sum(r[:n] ** 2))
    s2 = rss / max(n - p, 1)
    if pack.n_prior:                       # prior rows were weighted with the scatter
        s2 = max(s2, problem.sigma_db ** 2)
    sd = with_model_floor(pack, x, parameter_sd(J, r, n, problem.clusters(), s2))
    params, sigma = pack.values(x, sd)
    out = score(problem, effects, pack.scenario(x), params, sigma, rss, n, p, nfev,
                time.perf_counter() - t0, x)
    out.budget_hit = hit
    out.interval = intervals(pack, x, sd)
    out.alternatives = second_minimum(fun, pack, effects, x, problem.sigma_db)
    out.n_eval = fun.n
    out.units = {e: {pn: pack.units[(e, pn)] for pn in ps} for e, ps in params.items()}
    return out


#: Training Δχ² within which a second minimum explains the data alike (the rule's BIC margin,
#: Kass & Raftery).
ALIKE_CHI2 = 10.0


def second_minimum(fun, pack, effects, x, sigma_db) -> list:
    """``[{"parameters", "delta_chi2"}]`` of the best finished start whose
    ``Effect.basin_parameter`` lies :data:`~powertrain.diagnosis.starts.BASIN_RATIO` or more
    from the fit's at ``x`` within Δχ² < :data:`ALIKE_CHI2`; else []."""
    name = EFFECTS[effects[0]].basin_parameter if len(effects) == 1 else None
    if name is None or not fun.minima:
        return []
    j = pack.names.index((effects[0], name))
    val = (lambda v: math.exp(v[j])) if pack.log[j] else (lambda v: v[j])
    c0 = min([c for c, _ in fun.minima] + [float(fun.best[0])])
    far = [(c, v) for c, v in fun.minima if abs(math.log(val(v) / val(x))) >= math.log(BASIN_RATIO)]
    if not far:
        return []
    c, v = min(far, key=lambda t: t[0])
    d = 2.0 * (c - c0) / sigma_db ** 2
    if d >= ALIKE_CHI2:
        return []
    return [{"parameters": pack.values(v, np.full(v.size, np.nan))[0], "delta_chi2": d}]


def score(problem, effects, sc, params, sigma, rss, n, p, nfev, seconds, x=None) -> FitOutcome:
    """Held-out scores of scenario ``sc``: mean squared gap per speed, overall, per channel
    (infinite where it has no steady state at a held-out speed)."""
    try:
        g = problem.gaps(sc, "test")
        both = g if problem.phase_w is None else np.concatenate([g, problem.phase_gaps(sc, "test")], axis=-1)
    except FloatingPointError:
        g = np.full(problem.valid["test"].shape, np.nan)
        per_rpm, mse, ch = np.full(g.shape[0], np.inf), math.inf, [math.nan] * g.shape[1]
    else:
        per_rpm, mse, ch = _heldout_means(g, both)
    bic = n * math.log(max(rss, 1e-300) / n) + p * math.log(n)
    return FitOutcome(tuple(effects), params, sigma, rss, n, p, bic, mse, math.sqrt(mse),
                      per_rpm, ch, nfev, seconds, x=x, heldout_gaps=g)


def per_speed_mse(g, ok):
    """Mean of ``g[i][ok[i]] ** 2`` for every speed i (NaN where none is ``ok``)."""
    return np.array([np.mean(g[i][ok[i]] ** 2) if ok[i].any() else np.nan for i in range(g.shape[0])])


def _heldout_means(g, both):
    """Mean squared gap per speed and overall (``both``), RMS per channel (``g``)."""
    valid, ok = np.isfinite(g), np.isfinite(both)
    ch = []
    for c in range(g.shape[1]):
        v = g[:, c][valid[:, c]]
        ch.append(float(np.sqrt(np.mean(v ** 2))) if v.size else float("nan"))
    return per_speed_mse(both, ok), float(np.mean(both[ok] ** 2)), ch


def baseline_outcome(problem: Problem) -> FitOutcome:
    """The baseline model (no effect) scored like a candidate."""
    r0 = problem.vector({})
    return score(problem, (), {}, {}, {}, float(np.sum(r0 ** 2)),
                 int(problem.valid["train"].sum()), 0, 1, 0.0)
