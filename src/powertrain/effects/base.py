"""The effect interface: one class per unmodelled effect, parameters generated from the engine.

An effect has a ``name``, a ``kind`` (structure, excitation, sensor), a ``description``,
bounded ``parameters(engine)``, ``applicable(engine)`` and ``apply(engine, params)``; on the
fast cached path (:func:`powertrain.effects.predict`) it contributes through hooks, each a
no-op by default. Adding one: a subclass module and a line in
:mod:`powertrain.effects.registry` (docs/extending.md).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from powertrain.analysis.channel import DIRECTIONS
from powertrain.models.extensions import with_base_compliance


@dataclass(frozen=True)
class Parameter:
    """One bounded parameter of an effect.

    Attributes
    ----------
    name, unit, description : str
    lower, upper, default : float
        Bounds and the value that reduces the effect to the baseline (SI).
    log : bool
        Fitted in log space (positive, scale-like parameters).
    prior_sd : float or None
        Standard deviation of a Gaussian prior about ``default`` in the fitted coordinate
        (None: flat between the bounds).
    """

    name: str
    unit: str
    lower: float
    upper: float
    default: float
    log: bool = False
    description: str = ""
    prior_sd: float | None = None


def mount_labels(engine) -> list:
    """Names of the engine's mounts in file order (three generic ones without an engine)."""
    if engine is None:
        return ["mount 1", "mount 2", "mount 3"]
    return [m.name for m in engine.mounts]


