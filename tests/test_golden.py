"""No result changes: the command-line outputs recorded before the solver refactoring (issue 19)
are reproduced to 1e-6 relative.

Each case runs one command in-process and compares every number of its output file with the
golden file in tests/data/golden/: CSV column by column, JSON key path by key path (keys may be
added, never removed). Text, file paths and the provenance block (time stamps, command line)
are not compared. A number matches when ``|new - old| <= RTOL * |old| + ATOL_REL * scale``,
``scale`` the largest magnitude of that column (CSV) or key (JSON) in the golden file: the
absolute part only covers round-off noise on values ~1e-12 of their column (e.g. an order
the load does not excite).

Record again (only when a result change is intended and explained in the changelog):
``python tests/test_golden.py --record``.
"""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from powertrain.cli import main

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "data" / "golden"
ENGINES = ROOT / "engines"
MOUNTS = ROOT / "mounts"
RTOL = 1e-6
ATOL_REL = 1e-10
#: JSON subtrees not compared (time stamps, command line, absolute paths).
SKIPPED_KEYS = {"provenance"}
GRID = ["--from", "1000", "--to", "6000", "--step", "1000"]


def _cases():
    cases = {}
    for engine in ("default", "default-modal-body", "default-torque-rod"):
        for solver in ("newmark", "harmonic"):
            cases[f"runup-{engine}-{solver}.csv"] = [
                "runup", "--engine", str(ENGINES / f"{engine}.toml"), "--solver", solver,
                *GRID, "--quiet", "--csv"]
        cases[f"modes-{engine}.json"] = ["modes", "--engine", str(ENGINES / f"{engine}.toml"),
                                         "--json"]
    cases["modes-default-static.json"] = ["modes", "--static", "--json"]
    cases["whatif.json"] = ["whatif", "--scale", "left.z.stiffness=1.2", "--workers", "1",
                            "--quiet", "--json"]
    cases["stiffness.csv"] = ["stiffness", str(MOUNTS / "hydraulic-engine-mount-z.toml"),
                              "--format", "csv"]
    cases["stiffness-engine-mass.csv"] = [
        "stiffness", str(MOUNTS / "thesis-appendix-a.toml"), "--freq", "5,10,12,15,17,20,25,30,40",
        "--engine-mass", "100", "--force", "100", "--format", "csv"]
    cases["stiffness-time.csv"] = [
        "stiffness", str(MOUNTS / "thesis-appendix-a.toml"), "--freq", "5,10,20",
        "--engine-mass", "100", "--force", "100", "--method", "time", "--format", "csv"]
    cases["stiffness-torque-rod.csv"] = [
        "stiffness", "--engine", str(ENGINES / "default-torque-rod.toml"), "--mount",
        "torque_rod.x", "--freq", "1:100:3", "--format", "csv"]
    return cases


CASES = _cases()


def run_case(name, out_dir: Path) -> Path:
    """Run case ``name``; its output file in ``out_dir``."""
    args = list(CASES[name])
    out = out_dir / name
    if args[0] == "stiffness":            # CSV on stdout
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 0, r.output
        out.write_text(r.stdout)
    else:
        r = CliRunner().invoke(main, args + [str(out)])
        assert r.exit_code == 0, r.output
    return out


def _number(text):
    try:
        v = float(text)
    except (TypeError, ValueError):
        return None
    return v


def _csv_columns(path: Path) -> dict:
    lines = [ln for ln in path.read_text().splitlines() if ln and not ln.startswith("#")]
    rows = list(csv.reader(lines))
    header, body = rows[0], rows[1:]
    return {h: [r[i] for r in body] for i, h in enumerate(header)}


def _json_leaves(node, path=(), out=None) -> dict:
    out = {} if out is None else out
    if isinstance(node, dict):
        for k, v in node.items():
            if k not in SKIPPED_KEYS:
                _json_leaves(v, path + (k,), out)
    elif isinstance(node, list):
        for i, v in enumerate(node):
            _json_leaves(v, path + (i,), out)
    else:
        out[path] = node
    return out


def _close(new, old, scale) -> bool:
    if math.isnan(old):
        return math.isnan(new)
    return abs(new - old) <= RTOL * abs(old) + ATOL_REL * scale


def compare_csv(new: Path, old: Path) -> list:
    a, b = _csv_columns(new), _csv_columns(old)
    bad = [f"column {h} missing" for h in b if h not in a]
    for h, col in b.items():
        if h not in a:
            continue
        if len(a[h]) != len(col):
            bad.append(f"column {h}: {len(a[h])} rows, golden {len(col)}")
            continue
        nums = [_number(x) for x in col]
        scale = max((abs(x) for x in nums if x is not None and math.isfinite(x)), default=0.0)
        for i, (x_new, x_old, v_old) in enumerate(zip(a[h], col, nums)):
            if v_old is None:
                if x_new != x_old:
                    bad.append(f"{h}[{i}]: {x_new!r} != {x_old!r}")
            elif _number(x_new) is None or not _close(_number(x_new), v_old, scale):
                bad.append(f"{h}[{i}]: {x_new} != {x_old}")
    return bad


def compare_json(new: Path, old: Path) -> list:
    a = _json_leaves(json.loads(new.read_text()))
    b = _json_leaves(json.loads(old.read_text()))
    scales = {}
    for path, v in b.items():
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            key = tuple(p for p in path if isinstance(p, str))
            scales[key] = max(scales.get(key, 0.0), abs(v))
    bad = []
    for path, v in b.items():
        if path not in a:
            bad.append(f"{path} missing")
        elif isinstance(v, bool) or v is None:
            if a[path] != v:
                bad.append(f"{path}: {a[path]!r} != {v!r}")
        elif isinstance(v, (int, float)):
            key = tuple(p for p in path if isinstance(p, str))
            if not isinstance(a[path], (int, float)) or not _close(a[path], v, scales[key]):
                bad.append(f"{path}: {a[path]} != {v}")
    return bad


@pytest.mark.parametrize("name", sorted(CASES))
def test_golden(name, tmp_path):
    new = run_case(name, tmp_path)
    old = GOLDEN / name
    bad = compare_json(new, old) if name.endswith(".json") else compare_csv(new, old)
    assert not bad, f"{name}: {len(bad)} differences, first: {bad[:5]}"


def test_comparison_can_fail(tmp_path):
    """The comparison sees a change of 1e-5 relative in one number."""
    old = GOLDEN / "modes-default.json"
    data = json.loads(old.read_text())
    data["modes"][0]["frequency_hz"] *= 1 + 1e-5
    new = tmp_path / "changed.json"
    new.write_text(json.dumps(data))
    assert compare_json(new, old) and not compare_json(old, old)


if __name__ == "__main__" and "--record" in sys.argv:
    GOLDEN.mkdir(parents=True, exist_ok=True)
    for case in CASES:
        print("recorded", run_case(case, GOLDEN))
