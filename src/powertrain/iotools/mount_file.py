"""Mount files (``mounts/*.toml``, datasheet units; docs/reference/mount-file.md) into a
:class:`~powertrain.models.mount.MountModel` in SI and back (:func:`write_mount`); the optional
``[amplitude]``, ``[friction]``, ``[static]`` sections become :mod:`powertrain.physics.mount_laws`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.tomlfile import get, number, read_toml
from powertrain.models.mount import TOPOLOGIES, MountModel
from powertrain.outputs import atomic_write
from powertrain.physics.mount_laws import BergFriction, PowerLaw, StaticCurve, TableLaw
from powertrain.units import from_si, to_si

#: The unit each parameter family is written in by :func:`write_mount`.
DATASHEET_UNITS = {"c": "N/mm", "d": "N*s/mm", "m": "kg"}
#: Units of the nonlinear sections' lengths and forces, written only when a section needs them.
SECTION_UNITS = {"x": "mm", "F": "N"}
_DIMENSION = {"c": "stiffness", "d": "damping", "m": "mass", "x": "length", "F": "force"}
#: The ``limits`` of a power law when the file gives none (those of :class:`PowerLaw`).
DEFAULT_LIMITS = PowerLaw(1.0, 0.0).limits
#: Plausible upper bounds in SI (1e9 N/mm, 1e6 N*s/mm, 10 t): a steel bar is ~1e6 N/mm, so
#: anything beyond is a unit error and would only ruin the conditioning of the assembly.
MAX_SI = {"c": 1e12, "d": 1e9, "m": 1e4}


def read_mount(path) -> MountModel:
    """Load a mount file into a :class:`~powertrain.models.mount.MountModel` (SI)."""
    path = str(path)
    doc = read_toml(path)
    _no_unknown_keys(doc, {"mount", "units", "parameters", *_SECTIONS}, path, "")
    mount = get(doc, "mount", path, types=dict)
    _no_unknown_keys(mount, {"name", "model", "source", "notes"}, path, "mount")
    model = get(mount, "model", path, "mount", types=str)
    if model not in TOPOLOGIES:
        raise InputError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})",
                         file=path, key="mount.model")
    topo = TOPOLOGIES[model]
    units = get(doc, "units", path, types=dict)
    _no_unknown_keys(units, set(_DIMENSION), path, "units")
    params_raw = get(doc, "parameters", path, types=dict)
    unknown = sorted(set(params_raw) - set(topo.parameters))
    if unknown:
        raise InputError(f"unknown parameter for model {model!r} (expected {', '.join(topo.parameters)})",
                         file=path, key=f"parameters.{unknown[0]}")
    params = {}
    for p in topo.parameters:
        family = p[0]
        unit = get(units, family, path, "units", types=str)
        raw = get(params_raw, p, path, "parameters")
        value = number(raw, path, f"parameters.{p}", nonneg=True)
        params[p] = float(to_si(value, unit, _DIMENSION[family], file=path, key=f"units.{family}"))
        if params[p] > MAX_SI[family]:
            raise InputError(f"{value:g} {unit} above the plausible "
                             f"{from_si(MAX_SI[family], unit):g} {unit} (unit error?)",
                             file=path, key=f"parameters.{p}")
    laws = {field: reader(get(doc, section, path, types=dict), _Units(units, path))
            for section, (field, reader) in _SECTIONS.items() if section in doc}
    model = MountModel(topo, params, name=str(mount.get("name", Path(path).stem)),
                       source=str(mount.get("source", "")), notes=str(mount.get("notes", "")), **laws)
    check_network(model, path)
    return model


def check_plausible(model: MountModel, path) -> None:
    """Refuse a parameter above :data:`MAX_SI` or not finite (one set from the command line)."""
    for p, value in model.params.items():
        top = MAX_SI[p[0]]
        if not value <= top:
            unit = {"c": "N/m", "d": "N*s/m", "m": "kg"}[p[0]]
            raise InputError(f"{p} = {value:g} {unit} above the plausible {top:g} {unit} "
                             "(unit error?)", file=path, key=f"parameters.{p}")


def check_network(model: MountModel, path) -> None:
    """Refuse a network singular at 0 Hz (an internal node held by no spring to the engine
    side or the ground), where every solver condenses it; the error names the loose nodes."""
    try:
        with np.errstate(all="ignore"):
            model.static_stiffness()
    except FloatingPointError:
        loose = _loose_nodes(model)
        held = (f"internal node{'s' if len(loose) > 1 else ''} {', '.join(loose)} "
                "held by no spring to the engine side or the ground") if loose else \
            "an internal node's springs are below 1e-13 of the stiffest"
        raise InputError(f"the mount network is singular at 0 Hz ({held}; every spring and "
                         "damper 0?): no static stiffness can be computed", file=path,
                         key="parameters") from None


def _loose_nodes(model: MountModel) -> list:
    """Labels of the internal nodes joined to neither engine side nor ground by nonzero springs."""
    topo = model.topology
    held = {"E", "G"}
    springs = [(a, b) for a, b, c, _ in topo.elements if c and model.params[c] > 0]
    grown = True
    while grown:
        grown = False
        for a, b in springs:
            if (a in held) != (b in held):
                held |= {a, b}
                grown = True
    return [topo.masses[k - 1] or f"node {k}" for k in range(1, topo.n_internal + 1) if f"n{k}" not in held]


class _Units:
    """The ``[units]`` table of one file: a section's numbers to SI (errors name ``units.x``)."""

    def __init__(self, units: dict, path: str):
        self.units, self.path = units, path

    def si(self, value, family: str):
        unit = get(self.units, family, self.path, "units", types=str)
        return to_si(value, unit, _DIMENSION[family], file=self.path, key=f"units.{family}")


