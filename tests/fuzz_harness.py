"""Malformed-input campaign shared by ``tests/test_fuzz_inputs.py`` (bounded, in CI) and
``scripts/fuzz_inputs.py`` (longer run).

Each *case* is a set of input files (valid seeds mutated by hypothesis) plus one CLI command.
The command runs in a persistent worker process (imports paid once; a memory limit so that a
runaway allocation fails instead of swapping; killed and restarted on a timeout) and its
outcome is classified:

* ``ok``: exit 0, every output file and stdout free of NaN/inf;
* ``clean_error``: exit 1 with one line on stderr, ``error: ...`` naming the mutated file
  (or the mutated option), no output file left; click's own usage errors (exit 2) count too;
* ``traceback``, ``hang`` (timeout), ``nan_output``, ``leftover`` (a failed run left an output
  file, or any run a temporary ``.NAME.*.tmp`` file), ``lost_file`` (a file that was in the
  folder before, an input or an earlier output, is gone or changed after a failed run, or
  after a successful run that was not asked to write it) and ``unclear_error`` (exit 1 but
  not one line naming the file or key): failures.
"""

from __future__ import annotations

import copy
import json
import math
import os
import re
import select
import shutil
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
FAILURES = ("traceback", "hang", "nan_output", "leftover", "lost_file", "unclear_error")
#: Seconds a single command may take before it counts as a hang.
TIMEOUT = 60.0
#: Address-space limit of the worker [bytes].
MEMORY_LIMIT = 3 * 2 ** 30

_WORKER = r"""
import contextlib, io, json, os, resource, sys, traceback, warnings
resource.setrlimit(resource.RLIMIT_AS, (int(sys.argv[1]), int(sys.argv[1])))
from powertrain.cli import main
for line in sys.stdin:
    req = json.loads(line)
    os.chdir(req["cwd"])
    out, err = io.StringIO(), io.StringIO()
    tb = ""
    code = 0
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            main.main(req["args"], prog_name="powertrain", standalone_mode=True)
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except BaseException:
            tb = traceback.format_exc()
            code = -1
    sys.__stdout__.write(json.dumps({"code": code, "stdout": out.getvalue()[-20000:],
                                     "stderr": err.getvalue()[-20000:], "traceback": tb}) + "\n")
    sys.__stdout__.flush()
"""


class Worker:
    """A persistent ``powertrain`` CLI process fed one command at a time."""

    def __init__(self, timeout: float = TIMEOUT):
        self.timeout = timeout
        self.proc = None

    def _start(self):
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
        self.proc = subprocess.Popen([sys.executable, "-c", _WORKER, str(MEMORY_LIMIT)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     env=env)

    def close(self):
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc.stdin.close()
            self.proc.stdout.close()
            self.proc = None

    def run(self, args: list[str], cwd: Path) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        self.proc.stdin.write(json.dumps({"args": args, "cwd": str(cwd)}) + "\n")
        self.proc.stdin.flush()
        ready, _, _ = select.select([self.proc.stdout], [], [], self.timeout)
        if not ready:
            self.close()
            return {"code": None, "stdout": "", "stderr": "", "traceback": "", "hang": True}
        line = self.proc.stdout.readline()
        if not line:                                  # worker died (e.g. killed by the OS)
            self.close()
            return {"code": -1, "stdout": "", "stderr": "", "traceback": "worker died"}
        return json.loads(line)


@dataclass
class Case:
    """Input files (name -> bytes, or the marker ``"fifo"``), one command, its outputs."""

    files: dict
    args: list
    outputs: list
    mutated: str | tuple              # file name or option the error must name (or one of)
    description: str = ""
    setup: list = field(default_factory=list)   # callables(folder) run after writing files


_NONFINITE = re.compile(r"(?<![A-Za-z_])(nan|inf|infinity)(?![A-Za-z_])", re.IGNORECASE)


def _nonfinite_in(path: Path) -> bool:
    head = path.read_bytes()[:8]
    if path.suffix == ".png" or head == b"\x89PNG\r\n\x1a\n":
        return False
    if path.suffix == ".h5" or head == b"\x89HDF\r\n\x1a\n":
        import h5py
        bad = []

        def visit(_, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fc":
                if not np.all(np.isfinite(obj[()])):
                    bad.append(obj.name)
        with h5py.File(path, "r") as h5:
            h5.visititems(visit)
        return bool(bad)
    text = path.read_text(encoding="utf-8", errors="replace")
    if path.suffix == ".json":                # numbers only: descriptions may say "-> inf"
        def bad(constant):
            raise ValueError(constant)
        try:
            json.loads(text, parse_constant=bad)
        except ValueError:
            return True
        return False
    return bool(_NONFINITE.search(text))


def write_case(case: Case, folder: Path) -> None:
    for name, content in case.files.items():
        p = folder / name
        p.parent.mkdir(parents=True, exist_ok=True)
        if content == "fifo":
            os.mkfifo(p)
        else:
            p.write_bytes(content)
    for fn in case.setup:
        fn(folder)


def classify(case: Case, res: dict, folder: Path) -> tuple[str, str]:
    """(outcome, detail) of one run."""
    if res.get("hang"):
        return "hang", "timeout"
    if res["traceback"] or res["code"] not in (0, 1, 2):
        return "traceback", res["traceback"].strip().splitlines()[-1] if res["traceback"] \
            else f"exit {res['code']}"
    lost = lost_files(case, folder, failed=res["code"] != 0)
    if lost:
        return "lost_file", ", ".join(lost)
    temps = temporary_files(folder)
    if temps:
        return "leftover", ", ".join(temps)
    present = [o for o in case.outputs if os.path.exists(folder / o)]
    if res["code"] != 0:
        created = [o for o in present if o not in case.files]
        if created:
            return "leftover", ", ".join(created)
        err = res["stderr"].strip()
        if res["code"] == 2 and "Error:" in err:
            return "clean_error", err.splitlines()[-1]
        lines = err.splitlines()
        names = case.mutated if isinstance(case.mutated, tuple) else (case.mutated,)
        if len(lines) == 1 and lines[0].startswith("error:") and \
                any(Path(name).name in lines[0] for name in names):
            return "clean_error", lines[0]
        return "unclear_error", err[-300:]
    if _NONFINITE.search(res["stdout"]) or any(_nonfinite_in(folder / o) for o in present):
        return "nan_output", res["stdout"][-300:]
    return "ok", ""


def lost_files(case: Case, folder: Path, failed: bool) -> list:
    """Files the case put in the folder that are gone or changed: after a failed run any of
    them, after a successful one those that are not its outputs."""
    lost = []
    for name, content in case.files.items():
        if content == "fifo" or (not failed and name in case.outputs):
            continue
        p = folder / name
        if not p.is_file() or p.read_bytes() != content:
            lost.append(name)
    return lost


def temporary_files(folder: Path) -> list:
    """Temporary output files (``.NAME.*.tmp``) anywhere under ``folder``."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob(".*.tmp"))


def run_case(worker: Worker, case: Case, folder: Path) -> tuple[str, str]:
    """Write the case into an empty ``folder``, run it, classify it, clean the folder."""
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    write_case(case, folder)
    try:
        res = worker.run(case.args, folder)
        return classify(case, res, folder)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# --------------------------------------------------------------------------- seeds
def _read(rel: str) -> bytes:
    return (ROOT / rel).read_bytes()


def seed_pressure_csv() -> bytes:
    """Pressure traces of the default engine's single-zone model at 1000 and 3000 rpm."""
    from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
    engine = read_engine(DEFAULT_ENGINE_PATH)
    lines = ["speed [rpm],cylinder,crank_angle [deg],pressure [bar]"]
    for rpm in (1000.0, 3000.0):
        grid, p, _ = engine.cycle_pressures(rpm)
        step = p.shape[1] // 144
        for c in range(p.shape[0]):
            for j in range(0, p.shape[1], step):
                lines.append(f"{rpm:g},{c + 1},{math.degrees(grid[j]):.4f},{p[c, j] / 1e5:.5f}")
    return ("\n".join(lines) + "\n").encode()


def seed_measured_csv() -> bytes:
    """The shipped example measurement, speeds 1000..3000 rpm only (quick)."""
    out = []
    for line in _read("examples/measured-runup.csv").decode().splitlines():
        f = line.split(",")
        if line.startswith("#") or f[0] == "mount" or (len(f) > 3 and float(f[3]) <= 3000):
            out.append(line)
    return ("\n".join(out) + "\n").encode()


_SEEDS: dict = {}


def seeds(worker: Worker, folder: Path) -> dict:
    """Valid seed files (built once): engine, mounts, CSVs, variants, a run-up HDF5."""
    if _SEEDS:
        return _SEEDS
    _SEEDS["engine"] = _read("engines/default.toml")
    _SEEDS["engine-nonlinear"] = _read("engines/default-nonlinear.toml")   # issue 20 sections
    for p in sorted((ROOT / "mounts").glob("*.toml")):
        _SEEDS[f"mounts/{p.name}"] = p.read_bytes()
    _SEEDS["pressure.csv"] = seed_pressure_csv()
    _SEEDS["measured.csv"] = seed_measured_csv()
    _SEEDS["variants.toml"] = _read("examples/whatif-variants.toml")
    folder.mkdir(parents=True, exist_ok=True)
    res = worker.run(["runup", "--from", "1000", "--to", "3000", "--step", "1000", "--solver",
                      "harmonic", "--quiet", "--out", "sim.h5", "--csv", "sim.csv"], folder)
    assert res["code"] == 0, res
    _SEEDS["sim.h5"] = (folder / "sim.h5").read_bytes()
    _SEEDS["sim.csv"] = (folder / "sim.csv").read_bytes()
    from benchmarks import signals
    from powertrain.iotools.raw_csv import write_raw_csv
    write_raw_csv(folder / "raw.csv", signals.analytic_sweep(fs=2048.0, duration=2.0,
                                                             rpm0=1500.0, rpm1=3000.0),
                  comment="SYNTHETIC: analytic sweep (fuzz seed)")
    _SEEDS["raw.csv"] = (folder / "raw.csv").read_bytes()
    res = worker.run(["stiffness", str(ROOT / "mounts" / "hydraulic-engine-mount-z.toml"),
                      "--freq", "1:200:10", "--format", "csv"], folder)
    _SEEDS["k.csv"] = res["stdout"].encode()
    raw_format_seeds(folder)
    transient_seeds(worker, folder)
    shutil.rmtree(folder, ignore_errors=True)
    return _SEEDS


def mount_files() -> dict:
    return {k: v for k, v in _SEEDS.items() if k.startswith("mounts/")}


# --------------------------------------------------------------------------- TOML
def toml_dumps(doc: dict) -> str:
    """Minimal TOML writer: each top-level key as one line of inline values."""
    return "".join(f"{_key(k)} = {_value(v)}\n" for k, v in doc.items())


def _key(k) -> str:
    return json.dumps(str(k))


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(max(min(v, 2 ** 63 - 1), -2 ** 63))
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) \
            else repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_loads(data: bytes) -> dict:
    import tomllib
    return tomllib.loads(data.decode())


WEIRD_NUMBERS = [0, -1, 1, 1e300, -1e300, 1e-300, -1e-300, 1e30, 1e-30, 2 ** 62, 7, 0.5,
                 float("nan"), float("inf"), -float("inf")]
WEIRD_VALUES = WEIRD_NUMBERS + ["", "abc", "1", "nan", True, [], [1, 2], [1, "a"], [[1.0]],
                                {}, {"value": 1.0}, {"value": [1, 2, 3], "unit": "mm"},
                                {"value": 1e300, "unit": "mm"}, {"value": "x", "unit": "1"},
                                {"value": 1, "unit": "furlong"}]


def weird_value():
    """A weird TOML value (a fresh copy: mutations must not change the shared constants)."""
    return st.one_of(st.sampled_from(WEIRD_VALUES).map(copy.deepcopy),
                     st.floats(allow_nan=True, allow_infinity=True),
                     st.integers(-2 ** 63, 2 ** 63 - 1),
                     st.text(max_size=6))


def _leaves(node, path=()):
    if isinstance(node, dict):
        if not node:
            yield path
        for k, v in node.items():
            yield from _leaves(v, path + (k,))
    elif isinstance(node, list) and node and any(isinstance(x, (dict, list)) for x in node):
        for i, v in enumerate(node):
            yield from _leaves(v, path + (i,))
    else:
        yield path


def mutate_toml(draw, data: bytes) -> bytes:
    """One to three structural mutations of a TOML document, or a byte-level one."""
    if draw(st.integers(0, 9)) == 0:
        return mutate_bytes(draw, data)
    doc = toml_loads(data)
    for _ in range(draw(st.integers(1, 3))):
        leaves = [p for p in _leaves(doc) if p]
        if not leaves:
            break
        path = draw(st.sampled_from(leaves))
        parent = doc
        for k in path[:-1]:
            parent = parent[k]
        last = path[-1]
        action = draw(st.sampled_from(["replace", "replace", "scale", "delete", "add",
                                       "element"]))
        old = parent[last]
        if action == "delete":
            del parent[last]
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["extra", "unit", "value", "x"]))] = draw(weird_value())
        elif action == "scale" and isinstance(old, (int, float)) and not isinstance(old, bool):
            parent[last] = old * draw(st.sampled_from([0, -1, 1e-300, 1e300, 1e6, 1e-6, 10]))
        elif action == "element" and isinstance(old, list) and old:
            i = draw(st.integers(0, len(old) - 1))
            old[i] = draw(weird_value())
        else:
            parent[last] = draw(weird_value())
    try:
        return toml_dumps(doc).encode()
    except (TypeError, ValueError):
        return data


