r"""``sensor_error``: each channel's sensor reads a gain error, each triad a small rotation
and cross-axis sensitivity.

Channel c of triad m reads :math:`10^{G_c/20}\,[(\mathbf R(\boldsymbol\varphi_m) +
\mathbf S_m)\mathbf v_m]_c`: the triad rotated by :math:`\boldsymbol\varphi_m` (Rodrigues),
:math:`\mathbf S_m` symmetric with zero diagonal (transverse sensitivity, typically ≤ 5 % by
datasheet). Parameters: a gain ``g<c>`` per channel, a rotation ``r<m><axis>`` and cross-axis
terms ``s<m>xy``, ``s<m>xz``, ``s<m>yz`` per mount triad.
"""

from __future__ import annotations

import numpy as np

from powertrain.effects.base import Effect, Parameter, mount_labels

#: Pairs of triad axes with a cross-axis sensitivity parameter.
CROSS_AXES = ("xy", "xz", "yz")
#: Bound of a cross-axis sensitivity [1] (datasheets ≤ 5 %, plus the mounting).
CROSS_AXIS_MAX = 0.08
#: Prior standard deviations of a rotation [rad] and of a cross-axis term [1].
ROTATION_PRIOR = 0.1
#: Rotation of the block-wise multi-start's extra starts [rad] (about 6°).
ROTATION_START = 0.1
_START_DIRECTIONS = [np.eye(3)[i] * sg for i in range(3) for sg in (1, -1)] + [
    np.array([a, b, c]) / np.sqrt(3) for a in (1, -1) for b in (1, -1) for c in (1, -1)]
CROSS_AXIS_PRIOR = 0.02


def rotation_matrix(phi):
    r"""Rotation matrix of the rotation vector ``phi`` [rad] (Rodrigues):
    :math:`\mathbf R = \mathbf I + \frac{\sin\theta}{\theta}[\boldsymbol\varphi]_\times +
    \frac{1 - \cos\theta}{\theta^2}[\boldsymbol\varphi]_\times^2`, θ = |φ|."""
    return rotation_matrices(np.reshape(phi, (1, 3)))[0]


def rotation_matrices(phi):
    """:func:`rotation_matrix` of each row of ``phi`` (n, 3) [rad] at once, (n, 3, 3)."""
    phi = np.asarray(phi, float)
    th = np.sqrt(np.einsum("ij,ij->i", phi, phi))
    zero = np.zeros(len(phi))
    K = np.stack([zero, -phi[:, 2], phi[:, 1], phi[:, 2], zero, -phi[:, 0],
                  -phi[:, 1], phi[:, 0], zero], axis=-1).reshape(-1, 3, 3)
    small = th < 1e-12                      # R = I + [φ]×
    t = np.where(small, 1.0, th)
    a = np.where(small, 1.0, np.sin(t) / t)
    b = np.where(small, 0.0, (1 - np.cos(t)) / t ** 2)
    return np.eye(3) + a[:, None, None] * K + b[:, None, None] * (K @ K)


def sensor_reading(velocity, gain_db, rotation, cross_axis=None):
    """What mis-calibrated, mis-oriented triads read from the true channel velocities.

    Parameters
    ----------
    velocity : ndarray (..., n_r, 3 n_m, n_h) complex
        True mount-point velocities, triads mount-major x, y, z.
    gain_db : ndarray (..., 3 n_m)
        Channel gain errors [dB].
    rotation : ndarray (..., n_m, 3)
        Rotation vector of each triad [rad].
    cross_axis : ndarray (..., n_m, 3), optional
        Cross-axis sensitivities (xy, xz, yz) of each triad [1] (default none).
    """
    v = np.asarray(velocity)
    gain_db = np.asarray(gain_db, float)
    lead, n_m = gain_db.shape[:-1], v.shape[-2] // 3
    T = rotation_matrices(np.reshape(rotation, (-1, 3))).reshape(lead + (n_m, 3, 3))
    if cross_axis is not None:
        S = np.zeros(lead + (n_m, 3, 3))
        cross = np.asarray(cross_axis, float)
        for k, (i, j) in enumerate(((0, 1), (0, 2), (1, 2))):
            S[..., i, j] = S[..., j, i] = cross[..., k]
        T = T + S
    T = T[..., None, :, :, :]                               # over the speeds
    out = T @ v.reshape(v.shape[:-2] + (n_m, 3, v.shape[-1]))
    out = out.reshape(out.shape[:-3] + v.shape[-2:])
    return out * 10.0 ** (gain_db / 20.0)[..., None, :, None]


def _sensor_arrays(params: dict, n_ch: int):
    """``(gains (3 n_m,), rotations (n_m, 3), cross-axis (n_m, 3))``, missing ones 0."""
    gains = np.array([params.get(f"g{c + 1}", 0.0) for c in range(n_ch)])
    rot = np.array([[params.get(f"r{m + 1}{ax}", 0.0) for ax in "xyz"]
                    for m in range(n_ch // 3)])
    cross = np.array([[params.get(f"s{m + 1}{ax}", 0.0) for ax in CROSS_AXES]
                      for m in range(n_ch // 3)])
    return gains, rot, cross


def apply_sensor_error(velocity, params: dict):
    """:func:`sensor_reading` with the parameters ``g<c>`` [dB], ``r<m><axis>`` [rad] and
    ``s<m><axes>`` [1] (missing ones 0)."""
    return sensor_reading(velocity, *_sensor_arrays(params, velocity.shape[1]))


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
                               f"rotation about engine {ax.upper()}", ROTATION_PRIOR)
                     for m, name in enumerate(mounts) for ax in "xyz")
        cross = tuple(Parameter(f"s{m + 1}{ax}", "1", -CROSS_AXIS_MAX, CROSS_AXIS_MAX, 0.0,
                                False, f"cross-axis sensitivity {ax[0]}-{ax[1]} of the triad "
                                       f"at mount {m + 1} ({name})", CROSS_AXIS_PRIOR)
                      for m, name in enumerate(mounts) for ax in CROSS_AXES)
        return gains + rots + cross

    def separable_groups(self, engine=None):
        """One block per triad, started at no rotation and at :data:`ROTATION_START` about 6
        axis and 8 diagonal directions (a gain error and a leaking rotation look alike)."""
        out = []
        for m, _ in enumerate(mount_labels(engine)):
            names = ([f"g{3 * m + a + 1}" for a in range(3)]
                     + [f"r{m + 1}{ax}" for ax in "xyz"] + [f"s{m + 1}{ax}" for ax in CROSS_AXES])
            starts = [{}] + [dict(zip([f"r{m + 1}{ax}" for ax in "xyz"], ROTATION_START * d))
                             for d in _START_DIRECTIONS]
            out.append((names, [3 * m, 3 * m + 1, 3 * m + 2], starts))
        return out

    def reading(self, velocity, p):
        return apply_sensor_error(velocity, p)

    def readings(self, velocities, params):
        arrays = [_sensor_arrays(p, velocities.shape[-2]) for p in params]
        return sensor_reading(velocities, *(np.stack(a) for a in zip(*arrays)))
