"""The pure decision rule: every constant of DecisionRule has a case on each side of its
threshold (the same evidence, the threshold just below / just above the statistic)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from powertrain.diagnosis.evidence import CandidateEvidence, Evidence, Status, VerdictKind
from powertrain.diagnosis.rule import DecisionRule, decide, improvement_t

N = 30
WIGGLE = np.sin(np.arange(N) * 1.7)
CELLS_OK = {"kind": "channels", "explained": 0.9, "t": 12.0, "baseline_excess_db": 1.5}


def cand(label, mse, bic, struct=0.2, cells=CELLS_OK, spread=0.3):
    effects = tuple(label.split("+"))
    return CandidateEvidence(label, effects, mse, mse + spread * WIGGLE, bic, struct,
                             dict(cells) if cells else None)


def evidence(*cands, base_mse=4.0, base_struct=0.5, noise=0.5):
    base = CandidateEvidence("", (), base_mse, np.full(N, base_mse), 1000.0, base_struct)
    return Evidence(base, list(cands), noise, math.sqrt(noise), "where")


def just(rule_value, above):
    """A threshold just above (or below) a statistic."""
    return rule_value * (1.01 if above else 0.99)


def test_clean_case_chooses_the_candidate():
    v = decide(evidence(cand("a", 1.0, 900.0)))
    assert v.kind is VerdictKind.EFFECT and v.label == "a" == v.chosen
    assert v.assessments["a"].status is Status.CHOSEN


def test_missing_cells_check_is_requested_not_guessed():
    v = decide(evidence(cand("a", 1.0, 900.0, cells=None)))
    assert v.kind is VerdictKind.PENDING and v.needs_cells_check == "a"


@pytest.mark.parametrize("above", [False, True])
def test_t_min(above):
    ev = evidence(cand("a", 1.0, 900.0, spread=1.0))
    t = improvement_t(ev.baseline, ev.candidates[0], ev.noise_mse)
    ev.candidates[0].cells["t"] = 1e6
    v = decide(ev, DecisionRule(t_min=just(t, above)))
    assert (v.chosen == "a") is (not above)


@pytest.mark.parametrize("above", [False, True])
def test_bic_margin(above):
    v = decide(evidence(cand("a", 1.0, 900.0)), DecisionRule(bic_margin=just(100.0, above)))
    assert (v.chosen == "a") is (not above)
    assert v.assessments["a"].status is (Status.NOT_SUPPORTED if above else Status.CHOSEN)


@pytest.mark.parametrize("above", [False, True])
def test_explained_min(above):
    explained = (4.0 - 1.0) / (4.0 - 0.5)
    v = decide(evidence(cand("a", 1.0, 900.0)), DecisionRule(explained_min=just(explained, above)))
    assert (v.chosen == "a") is (not above)
    if above:
        assert v.kind is VerdictKind.UNEXPLAINED and v.assessments["a"].status is Status.PARTIAL


@pytest.mark.parametrize("above", [False, True])
def test_pair_gain_min(above):
    a, b = cand("a", 1.5, 950.0), cand("b", 3.0, 980.0)
    ab = cand("a+b", 0.8, 800.0)
    gain = (1.5 - 0.8) / (1.5 - 0.5)
    v = decide(evidence(a, b, ab), DecisionRule(pair_gain_min=just(gain, above)))
    assert v.chosen == ("a" if above else "a+b")
    if above:
        assert v.assessments["a+b"].status is Status.NOT_BETTER_THAN_MEMBER


@pytest.mark.parametrize("above", [False, True])
def test_a_member_leaving_less_than_excess_min_db_keeps_the_pair_out(above):
    """Member a leaves sqrt(1.5 - 0.5) = 1 dB RMS over noise: with excess_min_db just above
    that, a second effect has nothing beyond the lab's repeatability to explain and a is
    the answer; just below, the pair (which passes every other pair test) is."""
    a, b = cand("a", 1.5, 950.0), cand("b", 3.0, 980.0)
    ab = cand("a+b", 0.8, 800.0)
    rule = DecisionRule(excess_min_db=just(1.0, above))
    v = decide(evidence(a, b, ab), rule)
    assert v.chosen == ("a" if above else "a+b")
    if above:
        assert v.assessments["a+b"].status is Status.NOT_BETTER_THAN_MEMBER
        assert "leaves 1.00 dB RMS over noise" in v.assessments["a+b"].text


@pytest.mark.parametrize("above", [False, True])
def test_excess_min_db_no_effect_vs_unexplained(above):
    excess = math.sqrt(4.0 - 0.5)
    v = decide(evidence(cand("a", 3.9, 999.0)), DecisionRule(excess_min_db=just(excess, above)))
    assert v.kind is (VerdictKind.NO_EFFECT if above else VerdictKind.UNEXPLAINED)


@pytest.mark.parametrize("above", [False, True])
def test_excess_min_db_skips_cells_check_on_small_excess(above):
    cells = {**CELLS_OK, "explained": 0.1, "baseline_excess_db": 0.4}
    v = decide(evidence(cand("a", 1.0, 900.0, cells=cells)),
               DecisionRule(excess_min_db=just(0.4, above)))
    assert (v.chosen == "a") is above
    if not above:
        assert v.assessments["a"].status is Status.FAILS_HELDOUT_CELLS


@pytest.mark.parametrize("above", [False, True])
def test_struct_abs_db(above):
    v = decide(evidence(cand("a", 1.0, 900.0, struct=0.4), base_struct=0.5),
               DecisionRule(struct_abs_db=just(0.4, above)))
    assert (v.chosen == "a") is above
    if not above:
        assert v.assessments["a"].status is Status.STRUCTURED_RESIDUAL


@pytest.mark.parametrize("above", [False, True])
def test_struct_rel(above):
    v = decide(evidence(cand("a", 1.0, 900.0, struct=0.7), base_struct=2.0),
               DecisionRule(struct_abs_db=0.1, struct_rel=just(0.35, above)))
    assert (v.chosen == "a") is above


@pytest.mark.parametrize("above", [False, True])
def test_xv_explained_min(above):
    v = decide(evidence(cand("a", 1.0, 900.0)), DecisionRule(xv_explained_min=just(0.9, above)))
    assert (v.chosen == "a") is (not above)


@pytest.mark.parametrize("above", [False, True])
def test_xv_t_min(above):
    ev = evidence(cand("a", 1.0, 900.0))
    ev.candidates[0].cells.update(t=3.5, speed_folds=3)     # scored over every speed fold
    v = decide(ev, DecisionRule(xv_t_min=just(3.5, above)))
    assert (v.chosen == "a") is (not above)
    if above:
        assert v.assessments["a"].status is Status.FAILS_HELDOUT_CELLS


@pytest.mark.parametrize("above", [False, True])
def test_xv_t_screen(above):
    """A cells check scored at the held-out speeds only that misses xv_t_min is asked for
    again over every speed fold when its t is above xv_t_screen, else it fails."""
    ev = evidence(cand("a", 1.0, 900.0))
    ev.candidates[0].cells.update(t=2.5, speed_folds=1)
    v = decide(ev, DecisionRule(xv_t_screen=just(2.5, above)))
    if above:
        assert v.kind is VerdictKind.UNEXPLAINED
        assert v.assessments["a"].status is Status.FAILS_HELDOUT_CELLS
    else:
        assert v.kind is VerdictKind.PENDING and v.needs_cells_check == "a"


@pytest.mark.parametrize("n_checked", [1, 2])
def test_n_checked(n_checked):
    first = cand("a", 1.0, 900.0, struct=5.0)          # fails the structure check
    second = cand("b", 1.2, 905.0, spread=0.0)
    v = decide(evidence(first, second), DecisionRule(n_checked=n_checked))
    assert v.chosen == (None if n_checked == 1 else "b")


def test_rivals_of_another_family_make_it_ambiguous():
    b = cand("b", 1.01, 901.0)
    b.heldout_per_rpm = 1.01 + 0.3 * np.cos(np.arange(N) * 0.9)
    v = decide(evidence(cand("a", 1.0, 900.0), b))
    assert v.kind is VerdictKind.AMBIGUOUS and set(v.ambiguous) == {"a", "b"}


@pytest.mark.parametrize("restater_first", [True, False])
def test_a_restating_rival_yields_to_the_candidate_it_restates(restater_first):
    """A "missing" mode shaped like a file mode (b restates a) is neither the answer nor a
    rival while the held-out speeds cannot tell them apart, whichever ranks first."""
    a = cand("a", 1.01 if restater_first else 1.0, 900.0)
    b = cand("b", 1.0 if restater_first else 1.01, 901.0)
    b.heldout_per_rpm = b.heldout_mse + 0.3 * np.cos(np.arange(N) * 0.9)
    b.restates = ((("a",), "shape pairs with mode 1"),)
    v = decide(evidence(a, b))
    assert v.kind is VerdictKind.EFFECT and v.chosen == "a" and not v.ambiguous
    assert v.assessments["b"].status is Status.RESTATES
    assert "restates a (shape pairs with mode 1)" in v.assessments["b"].text


@pytest.mark.parametrize("above", [False, True])
def test_rivals_in_the_screen_band_are_cross_fitted(above):
    """A rival whose held-out t against the answer lies between t_screen and t_min is
    judged on the cross-fitted speeds of both; below t_screen the verdict is final."""
    a = cand("a", 1.0, 900.0)
    b = cand("b", 1.01, 901.0)
    b.heldout_per_rpm = 1.01 + 0.3 * np.cos(np.arange(N) * 0.9)
    t = improvement_t(b, a, 0.5)
    v = decide(evidence(a, b), DecisionRule(t_screen=just(abs(t), above)))
    if above:
        assert v.kind is VerdictKind.AMBIGUOUS
    else:
        assert v.kind is VerdictKind.PENDING and set(v.needs_crossfit) == {"a", "b"}


@pytest.mark.parametrize("pair_bic", [880.0, 905.0])
def test_a_pair_rival_worse_everywhere_than_a_single_answer_is_no_rival(pair_bic):
    """Rival x+y (two effects) indistinguishable on the held-out speeds from the single a but
    worse there: no rival when its training BIC is also worse by more than bic_margin (a
    needs one cause where x+y need two); ambiguous while x+y is better in BIC."""
    a = cand("a", 1.0, 890.0)
    xy = cand("x+y", 1.01, pair_bic)
    xy.heldout_per_rpm = 1.01 + 0.3 * np.cos(np.arange(N) * 0.9)
    singles = [cand(e, 3.9, 999.0, spread=0.0) for e in "xy"]
    v = decide(evidence(a, xy, *singles))
    if pair_bic > 890.0 + DecisionRule().bic_margin:
        assert v.kind is VerdictKind.EFFECT and v.chosen == "a"
        assert "needs 2 effects where a does better" in v.assessments["x+y"].text
    else:
        assert v.kind is VerdictKind.AMBIGUOUS and set(v.ambiguous) == {"a", "x+y"}


def test_a_restating_candidate_clearly_better_is_the_answer():
    """The restatement only settles what the data cannot: b, significantly better than the
    candidate it restates (held-out t > t_min), stays the answer."""
    a = cand("a", 2.5, 950.0, spread=0.0)
    b = cand("b", 1.0, 900.0)
    b.restates = ((("a",), "shape pairs with mode 1"),)
    v = decide(evidence(a, b))
    assert v.kind is VerdictKind.EFFECT and v.chosen == "b"


@pytest.mark.parametrize("member_mse", [1.5, 2.5])
def test_pairs_sharing_a_member_answer_the_member_when_it_stands_alone(member_mse):
    """Two indistinguishable pairs m+x, m+y that each beat m: m is the answer when it is a
    big supported candidate itself (explains 71 %), with its second effect not identified;
    when m alone explains too little (43 % < explained_min) the verdict stays ambiguous."""
    member = cand("m", member_mse, 950.0, spread=0.0)
    mx = cand("m+x", 0.8, 900.0)
    my = cand("m+y", 0.81, 901.0)
    my.heldout_per_rpm = 0.81 + 0.3 * np.cos(np.arange(N) * 0.9)
    singles = [cand(e, 3.9, 999.0, spread=0.0) for e in "xy"]   # weak on their own
    v = decide(evidence(member, mx, my, *singles))
    if member_mse < 2.0:
        assert v.kind is VerdictKind.EFFECT and v.chosen == "m" and not v.ambiguous
        assert set(v.second_effect_between) == {"m+x", "m+y"}
        assert "cannot tell x from y" in v.text or "cannot tell y from x" in v.text
        assert v.assessments["m+x"].status is Status.INDISTINGUISHABLE
    else:
        assert v.kind is VerdictKind.AMBIGUOUS and set(v.ambiguous) == {"m+x", "m+y"}


def test_decide_is_pure():
    ev = evidence(cand("a", 1.0, 900.0))
    before = dataclasses.asdict(ev)
    decide(ev)
    decide(ev)
    after = dataclasses.asdict(ev)
    assert repr(before) == repr(after)


def test_rule_is_frozen_and_documented():
    rule = DecisionRule()
    with pytest.raises(dataclasses.FrozenInstanceError):
        rule.t_min = 1.0
    doc = DecisionRule.__doc__
    for f in dataclasses.fields(DecisionRule):
        assert f"    {f.name} :" in doc, f.name


def test_supported_candidate_within_noise_is_no_effect_not_unexplained():
    """A model equal to the measurement up to round-off: candidates fit the round-off
    'significantly' (huge BIC gains on tiny residuals) but there is nothing to explain."""
    base_mse, noise = 4.0e-4, 1.5e-4
    a = cand("a", 3.0e-4, 500.0, spread=1e-5)          # explains 40 %: partial
    ev = evidence(a, base_mse=base_mse, noise=noise)
    v = decide(ev)
    assert v.kind is VerdictKind.NO_EFFECT and "would change it by" in v.text


def _balancer_data(rpm, params):
    """The model's own noise-free orders 1 and 2 with a balancer error: (model, data)."""
    from powertrain.diagnosis.data import GapData
    from powertrain.effects import predict
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    from powertrain.solvers.fast_harmonic import HarmonicModel
    eng = read_engine(DEFAULT_ENGINE_PATH)
    hm = HarmonicModel(eng, rpm)
    v = predict(hm, {"balancer_error": params}).velocity
    lev = np.abs(v[:, :, [1, 3]]) / np.sqrt(2)
    return hm, GapData(rpm, [(m, d) for m in eng.mount_names for d in "xyz"],
                       ["order_1", "order_2"], np.array([1, 3]), lev, 1e-9)


