r"""Unmodelled effects as model extensions: the candidates for the sim-to-real gap.

One class per effect (interface :mod:`.base`), one registry (:data:`EFFECTS`); parameters
are generated from the engine (per mount, channel, triad, cylinder or balancer shaft).

================== =========== ===================================================================
name               kind        physics
================== =========== ===================================================================
base_compliance    structure   every mount stands on a local chassis base: mass m_b on a spring
                               c_b (damping ratio ζ_b = 5 %) instead of the rigid ground
mount_stiffness    structure   each mount's elastomer times a factor k_i: springs × k_i, dampers
                               × k_i^γ (γ one fitted damping exponent, prior 1 ± 0.5), masses
                               (fluid and rubber inertia) unchanged
amplitude_stiffness structure  every mount's amplitude law: springs × f = (A_ref/A)^n,
                               dampers × f^γ (PowerLaw, A_ref = 0.1 mm, A across the mount;
                               γ as mount_stiffness')
chassis_modes      structure   the body modes shared by the mount bases (modal body only):
                               frequency, modal mass and damping of each mode fitted
missing_body_mode  structure   one body mode the model lacks: frequency, modal mass, damping
                               and its shape at each mount base (also a rigid chassis with
                               its body side measured)
balancer_error     excitation  balancer shafts' unbalance g(1 ± a/2) and timing δ ± s/2 per shaft
cylinder_imbalance excitation  cylinder i's combustion (IMEP, or the combustion part of its
                               measured trace) times (1 + ε_i)
sensor_error       sensor      channel gains 10^(G_c/20) and triad rotations φ_m:
                               diag(10^(G/20)) R(φ_m) v
================== =========== ===================================================================
"""

from powertrain.effects.amplitude_stiffness import A_REF, amplitude_law
from powertrain.effects.balancer_error import with_balancer_error
from powertrain.effects.base import Effect, Parameter, map_networks, with_network_elastomer
from powertrain.effects.base_compliance import BASE_ZETA, with_base_compliance_all
from powertrain.effects.cylinder_imbalance import with_cylinder_imbalance
from powertrain.effects.mount_stiffness import with_mount_stiffness
from powertrain.effects.predict import Prediction, predict
from powertrain.effects.registry import EFFECT_CLASSES, EFFECTS, RESPONSE_EFFECTS, check_scenario
from powertrain.effects.sensor_error import apply_sensor_error, rotation_matrix, sensor_reading

__all__ = ["A_REF", "BASE_ZETA", "EFFECTS", "EFFECT_CLASSES", "RESPONSE_EFFECTS", "Effect",
           "Parameter", "Prediction", "amplitude_law", "apply_sensor_error",
           "check_scenario", "map_networks", "predict", "rotation_matrix", "sensor_reading",
           "with_balancer_error", "with_base_compliance_all",
           "with_cylinder_imbalance", "with_mount_stiffness", "with_network_elastomer"]
