"""The installed package: built as a wheel, installed in a fresh venv, run from an empty folder.

Issue 10, item 1: engines/, mounts/ and examples/ are package data found with
:mod:`importlib.resources`, so ``powertrain runup`` works outside the checkout. Issue 18:
``powertrain examples DIR`` copies them into a folder, and the README's commands (the main
job, then the five-minute tour) run unchanged in an empty folder after a wheel install. The fresh venv
sees the current environment's third-party packages through a ``.pth`` line (no download, and
no editable install of this checkout), and the wheel is installed with ``--no-deps``.
"""

from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.data import FOLDERS, default_engine_path, shipped_files

ROOT = Path(__file__).resolve().parents[1]


def test_shipped_files_are_the_checkout_folders():
    """In the checkout, package data and the top-level folders are the same files (no copy)."""
    assert default_engine_path().resolve() == (ROOT / "engines" / "default.toml").resolve()
    for folder in FOLDERS:
        shipped = {p.name for p in shipped_files(folder)}
        top = {p.name for p in (ROOT / folder).iterdir() if p.is_file()}
        assert shipped == top, folder


def _examples(folder) -> object:
    return CliRunner().invoke(main, ["examples", str(folder)])


def test_examples_copies_every_shipped_file_and_leaves_identical_ones(tmp_path):
    first = _examples(tmp_path / "tour")
    assert first.exit_code == 0, first.output
    n = sum(len(shipped_files(folder)) for folder in FOLDERS)
    assert f"copied {n} files" in first.output
    for folder in FOLDERS:
        for src in shipped_files(folder):
            assert (tmp_path / "tour" / folder / src.name).read_bytes() == src.read_bytes()
    again = _examples(tmp_path / "tour")
    assert again.exit_code == 0 and "copied 0 files" in again.output, again.output


def test_examples_never_overwrites_and_copies_nothing_on_a_clash(tmp_path):
    (tmp_path / "examples").mkdir()
    mine = tmp_path / "examples" / "measured-runup.csv"
    mine.write_text("my own measurement\n")
    result = _examples(tmp_path)
    assert result.exit_code == 1
    assert result.output.strip().splitlines() == [
        f"error: {mine}, key 'FOLDER': exists and differs from the shipped file; powertrain "
        "examples never overwrites (move it or choose another folder); nothing copied"]
    assert mine.read_text() == "my own measurement\n"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["examples", "measured-runup.csv"]
    (tmp_path / "file").write_text("x")
    assert _examples(tmp_path / "file").exit_code == 1
    assert (tmp_path / "file").read_text() == "x"


def _third_party_paths() -> list[str]:
    """Site folders of the running environment, minus anything that holds this checkout."""
    paths = site.getsitepackages() + [sysconfig.get_paths()["purelib"]]
    return sorted({p for p in paths if Path(p).is_dir() and not (Path(p) / "powertrain").is_dir()})


def _clean_env(venv_dir: Path) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PATH"] = f"{venv_dir / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    env["NUMBA_CACHE_DIR"] = str(venv_dir / "numba-cache")
    return env


def readme_tour(folder: Path) -> Path:
    """The README's "A five-minute tour" section, as a Markdown file of its own in ``folder``."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    tour = folder / "tour.md"
    tour.write_text(text.split("## A five-minute tour", 1)[1].split("\n## ", 1)[0])
    return tour


def _install_wheel(tmp_path: Path) -> tuple:
    """Build the wheel, install it into a fresh venv; (venv folder, its environment)."""
    wheels = tmp_path / "wheels"
    build = subprocess.run([sys.executable, "-m", "pip", "wheel", str(ROOT), "--no-deps",
                            "-q", "-w", str(wheels)], capture_output=True, text=True)
    assert build.returncode == 0, build.stderr[-2000:]
    wheel = next(wheels.glob("powertrain-*.whl"))
    venv_dir = tmp_path / "venv"
    venv.EnvBuilder(with_pip=False).create(venv_dir)
    vpython = venv_dir / "bin" / "python"
    vsite = subprocess.run([str(vpython), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                           capture_output=True, text=True, check=True).stdout.strip()
    (Path(vsite) / "third_party.pth").write_text("\n".join(_third_party_paths()) + "\n")
    env = _clean_env(venv_dir)
    inst = subprocess.run([str(vpython), "-m", "pip", "install", "--no-deps", "-q", str(wheel)],
                          capture_output=True, text=True, env=env)
    assert inst.returncode == 0, inst.stderr[-2000:]
    return venv_dir, env


def _check_no_scaffolding(wheel: Path) -> None:
    """The wheel holds the package and its data only: no ``benchmarks/`` and no truth
    generator, case plan, scoring or rate-sizing module (tests/test_architecture.py)."""
    from test_architecture import SCAFFOLDING
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names}
    assert tops <= {"powertrain", f"{wheel.name.split('-')[0]}-{wheel.name.split('-')[1]}.dist-info"}, tops
    assert not [n for n in names if n.endswith(".py") and Path(n).stem in SCAFFOLDING]


@pytest.mark.slow
def test_wheel_runs_the_readme_unchanged_in_an_empty_folder(tmp_path):
    """Issue 18: every command README.md shows (the front door's main job, then the
    five-minute tour), as shown, in an empty folder after a wheel install; each named output
    exists and each shown output matches (the docs test's rules, tests/test_docs_commands.py,
    which leaves README.md to this test so that its commands run once). Each command runs in
    its own process through the wheel's console script, so that the package data and the
    kernels' first compilation are the installed ones."""
    from test_docs_commands import check_shown, commands_of, run_command, shown_outputs
    venv_dir, env = _install_wheel(tmp_path)
    _check_no_scaffolding(next((tmp_path / "wheels").glob("powertrain-*.whl")))
    env["MPLBACKEND"] = "Agg"
    empty = tmp_path / "empty"
    empty.mkdir()
    where = subprocess.run(["python", "-c", "import powertrain; print(powertrain.__file__)"],
                           capture_output=True, text=True, env=env, cwd=empty, check=True)
    assert Path(where.stdout.strip()).resolve().is_relative_to(venv_dir.resolve())
    script = shutil.which("powertrain", path=env["PATH"])
    assert script and Path(script).resolve().is_relative_to(venv_dir.resolve()), script
    commands = [c for c in commands_of(ROOT / "README.md") if c.text]
    tour = [c.text for c in commands_of(readme_tour(tmp_path), root=tmp_path)]
    assert len(tour) >= 8 and tour[0] == "powertrain examples ."
    assert [c.text for c in commands][-len(tour):] == tour
    printed = {}
    for cmd in commands:
        failure = run_command(cmd, empty, env, printed.setdefault(cmd.block, []),
                              in_process=False)     # the wheel's console script
        assert failure is None, failure
    for shown in shown_outputs(ROOT / "README.md"):
        failure = check_shown(shown, printed.get(shown.block, []))
        assert failure is None, failure
    lines = (empty / "runup.csv").read_text().splitlines()
    assert lines[0].startswith("mount,direction,quantity,rpm")
    assert {ln.split(",")[3] for ln in lines[1:]} == {str(r) for r in range(1000, 6001, 500)}
