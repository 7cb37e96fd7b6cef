"""Test plans (issue 21, item 3): the plan file, the engine at a run's load, and a plan
diagnosis that keeps every key of a single-run diagnosis."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from powertrain.errors import InputError
from powertrain.iotools.plan import read_plan


def _csv(path, scale=1.0):
    rows = ["mount,direction,quantity,rpm,velocity_rms_mm_per_s"]
    for m in ("left", "right", "gearbox"):
        for d in "xyz":
            for r in range(1000, 6001, 250):
                rows.append(f"{m},{d},order_2,{r},{scale * r / 1000:.4g}")
    path.write_text("\n".join(rows) + "\n")


@pytest.mark.parametrize("text, key", [
    ("", "runs"),
    ("[[runs]]\nload = 1.0\n", "runs[1].file"),
    ('[[runs]]\nfile = "a.csv"\nload = -1\n', "runs[1].load"),
    ('[[runs]]\nfile = "a.csv"\nload = "x"\n', "runs[1].load"),
    ('[[runs]]\nfile = "a.csv"\nspeed = 3\n', "runs[1].speed"),
    ('[[runs]]\nfile = "a.csv"\nload = 0.5\ntraces = "p.csv"\n', "runs[1].load"),
    ('title = "x"\n[[runs]]\nfile = "a.csv"\n', "title"),
])
def test_bad_plan_names_the_plan_file_and_key(tmp_path, default_engine, text, key):
    _csv(tmp_path / "a.csv")
    plan = tmp_path / "plan.toml"
    plan.write_text(text)
    with pytest.raises(InputError) as err:
        read_plan(plan, default_engine)
    assert err.value.key == key and str(plan) in str(err.value)


def test_load_is_refused_for_an_engine_with_measured_traces(tmp_path, default_engine):
    from benchmarks.cases import traces_engine
    _csv(tmp_path / "a.csv")
    (tmp_path / "plan.toml").write_text('[[runs]]\nfile = "a.csv"\nload = 0.4\n')
    with pytest.raises(InputError, match="combustion model") as err:
        read_plan(tmp_path / "plan.toml", traces_engine(default_engine, 1000.0))
    assert err.value.key == "runs[1].load"


def test_plan_paths_are_relative_to_the_plan_file(tmp_path, default_engine):
    sub = tmp_path / "runs"
    sub.mkdir()
    _csv(sub / "wot.csv")
    _csv(sub / "part.csv", 0.5)
    (sub / "plan.toml").write_text('[[runs]]\nfile = "wot.csv"\n[[runs]]\nfile = "part.csv"\n'
                                   "load = 0.4\n")
    plan = read_plan(sub / "plan.toml", default_engine)
    assert [r.load for r in plan.runs] == [1.0, 0.4]
    lv = [r.measured.curves[("left", "x", "order_2")][1][0] for r in plan.runs]
    assert lv[1] == pytest.approx(0.5 * lv[0])


def test_engine_at_load_scales_the_combustion_model(default_engine):
    from powertrain.models.combustion import RPM
    e = default_engine
    part = e.at_load(0.4)
    assert e.at_load(1.0) is e
    _, p_part, _ = part.combustion.cycle_pressures(e.crank, 3000 * RPM)
    _, p_ref, _ = e.combustion.cycle_pressures(e.crank, 3000 * RPM, 0.4)
    np.testing.assert_array_equal(p_part, p_ref)
    scaled = part.combustion.with_cylinder_factors(np.array([1.0, 0.9, 1.0, 1.0]))
    _, p_w, info = scaled.cycle_pressures(e.crank, 3000 * RPM)
    assert info["imep_target"][1] == pytest.approx(0.9 * info["imep_target"][0])


def _cli(cwd, *args):
    """The ``powertrain`` command (its console entry point) in ``cwd``."""
    code = "import sys; from powertrain.cli import main; sys.exit(main())"
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, capture_output=True,
                          text=True, timeout=120)


@pytest.mark.slow
@pytest.mark.parametrize("args, words", [
    ([], "missing MEASURED file or --plan"),
    (["x.csv", "--plan", "p.toml"], "not both"),
    (["--plan", "p.csv"], "TOML"),
])
def test_cli_plan_or_measured_exactly_one(tmp_path, args, words):
    r = _cli(tmp_path, "diagnose", *args)
    assert r.returncode == 1 and words in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_cli_bad_plan_is_one_line_naming_file_and_key(tmp_path):
    (tmp_path / "plan.toml").write_text('[[runs]]\nfile = "a.csv"\nload = 0\n')
    r = _cli(tmp_path, "diagnose", "--plan", "plan.toml")
    assert r.returncode == 1
    assert len(r.stderr.strip().splitlines()) == 1
    assert "plan.toml" in r.stderr and "runs[1].load" in r.stderr


@pytest.mark.slow
def test_plan_diagnosis_keeps_every_single_run_key_and_adds_runs(default_engine):
    """Two load cases of one stiffer mount from the truth generator: named; the plan's JSON has
    every key of a single-run diagnosis, and a run entry per run."""
    from benchmarks.plans import make_plan_case
    from powertrain.diagnosis import diagnose
    from powertrain.workflows.measurement import FLOOR
    stiff = np.ones((3, 3))
    stiff[0] = 2.0                                   # the left mount twice as stiff
    case = make_plan_case(0, ["mount_temperature"], 1, phase="all", params={
        "mount_temperature": {"spring_factors": stiff, "mount": 0, "factor": 2.0}})
    assert case.detectable
    kw = {"noise_floor": FLOOR, "effects": ["mount_stiffness", "cylinder_imbalance"],
          "pairs": False, "band_check": False, "progress": False}
    single = diagnose(case.runs[0].measured, default_engine, **kw).to_dict()
    joint = diagnose(case.plan(), default_engine, **kw).to_dict()
    assert set(single) <= set(joint)
    assert [r["load"] for r in joint["runs"]] == [1.0, 0.4]
    assert joint["phase"]["measured"] == "all"
    assert all(abs(o) < 4 for o in joint["phase"]["crank_offset_deg_per_run"])
    assert joint["verdict"] == "mount_stiffness"


def test_a_run_with_traces_uses_them_as_the_engines_combustion(tmp_path, default_engine):
    """``traces =`` (relative to the plan) replaces the combustion model for that run: the
    part-load single-zone pressures written as a trace CSV give that run's load back."""
    from powertrain.models.combustion import RPM
    e = default_engine
    rows = ["speed [rpm],cylinder,crank_angle [deg],pressure [Pa]"]
    for n in (1000.0, 6000.0):
        theta, p, _ = e.combustion.cycle_pressures(e.crank, n * RPM, 0.4)
        for c in range(p.shape[0]):
            rows += [f"{n:g},{c + 1},{np.degrees(t):.4f},{v:.6g}"
                     for t, v in zip(theta[::8], p[c, ::8])]
    (tmp_path / "p.csv").write_text("\n".join(rows) + "\n")
    _csv(tmp_path / "a.csv")
    (tmp_path / "plan.toml").write_text('[[runs]]\nfile = "a.csv"\ntraces = "p.csv"\n')
    run = read_plan(tmp_path / "plan.toml", e).runs[0]
    eng = run.engine(e)
    assert run.traces == str(tmp_path / "p.csv")
    part, full = (x.excitation(1000.0).imep.mean() for x in (eng, e))
    ref = e.at_load(0.4).excitation(1000.0).imep.mean()
    assert part == pytest.approx(ref, rel=0.02) and part < 0.6 * full


def test_the_shipped_plan_example_is_the_scripts_output(default_engine):
    """examples/plan.toml and its runs (shipped, copied by ``powertrain examples``) are what
    scripts/make_plan_example.py writes, marked SYNTHETIC, and read as a two-run plan."""
    import importlib.util
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    spec = importlib.util.spec_from_file_location("make_plan_example",
                                                  root / "scripts" / "make_plan_example.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    for name, text in script.plan_files().items():
        shipped = (root / "examples" / name).read_text()
        assert shipped == text, name
        assert shipped.startswith("# SYNTHETIC"), name
    plan = read_plan(root / "examples" / "plan.toml", default_engine)
    assert [r.load for r in plan.runs] == [1.0, 0.4]
