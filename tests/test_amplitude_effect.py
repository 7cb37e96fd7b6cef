"""The diagnosis effect ``amplitude_stiffness`` is a fit of the mount laws: its run-up
application (an amplitude law on every mount, solved by the run-up's harmonic fixed point)
and its fast prediction (the same MountElement.two_port at the fast path's fixed point) are
one physics; the fast path also solves an engine's own nonlinear mounts."""

import dataclasses

import numpy as np
import pytest

from powertrain.effects import A_REF, EFFECTS, predict
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics.mount_laws import BergFriction, PowerLaw
from powertrain.solvers.fast_harmonic import HarmonicModel
from powertrain.workflows.runup import run_runup

#: The issue's bound for the run-up application against the fast prediction [dB].
AGREE_DB = 0.05
#: Entries compared in dB: above this fraction of the largest velocity (smaller ones are
#: cancellations at round-off, not levels).
SIGNIFICANT = 1e-4
RPM = [1200.0, 2500.0, 4800.0]


def _db_gap(a, b):
    a, b = np.abs(a), np.abs(b)
    m = b > SIGNIFICANT * b.max()
    return float(np.max(np.abs(20 * np.log10(a[m] / b[m]))))


@pytest.mark.parametrize("engine_file,gamma", [("default.toml", 1.0),
                                               ("default-modal-body.toml", 1.0),
                                               ("default.toml", 0.4)])
def test_runup_application_and_fast_prediction_agree_within_0_05_db(engine_file, gamma):
    eng = read_engine(DEFAULT_ENGINE_PATH.parent / engine_file)
    p = {"exponent": 0.25, "damping_exponent": gamma}
    fast = predict(HarmonicModel(eng, RPM), {"amplitude_stiffness": p})
    lawed = EFFECTS["amplitude_stiffness"].apply(eng, **p)
    assert all(mod.amplitude_law == PowerLaw(A_REF, 0.25, damping_exponent=gamma)
               for m in lawed.mounts for mod in m.directions.values())
    ref = run_runup(lawed, RPM, solver="harmonic").velocity
    base = run_runup(eng, RPM, solver="harmonic").velocity
    gap = _db_gap(fast.velocity, ref)
    print(f"{engine_file}: fast prediction vs run-up {gap:.2e} dB (bound {AGREE_DB} dB); "
          f"the effect itself {_db_gap(ref, base):.2f} dB; {fast.iterations} iterations")
    assert gap <= AGREE_DB
    assert _db_gap(ref, base) > 1.0                  # the exponent changes the run-up


def test_exponent_zero_leaves_the_engine_and_its_own_laws_alone(engine):
    law = PowerLaw(A_REF, 0.1)
    left = engine.mounts[0]
    own = engine.replace(mounts=[dataclasses.replace(left, directions={
        **left.directions, "z": dataclasses.replace(left.directions["z"], amplitude_law=law)})]
        + list(engine.mounts[1:]))
    assert EFFECTS["amplitude_stiffness"].apply(own, exponent=0.0) is own
    hm = HarmonicModel(own, [2000.0])
    v0 = predict(hm, {}).velocity
    assert np.array_equal(predict(hm, {"amplitude_stiffness": {"exponent": 0.0}}).velocity, v0)


def test_fast_path_solves_the_engines_own_amplitude_law_and_friction(engine):
    """An engine file's laws (here built in Python): the fast path's fixed point equals the
    run-up's harmonic fixed point, with a port law (Berg friction) too."""
    left, right = engine.mounts[0], engine.mounts[1]
    z_l = dataclasses.replace(left.directions["z"], amplitude_law=PowerLaw(A_REF, 0.2))
    z_r = dataclasses.replace(right.directions["z"],
                              port_law=BergFriction(40.0, 5e-5))
    eng = engine.replace(mounts=[dataclasses.replace(left, directions={**left.directions,
                                                                       "z": z_l}),
                                 dataclasses.replace(right, directions={**right.directions,
                                                                        "z": z_r})]
                         + list(engine.mounts[2:]))
    fast = predict(HarmonicModel(eng, RPM), {})
    assert fast.iterations > 1
    ref = run_runup(eng, RPM, solver="harmonic").velocity
    assert _db_gap(fast.velocity, ref) <= AGREE_DB
    assert np.max(np.abs(fast.velocity - ref)) <= 1e-5 * np.max(np.abs(ref))


def test_warm_start_converges_to_the_cold_answer_in_fewer_iterations(engine):
    hm = HarmonicModel(engine, RPM)
    cold = predict(hm, {"amplitude_stiffness": {"exponent": 0.3}})
    near = predict(hm, {"amplitude_stiffness": {"exponent": 0.3 + 1e-4}})
    warm = predict(hm, {"amplitude_stiffness": {"exponent": 0.3 + 1e-4}},
                   warm_amplitudes=cold.amplitudes)
    assert warm.iterations < near.iterations
    assert np.max(np.abs(warm.velocity - near.velocity)) <= 1e-5 * np.max(np.abs(near.velocity))


def test_fast_path_on_the_shipped_nonlinear_engine_equals_the_runup():
    """engines/default-nonlinear.toml (power law, table law, Berg friction from its mount
    files): the diagnosis' cached model and the run-up's harmonic fixed point agree."""
    eng = read_engine(DEFAULT_ENGINE_PATH.parent / "default-nonlinear.toml")
    fast = predict(HarmonicModel(eng, RPM), {})
    ref = run_runup(eng, RPM, solver="harmonic").velocity
    assert fast.iterations > 1
    assert _db_gap(fast.velocity, ref) <= AGREE_DB
