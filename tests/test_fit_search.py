"""The fits' trust-region search (:mod:`powertrain.diagnosis.search`): the stall watch, and
the amplitude fixed point's start for the next evaluation
(:mod:`powertrain.diagnosis.warm_start`)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from powertrain.diagnosis import search
from powertrain.diagnosis.warm_start import AmplitudeStart, scenario_vector


class _Problem:
    """A residual vector read from ``costs`` in turn (cost = 0.5 r^2)."""

    def __init__(self, costs):
        self.costs = iter(costs)
        self.sigma_db = 1.0

    def vector(self, scenario):
        return np.array([np.sqrt(2.0 * next(self.costs))])


#: One physical parameter (the fakes' packing).
_NAMES = [("mount_stiffness", "k")]


def _counted(costs, budget=10_000):
    pack = SimpleNamespace(n_prior=0, scenario=lambda x: {}, x0=np.zeros(1), names=_NAMES)
    return search.Counted(_Problem(costs), pack, budget)


def test_a_start_that_stops_improving_stalls_after_its_window():
    window = search.STALL_STEPS * (1 + 1)
    fun = _counted(1000.0 * (1 - 1e-6) ** np.arange(10 * window))
    fun.watch(1)
    with pytest.raises(search._Stalled):
        for _ in range(10 * window):
            fun(np.zeros(1))
    assert fun.n == window + 2          # the first sets the reference, then window + 1 more


def test_a_start_that_keeps_improving_never_stalls_and_no_watch_no_stall():
    n = 20 * search.STALL_STEPS
    fun = _counted(1000.0 * (1 - 1e-3) ** np.arange(n))
    fun.watch(1)
    for _ in range(n):
        fun(np.zeros(1))
    flat = _counted(np.full(n, 5.0))
    for _ in range(n):                  # the start grid runs unwatched
        flat(np.zeros(1))
    assert flat.best[0] == pytest.approx(5.0)


def test_a_stalled_search_hands_back_its_best_point():
    """A cost that creeps down by 1e-6 a call, wherever the search goes: the search stops
    on the stall, long before the budget or its iteration limit, and hands back None (the
    caller takes ``fun.best``, the lowest point seen)."""
    n_max = 10_000
    pack = SimpleNamespace(n_prior=0, scenario=lambda x: {}, x0=np.zeros(1), names=_NAMES,
                           lower=np.array([0.0]), upper=np.array([1.0]))
    fun = search.Counted(_Problem(1000.0 * (1 - 1e-6) ** np.arange(n_max)), pack, n_max)
    res, _, hit = search.trust_region(fun, pack, [np.array([0.5])])
    assert res is None and not hit
    assert fun.n == search.STALL_STEPS * 2 + 2
    assert fun.best[0] == pytest.approx(1000.0 * (1 - 1e-6) ** (fun.n - 1))


def test_the_amplitude_start_is_exact_for_amplitudes_log_linear_in_the_parameters():
    rng = np.random.default_rng(1)
    log_a0, slopes = rng.normal(-9, 1, (4, 3)), rng.normal(0, 2, (2, 4, 3))

    def amplitudes(v):
        return np.exp(log_a0 + np.tensordot(v, slopes, axes=1))

    st = AmplitudeStart()
    assert st.start(np.zeros(2)) is None
    base = np.array([0.3, 1.2])
    st.record(base, amplitudes(base))
    for j in range(2):                  # the columns of the base point
        col = base.copy()
        col[j] += 1e-4 * max(1.0, abs(base[j]))
        st.record(col, amplitudes(col))
    assert np.array_equal(st.base[0], base)
    trial = base + np.array([0.02, -0.05])        # ln A changes by less than 1
    np.testing.assert_allclose(st.start(trial), amplitudes(trial), rtol=1e-9)
    col = base.copy()
    col[1] += 1e-4 * 1.2
    np.testing.assert_allclose(st.start(col), amplitudes(col), rtol=1e-12)
    st.record(trial, amplitudes(trial))  # a step, not a column: the new base
    assert np.array_equal(st.base[0], trial)


def test_a_long_trial_step_is_predicted_within_a_factor_e_of_the_base():
    from powertrain.diagnosis.warm_start import MAX_LOG_CHANGE
    st = AmplitudeStart()
    base = np.array([0.1])
    st.record(base, np.full((2, 3), 1e-4))
    st.record(base + 1e-4, np.full((2, 3), 1e-4 * np.exp(20e-4)))   # slope 20 per unit
    far = st.start(np.array([0.9]))                                  # 20 * 0.8 = 16 in ln A
    np.testing.assert_allclose(far, 1e-4 * np.exp(MAX_LOG_CHANGE))
    near = st.start(np.array([0.11]))
    np.testing.assert_allclose(near, 1e-4 * np.exp(0.2), rtol=1e-9)


def test_scenario_vector_orders_effects_and_parameters_by_name():
    v = scenario_vector({"b": {"y": 2.0, "x": 1.0}, "a": {"k": 3.0}})
    assert v.tolist() == [3.0, 1.0, 2.0]


def test_a_refit_that_starts_without_a_steady_state_is_a_bad_point_not_a_crash():
    """A refit's first point (no best point yet) whose amplitude fixed point does not
    converge: the residuals of a point without a steady state, sized by the defaults'."""

    class NoSteadyState:
        solves, sigma_db = 0, 1.0

        def vector(self, sc):
            if sc["x"] != 0.0:
                raise FloatingPointError("left.z at 1000 rpm: did not converge")
            return np.zeros(5)

    pack = SimpleNamespace(n_prior=0, scenario=lambda x: {"x": float(x[0])}, x0=np.zeros(1),
                           names=_NAMES)
    fun = search.Counted(NoSteadyState(), pack, 100)
    r = fun(np.array([0.7]))
    assert r.shape == (5,) and np.all(r == search.NO_STEADY_STATE_RESIDUAL)


