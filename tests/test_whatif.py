"""``powertrain whatif``: variant operations, the sweep engine, retune targets, the command.

Oracles: the identity variant (exactly no change); the same task run serially and in a
process pool (identical numbers); dynamic scaling of a network by s multiplies K_CP(omega)
by s exactly (the network's dynamic stiffness matrix is homogeneous of degree one in c, d, m)
and, the body mass unchanged, the rigid-body modes by sqrt(s); unit conversion of --set
(150 N/mm = 150000 N/m); small-rotation kinematics of a moved mount point; the requested
curve of a retune target.
"""

from __future__ import annotations

import json
import math
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.assembly import assemble
from powertrain.cli import main
from powertrain.errors import InputError
from powertrain.parallel import SerialExecutor
from powertrain.workflows.operations import Variant, apply_operations
from powertrain.workflows.retune import band_weight, retune
from powertrain.workflows.sweeps import SweepTask, run_sweep
from powertrain.workflows.variants import (
    parse_move,
    parse_rotate,
    parse_scale,
    parse_set,
    parse_target,
    read_variants,
)
from powertrain.workflows.whatif import run_whatif

RPM = np.array([1500.0, 3000.0, 4500.0])
#: Identity variant: no change beyond round-off [dB].
IDENTITY_DB = 0.01
#: Closed-form checks (homogeneity, unit factors, kinematics): round-off only.
EXACT = 1e-9
#: Retune: the fitted |K_CP| within 10 % of the requested curve at every frequency of the
#: band, and the mean change within 5 percentage points of the requested +20 %. The
#: requested curve (baseline x band gain with its Bode phase) is met to 6 % / +16.6 % on
#: left.z, the gap being the price of keeping the input-point stiffness (what the body feels)
#: within 2 % of its target (see powertrain.workflows.retune).
RETUNE_BAND_REL = 0.10
RETUNE_MEAN_PTS = 0.05


def body_system(eng):
    b = eng.body
    return assemble(b.mass, b.cg, b.inertia, eng.mounts)


def engine_axes_static_stiffness(mount):
    """R diag(k_x, k_y, k_z) R^T [N/m]: the mount's static stiffness in engine axes."""
    k = np.diag([mount.directions[d].static_stiffness() for d in "xyz"])
    return mount.rotation @ k @ mount.rotation.T


def test_identity_variant_changes_nothing(engine):
    ops = (parse_scale("*.*.stiffness=1"), parse_scale("*.*.damping=1"),
           parse_move("*=0,0,0"), parse_rotate("left=0,0,0"))
    res = run_whatif(engine, [Variant("identity", ops)], RPM, workers=1)
    for row in res.channel_changes("identity"):
        assert abs(row["mean_delta_db"]) < IDENTITY_DB
        assert row["max_abs_delta_db"] < IDENTITY_DB


def test_variant_same_alone_and_in_process_pool_sweep(engine):
    ops = (parse_scale("left.z.stiffness=1.2"),)
    other = (parse_scale("gearbox.*.damping=0.8"),)
    tasks = [SweepTask("a", apply_operations(engine, ops), RPM, "harmonic"),
             SweepTask("b", apply_operations(engine, other), RPM, "harmonic")]
    alone = run_sweep(tasks[:1], SerialExecutor())[0]
    with ProcessPoolExecutor(max_workers=2) as pool:
        swept = run_sweep(tasks, pool)
    assert np.array_equal(alone.velocity, swept[0].velocity)
    assert swept[1].meta["variant"] == "b"
    for scheduler in ("processes", "serial", None):     # through the one executor factory
        again = run_sweep(tasks, scheduler, workers=2)
        assert np.array_equal(again[0].velocity, alone.velocity)
        assert [r.meta["variant"] for r in again] == ["a", "b"]


