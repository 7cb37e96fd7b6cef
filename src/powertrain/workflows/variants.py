r"""Variants of the mount system: spec strings parsed into operations
(:mod:`powertrain.workflows.operations`), one parser per option (:data:`PARSERS`) for the
command line and the variants file alike; errors name the option (or file, line and key).
Syntax: docs/guide/whatif.md.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from powertrain.effects import EFFECTS, check_scenario
from powertrain.errors import InputError
from powertrain.iotools.mount_file import DATASHEET_UNITS, SECTION_UNITS, read_mount
from powertrain.iotools.tomlfile import read_toml
from powertrain.units import UNITS, to_si
from powertrain.workflows.operations import (
    LAW_KEYS,
    WILDCARD,
    AddEffect,
    Move,
    Origin,
    Rotate,
    Scale,
    SetParameter,
    Swap,
    Target,
    Variant,
)

#: Scale kinds and what each scales.
SCALE_KINDS = {"stiffness": "every spring c_i", "damping": "every damper d_i",
               "dynamic": "every c_i, d_i and m_i (K_CP(omega) times the factor)"}
_NAME = r"[A-Za-z_][A-Za-z0-9_\-]*"


def _split(text: str, origin: Origin, form: str):
    parts = [s.strip() for s in text.split("=")] if isinstance(text, str) else []
    if len(parts) != 2 or not all(parts):
        raise origin.error(f"cannot read {text!r} (expected {form})")
    return parts


def _path_parts(left, n, text, origin, form, wildcard=True):
    parts = left.split(".")
    pattern = re.compile(rf"^(\*|{_NAME})$" if wildcard else rf"^{_NAME}$")
    if len(parts) != n or not all(pattern.match(p) for p in parts):
        raise origin.error(f"cannot read {text!r} (expected {form})")
    if n > 1:
        _direction(parts[1], text, origin)
    return parts


def _direction(d, text, origin):
    if d not in ("x", "y", "z", WILDCARD):
        raise origin.error(f"{text!r}: unknown direction {d!r} (expected x, y, z or *)")
    return d


def _float(s, text, origin, what="a number"):
    try:
        v = float(s)
    except ValueError:
        raise origin.error(f"{text!r}: {s!r} is not {what}") from None
    if not math.isfinite(v):
        raise origin.error(f"{text!r}: {s!r} is not finite")
    return v


def _quantity(s, text, origin):
    """``(number, unit)`` of ``VALUE[UNIT]`` (unit ``""`` when none)."""
    m = re.match(r"^([-+0-9.eE]+)\s*(.*)$", s.strip())
    if not m:
        raise origin.error(f"{text!r}: {s.strip()!r} is not a number")
    return _float(m.group(1), text, origin), m.group(2).strip()


def _vector3(s, text, origin):
    parts = s.split(",")
    if len(parts) != 3:
        raise origin.error(f"{text!r}: expected three comma-separated numbers")
    return tuple(_float(p.strip(), text, origin) for p in parts)


def _law_key(left, text, origin, form, column):
    """``(mount, direction, key)`` of ``MOUNT.DIR.SECTION.KEY``, a key of :data:`LAW_KEYS`
    allowed in ``column`` (2: --scale, 3: --set)."""
    mount, direction, section, name = _path_parts(left, 4, text, origin, form)
    key = f"{section}.{name}"
    allowed = [k for k, v in LAW_KEYS.items() if v[column]]
    if key not in allowed:
        raise origin.error(f"{text!r}: unknown key {key!r} (expected {', '.join(allowed)})")
    return mount, direction, key


def parse_scale(text: str, origin: Origin = Origin("--scale")) -> Scale:
    """``MOUNT.DIR.KIND=FACTOR`` -> :class:`Scale` (KIND stiffness|damping|dynamic, or a
    law key ``SECTION.KEY`` of :data:`LAW_KEYS`: ``left.z.amplitude.exponent=0.5``)."""
    form = "MOUNT.DIR.KIND=FACTOR, e.g. left.z.stiffness=1.2 or left.z.amplitude.exponent=0.5"
    left, right = _split(text, origin, form)
    if left.count(".") == 3:
        mount, direction, kind = _law_key(left, text, origin, form, 2)
    else:
        mount, direction, kind = _path_parts(left, 3, text, origin, form)
        if kind not in SCALE_KINDS:
            raise origin.error(f"{text!r}: unknown kind {kind!r} (expected "
                               f"{', '.join(SCALE_KINDS)}, or a law key such as amplitude.exponent)")
    factor = _float(right, text, origin, "a factor")
    if factor <= 0:
        raise origin.error(f"{text!r}: factor must be positive, got {factor:g}")
    return Scale(mount, direction, kind, factor, spec=text, origin=origin)


def parse_set(text: str, origin: Origin = Origin("--set")) -> SetParameter:
    """``MOUNT.DIR.PARAM=VALUE[UNIT]`` -> :class:`SetParameter` (SI value; default units
    c: N/mm, d: N·s/mm, m: kg)."""
    form = "MOUNT.DIR.PARAM=VALUE, e.g. right.y.c2=150 (N/mm) or left.z.friction.max_force=20"
    left, right = _split(text, origin, form)
    if left.count(".") == 3:
        mount, direction, key = _law_key(left, text, origin, form, 3)
        return SetParameter(mount, direction, key, _law_value(key, right, text, origin),
                            spec=text, origin=origin)
    mount, direction, param = _path_parts(left, 3, text, origin, form)
    if not re.match(r"^[cdm][0-9]+$", param):
        raise origin.error(f"{text!r}: unknown parameter {param!r} (expected c<n>, d<n> or m<n>)")
    value, unit = _quantity(right, text, origin)
    unit = unit or DATASHEET_UNITS[param[0]]
    if value < 0:
        raise origin.error(f"{text!r}: value must not be negative, got {value:g}")
    dimension = {"c": "stiffness", "d": "damping", "m": "mass"}[param[0]]
    if unit not in UNITS:
        raise origin.error(f"{text!r}: unknown unit {unit!r}")
    try:
        si = float(to_si(value, unit, dimension))
    except InputError as exc:
        raise origin.error(f"{text!r}: {exc.message}") from None
    return SetParameter(mount, direction, param, si, spec=text, origin=origin)


def _law_value(key, right, text, origin):
    """SI value of a law key's ``--set`` (``LO,HI`` for ``amplitude.limits``), checked."""
    dimension, family = LAW_KEYS[key][:2]
    if key == "amplitude.limits":
        parts = right.split(",")
        lo, hi = (_float(p.strip(), text, origin) for p in parts) if len(parts) == 2 else (math.nan, math.nan)
        if not 0 < lo <= 1 <= hi:
            raise origin.error(f"{text!r}: expected LO,HI with 0 < LO <= 1 <= HI")
        return (lo, hi)
    value, unit = _quantity(right, text, origin)
    unit = unit or (SECTION_UNITS[family] if family else "1")
    if dimension is None:
        if unit != "1":
            raise origin.error(f"{text!r}: {key} has no unit, got {unit!r}")
        return value
    if unit not in UNITS or UNITS[unit][0] != dimension:
        raise origin.error(f"{text!r}: unit {unit!r} is unknown or not a unit of {dimension}")
    si = float(to_si(value, unit, dimension))
    if key != "static.reference_deflection" and (si < 0 or si == 0 and "max" not in key):
        raise origin.error(f"{text!r}: the value must be {'>= 0' if 'max' in key else '> 0'}, got {value:g}")
    return si


