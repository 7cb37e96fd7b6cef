"""Operations on the mount system: what a variant spec becomes, and how it is applied.

Frozen, picklable dataclasses of SI values and their spec; each ``apply`` returns a new
:class:`~powertrain.models.engine.Engine`, unknown names raise
:class:`~powertrain.errors.InputError` naming the spec's origin. Parsers:
:mod:`powertrain.workflows.variants`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from powertrain.effects import EFFECTS, RESPONSE_EFFECTS
from powertrain.errors import InputError
from powertrain.iotools.mount_file import check_network, check_plausible
from powertrain.physics.mount_laws import BergFriction, PowerLaw, StaticCurve

#: Mount or direction name that matches every mount or direction.
WILDCARD = "*"

#: What-if keys of a mount direction's laws: ``"section.key"`` -> (dimension, unit family
#: ``x``/``F`` of :data:`powertrain.iotools.mount_file.SECTION_UNITS` or None, ``--scale``
#: allowed, ``--set`` allowed). ``amplitude.limits`` is set as ``LO,HI``.
LAW_KEYS = {
    "amplitude.reference": ("length", "x", True, True),
    "amplitude.exponent": (None, None, True, True),
    "amplitude.limits": (None, None, False, True),
    "amplitude.damping_exponent": (None, None, True, True),
    "friction.max_force": ("force", "F", True, True),
    "friction.half_displacement": ("length", "x", True, True),
    "static.force": ("force", "F", True, False),
    "static.reference_deflection": ("length", "x", False, True),
}
#: The law a ``--set`` creates in a direction without the section, linear until the set key
#: changes it (a static curve is never invented).
LAW_DEFAULTS = {"amplitude": PowerLaw(1e-4, 0.0, (0.2, 5.0)),
                "friction": BergFriction(0.0, 5e-5)}
_LAW_FIELDS = {"amplitude": ("amplitude_law", PowerLaw), "friction": ("port_law", BergFriction),
               "static": ("static_curve", StaticCurve)}


@dataclass(frozen=True)
class Origin:
    """Where a spec came from: option or variants-file ``key``, ``file``, 1-based ``line``."""

    key: str
    file: str | None = None
    line: int | None = None

    def error(self, message: str) -> InputError:
        """An :class:`InputError` located here."""
        return InputError(message, file=self.file, key=self.key, line=self.line)


@dataclass(frozen=True)
class Scale:
    """Scale springs, dampers or the whole network (``kind``; or a scalable key of
    :data:`LAW_KEYS`) of matching mount directions (names or ``*``) by ``factor`` > 0."""

    mount: str
    direction: str
    kind: str
    factor: float
    spec: str = ""
    origin: Origin = Origin("--scale")

    def apply(self, engine):
        f = self.factor
        if self.kind in LAW_KEYS:
            return _map_laws(engine, self, self.kind, lambda v: tuple(f * x for x in v)
                             if isinstance(v, tuple) else f * v)
        change = {"stiffness": lambda m: m.scaled(stiffness=f), "damping": lambda m: m.scaled(damping=f)}.get(
            self.kind, lambda m: m.scaled_dynamic_stiffness(f))
        return _map_directions(engine, self.mount, self.direction,
                               lambda m: _plausible(change(m), self), self.origin)


@dataclass(frozen=True)
class SetParameter:
    """Set ``parameter`` (``c2``, ``d4``, ``m1``... or a settable key of :data:`LAW_KEYS`) of
    matching mount directions to ``value`` (SI; ``(lo, hi)`` for ``amplitude.limits``)."""

    mount: str
    direction: str
    parameter: str
    value: float
    spec: str = ""
    origin: Origin = Origin("--set")

    def apply(self, engine):
        if self.parameter in LAW_KEYS:
            return _map_laws(engine, self, self.parameter, lambda v: self.value, create=True)

        def change(model):
            if self.parameter not in model.topology.parameters:
                raise self.origin.error(
                    f"{self.spec!r}: model {model.topology.name!r} has no parameter "
                    f"{self.parameter!r} (expected {', '.join(model.topology.parameters)})")
            return _plausible(model.with_params(**{self.parameter: self.value}), self)
        return _map_directions(engine, self.mount, self.direction, change, self.origin)


@dataclass(frozen=True)
class Swap:
    """Replace one mount direction's model by ``model``, read from ``path``."""

    mount: str
    direction: str
    model: object
    path: str = ""
    spec: str = ""
    origin: Origin = Origin("--swap")

    def apply(self, engine):
        new = _map_directions(engine, self.mount, self.direction, lambda m: self.model, self.origin)
        mounts = [dataclasses.replace(m, files={**m.files, self.direction: self.path})
                  if m.name == self.mount else m for m in new.mounts]
        return new.replace(mounts=mounts)


@dataclass(frozen=True)
class Move:
    """Shift matching mount points by ``offset`` (dx, dy, dz) in engine axes [m]."""

    mount: str
    offset: tuple
    spec: str = ""
    origin: Origin = Origin("--move")

    def apply(self, engine):
        d = np.asarray(self.offset, float)
        return _map_mounts(engine, self.mount, lambda m: dataclasses.replace(
            m, position=np.asarray(m.position, float) + d), self.origin)


@dataclass(frozen=True)
class Rotate:
    """Rotate matching mounts' local axes by ``angles`` (ax, ay, az) [rad] about engine X,
    then Y, then Z."""

    mount: str
    angles: tuple
    spec: str = ""
    origin: Origin = Origin("--rotate")

    def apply(self, engine):
        R = rotation_matrix(*self.angles)
        return _map_mounts(engine, self.mount, lambda m: dataclasses.replace(
            m, rotation=R @ np.asarray(m.rotation, float)), self.origin)


