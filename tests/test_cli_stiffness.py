"""``powertrain stiffness``: output columns, frequency ranges, both methods, and one-line
errors with a non-zero exit code and no output file left behind.

Oracles: the library functions the command wraps (frequency method = condensed network,
checked against the thesis in test_thesis_tables.py and test_mount_network.py) and the exit
code contract of :mod:`powertrain.cli` (0 success, non-zero on bad input, one stderr line).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from tolerances import TIME_VS_FREQUENCY_REL

from powertrain.cli import main

MOUNTS = Path(__file__).resolve().parents[1] / "mounts"
BASE = MOUNTS / "hydraulic-engine-mount-x.toml"
APPENDIX_A = MOUNTS / "thesis-appendix-a.toml"
K_COLUMNS = ["frequency_hz", "k_real_n_per_mm", "k_imag_n_per_mm"]
X_COLUMNS = ["x1_real_mm", "x1_imag_mm", "ft_real_n", "ft_imag_n"]


def run(*args):
    return CliRunner().invoke(main, ["stiffness", *map(str, args)])


def read_csv(text):
    lines = text.splitlines()
    header = lines[0].split(",")
    data = np.loadtxt(io.StringIO("\n".join(lines[1:])), delimiter=",", ndmin=2)
    return header, data


def test_csv_columns_and_400_rows():
    res = run(BASE, "--freq", "1:400:1", "--format", "csv")
    assert res.exit_code == 0, res.stderr
    header, data = read_csv(res.stdout)
    assert header[:3] == K_COLUMNS
    assert data.shape[0] == 400
    np.testing.assert_array_equal(data[:, 0], np.arange(1.0, 401.0))


def test_csv_columns_with_engine_mass():
    res = run(APPENDIX_A, "--freq", "5,10,40", "--engine-mass", 100, "--force", 100,
              "--format", "csv")
    assert res.exit_code == 0, res.stderr
    header, data = read_csv(res.stdout)
    assert header[:3] == K_COLUMNS
    assert set(X_COLUMNS) <= set(header)
    # Kovarik 2016, Table 3, MSC Nastran column, 5 Hz: x1 = -0.3653 - 0.6750i mm
    assert data[0, header.index("x1_real_mm")] == pytest.approx(-0.3653, abs=1e-4)
    assert data[0, header.index("x1_imag_mm")] == pytest.approx(-0.6750, abs=1e-4)


def test_csv_values_are_the_library_values():
    from powertrain.iotools.mount_file import read_mount
    res = run(BASE, "--freq", "5,50,200", "--format", "csv")
    header, data = read_csv(res.stdout)
    k = read_mount(BASE).cross_point_stiffness(data[:, 0]) / 1e3
    np.testing.assert_allclose(data[:, 1], k.real, rtol=1e-9)
    np.testing.assert_allclose(data[:, 2], k.imag, rtol=1e-9)


def test_table_output():
    res = run(BASE, "--freq", "5,10")
    assert res.exit_code == 0
    assert "k_real_n_per_mm" in res.stdout and "frequency" in res.stdout


@pytest.mark.parametrize("extra", [[], ["--engine-mass", "100", "--force", "100"]])
def test_time_method_agrees_with_frequency_method(extra):
    args = [APPENDIX_A, "--freq", "5,17,40,150", "--format", "csv", *extra]
    _, a = read_csv(run(*args, "--method", "frequency").stdout)
    res = run(*args, "--method", "time")
    assert res.exit_code == 0, res.stderr
    _, b = read_csv(res.stdout)
    cols = [1, 2] + ([5, 6, 7, 8] if extra else [])
    for c in cols:
        scale = np.max(np.abs(a[:, c]))
        assert np.max(np.abs(b[:, c] - a[:, c])) <= TIME_VS_FREQUENCY_REL * scale


def test_plot_is_written(tmp_path):
    out = tmp_path / "k.png"
    res = run(BASE, "--freq", "1:50:1", "--plot", out)
    assert res.exit_code == 0, res.stderr
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["k.png"]


#: (name, edit of BASE's text or None for a special file, key named in the message)
BAD_FILES = [
    ("missing-parameter", lambda s: s.replace("c3 = 1545.4\n", ""), "parameters.c3"),
    ("negative-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = -1"), "parameters.c3"),
    ("nan-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = nan"), "parameters.c3"),
    ("unknown-unit", lambda s: s.replace('c = "N/mm"', 'c = "N/furlong"'), "units.c"),
    ("wrong-dimension-unit", lambda s: s.replace('c = "N/mm"', 'c = "kg"'), "units.c"),
    ("unknown-model", lambda s: s.replace('"triple-parallel"', '"quintuple"'), "mount.model"),
    ("unknown-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = 1545.4\nc7 = 1"),
     "parameters.c7"),
    ("malformed-toml", lambda s: s.replace("c3 = 1545.4", "c3 = = 1545.4"), "line 22"),
    ("not-utf8", b"\xff\xfe\x00\x81", None),
    ("missing-file", None, None),
    ("directory", "dir", None),
]


def _one_error_line(res, *words):
    assert res.exit_code != 0
    assert res.stdout == ""
    lines = res.stderr.splitlines()
    assert len(lines) == 1, res.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


@pytest.mark.parametrize("name, content, key", BAD_FILES, ids=[b[0] for b in BAD_FILES])
def test_bad_mount_file(tmp_path, name, content, key):
    p = tmp_path / f"{name}.toml"
    if callable(content):
        p.write_text(content(BASE.read_text()))
    elif isinstance(content, bytes):
        p.write_bytes(content)
    elif content == "dir":
        p.mkdir()
    out = tmp_path / "plot.png"
    res = run(p, "--freq", "5,10", "--plot", out)
    _one_error_line(res, str(p), *([key] if key else []))
    assert not out.exists()
    assert sorted(q.name for q in tmp_path.iterdir()) == ([p.name] if p.exists() else [])


@pytest.mark.parametrize("freq", ["10,5", "5,5", "1:0:1", "abc", "5,-1", "", "0.01:1e12:1e-300,-0.0"])
def test_bad_frequencies(tmp_path, freq):
    out = tmp_path / "plot.png"
    res = run(BASE, "--freq", freq, "--plot", out)
    _one_error_line(res, "--freq")
    assert list(tmp_path.iterdir()) == []


def test_time_method_refuses_zero_frequency():
    _one_error_line(run(BASE, "--freq", "0,5", "--method", "time"), "--freq")


@pytest.mark.parametrize("args", [["--engine-mass", "100"], ["--force", "100"],
                                  ["--engine-mass", "-1", "--force", "100"]])
def test_engine_mass_and_force_go_together(args):
    _one_error_line(run(BASE, "--freq", "5", *args), "--engine-mass")
