"""The public Python API: the functions a notebook user calls are importable from the package
top, load on first use, the top namespace shows only them, and the study in
docs/guide/python-api.md runs as written and prints what the page shows under each block."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
from test_docs_commands import TRANSCRIPT, fenced_blocks, match_shown

import powertrain

ROOT = Path(__file__).resolve().parents[1]
GUIDE = ROOT / "docs" / "guide" / "python-api.md"
#: Printed before each block of the guide, to split what the blocks print.
MARK = "@@@ block "


@pytest.mark.parametrize("name", sorted(powertrain.API))
def test_every_api_name_resolves_to_a_documented_callable(name):
    obj = getattr(powertrain, name)
    assert callable(obj), name
    assert (obj.__doc__ or "").strip(), f"powertrain.{name} has no docstring"
    assert name in dir(powertrain)


def test_unknown_names_are_attribute_errors():
    with pytest.raises(AttributeError, match="no attribute 'runupp'"):
        _ = powertrain.runupp


def test_the_top_namespace_shows_only_the_public_names():
    """``dir(pt)`` lists the API, ``InputError``, ``PowertrainWarning``, ``__version__`` and
    ``API``: no
    ``annotations`` or ``importlib`` left by the module's own imports; every public name of
    before stays importable."""
    shown = dir(powertrain)
    assert "annotations" not in shown and "importlib" not in shown
    assert set(shown) == set(powertrain.__all__) | {"API"}
    assert set(powertrain.__all__) == {"InputError", "PowertrainWarning", "__version__",
                                       *powertrain.API}
    from powertrain import API, InputError, __version__  # noqa: F401
    assert powertrain.InputError is powertrain.errors.InputError


def test_import_powertrain_stays_light():
    """``import powertrain`` loads no workflow, solver or plotting module (the CLI's --help and
    a notebook's first import stay fast)."""
    code = ("import sys, powertrain; heavy = [m for m in sys.modules if m.startswith("
            "('powertrain.workflows', 'powertrain.solvers', 'powertrain.plotting', "
            "'matplotlib', 'numba'))]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]", out


def test_every_api_name_is_in_the_guide():
    text = GUIDE.read_text(encoding="utf-8")
    missing = [n for n in powertrain.API if f"`{n}(" not in text]
    assert not missing, f"not in docs/guide/python-api.md: {missing}"


def guide_blocks(path: Path = GUIDE) -> list:
    """``[(python block, its shown output or None)]`` of the guide, in order: a ```text block
    right after a ```python block (no heading between, not a ``$ `` transcript) shows what
    that block prints (the rule of the docs' commands, tests/test_docs_commands.py)."""
    blocks = fenced_blocks(path)
    out = []
    for here, after in zip(blocks, blocks[1:] + [None]):
        if here.kind != "python":
            continue
        shown = (after.lines if after is not None and after.kind == "text"
                 and not after.after_heading and after.lines
                 and not after.lines[0].startswith(TRANSCRIPT) else None)
        out.append(("\n".join(here.lines), shown, here.start))
    return out


def printed_per_block(stdout: str, n: int) -> list:
    """What each of ``n`` blocks printed, split at the :data:`MARK` lines."""
    parts = re.split(rf"^{re.escape(MARK)}\d+\n", stdout, flags=re.M)
    assert len(parts) == n + 1, stdout[-2000:]
    return parts[1:]


def test_the_guide_has_shown_outputs_to_compare():
    blocks = guide_blocks()
    assert len(blocks) >= 8
    assert sum(shown is not None for _, shown, _ in blocks) >= 7


def test_the_shown_output_check_can_fail():
    """A shown output that the block does not print is reported."""
    assert match_shown(["worst channel: left x synthesis 0.61 dB"],
                       ["worst channel: right x order_6 0.80 dB"]) is not None
    assert match_shown(["worst channel: right x order_6 0.80 dB"],
                       ["worst channel: right x order_6 0.7992 dB"]) is None


@pytest.mark.slow
def test_the_python_api_guide_runs_as_written(tmp_path):
    """The guide's Python blocks, in order, in one interpreter, in a folder prepared by
    ``powertrain examples .`` (as the guide says); what each prints matches the output shown
    under it (excerpts, ``...`` and numbers as for the docs' commands)."""
    subprocess.run([sys.executable, "-m", "powertrain.cli", "examples", "."], cwd=tmp_path,
                   check=True, capture_output=True)
    blocks = guide_blocks()
    script = "import matplotlib\nmatplotlib.use('Agg')\n" + "\n".join(
        f"print({MARK + str(k)!r}, flush=True)\n{code}" for k, (code, _, _) in
        enumerate(blocks))
    run = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True,
                         text=True, timeout=600, env={**os.environ, "MPLBACKEND": "Agg"})
    assert run.returncode == 0, run.stderr[-3000:]
    failures = []
    for (_, shown, line), printed in zip(blocks, printed_per_block(run.stdout, len(blocks))):
        if shown is not None:
            miss = match_shown(shown, printed.splitlines())
            if miss:
                failures.append(f"docs/guide/python-api.md:{line}: {miss}")
    assert not failures, "\n".join(failures)
    for name in ("runup.csv", "compare.json"):
        assert (tmp_path / name).stat().st_size > 0, name
