"""Engine model and excitation: each test names its oracle.

Oracles: the closed-form exact slider-crank acceleration and its Fourier series (Taylor 1985,
vol. 2, ch. 8; Heywood 1988, sec. 2.2), the first law (mean crank torque = IMEP V_d/(4π)),
symmetry of the flat inline-4 crank, Newton's third law (block load = shaking force +
torque reaction), two implementations that must agree (model vs measured-trace round trip,
engine vs assembly rigid-body modes).
"""

from __future__ import annotations

import dataclasses
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.errors import InputError
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.physics import slider_crank as sc
from powertrain.physics.balancer import matching_mass_radius

RPM = 3000.0
OMEGA = RPM * 2 * np.pi / 60
N = 1440  # samples per engine cycle (0.5 deg)
THETA = 4 * np.pi * np.arange(N) / N

#: Two exact evaluations of the same quantity (closed form vs library, or an invariant
#: that holds term by term): only round-off separates them, relative to the signal's scale.
EXACT_REL = 1e-9
#: Orders that must vanish by symmetry: relative to the largest order amplitude of the same
#: component set; FFT of a sum that cancels exactly leaves round-off only.
ZERO_ORDER_REL = 1e-9
#: Mean torque vs IMEP V_d/(4π): both sides come from the same pressure; they differ by the
#: linear interpolation of the 0.125-deg pressure grid at 0.5-deg samples, < 0.1 %.
MEAN_TORQUE_REL = 1e-3


def no_offset(eng):
    return eng.replace(crank=dataclasses.replace(eng.crank, pin_offset=0.0))


def orders(load):
    """Complex amplitudes per order (index j = order j/2) of an (N, k) cycle signal."""
    return harmonic_amplitudes(load, axis=0)


# ----------------------------------------------------------------- kinematics

def test_kinematic_derivatives_match_finite_differences():
    """Oracle: central differences of the exact position (h = 1e-4 rad, error O(h^2))."""
    r, l, e = 0.0421, 0.144, 0.0005
    th = np.linspace(-np.pi, 3 * np.pi, 777)
    h = 1e-4
    y, dy, d2y, _ = sc.piston_kinematics(th, r, l, e)
    yp = sc.piston_kinematics(th + h, r, l, e)[0]
    ym = sc.piston_kinematics(th - h, r, l, e)[0]
    # truncation h^2 |y'|/6 ~ 2e-9 r, round-off eps r / h ~ 2e-12 r (first derivative)
    assert np.max(np.abs((yp - ym) / (2 * h) - dy)) < 1e-7 * r
    assert np.max(np.abs((yp - 2 * y + ym) / h**2 - d2y)) < 1e-5 * r


def test_net_vertical_inertia_force_equals_closed_form(engine):
    """Oracle: the closed-form exact piston acceleration (e = 0),
    a = -r w^2 [cos t + lam cos 2t / sqrt(1 - lam^2 sin^2 t)
    + lam^3 sin^2 2t / (4 (1 - lam^2 sin^2 t)^(3/2))], summed over the four cylinders at their
    crank-pin angles; the net vertical force on the block is -m sum a (gas forces are
    internal). Compared exactly; then its 2nd-order Fourier coefficient against
    4 m r w^2 lam with the truncation error of the series A2 = lam + lam^3/4 + 15 lam^5/128
    + ..., i.e. |A2 - lam| <= lam^3/4 (1 + lam^2) for lam < 0.5, and against the 3-term
    series within lam^7."""
    eng = no_offset(engine).with_balancers(enabled=False)
    ct = eng.crank
    r, l, m = ct.crank_radius, ct.rod_length, ct.reciprocating_mass
    lam = r / l
    fz = eng.generalized_load(RPM, THETA)[:, 2]
    closed = np.zeros(N)
    for pin in ct.crank_pin_angles:
        t = THETA - pin
        s2 = 1 - lam**2 * np.sin(t) ** 2
        a = -r * OMEGA**2 * (np.cos(t) + lam * np.cos(2 * t) / np.sqrt(s2)
                             + lam**3 * np.sin(2 * t) ** 2 / (4 * s2**1.5))
        closed += -m * a
    scale = 4 * m * r * OMEGA**2
    assert np.max(np.abs(fz - closed)) < EXACT_REL * scale
    c2 = orders(fz)[4]  # harmonic 4 of the 720-deg window = order 2
    leading = 4 * m * r * OMEGA**2 * lam
    assert abs(c2.imag) < EXACT_REL * scale
    assert abs(c2.real - leading) <= leading * lam**2 / 4 * (1 + lam**2)
    assert abs(c2.real - leading) > 0.5 * leading * lam**2 / 4   # the truncation is real
    assert abs(c2.real / scale - sc.second_order_coefficient(lam, 3)) < lam**7


