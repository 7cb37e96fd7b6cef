"""The static operating point (issue 20, item 2): closed form, residuals, torque-reaction
sign, a nonlinear curve against a direct root-find, the run-up's per-speed scaling, the
command's JSON shape and bad input."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from powertrain.cli import main
from powertrain.iotools.engine_file import read_engine
from powertrain.models.engine import MountSpec, RigidBody
from powertrain.models.mount import MountModel
from powertrain.physics.mount_laws import CurveReader, StaticCurve
from powertrain.solvers.operating_point import (
    TOLERANCE,
    StaticSupport,
    operating_point,
    static_factors,
    static_load,
)
from powertrain.units import STANDARD_GRAVITY

ROOT = Path(__file__).resolve().parents[1]
NONLINEAR = ROOT / "engines" / "default-nonlinear.toml"
K_XY, K_Z = 1.0e5, 2.0e5          # N/m
A, B = 0.3, 0.25                  # mount half-spacings along engine X and Y [m]
MASS = 180.0


def _linear_curve(k):
    return StaticCurve((-0.02, 0.0, 0.02), (-0.02 * k, 0.0, 0.02 * k), 0.0)


def _symmetric_engine(z_curve=None, rotation_sign=1, gear_ratio=1.0, mass=MASS):
    """The default engine's crank train and combustion on four symmetric mounts about the
    CG: Kelvin-Voigt networks k_x = k_y = 1e5 N/m, along z a static curve (default: linear,
    2e5 N/m)."""
    base = read_engine()
    z_curve = z_curve or _linear_curve(K_Z)

    def kv(k, curve=None):
        return dataclasses.replace(MountModel.from_values("kelvin-voigt", [k, 100.0]),
                                   static_curve=curve)
    mounts = [MountSpec(f"m{i}", np.array([sx * A, sy * B, 0.0]), np.eye(3),
                        {"x": kv(K_XY), "y": kv(K_XY), "z": kv(K_Z, z_curve)})
              for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)])]
    crank = dataclasses.replace(base.crank, rotation_sign=rotation_sign)
    return base.replace(mounts=mounts, crank=crank, gear_ratio=gear_ratio,
                        body=RigidBody(mass, np.zeros(3), np.diag([8.0, 20.0, 18.0])))


def test_closed_form_sag_and_roll():
    """Symmetric mounts, linear curves: sag m g / sum k_z, roll -i T n / (sum k_z y^2),
    nothing else moves (to 1e-12 relative)."""
    e = _symmetric_engine()
    op = operating_point(e, 2000.0)
    sag = -MASS * STANDARD_GRAVITY / (4 * K_Z)
    roll = -op.mean_torque / (4 * K_Z * B ** 2)
    print(f"sag {op.body[2] * 1e3:.6f} mm (closed form {sag * 1e3:.6f}), roll "
          f"{np.rad2deg(op.body[3]):.6f} deg (closed form {np.rad2deg(roll):.6f})")
    assert op.body[2] == pytest.approx(sag, rel=1e-12)
    assert op.body[3] == pytest.approx(roll, rel=1e-12)
    assert np.max(np.abs(op.body[[0, 1, 4, 5]])) < 1e-12 * abs(sag)
    assert np.allclose(op.static_factor, 1.0, rtol=1e-12)
    assert op.force[:, 2].sum() == pytest.approx(-MASS * STANDARD_GRAVITY, rel=1e-12)


def test_mean_torque_is_the_full_load_curve():
    """The single-zone model is calibrated to the full-load torque: the mean brake torque
    (indicated work less FMEP) gives it back."""
    e = read_engine()
    fl = e.combustion.full_load
    for rpm in (1000.0, 3000.0, 5500.0):
        want = np.interp(rpm * np.pi / 30, fl.speed, fl.torque)
        assert e.mean_brake_torque(rpm) == pytest.approx(want, rel=1e-9)


@pytest.mark.parametrize("sign,ratio", [(1, 1.0), (-1, 1.0), (1, 3.5), (-1, 3.5)])
def test_torque_reaction_sign_and_gear_ratio(sign, ratio):
    """The reaction -i T n: the body rolls against the crank's rotation sense, i times as
    far with gear ratio i (linear curves); the load's moment is -i T n exactly."""
    e = _symmetric_engine(rotation_sign=sign, gear_ratio=ratio)
    op = operating_point(e, 3000.0)
    assert op.mean_torque > 0
    assert np.sign(op.body[3]) == -sign
    ref = operating_point(_symmetric_engine(), 3000.0).body[3]
    assert op.body[3] == pytest.approx(sign * ratio * ref, rel=1e-12)
    assert np.allclose(static_load(e, op.mean_torque)[3:],
                       [-ratio * sign * op.mean_torque, 0.0, 0.0], rtol=1e-15)


