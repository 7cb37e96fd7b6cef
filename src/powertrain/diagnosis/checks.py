r"""Evidence beyond the held-out speeds (step 3 of the diagnosis).

* :func:`structured_residual`: held-out residual averaged per (channel, order) over groups
  of about 4 adjacent speeds (noise averages out, structure does not);
* :func:`heldout_cells_check`: the candidate refitted without some (channel, order) cells
  must predict them at the held-out speeds. Physical effects withhold channels (one of
  every mount triad, :func:`channel_folds`); sensor-like candidates withhold each channel's
  informative orders (:func:`order_folds`): a gain is the same on every order, a
  frequency-tied gap is not;
* :func:`noise_mse`: :math:`E_n = \hat\sigma^2 u`, the held-out mean squared gap a perfect
  model leaves, :math:`u` the uncensored fraction of scored points;
* :func:`crossfit`: refits with each other third of the speeds held out;
* :func:`band_check`: the chosen effect refitted on four speed bands from its optimum: a
  parameter that trends with speed points to another effect.
"""

from __future__ import annotations

import math
import time

import numpy as np

from powertrain.analysis.noise_floor import above_floor
from powertrain.diagnosis.fit import FitOutcome, Problem, fit_candidate, per_speed_mse
from powertrain.diagnosis.significance import log_ratio_t
from powertrain.effects import EFFECTS

#: Fallback order split with fewer than two informative orders [order].
ORDER_SPLIT = 2.0
#: Folds of the (channel, informative order) cells for response-only candidates.
ORDER_FOLDS = 3
#: Measured training points above the floor that make an order informative.
MIN_ORDER_POINTS = 10


def channel_folds(n_mounts: int) -> tuple:
    """Fold j withholds channel (j + m) mod 3 of every mount m's triad."""
    return tuple(tuple(3 * m + (j + m) % 3 for m in range(n_mounts)) for j in range(3))