# ----------------------------------------------------------------- torque and IMEP

def test_mean_torque_equals_imep_times_displacement_over_4pi(engine):
    """Oracle: first law over one 4-stroke cycle, mean T = sum(IMEP_i V_d)/(4 pi); the
    calibrated IMEP is the one the full-load torque implies, 4 pi T_b/V_D + FMEP."""
    exc = engine.excitation(RPM, THETA)
    vd = engine.crank.swept_volume
    t_mean = exc.torque.sum(axis=1).mean()
    expected = exc.imep.sum() * vd / (4 * np.pi)
    assert t_mean == pytest.approx(expected, rel=MEAN_TORQUE_REL)
    fl = engine.combustion.full_load
    imep_target = fl.imep(OMEGA, engine.crank.displacement)
    np.testing.assert_allclose(exc.imep, imep_target, rtol=1e-9)
    brake = t_mean - np.interp(OMEGA, fl.speed, fl.fmep) * engine.crank.displacement / (4 * np.pi)
    assert brake == pytest.approx(np.interp(OMEGA, fl.speed, fl.torque), rel=MEAN_TORQUE_REL)
    # the block carries the torque reaction: mean Mx = -mean T (crank turns about +X)
    assert exc.load[:, 3].mean() == pytest.approx(-t_mean, rel=MEAN_TORQUE_REL)


def test_block_load_is_shaking_force_plus_torque_reaction(engine):
    """Oracle: Newton's third law per cylinder. Head, side-thrust, pin-offset couple and
    main-bearing forces sum to the shaking force -m a u on the pin line plus the torque
    reaction -T about +X (see powertrain.physics.slider_crank)."""
    eng = engine.with_balancers(enabled=False)
    ct = eng.crank
    exc = eng.excitation(RPM, THETA)
    force, moment = exc.load[:, :3], exc.load[:, 3:]
    u, s = ct.cylinder_axis, ct.lateral_axis
    f_exp = exc.inertia_force.sum(axis=1)[:, None] * u
    m_exp = np.zeros((N, 3))
    for i in range(ct.n_cylinders):
        y = sc.piston_kinematics(THETA - ct.crank_pin_angles[i], ct.crank_radius,
                                 ct.rod_length, ct.pin_offset)[0]
        point = np.array([ct.cylinder_x[i], 0, 0]) + ct.pin_offset * s + y[:, None] * u
        m_exp += np.cross(point - eng.body.cg, exc.inertia_force[:, i, None] * u)
    m_exp[:, 0] -= exc.torque.sum(axis=1)
    scale = np.abs(moment).max()
    assert np.max(np.abs(force - f_exp)) < EXACT_REL * np.abs(f_exp).max()
    assert np.max(np.abs(moment - m_exp)) < EXACT_REL * scale


def test_load_is_periodic_over_the_engine_cycle(engine):
    """Oracle: a 4-stroke cycle repeats every 4 pi."""
    a = engine.generalized_load(RPM, THETA[:50])
    b = engine.generalized_load(RPM, THETA[:50] + 4 * np.pi)
    np.testing.assert_allclose(a, b, atol=1e-9 * np.abs(a).max())
    assert engine.generalized_load(RPM, THETA[:7]).shape == (7, 6)


# ----------------------------------------------------------------- orders

def test_equal_cylinders_give_no_half_orders_and_no_first_order(engine):
    """Oracle: equal cylinders fire every 180 deg on a flat crank, so the load repeats
    every half revolution: only orders 2, 4, 6 ... (no half orders, no first order)."""
    for eng in (engine, engine.with_balancers(enabled=False)):
        spec = orders(eng.generalized_load(RPM, THETA))
        j = np.arange(spec.shape[0])
        scale = np.abs(spec[1:]).max()
        assert np.abs(spec[j % 4 != 0]).max() < ZERO_ORDER_REL * scale


