"""Transient manoeuvres (issue 38): the manoeuvre file's checks, the linear limit against the
run-up, the discrete energy balance over a start, rest after a stop and the static operating
point under a held torque, the ISO 2631-1 weightings against the standard's table, and the
command line."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import DEFAULT_ENGINE, EXAMPLES, shared_engine
from transient_oracle import Curves, Oracle, integrate, with_curve_laws, write_case

import powertrain as pt
from powertrain.analysis.alignment import AlignmentWarning
from powertrain.analysis.comfort import weighting_analog
from powertrain.analysis.orders import order_spectrum
from powertrain.cli.group import main
from powertrain.iotools.engine_file import read_engine
from powertrain.iotools.manoeuvre_file import read_manoeuvre
from powertrain.iotools.raw_hdf5 import write_raw_hdf5
from powertrain.models.manoeuvre import Manoeuvre
from powertrain.models.recording import RawRecording
from powertrain.physics.mount_laws import BergFriction, PowerLaw
from powertrain.solvers.newmark import newmark, newmark_ports
from powertrain.solvers.operating_point import StaticSupport, operating_point
from powertrain.solvers.transient import StretchRuleWarning, simulate_transient
from powertrain.solvers.transient_load import TorqueLimitWarning, transient_load
from powertrain.workflows.transient_recording import compare_transient
from powertrain.workflows.whatif import command_variants, variant_engine

#: Linear limit: order levels of the transient held at one speed vs the run-up's Newmark
#: stepper, |dB| <= 0.05 (issue 38). Both integrate the same load with the same step from
#: the same harmonic start, so only round-off and the load table's interpolation (exact on
#: the grid) separate them; measured 3e-6 dB.
LINEAR_LIMIT_DB = 0.05
#: Energy balance over a start: input work = kinetic + stored + dissipated, relative to the
#: input work, <= 0.5 % (issue 38). The trapezoidal rule (Newmark average acceleration)
#: conserves the discrete energy exactly, so round-off alone is left (measured ~1e-12).
ENERGY_REL = 5e-3
#: The laws of the nonlinear energy balance (scripts/bench_nonlinear_runup.py's).
BERG = BergFriction(max_force=40.0, half_displacement=5e-5)
POWER = PowerLaw(reference=1e-4, exponent=0.15, limits=(0.2, 5.0))
#: Rest after a stop: every mount deflection within 0.01 mm of the zero-torque static point
#: (issue 38), linear mounts.
REST_M = 1e-5
#: Held torque: the mean deflection over the last two engine cycles within 0.01 mm of the
#: static operating point of that torque (linear mounts: the static stiffness is the
#: networks' at 0 Hz; the firing's order content has no mean).
HELD_M = 1e-5
#: Independent check: the transient against solve_ivp (Radau, rtol 1e-8) on the same laws,
#: |difference| <= 1 % of the peak deflection and of the peak force (issue 38). Both follow
#: the same stretch rule, so what is left is the Newmark step (1 deg at the top speed).
IVP_REL = 0.01
#: The stretch rule against the curve itself at every instant: |difference| <= 2 % of the
#: peak deflection and force (the curves' linearisation over 2 ms, the same amplitude law
#: and centres; 0.15 % measured on the force).
CURVE_REL = 0.02
#: ISO 2631-1 Table 3 (weighting factors x 1000, printed to 3 digits): 0.5 unit of the last
#: printed digit, plus 1e-3 relative for the printed rounding of the frequencies.
ISO_TABLE_ABS = 0.5e-3 + 1e-3

GOOD = """
[manoeuvre]
name = "t"
crank_inertia = {value = 0.18, unit = "kg*m^2"}
[speed]
time = {value = [0.0, 0.2, 0.5], unit = "s"}
speed = {value = [0.0, 250.0, 900.0], unit = "rpm"}
[load]
time = {value = [0.0, 0.5], unit = "s"}
imep_scale = {value = [0.0, 0.1], unit = "1"}
"""

STARTER = """[starter]
ratio = {value = 13.0, unit = "1"}
reaction_point = {value = [380.0, -160.0, -120.0], unit = "mm"}
until = {value = 0.2, unit = "s"}
"""

#: name -> (text replaced, replacement, key named in the error)
BAD = {
    "non-monotonic time": ("[0.0, 0.2, 0.5], unit = \"s\"}\nspeed",
                           "[0.0, 0.3, 0.2], unit = \"s\"}\nspeed", "speed.time"),
    "negative speed": ("[0.0, 250.0, 900.0]", "[0.0, -50.0, 900.0]", "speed.speed"),
    "gap": ("[0.0, 0.2, 0.5], unit = \"s\"}\nspeed", "[0.0, 0.2, 9.5], unit = \"s\"}\nspeed",
            "speed.time"),
    "load ends early": ("time = {value = [0.0, 0.5], unit = \"s\"}\nimep",
                        "time = {value = [0.0, 0.4], unit = \"s\"}\nimep", "load.time"),
    "missing column": ("imep_scale = {value = [0.0, 0.1], unit = \"1\"}", "", "load"),
    "missing speed": ("speed = {value = [0.0, 250.0, 900.0], unit = \"rpm\"}", "",
                      "speed.speed"),
    "10-hour profile": ("[0.0, 0.2, 0.5], unit = \"s\"}\nspeed",
                        "[0.0, 0.2, 36000.0], unit = \"s\"}\nspeed", "speed.time"),
    "not from 0": ("[0.0, 0.2, 0.5], unit = \"s\"}\nspeed",
                   "[0.1, 0.2, 0.5], unit = \"s\"}\nspeed", "speed.time"),
    "wrong unit": ("unit = \"rpm\"", "unit = \"N\"", "speed.speed.unit"),
    "unknown key": ("name = \"t\"", "name = \"t\"\nspeeed = 1", "manoeuvre.speeed"),
    "huge crank inertia": ("value = 0.18, unit", "value = 1e12, unit", "manoeuvre.crank_inertia"),
    "no crank inertia where the speed changes": (
        'crank_inertia = {value = 0.18, unit = "kg*m^2"}', "", "manoeuvre.crank_inertia"),
    "huge gear ratio": ('name = "t"', 'name = "t"\ngear_ratio = {value = 1e9, unit = "1"}',
                        "manoeuvre.gear_ratio"),
    "starter ratio": ("[load]", STARTER.replace("13.0", "1e12") + "[load]", "starter.ratio"),
    "starter far away": ("[load]", STARTER.replace("380.0", "3.8e9") + "[load]",
                         "starter.reaction_point"),
    "motored intake pressure": ('imep_scale = {value = [0.0, 0.1], unit = "1"}',
                                'imep_scale = {value = [0.0, 0.1], unit = "1"}\n'
                                'motored_intake_pressure = {value = 10.0, unit = "bar"}',
                                "load.motored_intake_pressure"),
    "trigger after the end": ('name = "t"', 'name = "t"\ntrigger_time = {value = 0.5, unit = "s"}',
                              "manoeuvre.trigger_time"),
    "negative trigger": ('name = "t"', 'name = "t"\ntrigger_time = {value = -1, unit = "ms"}',
                         "manoeuvre.trigger_time.value"),
    "too many rows": ("[0.0, 0.2, 0.5], unit = \"s\"}\nspeed",
                      "[" + ", ".join(str(i * 1e-3) for i in range(5000))
                      + "], unit = \"s\"}\nspeed", "speed.time.value"),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_bad_manoeuvre_file_is_one_line_naming_file_and_key(name, tmp_path):
    old, new, key = BAD[name]
    assert old in GOOD, name
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace(old, new), encoding="utf-8")
    with pytest.raises(pt.InputError) as err:
        read_manoeuvre(path)
    text = str(err.value)
    assert "\n" not in text and str(path) in text and f"'{key}'" in text, text


@pytest.mark.parametrize("change, key", [
    (dict(time=[0.0, 1.0, 0.5, 3.0]), "speed.time"),                     # backwards
    (dict(time=[0.0, 1.0, 1.0, 3.0]), "speed.time"),                     # repeated
    (dict(speed=[0.0, np.nan, 50.0, 80.0]), "speed.speed"),
    (dict(speed=[0.0, -5.0, 50.0, 80.0]), "speed.speed"),                # no reversal
    (dict(time=[0.0, 1.0, 2.0, 4.0]), "load.time"),                      # load ends early
    (dict(time=["a", "b", "c", "d"]), "speed.time"),                     # not numbers
])
def test_a_manoeuvre_built_in_python_is_checked_as_its_file(change, key):
    """The model checks itself: an object made in a notebook gets the file's one-line
    errors (pt.InputError naming the key), not an IndexError deep in the solver."""
    m = read_manoeuvre(EXAMPLES / "start.toml")
    table = {"time": [0.0, 1.0, 2.0, 3.0], "speed": [0.0, 30.0, 50.0, 80.0], **change}
    with pytest.raises(pt.InputError) as err:
        m.with_speed(table["time"], table["speed"])
    assert f"'{key}'" in str(err.value) and "\n" not in str(err.value), str(err.value)


def test_a_hold_may_be_longer_than_the_gap_rule(tmp_path):
    """Rows more than 5 s apart are a gap only where the value changes between them."""
    path = tmp_path / "hold.toml"
    path.write_text(GOOD.replace('"s"}\nimep_scale = {value = [0.0, 0.1]',
                                 '"s"}\nimep_scale = {value = [0.1, 0.1]')
                    .replace("time = {value = [0.0, 0.5], unit = \"s\"}\nimep",
                             "time = {value = [0.0, 59.0], unit = \"s\"}\nimep"),
                    encoding="utf-8")
    assert read_manoeuvre(path).load_time[-1] == 59.0


def test_a_good_file_reads_in_si_and_the_crank_angle_is_exact(tmp_path):
    path = tmp_path / "good.toml"
    path.write_text(GOOD, encoding="utf-8")
    m = read_manoeuvre(path)
    w = 250.0 * np.pi / 30.0
    theta, omega, alpha = m.crank_motion([0.1, 0.2])
    assert omega[1] == pytest.approx(w) and alpha[0] == pytest.approx(w / 0.2)
    assert theta[1] == pytest.approx(0.5 * w * 0.2)            # area under the ramp


def stiffer(engine):
    """``engine`` with every mount 50 % stiffer (springs, dampers and masses)."""
    return variant_engine(engine, command_variants(engine, {"scale": ["*.*.dynamic=1.5"]})[0])[0]


def _held(rpm, seconds, torque=None, gear=0.0):
    """A manoeuvre held at ``rpm``; full IMEP scale, or a mean torque step 0 -> ``torque``
    over 0.1..0.3 s."""
    w = rpm * np.pi / 30.0
    if torque is None:
        return Manoeuvre("held", np.array([0.0, seconds]), np.full(2, w),
                         np.array([0.0, seconds]), np.ones(2))
    return Manoeuvre("held", np.array([0.0, seconds]), np.full(2, w),
                     np.array([0.0, 0.1, 0.3, seconds]), np.array([0.0, 0.0, torque, torque]),
                     "mean_torque", gear, 0.18)


def test_linear_limit_gives_the_runup_order_levels(default_engine):
    rpm, cycles = 2000.0, 6
    run = simulate_transient(default_engine,
                             _held(rpm, cycles * 4 * np.pi / (rpm * np.pi / 30.0)))
    n = 720                                                  # 1 deg steps, one cycle
    ours = order_spectrum(run.velocity[-2 * n - 1:-1, :9], 4).T
    ref = pt.runup(default_engine, rpm=[rpm]).velocity[0]
    big = np.abs(ref) > 1e-3 * np.abs(ref).max()
    db = 20 * np.log10(np.abs(ours[big]) / np.abs(ref[big]))
    assert np.max(np.abs(db)) <= LINEAR_LIMIT_DB, np.max(np.abs(db))


def test_the_energy_balance_closes_over_a_start(default_engine):
    system = default_engine.assemble()
    m = read_manoeuvre(EXAMPLES / "start.toml")
    run = simulate_transient(default_engine, m, system=system)
    # every coordinate: the one linear stretch run again, its body the transient's
    t = run.load.t
    F = np.zeros((t.size, system.n_dof))
    F[:, :6] = run.load.F
    x, v, _ = newmark(system.M, system.C, system.K, F, t[1] - t[0])
    assert np.allclose(x[:, :6], run.body, atol=1e-9 * np.abs(run.body).max())
    h = t[1] - t[0]
    work = np.sum(np.einsum("ij,ij->i", np.diff(x, axis=0), 0.5 * (F[1:] + F[:-1])))
    vm = 0.5 * (v[1:] + v[:-1])
    dissipated = h * np.sum(np.einsum("ij,jk,ik->i", vm, system.C, vm))
    end = 0.5 * (v[-1] @ system.M @ v[-1] + x[-1] @ system.K @ x[-1])
    assert abs(work - end - dissipated) <= ENERGY_REL * abs(work), (work, end, dissipated)


def _curve_potential(curves, d0, u):
    """Each curve's potential from its zero-torque deflection ``d0`` over the deflection
    ``u`` [J] (Gauss-Legendre, 40 nodes on the piecewise cubic's span)."""
    s, w = np.polynomial.legendre.leggauss(40)
    f = np.array([curves(d0 + 0.5 * (1 + si) * u)[0] for si in s]) - curves(d0)[0]
    return 0.5 * u * (w @ f)


def _berg_releasable(z):
    """Energy a Berg element carrying ``z`` [N] gives back unloading to 0 [J] (its branch
    from a reversal there, :data:`BERG`)."""
    fm, x2 = BERG.max_force, BERG.half_displacement
    d = -np.sign(z)
    y = np.linspace(0.0, 1.0, 2001)[:, None] * (-z * x2 * (1 - d * z / fm) / fm)
    f = z + y * (fm - d * z) / (x2 * (1 - d * z / fm) + d * y)
    return -np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(y, axis=0), axis=0)


