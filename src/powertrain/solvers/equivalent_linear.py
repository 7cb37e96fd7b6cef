r"""Equivalent-linear steady state of a model with nonlinear mount elements.

A nonlinear element (:mod:`powertrain.physics.mount_elements`) acts through its describing
function at the amplitude of the relative displacement across it, :math:`A = \sqrt 2\,` RMS
over orders 0.5 to 8, :math:`A = (\sum_j |\hat u_j|^2)^{1/2}`. :func:`fixed_point` solves
:math:`A = g(A)` (:math:`g` the amplitudes of the response at :math:`A`) by Anderson
acceleration (Walker & Ni 2011) over the last :data:`DEPTH` iterates in log amplitudes;
where the residual :math:`\ln g(A) - \ln A` grows the history is dropped and the step damped
(relaxation halved, down to 1/64). Converged when the change is below :data:`TOLERANCE` of
the largest amplitude, else :class:`AmplitudeNotConverged`.
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
    changed most relative to itself, by ``change`` per iteration after ``iterations``, at
    ``rpm``."""

    def __init__(self, element: str, rpm: float, change: float, iterations: int):
        self.element, self.rpm, self.change = element, float(rpm), float(change)
        super().__init__(f"{element} at {rpm:g} rpm: the equivalent-linear amplitude did "
                         f"not converge in {iterations} iterations (its amplitude changes "
                         f"by {change:.1e} of itself per iteration)")


def amplitudes_of(relative) -> np.ndarray:
    """Amplitudes (m,) [m] of the relative-motion harmonics ``relative`` (n_h, m), j = order j/2."""
    return np.sqrt(np.sum(np.abs(relative[AMPLITUDE_HARMONICS]) ** 2, axis=0))


def amplitude_fixed_point(solve, relative_motion, ports, rpm, start=None, tolerance=TOLERANCE):
    """The equivalent-linear steady state at one speed (:func:`fixed_point`).

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
        Relative change of the amplitudes at convergence.

    Returns
    -------
    amplitudes : ndarray (m,); solution : the ``solve`` result at them.
    """
    A = np.zeros(len(ports.names)) if start is None else np.asarray(start, float).copy()
    A, solution, _ = fixed_point(lambda a: solve(ports.network_amplitudes(a)),
                                 lambda x: amplitudes_of(relative_motion(x)), ports.names,
                                 rpm, A, tolerance)
    return A, solution


def fixed_point(solve, amplitudes, names, rpm, start, tolerance=TOLERANCE):
    """The fixed point :math:`A = g(A)` at one speed (``start`` (m,)) or several (``start``
    (n_r, m), each row converged on its own largest amplitude).

    Parameters
    ----------
    solve : callable
        ``solve(A)``: the response at the nonlinear elements' amplitudes A [m].
    amplitudes : callable
        ``amplitudes(solution)``: :math:`g(A)`, the amplitudes of that response [m], A's shape.
    names : sequence of str
        ``mount.direction`` of each element, for the error.
    rpm : float or ndarray (n_r,)
        Speed of each row, for the error.
    start : ndarray (m,) or (n_r, m)
        First guess [m].
    tolerance : float
        Relative change of the amplitudes at convergence.

    Returns
    -------
    amplitudes, solution, iterations (solves made)

    Raises
    ------
    AmplitudeNotConverged
        No convergence within :data:`MAX_ITERATIONS` (a FloatingPointError).
    """
    A = np.array(start, float)
    steps = AndersonSteps(DEPTH)
    for it in range(1, MAX_ITERATIONS + 1):
        solution = solve(A)
        G = amplitudes(solution)
        size = np.maximum(np.max(np.abs(G), axis=-1, keepdims=True), np.finfo(float).tiny)
        err = np.max(np.abs(G - A), axis=-1, keepdims=True) / size
        if np.max(err) <= tolerance:
            return A, solution, it
        floor = AMPLITUDE_FLOOR * size
        x = np.log(np.maximum(A, floor))
        residual = np.log(np.maximum(G, floor)) - x
        A = np.exp(steps.next(x.ravel(), residual.ravel())).reshape(x.shape)
    r = int(np.argmax(err.ravel()))
    row = np.atleast_2d(residual)[r]
    worst = int(np.argmax(np.abs(row)))
    raise AmplitudeNotConverged(names[worst], float(np.ravel(rpm)[r]),
                                -np.expm1(-abs(row[worst])), MAX_ITERATIONS)


class AndersonSteps:
    """Anderson acceleration of ``ln A = ln g(A)`` over ``depth`` iterates, damped where the
    residual grows."""

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
