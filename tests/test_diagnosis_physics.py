"""Physics of the diagnosis' answers: its own run-up is 'no effect' on any speed grid; the
'where' step names orders for an excitation gap and a band for a structural one; cylinder
imbalance acts on measured pressure traces; equivalent explanations are listed; the balancer
has per-shaft timing."""

from __future__ import annotations

import numpy as np
import pytest

from powertrain.analysis.orders import order_label
from powertrain.diagnosis import diagnose
from powertrain.diagnosis.data import gap_data
from powertrain.diagnosis.where import decompose_gap
from powertrain.effects import EFFECTS, predict
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.measured import read_measured
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows.runup import run_runup

#: Same linear model, two code paths: round-off only.
EXACT = 1e-9


def _own_csv(engine, step, path):
    """The model's own harmonic run-up written as a long-format CSV (6 significant digits)."""
    lo, hi = engine.speed_range_rpm()
    rpm = np.arange(np.ceil(lo / step) * step, hi + 1e-9, step)
    res = run_runup(engine, rpm, solver="harmonic")
    lines = ["mount,direction,quantity,rpm,velocity_rms_mm_per_s"]
    for c, (m, d) in enumerate(res.channels):
        for h, o in enumerate(res.orders):
            lev = np.abs(res.velocity[:, c, h]) / np.sqrt(2) * 1e3
            lines += [f"{m},{d},{order_label(o)},{r:g},{v:.6g}" for r, v in zip(res.rpm, lev)]
    path.write_text("\n".join(lines) + "\n")
    return read_measured(str(path), mounts=engine.mount_names)


@pytest.mark.slow
@pytest.mark.parametrize("step", [50.0, 100.0])
def test_own_runup_is_no_effect_on_any_grid(engine, step, tmp_path):
    meas = _own_csv(engine, step, tmp_path / "own.csv")
    res = diagnose(meas, engine, noise_floor=1e-6, progress=False)
    assert res.verdict == "no effect", res.verdict_text
    assert res.chosen is None


def _gap_parts(engine, scenario):
    """Decomposition of the gap between the baseline and the model with ``scenario``
    applied, used as the 'measurement' (noise-free, 100-rpm grid)."""
    from powertrain.iotools.measured import MeasuredRunup
    rpm = np.arange(1000.0, 6000.1, 100.0)
    hm = HarmonicModel(engine, rpm)
    v = predict(hm, scenario).velocity
    orders = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
    curves = {(m, d, order_label(o)): (rpm, np.abs(v[:, 3 * mi + ai, int(2 * o) - 1]) / 2 ** .5)
              for mi, m in enumerate(engine.mount_names) for ai, d in enumerate("xyz")
              for o in orders}
    data = gap_data(MeasuredRunup(curves), engine, 1e-9)
    base = predict(hm, {}).velocity
    from powertrain.diagnosis.data import model_levels, residuals_db
    gap = residuals_db(model_levels(base, data), data.level, data.floor)
    mask = np.isfinite(gap)
    return decompose_gap(np.where(mask, gap, np.nan), data, mask)["attribution"]


@pytest.mark.slow
def test_where_attributes_half_orders_to_excitation_and_names_them(engine):
    att = _gap_parts(engine, {"cylinder_imbalance": {"e2": -0.1}})
    assert att["kind"] == "excitation", att
    # a weak cylinder of an inline-4 feeds the non-firing orders, not the firing ones
    assert {0.5, 1.0, 1.5} <= set(att["orders"]) and not set(att["orders"]) & {2.0, 4.0, 6.0}