def _energy(engine, m):
    """Terms of the energy balance over ``m`` from the run's outputs [J] (see the test)."""
    system = engine.assemble()
    run = simulate_transient(engine, m, system=system)
    X, V, Z, S, c = (run.coordinates, run.coordinate_velocity, run.port_law_force,
                     run.network_scales, run.curve_load)
    h, n_t = run.load.t[1] - run.load.t[0], X.shape[0]
    F = np.zeros_like(X)
    F[:, :6] = run.load.F
    Cp, Kp, _, _ = system.network_parts()
    R, U, dX = system.port_rows, X @ system.port_rows.T, np.diff(X, axis=0)
    vm, xm = 0.5 * (V[1:] + V[:-1]), 0.5 * (X[1:] + X[:-1])
    sup = StaticSupport.of(engine)
    curves = Curves(sup.curves)
    d0 = operating_point(engine, 1000.0, sup, mean_torque=0.0).deflection.ravel()
    k0, f0 = sup.stiffness, curves(d0)[0]
    sub = run.curve_steps
    lo = np.arange(n_t - 1) // sub                              # each step's curve piece
    start = np.arange(0, n_t - 1, sub)                          # read at its predicted middle
    um = U[start] + 0.5 * h * np.minimum(sub, n_t - 1 - start)[:, None] * (V[start] @ R.T)
    at = np.array([curves(d0 + u) for u in um])                 # (pieces, 2, n_net)
    fs = at[lo, 1] / curves.ref_tangent                         # static factors
    c1 = at[lo, 0] - f0 - fs * k0 * um[lo]                      # curve loads, law at 1
    el = np.zeros(n_t - 1)
    visc = np.zeros(n_t - 1)
    for n in range(R.shape[0]):
        el += (S[:-1, n, 0] - fs[:, n]) * np.einsum("ij,ij->i", dX @ Kp[n], xm)
        visc += S[:-1, n, 1] * np.einsum("ij,ij->i", vm @ Cp[n], vm)
    ports = system.port_forces()
    du = np.diff(X @ ports.rows.T, axis=0)
    dyn = np.einsum("n,na,na->n", S[-1, :, 0], X[-1] @ Kp, X[-1][None, :]) \
        - S[-1, :, 0] * k0 * U[-1] ** 2
    return {"input": np.sum(np.einsum("ij,ij->i", dX, 0.5 * (F[1:] + F[:-1]))),
            "kinetic": 0.5 * V[-1] @ system.M @ V[-1],
            "curves": np.sum(_curve_potential(curves, d0, U[-1])),
            "networks": 0.5 * np.sum(dyn),
            "friction held": np.sum(_berg_releasable(Z[-1])),
            "viscous": h * np.sum(visc),
            "friction": np.sum(0.5 * (Z[1:] + Z[:-1]) * du) - np.sum(_berg_releasable(Z[-1])),
            "amplitude law": np.sum(el) + np.sum((c[:-1] - c1) * np.diff(U, axis=0))}


