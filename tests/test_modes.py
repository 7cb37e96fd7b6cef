"""``powertrain modes`` (issue 13, item 2) against a closed form and an independent derivation.

Tolerances: frequencies 1e-6 relative and kinetic-energy shares 0.01 percentage points (the
issue's); both computations are exact linear algebra, so they agree to round-off.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from click.testing import CliRunner
from scipy.spatial.transform import Rotation

from powertrain.cli import main
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics.condensation import condense
from powertrain.solvers.modes import COORDINATES
from powertrain.workflows.modes import modes as engine_modes

DATA = Path(__file__).parent / "data"
REFERENCE = DATA / "modes-reference-engine.toml"
MOUNTS = Path(DEFAULT_ENGINE_PATH).parents[1] / "mounts"
FREQ_REL = 1e-6
KED_PP = 0.01

SYMMETRIC = """
[engine]
name = "symmetric four-mount layout"

[body]
mass = {{value = {m}, unit = "kg"}}
cg = {{value = [0.0, 0.0, 0.0], unit = "mm"}}
inertia = {{value = [[{ixx}, 0.0, 0.0], [0.0, {iyy}, 0.0], [0.0, 0.0, {izz}]], unit = "kg*m^2"}}
"""
MOUNT = """
[mounts.{name}]
position = {{value = [{x}, {y}, 0.0], unit = "mm"}}
orientation = {{value = [0.0, 0.0, 90.0], unit = "deg"}}
stiffness = {{value = [{ky}, {kx}, {kz}], unit = "N/mm"}}
damping = {{value = [{cy}, {cx}, {cz}], unit = "N*s/mm"}}
"""


def _symmetric(tmp_path):
    """Four equal mounts at (±a, ±b) in the CG plane, diagonal inertia: decoupled modes.

    Each mount is turned by 90° about Z with its x and y stiffness swapped, so in engine axes
    it acts with kx, ky, kz (exercises the Euler orientation).
    """
    p = dict(m=150.0, ixx=6.0, iyy=14.0, izz=12.0)
    k = dict(kx=110.0, ky=90.0, kz=200.0, cx=0.15, cy=0.12, cz=0.3)
    a, b = 0.35, 0.25
    text = SYMMETRIC.format(**p)
    for i, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)]):
        text += MOUNT.format(name=f"m{i}", x=1e3 * sx * a, y=1e3 * sy * b, **k)
    path = tmp_path / "symmetric.toml"
    path.write_text(text)
    kx, ky, kz = (1e3 * k[n] for n in ("kx", "ky", "kz"))
    cx, cy, cz = (1e3 * k[n] for n in ("cx", "cy", "cz"))
    # closed form: stiffness, damping and inertia of each decoupled coordinate
    closed = {"x": (4 * kx, 4 * cx, p["m"]), "y": (4 * ky, 4 * cy, p["m"]),
              "z": (4 * kz, 4 * cz, p["m"]), "rx": (4 * kz * b**2, 4 * cz * b**2, p["ixx"]),
              "ry": (4 * kz * a**2, 4 * cz * a**2, p["iyy"]),
              "rz": (4 * (kx * b**2 + ky * a**2), 4 * (cx * b**2 + cy * a**2), p["izz"])}
    return path, closed


@pytest.mark.parametrize("static", [True, False], ids=["static", "dynamic"])
def test_symmetric_layout_matches_closed_form(tmp_path, static):
    """Oracle: closed form. Each decoupled coordinate is a single-DOF oscillator:
    f = sqrt(k/J)/2π, ζ = c/(2 sqrt(kJ)) (dynamic; 0 static), 100 % energy in it, and with a
    diagonal inertia the torque-roll axis is the crank axis (the roll mode's axis: 0°)."""
    path, closed = _symmetric(tmp_path)
    res = engine_modes(read_engine(path), static=static)
    assert [m.kind for m in res.modes] == ["rigid-body"] * 6
    for m in res.modes:
        k, c, J = closed[m.dominant]
        assert m.frequency_hz == pytest.approx(np.sqrt(k / J) / (2 * np.pi), rel=FREQ_REL)
        zeta = 0.0 if static else c / (2 * np.sqrt(k * J))
        assert m.damping_ratio == pytest.approx(zeta, rel=1e-9, abs=1e-12)
        assert m.ked_percent.max() == pytest.approx(100.0, abs=KED_PP)
    assert sorted(m.dominant for m in res.modes) == sorted(COORDINATES)
    np.testing.assert_allclose(res.torque_roll_axis["direction"], [1, 0, 0], atol=1e-12)
    roll = next(m for m in res.modes if m.dominant == "rx")
    assert roll.angle_to_torque_roll_axis_deg == pytest.approx(0.0, abs=1e-6)


def _independent_reference(path):
    """Six-DOF modes of a rigid body on linear springs, derived and coded apart from the
    package (Lagrange's equations; e.g. Harris' Shock and Vibration Handbook, ch. 3
    'Vibration of a resiliently supported rigid body').

    Reads the file with tomllib, builds each mount's rotation with scipy's extrinsic 'xyz'
    Euler convention (= Rz·Ry·Rx), writes the elastic energy
    V(q) = ½ Σ_mounts Σ_local k_d (e_d·(u + θ×r))² and takes its Hessian by polarisation,
    K_ij = V(e_i + e_j) − V(e_i) − V(e_j) (exact for a quadratic form); the kinetic energy
    gives M = diag(m, m, m, I_CG). Modes from scipy.linalg.eigh; energy shares
    φ_j(Mφ)_j/φᵀMφ.
    """
    import tomllib
    doc = tomllib.loads(path.read_text())
    b = doc["body"]
    mass = b["mass"]["value"]
    cg = np.array(b["cg"]["value"]) / 1e3
    inertia = np.array(b["inertia"]["value"])
    springs = []
    for m in doc["mounts"].values():
        R = Rotation.from_euler("xyz", m["orientation"]["value"], degrees=True).as_matrix()
        r = np.array(m["position"]["value"]) / 1e3 - cg
        for d in range(3):
            springs.append((m["stiffness"]["value"][d] * 1e3, R[:, d], r))

    def energy(q):
        u, th = q[:3], q[3:]
        return 0.5 * sum(k * (e @ (u + np.cross(th, r))) ** 2 for k, e, r in springs)

    eye = np.eye(6)
    K = np.array([[energy(eye[i] + eye[j]) - energy(eye[i]) - energy(eye[j])
                   for j in range(6)] for i in range(6)])
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = inertia
    w2, phi = sla.eigh(K, M)
    ked = 100 * phi * (M @ phi) / np.einsum("ij,ij->j", phi, M @ phi)
    return np.sqrt(w2) / (2 * np.pi), ked.T


def test_static_modes_reproduce_independent_six_dof_reference(tmp_path):
    """Oracle: the independent derivation above, for an engine file with Euler-angle
    orientations, inline springs, an offset CG and products of inertia; through the CLI's
    JSON (frequencies 1e-6 relative, energy 0.01 percentage points)."""
    out = tmp_path / "modes.json"
    res = CliRunner().invoke(main, ["modes", "--engine", str(REFERENCE), "--static",
                                    "--json", str(out)])
    assert res.exit_code == 0, res.output
    data = json.loads(out.read_text())
    f_ref, ked_ref = _independent_reference(REFERENCE)
    f = [m["frequency_hz"] for m in data["modes"]]
    np.testing.assert_allclose(f, f_ref, rtol=FREQ_REL)
    ked = np.array([[m["ked_percent"][c] for c in COORDINATES] for m in data["modes"]])
    np.testing.assert_allclose(ked, ked_ref, atol=KED_PP)
    assert all(m["damping_ratio"] == 0.0 for m in data["modes"])
    assert data["method"].startswith("static")


def test_json_keys_and_order(tmp_path):
    """Oracle: the issue's JSON layout, modes sorted by frequency."""
    out = tmp_path / "m.json"
    res = CliRunner().invoke(main, ["modes", "--json", str(out), "--plot",
                                    str(tmp_path / "m.png")])
    assert res.exit_code == 0, res.output
    data = json.loads(out.read_text())
    assert {"modes", "torque_roll_axis", "method"} <= set(data)
    assert len(data["modes"]) == 6
    for m in data["modes"]:
        assert {"frequency_hz", "damping_ratio", "dominant", "ked_percent"} <= set(m)
        assert set(m["ked_percent"]) == set(COORDINATES)
        assert sum(m["ked_percent"].values()) == pytest.approx(100.0, abs=1e-9)
        assert m["dominant"] == max(m["ked_percent"], key=m["ked_percent"].get)
    f = [m["frequency_hz"] for m in data["modes"]]
    assert f == sorted(f)
    assert (tmp_path / "m.png").stat().st_size > 0


SLS_MOUNT = """
[mount]
name = "standard linear solid (a massless internal node)"
model = "sls"

[units]
c = "N/mm"
d = "N*s/mm"

[parameters]
c1 = 150.0
c2 = 60.0
d2 = 0.4
"""


def _engine_text():
    """The default engine file's text with absolute mount paths (to be written elsewhere)."""
    return Path(DEFAULT_ENGINE_PATH).read_text().replace("../mounts/", f"{MOUNTS}/")


def _with_massless_node(tmp_path):
    """The default engine with its gearbox mount's x direction an SLS network, whose internal
    node has no mass (the model's mass matrix is singular)."""
    (tmp_path / "sls-x.toml").write_text(SLS_MOUNT)
    path = tmp_path / "sls.toml"
    path.write_text(_engine_text().replace(f"{MOUNTS}/elastomeric-gearbox-mount-x.toml",
                                           str(tmp_path / "sls-x.toml")))
    return path


@pytest.mark.parametrize("path", [DEFAULT_ENGINE_PATH,
                                  Path(DEFAULT_ENGINE_PATH).parent / "default-torque-rod.toml",
                                  Path(DEFAULT_ENGINE_PATH).parent / "default-modal-body.toml",
                                  REFERENCE, "massless-node"],
                         ids=["default", "torque-rod", "modal-body", "reference", "massless-node"])
def test_dynamic_modes_are_roots_of_the_condensed_model(path, tmp_path):
    """Oracle: a second solver. Every damped mode's complex frequency s is an eigenvalue of
    the full state-space model M q'' + C q' + K q = 0 with the networks' internal degrees of
    freedom (scipy.linalg.eig, generalized), and a root of the condensed problem on the
    retained coordinates, D_R(s) phi = 0 with every network through its two-port at s
    (powertrain.physics.condensation.condense): D_R(s) is singular to round-off and its null
    vector is the mode's shape (MAC 1). The modes are distinct and sorted."""
    e = read_engine(_with_massless_node(tmp_path) if path == "massless-node" else path)
    system = e.assemble()
    n = system.n_dof
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-system.K, -system.C]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), system.M]])
    lam = sla.eig(A, B, right=False)
    lam = lam[np.isfinite(lam)]
    res = engine_modes(e)
    keep = system.retained
    s = [2 * np.pi * (-m.damping_ratio * m.frequency_hz + 1j * m.damped_frequency_hz)
         for m in res.modes]
    for si, m in zip(s, res.modes):
        assert np.min(np.abs(lam - si)) / abs(si) < 1e-8
        _, sigma, vh = np.linalg.svd(condense(system, keep, si))
        assert sigma[-1] / sigma[0] < 1e-8
        null = np.conj(vh[-1])[:6]
        mac = abs(np.vdot(null, m.shape)) ** 2 / (np.vdot(null, null).real
                                                  * np.vdot(m.shape, m.shape).real)
        assert mac == pytest.approx(1.0, abs=1e-6)
    assert min(abs(a - b) for i, a in enumerate(s) for b in s[i + 1:]) > 1e-6 * abs(s[0])
    assert [m.frequency_hz for m in res.modes] == sorted(m.frequency_hz for m in res.modes)


