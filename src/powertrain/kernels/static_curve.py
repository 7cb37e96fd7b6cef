r"""Static curves read as their piecewise cubics (each network's PCHIP as
:class:`scipy.interpolate.PPoly` holds it), straight with the end slopes beyond their
points: the operating point (:mod:`powertrain.solvers.operating_point`) and the transient's
pieces (:mod:`powertrain.kernels.transient`) read the curves here.
"""

from numba import njit


@njit(cache=True, nogil=True)
def curve_point(breaks, coefficients, count, r, d):
    """``(force, tangent)`` [N, N/m] of network ``r``'s static curve at the deflection
    ``d`` [m]: the piecewise cubic of ``count[r]`` breakpoints ``breaks[r]`` (n_net, n_b)
    with the coefficients ``coefficients[r, j]`` (highest power first, as
    :class:`scipy.interpolate.PPoly`'s) on each segment, straight with the end slopes
    beyond its ends."""
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
    """Each network's curve force and tangent at its deflection ``d`` (n_net,) [m] into
    ``force``, ``tangent`` (:func:`curve_point`)."""
    for r in range(d.shape[0]):
        force[r], tangent[r] = curve_point(breaks, coefficients, count, r, d[r])
