r"""Step 3 of the diagnosis: fit candidate effects on the training speeds, score them on the
held-out ones.

Each candidate (one effect of the registry, or a pair) is fitted on the training speeds by
bounded least squares in dB (``scipy.optimize.least_squares``, trust region reflective,
multi-start: the defaults, given starts and, for single effects that declare one, the two
best points of a coarse grid) and scored on the held-out speeds. Every fit has an
evaluation budget (:data:`EVAL_BUDGET` residual evaluations, Jacobian columns included):
when it is hit the best point so far is kept and the outcome says so (``budget_hit``).

Parameters with a prior (``Parameter.prior_sd``) add the residual
:math:`\hat\sigma\,(x - x_0)/s_p` per parameter (:math:`\hat\sigma` the measured scatter in
dB): a maximum a posteriori fit, so that directions the magnitudes do not identify stay at
the prior's centre; the BIC and the held-out scores use the data residuals only.

Parameter uncertainties are the 1σ of the Gauss–Newton covariance
:math:`\hat s^2 (J^TJ)^{-1}` (residual correlation along speed ignored: optimistic).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.noise_floor import above_floor
from powertrain.diagnosis.data import GapData, model_levels, noise_sigma_db, residuals_db
from powertrain.effects import EFFECTS, predict

#: Residual evaluations per fit (all starts, grid and Jacobian columns included; weighted by
#: the effects' ``eval_cost``, an iterated amplitude-dependent solve counting 10); a fit that
#: reaches it stops with the best point so far and reports ``budget_hit``.
EVAL_BUDGET = 2500
#: Starts of a block refined after screening (block-wise multi-start).
BLOCK_REFINED = 2
#: Share of a fit's evaluation budget the block-wise multi-start may use.
BLOCK_SHARE = 0.4


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
    budget_hit: bool = False
    x: np.ndarray | None = None
    heldout_gaps: np.ndarray | None = field(default=None, repr=False)
    status_code: object = None
    units: dict = field(default_factory=dict)
    #: Residual evaluations spent, weighted by cost (the budget's unit).
    n_eval: float = 0.0

    @property
    def label(self) -> str:
        return "+".join(self.effects)


class Problem:
    """Residual functions on the training and held-out speeds.

    ``train_cells`` / ``test_cells`` (bool (n_ch, n_orders)) restrict the (channel, order)
    cells fitted / scored (held-out channels or orders).
    """

    def __init__(self, hm_train, hm_test, data: GapData, train_idx, test_idx, train_cells=None,
                 test_cells=None):
        self.hm = {"train": hm_train, "test": hm_test}
        self.engine = hm_train.engine       # for the effects' parameters (layout only)
        self.data = data
        self.idx = {"train": train_idx, "test": test_idx}
        om = data.order_mask
        self.meas = {k: data.level[v][:, :, om] for k, v in self.idx.items()}
        self.sub = data.orders_only()
        self.valid = {k: np.isfinite(v) for k, v in self.meas.items()}
        sig = noise_sigma_db(data)
        #: measured scatter [dB, 1σ] (weight of the parameter priors; 1 dB if unknown)
        self.sigma_db = sig if np.isfinite(sig) and sig > 0 else 1.0
        self._last = {}
        for part, cells in (("train", train_cells), ("test", test_cells)):
            if cells is not None:
                self.valid[part] = self.valid[part] & np.asarray(cells, bool)[None]

    def __getstate__(self):
        # sent to other processes (parallel fits): the engine without its pressure cache
        state = dict(self.__dict__)
        if hasattr(self.engine, "replace"):
            state["engine"] = self.engine.replace()
        return state

    def restricted(self, train_cells=None, test_cells=None) -> Problem:
        """The same problem with (channel, order) cells withheld from fitting / scoring."""
        return Problem(self.hm["train"], self.hm["test"], self.data, self.idx["train"],
                       self.idx["test"], train_cells, test_cells)

    def gaps(self, scenario, part="train"):
        # the physical part of the scenario is solved once per distinct value: a sensor
        # error only re-reads the same velocities (cheap finite-difference columns)
        phys = {k: v for k, v in scenario.items() if not EFFECTS[k].response_only}
        key = repr(sorted((k, sorted(v.items())) for k, v in phys.items()))
        last = self._last.get(part)
        if last is not None and last[0] == key:
            vel = last[1]
        else:
            vel = predict(self.hm[part], phys).velocity
            self._last[part] = (key, vel)
        for k, v in scenario.items():
            if EFFECTS[k].response_only:
                vel = EFFECTS[k].reading(vel, v)
        sim = model_levels(vel, self.sub)
        g = residuals_db(sim, self.meas[part], self.data.floor)
        return np.where(self.valid[part], g, np.nan)

    def vector(self, scenario, part="train"):
        g = self.gaps(scenario, part)
        return g[self.valid[part]]


@dataclass
class Packing:
    """Parameters of a candidate as one vector (log space for scale-like parameters)."""

    names: list
    lower: np.ndarray
    upper: np.ndarray
    log: np.ndarray
    x0: np.ndarray

    units: dict = None
    prior_sd: np.ndarray = None

    @property
    def n_prior(self) -> int:
        return 0 if self.prior_sd is None else int(np.isfinite(self.prior_sd).sum())

    @classmethod
    def of(cls, effects, engine=None):
        names, lo, hi, logs, x0, units, prior = [], [], [], [], [], {}, []
        for e in effects:
            for p in EFFECTS[e].parameters(engine):
                prior.append(np.nan if p.prior_sd is None else p.prior_sd)
                units[(e, p.name)] = p.unit
                names.append((e, p.name))
                lo.append(math.log(p.lower) if p.log else p.lower)
                hi.append(math.log(p.upper) if p.log else p.upper)
                logs.append(p.log)
                x0.append(math.log(p.default) if p.log else p.default)
        return cls(names, np.array(lo), np.array(hi), np.array(logs, bool), np.array(x0), units,
                   np.array(prior, float))

    def scenario(self, x):
        sc = {}
        for (e, p), lg, v in zip(self.names, self.log, x):
            sc.setdefault(e, {})[p] = float(math.exp(v) if lg else v)
        return sc

    def values(self, x, sd):
        """``params``, ``sigma`` dicts (SI) from the vector and its 1σ."""
        params, sigma = {}, {}
        for (e, pn), lg, v, s in zip(self.names, self.log, x, sd):
            val = math.exp(v) if lg else v
            params.setdefault(e, {})[pn] = float(val)
            sigma.setdefault(e, {})[pn] = float(val * s if lg else s)
        return params, sigma


class _Budget(Exception):
    """Raised inside the residual function when the fit's evaluation budget is spent."""