@pytest.mark.filterwarnings("ignore::powertrain.solvers.transient.StretchRuleWarning")
@pytest.mark.parametrize("laws", ["curve+friction", "curve+friction+amplitude"])
def test_the_energy_balance_closes_over_a_start_on_nonlinear_mounts(default_engine, laws):
    """Every mount direction on a static curve with Berg's friction (and the power law),
    the start of examples/start.toml, each term from the run's outputs: input work (load
    on the body) = kinetic (every coordinate) + stored (the curves' potential from the
    zero-torque point, integrated here from the written-out curves; the networks' springs
    beyond their static part; what the friction elements give back unloading) +
    dissipated (dampers; friction; the amplitude law: the work of its scale on the springs
    and curve loads, stretch by stretch, against the same stretches at scale 1), within
    0.5 % of the input (issue 38). Measured 0.082 % without the amplitude law, 0.093 %
    with it, whose term takes 2.3 % of the input: the law's scale on the motion about each
    stretch's centre changes from stretch to stretch with the amplitude, a loop about the
    centre."""
    extra = {"amplitude_law": POWER} if laws.endswith("amplitude") else {}
    engine = with_curve_laws(default_engine, port_law=BERG, **extra)
    e = _energy(engine, read_manoeuvre(EXAMPLES / "start.toml"))
    out = sum(v for k, v in e.items() if k != "input")
    assert abs(e["input"] - out) <= ENERGY_REL * e["input"], e
    assert min(e["viscous"], e["friction"]) > 0.0, e
    assert e["amplitude law"] >= -1e-6 * e["input"], e       # 0 without a law, to round-off


