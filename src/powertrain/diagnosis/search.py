"""The trust-region search of a candidate fit: the counted residual function (budget, best
point, stall watch), SciPy's forward-difference Jacobian with sensor columns read at once,
and the multi-start."""

from __future__ import annotations

import inspect
import warnings

import numpy as np
from scipy.optimize import least_squares
from scipy.optimize._numdiff import approx_derivative

from powertrain.effects import EFFECTS

#: Residual of every point where a trial parameter set has no steady state.
NO_STEADY_STATE_RESIDUAL = 1e3
#: A start stops when its best cost falls by less than ``STALL_REL`` (relative) over
#: ``STALL_STEPS`` steps of p + 1 evaluations (a crawl along an active bound); 2e-4 of the
#: cost moves the BIC by about 0.2 per 1000 residuals, far below the rule's margin of 10.
STALL_REL = 2e-4
STALL_STEPS = 20
#: Relative step of the forward-difference Jacobian columns.
DIFF_STEP = 1e-4


class Exhausted(Exception):
    """The fit's evaluation budget is spent."""


class _Stalled(Exception):
    """A start has stalled (:data:`STALL_REL`)."""


class Counted:
    """Residual function of ``problem`` over ``pack``'s vector with an evaluation count
    (``budget`` at most), the best point seen and a stall watch (:meth:`watch`)."""

    def __init__(self, problem, pack, budget):
        self.problem, self.pack, self.budget = problem, pack, budget
        #: residual evaluations charged (one per point, cached or solved)
        self.n = 0
        self.best = (np.inf, None, None)
        #: ``(cost, x)`` of every start the trust region finished (:func:`trust_region`)
        self.minima = []
        self.last = (None, None)
        self._stall = None
        self._response_only = np.array([EFFECTS[e].response_only for e, _ in pack.names])
        self.has_prior = pack.n_prior > 0
        if self.has_prior:
            self.prior_on = np.isfinite(pack.prior_sd)
            self.prior_w = problem.sigma_db / pack.prior_sd[self.prior_on]

    def prior(self, x):
        """Prior residuals at ``x`` (empty without priors)."""
        if not self.has_prior:
            return np.empty(0)
        return self.prior_w * (np.asarray(x) - self.pack.x0)[self.prior_on]

    def _data_size(self, problem, x):
        """Number of data residuals: the best point's, else the defaults'."""
        if self.best[2] is not None:
            return self.best[2].size - self.prior(x).size
        return problem.vector(self.pack.scenario(self.pack.x0)).size

    def evaluate(self, problem, x):
        """Residuals of ``problem`` at ``x`` with the prior's, charged (raises when spent)."""
        self._check_budget()
        r = self.residuals(problem, x)
        self.n += 1
        return r

    def _check_budget(self):
        if self.n >= self.budget:
            raise Exhausted

    def residuals(self, problem, x):
        """Residuals of ``problem`` at ``x`` with the prior's, uncharged (no steady state:
        :data:`NO_STEADY_STATE_RESIDUAL`)."""
        try:
            v = problem.vector(self.pack.scenario(x))
        except FloatingPointError:
            v = np.full(self._data_size(problem, x), NO_STEADY_STATE_RESIDUAL)
        return self._with_prior(v, x)

    def _with_prior(self, v, x):
        return np.concatenate([v, self.prior(x)])

    def watch(self, n_params):
        """Watch the next start of ``n_params`` parameters for a stall (None: stop)."""
        self._stall = None if n_params is None else [STALL_STEPS * (n_params + 1), 0, np.inf]

    def _check_stall(self, c):
        w = self._stall
        if w is None:
            return
        if c < w[2] * (1.0 - STALL_REL):
            w[1], w[2] = 0, c
            return
        w[1] += 1
        if w[1] > w[0]:
            raise _Stalled

    def __call__(self, x):
        return self._seen(x, self.evaluate(self.problem, x))

    def _seen(self, x, r):
        """Note residuals ``r`` at ``x``: best point, stall watch, last point (Jacobian f0)."""
        c = 0.5 * float(np.sum(r ** 2))
        if c < self.best[0]:
            self.best = (c, np.array(x, float), r)
        self._check_stall(c)
        self.last = (np.array(x, float), r)
        return r

    def columns(self, x0, xs, problem=None) -> list:
        """Residuals at each of ``xs`` (a Jacobian's points at ``x0``) as by calling this on
        each in turn; points moving only response-only parameters are read at once.
        ``problem``: another than the fit's (points only charged)."""
        keep = problem is None
        problem = self.problem if keep else problem
        out, run = [], []
        for x in xs:
            moved = np.flatnonzero(x != x0)
            if moved.size and np.all(self._response_only[moved]):
                run.append(x)
                continue
            out += self._read(problem, run, keep)
            run = []
            out.append(self._point(problem, x, keep))
        return out + self._read(problem, run, keep)

    def _point(self, problem, x, keep):
        r = self.evaluate(problem, x)
        return self._seen(x, r) if keep else r

    def _read(self, problem, run, keep) -> list:
        """Residuals of the points ``run``, read at once from the cache (else one evaluated)."""
        out, scenarios = [], [self.pack.scenario(x) for x in run]
        while run:
            vs = problem.read_vectors(scenarios)
            if vs is None:
                out.append(self._point(problem, run[0], keep))
                run, scenarios = run[1:], scenarios[1:]
                continue
            for x, v in zip(run, vs):
                self._check_budget()
                self.n += 1
                r = self._with_prior(v, x)
                out.append(self._seen(x, r) if keep else r)
            break
        return out