class Effect:
    """A candidate unmodelled effect (subclass per effect; see the module docstring)."""

    name = ""
    kind = ""
    description = ""
    #: False when the effect is not a change of the linear engine model (no ``apply``).
    engine_change = True
    #: True when the effect only changes what the sensors read.
    response_only = False
    #: True when some parameters belong to one channel each (held-out orders per channel).
    withhold_orders = False
    #: Side attributions at which the effect is a candidate; None: any.
    locations = None
    #: A parameter whose distant values can each explain the data (a second basin kept).
    basin_parameter = None
    #: Parameters whose uncertainty carries the model-discrepancy floor.
    model_floor = ()

    def parameters(self, engine=None) -> tuple:
        """Parameters for ``engine`` (default layout without one)."""
        raise NotImplementedError

    def start_grid(self, engine=None) -> tuple:
        """Coarse grid of start values per parameter (empty: start at the defaults)."""
        return ()

    def separable_groups(self, engine=None) -> list:
        """Blocks acting on disjoint channels for a block-wise multi-start:
        ``[(parameter names, channel indices, [start dicts]), ...]``."""
        return []

    def data_starts(self, engine, gaps) -> list:
        """Start parameter sets read from the data ``gaps``
        (:class:`~powertrain.effects.missing_body_mode.BodyGaps`); none by default."""
        return []

    def signed(self, engine=None) -> list:
        """Parameters whose sign the magnitudes leave open at a data start (both tried)."""
        return []

    def applicable(self, engine) -> bool:
        """Whether the effect can act on ``engine``."""
        return True

    def defaults(self, engine=None) -> dict:
        """``{parameter: default}`` for ``engine``."""
        return {p.name: p.default for p in self.parameters(engine)}

    def bounds(self, engine=None):
        ps = self.parameters(engine)
        return np.array([p.lower for p in ps]), np.array([p.upper for p in ps])

    def to_dict(self, engine=None) -> dict:
        return {"name": self.name, "kind": self.kind, "description": self.description,
                "parameters": [dataclasses.asdict(p) for p in self.parameters(engine)]}

    # A mount effect declares its change once; :meth:`apply` and the fast-path hooks use it.
    def network_scales(self, engine, p):
        """``(spring (n_net,), damper (n_net,))`` factors per network (mount-major x, y, z), or
        None."""
        return None

    def mount_law(self, p):
        """The amplitude law every network takes, or None (each keeps its own)."""
        return None

    def base_under_mounts(self, p):
        """``(mass [kg], stiffness [N/m], damping ratio [1])`` of a base under every network, or
        None."""
        return None

    def apply(self, engine, **params):
        """The engine with the effect's declared network changes in every mount model."""
        if not self.engine_change:
            raise NotImplementedError(f"{self.name} is not a change of the engine model")
        p = {**self.defaults(engine), **params}
        scales, law, base = self.network_scales(engine, p), self.mount_law(p), \
            self.base_under_mounts(p)
        if scales is None and law is None and base is None:
            return engine
        return map_networks(engine, lambda mi, m, ax, mod: changed_network(
            mod, None if scales is None else (scales[0][3 * mi + DIRECTIONS.index(ax)],
                                              scales[1][3 * mi + DIRECTIONS.index(ax)]),
            law, base))

    def warm(self, hm):
        """Fill the parts of the cached model ``hm`` this effect needs."""

    def elastomer_scale(self, hm, p):
        """:meth:`network_scales` on the cached model."""
        return self.network_scales(hm.engine, p)

    def two_port(self, hm, abc, p):
        """The networks' two-ports ``(a, b, c)``, each (n_r, 17, n_net), with the effect."""
        base = self.base_under_mounts(p)
        return abc if base is None else hm.two_ports_on_base(abc, *base)

    def load_terms(self, hm, p):
        """The change of the load harmonics as a weighted sum of fixed parts, ``(name, weights
        (n_b,), parts (n_b, n_r, 17, 6))``, or None."""
        return None

    def load_delta(self, hm, p):
        """Change of the load harmonics (n_r, 17, 6) from :meth:`load_terms`, or None."""
        terms = self.load_terms(hm, p)
        if terms is None or not np.any(terms[1]):
            return None
        return np.tensordot(terms[1], terms[2], axes=1)

    def elements(self, hm, elements, p):
        """The networks' mount elements (network order) with the effect (:meth:`mount_law`)."""
        law = self.mount_law(p)
        if law is None:
            return elements
        return [dataclasses.replace(el, amplitude_law=law) for el in elements]

    def body_change(self, hm, p, body):
        """The modal body under the mounts with the effect (called only when there is one)."""
        return body

    def reading(self, velocity, p):
        """What the sensors read from the channel velocities (n_r, n_ch, n_h)."""
        return velocity

    def readings(self, velocities, params):
        """:meth:`reading` of each of ``velocities`` (n_b, n_r, n_ch, n_h) with its ``params``."""
        return np.stack([self.reading(v, p) for v, p in zip(velocities, params)])

    def summary(self, params) -> str:
        """The fitted effect in one phrase for the report ('' : none)."""
        return ""

    def alternatives(self, params, engine=None) -> list:
        """Other parameter sets that may explain the same magnitudes, ``[(description,
        params), ...]``."""
        return []

    def restates(self, params, engine=None, band=None) -> tuple | None:
        """``(effect, reason)`` when the fitted ``params`` say what another, more constrained
        effect says; ``band``: measured order-frequency range [Hz] (None: unknown)."""
        return None

    def alternative_text(self, params, other, delta_chi2) -> str:
        """The verdict's sentence on a second minimum ``other`` (χ² higher by ``delta_chi2``)."""
        name = self.basin_parameter
        return (f"two minima explain the data alike: {name} {params[name]:.4g} or "
                f"{other[name]:.4g} (the data prefer {params[name]:.4g}: training chi2 lower "
                f"by {delta_chi2:.1f})")

    def interval_text(self, interval) -> str:
        """The verdict's sentence on the 95 % intervals ``{parameter: [lo, hi]}`` ("": none)."""
        return ""

    def bound_warnings(self, params) -> list:
        """Warnings on fitted ``params`` at a bound that matters."""
        return []

    def finding(self, params, engine=None, phase="none") -> dict | None:
        """What the fitted ``params`` name in the field's words, a dict with a ``text``, given
        the measured ``phase`` (``"none"``, ``"whole"``, ``"all"``); None by default."""
        return None


def map_networks(engine, fn):
    """The engine with every mount network replaced by ``fn(mount index, mount, axis, model)``."""
    return engine.replace(mounts=[dataclasses.replace(
        m, directions={ax: fn(mi, m, ax, mod) for ax, mod in m.directions.items()})
        for mi, m in enumerate(engine.mounts)])


def with_network_elastomer(engine, factors):
    """Every network's springs and dampers times its own factor (mount-major x, y, z)."""
    f = iter(np.asarray(factors, float).ravel())
    return map_networks(engine, lambda mi, m, ax, mod: mod.scaled(*(2 * (float(next(f)),))))


def changed_network(model, scales=None, law=None, base=None):
    """A mount model with ``scales`` = (spring, damper) factors, amplitude law ``law`` and a
    base ``base`` = (mass [kg], stiffness [N/m], damping ratio [1])."""
    if scales is not None:
        model = model.scaled(float(scales[0]), float(scales[1]))
    if law is not None:
        model = dataclasses.replace(model, amplitude_law=law)
    if base is not None:
        mass, stiffness, zeta = base
        model = with_base_compliance(model, mass, stiffness, 2 * zeta * np.sqrt(stiffness * mass))
    return model