def test_the_stretch_kernel_steps_as_the_public_newmark_with_port_laws(default_engine):
    """Berg's friction on every mount direction, no curve, no amplitude law: the start is one
    piece of the stretch kernel, which must give the states and port forces that the public
    wrapper :func:`newmark_ports` gives on the assembled matrices and the same load."""
    mounts = [dataclasses.replace(m, directions={
        a: dataclasses.replace(mod, port_law=BERG) for a, mod in m.directions.items()})
        for m in default_engine.mounts]
    engine = dataclasses.replace(default_engine, mounts=mounts)
    m = read_manoeuvre(EXAMPLES / "start.toml")
    run = simulate_transient(engine, m)
    s = engine.assemble()
    F = np.zeros((run.load.t.size, s.n_dof))
    F[:, :6] = run.load.F
    ports = s.port_forces()
    X, _, _, Z = newmark_ports(s.M, s.C, s.K, F, run.load.t[1], ports)
    assert run.curve_steps == run.load.t.size - 1 and ports.kinds.size == 9
    assert np.max(np.abs(run.coordinates - X)) <= 1e-9 * np.max(np.abs(X))
    assert np.max(np.abs(run.port_law_force - Z)) <= 1e-9 * np.max(np.abs(Z))


def test_after_a_stop_the_body_rests_at_the_zero_torque_point(default_engine):
    run = simulate_transient(default_engine, read_manoeuvre(EXAMPLES / "stop.toml"))
    assert np.max(np.abs(run.deflection[-1])) <= REST_M
    assert np.max(np.abs(run.deflection)) > 10 * REST_M          # it did move


