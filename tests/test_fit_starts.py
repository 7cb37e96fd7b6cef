"""Start points of the diagnosis' fits (:mod:`powertrain.diagnosis.starts`), the triad model of
``sensor_error`` and how the diagnosis checks it.

A triad rotated by a few degrees about an oblique axis leaks a strong axis into a weak one;
from zero rotation, a large false gain on the weak channel is a local optimum. The block-wise
multi-start (:func:`powertrain.diagnosis.fit._block_start`) must find the rotation; the
held-out-order folds must keep some orders of every channel (:func:`order_folds`).
"""

from __future__ import annotations

import numpy as np
import pytest

from powertrain.analysis.orders import order_label
from powertrain.diagnosis import fit, search
from powertrain.diagnosis.checks import ORDER_FOLDS, order_folds
from powertrain.diagnosis.core import _Setup
from powertrain.diagnosis.fit import fit_candidate
from powertrain.effects import EFFECTS, predict, sensor_reading
from powertrain.iotools.measured import MeasuredRunup
from powertrain.solvers.fast_harmonic import HarmonicModel


def test_cross_axis_terms_make_a_symmetric_off_diagonal(engine):
    v = np.zeros((1, 9, 1), complex)
    v[0, 0, 0] = 1.0                      # mount 1 x only
    p = {"s1xy": 0.03, "s1xz": -0.02}
    out = EFFECTS["sensor_error"].reading(v, p)
    assert out[0, 1, 0] == pytest.approx(0.03) and out[0, 2, 0] == pytest.approx(-0.02)
    v2 = np.zeros_like(v)
    v2[0, 1, 0] = 1.0                     # mount 1 y only: the same term, transposed
    assert EFFECTS["sensor_error"].reading(v2, p)[0, 0, 0] == pytest.approx(0.03)
    same = sensor_reading(v, np.zeros(9), np.zeros((3, 3)))
    assert np.allclose(same, v)


def _setup(engine, params, seed=7, scatter_db=0.3, effect="sensor_error"):
    """Measured order curves of the cached model with ``effect`` at ``params``, with
    log-normal scatter (synthetic)."""
    rpm = np.arange(1000.0, 6000.1, 100.0)
    hm = HarmonicModel(engine, rpm)
    vel = predict(hm, {effect: params}).velocity
    rng = np.random.default_rng(seed)
    lev = np.abs(vel) / np.sqrt(2) * 10 ** (rng.normal(0, scatter_db, vel.shape) / 20)
    lev = np.sqrt(lev ** 2 + 1e-12)
    curves = {}
    for c, (m, d) in enumerate(hm.channels):
        for o in (0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0):
            curves[(m, d, order_label(o))] = (rpm, lev[:, c, int(round(2 * o)) - 1])
    return _Setup(MeasuredRunup(curves, source="synthetic"), engine, 1e-6, [effect])


def test_block_multistart_finds_an_oblique_triad_rotation(engine):
    """Gearbox triad rotated 7.5 deg about (1, 1, -1)/sqrt(3), one gain -2 dB: the fit lands
    within the scatter of the truth, not on a large false gain."""
    phi = np.deg2rad(7.5) * np.array([1.0, 1.0, -1.0]) / np.sqrt(3)
    truth = {"g8": -2.0, "r3x": phi[0], "r3y": phi[1], "r3z": phi[2]}
    s = _setup(engine, truth)
    o = fit_candidate(s.problem, ("sensor_error",))
    p = o.params["sensor_error"]
    assert not o.budget_hit
    assert max(abs(p[f"g{c}"]) for c in (7, 9)) < 1.0          # no false gain
    assert p["g8"] == pytest.approx(-2.0, abs=0.5)
    assert np.linalg.norm([p["r3x"], p["r3y"], p["r3z"]] - phi) < np.deg2rad(2.5)


