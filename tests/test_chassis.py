"""Chassis model, body-side results and path contributions (issue 13, items 3 and 4)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tomllib
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.errors import InputError
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.measured import read_measured
from powertrain.iotools.runup_hdf5 import read_runup_hdf5
from powertrain.workflows.runup import run_runup

ENGINES = Path(DEFAULT_ENGINE_PATH).parent
MODAL = ENGINES / "default-modal-body.toml"
ENGINE_FILE = MODAL          # the module's ``engine`` (tests/conftest.py)
#: Issue 13: body-side curves, Newmark vs harmonic (the run-up's own Newmark tolerance).
NEWMARK_VS_HARMONIC = 5e-3
BODY_CHANNELS = [("left/passive", "z"), ("right/passive", "z"), ("gearbox/passive", "z"),
                 ("left/passive", "y"), ("seat_rail", "z"), ("seat_rail", "y")]


@pytest.fixture(scope="module")
def runups(engine):
    return run_runup(engine, solver="newmark"), run_runup(engine, solver="harmonic")


def test_modal_body_file_is_the_default_plus_a_body():
    """Oracle: engines/default-modal-body.toml differs from default.toml only by its name and
    the [chassis] section (the files cannot drift apart)."""
    with open(DEFAULT_ENGINE_PATH, "rb") as fh:
        base = tomllib.load(fh)
    with open(MODAL, "rb") as fh:
        modal = tomllib.load(fh)
    chassis = modal.pop("chassis")
    assert modal["engine"].pop("name") != base["engine"].pop("name")
    assert modal == base
    assert chassis["model"] == "modal" and len(chassis["modes"]) == 4


def test_channels_of_both_sides(engine, runups):
    newm, _ = runups
    assert newm.mounts == ["left", "right", "gearbox"]
    assert newm.points == ["seat_rail"]
    names = [m for m, _ in newm.channels]
    for m in ("left", "right", "gearbox"):
        assert m in names and f"{m}/passive" in names
    assert newm.side("left/passive") == "passive" and newm.side("seat_rail") == "passive"
    assert newm.side("left") == "active"


@pytest.mark.parametrize("quantity", ["synthesis", "order_2", "order_4"])
def test_body_side_newmark_matches_harmonic(runups, quantity):
    """Oracle: a second solver. Body-side curves of a modal-body run-up, time domain
    (Newmark) vs frequency domain (direct harmonic solve), within 0.5 %."""
    newm, harm = runups
    for ch in BODY_CHANNELS:
        a, b = newm.curve(*ch, quantity), harm.curve(*ch, quantity)
        ok = b > 1e-6 * b.max()
        np.testing.assert_allclose(a[ok], b[ok], rtol=NEWMARK_VS_HARMONIC, err_msg=str(ch))


def test_path_contributions_sum_to_the_point_response(runups):
    """Oracle: superposition. The body is loaded through the mounts only, so the complex path
    contributions (mount × local direction) sum to the body point's velocity: to round-off in
    the harmonic solve, within the Newmark tolerance in the time domain."""
    newm, harm = runups
    for res, tol in ((harm, 1e-9), (newm, NEWMARK_VS_HARMONIC)):
        for order in (2.0, 4.0):
            pc = res.path_contributions("seat_rail", "z", order)
            total = res.velocity[:, res.channel_index("seat_rail", "z"), res.order_index(order)]
            assert pc.shape == (res.rpm.size, 9)
            np.testing.assert_allclose(pc.sum(axis=1), total, rtol=tol,
                                       atol=tol * np.abs(total).max())


def test_rigid_chassis_is_unchanged():
    """Oracle: the rigid chassis is the thesis set-up — a modal body with very stiff, very
    heavy modes converges to it on the engine side."""
    rigid = read_engine(DEFAULT_ENGINE_PATH)
    from powertrain.models.chassis import BodyMode, Chassis
    stiff = Chassis(model="modal", modes=(BodyMode(5000.0, 0.05, 1e6, {
        m: np.array([0.0, 0.0, 1.0]) for m in rigid.mount_names}),))
    a = run_runup(rigid, [2000.0, 4000.0], solver="harmonic")
    b = run_runup(rigid.replace(chassis=stiff), [2000.0, 4000.0], solver="harmonic")
    for ch in a.channels:
        np.testing.assert_allclose(b.curve(*ch, "order_2"), a.curve(*ch, "order_2"), rtol=1e-6)


def _frf_csv(engine, rpm, path):
    """Receptances of the modal body, sampled at every order frequency of the run-up."""
    ch = engine.chassis
    f = np.unique(np.outer(rpm / 60.0, np.arange(1, 17) / 2.0).ravel())
    f = np.concatenate([[0.5 * f[0]], f, [2 * f[-1]]])
    names = engine.mount_names + list(ch.points)
    lines = ["# receptances of engines/default-modal-body.toml's body (a test's stand-in for "
             "measured data)",
             "frequency_hz,response,excitation,receptance_real_m_per_n,receptance_imag_m_per_n"]
    for r in names:
        for e in engine.mount_names:
            H = np.array([ch.receptance_at(2 * np.pi * fi, [r], [e]) for fi in f])
            for a, rd in enumerate("xyz"):
                for b, ed in enumerate("xyz"):
                    lines += [f"{float(fi)!r},{r}.{rd},{e}.{ed},{float(h.real)!r},{float(h.imag)!r}"
                              for fi, h in zip(f, H[:, a, b])]
    path.write_text("\n".join(lines) + "\n")


def test_measured_receptance_body_reproduces_the_modal_body(tmp_path, engine):
    """Oracle: a second, independent coupling. The modal body's receptances written as a
    measured FRF file and coupled by admittance in the harmonic solver give the same
    engine-side, body-side, body-point and path results as the modal body assembled into
    the equations of motion."""
    rpm = np.array([2000.0, 3500.0])
    _frf_csv(engine, rpm, tmp_path / "body.csv")
    text = MODAL.read_text()
    text = text[:text.index("\n[chassis]\n") + 1] + (
        '[chassis]\nmodel = "frf"\nfrf = "body.csv"\n\n[chassis.points.seat_rail]\n')
    text = text.replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/')
    (tmp_path / "frf.toml").write_text(text)
    frf = read_engine(tmp_path / "frf.toml")
    a = run_runup(engine, rpm, solver="harmonic")
    b = run_runup(frf, rpm, solver="harmonic")
    assert a.channels == b.channels
    k = [a.order_index(o) for o in (1.0, 2.0, 4.0)]
    for sig in ("velocity", "mount_force"):
        x, y = getattr(a, sig)[..., k], getattr(b, sig)[..., k]
        np.testing.assert_allclose(y, x, rtol=1e-6, atol=1e-9 * np.abs(x).max())
    np.testing.assert_allclose(b.path_contribution[..., k], a.path_contribution[..., k],
                               rtol=1e-6, atol=1e-9 * np.abs(a.path_contribution).max())
    with pytest.raises(InputError) as info:
        run_runup(frf, rpm, solver="newmark")
    assert info.value.key == "chassis.model"


def test_csv_and_hdf5_carry_both_sides(tmp_path, runups):
    """Oracle: the issue's CSV columns; files read back into passive-side channels."""
    newm, _ = runups
    newm.to_csv(tmp_path / "r.csv")
    newm.to_hdf5(tmp_path / "r.h5")
    lines = (tmp_path / "r.csv").read_text().splitlines()
    # the columns, in order (columns may be added after them, e.g. phase_deg)
    assert lines[0].startswith("mount,direction,quantity,rpm,side,velocity_rms_mm_per_s,"
                               "acceleration_rms_m_per_s2,force_rms_n")
    passive = [ln for ln in lines if ",passive," in ln]
    assert any(ln.startswith("left,z,order_2,") for ln in passive)
    assert any(ln.startswith("seat_rail,z,") and ln.endswith(",") for ln in passive)
    meas = read_measured(tmp_path / "r.csv", mounts=["left", "right", "gearbox"])
    rpm, lev = meas.curve("left/passive", "z", "order_2")
    np.testing.assert_allclose(lev, newm.curve("left/passive", "z", "order_2"), rtol=1e-7)
    back = read_runup_hdf5(tmp_path / "r.h5")
    assert back.channels == newm.channels and back.points == ["seat_rail"]
    np.testing.assert_array_equal(back.path_contribution, newm.path_contribution)
    iso = newm.isolation_db("left", "z", "order_2")
    assert np.all(np.isfinite(iso)) and np.all(iso > 0)


