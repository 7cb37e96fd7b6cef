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
#: The shipped nonlinear files: friction + static curve, power law, table law.
NONLINEAR = MOUNTS / "hydraulic-engine-mount-z-nonlinear.toml"
POWER = MOUNTS / "hydraulic-engine-mount-y-power.toml"
TABLE = MOUNTS / "elastomeric-gearbox-mount-z-table.toml"


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


def test_nonlinear_sections_in_si():
    """[amplitude], [friction], [static] become the mount_laws objects, x in mm -> m."""
    from powertrain.physics.mount_laws import BergFriction, PowerLaw, StaticCurve, TableLaw
    m = read_mount(NONLINEAR)
    assert m.port_law == BergFriction(40.0, 0.05e-3)
    assert isinstance(m.static_curve, StaticCurve) and m.amplitude_law is None
    assert m.static_curve.deflection[0] == pytest.approx(-12e-3, rel=1e-15)
    assert m.static_curve.force[-1] == 1419.01
    assert m.static_curve.reference_deflection == pytest.approx(-5e-3, rel=1e-15)
    # the file's claim: tangent at the reference deflection = the network's static stiffness
    assert m.static_curve.tangent_at(-5e-3) == pytest.approx(m.static_stiffness(), rel=2e-5)
    power = read_mount(POWER).amplitude_law
    assert power == PowerLaw(pytest.approx(1e-4, rel=1e-15), 0.1, (0.5, 2.0))
    table = read_mount(TABLE).amplitude_law
    assert isinstance(table, TableLaw) and table.damping_scale[0] == 1.06
    np.testing.assert_allclose(table.amplitudes, [2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3],
                               rtol=1e-15)
    assert table.scales(1e-4) == (1.0, 1.0)


def test_power_law_limits_default_and_other_units(tmp_path):
    """limits default to PowerLaw's (0.2, 5.0); x in um and F in kN convert once."""
    text = POWER.read_text().replace("limits = [0.5, 2.0]\n", "").replace(
        'x = "mm"', 'x = "um"').replace("reference = 0.1", "reference = 100.0")
    p = tmp_path / "um.toml"
    p.write_text(text)
    law = read_mount(p).amplitude_law
    assert law.limits == (0.2, 5.0) and law.reference == pytest.approx(1e-4, rel=1e-15)
    text = NONLINEAR.read_text().replace('F = "N"', 'F = "kN"').replace(
        "max_force = 40.0", "max_force = 0.04")
    p.write_text(text)
    assert read_mount(p).port_law.max_force == pytest.approx(40.0, rel=1e-15)


@pytest.mark.parametrize("path", [NONLINEAR, POWER, TABLE], ids=lambda p: p.name)
def test_nonlinear_round_trip(tmp_path, path):
    """write_mount writes every section back; reading it gives the same laws."""
    m = read_mount(path)
    p = tmp_path / "out.toml"
    write_mount(m, p)
    m2 = read_mount(p)
    np.testing.assert_allclose(m2.values, m.values, rtol=1e-8)
    for field in ("amplitude_law", "port_law", "static_curve"):
        a, b = getattr(m, field), getattr(m2, field)
        assert (a is None) == (b is None)
        if a is not None:
            assert type(a) is type(b)
            for name, value in vars(a).items():
                if value is None:
                    assert getattr(b, name) is None
                else:
                    np.testing.assert_allclose(getattr(b, name), value, rtol=1e-12)
    assert format_mount(m2) == p.read_text()


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



def _sub(old, new, base=NONLINEAR):
    """An edit of a shipped nonlinear file: ``old`` (which must be there) -> ``new``."""
    def edit(_):
        text = base.read_text()
        assert old in text
        return text.replace(old, new)
    return edit