def test_dynamic_scaling_scales_kcp_exactly_and_modes_by_sqrt(engine):
    s = 1.7
    scaled = apply_operations(engine, (parse_scale("*.*.dynamic=1.7"),))
    f = np.array([0.0, 5.0, 33.0, 150.0, 800.0])
    for m0, m1 in zip(engine.mounts, scaled.mounts):
        for d in "xyz":
            k0 = m0.directions[d].cross_point_stiffness(f)
            k1 = m1.directions[d].cross_point_stiffness(f)
            assert np.max(np.abs(k1 - s * k0) / np.abs(k0)) < EXACT
    modes0, _ = body_system(engine).rigid_body_modes()
    modes1, _ = body_system(scaled).rigid_body_modes()
    assert np.max(np.abs(modes1 / modes0 - math.sqrt(s))) < EXACT
    # springs only: the static stiffness (and so the modes) scale the same way
    stiff = apply_operations(engine, (parse_scale("*.*.stiffness=1.7"),))
    modes2, _ = body_system(stiff).rigid_body_modes()
    assert np.max(np.abs(modes2 / modes0 - math.sqrt(s))) < EXACT


def test_set_converts_datasheet_units(engine):
    op = parse_set("right.y.c2=150")
    assert op.value == pytest.approx(150000.0, rel=EXACT)
    new = apply_operations(engine, (op,))
    assert new.mount("right").directions["y"].params["c2"] == pytest.approx(150000.0)
    assert engine.mount("right").directions["y"].params["c2"] != 150000.0   # not mutated
    assert parse_set("left.z.d1=2").value == pytest.approx(2000.0)           # N*s/mm
    assert parse_set("left.z.m1=5").value == pytest.approx(5.0)              # kg
    assert parse_set("left.z.c1=1.5e5 N/m").value == pytest.approx(1.5e5)


def test_move_and_rotate_change_the_assembled_geometry(engine):
    moved = apply_operations(engine, (parse_move("gearbox=0,20,10"),))
    p0 = engine.mount("gearbox").position
    assert np.allclose(moved.mount("gearbox").position - p0, [0, 0.020, 0.010], atol=EXACT)
    # pure yaw rate theta_z moves a point along X by -theta_z * (y - y_cg): 20 mm more
    s0, s1 = body_system(engine), body_system(moved)
    row = s0.channels.index(("gearbox", "x"))
    assert s1.channel_matrix[row, 5] - s0.channel_matrix[row, 5] == pytest.approx(-0.020,
                                                                                  abs=EXACT)
    # 90 deg about engine Z: the mount's local x axis now points along engine Y, so its
    # x and y static stiffnesses swap in engine axes
    rot = apply_operations(engine, (parse_rotate("left=0,0,90"),))
    k0, k1 = (engine_axes_static_stiffness(e.mount("left")) for e in (engine, rot))
    assert k1[1, 1] == pytest.approx(k0[0, 0], rel=EXACT)
    assert k1[0, 0] == pytest.approx(k0[1, 1], rel=EXACT)
    assert np.allclose(rot.mount("left").rotation[:, 0], [0, 1, 0], atol=EXACT)


def test_band_weight_blends_over_half_an_octave():
    w = band_weight([100.0, 300.0, 100 / 2 ** 0.25, 100 / 2 ** 0.5, 600.0, 0.0], 100, 300)
    assert np.allclose(w, [1, 1, 0.5, 0, 0, 0], atol=EXACT)


def test_target_retune_fits_requested_curve_in_band(engine):
    target = parse_target("left.z:+20%:100-300Hz")
    tf = retune(engine.mount("left").directions["z"], target)
    band = tf.band
    err = np.abs(np.abs(tf.kcp_fitted[band]) / np.abs(tf.kcp_target[band]) - 1)
    assert np.max(err) < RETUNE_BAND_REL
    assert abs(tf.mean_band_change - 0.20) < RETUNE_MEAN_PTS
    assert tf.kip_rel_rms < 0.05
    # beyond the blend (half an octave) the requested magnitude is the baseline's; only
    # its phase carries the Bode tail of the change
    out = (tf.frequency_hz < 100 / 2 ** 0.5) | (tf.frequency_hz > 300 * 2 ** 0.5)
    assert np.allclose(np.abs(tf.kcp_target[out]), np.abs(tf.kcp_baseline[out]), rtol=EXACT)