def _residual(engine, op):
    s = StaticSupport.of(engine)
    r = static_load(engine, op.mean_torque) - s.rows.T @ s.forces(s.rows @ op.body)
    w = engine.body.mass * STANDARD_GRAVITY
    return np.linalg.norm(r[:3]) / w, np.linalg.norm(r[3:]) / w


def test_residual_tolerances_on_the_shipped_nonlinear_engine():
    """The residual recomputed here is within the stated tolerance of the weight (x 1 m)."""
    e = read_engine(NONLINEAR)
    for rpm in (1000.0, 3500.0, 6000.0):
        op = operating_point(e, rpm)
        f, m = _residual(e, op)
        print(f"{rpm:g} rpm: {op.iterations} Newton steps, force residual {f:.1e}, moment "
              f"residual {m:.1e} (tolerance {TOLERANCE:g})")
        assert f <= TOLERANCE and m <= TOLERANCE
        assert np.any(np.abs(op.static_factor - 1) > 1e-3)        # the curves act


def test_nonlinear_curve_against_a_direct_root_find():
    """A progressive curve on the symmetric engine: Newton's operating point and scipy's
    hybrid root-finder on the same equations agree to 1e-9 m and 1e-9 rad."""
    from scipy.optimize import root
    curve = StaticCurve((-0.012, -0.006, -0.002, 0.0, 0.004),
                        (-3000.0, -900.0, -250.0, 0.0, 600.0), -0.003)
    e = _symmetric_engine(z_curve=curve, gear_ratio=3.0)
    op = operating_point(e, 3000.0)
    s = StaticSupport.of(e)
    load = static_load(e, op.mean_torque)
    sol = root(lambda q: load - s.rows.T @ s.forces(s.rows @ q), np.zeros(6), tol=1e-13)
    assert np.max(np.abs(sol.fun)) < 1e-9 * MASS * STANDARD_GRAVITY       # a root
    print(f"Newton vs hybr: {np.max(np.abs(op.body - sol.x)):.1e} (m, rad); "
          f"sag {op.body[2] * 1e3:.4f} mm, roll {np.rad2deg(op.body[3]):.4f} deg")
    assert np.max(np.abs(op.body - sol.x)) < 1e-9
    assert op.deflection[0, 2] != pytest.approx(op.deflection[1, 2], abs=1e-4)
    z = op.deflection[:, 2]
    assert np.allclose(op.static_factor[2::3], curve.tangent_at(z) / curve.tangent_at(-0.003))


def test_no_equilibrium_names_the_speed():
    """Curves that saturate below the weight: an error naming the speed, no result."""
    from powertrain.errors import InputError
    weak = StaticCurve((-0.003, -0.002, -0.001, 0.0), (-1001.0, -1000.0, -10.0, 0.0))
    e = _symmetric_engine(z_curve=weak, mass=500.0)
    with pytest.raises(InputError, match="2500 rpm"):
        operating_point(e, 2500.0)


