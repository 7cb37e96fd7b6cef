"""Operations on the mount system: what a variant spec becomes, and how it is applied.

Frozen, picklable dataclasses holding SI values and the spec they came from
(:class:`Scale`, :class:`SetParameter`, :class:`Swap`, :class:`Move`, :class:`Rotate`,
:class:`Target`, :class:`AddEffect`); each ``apply`` returns a new
:class:`~powertrain.models.engine.Engine` (nothing is mutated). :func:`apply_operations`
applies a sequence in order; unknown mount, direction or parameter names raise
:class:`~powertrain.errors.InputError` naming where the spec came from. The spec syntax and
its parsers: :mod:`powertrain.workflows.variants`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from powertrain.errors import InputError

#: Mount or direction name that matches every mount or direction.
WILDCARD = "*"


@dataclass(frozen=True)
class Origin:
    """Where a spec came from, for error messages.

    Attributes
    ----------
    key : str
        Command-line option (``--scale``) or variants-file key (``variant[2].scale``).
    file : str or None
        Variants file.
    line : int or None
        1-based line in ``file``.
    """

    key: str
    file: str | None = None
    line: int | None = None

    def error(self, message: str) -> InputError:
        """An :class:`InputError` located here."""
        return InputError(message, file=self.file, key=self.key, line=self.line)


@dataclass(frozen=True)
class Scale:
    """Scale springs, dampers or the whole network of matching mount directions.

    Attributes
    ----------
    mount, direction : str
        Names or ``*``.
    kind : {"stiffness", "damping", "dynamic"}
    factor : float
        > 0 [1].
    """

    mount: str
    direction: str
    kind: str
    factor: float
    spec: str = ""
    origin: Origin = Origin("--scale")

    def apply(self, engine):
        def change(model):
            if self.kind == "stiffness":
                return model.scaled(stiffness=self.factor)
            if self.kind == "damping":
                return model.scaled(damping=self.factor)
            return model.scaled_dynamic_stiffness(self.factor)
        return _map_directions(engine, self.mount, self.direction, change, self.origin)


@dataclass(frozen=True)
class SetParameter:
    """Set one parameter of matching mount directions.

    Attributes
    ----------
    mount, direction : str
        Names or ``*``.
    parameter : str
        ``c2``, ``d4``, ``m1``...
    value : float
        SI value: [N/m], [N·s/m] or [kg].
    """

    mount: str
    direction: str
    parameter: str
    value: float
    spec: str = ""
    origin: Origin = Origin("--set")

    def apply(self, engine):
        def change(model):
            if self.parameter not in model.topology.parameters:
                raise self.origin.error(
                    f"{self.spec!r}: model {model.topology.name!r} has no parameter "
                    f"{self.parameter!r} (expected {', '.join(model.topology.parameters)})")
            return model.with_params(**{self.parameter: self.value})
        return _map_directions(engine, self.mount, self.direction, change, self.origin)


@dataclass(frozen=True)
class Swap:
    """Replace one mount direction's model.

    Attributes
    ----------
    mount, direction : str
    model : MountModel
        The new model (SI).
    path : str
        Mount file it was read from (or a description).
    """

    mount: str
    direction: str
    model: object
    path: str = ""
    spec: str = ""
    origin: Origin = Origin("--swap")

    def apply(self, engine):
        new = _map_directions(engine, self.mount, self.direction, lambda m: self.model,
                              self.origin)
        mounts = [dataclasses.replace(m, files={**m.files, self.direction: self.path})
                  if m.name == self.mount else m for m in new.mounts]
        return new.replace(mounts=mounts)


@dataclass(frozen=True)
class Move:
    """Shift matching mount points.

    Attributes
    ----------
    mount : str
        Name or ``*``.
    offset : tuple of float
        (dx, dy, dz) in engine axes [m].
    """

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
    """Rotate matching mounts' local axes about the engine axes through the mount point.

    Attributes
    ----------
    mount : str
        Name or ``*``.
    angles : tuple of float
        (ax, ay, az) [rad]: first ax about engine X, then ay about Y, then az about Z.
    """

    mount: str
    angles: tuple
    spec: str = ""
    origin: Origin = Origin("--rotate")

    def matrix(self) -> np.ndarray:
        """:math:`R_z(a_z) R_y(a_y) R_x(a_x)` (fixed engine axes)."""
        return rotation_matrix(*self.angles)

    def apply(self, engine):
        R = self.matrix()
        return _map_mounts(engine, self.mount, lambda m: dataclasses.replace(
            m, rotation=R @ np.asarray(m.rotation, float)), self.origin)


@dataclass(frozen=True)
class Target:
    """A desired change of a mount direction's K_CP over a band (resolved by fitting, see
    :func:`powertrain.workflows.retune.retune`; cannot be applied directly).

    Attributes
    ----------
    mount, direction : str
    factor : float
        Desired K_CP ratio inside the band (1.2 for ``+20%``) [1], > 0.
    f_lo, f_hi : float
        Band [Hz], 0 < f_lo < f_hi.
    blend_octaves : float
        Width of the smooth transition outside the band [octaves] (default 0.5).
    """

    mount: str
    direction: str
    factor: float
    f_lo: float
    f_hi: float
    blend_octaves: float = 0.5
    spec: str = ""
    origin: Origin = Origin("--target")

    def apply(self, engine):
        raise TypeError("a Target must be resolved by powertrain.workflows.retune.resolve_targets first")

    def check(self, engine) -> None:
        """Raise :class:`InputError` if the mount or direction is unknown."""
        _map_directions(engine, self.mount, self.direction, lambda m: m, self.origin)


@dataclass(frozen=True)
class AddEffect:
    """An unmodelled effect of :data:`powertrain.effects.EFFECTS` with its parameters.

    Engine-model effects are applied by :meth:`apply`; the response-level ones
    (``amplitude_stiffness``, ``sensor_error``) leave the engine unchanged here and are
    applied to the run-up by :func:`powertrain.workflows.sweeps.run_task` through
    :func:`powertrain.workflows.runup.runup_with_effects`.

    Attributes
    ----------
    effect : str
    params : tuple of (name, SI value)
    """

    effect: str
    params: tuple = ()
    spec: str = ""
    origin: Origin = Origin("--effect")

    @property
    def scenario(self) -> dict:
        return {self.effect: dict(self.params)}

    def apply(self, engine):
        from powertrain.effects import EFFECTS, RESPONSE_EFFECTS
        if self.effect in RESPONSE_EFFECTS:
            return engine
        eff = EFFECTS[self.effect]
        return eff.apply(engine, **{**eff.defaults(engine), **dict(self.params)})


def effect_scenario(operations, names=None) -> dict:
    """``{effect: {parameter: value}}`` of the :class:`AddEffect` operations, merged in order
    (only the effects in ``names``, if given)."""
    sc: dict = {}
    for op in operations:
        if isinstance(op, AddEffect) and (names is None or op.effect in names):
            sc.setdefault(op.effect, {}).update(dict(op.params))
    return sc


def response_scenario(operations) -> dict:
    """The response-level effects of a variant's operations, merged in order."""
    from powertrain.effects import RESPONSE_EFFECTS
    return effect_scenario(operations, RESPONSE_EFFECTS)


