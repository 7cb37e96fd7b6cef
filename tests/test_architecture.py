"""Import contract of the kernels subpackage (STYLE.md, "Kernels apart").

``src/powertrain/kernels`` holds Numba kernels over plain SI floats and arrays; it may import
numpy, numba and math only -- no I/O, plotting, CLI, model objects or other powertrain
modules (relative imports included). Checked on the source with :mod:`ast`, so nothing is
imported to check it.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

KERNELS = Path(__file__).resolve().parents[1] / "src" / "powertrain" / "kernels"
ALLOWED = {"numpy", "numba", "math"}
#: ``from __future__ import annotations`` changes syntax only; it is not a dependency.
SYNTAX_ONLY = {"__future__"}
SOURCES = sorted(KERNELS.rglob("*.py"))


def imported_modules(path: Path) -> list[tuple[int, str]]:
    """(line, top-level module) of every import statement anywhere in the file."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(node.lineno, a.name.split(".")[0]) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                found.append((node.lineno, "." * node.level + (node.module or "")))
            else:
                found.append((node.lineno, node.module.split(".")[0]))
        elif (isinstance(node, ast.Call) and isinstance(node.func, (ast.Name, ast.Attribute))
              and getattr(node.func, "id", getattr(node.func, "attr", "")) in
              ("__import__", "import_module")):
            found.append((node.lineno, "<dynamic import>"))
    return found


def test_kernels_exist():
    assert (KERNELS / "__init__.py").exists()
    assert len(SOURCES) >= 2


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_kernel_imports_only_numpy_numba_math(path):
    bad = [(line, mod) for line, mod in imported_modules(path)
           if mod not in ALLOWED | SYNTAX_ONLY]
    assert not bad, f"{path.name} imports {bad}; kernels may import only {sorted(ALLOWED)}"


def test_the_checker_catches_forbidden_imports(tmp_path):
    p = tmp_path / "k.py"
    p.write_text("import numpy as np\nfrom powertrain.units import to_si\n"
                 "from . import other\nimport matplotlib.pyplot\n")
    mods = {m for _, m in imported_modules(p)} - ALLOWED
    assert mods == {"powertrain", ".", "matplotlib"}