def test_under_a_held_torque_the_body_sits_at_its_static_operating_point(default_engine):
    rpm, torque, gear = 1500.0, 100.0, 2.1
    run = simulate_transient(default_engine, _held(rpm, 1.6, torque, gear))
    n = int(round(2 * 4 * np.pi / (rpm * np.pi / 30.0) / (run.load.t[1] - run.load.t[0])))
    mean = run.deflection[-n - 1:-1].mean(axis=0)
    op0 = operating_point(default_engine, rpm, mean_torque=0.0)
    op = operating_point(default_engine, rpm, mean_torque=gear * torque)
    static = (op.deflection - op0.deflection).ravel()
    assert np.max(np.abs(mean - static)) <= HELD_M, np.abs(mean - static).max()
    assert np.max(np.abs(static)) > 0.5e-3                      # a real roll, 0.5 mm+


@pytest.mark.parametrize("kind", ["imep_scale", "mean_torque"])
def test_the_load_table_runs_from_the_cycle_without_burn_to_full_load(default_engine, kind):
    """IMEP scale 0 is the motored cycle (no burn: its brake torque is the friction's and
    the pumping's drag), s0 the fired cycle of zero torque, 1 the full load; a negative
    mean torque (engine braking) is as much of that drag."""
    rpm, e = 1500.0, default_engine
    drag = e.motored().mean_brake_torque(rpm)
    work = [np.sum(e.indicated_work(rpm, x)) for x in (0.0, 1.0)]
    s0 = work[0] / work[1]
    values = ([0.0, 0.5 * s0, s0, 1.0] if kind == "imep_scale"
              else [drag, 0.5 * drag, 0.0, e.mean_brake_torque(rpm)])
    w = rpm * np.pi / 30.0
    t = np.arange(4.0)
    m = Manoeuvre("held", np.array([0.0, 3.0]), np.full(2, w), t, np.array(values), kind)
    load = transient_load(e, m, t)
    expected = [drag, 0.5 * drag, 0.0, e.mean_brake_torque(rpm)]
    assert drag < -5.0                                      # friction and pumping
    np.testing.assert_allclose(load.engine_torque, expected, atol=1e-6 * abs(expected[-1]))
    np.testing.assert_allclose(load.scale, [0.0, 0.5 * s0, s0, 1.0], atol=1e-12)
    throttled = dataclasses.replace(m, motored_intake_pressure=0.35e5)
    assert transient_load(e, throttled, t).engine_torque[0] != load.engine_torque[0]
    assert read_manoeuvre(EXAMPLES / "stop.toml").motored_intake_pressure == 0.35e5