def test_a_measured_frf_chassis_takes_the_ground_under_the_mounts(tmp_path):
    """A measured receptance (``[chassis] model = "frf"``) is coupled in the harmonic solver
    only: the modes of an engine with one are those of the same engine on a rigid ground."""
    (tmp_path / "body.csv").write_text(
        "frequency_hz,response,excitation,receptance_real_m_per_n,receptance_imag_m_per_n\n"
        + "".join(f"{f},{r}.{a},{x}.{b},1e-8,0.0\n" for f in (10.0, 100.0)
                  for r in ("left", "right", "gearbox") for x in ("left", "right", "gearbox")
                  for a in "xyz" for b in "xyz"))
    (tmp_path / "frf.toml").write_text(_engine_text() + '\n[chassis]\nmodel = "frf"\nfrf = "body.csv"\n')
    rigid, frf = (engine_modes(read_engine(p)) for p in (DEFAULT_ENGINE_PATH,
                                                          tmp_path / "frf.toml"))
    assert [m.frequency_hz for m in frf.modes] == [m.frequency_hz for m in rigid.modes]
    assert [m.damping_ratio for m in frf.modes] == [m.damping_ratio for m in rigid.modes]


def test_modes_of_an_engine_file_without_excitation():
    """Oracle: the issue — an engine file with only [engine], [body], [mounts.*] runs modes."""
    res = CliRunner().invoke(main, ["modes", "--engine", str(REFERENCE)])
    assert res.exit_code == 0, res.output
    assert "torque-roll axis" in res.output