def test_variants_file_and_errors_name_file_and_line(tmp_path, engine):
    good = tmp_path / "v.toml"
    good.write_text('[[variant]]\nname = "stiff"\nscale = ["left.z.stiffness=1.2"]\n\n'
                    '[[variant]]\nname = "moved"\nmove = ["gearbox=0,0,10"]\n'
                    'rotate = ["left=0,0,5"]\n')
    vs = read_variants(good)
    assert [v.name for v in vs] == ["stiff", "moved"]
    assert len(vs[1].operations) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text('[[variant]]\nname = "a"\nscale = ["left.z.stiffness=1.2"]\n\n'
                   '[[variant]]\nname = "b"\nscale = ["left.q.stiffness=1.2"]\n')
    with pytest.raises(InputError) as exc:
        read_variants(bad)
    assert "line 7" in str(exc.value) and "variant[2].scale" in str(exc.value)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text('[[variant]]\nname = "a"\nscale = ["front.z.stiffness=1.2"]\n')
    with pytest.raises(InputError) as exc:
        apply_operations(engine, read_variants(unknown)[0].operations)
    assert "front" in str(exc.value) and "line 3" in str(exc.value)


@pytest.mark.parametrize("args", [
    ["--scale", "left.z.stiffness=0"],
    ["--scale", "left.z.stiffness=-1"],
    ["--scale", "left.q.stiffness=1.2"],
    ["--scale", "front.z.stiffness=1.2"],
    ["--scale", "left.z.stiffnes=1.2"],
    ["--scale", "left.z=1.2"],
    ["--set", "right.y.c9=150"],
    ["--set", "right.y.c2=abc"],
    ["--set", "right.y.c2=150 kg"],
    ["--move", "gearbox=0,10"],
    ["--rotate", "nowhere=0,0,5"],
    ["--swap", "left.z=does-not-exist.toml"],
    ["--target", "left.z:+20%"],
    ["--target", "left.z:-100%:100-300Hz"],
    ["--target", "left.z:+20%:300-100Hz"],
    ["--effect", "chassis_wobble"],
    ["--effect", "mount_stiffness:k4=1.2"],
    ["--effect", "mount_stiffness:k1=5"],
    ["--effect", "base_compliance:c_base=400kg"],
    ["--effect", "sensor_error:g1"],
    [],
])
def test_bad_specs_one_line_nonzero_exit_no_output(tmp_path, args):
    out = tmp_path / "out.json"
    r = CliRunner().invoke(main, ["whatif", "--from", "2000", "--to", "3000", "--step",
                                  "1000", "--workers", "1", "--quiet", "--json", str(out)]
                           + args)
    assert r.exit_code != 0
    assert len(r.output.strip().splitlines()) == 1, r.output
    assert not out.exists()


def test_cli_json(tmp_path):
    out = tmp_path / "w.json"
    r = CliRunner().invoke(main, ["whatif", "--from", "2000", "--to", "4000", "--step",
                                  "1000", "--workers", "1", "--scale",
                                  "left.z.dynamic=1.2", "--json", str(out)])
    assert r.exit_code == 0, r.output
    doc = json.loads(out.read_text())
    assert doc["baseline"]["solver"] == "harmonic"
    (v,) = doc["variants"]
    assert v["name"] == "command line"
    row = v["channels"][0]
    assert {"mount", "direction", "quantity", "mean_delta_db",
            "max_abs_delta_db"} <= set(row)
    assert {r["quantity"] for r in v["channels"]} == {"synthesis", "order_2", "order_4"}
    assert len(v["channels"]) == 27


# --------------------------------------------------------------------------- effects
#: Newmark (1° step) against the exact harmonic steady state: the run-up's own tolerance.
NEWMARK_REL = 5e-3