class Differences:
    """SciPy's forward-difference Jacobian (``jac="2-point"``, bounds ``lower``, ``upper``)
    with its points evaluated by ``fun.columns``: the same Jacobian and count."""

    def __init__(self, fun, lower, upper):
        self.fun, self.bounds = fun, (lower, upper)

    @classmethod
    def or_two_point(cls, fun, lower, upper):
        """A :class:`Differences`, or ``"2-point"`` on SciPy < 1.16 (no ``workers``)."""
        if "workers" not in inspect.signature(approx_derivative).parameters:
            return "2-point"
        return cls(fun, lower, upper)

    def __call__(self, x):
        last_x, f0 = self.fun.last
        if last_x is None or not np.array_equal(last_x, x):
            f0 = self.fun(x)               # as "2-point" without f0: evaluated first
        return approx_derivative(self.fun, x, method="2-point", rel_step=DIFF_STEP, f0=f0, bounds=self.bounds,
                                 workers=lambda _, xs: self.fun.columns(x, list(xs)))


def trust_region(fun, pack, cands):
    """Best trust-region fit of ``fun`` over the starts ``cands`` within ``pack``'s bounds:
    (result, nfev, budget hit); result None when a stalled start or the budget ends it
    (then ``fun.best``)."""
    span = pack.upper - pack.lower
    best, nfev, stalled = None, 0, False
    jac = Differences.or_two_point(fun, pack.lower, pack.upper)
    for x_start in cands:
        fun.watch(len(x_start))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = least_squares(fun, x_start, jac=jac, bounds=(pack.lower, pack.upper),
                                    x_scale=np.maximum(span / 8, 1e-3), method="trf",
                                    max_nfev=60 * len(x_start), diff_step=DIFF_STEP)
        except Exhausted:
            return None, nfev, True
        except _Stalled:
            stalled = True
            continue
        finally:
            fun.watch(None)
        nfev += res.nfev
        fun.minima.append((float(res.cost), np.array(res.x, float)))
        if best is None or res.cost < best.cost:
            best = res
    if stalled and (best is None or fun.best[0] < best.cost):
        return None, nfev, False
    return best, nfev, False


def jacobian(fun, x, pack):
    """Residuals and forward-difference Jacobian of ``fun`` at ``x`` within ``pack``'s bounds."""
    def full(x):
        return fun.residuals(fun.problem, x)
    r0 = full(x)
    J = np.empty((r0.size, x.size))
    for j in range(x.size):
        h = 1e-4 * max(1.0, abs(x[j]))
        xj = x.copy()
        xj[j] = min(x[j] + h, pack.upper[j]) if x[j] + h <= pack.upper[j] else x[j] - h
        J[:, j] = (full(xj) - r0) / (xj[j] - x[j])
    return r0, J