def mutate_bytes(draw, data: bytes) -> bytes:
    """Truncate, flip bytes, insert junk or a huge cell."""
    action = draw(st.sampled_from(["truncate", "flip", "insert", "huge", "empty"]))
    b = bytearray(data)
    if action == "empty" or not b:
        return b""
    i = draw(st.integers(0, len(b) - 1))
    if action == "truncate":
        return bytes(b[:i])
    if action == "flip":
        for _ in range(draw(st.integers(1, 8))):
            j = draw(st.integers(0, len(b) - 1))
            b[j] ^= 1 << draw(st.integers(0, 7))
        return bytes(b)
    if action == "insert":
        junk = draw(st.binary(min_size=1, max_size=20))
        return bytes(b[:i]) + junk + bytes(b[i:])
    return bytes(b[:i]) + b"9" * 200_000 + bytes(b[i:])


# --------------------------------------------------------------------------- CSV
def mutate_csv(draw, data: bytes) -> bytes:
    """Mutate one cell (or a row, or the header), or the bytes."""
    if draw(st.integers(0, 5)) == 0:
        return mutate_bytes(draw, data)
    lines = data.decode().splitlines()
    rows = [i for i, ln in enumerate(lines) if ln and not ln.startswith("#")]
    i = draw(st.sampled_from(rows))
    cells = lines[i].split(",")
    action = draw(st.sampled_from(["cell", "cell", "cell", "drop_cell", "add_cell", "drop_row",
                                   "dup_row"]))
    if action == "cell":
        j = draw(st.integers(0, len(cells) - 1))
        cells[j] = draw(st.one_of(
            st.sampled_from(["", "nan", "inf", "-inf", "1e300", "-1e300", "1e-300", "0", "-1",
                             "abc", "x", "4", "7", "1e308", "-0", "9" * 400]),
            st.floats(allow_nan=True, allow_infinity=True).map(repr),
            st.text(alphabet="0123456789.-+eE,x ", max_size=8)))
    elif action == "drop_cell" and len(cells) > 1:
        cells.pop(draw(st.integers(0, len(cells) - 1)))
    elif action == "add_cell":
        cells.append("1")
    elif action == "drop_row":
        cells = None
    elif action == "dup_row":
        lines.insert(i, lines[i])
    if cells is None:
        del lines[i]
    else:
        lines[i] = ",".join(cells)
    return ("\n".join(lines) + "\n").encode()


# --------------------------------------------------------------------------- HDF5
H5_MUTATIONS = ["settings", "meta", "mount_int", "velocity_shape", "empty_rpm", "nan_velocity",
                "delete", "softlink_loop", "flip", "rpm_zero", "format", "huge_rpm",
                "direction", "string_rpm", "orders_shape"]


def mutate_hdf5(draw, data: bytes, folder_name: str) -> tuple[bytes, str]:
    """A mutated copy of a run-up HDF5 (built through h5py in a scratch file)."""
    import tempfile

    import h5py
    action = draw(st.sampled_from(H5_MUTATIONS))
    if action == "flip":
        return mutate_bytes(draw, data), action
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "x.h5"
        p.write_bytes(data)
        with h5py.File(p, "r+") as h5:
            if action == "settings":
                h5.attrs["settings"] = draw(st.sampled_from(["{", "[]", "1", "null", "nan"]))
            elif action == "meta":
                h5.attrs["meta"] = "not json"
            elif action == "mount_int":
                del h5["channels/mount"]
                h5["channels/mount"] = np.arange(9)
            elif action == "velocity_shape":
                del h5["velocity/amplitude"]
                h5["velocity/amplitude"] = np.ones(draw(st.sampled_from([(3,), (2, 9, 16),
                                                                         (3, 9), (0, 9, 16)])))
            elif action == "empty_rpm":
                del h5["rpm"]
                h5["rpm"] = np.zeros(0)
            elif action == "nan_velocity":
                v = h5["velocity/amplitude"][()]
                v.flat[draw(st.integers(0, v.size - 1))] = draw(
                    st.sampled_from([np.nan, np.inf, 1e300]))
                h5["velocity/amplitude"][...] = v
            elif action == "delete":
                del h5[draw(st.sampled_from(["rpm", "orders", "channels", "velocity",
                                             "diagnostics", "mount_force/mean"]))]
            elif action == "softlink_loop":
                del h5["rpm"]
                h5["rpm"] = h5py.SoftLink("/rpm")
            elif action == "rpm_zero":
                h5["rpm"][0] = draw(st.sampled_from([0.0, -1.0, np.nan, 1e300]))
            elif action == "format":
                h5.attrs["format"] = "other"
            elif action == "huge_rpm":
                h5["rpm"][...] = h5["rpm"][()] * 1e6
            elif action == "direction":
                h5["channels/direction"][0] = b"q"
            elif action == "string_rpm":
                del h5["rpm"]
                h5["rpm"] = np.array([b"a", b"b", b"c"])
            elif action == "orders_shape":
                del h5["orders"]
                h5["orders"] = np.ones(3)
        return p.read_bytes(), action


# --------------------------------------------------------------------------- options
def option_value():
    return st.one_of(
        st.sampled_from(["0", "-1", "1e12", "1e300", "nan", "inf", "-inf", "0.01", "1e-300",
                         "abc", "", "7", "1000", "6500", "9000", "2", "0.3"]),
        st.floats(allow_nan=True, allow_infinity=True).map(repr))


def freq_spec():
    part = st.one_of(
        st.sampled_from(["0:1e12:1", "1:400:1", "1:10:0", "10:1:1", "1e300", "-5", "nan",
                         "1:2:3:4", "a", "", ":", "5", "1:1e9:0.001", "0:1:1e-300"]),
        st.tuples(option_value(), option_value(), option_value()).map(":".join),
        option_value())
    return st.lists(part, min_size=1, max_size=3).map(",".join)


def effect_spec():
    from powertrain.effects import EFFECTS
    names = sorted(EFFECTS) + ["nope", ""]
    param = st.tuples(st.sampled_from(["k1", "c_base", "m_base", "exponent", "g3", "lag",
                                       "x", ""]),
                      st.one_of(option_value(), st.sampled_from(["400N/mm", "8kg", "5deg",
                                                                 "1furlong", "1e300N/mm"])))
    params = st.lists(param, max_size=3).map(lambda ps: ",".join(f"{k}={v}" for k, v in ps))
    return st.tuples(st.sampled_from(names), params).map(
        lambda t: t[0] + (":" + t[1] if t[1] else ""))


def mount_op_spec(kind: str):
    target = st.sampled_from(["left.z", "right.y", "gearbox.x", "*.*", "nope.z", "left.q",
                              "left", ""])
    if kind == "scale":
        what = st.sampled_from(["stiffness", "damping", "dynamic", "mass", ""])
        return st.tuples(target, what, option_value()).map(lambda t: f"{t[0]}.{t[1]}={t[2]}")
    if kind == "set":
        par = st.sampled_from(["c1", "d2", "m1", "c9", "x"])
        unit = st.sampled_from(["", "N/mm", "kg", "furlong"])
        return st.tuples(target, par, option_value(), unit).map(
            lambda t: f"{t[0]}.{t[1]}={t[2]}{t[3]}")
    if kind in ("move", "rotate"):
        mount = st.sampled_from(["left", "right", "gearbox", "nope", "*"])
        return st.tuples(mount, st.lists(option_value(), min_size=1, max_size=4)).map(
            lambda t: f"{t[0]}=" + ",".join(t[1]))
    band = st.sampled_from(["100-300Hz", "300-100Hz", "0-1e12Hz", "1-2", "nanHz", ""])
    change = st.sampled_from(["+20%", "-100%", "+1e300%", "x", "0.5", "nan%"])
    return st.tuples(target, change, band).map(lambda t: ":".join(t))


# --------------------------------------------------------------------------- cases
QUICK_RUNUP = ["--from", "1000", "--to", "2000", "--step", "1000", "--solver", "harmonic",
               "--quiet"]


def _engine_with(**changes) -> bytes:
    """The seed engine with top-level tables replaced (TOML text)."""
    doc = toml_loads(_SEEDS["engine"])
    doc.update(changes)
    return toml_dumps(doc).encode()


def case_engine(draw) -> Case:
    text = mutate_toml(draw, _SEEDS["engine"])
    files = {"engines/e.toml": text, **mount_files()}
    return Case(files, ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP, "--out", "o.h5",
                        "--csv", "o.csv"], ["o.h5", "o.csv"], "e.toml", "engine TOML")


def case_mount(draw) -> Case:
    name = draw(st.sampled_from(sorted(mount_files())))
    text = mutate_toml(draw, _SEEDS[name])
    files = {**mount_files(), name: text}
    if draw(st.booleans()):
        return Case(files, ["stiffness", name, "--freq", "1:200:10", "--format", "csv"], [],
                    Path(name).name, "mount TOML (stiffness)")
    # a mount file with [amplitude], [friction] or [static] runs in the engine that uses it
    nonlinear = Path(name).name.encode() in _SEEDS["engine-nonlinear"]
    files["engines/e.toml"] = _SEEDS["engine-nonlinear" if nonlinear else "engine"]
    return Case(files, ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP, "--csv", "o.csv"],
                ["o.csv"], Path(name).name, "mount TOML (run-up)")


def case_pressure(draw) -> Case:
    doc = toml_loads(_SEEDS["engine"])
    doc["combustion"] = {"model": "measured", "traces": "../p.csv"}
    files = {"engines/e.toml": toml_dumps(doc).encode(), **mount_files(),
             "p.csv": mutate_csv(draw, _SEEDS["pressure.csv"])}
    return Case(files, ["runup", "--engine", "engines/e.toml", "--from", "1000", "--to", "3000",
                        "--step", "2000", "--solver", "harmonic", "--quiet", "--csv", "o.csv"],
                ["o.csv"], "p.csv", "pressure CSV")


def case_stiffness(draw) -> Case:
    files = {"k.csv": mutate_csv(draw, _SEEDS["k.csv"])}
    model = draw(st.sampled_from(["kelvin-voigt", "sls", "single"]))
    return Case(files, ["fit-mount", "k.csv", "--model", model, "--starts", "2", "--out",
                        "f.toml"], ["f.toml"], "k.csv", "stiffness CSV")


def case_measured_csv(draw) -> Case:
    files = {"m.csv": mutate_csv(draw, _SEEDS["measured.csv"]), "sim.h5": _SEEDS["sim.h5"]}
    return Case(files, ["compare", "m.csv", "--sim", "sim.h5", "--quiet", "--json", "c.json"],
                ["c.json"], "m.csv", "measured CSV")


def case_measured_hdf5(draw) -> Case:
    data, action = mutate_hdf5(draw, _SEEDS["sim.h5"], "m.h5")
    files = {"m.h5": data, "sim.csv": _SEEDS["sim.csv"]}
    return Case(files, ["compare", "m.h5", "--sim", "sim.csv", "--quiet", "--json", "c.json"],
                ["c.json"], "m.h5", f"measured HDF5 ({action})")


def case_variants(draw) -> Case:
    files = {"v.toml": mutate_toml(draw, _SEEDS["variants.toml"]), **mount_files()}
    return Case(files, ["whatif", "--variants", "v.toml", "--from", "1000", "--to", "2000",
                        "--step", "1000", "--workers", "1", "--quiet", "--json", "w.json"],
                ["w.json"], "v.toml", "what-if variants TOML")


def case_options(draw) -> Case:
    kind = draw(st.sampled_from(["runup", "freq", "effect", "whatif", "compare", "fit"]))
    files = {**mount_files()}
    if kind == "runup":
        opt = draw(st.sampled_from(["--from", "--to", "--step", "--angle-step"]))
        args = ["runup", "--from", "1000", "--to", "2000", "--step", "1000", "--quiet",
                "--csv", "o.csv", opt, draw(option_value())]
        if opt != "--angle-step":
            args += ["--solver", "harmonic"]
        return Case(files, args, ["o.csv"], opt, f"option {opt}")
    if kind == "freq":
        spec = draw(freq_spec())
        return Case(files, ["stiffness", "mounts/hydraulic-engine-mount-z.toml", "--freq", spec,
                            "--format", "csv"], [], "--freq", "option --freq")
    if kind == "effect":
        return Case(files, ["runup", *QUICK_RUNUP, "--csv", "o.csv", "--effect",
                            draw(effect_spec())], ["o.csv"], "--effect", "option --effect")
    if kind == "whatif":
        opt = draw(st.sampled_from(["scale", "set", "move", "rotate", "target"]))
        return Case(files, ["whatif", "--from", "1000", "--to", "2000", "--step", "1000",
                            "--workers", "1", "--quiet", "--json", "w.json", f"--{opt}",
                            draw(mount_op_spec(opt))], ["w.json"], f"--{opt}",
                    f"option --{opt}")
    if kind == "compare":
        opt = draw(st.sampled_from(["--step", "--noise-floor"]))
        files.update({"m.csv": _SEEDS["measured.csv"]})
        return Case(files, ["compare", "m.csv", "--solver", "harmonic", "--quiet", "--json",
                            "c.json", opt, draw(option_value())], ["c.json"], opt,
                    f"option {opt}")
    opt = draw(st.sampled_from(["--seed", "--starts", "--fmin", "--fmax", "--max-mass"]))
    value = draw(st.one_of(option_value(), st.integers(-2 ** 70, 2 ** 70).map(str)))
    files.update({"k.csv": _SEEDS["k.csv"]})
    return Case(files, ["fit-mount", "k.csv", "--model", "sls", "--starts", "2", "--out",
                        "f.toml", opt, value], ["f.toml"], opt, f"option {opt}")


