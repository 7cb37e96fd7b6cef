"""What-if on a mount direction's laws: --scale/--set of [amplitude], [friction] and
[static] keys, in variants files too, and a retune target at an amplitude."""

import dataclasses

import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.errors import InputError
from powertrain.physics.mount_laws import BergFriction, PowerLaw, StaticCurve
from powertrain.workflows.operations import LAW_DEFAULTS, apply_operations
from powertrain.workflows.retune import retune
from powertrain.workflows.runup import run_runup
from powertrain.workflows.variants import (
    parse_scale,
    parse_set,
    parse_target,
    read_variants,
)
from powertrain.workflows.whatif import run_whatif


def _with(engine, mount, direction, **laws):
    m = engine.mount(mount)
    model = dataclasses.replace(m.directions[direction], **laws)
    return engine.replace(mounts=[dataclasses.replace(x, directions={**x.directions,
                                                                     direction: model})
                                  if x.name == mount else x for x in engine.mounts])


def _law(engine, mount, direction, field):
    return getattr(engine.mount(mount).directions[direction], field)


@pytest.fixture(scope="module")
def lawed(engine):
    curve = StaticCurve((-4e-3, 0.0, 4e-3), (-1200.0, 0.0, 1500.0), 1.5e-3)
    return _with(engine, "left", "z", amplitude_law=PowerLaw(1e-4, 0.15, (0.2, 5.0)),
                 port_law=BergFriction(40.0, 5e-5), static_curve=curve)


def test_scale_multiplies_each_law_key(lawed):
    e = apply_operations(lawed, [parse_scale("left.z.amplitude.exponent=2"),
                                 parse_scale("left.z.amplitude.reference=0.5"),
                                 parse_scale("left.z.friction.max_force=0.5"),
                                 parse_scale("left.z.friction.half_displacement=3"),
                                 parse_scale("left.z.static.force=1.2")])
    assert _law(e, "left", "z", "amplitude_law") == PowerLaw(5e-5, 0.3, (0.2, 5.0))
    fr = _law(e, "left", "z", "port_law")
    assert (fr.max_force, fr.half_displacement) == pytest.approx((20.0, 1.5e-4))
    st = _law(e, "left", "z", "static_curve")
    assert st.force == pytest.approx((-1440.0, 0.0, 1800.0))
    assert st.reference_deflection == 1.5e-3
    assert _law(lawed, "left", "z", "port_law").max_force == 40.0      # nothing mutated


def test_set_takes_the_mount_files_units_and_creates_amplitude_and_friction(engine, lawed):
    e = apply_operations(lawed, [parse_set("left.z.amplitude.reference=0.2"),
                                 parse_set("left.z.amplitude.limits=0.5,3"),
                                 parse_set("left.z.friction.half_displacement=20um"),
                                 parse_set("left.z.static.reference_deflection=-1")])
    assert _law(e, "left", "z", "amplitude_law") == PowerLaw(2e-4, 0.15, (0.5, 3.0))
    assert _law(e, "left", "z", "port_law").half_displacement == pytest.approx(2e-5)
    assert _law(e, "left", "z", "static_curve").reference_deflection == pytest.approx(-1e-3)
    new = apply_operations(engine, [parse_set("*.*.friction.max_force=20"),
                                    parse_set("right.y.amplitude.exponent=0.1")])
    assert all(_law(new, m.name, d, "port_law") == BergFriction(20.0, 5e-5)
               for m in new.mounts for d in "xyz")
    assert _law(new, "right", "y", "amplitude_law") == \
        dataclasses.replace(LAW_DEFAULTS["amplitude"], exponent=0.1)
    assert _law(new, "right", "x", "amplitude_law") is None


@pytest.mark.parametrize("spec, message", [
    ("left.z.amplitude.exponent=2", "has no [amplitude] section (--set creates one)"),
    ("*.*.friction.max_force=2", "has no [friction] section"),
    ("left.z.static.force=2", "has no [static] section"),
])
def test_scale_needs_the_section(engine, spec, message):
    with pytest.raises(InputError, match=r".*" + message.replace("[", r"\[").replace(
            "]", r"\]").replace("(", r"\(").replace(")", r"\)")):
        parse_scale(spec).apply(engine)


def test_wildcard_skips_directions_without_the_section(lawed):
    e = parse_scale("*.*.friction.max_force=2").apply(lawed)
    assert _law(e, "left", "z", "port_law").max_force == 80.0
    assert _law(e, "left", "x", "port_law") is None


@pytest.mark.parametrize("option, spec, message", [
    ("--set", "left.z.static.reference_deflection=1", "no [static] section"),
    ("--set", "left.z.amplitude.limits=2,4", "0 < LO <= 1 <= HI"),
    ("--set", "left.z.friction.max_force=-1", "must be >= 0"),
    ("--set", "left.z.friction.max_force=2mm", "not a unit of force"),
    ("--set", "left.z.amplitude.exponent=0.2N", "has no unit"),
    ("--scale", "left.z.amplitude.limits=2", "unknown key 'amplitude.limits'"),
    ("--scale", "left.z.amplitude.exponent=2", "no [amplitude] section"),
    ("--target", "left.z:+20%:100-300Hz:0.3mm", "no amplitude law or friction"),
])
def test_bad_law_specs_give_one_line_and_exit_1(tmp_path, option, spec, message):
    out = tmp_path / "w.json"
    r = CliRunner().invoke(main, ["whatif", "--from", "2000", "--to", "2000",
                                  "--workers", "1", "--quiet", option, spec,
                                  "--json", str(out)])
    assert r.exit_code == 1, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and message in lines[0] and option in lines[0], r.output
    assert not out.exists()