BAD = [
    ("unknown model", 'model = "modal"', 'model = "elastic"', "chassis.model"),
    ("missing shape", "gearbox = [0.0, 0.0, 0.1], ", "", "chassis.modes[0].shape.gearbox"),
    ("unknown shape name", "seat_rail = [0.0, 0.02, 0.3]}",
     "seat_rail = [0.0, 0.02, 0.3], boot = [0, 0, 1]}", "chassis.modes[0].shape.boot"),
    ("negative modal mass", 'modal_mass = {value = 40.0, unit = "kg"}',
     'modal_mass = {value = -40.0, unit = "kg"}', "chassis.modes[0].modal_mass.value"),
    ("frequency unit", 'frequency = {value = 28.0, unit = "Hz"}',
     'frequency = {value = 28.0, unit = "mm"}', "chassis.modes[0].frequency.unit"),
    ("short shape", "left = [0.0, 0.05, 1.0]", "left = [0.0, 1.0]",
     "chassis.modes[0].shape.left"),
    ("point named like a mount", "[chassis.points.seat_rail]", "[chassis.points.left]",
     "chassis.points.left"),
    ("frf without file", 'model = "modal"', 'model = "frf"', "chassis.modes"),
]


@pytest.mark.parametrize("what,old,new,key", BAD, ids=[b[0] for b in BAD])
def test_bad_chassis_names_file_and_key(tmp_path, what, old, new, key):
    """Oracle: the brief — one error naming file and key."""
    text = MODAL.read_text()
    assert old in text
    text = text.replace(old, new, 1).replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/')
    p = tmp_path / "bad.toml"
    p.write_text(text)
    with pytest.raises(InputError) as info:
        read_engine(p)
    assert info.value.file == str(p)
    assert info.value.key == key, info.value.one_line()