def test_evaluation_budget_stops_a_fit_and_says_so():
    """A fit that reaches its evaluation budget keeps its best point and is flagged."""
    from powertrain.diagnosis.data import split_rpm
    from powertrain.diagnosis.fit import Problem, fit_candidate
    rpm = np.arange(1000.0, 6000.1, 250.0)
    hm, data = _balancer_data(rpm, {"gain": 0.6, "lag": 0.2})
    tr, te = split_rpm(rpm)
    prob = Problem(hm.subset(tr), hm.subset(te), data, tr, te)
    small = fit_candidate(prob, ("balancer_error",), budget=8)
    full = fit_candidate(prob, ("balancer_error",))
    assert small.budget_hit and small.n_eval <= 8 and not full.budget_hit
    assert full.heldout_mse < small.heldout_mse


def test_improvement_t_is_a_relative_improvement():
    """Per-speed log ratios: an improvement by the same factor at every speed has no scatter
    (unbounded t) however much the gap varies along the run-up, while a difference of the
    gaps would scatter with the gap; adding the noise's E_n keeps it finite and large."""
    gap = np.linspace(1.0, 40.0, N)                       # gap grows towards a resonance
    base = CandidateEvidence("", (), float(gap.mean()), gap, 0.0)
    half = CandidateEvidence("a", ("a",), float(gap.mean() / 2), gap / 2, 0.0)
    assert improvement_t(base, half) > 1e6
    d = gap - gap / 2
    assert np.mean(d) / (np.std(d, ddof=1) / np.sqrt(N)) < 10   # the difference's t
    assert 10 < improvement_t(base, half, noise_mse=1.0) < 1e6