def test_variants_file_with_law_keys(tmp_path, engine):
    path = tmp_path / "v.toml"
    path.write_text('[[variant]]\nname = "friction"\nset = ["left.*.friction.max_force=30"]\n'
                    '[[variant]]\nname = "softer"\nset = ["*.z.amplitude.exponent=0.2"]\n'
                    'scale = ["left.z.stiffness=0.9"]\n')
    v = read_variants(path)
    e = apply_operations(engine, v[1].operations)
    assert _law(e, "gearbox", "z", "amplitude_law").exponent == 0.2
    bad = tmp_path / "bad.toml"
    bad.write_text('[[variant]]\nname = "x"\nscale = ["left.z.friction.max_force=3"]\n')
    with pytest.raises(InputError, match="variant\\[1\\].scale.*no \\[friction\\]"):
        apply_operations(engine, read_variants(bad)[0].operations)


def test_whatif_runs_the_laws_through_the_harmonic_fixed_point(engine):
    """whatif's default solver (harmonic) solves the variant's laws: its variant run is the
    run-up of the changed engine."""
    rpm = np.array([1500.0, 3000.0])
    from powertrain.workflows.operations import Variant
    ops = (parse_set("left.z.amplitude.exponent=0.3"), parse_set("right.z.friction.max_force=30"))
    res = run_whatif(engine, [Variant("laws", ops)], rpm, workers=1)
    ref = run_runup(apply_operations(engine, ops), rpm, solver="harmonic")
    base = run_runup(engine, rpm, solver="harmonic")
    v = res.variants[0].result.velocity
    assert np.max(np.abs(v - ref.velocity)) <= 1e-12 * np.max(np.abs(ref.velocity))
    assert np.max(np.abs(v - base.velocity)) > 1e-3 * np.max(np.abs(base.velocity))


@pytest.mark.slow
def test_target_at_an_amplitude_meets_the_request_there(lawed):
    t = parse_target("left.z:+20%:100-300Hz:0.03mm")
    assert t.amplitude == pytest.approx(3e-5)
    model = lawed.mount("left").directions["z"]
    tf = retune(model, t, seed=1, starts=4, hops=0)
    assert (tf.model.amplitude_law, tf.model.port_law) == (model.amplitude_law,
                                                           model.port_law)
    s = 2j * np.pi * tf.frequency_hz
    k_new = -tf.model.element().two_port(s, t.amplitude)[1]
    k_old = -model.element().two_port(s, t.amplitude)[1]
    assert np.max(np.abs(k_new - tf.kcp_fitted)) <= 1e-9 * np.max(np.abs(k_new))
    assert np.max(np.abs(k_old - tf.kcp_baseline)) <= 1e-9 * np.max(np.abs(k_old))
    change = np.mean(np.abs(k_new[tf.band]) / np.abs(k_old[tf.band])) - 1
    print(f"target at 0.03 mm: mean band change {100 * change:+.1f} % (asked +20 %), "
          f"max band error {100 * tf.max_band_error:.1f} %")
    assert abs(change - 0.2) < 0.05
    assert tf.to_dict()["amplitude_mm"] == pytest.approx(0.03)


def test_scale_and_set_on_the_shipped_nonlinear_engine():
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    eng = read_engine(DEFAULT_ENGINE_PATH.parent / "default-nonlinear.toml")
    fr0 = _law(eng, "left", "z", "port_law")
    e = apply_operations(eng, [parse_scale("*.z.friction.max_force=0.5"),
                               parse_scale("left.y.amplitude.exponent=2"),
                               parse_set("right.z.friction.half_displacement=0.1")])
    assert _law(e, "left", "z", "port_law").max_force == pytest.approx(0.5 * fr0.max_force)
    assert _law(e, "right", "z", "port_law").half_displacement == pytest.approx(1e-4)
    assert _law(e, "left", "y", "amplitude_law").exponent == pytest.approx(
        2 * _law(eng, "left", "y", "amplitude_law").exponent)
    assert _law(e, "gearbox", "z", "port_law") is None          # the wildcard skipped it
    with pytest.raises(InputError, match="TableLaw, which has no exponent"):
        parse_scale("gearbox.z.amplitude.exponent=2").apply(eng)


def test_damping_exponent_of_an_amplitude_law_is_set_and_scaled(lawed):
    """``amplitude.damping_exponent`` (the mount file's optional key): set, then scaled."""
    e = apply_operations(lawed, [parse_set("left.z.amplitude.damping_exponent=0.5"),
                                 parse_scale("left.z.amplitude.damping_exponent=0.4")])
    law = _law(e, "left", "z", "amplitude_law")
    assert law == PowerLaw(1e-4, 0.15, (0.2, 5.0), damping_exponent=pytest.approx(0.2))
    ks, ds = law.scales(2e-4)
    assert ds == pytest.approx(ks ** 0.2)
    assert _law(lawed, "left", "z", "amplitude_law").damping_exponent == 1.0
