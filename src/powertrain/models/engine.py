r"""The engine model: crank train, rigid powertrain body, mounts, balancer shafts, combustion.

Everything is SI, in engine axes (Kovarik 2016, sec. 4.1): origin at the centre of the 3rd
main bearing, X along the crank axis (opposite to the vehicle's ISO 8855 X), Y to the right,
Z up. The load on the rigid powertrain (:meth:`Engine.generalized_load`,
``docs/guide/excitation.md``) is, per cylinder at its X, the block forces of
:func:`powertrain.physics.slider_crank.crank_forces`, the residual rotating-mass force
:math:`(1-k_{cw})\,m_{rot}\,r\omega^2(\cos\theta_i\,\mathbf u + \sin\theta_i\,\mathbf s)`
on the crank axis, and the balancer-shaft forces, with moments about the CG.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.assembly import assemble
from powertrain.errors import InputError
from powertrain.kernels import kernel_input
from powertrain.kernels.load_table import cylinder_pressures, gas_table
from powertrain.models.combustion import RPM, LoadedCombustion, MotoredCombustion
from powertrain.models.crank_train import Balancer, CrankTrain
from powertrain.models.memo import Memo
from powertrain.physics import balancer as bal
from powertrain.physics import combustion as comb
from powertrain.physics import slider_crank as sc


@dataclass(frozen=True, eq=False)
class RigidBody:
    """Mass properties of the powertrain (engine + gearbox) as one rigid body.

    Attributes
    ----------
    mass : float
        [kg]
    cg : ndarray, shape (3,)
        Centre of gravity in engine axes [m].
    inertia : ndarray, shape (3, 3)
        Inertia tensor about the CG in engine axes [kg·m²] (:math:`I_{xy} = -\\int xy\\,dm`).
    """

    mass: float
    cg: np.ndarray
    inertia: np.ndarray

@dataclass(frozen=True, eq=False)
class MountSpec:
    """One mount of the powertrain.

    Attributes
    ----------
    name : str
        Any name (e.g. ``left``, ``torque_rod``).
    position : ndarray, shape (3,)
        Engine-side mount point (measurement point) in engine axes [m].
    rotation : ndarray, shape (3, 3)
        Columns are the mount's local x, y, z axes in engine axes.
    directions : dict of str to MountModel
        The mount model along each local axis ``x``, ``y``, ``z``.
    files : dict of str to str
        Mount file of each direction.
    """

    name: str
    position: np.ndarray
    rotation: np.ndarray
    directions: dict
    files: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Excitation:
    """What drives the block at one speed, sampled at given cylinder-1 crank angles.

    Attributes
    ----------
    rpm : float
        Engine speed [rpm].
    crank_angle : ndarray, shape (n,)
        Cylinder-1 crank angle [rad].
    pressure, gas_force, inertia_force, torque, torque_gas, torque_inertia : ndarray, (n, n_cyl)
        Per cylinder: absolute pressure [Pa], gas force on the piston [N], reciprocating
        inertia force along the cylinder axis [N], crank torque and its gas and inertia
        parts [N·m].
    load : ndarray, shape (n, 6)
        ``[Fx, Fy, Fz, Mx, My, Mz]`` on the powertrain about its CG, engine axes [N, N·m].
    imep : ndarray, shape (n_cyl,)
        Net IMEP of each cylinder [Pa].
    info : dict
        Model details (intake pressure, heat released ...).
    """

    rpm: float
    crank_angle: np.ndarray
    pressure: np.ndarray
    gas_force: np.ndarray
    inertia_force: np.ndarray
    torque: np.ndarray
    torque_gas: np.ndarray
    torque_inertia: np.ndarray
    load: np.ndarray
    imep: np.ndarray
    info: dict

    def order_spectrum(self, max_order: float = 8.0):
        """Orders and complex amplitudes of the load; the crank angles must sample
        ``[0, 4π)`` equally spaced.

        Returns
        -------
        orders : ndarray
            0, 0.5, 1, ... ``max_order`` (per crank revolution).
        amplitudes : ndarray of complex, shape (n_orders, 6)
            Complex amplitude of each load component [N, N·m] (order 0: the mean).
        """
        spec = harmonic_amplitudes(self.load, axis=0)
        n_h = int(round(2 * max_order)) + 1
        return np.arange(n_h) / 2.0, spec[:n_h]


@dataclass(frozen=True, eq=False)
class Engine:
    """An engine-gearbox powertrain on its mounts, with its excitation.

    Attributes
    ----------
    name : str
    crank : CrankTrain or None
        None without ``[crank_train]`` (no excitation).
    body : RigidBody
    mounts : list of MountSpec
        Any number (>= 3) of mounts, in file order.
    balancer : Balancer
    combustion : SingleZoneCombustion or MeasuredPressure or None
        None without ``[combustion]`` (no excitation).
    file : str
        Engine file it was read from ("" if built in code).
    chassis : Chassis or None
        The body under the mounts (:mod:`powertrain.models.chassis`); None = rigid.
    gear_ratio : float
        Gear ratio of the run (``[drive] gear_ratio``) on the mean drive-torque reaction of
        the operating point, not on the order excitation [-].
    """

    name: str
    crank: CrankTrain
    body: RigidBody
    mounts: list
    balancer: Balancer
    combustion: object
    file: str = ""
    chassis: object = None
    gear_ratio: float = 1.0
    _cache: Memo = field(default_factory=Memo, init=False, repr=False, compare=False)

    def replace(self, **changes) -> Engine:
        """A copy with fields replaced (``dataclasses.replace``; its memo starts empty)."""
        return dataclasses.replace(self, **changes)

    def with_balancers(self, enabled: bool = True, mass_radius: float | None = None) -> Engine:
        """A copy with the balancer shafts on or off (and every shaft's unbalance
        ``mass_radius`` [kg·m] when given)."""
        shafts = self.balancer.shafts
        if mass_radius is not None:
            shafts = tuple(dataclasses.replace(s, mass_radius=float(mass_radius)) for s in shafts)
        return self.replace(balancer=dataclasses.replace(self.balancer, enabled=bool(enabled),
                                                         shafts=shafts))

    def with_imep_factors(self, factors) -> Engine:
        """A copy with per-cylinder IMEP factors (single-zone model only)."""
        factors = np.asarray(factors, dtype=float)
        if factors.shape != (self.crank.n_cylinders,):
            raise ValueError(f"expected {self.crank.n_cylinders} factors")
        return self.replace(combustion=dataclasses.replace(self.combustion,
                                                           imep_factors=factors))

    def at_load(self, load: float) -> Engine:
        """A copy at ``load`` times the nominal load (IMEP scale); load 1 returns ``self``."""
        if float(load) == 1.0:
            return self
        return self.replace(combustion=LoadedCombustion(self.combustion, float(load)))

    def motored(self, intake_pressure=None) -> Engine:
        """A copy (memoised) whose cylinders run without burn from ``intake_pressure`` [Pa]
        (None: the model's default); it shares this one's geometry-only load patterns."""
        if (key := ("motored", intake_pressure)) not in self._cache:
            out = self.replace(combustion=MotoredCombustion(self.combustion, intake_pressure))
            if "load patterns" in self._cache:
                out._cache["load patterns"] = self._cache["load patterns"]
            self._cache[key] = out
        return self._cache[key]

    @property
    def mount_names(self) -> list:
        return [m.name for m in self.mounts]

    def mount(self, name: str) -> MountSpec:
        """The mount called ``name``."""
        for m in self.mounts:
            if m.name == name:
                return m
        raise KeyError(name)

    def mount_section(self, element: str):
        """``(file, key)`` of the mount direction ``element`` (``"left.y"``): its mount file and
        ``amplitude`` or ``friction``; the engine file and ``engine`` where unknown."""
        name, _, direction = element.rpartition(".")
        try:
            mount = self.mount(name)
            model = mount.directions[direction]
        except KeyError:
            return self.file, "engine"
        law = getattr(model, "amplitude_law", None)
        key = "amplitude" if law is not None and not law.constant else "friction"
        return mount.files.get(direction, self.file), key

    def require_excitation(self):
        """Raise :class:`~powertrain.errors.InputError` when the excitation is missing."""
        for section, value in (("crank_train", self.crank), ("combustion", self.combustion)):
            if value is None:
                raise InputError(f"missing section [{section}]: this command needs the "
                                 "engine's excitation", file=self.file or None, key=section)

    def speed_range_rpm(self):
        """Speeds [rpm] for which the combustion model is defined."""
        self.require_excitation()
        lo, hi = self.combustion.speed_range()
        return lo / RPM, hi / RPM

    def _check_speed(self, rpm):
        rpm = float(rpm)
        lo, hi = self.speed_range_rpm()
        if not np.isfinite(rpm) or not lo - 1e-6 <= rpm <= hi + 1e-6:
            key = getattr(self.combustion, "speed_key", "combustion.traces")
            raise InputError(f"engine speed {rpm:g} rpm outside the model's range "
                             f"{lo:g}..{hi:g} rpm", file=self.file or None, key=key)
        return rpm

    def cycle_pressures(self, rpm: float, load: float = 1.0):
        """Grid, pressures and model info of every cylinder (cached per speed and load)."""
        rpm = self._check_speed(rpm)
        key = (rpm, float(load))
        kept = self._cache.setdefault("cycle pressures", {})
        if key not in kept:
            if len(kept) > 64:
                kept.clear()
            kept[key] = self.combustion.cycle_pressures(self.crank, rpm * RPM, load)
        return kept[key]

    def cylinder_pressure(self, rpm: float, crank_angle_rad, load: float = 1.0) -> np.ndarray:
        """Absolute pressure [Pa] of every cylinder, ``(n, n_cyl)``, at cylinder-1 crank angles
        [rad] (periodic over 4π, linear between grid points)."""
        return self.cylinder_pressures([rpm], crank_angle_rad, load)[0]

    def cylinder_pressures(self, speeds_rpm, crank_angle_rad, load: float = 1.0) -> np.ndarray:
        """:meth:`cylinder_pressure` at every speed [rpm], shape ``(n_speeds, n, n_cyl)``."""
        return self.pressure_tables(speeds_rpm, crank_angle_rad, [load])[0]

    def pressure_tables(self, speeds_rpm, crank_angle_rad, loads) -> np.ndarray:
        """:meth:`cylinder_pressure` at every load [-] and speed [rpm],
        ``(n_loads, n_speeds, n, n_cyl)``."""
        local = self.local_angles(crank_angle_rad)
        speeds = np.atleast_1d(speeds_rpm)
        cycles = [[self.cycle_pressures(n, load) for n in speeds] for load in loads]
        theta_g = cycles[0][0][0]
        if any(not np.array_equal(c[0], theta_g) for row in cycles for c in row):
            return np.array([[self.cylinder_pressure(n, crank_angle_rad, load) for n in speeds]
                             for load in loads])
        i0, i1, w = _periodic_interpolation(local, theta_g, 4.0 * np.pi)
        out = np.empty((len(cycles), speeds.size) + local.shape)
        for j, row in enumerate(cycles):
            for s, (_, p, _) in enumerate(row):
                cylinder_pressures(kernel_input(p), i0, i1, w, out[j, s])
        return out

    def local_angles(self, crank_angle_rad) -> np.ndarray:
        """Each cylinder's cycle angle on ``[-π, 3π)`` [rad], shape ``(n, n_cyl)``."""
        th = np.atleast_1d(np.asarray(crank_angle_rad, dtype=float))
        local = th[:, None] - self.crank.firing_angles[None, :]
        return np.mod(local + np.pi, 4.0 * np.pi) - np.pi

    def excitation(self, rpm: float, crank_angle_rad=None, load: float = 1.0,
                   n_points: int = 1440) -> Excitation:
        """Pressures, per-cylinder forces and torques and the total load at one speed.

        Parameters
        ----------
        rpm : float
            Engine speed [rpm] (constant).
        crank_angle_rad : array_like, optional
            Cylinder-1 crank angles [rad]; default ``n_points`` equally spaced on ``[0, 4π)``.
        load : float
            Fraction of the full-load torque [-].
        n_points : int
            Number of default crank angles.
        """
        if crank_angle_rad is None:
            crank_angle_rad = 4.0 * np.pi * np.arange(n_points) / n_points
        return self._evaluate(rpm, crank_angle_rad, load, detail=True)

    def _evaluate(self, rpm, crank_angle_rad, load, detail):
        th = np.atleast_1d(np.asarray(crank_angle_rad, dtype=float))
        ct = self.crank
        omega = self._check_speed(rpm) * RPM
        p = self.cylinder_pressure(rpm, th, load)
        fg = (p - ct.crankcase_pressure) * ct.piston_area
        total, out = self._block_load(th, omega, fg)
        if not detail:
            return total
        info = self.cycle_pressures(rpm, load)[2]
        imep = self.indicated_work(rpm, load) / ct.swept_volume
        return Excitation(rpm=float(rpm), crank_angle=th, pressure=p, gas_force=fg,
                          inertia_force=out["inertia"], torque=out["torque"],
                          torque_gas=out["torque_gas"], torque_inertia=out["torque_inertia"],
                          load=total, imep=imep, info=dict(info))

    def _load_patterns(self, th):
        """Block loads of a unit gas force per cylinder (list of (n, 6)) and of a unit omega^2."""
        unit = np.eye(self.crank.n_cylinders)
        gas = [self._block_load(th, 0.0, np.broadcast_to(u, (th.size, unit.shape[0])))[0]
               for u in unit]
        return gas, self._block_load(th, 1.0, np.zeros((th.size, unit.shape[0])))[0]

    def motion_patterns(self, crank_angle_rad):
        """Generalized loads (n, 6) of a unit omega^2 and of a unit crank acceleration at the
        angles [rad], without gas force (cached for the last grid)."""
        th = np.atleast_1d(np.asarray(crank_angle_rad, dtype=float))
        inertia = self._cache.last_grid("load patterns", th, self._load_patterns)[1]
        return inertia, self._cache.last_grid("acceleration pattern", th,
                                              self._acceleration_pattern)

    def _acceleration_pattern(self, th):
        return self._block_load(th, 0.0, np.zeros((th.size, self.crank.n_cylinders)), 1.0)[0]

    def _block_load(self, th, omega, fg, alpha=0.0):
        r"""Generalized load (n, 6) on the block and the per-cylinder forces of
        :func:`~powertrain.physics.slider_crank.crank_forces`; linear in the gas forces ``fg``,
        in omega^2 and in alpha (the latter not on the balancer shafts). The force is
        :math:`\sum_c (a_c\mathbf u + b_c\mathbf s)`, the moment about the CG adds the side
        thrust's and the pin offset's couple :math:`(y N + e F_g)\,\mathbf s\times\mathbf u`,
        with :math:`a_c = F_g - F_r\cos\beta + m_r r(\omega^2\cos\theta_c + \alpha\sin\theta_c)`,
        :math:`b_c = m_r r(\omega^2\sin\theta_c - \alpha\cos\theta_c)`."""
        ct = self.crank
        u, s = ct.cylinder_axis, ct.lateral_axis
        theta = th[:, None] - np.asarray(ct.crank_pin_angles, float)[None, :]
        k = sc.crank_forces(theta, omega, fg, ct.crank_radius, ct.rod_length, ct.pin_offset,
                            ct.reciprocating_mass, alpha)
        m_r = (1.0 - ct.counterweight_fraction) * ct.rotating_mass * ct.crank_radius
        cos, sin = np.cos(theta), np.sin(theta)
        a = fg - k["rod"] * np.cos(k["beta"]) + m_r * (omega**2 * cos + alpha * sin)
        b = m_r * (omega**2 * sin - alpha * cos)
        x = np.asarray(ct.cylinder_x, float)
        ex, cg = np.array([1.0, 0.0, 0.0]), self.body.cg
        arm_a = (a @ x)[:, None] * ex - a.sum(axis=1)[:, None] * cg
        arm_b = (b @ x)[:, None] * ex - b.sum(axis=1)[:, None] * cg
        force = np.outer(a.sum(axis=1), u) + np.outer(b.sum(axis=1), s)
        moment = (np.cross(arm_a, u) + np.cross(arm_b, s)
                  + np.outer(np.sum(k["y"] * k["side"] + ct.pin_offset * fg, axis=1),
                             np.cross(s, u)))
        if self.balancer.enabled:
            for sh in self.balancer.shafts:
                f_u, f_s = bal.shaft_force(th, omega, sh.mass_radius, sh.phase, sh.sense,
                                           self.balancer.ratio)
                f = np.outer(f_u, u) + np.outer(f_s, s)
                force = force + f
                moment = moment + np.cross(sh.position - cg, f)
        out = {name: k[name] for name in ("inertia", "torque", "torque_gas", "torque_inertia")}
        return np.hstack([force, moment]), out

    def indicated_work(self, rpm: float, load: float = 1.0) -> np.ndarray:
        r"""Net indicated work per cycle of every cylinder, :math:`W_i = \oint p_i\,dV` [J]."""
        theta_g, p_g, _ = self.cycle_pressures(rpm, load)
        key = ("dV", theta_g.size, float(theta_g[0]), float(theta_g[-1]))
        if key not in self._cache:                   # the same grid at every speed
            self._cache[key] = self.crank.volume(theta_g)[1]
        dtheta = theta_g[1] - theta_g[0]
        return comb.indicated_work(np.atleast_2d(p_g), self._cache[key], dtheta)

    def mean_brake_torque(self, rpm: float, load: float = 1.0) -> float:
        r"""Mean brake torque [N·m]: :math:`(\sum_i W_i - \mathrm{FMEP}\,V_D)/(4\pi)` (FMEP
        from the combustion model, zero for measured traces)."""
        fmep = self.combustion.friction_mean_effective_pressure(self._check_speed(rpm) * RPM)
        work = float(np.sum(self.indicated_work(rpm, load)))
        return (work - fmep * self.crank.displacement) / (4.0 * np.pi)

    def generalized_load(self, rpm: float, crank_angle_rad, load: float = 1.0) -> np.ndarray:
        """``[Fx, Fy, Fz, Mx, My, Mz]`` on the powertrain about its CG, engine axes.

        Parameters
        ----------
        rpm : float
            Engine speed [rpm].
        crank_angle_rad : array_like, shape (n,)
            Cylinder-1 crank angle [rad]; the load is periodic over 4π.
        load : float
            Fraction of full-load torque [-] (default full load).

        Returns
        -------
        ndarray, shape (n, 6)
            [N, N, N, N·m, N·m, N·m].
        """
        return self._evaluate(rpm, crank_angle_rad, load, detail=False)

    def load_table(self, speeds_rpm, crank_angle_rad, load: float = 1.0) -> np.ndarray:
        """:meth:`generalized_load` (n_speeds, n, 6) at every speed [rpm] and angle [rad], to
        round-off, as sum_i F_g,i G_i + omega^2 I from load patterns evaluated once."""
        return self.load_tables(speeds_rpm, crank_angle_rad, [load])[0]

    def load_tables(self, speeds_rpm, crank_angle_rad, loads) -> np.ndarray:
        """:meth:`load_table` at every load [-], shape (n_loads, n_speeds, n, 6)."""
        th = np.atleast_1d(np.asarray(crank_angle_rad, dtype=float))
        speeds = np.atleast_1d(np.asarray(speeds_rpm, dtype=float))
        ct = self.crank
        gas, inertia = self._cache.last_grid("load patterns", th, self._load_patterns)
        fg = (self.pressure_tables(speeds, th, loads) - ct.crankcase_pressure) * ct.piston_area
        table = np.empty(fg.shape[:-1] + (6,))
        gas_table(*(kernel_input(a) for a in (fg, np.asarray(gas), inertia,
                                              (speeds * RPM) ** 2)), table)
        return table

    def assemble(self, static_factors=None, *, rigid_ground=False):
        """The assembled linear model of body, mounts and chassis
        (:func:`powertrain.assembly.assemble`).

        Parameters
        ----------
        static_factors : array_like (3 n_mounts,), optional
            Each network's static factor at an operating point; None: unscaled.
        rigid_ground : bool
            Mounts on rigid ground whatever the chassis.
        """
        b = self.body
        chassis = None if rigid_ground else self.chassis
        return assemble(b.mass, b.cg, b.inertia, self.mounts, chassis, static_factors)

    def rigid_body_modes(self):
        """Natural frequencies [Hz] and mode shapes on the mounts' static stiffness (undamped,
        rigid chassis)."""
        return self.assemble(rigid_ground=True).rigid_body_modes()


def _periodic_interpolation(x, xp, period):
    """``(i0, i1, w)`` with ``fp[i0] (1 - w) + fp[i1] w`` equal to
    ``np.interp(x, xp, fp, period=period)``."""
    xp_m = np.mod(xp, period)
    order = np.argsort(xp_m, kind="stable")
    xs = np.concatenate([[xp_m[order[-1]] - period], xp_m[order], [xp_m[order[0]] + period]])
    idx = np.concatenate([[order[-1]], order, [order[0]]])
    x_m = np.mod(x, period)
    j = np.clip(np.searchsorted(xs, x_m, side="right") - 1, 0, xs.size - 2)
    w = (x_m - xs[j]) / (xs[j + 1] - xs[j])
    return idx[j], idx[j + 1], w
