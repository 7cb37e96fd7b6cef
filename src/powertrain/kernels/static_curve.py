r"""Static curves as piecewise cubics (each network's PCHIP in
:class:`scipy.interpolate.PPoly` form), straight with the end slopes beyond their ends.
"""

from numba import njit


@njit(cache=True, nogil=True)
def curve_point(breaks, coefficients, count, r, d):
    """``(force, tangent)`` [N, N/m] of network ``r``'s curve at the deflection ``d`` [m]:
    ``count[r]`` breakpoints ``breaks[r]`` (n_net, n_b), segment j's ``coefficients[r, j]``
    highest power first."""
    last = count[r] - 1
    x0, x1 = breaks[r, 0], breaks[r, last]
    x = min(max(d, x0), x1)
    j = 0
    while j < last - 1 and breaks[r, j + 1] <= x:
        j += 1
    c = coefficients[r, j]
    dx = x - breaks[r, j]
    force = ((c[0] * dx + c[1]) * dx + c[2]) * dx + c[3]
    tangent = (3.0 * c[0] * dx + 2.0 * c[1]) * dx + c[2]
    return force + tangent * (d - x), tangent


@njit(cache=True, nogil=True)
def curve_values(breaks, coefficients, count, d, force, tangent):
    """:func:`curve_point` of every network at ``d`` (n_net,) [m] into ``force``, ``tangent``
    (``breaks``, ``coefficients``, ``count`` as there)."""
    for r in range(d.shape[0]):
        force[r], tangent[r] = curve_point(breaks, coefficients, count, r, d[r])