def _numbers(t: dict, key: str, path: str, prefix: str, *, positive=False, nonneg=False,
             increasing=False) -> np.ndarray:
    """A non-empty list of finite numbers ``t[key]`` (optionally > 0, strictly increasing)."""
    raw = get(t, key, path, prefix, types=list)
    full = f"{prefix}.{key}"
    if not raw:
        raise InputError("expected a non-empty list of numbers", file=path, key=full)
    vals = np.array([number(v, path, full, positive=positive, nonneg=nonneg) for v in raw])
    if increasing and np.any(np.diff(vals) <= 0):
        i = int(np.argmax(np.diff(vals) <= 0))
        raise InputError(f"must be strictly increasing ({vals[i]:g} then {vals[i + 1]:g})",
                         file=path, key=full)
    return vals


def _same_length(values: np.ndarray, like: np.ndarray, like_key: str, path, key) -> None:
    if len(values) != len(like):
        raise InputError(f"has {len(values)} values, {like_key} has {len(like)}", file=path, key=key)


def _read_amplitude(t: dict, units: _Units):
    """``[amplitude]`` -> :class:`PowerLaw` or :class:`TableLaw` (SI)."""
    path = units.path
    law = get(t, "law", path, "amplitude", types=str)
    if law == "power":
        _no_unknown_keys(t, {"law", "reference", "exponent", "limits", "damping_exponent"}, path, "amplitude")
        reference = number(get(t, "reference", path, "amplitude"), path, "amplitude.reference", positive=True)
        exponent = number(get(t, "exponent", path, "amplitude"), path, "amplitude.exponent")
        limits = tuple(_numbers(t, "limits", path, "amplitude", positive=True).tolist()) \
            if "limits" in t else DEFAULT_LIMITS
        if len(limits) != 2 or not limits[0] <= 1.0 <= limits[1]:
            raise InputError(f"expected [lo, hi] with 0 < lo <= 1 <= hi, got {list(limits)}",
                             file=path, key="amplitude.limits")
        gamma = number(t.get("damping_exponent", 1.0), path, "amplitude.damping_exponent")
        return PowerLaw(float(units.si(reference, "x")), exponent, limits, gamma)
    if law == "table":
        _no_unknown_keys(t, {"law", "amplitudes", "stiffness_scale", "damping_scale"}, path, "amplitude")
        amps = _numbers(t, "amplitudes", path, "amplitude", positive=True, increasing=True)
        scales = {}
        for key in ("stiffness_scale", "damping_scale"):
            if key in t or key == "stiffness_scale":
                scales[key] = _numbers(t, key, path, "amplitude", positive=True)
                _same_length(scales[key], amps, "amplitudes", path, f"amplitude.{key}")
        damping = scales.get("damping_scale")
        return TableLaw(tuple(units.si(amps, "x").tolist()), tuple(scales["stiffness_scale"].tolist()),
                        None if damping is None else tuple(damping.tolist()))
    raise InputError(f"unknown law {law!r} (expected power or table)", file=path, key="amplitude.law")


def _read_friction(t: dict, units: _Units) -> BergFriction:
    """``[friction]`` -> :class:`BergFriction` (SI)."""
    path = units.path
    _no_unknown_keys(t, {"max_force", "half_displacement"}, path, "friction")
    fmax = number(get(t, "max_force", path, "friction"), path, "friction.max_force", nonneg=True)
    x2 = number(get(t, "half_displacement", path, "friction"), path,
                "friction.half_displacement", positive=True)
    return BergFriction(float(units.si(fmax, "F")), float(units.si(x2, "x")))