def parse_swap(text: str, origin: Origin = Origin("--swap"), base: Path | None = None) -> Swap:
    """``MOUNT.DIR=FILE.toml`` -> :class:`Swap` (file read now, relative to ``base``)."""
    form = "MOUNT.DIR=FILE.toml, e.g. left.z=mounts/hydraulic-engine-mount-z.toml"
    left, right = _split(text, origin, form)
    mount, direction = _path_parts(left, 2, text, origin, form, wildcard=False)
    path = Path(right)
    if base is not None and not path.is_absolute():
        path = Path(base) / path
    if not path.is_file():
        raise origin.error(f"{text!r}: mount file not found: {path}")
    return Swap(mount, direction, read_mount(path), path=str(path), spec=text, origin=origin)


def parse_move(text: str, origin: Origin = Origin("--move")) -> Move:
    """``MOUNT=DX,DY,DZ`` [mm, engine axes] -> :class:`Move` (SI offset)."""
    form = "MOUNT=DX,DY,DZ in mm, e.g. gearbox=0,0,10"
    left, right = _split(text, origin, form)
    (mount,) = _path_parts(left, 1, text, origin, form)
    d = _vector3(right, text, origin)
    return Move(mount, tuple(1e-3 * v for v in d), spec=text, origin=origin)


def parse_rotate(text: str, origin: Origin = Origin("--rotate")) -> Rotate:
    """``MOUNT=AX,AY,AZ`` [deg about engine X, Y, Z] -> :class:`Rotate` (SI angles)."""
    form = "MOUNT=AX,AY,AZ in degrees, e.g. left=0,0,5"
    left, right = _split(text, origin, form)
    (mount,) = _path_parts(left, 1, text, origin, form)
    a = _vector3(right, text, origin)
    return Rotate(mount, tuple(math.radians(v) for v in a), spec=text, origin=origin)


