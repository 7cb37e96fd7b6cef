"""Test plans (TOML, docs/guide/diagnose.md): several measured run-ups of one car diagnosed
together, each ``[[runs]]`` with ``file`` and optionally ``load`` (IMEP scale) or ``traces``
(a pressure-trace CSV), paths relative to the plan.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from powertrain.errors import InputError
from powertrain.iotools.measured import read_measured
from powertrain.iotools.pressure_csv import read_pressure_traces
from powertrain.iotools.tomlfile import get, number, read_toml

#: Keys a run may have.
RUN_KEYS = ("file", "load", "traces")


@dataclass
class PlanRun:
    """One run of a plan: its ``measured`` order curves, the combustion model's IMEP scale
    ``load`` (1: as in the engine file) or the pressure-trace CSV ``traces`` replacing it."""

    measured: object
    load: float = 1.0
    traces: str | None = None

    @property
    def file(self) -> str:
        return getattr(self.measured, "source", "")

    def engine(self, engine):
        """``engine`` in this run's operating state."""
        if self.traces is not None:
            engine = engine.replace(combustion=read_pressure_traces(self.traces, engine.crank.n_cylinders))
        return engine.at_load(self.load)

    def to_dict(self) -> dict:
        return {"file": self.file, "load": self.load, "traces": self.traces}


@dataclass
class Plan:
    """Runs of one car diagnosed together (:func:`powertrain.diagnosis.diagnose`)."""

    runs: list
    source: str = ""
    notes: list = field(default_factory=list)

    @property
    def synthetic(self) -> bool:
        """Some run is a synthetic measurement."""
        return any(getattr(r.measured, "synthetic", False) for r in self.runs)


def read_plan(path, engine) -> Plan:
    """Read a plan file; every run's measured file read for ``engine``'s mounts.

    Raises
    ------
    InputError
        Naming the plan file and the key (``runs[2].load``) or the run's own file.
    """
    path = str(path)
    data = read_toml(path)
    extra = sorted(set(data) - {"runs"})
    if extra:
        raise InputError(f"unknown key (a plan has [[runs]] only): {extra[0]}", file=path, key=extra[0])
    runs = get(data, "runs", path, types=list)
    if not runs or not all(isinstance(r, dict) for r in runs):
        raise InputError("expected one or more [[runs]] tables", file=path, key="runs")
    base, out = Path(path).parent, []
    for i, run in enumerate(runs, start=1):
        load, traces, file = _run_keys(run, path, f"runs[{i}]", engine, base)
        out.append(PlanRun(read_measured(file, mounts=engine.mount_names), load, traces))
    return Plan(out, source=path)


def _run_keys(run, path, key, engine, base):
    """``(load, traces path, measured path)`` of one run, checked."""
    unknown = sorted(set(run) - set(RUN_KEYS))
    if unknown:
        raise InputError(f"unknown key (known: {', '.join(RUN_KEYS)})", file=path, key=f"{key}.{unknown[0]}")
    file = str(base / get(run, "file", path, key, types=str))
    load = number(get(run, "load", path, key, default=1.0), path, f"{key}.load", positive=True)
    traces = get(run, "traces", path, key, default=None, types=str)
    if traces is not None and "load" in run:
        raise InputError("give either load or traces, not both", file=path, key=f"{key}.load")
    if "load" in run and getattr(engine.combustion, "model", "") == "measured":
        raise InputError("load applies to engines with a combustion model; this engine has "
                         "measured pressure traces (give traces = ... instead)", file=path, key=f"{key}.load")
    if traces is not None:
        traces = str(base / traces)
    return load, traces, file