def test_text_says_which_modes_and_pairs_them_with_the_static_ones():
    """Issue 18: `runup` prints the undamped static-stiffness modes, `modes` the damped ones
    at dynamic stiffness; each output says which, both sort by frequency, and `modes` pairs
    each damped mode with the static mode of the most similar shape (MAC)."""
    static = engine_modes(read_engine(DEFAULT_ENGINE_PATH), static=True)
    damped = engine_modes(read_engine(DEFAULT_ENGINE_PATH))
    assert "undamped" in static.to_text().splitlines()[0]
    assert "static (0 Hz) stiffness" in static.to_text().splitlines()[0]
    assert "damped, each with the mounts' dynamic stiffness" in damped.to_text()
    # one-to-one pairing with the static modes, by shape
    f_static = sorted(m.frequency_hz for m in static.modes)
    paired = sorted(m.static_frequency_hz for m in damped.modes)
    np.testing.assert_allclose(paired, f_static, rtol=1e-12)
    assert all(0.0 < m.static_mac <= 1.0 + 1e-12 for m in damped.modes)
    assert all(m.static_mac == pytest.approx(1.0) for m in static.modes)
    # runup prints the static modes, labelled as such, with the same dominant coordinates
    res = CliRunner().invoke(main, ["runup", "--solver", "harmonic", "--to", "1000"])
    assert res.exit_code == 0, res.output
    line = next(ln for ln in res.output.splitlines() if ln.startswith("rigid-body modes"))
    assert "undamped" in line and "static stiffness" in line and "powertrain modes" in line
    expected = ", ".join(f"{m.frequency_hz:.1f} ({m.dominant})" for m in static.modes)
    assert expected in line


