"""Shared test set-up: the data paths, the engines (each file read once per session), the
assembled rigid system and hypothesis' fixed draws.

``engine`` is the engine of the test module: the file named by the module's
``ENGINE_FILE`` (e.g. ``ENGINE_FILE = MODAL``) or the shipped default engine. Engines are
immutable, so one object per file serves every module.

Every random draw of the suite is seeded (the seed is named in the failure message);
hypothesis runs derandomised (the profile ``fixed``: the same examples every run, the
failing example printed when one fails).
"""

from __future__ import annotations

import functools
from pathlib import Path

import pytest
from hypothesis import settings

from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine

settings.register_profile("fixed", derandomize=True)
settings.load_profile("fixed")

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ROOT / "engines"
MOUNTS = ROOT / "mounts"
EXAMPLES = ROOT / "examples"
DEFAULT_ENGINE = Path(DEFAULT_ENGINE_PATH)
MODAL = DEFAULT_ENGINE.parent / "default-modal-body.toml"
TORQUE_ROD = DEFAULT_ENGINE.parent / "default-torque-rod.toml"


@functools.cache
def shared_engine(path=DEFAULT_ENGINE):
    """The engine of ``path``, read once per session."""
    return read_engine(Path(path))


@pytest.fixture(scope="module")
def engine(request):
    """The module's ``ENGINE_FILE`` engine, or the default engine."""
    return shared_engine(getattr(request.module, "ENGINE_FILE", DEFAULT_ENGINE))


@pytest.fixture(scope="session")
def default_engine():
    return shared_engine(DEFAULT_ENGINE)


@pytest.fixture(scope="module")
def system(engine):
    """The module engine's body on its mounts, rigid chassis (:func:`powertrain.assembly.assemble`)."""
    from powertrain.assembly import assemble
    b = engine.body
    return assemble(b.mass, b.cg, b.inertia, engine.mounts)


def pytest_collection_modifyitems(config, items):
    """The rate tests first, the longest (``long_rates``) leading: with the tests shared out
    as they free up (pytest-xdist), the few minutes-long ones start at once and the many short
    ones fill in around them, so that the test processes finish together (longest first:
    collected last, a plan test could start in the suite's last minutes and run on alone).
    The browser tests run last, when the Chromium install that .ci/run starts in the
    background has ended. The order is otherwise kept (a stable sort)."""
    def rank(item):
        return (item.get_closest_marker("long_rates") is None,
                item.get_closest_marker("rates") is None,
                item.get_closest_marker("browser") is not None)
    items.sort(key=rank)
