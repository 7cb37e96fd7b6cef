r"""A transient manoeuvre's load read from its tables at every step
(:mod:`powertrain.solvers.transient_load`): the gas load trilinear in load level, speed and
crank angle, the inertia and acceleration patterns linear in the angle,

.. math:: \mathbf f_k = \phi_k\,\tilde{\mathbf G}(\lambda_k, n_k, \theta_k)
   + \omega_k^2\,\mathbf I(\theta_k) + \alpha_k\,\tilde{\mathbf A}(\theta_k).

One loop rather than NumPy expressions over all steps: the eight gathers of those would each
build an array of all steps.
"""

from numba import njit


@njit(cache=True, nogil=True)
def _angle_row(pattern, u, fu, c):
    """Component ``c`` of ``pattern`` (n_theta + 1, 6) at row ``u`` plus ``fu``, linear."""
    return pattern[u, c] * (1.0 - fu) + pattern[u + 1, c] * fu


@njit(cache=True, nogil=True)
def table_load(gas, inertia, acceleration, levels, speeds, angles, fade, omega2, alpha, out):
    """Fill ``out`` (n, 6) with the load at each step.

    ``gas`` (n_levels, n_speeds, n_theta + 1, 6), ``inertia`` and ``acceleration``
    (n_theta + 1, 6) are periodic tables (the first angle repeated last). ``levels`` and
    ``speeds`` (n, 2) hold each step's lower table index and its weight towards the next,
    ``angles`` (n,) the fractional angle index in ``[0, n_theta)``; ``fade`` (n,) scales the
    gas load, ``omega2`` (n,) [rad²/s²] and ``alpha`` (n,) [rad/s²] the patterns.
    """
    n_theta = inertia.shape[0] - 1
    n_level, n_speed = gas.shape[0], gas.shape[1]
    for k in range(out.shape[0]):
        u = min(int(angles[k]), n_theta - 1)
        fu = angles[k] - u
        s0, fs = int(levels[k, 0]), levels[k, 1]
        v0, fv = int(speeds[k, 0]), speeds[k, 1]
        s1, v1 = min(s0 + 1, n_level - 1), min(v0 + 1, n_speed - 1)
        for c in range(6):
            g = ((_angle_row(gas[s0, v0], u, fu, c) * (1.0 - fv)
                  + _angle_row(gas[s0, v1], u, fu, c) * fv) * (1.0 - fs)
                 + (_angle_row(gas[s1, v0], u, fu, c) * (1.0 - fv)
                    + _angle_row(gas[s1, v1], u, fu, c) * fv) * fs)
            out[k, c] = (fade[k] * g + omega2[k] * _angle_row(inertia, u, fu, c)
                         + alpha[k] * _angle_row(acceleration, u, fu, c))
