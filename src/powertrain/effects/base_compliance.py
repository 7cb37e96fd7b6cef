r"""``base_compliance``: every mount stands on a local chassis base.

Mass :math:`m_b` on a spring :math:`c_b` with damping ratio ζ_b = 5 % between each network
and the ground (or the body) (:meth:`BaseCompliance.base_under_mounts`); at the upper bound
of ``c_base`` (the default) the ground is rigid.
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, changed_network, map_networks

#: Damping ratio of the local base [1].
BASE_ZETA = 0.05
#: Upper bound of c_base, the default: the rigid ground [N/m].
C_RIGID = 2.0e7


def with_base_compliance_all(engine, c_base=np.inf, m_base=10.0, zeta=BASE_ZETA):
    r"""Every mount network on a base of ``m_base`` [kg] on a spring ``c_base`` [N/m] with
    :math:`d_b = 2\zeta\sqrt{c_b m_b}` [N·s/m]; ``c_base = inf`` returns the engine unchanged."""
    if not np.isfinite(c_base):
        return engine
    return map_networks(engine, lambda mi, m, ax, mod: changed_network(
        mod, base=(m_base, c_base, zeta)))


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

    def base_under_mounts(self, p):
        cb = p["c_base"]
        if not cb < C_RIGID:
            return None                      # the upper bound is the rigid ground (default)
        return p["m_base"], cb, BASE_ZETA
