"""The diagnosis driver: data → where → candidates → fit → decide → result.

:func:`diagnose` runs the steps of the modules of this package in order; every decision
is taken by the pure :func:`powertrain.diagnosis.rule.decide`.
"""

from __future__ import annotations

import math
import os
import time

import numpy as np

from powertrain.diagnosis import candidates as cand
from powertrain.diagnosis.checks import (
    band_check,
    crossfit,
    crossfit_baseline,
    heldout_cells_check,
    noise_mse,
    structured_residual,
)
from powertrain.diagnosis.data import (
    DEFAULT_NOISE_FLOOR,
    HELDOUT_BLOCKS,
    MIN_RPM,
    N_BLOCKS,
    N_FIT_RPM,
    N_FOLDS,
    N_TEST_RPM,
    even,
    gap_data,
    model_levels,
    noise_sigma_db,
    residuals_db,
    speed_groups,
    split_rpm,
)
from powertrain.diagnosis.evidence import CandidateEvidence, Evidence, VerdictKind
from powertrain.diagnosis.fit import EVAL_BUDGET, Problem, baseline_outcome, fit_candidate
from powertrain.diagnosis.plan import PlanSetup
from powertrain.diagnosis.report import fit_notes
from powertrain.diagnosis.result import DiagnosisResult
from powertrain.diagnosis.rule import DecisionRule, decide
from powertrain.diagnosis.sides import fitted_shape, side_attribution, with_measured_body_side
from powertrain.diagnosis.where import decompose_gap, regions, rigid_span_gap, where_text
from powertrain.effects import EFFECTS, predict
from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.iotools.measured import read_measured
from powertrain.iotools.plan import read_plan
from powertrain.parallel import run_map, single_blas_thread
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows import arguments as args


def diagnose(measured, engine=None, *, noise_floor=DEFAULT_NOISE_FLOOR, effects=None,
             pairs=True, band_check=True, rule=None, scheduler=None, progress=True,
             budget=EVAL_BUDGET) -> DiagnosisResult:
    """Diagnose the gap between ``engine``'s simulated run-up and ``measured``.

    Parameters
    ----------
    measured : MeasuredRunup, Plan, str or path
        Measured order curves [m/s RMS] or their file (CSV or run-up HDF5); or a test plan
        (:class:`powertrain.iotools.plan.Plan` or its ``.toml``): one parameter set for all runs.
    engine : Engine, str or path, optional
        Baseline model or its file (default: the shipped ``engines/default.toml``).
    noise_floor : float
        RMS noise floor of the measured order curves [m/s].
    effects : sequence of str, optional
        Candidates (default: every registry effect that applies to ``engine``).
    pairs : bool
        Also fit pairs of the best single candidates.
    band_check : bool
        Refit the chosen effect on speed bands (confounding check).
    rule : DecisionRule, optional
        Decision constants.
    scheduler : str
        Where the fits run (:func:`powertrain.parallel.executor`): ``serial`` (default),
        ``processes``, ``local`` or ``tcp://HOST:PORT``; the result is the same on each.
    progress : bool
        Progress bar on stderr (only on a terminal).
    budget : int
        Residual evaluations per fit.

    Returns
    -------
    DiagnosisResult

    Raises
    ------
    InputError
        An unknown effect, a file that cannot be read, order curves of another signal than
        velocity, too few speeds to split, or nothing comparable.
    """
    effects = None if effects is None else args.names(effects, "--effects")
    noise_floor = args.nonnegative(noise_floor, "--noise-floor", "m/s")
    budget = args.integer(budget, "budget", minimum=1)
    pairs, band_check = args.flag(pairs, "--no-pairs"), args.flag(band_check, "band_check")
    engine, measured = _inputs(measured, engine, effects)
    with single_blas_thread():
        return _diagnose(measured, engine, noise_floor, effects, pairs, band_check,
                         rule or DecisionRule(), scheduler or "serial", progress, budget)