def test_order_folds_keep_orders_of_every_channel(engine):
    s = _setup(engine, {"g1": 3.0})
    folds = order_folds(s.problem)
    assert len(folds) == ORDER_FOLDS
    held = np.sum(folds, axis=0)
    assert held.max() == 1                                    # each cell withheld once at most
    informative = held.any(axis=0)
    assert informative.sum() >= 2
    for f in folds:                                           # every channel keeps some orders
        assert (~f[:, informative]).any(axis=1).all()
    # orders at the floor everywhere (the half orders here) are never withheld
    usable = np.isfinite(s.problem.meas["train"]) & (s.problem.meas["train"] > 3e-6)
    assert not (held.astype(bool) & ~usable.any(axis=0)[None, :]).any()


@pytest.mark.slow          # ~7-11 s: keeps the fast lane under 3 min
def test_balancer_one_shaft_late_is_found_with_its_sign(engine):
    """One shaft ~10 deg late (lag 0.085, skew 0.17 rad): the mirror timing (skew < 0) is a
    local optimum that a coarse start grid without intermediate timings settled on."""
    truth = {"gain": 1.0, "lag": 0.085, "asym": -0.05, "skew": 0.17}
    s = _setup(engine, truth, effect="balancer_error")
    p = fit_candidate(s.problem, ("balancer_error",)).params["balancer_error"]
    assert p["skew"] == pytest.approx(0.17, abs=0.03)
    assert p["lag"] == pytest.approx(0.085, abs=0.03)


def test_a_refit_starts_from_its_given_optimum_only():
    """``defaults=False`` (the checks, the band check, the pairs): the given starts alone;
    without starts the defaults still serve, and by default they come first."""
    from powertrain.diagnosis.packing import Packing
    from powertrain.diagnosis.starts import start_points
    pack = Packing.of(("balancer_error",), None)
    given = [pack.x0 + 0.25 * (pack.upper - pack.lower)]
    only = start_points(None, pack, ("balancer_error",), given, False, None, defaults=False)
    assert len(only) == 1 and np.allclose(only[0], given[0])
    both = start_points(None, pack, ("balancer_error",), given, False, None)
    assert len(both) == 2 and np.allclose(both[0], np.clip(pack.x0, pack.lower, pack.upper))
    fallback = start_points(None, pack, ("balancer_error",), None, False, None, defaults=False)
    assert len(fallback) == 1


def test_readings_at_once_equal_each_reading_alone():
    """A Jacobian's sensor columns are read at once (:meth:`Effect.readings`): each reading
    is bit for bit the one of its parameters alone, vectorised or not."""
    rng = np.random.default_rng(3)
    v = rng.normal(size=(12, 9, 16)) + 1j * rng.normal(size=(12, 9, 16))
    params = [{}, {"g2": 1.5}, {"r1z": 0.04, "r3x": -0.1}, {"s2xy": 0.03, "g9": -2.0}]
    for name in ("sensor_error", "balancer_error"):
        eff = EFFECTS[name]
        batch = eff.readings(np.broadcast_to(v, (len(params),) + v.shape), params)
        for b, p in enumerate(params):
            assert np.array_equal(batch[b], eff.reading(v, p if eff.response_only else {}))


@pytest.mark.slow
@pytest.mark.parametrize("effects, budget", [
    (("sensor_error",), fit.EVAL_BUDGET),
    (("mount_stiffness", "sensor_error"), fit.EVAL_BUDGET),
    (("sensor_error",), 700),                  # the budget runs out inside a Jacobian
])
def test_sensor_columns_read_at_once_fit_as_scipys_own_differences(engine, monkeypatch,
                                                                   effects, budget):
    """The trust region's Jacobian with its sensor columns read at once
    (:class:`search.Differences`) is SciPy's ``jac="2-point"``: the same parameters,
    evaluations, budget and best point, bit for bit; and it did read columns at once."""
    s = _setup(engine, {"g2": 2.0, "r1z": 0.05})
    read = []
    real = fit.Problem.read_vectors
    monkeypatch.setattr(fit.Problem, "read_vectors",
                        lambda self, scs: read.append(len(scs)) or real(self, scs))
    at_once = fit_candidate(s.problem, effects, budget=budget)
    assert search.Differences.or_two_point(None, 0, 1) != "2-point" and sum(read) > 10
    monkeypatch.setattr(search.Differences, "or_two_point",
                        classmethod(lambda cls, *args: "2-point"))
    one_by_one = fit_candidate(s.problem, effects, budget=budget)
    for key in ("params", "nfev", "n_eval", "rss_train", "budget_hit", "heldout_mse"):
        assert getattr(at_once, key) == getattr(one_by_one, key), key
    assert np.array_equal(at_once.x, one_by_one.x)
    assert at_once.budget_hit == (budget < fit.EVAL_BUDGET)