def test_one_weaker_cylinder_gives_half_orders_in_the_torque_reaction_only(engine):
    """Oracle: cylinder 3 at 90 % IMEP breaks the 180-deg periodicity of the torque, so
    half orders appear in Mx (torque reaction); gas forces are internal, so the forces and
    the pitch/yaw moments keep their spectrum. The change in Mx is exactly minus the change
    of cylinder 3's crank torque."""
    weak = engine.with_imep_factors([1.0, 1.0, 0.9, 1.0])
    e0, e1 = engine.excitation(RPM, THETA), weak.excitation(RPM, THETA)
    s0, s1 = orders(e0.load), orders(e1.load)
    half = np.arange(s1.shape[0]) % 2 == 1
    mx_mean = abs(e1.load[:, 3].mean())
    assert np.abs(s1[1, 3]) > 0.01 * mx_mean           # order 0.5 in Mx: a few N m
    assert np.abs(s1[half, 3]).max() > 0.02 * mx_mean
    assert np.abs(s0[half]).max() < ZERO_ORDER_REL * np.abs(s0[1:]).max()
    np.testing.assert_allclose(s1[:, [0, 1, 2, 4, 5]], s0[:, [0, 1, 2, 4, 5]],
                               atol=EXACT_REL * np.abs(s0).max())
    d_mx = e1.load[:, 3] - e0.load[:, 3]
    d_t3 = e1.torque[:, 2] - e0.torque[:, 2]
    np.testing.assert_allclose(d_mx, -d_t3, atol=EXACT_REL * np.abs(e0.load[:, 3]).max())
    assert e1.imep[2] == pytest.approx(0.9 * e0.imep[2], rel=1e-9)


def test_first_order_free_forces_and_moments_vanish_for_the_flat_crank(engine):
    """Oracle: flat inline-4 crank (0, 180, 180, 0 deg at x = -1.5p, -0.5p, 0.5p, 1.5p):
    sum exp(i psi) = 0 and sum x exp(i psi) = 0, so first-order forces and moments cancel,
    also with the rotating masses left unbalanced (counterweight fraction 0)."""
    ct = dataclasses.replace(engine.crank, counterweight_fraction=0.0)
    eng = engine.replace(crank=ct).with_balancers(enabled=False)
    spec = orders(eng.generalized_load(RPM, THETA))
    assert np.abs(spec[2]).max() < ZERO_ORDER_REL * np.abs(spec[1:]).max()


def test_balancer_shafts_cancel_the_second_order_vertical_force(engine):
    """Oracle: two counter-rotating shafts at 2w with m_b r_b = 4 m r A2 / (2 * 2^2) give
    -4 m r w^2 A2 cos 2t vertically and cancel each other laterally (Lanchester). With
    e = 0, A2 from the 3-term series (error < lam^7); residual relative to the unbalanced
    2nd order < lam^7/lam."""
    eng = no_offset(engine)
    ct = eng.crank
    lam = ct.crank_radius / ct.rod_length
    mr = matching_mass_radius(ct.reciprocating_mass, ct.crank_radius,
                              sc.second_order_coefficient(lam, 3))
    off = orders(eng.with_balancers(enabled=False).generalized_load(RPM, THETA))
    on = orders(eng.with_balancers(enabled=True, mass_radius=mr).generalized_load(RPM, THETA))
    ref = abs(off[4, 2])
    assert ref == pytest.approx(4 * ct.reciprocating_mass * ct.crank_radius * OMEGA**2
                                * sc.second_order_coefficient(lam, 3), rel=lam**6)
    assert abs(on[4, 2]) < lam**6 * ref
    assert abs(on[4, 1]) < EXACT_REL * ref                 # lateral components cancel
    assert abs(on[4, 4]) < lam**6 * ref * 1.0              # shafts at x = 0: no 2nd-order pitch
    # the shipped engine carries (rounded) matching shafts: the 2nd order is gone to 1 %
    shipped = orders(engine.generalized_load(RPM, THETA))
    assert abs(shipped[4, 2]) < 0.01 * ref
    assert engine.balancer.enabled


# ----------------------------------------------------------------- engine file

