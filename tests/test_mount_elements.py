"""Mount elements plug into every stepper: a nonlinear port law (the Jenkins friction element,
closed-form describing function) integrated by the dense Newmark kernel and solved
equivalent-linearly by the harmonic and admittance steppers.

Tolerances (each stated where it is checked):
* describing function against a direct integration of the element: 1e-3 of |k_eq|; the loop
  area against the closed form's energy per cycle (pi A^2 Im k_eq): 1e-3 of 4 F_s A;
* single-DOF oscillator with friction, harmonic (describing function) against time domain:
  first-harmonic amplitude 1 %, phase 1 deg (away from a 1/3 subharmonic resonance, where
  the neglected third harmonic matters);
* zero slip force equals the linear model exactly (a zero force adds zero to the same arithmetic);
* a friction element that never slips equals the linear network with its stiffness added;
* default engine, friction on every mount direction: harmonic against dense Newmark 0.5 %.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from powertrain.assembly import assemble
from powertrain.kernels.port_forces import port_force_loop
from powertrain.physics.mount_elements import JenkinsFriction, PortForces
from powertrain.solvers import equivalent_linear
from powertrain.solvers.equivalent_linear import amplitude_fixed_point
from powertrain.solvers.newmark import newmark_ports
from powertrain.solvers.steppers import Cycles, DenseNewmarkStepper, ModalPortStepper, choose_stepper
from powertrain.workflows.runup import run_runup

RPM = [1500.0, 3000.0, 5000.0]
LAW = JenkinsFriction(3e5, 30.0)


def with_law(engine, law, directions="xyz"):
    """The engine with ``law`` in parallel with every mount direction in ``directions``."""
    mounts = [dataclasses.replace(m, directions={
        a: dataclasses.replace(mod, port_law=law) if a in directions else mod
        for a, mod in m.directions.items()}) for m in engine.mounts]
    return dataclasses.replace(engine, mounts=mounts)


@pytest.mark.parametrize("amplitude", [5e-5, 2e-4, 5e-4, 2e-3])   # stick, then slip
def test_describing_function_of_the_jenkins_element_against_direct_integration(amplitude):
    n = 4000
    t = np.arange(3 * n) / n * 2 * np.pi
    U = (amplitude * np.sin(t))[:, None]
    F = np.empty_like(U)
    port_force_loop(np.array([LAW.kind]), LAW.parameters()[None], np.array([[0.0]]), U,
                    np.zeros_like(U), F)
    f, u, tt = F[-n:, 0], U[-n:, 0], t[-n:]
    k_num = 2 / n * np.sum(f * np.exp(-1j * tt)) / (-1j * amplitude)   # u = Re(-iA e^{it})
    k_df = LAW.describing_stiffness(amplitude)
    assert abs(k_num - k_df) <= 1e-3 * abs(k_df)
    loop = abs(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(u)))             # loop area [J]
    energy = np.pi * amplitude ** 2 * k_df.imag
    # against the loop of a rigid-plastic slider, 4 F_s A
    assert abs(loop - energy) <= 1e-3 * 4 * LAW.slip_force * amplitude


def _sdof(f_hz, m=10.0, k=4e5, c=50.0, force=200.0, cycles=60, n=720):
    """A mass on a spring, a damper and a friction element under F cos(wt): the harmonic
    amplitude from the describing function and from the time domain's last cycle."""
    ports = PortForces(np.array([[1.0]]), np.array([LAW.kind]), LAW.parameters()[None],
                       [LAW], np.array([[1.0]]), ["sdof"], np.array([0]), 1)
    w = 2 * np.pi * f_hz

    def relative(X):
        out = np.zeros((17, 1), complex)
        out[2, 0] = X
        return out

    A, X = amplitude_fixed_point(
        lambda a: force / (k + 1j * w * c - w * w * m + LAW.describing_stiffness(a[0])),
        relative, ports, 0.0)
    h = 2 * np.pi / w / n
    t = np.arange(cycles * n + 1) * h
    x, *_ = newmark_ports([[m]], [[c]], [[k]], (force * np.cos(w * t))[:, None], h, ports,
                          np.array([X.real]), np.array([(1j * w * X).real]))
    last, before = x[-n - 1:-1, 0], x[-2 * n - 1:-n - 1, 0]
    X_t = 2 / n * np.sum(last * np.exp(-1j * w * t[-n - 1:-1]))
    return X, X_t, np.max(np.abs(last - before)) / np.max(np.abs(last)), A[0]