def test_a_mean_torque_beyond_the_engine_is_said(default_engine):
    """Review 2: 500 N m from an engine of 250 N m full load (or braking beyond its motored
    drag) is not silently cut: a TorqueLimitWarning says when and how much."""
    w = 1500.0 * np.pi / 30.0
    m = Manoeuvre("over", np.array([0.0, 1.0]), np.full(2, w), np.array([0.0, 1.0]),
                  np.array([500.0, -500.0]), "mean_torque", 2.1, 0.18)
    with pytest.warns(TorqueLimitWarning, match="beyond what the engine gives"):
        transient_load(default_engine, m, np.linspace(0.0, 1.0, 11))


def test_the_motored_cycle_is_the_polytropes_closed_form(default_engine):
    """Without burn the pressure at firing TDC is the intake pressure compressed from BDC
    along n_c to the start of combustion, then along n_e (physics/combustion.py's model):
    p = p_i (V_BDC/V_s)^n_c (V_s/V_TDC)^n_e, to the grid's rounding."""
    c, crank = default_engine.combustion, default_engine.crank
    theta, p, _ = c.motored_pressures(crank, 150.0, 0.8e5)
    tdc, bdc = int(np.argmin(np.abs(theta))), int(np.argmin(np.abs(theta + np.pi)))
    V = crank.volume(np.array([-np.pi, c.start, theta[tdc]]))[0]
    closed = 0.8e5 * (V[0] / V[1]) ** c.n_compression * (V[1] / V[2]) ** c.n_expansion
    assert p[0, bdc] == pytest.approx(0.8e5, rel=1e-9)
    np.testing.assert_allclose(p[:, tdc], closed, rtol=1e-6)


def test_a_held_torque_on_static_curves_starts_at_its_static_point():
    """back-out.toml starts at 1500 rpm under 200 N m in 2nd gear: on the static curves of
    default-nonlinear.toml the body starts where the curves hold that torque (before the
    start was on the zero-torque tangents: right.z 2.8 mm off, its jolt the peak force)."""
    engine = shared_engine(DEFAULT_ENGINE.parent / "default-nonlinear.toml")
    m = read_manoeuvre(EXAMPLES / "back-out.toml")
    run = simulate_transient(engine, m)
    op0 = operating_point(engine, 1500.0, mean_torque=0.0)
    op = operating_point(engine, 1500.0, mean_torque=m.gear_ratio * 200.0)
    static = (op.deflection - op0.deflection).ravel()
    first = run.deflection[run.load.t <= 0.1].mean(axis=0)
    assert np.max(np.abs(static)) > 5e-3                          # 6.5 mm on left.z
    assert np.max(np.abs(first - static)) <= 5e-5, np.abs(first - static).max()


@pytest.mark.parametrize("name, freq, table", [
    ("Wk", [1.0, 2.0, 4.0, 6.3, 8.0, 16.0, 31.5, 63.0],
     [0.482, 0.531, 0.967, 1.054, 1.036, 0.768, 0.405, 0.186]),
    ("Wd", [1.0, 2.0, 4.0, 8.0, 16.0], [1.011, 0.890, 0.512, 0.253, 0.125]),
])
def test_iso_2631_weightings_give_the_standards_table(name, freq, table):
    num, den = weighting_analog(name)
    s = 2j * np.pi * np.asarray(freq, float)
    gain = np.abs(np.polyval(num, s) / np.polyval(den, s))
    assert np.allclose(gain, table, rtol=1e-3, atol=ISO_TABLE_ABS)


def test_the_command_writes_what_it_says_and_reports_the_seat(tmp_path):
    modal = shared_engine(EXAMPLES.parent / "engines" / "default-modal-body.toml").file
    (tmp_path / "m.toml").write_text(GOOD, encoding="utf-8")
    args = ["transient", str(tmp_path / "m.toml"), "--engine", modal, "--json",
            str(tmp_path / "s.json"), "--csv", str(tmp_path / "s.csv")]
    res = CliRunner().invoke(main, args)
    assert res.exit_code == 0, res.output
    assert "seat seat_rail (ISO 2631-1)" in res.output and "wrote" in res.output
    doc = json.loads((tmp_path / "s.json").read_text())
    assert doc["seat"]["weighted_rms_m_per_s2"]["z"] > 0
    assert doc["channels"]["left.z"]["peak_to_peak_displacement_mm"] > 0
    head = (tmp_path / "s.csv").read_text().splitlines()[1].split(",")
    assert head[:3] == ["time_s", "rpm", "engine_torque_nm"]


