r"""Variants of the mount system: parse spec strings into operations, apply them to an Engine.

Three layers, all pure (nothing is mutated; every ``apply`` returns a new
:class:`~powertrain.models.engine.Engine`):

1. **parse** -- :func:`parse_scale`, :func:`parse_set`, :func:`parse_swap`, :func:`parse_move`,
   :func:`parse_rotate`, :func:`parse_target` turn one spec string (command-line option or
   variants-file entry) into an operation object; syntax errors raise
   :class:`~powertrain.errors.InputError` naming the option (or file, line and key);
2. **operations** (:mod:`powertrain.workflows.operations`) -- frozen, picklable
   dataclasses (:class:`Scale`, :class:`SetParameter`, :class:`Swap`, :class:`Move`,
   :class:`Rotate`, :class:`Target`) holding SI values and the spec they came from;
3. **apply** -- :func:`apply_operations` applies a sequence in order; unknown mount,
   direction or parameter names raise :class:`InputError` naming where the spec came from.

Spec syntax (``MOUNT`` a mount name of the engine or ``*``; ``DIR`` a local direction of the
mount, ``x``, ``y``, ``z`` or ``*``; the default engine's mounts are ``left``, ``right``,
``gearbox`` with local axes parallel to the engine axes):

=========================================  ==================================================
``--scale MOUNT.DIR.KIND=FACTOR``          ``KIND``: ``stiffness`` (every spring c_i of the
                                           network times FACTOR), ``damping`` (every damper
                                           d_i), ``dynamic`` (every c_i, d_i and m_i: the
                                           whole K_CP(ω) times FACTOR, exactly), or a law
                                           key ``SECTION.KEY`` of :data:`LAW_KEYS`
                                           (``amplitude.exponent``; its section must
                                           exist); FACTOR > 0
``--set MOUNT.DIR.PARAM=VALUE[UNIT]``      one network parameter in its datasheet unit
                                           (c in N/mm, d in N·s/mm, m in kg, the table
                                           :data:`powertrain.iotools.mount_file.DATASHEET_UNITS`)
                                           or in an explicit unit of :mod:`powertrain.units`
                                           (``150N/mm``, ``1.5e5 N/m``); VALUE >= 0; or a
                                           law key (x in mm, F in N, ``LAW_KEYS``; a
                                           missing section: ``LAW_DEFAULTS``)
``--swap MOUNT.DIR=FILE.toml``             replace one direction's model by a mount file
``--move MOUNT=DX,DY,DZ``                  shift the mount point [mm], engine axes
``--rotate MOUNT=AX,AY,AZ``                rotate the mount's local axes about the engine
                                           axes through the mount point [deg]: first AX
                                           about X, then AY about Y, then AZ about Z (fixed
                                           axes), :math:`R' = R_z R_y R_x R`
``--target MOUNT.DIR:CHANGE:BAND[:WIDTH]`` retune to a desired K_CP change, see
``[:AMPLITUDE]``                           :mod:`powertrain.workflows.retune` (at an
                                           amplitude ``0.3mm``: the laws' K_CP there)
``--effect NAME[:PARAM=VALUE[UNIT],...]``  add an unmodelled effect of
                                           :data:`powertrain.effects.EFFECTS` (e.g.
                                           ``mount_stiffness:k1=1.5``,
                                           ``base_compliance:c_base=400N/mm,m_base=8kg``);
                                           VALUE in the parameter's unit (N/m, kg, rad,
                                           dB, 1) or an explicit one of the same
                                           dimension; inside the effect's bounds; run by
                                           :func:`powertrain.workflows.runup.runup_with_effects`
=========================================  ==================================================

What "scale stiffness" means for a lumped network
-------------------------------------------------
A mount direction is a network of springs :math:`c_i`, dampers :math:`d_i` and internal
masses :math:`m_i`. ``stiffness`` scales every :math:`c_i` by :math:`s`: the static
stiffness :math:`K_{CP}(0)` (a function of the springs only, homogeneous of degree one in
them) is scaled by exactly :math:`s`, and so is every rigid-body mode frequency's square
when all mounts are scaled; at higher frequency :math:`K_{CP}(\omega)` is *not* simply
scaled: the internal resonances move by :math:`\sqrt s` (masses unchanged) and the dampers
weigh less (:math:`s>1`) or more. ``dynamic`` scales :math:`c_i, d_i, m_i` together:
the dynamic stiffness matrix :math:`-\omega^2 M + i\omega C + K` of the network is scaled
by :math:`s`, the internal motion per unit engine-side motion is unchanged, so
:math:`K_{CP}(\omega)` is :math:`s` times the baseline at every frequency
(:meth:`~powertrain.models.mount.MountModel.scaled_dynamic_stiffness`) -- the variant a
supplier delivers with "20 % stiffer, same characteristic".
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


# --------------------------------------------------------------------------- parse
def _split(text: str, origin: Origin, form: str):
    if not isinstance(text, str) or text.count("=") != 1:
        raise origin.error(f"cannot read {text!r} (expected {form})")
    left, right = (s.strip() for s in text.split("="))
    if not left or not right:
        raise origin.error(f"cannot read {text!r} (expected {form})")
    return left, right


def _path_parts(left, n, text, origin, form, wildcard=True):
    parts = left.split(".")
    pattern = re.compile(rf"^(\*|{_NAME})$" if wildcard else rf"^{_NAME}$")
    if len(parts) != n or not all(pattern.match(p) for p in parts):
        raise origin.error(f"cannot read {text!r} (expected {form})")
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


def _vector3(s, text, origin):
    parts = s.split(",")
    if len(parts) != 3:
        raise origin.error(f"{text!r}: expected three comma-separated numbers")
    return tuple(_float(p.strip(), text, origin) for p in parts)


def _law_key(left, text, origin, form, column):
    """``(mount, direction, key)`` of ``MOUNT.DIR.SECTION.KEY``, the key one that
    :data:`LAW_KEYS` allows in ``column`` (2: --scale, 3: --set)."""
    mount, direction, section, name = _path_parts(left, 4, text, origin, form)
    _direction(direction, text, origin)
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
        _direction(direction, text, origin)
        if kind not in SCALE_KINDS:
            raise origin.error(f"{text!r}: unknown kind {kind!r} (expected "
                               f"{', '.join(SCALE_KINDS)}, or a law key such as "
                               "amplitude.exponent)")
    factor = _float(right, text, origin, "a factor")
    if factor <= 0:
        raise origin.error(f"{text!r}: factor must be positive, got {factor:g}")
    return Scale(mount, direction, kind, factor, spec=text, origin=origin)


def parse_set(text: str, origin: Origin = Origin("--set")) -> SetParameter:
    """``MOUNT.DIR.PARAM=VALUE[UNIT]`` -> :class:`SetParameter` (SI value).

    Without a unit the parameter family's datasheet unit applies (c: N/mm, d: N·s/mm, m: kg).
    """
    form = "MOUNT.DIR.PARAM=VALUE, e.g. right.y.c2=150 (N/mm) or left.z.friction.max_force=20"
    left, right = _split(text, origin, form)
    if left.count(".") == 3:
        mount, direction, key = _law_key(left, text, origin, form, 3)
        return SetParameter(mount, direction, key, _law_value(key, right, text, origin),
                            spec=text, origin=origin)
    mount, direction, param = _path_parts(left, 3, text, origin, form)
    _direction(direction, text, origin)
    if not re.match(r"^[cdm][0-9]+$", param):
        raise origin.error(f"{text!r}: unknown parameter {param!r} (expected c<n>, d<n> "
                           "or m<n>)")
    m = re.match(r"^([-+0-9.eE]+)\s*(.*)$", right)
    if not m:
        raise origin.error(f"{text!r}: {right!r} is not a number")
    value = _float(m.group(1), text, origin)
    unit = m.group(2).strip() or DATASHEET_UNITS[param[0]]
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
    """SI value of a law key's ``--set`` (:data:`LAW_KEYS`: its datasheet unit, or an
    explicit one of the same dimension; ``LO,HI`` for ``amplitude.limits``), checked as the
    mount file checks it."""
    dimension, family = LAW_KEYS[key][:2]
    if key == "amplitude.limits":
        parts = right.split(",")
        lo, hi = (_float(p.strip(), text, origin) for p in parts) if len(parts) == 2 else \
            (math.nan, math.nan)
        if not 0 < lo <= 1 <= hi:
            raise origin.error(f"{text!r}: expected LO,HI with 0 < LO <= 1 <= HI")
        return (lo, hi)
    m = re.match(r"^([-+0-9.eE]+)\s*(.*)$", right)
    if not m:
        raise origin.error(f"{text!r}: {right!r} is not a number")
    value, unit = _float(m.group(1), text, origin), m.group(2).strip()
    unit = unit or (SECTION_UNITS[family] if family else "1")
    if dimension is None:
        if unit != "1":
            raise origin.error(f"{text!r}: {key} has no unit, got {unit!r}")
        return value
    if unit not in UNITS or UNITS[unit][0] != dimension:
        raise origin.error(f"{text!r}: unit {unit!r} is unknown or not a unit of {dimension}")
    si = float(to_si(value, unit, dimension))
    if key != "static.reference_deflection" and (si < 0 or si == 0 and "max" not in key):
        raise origin.error(f"{text!r}: the value must be {'>= 0' if 'max' in key else '> 0'}"
                           f", got {value:g}")
    return si


def parse_swap(text: str, origin: Origin = Origin("--swap"), base: Path | None = None) -> Swap:
    """``MOUNT.DIR=FILE.toml`` -> :class:`Swap` (the mount file is read now).

    ``base``: folder relative paths are taken from (variants file folder; default cwd).
    """
    form = "MOUNT.DIR=FILE.toml, e.g. left.z=mounts/hydraulic-engine-mount-z.toml"
    left, right = _split(text, origin, form)
    mount, direction = _path_parts(left, 2, text, origin, form, wildcard=False)
    _direction(direction, text, origin)
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
    """``MOUNT.DIR:CHANGE:BAND[:WIDTH][:AMPLITUDE]`` -> :class:`Target`.

    CHANGE: ``+20%``, ``-15%`` or a factor ``*1.2``; BAND: ``100-300Hz`` (``Hz`` optional);
    WIDTH: transition outside the band, ``0.5oct`` (default half an octave); AMPLITUDE:
    the relative-displacement amplitude the change is asked at, with a length unit
    (``0.3mm``, ``50um``), for a direction with an amplitude law or friction.
    """
    form = "MOUNT.DIR:CHANGE:BAND[:WIDTH][:AMPLITUDE], e.g. left.z:+20%:100-300Hz:0.3mm"
    parts = [p.strip() for p in text.split(":")] if isinstance(text, str) else []
    if len(parts) not in (3, 4, 5):
        raise origin.error(f"cannot read {text!r} (expected {form})")
    mount, direction = _path_parts(parts[0], 2, text, origin, form, wildcard=False)
    _direction(direction, text, origin)
    change = parts[1].replace(" ", "")
    m_pct = re.match(r"^([+-][0-9.eE+-]+)%$", change)
    m_fac = re.match(r"^[*x]([0-9.eE+-]+)$", change)
    if m_pct:
        factor = 1.0 + _float(m_pct.group(1), text, origin) / 100.0
    elif m_fac:
        factor = _float(m_fac.group(1), text, origin)
    else:
        raise origin.error(f"{text!r}: cannot read change {parts[1]!r} (expected +20%, -15% "
                           "or *1.2)")
    if factor <= 0:
        raise origin.error(f"{text!r}: the change must leave a positive stiffness "
                           f"(factor {factor:g})")
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
        elif k == len(parts) - 4:        # the last part: an amplitude, x units (mm)
            amplitude = _law_value("amplitude.reference", extra, text, origin)
        else:
            raise origin.error(f"{text!r}: cannot read width {extra!r} (expected e.g. "
                               "0.5oct)")
    return Target(mount, direction, factor, f_lo, f_hi, width, spec=text, origin=origin,
                  amplitude=amplitude)


def parse_effect(text: str, origin: Origin = Origin("--effect"), engine=None) -> AddEffect:
    """``NAME[:PARAM=VALUE[UNIT][,PARAM=VALUE...]]`` -> :class:`AddEffect` (SI values).

    Parameters are those the effect generates for ``engine`` (default: the default layout,
    three mounts, four cylinders).

    Without a unit a value is in the parameter's own unit (:data:`powertrain.effects.
    EFFECTS`: N/m, kg, m, rad, dB or 1); an explicit unit must have the same dimension
    (``c_base=400N/mm``, ``lag=5deg``). Unknown effect or parameter, a value outside the
    effect's bounds: an error naming the option.
    """
    form = "NAME[:PARAM=VALUE,...], e.g. mount_stiffness:k1=1.5"
    name, _, rest = text.partition(":")
    name = name.strip()
    if name not in EFFECTS:
        raise origin.error(f"{text!r}: unknown effect {name!r} (expected "
                           f"{', '.join(EFFECTS)})")
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
        m = re.match(r"^([-+0-9.eE]+)\s*(.*)$", value.strip())
        if not m:
            raise origin.error(f"{text!r}: {value.strip()!r} is not a number")
        v = _float(m.group(1), text, origin)
        unit = m.group(2).strip() or p.unit
        if unit != p.unit:
            if unit not in UNITS or p.unit not in UNITS or UNITS[unit][0] != UNITS[p.unit][0]:
                raise origin.error(f"{text!r}: unit {unit!r} of {key} is unknown or not a "
                                   f"unit of {p.unit}")
            v = v * UNITS[unit][1] / UNITS[p.unit][1]
        params.append((key, float(v)))
    try:
        check_scenario({name: dict(params)}, engine)  # bounds, finiteness: one rule
    except ValueError as exc:
        raise origin.error(f"{text!r}: {exc}") from None
    return AddEffect(name, tuple(params), spec=text, origin=origin)


#: Operation keyword (CLI option without ``--``, variants-file key) -> parser.
PARSERS = {"scale": parse_scale, "set": parse_set, "swap": parse_swap, "move": parse_move,
           "rotate": parse_rotate, "target": parse_target, "effect": parse_effect}


def parse_operations(specs: dict, *, base: Path | None = None, engine=None) -> tuple:
    """Operations from ``{"scale": [...], "set": [...], ...}`` of command-line strings, in
    the order scale, set, swap, move, rotate, target (each list in its given order);
    effects' parameters are those generated for ``engine`` (default layout without one)."""
    ops = []
    for kind, parser in PARSERS.items():
        for text in specs.get(kind, ()) or ():
            origin = Origin(f"--{kind}")
            if kind == "swap":
                ops.append(parser(text, origin, base=base))
            elif kind == "effect" and engine is not None:
                ops.append(parser(text, origin, engine=engine))
            else:
                ops.append(parser(text, origin))
    return tuple(ops)


# --------------------------------------------------------------------------- variants file
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
    """The ``[[variant]]`` tables of a variants file (nothing else allowed at the top)."""
    unknown = sorted(set(doc) - {"variant"})
    if unknown:
        raise InputError("unknown key (expected [[variant]] tables)", file=path, key=unknown[0])
    tables = doc.get("variant")
    if not isinstance(tables, list) or not tables or not all(isinstance(t, dict)
                                                             for t in tables):
        raise InputError("expected one or more [[variant]] tables", file=path, key="variant")
    return tables


def _block_locator(path: str):
    """``locate(k, needle)``: 1-based line of ``needle`` within the k-th [[variant]] block
    (or of its header; None past the last block)."""
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
        raise InputError("missing or empty name", file=path, line=locate(k, "name"),
                         key=f"{key0}.name")
    if name in names or name == "baseline":
        raise InputError(f"duplicate or reserved variant name {name!r}", file=path,
                         line=locate(k, "name"), key=f"{key0}.name")
    ops = []
    for kind, parser in PARSERS.items():
        specs = t.get(kind, [])
        if isinstance(specs, str):
            specs = [specs]
        if not isinstance(specs, list) or not all(isinstance(s, str) for s in specs):
            raise InputError("expected a list of strings", file=path,
                             line=locate(k, kind), key=f"{key0}.{kind}")
        for text in specs:
            origin = Origin(f"{key0}.{kind}", file=path, line=locate(k, text))
            if kind == "swap":
                ops.append(parser(text, origin, base=Path(path).parent))
            else:
                ops.append(parser(text, origin))
    if not ops:
        raise InputError("variant has no operation", file=path, line=locate(k, ""), key=key0)
    return Variant(name, tuple(ops), Origin(key0, file=path, line=locate(k, "")))