def parse_target(text: str, origin: Origin = Origin("--target")) -> Target:
    """``MOUNT.DIR:CHANGE:BAND[:WIDTH][:AMPLITUDE]`` -> :class:`Target`: CHANGE ``+20%`` or
    ``*1.2``, BAND ``100-300Hz``, WIDTH ``0.5oct`` (default), AMPLITUDE ``0.3mm``."""
    form = "MOUNT.DIR:CHANGE:BAND[:WIDTH][:AMPLITUDE], e.g. left.z:+20%:100-300Hz:0.3mm"
    parts = [p.strip() for p in text.split(":")] if isinstance(text, str) else []
    if len(parts) not in (3, 4, 5):
        raise origin.error(f"cannot read {text!r} (expected {form})")
    mount, direction = _path_parts(parts[0], 2, text, origin, form, wildcard=False)
    change = parts[1].replace(" ", "")
    m_pct = re.match(r"^([+-][0-9.eE+-]+)%$", change)
    m_fac = re.match(r"^[*x]([0-9.eE+-]+)$", change)
    if m_pct:
        factor = 1.0 + _float(m_pct.group(1), text, origin) / 100.0
    elif m_fac:
        factor = _float(m_fac.group(1), text, origin)
    else:
        raise origin.error(f"{text!r}: cannot read change {parts[1]!r} (expected +20%, -15% or *1.2)")
    if factor <= 0:
        raise origin.error(f"{text!r}: the change must leave a positive stiffness (factor {factor:g})")
    m_band = re.match(r"^([0-9.eE+]+)\s*-\s*([0-9.eE+]+)\s*(Hz)?$", parts[2])
    if not m_band:
        raise origin.error(f"{text!r}: cannot read band {parts[2]!r} (expected e.g. 100-300Hz)")
    f_lo = _float(m_band.group(1), text, origin)
    f_hi = _float(m_band.group(2), text, origin)
    if not 0 < f_lo < f_hi:
        raise origin.error(f"{text!r}: band must satisfy 0 < low < high [Hz]")
    width, amplitude = 0.5, None
    for k, extra in enumerate(parts[3:]):
        m_w = re.match(r"^([0-9.eE+]+)\s*oct$", extra)
        if m_w and k == 0:
            width = _float(m_w.group(1), text, origin)
            if width <= 0:
                raise origin.error(f"{text!r}: width must be positive")
        elif k == len(parts) - 4:        # the last part: an amplitude
            amplitude = _law_value("amplitude.reference", extra, text, origin)
        else:
            raise origin.error(f"{text!r}: cannot read width {extra!r} (expected e.g. 0.5oct)")
    return Target(mount, direction, factor, f_lo, f_hi, width, spec=text, origin=origin, amplitude=amplitude)


def parse_effect(text: str, origin: Origin = Origin("--effect"), engine=None) -> AddEffect:
    """``NAME[:PARAM=VALUE[UNIT][,PARAM=VALUE...]]`` -> :class:`AddEffect` (SI values), the
    parameters those of ``engine`` (default layout without), values in their own unit
    unless one of the same dimension is given (``c_base=400N/mm``)."""
    form = "NAME[:PARAM=VALUE,...], e.g. mount_stiffness:k1=1.5"
    name, _, rest = text.partition(":")
    name = name.strip()
    if name not in EFFECTS:
        raise origin.error(f"{text!r}: unknown effect {name!r} (expected {', '.join(EFFECTS)})")
    spec = {p.name: p for p in EFFECTS[name].parameters(engine)}
    params = []
    for item in [x.strip() for x in rest.split(",")] if rest.strip() else []:
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq:
            raise origin.error(f"{text!r}: expected PARAM=VALUE in {item!r} ({form})")
        if key not in spec:
            raise origin.error(f"{text!r}: effect {name!r} has no parameter {key!r} "
                               f"(expected {', '.join(spec)})")
        p = spec[key]
        v, unit = _quantity(value, text, origin)
        unit = unit or p.unit
        if unit != p.unit:
            if unit not in UNITS or p.unit not in UNITS or UNITS[unit][0] != UNITS[p.unit][0]:
                raise origin.error(f"{text!r}: unit {unit!r} of {key} is unknown or not a unit of {p.unit}")
            v = v * UNITS[unit][1] / UNITS[p.unit][1]
        params.append((key, float(v)))
    try:
        check_scenario({name: dict(params)}, engine)
    except ValueError as exc:
        raise origin.error(f"{text!r}: {exc}") from None
    return AddEffect(name, tuple(params), spec=text, origin=origin)