def test_a_recorded_speed_drives_the_same_run(default_engine, tmp_path):
    """A run written as raw time data (rpm channel) and read back with ``speed_from``
    gives the same peaks: the speed table is the recording's, within its block means."""
    (tmp_path / "m.toml").write_text(GOOD, encoding="utf-8")
    first = pt.transient(tmp_path / "m.toml", default_engine)
    write_raw_hdf5(tmp_path / "raw.h5", first.recording(), synthetic=True)
    again = pt.transient(tmp_path / "m.toml", default_engine, speed_from=tmp_path / "raw.h5")
    a, b = first.peaks(), again.peaks()
    assert np.allclose(b["max_acceleration"][:9], a["max_acceleration"][:9], rtol=0.01)
    assert np.allclose(b["peak_force"][:9], a["peak_force"][:9], rtol=0.01)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::powertrain.solvers.transient.StretchRuleWarning")
def test_solve_ivp_on_the_laws_written_out_agrees(tmp_path):
    """One mount direction with a static curve, an amplitude law and Berg's friction on a
    6-DOF body (every other direction Kelvin-Voigt), a 0.12 s flare from rest: Radau at
    rtol 1e-8 on the laws written out (tests/transient_oracle.py) and the transient agree
    within 1 % of the peak deflection and force (measured 0.001 %; 0.1 % before the
    acceleration was solved anew at each change of the laws)."""
    run, oracle, net, ch = _one_direction_flare(tmp_path, continuous=False)
    U, F = integrate(oracle, run.stretch_steps, curve_every=run.curve_steps)
    u, force = U[:, net], F[:, ch]
    assert np.max(np.abs(u)) > 3e-3                                  # millimetres on the curve
    assert np.max(np.abs(run.deflection[:, net] - u)) <= IVP_REL * np.max(np.abs(u))
    assert np.max(np.abs(run.force[:, ch] - force)) <= IVP_REL * np.max(np.abs(force))


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::powertrain.solvers.transient.StretchRuleWarning")
def test_the_stretch_rule_tends_to_the_curve_itself_under_an_amplitude_law(tmp_path):
    """The same flare against the curve evaluated at every instant (``continuous=True``,
    the amplitude law per stretch about the networks' centres as in the transient): the
    curves' linearisation over 2 ms stays within 2 % of the peak deflection and force
    (measured 0.002 % and 0.09 % about each piece's predicted middle; 0.02 % and 0.15 %
    about its start; 3.3 % and 15 % when every 10 ms stretch's start put the force back on
    the curve with the law's scale on the whole tangent)."""
    run, oracle, net, ch = _one_direction_flare(tmp_path, continuous=True)
    U, F = integrate(oracle, run.stretch_steps)
    u, force = U[:, net], F[:, ch]
    assert np.max(np.abs(run.deflection[:, net] - u)) <= CURVE_REL * np.max(np.abs(u))
    assert np.max(np.abs(run.force[:, ch] - force)) <= CURVE_REL * np.max(np.abs(force))


def _one_direction_flare(tmp_path, continuous):
    """A 0.12 s flare from rest on a 6-DOF body whose left.z has a static curve, the power
    law and Berg's friction (every other direction Kelvin-Voigt): the transient, the
    oracle on the same load, the network and channel index of left.z."""
    engine = read_engine(write_case(tmp_path, DEFAULT_ENGINE.read_text(encoding="utf-8")))
    system = engine.assemble()
    assert system.n_dof == 6 and system.port_forces().names == ["left.z"]
    w = 900.0 * np.pi / 30.0
    m = Manoeuvre("flare", np.array([0.0, 0.12]), np.array([0.0, w]), np.array([0.0, 0.12]),
                  np.zeros(2), crank_inertia=0.3)
    run = simulate_transient(engine, m, system=system)
    net = system.network_names.index("left.z")
    ch = [f"{a}.{b}" for a, b in system.channels].index("left.z")
    oracle = Oracle(engine, system, run.load.t, run.load.F, continuous=continuous)
    return run, oracle, net, ch


def test_whatif_over_a_manoeuvre_ranks_by_the_peak_deflection(default_engine, tmp_path):
    """Without a seat the variants are ranked by the peak mount deflection: softer mounts
    deflect more under the same start, so they rank last."""
    (tmp_path / "m.toml").write_text(GOOD, encoding="utf-8")
    rank = pt.whatif(default_engine, scale="*.*.dynamic=0.5", manoeuvre=tmp_path / "m.toml")
    defl, _ = rank.peak_deflection()
    assert rank.names == ["baseline", "command line"] and defl[1] > defl[0]
    assert rank.to_dict()["ranking"] == ["baseline", "command line"]
    assert rank.to_dict()["ranked_by"] == "peak_mount_deflection"
    assert "ranked by peak mount deflection" in rank.to_text()


