r"""Equivalent-linear steady state of a model with nonlinear mount elements.

In the frequency domain a nonlinear element (:mod:`powertrain.physics.mount_elements`)
acts through its describing function at the amplitude :math:`A` of the relative
displacement across it, :math:`A = \sqrt 2\,` RMS over the engine cycle of orders 0.5 to 8,
i.e. :math:`A = (\sum_j |\hat u_j|^2)^{1/2}` over those harmonics. The amplitudes and the
response depend on each other: :func:`amplitude_fixed_point` solves
:math:`A = g(A)`, :math:`g` the amplitudes of the response at :math:`A`, by Anderson
acceleration (Walker & Ni 2011) in log amplitudes: each step combines the last
:data:`DEPTH` iterates so that the linearised residual :math:`\ln g(A) - \ln A` vanishes (a
steep law converges in a few steps where plain iteration creeps, and amplitudes stay
positive). Where the residual grows the history is dropped and a damped step
:math:`\ln A \leftarrow \ln A + \rho\,(\ln g(A) - \ln A)` follows (relaxation :math:`\rho`
halved each time, down to 1/64). Converged when the change is below
:data:`TOLERANCE` of the largest amplitude; a fixed point that does not converge is an
:class:`AmplitudeNotConverged` naming the element whose amplitude changes most relative to
itself, and the speed. A linear model needs none of this: the steppers solve it once.
"""

from __future__ import annotations

import numpy as np

#: Orders whose motion makes an element's amplitude (as half-orders: harmonics 1..16).
AMPLITUDE_HARMONICS = slice(1, 17)
#: Fixed point: relative change of the amplitudes at convergence, and iteration limit.
TOLERANCE = 1e-9
MAX_ITERATIONS = 200
#: Anderson acceleration: earlier iterates combined per step.
DEPTH = 5
#: Amplitudes below this fraction of the largest are weighed (and blamed) as this fraction.
AMPLITUDE_FLOOR = 1e-6


class AmplitudeNotConverged(FloatingPointError):
    """The equivalent-linear amplitudes did not converge: ``element`` (``mount.direction``)
    changed most relative to its own amplitude, at ``rpm``."""

    def __init__(self, element: str, rpm: float, change: float, iterations: int):
        self.element, self.rpm, self.change = element, float(rpm), float(change)
        super().__init__(f"{element} at {rpm:g} rpm: the equivalent-linear amplitude did "
                         f"not converge in {iterations} iterations (its amplitude changes "
                         f"by {change:.1e} of itself per iteration)")


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
    AmplitudeNotConverged
        No convergence within :data:`MAX_ITERATIONS` (a FloatingPointError).
    """
    A = np.zeros(len(ports.names)) if start is None else np.asarray(start, float).copy()
    steps = AndersonSteps(DEPTH)
    for _ in range(MAX_ITERATIONS):
        solution = solve(ports.network_amplitudes(A))
        G = amplitudes_of(relative_motion(solution))
        if np.max(np.abs(G - A)) <= tolerance * np.max(G):
            return A, solution
        floor = AMPLITUDE_FLOOR * max(np.max(G), np.finfo(float).tiny)
        x = np.log(np.maximum(A, floor))
        residual = np.log(np.maximum(G, floor)) - x
        A = np.exp(steps.next(x, residual))
    worst = int(np.argmax(np.abs(residual)))
    raise AmplitudeNotConverged(ports.names[worst], rpm, -np.expm1(-abs(residual[worst])),
                                MAX_ITERATIONS)


class AndersonSteps:
    """Anderson acceleration of ``ln A = ln g(A)``, with a damped step as the fallback where
    the residual grows (module docstring)."""

    def __init__(self, depth):
        self.depth, self.relax, self.last = depth, 1.0, np.inf
        self.x, self.f = [], []                       # log iterates and their residuals

    def next(self, x, residual) -> np.ndarray:
        """The next log amplitudes after ``x`` (``residual``: log g(A) - log A)."""
        size = np.max(np.abs(residual))
        if size > self.last:                          # growing: damp, forget the history
            self.relax = max(self.relax / 2, 1.0 / 64)
            self.x, self.f = [], []
        self.last = size
        self.x, self.f = (self.x + [x])[-self.depth - 1:], (self.f + [residual])[-self.depth - 1:]
        step = self.relax * residual
        if len(self.x) > 1:
            dX, dF = np.diff(self.x, axis=0).T, np.diff(self.f, axis=0).T
            gamma = np.linalg.lstsq(dF, residual, rcond=1e-10)[0]
            step = step - (dX + self.relax * dF) @ gamma
        return x + step