@dataclass(frozen=True)
class Target:
    """A desired K_CP ratio ``factor`` of a mount direction over the band ``f_lo..f_hi`` [Hz],
    blended over ``blend_octaves`` outside, at ``amplitude`` [m] (None: the network alone);
    resolved by :func:`powertrain.workflows.retune.retune`."""

    mount: str
    direction: str
    factor: float
    f_lo: float
    f_hi: float
    blend_octaves: float = 0.5
    spec: str = ""
    origin: Origin = Origin("--target")
    amplitude: float | None = None

    def apply(self, engine):
        raise TypeError("a Target must be resolved by powertrain.workflows.retune.resolve_targets first")

    def check(self, engine) -> None:
        """Raise :class:`InputError` if the mount or direction is unknown."""
        _map_directions(engine, self.mount, self.direction, lambda m: m, self.origin)


@dataclass(frozen=True)
class AddEffect:
    """An unmodelled effect of :data:`powertrain.effects.EFFECTS` with ``params`` ((name, SI
    value) pairs); response-level effects leave the engine as it is (they act on the run-up,
    :func:`powertrain.workflows.runup.runup_with_effects`)."""

    effect: str
    params: tuple = ()
    spec: str = ""
    origin: Origin = Origin("--effect")

    def apply(self, engine):
        if self.effect in RESPONSE_EFFECTS:
            return engine
        eff = EFFECTS[self.effect]
        return eff.apply(engine, **{**eff.defaults(engine), **dict(self.params)})


def effect_scenario(operations, names=None) -> dict:
    """``{effect: {parameter: value}}`` of the :class:`AddEffect` operations (in ``names``)."""
    sc: dict = {}
    for op in operations:
        if isinstance(op, AddEffect) and (names is None or op.effect in names):
            sc.setdefault(op.effect, {}).update(dict(op.params))
    return sc


@dataclass(frozen=True)
class Variant:
    """A named sequence of operations applied in order to the baseline engine."""

    name: str
    operations: tuple = ()
    origin: Origin | None = None

    @property
    def specs(self) -> list:
        return [op.spec for op in self.operations]


def rotation_matrix(ax: float, ay: float, az: float) -> np.ndarray:
    """:math:`R_z(a_z) R_y(a_y) R_x(a_x)`: rotations about the fixed X, Y, Z axes [rad]."""
    cx, sx, cy, sy, cz, sz = (math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay),
                              math.cos(az), math.sin(az))
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def _map_mounts(engine, mount, change, origin):
    names = engine.mount_names
    if mount != WILDCARD and mount not in names:
        raise origin.error(f"unknown mount {mount!r} (expected {', '.join(names)} or *)")
    mounts = [change(m) if mount in (WILDCARD, m.name) else m for m in engine.mounts]
    return engine.replace(mounts=mounts)


def _map_directions(engine, mount, direction, change, origin):
    def per_mount(m):
        dirs = list(m.directions)
        if direction != WILDCARD and direction not in dirs:
            raise origin.error(f"unknown direction {direction!r} of mount {m.name!r} "
                               f"(expected {', '.join(dirs)} or *)")
        new = {d: change(model) if direction in (WILDCARD, d) else model for d, model in m.directions.items()}
        return dataclasses.replace(m, directions=new)
    return _map_mounts(engine, mount, per_mount, origin)


def law_changed(model, key, change, create=False):
    """``model`` with the law value ``key`` replaced by ``change(old)`` (``create``: from
    :data:`LAW_DEFAULTS` if missing); LookupError when there is no such law."""
    section, name = key.split(".")
    field, kind = _LAW_FIELDS[section]
    law = getattr(model, field)
    if law is None and create:
        law = LAW_DEFAULTS.get(section)
    if law is None:
        raise LookupError(f"the mount direction has no [{section}] section"
                          + (" (--set creates [amplitude] and [friction] only)" if create
                             else " (--set creates one)" if section in LAW_DEFAULTS else ""))
    if not isinstance(law, kind):
        raise LookupError(f"its [{section}] law is a {type(law).__name__}, which has no {name}")
    new = dataclasses.replace(law, **{name: change(getattr(law, name))})
    return dataclasses.replace(model, **{field: new})


def _plausible(model, op):
    """``model`` if plausible as a mount file's must be, else an error at ``op``'s origin."""
    try:
        check_plausible(model, None)
        check_network(model, None)
    except InputError as exc:
        raise op.origin.error(f"{op.spec!r}: {exc.message}") from None
    return model


def _map_laws(engine, op, key, change, create=False):
    """``law_changed`` on ``op``'s directions; a wildcard skips those without the law."""
    done, missing = [], []

    def one(model):
        try:
            new = law_changed(model, key, change, create)
        except LookupError as exc:
            missing.append(str(exc))
            return model
        done.append(new)
        return new
    new = _map_directions(engine, op.mount, op.direction, one, op.origin)
    if missing and (not done or WILDCARD not in (op.mount, op.direction)):
        raise op.origin.error(f"{op.spec!r}: {missing[0]}")
    return new


def apply_operations(engine, operations):
    """Apply operations in order; returns a new Engine.

    Parameters
    ----------
    engine : Engine
        The engine (not changed).
    operations : sequence
        Operation objects, :class:`Target` resolved first.
    """
    for op in operations:
        engine = op.apply(engine)
    return engine