@pytest.mark.parametrize("f_hz", [20.0, 30.0, 40.0])
def test_single_dof_friction_harmonic_agrees_with_time_domain(f_hz):
    X, X_t, periodicity, A = _sdof(f_hz)
    assert A > LAW.slip_force / LAW.stiffness            # the element slips
    assert periodicity < 1e-5                            # the time run converged
    assert abs(abs(X_t) / abs(X) - 1) < 1e-2
    assert abs(np.angle(X_t / X, deg=True)) < 1.0


def test_zero_slip_force_is_the_linear_model(engine):
    free = with_law(engine, JenkinsFriction(3e5, 0.0))
    h_lin = run_runup(engine, RPM, solver="harmonic")
    h_nl = run_runup(free, RPM, solver="harmonic")
    n_lin = run_runup(engine, RPM, stepper="dense")
    n_nl = run_runup(free, RPM, stepper="dense")
    n_modal = run_runup(free, RPM)              # auto: modal with the port laws
    assert "modal with the port laws" in n_modal.settings["integrator"]
    for name in ("velocity", "mount_force", "mean_mount_force"):   # the same arithmetic
        np.testing.assert_array_equal(getattr(h_nl, name), getattr(h_lin, name))
        np.testing.assert_array_equal(getattr(n_nl, name), getattr(n_lin, name))
        # the modal recurrence starts from the acceleration of the equation of motion
        x, y = getattr(n_modal, name), getattr(n_lin, name)
        assert np.max(np.abs(x - y)) <= 1e-5 * np.max(np.abs(y)), name


def test_friction_that_never_slips_is_its_spring_in_parallel(engine):
    """Oracle: the linear network with the element's stiffness added to its E-G spring c1
    (orders only: a port law carries no mean force)."""
    stuck = with_law(engine, JenkinsFriction(LAW.stiffness, 1e9), "z")
    mounts = [dataclasses.replace(m, directions={
        **m.directions, "z": m.directions["z"].with_params(
            c1=m.directions["z"].params["c1"] + LAW.stiffness)}) for m in engine.mounts]
    spring = dataclasses.replace(engine, mounts=mounts)
    for solver, stepper in (("harmonic", "auto"), ("newmark", "dense")):
        a = run_runup(spring, RPM, solver=solver, stepper=stepper)
        b = run_runup(stuck, RPM, solver=solver, stepper=stepper)
        for name in ("velocity", "mount_force"):
            x, y = getattr(a, name), getattr(b, name)
            assert np.max(np.abs(x - y)) <= 1e-8 * np.max(np.abs(x)), (solver, name)


@pytest.fixture(scope="module")
def friction_runups(engine):
    rough = with_law(engine, LAW)
    return (run_runup(rough, RPM, solver="harmonic"), run_runup(rough, RPM),
            run_runup(engine, RPM, solver="harmonic"))


def test_friction_on_every_mount_harmonic_agrees_with_dense_newmark(friction_runups):
    harmonic, newmark, linear = friction_runups
    assert np.all(newmark.periodicity < 1e-3)
    assert np.max(np.abs(newmark.synthesis_rms() / harmonic.synthesis_rms() - 1)) < 5e-3
    # and the friction matters: the linear model is far off
    assert np.max(np.abs(linear.synthesis_rms() / harmonic.synthesis_rms() - 1)) > 0.1


def test_friction_with_a_modal_body(engine):
    """The port rows with a moving base (engine side minus body side): harmonic against
    dense Newmark on the modal-body engine."""
    from conftest import MODAL, shared_engine
    rough = with_law(shared_engine(MODAL), LAW)
    a = run_runup(rough, RPM, solver="harmonic")
    b = run_runup(rough, RPM, cycles=12)        # the body modes settle more slowly
    sa, sb = a.synthesis_rms(), b.synthesis_rms()
    moving = sa > 1e-6 * sa.max()
    assert np.max(np.abs(sb[moving] / sa[moving] - 1)) < 5e-3