class _Counted:
    """Residual function with an evaluation count, a budget and the best point seen."""

    def __init__(self, problem, pack, budget, cost=1.0):
        self.problem, self.pack, self.budget, self.cost = problem, pack, budget, cost
        self.n = 0.0
        self.best = (np.inf, None, None)
        self.has_prior = pack.n_prior > 0
        if self.has_prior:
            self.prior_on = np.isfinite(pack.prior_sd)
            self.prior_w = problem.sigma_db / pack.prior_sd[self.prior_on]

    def prior(self, x):
        """Prior residuals (empty without priors)."""
        if not self.has_prior:
            return np.empty(0)
        return self.prior_w * (np.asarray(x) - self.pack.x0)[self.prior_on]

    def charge(self, cost=None):
        """Count one evaluation (raises when the budget is spent)."""
        if self.n >= self.budget:
            raise _Budget
        self.n += self.cost if cost is None else cost

    def __call__(self, x):
        self.charge()
        r = np.concatenate([self.problem.vector(self.pack.scenario(x)), self.prior(x)])
        c = 0.5 * float(np.sum(r ** 2))
        if c < self.best[0]:
            self.best = (c, np.array(x, float), r)
        return r


def _starts(problem, pack, effects, starts, grid, fun):
    span = pack.upper - pack.lower
    lo, hi = pack.lower + 1e-9 * span, pack.upper - 1e-9 * span
    cands = [np.clip(pack.x0, lo, hi)] + [np.clip(s, lo, hi) for s in starts or []]
    # coarse grid of start points for effects that declare one (the cylinder IMEP factors
    # need one: at e = 0 the half orders vanish and the gradient of their level with them)
    sg = EFFECTS[effects[0]].start_grid(problem.engine) if len(effects) == 1 else ()
    if grid and sg:
        mesh = np.meshgrid(*sg, indexing="ij")
        pts = np.stack([m.ravel() for m in mesh], axis=1).astype(float)
        pts[:, pack.log] = np.log(pts[:, pack.log])
        costs = [np.sum(fun(p) ** 2) for p in pts]
        cands += [np.clip(pts[i], lo, hi) for i in np.argsort(costs)[:2]]
    if grid and len(effects) == 1:
        xb = _block_start(fun, pack, effects[0])
        if xb is not None:
            cands.append(np.clip(xb, lo, hi))
    return cands