@pytest.mark.slow
def test_cli_runup_modal_body_and_modes(tmp_path):
    runner = CliRunner()
    res = runner.invoke(main, ["runup", "--engine", str(MODAL), "--from", "2000", "--to",
                               "3000", "--step", "1000", "--quiet", "--out",
                               str(tmp_path / "r.h5"), "--plot", str(tmp_path / "r.png"),
                               "--path-plot", str(tmp_path / "p.png")])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "r.png").stat().st_size > 0 and (tmp_path / "p.png").stat().st_size > 0
    res = runner.invoke(main, ["modes", "--engine", str(MODAL)])
    assert res.exit_code == 0, res.output
    assert "(chassis)" in res.output


def test_whatif_objective_on_the_body_side(tmp_path):
    """Oracle: the what-if's own definition — the objective's mean change equals the mean of
    20 log10(v/v0) over the band of that body-point channel in the JSON."""
    import json
    out = tmp_path / "w.json"
    res = CliRunner().invoke(main, ["whatif", "--engine", str(MODAL), "--from", "1500", "--to",
                                    "3000", "--step", "500", "--scale",
                                    "left.z.stiffness=0.8", "--objective",
                                    "seat_rail.z:order_2:1500-2500", "--json", str(out),
                                    "--workers", "1"])
    assert res.exit_code == 0, res.output
    assert "objective: minimise seat_rail.z order_2" in res.output
    data = json.loads(out.read_text())
    rank = data["objective"]["ranking"][0]
    rows = data["variants"][0]["channels"]
    row = next(r for r in rows if (r["mount"], r["direction"], r["quantity"])
               == ("seat_rail", "z", "order_2"))
    assert rank["mean_delta_db"] == pytest.approx(np.mean(row["delta_db"][:3]), rel=1e-12)
    bad = CliRunner().invoke(main, ["whatif", "--engine", str(MODAL), "--scale",
                                    "left.z.stiffness=0.8", "--objective", "seat.z:order_2:1-2"])
    assert bad.exit_code == 1 and "--objective" in bad.output


def test_uff58_receptances_read_like_csv(tmp_path, engine):
    """Oracle: the same receptances written as UFF 58 (pyuff, another file path) couple to
    the same result as the modal body (ASCII UFF keeps ~6 significant digits: 1e-4)."""
    import pyuff
    rpm = np.array([2500.0])
    f = np.unique(np.outer(rpm / 60.0, np.arange(1, 17) / 2.0).ravel())
    f = np.concatenate([[0.5 * f[0]], f, [2 * f[-1]]])
    ch = engine.chassis
    sets = []
    for r in engine.mount_names + list(ch.points):
        for e in engine.mount_names:
            H = np.array([ch.receptance_at(2 * np.pi * fi, [r], [e]) for fi in f])
            for a in range(3):
                for b in range(3):
                    sets.append(pyuff.prepare_58(
                        binary=0, func_type=4, rsp_ent_name=r, rsp_node=1, rsp_dir=a + 1,
                        ref_ent_name=e, ref_node=1, ref_dir=b + 1, data=H[:, a, b], x=f,
                        id1="receptance", ord_data_type=6, abscissa_spacing=0,
                        abscissa_spec_data_type=18, ordinate_spec_data_type=8,
                        orddenom_spec_data_type=13, z_axis_spec_data_type=0, ver_num=0,
                        load_case_id=0, z_axis_value=0.0))
    pyuff.UFF(str(tmp_path / "body.uff")).write_sets(sets, mode="overwrite")
    text = MODAL.read_text()
    text = text[:text.index("\n[chassis]\n") + 1] + (
        '[chassis]\nmodel = "frf"\nfrf = "body.uff"\n\n[chassis.points.seat_rail]\n')
    text = text.replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/')
    (tmp_path / "frf.toml").write_text(text)
    a = run_runup(engine, rpm, solver="harmonic")
    b = run_runup(read_engine(tmp_path / "frf.toml"), rpm, solver="harmonic")
    k = a.order_index(2.0)
    np.testing.assert_allclose(b.velocity[..., k], a.velocity[..., k], rtol=1e-4,
                               atol=1e-6 * np.abs(a.velocity[..., k]).max())


