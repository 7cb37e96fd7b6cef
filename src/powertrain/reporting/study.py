"""Reading a study file (TOML, docs/reference/study-file.md): engine, measured run-up or plan,
noise floor and one table per step (present table: step included, empty: its defaults).
Paths are relative to the study file. All is checked and read before any step runs.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path

from powertrain.errors import InputError
from powertrain.iotools.engine_file import DEFAULT_ENGINE_PATH, read_engine
from powertrain.iotools.measured import read_measured
from powertrain.iotools.plan import read_plan
from powertrain.iotools.tomlfile import quantity, read_toml
from powertrain.reporting import keys as k
from powertrain.reporting.steps import STEPS

#: Keys of the top level of a study file besides the steps' tables.
TOP_KEYS = ("title", "engine", "measured", "plan", "noise_floor")
#: Default RMS noise floor of the measured order curves [m/s] (as compare and diagnose).
DEFAULT_NOISE_FLOOR = 1e-6


@dataclass(frozen=True)
class Study:
    """A study file as read: engine, measurement, steps and their options.

    Attributes
    ----------
    path : str
        The study file.
    title : str
    engine : Engine
    engine_file : str or None
        The engine file named (None: the shipped default).
    measured : MeasuredRunup or None
    plan : Plan or None
        A test plan of several run-ups.
    noise_floor : float
        RMS noise floor of the measured order curves [m/s].
    steps : dict
        Step name -> its checked options, in report order.
    files : list of (str, str)
        ``(role, path)`` of every file read.
    """

    path: str
    title: str
    engine: object
    engine_file: str | None
    measured: object = None
    plan: object = None
    noise_floor: float = DEFAULT_NOISE_FLOOR
    steps: dict = field(default_factory=dict)
    files: list = field(default_factory=list)

    def runs(self) -> list:
        """``(label, measured, engine, plan run or None)`` of every measured run-up (each plan
        run with the engine in its operating state)."""
        if self.plan is None:
            return [] if self.measured is None else [("", self.measured, self.engine, None)]
        out = []
        for i, run in enumerate(self.plan.runs, start=1):
            how = f"traces {Path(run.traces).name}" if run.traces else f"load {run.load:g}"
            out.append((f"run {i}: {Path(run.file).name} ({how})", run.measured,
                        run.engine(self.engine), run))
        return out


def read_study(path) -> Study:
    """Read and check the study file ``path`` and the engine, measurement and plan it names.

    Raises
    ------
    InputError
        Naming the study file (or a file it names) and the key.
    """
    path = str(path)
    doc = read_toml(path)
    where = k.Where(path, Path(path).parent)
    k.check_keys(doc, TOP_KEYS + tuple(STEPS), where)
    engine_file = k.file_path(doc, "engine", where)
    engine = read_engine(engine_file or DEFAULT_ENGINE_PATH)
    where = k.Where(path, where.base, engine)
    measured, plan = _measurement(doc, where, engine)
    steps = {}
    for name, step in STEPS.items():
        if name not in doc:
            continue
        if not isinstance(doc[name], dict):
            raise where.error(f"expected a table [{name}], got {type(doc[name]).__name__}",
                              name)
        if step.needs_measured and measured is None and plan is None:
            raise where.error(f"{name} needs a measurement: give measured = FILE or plan = "
                              "PLAN.toml", name)
        steps[name] = step.options(doc[name], where)
    if not steps:
        raise where.error(f"no step: add one or more of the tables {', '.join(STEPS)}",
                          "steps")
    study = Study(path=path, title=k.string(doc, "title", where, "", "") or Path(path).stem,
                  engine=engine, engine_file=engine_file, measured=measured, plan=plan,
                  noise_floor=_noise_floor(doc, where), steps=steps)
    return _with_files(study, where)


def _measurement(doc, where, engine):
    """``(measured, plan)``: one of them read, or neither."""
    if "measured" in doc and "plan" in doc:
        raise where.error("give either measured or plan, not both", "plan")
    measured = k.file_path(doc, "measured", where)
    plan = k.file_path(doc, "plan", where)
    if plan is not None:
        return None, read_plan(plan, engine)
    if measured is not None:
        return read_measured(measured, mounts=engine.mount_names), None
    return None, None


def _noise_floor(doc, where) -> float:
    if "noise_floor" not in doc:
        return DEFAULT_NOISE_FLOOR
    value = quantity(doc, "noise_floor", "velocity", where.path, nonneg=True)
    if value > 1.0:
        raise where.error(f"{value:g} m/s is not a noise floor of order curves", "noise_floor")
    return value


def _with_files(study: Study, where) -> Study:
    """``study`` with ``files``: ``(role, path)`` of every file it reads."""
    files = [("study", study.path), ("engine", study.engine.file)]
    for m in study.engine.mounts:
        files += [(f"mount {m.name}.{d}", os.path.normpath(f)) for d, f in m.files.items()]
    if study.measured is not None:
        files.append(("measured", study.measured.source))
    if study.plan is not None:
        files.append(("plan", study.plan.source))
        for i, run in enumerate(study.plan.runs, start=1):
            files.append((f"plan run {i}", run.file))
            if run.traces:
                files.append((f"plan run {i} pressure traces", run.traces))
    opts = study.steps.get("whatif")
    if opts and opts["variants"]:
        files.append(("what-if variants", opts["variants"]))
    for spec in (opts or {}).get("ops", {}).get("swap", []):
        files.append((f"what-if swap {spec.partition('=')[0]}", spec.partition("=")[2]))
    files += [("manoeuvre", f) for f in study.steps.get("transient", {}).get("files", [])]
    roles = {}                               # real path -> [path, roles]
    for role, f in files:
        roles.setdefault(os.path.realpath(f), [f, []])[1].append(role)
    merged = [(_roles(rs), f) for f, rs in roles.values()]
    return replace(study, files=merged)


def _roles(roles: list) -> str:
    """``mount left.x, right.x`` for one file of several roles of one kind."""
    kind = roles[0].split(" ")[0]
    if len(roles) > 1 and all(r.startswith(kind + " ") for r in roles):
        return kind + " " + ", ".join(r[len(kind) + 1:] for r in roles)
    return ", ".join(roles)


def check_study_path(study) -> str:
    """``study`` as the path of a TOML file, else an InputError naming ``STUDY``."""
    if not isinstance(study, (str, os.PathLike)):
        raise InputError(f"expected a study file (TOML), got {type(study).__name__}",
                         key="STUDY")
    if not str(study).lower().endswith(".toml"):
        raise InputError("a study is a TOML file (STUDY.toml)", file=study, key="STUDY")
    return str(study)