def test_static_factors_function():
    """``static_factors`` (what the continuous sweep calls): ones without curves, the
    operating point's factors with them."""
    assert np.array_equal(static_factors(read_engine(), 2000.0), np.ones(9))
    e = read_engine(NONLINEAR)
    assert np.array_equal(static_factors(e, 2000.0), operating_point(e, 2000.0).static_factor)


def test_runup_scales_the_networks_at_the_operating_point(tmp_path):
    """The harmonic run-up of an engine with static curves equals, speed by speed, the
    run-up of the same networks scaled by the operating point's factors (no curves); the
    HDF5 file records the operating point and reads it back."""
    from powertrain.iotools.runup_hdf5 import read_runup_hdf5
    from powertrain.workflows.runup import run_runup, runup
    e = read_engine(NONLINEAR)
    rpm = [1500.0, 4000.0]
    run = runup(e, rpm, solver="harmonic")
    for i, n in enumerate(rpm):
        f = run.operating_point.points[i].static_factor
        mounts = [dataclasses.replace(m, directions={
            a: dataclasses.replace(mdl.scaled(f[3 * k + j], f[3 * k + j]), static_curve=None)
            for j, (a, mdl) in enumerate(m.directions.items())}) for k, m in enumerate(e.mounts)]
        ref = run_runup(e.replace(mounts=mounts), [n], solver="harmonic")
        dev = np.max(np.abs(run.velocity[i] - ref.velocity[0])) / np.max(np.abs(ref.velocity))
        print(f"{n:g} rpm: factors {np.round(f, 4).tolist()}, deviation {dev:.1e}")
        assert dev < 1e-9
    run.to_hdf5(tmp_path / "r.h5")
    back = read_runup_hdf5(tmp_path / "r.h5").operating_point
    assert back.to_dict() == run.operating_point.to_dict()


def test_cli_json_shape(tmp_path):
    out = tmp_path / "static.json"
    res = CliRunner().invoke(main, ["static", "--engine", str(NONLINEAR), "--rpm",
                                    "1000,2000", "--json", str(out)])
    assert res.exit_code == 0, res.output
    assert "left.z" in res.output and "deflection [mm]" in res.output
    doc = json.loads(out.read_text())
    assert set(doc) == {"rpm", "mean_torque_nm", "gear_ratio", "body", "mounts", "provenance"}
    assert doc["rpm"] == [1000.0, 2000.0] and doc["gear_ratio"] == 1.0
    assert set(doc["body"]) == {"displacement_mm", "rotation_deg"}
    assert np.shape(doc["body"]["displacement_mm"]) == (2, 3)
    assert list(doc["mounts"]) == ["left", "right", "gearbox"]
    for m in doc["mounts"].values():
        assert set(m) == {"deflection_mm", "force_n", "tangent_stiffness_n_per_mm",
                          "static_factor"}
        assert all(np.shape(v) == (2, 3) for v in m.values())
    from powertrain import static
    api = static(NONLINEAR, [1000.0, 2000.0]).to_dict()
    assert doc["body"] == api["body"] and doc["mounts"] == api["mounts"]   # full precision


def _engine_with_drive(tmp_path, drive):
    text = (ROOT / "engines" / "default.toml").read_text()
    text = text.replace('files = {x = "../mounts/', f'files = {{x = "{ROOT}/mounts/')
    text = text.replace('y = "../mounts/', f'y = "{ROOT}/mounts/')
    text = text.replace('z = "../mounts/', f'z = "{ROOT}/mounts/')
    path = tmp_path / "e.toml"
    path.write_text(text + "\n[drive]\n" + drive + "\n")
    return path


def test_gear_ratio_read_and_used(tmp_path):
    path = _engine_with_drive(tmp_path, 'gear_ratio = {value = 3.2, unit = "1"}')
    e = read_engine(path)
    assert e.gear_ratio == 3.2
    op, op1 = operating_point(e, 2000.0), operating_point(read_engine(), 2000.0)
    assert op.gear_ratio == 3.2 and abs(op.body[3]) > 2 * abs(op1.body[3])