@dataclass(frozen=True)
class Variant:
    """A named sequence of operations applied in order to the baseline engine."""

    name: str
    operations: tuple = ()
    origin: Origin | None = None

    @property
    def specs(self) -> list:
        return [op.spec for op in self.operations]

    @property
    def targets(self) -> list:
        return [op for op in self.operations if isinstance(op, Target)]


# --------------------------------------------------------------------------- geometry
def rotation_matrix(ax: float, ay: float, az: float) -> np.ndarray:
    """:math:`R_z(a_z) R_y(a_y) R_x(a_x)`: rotations about the fixed X, Y, Z axes [rad]."""
    cx, sx, cy, sy, cz, sz = (math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay),
                              math.cos(az), math.sin(az))
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


# --------------------------------------------------------------------------- apply
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
        new = {d: change(model) if direction in (WILDCARD, d) else model
               for d, model in m.directions.items()}
        return dataclasses.replace(m, directions=new)
    return _map_mounts(engine, mount, per_mount, origin)


def apply_operations(engine, operations):
    """Apply operations in order; returns a new Engine (``engine`` is not changed).

    Parameters
    ----------
    engine : Engine
    operations : sequence of operation objects (not :class:`Target`; resolve those first)

    Raises
    ------
    InputError
        Unknown mount, direction or parameter, named with the spec's origin.
    """
    for op in operations:
        engine = op.apply(engine)
    return engine


def check_operations(engine, operations) -> None:
    """Validate names of every operation against ``engine`` (targets included)."""
    for op in operations:
        if isinstance(op, Target):
            op.check(engine)
        else:
            engine = op.apply(engine)
