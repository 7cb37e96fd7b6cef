r"""``sensor_error``: each channel's sensor reads a gain error, each triad a small rotation.

Channel c of triad m reads :math:`10^{G_c/20}\,[\mathbf R(\boldsymbol\varphi_m)
\mathbf v_m]_c`: the triad's axes are rotated by :math:`\boldsymbol\varphi_m` (Rodrigues)
from the engine axes, then each axis has its own gain. One gain ``g<c>`` per channel and a
rotation ``r<m><axis>`` per mount triad, generated from the engine's mounts.
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, mount_labels


def rotation_matrix(phi):
    r"""Rotation matrix of the rotation vector ``phi`` [rad] (Rodrigues):
    :math:`\mathbf R = \mathbf I + \frac{\sin\theta}{\theta}[\boldsymbol\varphi]_\times +
    \frac{1 - \cos\theta}{\theta^2}[\boldsymbol\varphi]_\times^2`, θ = |φ|."""
    phi = np.asarray(phi, float)
    th = float(np.linalg.norm(phi))
    K = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
    if th < 1e-12:
        return np.eye(3) + K
    return np.eye(3) + np.sin(th) / th * K + (1 - np.cos(th)) / th ** 2 * (K @ K)


def sensor_reading(velocity, gain_db, rotation):
    """What mis-calibrated, mis-oriented triads read from the true channel velocities.

    Parameters
    ----------
    velocity : ndarray (n_r, 3 n_m, n_h) complex
        True mount-point velocities, triads mount-major x, y, z.
    gain_db : ndarray (3 n_m,)
        Channel gain errors [dB].
    rotation : ndarray (n_m, 3)
        Rotation vector of each triad [rad].
    """
    v = np.asarray(velocity)
    out = np.empty_like(v)
    for m in range(v.shape[1] // 3):
        sl = slice(3 * m, 3 * m + 3)
        out[:, sl] = np.einsum("ij,rjh->rih", rotation_matrix(rotation[m]), v[:, sl])
    return out * 10.0 ** (np.asarray(gain_db, float) / 20.0)[None, :, None]


def apply_sensor_error(velocity, params: dict):
    """:func:`sensor_reading` with the parameters ``g<c>`` [dB] and ``r<m><axis>`` [rad]
    (missing ones 0)."""
    n_ch = velocity.shape[1]
    gains = np.array([params.get(f"g{c + 1}", 0.0) for c in range(n_ch)])
    rot = np.array([[params.get(f"r{m + 1}{ax}", 0.0) for ax in "xyz"]
                    for m in range(n_ch // 3)])
    return sensor_reading(velocity, gains, rot)


class SensorError(Effect):
    name = "sensor_error"
    kind = "sensor"
    description = ("per-channel sensor gain (calibration) and per-triad orientation (mounting) "
                   "errors")
    engine_change = False
    response_only = True

    def parameters(self, engine=None):
        mounts = mount_labels(engine)
        gains = tuple(Parameter(f"g{3 * m + a + 1}", "dB", -8.0, 8.0, 0.0, False,
                                f"gain error of channel {3 * m + a + 1} ({name} {ax}; "
                                f"mount-major x, y, z)")
                      for m, name in enumerate(mounts) for a, ax in enumerate("xyz"))
        rots = tuple(Parameter(f"r{m + 1}{ax}", "rad", -0.15, 0.15, 0.0, False,
                               f"orientation error of the triad at mount {m + 1} ({name}): "
                               f"rotation about engine {ax.upper()}")
                     for m, name in enumerate(mounts) for ax in "xyz")
        return gains + rots

    def reading(self, velocity, p):
        return apply_sensor_error(velocity, p)