#: Bad [amplitude], [friction], [static] sections and their units (issue 20, item 9).
BAD_SECTIONS = [
    ("static-not-monotone", _sub("-851.41, -586.52", "-586.52, -851.41"), "static.force"),
    ("static-deflection-unsorted", _sub("-7.0, -5.0", "-5.0, -7.0"), "static.deflection"),
    ("static-duplicate-deflection", _sub("-7.0, -5.0", "-5.0, -5.0"), "static.deflection"),
    ("static-unequal-lengths", _sub(", 1419.01]", "]"), "static.force"),
    ("static-one-point", _sub("deflection = [-12.0, -9.0, -7.0, -5.0, -3.0, 0.0, 3.0, 6.0, 9.0]"
                              "\nforce = [-2743.42, -1419.01, -851.41, -586.52, -359.48, 0.0, "
                              "312.18, 662.2, 1419.01]", "deflection = [0.0]\nforce = [0.0]"),
     "static.deflection"),
    ("static-flat-end", _sub("662.2, 1419.01]", "1400.0, 1419.01]"), "static.force"),
    ("static-missing-force", _sub("force = [", "forces = ["), "static.forces"),
    ("static-text-deflection", _sub("reference_deflection = -5.0", 'reference_deflection = "a"'),
     "static.reference_deflection"),
    ("friction-negative-max-force", _sub("max_force = 40.0", "max_force = -40.0"),
     "friction.max_force"),
    ("friction-zero-half-displacement", _sub("half_displacement = 0.05", "half_displacement = 0"),
     "friction.half_displacement"),
    ("friction-negative-half-displacement",
     _sub("half_displacement = 0.05", "half_displacement = -0.05"), "friction.half_displacement"),
    ("friction-missing-key", _sub("max_force = 40.0\n", ""), "friction.max_force"),
    ("friction-unknown-key", _sub("max_force = 40.0", "max_force = 40.0\nmu = 0.3"),
     "friction.mu"),
    ("x-is-a-force", _sub('x = "mm"', 'x = "N"'), "units.x"),
    ("F-is-a-length", _sub('F = "N"', 'F = "mm"'), "units.F"),
    ("friction-without-F", _sub('F = "N"\n', ""), "units.F"),
    ("static-without-x", _sub('x = "mm"\n', ""), "units.x"),
    ("amplitude-without-x", _sub('x = "mm"\n', "", POWER), "units.x"),
    ("power-zero-reference", _sub("reference = 0.1", "reference = 0.0", POWER),
     "amplitude.reference"),
    ("power-negative-reference", _sub("reference = 0.1", "reference = -0.1", POWER),
     "amplitude.reference"),
    ("power-limits-reversed", _sub("[0.5, 2.0]", "[2.0, 0.5]", POWER), "amplitude.limits"),
    ("power-limits-above-one", _sub("[0.5, 2.0]", "[1.5, 2.0]", POWER), "amplitude.limits"),
    ("power-limits-below-one", _sub("[0.5, 2.0]", "[0.5, 0.8]", POWER), "amplitude.limits"),
    ("power-limits-zero", _sub("[0.5, 2.0]", "[0.0, 2.0]", POWER), "amplitude.limits"),
    ("power-limits-three", _sub("[0.5, 2.0]", "[0.5, 1.0, 2.0]", POWER), "amplitude.limits"),
    ("power-exponent-nan", _sub("exponent = 0.1", "exponent = nan", POWER),
     "amplitude.exponent"),
    ("power-table-key", _sub("exponent = 0.1", "exponent = 0.1\namplitudes = [1.0]", POWER),
     "amplitude.amplitudes"),
    ("unknown-law", _sub('law = "power"', 'law = "exp"', POWER), "amplitude.law"),
    ("table-unsorted", _sub("[0.02, 0.05, 0.1,", "[0.05, 0.02, 0.1,", TABLE),
     "amplitude.amplitudes"),
    ("table-duplicate", _sub("[0.02, 0.05, 0.1,", "[0.02, 0.02, 0.1,", TABLE),
     "amplitude.amplitudes"),
    ("table-zero-amplitude", _sub("[0.02, 0.05, 0.1,", "[0.0, 0.05, 0.1,", TABLE),
     "amplitude.amplitudes"),
    ("table-zero-stiffness-scale", _sub("[1.2, 1.09,", "[0.0, 1.09,", TABLE),
     "amplitude.stiffness_scale"),
    ("table-negative-damping-scale", _sub("[1.06, 1.03,", "[-1.06, 1.03,", TABLE),
     "amplitude.damping_scale"),
    ("table-short-stiffness-scale", _sub("[1.2, 1.09,", "[1.09,", TABLE),
     "amplitude.stiffness_scale"),
    ("table-long-damping-scale", _sub("[1.06, 1.03,", "[1.1, 1.06, 1.03,", TABLE),
     "amplitude.damping_scale"),
    ("table-empty", _sub("[0.02, 0.05, 0.1, 0.2, 0.5, 1.0]", "[]", TABLE),
     "amplitude.amplitudes"),
    ("table-scalar", _sub("[0.02, 0.05, 0.1, 0.2, 0.5, 1.0]", "0.1", TABLE),
     "amplitude.amplitudes"),
    ("unknown-section", _sub("[friction]", "[friktion]"), "friktion"),
]


