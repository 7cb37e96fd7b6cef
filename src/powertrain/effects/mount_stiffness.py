r"""``mount_stiffness``: each mount's elastomer times its own factor :math:`k_i`.

Temperature, preload and spread change the rubber's modulus and damping: every spring of
the mount's networks × :math:`k_i`, every damper × :math:`k_i^{\gamma}`, masses kept, so
resonances move by about :math:`\sqrt{k_i}`. The damping exponent :math:`\gamma` (one for
all mounts; loss factor :math:`\eta \propto k^{\gamma - 1}`) has a Gaussian prior about 1,
the thesis' constant loss factor (:data:`DAMPING_EXPONENT_PRIOR`).
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, mount_labels

#: Bounds of the damping exponent γ (dampers × k^γ) [1].
DAMPING_EXPONENT_RANGE = (0.0, 2.0)
#: Prior 1σ of γ about 1 (constant loss factor) [1].
DAMPING_EXPONENT_PRIOR = 0.5


def damping_exponent_parameter(factor: str) -> Parameter:
    """The elastomer effects' ``damping_exponent`` γ: dampers × ``factor``^γ."""
    return Parameter("damping_exponent", "1", *DAMPING_EXPONENT_RANGE, 1.0, False,
                     f"exponent γ of the dampers' factor {factor}^γ (1: constant loss factor)",
                     DAMPING_EXPONENT_PRIOR)


def with_mount_stiffness(engine, *k, damping_exponent=1.0, **named):
    """Mount i's springs times ``k<i>`` [1] and dampers times ``k<i> ** damping_exponent``
    (positional or ``k1=...`` in file order; missing ones 1)."""
    f = [float(x) for x in k] + [1.0] * len(engine.mounts)
    for key, v in named.items():
        f[int(key[1:]) - 1] = float(v)
    params = {f"k{i + 1}": f[i] for i in range(len(engine.mounts))}
    return MountStiffness().apply(engine, damping_exponent=float(damping_exponent), **params)


class MountStiffness(Effect):
    name = "mount_stiffness"
    kind = "structure"
    description = ("per-mount elastomer stiffness offset (temperature, preload, spread): springs "
                   "scaled, dampers with a fitted exponent, fluid and rubber inertia kept")

    def parameters(self, engine=None):
        return tuple(Parameter(f"k{i + 1}", "1", 0.3, 3.0, 1.0, True,
                               f"elastomer factor of mount {i + 1} ({name}): springs times "
                               "it, dampers times it to the damping exponent; its masses "
                               "unchanged")
                     for i, name in enumerate(mount_labels(engine))) + (
            damping_exponent_parameter("k_i"),)

    def start_grid(self, engine=None):
        n = len(mount_labels(engine))
        factors = ((0.5, 1.0, 2.0),) * n if n <= 4 else ((0.6, 1.6),) * n
        return factors + ((1.0,),)                 # γ starts at its prior's centre

    def alternatives(self, params, engine=None):
        """The factors of every differing pair of mounts swapped (mirror-image mounts)."""
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

    def network_scales(self, engine, p):
        s = np.repeat([p.get(f"k{mi + 1}", 1.0) for mi in range(len(engine.mounts))], 3)
        return None if np.all(s == 1.0) else (s, s ** p.get("damping_exponent", 1.0))
