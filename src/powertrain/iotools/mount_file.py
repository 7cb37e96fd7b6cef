"""Mount files: ``mounts/*.toml`` in datasheet units (c in N/mm, d in N·s/mm, m in kg).

Layout::

    [mount]
    name = "Hydraulic engine mount, X direction"
    model = "triple-parallel"          # a preset of powertrain.models.mount.TOPOLOGIES
    source = "Kovarik 2016, Fig. 37"   # optional
    notes = "..."                      # optional

    [units]                            # every quantity declares its unit
    c = "N/mm"
    d = "N*s/mm"
    m = "kg"

    [parameters]
    c1 = 0.0
    d1 = 0.0
    ...

Values are converted to SI once, here. Missing or negative parameters, NaN, unknown units
or models and unknown keys raise :class:`powertrain.errors.InputError` naming file and key.
"""

from __future__ import annotations

from pathlib import Path

from powertrain.errors import InputError
from powertrain.iotools.tomlfile import get, number, read_toml
from powertrain.models.mount import TOPOLOGIES, MountModel
from powertrain.outputs import atomic_write
from powertrain.units import from_si, to_si

#: The unit each parameter family is written in by :func:`write_mount`.
DATASHEET_UNITS = {"c": "N/mm", "d": "N*s/mm", "m": "kg"}
_DIMENSION = {"c": "stiffness", "d": "damping", "m": "mass"}
#: Plausible upper bounds in SI (1e9 N/mm, 1e6 N*s/mm, 10 t): a steel bar is ~1e6 N/mm, so
#: anything beyond is a unit error and would only ruin the conditioning of the assembly.
MAX_SI = {"c": 1e12, "d": 1e9, "m": 1e4}


def read_mount(path) -> MountModel:
    """Load a mount file into a :class:`~powertrain.models.mount.MountModel` (SI)."""
    path = str(path)
    doc = read_toml(path)
    _no_unknown_keys(doc, {"mount", "units", "parameters"}, path, "")
    mount = get(doc, "mount", path, types=dict)
    _no_unknown_keys(mount, {"name", "model", "source", "notes"}, path, "mount")
    model = get(mount, "model", path, "mount", types=str)
    if model not in TOPOLOGIES:
        raise InputError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})",
                         file=path, key="mount.model")
    topo = TOPOLOGIES[model]
    units = get(doc, "units", path, types=dict)
    _no_unknown_keys(units, set(DATASHEET_UNITS), path, "units")
    params_raw = get(doc, "parameters", path, types=dict)
    unknown = sorted(set(params_raw) - set(topo.parameters))
    if unknown:
        raise InputError(f"unknown parameter for model {model!r} "
                         f"(expected {', '.join(topo.parameters)})",
                         file=path, key=f"parameters.{unknown[0]}")
    params = {}
    for p in topo.parameters:
        family = p[0]
        unit = get(units, family, path, "units", types=str)
        raw = get(params_raw, p, path, "parameters")
        value = number(raw, path, f"parameters.{p}", nonneg=True)
        params[p] = float(to_si(value, unit, _DIMENSION[family], file=path,
                                key=f"units.{family}"))
        if params[p] > MAX_SI[family]:
            raise InputError(f"{value:g} {unit} above the plausible "
                             f"{from_si(MAX_SI[family], unit):g} {unit} (unit error?)",
                             file=path, key=f"parameters.{p}")
    return MountModel(topo, params, name=str(mount.get("name", Path(path).stem)),
                      source=str(mount.get("source", "")), notes=str(mount.get("notes", "")))


def _no_unknown_keys(table: dict, known: set, path: str, prefix: str) -> None:
    """Raise :class:`InputError` naming the first key of ``table`` not in ``known``."""
    unknown = sorted(set(table) - known)
    if unknown:
        key = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise InputError(f"unknown key (expected {', '.join(sorted(known))})",
                         file=path, key=key)


def format_mount(model: MountModel, *, comment: str = "") -> str:
    """The TOML text of a mount file in datasheet units."""
    def q(s):
        return '"' + str(s).replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines = []
    for line in comment.splitlines():
        lines.append(f"# {line}".rstrip())
    lines += ["[mount]", f"name = {q(model.name or model.topology.description)}",
              f"model = {q(model.topology.name)}"]
    if model.source:
        lines.append(f"source = {q(model.source)}")
    if model.notes:
        lines.append(f"notes = {q(model.notes)}")
    lines += ["", "[units]"] + [f'{k} = "{u}"' for k, u in DATASHEET_UNITS.items()]
    lines += ["", "[parameters]"]
    for p in model.topology.parameters:
        lines.append(f"{p} = {from_si(model.params[p], DATASHEET_UNITS[p[0]]):.8g}")
    return "\n".join(lines) + "\n"


def write_mount(model: MountModel, path, *, comment: str = "") -> None:
    """Write a mount file atomically (temporary file, then rename)."""
    text = format_mount(model, comment=comment)
    with atomic_write(path) as fh:
        fh.write(text)
