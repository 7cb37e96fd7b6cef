"""The architecture as written: the kernels' import contract and docs/architecture.md.

The module map of docs/architecture.md names every package and top-level module of
``src/powertrain`` and nothing else, every module it names inside a package exists, and its
list of layers is the import-linter ``layers`` contract in its order.

Import contract of the kernels subpackage (STYLE.md, "Kernels apart"):

``src/powertrain/kernels`` holds Numba kernels over plain SI floats and arrays; it may import
numpy, numba, math and its own modules (absolute imports) only -- no I/O, plotting, CLI,
model objects or other powertrain modules (relative imports included). Checked on the
source with :mod:`ast`, so nothing is imported to check it.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

KERNELS = Path(__file__).resolve().parents[1] / "src" / "powertrain" / "kernels"
ALLOWED = {"numpy", "numba", "math", "powertrain.kernels"}
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
            elif node.module.startswith("powertrain.kernels."):
                found.append((node.lineno, "powertrain.kernels"))
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


# ---------------------------------------------------------------- docs/architecture.md
DOC = Path(__file__).resolve().parents[1] / "docs" / "architecture.md"
PACKAGE = KERNELS.parent


def _text_block(section: str) -> list[str]:
    """Lines of the first ```text block under the ``## section`` heading of the doc."""
    text = DOC.read_text(encoding="utf-8")
    head = text.index(f"\n## {section}\n")
    start = text.index("```text\n", head) + len("```text\n")
    return text[start:text.index("```", start)].splitlines()


def doc_module_map() -> dict[str, set[str]]:
    """Top-level unit (``cli/``, ``assembly.py``) -> modules named under it (``runup.py``)."""
    units: dict[str, set[str]] = {}
    current = None
    for line in _text_block("Module map"):
        if not line.strip():
            continue
        name = line.split()[0]
        if not line.startswith(" "):
            assert name.endswith(("/", ".py")), f"module map line {line!r}"
            current = name
            units[current] = set()
        else:
            assert current is not None and current.endswith("/"), f"module map line {line!r}"
            units[current].add(name)
    return units