def test_friction_through_the_admittance_coupling(tmp_path, engine):
    """Oracle: the modal body's receptances as a measured body (admittance stepper) give the
    modal body's equivalent-linear run-up."""
    from conftest import ENGINES, MODAL, shared_engine
    from test_chassis import _frf_csv

    from powertrain.iotools.engine_file import read_engine
    modal = shared_engine(MODAL)
    rpm = np.array(RPM)
    _frf_csv(modal, rpm, tmp_path / "body.csv")
    text = MODAL.read_text()
    text = text[:text.index("\n[chassis]\n") + 1] + (
        '[chassis]\nmodel = "frf"\nfrf = "body.csv"\n\n[chassis.points.seat_rail]\n')
    (tmp_path / "frf.toml").write_text(
        text.replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/'))
    a = run_runup(with_law(modal, LAW), rpm, solver="harmonic")
    b = run_runup(with_law(read_engine(tmp_path / "frf.toml"), LAW), rpm, solver="harmonic")
    assert a.channels == b.channels
    for sig in ("velocity", "mount_force"):
        x, y = getattr(a, sig), getattr(b, sig)
        assert np.max(np.abs(x - y)) <= 1e-6 * np.max(np.abs(x)), sig


def test_modal_stepper_refuses_a_nonlinear_model_and_auto_picks_modal_ports(engine):
    b = engine.body
    system = assemble(b.mass, b.cg, b.inertia, with_law(engine, LAW).mounts)
    grid = Cycles(720, 1.0, 6, 2)
    with pytest.raises(ValueError, match="linear models only"):
        choose_stepper(system, "newmark", "modal", grid)
    assert isinstance(choose_stepper(system, "newmark", "auto", grid), ModalPortStepper)
    assert isinstance(choose_stepper(system, "newmark", "dense", grid), DenseNewmarkStepper)
    linear = assemble(b.mass, b.cg, b.inertia, engine.mounts)
    assert linear.port_forces() is None


def test_a_fixed_point_that_does_not_converge_names_the_element_and_speed(engine,
                                                                          monkeypatch):
    monkeypatch.setattr(equivalent_linear, "MAX_ITERATIONS", 1)
    with pytest.raises(FloatingPointError, match=r"left\.[xyz] at 3000 rpm|[a-z]+\.[xyz] at "
                                                 r"3000 rpm"):
        run_runup(with_law(engine, LAW), [3000.0], solver="harmonic")


def test_elements_in_one_call_equal_each_element_alone(engine):
    """``element_two_ports`` (the fixed point's batched call: amplitude laws, array static
    factors, port laws) against ``MountElement.two_port`` of each element alone."""
    from powertrain.physics.mount_elements import MountElement, element_two_ports
    from powertrain.physics.mount_laws import PowerLaw
    models = [m.directions[ax] for m in engine.mounts for ax in ("x", "y", "z")][:4]
    static = np.array([[0.9], [1.1], [1.3]])
    els = [MountElement(models[0].network()),
           MountElement(models[1].network(), amplitude_law=PowerLaw(1e-4, 0.2), static_factor=static),
           MountElement(models[2].network(), port_law=JenkinsFriction(3e5, 20.0)),
           MountElement(models[3].network(), JenkinsFriction(2e5, 5.0), PowerLaw(1e-4, 0.1), 1.2)]
    s = 1j * np.array([0.0, 60.0, 400.0, 900.0]) * np.ones((3, 1))
    A = np.array([[1e-5, 2e-4, 5e-5, 1e-4], [3e-5, 1e-4, 2e-4, 4e-5], [1e-6, 1e-3, 1e-4, 1e-4]])
    got = element_two_ports(els, s, A[:, None, :])
    for k, el in enumerate(els):
        ref = el.two_port(s, A[:, k:k + 1])
        for x, y in zip(got, ref):
            np.testing.assert_allclose(x[..., k], y, rtol=1e-12, atol=0)