def case_raw_csv(draw) -> Case:
    files = {"raw.csv": mutate_csv(draw, _SEEDS["raw.csv"])}
    return Case(files, ["track", "raw.csv", "--quantity", "acceleration", "--orders", "1,2,4",
                        "--quiet", "--csv", "t.csv"], ["t.csv"], "raw.csv",
                "raw time-data CSV (track)")


#: Input kind -> case builder.
KINDS = {"engine": case_engine, "mount": case_mount, "pressure_csv": case_pressure,
         "stiffness_csv": case_stiffness, "measured_csv": case_measured_csv,
         "measured_hdf5": case_measured_hdf5, "variants": case_variants,
         "options": case_options, "raw_csv": case_raw_csv}


# --------------------------------------------------------------------------- issue 10's list
def _engine_text_sub(pattern: str, repl: str) -> bytes:
    text, n = re.subn(pattern, repl, _SEEDS["engine"].decode(), flags=re.M)
    assert n, pattern
    return text.encode()


def _engine_case(text: bytes, what: str) -> Case:
    return Case({"engines/e.toml": text, **mount_files()},
                ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP, "--out", "o.h5"],
                ["o.h5"], "e.toml", what)


def _all_mounts_at(pos: str) -> bytes:
    return _engine_text_sub(r"^position = \{value = \[[-0-9., ]+\], unit = \"mm\"\}(?=.*\n"
                            r"(?:.*\n)?(local_x|orientation))",
                            f'position = {{value = [{pos}], unit = "mm"}}')


def _zero_mount_files() -> dict:
    zero = b'[mount]\nname = "zero"\nmodel = "kelvin-voigt"\n[units]\nc = "N/mm"\n' \
           b'd = "N*s/mm"\nm = "kg"\n[parameters]\nc1 = 0\nd1 = 0\n'
    return {name: zero for name in mount_files()}


def _mutate_h5_fixed(action: str) -> bytes:
    """A run-up HDF5 with one named defect (deterministic)."""
    values = iter([action])

    def draw(strategy):
        if values is not None:
            try:
                return next(values)
            except StopIteration:
                pass
        return {"settings": "{", "velocity_shape": (3,), "rpm_zero": np.nan}.get(
            action, 0)
    data, _ = mutate_hdf5(draw, _SEEDS["sim.h5"], "m.h5")
    return data


def _flip(data: bytes, positions) -> bytes:
    b = bytearray(data)
    for p in positions:
        b[p % len(b)] ^= 0xFF
    return bytes(b)


def issue_cases() -> dict:
    """Every failure issue 10 lists (that runs in seconds), as a named case."""
    e = _engine_case
    cases = {
        "engine: list where a number belongs": e(_engine_text_sub(
            r"^bore = .*$", 'bore = {value = [82.5, 1.0], unit = "mm"}'), "bore list"),
        "engine: firing order mixing strings and ints": e(_engine_text_sub(
            r"^firing_order = .*$", 'firing_order = [1, "3", 4, 2]'), "firing order"),
        "engine: huge counterweight_fraction": e(_engine_text_sub(
            r"^counterweight_fraction = .*$",
            'counterweight_fraction = {value = 1e300, unit = "1"}'), "counterweight"),
        "engine: bore huge": e(_engine_text_sub(
            r"^bore = .*$", 'bore = {value = 1e300, unit = "mm"}'), "bore huge"),
        "engine: imep_factors 1e-300": e(_engine_text_sub(
            r"^imep_factors = .*$", 'imep_factors = {value = [1e-300, 1, 1, 1], unit = "1"}'),
            "imep"),
        "engine: mounts all at the CG": e(_all_mounts_at("200.0, 10.0, 70.0"), "mounts at CG"),
        "engine: all-zero mounts": Case({"engines/e.toml": _SEEDS["engine"],
                                         **_zero_mount_files()},
                                        ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP,
                                         "--out", "o.h5"], ["o.h5"], "e.toml", "zero mounts"),
        "engine file is a FIFO": Case({"engines/e.toml": "fifo", **mount_files()},
                                      ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP,
                                       "--out", "o.h5"], ["o.h5"], "e.toml", "FIFO"),
        "measured CSV is a FIFO": Case({"m.csv": "fifo"}, ["compare", "m.csv", "--quiet",
                                                           "--json", "c.json"],
                                       ["c.json"], "m.csv", "FIFO"),
        "CSV cell over 128 kB": Case({"k.csv": _SEEDS["k.csv"].replace(
            b"\n1,", b"\n1" + b"0" * 140_000 + b",", 1)},
                                     ["fit-mount", "k.csv", "--starts", "2", "--out", "f.toml"],
                                     ["f.toml"], "k.csv", "big cell"),
        "fit-mount on 1e300 N/mm data": Case(
            {"k.csv": re.sub(rb"\n(\d+),[^,]+,[^,]+,", rb"\n\1,1e300,1e300,", _SEEDS["k.csv"])},
            ["fit-mount", "k.csv", "--starts", "2", "--out", "f.toml"], ["f.toml"], "k.csv",
            "1e300 N/mm"),
        "fit-mount --seed -1": Case({"k.csv": _SEEDS["k.csv"]},
                                    ["fit-mount", "k.csv", "--starts", "2", "--out", "f.toml",
                                     "--seed", "-1"], ["f.toml"], "--seed", "seed"),
        "--angle-step 0": Case({}, ["runup", "--from", "1000", "--to", "2000", "--angle-step",
                                    "0", "--out", "o.h5"], ["o.h5"], "--angle-step", ""),
        "runup --to 9000 names --to": Case({}, ["runup", "--to", "9000", "--quiet", "--out",
                                                "o.h5"], ["o.h5"], "--to", ""),
        "--from 1000 --to 1e12": Case({}, ["runup", "--from", "1000", "--to", "1e12", "--out",
                                           "o.h5"], ["o.h5"], "--step", ""),
        "--freq 0:1e12:1": Case({**mount_files()}, ["stiffness",
                                                   "mounts/hydraulic-engine-mount-z.toml",
                                                   "--freq", "0:1e12:1"], [], "--freq", ""),
        "stiffness --freq 1e300": Case({**mount_files()}, ["stiffness",
                                                          "mounts/hydraulic-engine-mount-z.toml",
                                                          "--freq", "1e300"], [], "--freq", ""),
        "compare --step 0.01": Case({"m.csv": _SEEDS["measured.csv"]},
                                    ["compare", "m.csv", "--step", "0.01", "--quiet", "--json",
                                     "c.json"], ["c.json"], "--step", ""),
        "plot path under a regular file": Case({"file": b"x"},
                                               ["runup", *QUICK_RUNUP, "--out", "o.h5",
                                                "--plot", "file/p.png"], ["o.h5"], "--plot", ""),
    }
    for action, what in (("settings", "non-JSON settings"), ("mount_int", "integer mount names"),
                         ("velocity_shape", "wrong-shaped velocity"),
                         ("softlink_loop", "soft-link loop"), ("empty_rpm", "empty rpm array")):
        cases[f"HDF5: {what}"] = Case(
            {"m.h5": _mutate_h5_fixed(action), "sim.csv": _SEEDS["sim.csv"]},
            ["compare", "m.h5", "--sim", "sim.csv", "--quiet", "--json", "c.json"], ["c.json"],
            "m.h5", what)
    for k, pos in enumerate((100, 3000, 20000, 60000)):
        cases[f"HDF5: flipped bytes #{k + 1}"] = Case(
            {"m.h5": _flip(_SEEDS["sim.h5"], range(pos, pos + 64)), "sim.csv": _SEEDS["sim.csv"]},
            ["compare", "m.h5", "--sim", "sim.csv", "--quiet", "--json", "c.json"], ["c.json"],
            "m.h5", "flipped")
    return cases


# --------------------------------------------------------------------------- issue 18
# Raw HDF5, UFF and MDF4 time data, channel maps, the FRF chassis, diagnose, track and sweep
# options, scheduler addresses, and data safety (earlier files never lost).
LAB_NAMES = {"rpm": "EngSpeed", "tacho": "Tacho1", "left.z": "ACC_L_Z", "right.z": "VEL_R_Z"}
CHANNEL_MAP = (b'rpm = "EngSpeed"\ntacho = "Tacho1"\n\n[channels]\n'
               b'"ACC_L_Z" = { mount = "left", direction = "z", quantity = "acceleration", '
               b'unit = "g" }\n'
               b'"VEL_R_Z" = { mount = "right", direction = "z", quantity = "velocity", '
               b'unit = "mm/s" }\n')


def raw_format_seeds(folder: Path) -> None:
    """The raw seed as HDF5, UFF 58 and MDF4; a lab-named CSV with its channel map; a
    modal-body engine with a measured receptance (FRF) body, CSV and UFF."""
    from powertrain.iotools.raw import read_raw
    from powertrain.iotools.raw_hdf5 import write_raw_hdf5
    from powertrain.iotools.raw_mdf import write_raw_mdf
    from powertrain.iotools.raw_uff import write_raw_uff
    rec = read_raw(folder / "raw.csv")
    for name, write in (("raw.h5", write_raw_hdf5), ("raw.uff", write_raw_uff),
                        ("raw.mf4", write_raw_mdf)):
        write(folder / name, rec)
        _SEEDS[name] = (folder / name).read_bytes()
    lines = _SEEDS["raw.csv"].decode().splitlines()
    head = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    cols = lines[head].split(",")
    for i, c in enumerate(cols):
        bare = c.split(" [")[0]
        if bare in LAB_NAMES:
            cols[i] = LAB_NAMES[bare] + (" [1/min]" if bare == "rpm" else
                                         " [V]" if bare == "tacho" else "")
    lines[head] = ",".join(cols)
    _SEEDS["lab.csv"] = ("\n".join(lines) + "\n").encode()
    _SEEDS["map.toml"] = CHANNEL_MAP
    _frf_seeds()


FRF_RPM = 2000.0


def _frf_seeds() -> None:
    from powertrain.iotools.engine_file import read_engine
    engine = read_engine(ROOT / "engines" / "default-modal-body.toml")
    ch = engine.chassis
    f = np.unique(np.outer([FRF_RPM / 60.0], np.arange(1, 17) / 2.0).ravel())
    f = np.concatenate([[0.5 * f[0]], f, [2 * f[-1]]])
    rows = ["frequency_hz,response,excitation,receptance_real_m_per_n,"
            "receptance_imag_m_per_n"]
    records = []
    for r in engine.mount_names + list(ch.points):
        for e in engine.mount_names:
            H = np.array([ch.receptance_at(2 * np.pi * fi, [r], [e]) for fi in f])
            for a, rd in enumerate("xyz"):
                for b, ed in enumerate("xyz"):
                    rows += [f"{fi!r},{r}.{rd},{e}.{ed},{h.real!r},{h.imag!r}"
                             for fi, h in zip(f.tolist(), H[:, a, b].tolist())]
                    records.append(dict(rsp_ent_name=r, rsp_dir=a + 1, ref_ent_name=e,
                                        ref_dir=b + 1, data=H[:, a, b], x=f))
    _SEEDS["body.csv"] = ("\n".join(rows) + "\n").encode()
    _SEEDS["frf_records"] = records
    text = (ROOT / "engines" / "default-modal-body.toml").read_text()
    text = text[:text.index("\n[chassis]\n") + 1]
    for ext in ("csv", "uff"):
        _SEEDS[f"frf-{ext}.toml"] = (text + f'[chassis]\nmodel = "frf"\nfrf = "../body.{ext}"'
                                     '\n\n[chassis.points.seat_rail]\n').encode()


def frf_uff(records) -> bytes:
    """UFF 58 receptance records (ASCII) as bytes."""
    import tempfile
    import warnings

    import pyuff
    sets = [pyuff.prepare_58(binary=0, func_type=4, rsp_node=1, ref_node=1, id1="receptance",
                             ord_data_type=6, abscissa_spacing=0, abscissa_spec_data_type=18,
                             ordinate_spec_data_type=8, orddenom_spec_data_type=13,
                             z_axis_spec_data_type=0, ver_num=0, load_case_id=0,
                             z_axis_value=0.0, **r) for r in records]
    with tempfile.TemporaryDirectory() as tmp, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = Path(tmp) / "b.uff"
        pyuff.UFF(str(p)).write_sets(sets, mode="overwrite")
        return p.read_bytes()


RAW_H5_MUTATIONS = ["comments_text", "comments_ints", "dangling_time", "dangling_channel",
                    "channels_dataset", "huge_time", "huge_channel", "delete", "string_time",
                    "two_d", "nan_value", "time_backwards", "unit", "format", "flip",
                    "empty_time", "synthetic_array"]


def mutate_raw_hdf5(draw, data: bytes) -> tuple[bytes, str]:
    """A mutated copy of a raw HDF5 file (see RAW_H5_MUTATIONS)."""
    import tempfile

    import h5py
    action = draw(st.sampled_from(RAW_H5_MUTATIONS))
    if action == "flip":
        return mutate_bytes(draw, data), action
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "x.h5"
        p.write_bytes(data)
        with h5py.File(p, "r+") as h5:
            chan = "channels/" + sorted(h5["channels"])[0]
            _RAW_H5_EDITS[action](h5, chan, draw)
        return p.read_bytes(), action


def _replace(h5, name, value):
    del h5[name]
    h5[name] = value


def _huge(h5, name):
    del h5[name]
    h5.create_dataset(name, shape=(2 ** 40,), chunks=(1024,), dtype="f8")


def _edit_value(h5, name, index, value):
    v = h5[name][()]
    v[index] = value
    h5[name][...] = v


