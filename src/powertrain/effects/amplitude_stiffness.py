r"""``amplitude_stiffness``: the elastomer's stiffness depends on the amplitude across the mount.

One :class:`~powertrain.physics.mount_laws.PowerLaw` on every mount direction: springs × f,
dampers × :math:`f^{\gamma}`, :math:`f = \mathrm{clip}((A_{ref}/A)^{n}, 0.2, 5)`, with
:math:`A_{ref}` = 0.1 mm (where the networks were fitted), :math:`A` the relative
displacement amplitude across the mount, masses kept; one exponent :math:`n` and one
damping exponent :math:`\gamma` for all mounts. Solved at the harmonic fixed point
(:mod:`powertrain.solvers.equivalent_linear`); at :math:`n = 0` the mounts are unchanged.
"""

from __future__ import annotations

from powertrain.effects.base import Effect, Parameter
from powertrain.effects.mount_stiffness import damping_exponent_parameter
from powertrain.physics.mount_laws import PowerLaw

#: Reference amplitude of the mount data (dynamic stiffness measured at 0.1 mm) [m].
A_REF = 1.0e-4


def amplitude_law(exponent: float, damping_exponent: float = 1.0) -> PowerLaw:
    """The candidate's law: :class:`PowerLaw` at :data:`A_REF` with its default limits."""
    return PowerLaw(A_REF, float(exponent), damping_exponent=float(damping_exponent))


class AmplitudeStiffness(Effect):
    name = "amplitude_stiffness"
    kind = "structure"
    description = ("amplitude-dependent mount stiffness: springs x f = (A_ref/A)^n, dampers "
                   "x f^γ (A_ref = 0.1 mm, A across the mount), at the harmonic fixed point")

    def parameters(self, engine=None):
        return (Parameter("exponent", "1", 0.0, 1.0, 0.0, False,
                          "power-law exponent n of every mount's elastomer"),
                damping_exponent_parameter("f"))

    def start_grid(self, engine=None):
        return ((0.1, 0.2, 0.35), (1.0,))

    def mount_law(self, p):
        if p.get("exponent", 0.0) == 0.0:
            return None
        return amplitude_law(p["exponent"], p.get("damping_exponent", 1.0))
