"""Verification of the mount laws read from mount files (issue 20, item 7; the laws are
:mod:`powertrain.physics.mount_laws`, the files :mod:`powertrain.iotools.mount_file`).

Tolerances (each stated where it is checked):
* exponent 0, a flat table, a power law clipped to 1 and zero friction (max_force = 0),
  written into every mount file of the default engine, equal the linear model: harmonic and
  dense Newmark run-ups to 1e-12 of the largest value (in practice bit-identical or a few
  ulps: the same arithmetic with factors of exactly 1 and a force of exactly 0);
* Berg's describing function against a direct integration of the kernel's element
  (``kernels.port_forces.port_force_loop``, 4000 points a cycle, from the unloaded state
  until the loop repeats to 1e-12 of max_force: 157 cycles at A = 0.2 x2, 6 at 20 x2):
  1e-11 of |k_eq| (measured 1e-14 to 3e-13: the reversals fall on samples, so the sampled
  first harmonic is exact up to round-off); the loop area (the integral of F du over the
  cycle, du = A cos(t) dt, same quadrature) against the energy per cycle: 1e-11; the loop
  tips against ``loop_amplitude_force``: 1e-9;
* the static curve passes through its points to 1e-12 of the largest force, is increasing
  on a dense grid, and goes on straight beyond them with scipy's PCHIP end slope (1e-12).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import DEFAULT_ENGINE, ENGINES, MOUNTS
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

from powertrain.iotools.engine_file import read_engine
from powertrain.iotools.mount_file import read_mount
from powertrain.kernels.port_forces import port_force_loop
from powertrain.physics.mount_laws import BergFriction, StaticCurve, pchip_cubic
from powertrain.workflows.runup import run_runup

RPM = [1500.0, 3000.0, 5000.0]

#: Sections that leave every mount as it is (appended to every mount file).
NEUTRAL = {
    "exponent-0": '[amplitude]\nlaw = "power"\nreference = 0.1\nexponent = 0.0\n',
    "flat-table": '[amplitude]\nlaw = "table"\namplitudes = [0.01, 0.1, 1.0]\n'
                  'stiffness_scale = [1.0, 1.0, 1.0]\n',
    # not `constant` (exponent 0.15): the fixed point runs, the clip makes every factor 1
    "power-clipped-to-1": '[amplitude]\nlaw = "power"\nreference = 0.1\nexponent = 0.15\n'
                          'limits = [1.0, 1.0]\n',
    "zero-friction": "[friction]\nmax_force = 0.0\nhalf_displacement = 0.05\n",
}


def engine_with_sections(folder: Path, sections: str, engine=DEFAULT_ENGINE):
    """A copy of ``engine`` whose every mount file carries ``sections`` (x in mm, F in N)."""
    (folder / "engines").mkdir(parents=True, exist_ok=True)
    (folder / "mounts").mkdir(exist_ok=True)
    for p in MOUNTS.glob("*.toml"):
        text = p.read_text()
        if "\nx = " not in text:
            text = text.replace('m = "kg"\n', 'm = "kg"\nx = "mm"\nF = "N"\n')
            text += "\n" + sections
        (folder / "mounts" / p.name).write_text(text)
    shutil.copy(engine, folder / "engines" / Path(engine).name)
    return read_engine(folder / "engines" / Path(engine).name)


@pytest.fixture(scope="module")
def linear_runups(engine):
    return {"harmonic": run_runup(engine, RPM, solver="harmonic"),
            "dense": run_runup(engine, RPM, stepper="dense")}


@pytest.mark.slow
@pytest.mark.parametrize("case", NEUTRAL)
def test_neutral_laws_equal_the_linear_model(tmp_path, case, linear_runups):
    neutral = engine_with_sections(tmp_path, NEUTRAL[case])
    law = neutral.mounts[0].directions["z"]
    assert (law.amplitude_law or law.port_law) is not None          # the section was read
    for name, options in (("harmonic", {"solver": "harmonic"}), ("dense", {"stepper": "dense"})):
        got, want = run_runup(neutral, RPM, **options), linear_runups[name]
        for field in ("velocity", "mount_force", "mean_mount_force"):
            x, y = getattr(got, field), getattr(want, field)
            assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(y)), (name, field)


BERG = BergFriction(40.0, 0.05e-3)


@pytest.mark.parametrize("amplitude", [0.2 * BERG.half_displacement, BERG.half_displacement,
                                       4 * BERG.half_displacement, 20 * BERG.half_displacement])
def test_berg_describing_function_against_direct_integration(amplitude):
    n = 4000
    cycles = 400 if amplitude < BERG.half_displacement else 40
    t = np.arange(cycles * n) / n * 2 * np.pi
    U = (amplitude * np.sin(t))[:, None]
    F = np.empty_like(U)
    port_force_loop(np.array([BERG.kind]), BERG.parameters()[None],
                    BERG.initial_state(0.0)[None], U, np.zeros_like(U), F)
    f, tt = F[-n:, 0], t[-n:]
    assert np.max(np.abs(f - F[-2 * n:-n, 0])) <= 1e-12 * BERG.max_force   # steady loop
    k_num = 2 / n * np.sum(f * np.exp(-1j * tt)) / (-1j * amplitude)       # u = Re(-iA e^{it})
    k_df = BERG.describing_stiffness(amplitude)
    assert abs(k_num - k_df) <= 1e-11 * abs(k_df)
    loop = 2 * np.pi / n * np.sum(f * amplitude * np.cos(tt))            # the integral of F du
    energy = BERG.energy_per_cycle(amplitude)
    assert abs(loop - energy) <= 1e-11 * energy
    tip = BERG.loop_amplitude_force(amplitude)
    assert abs(f[n // 4] - tip) <= 1e-9 * tip and abs(f[3 * n // 4] + tip) <= 1e-9 * tip


CURVES = {
    "shipped": read_mount(MOUNTS / "hydraulic-engine-mount-z-nonlinear.toml").static_curve,
    "issue": StaticCurve((-8e-3, -4e-3, 0.0, 2e-3, 4e-3, 6e-3, 8e-3),
                         (-2600.0, -1100.0, 0.0, 550.0, 1200.0, 2100.0, 4200.0), 1.5e-3),
}


@pytest.mark.parametrize("name", CURVES)
def test_static_curve_through_its_points_monotone_and_straight_beyond(name):
    curve = CURVES[name]
    x, f = np.array(curve.deflection), np.array(curve.force)
    scale = np.max(np.abs(f))
    assert np.max(np.abs(curve.force_at(x) - f)) <= 1e-12 * scale
    dense = np.linspace(x[0] - 0.5 * np.ptp(x), x[-1] + 0.5 * np.ptp(x), 20001)
    assert np.all(np.diff(curve.force_at(dense)) > 0)
    assert np.all(curve.tangent_at(dense) > 0)
    slope = PchipInterpolator(x, f).derivative()
    for end, outside in ((0, dense[dense < x[0]]), (-1, dense[dense > x[-1]])):
        straight = f[end] + slope(x[end]) * (outside - x[end])
        assert np.max(np.abs(curve.force_at(outside) - straight)) <= 1e-12 * scale
        assert np.allclose(curve.tangent_at(outside), slope(x[end]), rtol=1e-12, atol=0)
    assert curve.factor(curve.reference_deflection) == 1.0


def test_shipped_nonlinear_engine_runs_harmonic_end_to_end():
    """engines/default-nonlinear.toml: friction, power and table laws through the fixed
    point, warm-started across speeds; the laws change the result (> 1 %)."""
    from conftest import shared_engine
    nonlinear = read_engine(ENGINES / "default-nonlinear.toml")
    a = run_runup(nonlinear, RPM, solver="harmonic")
    b = run_runup(shared_engine(), RPM, solver="harmonic")
    va, vb = a.synthesis_rms("velocity"), b.synthesis_rms("velocity")
    assert np.all(np.isfinite(va))
    assert np.max(np.abs(va / vb - 1)) > 0.01


def test_fixed_point_that_does_not_converge_is_one_line_at_the_cli(tmp_path, monkeypatch):
    from powertrain.cli import main
    from powertrain.solvers import equivalent_linear
    monkeypatch.setattr(equivalent_linear, "MAX_ITERATIONS", 1)
    out = tmp_path / "o.csv"
    res = CliRunner().invoke(main, ["runup", "--solver", "harmonic", "--engine",
                                    str(ENGINES / "default-nonlinear.toml"), "--from", "3000",
                                    "--to", "3000", "--quiet", "--csv", str(out)])
    assert res.exit_code == 1 and not out.exists()
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.output
    assert ".toml, key '" in lines[0]           # the mount file and section (or the engine)
    assert any(f"{m}.{d} at 3000 rpm" in lines[0] for m in ("left", "right", "gearbox")
               for d in "xyz")


@settings(max_examples=80, deadline=None)
@given(st.integers(2, 12), st.sampled_from(["rising", "any", "ties", "stiffening"]),
       st.integers(0, 2**32 - 1))
def test_the_static_curves_pchip_is_scipys_bit_for_bit(n, shape, seed):
    """pchip_cubic (the static support's and CurveReader's cubic) against
    scipy.interpolate.PchipInterpolator: the same breaks and coefficients, bit for bit, on
    rising curves, any curve, curves with flat segments and a stiffening sinh shape."""
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.uniform(1e-4, 1e-2, n)) - 0.02
    y = {"rising": np.cumsum(rng.uniform(-100.0, 1000.0, n)),
         "any": rng.standard_normal(n) * 1e3,
         "ties": np.round(rng.standard_normal(n)) * 500.0,
         "stiffening": np.sinh(x * 300.0) * 2e3}[shape]
    want = PchipInterpolator(x, y, extrapolate=False)
    breaks, coefficients = pchip_cubic(x, y)
    assert np.array_equal(breaks, want.x)
    assert np.array_equal(coefficients, want.c.T)
