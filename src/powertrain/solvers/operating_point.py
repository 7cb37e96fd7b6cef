r"""The static operating point of the powertrain on its mounts, per engine speed.

The six-DOF body (:math:`\mathbf q = (\mathbf u, \boldsymbol\theta)` at the CG, engine axes)
carries its weight :math:`-mg\,\mathbf e_z` (:math:`g` = 9.80665 m/s²) and the mean
drive-torque reaction :math:`-i\,T_{mean}\,\mathbf n` (:math:`\mathbf n = \pm\mathbf e_x` the
crank's rotation sense, :math:`T_{mean}` the mean brake torque, :math:`i` the gear ratio).
With small displacements each mount direction deflects by :math:`\delta = \mathbf r^T\mathbf q`
(engine side minus base, :func:`powertrain.physics.rigid_body.direction_row`) and pushes the
engine with :math:`-F(\delta)\,\mathbf r`, :math:`F` its static curve
(:class:`~powertrain.physics.mount_laws.StaticCurve`) or :math:`k_0\delta`. Equilibrium

.. math:: \mathbf R(\mathbf q) = \mathbf W - \sum F(\mathbf r^T\mathbf q)\,\mathbf r = 0

is solved by Newton with the tangent stiffness :math:`\sum F'(\delta)\,\mathbf r\mathbf r^T`
and a halving line search to :data:`TOLERANCE`. A network's *static factor*, its curve's
tangent there over that at its reference deflection (1 without a curve), scales its springs
and dampers (:meth:`~powertrain.physics.mount_elements.MountElement.at_operating_point`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.errors import InputError
from powertrain.kernels import kernel_input
from powertrain.kernels.static_curve import curve_values
from powertrain.physics.mount_laws import pchip_cubic
from powertrain.physics.rigid_body import direction_row
from powertrain.units import STANDARD_GRAVITY

#: Force residual over the weight, and moment residual over the weight × 1 m, at convergence.
TOLERANCE = 1e-9
#: Newton iterations before the operating point is declared not found.
MAX_ITERATIONS = 100
#: Smallest line-search step of a Newton iteration.
MIN_STEP = 2.0 ** -30
#: Local mount directions, in order.
DIRECTIONS = ("x", "y", "z")


@dataclass(frozen=True, eq=False)
class StaticSupport:
    """The mounts as the static equilibrium sees them, one entry per network (mount order,
    then local x, y, z).

    Attributes
    ----------
    rows : ndarray (n_net, 6)
        Deflection per unit body coordinate.
    curves : list
        Each network's :class:`~powertrain.physics.mount_laws.StaticCurve` or None.
    stiffness : ndarray (n_net,)
        Static stiffness of the networks [N/m] (used where there is no curve).
    cubics : tuple
        ``(breaks (n_net, n_b), coefficients (n_net, n_b - 1, 4), count (n_net,))``: each
        network's force as a piecewise cubic (its curve's PCHIP or its static stiffness's
        line, :func:`~powertrain.kernels.static_curve.curve_values`).
    reference_tangent : ndarray (n_net,)
        Tangent stiffness at each curve's reference deflection, else the static one [N/m].
    """

    rows: np.ndarray
    curves: list
    stiffness: np.ndarray
    cubics: tuple
    reference_tangent: np.ndarray

    @classmethod
    def of(cls, engine) -> StaticSupport:
        """The support of the mounts of ``engine``."""
        cg = np.asarray(engine.body.cg, float)
        rows, curves, k0 = [], [], []
        for mount in engine.mounts:
            r = np.asarray(mount.position, float) - cg
            R = np.asarray(mount.rotation, float)
            for a, axis in enumerate(DIRECTIONS):
                model = mount.directions[axis]
                rows.append(direction_row(r, R[:, a]))
                curves.append(model.static_curve)
                k0.append(model.static_stiffness())
        cubics = tuple(kernel_input(a, a.dtype) for a in _padded([_cubic(c, k) for c, k in zip(curves, k0)]))
        reference = np.array([0.0 if c is None else c.reference_deflection for c in curves])
        tangent = np.empty(len(curves))
        curve_values(*cubics, kernel_input(reference), np.empty(len(curves)), tangent)
        return cls(np.array(rows), curves, np.array(k0), cubics, tangent)

    def read(self, deflection):
        """``(force [N], tangent stiffness [N/m])`` of every network at its ``deflection`` [m]."""
        force, tangent = np.empty(len(self.curves)), np.empty(len(self.curves))
        curve_values(*self.cubics, kernel_input(deflection), force, tangent)
        return force, tangent

    def forces(self, deflection) -> np.ndarray:
        """Force of every network [N] at its ``deflection`` [m]."""
        return self.read(deflection)[0]

    def tangents(self, deflection) -> np.ndarray:
        """Tangent stiffness of every network [N/m] at its ``deflection`` [m]."""
        return self.read(deflection)[1]

    def factors(self, deflection) -> np.ndarray:
        """Static factor of every network at its ``deflection`` [m] (1 without a curve)."""
        return self.read(deflection)[1] / self.reference_tangent


def _padded(pieces):
    """The networks' ``(breaks, coefficients)`` padded to one size, and their counts."""
    size = max(b.size for b, _ in pieces)
    breaks, coefficients = np.empty((len(pieces), size)), np.zeros((len(pieces), size - 1, 4))
    for i, (b, c) in enumerate(pieces):
        breaks[i, :b.size], breaks[i, b.size:] = b, b[-1]
        coefficients[i, :len(c)] = c
    return breaks, coefficients, np.array([b.size for b, _ in pieces], np.int64)


