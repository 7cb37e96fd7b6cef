"""State you can see: no module-level mutable state and no writes past a frozen dataclass.

Checked on the source of ``src/powertrain`` with :mod:`ast`, so that it stays true:

* no module-level name is bound to an empty mutable container (a list, dict or set literal,
  or a call of a container type with nothing in it: ``dict()``, ``defaultdict(list)``,
  ``weakref.WeakKeyDictionary()``...), the shape of a registry filled at run time or a
  cache; memoisation lives in the objects that own it (:mod:`powertrain.models.memo`), the
  active output transaction and the recorded command line in context variables;
* no ``object.__setattr__`` anywhere: a frozen dataclass is built with its values, or
  copied with ``dataclasses.replace``.

Also: a model's memo is not part of its value (a copy and a pickle start empty) and a
replaced model starts with an empty one.
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import pickle
from pathlib import Path

import pytest

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine

SRC = Path(__file__).resolve().parents[1] / "src" / "powertrain"
SOURCES = sorted(SRC.rglob("*.py"))
#: Container types whose call with no items makes an empty mutable container.
CONTAINERS = {"dict", "list", "set", "bytearray", "defaultdict", "OrderedDict", "deque",
              "Counter", "ChainMap", "WeakKeyDictionary", "WeakValueDictionary", "WeakSet"}


def _module_statements(body):
    """The statements run at import: the module's, and those of its ``if``, ``try``,
    ``with`` and ``for`` blocks (not the bodies of functions and classes)."""
    for node in body:
        yield node
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            continue
        for field in ("body", "orelse", "finalbody"):
            yield from _module_statements(getattr(node, field, []))
        for handler in getattr(node, "handlers", []):
            yield from _module_statements(handler.body)


def _empty_container(value) -> bool:
    if isinstance(value, ast.List):
        return not value.elts
    if isinstance(value, ast.Dict):
        return not value.keys
    if isinstance(value, ast.Call):
        func = value.func
        name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
        if name not in CONTAINERS:
            return False
        items = value.args[1:] if name == "defaultdict" else value.args
        return not items and not value.keywords
    return False


def module_level_containers(source: str) -> list[tuple[int, str]]:
    """(line, name) of every module-level name bound to an empty mutable container."""
    found = []
    for node in _module_statements(ast.parse(source).body):
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, ast.AnnAssign) and node.value is not None:
            targets, value = [node.target], node.value
        else:
            continue
        if _empty_container(value):
            found += [(node.lineno, ast.unparse(t)) for t in targets]
    return found


def setattr_past_freeze(source: str) -> list[int]:
    """Lines of every ``object.__setattr__`` (called or not)."""
    return [node.lineno for node in ast.walk(ast.parse(source))
            if isinstance(node, ast.Attribute) and node.attr == "__setattr__"
            and isinstance(node.value, ast.Name) and node.value.id == "object"]


def _rel(path):
    return str(path.relative_to(SRC))


@pytest.mark.parametrize("path", SOURCES, ids=_rel)
def test_no_module_level_mutable_container(path):
    found = module_level_containers(path.read_text(encoding="utf-8"))
    assert not found, (f"{_rel(path)}: module-level mutable state {found}; keep it in the "
                       "object that owns it, pass it, or use a contextvars.ContextVar")


@pytest.mark.parametrize("path", SOURCES, ids=_rel)
def test_no_object_setattr(path):
    lines = setattr_past_freeze(path.read_text(encoding="utf-8"))
    assert not lines, (f"{_rel(path)}: object.__setattr__ at lines {lines}; build the value "
                       "before the frozen dataclass, or use dataclasses.replace")


def test_the_checkers_catch_state_and_setattr():
    bad = ("import weakref\nfrom collections import defaultdict\n_A = []\n_B: dict = {}\n"
           "_C = set()\nif True:\n    _D = weakref.WeakKeyDictionary()\n"
           "_E = defaultdict(list)\n")
    assert [n for _, n in module_level_containers(bad)] == ["_A", "_B", "_C", "_D", "_E"]
    fine = ("A = [1, 2]\nB = {'a': 1}\nC = ()\nD = frozenset()\nE = dict(a=1)\n"
            "def f():\n    x = []\n    return x\nclass K:\n    y = {}\n")
    assert module_level_containers(fine) == []
    assert setattr_past_freeze("def f(self):\n    object.__setattr__(self, 'a', 1)\n") == [2]
    assert setattr_past_freeze("def f(self):\n    setattr(self, 'a', 1)\n") == []


def test_a_models_memo_is_not_part_of_its_value():
    """The engine, crank train and combustion memos fill as they are used; a deep copy, a
    pickle and a replaced model start empty and give the same values."""
    engine = read_engine(DEFAULT_ENGINE_PATH)
    work = engine.indicated_work(3000.0)
    assert engine._cache and engine.crank._memo and engine.combustion._memo
    for other in (pickle.loads(pickle.dumps(engine)), copy.deepcopy(engine),
                  engine.replace(name="copy")):
        assert not other._cache
        assert (work == other.indicated_work(3000.0)).all()
    for part in (engine.crank, engine.combustion):
        for other in (pickle.loads(pickle.dumps(part)), copy.deepcopy(part),
                      dataclasses.replace(part)):
            assert not other._memo