def _sparse(n, base, hit, every=5):
    """Per-speed gaps: ``base`` everywhere, ``hit`` at every ``every``-th speed (a gap that
    sits at a few resonance crossings)."""
    g = np.full(n, base)
    g[::every] = hit
    return g


def _crossfit_case(n_held=17, n_all=51):
    """A candidate that removes a gap sitting at a few speeds: few informative held-out
    speeds (t between t_screen and t_min), three times as many over all speed folds."""
    base = CandidateEvidence("", (), 4.0, _sparse(n_held, 0.6, 12.0), 1000.0, 0.5)
    c = CandidateEvidence("a", ("a",), 0.7, _sparse(n_held, 0.55, 1.0) * (1 + 0.2 * WIGGLE[:n_held]),
                          900.0, 0.2, dict(CELLS_OK))
    wiggle = 1 + 0.2 * np.sin(np.arange(n_all) * 1.7)
    base_x, c_x = _sparse(n_all, 0.6, 12.0), _sparse(n_all, 0.55, 1.0) * wiggle
    return Evidence(base, [c], 0.5, math.sqrt(0.5), "where"), base_x, c_x


@pytest.mark.parametrize("above", [False, True])
def test_t_screen(above):
    """Held-out t between t_screen and t_min: cross-fitting is requested (pending), not
    guessed; below t_screen the candidate is simply not supported."""
    ev, _, _ = _crossfit_case()
    t = improvement_t(ev.baseline, ev.candidates[0], ev.noise_mse)
    assert 2.0 < t < 4.0
    v = decide(ev, DecisionRule(t_screen=just(t, above)))
    if above:
        assert v.kind is VerdictKind.UNEXPLAINED and not v.needs_crossfit
    else:
        assert v.kind is VerdictKind.PENDING and v.needs_crossfit == ["a"]