def test_default_engine_file_structure(engine):
    """Oracle: the brief (names, axes) and rotation matrices being orthonormal."""
    assert Path(DEFAULT_ENGINE_PATH).is_file()
    assert [m.name for m in engine.mounts] == ["left", "right", "gearbox"]
    for m in engine.mounts:
        assert set(m.directions) == {"x", "y", "z"}
        np.testing.assert_allclose(m.rotation.T @ m.rotation, np.eye(3), atol=1e-12)
        assert np.linalg.det(m.rotation) == pytest.approx(1.0)
        assert m.position.shape == (3,)
    assert engine.body.inertia.shape == (3, 3) and engine.body.cg.shape == (3,)
    assert engine.crank.displacement == pytest.approx(1.8e-3, rel=0.01)
    np.testing.assert_allclose(np.degrees(engine.crank.firing_angles), [0, 540, 180, 360])
    assert engine.with_balancers(enabled=False).balancer.enabled is False
    assert engine.balancer.enabled is True          # copies do not touch the original



def test_rotated_crank_pins_keep_theta_zero_at_cylinder_1_firing_tdc(tmp_path, engine):
    """Oracle: only the pins' differences are geometry — the engine file with every crank-pin
    angle turned by 37 deg must load the block exactly as the shipped one (complex order
    amplitudes, i.e. magnitude and phase re cylinder-1 firing TDC, to round-off); before the
    reader referred the pins to cylinder 1, the forces took the raw pins and the firing the
    relative ones: the rotated file's forces then differed by 54 times the largest force order
    of the shipped one (the balancer shafts, phased re cylinder-1 TDC, no longer matched)."""
    pins = 'crank_pin_angles = {value = [0.0, 180.0, 180.0, 0.0], unit = "deg"}'
    turned = read_engine(_variant(tmp_path, pins, pins.replace(
        "[0.0, 180.0, 180.0, 0.0]", "[37.0, 217.0, 217.0, 397.0]")))
    np.testing.assert_allclose(turned.crank.firing_angles, engine.crank.firing_angles,
                               atol=1e-12)
    for rpm in (1500.0, 4500.0):
        _, ref = engine.excitation(rpm).order_spectrum(8.0)
        _, got = turned.excitation(rpm).order_spectrum(8.0)
        for part in (slice(0, 3), slice(3, 6)):          # forces [N], moments [N m]
            err = np.abs(got[:, part] - ref[:, part]).max() / np.abs(ref[:, part]).max()
            assert err < EXACT_REL, (rpm, part, err)

def _variant(tmp_path, old, new, count=1):
    text = Path(DEFAULT_ENGINE_PATH).read_text()
    mounts = (Path(DEFAULT_ENGINE_PATH).parent.parent / "mounts").resolve()
    assert old in text, old
    text = text.replace(old, new, count)
    (tmp_path / "engines").mkdir(exist_ok=True)
    shutil.copytree(mounts, tmp_path / "mounts", dirs_exist_ok=True)
    p = tmp_path / "engines" / "bad.toml"
    p.write_text(text)
    return p


BAD_FILES = [
    ("missing key", 'mass = {value = 195.0, unit = "kg"}', "", "body.mass"),
    ("unknown unit", 'bore = {value = 82.5, unit = "mm"}',
     'bore = {value = 82.5, unit = "furlong"}', "crank_train.bore.unit"),
    ("negative mass", 'reciprocating_mass = {value = 0.58, unit = "kg"}',
     'reciprocating_mass = {value = -0.58, unit = "kg"}', "crank_train.reciprocating_mass.value"),
    ("NaN", 'cg = {value = [200.0, 10.0, 70.0], unit = "mm"}',
     'cg = {value = [200.0, nan, 70.0], unit = "mm"}', "body.cg.value"),
    ("non-positive-definite inertia", "[[9.5, 0.0, 2.0]", "[[-9.5, 0.0, 2.0]", "body.inertia"),
    ("missing mount file", "../mounts/elastomeric-gearbox-mount-y.toml",
     "../mounts/no-such-mount.toml", "mounts.gearbox.files.y"),
    ("unknown key", "cylinders = 4", "cylinders = 4\nbore_mm = 82.5", "crank_train.bore_mm"),
    ("bad mount name", "[mounts.gearbox]", '[mounts."rear.tail"]', "mounts.rear.tail"),
    ("bad firing order", "firing_order = [1, 3, 4, 2]", "firing_order = [1, 3, 3, 2]",
     "crank_train.firing_order"),
    ("wrong dimension", 'stroke = {value = 84.2, unit = "mm"}',
     'stroke = {value = 84.2, unit = "kg"}', "crank_train.stroke.unit"),
]