def _synthetic_gap(fn, step=100.0):
    """GapData on a speed grid (9 channels, orders 0.5..6) and a gap [dB] fn(f, order, rpm, c)."""
    from powertrain.diagnosis.data import GapData
    rpm = np.arange(1000.0, 6000.1, step)
    orders = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0])
    harm = (2 * orders).astype(int) - 1
    data = GapData(rpm, [(m, d) for m in ("a", "b", "c") for d in "xyz"],
                   [order_label(o) for o in orders], harm,
                   np.ones((rpm.size, 9, orders.size)), 1e-9)
    r, c, k = np.meshgrid(np.arange(rpm.size), np.arange(9), np.arange(orders.size),
                          indexing="ij")
    gap = fn(orders[k] * rpm[r] / 60.0, orders[k], rpm[r], c)
    return decompose_gap(gap, data, np.ones(gap.shape, bool))["attribution"]


@pytest.mark.parametrize("step", [pytest.param(50.0, marks=pytest.mark.slow), 100.0])
def test_where_attributes_a_frequency_fixed_gap_to_structure_with_its_band(step):
    """A resonance at 150 Hz seen by every order (a bracket, a body mode): structure, and
    the band named contains 150 Hz; same on a 50- and a 100-rpm grid."""
    def fn(f, o, n, c):
        return 6.0 / (1 + ((f - 150.0) / 15.0) ** 2) * (1 + 0.1 * c)
    att = _synthetic_gap(fn, step)
    assert att["kind"] == "structure", att
    assert att["band_hz"][0] <= 150.0 <= att["band_hz"][1]


@pytest.mark.parametrize("step", [pytest.param(50.0, marks=pytest.mark.slow), 100.0])
def test_where_attributes_an_order_bound_gap_to_excitation_with_its_orders(step):
    def fn(f, o, n, c):
        return np.where(np.isin(o, (0.5, 1.5)), 8.0 + 0.001 * n, 0.0)
    att = _synthetic_gap(fn, step)
    assert att["kind"] == "excitation" and att["orders"] == [0.5, 1.5], att


def test_cylinder_imbalance_applies_to_measured_pressure_traces(engine):
    from benchmarks.cases import traces_engine
    tr = traces_engine(engine, step_rpm=500.0)
    assert EFFECTS["cylinder_imbalance"].applicable(tr)
    rpm = [2000.0]
    weak = EFFECTS["cylinder_imbalance"].apply(tr, e2=-0.1)
    _, p0, i0 = tr.combustion.cycle_pressures(tr.crank, 2000 * np.pi / 30)
    _, p1, i1 = weak.combustion.cycle_pressures(tr.crank, 2000 * np.pi / 30)
    imep = i1["imep_target"] / i0["imep_target"] - 1.0
    assert -0.14 < imep[1] < -0.06 and np.all(np.abs(imep[[0, 2, 3]]) < 1e-9)
    assert np.max(p1[1]) < np.max(p0[1])
    # fast path (linearised) against the engine-level change, to first order
    hm = HarmonicModel(tr, rpm)
    v = predict(hm, {"cylinder_imbalance": {"e2": -0.1}}).velocity
    ref = run_runup(weak, rpm, solver="harmonic").velocity
    half = [0, 1, 2]                                      # orders 0.5, 1, 1.5
    assert np.max(np.abs(v[..., half] - ref[..., half])) <= 0.05 * np.max(np.abs(ref[..., half]))


def test_one_shaft_late_is_timing_not_gain(engine):
    """skew: the first shaft 20 deg late = lag 10 deg, skew 20 deg (per-shaft timing), the
    engine-level change and the fast path agree exactly."""
    p = {"lag": np.deg2rad(10.0), "skew": np.deg2rad(20.0)}
    eng = EFFECTS["balancer_error"].apply(engine, **p)
    d = [a.phase - b.phase for a, b in zip(eng.balancer.shafts, engine.balancer.shafts)]
    s = [sh.sense for sh in engine.balancer.shafts]
    assert np.allclose(-np.array(d) * np.array(s), [np.deg2rad(20.0), 0.0])
    hm = HarmonicModel(engine, [2500.0])
    v = predict(hm, {"balancer_error": p}).velocity
    ref = run_runup(eng, [2500.0], solver="harmonic").velocity
    assert np.max(np.abs(v - ref)) <= EXACT * np.max(np.abs(ref))