def _cubic(curve, stiffness):
    """``(breaks, coefficients)`` of the ``curve``'s PCHIP, or of the line ``stiffness`` × δ."""
    if curve is None:
        return np.array([0.0, 1.0]), np.array([[0.0, 0.0, stiffness, 0.0]])
    return pchip_cubic(curve.deflection, curve.force)


@dataclass(frozen=True)
class OperatingPoint:
    """The static equilibrium at one speed (SI).

    Attributes
    ----------
    rpm, mean_torque, gear_ratio : float
        Speed [rpm], mean brake torque :math:`T_{mean}` [N·m], gear ratio [-].
    body : ndarray (6,)
        Displacement [m] and small rotation [rad] of the body at the CG, engine axes.
    deflection, force, tangent_stiffness : ndarray (n_mounts, 3)
        Per mount and local direction: engine side minus base [m], the curve's force [N]
        (pushing the engine with minus it), its tangent stiffness [N/m].
    static_factor : ndarray (n_mounts * 3,)
        Each network's static factor.
    iterations : int
        Newton iterations taken.
    residual : tuple of float
        Force residual over the weight, moment residual over the weight × 1 m.
    """

    rpm: float
    mean_torque: float
    gear_ratio: float
    body: np.ndarray
    deflection: np.ndarray
    force: np.ndarray
    tangent_stiffness: np.ndarray
    static_factor: np.ndarray
    iterations: int
    residual: tuple


def has_static_curves(engine) -> bool:
    """True when some mount direction of ``engine`` has a static curve."""
    return any(getattr(model, "static_curve", None) is not None
               for mount in engine.mounts for model in mount.directions.values())


def static_load(engine, mean_torque: float) -> np.ndarray:
    """Generalized load (6,) [N, N·m] on the body about its CG: the weight and the reaction
    :math:`-i\\,T_{mean}\\,\\mathbf n` of the ``mean_torque`` [N·m] of ``engine``."""
    n = np.array([float(engine.crank.rotation_sign), 0.0, 0.0])
    load = np.zeros(6)
    load[2] = -engine.body.mass * STANDARD_GRAVITY
    load[3:] = -engine.gear_ratio * mean_torque * n
    return load


def operating_point(engine, rpm: float, support: StaticSupport | None = None,
                    start=None, mean_torque: float | None = None) -> OperatingPoint:
    """The static operating point of ``engine`` at ``rpm`` (module docstring).

    Parameters
    ----------
    engine : Engine
    rpm : float
        Speed [rpm].
    support : StaticSupport, optional
        The mounts (default built from ``engine``).
    start : ndarray (6,), optional
        Newton's first guess [m, rad] (default zero).
    mean_torque : float, optional
        Mean brake torque [N·m]; default the engine's at ``rpm``.

    Raises
    ------
    InputError
        When Newton's method does not converge.
    """
    engine.require_excitation()
    support = support or StaticSupport.of(engine)
    torque = engine.mean_brake_torque(rpm) if mean_torque is None else float(mean_torque)
    q, iterations, residual = _equilibrium(support, static_load(engine, torque),
                                           engine.body.mass * STANDARD_GRAVITY, start)
    if q is None:
        raise InputError(f"the static operating point at {float(rpm):g} rpm did not "
                         f"converge in {MAX_ITERATIONS} Newton iterations (force residual "
                         f"{residual[0]:.1e} of the weight)", file=engine.file or None,
                         key="mounts")
    d = support.rows @ q
    shape = (len(engine.mounts), 3)
    return OperatingPoint(float(rpm), float(torque), float(engine.gear_ratio), q,
                          d.reshape(shape), support.forces(d).reshape(shape),
                          support.tangents(d).reshape(shape), support.factors(d),
                          iterations, residual)


def operating_points(engine, rpm) -> list:
    """:func:`operating_point` of ``engine`` at every speed of ``rpm``, each started from the last."""
    support = StaticSupport.of(engine)
    out, start = [], None
    for n in np.atleast_1d(np.asarray(rpm, float)):
        out.append(operating_point(engine, n, support, start))
        start = out[-1].body
    return out


def static_factors(engine, rpm) -> np.ndarray:
    """Static factor (n_networks,) of every network of ``engine`` at the operating point of
    ``rpm`` [rpm]; all 1 without static curves."""
    if not has_static_curves(engine):
        return np.ones(3 * len(engine.mounts))
    return operating_point(engine, rpm).static_factor


def _residual(support, load, weight, q):
    """Generalized residual (6,) and its size ``(force / W, moment / (W · 1 m))``."""
    r = load - support.rows.T @ support.forces(support.rows @ q)
    return r, (float(np.linalg.norm(r[:3])) / weight, float(np.linalg.norm(r[3:])) / weight)


def _equilibrium(support, load, weight, start):
    """Newton with a halving line search: ``(q, iterations, residual)``, q None if not converged."""
    q = np.zeros(6) if start is None else np.asarray(start, float).copy()
    r, size = _residual(support, load, weight, q)
    for it in range(MAX_ITERATIONS + 1):
        if max(size) <= TOLERANCE:
            return q, it, size
        if it == MAX_ITERATIONS:
            break
        rows = support.rows
        kt = rows.T @ (support.tangents(rows @ q)[:, None] * rows)
        try:
            dq = np.linalg.solve(kt, r)
        except np.linalg.LinAlgError:
            break
        step = 1.0
        while step >= MIN_STEP:
            r_new, size_new = _residual(support, load, weight, q + step * dq)
            if max(size_new) < max(size):
                break
            step /= 2
        else:
            break
        q, r, size = q + step * dq, r_new, size_new
    return None, MAX_ITERATIONS, size