def test_effects_through_the_normal_runup_match_the_fast_path(engine):
    """Every diagnosis effect runs through run_runup (Newmark here) and agrees with the
    cached frequency-domain path of the diagnosis (:func:`powertrain.effects.predict`)."""
    from powertrain.effects import predict
    from powertrain.solvers.fast_harmonic import HarmonicModel
    from powertrain.workflows.runup import runup_with_effects
    scenarios = [{"base_compliance": {"c_base": 4e5, "m_base": 8.0}},
                 {"mount_stiffness": {"k1": 1.5, "k3": 0.7}},
                 {"amplitude_stiffness": {"exponent": 0.2}},
                 {"balancer_error": {"gain": 0.8, "lag": 0.1, "asym": 0.2}},
                 {"sensor_error": {"g2": 3.0, "r1z": 0.05}}]
    for sc in scenarios:
        nm = runup_with_effects(engine, RPM, sc, solver="newmark")
        ref = predict(HarmonicModel(engine, RPM), sc).velocity
        err = np.max(np.abs(nm.velocity - ref)) / np.max(np.abs(ref))
        assert err < NEWMARK_REL, (sc, err)
        assert nm.settings["effects"][next(iter(sc))]


def test_whatif_effect_option_units_and_variants_file(tmp_path, engine):
    from powertrain.workflows.variants import parse_effect
    op = parse_effect("base_compliance:c_base=400N/mm,m_base=8kg")
    assert dict(op.params) == {"c_base": pytest.approx(4e5), "m_base": 8.0}
    assert dict(parse_effect("balancer_error:lag=5deg").params)["lag"] == pytest.approx(
        math.radians(5))
    f = tmp_path / "v.toml"
    f.write_text('[[variant]]\nname = "warm mounts"\neffect = ["mount_stiffness:k1=0.7,'
                 'k2=0.7"]\n')
    (v,) = read_variants(f)
    res = run_whatif(engine, [v], RPM, workers=1)
    ch = {(r["mount"], r["direction"], r["quantity"]): r
          for r in res.channel_changes("warm mounts")}
    # softer engine mounts (springs and dampers x 0.7): left X synthesis moves by -0.13 dB
    # on average, 0.22 dB at most at these speeds -- small: the body is mass-controlled
    # above its rigid-body modes
    row = ch[("left", "x", "synthesis")]
    assert row["mean_delta_db"] < -0.08 and row["max_abs_delta_db"] > 0.15
    r = CliRunner().invoke(main, ["whatif", "--from", "2000", "--to", "3000", "--step",
                                  "1000", "--workers", "1", "--quiet", "--effect",
                                  "sensor_error:g1=6", "--json", str(tmp_path / "w.json")])
    assert r.exit_code == 0, r.output
    doc = json.loads((tmp_path / "w.json").read_text())
    rows = {(c["mount"], c["direction"], c["quantity"]): c
            for c in doc["variants"][0]["channels"]}
    assert rows[("left", "x", "order_2")]["mean_delta_db"] == pytest.approx(6.0, abs=1e-9)
    assert rows[("left", "y", "order_2")]["mean_delta_db"] == pytest.approx(0.0, abs=1e-9)


def test_runup_effect_option(tmp_path):
    out = tmp_path / "r.h5"
    args = ["runup", "--from", "2000", "--to", "3000", "--step", "1000", "--solver",
            "harmonic", "--out", str(out)]
    r0 = CliRunner().invoke(main, args)
    r1 = CliRunner().invoke(main, args + ["--effect", "sensor_error:g3=6"])
    assert r0.exit_code == 0 and r1.exit_code == 0, r1.output
    assert "effects: sensor_error(" in r1.output
    row0 = [ln.split() for ln in r0.output.splitlines() if ln.startswith("2000")][0]
    row1 = [ln.split() for ln in r1.output.splitlines() if ln.startswith("2000")][0]
    assert float(row1[3]) / float(row0[3]) == pytest.approx(10 ** (6 / 20), rel=1e-3)
    assert row1[1] == row0[1]
    bad = CliRunner().invoke(main, args + ["--effect", "sensor_error:g3=60"])
    assert bad.exit_code == 1 and len(bad.output.strip().splitlines()) == 1
