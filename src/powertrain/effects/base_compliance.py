r"""``base_compliance``: every mount stands on a local chassis base.

Mass :math:`m_b` on a spring :math:`c_b` with damping ratio ζ_b = 5 % between the network
and the ground (or the body). On the cached path the base node is condensed from the
network's two-port exactly: with :math:`k_b = c_b + i\omega d_b` and
:math:`z = c + k_b - \omega^2 m_b`,

.. math:: a' = a - b^2/z,\quad b' = b\,k_b/z,\quad c' = k_b - k_b^2/z

(:math:`a'` the input-point stiffness on a rigid ground; :math:`b', c'` couple a modal body).
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, map_networks

#: Damping ratio of the local base [1].
BASE_ZETA = 0.05
#: Upper bound of c_base, the default: the rigid ground [N/m].
C_RIGID = 2.0e7


def with_base_compliance_all(engine, c_base=np.inf, m_base=10.0, zeta=BASE_ZETA):
    r"""Every mount network on a local compliant base (all mounts alike).

    Base of mass ``m_base`` [kg] on a spring ``c_base`` [N/m] with the damper
    :math:`d_b = 2\zeta\sqrt{c_b m_b}` [N·s/m]
    (:func:`powertrain.models.extensions.with_base_compliance`). ``c_base = inf`` (default)
    is the rigid ground: the engine is returned unchanged.
    """
    from powertrain.models.extensions import with_base_compliance
    if not np.isfinite(c_base):
        return engine
    d_base = 2 * zeta * np.sqrt(c_base * m_base)
    return map_networks(engine, lambda mi, m, ax, mod: with_base_compliance(
        mod, m_base, c_base, d_base))


class BaseCompliance(Effect):
    name = "base_compliance"
    kind = "structure"
    description = "local compliant chassis base under every mount (rigid ground at c_base -> inf)"

    def parameters(self, engine=None):
        return (Parameter("c_base", "N/m", 1.0e5, C_RIGID, C_RIGID, True,
                          "base (chassis) stiffness under each mount; the upper bound (the "
                          "default) is the rigid ground"),
                Parameter("m_base", "kg", 1.0, 60.0, 10.0, True,
                          "base (chassis) mass at each mount"))

    def start_grid(self, engine=None):
        return ((1.5e5, 4e5, 1e6, 3e6), (2.0, 6.0, 15.0, 40.0))

    def apply(self, engine, c_base=np.inf, m_base=10.0):
        return with_base_compliance_all(engine, c_base, m_base)

    def two_port(self, hm, abc, p):
        cb, mb = p["c_base"], p["m_base"]
        if cb >= C_RIGID:
            return abc                       # upper bound = rigid ground (the default)
        a, b, c = abc
        w = hm.omega[..., None]
        kb = cb + 1j * w * 2 * BASE_ZETA * np.sqrt(cb * mb)
        z = c + kb - w ** 2 * mb
        return a - b ** 2 / z, b * kb / z, kb - kb ** 2 / z