def tree_units() -> set[str]:
    """Packages (``cli/``) and modules (``assembly.py``) at the top of src/powertrain."""
    return ({p.name + "/" for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
            | {p.name for p in PACKAGE.glob("*.py") if p.name != "__init__.py"})


def test_module_map_names_every_top_level_unit_and_only_those():
    named = set(doc_module_map())
    assert not named - tree_units(), f"named in docs/architecture.md, not in the package: " \
        f"{sorted(named - tree_units())}"
    assert not tree_units() - named, f"in the package, missing from the module map of " \
        f"docs/architecture.md: {sorted(tree_units() - named)}"


def tree_modules(unit: str) -> set[str]:
    """Modules (``runup.py``) of the package ``unit`` (``cli/``), ``__init__.py`` aside."""
    return {p.name for p in (PACKAGE / unit).glob("*.py") if p.name != "__init__.py"}


def test_every_module_the_map_names_inside_a_package_exists():
    missing = [f"{unit}{mod}" for unit, mods in doc_module_map().items() for mod in mods
               if not (PACKAGE / unit / mod).is_file()]
    assert not missing, f"docs/architecture.md names modules that do not exist: {missing}"


def test_every_module_of_a_package_is_in_the_map():
    """The map is the package tree: a module added to a package is named under it."""
    unnamed = [f"{unit}{mod}" for unit, mods in doc_module_map().items()
               if unit.endswith("/") and unit != "data/"
               for mod in sorted(tree_modules(unit) - mods)]
    assert not unnamed, f"modules missing from the module map of docs/architecture.md: {unnamed}"


def test_layers_of_the_doc_are_the_contract_in_its_order():
    try:
        import tomllib
    except ModuleNotFoundError:                     # pragma: no cover (Python < 3.11)
        import tomli as tomllib
    conf = tomllib.loads((PACKAGE.parents[1] / "pyproject.toml").read_text(encoding="utf-8"))
    layers = next(c for c in conf["tool"]["importlinter"]["contracts"]
                  if c["id"] == "layers")["layers"]
    contract = [" ".join(layer.replace("powertrain.", "").split()) for layer in layers]
    doc = [line.split("  ")[0].strip() for line in _text_block("Layers") if line.strip()]
    assert doc == contract


def test_the_map_checker_sees_a_missing_and_a_stale_unit(tmp_path, monkeypatch):
    """The comparison can fail: a unit dropped from the doc and one the package lacks."""
    doc = DOC.read_text(encoding="utf-8").replace("\nunits.py ", "\nno_such_unit.py ")
    fake = tmp_path / "architecture.md"
    fake.write_text(doc, encoding="utf-8")
    monkeypatch.setattr(sys.modules[__name__], "DOC", fake)
    named = set(doc_module_map())
    assert "units.py" in tree_units() - named
    assert "no_such_unit.py" in named - tree_units()


# ---------------------------------------------------------------- sizes (issue 19)
def _code_metrics():
    """``scripts/code_metrics.py`` measured on this checkout (one rule, printed and tested)."""
    import importlib.util
    path = PACKAGE.parents[1] / "scripts" / "code_metrics.py"
    spec = importlib.util.spec_from_file_location("code_metrics", path)
    mod = sys.modules.setdefault("code_metrics", importlib.util.module_from_spec(spec))
    spec.loader.exec_module(mod)        # registered first: its dataclass looks itself up
    return mod, mod.measure(PACKAGE)


def test_no_module_over_the_size_limit_and_few_loose_modules():
    cm, m = _code_metrics()
    assert not m.long_modules, f"modules over {cm.MODULE_MAX} lines: {m.long_modules}"
    assert len(m.loose_modules) <= cm.LOOSE_MAX, m.loose_modules


def test_no_function_over_the_size_limit_outside_kernels():
    cm, m = _code_metrics()
    assert not m.long_functions, f"functions over {cm.FUNCTION_MAX} lines: {m.long_functions}"


def test_cli_commands_are_thin():
    """A command parses, calls one library function, prints and writes (issue 19)."""
    cm, m = _code_metrics()
    assert not m.long_commands, f"CLI commands over {cm.COMMAND_MAX} lines: {m.long_commands}"


def test_no_variant_is_chosen_by_comparing_its_name():
    """Chassis, solver and combustion variants are types chosen once (in the file readers);
    no ``x.model == "modal"`` or ``solver == "harmonic"`` elsewhere."""
    _, m = _code_metrics()
    assert not m.variant_comparisons, m.variant_comparisons


def test_the_size_checker_can_fail(tmp_path):
    cm, _ = _code_metrics()
    pkg = tmp_path / "powertrain"
    (pkg / "cli").mkdir(parents=True)
    body = "\n".join(f"    x{i} = {i}" for i in range(70))
    (pkg / "long.py").write_text(f"def f(solver):\n{body}\n    return solver == 'newmark'\n")
    (pkg / "cli" / "c.py").write_text(f"@main.command()\ndef c():\n{body}\n")
    m = cm.measure(pkg)
    assert [f[1] for f in m.long_functions] == ["f", "c"] or {f[1] for f in m.long_functions} \
        == {"f", "c"}
    assert [c[1] for c in m.long_commands] == ["c"]
    assert len(m.variant_comparisons) == 1


def test_the_line_count_tells_each_line_once(tmp_path):
    """``code_metrics.line_kinds``: every line once, a docstring's blank line as docstring."""
    cm, _ = _code_metrics()
    pkg = tmp_path / "powertrain"
    pkg.mkdir()
    (pkg / "m.py").write_text('"""Doc.\n\nMore."""\n\n# note\nx = 1  # end\n\n\n'
                              'def f():\n    """One."""\n    return x\n')
    assert cm.line_kinds(pkg) == {"total": 11, "code": 3, "docstrings": 4, "blank": 3,
                                  "comments": 1}


# ------------------------------------------------- the benchmark's scaffolding (issue 36)
#: Modules of the blind benchmark and the rate tests, which live in ``benchmarks/`` (not
#: installed): the truth generator, its truth effects, case plans, scoring and rate sizing.
SCAFFOLDING = {"validation", "truth", "kinds", "cases", "passive", "plans", "scoring",
               "sizing", "rates", "rate_tests", "signals"}
#: Names only the scaffolding defines (a module moved back under another name still shows).
SCAFFOLDING_DEFS = ("simulate_truth", "case_plan", "is_detectable", "wilson_interval",
                    "sequential_plan", "make_plan_case", "passive_plan", "fresh_seed")


def scaffolding_in(package: Path) -> list:
    """Modules and packages of ``package`` named as the scaffolding, and functions the
    scaffolding defines, as ``path`` or ``path:name``."""
    found = [str(p.relative_to(package)) for p in package.rglob("*")
             if (p.suffix == ".py" and p.stem in SCAFFOLDING)
             or ((p / "__init__.py").is_file() and p.name in SCAFFOLDING)]
    for path in package.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        found += [f"{path.relative_to(package)}:{node.name}" for node in ast.walk(tree)
                  if isinstance(node, (ast.FunctionDef, ast.ClassDef))
                  and node.name in SCAFFOLDING_DEFS]
    return found


def test_the_package_holds_no_truth_generator_case_plan_scoring_or_rate_sizing():
    """The installed package is the product: the benchmark's scaffolding is in benchmarks/,
    beside it, and the wheel takes only src/ (``[tool.setuptools.packages.find]``; the wheel
    test checks the built wheel the same way)."""
    try:
        import tomllib
    except ModuleNotFoundError:                     # pragma: no cover (Python < 3.11)
        import tomli as tomllib
    assert scaffolding_in(PACKAGE) == []
    root = PACKAGE.parents[1]
    conf = tomllib.loads((root / "pyproject.toml").read_text(encoding="utf-8"))
    assert conf["tool"]["setuptools"]["packages"]["find"]["where"] == ["src"]
    assert (root / "benchmarks" / "__init__.py").is_file()
    assert {p.stem for p in (root / "benchmarks").glob("*.py")} >= SCAFFOLDING - {"validation"}


def test_the_scaffolding_checker_can_fail(tmp_path):
    pkg = tmp_path / "powertrain"
    (pkg / "validation").mkdir(parents=True)
    (pkg / "validation" / "__init__.py").write_text("")
    (pkg / "tools.py").write_text("def wilson_interval(k, n):\n    return k / n\n")
    assert sorted(scaffolding_in(pkg)) == ["tools.py:wilson_interval", "validation"]


def test_no_re_exports_below_the_package_top():
    """Every symbol is imported from its home: no ``noqa: F401`` hand-on imports and no module
    ``__getattr__`` anywhere but the package's own ``__init__`` (the public API)."""
    src = PACKAGE
    found = []
    for path in sorted(src.rglob("*.py")):
        text = path.read_text()
        if "noqa: F401" in text:
            found.append(f"{path.relative_to(src)}: noqa: F401")
        tree = ast.parse(text)
        if path != src / "__init__.py" and any(
                isinstance(n, ast.FunctionDef) and n.name == "__getattr__" for n in tree.body):
            found.append(f"{path.relative_to(src)}: module __getattr__")
    assert not found, found