def structured_residual(g, censored, groups, sigma, cells=None):
    r"""Structured part of held-out residuals [dB RMS beyond noise] and its χ² ratio.

    Per group and (channel, order), the mean :math:`\bar g` of :math:`n` uncensored
    residuals (noise gives :math:`E[\bar g^2] = \sigma^2/n`): returns
    :math:`\sqrt{\max(0,\ \overline{\bar g^2 - \sigma^2/n})}` and
    :math:`\overline{n\bar g^2/\sigma^2}` (≈ 1 for noise); without a scored cell, inf if
    no gap is finite, else (0, NaN).

    Parameters
    ----------
    g : ndarray (n_test, n_ch, n_o)
        Held-out residuals [dB] (NaN where not scored).
    censored : ndarray bool, same shape
    groups : list of index arrays into the first axis
        Groups of adjacent speeds.
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
    z = np.concatenate(z) if z else np.empty(0)
    if not z.size:
        return (float("inf"), float("inf")) if not np.isfinite(g).any() else (0.0, float("nan"))
    chi_r = float(np.mean(np.concatenate(chi))) if chi else float("nan")
    return float(math.sqrt(max(float(np.mean(z)), 0.0))), chi_r


def cells_mse(o: FitOutcome, cells):
    """Held-out mean squared gap of ``o`` on the (channel, order) ``cells``; and per speed."""
    g = o.heldout_gaps
    ok = np.isfinite(g) & np.asarray(cells, bool)[None]
    return float(np.mean(g[ok] ** 2)) if ok.any() else float("nan"), per_speed_mse(g, ok)


def noise_mse(problem: Problem, sigma, cells=None) -> float:
    r"""Expected held-out mean squared gap of a perfect model [dB²]: :math:`\hat\sigma^2`
    times the uncensored fraction of scored points (phase gaps count as uncensored)."""
    if not (np.isfinite(sigma) and sigma > 0):
        return 0.0
    valid = problem.valid["test"]
    if cells is not None:
        valid = valid & np.asarray(cells, bool)[None]
    unc = int((valid & above_floor(problem.meas["test"], problem.data.floor)).sum())
    n = int(valid.sum())
    if cells is None and problem.phase_w is not None:
        n_phase = int(problem.phase_on["test"].sum())
        unc, n = unc + n_phase, n + n_phase
    return float(sigma ** 2 * unc / n) if n else 0.0


def order_folds(problem: Problem) -> list:
    """Withheld-cell masks (n_ch, n_o): channel c's i-th informative order (at least
    :data:`MIN_ORDER_POINTS` training points above the floor) in fold (c + i) mod
    :data:`ORDER_FOLDS`; a channel's only informative order is never withheld (its gain
    needs it). Fewer than two informative orders: orders ≤ :data:`ORDER_SPLIT` vs the rest."""
    n_ch, n_o = problem.valid["train"].shape[1:]
    usable = above_floor(problem.meas["train"], problem.data.floor) & problem.valid["train"]
    informative = usable.sum(axis=0) >= MIN_ORDER_POINTS
    if informative.any(axis=0).sum() < 2:
        order = (problem.sub.harmonic + 1) / 2.0
        low = np.broadcast_to(order <= ORDER_SPLIT + 1e-9, (n_ch, n_o))
        return [low, ~low]
    folds = [np.zeros((n_ch, n_o), bool) for _ in range(ORDER_FOLDS)]
    for c in range(n_ch):
        orders = np.flatnonzero(informative[c])
        if orders.size < 2:
            continue
        for i, k in enumerate(orders):
            folds[(c + i) % ORDER_FOLDS][c, k] = True
    return folds


def _folds(problem: Problem, effects):
    n_ch, n_o = problem.valid["test"].shape[1:]
    if any(EFFECTS[e].response_only or EFFECTS[e].withhold_orders for e in effects):
        return "orders", order_folds(problem)
    folds = []
    for f in channel_folds(n_ch // 3):
        m = np.zeros((n_ch, n_o), bool)
        m[[c for c in f if c < n_ch]] = True
        folds.append(m)
    return "channels", folds


def heldout_cells_check(problem: Problem, o: FitOutcome, baseline: FitOutcome, sigma,
                        budget=None, folds=(), first=None):
    """Refit ``o``'s effects without some (channel, order) cells; score those held out.

    Parameters
    ----------
    problem : Problem
    o, baseline : FitOutcome
        The candidate and the baseline.
    sigma : float
        Noise [dB, 1σ].
    budget : int, optional
        Evaluations per refit.
    folds : sequence of (Problem, FitOutcome)
        Other speed folds and their baselines: also score the cells there.
    first : dict, optional
        An earlier check's ``parts[0]``, reused instead of refitted.

    Returns
    -------
    dict
        ``kind``, ``explained`` (fraction of the cells' excess over noise removed), ``t``,
        ``baseline_excess_db``, ``heldout_rms_db``, ``speed_folds``, ``seconds``; ``parts``
        (per speed fold, not in the JSON).
    """
    t0 = time.perf_counter()
    kind, cells = _folds(problem, o.effects)
    kw = {} if budget is None else {"budget": budget}
    parts = [first or _cells_fold(problem, o, baseline, cells, sigma, kw)]
    parts += [_cells_fold(p, o, b, cells, sigma, kw) for p, b in folds]
    n = sum(q["n"] for q in parts)
    e0, ec, e_n = (sum(q[k] * q["n"] for q in parts) / n if n else float("nan") for k in ("e0", "ec", "e_n"))
    per_0, per_c = (np.concatenate([q[k] for q in parts]) for k in ("per_0", "per_c"))
    excess = max(e0 - e_n, 0.0)
    return {"kind": kind, "explained": (e0 - ec) / excess if excess > 0 else float("nan"),
            "t": log_ratio_t(per_0, per_c, e_n), "baseline_excess_db": math.sqrt(excess),
            "heldout_rms_db": math.sqrt(ec), "speed_folds": len(parts),
            "seconds": time.perf_counter() - t0, "parts": parts}


def _cells_fold(problem, o, baseline, cell_folds, sigma, kw) -> dict:
    """One speed fold of :func:`heldout_cells_check`: the withheld cells' mean squared gaps."""
    g_all = np.full(problem.valid["test"].shape, np.nan)
    for held in cell_folds:
        if not held.any() or held.all():
            continue
        fo = fit_candidate(problem.restricted(~held, held), o.effects, starts=[o.x],
                           grid=False, defaults=False, **kw)
        g_all = np.where(np.isfinite(fo.heldout_gaps), fo.heldout_gaps, g_all)
    ok = np.isfinite(g_all)
    per_c = per_speed_mse(g_all, ok)
    cells = ok.any(axis=0)
    e0, per_0 = cells_mse(baseline, cells)
    ec = float(np.mean(g_all[ok] ** 2)) if ok.any() else float("nan")
    return {"per_0": per_0, "per_c": per_c, "e0": e0, "ec": ec, "n": int(ok.sum()),
            "e_n": noise_mse(problem, sigma, cells)}


def crossfit(folds, o: FitOutcome, budget=None) -> np.ndarray:
    """Mean squared gap per speed of ``o``'s effects over all speed folds: its own held-out
    scores, then refits from ``o.x`` on each of ``folds`` (``[(Problem, baseline)]``)."""
    kw = {} if budget is None else {"budget": budget}
    parts = [o.heldout_per_rpm]
    for p, _ in folds:
        parts.append(fit_candidate(p, o.effects, starts=[o.x], grid=False, defaults=False,
                                   **kw).heldout_per_rpm)
    return np.concatenate(parts)


def crossfit_baseline(folds, baseline: FitOutcome) -> np.ndarray:
    """The baseline's mean squared gap per speed over the speeds :func:`crossfit` scores."""
    return np.concatenate([baseline.heldout_per_rpm] + [b.heldout_per_rpm for _, b in folds])


#: Budget of one band refit [trust-region steps of p + 1 evaluations]: an answer that holds
#: on the band needs a few; one that wanders is stopped (``budget_hit``).
BAND_STEPS = 20


def band_check(problem_factory, effect, data, train_idx, start, n_bands=4):
    """Refit ``effect`` on ``n_bands`` speed bands of ``train_idx`` from ``start`` (its
    whole-range optimum); ``problem_factory(idx)`` builds each band's problem."""
    out = []
    edges = np.linspace(0, train_idx.size, n_bands + 1).astype(int)
    for b in range(n_bands):
        idx = train_idx[edges[b]:edges[b + 1]]
        if idx.size < 3:
            continue
        fo = fit_candidate(problem_factory(idx), (effect,), starts=[start], grid=False,
                           defaults=False, budget=BAND_STEPS * (np.size(start) + 1))
        out.append({"rpm_from": float(data.rpm[idx[0]]), "rpm_to": float(data.rpm[idx[-1]]),
                    "parameters": fo.params[effect], "sigma": fo.sigma[effect],
                    "budget_hit": bool(fo.budget_hit)})
    return out