def _inputs(measured, engine, effects):
    """``(engine, measured)``, read from files if paths; effect names checked."""
    for e in effects or []:
        if e not in EFFECTS:
            raise InputError(f"unknown effect {e!r} (known: {', '.join(EFFECTS)})", key="--effects")
    engine = engine_or_default(engine)
    if isinstance(measured, (str, os.PathLike)) and str(measured).lower().endswith(".toml"):
        measured = read_plan(measured, engine)
    elif isinstance(measured, (str, os.PathLike)):
        measured = read_measured(measured, mounts=engine.mount_names)
    elif not hasattr(measured, "runs") and not hasattr(measured, "signal"):
        raise InputError("expected a MeasuredRunup, a Plan or a file, got "
                         f"{type(measured).__name__}", key="MEASURED")
    for m in [r.measured for r in measured.runs] if hasattr(measured, "runs") else [measured]:
        if m.signal != "velocity":
            raise InputError("diagnose needs velocity, acceleration or displacement order "
                             f"curves (this file holds {m.signal})", file=m.source or None)
    return engine, measured


class _Setup:
    """Data, split, cached models and the fitting problem of one diagnosis."""

    def __init__(self, measured, engine, noise_floor, effects):
        self.src = getattr(measured, "source", "")
        engine = with_measured_body_side(engine, measured)
        self.data = data = gap_data(measured, engine, noise_floor)
        _check_data(data, self.src)
        self.train_all, self.test_all = split_rpm(data.rpm)
        self.train_idx = even(self.train_all, N_FIT_RPM)
        self.test_idx = even(self.test_all, N_TEST_RPM)
        self.effects = cand.applicable(engine, effects)
        self.hm = HarmonicModel(engine, data.rpm)
        if data.channels != self.hm.channels:
            self.hm.use_channels(data.channels)
        cand.warm_caches(self.hm, self.effects)     # once, on every speed: subsets share it
        need = np.union1d(self.train_all, self.test_idx)
        self.hm_need = self.hm.subset(need)
        self.pos = {int(r): i for i, r in enumerate(need)}
        self.problem = Problem(self.sub(self.train_idx), self.sub(self.test_idx), data,
                               self.train_idx, self.test_idx)

    def sub(self, idx):
        return self.hm_need.subset([self.pos[int(i)] for i in idx])

    def fold_problems(self) -> list:
        """``[(Problem, baseline outcome)]`` of speed folds 1, 2, built on first use."""
        if getattr(self, "_folds", None) is None:
            self._folds = []
            for k in range(1, N_FOLDS):
                tr, te = split_rpm(self.data.rpm, fold=k)
                tr, te = even(tr, N_FIT_RPM), even(te, N_TEST_RPM)
                hm = self.hm.subset(np.union1d(tr, te))
                cand.warm_caches(hm, self.effects)
                pos = {int(r): i for i, r in enumerate(np.union1d(tr, te))}
                p = Problem(hm.subset([pos[int(i)] for i in tr]),
                            hm.subset([pos[int(i)] for i in te]), self.data, tr, te)
                self._folds.append((p, baseline_outcome(p)))
        return self._folds

    def split_dict(self):
        d = self.data
        return {"description": f"{N_BLOCKS} contiguous speed blocks, blocks "
                               f"{', '.join(str(b + 1) for b in HELDOUT_BLOCKS)} held out: "
                               f"{self.test_all.size} held-out speeds ({self.test_idx.size} scored), "
                               f"{self.train_all.size} training speeds ({self.train_idx.size} fitted); all "
                               f"channels and measured orders; synthesis not fitted",
                "train_rpm": d.rpm[self.train_idx].tolist(),
                "heldout_rpm": d.rpm[self.test_idx].tolist()}


def _check_data(data, src):
    if data.rpm.size < MIN_RPM:
        raise InputError(f"only {data.rpm.size} measured speeds inside the engine's range: "
                         f"too few to split into training and held-out speeds (need at least "
                         f"{MIN_RPM})", file=src or None, key="rpm")
    om = data.order_mask
    if not om.any() or data.usable[:, :, om].sum() < 20:
        raise InputError("fewer than 20 measured order points above the noise floor's "
                         "censoring level (3x the floor): nothing to diagnose", file=src or None)


def _where(s: _Setup):
    data = s.data
    vel0 = predict(s.hm, {}).velocity
    sim = model_levels(vel0, data)
    gap = residuals_db(sim, data.level, data.floor)
    gap_map = np.where(data.censored, np.nan, gap)
    mask = np.isfinite(gap_map) & data.order_mask[None, None, :]
    parts = decompose_gap(gap_map, data, mask)
    parts["sides"] = side_attribution(gap_map, data)
    na = data.n_active
    return gap_map, parts, rigid_span_gap(vel0[:, :na], data.active_only(), s.hm.channel_matrix), \
        regions(gap_map, data, parts), sim


def _fit_job(job):
    problem, effects, starts, budget = job
    with single_blas_thread():
        return fit_candidate(problem, effects, starts=starts, budget=budget, defaults=starts is None)


