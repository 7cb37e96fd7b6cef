"""Size and shape of the package's code, as issue 19 measures it.

Prints, for ``src/powertrain`` (or the checkout given as the first argument):

* functions over 60 lines outside ``kernels/`` (a function's lines run from its ``def`` to its
  last statement, docstring included, decorators not);
* modules over 500 lines;
* CLI command functions (decorated with ``@main.command``) over 40 lines;
* comparisons of a chassis, solver or combustion model *name* with a string
  (``x.model == "modal"``, ``solver == "harmonic"``) outside the file readers (``iotools``);
* modules loose at the top of the package (``__init__.py`` not counted);
* the package's lines, each counted once as docstring, blank, comment or code.

The last line is a one-line summary. ``tests/test_architecture.py`` holds the same limits.

    python scripts/code_metrics.py            # this checkout
    python scripts/code_metrics.py ../other   # another checkout (e.g. a worktree of an old commit)
"""

from __future__ import annotations

import ast
import sys
from dataclasses import dataclass
from pathlib import Path

FUNCTION_MAX = 60
MODULE_MAX = 500
COMMAND_MAX = 40
LOOSE_MAX = 8
#: Attribute or variable names whose comparison with a string literal selects a variant.
VARIANT_NAMES = ("model", "solver", "stepper", "chassis", "combustion")


@dataclass
class Metrics:
    long_functions: list      # (path, name, lines)
    long_modules: list        # (path, lines)
    long_commands: list       # (path, name, lines)
    variant_comparisons: list  # (path, line, text)
    loose_modules: list       # names

    def summary(self) -> str:
        return (f"functions > {FUNCTION_MAX} lines (outside kernels): {len(self.long_functions)}; "
                f"modules > {MODULE_MAX} lines: {len(self.long_modules)}; CLI commands > "
                f"{COMMAND_MAX} lines: {len(self.long_commands)}; variant-name comparisons: "
                f"{len(self.variant_comparisons)}; loose top-level modules: "
                f"{len(self.loose_modules)}")


def _is_command(node) -> bool:
    return any("command" in ast.unparse(d) for d in node.decorator_list)


def _span(node) -> int:
    """Lines from ``def`` to the last statement (docstring included, decorators not)."""
    return node.end_lineno - node.lineno + 1


def _variant_comparison(node) -> bool:
    """``<...>.model == "x"`` or ``solver != "y"`` style comparisons with a string."""
    if not isinstance(node, ast.Compare) or not any(
            isinstance(op, (ast.Eq, ast.NotEq, ast.In, ast.NotIn)) for op in node.ops):
        return False
    sides = [node.left, *node.comparators]
    has_string = any(isinstance(s, ast.Constant) and isinstance(s.value, str) for s in sides)
    has_string |= any(isinstance(s, (ast.Tuple, ast.List, ast.Set)) and s.elts and all(
        isinstance(e, ast.Constant) and isinstance(e.value, str) for e in s.elts) for s in sides)
    named = any((isinstance(s, ast.Attribute) and s.attr in VARIANT_NAMES)
                or (isinstance(s, ast.Name) and s.id in VARIANT_NAMES) for s in sides)
    return has_string and named


def measure(package: Path) -> Metrics:
    m = Metrics([], [], [], [], [])
    for path in sorted(package.rglob("*.py")):
        rel = path.relative_to(package).as_posix()
        text = path.read_text(encoding="utf-8")
        lines = text.count("\n") + 1
        if lines > MODULE_MAX:
            m.long_modules.append((rel, lines))
        if path.parent == package and path.name != "__init__.py":
            m.loose_modules.append(path.stem)
        tree = ast.parse(text, filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                span = _span(node)
                if rel.startswith("cli/") and _is_command(node) and span > COMMAND_MAX:
                    m.long_commands.append((rel, node.name, span))
                if not rel.startswith("kernels/") and span > FUNCTION_MAX:
                    m.long_functions.append((rel, node.name, span))
            elif _variant_comparison(node) and not rel.startswith("iotools/"):
                m.variant_comparisons.append((rel, node.lineno, ast.unparse(node)))
    return m


def _docstring_lines(tree) -> set:
    """Line numbers of the module's, classes' and functions' docstrings."""
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            first = node.body[0] if node.body else None
            if (isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant)
                    and isinstance(first.value.value, str)):
                out.update(range(first.lineno, first.end_lineno + 1))
    return out


def line_kinds(package: Path) -> dict:
    """``{"total", "code", "docstrings", "blank", "comments"}`` over the package's modules:
    a line inside a docstring counts as docstring, else blank, comment (``#`` first) or code."""
    n = dict.fromkeys(("total", "code", "docstrings", "blank", "comments"), 0)
    for path in sorted(package.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        doc = _docstring_lines(ast.parse(text))
        for i, line in enumerate(text.splitlines(), 1):
            kind = ("docstrings" if i in doc else "blank" if not line.strip()
                    else "comments" if line.lstrip().startswith("#") else "code")
            n[kind] += 1
            n["total"] += 1
    return n


def main(argv: list[str]) -> None:
    root = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    m = measure(root / "src" / "powertrain")
    for rel, name, n in m.long_functions:
        print(f"function {rel}:{name} {n} lines")
    for rel, n in m.long_modules:
        print(f"module {rel} {n} lines")
    for rel, name, n in m.long_commands:
        print(f"command {rel}:{name} {n} lines")
    for rel, line, text in m.variant_comparisons:
        print(f"variant {rel}:{line} {text}")
    print("loose top-level modules: " + ", ".join(m.loose_modules))
    n = line_kinds(root / "src" / "powertrain")
    print(f"lines: {n['total']} (code {n['code']}, docstrings {n['docstrings']}, blank "
          f"{n['blank']}, comments {n['comments']})")
    print(m.summary())


if __name__ == "__main__":
    main(sys.argv)
