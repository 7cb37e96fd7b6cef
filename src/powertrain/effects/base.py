"""The effect interface: one class per unmodelled effect, parameters generated from the engine.

An effect has a ``name``, a ``kind`` (structure, excitation, sensor), a ``description``,
``parameters(engine)`` (bounded, with units; generated from the engine's mounts, cylinders,
balancer shafts and channels), ``applicable(engine)`` and ``apply(engine, params)`` (the
changed engine model, where the effect is one). For the fast cached path
(:func:`powertrain.effects.predict`) an effect contributes through hooks, each a no-op by
default: an elastomer scale per network, a change of the networks' two-ports, a load
change, the networks' mount elements (an amplitude law), a change of the sensor reading. To add an
effect: one new module with a subclass and its tests, and one line in
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
        Standard deviation of a Gaussian prior about ``default`` (in the fitted coordinate;
        None: flat between the bounds). For parameters that magnitudes alone identify poorly
        (a triad's rotation and cross-axis terms), the prior keeps the unidentified
        directions at the datasheet's typical value instead of wherever the noise pushes
        them (maximum a posteriori fit, :mod:`powertrain.diagnosis.fit`).
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
    #: False for effects that are not a change of the linear engine model (``apply`` absent).
    engine_change = True
    #: True when the effect only changes what the sensors read (the physics is untouched).
    response_only = False
    #: True when some parameters belong to one channel each (a gain, a mode's shape at one
    #: base): the held-out cells check then withholds orders per channel, not channels.
    withhold_orders = False
    #: Side attributions (``location`` of :func:`powertrain.diagnosis.sides.side_attribution`)
    #: at which the effect is a candidate; None: at any (also without body-side data).
    locations = None
    #: A parameter whose distant values can each explain the data (a resonance's frequency):
    #: the fit then keeps a start in a second basin of it and reports a second minimum that
    #: explains alike (:mod:`powertrain.diagnosis.starts`); None: no such parameter.
    basin_parameter = None
    #: Parameters whose reported uncertainty carries the relative model-discrepancy floor
    #: (:data:`powertrain.diagnosis.uncertainty.MODEL_FLOOR`).
    model_floor = ()

    # ------------------------------------------------------------------ description
    def parameters(self, engine=None) -> tuple:
        """Parameters for ``engine`` (default layout without one)."""
        raise NotImplementedError

    def start_grid(self, engine=None) -> tuple:
        """Coarse grid of start values per parameter (empty: start at the defaults)."""
        return ()

    def separable_groups(self, engine=None) -> list:
        """Blocks of parameters that act on disjoint channels, for a block-wise multi-start
        before the joint fit: ``[(parameter names, channel indices, [start dicts]), ...]``
        (empty: none). Only meaningful for effects whose channels do not interact (sensor
        readings)."""
        return []

    def data_starts(self, engine, gaps) -> list:
        """Start parameter sets read from the data (``gaps``:
        :class:`~powertrain.effects.missing_body_mode.BodyGaps` against the model without
        the effect), screened with the grid's starts; none by default."""
        return []

    def signed(self, engine=None) -> list:
        """Parameters whose sign the data's magnitudes leave open at a data start (a mode's
        shape): the fit's starts try both (:mod:`powertrain.diagnosis.starts`)."""
        return []

    def applicable(self, engine) -> bool:
        """Whether the effect can act on ``engine``."""
        return True

    def defaults(self, engine=None) -> dict:
        """``{parameter: default}`` for ``engine`` (the cached model keeps them per effect:
        :meth:`HarmonicModel.effect_defaults
        <powertrain.solvers.fast_harmonic.HarmonicModel.effect_defaults>`)."""
        return {p.name: p.default for p in self.parameters(engine)}

    def bounds(self, engine=None):
        ps = self.parameters(engine)
        return np.array([p.lower for p in ps]), np.array([p.upper for p in ps])

    def to_dict(self, engine=None) -> dict:
        return {"name": self.name, "kind": self.kind, "description": self.description,
                "parameters": [dataclasses.asdict(p) for p in self.parameters(engine)]}

    # ------------------------------------------------------------------ engine model
    # ------------------------------------------------------------------ what the effect changes
    # A mount effect states its change once, by these declarations; :meth:`apply` puts it
    # into the engine model and the fast-path hooks below into the frequency view.
    def network_scales(self, engine, p):
        """Factors on every network's springs and on its dampers (network order: mount-major
        x, y, z), ``(spring (n_net,), damper (n_net,))``, or None (unchanged)."""
        return None

    def mount_law(self, p):
        """The amplitude law every network takes, or None (each keeps its own)."""
        return None

    def base_under_mounts(self, p):
        """``(mass [kg], stiffness [N/m], damping ratio [1])`` of a base under every network,
        or None (the ground or body as the engine has it)."""
        return None

    def apply(self, engine, **params):
        """The engine with the effect: its declared network changes in every mount model
        (effects that change the engine otherwise override this)."""
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

    # ------------------------------------------------------------------ fast-path hooks
    def warm(self, hm):
        """Fill the parts of the cached model ``hm`` this effect needs."""

    def elastomer_scale(self, hm, p):
        """Factors on every network's springs and on its dampers, ``(spring (n_net,),
        damper (n_net,))``, or None: :meth:`network_scales`."""
        return self.network_scales(hm.engine, p)

    def two_port(self, hm, abc, p):
        """The networks' two-ports ``(a, b, c)``, each (n_r, 17, n_net), with the effect: on
        :meth:`base_under_mounts` (:meth:`HarmonicModel.two_ports_on_base
        <powertrain.solvers.fast_harmonic.HarmonicModel.two_ports_on_base>`)."""
        base = self.base_under_mounts(p)
        return abc if base is None else hm.two_ports_on_base(abc, *base)

    def load_terms(self, hm, p):
        """The effect's change of the load harmonics as a weighted sum of fixed parts,
        ``(name, weights (n_b,), parts (n_b, n_r, 17, 6))`` (``name`` names the parts on
        ``hm``), or None: the cached model then solves each part once
        (:meth:`HarmonicModel.load_velocity`)."""
        return None

    def load_delta(self, hm, p):
        """Change of the load harmonics (n_r, 17, 6), or None (no change): the sum of
        :meth:`load_terms` (an effect changes the load through its terms only)."""
        terms = self.load_terms(hm, p)
        if terms is None or not np.any(terms[1]):
            return None
        return np.tensordot(terms[1], terms[2], axes=1)

    def elements(self, hm, elements, p):
        """The networks' mount elements (list in network order,
        :class:`~powertrain.physics.mount_elements.MountElement`) with the effect, e.g. an
        amplitude law set (:meth:`mount_law`); a nonlinear element makes :func:`powertrain.effects.predict`
        iterate to its amplitudes. Unchanged by default."""
        law = self.mount_law(p)
        if law is None:
            return elements
        return [dataclasses.replace(el, amplitude_law=law) for el in elements]

    def body_change(self, hm, p, body):
        """The modal body under the mounts (:class:`~powertrain.solvers.body_coupling.ModalBody`)
        with the effect; only called when the engine has one."""
        return body

    def reading(self, velocity, p):
        """What the sensors read from the channel velocities (n_r, n_ch, n_h)."""
        return velocity

    def readings(self, velocities, params):
        """:meth:`reading` of each of ``velocities`` (n_b, n_r, n_ch, n_h) with the parameter
        dict of the same index in ``params``, stacked: a finite-difference Jacobian's columns
        read at once (a response-only effect vectorises it; the same values)."""
        return np.stack([self.reading(v, p) for v, p in zip(velocities, params)])

    def summary(self, params) -> str:
        """The fitted effect in one phrase for the report ('' : none)."""
        return ""

    # ------------------------------------------------------------------ identifiability
    def alternatives(self, params, engine=None) -> list:
        """Other parameter sets that may explain the same magnitudes, as
        ``[(description, params), ...]`` (the diagnosis keeps those the data cannot tell
        apart from ``params``); none by default."""
        return []

    def restates(self, params, engine=None, band=None) -> tuple | None:
        """``(effect, reason)`` when the fitted ``params`` say what another, more constrained
        effect of the library says (e.g. a "missing" body mode whose shape pairs with one of
        the file's modes: that mode, misplaced); the decision rule then prefers that effect
        while the held-out speeds cannot tell the two apart. ``band``: ``(lowest, highest)``
        order frequency measured above the floor [Hz] (None: unknown). None by default."""
        return None

    def alternative_text(self, params, other, delta_chi2) -> str:
        """The verdict's sentence on a second minimum ``other`` (parameters) of the fitted
        ``params`` that explains the data alike (training χ² higher by ``delta_chi2``)."""
        name = self.basin_parameter
        return (f"two minima explain the data alike: {name} {params[name]:.4g} or "
                f"{other[name]:.4g} (the data prefer {params[name]:.4g}: training chi2 lower "
                f"by {delta_chi2:.1f})")

    def interval_text(self, interval) -> str:
        """The verdict's sentence on the 95 % intervals ``{parameter: [lo, hi]}`` of the
        fitted parameters ("" : none said)."""
        return ""

    def bound_warnings(self, params) -> list:
        """Warnings for the verdict on fitted ``params`` at a bound that matters to what the
        answer says; [] by default."""
        return []

    def finding(self, params, engine=None, phase="none") -> dict | None:
        """What the fitted ``params`` name in the field's words (e.g. which cylinder, weak or
        strong), as a dict with a ``text``, given the measured ``phase`` (``"none"``,
        ``"whole"``: whole orders only, ``"all"``); None by default."""
        return None