@pytest.mark.parametrize("what,old,new,key", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_engine_files_name_file_and_key(tmp_path, what, old, new, key):
    """Oracle: the brief — bad input raises InputError naming the file and the key."""
    p = _variant(tmp_path, old, new)
    with pytest.raises(InputError) as info:
        read_engine(p)
    assert info.value.file == str(p)
    assert info.value.key == key, info.value.one_line()


def test_unreadable_engine_files_name_the_file(tmp_path):
    """Oracle: the brief — missing, directory and malformed files give InputError."""
    for p in (tmp_path / "nope.toml", tmp_path):
        with pytest.raises(InputError) as info:
            read_engine(p)
        assert info.value.file == str(p)
    bad = tmp_path / "broken.toml"
    bad.write_text("[engine\nname = ")
    with pytest.raises(InputError, match="not valid TOML") as info:
        read_engine(bad)
    assert info.value.file == str(bad)


def test_speed_outside_the_full_load_curve_is_an_input_error(engine):
    with pytest.raises(InputError) as info:
        engine.generalized_load(9000.0, THETA[:3])
    assert info.value.key == "combustion.full_load.speed"


# ----------------------------------------------------------------- measured traces

def _pressure_csv(speeds_rpm, theta, pressure) -> str:
    """CSV text of traces ``pressure[i_speed, i_cyl, k]`` [Pa] at angles ``theta`` [rad]
    (written in rpm, deg, bar: the format of powertrain.iotools.pressure_csv)."""
    lines = ["# cylinder pressure traces", "speed [rpm],cylinder,crank_angle [deg],pressure [bar]"]
    for i, n in enumerate(speeds_rpm):
        for c in range(pressure.shape[1]):
            lines += [f"{n:.6g},{c + 1},{math.degrees(a):.6g},{p / 1e5:.8g}"
                      for a, p in zip(theta, pressure[i, c])]
    return "\n".join(lines) + "\n"


def test_measured_traces_reproduce_the_model_load(tmp_path, engine):
    """Oracle: two routes to the same load — single-zone pressures written as a trace CSV
    (0.25-deg steps, bar to 8 digits) and read back must give the same load to the
    resampling error (< 0.5 % of the peak), and between two speeds the traces blend
    linearly."""
    speeds = [2000.0, 4000.0]
    theta_g = -np.pi + 4 * np.pi * np.arange(2880) / 2880
    traces = np.empty((2, 4, theta_g.size))
    for k, n in enumerate(speeds):
        th, pc, _ = engine.cycle_pressures(n)
        for c in range(4):
            traces[k, c] = np.interp(theta_g, th, pc[c], period=4 * np.pi)
    csv = tmp_path / "traces.csv"
    csv.write_text(_pressure_csv(speeds, theta_g, traces))
    text = Path(DEFAULT_ENGINE_PATH).read_text()
    start = text.index("[combustion]")
    text = text[:start] + f'[combustion]\nmodel = "measured"\ntraces = "{csv.name}"\n'
    mounts = (Path(DEFAULT_ENGINE_PATH).parent.parent / "mounts").resolve()
    text = text.replace("../mounts/", f"{mounts.as_posix()}/")
    ef = tmp_path / "measured.toml"
    ef.write_text(text)
    meas = read_engine(ef)
    for n in speeds:
        a, b = meas.generalized_load(n, THETA), engine.generalized_load(n, THETA)
        assert np.max(np.abs(a - b), axis=0).max() < 5e-3 * np.abs(b).max()
    mid = meas.cylinder_pressure(3000.0, THETA)
    lo, hi = meas.cylinder_pressure(2000.0, THETA), meas.cylinder_pressure(4000.0, THETA)
    np.testing.assert_allclose(mid, 0.5 * (lo + hi), rtol=1e-12)
    with pytest.raises(InputError):
        meas.generalized_load(5000.0, THETA[:3])
    csv.write_text("speed,cylinder,crank_angle [deg],pressure [bar]\n1000,1,0,1\n")
    with pytest.raises(InputError) as info:
        read_engine(ef)
    assert info.value.key == "speed" and info.value.file == str(csv)


def test_load_table_equals_the_load_at_each_speed(engine):
    """Oracle: the sweep's load table (patterns of unit gas force per cylinder and of unit
    omega^2 evaluated once, pressures interpolated with weights found once) equals
    ``generalized_load`` speed by speed to round-off (1e-12 of the peak), with one weaker
    cylinder so that the cylinders differ."""
    weak = engine.with_imep_factors([1.0, 1.0, 0.9, 1.0])
    speeds = np.array([1000.0, 2345.0, 6000.0])
    theta = np.linspace(-3.0, 15.0, 301)                   # beyond one cycle, both sides
    table = weak.load_table(speeds, theta)
    direct = np.stack([weak.generalized_load(n, theta) for n in speeds])
    assert table.shape == (3, 301, 6)
    assert np.abs(table - direct).max() < 1e-12 * np.abs(direct).max()


def test_pressure_tables_are_numpys_periodic_interpolation_of_each_cycle(engine):
    """Oracle: ``numpy.interp`` with the period 4 pi on each cylinder's cycle grid, at
    every load and speed, angles beyond one cycle on both sides (the same sums: exact to
    round-off)."""
    speeds, loads = np.array([1000.0, 3456.0]), [0.3, 1.0]
    theta = np.linspace(-3.0, 15.0, 301)
    table = engine.pressure_tables(speeds, theta, loads)
    local = engine.local_angles(theta)
    for j, load in enumerate(loads):
        for s, n in enumerate(speeds):
            grid, p, _ = engine.cycle_pressures(n, load)
            for c in range(p.shape[0]):
                expect = np.interp(local[:, c], grid, p[c], period=4 * np.pi)
                assert np.allclose(table[j, s, :, c], expect, rtol=1e-13, atol=0.0)


def test_the_motored_copy_is_kept_per_intake_pressure(engine):
    """The motored copy of an engine is one object per intake pressure, its own cycles
    computed once; a copy of the engine keeps none."""
    assert engine.motored() is engine.motored()
    assert engine.motored(8e4) is engine.motored(8e4) is not engine.motored(9e4)
    assert dataclasses.replace(engine).motored() is not engine.motored()


# ----------------------------------------------------------------- rigid-body modes

def test_rigid_body_frequencies_of_the_default_powertrain(engine):
    """Six rigid-body modes on the static stiffness of the thesis mounts; expected in the
    5-20 Hz band. Oracle: an independent 6×6 eigenproblem built here from each mount's 0 Hz
    cross-point stiffness rotated to engine axes, K = sum B^T R diag(k) R^T B with
    B = [I, -skew(p - cg)], must give the assembly's frequencies (internal masses condensed)."""
    f, _ = engine.rigid_body_modes()
    print("rigid-body frequencies [Hz]:", ", ".join(f"{x:.2f}" for x in f))
    assert np.all((f > 5.0) & (f < 20.0))
    from scipy.linalg import eigh
    K = np.zeros((6, 6))
    for m in engine.mounts:
        d = m.position - engine.body.cg
        skew = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
        B = np.hstack([np.eye(3), -skew])
        k = np.diag([m.directions[a].static_stiffness() for a in "xyz"])
        K += B.T @ (m.rotation @ k @ m.rotation.T) @ B
    M = np.zeros((6, 6))
    M[:3, :3] = engine.body.mass * np.eye(3)
    M[3:, 3:] = engine.body.inertia
    f2 = np.sqrt(eigh(K, M, eigvals_only=True)) / (2 * np.pi)
    np.testing.assert_allclose(np.sort(f2), np.sort(f), rtol=1e-6)


# ----------------------------------------------------------------- command line

def test_excitation_cli_writes_csv_with_the_exact_columns(tmp_path, engine):
    """Oracle: the brief's column list; the CSV rows are the library's load."""
    from powertrain.cli import main
    out = tmp_path / "out" / "load.csv"
    png = tmp_path / "load.png"
    res = CliRunner().invoke(main, ["excitation", "--rpm", "3000", "--csv", str(out),
                                    "--plot", str(png)])
    assert res.exit_code == 0, res.output
    assert "IMEP" in res.output and "order" in res.output
    lines = out.read_text().splitlines()
    header = lines[0].split(",")
    assert header[:7] == ["crank_angle_deg", "fx_n", "fy_n", "fz_n", "mx_nm", "my_nm", "mz_nm"]
    assert len(header) == 7 + 4 * 4
    data = np.loadtxt(out, delimiter=",", skiprows=1)
    assert data.shape == (1440, len(header))
    np.testing.assert_allclose(data[:, 0], np.degrees(THETA), atol=1e-6)
    ref = engine.generalized_load(3000.0, THETA)
    np.testing.assert_allclose(data[:, 1:7], ref, rtol=1e-8, atol=1e-6 * np.abs(ref).max())
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("args,key", [
    (["--rpm", "9000"], "combustion.full_load.speed"),
    (["--rpm", "-5"], "--rpm"),
    (["--rpm", "3000", "--step", "0.7"], "--step"),
    (["--rpm", "3000", "--engine", "no/such/engine.toml"], None),
])
def test_excitation_cli_errors_leave_no_file(tmp_path, args, key):
    """Oracle: the CLI contract — one line on stderr, exit code 1, no output written."""
    from powertrain.cli import main
    out = tmp_path / "load.csv"
    png = tmp_path / "load.png"
    res = CliRunner().invoke(main, ["excitation", *args, "--csv", str(out), "--plot", str(png)])
    assert res.exit_code == 1
    msg = res.stderr if hasattr(res, "stderr") else res.output
    assert msg.startswith("error:") and msg.count("\n") == 1
    if key:
        assert f"key '{key}'" in msg
    assert not out.exists() and not png.exists()
    assert list(tmp_path.iterdir()) == []


def test_math_helpers():
    """Oracle: the series coefficient against an FFT of the exact acceleration (e = 0)."""
    lam = 0.3
    th = 2 * np.pi * np.arange(4096) / 4096
    a2 = -np.fft.rfft(sc.piston_kinematics(th, lam, 1.0)[2] / lam)[2].real * 2 / 4096
    assert abs(a2 - sc.second_order_coefficient(lam, 3)) < lam**7
    assert math.isclose(sc.second_order_coefficient(lam, 1), lam)


def test_crank_volume_is_kept_per_grid_and_read_only():
    """``CrankTrain.volume`` keeps its last grid's result (the combustion models ask for the
    same grid at every speed and cylinder): equal to the kinematics on any grid, read-only,
    recomputed when the grid changes; a replaced crank train starts afresh."""
    crank = read_engine(DEFAULT_ENGINE_PATH).crank
    for n in (720, 360, 720):
        theta = np.linspace(-np.pi, 3 * np.pi, n, endpoint=False)
        V, dV = crank.volume(theta)
        want = sc.cylinder_volume(theta, crank.bore, crank.crank_radius, crank.rod_length,
                                  crank.pin_offset, crank.compression_ratio)
        np.testing.assert_array_equal(V, want[0])
        np.testing.assert_array_equal(dV, want[1])
        assert crank.volume(theta.copy())[0] is V and not V.flags.writeable
    other = dataclasses.replace(crank, compression_ratio=crank.compression_ratio + 1.0)
    assert not np.array_equal(other.volume(theta)[0], V)


def test_load_table_keeps_its_patterns_per_grid_and_equals_the_generalized_load():
    """``Engine.load_table`` keeps the unit-load patterns of its last crank-angle grid (the
    amplitude truth runs hundreds of one-speed run-ups on one engine): on a repeated, a new
    and the first grid again it equals ``generalized_load`` at every speed to round-off, and
    the kept patterns are read-only."""
    engine = read_engine(DEFAULT_ENGINE_PATH)
    rpm = np.array([1500.0, 4200.0])
    for n in (720, 360, 720, 720):
        theta = np.arange(n) * (4 * np.pi / n)
        table = engine.load_table(rpm, theta)
        for i, r in enumerate(rpm):
            want = engine.generalized_load(r, theta)
            np.testing.assert_allclose(table[i], want, rtol=1e-10,
                                       atol=1e-9 * np.abs(want).max())
    gas, inertia = engine._cache["load patterns"][1]
    assert engine.load_table(rpm, theta.copy()) is not table
    assert engine._cache["load patterns"][1][1] is inertia and not inertia.flags.writeable
    assert all(not g.flags.writeable for g in gas)