_RAW_H5_EDITS = {
    "comments_text": lambda h5, c, d: h5.attrs.__setitem__("comments", d(st.sampled_from(
        ["not json", "{", "", "null"]))),
    "comments_ints": lambda h5, c, d: h5.attrs.__setitem__("comments", "[1, 2]"),
    "dangling_time": lambda h5, c, d: _replace(h5, "time", __import__("h5py").SoftLink("/x")),
    "dangling_channel": lambda h5, c, d: _replace(h5, c, __import__("h5py").SoftLink("/x")),
    "channels_dataset": lambda h5, c, d: _replace(h5, "channels", np.ones(4)),
    "huge_time": lambda h5, c, d: _huge(h5, "time"),
    "huge_channel": lambda h5, c, d: _huge(h5, c),
    "delete": lambda h5, c, d: h5.__delitem__(d(st.sampled_from(["time", "channels", "rpm",
                                                                 "tacho", c]))),
    "string_time": lambda h5, c, d: _replace(h5, "time", np.array([b"a", b"b"])),
    "two_d": lambda h5, c, d: _replace(h5, c, np.ones((3, 4))),
    "nan_value": lambda h5, c, d: _edit_value(h5, d(st.sampled_from(["time", "rpm", c])),
                                              d(st.integers(0, 100)),
                                              d(st.sampled_from([np.nan, np.inf, 1e300]))),
    "time_backwards": lambda h5, c, d: _edit_value(h5, "time", 50, -1.0),
    "unit": lambda h5, c, d: h5[d(st.sampled_from(["time", "rpm", c]))].attrs.__setitem__(
        "unit", d(st.sampled_from(["furlong", "", "m/s^2", "1e300"]))),
    "format": lambda h5, c, d: h5.attrs.__setitem__("format", "other"),
    "empty_time": lambda h5, c, d: _replace(h5, "time", np.zeros(0)),
    "synthetic_array": lambda h5, c, d: h5.attrs.__setitem__("synthetic", np.array([1, 0])),
}


def _track(raw: str, *extra) -> list:
    return ["track", raw, "--orders", "1,2,4", "--quantity", "acceleration", "--quiet",
            "--csv", "t.csv", *extra]


def case_raw_hdf5(draw) -> Case:
    data, action = mutate_raw_hdf5(draw, _SEEDS["raw.h5"])
    return Case({"raw.h5": data}, _track("raw.h5"), ["t.csv"], "raw.h5",
                f"raw HDF5 ({action})")


def _uff_cut_at_dataset(data: bytes, keep: int) -> bytes:
    """The first ``keep`` datasets of a UFF file (a cut exactly at a dataset boundary)."""
    starts = [m.start() for m in re.finditer(rb"(?:^|\n)[ ]*-1[ ]*\n[ ]*58", data)]
    return data[:starts[keep] + 1] if keep < len(starts) else data


def case_uff(draw) -> Case:
    action = draw(st.sampled_from(["bytes", "bytes", "fraction", "boundary"]))
    data = _SEEDS["raw.uff"]
    if action == "bytes":
        data = mutate_bytes(draw, data)
    elif action == "fraction":
        data = data[:int(len(data) * draw(st.sampled_from([0.1, 0.5, 0.9, 0.99, 0.999])))]
    else:
        data = _uff_cut_at_dataset(data, draw(st.integers(0, 3)))
    return Case({"raw.uff": data}, _track("raw.uff"), ["t.csv"], "raw.uff",
                f"raw UFF ({action})")


MDF_DEFECTS = ["zero_length", "one_sample", "other_time_base", "nan_values", "text_channel",
               "no_channels", "bytes"]


def mdf_with(defect: str) -> bytes:
    """An MDF4 file with one structural defect (built by asammdf)."""
    import tempfile

    from asammdf import MDF, Signal
    t = np.arange(4096) / 2048.0
    good = [Signal(np.sin(t * 200), t, name="left.z", unit="g"),
            Signal(1500 + 500 * t, t, name="rpm", unit="rpm")]
    sigs = {"zero_length": [Signal(np.zeros(0), np.zeros(0), name="left.z", unit="g")],
            "one_sample": [Signal(np.zeros(1), np.zeros(1), name="left.z", unit="g")],
            "other_time_base": [Signal(np.zeros(10), np.arange(10.0), name="right.z",
                                       unit="g")],
            "nan_values": [Signal(np.full(t.size, np.nan), t, name="right.z", unit="g")],
            "text_channel": [Signal(np.array([b"ab"] * t.size), t, name="right.z",
                                    encoding="utf-8")],
            "no_channels": []}[defect]
    mdf = MDF(version="4.10")
    groups = [good, sigs] if defect != "no_channels" else []
    for g in groups:
        if g:
            mdf.append(g)
    with tempfile.TemporaryDirectory() as tmp:
        out = mdf.save(str(Path(tmp) / "x.mf4"), overwrite=True)
        mdf.close()
        return Path(out).read_bytes()


def case_mdf4(draw) -> Case:
    defect = draw(st.sampled_from(MDF_DEFECTS))
    data = mutate_bytes(draw, _SEEDS["raw.mf4"]) if defect == "bytes" else mdf_with(defect)
    return Case({"raw.mf4": data}, _track("raw.mf4"), ["t.csv"], "raw.mf4",
                f"raw MDF4 ({defect})")


def case_channel_map(draw) -> Case:
    files = {"lab.csv": _SEEDS["lab.csv"], "map.toml": mutate_toml(draw, _SEEDS["map.toml"])}
    # a map that drops a unit or the speed channel is named through the data file's channel
    return Case(files, _track("lab.csv", "--channels", "map.toml"), ["t.csv"],
                ("map.toml", "lab.csv"), "channel map TOML")


FRF_RUNUP = ["runup", "--engine", "engines/e.toml", "--from", "2000", "--to", "2000",
             "--step", "500", "--solver", "harmonic", "--quiet", "--csv", "o.csv"]


def case_frf_chassis(draw) -> Case:
    """The FRF (measured receptance) chassis: a mutated receptance CSV or UFF record, or a
    mutated [chassis] table."""
    where = draw(st.sampled_from(["csv", "csv", "uff", "engine"]))
    files = {**mount_files()}
    if where == "csv":
        files.update({"engines/e.toml": _SEEDS["frf-csv.toml"],
                      "body.csv": mutate_csv(draw, _SEEDS["body.csv"])})
        return Case(files, FRF_RUNUP, ["o.csv"], "body.csv", "FRF chassis (receptance CSV)")
    if where == "uff":
        records = copy.deepcopy(_SEEDS["frf_records"])
        r = records[draw(st.integers(0, len(records) - 1))]
        field_ = draw(st.sampled_from(["rsp_dir", "ref_dir", "rsp_ent_name", "data", "x"]))
        if field_ in ("rsp_dir", "ref_dir"):
            r[field_] = draw(st.sampled_from([0, 4, 5, -6, 6]))   # pyuff writes -6..6
        elif field_ == "rsp_ent_name":
            r[field_] = draw(st.sampled_from(["", "nope", "left.z"]))
        else:
            v = np.array(r[field_], dtype=complex if field_ == "data" else float)
            v[draw(st.integers(0, v.size - 1))] = draw(st.sampled_from([np.nan, np.inf, -1.0]))
            r[field_] = v
        data = frf_uff(records)
        if draw(st.booleans()):
            data = data[:int(len(data) * 0.9)]
        files.update({"engines/e.toml": _SEEDS["frf-uff.toml"], "body.uff": data})
        return Case(files, FRF_RUNUP, ["o.csv"], "body.uff", f"FRF chassis (UFF {field_})")
    files.update({"engines/e.toml": mutate_toml(draw, _SEEDS["frf-csv.toml"]),
                  "body.csv": _SEEDS["body.csv"]})
    return Case(files, FRF_RUNUP, ["o.csv"], "e.toml", "FRF chassis ([chassis] table)")


DIAGNOSE = ["--effects", "sensor_error", "--no-pairs", "--quiet", "--json", "d.json"]


def case_diagnose(draw) -> Case:
    files = {"m.csv": mutate_csv(draw, _SEEDS["measured.csv"])}
    return Case(files, ["diagnose", "m.csv", *DIAGNOSE], ["d.json"], "m.csv",
                "diagnose (measured CSV)")


def case_track_options(draw) -> Case:
    opt = draw(st.sampled_from(["--rpm-step", "--orders", "--pulses-per-rev", "--bandwidth",
                                "--csv"]))
    extra = []
    if opt == "--rpm-step":
        value = draw(st.one_of(option_value(), st.sampled_from(["1e-9", "1e-300", "0.5"])))
    elif opt == "--orders":
        value = draw(st.one_of(st.sampled_from(["1:inf:1", "1:2:1e-12", "1e300", "0.5:8:0.5",
                                                "1,1e6", "-1", "1:2", "0.001:0.002:0.001"]),
                               freq_spec()))
    elif opt == "--pulses-per-rev":
        value = draw(st.sampled_from(["9" * 400, "0", "-1", "1", "4", "1e3", "100001"]))
        extra = ["--tacho", "tacho"]
    elif opt == "--bandwidth":
        value = draw(option_value())
        extra = ["--method", "vkf"]
    else:
        value = draw(st.sampled_from(["a" * 300 + ".csv", "x/" * 200 + "t.csv",
                                      "raw.csv/t.csv"]))
    args = ["track", "raw.csv", "--orders", "1,2,4", "--quantity", "acceleration", "--quiet",
            opt, value, *extra]
    outputs = [value] if opt == "--csv" else []
    return Case({"raw.csv": _SEEDS["raw.csv"]}, args, outputs, opt, f"track option {opt}")


def case_sweep_options(draw) -> Case:
    rate = draw(st.one_of(st.sampled_from(["1e9", "1e-3", "1e-320", "0", "-5", "nan", "inf",
                                           "50", "100", "400", "1000", "abc"]),
                          st.floats(1e-3, 1e6).map(repr)))
    fs = draw(st.sampled_from(["8192", "16000", "12600", "256", "255", "1e300", "nan",
                               "4096"]))
    args = ["runup", "--from", "2000", "--to", "2100", "--sweep", rate, "--sample-rate", fs,
            "--quiet", "--csv", "s.csv"]
    return Case({}, args, ["s.csv"], "--s", f"runup --sweep {rate} --sample-rate {fs}")


def case_modes_engine(draw) -> Case:
    """``modes`` on a mutated modal-body engine (finite extremes, zero shapes)."""
    text = mutate_toml(draw, _read("engines/default-modal-body.toml"))
    return Case({"engines/e.toml": text, **mount_files()},
                ["modes", "--engine", "engines/e.toml", "--json", "m.json"], ["m.json"],
                "e.toml", "modes (modal-body engine)")


KINDS.update({"raw_hdf5": case_raw_hdf5, "uff": case_uff, "mdf4": case_mdf4,
              "channel_map": case_channel_map, "frf_chassis": case_frf_chassis,
              "diagnose": case_diagnose, "track_options": case_track_options,
              "sweep_options": case_sweep_options, "modes": case_modes_engine})


# --------------------------------------------------------------------------- issue 18's list
class FakeServers:
    """Local TCP servers for scheduler addresses: ``http`` answers like a web server once
    it gets a request (sends nothing first), ``silent`` accepts and never answers."""

    def __init__(self):
        import socket
        import threading
        self.socks, self.conns, self.address = [], [], {}
        for kind in ("http", "silent", "eager_http"):
            sock = socket.socket()
            sock.bind(("127.0.0.1", 0))
            sock.listen(8)
            self.socks.append(sock)
            self.address[kind] = f"tcp://127.0.0.1:{sock.getsockname()[1]}"
            threading.Thread(target=self._serve, args=(sock, kind), daemon=True).start()

    def _serve(self, sock, kind):
        try:
            while True:
                conn, _ = sock.accept()
                self.conns.append(conn)
                if kind == "eager_http":
                    conn.sendall(b"HTTP/1.0 400 Bad request\r\nContent-Length: 0\r\n\r\n")
        except OSError:
            pass

    def close(self):
        for s in self.socks + self.conns:
            s.close()


_SERVERS: list = []


def fake_servers() -> FakeServers:
    if not _SERVERS:
        _SERVERS.append(FakeServers())
    return _SERVERS[0]


def _raw_h5_with(action: str) -> bytes:
    import tempfile

    import h5py
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "x.h5"
        p.write_bytes(_SEEDS["raw.h5"])
        with h5py.File(p, "r+") as h5:
            chan = "channels/" + sorted(h5["channels"])[0]
            _RAW_H5_EDITS[action](h5, chan, lambda strategy: "not json")
        return p.read_bytes()


def _tacho_with_edges(n: int) -> bytes:
    """The raw seed CSV with a tacho of ``n`` pulses over the record."""
    lines = _SEEDS["raw.csv"].decode().splitlines()
    head = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
    col = next(i for i, c in enumerate(lines[head].split(",")) if c.startswith("tacho"))
    rows = lines[head + 1:]
    period = len(rows) // n
    for k, ln in enumerate(rows):
        cells = ln.split(",")
        cells[col] = "5" if k % period < period // 4 else "0"
        rows[k] = ",".join(cells)
    return ("\n".join(lines[:head + 1] + rows) + "\n").encode()


def _mdf_damaged_record_length() -> bytes:
    """The seed MDF4 with its channel group's invalidation-bytes count (offset 100 of the
    CG block, MDF 4.1) set to 3.4 GB per record: found by the long campaign (MemoryError)."""
    b = bytearray(_SEEDS["raw.mf4"])
    i = b.index(b"##CG") + 100
    b[i:i + 4] = (0xCDC5D000).to_bytes(4, "little")
    return bytes(b)


