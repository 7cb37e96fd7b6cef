"""Layers enforced by import-linter (pyproject.toml, [tool.importlinter]), ordered by the data
flow of docs/architecture.md: every top-level unit is in the layers contract; kernels import
nothing else of the package; file-format readers and writers (iotools) only at the edges."""

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


def test_iotools_is_kept_at_the_edges():
    """No file-format module below the workflows: the whole iotools package is forbidden to
    the model, physics, solvers, effects, analysis and plotting."""
    contract = _contracts()["iotools-at-the-edges"]
    assert "powertrain.iotools" in contract["forbidden_modules"]
    for unit in ("models", "assembly", "physics", "kernels", "solvers", "effects", "analysis",
                 "plotting"):
        assert f"powertrain.{unit}" in contract["source_modules"], unit


def _layer_units() -> set[str]:
    names = set()
    for layer in _contracts()["layers"]["layers"]:
        for part in layer.replace(":", "|").split("|"):
            names.add(part.strip().removeprefix("powertrain."))
    return names


def test_every_top_level_unit_is_in_the_layers_contract():
    """Every module and package at the top of the package sits in one layer: none is left
    outside the contract as a 'leaf'."""
    src = ROOT / "src/powertrain"
    names = {p.stem for p in src.glob("*.py") if p.stem != "__init__"} | {
        p.name for p in src.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    missing = names - _layer_units()
    assert not missing, sorted(missing)
    assert not _layer_units() - names, sorted(_layer_units() - names)


def test_ignored_imports_only_shrink():
    """The layers contract may list known upward imports only while they are being removed;
    the list must not grow."""
    assert len(_contracts()["layers"].get("ignore_imports", [])) <= 5


def _cycles(graph) -> list[list[str]]:
    """Strongly connected groups of more than one module in the direct-import graph."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.find_modules_directly_imported_by(v):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for module in sorted(graph.modules):
        if module not in index:
            visit(module)
    return found


def test_no_import_cycle_between_modules():
    """Issue 19: no cycle anywhere in the package (e.g. the raw readers and their entry point,
    the command group and its commands)."""
    grimp = pytest.importorskip("grimp")
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    assert _cycles(grimp.build_graph("powertrain")) == []


def test_the_cycle_finder_finds_a_cycle():
    class Graph:
        modules = {"a", "b", "c"}

        @staticmethod
        def find_modules_directly_imported_by(m):
            return {"a": {"b"}, "b": {"a"}, "c": set()}[m]

    assert _cycles(Graph()) == [["a", "b"]]