@pytest.mark.parametrize("above", [False, True])
def test_crossfit_t_is_judged_against_t_min(above):
    """Once cross-fitted, the candidate is supported when its t over every speed exceeds
    t_min (the same threshold), and the verdict no longer waits for it."""
    from powertrain.diagnosis.rule import crossfit_t
    ev, bx, cx = _crossfit_case()
    ev.baseline.crossfit, ev.candidates[0].crossfit = bx, cx
    tx = crossfit_t(ev.baseline, ev.candidates[0], ev.noise_mse)
    t = improvement_t(ev.baseline, ev.candidates[0], ev.noise_mse)
    assert tx > 4.0 > t
    v = decide(ev, DecisionRule(t_min=just(tx, above)))
    assert v.kind is not VerdictKind.PENDING
    assert (v.chosen == "a") is (not above)
    assert v.assessments["a"].t_crossfit == pytest.approx(tx)


def test_crossfit_folds_score_every_speed_once():
    """The three speed folds hold out every speed exactly once; fold 0 is the split the
    fits use."""
    from powertrain.diagnosis.data import N_FOLDS, split_rpm
    rpm = np.arange(800.0, 6001.0, 100.0)
    held = np.concatenate([split_rpm(rpm, k)[1] for k in range(N_FOLDS)])
    assert np.array_equal(np.sort(held), np.arange(rpm.size))
    for k in range(N_FOLDS):
        tr, te = split_rpm(rpm, k)
        assert np.intersect1d(tr, te).size == 0 and tr.size + te.size == rpm.size
    assert np.array_equal(split_rpm(rpm)[1], split_rpm(rpm, 0)[1])