def _read_static(t: dict, units: _Units) -> StaticCurve:
    """``[static]`` -> :class:`StaticCurve` (SI), increasing, with positive tangents."""
    path = units.path
    _no_unknown_keys(t, {"deflection", "force", "reference_deflection"}, path, "static")
    x = _numbers(t, "deflection", path, "static", increasing=True)
    f = _numbers(t, "force", path, "static", increasing=True)
    _same_length(f, x, "deflection", path, "static.force")
    if len(x) < 2:
        raise InputError("a static curve needs at least 2 points", file=path, key="static.deflection")
    ref = number(get(t, "reference_deflection", path, "static", default=0.0), path,
                 "static.reference_deflection")
    curve = StaticCurve(tuple(units.si(x, "x").tolist()), tuple(units.si(f, "F").tolist()),
                        float(units.si(ref, "x")))
    ends = curve.tangent_at([curve.deflection[0], curve.deflection[-1]])
    if not curve.tangent_at(curve.reference_deflection) > 0:
        raise InputError("the curve's tangent there is zero", file=path, key="static.reference_deflection")
    if not np.all(ends > 0):
        raise InputError("the curve's end slope (PCHIP's end-point derivative) is zero; "
                         "add a point beyond", file=path, key="static.force")
    return curve


#: Section -> (MountModel field, reader).
_SECTIONS = {"amplitude": ("amplitude_law", _read_amplitude), "friction": ("port_law", _read_friction),
             "static": ("static_curve", _read_static)}


def _no_unknown_keys(table: dict, known: set, path: str, prefix: str) -> None:
    """Raise :class:`InputError` naming the first key of ``table`` not in ``known``."""
    unknown = sorted(set(table) - known)
    if unknown:
        key = f"{prefix}.{unknown[0]}" if prefix else unknown[0]
        raise InputError(f"unknown key (expected {', '.join(sorted(known))})", file=path, key=key)


def format_mount(model: MountModel, *, comment: str = "") -> str:
    """The TOML text of a mount file in datasheet units."""
    def q(s):
        return '"' + str(s).replace("\\", "\\\\").replace('"', '\\"') + '"'
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    lines += ["[mount]", f"name = {q(model.name or model.topology.description)}",
              f"model = {q(model.topology.name)}"]
    if model.source:
        lines.append(f"source = {q(model.source)}")
    if model.notes:
        lines.append(f"notes = {q(model.notes)}")
    units = {**DATASHEET_UNITS, **(SECTION_UNITS if not model.linear else {})}
    lines += ["", "[units]"] + [f'{k} = "{u}"' for k, u in units.items()]
    lines += ["", "[parameters]"]
    for p in model.topology.parameters:
        lines.append(f"{p} = {from_si(model.params[p], DATASHEET_UNITS[p[0]]):.8g}")
    return "\n".join(lines + _section_lines(model)) + "\n"


def _section_lines(model: MountModel) -> list:
    """The ``[amplitude]``, ``[friction]`` and ``[static]`` lines of ``model`` (mm, N)."""
    def x(v):
        return _toml_number(from_si(v, SECTION_UNITS["x"]))

    def xs(vs):
        return "[" + ", ".join(x(v) for v in vs) + "]"

    def plain(vs):
        return "[" + ", ".join(_toml_number(v) for v in vs) + "]"

    def forces(vs):
        return plain(from_si(np.asarray(vs, float), SECTION_UNITS["F"]))
    lines = []
    law = model.amplitude_law
    if isinstance(law, PowerLaw):
        lines += ["", "[amplitude]", 'law = "power"', f"reference = {x(law.reference)}",
                  f"exponent = {_toml_number(law.exponent)}", f"limits = {plain(law.limits)}"]
        if law.damping_exponent != 1.0:
            lines.append(f"damping_exponent = {_toml_number(law.damping_exponent)}")
    elif isinstance(law, TableLaw):
        lines += ["", "[amplitude]", 'law = "table"', f"amplitudes = {xs(law.amplitudes)}",
                  f"stiffness_scale = {plain(law.stiffness_scale)}"]
        if law.damping_scale is not None:
            lines.append(f"damping_scale = {plain(law.damping_scale)}")
    if isinstance(model.port_law, BergFriction):
        fmax = from_si(model.port_law.max_force, SECTION_UNITS["F"])
        lines += ["", "[friction]", f"max_force = {_toml_number(fmax)}",
                  f"half_displacement = {x(model.port_law.half_displacement)}"]
    curve = model.static_curve
    if curve is not None:
        lines += ["", "[static]", f"deflection = {xs(curve.deflection)}", f"force = {forces(curve.force)}",
                  f"reference_deflection = {x(curve.reference_deflection)}"]
    return lines


def _toml_number(value: float) -> str:
    """A float as TOML (8 significant digits, always with a decimal point or exponent)."""
    text = f"{float(value):.8g}"
    return text if any(c in text for c in ".en") else text + ".0"


def write_mount(model: MountModel, path, *, comment: str = "") -> None:
    """Write a mount file atomically (temporary file, then rename)."""
    text = format_mount(model, comment=comment)
    with atomic_write(path) as fh:
        fh.write(text)