@pytest.mark.parametrize("drive,key", [
    ('gear_ratio = {value = 0.0, unit = "1"}', "drive.gear_ratio"),
    ('gear_ratio = {value = -2.0, unit = "1"}', "drive.gear_ratio"),
    ('gear_ratio = 3.0', "drive.gear_ratio"),
    ('ratio = {value = 3.0, unit = "1"}', "drive.ratio"),
])
def test_bad_drive_section(tmp_path, drive, key):
    path = _engine_with_drive(tmp_path, drive)
    res = CliRunner().invoke(main, ["static", "--engine", str(path)])
    assert res.exit_code == 1
    line = res.stderr.strip() if hasattr(res, "stderr") else res.output.strip()
    assert len(line.splitlines()) == 1 and str(path) in line and key in line, line


@pytest.mark.parametrize("rpm", ["abc", "0", "1000,900", "100:200:10", "9000", ""])
def test_bad_rpm(tmp_path, rpm):
    out = tmp_path / "s.json"
    res = CliRunner().invoke(main, ["static", "--rpm", rpm, "--json", str(out)])
    assert res.exit_code == 1
    assert "--rpm" in res.output and "Traceback" not in res.output
    assert not out.exists()


def test_runup_with_effects_records_every_speed(tmp_path):
    """A run-up with an amplitude effect keeps the operating points of every speed, in
    order, and the HDF5 file reads them back."""
    from powertrain import runup
    from powertrain.iotools.runup_hdf5 import read_runup_hdf5
    run = runup(NONLINEAR, [1500.0, 2500.0], solver="harmonic",
                effects=["amplitude_stiffness:exponent=0.2"])
    assert run.operating_point.rpm.tolist() == [1500.0, 2500.0]
    run.to_hdf5(tmp_path / "e.h5")
    assert read_runup_hdf5(tmp_path / "e.h5").operating_point.rpm.tolist() == [1500.0, 2500.0]


@settings(max_examples=40, deadline=None)
@given(st.floats(-0.02, -1e-3), st.lists(st.floats(1e-3, 1e-2), min_size=2, max_size=7),
       st.floats(1e4, 1e6), st.lists(st.floats(-0.05, 0.05) | st.sampled_from([0.0, 1e-12]),
                                    min_size=3, max_size=3))
def test_the_supports_piecewise_cubics_read_as_the_curves_pchip(first, gaps, k, deflections):
    """StaticSupport reads every network at once through the kernel's piecewise cubics:
    a curve as its CurveReader (scipy's PCHIP, straight beyond its points) to round-off,
    and a direction without a curve as exactly its static stiffness times the deflection."""
    x = first + np.r_[0.0, np.cumsum(gaps)]
    rng = np.random.default_rng(len(gaps))
    force = np.cumsum(rng.uniform(0.2, 3.0, x.size)) * k * 1e-3
    curve = StaticCurve(tuple(x), tuple(force - np.interp(0.0, x, force)), float(x[1]))
    e = _symmetric_engine(z_curve=curve)
    s = StaticSupport.of(e)
    d = np.tile(np.asarray(deflections), len(e.mounts))
    f, t = s.read(d)
    reader = CurveReader(curve)
    np.testing.assert_allclose(f[2], reader.force_at(d[2]), rtol=1e-12,
                               atol=1e-12 * np.max(np.abs(force)))
    np.testing.assert_allclose(t[2], reader.tangent_at(d[2]), rtol=1e-12,
                               atol=1e-12 * k)
    plain = [r for r, c in enumerate(s.curves) if c is None]
    assert np.array_equal(f[plain], s.stiffness[plain] * d[plain])
    assert np.array_equal(t[plain], s.stiffness[plain])
    assert np.allclose(s.factors(d)[plain], 1.0, rtol=0, atol=0)
