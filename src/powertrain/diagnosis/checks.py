r"""Evidence beyond the held-out speeds: residual structure, held-out (channel, order) cells,
the noise a perfect model would leave, and the speed-band confounding check.

* :func:`structured_residual`: the held-out residual averaged per channel and order over
  groups of about 4 adjacent held-out speeds (noise averages out, structure does not);
* :func:`heldout_cells_check`: the candidate refitted without some (channel, order) cells
  must predict them at the held-out speeds. Physical effects withhold channels (folds
  generated from the mounts, :func:`channel_folds`: one channel of every mount triad each —
  the rigid body carries the effect to a channel it was not fitted on); candidates with
  sensor errors or per-channel parameters (``Effect.withhold_orders``: a missing body
  mode's shape at each base) withhold orders per channel (:func:`order_folds`: each channel's
  *informative* orders, with points above the noise floor, dealt into :data:`ORDER_FOLDS`
  staggered folds so that every refit still sees an informative order of every channel).
  A gain or a triad rotation is the same on every order of its channels, a frequency-tied
  gap is not, so free gains cannot absorb a structural gap;
* :func:`noise_mse`: :math:`E_n = \hat\sigma^2 u`, the held-out mean squared gap a perfect
  model would leave, :math:`u` the fraction of scored held-out points that are not censored;
* :func:`crossfit`: the candidate refitted with each other third of the speed blocks held
  out, so that every speed is scored once by a fit that did not see it (for candidates
  whose held-out t on one third of the speeds is short of the rule's);
* :func:`band_check`: the chosen effect refitted on four speed bands, each started from its
  whole-range optimum (no start grid: the trend of one answer is asked for, not another
  basin): a parameter believed constant that trends with speed points to a different
  effect.
"""

from __future__ import annotations

import math
import time

import numpy as np

from powertrain.analysis.noise_floor import above_floor
from powertrain.diagnosis.fit import FitOutcome, Problem, fit_candidate
from powertrain.diagnosis.significance import log_ratio_t
from powertrain.effects import EFFECTS

#: Fallback order split when fewer than two orders are informative: orders up to this one
#: form the "low" fold [order].
ORDER_SPLIT = 2.0
#: Folds of the (channel, informative order) cells for response-only candidates.
ORDER_FOLDS = 3
#: Measured training points above the floor that make an order informative.
MIN_ORDER_POINTS = 10


def channel_folds(n_mounts: int) -> tuple:
    """Channel folds: fold j withholds channel (j + m) mod 3 of mount m's triad, for every
    mount (three mounts: (0, 4, 8), (1, 5, 6), (2, 3, 7))."""
    return tuple(tuple(3 * m + (j + m) % 3 for m in range(n_mounts)) for j in range(3))


