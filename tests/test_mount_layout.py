"""Any mount layout (issue 13, item 1): named mounts, Euler orientation, inline springs,
engine files without excitation."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import tomllib
from click.testing import CliRunner

from powertrain.assembly import assemble
from powertrain.cli import main
from powertrain.errors import InputError
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, euler_rotation, read_engine

ENGINES = Path(DEFAULT_ENGINE_PATH).parent
TORQUE_ROD = ENGINES / "default-torque-rod.toml"

MINIMAL = """
[engine]
name = "modes-only layout"

[body]
mass = {value = 150.0, unit = "kg"}
cg = {value = [0.0, 0.0, 0.0], unit = "mm"}
inertia = {value = [[6.0, 0.0, 0.0], [0.0, 12.0, 0.0], [0.0, 0.0, 11.0]], unit = "kg*m^2"}

[mounts.front]
position = {value = [-300.0, 0.0, -100.0], unit = "mm"}
orientation = {value = [0.0, 0.0, 0.0], unit = "deg"}
stiffness = {value = [100.0, 100.0, 200.0], unit = "N/mm"}

[mounts.rear_left]
position = {value = [300.0, -250.0, -100.0], unit = "mm"}
ORIENT_LEFT
stiffness = {value = [80.0, 90.0, 150.0], unit = "N/mm"}
damping = {value = [0.1, 0.1, 0.2], unit = "N*s/mm"}