def _fit_all(s: _Setup, pairs, scheduler, progress, budget, e_n, rule, baseline, sigma):
    """Fit singles, then pairs (:func:`pair_candidates`), each with its structured residual."""
    desc = "diagnose: candidate fits" if progress else None
    jobs = [(s.problem, (e,), None, budget) for e in s.effects]
    singles = run_map(_fit_job, jobs, scheduler, progress=desc)
    _structure(s, baseline, singles, sigma)
    outcomes = list(singles)
    if pairs:
        by = {o.effects[0]: o for o in singles}
        jobs = [(s.problem, (a, b), [np.concatenate([by[a].x, by[b].x])], budget)
                for a, b in pair_candidates(singles, e_n, rule)]
        found = run_map(_fit_job, jobs, scheduler, progress=desc and "diagnose: pairs")
        _structure(s, baseline, found, sigma)
        outcomes += found
    return outcomes


def pair_candidates(singles, e_n, rule) -> list:
    """Pairs worth fitting: the best single with each other and the second with the third;
    none when the best leaves an excess below ``rule.excess_min_db`` and no structure.

    Parameters
    ----------
    singles : list of FitOutcome
    e_n : float
        Noise mean squared gap [dB²].
    rule : DecisionRule
    """
    ranked = sorted(singles, key=lambda o: o.heldout_mse)
    if not ranked:
        return []
    top = ranked[0]
    if (math.sqrt(max(top.heldout_mse - e_n, 0.0)) < rule.excess_min_db
            and top.struct_db <= rule.struct_abs_db):
        return []
    best = top.effects[0]
    out = [(best, o.effects[0]) for o in ranked[1:]]
    if len(ranked) >= 3:
        out.append((ranked[1].effects[0], ranked[2].effects[0]))
    return out


def _evidence(o, struct=None):
    return CandidateEvidence(o.label, o.effects, o.heldout_mse, o.heldout_per_rpm, o.bic,
                             o.struct_db if struct is None else struct, o.cells_check, o.crossfit, o.restates)


def _decide(s, baseline, outcomes, sigma, rule, where_phrase, budget):
    """Decide; run held-out cells checks as the rule asks for them."""
    e_n = noise_mse(s.problem, sigma)
    by_label = {o.label: o for o in outcomes}
    while True:
        ev = Evidence(_evidence(baseline), [_evidence(o) for o in outcomes], e_n, sigma, where_phrase)
        verdict = decide(ev, rule)
        if verdict.kind is not VerdictKind.PENDING:
            return verdict, e_n
        if verdict.needs_crossfit:
            folds = s.fold_problems()
            if baseline.crossfit is None:
                baseline.crossfit = crossfit_baseline(folds, baseline)
            for label in verdict.needs_crossfit:
                by_label[label].crossfit = crossfit(folds, by_label[label], budget=budget)
            continue
        o = by_label[verdict.needs_cells_check]
        # all speed folds when held-out t was short, or on a retry (reusing the first refits)
        all_folds = not verdict.assessments[o.label].t_stat > rule.t_min or o.cells_check is not None
        first = o.cells_check["parts"][0] if o.cells_check is not None else None
        o.cells_check = heldout_cells_check(
            s.problem, o, baseline, sigma, budget=budget,
            folds=s.fold_problems() if all_folds else (), first=first)


def _structure(s, baseline, outcomes, sigma):
    groups = speed_groups(s.test_idx)
    cens_t = ~s.data.usable[s.test_idx][:, :, s.data.order_mask]
    for o in [baseline] + outcomes:
        o.struct_db, o.chi2_ratio = structured_residual(o.heldout_gaps, cens_t, groups, sigma)


