r"""The truth simulator of the blind benchmark: an independent numerical path.

The diagnosis fits its candidates with the frequency-domain harmonic model
(:mod:`powertrain.solvers.fast_harmonic`, the mount networks condensed into two-ports) and
the effects' own parametrisations. The truth is made differently:

* **assembly** — written here, not :func:`powertrain.assembly.assemble`: every mount network
  keeps its ground node (:func:`~powertrain.physics.mount_network.network_matrices` with
  ``include_ground=True``), which is either fixed or tied to a *chassis base*; the
  powertrain may carry a *bending* degree of freedom;
* **solver** — time integration: :func:`powertrain.workflows.runup.run_runup` with the Newmark
  solver (average acceleration, 1° crank steps, 6 cycles, the last 2 order-analysed) on the
  system assembled here;
* **effects** — physical models of their own (:class:`TruthSpec`), parametrised unlike the
  candidates:

  - mount temperature: per mount *and direction* spring factors ``s``, dampers ``s**0.7``;
  - amplitude-dependent elastomer: springs times :math:`(a/a_\mathrm{ref})^{-\beta}` per mount
    type, :math:`a` the engine-side peak displacement of the previous pass (fixed point,
    :data:`AMPLITUDE_PASSES` passes, :math:`a \ge 1\,\mu m`), dampers unchanged;
  - balancer: per-shaft unbalance factor and per-shaft angle error;
  - weak cylinder: the *combustion part* of that cylinder's pressure trace (trace minus its
    polytropic motored pressure, fitted on the compression stroke) scaled so that its IMEP
    drops by the given fraction, and retarded by a small angle — for single-zone and
    measured-trace engines alike;
  - chassis: a base mass under every mount with its own three springs, all bases on one or
    two global chassis modes (random shapes);
  - body modes (:class:`BodyModes`): the mount bases directly on a vehicle body's modes,
    each mode's frequency, modal mass, damping and shape its own; with ``passive`` the
    body side of every mount is output too (base node or attachment-point motion), as a
    test lab measures both sides;
  - sensors: per-channel gain, triad rotation and cross-axis sensitivity (a 3×3 matrix per
    triad); a sensor bracket's resonance (base-excitation transmissibility);
  - powertrain bending: a flexible degree of freedom of the gearbox part, inertially coupled
    to the rigid body, moving the mount points.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.channel import passive_name
from powertrain.assembly import AssembledSystem
from powertrain.physics.combustion import indicated_work

#: Reference amplitude of the mount data [m] (mount files are measured at 0.1 mm).
AMPLITUDE_REF = 1.0e-4
#: Smallest amplitude used in the power law [m].
AMPLITUDE_MIN = 1.0e-6
#: Passes of the amplitude fixed point after the linear run.
AMPLITUDE_PASSES = 2
#: Newmark settings of the truth (the run-up defaults: 1 deg, 6 cycles, last 2 processed).
NEWMARK = {"solver": "newmark", "angle_step_deg": 1.0, "cycles": 6, "processed_cycles": 2}


@dataclass(frozen=True)
class ChassisBase:
    """A compliant chassis under the mounts.

    Attributes
    ----------
    mass : ndarray (n_mounts,)
        Base mass under each mount [kg].
    stiffness : ndarray (n_mounts, 3)
        Springs from each base to the chassis along engine X, Y, Z [N/m].
    zeta : float
        Damping ratio of the base springs [-].
    mode_hz, modal_mass : ndarray (n_modes,)
        Global chassis modes [Hz] and modal masses [kg].
    shapes : ndarray (n_modes, n_mounts, 3)
        Chassis motion at each base per unit modal coordinate [-].
    mode_zeta : float
        Damping ratio of the chassis modes [-].
    """

    mass: np.ndarray
    stiffness: np.ndarray
    zeta: float
    mode_hz: np.ndarray
    modal_mass: np.ndarray
    shapes: np.ndarray
    mode_zeta: float


@dataclass(frozen=True)
class BodyModes:
    """A vehicle body whose modes the mount bases sit on directly (no base mass between).

    Attributes
    ----------
    mode_hz, modal_mass, zeta : ndarray (n_modes,)
        [Hz], [kg], [-].
    shapes : ndarray (n_modes, n_mounts, 3)
        Body motion at each mount's attachment point per unit modal coordinate, engine
        axes [-].
    """

    mode_hz: np.ndarray
    modal_mass: np.ndarray
    zeta: np.ndarray
    shapes: np.ndarray


@dataclass(frozen=True)
class BendingMode:
    """Engine-gearbox bending: the gearbox part (mass ``mass`` at ``point``) moves by
    ``shape_point`` η relative to the rigid body; mount points move by ``shape_mounts`` η.

    Attributes: ``frequency_hz`` [Hz], ``zeta`` [-], ``mass`` [kg], ``point`` (3,) [m, engine
    axes], ``shape_point`` (3,) [-], ``shape_mounts`` (n_mounts, 3) [-].
    """

    frequency_hz: float
    zeta: float
    mass: float
    point: np.ndarray
    shape_point: np.ndarray
    shape_mounts: np.ndarray


@dataclass(frozen=True)
class TruthSpec:
    """Everything the truth differs in from the baseline engine.

    Attributes
    ----------
    engine : Engine
        Engine whose load is used (balancer or combustion already modified).
    mounts : list of MountSpec
        Mounts (elastomer already modified).
    chassis : ChassisBase or None
    bending : BendingMode or None
    amplitude_beta : ndarray (n_mounts,) or None
        Exponent of the amplitude power law per mount [-].
    sensor : list of callables or empty
        Each maps ``(velocity (n_r, n_ch, n_o) complex, frequency_hz (n_r, n_o))`` to the
        reading.
    """

    engine: object
    mounts: list
    chassis: ChassisBase | None = None
    bending: BendingMode | None = None
    amplitude_beta: np.ndarray | None = None
    sensor: list = field(default_factory=list)
    #: a modal body under the mounts (bases directly on its modes)
    body: BodyModes | None = None
    #: also output every mount's body side (channels ``NAME/passive``, after the engine side)
    passive: bool = False


# ----------------------------------------------------------------------- assembly
def _point_row(r, e):
    """Row mapping the rigid-body coordinates (u, θ) to the motion of point r along e (the
    cross product r × e written out: the same products as ``np.cross``, without its
    overhead on 3-vectors, paid at every assembly of the amplitude truth)."""
    return np.array([e[0], e[1], e[2], r[1] * e[2] - r[2] * e[1], r[2] * e[0] - r[0] * e[2],
                     r[0] * e[1] - r[1] * e[0]], float)


def _rigid_mass(body):
    M = np.zeros((6, 6))
    M[:3, :3] = body.mass * np.eye(3)
    M[3:, 3:] = np.asarray(body.inertia, float)
    return M


def _layout(mounts, chassis, bending, body=None):
    """Index of the first bending, network, base and chassis-mode (or body-mode)
    coordinates."""
    n_int = sum(mt.directions[a].network()[0].size for mt in mounts for a in "xyz")
    i_bend = 6
    i_net = i_bend + (1 if bending is not None else 0)
    i_base = i_net + n_int
    i_mode = i_base + (3 * len(mounts) if chassis is not None else 0)
    n = i_mode + (len(chassis.mode_hz) if chassis is not None else 0)
    n += len(body.mode_hz) if body is not None else 0
    return i_bend, i_net, i_base, i_mode, n


def assemble_truth(body, mounts, chassis=None, bending=None, modes=None,
                   passive=False) -> AssembledSystem:
    """Linear model of the rigid powertrain on its mount networks, with optional chassis
    bases, body modes ``modes`` (:class:`BodyModes`; not with ``chassis``) and bending mode
    (see the module docstring). ``passive``: the body side of every mount as further
    channels (``NAME/passive``). Force outputs are left zero."""
    if chassis is not None and modes is not None:
        raise ValueError("chassis bases and body modes are exclusive")
    i_bend, i_net, i_base, i_mode, n = _layout(mounts, chassis, bending, modes)
    M, C, K = (np.zeros((n, n)) for _ in range(3))
    M[:6, :6] = _rigid_mass(body)
    cg = np.asarray(body.cg, float)
    start = i_net
    for m, mt in enumerate(mounts):
        r = np.asarray(mt.position, float) - cg
        R = np.asarray(mt.rotation, float)
        for a, axis in enumerate("xyz"):
            e = R[:, a]
            Mn, Cn, Kn = mt.directions[axis].matrices(include_ground=True)
            ni = Mn.shape[0] - 2
            L = np.zeros((ni + 2, n))
            L[0, :6] = _point_row(r, e)
            if bending is not None:
                L[0, i_bend] = e @ bending.shape_mounts[m]
            L[1:ni + 1, start:start + ni] = np.eye(ni)
            if chassis is not None:
                L[ni + 1, i_base + 3 * m:i_base + 3 * m + 3] = e
            elif modes is not None:
                L[ni + 1, i_mode:] = modes.shapes[:, m, :] @ e
            for G, g in ((M, Mn), (C, Cn), (K, Kn)):
                G += L.T @ g @ L
            start += ni
    if chassis is not None:
        _add_chassis(M, C, K, chassis, i_base, i_mode, len(mounts))
    if modes is not None:
        _add_body_modes(M, C, K, modes, i_mode)
    if bending is not None:
        _add_bending(M, C, K, bending, cg, i_bend)
    channels = [(mt.name, a) for mt in mounts for a in "xyz"]
    Cm = np.zeros((len(channels), n))
    for m, mt in enumerate(mounts):
        r = np.asarray(mt.position, float) - cg
        for a in range(3):
            Cm[3 * m + a, :6] = _point_row(r, np.eye(3)[a])
            if bending is not None:
                Cm[3 * m + a, i_bend] = bending.shape_mounts[m][a]
    if passive:
        channels, Cm = _passive_outputs(channels, Cm, mounts, chassis, modes, i_base, i_mode)
    Z = np.zeros_like(Cm)
    return AssembledSystem(M, C, K, channels, Cm, Z, Z.copy())


def _add_chassis(M, C, K, ch: ChassisBase, i_base, i_mode, n_mounts):
    for k, (f, mu) in enumerate(zip(ch.mode_hz, ch.modal_mass)):
        w = 2 * np.pi * f
        j = i_mode + k
        M[j, j] += mu
        K[j, j] += mu * w ** 2
        C[j, j] += 2 * ch.mode_zeta * mu * w
    for m in range(n_mounts):
        for a in range(3):
            j = i_base + 3 * m + a
            M[j, j] += ch.mass[m]
            row = np.zeros(M.shape[0])
            row[j] = 1.0
            row[i_mode:i_mode + len(ch.mode_hz)] = -ch.shapes[:, m, a]
            k = ch.stiffness[m, a]
            c = 2 * ch.zeta * np.sqrt(k * ch.mass[m])
            K += k * np.outer(row, row)
            C += c * np.outer(row, row)


def _add_body_modes(M, C, K, modes: BodyModes, i_mode):
    for k, (f, mu, z) in enumerate(zip(modes.mode_hz, modes.modal_mass, modes.zeta)):
        w = 2 * np.pi * f
        j = i_mode + k
        M[j, j] += mu
        K[j, j] += mu * w ** 2
        C[j, j] += 2 * z * mu * w


def _passive_outputs(channels, Cm, mounts, chassis, modes, i_base, i_mode):
    """Channels and output rows with the body side of every mount appended: the base node
    (chassis bases), the body's motion at the attachment point (body modes), or zero
    (rigid ground)."""
    rows = np.zeros((3 * len(mounts), Cm.shape[1]))
    for m in range(len(mounts)):
        for a in range(3):
            if chassis is not None:
                rows[3 * m + a, i_base + 3 * m + a] = 1.0
            elif modes is not None:
                rows[3 * m + a, i_mode:] = modes.shapes[:, m, a]
    names = [(passive_name(mt.name), a) for mt in mounts for a in "xyz"]
    return channels + names, np.vstack([Cm, rows])


def _add_bending(M, C, K, b: BendingMode, cg, i):
    r = np.asarray(b.point, float) - cg
    P = np.array([_point_row(r, np.eye(3)[a]) for a in range(3)])     # (3, 6)
    w = 2 * np.pi * b.frequency_hz
    M[i, i] += b.mass
    coupling = b.mass * (b.shape_point @ P)
    M[i, :6] += coupling
    M[:6, i] += coupling
    K[i, i] += b.mass * w ** 2
    C[i, i] += 2 * b.zeta * b.mass * w


# ----------------------------------------------------------------------- run-up
def simulate_truth(spec: TruthSpec, rpm):
    """Noise-free truth: complex velocity amplitudes (n_r, n_ch, 16) [m/s, peak] of the
    measured channels, by Newmark run-up on the truth assembly."""
    from powertrain.workflows.runup import run_runup
    rpm = np.asarray(rpm, float)
    body = spec.engine.body
    if spec.amplitude_beta is None:
        sys_ = assemble_truth(body, spec.mounts, spec.chassis, spec.bending, spec.body,
                              spec.passive)
        res = run_runup(spec.engine, rpm, system=sys_, **NEWMARK)
        vel = res.velocity
    else:
        vel = _amplitude_runup(spec, rpm)
    freq = np.asarray(rpm)[:, None] / 60.0 * (np.arange(1, 17) * 0.5)[None, :]
    for reading in spec.sensor:
        vel = reading(vel, freq)
    return vel


def _amplitude_runup(spec: TruthSpec, rpm):
    """Equivalent linearisation of the amplitude power law, one assembly per speed."""
    from powertrain.workflows.runup import run_runup
    body = spec.engine.body
    sys0 = assemble_truth(body, spec.mounts, spec.chassis, spec.bending, spec.body,
                          spec.passive)
    res = run_runup(spec.engine, rpm, system=sys0, **NEWMARK)
    disp, vel = res.displacement, res.velocity
    factors = None
    for _ in range(AMPLITUDE_PASSES):
        new = _amplitude_factors(spec, disp)
        factors = new if factors is None else np.sqrt(factors * new)   # damped update
        for i, n_rpm in enumerate(rpm):
            mounts = [_scaled_mount(mt, factors[i, m]) for m, mt in enumerate(spec.mounts)]
            s = assemble_truth(body, mounts, spec.chassis, spec.bending, spec.body,
                               spec.passive)
            r = run_runup(spec.engine, [n_rpm], system=s, **NEWMARK)
            disp[i], vel[i] = r.displacement[0], r.velocity[0]
    return vel


def _amplitude_factors(spec, disp):
    """Spring factors (n_r, n_mounts, 3) from the engine-side peak displacement."""
    n_r = disp.shape[0]
    out = np.ones((n_r, len(spec.mounts), 3))
    for m, mt in enumerate(spec.mounts):
        R = np.asarray(mt.rotation, float)
        local = np.einsum("ja,rjo->rao", R, disp[:, 3 * m:3 * m + 3, :])
        a = np.sqrt(np.sum(np.abs(local) ** 2, axis=-1))
        a = np.maximum(a, AMPLITUDE_MIN)
        out[:, m, :] = (a / AMPLITUDE_REF) ** (-spec.amplitude_beta[m])
    return out


def _scaled_mount(mt, spring_factors):
    dirs = {ax: mt.directions[ax].scaled(stiffness=float(f), damping=1.0)
            for ax, f in zip("xyz", spring_factors)}
    return dataclasses.replace(mt, directions=dirs)


# ----------------------------------------------------------------------- effects
def mount_with_elastomer(mt, spring_factors):
    """Mount with its springs × ``spring_factors`` (per local direction) and its dampers ×
    factor**0.7 (the loss factor falls as the elastomer stiffens); masses kept."""
    dirs = {ax: mt.directions[ax].scaled(stiffness=float(f), damping=float(f) ** 0.7)
            for ax, f in zip("xyz", spring_factors)}
    return dataclasses.replace(mt, directions=dirs)


def engine_with_shaft_errors(engine, gains, angle_errors):
    """Balancer shafts with unbalance × ``gains`` and lagging by ``angle_errors`` [rad of
    shaft angle] (a lag turns the unbalance back against the shaft's sense)."""
    shafts = tuple(dataclasses.replace(s, mass_radius=s.mass_radius * g,
                                       phase=s.phase - s.sense * d)
                   for s, g, d in zip(engine.balancer.shafts, gains, angle_errors))
    return engine.replace(balancer=dataclasses.replace(engine.balancer, shafts=shafts))


@dataclass(frozen=True, eq=False)
class WeakCylinder:
    """Combustion model wrapper: cylinder ``cylinder`` (0-based) loses ``deficit`` of its
    IMEP by scaling the combustion part of its trace, retarded by ``retard`` [rad]."""

    base: object
    cylinder: int
    deficit: float
    retard: float = 0.0

    @property
    def model(self):
        return self.base.model

    def speed_range(self):
        return self.base.speed_range()

    def cycle_pressures(self, crank, omega, load=1.0):
        theta, p, info = self.base.cycle_pressures(crank, omega, load)
        p = np.array(p, float)
        V, dV = crank.volume(theta)
        pc = p[self.cylinder]
        part = combustion_part(theta, pc, V)
        shifted = np.interp(theta - self.retard, theta, part, period=4 * np.pi)
        dth = theta[1] - theta[0]
        w_all = indicated_work(pc, dV, dth)
        w_rest = indicated_work(pc - part, dV, dth)
        f = ((1 - self.deficit) * w_all - w_rest) / indicated_work(shifted, dV, dth)
        p[self.cylinder] = pc - part + f * shifted
        return theta, p, dict(info)


def combustion_part(theta, pressure, volume):
    """Pressure rise due to combustion [Pa]: the trace minus its polytropic motored pressure
    (exponent fitted on the compression stroke, −90° to −40°), tapered to zero from 100°
    to 160° after firing TDC and zero before −40°."""
    deg = np.rad2deg(theta)
    comp = (deg >= -90) & (deg <= -40)
    kappa = -np.polyfit(np.log(volume[comp]), np.log(pressure[comp]), 1)[0]
    j = int(np.argmin(np.abs(deg + 40)))
    motored = pressure[j] * (volume[j] / volume) ** kappa
    w = np.where((deg >= -40) & (deg <= 100), 1.0, 0.0)
    taper = (deg > 100) & (deg < 160)
    w[taper] = 0.5 * (1 + np.cos(np.pi * (deg[taper] - 100) / 60))
    return w * (pressure - motored)


def triad_reading(mount_index, matrix):
    """Sensor reading: the triad of mount ``mount_index`` reads ``matrix`` @ v."""
    T = np.asarray(matrix)

    def read(vel, freq):
        out = vel.copy()
        s = slice(3 * mount_index, 3 * mount_index + 3)
        out[:, s, :] = np.einsum("ij,rjo->rio", T, vel[:, s, :])
        return out
    return read


def bracket_reading(channels, frequency_hz, zeta):
    """Sensor on a bracket: channel readings times the base-excitation transmissibility
    :math:`(\\omega_s^2 + 2i\\zeta\\omega_s\\omega)/(\\omega_s^2 - \\omega^2 + 2i\\zeta\\omega_s\\omega)`."""
    ws = 2 * np.pi * frequency_hz

    def read(vel, freq):
        w = 2 * np.pi * freq
        T = (ws ** 2 + 2j * zeta * ws * w) / (ws ** 2 - w ** 2 + 2j * zeta * ws * w)
        out = vel.copy()
        for c in channels:
            out[:, c, :] = vel[:, c, :] * T
        return out
    return read