#: Operation keyword (CLI option without ``--``, variants-file key) -> parser.
PARSERS = {"scale": parse_scale, "set": parse_set, "swap": parse_swap, "move": parse_move,
           "rotate": parse_rotate, "target": parse_target, "effect": parse_effect}


def parse_operations(specs: dict, *, base: Path | None = None, engine=None) -> tuple:
    """Operations of ``{"scale": [...], "set": [...], ...}``, in :data:`PARSERS`' order."""
    return tuple(_parse(kind, text, Origin(f"--{kind}"), base, engine)
                 for kind in PARSERS for text in specs.get(kind, ()) or ())


def _parse(kind, text, origin, base=None, engine=None):
    """One spec of option ``kind`` (swap paths relative to ``base``)."""
    if kind == "swap":
        return parse_swap(text, origin, base=base)
    if kind == "effect":
        return parse_effect(text, origin, engine=engine)
    return PARSERS[kind](text, origin)


VARIANTS_FILE_KEYS = ("name",) + tuple(PARSERS)


def read_variants(path) -> list:
    """Read a variants file (TOML): a list of :class:`Variant`.

    Layout::

        [[variant]]
        name = "left z +20 % stiffness"
        scale = ["left.z.stiffness=1.2"]      # optional lists of specs, same syntax
        set = ["right.y.c2=150"]              # as the command-line options; applied in
        swap = ["left.z=my-mount.toml"]       # the order scale, set, swap, move,
        move = ["gearbox=0,0,10"]             # rotate, target; swap paths relative to
        rotate = ["left=0,0,5"]               # the variants file
        target = ["left.z:+20%:100-300Hz"]
        effect = ["mount_stiffness:k3=0.7"]   # unmodelled effects (powertrain.effects)

    Errors name the file, the line and the key (``variant[2].scale``).
    """
    path = str(path)
    tables = _variant_tables(read_toml(path), path)
    locate = _block_locator(path)
    variants, names = [], set()
    for k, t in enumerate(tables):
        variants.append(_read_variant(k, t, path, locate, names))
        names.add(variants[-1].name)
    return variants


def _variant_tables(doc: dict, path: str) -> list:
    """The ``[[variant]]`` tables of a variants file (nothing else at the top)."""
    unknown = sorted(set(doc) - {"variant"})
    if unknown:
        raise InputError("unknown key (expected [[variant]] tables)", file=path, key=unknown[0])
    tables = doc.get("variant")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict) for t in tables):
        raise InputError("expected one or more [[variant]] tables", file=path, key="variant")
    return tables


def _block_locator(path: str):
    """``locate(k, needle)``: 1-based line of ``needle`` in the k-th [[variant]] block."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    headers = [i for i, ln in enumerate(lines) if re.match(r"^\s*\[\[\s*variant\s*\]\]", ln)]

    def locate(k, needle):
        if k >= len(headers):
            return None
        end = headers[k + 1] if k + 1 < len(headers) else len(lines)
        for i in range(headers[k], end):
            if needle and needle in lines[i]:
                return i + 1
        return headers[k] + 1
    return locate


def _read_variant(k: int, t: dict, path: str, locate, names: set) -> Variant:
    """The k-th (0-based) ``[[variant]]`` table; ``names``: the names taken before it."""
    key0 = f"variant[{k + 1}]"
    bad = sorted(set(t) - set(VARIANTS_FILE_KEYS))
    if bad:
        raise InputError(f"unknown key (expected {', '.join(VARIANTS_FILE_KEYS)})",
                         file=path, line=locate(k, bad[0]), key=f"{key0}.{bad[0]}")
    name = t.get("name")
    if not isinstance(name, str) or not name.strip():
        raise InputError("missing or empty name", file=path, line=locate(k, "name"), key=f"{key0}.name")
    if name in names or name == "baseline":
        raise InputError(f"duplicate or reserved variant name {name!r}", file=path,
                         line=locate(k, "name"), key=f"{key0}.name")
    ops = []
    for kind in PARSERS:
        specs = t.get(kind, [])
        if isinstance(specs, str):
            specs = [specs]
        if not isinstance(specs, list) or not all(isinstance(s, str) for s in specs):
            raise InputError("expected a list of strings", file=path,
                             line=locate(k, kind), key=f"{key0}.{kind}")
        ops += [_parse(kind, text, Origin(f"{key0}.{kind}", file=path, line=locate(k, text)),
                       Path(path).parent) for text in specs]
    if not ops:
        raise InputError("variant has no operation", file=path, line=locate(k, ""), key=key0)
    return Variant(name, tuple(ops), Origin(key0, file=path, line=locate(k, "")))
