"""Mount files (iotools/mount_file.py): the shipped files load, units convert once, bad
input is refused with an error naming the file and the key.

Oracles: the parameter lists printed in Kovarik (2016), Figs 37-42 and Appendix A
(transcribed in ``mounts/*.toml``), and the unit table of :mod:`powertrain.units`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from powertrain.errors import InputError
from powertrain.iotools.mount_file import format_mount, read_mount, write_mount
from powertrain.models.mount import TOPOLOGIES

MOUNTS = Path(__file__).resolve().parents[1] / "mounts"
SHIPPED = sorted(MOUNTS.glob("*.toml"))
BASE = MOUNTS / "hydraulic-engine-mount-x.toml"


def test_there_are_shipped_mount_files():
    names = {p.name for p in SHIPPED}
    assert {"thesis-appendix-a.toml", "hydraulic-engine-mount-x.toml",
            "hydraulic-engine-mount-y.toml", "hydraulic-engine-mount-z.toml",
            "elastomeric-gearbox-mount-x.toml", "elastomeric-gearbox-mount-y.toml",
            "elastomeric-gearbox-mount-z.toml"} <= names


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.name)
def test_shipped_file_loads(path):
    m = read_mount(path)
    assert m.topology.name in TOPOLOGIES
    assert set(m.params) == set(m.topology.parameters)
    assert np.all(np.isfinite(m.values)) and np.all(m.values >= 0)
    assert m.name and m.source
    k = m.cross_point_stiffness(np.array([1.0, 10.0, 100.0]))
    assert np.all(np.isfinite(k)) and np.all(k.real > 0)


def test_si_conversion():
    """Kovarik 2016, Fig. 37: c2 = 194.1 N/mm, d2 = 2.087 N s/mm, m1 = 200 kg -> SI."""
    m = read_mount(BASE)
    assert m.params["c2"] == pytest.approx(194100.0, rel=1e-15)
    assert m.params["d2"] == pytest.approx(2087.0, rel=1e-15)
    assert m.params["m1"] == 200.0


def test_appendix_a_deck_values():
    """Appendix A: CONM2 in tonne, PBUSH K in N/mm, B in N s/mm (reading note 4)."""
    m = read_mount(MOUNTS / "thesis-appendix-a.toml")
    assert m.params["m1"] == 200.0 and m.params["m2"] == 200.0 and m.params["m3"] == 0.01
    assert m.params["c4"] == pytest.approx(2172.32001e3)
    assert m.params["d6"] == pytest.approx(41.1e3)


def test_gearbox_x_is_printed_identical_to_engine_z():
    """Reading note 2: the thesis prints Fig. 40 identical to Fig. 39 (used as printed)."""
    gx = read_mount(MOUNTS / "elastomeric-gearbox-mount-x.toml")
    ez = read_mount(MOUNTS / "hydraulic-engine-mount-z.toml")
    assert gx.params == ez.params
    assert "copy error" in gx.notes


def test_units_other_than_datasheet_are_converted(tmp_path):
    text = BASE.read_text().replace('c = "N/mm"', 'c = "N/m"').replace("c2 = 194.1",
                                                                        "c2 = 194100")
    p = tmp_path / "si.toml"
    p.write_text(text)
    m = read_mount(p)
    assert m.params["c2"] == 194100.0
    assert m.params["c3"] == 1545.4      # the other springs are now read in N/m as well


def test_round_trip(tmp_path):
    m = read_mount(BASE)
    p = tmp_path / "out.toml"
    write_mount(m, p, comment="round trip")
    m2 = read_mount(p)
    assert m2.topology is m.topology
    np.testing.assert_allclose(m2.values, m.values, rtol=1e-8)
    assert format_mount(m2, comment="round trip") == p.read_text()


#: (name, edit of BASE's text, key that the error must name)
BAD = [
    ("missing-parameter", lambda s: s.replace("c3 = 1545.4\n", ""), "parameters.c3"),
    ("negative-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = -1545.4"),
     "parameters.c3"),
    ("nan-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = nan"), "parameters.c3"),
    ("inf-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = inf"), "parameters.c3"),
    ("text-parameter", lambda s: s.replace("c3 = 1545.4", 'c3 = "1545.4"'), "parameters.c3"),
    ("unknown-unit", lambda s: s.replace('c = "N/mm"', 'c = "N/furlong"'), "units.c"),
    ("wrong-dimension-unit", lambda s: s.replace('c = "N/mm"', 'c = "kg"'), "units.c"),
    ("missing-unit", lambda s: s.replace('d = "N*s/mm"\n', ""), "units.d"),
    ("unknown-model", lambda s: s.replace('"triple-parallel"', '"quintuple"'), "mount.model"),
    ("unknown-parameter", lambda s: s.replace("c3 = 1545.4", "c3 = 1545.4\nc7 = 1.0"),
     "parameters.c7"),
    ("unknown-unit-key", lambda s: s.replace('m = "kg"', 'm = "kg"\nk = "N/mm"'), "units.k"),
    ("unknown-mount-key", lambda s: s.replace("[mount]", '[mount]\nmodle = "x"'),
     "mount.modle"),
    ("unknown-table", lambda s: s + "\n[parameter]\nc1 = 1\n", "parameter"),
    ("missing-table", lambda s: s.replace("[units]", "[unit]"), "unit"),
]


@pytest.mark.parametrize("name, edit, key", BAD, ids=[b[0] for b in BAD])
def test_bad_input_names_file_and_key(tmp_path, name, edit, key):
    p = tmp_path / f"{name}.toml"
    p.write_text(edit(BASE.read_text()))
    with pytest.raises(InputError) as info:
        read_mount(p)
    assert info.value.file == str(p)
    assert info.value.key == key
    assert "\n" not in str(info.value)


def test_malformed_toml(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(BASE.read_text().replace("c3 = 1545.4", "c3 = = 1545.4"))
    with pytest.raises(InputError, match="not valid TOML.*line") as info:
        read_mount(p)
    assert info.value.file == str(p)


@pytest.mark.parametrize("kind", ["missing", "directory", "binary"])
def test_unreadable_file(tmp_path, kind):
    p = tmp_path / "m.toml"
    if kind == "directory":
        p.mkdir()
    elif kind == "binary":
        p.write_bytes(b"\xff\xfe\x00\x81 not text")
    with pytest.raises(InputError) as info:
        read_mount(p)
    assert info.value.file == str(p)