def test_a_fit_without_a_steady_state_at_a_held_out_speed_is_scored_unsupported():
    """Parameters whose amplitude fixed point converges at the training speeds but not at a
    held-out one (found by a rate run: a plan's pair fit) predict nothing there: the held-out
    gap is infinite, the rule finds the candidate unsupported, and nothing crashes."""
    from powertrain.diagnosis.evidence import CandidateEvidence, Evidence, Status
    from powertrain.diagnosis.fit import score
    from powertrain.diagnosis.rule import decide

    def no_steady_state(sc, part):
        raise FloatingPointError("gearbox.y at 1500 rpm: the amplitude fixed point did not "
                                 "converge")

    stub = SimpleNamespace(gaps=no_steady_state, phase_w=None,
                           valid={"test": np.ones((17, 9, 8), bool)})
    o = score(stub, ("amplitude_stiffness",), {}, {}, {}, 300.0, 2000, 1, 40, 0.1)
    assert o.heldout_mse == np.inf and np.all(o.heldout_per_rpm == np.inf)
    assert np.isnan(o.heldout_gaps).all() and np.isnan(o.heldout_channel_rms).all()
    base = CandidateEvidence("", (), 2.0, np.full(17, 2.0), 1000.0, 0.5)
    c = CandidateEvidence(o.label, o.effects, o.heldout_mse, o.heldout_per_rpm, o.bic, 0.2)
    v = decide(Evidence(base, [c], 0.4, 0.63, ""))
    assert v.assessments[o.label].status is Status.NOT_SUPPORTED and v.chosen is None


def test_starts_read_from_the_data_are_kept_inside_their_bounds(monkeypatch):
    from powertrain.diagnosis import starts
    seen = {}

    def fake(problem, pack, effect, fun, lo, hi):
        seen["lo"], seen["hi"] = lo, hi
        return []
    monkeypatch.setattr(starts, "_data_starts", fake)
    monkeypatch.setattr(starts, "_block_start", lambda fun, pack, effect: None)
    pack = SimpleNamespace(lower=np.array([0.0, -1.0]), upper=np.array([10.0, 1.0]),
                           x0=np.array([1.0, 0.0]), log=np.array([False, False]))
    problem = SimpleNamespace(engine=None)
    monkeypatch.setattr(starts.EFFECTS["missing_body_mode"].__class__, "start_grid",
                        lambda self, engine: ())
    starts.start_points(problem, pack, ("missing_body_mode",), None, True, None)
    margin = starts.DATA_START_MARGIN * (pack.upper - pack.lower)
    np.testing.assert_allclose(seen["lo"], pack.lower + margin)
    np.testing.assert_allclose(seen["hi"], pack.upper - margin)


def test_a_cells_check_over_all_folds_reuses_the_held_out_speeds_part(monkeypatch):
    """The retry of a cells check over every speed fold refits only the other folds: the
    held-out speeds' part of the first check is reused (the same numbers, one refit fewer)."""
    from powertrain.diagnosis import checks
    calls = []

    def fake_fold(problem, o, baseline, cells, sigma, kw):
        calls.append(problem)
        return {"n": 2, "e0": 4.0, "ec": 1.0, "e_n": 0.5, "per_0": np.array([4.0, 4.0]),
                "per_c": np.array([1.0, 1.0])}
    monkeypatch.setattr(checks, "_cells_fold", fake_fold)
    monkeypatch.setattr(checks, "_folds", lambda problem, effects: ("orders", []))
    o = SimpleNamespace(effects=("chassis_modes",))
    first = checks.heldout_cells_check("held-out", o, None, 1.0)
    assert calls == ["held-out"] and first["speed_folds"] == 1
    again = checks.heldout_cells_check("held-out", o, None, 1.0, folds=[("f1", None),
                                                                       ("f2", None)],
                                       first=first["parts"][0])
    assert calls == ["held-out", "f1", "f2"] and again["speed_folds"] == 3
    assert again["explained"] == first["explained"]