def test_negative_energy_shares_are_explained():
    """The static default modes carry a -0.2 % share (products of inertia); the table says
    the shares are signed and that each row adds up to 100 %, and prints no '-0.0'."""
    res = engine_modes(read_engine(DEFAULT_ENGINE_PATH), static=True)
    lowest = min(float(np.min(m.ked_percent)) for m in res.modes)
    assert lowest < -0.05
    text = res.to_text()
    assert f"energy shares are signed (lowest {lowest:.1f} %)" in text
    assert "adds up to 100 %" in text and " -0.0 " not in text
    for m in res.modes:
        assert m.ked_percent.sum() == pytest.approx(100.0, abs=1e-9)


def test_modes_of_nonlinear_mounts_take_the_networks_as_measured():
    """engines/default-nonlinear.toml has the default engine's networks with amplitude laws,
    friction and static curves (factor 1 at the reference deflection) added: its printed
    static modes and its damped modes are the linear engine's to 1e-9, and both say so; the
    linear engine's label is unchanged."""
    from conftest import ENGINES

    from powertrain.results.runup import RIGID_BODY_MODES_LABEL
    from powertrain.solvers.modes import AS_MEASURED
    from powertrain.workflows.runup import runup
    linear = read_engine(DEFAULT_ENGINE_PATH)
    nonlinear = read_engine(ENGINES / "default-nonlinear.toml")
    a, b = (e.rigid_body_modes()[0] for e in (nonlinear, linear))
    assert np.allclose(a, b, rtol=1e-9, atol=0)
    da, db = (engine_modes(e) for e in (nonlinear, linear))
    assert np.allclose([m.frequency_hz for m in da.modes], [m.frequency_hz for m in db.modes],
                       rtol=1e-9, atol=0)
    assert AS_MEASURED in da.to_text() and AS_MEASURED not in db.to_text()
    text = runup(nonlinear, [3000.0], solver="harmonic").to_text().splitlines()[1]
    assert text.startswith(f"rigid-body modes, undamped, {AS_MEASURED} at their static")
    assert runup(linear, [3000.0], solver="harmonic").to_text().splitlines()[1].startswith(
        RIGID_BODY_MODES_LABEL)


def test_the_shape_of_a_root_exact_to_the_last_bit():
    """An undamped two-degree-of-freedom model whose root 2i makes K + sC + s²M exactly
    singular: the shape is still its null vector (the first coordinate alone)."""
    from types import SimpleNamespace

    from powertrain.solvers.modes import root_shapes
    model = SimpleNamespace(M=np.eye(2), C=np.zeros((2, 2)), K=np.diag([4.0, 9.0]), n_dof=2)
    x = root_shapes(model, np.array([2j]))[:, 0]
    assert abs(x[1]) < 1e-9 * abs(x[0])