def _measured_truncated() -> bytes:
    """The seed measurement cut inside the gearbox x channel: gearbox channels have no
    held-out speeds (printed NaN dB, found by the long campaign)."""
    data = _SEEDS["measured.csv"]
    return data[:data.index(b"gearbox,x,synthesis,2600")]


def _modal_engine_sub(pattern: str, repl: str, count: int = 0) -> bytes:
    text, n = re.subn(pattern, repl, _read("engines/default-modal-body.toml").decode(),
                      count=count, flags=re.M)
    assert n, pattern
    return text.encode()


def _measured_with_level(value: str, row: str = "") -> bytes:
    """The seed measurement with the level of its first data row starting with ``row``
    replaced by ``value``."""
    lines = _SEEDS["measured.csv"].decode().splitlines()
    i = next(i for i, ln in enumerate(lines) if ln and ln[0] not in "#m"
             and ln.startswith(row))
    cells = lines[i].split(",")
    cells[-1] = value
    lines[i] = ",".join(cells)
    return ("\n".join(lines) + "\n").encode()


def issue_18_cases() -> dict:
    """Every root cause issue 18 lists, as a named case: name -> (case, expected outcome)."""
    mf = mount_files()
    zero = _zero_mount_files()
    name_z = "mounts/hydraulic-engine-mount-z.toml"
    srv = fake_servers()
    records = copy.deepcopy(_SEEDS["frf_records"])
    records[3]["rsp_dir"] = 5
    cases = {
        "stiffness on an all-zero mount": Case(
            {**zero, "mounts/thesis.toml": _zero_thesis_mount()},
            ["stiffness", "mounts/thesis.toml", "--format", "csv"], [], "thesis.toml", ""),
        "stiffness --force nan": Case({**mf}, ["stiffness", name_z, "--engine-mass", "100",
                                               "--force", "nan", "--format", "csv"], [],
                                      "--force", ""),
        "diagnose on a 1e-300 level --json": Case(
            {"m.csv": _measured_with_level("1e-300")}, ["diagnose", "m.csv", *DIAGNOSE],
            ["d.json"], "m.csv", ""),
        "diagnose on a measurement cut short": Case(
            {"m.csv": _measured_truncated()}, ["diagnose", "m.csv", *DIAGNOSE], ["d.json"],
            "m.csv", ""),
        "track --rpm-step 1e-300": Case({"raw.csv": _SEEDS["raw.csv"]}, _track(
            "raw.csv", "--rpm-step", "1e-300"), ["t.csv"], "--rpm-step", ""),
        "track --rpm-step 1e-9": Case({"raw.csv": _SEEDS["raw.csv"]}, _track(
            "raw.csv", "--rpm-step", "1e-9"), ["t.csv"], "--rpm-step", ""),
        "track --orders 1:inf:1": Case({"raw.csv": _SEEDS["raw.csv"]}, [
            "track", "raw.csv", "--orders", "1:inf:1", "--csv", "t.csv"], ["t.csv"],
            "--orders", ""),
        "track --orders 1:2:1e-12": Case({"raw.csv": _SEEDS["raw.csv"]}, [
            "track", "raw.csv", "--orders", "1:2:1e-12", "--csv", "t.csv"], ["t.csv"],
            "--orders", ""),
        "track --pulses-per-rev with 400 digits": Case({"raw.csv": _SEEDS["raw.csv"]}, _track(
            "raw.csv", "--tacho", "tacho", "--pulses-per-rev", "9" * 400), ["t.csv"],
            "--pulses-per-rev", ""),
        "track: a tacho with 3 edges": Case({"raw.csv": _tacho_with_edges(3)}, _track(
            "raw.csv", "--tacho", "tacho", "--pulses-per-rev", "1"), ["t.csv"], "raw.csv", ""),
        "track: a FIFO": Case({"raw.csv": "fifo"}, _track("raw.csv"), ["t.csv"], "raw.csv",
                              ""),
        "track: a 300-character output name": Case(
            {"raw.csv": _SEEDS["raw.csv"]}, ["track", "raw.csv", "--csv", "a" * 300 + ".csv"],
            [], "--csv", ""),
        "raw HDF5: non-JSON comments": Case({"raw.h5": _raw_h5_with("comments_text")},
                                            _track("raw.h5"), ["t.csv"], "raw.h5", ""),
        "raw HDF5: dangling soft link": Case({"raw.h5": _raw_h5_with("dangling_time")},
                                             _track("raw.h5"), ["t.csv"], "raw.h5", ""),
        "raw HDF5: /channels as a dataset": Case({"raw.h5": _raw_h5_with("channels_dataset")},
                                                 _track("raw.h5"), ["t.csv"], "raw.h5", ""),
        "raw HDF5: 2**40-long chunked /time": Case({"raw.h5": _raw_h5_with("huge_time")},
                                                   _track("raw.h5"), ["t.csv"], "raw.h5", ""),
        "MDF4 with zero-length channels": Case({"raw.mf4": mdf_with("zero_length")},
                                               _track("raw.mf4"), ["t.csv"], "raw.mf4", ""),
        "MDF4 with a damaged record length": Case(
            {"raw.mf4": _mdf_damaged_record_length()}, _track("raw.mf4"), ["t.csv"],
            "raw.mf4", ""),
        "UFF truncated at 90 %": Case({"raw.uff": _SEEDS["raw.uff"][
            :int(0.9 * len(_SEEDS["raw.uff"]))]}, _track("raw.uff"), ["t.csv"], "raw.uff", ""),
        "UFF cut after a whole dataset": Case({"raw.uff": _uff_cut_at_dataset(
            _SEEDS["raw.uff"], 3)}, _track("raw.uff"), ["t.csv"], "raw.uff", ""),
        "modes: 1e308 stiffness": Case(
            {**mf, "engines/e.toml": _read("engines/default-torque-rod.toml").replace(
                b"[150.0, 15.0, 15.0]", b"[1e308, 15.0, 15.0]")},
            ["modes", "--engine", "engines/e.toml", "--json", "m.json"], ["m.json"], "e.toml",
            ""),
        "modes: modal mass 1e-300": Case(
            {**mf, "engines/e.toml": _modal_engine_sub(
                r"modal_mass = \{value = 40.0", "modal_mass = {value = 1e-300")},
            ["modes", "--engine", "engines/e.toml", "--json", "m.json"], ["m.json"], "e.toml",
            ""),
        "modes: all body shapes zero": Case(
            {**mf, "engines/e.toml": _modal_engine_sub(
                r"^shape = .*$", "shape = {left = [0.0, 0.0, 0.0], right = [0.0, 0.0, 0.0], "
                "gearbox = [0.0, 0.0, 0.0], seat_rail = [0.0, 0.0, 0.0]}")},
            ["modes", "--engine", "engines/e.toml", "--json", "m.json"], ["m.json"], "e.toml",
            ""),
        "UFF receptance with rsp_dir = 5": Case(
            {**mf, "engines/e.toml": _SEEDS["frf-uff.toml"], "body.uff": frf_uff(records)},
            FRF_RUNUP, ["o.csv"], "body.uff", ""),
        "runup --sweep 1e9": _sweep_case("1e9"),
        "runup --sweep 1e-3": _sweep_case("1e-3"),
        "runup --sweep 1e-320": _sweep_case("1e-320"),
        "diagnose --scheduler tcp://host:notaport": _scheduler_case("tcp://host:notaport"),
        "diagnose --scheduler at an HTTP server": _scheduler_case(srv.address["http"]),
        "diagnose --scheduler at an answering HTTP server": _scheduler_case(
            srv.address["eager_http"]),
        "diagnose --scheduler at a silent server": _scheduler_case(srv.address["silent"]),
        "modes fails on its plot: the old m.json stays": Case(
            {"m.json": b"old\n", "afile": b""},
            ["modes", "--json", "m.json", "--plot", "afile/p.png"], ["m.json"], "afile", ""),
        "runup fails on its plot: the old o.csv and o.h5 stay": Case(
            {"o.csv": b"old\n", "o.h5": b"old\n", "afile": b""},
            ["runup", *QUICK_RUNUP, "--csv", "o.csv", "--out", "o.h5", "--plot", "afile/p.png"],
            ["o.csv", "o.h5"], "afile", ""),
    }
    out = {name: (case, "clean_error") for name, case in cases.items()}
    # a level of 1e-300 is a valid (censored) point, a short measurement a valid one too:
    # a finite diagnosis, no NaN
    for name in ("diagnose on a 1e-300 level --json", "diagnose on a measurement cut short"):
        out[name] = (out[name][0], "ok")
    for args in (["--from", "1000", "--to", "1300", "--sweep", "100"],
                 ["--from", "2000", "--to", "2500", "--sweep", "400", "--sample-rate",
                  "16000"]):
        out["runup " + " ".join(args) + " runs"] = (
            Case({}, ["runup", *args, "--quiet", "--csv", "y.csv"], ["y.csv"], "", ""), "ok")
    return out


def _zero_thesis_mount() -> bytes:
    text = _read("mounts/thesis-appendix-a.toml").decode()
    head, sep, params = text.partition("[parameters]")
    return (head + sep + re.sub(r"=\s*[-0-9.eE+]+", "= 0", params)).encode()


def _sweep_case(rate: str) -> Case:
    return Case({}, ["runup", "--from", "2000", "--to", "2500", "--sweep", rate, "--quiet",
                     "--csv", "y.csv"], ["y.csv"], "--sweep", "")


def _scheduler_case(address: str) -> Case:
    return Case({"m.csv": _SEEDS["measured.csv"]},
                ["diagnose", "m.csv", *DIAGNOSE, "--scheduler", address], ["d.json"],
                "--scheduler", "")


