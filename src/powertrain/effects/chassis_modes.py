r"""``chassis_modes``: the body modes shared by the mount bases are not where the model has them.

For an engine with a modal body each body mode k gets its frequency ``f<k>`` [Hz], modal mass
``m<k>`` [kg] and damping ratio ``z<k>`` [1] fitted; its shape is kept from the engine file
(shape and modal mass enter only as :math:`\psi\psi^T/m_k`, and magnitudes alone would leave
free shapes poorly identified). The effect moves the body-side channels most.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.effects.base import Effect, Parameter
from powertrain.errors import InputError

#: Frequency bounds relative to the file's value [1].
FREQ_RANGE = (0.6, 1.6)
#: Modal-mass bounds relative to the file's value [1].
MASS_RANGE = (0.25, 4.0)
#: Damping-ratio bounds [1].
ZETA_RANGE = (0.005, 0.25)
#: Prior standard deviation of ln(damping ratio) about the file's value [1] (a factor of two).
DAMPING_PRIOR = 0.7
#: Frequency factors of the start grid (each mode) [1].
GRID_FREQ = (0.85, 1.15)


def _modes(engine):
    ch = getattr(engine, "chassis", None)
    return () if ch is None else ch.body_modes


def mode_values(p, frequency_hz, modal_mass, damping_ratio):
    """Each mode's frequency [Hz], modal mass [kg] and damping ratio [1] with the parameters
    ``p`` (``f1``, ``m1``, ``z1``, ...; a missing one keeps the given value)."""
    return tuple([float(p.get(f"{key}{k + 1}", v)) for k, v in enumerate(values)]
                 for key, values in (("f", frequency_hz), ("m", modal_mass),
                                     ("z", damping_ratio)))


class ChassisModes(Effect):
    name = "chassis_modes"
    kind = "structure"
    #: held-out orders, not channels: the file's shapes are not what this effect claims
    withhold_orders = True
    description = ("body modes shared by the mount bases: frequency, modal mass and damping "
                   "of each of the engine file's body modes (shapes kept)")

    def parameters(self, engine=None):
        modes = _modes(engine)
        if not modes:      # generic layout without a modal body (not applicable there)
            return (Parameter("f1", "Hz", 5.0, 200.0, 30.0, True, "body mode 1 frequency"),
                    Parameter("m1", "kg", 1.0, 500.0, 40.0, True, "body mode 1 modal mass"),
                    Parameter("z1", "1", *ZETA_RANGE, 0.03, True, "body mode 1 damping ratio"))
        out = []
        for k, m in enumerate(modes):
            z0 = float(np.clip(m.damping_ratio, *ZETA_RANGE))
            out += [Parameter(f"f{k + 1}", "Hz", FREQ_RANGE[0] * m.frequency,
                              FREQ_RANGE[1] * m.frequency, m.frequency, True,
                              f"natural frequency of body mode {k + 1} (file: "
                              f"{m.frequency:g} Hz)"),
                    Parameter(f"m{k + 1}", "kg", MASS_RANGE[0] * m.modal_mass,
                              MASS_RANGE[1] * m.modal_mass, m.modal_mass, True,
                              f"modal mass of body mode {k + 1} (file: {m.modal_mass:g} kg)"),
                    Parameter(f"z{k + 1}", "1", *ZETA_RANGE, z0, True,
                              f"damping ratio of body mode {k + 1} (file: "
                              f"{m.damping_ratio:g})", DAMPING_PRIOR)]
        return tuple(out)

    def applicable(self, engine) -> bool:
        return bool(_modes(engine))

    def start_grid(self, engine=None):
        """Each mode's frequency at 0.85 and 1.15 × the file's (2^K start points)."""
        modes = _modes(engine)
        if not modes or len(modes) > 5:
            return ()
        out = []
        for m in modes:
            out += [tuple(g * m.frequency for g in GRID_FREQ), (m.modal_mass,),
                    (float(np.clip(m.damping_ratio, *ZETA_RANGE)),)]
        return tuple(out)

    def apply(self, engine, **params):
        if not _modes(engine):
            if params and params != self.defaults(None):
                raise InputError("effect chassis_modes needs an engine with a modal body "
                                 "([chassis] model = \"modal\")", key="chassis_modes")
            return engine             # nothing to change: the defaults are the baseline
        old = engine.chassis.modes
        values = mode_values(params, *([getattr(m, key) for m in old] for key in
                                       ("frequency", "modal_mass", "damping_ratio")))
        modes = tuple(dataclasses.replace(m, frequency=f, modal_mass=mm, damping_ratio=z)
                      for m, f, mm, z in zip(old, *values))
        return engine.replace(chassis=dataclasses.replace(engine.chassis, modes=modes))

    def body_change(self, hm, p, body):
        return body.with_modes(*mode_values(p, body.frequency_hz, body.modal_mass,
                                            body.damping_ratio))