def test_weak_cylinder_alternatives_are_offered(engine):
    alts = EFFECTS["cylinder_imbalance"].alternatives({"e1": 0.0, "e2": -0.1, "e3": 0.0,
                                                       "e4": 0.0}, engine)
    texts = " ".join(t for t, _ in alts)
    assert "others strong" in texts
    strong = next(p for t, p in alts if "others strong" in t)
    assert strong["e2"] == pytest.approx(0.0) and strong["e1"] == pytest.approx(1 / 0.9 - 1)


def test_mount_parameters_follow_the_engine(engine):
    n = len(engine.mounts)
    names = [p.name for p in EFFECTS["mount_stiffness"].parameters(engine)]
    assert names == [f"k{i + 1}" for i in range(n)] + ["damping_exponent"]
    g = [p.name for p in EFFECTS["sensor_error"].parameters(engine) if p.name.startswith("g")]
    assert len(g) == 3 * n


def test_four_mount_engine_gets_its_own_parameters_and_folds():
    """The torque-rod engine (4 mounts): a stiffness factor per mount, 12 channel gains,
    4 triad rotations, channel folds holding out one channel of every triad; the fast path
    of a factor on the fourth mount equals the engine-level change."""
    from powertrain.data import shipped_path
    from powertrain.diagnosis.checks import channel_folds
    eng = read_engine(shipped_path("engines", "default-torque-rod.toml"))
    n = len(eng.mounts)
    assert n == 4
    assert [p.name for p in EFFECTS["mount_stiffness"].parameters(eng)] == [
        "k1", "k2", "k3", "k4", "damping_exponent"]
    ps = EFFECTS["sensor_error"].parameters(eng)
    assert sum(p.name.startswith("g") for p in ps) == 12 and sum(
        p.name.startswith("r") for p in ps) == 12
    folds = channel_folds(n)
    assert sorted(c for f in folds for c in f) == list(range(12))
    assert all(len({c // 3 for c in f}) == n for f in folds)
    hm = HarmonicModel(eng, [2500.0])
    for p in ({"k4": 1.7}, {"k4": 1.7, "k1": 0.6, "damping_exponent": 0.6}):
        v = predict(hm, {"mount_stiffness": p}).velocity
        ref = run_runup(EFFECTS["mount_stiffness"].apply(eng, **p), [2500.0],
                        solver="harmonic").velocity
        assert np.max(np.abs(v - ref)) <= EXACT * np.max(np.abs(ref))


#: Linear effects: the fast path and the run-up of the changed engine are the same model.
#: Cylinder imbalance enters the fast path to first order in the IMEP deviation.
FIRST_ORDER = {"cylinder_imbalance": 2e-3,
               # both sides converge their amplitude fixed point to 1e-6 (relative)
               "amplitude_stiffness": 1e-6}


def _moved_parameters(effect, engine):
    """Every parameter a tenth of the way from its default towards its upper bound (the
    lower one for a default at the upper bound; geometric for log parameters)."""
    out = {}
    for p in effect.parameters(engine):
        bound = p.lower if p.default >= p.upper else p.upper
        if p.log and p.default > 0:
            out[p.name] = p.default * (bound / p.default) ** 0.1
        else:
            out[p.name] = p.default + 0.1 * (bound - p.default)
    return out


@pytest.mark.parametrize("name", [n for n, e in EFFECTS.items() if e.engine_change])
@pytest.mark.parametrize("engine_file", ["default.toml", "default-modal-body.toml"])
def test_runup_application_and_diagnosis_prediction_agree(name, engine_file):
    """One physics per effect: ``apply()`` (what the run-up and `whatif --effect` run) and
    the fast-path hooks behind ``predict()`` give the same velocities, for every effect that
    changes the engine model."""
    eng = read_engine(DEFAULT_ENGINE_PATH.parent / engine_file)
    effect = EFFECTS[name]
    if not effect.applicable(eng):
        pytest.skip(f"{name} does not act on {engine_file}")
    params = _moved_parameters(effect, eng)
    rpm = [1500.0, 4000.0]
    fast = predict(HarmonicModel(eng, rpm), {name: params}).velocity
    base = predict(HarmonicModel(eng, rpm), {}).velocity
    ref = run_runup(effect.apply(eng, **params), rpm, solver="harmonic").velocity
    assert np.max(np.abs(ref - base)) > 1e-4 * np.max(np.abs(ref)), \
        "the moved parameters change nothing"
    assert np.max(np.abs(fast - ref)) <= FIRST_ORDER.get(name, EXACT) * np.max(np.abs(ref))


def test_gap_decomposition_solve_is_the_minimum_norm_least_squares():
    """``where._solve`` (sparse normal equations on the columns with entries) against
    ``numpy.linalg.lstsq`` on a decomposition-like problem with empty columns (a channel
    without data, knots without data or penalty)."""
    from powertrain.diagnosis.where import _solve
    rng = np.random.default_rng(5)
    n, n_col = 300, 40
    X = np.zeros((n, n_col))
    rows = np.arange(n)
    X[rows, rng.integers(0, 4, n)] = 1.0               # constants of channels 0-3 (4 empty)
    j = rng.integers(5, 30, n)
    t = rng.uniform(size=n)
    X[rows, j], X[rows, j + 1] = 1 - t, t              # hat basis on knots 5-30
    P = np.zeros((n_col - 5 - 6, n_col))                # ridge on 5..33; 34..39 left empty
    P[np.arange(P.shape[0]), 5 + np.arange(P.shape[0])] = 0.3
    y = rng.normal(size=n)
    for cols in (np.arange(n_col), np.arange(5, n_col), np.arange(5)):
        A = np.vstack([X[:, cols], P[:, cols]])
        ref = np.linalg.lstsq(A, np.concatenate([y, np.zeros(P.shape[0])]), rcond=None)[0]
        got = _solve(X, P, y, cols)
        np.testing.assert_allclose(got[cols], ref, rtol=0, atol=1e-10 * np.abs(ref).max())
        assert not np.any(np.delete(got, cols))


def test_mount_stiffness_scales_springs_by_k_and_dampers_by_k_to_the_exponent(engine):
    """Springs × k, dampers × k^γ, masses kept; γ = 1 (the default) scales both alike."""
    from powertrain.effects import with_mount_stiffness
    for gamma in (1.0, 0.6):
        e = with_mount_stiffness(engine, k1=2.0, damping_exponent=gamma)
        for ax, mod in e.mounts[0].directions.items():
            old = engine.mounts[0].directions[ax].params
            for name, v in mod.params.items():
                f = {"c": 2.0, "d": 2.0 ** gamma}.get(name[0], 1.0)
                assert v == pytest.approx(f * old[name], rel=1e-12), (ax, name)
        assert e.mounts[1].directions["z"].params == engine.mounts[1].directions["z"].params


def test_scored_levels_equal_the_gap_rule_at_their_points():
    """The fits' level gaps (``data.ScoredLevels``: the measured side formed once) equal
    :func:`residuals_db` of :func:`order_levels` at the same points, censored or not."""
    from powertrain.analysis.noise_floor import censoring_level
    from powertrain.diagnosis.data import ScoredLevels, order_levels, residuals_db
    rng = np.random.default_rng(3)
    floor = 2e-6
    vel = (rng.lognormal(-11, 2, 500) * np.exp(2j * np.pi * rng.random(500)))
    meas = rng.lognormal(-11, 2, 500)
    meas[:20] = censoring_level(floor) * 0.5                 # at the floor: censored
    want = residuals_db(order_levels(vel, floor), meas, floor)
    np.testing.assert_allclose(ScoredLevels(meas, floor)(vel), want, rtol=0, atol=1e-12)
    assert np.any(want[:20] == 0.0) and np.all(want[:20] >= 0.0)
