"""The equivalent-linear amplitude fixed point (solvers/equivalent_linear.py): Anderson
acceleration in log amplitudes, damped iteration as the fallback.

* a steep power law (exponent 1.5, limits [0.001, 1000]) on the y directions of
  engines/default-nonlinear.toml converges at every speed (plain damped iteration did not in
  200 iterations at 1000 rpm) to a fixed point whose amplitudes reproduce themselves to the
  tolerance (1e-9 of the largest);
* a map without a fixed point is an error naming the element whose amplitude changes most
  relative to itself (not the largest in absolute terms) and the speed;
* at the command line that error names the element's mount file and section.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest
from click.testing import CliRunner
from conftest import ENGINES, ROOT

from powertrain.iotools.engine_file import read_engine
from powertrain.physics.mount_elements import PortForces
from powertrain.solvers import equivalent_linear
from powertrain.solvers.equivalent_linear import (
    TOLERANCE,
    AmplitudeNotConverged,
    amplitude_fixed_point,
    amplitudes_of,
)
from powertrain.workflows.runup import run_runup


def steep_engine():
    """engines/default-nonlinear.toml with the steep law of scripts/fixed_point_iterations.py
    on its y directions."""
    spec = importlib.util.spec_from_file_location(
        "fixed_point_iterations", ROOT / "scripts" / "fixed_point_iterations.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    return script.with_steep_y(read_engine(ENGINES / "default-nonlinear.toml"))


def ports_named(*names):
    """Kernel-free port laws (amplitude law only) called ``names``."""
    m = len(names)
    return PortForces(np.eye(m), np.zeros(m, np.int64), np.zeros((m, 1)), [None] * m,
                      np.eye(m), list(names), np.arange(m), m)


def test_a_steep_amplitude_law_converges(monkeypatch):
    seen = []
    original = equivalent_linear.amplitude_fixed_point

    def recording(solve, relative_motion, *args):
        A, solution = original(solve, relative_motion, *args)
        seen.append(np.max(np.abs(amplitudes_of(relative_motion(solve(
            args[0].network_amplitudes(A)))) - A)) / np.max(A))
        return A, solution

    from powertrain.solvers import steppers
    monkeypatch.setattr(steppers, "amplitude_fixed_point", recording)
    result = run_runup(steep_engine(), [1000.0, 3000.0, 6000.0], solver="harmonic")
    assert np.all(np.isfinite(result.synthesis_rms("velocity")))
    assert len(seen) == 3 and max(seen) <= 2 * TOLERANCE


def test_a_fixed_point_that_does_not_exist_names_the_element_that_oscillates():
    """Element ``small.y`` flips between 1 and 3 µm (no fixed point, the largest relative
    change); ``large.z`` settles at 1 mm (the largest amplitude)."""
    def solve(A):
        return np.array([1e-3, 3e-6 if A[1] < 2e-6 else 1e-6])

    def relative(solution):
        out = np.zeros((17, 2))
        out[2] = solution
        return out

    with pytest.raises(AmplitudeNotConverged, match=r"^small\.y at 1234 rpm") as err:
        amplitude_fixed_point(solve, relative, ports_named("large.z", "small.y"), 1234.0)
    assert err.value.element == "small.y" and err.value.change > 0.1


def test_no_convergence_at_the_cli_names_the_mount_file_and_section(tmp_path, monkeypatch):
    from powertrain.cli import main
    monkeypatch.setattr(equivalent_linear, "MAX_ITERATIONS", 2)
    out = tmp_path / "o.csv"
    res = CliRunner().invoke(main, ["runup", "--solver", "harmonic", "--engine",
                                    str(ENGINES / "default-nonlinear.toml"), "--from", "3000",
                                    "--to", "3000", "--quiet", "--csv", str(out)])
    assert res.exit_code == 1 and not out.exists()
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.output
    files = {"y": ("hydraulic-engine-mount-y-power.toml", "amplitude"),
             "z": ("hydraulic-engine-mount-z-nonlinear.toml", "friction")}
    named = [(m, d) for m in ("left", "right") for d in "yz" if f"{m}.{d} at 3000 rpm" in
             lines[0]]
    assert len(named) == 1
    file, key = files[named[0][1]]
    assert f"{file}, key '{key}'" in lines[0]