def _block_start(fun, pack, effect):
    """Block-wise multi-start (``Effect.separable_groups``): for each block (parameters that
    act on their own channels only) every start is screened with the gains set to the mean
    gap of their channels (:func:`_projected`), the best :data:`BLOCK_REFINED` are refined
    on the block's channels alone, and the blocks' optima are joined into one start for the
    joint fit. None when the effect declares no blocks. The screening and refits are
    charged to the fit's budget and stop at :data:`BLOCK_SHARE` of it."""
    groups = EFFECTS[effect].separable_groups(fun.problem.engine)
    if not groups:
        return None
    x = pack.x0.copy()
    n_ch, n_o = fun.problem.valid["train"].shape[1:]
    for names, chans, starts in groups:
        idx = np.array([pack.names.index((effect, n)) for n in names])
        cells = np.zeros((n_ch, n_o), bool)
        cells[chans] = True
        sub = fun.problem.restricted(train_cells=cells)
        screened = sorted((_projected(fun, sub, pack, effect, x, idx, st, chans)
                           for st in starts), key=lambda t: t[0])
        best = screened[0]
        for cost, xs in screened[:BLOCK_REFINED]:
            if fun.n >= BLOCK_SHARE * fun.budget:
                break
            res = _refine_block(fun, sub, pack, x, idx, xs)
            if res.cost * 2 < best[0]:
                best = (2 * res.cost, res.x)
        x[idx] = best[1]
    return x


def _projected(fun, sub, pack, effect, x, idx, start, chans):
    """(cost, block vector) of a start with each channel's gain set to minus its mean gap
    over the points above the floor (the least-squares gain, censoring aside)."""
    names = [pack.names[i][1] for i in idx]
    xs = np.array([start.get(n, pack.x0[i]) for n, i in zip(names, idx)])
    xx = x.copy()
    xx[idx] = xs
    fun.charge()
    g = sub.gaps(pack.scenario(xx))
    up = above_floor(sub.meas["train"], sub.data.floor) & np.isfinite(g)
    for c in chans:
        gi = names.index(f"g{c + 1}") if f"g{c + 1}" in names else None
        if gi is not None and up[:, c].any():
            shift = float(np.mean(g[:, c][up[:, c]]))
            xs[gi] = np.clip(xs[gi] - shift, pack.lower[idx[gi]], pack.upper[idx[gi]])
            g[:, c] = np.where(up[:, c], g[:, c] - shift, g[:, c])
    xx[idx] = xs
    r = np.concatenate([g[sub.valid["train"]], fun.prior(xx)])
    return float(np.sum(r ** 2)), xs


