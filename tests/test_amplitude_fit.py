"""``powertrain fit-mount`` on multi-amplitude data (issue 20 item 5): synthetic K*(f, X)
made by a different path — the time method (Newmark with Berg's element integrated, first
harmonic of the base force) of a known mount — fitted by the frequency-domain model
(amplitude law and describing function); the known laws come back.

Tolerances: exponent within 0.005, F_max and x2 within 1 %, residual per amplitude below
0.1 % (the two paths agree to ~1e-5, tests/test_amplitude_stiffness.py).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.iotools.stiffness_csv import read_stiffness_csv
from powertrain.workflows.amplitude_fit import fit_amplitudes

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "hydraulic-mount-amplitudes.csv"
#: The laws scripts/make_amplitude_example.py put into the example (SI).
EXPONENT, MAX_FORCE, HALF_DISPLACEMENT = 0.15, 40.0, 0.05e-3


@pytest.mark.slow
def test_fit_recovers_the_laws_of_the_time_domain_example():
    data = read_stiffness_csv(EXAMPLE)
    r = fit_amplitudes(data, "triple-parallel", friction=True, reference=0.1e-3, starts=8)
    law, friction = r.model.amplitude_law, r.model.port_law
    print(f"exponent {law.exponent:.6f} (true 0.15), max_force {friction.max_force:.4f} N "
          f"(40), half_displacement {friction.half_displacement * 1e3:.6f} mm (0.05); "
          f"residual per amplitude {[f'{100 * e:.2g} %' for e in r.rel_rms]}")
    assert abs(law.exponent - EXPONENT) < 5e-3
    assert abs(friction.max_force / MAX_FORCE - 1) < 0.01
    assert abs(friction.half_displacement / HALF_DISPLACEMENT - 1) < 0.01
    assert max(r.rel_rms) < 1e-3


def test_fit_without_friction_recovers_the_exponent(tmp_path):
    """The power law alone, from the time method's output written and read as CSV."""
    import dataclasses

    from powertrain.iotools.mount_file import read_mount
    from powertrain.physics.mount_laws import PowerLaw
    from powertrain.workflows.stiffness import amplitude_stiffness
    model = dataclasses.replace(read_mount(ROOT / "mounts" / "thesis-appendix-a.toml"),
                                amplitude_law=PowerLaw(0.2e-3, 0.3, (0.2, 5.0)))
    f = np.geomspace(2.0, 200.0, 20)
    csv = tmp_path / "k.csv"
    amplitude_stiffness(model, f, np.array([0.05, 0.2, 1.0]) * 1e-3, "time").to_csv(csv)
    r = fit_amplitudes(read_stiffness_csv(csv), model.topology, reference=0.2e-3, starts=4)
    assert abs(r.model.amplitude_law.exponent - 0.3) < 5e-3
    assert max(r.rel_rms) < 1e-3 and r.model.port_law is None


@pytest.mark.parametrize("args, key", [
    (["--friction"], "--friction"),          # single-amplitude data
    (["--reference", "0.1"], "--reference"),
])
def test_single_amplitude_data_refuse_the_multi_amplitude_options(tmp_path, args, key):
    data = tmp_path / "k.csv"
    data.write_text("frequency_hz,k_real_n_per_mm,k_imag_n_per_mm\n"
                    + "".join(f"{f},{100 + f},{f}\n" for f in range(1, 20)))
    r = CliRunner().invoke(main, ["fit-mount", str(data), "--out", str(tmp_path / "o.toml"),
                                  *args])
    assert r.exit_code == 1 and key in r.output and "Traceback" not in r.output
    assert not (tmp_path / "o.toml").exists()


def test_reference_must_be_one_of_the_amplitudes(tmp_path):
    r = CliRunner().invoke(main, ["fit-mount", str(EXAMPLE), "--reference", "0.2", "--out",
                                  str(tmp_path / "o.toml")])
    assert r.exit_code == 1 and "--reference" in r.output and "0.05, 0.1, 0.3, 1" in r.output


def test_csv_amplitude_blocks(tmp_path):
    head = "amplitude_mm,frequency_hz,k_real_n_per_mm,k_imag_n_per_mm\n"
    good = tmp_path / "good.csv"
    good.write_text(head + "0.5,1,10,1\n0.5,2,11,1\n0.1,1,20,2\n0.1,2,21,2\n")
    d = read_stiffness_csv(good)
    assert np.allclose(d.amplitudes, [1e-4, 5e-4])
    assert np.allclose(d.at(1e-4).kcp.real, [20e3, 21e3])
    again = tmp_path / "again.csv"
    again.write_text(head + "0.5,1,10,1\n0.1,1,20,2\n0.5,2,11,1\n")
    with pytest.raises(Exception, match="amplitude_mm.*again|again.*amplitude_mm"):
        read_stiffness_csv(again)