def test_a_plans_sensor_columns_read_at_once_are_its_runs_vectors(engine):
    """:meth:`JointProblem.read_vectors` (a plan's fit): each run's cached velocities read,
    joined as :meth:`JointProblem.vector` joins them; None while one run's cache holds
    another physical part (the point is then evaluated alone)."""
    from powertrain.diagnosis.plan import JointProblem, stacked
    runs = [_setup(engine, {"g2": 2.0}, seed=s) for s in (1, 2)]
    joint = JointProblem([r.problem for r in runs], stacked([r.data for r in runs]))
    base = {"mount_stiffness": {"k1": 1.1}, "sensor_error": {"g1": 0.5}}
    cols = [{**base, "sensor_error": {"g1": 0.5, "g4": 1.0}},
            {**base, "sensor_error": {"g1": 0.5, "r2x": 0.02}}]
    joint.vector(base)
    at_once = joint.read_vectors(cols)
    for got, sc in zip(at_once, cols):
        assert np.array_equal(got, joint.vector(sc))
    runs[1].problem.vector({"mount_stiffness": {"k1": 1.3}})
    assert joint.read_vectors(cols) is None


def test_an_evaluation_counts_one_whether_solved_or_read_from_the_cache(engine):
    """The budget's count does not see the problem's cache: a point whose amplitude fixed
    point is solved (several iterations) and the same point read from the cache each count
    one evaluation, with the same residuals."""
    from powertrain.diagnosis.packing import Packing
    problem = _setup(engine, {"exponent": 0.2}, effect="amplitude_stiffness").problem
    pack = Packing.of(("amplitude_stiffness",), problem.engine)
    x = pack.x0.copy()
    x[0] = 0.25                                     # the exponent: a nonlinear point
    problem.reset_warm()
    solved = search.Counted(problem, pack, 100)
    r_solved = solved(x)
    cached = search.Counted(problem, pack, 100)
    r_cached = cached(x)
    assert solved.n == cached.n == 1
    assert np.array_equal(r_solved, r_cached)


def _same_fit(a, b):
    for key in ("params", "sigma", "nfev", "n_eval", "rss_train", "budget_hit",
                "heldout_mse"):
        assert getattr(a, key) == getattr(b, key), key
    assert np.array_equal(a.x, b.x)


@pytest.mark.slow
@pytest.mark.parametrize("budget", [fit.EVAL_BUDGET, 40])
def test_a_fit_is_the_same_in_any_order_of_calls(engine, budget):
    """A fit stops on its own criteria: the same candidates fitted on the same data give
    the same outcomes, bit for bit, whether fitted first on a cold problem (its cached
    model empty) or after other fits filled its caches, in either order; also when the
    budget stops them (every evaluation counts one, solved or read from the cache, however
    many iterations its amplitude fixed point took)."""
    params = {"exponent": 0.2, "damping_exponent": 1.0}
    first, second = ("amplitude_stiffness",), ("mount_stiffness", "sensor_error")
    cold = _setup(engine, params, effect="amplitude_stiffness").problem
    a_then_b = [fit_candidate(cold, first, budget=budget),
                fit_candidate(cold, second, budget=budget)]
    warm = _setup(engine, params, effect="amplitude_stiffness").problem
    b_then_a = [fit_candidate(warm, second, budget=budget),
                fit_candidate(warm, first, budget=budget)]
    again = fit_candidate(cold, first, budget=budget)
    _same_fit(a_then_b[0], b_then_a[1])
    _same_fit(a_then_b[1], b_then_a[0])
    _same_fit(a_then_b[0], again)
    assert a_then_b[0].budget_hit == (budget < fit.EVAL_BUDGET)
    assert a_then_b[0].n_eval <= budget