def map_networks(engine, fn):
    """The engine with every mount network replaced by ``fn(mount index, mount, axis, model)``."""
    mounts = []
    for mi, m in enumerate(engine.mounts):
        mounts.append(dataclasses.replace(
            m, directions={ax: fn(mi, m, ax, mod) for ax, mod in m.directions.items()}))
    return engine.replace(mounts=mounts)


def with_network_elastomer(engine, factors):
    """Every network's springs and dampers times its own factor (network order: mount-major
    x, y, z, as :attr:`HarmonicModel.networks`), masses kept (:meth:`MountModel.scaled`)."""
    f = iter(np.asarray(factors, float).ravel())
    return map_networks(engine, lambda mi, m, ax, mod: mod.scaled(*(2 * (float(next(f)),))))


def changed_network(model, scales=None, law=None, base=None):
    """A mount model with an effect's declared changes: springs and dampers times
    ``scales`` = (spring, damper) factors, the amplitude law ``law``, a base ``base`` =
    (mass [kg], stiffness [N/m], damping ratio [1]) under it
    (:func:`powertrain.models.extensions.with_base_compliance`)."""
    if scales is not None:
        model = model.scaled(float(scales[0]), float(scales[1]))
    if law is not None:
        model = dataclasses.replace(model, amplitude_law=law)
    if base is not None:
        mass, stiffness, zeta = base
        model = with_base_compliance(model, mass, stiffness, 2 * zeta * np.sqrt(stiffness * mass))
    return model
