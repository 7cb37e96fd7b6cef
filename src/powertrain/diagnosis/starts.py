"""Start points of the candidate fits: the defaults, given starts, the effects' coarse start
grids, starts read from the data (``Effect.data_starts``) and a block-wise multi-start for
parameters acting on disjoint channels (``Effect.separable_groups``). Every evaluation is
charged to the fit's budget through ``fun``."""

from __future__ import annotations

import warnings

import numpy as np
from scipy.optimize import least_squares

from powertrain.analysis.noise_floor import above_floor
from powertrain.diagnosis.search import DIFF_STEP, Differences
from powertrain.effects import EFFECTS
from powertrain.effects.missing_body_mode import BodyGaps

#: Starts of a block refined after screening (block-wise multi-start).
BLOCK_REFINED = 2
#: Share of a fit's evaluation budget the block-wise multi-start may use.
BLOCK_SHARE = 0.4
#: Starts read from the data kept after screening.
DATA_KEPT = 2
#: Ratio of ``Effect.basin_parameter`` beyond which a start lies in another basin (a body
#: mode at 2-6 % damping is 4-12 % wide).
BASIN_RATIO = 1.25
#: Starts kept besides the cheapest, each in a basin of its own.
OTHER_BASINS = 2
#: Distance of a data start from its bounds [share of the span]: on a bound, ``trf``'s first
#: step is truncated to ~1e-9 and ``xtol`` ends the fit there.
DATA_START_MARGIN = 0.01


def start_points(problem, pack, effects, starts, grid, fun, defaults=True):
    """Start vectors of a fit of ``effects`` (``pack``'s coordinates): data starts, defaults
    (unless ``defaults`` is False with ``starts``), ``starts``, the two best points of the
    coarse grid and the block start (data, grid and block starts only with ``grid`` and a
    single effect); ``fun`` charges the evaluations of ``problem``."""
    span = pack.upper - pack.lower
    lo, hi = pack.lower + 1e-9 * span, pack.upper - 1e-9 * span
    cands = [np.clip(s, lo, hi) for s in starts or []]
    if defaults or not cands:
        cands = [np.clip(pack.x0, lo, hi)] + cands
    # a grid where a default has no gradient (at e = 0 the half orders vanish)
    sg = EFFECTS[effects[0]].start_grid(problem.engine) if grid and len(effects) == 1 else ()
    if sg:
        mesh = np.meshgrid(*sg, indexing="ij")
        pts = np.stack([m.ravel() for m in mesh], axis=1).astype(float)
        pts[:, pack.log] = np.log(pts[:, pack.log])
        costs = [np.sum(fun(p) ** 2) for p in pts]
        cands += [np.clip(pts[i], lo, hi) for i in np.argsort(costs)[:2]]
    if grid and len(effects) == 1:
        inner = DATA_START_MARGIN * span
        cands = _data_starts(problem, pack, effects[0], fun, pack.lower + inner, pack.upper - inner) + cands
        xb = _block_start(fun, pack, effects[0])
        if xb is not None:
            cands.append(np.clip(xb, lo, hi))
    return cands


def _data_starts(problem, pack, effect, fun, lo, hi):
    """The :data:`DATA_KEPT` cheapest data starts (plus other basins), signs chosen."""
    d = problem.data
    fun.evaluate(problem, pack.x0)
    sc = pack.scenario(pack.x0)
    gaps = BodyGaps(d.rpm[problem.idx["train"]], list(d.channels),
                    (d.harmonic[d.order_mask] + 1) / 2.0, problem.gaps(sc),
                    problem.meas["train"], problem.complex_excess(sc))
    starts = EFFECTS[effect].data_starts(problem.engine, gaps)
    pts = [np.clip(np.array([np.log(st[n]) if lg else st[n] for (_, n), lg in
                             zip(pack.names, pack.log)]), lo, hi) for st in starts]
    costs = [np.sum(fun(p) ** 2) for p in pts]
    order = np.argsort(costs)
    kept = [pts[i] for i in order[:DATA_KEPT]]
    for _ in range(OTHER_BASINS):
        other = _other_basin(pack, effect, pts, order, kept)
        kept += [] if other is None else [other]
    signed = [pack.names.index((effect, n)) for n in EFFECTS[effect].signed(problem.engine)]
    return [_signs(fun, x, signed) for x in kept] if signed else kept


def _other_basin(pack, effect, pts, order, kept):
    """The cheapest start at least :data:`BASIN_RATIO` from every kept one (or None)."""
    name = EFFECTS[effect].basin_parameter
    if name is None:
        return None
    j = pack.names.index((effect, name))
    val = (lambda x: np.exp(x[j])) if pack.log[j] else (lambda x: x[j])
    for i in order:
        if all(abs(np.log(val(pts[i]) / val(k))) >= np.log(BASIN_RATIO) for k in kept):
            return pts[i]
    return None


def _signs(fun, x, signed, passes=2):
    """Signs of the ``signed`` parameters: each flipped, largest first, kept if cheaper."""
    best = float(np.sum(fun(x) ** 2))
    for _ in range(passes):
        changed = False
        for i in sorted(signed, key=lambda i: -abs(x[i])):
            if x[i] == 0:
                continue
            y = x.copy()
            y[i] = -y[i]
            c = float(np.sum(fun(y) ** 2))
            if c < best:
                x, best, changed = y, c, True
        if not changed:
            break
    return x


def _block_start(fun, pack, effect):
    """Block-wise multi-start: each block's starts screened (:func:`_projected`), the best
    :data:`BLOCK_REFINED` refined on its channels (within :data:`BLOCK_SHARE` of the budget),
    the optima joined; None without blocks."""
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
        for _cost, xs in screened[:BLOCK_REFINED]:
            if fun.n >= BLOCK_SHARE * fun.budget:
                break
            res = _refine_block(fun, sub, pack, x, idx, xs)
            if res.cost * 2 < best[0]:
                best = (2 * res.cost, res.x)
        x[idx] = best[1]
    return x


def _projected(fun, sub, pack, effect, x, idx, start, chans):
    """(cost, block vector) of a start, each channel's gain set to minus its mean gap."""
    names = [pack.names[i][1] for i in idx]
    xs = np.array([start.get(n, pack.x0[i]) for n, i in zip(names, idx)])
    xx = x.copy()
    xx[idx] = xs
    fun.evaluate(sub, xx)
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


class _BlockResiduals:
    """Residuals on ``sub`` of the block ``idx`` (others at ``x``), charged to ``fun``."""

    def __init__(self, fun, sub, x, idx):
        self.fun, self.sub, self.x, self.idx = fun, sub, x, idx
        self.last = (None, None)

    def _full(self, v):
        xx = self.x.copy()
        xx[self.idx] = v
        return xx

    def __call__(self, v):
        r = self.fun.evaluate(self.sub, self._full(v))
        self.last = (np.array(v, float), r)
        return r

    def columns(self, v0, vs) -> list:
        return self.fun.columns(self._full(v0), [self._full(v) for v in vs], self.sub)


def _refine_block(fun, sub, pack, x, idx, xs):
    f = _BlockResiduals(fun, sub, x, idx)
    lower, upper = pack.lower[idx], pack.upper[idx]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return least_squares(f, xs, jac=Differences.or_two_point(f, lower, upper),
                             bounds=(lower, upper), method="trf", max_nfev=10 * idx.size, diff_step=DIFF_STEP)
