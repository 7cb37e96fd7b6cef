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
  file) and ``unclear_error`` (exit 1 but not one line naming the file or key): failures.
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
FAILURES = ("traceback", "hang", "nan_output", "leftover", "unclear_error")
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
    mutated: str                      # file name or option the error must name
    description: str = ""
    setup: list = field(default_factory=list)   # callables(folder) run after writing files


_NONFINITE = re.compile(r"(?<![A-Za-z_])(nan|inf|infinity)(?![A-Za-z_])", re.IGNORECASE)


def _nonfinite_in(path: Path) -> bool:
    if path.suffix == ".png":
        return False
    if path.suffix == ".h5":
        import h5py
        bad = []

        def visit(_, obj):
            if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "fc":
                if not np.all(np.isfinite(obj[()])):
                    bad.append(obj.name)
        with h5py.File(path, "r") as h5:
            h5.visititems(visit)
        return bool(bad)
    return bool(_NONFINITE.search(path.read_text(encoding="utf-8", errors="replace")))


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
    present = [o for o in case.outputs if (folder / o).exists()]
    if res["code"] != 0:
        if present:
            return "leftover", ", ".join(present)
        err = res["stderr"].strip()
        if res["code"] == 2 and "Error:" in err:
            return "clean_error", err.splitlines()[-1]
        lines = err.splitlines()
        if len(lines) == 1 and lines[0].startswith("error:") and \
                Path(case.mutated).name in lines[0]:
            return "clean_error", lines[0]
        return "unclear_error", err[-300:]
    if _NONFINITE.search(res["stdout"]) or any(_nonfinite_in(folder / o) for o in present):
        return "nan_output", res["stdout"][-300:]
    return "ok", ""


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
    from powertrain.iotools.raw_csv import write_raw_csv
    from powertrain.validation import signals
    write_raw_csv(folder / "raw.csv", signals.analytic_sweep(fs=2048.0, duration=2.0,
                                                             rpm0=1500.0, rpm1=3000.0),
                  comment="SYNTHETIC: analytic sweep (fuzz seed)")
    _SEEDS["raw.csv"] = (folder / "raw.csv").read_bytes()
    res = worker.run(["stiffness", str(ROOT / "mounts" / "hydraulic-engine-mount-z.toml"),
                      "--freq", "1:200:10", "--format", "csv"], folder)
    _SEEDS["k.csv"] = res["stdout"].encode()
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
    param = st.tuples(st.sampled_from(["k1", "c_base", "m_base", "kappa", "a_c", "g3", "lag",
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
    files["engines/e.toml"] = _SEEDS["engine"]
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