@pytest.mark.parametrize("name, edit, key", BAD + BAD_SECTIONS,
                         ids=[b[0] for b in BAD + BAD_SECTIONS])
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


def test_power_law_damping_exponent_read_written_and_applied(tmp_path):
    """``damping_exponent`` (optional, default 1: dampers like springs) puts f^γ on the
    dampers; written back only when not 1; a non-number names its key."""
    p = tmp_path / "gamma.toml"
    p.write_text(POWER.read_text().replace("limits = [0.5, 2.0]",
                                           "limits = [0.5, 2.0]\ndamping_exponent = 0.5"))
    law = read_mount(p).amplitude_law
    assert law.damping_exponent == 0.5
    ks, ds = law.scales(2e-4)
    assert ks == pytest.approx(0.5 ** 0.1) and ds == pytest.approx(ks ** 0.5)
    assert read_mount(POWER).amplitude_law.damping_exponent == 1.0
    assert "damping_exponent" not in format_mount(read_mount(POWER))
    out = tmp_path / "out.toml"
    write_mount(read_mount(p), out)
    assert read_mount(out).amplitude_law == law
    p.write_text(POWER.read_text().replace("limits = [0.5, 2.0]",
                                           'limits = [0.5, 2.0]\ndamping_exponent = "x"'))
    with pytest.raises(InputError, match="damping_exponent"):
        read_mount(p)


def test_a_network_singular_at_0_hz_is_refused_at_reading(tmp_path):
    """Issue 39: a mount file with every spring and damper 0 (masses kept) leaves the
    internal masses on no spring; refused when read (mount file, engine file and the API),
    naming the file, the key and the loose masses, not a FloatingPointError in a solver.
    A damper-only hold is not enough either (no static stiffness)."""
    import re

    import powertrain as pt
    text = BASE.read_text()
    head, sep, params = text.partition("[parameters]")
    (tmp_path / "mounts").mkdir()
    zero = tmp_path / "mounts" / BASE.name
    zero.write_text(head + sep + re.sub(r"^([cd]\d+) = .*$", r"\1 = 0", params, flags=re.M))
    with pytest.raises(InputError, match=r"hydraulic-engine-mount-x.toml, key 'parameters': "
                                         r"the mount network is singular at 0 Hz .*m1, m2, m3"):
        read_mount(zero)
    springs_only_zero = re.sub(r"^(c\d+) = .*$", r"\1 = 0", params, flags=re.M)
    zero.write_text(head + sep + springs_only_zero)
    with pytest.raises(InputError, match="singular at 0 Hz"):
        read_mount(zero)
    engines = Path(pt.read_engine().file).parent
    (tmp_path / "engines").mkdir()
    (tmp_path / "engines" / "default.toml").write_text((engines / "default.toml").read_text())
    for p in MOUNTS.glob("*.toml"):
        if p.name != BASE.name:
            (tmp_path / "mounts" / p.name).write_text(p.read_text())
    with pytest.raises(InputError, match="hydraulic-engine-mount-x.toml.*singular at 0 Hz"):
        pt.read_engine(tmp_path / "engines" / "default.toml")