[mounts.rear_right]
position = {value = [300.0, 250.0, -100.0], unit = "mm"}
orientation = {value = [0.0, 0.0, 0.0], unit = "deg"}
stiffness = {value = [80.0, 90.0, 150.0], unit = "N/mm"}
"""


def _write(tmp_path, text, name="e.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_euler_rotation_is_rz_ry_rx():
    """Oracle: the issue's definition R = Rz(c)·Ry(b)·Rx(a), checked on elementary rotations
    and on a general composition built from scipy's extrinsic 'xyz' convention."""
    from scipy.spatial.transform import Rotation
    np.testing.assert_allclose(euler_rotation(0, 0, math.pi / 2)[:, 0], [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(euler_rotation(math.pi / 2, 0, 0)[:, 1], [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(euler_rotation(0, math.pi / 2, 0)[:, 2], [1, 0, 0], atol=1e-15)
    a, b, c = 0.3, -0.7, 1.1
    ref = Rotation.from_euler("xyz", [a, b, c]).as_matrix()   # extrinsic x, then y, then z
    np.testing.assert_allclose(euler_rotation(a, b, c), ref, atol=1e-14)


def test_euler_orientation_equals_local_axes(tmp_path):
    """Oracle: the same rotation given as Euler angles or as local_x/local_z vectors gives the
    same assembled stiffness matrix."""
    a, b, c = 10.0, 20.0, 30.0
    R = euler_rotation(*np.radians([a, b, c]))
    vec = (f"local_x = {{value = {R[:, 0].tolist()}, unit = \"1\"}}\n"
           f"local_z = {{value = {R[:, 2].tolist()}, unit = \"1\"}}")
    e1 = read_engine(_write(tmp_path, MINIMAL.replace(
        "ORIENT_LEFT", f'orientation = {{value = [{a}, {b}, {c}], unit = "deg"}}'), "a.toml"))
    e2 = read_engine(_write(tmp_path, MINIMAL.replace("ORIENT_LEFT", vec), "b.toml"))
    k1 = assemble(e1.body.mass, e1.body.cg, e1.body.inertia, e1.mounts).K
    k2 = assemble(e2.body.mass, e2.body.cg, e2.body.inertia, e2.mounts).K
    np.testing.assert_allclose(k1, k2, rtol=1e-12, atol=1e-9 * np.abs(k1).max())


def test_inline_springs_are_kelvin_voigt(tmp_path):
    """Oracle: an inline spring-damper is k + iωc in each local direction, in SI."""
    e = read_engine(_write(tmp_path, MINIMAL.replace(
        "ORIENT_LEFT", 'orientation = {value = [0, 0, 0], unit = "deg"}')))
    assert e.mount_names == ["front", "rear_left", "rear_right"]
    m = e.mount("rear_left")
    k = [m.directions[d].cross_point_stiffness(10.0)[0] for d in "xyz"]
    np.testing.assert_allclose(k, [80e3 + 1j * 2 * np.pi * 10 * 100, 90e3 + 1j * 2 * np.pi * 1e3,
                                   150e3 + 1j * 2 * np.pi * 10 * 200], rtol=1e-12)


def test_engine_without_excitation_names_missing_section(tmp_path):
    """Oracle: the issue — [engine], [body], [mounts.*] alone are valid for modes; commands
    that need excitation name the missing section (one line, exit 1)."""
    p = _write(tmp_path, MINIMAL.replace(
        "ORIENT_LEFT", 'orientation = {value = [0, 0, 0], unit = "deg"}'))
    e = read_engine(p)
    assert e.crank is None and e.combustion is None
    with pytest.raises(InputError) as info:
        e.generalized_load(2000.0, [0.0])
    assert info.value.key == "crank_train"
    runner = CliRunner()
    for args in (["runup", "--engine", str(p), "--quiet", "--out", str(tmp_path / "r.h5")],
                 ["whatif", "--engine", str(p), "--scale", "front.z.stiffness=1.2"]):
        res = runner.invoke(main, args)
        assert res.exit_code == 1, res.output
        assert "[crank_train]" in res.output and "Traceback" not in res.output
        assert len(res.output.strip().splitlines()) == 1
    assert not (tmp_path / "r.h5").exists()


BAD = [
    ("too few mounts", "", "", "mounts"),
    ("both orientations", "ORIENT_LEFT",
     'orientation = {value = [0, 0, 0], unit = "deg"}\nlocal_x = {value = [1, 0, 0], unit = "1"}',
     "mounts.rear_left.orientation"),
    ("no orientation", "ORIENT_LEFT", "", "mounts.rear_left.orientation"),
    ("orientation unit", "ORIENT_LEFT", 'orientation = {value = [0, 0, 0], unit = "mm"}',
     "mounts.rear_left.orientation.unit"),
    ("orientation length", "ORIENT_LEFT", 'orientation = {value = [0, 0], unit = "deg"}',
     "mounts.rear_left.orientation.value"),
    ("negative stiffness", "[80.0, 90.0, 150.0], unit = \"N/mm\"}\ndamping",
     "[80.0, -90.0, 150.0], unit = \"N/mm\"}\ndamping", "mounts.rear_left.stiffness.value"),
    ("damping unit", 'unit = "N*s/mm"', 'unit = "N/mm"', "mounts.rear_left.damping.unit"),
    ("no stiffness", 'stiffness = {value = [100.0, 100.0, 200.0], unit = "N/mm"}', "",
     "mounts.front.stiffness"),
    ("files and stiffness", 'stiffness = {value = [100.0, 100.0, 200.0], unit = "N/mm"}',
     'stiffness = {value = [100.0, 100.0, 200.0], unit = "N/mm"}\nfiles = {x = "a.toml"}',
     "mounts.front.stiffness"),
    ("bad mount name", "[mounts.front]", '[mounts."front wheel"]', "mounts.front wheel"),
    ("unsupported body", "[100.0, 100.0, 200.0]", "[0.0, 0.0, 200.0]", "mounts"),
]


@pytest.mark.parametrize("what,old,new,key", BAD, ids=[b[0] for b in BAD])
def test_bad_mount_layouts_name_file_and_key(tmp_path, what, old, new, key):
    """Oracle: the brief — bad input raises InputError naming the file and the key."""
    text = MINIMAL.replace(old, new, 1).replace(
        "ORIENT_LEFT", 'orientation = {value = [0, 0, 0], unit = "deg"}')
    if what == "too few mounts":
        text = text[:text.index("[mounts.rear_right]")]
    if what == "unsupported body":
        text = text.replace("[80.0, 90.0, 150.0]", "[0.0, 0.0, 150.0]")
    p = _write(tmp_path, text)
    with pytest.raises(InputError) as info:
        read_engine(p)
    assert info.value.file == str(p)
    assert info.value.key == key, info.value.one_line()


def test_torque_rod_engine_is_the_default_plus_a_rod():
    """Oracle: the shipped torque-rod example differs from engines/default.toml only by the
    name and the fourth mount (the two files cannot drift apart)."""
    with open(DEFAULT_ENGINE_PATH, "rb") as fh:
        base = tomllib.load(fh)
    with open(TORQUE_ROD, "rb") as fh:
        rod = tomllib.load(fh)
    rod_mount = rod["mounts"].pop("torque_rod")
    assert rod["engine"].pop("name") != base["engine"].pop("name")
    assert rod == base
    assert set(rod_mount) == {"position", "orientation", "stiffness", "damping"}
    e = read_engine(TORQUE_ROD)
    assert e.mount_names == ["left", "right", "gearbox", "torque_rod"]


def test_torque_rod_runs_runup_and_whatif(tmp_path):
    """Oracle: the issue's done-when — the fourth mount appears in run-up CSV and what-if."""
    runner = CliRunner()
    csv = tmp_path / "r.csv"
    res = runner.invoke(main, ["runup", "--engine", str(TORQUE_ROD), "--solver", "harmonic",
                               "--from", "2000", "--to", "3000", "--step", "1000", "--quiet",
                               "--out", str(tmp_path / "r.h5"), "--csv", str(csv)])
    assert res.exit_code == 0, res.output
    mounts = {line.split(",")[0] for line in csv.read_text().splitlines()[1:]}
    assert mounts == {"left", "right", "gearbox", "torque_rod"}
    res = runner.invoke(main, ["whatif", "--engine", str(TORQUE_ROD), "--from", "2000", "--to",
                               "3000", "--step", "1000", "--scale",
                               "torque_rod.z.stiffness=1.2", "--json", str(tmp_path / "w.json")])
    assert res.exit_code == 0, res.output
    assert "torque_rod.z" in res.output


def test_stiffness_of_an_engine_files_mount():
    """Oracle: an inline spring-damper's K* = k + iωc in N/mm (the torque rod's x)."""
    res = CliRunner().invoke(main, ["stiffness", "--engine", str(TORQUE_ROD), "--mount",
                                    "torque_rod.x", "--freq", "100", "--format", "csv"])
    assert res.exit_code == 0, res.output
    row = [r for r in res.output.splitlines() if r and not r.startswith(("#", "freq"))][0]
    f, k_re, k_im = (float(v) for v in row.split(",")[:3])
    with open(TORQUE_ROD, "rb") as fh:
        rod = tomllib.load(fh)["mounts"]["torque_rod"]
    assert k_re == pytest.approx(rod["stiffness"]["value"][0], rel=1e-9)
    assert k_im == pytest.approx(2 * np.pi * 100 * rod["damping"]["value"][0], rel=1e-6)
    for args in (["--engine", str(TORQUE_ROD), "--mount", "rod.x"], []):
        bad = CliRunner().invoke(main, ["stiffness", *args])
        assert bad.exit_code == 1 and len(bad.output.strip().splitlines()) == 1