def test_crossfit_scores_each_fold_with_a_refit_that_did_not_see_it():
    """checks.crossfit: fold 0 is the candidate's own held-out score, folds 1, 2 refits on
    their training speeds; on the model's own (noise-free) response with the effect every
    speed is predicted, and the baseline over the same speeds is not."""
    from powertrain.diagnosis.checks import crossfit, crossfit_baseline
    from powertrain.diagnosis.data import N_FOLDS, split_rpm
    from powertrain.diagnosis.fit import Problem, baseline_outcome, fit_candidate
    rpm = np.arange(1000.0, 6000.1, 200.0)
    hm, data = _balancer_data(rpm, {"gain": 1.4, "lag": 0.2})
    probs = [Problem(hm.subset(tr), hm.subset(te), data, tr, te)
             for tr, te in (split_rpm(rpm, k) for k in range(N_FOLDS))]
    o = fit_candidate(probs[0], ("balancer_error",))
    folds = [(p, baseline_outcome(p)) for p in probs[1:]]
    per = crossfit(folds, o)
    base = crossfit_baseline(folds, baseline_outcome(probs[0]))
    assert per.size == base.size == rpm.size
    assert np.array_equal(per[:o.heldout_per_rpm.size], o.heldout_per_rpm)
    assert np.nanmax(per) < 1e-6 < np.nanmin(base)


