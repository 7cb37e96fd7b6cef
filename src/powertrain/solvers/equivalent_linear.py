r"""Equivalent-linear steady state of a model with nonlinear mount elements.

In the frequency domain a nonlinear element (:mod:`powertrain.physics.mount_elements`)
acts through its describing function at the amplitude :math:`A` of the relative
displacement across it, :math:`A = \sqrt 2\,` RMS over the engine cycle of orders 0.5 to 8,
i.e. :math:`A = (\sum_j |\hat u_j|^2)^{1/2}` over those harmonics. The amplitudes and the
response depend on each other: :func:`amplitude_fixed_point` iterates
:math:`A \leftarrow A + \rho\,(A(\hat{\mathbf q}(A)) - A)` (relaxation :math:`\rho` halved
whenever the change grows) until the change is below :data:`TOLERANCE` of the largest
amplitude; a fixed point that does not converge is an error naming the element and speed.
A linear model needs none of this: the steppers solve it once, as before.
"""

from __future__ import annotations

import numpy as np

#: Orders whose motion makes an element's amplitude (as half-orders: harmonics 1..16).
AMPLITUDE_HARMONICS = slice(1, 17)
#: Fixed point: relative change of the amplitudes at convergence, and iteration limit.
TOLERANCE = 1e-9
MAX_ITERATIONS = 200


def amplitudes_of(relative) -> np.ndarray:
    """Amplitudes (m,) [m] of the relative-motion harmonics ``relative`` (n_h, m), index j
    = order j/2."""
    return np.sqrt(np.sum(np.abs(relative[AMPLITUDE_HARMONICS]) ** 2, axis=0))


def amplitude_fixed_point(solve, relative_motion, ports, rpm, start=None, tolerance=TOLERANCE):
    """The equivalent-linear steady state.

    Parameters
    ----------
    solve : callable
        ``solve(amplitudes)``: the response with the amplitudes (n_networks,) [m] of every
        network (:meth:`PortForces.network_amplitudes`).
    relative_motion : callable
        ``relative_motion(solution)``: the nonlinear elements' relative-motion harmonics
        (n_h, m) [m].
    ports : PortForces
        The nonlinear elements (their ``names`` for the error).
    rpm : float
        Speed, for the error.
    start : ndarray (m,), optional
        First guess (e.g. the previous speed's amplitudes); default: zero.
    tolerance : float
        Relative change of the amplitudes at convergence (a time-domain run, which goes on
        to its own steady state, starts from a looser fixed point).

    Returns
    -------
    amplitudes : ndarray (m,); solution : the ``solve`` result at them.

    Raises
    ------
    FloatingPointError
        No convergence within :data:`MAX_ITERATIONS`.
    """
    A = np.zeros(len(ports.names)) if start is None else np.asarray(start, float).copy()
    relax, last = 1.0, np.inf
    for _ in range(MAX_ITERATIONS):
        solution = solve(ports.network_amplitudes(A))
        change = amplitudes_of(relative_motion(solution)) - A
        size = max(np.max(np.abs(A + change)), np.finfo(float).tiny)
        err = np.max(np.abs(change)) / size
        if err <= tolerance:
            return A, solution
        if err > last:
            relax = max(relax / 2, 1.0 / 64)
        last = err
        A = A + relax * change
    worst = ports.names[int(np.argmax(np.abs(change)))]
    raise FloatingPointError(f"{worst} at {rpm:g} rpm: the equivalent-linear amplitude did "
                             f"not converge in {MAX_ITERATIONS} iterations (change {err:.1e})")
