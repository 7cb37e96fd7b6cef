r"""The engine's load tables, built from the gas forces and unit-load patterns
(:func:`gas_table`) at the cylinder pressures of the table's angles
(:func:`cylinder_pressures`), and read at every step of a transient (:func:`table_load`): the
gas load trilinear in load level, speed and crank angle, the inertia and acceleration
patterns linear in the angle,

.. math:: \mathbf f_k = \phi_k\,\tilde{\mathbf G}(\lambda_k, n_k, \theta_k)
   + \omega_k^2\,\mathbf I(\theta_k) + \alpha_k\,\tilde{\mathbf A}(\theta_k).
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
    (n_theta + 1, 6) are periodic tables (first angle repeated last). ``levels`` and
    ``speeds`` (n, 2) hold each step's lower table index and weight towards the next,
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


@njit(cache=True, nogil=True)
def gas_table(gas_force, patterns, inertia, omega2, out):
    """Fill ``out`` (n_loads, n_speeds, n, 6) with ``omega2 I + sum over cylinders of F_g G``:
    gas forces ``gas_force`` (n_loads, n_speeds, n, n_cyl) [N], unit-gas-force loads
    ``patterns`` (n_cyl, n, 6), unit-omega² load ``inertia`` (n, 6), ``omega2`` (n_speeds,)
    [rad²/s²]."""
    n_load, n_speed, n, n_cyl = gas_force.shape
    for a in range(n_load):
        for s in range(n_speed):
            for t in range(n):
                for k in range(6):
                    v = omega2[s] * inertia[t, k]
                    for c in range(n_cyl):
                        v += gas_force[a, s, t, c] * patterns[c, t, k]
                    out[a, s, t, k] = v


@njit(cache=True, nogil=True)
def cylinder_pressures(cycle, i0, i1, w, out):
    """Fill ``out`` (n, n_cyl) with ``cycle[c, i0] (1 - w) + cycle[c, i1] w``: each cylinder's
    pressure of ``cycle`` (n_cyl, n_grid) [Pa] interpolated at ``i0``, ``i1``, ``w`` (n, n_cyl)."""
    for t in range(i0.shape[0]):
        for c in range(i0.shape[1]):
            out[t, c] = cycle[c, i0[t, c]] * (1.0 - w[t, c]) + cycle[c, i1[t, c]] * w[t, c]