def _pair_case():
    """A pair whose gain over its better member sits at a few held-out speeds: held-out t
    between t_screen and t_min."""
    n = N
    a = CandidateEvidence("a", ("a",), 1.5, _sparse(n, 1.0, 4.0), 950.0, 0.2, dict(CELLS_OK))
    ab = CandidateEvidence("a+b", ("a", "b"), 0.8, _sparse(n, 0.95, 1.1)
                           * (1 + 0.2 * WIGGLE), 800.0, 0.2, dict(CELLS_OK))
    b = cand("b", 3.0, 980.0)
    return evidence(a, b, ab), a, ab


def test_pair_against_member_is_cross_fitted_in_the_band():
    ev, a, ab = _pair_case()
    t = improvement_t(a, ab, ev.noise_mse)
    assert 2.0 < t < 4.0
    v = decide(ev)
    assert v.kind is VerdictKind.PENDING and v.needs_crossfit == ["a+b", "a"]
    assert decide(ev, DecisionRule(t_screen=just(t, True))).chosen == "a"


@pytest.mark.parametrize("above", [False, True])
def test_pair_cross_fitted_against_member_uses_t_min(above):
    from powertrain.diagnosis.rule import crossfit_t
    ev, a, ab = _pair_case()
    n3 = 3 * N
    wig = 1 + 0.2 * np.sin(np.arange(n3) * 1.7)
    ev.baseline.crossfit = np.full(n3, 4.0)
    a.crossfit, ab.crossfit = _sparse(n3, 1.0, 4.0), _sparse(n3, 0.95, 1.1) * wig
    tx = crossfit_t(a, ab, ev.noise_mse)
    assert tx > 4.0
    v = decide(ev, DecisionRule(t_min=just(tx, above)))
    assert v.kind is not VerdictKind.PENDING
    assert v.chosen == ("a" if above else "a+b")


@pytest.mark.parametrize("above", [False, True])
def test_no_claim_without_excess_over_noise(above):
    """A baseline within noise (excess sqrt(0.54 - 0.5) = 0.2 dB) with a structured residual
    within struct_abs_db: no effect before any candidate is weighed, however well one passes
    the rest of the rule (it fits round-off); just below the excess, the candidate."""
    ev = evidence(cand("a", 0.501, 900.0, struct=0.1, spread=0.0001), base_mse=0.54,
                  base_struct=0.3)
    v = decide(ev, DecisionRule(excess_min_db=just(0.2, above), explained_min=0.5))
    assert v.kind is (VerdictKind.NO_EFFECT if above else VerdictKind.EFFECT), v.text
