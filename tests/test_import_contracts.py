"""Layers enforced by import-linter (pyproject.toml, [tool.importlinter]): cli -> workflows ->
model and assembly -> physics and kernels; kernels import nothing else of the package;
file-format readers and writers (iotools) only at the edges."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:            # pragma: no cover (Python < 3.11)
    import tomli as tomllib

ROOT = Path(__file__).resolve().parents[1]


def _contracts():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    return {c["id"]: c for c in conf["tool"]["importlinter"]["contracts"]}


def test_lint_imports_passes():
    exe = shutil.which("lint-imports") or str(Path(sys.executable).parent / "lint-imports")
    if not Path(exe).exists():
        pytest.fail("lint-imports not installed (pip install -e '.[test]')")
    run = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-2000:]
    assert "0 broken" in run.stdout


def test_every_iotools_format_module_is_kept_at_the_edges():
    forbidden = set(_contracts()["iotools-at-the-edges"]["forbidden_modules"])
    modules = {f"powertrain.iotools.{p.stem}" for p in (ROOT / "src/powertrain/iotools")
               .glob("*.py") if p.stem not in ("__init__", "atomic")}
    assert modules <= forbidden, sorted(modules - forbidden)


def test_every_top_level_module_is_placed():
    """A new top-level module must be put in a layer, or be a leaf utility listed here."""
    leaves = {"errors", "units", "parallel", "progress", "provenance", "plotting",
              "plotting_body", "plotting_orders", "tracked", "results", "analysis", "iotools", "data", "cli"}
    layers = " ".join(_contracts()["layers"]["layers"])
    src = ROOT / "src/powertrain"
    names = {p.stem for p in src.glob("*.py") if p.stem != "__init__"} | {
        p.name for p in src.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    missing = {n for n in names - leaves if f"powertrain.{n}" not in layers}
    assert not missing, sorted(missing)