# --------------------------------------------------------------------------- data safety
def _cli_process(args, cwd):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")])
    return subprocess.Popen([sys.executable, "-m", "powertrain.cli", *args], cwd=cwd, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def concurrent_runs(folder: Path, n: int = 2) -> tuple[str, str]:
    """``n`` concurrent ``track`` runs writing the same two paths with different orders:
    afterwards the CSV and the HDF5 must come from one run (``lost_file`` if mixed or
    missing) and no temporary file may be left."""
    import h5py
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    (folder / "raw.csv").write_bytes(_SEEDS["raw.csv"])
    procs = [_cli_process(["track", "raw.csv", "--orders", str(k + 1), "--quantity",
                           "acceleration", "--quiet", "--csv", "t.csv", "--out", "t.h5"],
                          folder) for k in range(n)]
    codes = [p.wait(timeout=TIMEOUT) for p in procs]
    errs = [p.stderr.read() for p in procs]
    for p in procs:
        p.stderr.close()
    try:
        if any(codes) or not (folder / "t.csv").exists() or not (folder / "t.h5").exists():
            return ("traceback" if any(c not in (0, 1) for c in codes) else "lost_file",
                    f"exit codes {codes}: {errs}"[-300:])
        temps = temporary_files(folder)
        if temps:
            return "leftover", ", ".join(temps)
        csv_orders = {ln.split(",")[2] for ln in (folder / "t.csv").read_text().splitlines()
                      if ln and not ln.startswith(("#", "mount"))} - {"synthesis"}
        with h5py.File(folder / "t.h5", "r") as h5:
            h5_orders = {f"order_{o:g}" for o in h5["orders"][()]}
        if csv_orders != h5_orders:
            return "lost_file", f"mixed outputs: CSV {csv_orders}, HDF5 {h5_orders}"
        return "ok", ""
    finally:
        shutil.rmtree(folder, ignore_errors=True)


#: Temporary files found right after each SIGKILL of :func:`killed_run` (the later run
#: must sweep them).
KILL_TEMPS: list = []


def killed_run(folder: Path, delay: float) -> tuple[str, str]:
    """SIGKILL a ``runup`` writing three outputs over older files after ``delay`` seconds,
    then run a later command into the same folder: the older files must be intact or
    completely replaced and no temporary file may remain after the later run."""
    import signal
    import time
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    old = {"o.csv": b"old\n", "o.h5": b"old\n", "o.png": b"old\n"}
    for name, content in old.items():
        (folder / name).write_bytes(content)
    proc = _cli_process(["runup", "--from", "1000", "--to", "6000", "--step", "250",
                         "--solver", "harmonic", "--quiet", "--csv", "o.csv", "--out", "o.h5",
                         "--plot", "o.png"], folder)
    time.sleep(delay)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    proc.stderr.close()
    try:
        for name, content in old.items():
            data = (folder / name).read_bytes() if (folder / name).exists() else None
            if data is None or (data != content and data[:4] == content[:4]):
                return "lost_file", f"{name} after SIGKILL at {delay:.2f} s"
        KILL_TEMPS.append(len(temporary_files(folder)))
        later = _cli_process(["modes", "--json", "m.json"], folder)
        later.wait(timeout=TIMEOUT)
        later.stderr.close()
        temps = temporary_files(folder)
        if temps:
            return "leftover", f"after SIGKILL at {delay:.2f} s and a later run: {temps}"
        return "ok", ""
    finally:
        shutil.rmtree(folder, ignore_errors=True)


# --------------------------------------------------------------------------- issue 39
def _one_zero_mount_file(name: str = "mounts/hydraulic-engine-mount-z.toml") -> bytes:
    """A shipped mount file with every spring and damper 0 (masses kept): singular at 0 Hz."""
    head, sep, params = _SEEDS[name].decode().partition("[parameters]")
    return (head + sep + re.sub(r"^([cd]\d+) = .*$", r"\1 = 0", params, flags=re.M)).encode()


def _frf_uff_with(record: int, index: int, value) -> bytes:
    """The seed receptance UFF with one value of one record replaced (found by the long
    campaign: left.z/left.z at the 4th frequency, inf, which pyuff writes as 1.8e308)."""
    records = copy.deepcopy(_SEEDS["frf_records"])
    data = np.array(records[record]["data"], complex)
    data[index] = value
    records[record]["data"] = data
    return frf_uff(records)


def _report_folder_in_the_way(folder: Path) -> None:
    (folder / "rep" / "gap_map.png").mkdir(parents=True)


def issue_39_cases() -> dict:
    """The last bad inputs issue 39 lists (and what they led to), as named cases: name ->
    (case, expected outcome). ``slow``: those that run a diagnosis (seconds each)."""
    name_z = "mounts/hydraulic-engine-mount-z.toml"
    zero = {**mount_files(), name_z: _one_zero_mount_file()}
    cases = {
        "runup: a mount file with every spring and damper 0": (Case(
            {**zero, "engines/e.toml": _SEEDS["engine"]},
            ["runup", "--engine", "engines/e.toml", *QUICK_RUNUP, "--csv", "o.csv"], ["o.csv"],
            "hydraulic-engine-mount-z.toml", ""), "clean_error"),
        "stiffness: a mount file with every spring and damper 0": (Case(
            zero, ["stiffness", name_z, "--format", "csv"], [], "hydraulic-engine-mount-z.toml",
            ""), "clean_error"),
        "whatif --set leaving an internal mass on no spring": (Case(
            {**mount_files()}, ["whatif", "--from", "1000", "--to", "2000", "--step", "1000",
                                "--workers", "1", "--quiet", "--json", "w.json", "--set",
                                "left.z.c3=0"], ["w.json"], "--set", ""), "clean_error"),
        "raw HDF5: empty /time": (Case({"raw.h5": _raw_h5_with("empty_time")},
                                       _track("raw.h5"), ["t.csv"], "raw.h5", ""),
                                  "clean_error"),
        "raw HDF5: synthetic attribute an array": (Case(
            {"raw.h5": _raw_h5_with("synthetic_array")}, _track("raw.h5"), ["t.csv"],
            "raw.h5", ""), "clean_error"),
        "FRF chassis: a receptance of 1.8e308 m/N (pyuff's inf)": (Case(
            {**mount_files(), "engines/e.toml": _SEEDS["frf-uff.toml"],
             "body.uff": _frf_uff_with(8, 8, np.inf)}, FRF_RUNUP, ["o.csv"], "body.uff", ""),
            "clean_error"),
        "diagnose --report onto a folder named gap_map.png: d.json stays": (Case(
            {"m.csv": _SEEDS["measured.csv"], "d.json": b"old\n"},
            ["diagnose", "m.csv", *DIAGNOSE, "--report", "rep"], ["d.json"], "gap_map.png", "",
            [_report_folder_in_the_way]), "clean_error"),
    }
    slow = {
        "diagnose on a 1e-300 level --json --report": (Case(
            {"m.csv": _measured_with_level("1e-300", "left,z,order_2,2000,")},
            ["diagnose", "m.csv", *DIAGNOSE, "--report", "rep"],
            ["d.json", "rep/diagnosis.json", "rep/summary.txt"], "m.csv", ""), "ok"),
    }
    return cases, slow


# --------------------------------------------------------------------------- transient (38)
# `powertrain transient MANOEUVRE.toml` and `powertrain whatif --manoeuvre`: mutated manoeuvre
# files, options, recordings for --compare / --speed-from, what-if specs. The seeds are
# windows of the shipped examples (each runs in well under a second).
#: Shipped manoeuvre -> the window [s] of it cut out as a seed.
MANOEUVRE_WINDOWS = {"start": (0.0, 0.45), "stop": (0.8, 1.4), "tip-in": (0.2, 0.6),
                     "back-out": (0.2, 0.6)}


def _table_window(table: dict, t0: float, t1: float) -> dict:
    """A [speed] or [load] table cut to ``t0..t1`` (the ends interpolated), from 0."""
    t = np.asarray(table["time"]["value"], float)
    tt = np.r_[t0, t[(t > t0) & (t < t1)], t1]
    out = {"time": {"value": [round(x - t0, 9) for x in tt.tolist()],
                    "unit": table["time"]["unit"]}}
    for key, col in table.items():
        if key == "time":
            continue
        if isinstance(col, dict) and isinstance(col.get("value"), list):
            v = np.interp(tt, t, np.asarray(col["value"], float))
            out[key] = {"value": [round(x, 9) for x in v.tolist()], "unit": col["unit"]}
        else:
            out[key] = col
    return out


def cut_manoeuvre(data: bytes, t0: float, t1: float) -> bytes:
    """A manoeuvre file cut to its window ``t0..t1`` [s] (trigger and starter moved)."""
    doc = toml_loads(data)
    for section in ("speed", "load"):
        doc[section] = _table_window(doc[section], t0, t1)
    head = doc["manoeuvre"]
    if "trigger_time" in head:
        head["trigger_time"]["value"] = round(min(max(head["trigger_time"]["value"] - t0, 0.0),
                                                  0.5 * (t1 - t0)), 9)
    if "starter" in doc:
        until = doc["starter"]["until"]
        until["value"] = round(min(max(until["value"] - t0, 0.0), t1 - t0), 9)
    return toml_dumps(doc).encode()


def transient_seeds(worker: Worker, folder: Path) -> None:
    """Manoeuvre windows ``m/NAME.toml``; the start's and the tip-in's recordings as raw
    HDF5 (``--raw``) and CSV; a channel map of the start's recording."""
    from powertrain.iotools.raw import read_raw
    from powertrain.iotools.raw_csv import write_raw_csv
    for name, (t0, t1) in MANOEUVRE_WINDOWS.items():
        _SEEDS[f"m/{name}.toml"] = cut_manoeuvre(_read(f"examples/{name}.toml"), t0, t1)
    (folder / "m").mkdir(parents=True, exist_ok=True)
    (folder / "engines").mkdir(exist_ok=True)
    (folder / "engines" / "e.toml").write_bytes(_read("engines/default-modal-body.toml"))
    shutil.copytree(ROOT / "mounts", folder / "mounts", dirs_exist_ok=True)
    for name in ("start", "tip-in", "stop", "start-modal"):
        toml = name.removesuffix("-modal")
        (folder / "m" / f"{toml}.toml").write_bytes(_SEEDS[f"m/{toml}.toml"])
        engine = ["--engine", "engines/e.toml"] if name.endswith("-modal") else []
        res = worker.run(["transient", f"m/{toml}.toml", "--quiet", "--raw", f"{name}-raw.h5",
                          *engine], folder)
        assert res["code"] == 0, res
        _SEEDS[f"{name}-raw.h5"] = (folder / f"{name}-raw.h5").read_bytes()
        rec = read_raw(folder / f"{name}-raw.h5")
        write_raw_csv(folder / f"{name}-raw.csv", rec, comment=rec.comments[0])
        _SEEDS[f"{name}-raw.csv"] = (folder / f"{name}-raw.csv").read_bytes()
    _SEEDS["rec-map.toml"] = (b'rpm = "rpm"\n\n[channels]\n'
                              b'"left.z" = { mount = "left", direction = "z", '
                              b'quantity = "acceleration", unit = "m/s^2" }\n'
                              b'"right.z" = { mount = "right", direction = "z", '
                              b'quantity = "acceleration", unit = "m/s^2" }\n')


def manoeuvre_files() -> dict:
    return {k: v for k, v in _SEEDS.items() if k.startswith("m/")}


TRANSIENT_OUT = ["--quiet", "--json", "j.json", "--csv", "t.csv"]


def _manoeuvre_case(text: bytes, what: str, *extra, engine: str = "") -> Case:
    files = {"m.toml": text}
    if engine:                                    # a shipped engine with its mount files
        files.update({**mount_files(), "engines/e.toml": _read(f"engines/{engine}.toml")})
        extra = (*extra, "--engine", "engines/e.toml")
        what += f" on {engine}"
    return Case(files, ["transient", "m.toml", *TRANSIENT_OUT, *extra],
                ["j.json", "t.csv"], "m.toml", what)


def _rows(draw, n: int, kind: str) -> list:
    """A column of ``n`` rows: times (``kind`` "time") or speeds [rpm]."""
    if kind == "time":
        style = draw(st.sampled_from(["uniform", "uniform", "duplicate", "backwards", "late",
                                      "tiny", "huge", "nan"]))
        dt = draw(st.sampled_from([1e-9, 1e-4, 0.01, 0.1, 1.0, 6.0, 3600.0]))
        t = [k * dt for k in range(n)]
        if style == "duplicate" and n > 2:
            t[n // 2] = t[n // 2 - 1]
        elif style == "backwards" and n > 2:
            t[n // 2], t[n // 2 - 1] = t[n // 2 - 1], t[n // 2]
        elif style == "late":
            t = [x + draw(st.sampled_from([1e-12, 0.1, -0.1])) for x in t]
        elif style == "tiny":
            t = [k * 1e-300 for k in range(n)]
        elif style == "huge":
            t[-1] = draw(st.sampled_from([36000.0, 1e300, 60.0, 59.999]))
        elif style == "nan":
            t[draw(st.integers(0, n - 1))] = draw(st.sampled_from([math.nan, math.inf]))
        return t
    base = draw(st.sampled_from([0.0, 300.0, 800.0, 1500.0, 12000.0]))
    slope = draw(st.sampled_from([0.0, 10.0, -200.0, 1000.0, -1e6]))
    return [base + slope * k for k in range(n)]


def _mangle_table(draw, doc: dict) -> str:
    """One semantic mutation of the [speed] or [load] table (or of its neighbours)."""
    section = draw(st.sampled_from(["speed", "load"]))
    table = doc.setdefault(section, {})
    col = "speed" if section == "speed" else next(
        (k for k in ("imep_scale", "mean_torque") if k in table), "imep_scale")
    n = draw(st.sampled_from([0, 1, 2, 3, 50, 4096, 4097]))
    action = draw(st.sampled_from(["times", "values", "lengths", "unit", "long", "cross_zero",
                                   "column", "swap_kind", "extreme", "extreme"]))
    if action == "extreme":
        return _extreme_manoeuvre(draw, doc)
    if action == "times":
        table["time"] = {"value": _rows(draw, max(n, 2) if n < 4096 else 50, "time"),
                         "unit": "s"}
        table[col] = {"value": [1.0] * len(table["time"]["value"]),
                      "unit": table.get(col, {}).get("unit", "1")}
    elif action == "values":
        k = len(table.get("time", {}).get("value", [0, 1]))
        table[col] = {"value": [draw(st.sampled_from(WEIRD_NUMBERS)) for _ in range(k)],
                      "unit": table.get(col, {}).get("unit", "1")}
    elif action == "lengths":
        table["time"] = {"value": [0.1 * k for k in range(n)], "unit": "s"}
    elif action == "unit":
        key = draw(st.sampled_from(["time", col]))
        if isinstance(table.get(key), dict):
            table[key]["unit"] = draw(st.sampled_from(["ms", "min", "h", "rad/s", "Hz", "rpm",
                                                       "N*m", "kN*m", "%", "1", "furlong", ""]))
    elif action == "long":                                   # 10-hour, 60 s, 1 ms profiles
        end = draw(st.sampled_from([36000.0, 60.0, 61.0, 1e-3, 1e-9]))
        for sec in ("speed", "load"):
            t = doc.get(sec, {}).get("time", {})
            if isinstance(t, dict) and isinstance(t.get("value"), list) and t["value"]:
                v = np.asarray(t["value"], float)
                t["value"] = (v * end / v[-1] if np.all(np.isfinite(v)) and v[-1] > 0
                              else v).tolist()
    elif action == "cross_zero" and section == "speed":
        k = len(table.get("time", {}).get("value", [0, 1]))
        table["speed"] = {"value": _rows(draw, k, "speed"), "unit": "rpm"}
        doc.setdefault("manoeuvre", {})["reversal"] = draw(st.booleans())
    elif action == "column":
        table.pop(draw(st.sampled_from(["time", col])), None)
    elif action == "swap_kind" and section == "load" and col in table:
        table["mean_torque" if col == "imep_scale" else "imep_scale"] = table.pop(col)
    return f"{section}: {action}"


def _extreme_manoeuvre(draw, doc: dict) -> str:
    """Valid but extreme tables: very short or long, speeds at the bounds, crossing zero,
    the largest load, gear ratio and inertia, a starter engaged to the end."""
    end = draw(st.sampled_from([1e-6, 1e-3, 0.05, 0.3, 0.3, 1.0, 5.0]))
    n = draw(st.sampled_from([2, 3, 7, 200]))
    t = [end * k / (n - 1) for k in range(n)]
    rpm = draw(st.lists(st.sampled_from([0.0, 1e-9, 30.0, -40.0, 800.0, 6000.0, 12000.0,
                                         -12000.0, 1e-300]), min_size=n, max_size=n))
    doc["speed"] = {"time": {"value": t, "unit": "s"}, "speed": {"value": rpm, "unit": "rpm"}}
    kind = draw(st.sampled_from(["imep_scale", "mean_torque"]))
    load = draw(st.sampled_from([0.0, 2.0, 1e-300, 0.06]) if kind == "imep_scale" else
                st.sampled_from([0.0, 5000.0, -5000.0, 1e-300]))
    doc["load"] = {"time": {"value": [0.0, end], "unit": "s"},
                   kind: {"value": [load, load], "unit": "1" if kind == "imep_scale" else "N*m"}}
    head = doc.setdefault("manoeuvre", {})
    head["reversal"] = True
    head["gear_ratio"] = {"value": draw(st.sampled_from([0.0, 50.0, 1e-300, 3.0])), "unit": "1"}
    head["crank_inertia"] = {"value": draw(st.sampled_from([20.0, 1e-300, 1e-9, 0.18])),
                             "unit": "kg*m^2"}
    head.pop("trigger_time", None)
    if draw(st.booleans()):
        doc["starter"] = {"ratio": {"value": draw(st.sampled_from([0.1, 100.0])), "unit": "1"},
                          "reaction_point": {"value": [0.0, 0.0, 3000.0], "unit": "mm"},
                          "until": {"value": end, "unit": "s"}}
    return f"extreme: {end:g} s, {n} rows, {kind} {load:g}"


MANOEUVRE_KEYS = {"manoeuvre": ["gear_ratio", "crank_inertia", "reversal", "trigger_time",
                                "name", "notes"],
                  "load": ["motored_intake_pressure"],
                  "starter": ["ratio", "reaction_point", "until"]}


def _mangle_key(draw, doc: dict) -> str:
    """A scalar of [manoeuvre], [load] or [starter] set weird, dropped or renamed, or a
    section dropped or replaced."""
    section = draw(st.sampled_from(sorted(MANOEUVRE_KEYS)))
    key = draw(st.sampled_from(MANOEUVRE_KEYS[section]))
    table = doc.setdefault(section, {})
    if not isinstance(table, dict):
        return f"{section} not a table"
    action = draw(st.sampled_from(["number", "number", "weird", "drop", "rename", "section"]))
    unit = {"gear_ratio": "1", "crank_inertia": "kg*m^2", "trigger_time": "s",
            "motored_intake_pressure": "bar", "ratio": "1", "until": "s"}.get(key, "mm")
    if action == "number":
        v = draw(st.one_of(st.sampled_from(WEIRD_NUMBERS + [50.0, 50.1, 20.0, 0.1, 100.0,
                                                             0.45, 0.4499, 4.0, 0.05]),
                           st.floats(-1e3, 1e3)))
        table[key] = ({"value": [v, v, v], "unit": unit} if key == "reaction_point"
                      else {"value": v, "unit": unit} if key not in ("reversal", "name", "notes")
                      else v)
    elif action == "weird":
        table[key] = draw(weird_value())
    elif action == "drop":
        table.pop(key, None)
    elif action == "rename" and key in table:
        table[draw(st.sampled_from([key.upper(), key + "s", "trigger", "x"]))] = table.pop(key)
    elif action == "section":
        doc[section] = draw(st.sampled_from([{}, [], 1, "x", [{}]]))
    return f"{section}.{key}: {action}"


def case_manoeuvre(draw) -> Case:
    """A mutated manoeuvre file (structural, semantic or byte-level) on ``transient``."""
    seed = draw(st.sampled_from(sorted(manoeuvre_files())))
    how = draw(st.sampled_from(["toml", "table", "table", "key", "key"]))
    engine = draw(st.sampled_from(["", "", "", "default-modal-body", "default-nonlinear",
                                   "default-torque-rod"]))
    if how == "toml":
        return _manoeuvre_case(mutate_toml(draw, _SEEDS[seed]), f"manoeuvre TOML ({seed})",
                               engine=engine)
    doc = toml_loads(_SEEDS[seed])
    what = [(_mangle_table if how == "table" else _mangle_key)(draw, doc)
            for _ in range(draw(st.integers(1, 2)))]
    try:
        text = toml_dumps(doc).encode()
    except (TypeError, ValueError):
        text = _SEEDS[seed]
    return _manoeuvre_case(text, f"manoeuvre ({seed}: {'; '.join(what)})", engine=engine)


TRANSIENT_OUTPUTS = {"--out": ".h5", "--csv": ".csv", "--json": ".json", "--plot": ".png",
                     "--raw": ".h5", "--compare-plot": ".png"}


def _output_path(draw, opt: str) -> str:
    """An output path for ``opt``: ordinary, or odd (under a regular file, an existing
    folder, a long name, no suffix, onto an earlier output, onto the manoeuvre file or the
    recording read)."""
    suffix = TRANSIENT_OUTPUTS[opt]
    odd = {".csv": ["m.toml"], ".json": ["m.toml"], ".h5": ["rec.h5"], ".png": []}[suffix]
    return draw(st.sampled_from([
        "o" + suffix, "sub/o" + suffix, "afile/o" + suffix, "dir", "a" * 300 + suffix, "o",
        "old" + suffix, "", *odd]))


def case_transient_options(draw) -> Case:
    """``transient`` with one odd option (or two outputs) on a valid manoeuvre."""
    seed = draw(st.sampled_from(["m/start.toml", "m/tip-in.toml"]))
    files = {"m.toml": _SEEDS[seed], "afile": b"x", "old.h5": b"old\n", "old.csv": b"old\n",
             "old.json": b"old\n", "old.png": b"old\n"}
    setup = [lambda folder: (folder / "dir").mkdir()]
    args = ["transient", "m.toml", "--quiet", "--json", "j.json"]
    outputs = ["j.json"]
    opt = draw(st.sampled_from(["--angle-step", "--seat", "--channels", "--quantity",
                                "--trigger", "--channel-map", "--speed-average", "--engine",
                                "output", "output", "output"]))
    if opt == "--angle-step":
        args += [opt, draw(st.one_of(option_value(), st.sampled_from(
            ["0.01", "10", "10.0001", "0.0099", "5", "1e-3"])))]
        engine = draw(st.sampled_from(["", "default-nonlinear", "default-modal-body"]))
        if engine:                                # friction and curves at coarse steps
            files.update({**mount_files(), "engines/e.toml": _read(f"engines/{engine}.toml")})
            args += ["--engine", "engines/e.toml"]
    elif opt in ("--seat", "--channels"):
        args += [opt, draw(st.sampled_from(["seat_rail", "left.z", "left.z,right.z", "left",
                                            "", ",", "left.z,,", "left.q", "seat_rail.z",
                                            "left/passive.z", "x" * 500, "left.z," * 50]))]
        if draw(st.booleans()):
            files["engines/e.toml"] = _read("engines/default-modal-body.toml")
            files.update(mount_files())
            args += ["--engine", "engines/e.toml"]
        if opt == "--channels":
            args += ["--plot", "p.png"]
            outputs.append("p.png")
    elif opt == "--quantity":
        args += [opt, draw(st.sampled_from(["force", "displacement", "velocity", "", "nan"])),
                 "--plot", "p.png"]
        outputs.append("p.png")
    elif opt in ("--trigger", "--channel-map", "--speed-average"):
        return _recording_option_case(draw, opt, files)
    elif opt == "--engine":
        files.update(mount_files())
        files["engines/e.toml"] = draw(st.sampled_from([
            _read("engines/default-modal-body.toml"), _read("engines/default-torque-rod.toml"),
            _SEEDS["frf-csv.toml"], b"", _SEEDS["engine"][:200]]))
        files["body.csv"] = _SEEDS["body.csv"]
        args += [opt, "engines/e.toml"]
        opt = (opt, "e.toml")
    else:
        picks = draw(st.lists(st.sampled_from(sorted(TRANSIENT_OUTPUTS)), min_size=1,
                              max_size=3, unique=True))
        if "--compare-plot" in picks:
            files["rec.h5"] = _SEEDS["start-raw.h5"]
            files["m.toml"] = _SEEDS["m/start.toml"]
            args += ["--compare", "rec.h5"]
        for p in picks:
            path = _output_path(draw, p)
            if path in args:                        # one output per path
                continue
            args += [p, path]
            if path not in ("dir", ""):                     # a folder there before
                outputs.append(path)
        opt = tuple(picks) + ("afile", "dir", "j.json", "m.toml", "rec.h5")
    return Case(files, args, outputs, opt, f"transient option {opt}", setup)


def _recording_option_case(draw, opt, files) -> Case:
    """--trigger, --channel-map or --speed-average with (or without) a recording."""
    use = draw(st.sampled_from(["--compare", "--speed-from", "both", "none"]))
    seed = draw(st.sampled_from(["start", "tip-in"]))
    ext = draw(st.sampled_from(["h5", "csv"]))
    files.update({"m.toml": _SEEDS[f"m/{seed}.toml"], f"rec.{ext}": _SEEDS[f"{seed}-raw.{ext}"]})
    args = ["transient", "m.toml", "--quiet", "--json", "j.json"]
    if use in ("--compare", "both"):
        args += ["--compare", f"rec.{ext}"]
    if use in ("--speed-from", "both"):
        args += ["--speed-from", f"rec.{ext}"]
    if opt == "--trigger":
        args += [opt, draw(st.sampled_from(["trigger", "rpm", "left.z", "nope", "", " ",
                                            "time", "cycle", "tacho", "TRIGGER"]))]
    elif opt == "--channel-map":
        files["map.toml"] = draw(st.sampled_from([_SEEDS["rec-map.toml"], _SEEDS["map.toml"]]))
        if draw(st.booleans()):
            files["map.toml"] = mutate_toml(draw, files["map.toml"])
        where = draw(st.sampled_from(["map.toml", "map.toml", "nope.toml", "m.toml",
                                      f"rec.{ext}"]))
        args += [opt, where]
        return Case(files, args, ["j.json"], (opt, f"rec.{ext}", where),
                    f"transient {opt} ({use}, {seed}, {ext})")
    else:
        args += [opt]
    return Case(files, args, ["j.json"], (opt, f"rec.{ext}", "map.toml", "m.toml"),
                f"transient {opt} ({use}, {seed}, {ext})")


REC_MUTATIONS = ["truncate", "tiny", "shift", "nan", "constant_rpm", "negative_rpm", "rename",
                 "nonuniform", "drop_rpm", "huge_rpm", "decimate", "pad", "reverse", "scale",
                 "held_rpm", "tacho", "tacho", "trigger", "bytes"]


def _rec_arrays(data: bytes, ext: str) -> tuple:
    """A seed recording's columns: (name -> values), the CSV header's comment lines."""
    if ext == "csv":
        lines = data.decode().splitlines()
        head = next(i for i, ln in enumerate(lines) if not ln.startswith("#"))
        values = np.loadtxt(lines[head + 1:], delimiter=",", ndmin=2)
        return dict(zip(lines[head].split(","), values.T)), lines[:head]
    import tempfile

    import h5py
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "x.h5"
        p.write_bytes(data)
        with h5py.File(p, "r") as h5:
            cols = {"time": h5["time"][()], "rpm": h5["rpm"][()]}
            if "trigger" in h5:
                cols["trigger"] = h5["trigger"][()]
            cols.update({f"channels/{k}": v[()] for k, v in h5["channels"].items()})
    return cols, []


def _rec_bytes(cols: dict, comments: list, data: bytes, ext: str) -> bytes:
    """The recording with its columns replaced (CSV text, or the HDF5 seed's datasets
    rewritten, their attributes kept)."""
    if ext == "csv":
        n = max(len(v) for v in cols.values())
        rows = [",".join(f"{v[i]:.9g}" if i < len(v) else "" for v in cols.values())
                for i in range(n)]
        return ("\n".join(comments + [",".join(cols)] + rows) + "\n").encode()
    import tempfile

    import h5py
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "x.h5"
        p.write_bytes(data)
        with h5py.File(p, "r+") as h5:
            old = [k for k in ["time", "rpm", "trigger"] if k in h5] + \
                [f"channels/{k}" for k in h5["channels"]]
            for name in old:
                attrs = dict(h5[name].attrs)
                del h5[name]
                if name in cols:
                    h5[name] = cols[name]
                    h5[name].attrs.update(attrs)
            for name in set(cols) - set(old):     # added or renamed: mount and direction too
                h5[name] = cols[name]
                mount, _, direction = name.rpartition("/")[2].rpartition(".")
                h5[name].attrs.update({"unit": "V"} if name in ("tacho", "trigger") else
                                      {**attrs, "mount": mount, "direction": direction})
        return p.read_bytes()


def _mutate_columns(draw, cols: dict, action: str) -> dict:
    """One defect of a recording's columns (REC_MUTATIONS)."""
    names = list(cols)
    tname = names[0]
    rpm = next(n for n in names if n.split(" ")[0] == "rpm")
    chans = [n for n in names if n not in (tname, rpm) and "trigger" not in n]
    n = len(cols[tname])
    if action in ("truncate", "tiny", "decimate", "pad", "reverse"):
        if action == "truncate":
            idx = np.arange(int(n * draw(st.sampled_from([0.05, 0.3, 0.49, 0.51, 0.7,
                                                          0.95]))))
        elif action == "tiny":
            idx = np.arange(draw(st.integers(0, 3)))
        elif action == "decimate":
            idx = np.arange(0, n, draw(st.sampled_from([7, 50, 300, 1000])))
        elif action == "reverse":
            idx = np.arange(n)[::-1]
        else:
            idx = np.r_[np.arange(n), np.full(draw(st.sampled_from([n, 20 * n])), n - 1)]
        out = {k: v[idx] for k, v in cols.items()}
        if action == "pad":
            dt = cols[tname][1] - cols[tname][0]
            out[tname] = cols[tname][0] + dt * np.arange(idx.size)
        return out
    cols = {k: v.copy() for k, v in cols.items()}
    if action == "shift":
        cols[tname] += draw(st.sampled_from([-1.0, 0.3, 1e6, -1e6, 1e-9, 1e300, 100.0]))
    elif action == "nan":
        col = draw(st.sampled_from([tname, rpm] + chans))
        cols[col][draw(st.integers(0, n - 1))] = draw(st.sampled_from([np.nan, np.inf,
                                                                       -np.inf, 1e300]))
    elif action == "constant_rpm":
        cols[rpm][:] = draw(st.sampled_from([0.0, 800.0, 1e-300, 20000.0, -800.0]))
    elif action == "negative_rpm":
        cols[rpm] = -cols[rpm]
    elif action == "huge_rpm":
        cols[rpm] = cols[rpm] * draw(st.sampled_from([1e6, 20.0, 1e-6]))
    elif action == "scale":
        col = draw(st.sampled_from(chans))
        cols[col] = cols[col] * draw(st.sampled_from([0.0, 1e300, -1.0, 1e-300]))
    elif action == "nonuniform":
        t = cols[tname]
        k = draw(st.integers(1, n - 2))
        t[k] = draw(st.sampled_from([t[k - 1], 0.5 * (t[k - 1] + t[k]), t[k + 1],
                                     t[k] + 1e-9]))
        if draw(st.booleans()):
            t[k:] += draw(st.sampled_from([0.01, 1.0]))
    elif action == "rename":
        old = draw(st.sampled_from(chans + [rpm]))
        new = draw(st.sampled_from(["front.z", "left.q", "left", "rpm2", "left.z", "seat.z",
                                    "time", "left/passive.z"]))
        unit = old.partition(" ")[2]
        cols = {((new + (" " + unit if unit else "")) if "/" not in old else
                 "channels/" + new) if k == old else k: v for k, v in cols.items()}
    elif action == "drop_rpm":
        del cols[rpm]
    elif action == "held_rpm":                   # an ECU's speed: held between updates
        k = draw(st.sampled_from([10, 100, 1000]))
        cols[rpm] = np.repeat(cols[rpm][::k], k)[:n]
    elif action == "tacho":
        cols = _tacho_columns(draw, cols, tname, rpm)
    elif action == "trigger":
        cols = _trigger_columns(draw, cols, tname)
    return cols


def _tacho_columns(draw, cols: dict, tname: str, rpm: str) -> dict:
    """The rpm channel replaced by a once-per-revolution tacho [V] of the same speed, with
    a defect: none, a pulse missing, two per revolution, flat, noisy, NaN."""
    t, speed = cols[tname], cols.pop(rpm)
    rev = np.r_[0.0, np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t))] / 60.0
    defect = draw(st.sampled_from(["none", "none", "missing", "double", "flat", "noise",
                                   "nan", "offset"]))
    if defect == "double":
        rev = 2.0 * rev
    if defect == "offset":
        rev = rev + draw(st.sampled_from([0.3, 0.99, -0.5]))
    v = np.where(np.mod(rev, 1.0) < 0.25, 5.0, 0.0)
    if defect == "missing":
        hi = np.flatnonzero(v > 0)
        v[hi[hi.size // 2:hi.size // 2 + 50]] = 0.0
    elif defect == "flat":
        v[:] = draw(st.sampled_from([0.0, 5.0]))
    elif defect == "noise":
        v = v + np.random.default_rng(0).normal(0.0, 2.0, v.size)
    elif defect == "nan":
        v[draw(st.integers(0, v.size - 1))] = np.nan
    cols["tacho [V]" if " " in tname else "tacho"] = v
    return cols


def _trigger_columns(draw, cols: dict, tname: str) -> dict:
    """The trigger channel (added where there is none) with a defect: flat, a glitch,
    falling, noisy, NaN, two steps."""
    t = cols[tname]
    name = next((k for k in cols if k.split(" ")[0] == "trigger"),
                "trigger [V]" if " " in tname else "trigger")
    v = np.where(t >= t[0] + draw(st.sampled_from([0.0, 0.1, 0.3, 1e-9])), 5.0, 0.0)
    defect = draw(st.sampled_from(["flat", "glitch", "falling", "noise", "nan", "two",
                                   "late"]))
    if defect == "flat":
        v[:] = 5.0
    elif defect == "glitch":
        v[:] = 0.0
        v[t.size // 3] = 5.0
    elif defect == "falling":
        v = 5.0 - v
    elif defect == "noise":
        v = v + np.random.default_rng(1).normal(0.0, 3.0, v.size)
    elif defect == "nan":
        v[draw(st.integers(0, v.size - 1))] = np.nan
    elif defect == "two":
        v[t > t[0] + 0.2] = 0.0
        v[t > t[0] + 0.3] = 5.0
    else:
        v = np.where(t >= t[-1] - 1e-4, 5.0, 0.0)
    cols[name] = v
    return cols


def mutated_recording(draw, seed: str, ext: str) -> tuple[bytes, str]:
    """A seed recording (``start``/``tip-in``, ``csv``/``h5``) with one defect."""
    data = _SEEDS[f"{seed}-raw.{ext}"]
    action = draw(st.sampled_from(REC_MUTATIONS))
    if action == "bytes":
        if ext == "csv":
            return mutate_csv(draw, data), "csv cell"
        return mutate_raw_hdf5(draw, data)
    cols, comments = _rec_arrays(data, ext)
    return _rec_bytes(_mutate_columns(draw, cols, action), comments, data, ext), action


def case_transient_recording(draw) -> Case:
    """A mutated recording for ``--compare`` and/or ``--speed-from`` (CSV or HDF5)."""
    seed = draw(st.sampled_from(["start", "start", "tip-in", "stop", "start-modal"]))
    ext = draw(st.sampled_from(["csv", "h5"]))
    data, action = mutated_recording(draw, seed, ext)
    files = {"m.toml": _SEEDS[f"m/{seed.removesuffix('-modal')}.toml"], f"rec.{ext}": data}
    use = draw(st.sampled_from(["--compare", "--speed-from", "both"]))
    args = ["transient", "m.toml", "--quiet", "--json", "j.json"]
    if use in ("--compare", "both"):
        args += ["--compare", f"rec.{ext}"]
    if use in ("--speed-from", "both"):
        args += ["--speed-from", f"rec.{ext}"]
    if seed == "tip-in" or action == "trigger":     # the start's seed has no trigger
        args += ["--trigger", "trigger"]
    if "--speed-from" in args and draw(st.booleans()):
        args += ["--speed-average"]
    if seed.endswith("-modal") and draw(st.booleans()):       # else: body channels unused
        files.update({**mount_files(),
                      "engines/e.toml": _read("engines/default-modal-body.toml")})
        args += ["--engine", "engines/e.toml"]
    return Case(files, args, ["j.json"], f"rec.{ext}",
                f"transient {use} recording ({seed} {ext}: {action})")


RUNUP_ONLY = ["--from", "--to", "--step", "--solver", "--signal", "--objective", "--measured",
              "--workers", "--scheduler", "--target-out", "--target-plot"]


def case_whatif_manoeuvre(draw) -> Case:
    """``whatif --manoeuvre`` with a mutated variants file, an odd --scale/--set/--move/
    --rotate/--target spec, a run-up option, or a mutated manoeuvre."""
    seed = draw(st.sampled_from(["m/start.toml", "m/stop.toml"]))
    files = {"m.toml": _SEEDS[seed], **mount_files()}
    args = ["whatif", "--manoeuvre", "m.toml", "--quiet", "--json", "w.json"]
    what = draw(st.sampled_from(["variants", "spec", "spec", "extreme", "extreme",
                                 "runup_option", "manoeuvre"]))
    if what == "extreme":                     # a valid spec, an extreme factor or value
        op = draw(st.sampled_from(["scale", "scale", "set", "move", "swap", "swap"]))
        target = draw(st.sampled_from(["left.z", "right.y", "gearbox.x", "*.*", "*.z"]))
        value = draw(st.sampled_from(["1e-9", "1e-3", "0.5", "2", "1e3", "1e9", "1e12"]))
        if op == "move":
            spec = f"{target.split('.')[0].replace('*', 'left')}={value},0,{value}"
        elif op == "swap":                        # a mount file with static curve, law
            spec = (target.replace("*", "left") + "=" + draw(st.sampled_from(
                sorted(mount_files()) + ["mounts/nope.toml", "m.toml"])))
            if draw(st.booleans()):               # ... and its law or curve mangled
                files["mounts/x.toml"] = mutate_toml(draw, files[spec.split("=")[1]]) \
                    if spec.split("=")[1] in files else b""
                spec = spec.split("=")[0] + "=mounts/x.toml"
        else:
            part = draw(st.sampled_from(["stiffness", "damping", "dynamic"] if op == "scale"
                                        else ["c1", "d1", "m1", "c2"]))
            spec = f"{target}.{part}={value}"
        args += [f"--{op}", spec]
        mutated = (f"--{op}", spec.partition("=")[2].rpartition("/")[2] or "?")
    elif what == "variants":
        files["v.toml"] = mutate_toml(draw, _SEEDS["variants.toml"])
        args += ["--variants", "v.toml"]
        mutated = "v.toml"
    elif what == "spec":
        op = draw(st.sampled_from(["scale", "scale", "set", "move", "rotate", "target"]))
        args += [f"--{op}", draw(mount_op_spec(op))]
        mutated = f"--{op}"
    elif what == "runup_option":
        mutated = draw(st.sampled_from(RUNUP_ONLY))
        args += [mutated, "1000", "--scale", "left.z.dynamic=1.2"]
    else:
        files["m.toml"] = mutate_toml(draw, _SEEDS[seed])
        args += ["--scale", "left.z.stiffness=1.1"]
        mutated = "m.toml"
    if draw(st.integers(0, 4)) == 0:
        args += ["--delta-plot", "d.png"]
        return Case(files, args, ["w.json", "d.png"], mutated, f"whatif --manoeuvre ({what})")
    return Case(files, args, ["w.json"], mutated, f"whatif --manoeuvre ({what})")


KINDS.update({"manoeuvre": case_manoeuvre, "transient_options": case_transient_options,
              "transient_recording": case_transient_recording,
              "whatif_manoeuvre": case_whatif_manoeuvre})
#: The input kinds of ``transient`` and ``whatif --manoeuvre`` (issue 38).
TRANSIENT_KINDS = ("manoeuvre", "transient_options", "transient_recording",
                   "whatif_manoeuvre")


def _fixed(*values):
    """A ``draw`` that returns ``values`` in order (a deterministic mutation)."""
    it = iter(values)
    return lambda strategy: next(it)


def _recording_with(seed: str, ext: str, action: str, *draws) -> bytes:
    """The seed recording with one defect of :func:`_mutate_columns`, drawn as given."""
    data = _SEEDS[f"{seed}-raw.{ext}"]
    cols, comments = _rec_arrays(data, ext)
    return _rec_bytes(_mutate_columns(_fixed(*draws), cols, action), comments, data, ext)


def issue_38_cases() -> dict:
    """Every failure the transient kinds' campaign found, as a named case: name -> (case,
    expected outcome)."""
    mf = mount_files()
    whatif = ["whatif", "--manoeuvre", "m.toml", "--quiet", "--json", "w.json"]
    cases = {
        "whatif --manoeuvre --scale left.z.stiffness=1.6e268 (a singular network)": Case(
            {**mf, "m.toml": _SEEDS["m/start.toml"]},
            [*whatif, "--scale", "left.z.stiffness=1.5746172860597073e+268"], ["w.json"],
            "--scale", ""),
        "whatif (run-up) --scale left.z.stiffness=1e300": Case(
            {**mf}, ["whatif", "--from", "1000", "--to", "2000", "--step", "1000", "--workers",
                     "1", "--quiet", "--json", "w.json", "--scale", "left.z.stiffness=1e300"],
            ["w.json"], "--scale", ""),
    }
    cases["whatif --scale *.*.damping=1e9 (every damper above the plausible)"] = Case(
        {**mf}, ["whatif", "--from", "1000", "--to", "2000", "--step", "1000", "--workers",
                 "1", "--quiet", "--json", "w.json", "--scale", "*.*.damping=1e9"],
        ["w.json"], "--scale", "a damper above the plausible")
    cases["whatif --manoeuvre --set right.y.d1=1e12 (N*s/mm: singular at some frequency)"] = \
        Case({**mf, "m.toml": _SEEDS["m/stop.toml"]}, [*whatif, "--set", "right.y.d1=1e12"],
             ["w.json"], "--set", "")
    for ext in ("h5", "csv"):          # found as a tacho's pulse split in two: 9478 rpm
        cases[f"--speed-from a recorded speed of 7500 rpm, above the engine ({ext})"] = Case(
            {"m.toml": _SEEDS["m/tip-in.toml"],
             f"rec.{ext}": _recording_with("tip-in", ext, "huge_rpm", 5.0)},
            ["transient", "m.toml", "--quiet", "--json", "j.json", "--speed-from", f"rec.{ext}",
             "--trigger", "trigger", "--speed-average"], ["j.json"], f"rec.{ext}", "")
    rest = toml_loads(_SEEDS["m/tip-in.toml"])
    rest["speed"]["speed"]["value"] = [0.0] * len(rest["speed"]["time"]["value"])
    rest["load"]["mean_torque"]["value"] = [5000.0] * len(rest["load"]["time"]["value"])
    rest["manoeuvre"]["gear_ratio"]["value"] = 50.0
    cases["at rest, 5000 N*m in a gear of 50 on the static curves (no static point)"] = \
        _manoeuvre_case(toml_dumps(rest).encode(), "", engine="default-nonlinear")
    out = {name: (case, "clean_error") for name, case in cases.items()}
    # Newton on the curves' static point was held to round-off near the zero-torque point
    # (FloatingPointError on every neutral start above standstill: stop.toml)
    out["stop (window) on the static curves: the static point near zero torque"] = (
        _manoeuvre_case(_SEEDS["m/stop.toml"], "", engine="default-nonlinear"), "ok")
    out["whatif --manoeuvre (stop window) --swap left.z= a mount with a static curve"] = (
        Case({**mf, "m.toml": _SEEDS["m/stop.toml"]},
             [*whatif, "--swap", "left.z=mounts/hydraulic-engine-mount-z-nonlinear.toml"],
             ["w.json"], "--swap", ""), "ok")
    return out
