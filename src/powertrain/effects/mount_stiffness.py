r"""``mount_stiffness``: each mount's elastomer times its own factor :math:`k_i`.

Temperature, preload and part-to-part spread change the rubber's modulus, and with a
frequency-independent loss factor its damping in proportion; the fluid column of a
hydromount and the lumped rubber masses keep their inertia. Every spring and damper of the
mount's networks is therefore scaled by :math:`k_i` and every mass kept
(:meth:`MountModel.scaled`): the network's dynamic stiffness becomes
:math:`k_i(\mathbf K + i\omega\mathbf C) - \omega^2\mathbf M`, so its resonances move by
about :math:`\sqrt{k_i}`. One parameter ``k<i>`` per mount of the engine (file order).
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, map_networks, mount_labels


def with_mount_stiffness(engine, *k, **named):
    """Mount i's elastomer times ``k<i>`` [1] (i = 1..n in engine-file order; positional
    factors or ``k1=...``), all three directions alike; missing factors 1."""
    f = [float(x) for x in k] + [1.0] * len(engine.mounts)
    for key, v in named.items():
        f[int(key[1:]) - 1] = float(v)
    return map_networks(engine, lambda mi, m, ax, mod: mod.scaled(f[mi], f[mi]))


class MountStiffness(Effect):
    name = "mount_stiffness"
    kind = "structure"
    description = ("per-mount elastomer stiffness offset (temperature, preload, spread): springs "
                   "and dampers scaled, fluid and rubber inertia kept")

    def parameters(self, engine=None):
        return tuple(Parameter(f"k{i + 1}", "1", 0.3, 3.0, 1.0, True,
                               f"elastomer (spring and damper) factor of mount {i + 1} "
                               f"({name}); its masses unchanged")
                     for i, name in enumerate(mount_labels(engine)))

    def start_grid(self, engine=None):
        n = len(mount_labels(engine))
        return ((0.5, 1.0, 2.0),) * n if n <= 4 else ((0.6, 1.6),) * n

    def apply(self, engine, **params):
        return with_mount_stiffness(engine, **params)

    def alternatives(self, params, engine=None):
        """The factors of two mounts swapped (mirror-image mounts can give the same
        magnitudes), for every pair whose factors differ."""
        names = mount_labels(engine)
        k = [params.get(f"k{i + 1}", 1.0) for i in range(len(names))]
        out = []
        for i in range(len(k)):
            for j in range(i + 1, len(k)):
                if abs(np.log(k[i] / k[j])) > 0.02:
                    alt = dict(params, **{f"k{i + 1}": k[j], f"k{j + 1}": k[i]})
                    out.append((f"{names[i]} and {names[j]} swapped: k{i + 1}={k[j]:.3g}, "
                                f"k{j + 1}={k[i]:.3g}", alt))
        return out

    def elastomer_scale(self, hm, p):
        s = np.array([p.get(f"k{mi + 1}", 1.0) for mi, _, _ in hm.networks])
        return None if np.all(s == 1.0) else s