@pytest.mark.parametrize("edit,key", [
    (lambda lines: lines[:2] + lines[3:], "response"),                  # a pair loses a row
    (lambda lines: [ln for ln in lines if "left.x,right.y" not in ln
                    and "right.y,left.x" not in ln], "response"),       # a pair is missing
    (lambda lines: lines[:2] + [lines[2].replace("left.x", "boot.x", 1)] + lines[3:],
     "response"),
    (lambda lines: lines[:2] + [lines[2].replace(",", ",nan,", 1).replace(",nan,", ",", 0)]
     + lines[3:], None),
], ids=["grid", "missing pair", "unknown point", "bad cell"])
def test_bad_receptance_file(tmp_path, engine, edit, key):
    """Oracle: the brief — bad FRF files give one error naming file (and column)."""
    _frf_csv(engine, np.array([2000.0]), tmp_path / "body.csv")
    lines = (tmp_path / "body.csv").read_text().splitlines()
    (tmp_path / "body.csv").write_text("\n".join(edit(lines)) + "\n")
    text = MODAL.read_text()
    text = text[:text.index("\n[chassis]\n") + 1] + (
        '[chassis]\nmodel = "frf"\nfrf = "body.csv"\n\n[chassis.points.seat_rail]\n')
    text = text.replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/')
    (tmp_path / "frf.toml").write_text(text)
    with pytest.raises(InputError) as info:
        read_engine(tmp_path / "frf.toml")
    assert info.value.file == str(tmp_path / "body.csv")
    if key:
        assert info.value.key in (key, "frequency_hz"), info.value.one_line()


def test_paths_of_a_rotated_mount_sum_to_the_point_response():
    """Oracle: superposition, with a mount whose local axes are turned (the torque rod,
    Euler angles): contributions along local axes still add up to the point velocity."""
    from powertrain.models.chassis import BodyMode, Chassis
    e = read_engine(ENGINES / "default-torque-rod.toml")
    rng = np.random.default_rng(5)
    names = e.mount_names + ["seat_rail"]
    body = Chassis(model="modal", points=("seat_rail",), modes=tuple(
        BodyMode(f, 0.03, 20.0, {n: rng.normal(size=3) for n in names})
        for f in (30.0, 55.0, 90.0)))
    res = run_runup(e.replace(chassis=body), [2000.0, 3000.0], solver="harmonic")
    for d in "xyz":
        pc = res.path_contributions("seat_rail", d, 2.0)
        total = res.velocity[:, res.channel_index("seat_rail", d), res.order_index(2.0)]
        np.testing.assert_allclose(pc.sum(axis=1), total, rtol=1e-9)
    assert len(res.paths) == 12 and ("torque_rod", "x") in res.paths


def test_a_point_dropped_from_the_engine_file_names_the_engine_file(tmp_path, engine):
    """Fuzz find: deleting ``[chassis.points.seat_rail]`` from an FRF engine file left its
    receptance rows naming an unknown point; the one-line error names the receptance file
    and the engine file that defines the names."""
    _frf_csv(engine, np.array([2000.0]), tmp_path / "body.csv")
    text = MODAL.read_text()
    text = text[:text.index("\n[chassis]\n") + 1] + '[chassis]\nmodel = "frf"\nfrf = "body.csv"\n'
    text = text.replace('"../mounts/', f'"{ENGINES.parent / "mounts"}/')
    (tmp_path / "frf.toml").write_text(text)
    with pytest.raises(InputError) as info:
        read_engine(tmp_path / "frf.toml")
    line = info.value.one_line()
    assert "body.csv" in line and "frf.toml" in line and "seat_rail" in line, line