def _diagnose(measured, engine, noise_floor, effects, pairs, do_bands, rule, scheduler, progress, budget):
    t0 = time.perf_counter()
    if hasattr(measured, "runs"):
        s = PlanSetup(measured, engine, noise_floor, effects, _Setup)
    else:
        s = _Setup(measured, engine, noise_floor, effects)
    w = getattr(s, "first", s)                 # where and the figures: a plan's first run
    gap_map, parts, rigid, found, sim0 = _where(w)
    s.effects = cand.at_location(s.effects, parts.get("sides"))
    sigma = noise_sigma_db(s.data)
    baseline = baseline_outcome(s.problem)
    _structure(s, baseline, [], sigma)
    outcomes = _fit_all(s, pairs, scheduler, progress, budget, noise_mse(s.problem, sigma), rule,
                        baseline, sigma)
    band = s.data.band_hz()
    for o in outcomes:
        o.restates = cand.restatements(o, s.problem.engine, band)
    verdict, e_n = _decide(s, baseline, outcomes, sigma, rule, where_text(found, parts), budget)
    for o in outcomes:
        a = verdict.assessments[o.label]
        o.t_stat, o.bic_gain, o.explained = a.t_stat, a.bic_gain, a.explained
        o.t_crossfit = a.t_crossfit
        o.status, o.status_code = a.text, a.status
    outcomes.sort(key=lambda o: o.heldout_mse)
    chosen = next((o for o in outcomes if o.label == verdict.chosen), None)
    if chosen is not None and len(chosen.effects) == 1 and parts.get("sides"):
        e = chosen.effects[0]
        parts["sides"]["fitted_shape"] = fitted_shape(e, chosen.params[e], s.problem.engine)
    gap_after, sim_after, bands = None, None, []
    if chosen is not None:
        gap_after, sim_after = _gap_after(w, {e: chosen.params[e] for e in chosen.effects})
        if do_bands and len(chosen.effects) == 1 and w is s:
            def factory(idx):
                return Problem(s.sub(idx), s.problem.hm["test"], s.data, idx, s.test_idx)
            bands = band_check(factory, chosen.effects[0], s.data,
                               s.train_all[::max(1, s.train_all.size // 48)], chosen.x)
    eq = cand.equivalents(s, chosen, rule, noise_mse=e_n)
    what = "order magnitudes and phases" if s.data.has_phase else "order magnitudes"
    text = verdict.text if not eq else verdict.text + (
        f"; the {what} cannot tell it from {len(eq)} equivalent explanation(s): "
        + "; ".join(x["text"] for x in eq[:3]) + ("; ..." if len(eq) > 3 else ""))
    finding = _finding(s, chosen)
    if finding is not None:
        text += f"; {finding['text']}"
    text += "".join(f"; {t}" for t in fit_notes(chosen, outcomes, bands, budget))
    return DiagnosisResult(
        w.data, s.src, getattr(engine, "name", ""), gap_map, gap_after, parts, rigid, found,
        sigma, w.split_dict(), baseline, outcomes, chosen, verdict.label, text, bands,
        time.perf_counter() - t0, synthetic=bool(getattr(measured, "synthetic", False)),
        noise_mse_heldout=e_n, ambiguous=verdict.ambiguous, rule=rule,
        second_effect_between=verdict.second_effect_between, verdict_kind=verdict.kind, equivalents=eq,
        budget_hits=[o.label for o in outcomes if o.budget_hit], finding=finding,
        phase=_phase_dict(s, chosen), runs=s.run_entries(chosen) if w is not s else [],
        engine=engine, sim_levels=sim0, sim_after=sim_after)


def _gap_after(w, sc):
    """Gap map and model levels [m/s RMS] with effects ``sc`` (None, None: no steady state)."""
    try:
        vel = predict(w.hm, sc).velocity
    except FloatingPointError:
        return None, None
    sim = model_levels(vel, w.data)
    g1 = residuals_db(sim, w.data.level, w.data.floor)
    return np.where(w.data.censored, np.nan, g1), sim


def phase_kind(data) -> str:
    """Measured phase of ``data``: ``"all"`` (half orders too), ``"whole"`` or ``"none"``."""
    return "all" if data.has_half_order_phase else "whole" if data.has_phase else "none"


def _finding(s, chosen):
    """What the chosen single effect names (``Effect.finding``), or None."""
    if chosen is None or len(chosen.effects) != 1:
        return None
    e = chosen.effects[0]
    return EFFECTS[e].finding(chosen.params[e], s.problem.engine, phase_kind(s.data))


def _phase_dict(s, chosen) -> dict:
    """The JSON's ``phase``: what was measured, the crank-angle offsets [deg] with the answer."""
    sc = {} if chosen is None else {e: chosen.params[e] for e in chosen.effects}
    offsets = [None if o is None else math.degrees(o) for o in s.problem.crank_offsets(sc)]
    return {"measured": phase_kind(s.data), "crank_offset_deg": offsets[0],
            "crank_offset_deg_per_run": offsets, "scored_points": 0 if s.problem.phase_w is None
            else int(s.problem.phase_on["train"].sum() + s.problem.phase_on["test"].sum())}
