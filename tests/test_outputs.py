"""Output files (issue 10, item 4): mode from the umask, atomic, only what is asked, provenance,
the right key in every error, no leftovers after a failed run."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import h5py
import pytest
from click.testing import CliRunner

from powertrain.cli import main
from powertrain.errors import InputError
from powertrain.outputs import (
    OutputTransaction,
    atomic_write,
    json_text,
    sweep_stale_temps,
    write_csv,
)

QUICK = ["--from", "1000", "--to", "2000", "--step", "500"]


def _cli(args, cwd, umask=0o022):
    """Run the CLI in a subprocess under ``umask`` (stderr not a terminal: no progress bar)."""
    code = f"import os, sys; os.umask({umask}); from powertrain.cli import main; main()"
    return subprocess.run([sys.executable, "-c", code, *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def _mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.mark.parametrize("umask,expected", [(0o022, 0o644), (0o077, 0o600), (0o002, 0o664)])
def test_atomic_write_gets_the_umask_mode(tmp_path, umask, expected):
    old = os.umask(umask)
    try:
        with atomic_write(tmp_path / "a.txt") as fh:
            fh.write("x")
    finally:
        os.umask(old)
    assert _mode(tmp_path / "a.txt") == expected
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]      # no temporary file left


def test_failed_block_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_write(tmp_path / "a.txt") as fh:
            fh.write("half")
            raise RuntimeError
    assert list(tmp_path.iterdir()) == []


def test_transaction_commits_all_outputs_together(tmp_path):
    (tmp_path / "a.txt").write_text("old")
    with OutputTransaction():
        with atomic_write(tmp_path / "a.txt") as fh:
            fh.write("new")
        with atomic_write(tmp_path / "sub" / "b.txt") as fh:
            fh.write("b")
        assert (tmp_path / "a.txt").read_text() == "old"       # staged, not yet replaced
    assert (tmp_path / "a.txt").read_text() == "new"
    assert (tmp_path / "sub" / "b.txt").read_text() == "b"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.txt", "b.txt", "sub"]


def test_failed_transaction_keeps_earlier_files_and_removes_its_own(tmp_path):
    (tmp_path / "a.txt").write_text("old")
    with pytest.raises(RuntimeError):
        with OutputTransaction():
            with atomic_write(tmp_path / "a.txt") as fh:
                fh.write("new")
            with atomic_write(tmp_path / "sub" / "deeper" / "b.txt") as fh:
                fh.write("b")
            raise RuntimeError
    assert (tmp_path / "a.txt").read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["a.txt"]      # no temp, no new folder


def test_commit_replaces_all_targets_or_none(tmp_path, monkeypatch):
    """Issue 39: a target that cannot take its file at the commit (a folder put in its way
    after the work) fails the commit before any file is replaced; a rename that fails all
    the same puts back the files replaced before it."""
    import powertrain.outputs as outputs
    for check in (True, False):
        if not check:                                  # the rename itself fails
            monkeypatch.setattr(outputs, "_check_target", lambda target: None)
        (tmp_path / "a.txt").write_text("old")
        with pytest.raises(InputError, match="b.txt"):
            with OutputTransaction():
                for name in ("a.txt", "new.txt", "b.txt"):
                    with atomic_write(tmp_path / name) as fh:
                        fh.write("new")
                (tmp_path / "b.txt").mkdir()
        assert (tmp_path / "a.txt").read_text() == "old"
        assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt", "b.txt"]
        (tmp_path / "b.txt").rmdir()


def test_json_and_csv_writers_refuse_nan(tmp_path):
    """No NaN or inf reaches a JSON or CSV file: refused naming the file (and the CSV line);
    a comment line may say anything."""
    with pytest.raises(InputError, match="r.json.*non-finite"):
        json_text({"a": [1.0, float("nan")]}, tmp_path / "r.json")
    with pytest.raises(InputError, match="r.csv, line 3.*non-finite"):
        write_csv(tmp_path / "r.csv", "a,b\n1,2\n3,-inf\n")
    assert not list(tmp_path.iterdir())
    write_csv(tmp_path / "r.csv", "# nan and inf in a comment\na,b\n1,\n")
    assert json.loads(json_text({"a": None}, tmp_path / "r.json")) == {"a": None}


def test_stale_temporary_files_of_dead_processes_are_swept(tmp_path):
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True).stdout.strip()
    stale = tmp_path / f".x.csv.pt{dead}-abc123.tmp"
    mine = tmp_path / f".y.csv.pt{os.getpid()}-abc123.tmp"
    other = tmp_path / ".z.csv.abc.tmp"                          # not ours: kept
    for p in (stale, mine, other):
        p.write_text("half")
    assert sweep_stale_temps(tmp_path) == [stale]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([mine.name, other.name])


def test_modes_failing_on_its_plot_keeps_the_old_json(tmp_path):
    """Issue 18: a failing command never deletes a file it did not create."""
    (tmp_path / "m.json").write_text("old\n")
    (tmp_path / "afile").write_text("")
    r = _cli(["modes", "--json", "m.json", "--plot", "afile/p.png"], tmp_path)
    assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
    assert (tmp_path / "m.json").read_text() == "old\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "m.json"]


@pytest.mark.slow
def test_runup_outputs_0644_with_provenance_and_balancers_off(tmp_path):
    r = _cli(["runup", *QUICK, "--no-balancers", "--out", "r.h5", "--csv", "r.csv",
              "--plot", "r.png"], tmp_path)
    assert r.returncode == 0, r.stderr
    assert "wrote r.h5, r.csv, r.png" in r.stdout
    for name in ("r.h5", "r.csv", "r.png"):
        assert _mode(tmp_path / name) == 0o644, name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv", "r.h5", "r.png"]
    with h5py.File(tmp_path / "r.h5", "r") as h5:
        prov = json.loads(h5.attrs["provenance"])
        as_run = json.loads(h5.attrs["engine_as_run"])
        assert h5.attrs["command_line"].startswith("powertrain runup --from 1000")
    assert as_run["balancer"]["enabled"] is False
    assert "--no-balancers" in prov["command_line"]
    assert prov["modifications"] == ["balancer shafts switched off (--no-balancers)"]
    assert prov["powertrain_version"] and prov["created"].endswith("+00:00")
    assert {m["name"] for m in as_run["mounts"]} == {"left", "right", "gearbox"}


@pytest.mark.slow
def test_runup_effect_recorded(tmp_path):
    r = _cli(["runup", *QUICK, "--solver", "harmonic", "--quiet", "--out", "r.h5",
              "--effect", "base_compliance:c_base=400N/mm,m_base=8kg"], tmp_path)
    assert r.returncode == 0, r.stderr
    with h5py.File(tmp_path / "r.h5", "r") as h5:
        prov = json.loads(h5.attrs["provenance"])
    assert prov["effects"]["base_compliance"]["c_base"] == pytest.approx(400e3)


def test_runup_writes_only_what_is_asked(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = CliRunner().invoke(main, ["runup", *QUICK, "--solver", "harmonic"],
                           catch_exceptions=False)
    assert r.exit_code == 0
    assert "no file written" in r.output
    assert list(tmp_path.iterdir()) == []
    r = _cli(["runup", *QUICK, "--solver", "harmonic", "--csv", "only.csv"], tmp_path)
    assert r.returncode == 0 and "wrote only.csv" in r.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["only.csv"]


@pytest.mark.parametrize("args,key", [
    (["--to", "9000"], "--to"),
    (["--from", "200", "--to", "2000"], "--from"),
    (["--from", "2000", "--to", "1000"], "--to"),
    (["--step", "0"], "--step"),
    (["--from", "1000", "--to", "1e12", "--step", "1"], "--step"),
    (["--angle-step", "0"], "--angle-step"),
    (["--angle-step", "7"], "--angle-step"),
    (["--angle-step", "nan"], "--angle-step"),
])
def test_runup_errors_name_the_right_option(tmp_path, args, key):
    r = CliRunner().invoke(main, ["runup", "--out", str(tmp_path / "r.h5"), *args])
    assert r.exit_code == 1
    lines = r.output.strip().splitlines()
    assert len(lines) == 1 and f"key '{key}'" in lines[0], r.output
    assert list(tmp_path.iterdir()) == []


def test_unwritable_output_refused_before_work(tmp_path):
    (tmp_path / "file").write_text("")
    r = _cli(["runup", *QUICK, "--out", "r.h5", "--plot", "file/p.png"], tmp_path)
    assert r.returncode == 1
    assert r.stderr.count("\n") == 1 and "--plot" in r.stderr, r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


@pytest.mark.parametrize("args,key", [
    (["runup", *QUICK, "--out", "r.h5", "--csv", "./r.h5"], "--csv"),
    (["runup", "--from", "2000", "--to", "2100", "--sweep", "200", "--out", "s.h5",
      "--raw", "sub/../s.h5"], "--raw"),
    (["transient", "START", "--json", "t.out", "--plot", "t.out"], "--plot"),
])
@pytest.mark.slow
def test_two_outputs_naming_one_file_are_refused_before_work(tmp_path, args, key):
    """The second output would overwrite the first: one line naming both options."""
    (tmp_path / "sub").mkdir()
    start = str(Path(__file__).parents[1] / "examples" / "start.toml")
    r = _cli([start if a == "START" else a for a in args], tmp_path)
    assert r.returncode == 1
    assert r.stderr.count("\n") == 1 and f"key '{key}'" in r.stderr, r.stderr
    assert "also the" in r.stderr and sorted(p.name for p in tmp_path.iterdir()) == ["sub"]


def test_failure_after_writing_removes_the_earlier_outputs(tmp_path, monkeypatch):
    """A run that fails on its last output leaves none of its outputs behind."""
    from powertrain.errors import InputError
    from powertrain.results.runup import RunupResult

    def broken(self, path=None, **kw):
        raise InputError("cannot draw", file=path, key="--plot")
    monkeypatch.setattr(RunupResult, "plot", broken)
    r = CliRunner().invoke(main, ["runup", *QUICK, "--solver", "harmonic",
                                  "--out", str(tmp_path / "r.h5"),
                                  "--csv", str(tmp_path / "r.csv"),
                                  "--plot", str(tmp_path / "r.png")])
    assert r.exit_code == 1, r.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_progress_bar_quiet_when_not_a_terminal(tmp_path):
    r = _cli(["runup", *QUICK, "--solver", "harmonic"], tmp_path)
    assert r.returncode == 0 and r.stderr == ""


def test_progress_bar_shown_on_a_terminal():
    """On a TTY the bar appears; disabled (``--quiet``) it does not."""
    import io

    from powertrain.progress import progress_bar

    class FakeTTY(io.StringIO):
        def isatty(self):
            return True
    buf = FakeTTY()
    old, sys.stderr = sys.stderr, buf
    try:
        list(progress_bar(range(3), desc="x"))
        shown = buf.getvalue()
        buf.seek(0)
        buf.truncate()
        list(progress_bar(range(3), desc="x", enabled=False))
        hidden = buf.getvalue()
    finally:
        sys.stderr = old
    assert "x" in shown and "0/3" in shown and hidden == ""


def test_activity_bar_ticks_on_a_terminal_only():
    import io
    import time

    from powertrain.progress import activity

    class FakeTTY(io.StringIO):
        def isatty(self):
            return True
    buf = FakeTTY()
    old, sys.stderr = sys.stderr, buf
    try:
        with activity("work", interval=0.05):
            time.sleep(0.2)
        shown = buf.getvalue()
    finally:
        sys.stderr = old
    assert "work" in shown and "elapsed" in shown
    plain = io.StringIO()
    old, sys.stderr = sys.stderr, plain
    try:
        with activity("work", interval=0.05):
            time.sleep(0.1)
    finally:
        sys.stderr = old
    assert plain.getvalue() == ""
