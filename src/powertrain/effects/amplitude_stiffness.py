r"""``amplitude_stiffness``: the elastomer's stiffness depends on the amplitude across the mount.

A fit of the mount laws (:mod:`powertrain.physics.mount_laws`), not a physics of its own: the
candidate puts one :class:`~powertrain.physics.mount_laws.PowerLaw` on every mount direction,

.. math:: \text{springs} \times f,\quad \text{dampers} \times f^{\gamma},\qquad
   f = \mathrm{clip}\big((A_{ref}/A)^{n},\ 0.2,\ 5\big),

:math:`A_{ref}` = 0.1 mm (where mount data are measured and the networks fitted, so the
network is unchanged at :math:`A_{ref}`), :math:`A` the amplitude of the relative
displacement across the mount direction (√2 × RMS of orders 0.5–8), masses kept; one
exponent :math:`n` and one damping exponent :math:`\gamma` (as ``mount_stiffness``'s: prior
1 ± 0.5, a constant loss factor at 1) for all mounts (one law per mount design is not
separable from ``mount_stiffness``). :meth:`~AmplitudeStiffness.apply` sets
:attr:`MountModel.amplitude_law <powertrain.models.mount.MountModel.amplitude_law>`,
which the run-up's harmonic fixed point
(:mod:`powertrain.solvers.equivalent_linear`) solves; the fast path
(:func:`powertrain.effects.predict`) evaluates the same
:meth:`MountElement.two_port <powertrain.physics.mount_elements.MountElement.two_port>` at
its own fixed-point amplitudes. At :math:`n = 0` (the default) the mounts are left as they
are (a law of the engine's mount files included); otherwise the candidate's law replaces
theirs. tests/amplitude_oracle.py checks the linearisation against a cycle-by-cycle
Newmark integration.
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
