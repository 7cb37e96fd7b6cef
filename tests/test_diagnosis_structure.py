"""Size limits of the diagnosis package (DEVELOPERS.md: modules that each do one step,
≤ 400 lines; functions readable at once, ≤ 60 lines)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "powertrain" / "diagnosis"
SOURCES = sorted(PACKAGE.glob("*.py"))
MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 60


def test_diagnosis_is_a_package_of_steps():
    names = {p.stem for p in SOURCES}
    assert {"data", "where", "candidates", "fit", "rule", "result"} <= names


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_module_and_function_sizes(path):
    text = path.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= MAX_MODULE_LINES, path.name
    long = [(f.name, f.end_lineno - f.lineno + 1) for f in ast.walk(ast.parse(text))
            if isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef))
            and f.end_lineno - f.lineno + 1 > MAX_FUNCTION_LINES]
    assert not long, f"{path.name}: functions over {MAX_FUNCTION_LINES} lines: {long}"
