"""The public API documents itself: every public function and class of the library layers
has a docstring, and a numpydoc ``Parameters`` section names every parameter it has
(python-control's docstrings_test idea, STYLE.md item 11)."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re

import pytest

import powertrain

LAYERS = ("physics", "solvers", "analysis", "models", "kernels", "iotools", "results")


def _modules():
    for layer in LAYERS:
        pkg = importlib.import_module(f"powertrain.{layer}")
        yield pkg
        for info in pkgutil.iter_modules(pkg.__path__):
            yield importlib.import_module(f"powertrain.{layer}.{info.name}")
    for name in ("assembly", "workflows.runup", "units", "errors", "outputs"):
        yield importlib.import_module(f"powertrain.{name}")


def _public_objects():
    for mod in _modules():
        for name, obj in vars(mod).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != mod.__name__:
                continue
            if inspect.isfunction(obj) or inspect.isclass(obj):
                yield f"{mod.__name__}.{name}", obj
            elif hasattr(obj, "py_func"):          # numba dispatcher
                yield f"{mod.__name__}.{name}", obj.py_func


def _params_section(doc):
    m = re.search(r"^Parameters\n-+\n(.*?)(?:\n\n[A-Z][a-z]+\n-+\n|\Z)", doc, re.S | re.M)
    return m.group(1) if m else None


OBJECTS = sorted(_public_objects(), key=lambda t: t[0])


def test_there_is_something_to_check():
    assert len(OBJECTS) > 40
    assert powertrain.__version__


@pytest.mark.parametrize("name,obj", OBJECTS, ids=[n for n, _ in OBJECTS])
def test_public_object_has_docstring(name, obj):
    assert inspect.getdoc(obj), f"{name} has no docstring"


WITH_PARAMETERS = [(n, o) for n, o in OBJECTS
                   if inspect.isfunction(o) and _params_section(inspect.getdoc(o) or "")]


@pytest.mark.parametrize("name,obj", WITH_PARAMETERS, ids=[n for n, _ in WITH_PARAMETERS])
def test_parameters_section_names_every_parameter(name, obj):
    section = _params_section(inspect.getdoc(obj) or "")
    documented = set(re.findall(r"^(\*{0,2}\w+(?:\s*,\s*\w+)*)\s*(?::|$)", section, re.M))
    names = {n.strip().lstrip("*") for entry in documented for n in entry.split(",")}
    sig = [p for p in inspect.signature(obj).parameters if p not in ("self", "cls")]
    missing = [p for p in sig if p not in names and p.lstrip("*") not in names]
    assert not missing, f"{name}: parameters not documented: {missing}"
