"""The blind benchmark's truth simulator against the model's own path, and its effects.

Oracles: the run-up's harmonic solver on :func:`powertrain.assembly.assemble` (a second,
independent path: frequency domain, different assembly code), the engine's own balancer
model for a common balancer gain and lag, the indicated work of a pressure trace for the
weak cylinder, and counts of the case plan.
"""

import numpy as np
import pytest

from benchmarks import truth as tr
from benchmarks.cases import baseline_velocity, case_plan, engines, is_detectable, make_case, truth_velocity
from benchmarks.kinds import IN_LIBRARY, KINDS, PASSIVE_KINDS
from powertrain.effects import with_balancer_error
from powertrain.physics.combustion import indicated_work
from powertrain.workflows.measurement import RPM, gap_stats, measure
from powertrain.workflows.runup import run_runup

#: Newmark (1 deg steps) vs exact harmonic steady state: relative to the largest amplitude.
NEWMARK_REL = 5e-4
#: Same model on both paths: gap statistics [dB].
SAME_DB = 0.02


def test_truth_baseline_equals_the_model_on_the_other_path(engine):
    rpm = RPM[::10]
    h = run_runup(engine, rpm, solver="harmonic").velocity
    v = tr.simulate_truth(tr.TruthSpec(engine, list(engine.mounts)), rpm)
    assert np.abs(v - h).max() / np.abs(h).max() < NEWMARK_REL


def test_traces_engine_reproduces_the_single_zone_engine():
    e = engines()
    assert max(gap_stats(baseline_velocity("sz"), baseline_velocity("traces"))) < SAME_DB
    assert e["traces"].combustion.model == "measured"


@pytest.mark.parametrize("gain, lag", [(1.3, 0.0), (1.0, 0.3)])
def test_balancer_truth_equals_the_engine_balancer(engine, gain, lag):
    h = run_runup(with_balancer_error(engine, gain=gain, lag=lag), RPM,
                  solver="harmonic").velocity
    v = truth_velocity(engine, [("balancer_shafts", {"gains": np.array([gain, gain]),
                                                      "angle_errors": np.array([lag, lag])})])
    assert max(gap_stats(h, v)) < SAME_DB


@pytest.mark.parametrize("kind", ["sz", "traces"])
def test_weak_cylinder_loses_the_stated_imep(kind):
    e = engines()[kind]
    weak = tr.WeakCylinder(e.combustion, 2, 0.09, np.deg2rad(1.5))
    omega = 3000 * 2 * np.pi / 60
    theta, p0, _ = e.combustion.cycle_pressures(e.crank, omega)
    _, p1, _ = weak.cycle_pressures(e.crank, omega)
    _, dV = e.crank.volume(theta)
    w = [indicated_work(p[2], dV, theta[1] - theta[0]) for p in (p0, p1)]
    assert w[1] / w[0] == pytest.approx(0.91, abs=1e-6)
    assert np.array_equal(p0[[0, 1, 3]], p1[[0, 1, 3]])
    assert p1[2].max() < p0[2].max()                 # less and later combustion
    assert p1[2][theta < np.deg2rad(-40)] == pytest.approx(p0[2][theta < np.deg2rad(-40)])


def test_chassis_and_bending_assembly_is_a_proper_model(engine):
    rng = np.random.default_rng(0)
    parts = {}
    for name in ("chassis_base", "powertrain_bending"):
        p = KINDS[name].draw(rng, engine)
        KINDS[name].apply(p, parts)
    s = tr.assemble_truth(engine.body, engine.mounts, parts["chassis"], parts["bending"])
    assert np.allclose(s.M, s.M.T) and np.allclose(s.K, s.K.T)
    assert np.linalg.eigvalsh(s.M).min() > 0
    assert np.linalg.eigvalsh(s.K).min() > 0
    # bending DOF absent, chassis infinitely far: back to the rigid assembly's rigid modes
    s0 = tr.assemble_truth(engine.body, engine.mounts)
    f0, _ = s0.rigid_body_modes()
    f1, _ = engine.rigid_body_modes()
    assert f0 == pytest.approx(f1, rel=1e-9)


def test_case_plan_covers_every_kind_and_is_reproducible():
    plan = case_plan(25, 7)
    assert plan == case_plan(25, 7) and plan != case_plan(25, 8)
    singles = [n[0] for n, _, _ in plan if len(n) == 1]
    assert len(singles) == 14 + 4
    assert set(singles) == set(KINDS) - set(PASSIVE_KINDS)     # passive plan's kinds apart
    assert sum(1 for n, _, _ in plan if not n) == 4
    pairs = [n for n, _, _ in plan if len(n) == 2]
    assert len(pairs) == 3 and all(set(p) <= set(IN_LIBRARY) and p[0] != p[1] for p in pairs)
    assert {e for n, e, _ in plan if n == ["weak_cylinder"]} == {"sz", "traces"}


def test_detectability_rule_both_sides():
    assert is_detectable((1.0, 0.0)) and not is_detectable((0.99, 2.99))
    assert is_detectable((0.2, 3.0))


def test_measurement_scatter_has_the_drawn_sigma(engine):
    v = baseline_velocity("sz")
    rng = np.random.default_rng(1)
    m = measure(v, 0.8, rng, channels=[(mt.name, a) for mt in engine.mounts for a in "xyz"])
    lev = m.curve("left", "z", "order_2")[1]
    true = np.abs(v[:, 2, 3]) / np.sqrt(2)           # far above the floor
    assert np.std(20 * np.log10(lev / true)) == pytest.approx(0.8, rel=0.3)


def test_effect_free_case_is_the_noisy_baseline():
    c = make_case(0, [], "sz", 5)
    assert c.category == "none" and not c.detectable and c.truth_set == []
    assert c.stats == (0.0, 0.0)