def structured_residual(g, censored, groups, sigma, cells=None):
    r"""Structured part of held-out residuals [dB RMS beyond noise] and its χ² ratio.

    For every group of adjacent held-out speeds and every (channel, order) the mean
    residual :math:`\bar g` of the :math:`n` uncensored points is formed; pure noise of
    scatter :math:`\sigma` gives :math:`E[\bar g^2] = \sigma^2/n`. Returned:
    :math:`\sqrt{\max(0,\ \overline{\bar g^2 - \sigma^2/n})}` and the ratio
    :math:`\overline{n\bar g^2/\sigma^2}` (≈ 1 for noise). Without a cell of two scored
    points: infinite when no held-out gap is finite (a fit without a steady state at the
    held-out speeds predicts nothing there), else 0 (all censored: nothing left to see) and
    a NaN ratio.

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
    z = np.concatenate(z) if z else np.empty(0)
    if not z.size:      # no cell with two scored points: nothing predicted, or nothing left
        return (float("inf"), float("inf")) if not np.isfinite(g).any() else (0.0, float("nan"))
    chi_r = float(np.mean(np.concatenate(chi))) if chi else float("nan")
    return float(math.sqrt(max(float(np.mean(z)), 0.0))), chi_r


def cells_mse(o: FitOutcome, cells):
    """Held-out mean squared gap of ``o`` on the (channel, order) ``cells``; and per speed."""
    g = o.heldout_gaps
    ok = np.isfinite(g) & np.asarray(cells, bool)[None]
    per = np.array([np.mean(g[i][ok[i]] ** 2) if ok[i].any() else np.nan
                    for i in range(g.shape[0])])
    return float(np.mean(g[ok] ** 2)) if ok.any() else float("nan"), per


def noise_mse(problem: Problem, sigma, cells=None) -> float:
    r"""Expected held-out mean squared gap of a perfect model [dB²]: :math:`\hat\sigma^2`
    times the fraction of scored held-out points that are not censored (a censored point's
    residual, :math:`\max(0, 20\log_{10}(s'/\kappa f))`, is 0 for a model below the
    censoring level, whatever the noise); a scored phase gap (:mod:`powertrain.diagnosis.phase`,
    all cells only) counts as one uncensored point."""
    if not (np.isfinite(sigma) and sigma > 0):
        return 0.0
    valid = problem.valid["test"]
    if cells is not None:
        valid = valid & np.asarray(cells, bool)[None]
    unc = int((valid & above_floor(problem.meas["test"], problem.data.floor)).sum())
    n = int(valid.sum())
    if cells is None and problem.phase_w is not None:   # phase gaps: uncensored, 1σ each
        n_phase = int(problem.phase_on["test"].sum())
        unc, n = unc + n_phase, n + n_phase
    return float(sigma ** 2 * unc / n) if n else 0.0


def order_folds(problem: Problem) -> list:
    """Withheld-cell masks (n_ch, n_o) over each channel's informative orders (at least
    :data:`MIN_ORDER_POINTS` training points of that channel above the floor): the i-th
    informative order of channel c is withheld in fold (c + i) mod :data:`ORDER_FOLDS`, so
    every order keeps some of its channels; a channel with a single informative order never
    has it withheld (its gain would have nothing left to be fitted on). With fewer than two
    informative orders overall, orders ≤ :data:`ORDER_SPLIT` vs the others."""
    n_ch, n_o = problem.valid["train"].shape[1:]
    usable = above_floor(problem.meas["train"], problem.data.floor) & problem.valid["train"]
    informative = usable.sum(axis=0) >= MIN_ORDER_POINTS              # (n_ch, n_o)
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
    """Refit ``o``'s effects without some (channel, order) cells and score the withheld
    cells at the held-out speeds (cross-validation over cells as well as speeds). With
    ``folds`` (``[(Problem, its baseline FitOutcome)]`` of the other speed folds: a
    candidate judged on cross-fitted speeds, :func:`crossfit`) the withheld cells are scored
    at the held-out speeds of every speed fold; ``first``: the held-out speeds' part of an
    earlier check of ``o`` (its ``parts[0]``), reused instead of refitted.

    Returns
    -------
    dict
        ``kind``, ``explained`` (fraction of the withheld cells' held-out excess over noise
        removed), ``t`` (per-speed significance), ``baseline_excess_db``,
        ``heldout_rms_db``, ``speed_folds`` and ``seconds``; and ``parts``, each speed
        fold's sums (not written to the JSON).
    """
    t0 = time.perf_counter()
    kind, cells = _folds(problem, o.effects)
    kw = {} if budget is None else {"budget": budget}
    parts = [first or _cells_fold(problem, o, baseline, cells, sigma, kw)]
    parts += [_cells_fold(p, o, b, cells, sigma, kw) for p, b in folds]
    n = sum(q["n"] for q in parts)
    e0, ec, e_n = (sum(q[k] * q["n"] for q in parts) / n if n else float("nan")
                   for k in ("e0", "ec", "e_n"))
    per_0, per_c = (np.concatenate([q[k] for q in parts]) for k in ("per_0", "per_c"))
    excess = max(e0 - e_n, 0.0)
    return {"kind": kind, "explained": (e0 - ec) / excess if excess > 0 else float("nan"),
            "t": log_ratio_t(per_0, per_c, e_n), "baseline_excess_db": math.sqrt(excess),
            "heldout_rms_db": math.sqrt(ec), "speed_folds": len(parts),
            "seconds": time.perf_counter() - t0, "parts": parts}


def _cells_fold(problem, o, baseline, cell_folds, sigma, kw) -> dict:
    """One speed fold of :func:`heldout_cells_check`: the withheld cells' mean squared gaps
    (baseline, refits, noise), per speed and over all scored points."""
    g_all = np.full(problem.valid["test"].shape, np.nan)
    for held in cell_folds:
        if not held.any() or held.all():
            continue
        fo = fit_candidate(problem.restricted(~held, held), o.effects, starts=[o.x],
                           grid=False, defaults=False, **kw)
        g_all = np.where(np.isfinite(fo.heldout_gaps), fo.heldout_gaps, g_all)
    ok = np.isfinite(g_all)
    per_c = np.array([np.mean(g_all[i][ok[i]] ** 2) if ok[i].any() else np.nan
                      for i in range(g_all.shape[0])])
    cells = ok.any(axis=0)
    e0, per_0 = cells_mse(baseline, cells)
    ec = float(np.mean(g_all[ok] ** 2)) if ok.any() else float("nan")
    return {"per_0": per_0, "per_c": per_c, "e0": e0, "ec": ec, "n": int(ok.sum()),
            "e_n": noise_mse(problem, sigma, cells)}


def crossfit(folds, o: FitOutcome, budget=None) -> np.ndarray:
    """Mean squared gap per speed of ``o``'s effects over all speed folds: ``o``'s own
    held-out scores (fold 0), then refits on each other fold's training speeds (started
    from ``o``'s optimum) scored on the speeds that fold leaves out. ``folds`` are
    ``[(Problem, its baseline FitOutcome)]`` of folds 1, 2, ...; the baseline's vector over
    the same speeds is :func:`crossfit_baseline`."""
    kw = {} if budget is None else {"budget": budget}
    parts = [o.heldout_per_rpm]
    for p, _ in folds:
        parts.append(fit_candidate(p, o.effects, starts=[o.x], grid=False, defaults=False,
                                   **kw)
                     .heldout_per_rpm)
    return np.concatenate(parts)


def crossfit_baseline(folds, baseline: FitOutcome) -> np.ndarray:
    """The baseline's mean squared gap per speed over the speeds :func:`crossfit` scores."""
    return np.concatenate([baseline.heldout_per_rpm] + [b.heldout_per_rpm for _, b in folds])


#: Evaluation budget of one band refit in trust-region steps' worth of evaluations (p + 1
#: each, p fitted parameters): a refit from the whole-range optimum moves there in a few
#: steps when the answer holds on the band; one that wanders (a body mode refitted on a band
#: that does not see its resonance crawled to 1100 evaluations, a quarter of a diagnosis's
#: time) is stopped and says so (``budget_hit``).
BAND_STEPS = 20


def band_check(problem_factory, effect, data, train_idx, start, n_bands=4):
    """Refit one effect on speed bands of the training data, from its whole-range optimum
    ``start`` (fitted vector): parameter trend with speed. Each refit has a budget of
    :data:`BAND_STEPS` steps."""
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
