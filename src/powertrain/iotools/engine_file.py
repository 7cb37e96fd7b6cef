"""Engine files (``engines/*.toml``) into an :class:`~powertrain.models.engine.Engine` in SI.

Layout: docs/reference/engine-file.md. Every quantity is ``key = {value = ..., unit = "..."}``;
every problem is an :class:`~powertrain.errors.InputError` naming the file and the key.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from powertrain.analysis.channel import is_mount_name
from powertrain.data import default_engine_path
from powertrain.errors import InputError
from powertrain.iotools.combustion_section import read_combustion
from powertrain.iotools.engine_checks import check_engine
from powertrain.iotools.mount_file import read_mount
from powertrain.iotools.receptance import read_receptance
from powertrain.iotools.tomlfile import (
    array_quantity,
    check_keys,
    get,
    number,
    read_toml,
    scalar_quantity,
    subtable,
    unit_vector,
    vector3,
)
from powertrain.models import engine as em
from powertrain.models.chassis import MODELS, BodyMode, Chassis
from powertrain.models.crank_train import Balancer, BalancerShaft, CrankTrain
from powertrain.models.mount import MountModel

#: The shipped default engine (package data, see :mod:`powertrain.data`).
DEFAULT_ENGINE_PATH: Path = default_engine_path()

#: Fewest mounts an engine may have (any names are accepted).
MIN_MOUNTS = 3
DIRECTIONS = ("x", "y", "z")

_ALLOWED = {
    "": {"engine", "crank_train", "body", "mounts", "balancer", "combustion", "chassis", "drive"},
    "drive": {"gear_ratio"},
    "chassis": {"model", "modes", "points", "frf"},
    "chassis_mode": {"frequency", "damping_ratio", "modal_mass", "shape"},
    "chassis_point": {"description"},
    "engine": {"name", "source", "notes"},
    "crank_train": {"cylinders", "bore", "stroke", "rod_length", "pin_offset",
                    "compression_ratio", "cylinder_positions", "cylinder_axis", "rotation",
                    "crank_pin_angles", "firing_order", "reciprocating_mass", "rotating_mass",
                    "counterweight_fraction", "crankcase_pressure"},
    "body": {"mass", "cg", "inertia"},
    "mount": {"position", "local_x", "local_z", "orientation", "files", "stiffness", "damping"},
    "balancer": {"enabled", "speed_ratio", "shafts"},
    "shaft": {"name", "mass_radius", "position", "phase", "sense"},
}


def engine_or_default(engine=None) -> em.Engine:
    """``engine`` as an :class:`~powertrain.models.engine.Engine`: an Engine as it is, a path
    read (:func:`read_engine`), None the shipped default engine."""
    if engine is None or isinstance(engine, (str, os.PathLike)):
        return read_engine(DEFAULT_ENGINE_PATH if engine is None else engine)
    if not isinstance(engine, em.Engine):
        raise InputError(f"expected an Engine or an engine file, got {type(engine).__name__}", key="--engine")
    return engine


def read_engine(path=DEFAULT_ENGINE_PATH) -> em.Engine:
    """Load an engine file into an :class:`~powertrain.models.engine.Engine` (SI).

    Parameters
    ----------
    path : str or Path
        Engine TOML file; mount files and pressure traces are resolved relative to it.

    Raises
    ------
    InputError
        Naming the file and key of the first problem found.
    """
    path = str(path)
    doc = read_toml(path)
    check_keys(doc, _ALLOWED[""], path, "")
    meta = subtable(doc, "engine", path)
    check_keys(meta, _ALLOWED["engine"], path, "engine")
    name = get(meta, "name", path, "engine", types=str)
    body = _read_body(subtable(doc, "body", path), path)
    mounts = _read_mounts(subtable(doc, "mounts", path), path)
    crank = combustion = None
    if "crank_train" in doc:
        crank = _read_crank(subtable(doc, "crank_train", path), path)
    if "combustion" in doc:
        if crank is None:
            raise InputError("[combustion] needs a [crank_train] section", file=path, key="crank_train")
        combustion = read_combustion(subtable(doc, "combustion", path), path, crank)
    balancer = (_read_balancer(subtable(doc, "balancer", path), path) if "balancer" in doc
                else Balancer(enabled=False, ratio=2.0, shafts=()))
    chassis = (_read_chassis(subtable(doc, "chassis", path), path, [m.name for m in mounts])
               if "chassis" in doc else None)
    engine = em.Engine(name=name, crank=crank, body=body, mounts=mounts, balancer=balancer,
                       combustion=combustion, file=path, chassis=chassis, gear_ratio=_read_drive(doc, path))
    check_engine(engine, path)
    return engine


def _read_drive(doc, path) -> float:
    """``[drive] gear_ratio`` (dimensionless, > 0; 1 without the section or the key)."""
    if "drive" not in doc:
        return 1.0
    t = subtable(doc, "drive", path)
    check_keys(t, _ALLOWED["drive"], path, "drive")
    if "gear_ratio" not in t:
        return 1.0
    return scalar_quantity(t, "gear_ratio", "dimensionless", path, "drive", positive=True)


def _read_chassis(t, path, mount_names):
    """``[chassis]``: model rigid | modal | frf, body modes, body points of interest."""
    p = "chassis"
    check_keys(t, _ALLOWED[p], path, p)
    model = get(t, "model", path, p, types=str)
    if model not in MODELS:
        raise InputError(f"unknown model {model!r} (known: {', '.join(MODELS)})", file=path, key=f"{p}.model")
    points_raw = get(t, "points", path, p, default={}, types=dict)
    for name, pt in points_raw.items():
        key = f"{p}.points.{name}"
        if not _NAME_RE.match(name) or name in mount_names:
            raise InputError("body point names are letters, digits, '_' or '-' and differ "
                             "from the mount names", file=path, key=key)
        if not isinstance(pt, dict):
            raise InputError("expected a table", file=path, key=key)
        check_keys(pt, _ALLOWED["chassis_point"], path, key)
    points = tuple(points_raw)
    for k, other in (("modes", "modal"), ("frf", "frf")):
        if k in t and model != other:
            raise InputError(f"only with model = \"{other}\"", file=path, key=f"{p}.{k}")
    modes, receptance = (), None
    if model == "modal":
        raw = get(t, "modes", path, p, types=list)
        if not raw:
            raise InputError("need at least one body mode", file=path, key=f"{p}.modes")
        modes = tuple(_read_body_mode(m, path, f"{p}.modes[{k}]", mount_names, points)
                      for k, m in enumerate(raw))
    elif model == "frf":
        rel = get(t, "frf", path, p, types=str)
        full = Path(path).parent / rel
        if not full.is_file():
            raise InputError(f"receptance file not found: {full}", file=path, key=f"{p}.frf")
        receptance = read_receptance(full, mount_names, points, defined_in=path)
    return Chassis(model=model, modes=modes, points=points, receptance=receptance, file=path)


def _read_body_mode(m, path, p, mount_names, points):
    if not isinstance(m, dict):
        raise InputError("expected a table", file=path, key=p)
    check_keys(m, _ALLOWED["chassis_mode"], path, p)
    f = scalar_quantity(m, "frequency", "frequency", path, p, positive=True)
    zeta = scalar_quantity(m, "damping_ratio", "dimensionless", path, p, nonneg=True)
    mass = scalar_quantity(m, "modal_mass", "mass", path, p, positive=True)
    shape_raw = get(m, "shape", path, p, types=dict)
    sp = f"{p}.shape"
    check_keys(shape_raw, list(mount_names) + list(points), path, sp)
    shapes = {}
    for name in list(mount_names) + list(points):
        v = get(shape_raw, name, path, sp, types=list)
        if len(v) != 3:
            raise InputError(f"expected [sx, sy, sz], got {v!r}"[:200], file=path, key=f"{sp}.{name}")
        shapes[name] = np.array([number(x, path, f"{sp}.{name}") for x in v])
    return BodyMode(frequency=f, damping_ratio=zeta, modal_mass=mass, shapes=shapes)


def _read_crank(t, path) -> CrankTrain:
    p = "crank_train"
    check_keys(t, _ALLOWED[p], path, p)
    n = get(t, "cylinders", path, p, types=int)
    if isinstance(n, bool) or n < 1:
        raise InputError(f"must be a positive integer, got {n!r}", file=path, key=f"{p}.cylinders")
    bore = scalar_quantity(t, "bore", "length", path, p, positive=True)
    stroke = scalar_quantity(t, "stroke", "length", path, p, positive=True)
    rod = scalar_quantity(t, "rod_length", "length", path, p, positive=True)
    offset = scalar_quantity(t, "pin_offset", "length", path, p)
    if rod <= 0.5 * stroke + abs(offset):
        raise InputError("connecting rod must be longer than the crank radius plus the pin "
                         "offset", file=path, key=f"{p}.rod_length")
    eps = scalar_quantity(t, "compression_ratio", "dimensionless", path, p, positive=True)
    if eps <= 1.0:
        raise InputError(f"must exceed 1, got {eps}", file=path, key=f"{p}.compression_ratio")
    xs = array_quantity(t, "cylinder_positions", "length", path, p, (n,))
    axis = unit_vector(t, "cylinder_axis", path, p)
    if abs(axis[0]) > 1e-9:
        raise InputError("cylinder axis must be perpendicular to the crank axis (engine X)",
                         file=path, key=f"{p}.cylinder_axis")
    rot = get(t, "rotation", path, p, types=str)
    if rot not in ("+X", "-X"):
        raise InputError(f"expected \"+X\" or \"-X\", got {rot!r}", file=path, key=f"{p}.rotation")
    pins = array_quantity(t, "crank_pin_angles", "angle", path, p, (n,))
    pins = pins - pins[0]      # re cylinder 1: θ = 0 is its firing TDC, for forces and gas
    order_raw = get(t, "firing_order", path, p, types=list)
    key_fo = f"{p}.firing_order"
    if (any(isinstance(c, bool) or not isinstance(c, int) for c in order_raw)
            or sorted(order_raw) != list(range(1, n + 1))):
        raise InputError(f"must list the cylinders 1..{n} once each, got {order_raw!r}",
                         file=path, key=key_fo)
    k1 = order_raw.index(1)
    order = tuple(order_raw[k1:] + order_raw[:k1])
    firing = _firing_angles(pins, order, path, key_fo)
    m_rec = scalar_quantity(t, "reciprocating_mass", "mass", path, p, nonneg=True)
    m_rot = scalar_quantity(t, "rotating_mass", "mass", path, p, nonneg=True)
    cw = scalar_quantity(t, "counterweight_fraction", "dimensionless", path, p, nonneg=True)
    pcc = scalar_quantity(t, "crankcase_pressure", "pressure", path, p, nonneg=True)
    return CrankTrain(bore=bore, stroke=stroke, rod_length=rod, pin_offset=offset, compression_ratio=eps,
                      cylinder_x=xs, cylinder_axis=axis, rotation_sign=1 if rot == "+X" else -1,
                      crank_pin_angles=pins, firing_order=order, firing_angles=firing,
                      reciprocating_mass=m_rec, rotating_mass=m_rot, counterweight_fraction=cw,
                      crankcase_pressure=pcc)


def _firing_angles(pins, order, path, key):
    """Cylinder-1 crank angle of each cylinder's firing TDC on [0, 4π): along the firing order
    from cylinder 1 (at 0), each fires at its first TDC (``pin + 2πk``) after the previous."""
    two_pi = 2.0 * np.pi
    pins = np.mod(pins, two_pi)
    firing = np.zeros(len(pins))
    last = 0.0
    for cyl in order[1:]:
        a = pins[cyl - 1]
        while a <= last + 1e-9:
            a += two_pi
        firing[cyl - 1] = a
        last = a
    if last >= 2 * two_pi - 1e-9:
        raise InputError("firing order and crank-pin angles do not fit into one 720° cycle",
                         file=path, key=key)
    return firing + 0.0


def _read_body(t, path) -> em.RigidBody:
    p = "body"
    check_keys(t, _ALLOWED[p], path, p)
    mass = scalar_quantity(t, "mass", "mass", path, p, positive=True)
    cg = vector3(t, "cg", "length", path, p)
    inertia = array_quantity(t, "inertia", "inertia", path, p, (3, 3))
    key = f"{p}.inertia"
    if not np.allclose(inertia, inertia.T, rtol=1e-9, atol=1e-12 * np.abs(inertia).max()):
        raise InputError("inertia tensor must be symmetric", file=path, key=key)
    eig = np.linalg.eigvalsh(inertia)
    if eig.min() <= 0:
        raise InputError(f"inertia tensor must be positive definite (eigenvalues "
                         f"{', '.join(f'{v:.4g}' for v in eig)} kg*m^2)", file=path, key=key)
    if eig[0] + eig[1] < eig[2] * (1 - 1e-9):
        raise InputError("principal moments violate the triangle inequality "
                         "(not a physical body)", file=path, key=key)
    return em.RigidBody(mass=mass, cg=cg, inertia=inertia)


_NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_-]*$")


def _read_mounts(t, path) -> list:
    """Every ``[mounts.NAME]`` table, in file order (at least :data:`MIN_MOUNTS`)."""
    if len(t) < MIN_MOUNTS:
        raise InputError(f"need at least {MIN_MOUNTS} mounts, got {len(t)}", file=path, key="mounts")
    mounts = []
    for name in t:
        if not is_mount_name(name):
            raise InputError("mount names are letters, digits, '_' or '-' and start with a "
                             "letter; not nan or inf", file=path, key=f"mounts.{name}")
        p = f"mounts.{name}"
        m = get(t, name, path, "mounts", types=dict)
        check_keys(m, _ALLOWED["mount"], path, p)
        pos = vector3(m, "position", "length", path, p)
        rotation = _read_orientation(m, path, p)
        directions, paths = _read_mount_directions(m, path, p)
        mounts.append(em.MountSpec(name=name, position=pos, rotation=rotation,
                                   directions=directions, files=paths))
    return mounts


def euler_rotation(a, b, c) -> np.ndarray:
    """Local→engine rotation R = Rz(c)·Ry(b)·Rx(a) [angles in rad]: rotations about engine X
    by ``a``, then engine Y by ``b``, then engine Z by ``c`` (columns = local axes)."""
    ca, sa, cb, sb, cc, sc = (math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c))
    rx = np.array([[1.0, 0.0, 0.0], [0.0, ca, -sa], [0.0, sa, ca]])
    ry = np.array([[cb, 0.0, sb], [0.0, 1.0, 0.0], [-sb, 0.0, cb]])
    rz = np.array([[cc, -sc, 0.0], [sc, cc, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


def _read_orientation(m, path, p) -> np.ndarray:
    has_vectors = "local_x" in m or "local_z" in m
    if "orientation" in m:
        if has_vectors:
            raise InputError("give either orientation or local_x/local_z, not both",
                             file=path, key=f"{p}.orientation")
        angles = vector3(m, "orientation", "angle", path, p)
        return euler_rotation(*angles)
    if not has_vectors:
        raise InputError("missing key (give orientation or local_x and local_z)", file=path,
                         key=f"{p}.orientation")
    lx = unit_vector(m, "local_x", path, p)
    lz = unit_vector(m, "local_z", path, p)
    if abs(float(lx @ lz)) > 1e-6:
        raise InputError("local_x and local_z must be perpendicular", file=path, key=f"{p}.local_z")
    return np.column_stack([lx, np.cross(lz, lx), lz])


def _read_mount_directions(m, path, p):
    """Mount model per local direction: network files, or an inline spring-damper."""
    if "files" in m:
        for key in ("stiffness", "damping"):
            if key in m:
                raise InputError("give either files or an inline stiffness/damping, not both",
                                 file=path, key=f"{p}.{key}")
        base = Path(path).parent
        files = get(m, "files", path, p, types=dict)
        check_keys(files, DIRECTIONS, path, f"{p}.files")
        directions, paths = {}, {}
        for d in DIRECTIONS:
            rel = get(files, d, path, f"{p}.files", types=str)
            full = base / rel
            if not full.is_file():
                raise InputError(f"mount file not found: {full}", file=path, key=f"{p}.files.{d}")
            directions[d] = read_mount(full)
            paths[d] = str(full)
        return directions, paths
    if "stiffness" not in m:
        raise InputError("missing key (give files or an inline stiffness)", file=path, key=f"{p}.stiffness")
    k = array_quantity(m, "stiffness", "stiffness", path, p, (3,), nonneg=True)
    c = (array_quantity(m, "damping", "damping", path, p, (3,), nonneg=True) if "damping" in m
         else np.zeros(3))
    directions = {d: MountModel.from_values("kelvin-voigt", [k[i], c[i]], name=f"inline spring-damper {d}",
                                            source=f"{path}: {p}") for i, d in enumerate(DIRECTIONS)}
    return directions, {}


def _read_balancer(t, path) -> Balancer:
    p = "balancer"
    check_keys(t, _ALLOWED[p], path, p)
    enabled = get(t, "enabled", path, p, types=bool)
    ratio = scalar_quantity(t, "speed_ratio", "dimensionless", path, p, positive=True)
    shafts_raw = get(t, "shafts", path, p, types=list)
    shafts = []
    for k, s in enumerate(shafts_raw):
        sp = f"{p}.shafts[{k}]"
        if not isinstance(s, dict):
            raise InputError("expected a table", file=path, key=sp)
        check_keys(s, _ALLOWED["shaft"], path, sp)
        sense = get(s, "sense", path, sp, types=int)
        if sense not in (1, -1) or isinstance(sense, bool):
            raise InputError(f"expected +1 or -1, got {sense!r}", file=path, key=f"{sp}.sense")
        shafts.append(BalancerShaft(
            name=str(get(s, "name", path, sp, types=str)),
            mass_radius=scalar_quantity(s, "mass_radius", "unbalance", path, sp, nonneg=True),
            position=vector3(s, "position", "length", path, sp),
            phase=scalar_quantity(s, "phase", "angle", path, sp), sense=sense))
    return Balancer(enabled=enabled, ratio=ratio, shafts=tuple(shafts))