def _refine_block(fun, sub, pack, x, idx, xs):
    from scipy.optimize import least_squares

    def f(v):
        fun.charge()
        xx = x.copy()
        xx[idx] = v
        return np.concatenate([sub.vector(pack.scenario(xx)), fun.prior(xx)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return least_squares(f, xs, bounds=(pack.lower[idx], pack.upper[idx]), method="trf",
                             max_nfev=10 * idx.size, diff_step=1e-4)


def _least_squares(fun, pack, cands):
    """Best trust-region fit over the start points; (result-like, nfev, budget hit)."""
    from scipy.optimize import least_squares
    span = pack.upper - pack.lower
    best, nfev = None, 0
    for x_start in cands:
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = least_squares(fun, x_start, bounds=(pack.lower, pack.upper),
                                    x_scale=np.maximum(span / 8, 1e-3), method="trf",
                                    max_nfev=60 * len(x_start), diff_step=1e-4)
        except _Budget:
            return None, nfev, True
        nfev += res.nfev
        if best is None or res.cost < best.cost:
            best = res
    return best, nfev, False


def _jacobian(fun, x, pack):
    """Forward-difference Jacobian at ``x`` (used when the budget stopped the fit)."""
    def full(x):
        return np.concatenate([fun.problem.vector(pack.scenario(x)), fun.prior(x)])
    r0 = full(x)
    J = np.empty((r0.size, x.size))
    for j in range(x.size):
        h = 1e-4 * max(1.0, abs(x[j]))
        xj = x.copy()
        xj[j] = min(x[j] + h, pack.upper[j]) if x[j] + h <= pack.upper[j] else x[j] - h
        J[:, j] = (full(xj) - r0) / (xj[j] - x[j])
    return r0, J


def fit_candidate(problem: Problem, effects, starts=None, grid=True,
                  budget=EVAL_BUDGET) -> FitOutcome:
    """Fit one effect or a combination on the training speeds, score on the held-out ones."""
    t0 = time.perf_counter()
    pack = Packing.of(effects, problem.engine)
    fun = _Counted(problem, pack, budget, max(EFFECTS[e].eval_cost for e in effects))
    try:
        cands = _starts(problem, pack, effects, starts, grid, fun)
        best, nfev, hit = _least_squares(fun, pack, cands)
    except _Budget:                        # spent on the start grid already
        cands, best, nfev, hit = [pack.x0], None, 0, True
    if best is None:                       # budget spent: the best point evaluated so far
        x = fun.best[1] if fun.best[1] is not None else cands[0]
        r, J = _jacobian(fun, x, pack)
        nfev = int(fun.n)
    else:
        x, r, J = best.x, best.fun, best.jac
    n, p = r.size - pack.n_prior, len(pack.names)
    rss = float(np.sum(r[:n] ** 2))
    try:                                   # Gauss-Newton covariance in fitted coordinates
        s2 = rss / max(n - p, 1)
        if pack.n_prior:                   # prior rows were weighted with the scatter
            s2 = max(s2, problem.sigma_db ** 2)
        sd = np.sqrt(np.clip(np.diag(s2 * np.linalg.pinv(J.T @ J)), 0, None))
    except np.linalg.LinAlgError:
        sd = np.full(p, np.nan)
    params, sigma = pack.values(x, sd)
    out = score(problem, effects, pack.scenario(x), params, sigma, rss, n, p, nfev,
                time.perf_counter() - t0, x)
    out.budget_hit = hit
    out.n_eval = fun.n
    out.units = {e: {pn: pack.units[(e, pn)] for pn in ps} for e, ps in params.items()}
    return out


def score(problem, effects, sc, params, sigma, rss, n, p, nfev, seconds, x=None) -> FitOutcome:
    """Held-out scores of a scenario: mean squared gap per speed, overall, per channel."""
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
    return FitOutcome(tuple(effects), params, sigma, rss, n, p, bic, mse, math.sqrt(mse),
                      per_rpm, ch, nfev, seconds, x=x, heldout_gaps=g)


def baseline_outcome(problem: Problem) -> FitOutcome:
    """The baseline model (no effect) scored like a candidate."""
    r0 = problem.vector({})
    return score(problem, (), {}, {}, {}, float(np.sum(r0 ** 2)),
                 int(problem.valid["train"].sum()), 0, 1, 0.0)