def test_a_recorded_event_is_aligned_and_its_errors_reported(default_engine, tmp_path):
    """A simulated start written as raw time data 0.1 s late with a 0.01 m/s² tone on every
    channel: compared back, the shift is recovered to a sample and the RMS of the difference
    is the tone's; a set of mounts 50 % stiffer differs by far more."""
    (tmp_path / "m.toml").write_text(GOOD, encoding="utf-8")
    first = pt.transient(tmp_path / "m.toml", default_engine)
    rec = first.recording()
    h = first.time[1] - first.time[0]
    n0 = int(round(0.1 / h))
    t = np.arange(first.time.size + n0) * h
    tone = 0.01 * np.sin(2 * np.pi * 997.0 * t)
    chans = [dataclasses.replace(c, values=np.r_[np.zeros(n0), c.values] + tone)
             for c in rec.channels]
    write_raw_hdf5(tmp_path / "raw.h5", RawRecording(t, chans, np.r_[np.zeros(n0), rec.rpm],
                                                     None, "test", ["SYNTHETIC"]),
                   synthetic=True)
    same = compare_transient(first, tmp_path / "raw.h5")
    assert abs(same.shift - n0 * h) <= h
    rms = same.errors()["rms_difference"]
    assert np.allclose(rms, 0.01 / np.sqrt(2), rtol=0.1), rms
    stiff = pt.transient(tmp_path / "m.toml", stiffer(default_engine))
    other = compare_transient(stiff, tmp_path / "raw.h5").errors()["rms_difference"]
    assert np.max(other) > 5 * np.max(rms)


def test_a_speed_above_the_combustion_model_is_refused_before_any_work(default_engine,
                                                                         tmp_path):
    path = tmp_path / "fast.toml"
    path.write_text(GOOD.replace("900.0]", "9000.0]"), encoding="utf-8")
    with pytest.raises(pt.InputError, match="above the engine's combustion model") as err:
        pt.transient(path, default_engine)
    assert str(path) in str(err.value) and "'speed.speed'" in str(err.value)


def test_speed_from_removes_the_speed_profile_part_of_a_comparison(default_engine, tmp_path):
    """A start recorded with another speed profile (300 -> 950 rpm instead of 250 -> 900):
    compared with the file's own profile, lined up where the speeds match best, the RMS
    of the difference is above a quarter of the measured RMS (measured 35-40 %); driven by
    the recorded speed (``speed_from``) it falls below 1 % (measured 0.04-0.19 %: the speed
    table's block means)."""
    (tmp_path / "m.toml").write_text(GOOD, encoding="utf-8")
    (tmp_path / "other.toml").write_text(GOOD.replace("[0.0, 250.0, 900.0]",
                                                      "[0.0, 300.0, 950.0]"), encoding="utf-8")
    recorded = pt.transient(tmp_path / "other.toml", default_engine)
    write_raw_hdf5(tmp_path / "raw.h5", recorded.recording(), synthetic=True)
    nominal = pt.transient(tmp_path / "m.toml", default_engine)
    with pytest.warns(AlignmentWarning, match="differs from the event's"):   # other profile
        driven = pt.transient(tmp_path / "m.toml", default_engine,
                              speed_from=tmp_path / "raw.h5")
    with pytest.warns(AlignmentWarning):
        before = compare_transient(nominal, tmp_path / "raw.h5")
    after = compare_transient(driven, tmp_path / "raw.h5")
    assert after.shift_error < before.shift_error / 10
    before, after = (c.errors()["rms_difference_percent"] for c in (before, after))
    assert np.min(before) > 25.0 and np.max(after) < 1.0, (before, after)


def test_a_static_curve_with_an_amplitude_law_is_said_to_be_approximate(default_engine):
    """Where a direction has both, the stretch rule is an approximation (0.6 % on the fully
    nonlinear start against the continuous curve, docs/validation.md): a warning names the
    directions; with the curve alone there is none."""
    start = read_manoeuvre(EXAMPLES / "start.toml")
    with pytest.warns(StretchRuleWarning, match=r"left\.z.*static curve and amplitude law"):
        simulate_transient(with_curve_laws(default_engine, amplitude_law=POWER), start)
    simulate_transient(with_curve_laws(default_engine, port_law=BERG), start)
