"""The crank train and the balancer shafts of an engine (SI, engine axes;
:mod:`powertrain.models.engine`)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.models.memo import Memo
from powertrain.physics import slider_crank as sc


@dataclass(frozen=True, eq=False)
class CrankTrain:
    """Geometry and masses of the crank train (SI).

    Attributes
    ----------
    bore, stroke, rod_length, pin_offset : float
        [m]; the crank radius is ``stroke / 2``.
    compression_ratio : float
        Geometric compression ratio [-].
    cylinder_x : ndarray
        Each cylinder's position along the crank axis (engine X) [m], cylinder 1 first.
    cylinder_axis : ndarray, shape (3,)
        Unit vector :math:`\\mathbf u` of the cylinder axis (crank axis to head).
    rotation_sign : int
        +1: the crank turns positively about +X, −1: about −X.
    crank_pin_angles, firing_angles : ndarray
        Cylinder-1 crank angle at each cylinder's TDC, and at its firing TDC on ``[0, 4π)``
        [rad].
    firing_order : tuple of int
        Cylinder numbers (1-based), starting with 1.
    reciprocating_mass, rotating_mass : float
        Per cylinder [kg].
    counterweight_fraction : float
        Share of each throw's rotating mass balanced by its counterweights [-].
    crankcase_pressure : float
        Pressure under the piston [Pa].
    """

    bore: float
    stroke: float
    rod_length: float
    pin_offset: float
    compression_ratio: float
    cylinder_x: np.ndarray
    cylinder_axis: np.ndarray
    rotation_sign: int
    crank_pin_angles: np.ndarray
    firing_order: tuple
    firing_angles: np.ndarray
    reciprocating_mass: float
    rotating_mass: float
    counterweight_fraction: float
    crankcase_pressure: float
    _memo: Memo = field(default_factory=Memo, init=False, repr=False, compare=False)

    @property
    def n_cylinders(self) -> int:
        return len(self.cylinder_x)

    @property
    def firing_interval(self) -> float:
        """Crank angle over which the gas torque repeats [rad]: the least 4π / k whose shift
        maps the firing angles onto themselves (4π if none)."""
        angles = np.sort(np.mod(self.firing_angles, 4 * np.pi))
        for k in range(self.n_cylinders, 1, -1):
            if self.n_cylinders % k == 0:
                shifted = np.sort(np.mod(angles + 4 * np.pi / k, 4 * np.pi))
                gap = np.abs(shifted - angles)
                if np.all(np.minimum(gap, 4 * np.pi - gap) < 1e-6):
                    return float(4 * np.pi / k)
        return float(4 * np.pi)

    @property
    def crank_radius(self) -> float:
        """[m]"""
        return 0.5 * self.stroke

    @property
    def piston_area(self) -> float:
        """[m²]"""
        return np.pi * self.bore**2 / 4.0

    @property
    def swept_volume(self) -> float:
        """Swept volume of one cylinder from the exact kinematics [m³]."""
        return float(sc.swept_volume(self.bore, self.crank_radius, self.rod_length,
                                     self.pin_offset))

    @property
    def displacement(self) -> float:
        """Engine displacement [m³]."""
        return self.n_cylinders * self.swept_volume

    @property
    def lateral_axis(self) -> np.ndarray:
        """Unit vector :math:`\\mathbf s = \\sigma\\,\\mathbf e_x\\times\\mathbf u`."""
        return self.rotation_sign * np.cross([1.0, 0.0, 0.0], self.cylinder_axis)

    def volume(self, theta):
        """Cylinder volume [m³] and dV/dθ [m³/rad] at ``theta`` [rad] (last grid memoised)."""
        return self._memo.last_grid("volume", theta, lambda th: sc.cylinder_volume(
            th, self.bore, self.crank_radius, self.rod_length, self.pin_offset,
            self.compression_ratio))


@dataclass(frozen=True, eq=False)
class BalancerShaft:
    """One balancer shaft.

    Attributes
    ----------
    name : str
    mass_radius : float
        Unbalance [kg·m].
    position : ndarray, shape (3,)
        A point of the shaft axis at the unbalance's plane, engine axes [m].
    phase : float
        Unbalance angle at cylinder-1 TDC from :math:`\\mathbf u` towards :math:`\\mathbf s` [rad].
    sense : int
        +1 turns with the crank, −1 against it.
    """

    name: str
    mass_radius: float
    position: np.ndarray
    phase: float
    sense: int


@dataclass(frozen=True, eq=False)
class Balancer:
    """Balancer shafts turning at ``ratio`` × crank speed; ``enabled`` switches them."""

    enabled: bool
    ratio: float
    shafts: tuple
