"""The registry of effects read by the CLI, ``synth``, ``whatif`` and the diagnosis; adding an
effect is one entry in :data:`EFFECT_CLASSES` (docs/extending.md)."""

from __future__ import annotations

import numpy as np

from powertrain.effects.amplitude_stiffness import AmplitudeStiffness
from powertrain.effects.balancer_error import BalancerError
from powertrain.effects.base_compliance import BaseCompliance
from powertrain.effects.chassis_modes import ChassisModes
from powertrain.effects.cylinder_imbalance import CylinderImbalance
from powertrain.effects.missing_body_mode import MissingBodyMode
from powertrain.effects.mount_stiffness import MountStiffness
from powertrain.effects.sensor_error import SensorError

#: Effect classes in the order they act on the model (structure, excitation, sensor).
EFFECT_CLASSES = (BaseCompliance, ChassisModes, MissingBodyMode, MountStiffness,
                  AmplitudeStiffness, BalancerError, CylinderImbalance, SensorError)
#: name -> effect instance.
EFFECTS: dict = {cls.name: cls() for cls in EFFECT_CLASSES}
#: Effects that are not a change of the linear engine model (applied to the response).
RESPONSE_EFFECTS = tuple(n for n, e in EFFECTS.items() if not e.engine_change)


def check_scenario(scenario: dict, engine=None) -> dict:
    """Validate ``{effect: {parameter: value}}`` (SI) against the parameters the effects
    generate for ``engine`` and fill in the defaults; raises ``KeyError`` (unknown effect or
    parameter) or ``ValueError`` (value outside its bounds or not finite)."""
    out = {}
    for name, params in scenario.items():
        if name not in EFFECTS:
            raise KeyError(f"unknown effect {name!r} (expected {', '.join(EFFECTS)})")
        eff = EFFECTS[name]
        spec = {p.name: p for p in eff.parameters(engine)}
        for k, v in params.items():
            if k not in spec:
                raise KeyError(f"effect {name!r} has no parameter {k!r} (expected "
                               f"{', '.join(spec)})")
            p = spec[k]
            if not (np.isfinite(v) and p.lower <= v <= p.upper):
                u = "" if p.unit == "1" else f" {p.unit}"
                raise ValueError(f"{name}.{k} = {v:g}{u} outside the effect's bounds "
                                 f"{p.lower:g}..{p.upper:g}{u}")
        out[name] = {**eff.defaults(engine), **params}
    return out
