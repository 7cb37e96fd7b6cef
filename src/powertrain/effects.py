r"""Unmodelled effects as model extensions: a small library of candidates for the sim-to-real gap.

Each effect is a physical extension of the baseline model with a few bounded parameters whose
defaults reduce it to the baseline. The registry :data:`EFFECTS` gives for each its name,
parameter names, bounds, defaults and units; every effect can be used

* on an :class:`~powertrain.models.engine.Engine` (``Engine -> Engine``, for ``runup``,
  ``compare`` and ``whatif``) where the effect is a change of the engine model:
  :func:`with_base_compliance_all`, :func:`with_mount_stiffness`,
  :func:`with_balancer_error`, :func:`with_cylinder_imbalance`;
* on the ordinary run-up, every effect (:func:`runup_with_effects`, behind
  ``powertrain runup --effect`` and ``powertrain whatif --effect``), including the two that
  are not a change of the linear model: ``amplitude_stiffness`` (an amplitude-dependent
  mount, equivalent linearisation iterated to consistency) and ``sensor_error`` (a
  measurement effect); :func:`simulate` is its harmonic-only shortcut;
* on the fast cached path :func:`predict` (one :class:`~powertrain.solvers.fast_harmonic.
  HarmonicModel`, many parameter sets), which the diagnosis uses.

Library (parameter bounds in :data:`EFFECTS`):

================== =========== ===================================================================
name               kind        physics
================== =========== ===================================================================
base_compliance    structure   every mount stands on a local chassis base: mass m_b on a spring
                               c_b (damping ratio ζ_b = 5 %) instead of the rigid ground
mount_stiffness    structure   each mount's elastomer times a factor k_i (temperature, preload,
                               part-to-part spread): its springs and dampers × k_i (constant
                               loss factor), its masses (fluid and rubber inertia) unchanged
amplitude_stiffness structure  the elastomer's stiffness depends on the engine-side amplitude a
                               (data at a_ref = 0.1 mm): springs and dampers × g(a),
                               g(a) = 1 + κ[1/(1 + a/a_c) − 1/(1 + a_ref/a_c)], masses kept
balancer_error     excitation  balancer shafts' unbalance times g (shaft-to-shaft difference
                               a), timing lag δ
cylinder_imbalance excitation  cylinder i delivers (1 + ε_i) times the nominal IMEP
sensor_error       sensor      each channel's sensor reads 10^(G_c/20) times the true level
                               (calibration), and each mount's triad is rotated by a small
                               rotation vector φ_m (mounting orientation): the triad reads
                               diag(10^(G/20)) R(φ_m) v, R by Rodrigues' formula
================== =========== ===================================================================

Equivalent linearisation (``amplitude_stiffness``): at each speed every network's springs
and dampers (its elastomer; the masses are kept, as in ``mount_stiffness``, whose factor
multiplies) are scaled by :math:`g(a_n)`, where
:math:`a_n = \sqrt{\sum_h |\hat x_{E,n,h}|^2}` is the engine-side peak displacement
(:math:`\sqrt2` × RMS sum of the orders) of network n; the solve is repeated with the updated
factors until they change by less than 1e-6 (fixed-point iteration with under-relaxation
0.7; at most 60 iterations). Its time-domain check (Newmark, stiffness updated once per engine
cycle from the RMS of the previous cycle) is :func:`time_domain_amplitude_check`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from powertrain.solvers.fast_harmonic import N_HARMONICS, HarmonicModel

#: Reference amplitude of the mount data (dynamic stiffness measured at 0.1 mm) [m].
A_REF = 1.0e-4
#: Damping ratio of the local base of ``base_compliance`` [1].
BASE_ZETA = 0.05


@dataclass(frozen=True)
class Parameter:
    """One bounded parameter of an effect.

    Attributes
    ----------
    name, unit, description : str
    lower, upper, default : float
        Bounds and the value that reduces the effect to the baseline (SI).
    log : bool
        Fitted in log space (positive, scale-like parameters).
    """

    name: str
    unit: str
    lower: float
    upper: float
    default: float
    log: bool = False
    description: str = ""


@dataclass(frozen=True)
class Effect:
    """A candidate unmodelled effect.

    Attributes
    ----------
    name : str
    kind : {"structure", "excitation", "sensor"}
    parameters : tuple of Parameter
    description : str
    apply : callable or None
        ``apply(engine, **params) -> Engine`` where the effect is an engine-model change.
    """

    name: str
    kind: str
    parameters: tuple
    description: str
    apply: object = None
    start_grid: tuple = field(default=())

    @property
    def parameter_names(self) -> list:
        return [p.name for p in self.parameters]

    def defaults(self) -> dict:
        return {p.name: p.default for p in self.parameters}

    def bounds(self):
        return (np.array([p.lower for p in self.parameters]),
                np.array([p.upper for p in self.parameters]))

    def applicable(self, engine) -> bool:
        """Whether the effect can act on ``engine``."""
        if self.name == "cylinder_imbalance":
            return getattr(engine.combustion, "model", "") == "single-zone"
        if self.name == "balancer_error":
            return len(engine.balancer.shafts) > 0
        if self.name == "mount_stiffness":
            return len(engine.mounts) <= 3
        return True

    def warm(self, hm):
        """Fill the parts of the cached model ``hm`` this effect needs."""
        if self.name == "balancer_error":
            hm.shaft_loads()
        if self.name == "cylinder_imbalance":
            hm.imep_derivatives()

    def to_dict(self) -> dict:
        return {"name": self.name, "kind": self.kind, "description": self.description,
                "parameters": [dataclasses.asdict(p) for p in self.parameters]}


# ----------------------------------------------------------------------- Engine -> Engine
def _map_networks(engine, fn):
    mounts = []
    for mi, m in enumerate(engine.mounts):
        mounts.append(dataclasses.replace(
            m, directions={ax: fn(mi, m, ax, mod) for ax, mod in m.directions.items()}))
    return engine.replace(mounts=mounts)


def with_base_compliance_all(engine, c_base=np.inf, m_base=10.0, zeta=BASE_ZETA):
    r"""Every mount network on a local compliant base (all mounts alike).

    Base of mass ``m_base`` [kg] on a spring ``c_base`` [N/m] with the damper
    :math:`d_b = 2\zeta\sqrt{c_b m_b}` [N·s/m]
    (:func:`powertrain.models.extensions.with_base_compliance`). ``c_base = inf`` (default)
    is the rigid ground: the engine is returned unchanged.
    """
    from powertrain.models.extensions import with_base_compliance
    if not np.isfinite(c_base):
        return engine
    d_base = 2 * zeta * np.sqrt(c_base * m_base)
    return _map_networks(engine, lambda mi, m, ax, mod: with_base_compliance(
        mod, m_base, c_base, d_base))


def with_mount_stiffness(engine, k1=1.0, k2=1.0, k3=1.0):
    r"""Mount i's elastomer stiffened by ``k<i>`` [1] (i = 1, 2, 3 in engine-file order;
    default engine: left, right, gearbox), all three directions alike.

    Temperature, preload and part-to-part spread change the rubber's modulus, and with a
    frequency-independent loss factor its damping in proportion; the fluid column of a
    hydromount and the lumped rubber masses keep their inertia. Every spring and damper of
    the mount's networks is therefore scaled by :math:`k_i` and every mass kept
    (:meth:`MountModel.scaled`): the network's dynamic stiffness becomes
    :math:`k_i(\mathbf K + i\omega\mathbf C) - \omega^2\mathbf M`, so its resonances
    (the hydromount's notch and peak) move by about :math:`\sqrt{k_i}` — unlike a plain
    factor on :math:`K_{CP}(\omega)`, which would keep them fixed and, above the engine's
    rigid-body modes, barely change the engine-side velocities.
    """
    k = (k1, k2, k3)
    return _map_networks(engine, lambda mi, m, ax, mod: mod.scaled(k[mi], k[mi])
                         if mi < 3 else mod)


def with_network_elastomer(engine, factors):
    """Every network's springs and dampers times its own factor (network order: mount-major
    x, y, z, as :attr:`HarmonicModel.networks`), masses kept (:meth:`MountModel.scaled`)."""
    f = iter(np.asarray(factors, float).ravel())
    return _map_networks(engine, lambda mi, m, ax, mod: mod.scaled(*(2 * (float(next(f)),))))


def _shaft_factors(n, gain, asym):
    """Unbalance factor of each shaft: ``gain (1 ± asym/2)``, + for the first half of the
    shafts (file order), − for the others (two shafts: first +, second −)."""
    sign = np.where(np.arange(n) < n / 2.0, 1.0, -1.0) if n > 1 else np.zeros(n)
    return gain * (1.0 + 0.5 * asym * sign)


def with_balancer_error(engine, gain=1.0, lag=0.0, asym=0.0):
    r"""Balancer shafts' unbalance times ``gain`` [1], shaft-to-shaft unbalance difference
    ``asym`` [1] (first shaft × (1 + asym/2), second × (1 − asym/2): the forces of the
    counter-rotating pair no longer cancel sideways), and the drive lagging by ``lag`` [rad]
    of shaft angle: :math:`\alpha = \sigma(\rho\theta - \delta) + \phi`, a pure delay of the
    balancer force (its complex order amplitude times :math:`g e^{-i\delta}`)."""
    f = _shaft_factors(len(engine.balancer.shafts), gain, asym)
    shafts = tuple(dataclasses.replace(s, mass_radius=s.mass_radius * fk,
                                       phase=s.phase - s.sense * lag)
                   for s, fk in zip(engine.balancer.shafts, f))
    return engine.replace(balancer=dataclasses.replace(engine.balancer, shafts=shafts))


def with_cylinder_imbalance(engine, e1=0.0, e2=0.0, e3=0.0, e4=0.0):
    """Cylinder i's IMEP times (1 + e<i>) [1] (single-zone combustion only)."""
    base = np.asarray(engine.combustion.imep_factors, float)
    eps = np.array([e1, e2, e3, e4][:base.size])
    return engine.with_imep_factors(base * (1.0 + eps))


def amplitude_factor(a, kappa, a_c):
    r"""Stiffness factor of ``amplitude_stiffness``:
    :math:`g(a) = 1 + \kappa\,[1/(1 + a/a_c) - 1/(1 + a_{ref}/a_c)]`, g(a_ref) = 1.

    Parameters
    ----------
    a : array_like
        Engine-side peak displacement [m].
    kappa : float
        Stiffening from large to vanishing amplitude [1] (0 = none).
    a_c : float
        Characteristic amplitude [m].
    """
    a = np.asarray(a, float)
    return 1.0 + kappa * (1.0 / (1.0 + a / a_c) - 1.0 / (1.0 + A_REF / a_c))


# ----------------------------------------------------------------------- registry
EFFECTS: dict = {e.name: e for e in [
    Effect("base_compliance", "structure",
           (Parameter("c_base", "N/m", 1.0e5, 2.0e7, 2.0e7, True,
                      "base (chassis) stiffness under each mount; the upper bound (the "
                      "default) is the rigid ground"),
            Parameter("m_base", "kg", 1.0, 60.0, 10.0, True,
                      "base (chassis) mass at each mount")),
           "local compliant chassis base under every mount (rigid ground at c_base -> inf)",
           with_base_compliance_all,
           start_grid=((1.5e5, 4e5, 1e6, 3e6), (2.0, 6.0, 15.0, 40.0))),
    Effect("mount_stiffness", "structure",
           tuple(Parameter(f"k{i}", "1", 0.3, 3.0, 1.0, True,
                           f"elastomer (spring and damper) factor of mount {i} (file "
                           f"order); its masses unchanged")
                 for i in (1, 2, 3)),
           "per-mount elastomer stiffness offset (temperature, preload, spread): springs "
           "and dampers scaled, fluid and rubber inertia kept",
           with_mount_stiffness, start_grid=((0.5, 1.0, 2.0),) * 3),
    Effect("amplitude_stiffness", "structure",
           (Parameter("kappa", "1", 0.0, 3.0, 0.0, False,
                      "stiffening from large to vanishing amplitude"),
            Parameter("a_c", "m", 1.0e-6, 1.0e-3, 2.0e-5, True, "characteristic amplitude")),
           "amplitude-dependent mount stiffness, equivalent linearisation iterated to "
           "consistency (mount data at 0.1 mm)", None,
           start_grid=((0.3, 1.0, 2.0), (3e-6, 2e-5, 1.5e-4))),
    Effect("balancer_error", "excitation",
           (Parameter("gain", "1", 0.0, 2.0, 1.0, False, "balancer unbalance factor"),
            Parameter("lag", "rad", -0.7, 0.7, 0.0, False, "balancer timing lag"),
            Parameter("asym", "1", -0.8, 0.8, 0.0, False,
                      "unbalance difference between the shafts (first - second, relative)")),
           "balancer shafts' unbalance, shaft-to-shaft difference and timing error",
           with_balancer_error,
           start_grid=((0.6, 1.0, 1.4), (-0.35, 0.0, 0.35), (-0.3, 0.3))),
    Effect("cylinder_imbalance", "excitation",
           tuple(Parameter(f"e{i}", "1", -0.25, 0.25, 0.0, False,
                           f"relative IMEP deviation of cylinder {i}") for i in (1, 2, 3, 4)),
           "cylinder-to-cylinder IMEP differences (half and first orders); linearised load",
           with_cylinder_imbalance, start_grid=((-0.06, 0.06),) * 4),
    Effect("sensor_error", "sensor",
           tuple(Parameter(f"g{c}", "dB", -8.0, 8.0, 0.0, False,
                           f"gain error of channel {c} (mount-major x, y, z)")
                 for c in range(1, 10))
           + tuple(Parameter(f"r{m}{ax}", "rad", -0.15, 0.15, 0.0, False,
                             f"orientation error of the triad at mount {m}: rotation about "
                             f"engine {ax.upper()}")
                   for m in (1, 2, 3) for ax in "xyz"),
           "per-channel sensor gain (calibration) and per-triad orientation (mounting) "
           "errors", None),
]}


# ----------------------------------------------------------------------- fast path
@dataclass
class Prediction:
    """Complex channel velocities of a scenario on a :class:`HarmonicModel`.

    Attributes
    ----------
    velocity : ndarray (n_r, n_ch, 16) complex
        Peak amplitudes of orders 0.5..8 [m/s].
    iterations : int
        Fixed-point iterations of the equivalent linearisation (0 if none).
    factors : ndarray (n_r, n_net) or None
        Amplitude factors g(a_n) at convergence.
    """

    velocity: np.ndarray
    iterations: int = 0
    factors: np.ndarray | None = None


def _elastomer_factors(hm, scenario):
    """Per-network elastomer factor of ``mount_stiffness`` (None when absent or all 1)."""
    if "mount_stiffness" not in scenario:
        return None
    p = scenario["mount_stiffness"]
    k = np.array([p.get("k1", 1.0), p.get("k2", 1.0), p.get("k3", 1.0)])
    s = np.array([k[mi] if mi < 3 else 1.0 for mi, _, _ in hm.networks])
    return None if np.all(s == 1.0) else s


def _kip(hm, abc, scenario):
    a, b, c = abc
    if "base_compliance" in scenario:
        p = scenario["base_compliance"]
        cb, mb = p["c_base"], p["m_base"]
        if cb >= EFFECTS["base_compliance"].parameters[0].upper:
            return a                         # upper bound = rigid ground (the default)
        w = hm.omega[..., None]
        zb = cb + 1j * w * 2 * BASE_ZETA * np.sqrt(cb * mb) - w ** 2 * mb
        return a - b ** 2 / (c + zb)
    return a


def _load(hm, scenario):
    load = hm.load
    if "balancer_error" in scenario:
        p = scenario["balancer_error"]
        sh = hm.shaft_loads()
        on = 1.0 if hm.engine.balancer.enabled else 0.0
        f = _shaft_factors(sh.shape[0], p["gain"], p["asym"])
        load = load + np.tensordot(f * np.exp(-1j * p["lag"]) - on, sh, axes=1)
    if "cylinder_imbalance" in scenario:
        p = scenario["cylinder_imbalance"]
        d = hm.imep_derivatives()
        eps = np.array([p.get(f"e{i + 1}", 0.0) for i in range(d.shape[0])])
        load = load + np.tensordot(eps, d, axes=1)
    return load


def predict(hm: HarmonicModel, scenario: dict, *, tol=1e-6, max_iter=60) -> Prediction:
    """Channel velocities with the effects of ``scenario`` on the cached model.

    Parameters
    ----------
    hm : HarmonicModel
    scenario : dict
        ``{effect name: {parameter: value}}`` (SI); missing parameters take their defaults.
    tol, max_iter
        Convergence of the amplitude factors (``amplitude_stiffness``).

    Returns
    -------
    Prediction
    """
    sc = {}
    for name, p in scenario.items():
        if name not in EFFECTS:
            raise KeyError(f"unknown effect {name!r}")
        sc[name] = {**EFFECTS[name].defaults(), **p}
    s_el = _elastomer_factors(hm, sc)
    if s_el is None:
        abc = hm.two_ports()                 # cached
    else:                                    # exact: the rescaled networks' two-ports
        abc = hm.two_ports_scaled(s_el[None, None, :])
    load = _load(hm, sc)
    iterations, g = 0, None
    if "amplitude_stiffness" in sc and sc["amplitude_stiffness"]["kappa"] != 0.0:
        p = sc["amplitude_stiffness"]
        s0 = np.ones(len(hm.networks)) if s_el is None else s_el
        g = np.ones((hm.rpm.size, len(hm.networks)))
        for iterations in range(1, max_iter + 1):  # noqa: B007 (count returned)
            abc = hm.two_ports_scaled((s0[None, :] * g)[:, None, :])
            q = hm.solve(_kip(hm, abc, sc), load)
            g_new = amplitude_factor(hm.network_amplitude(q), p["kappa"], p["a_c"])
            change = np.max(np.abs(g_new - g))
            g = g + 0.7 * (g_new - g)
            if change < tol:
                break
        abc = hm.two_ports_scaled((s0[None, :] * g)[:, None, :])
    q = hm.solve(_kip(hm, abc, sc), load)
    v = hm.velocity(q)
    if "sensor_error" in sc:
        v = apply_sensor_error(v, sc["sensor_error"])
    return Prediction(v, iterations, g)


def apply_sensor_error(velocity, params: dict):
    """:func:`sensor_reading` with the ``sensor_error`` parameters ``g<c>`` [dB] and
    ``r<m><axis>`` [rad] (missing ones 0)."""
    n_ch = velocity.shape[1]
    gains = np.array([params.get(f"g{c + 1}", 0.0) for c in range(n_ch)])
    rot = np.array([[params.get(f"r{m + 1}{ax}", 0.0) for ax in "xyz"]
                    for m in range(n_ch // 3)])
    return sensor_reading(velocity, gains, rot)


def rotation_matrix(phi):
    r"""Rotation matrix of the rotation vector ``phi`` [rad] (Rodrigues):
    :math:`\mathbf R = \mathbf I + \frac{\sin\theta}{\theta}[\boldsymbol\varphi]_\times +
    \frac{1 - \cos\theta}{\theta^2}[\boldsymbol\varphi]_\times^2`, θ = |φ|."""
    phi = np.asarray(phi, float)
    th = float(np.linalg.norm(phi))
    K = np.array([[0.0, -phi[2], phi[1]], [phi[2], 0.0, -phi[0]], [-phi[1], phi[0], 0.0]])
    if th < 1e-12:
        return np.eye(3) + K
    return np.eye(3) + np.sin(th) / th * K + (1 - np.cos(th)) / th ** 2 * (K @ K)


def sensor_reading(velocity, gain_db, rotation):
    r"""What mis-calibrated, mis-oriented triads read from the true channel velocities.

    Channel c of triad m reads :math:`10^{G_c/20}\,[\mathbf R(\boldsymbol\varphi_m)
    \mathbf v_m]_c`: the triad's axes are rotated by :math:`\boldsymbol\varphi_m` from
    the engine axes, then each axis has its own gain.

    Parameters
    ----------
    velocity : ndarray (n_r, 3 n_m, n_h) complex
        True mount-point velocities, triads mount-major x, y, z.
    gain_db : ndarray (3 n_m,)
        Channel gain errors [dB].
    rotation : ndarray (n_m, 3)
        Rotation vector of each triad [rad].
    """
    v = np.asarray(velocity)
    out = np.empty_like(v)
    for m in range(v.shape[1] // 3):
        sl = slice(3 * m, 3 * m + 3)
        out[:, sl] = np.einsum("ij,rjh->rih", rotation_matrix(rotation[m]), v[:, sl])
    return out * 10.0 ** (np.asarray(gain_db, float) / 20.0)[None, :, None]


def simulate(engine, rpm, scenario: dict):
    """Run-up velocities (harmonic steady state) of ``engine`` with the effects of
    ``scenario`` applied; a :class:`~powertrain.results.RunupResult` holding the velocity
    only (displacement = velocity/(iω), acceleration = iω·velocity, no mount forces)."""
    from powertrain.analysis.orders import ORDERS
    from powertrain.results import RunupResult
    hm = HarmonicModel(engine, rpm)
    pred = predict(hm, scenario)
    w = hm.omega[:, 1:N_HARMONICS][:, None, :]
    v = pred.velocity
    return RunupResult(rpm=hm.rpm, orders=ORDERS.copy(), channels=list(hm.channels),
                       displacement=v / (1j * w), velocity=v, acceleration=1j * w * v,
                       mount_force=np.zeros_like(v), mean_mount_force=np.zeros(v.shape[:2]),
                       periodicity=np.zeros(hm.rpm.size),
                       settings={"solver": "harmonic (effects)", "effects": scenario},
                       meta={"engine": getattr(engine, "name", "")})


# ----------------------------------------------------------------------- the normal model
#: Effects that are not a change of the linear engine model (applied to the response).
RESPONSE_EFFECTS = ("amplitude_stiffness", "sensor_error")


def check_scenario(scenario: dict) -> dict:
    """Validate ``{effect: {parameter: value}}``: known names, values inside the bounds.

    Returns the scenario with every parameter filled in (defaults); raises ``KeyError``
    (unknown effect or parameter) or ``ValueError`` (value outside its bounds, not finite)
    with a one-line message.
    """
    out = {}
    for name, params in scenario.items():
        if name not in EFFECTS:
            raise KeyError(f"unknown effect {name!r} (expected {', '.join(EFFECTS)})")
        eff = EFFECTS[name]
        spec = {p.name: p for p in eff.parameters}
        for k, v in params.items():
            if k not in spec:
                raise KeyError(f"effect {name!r} has no parameter {k!r} (expected "
                               f"{', '.join(spec)})")
            p = spec[k]
            if not (np.isfinite(v) and p.lower <= v <= p.upper):
                u = "" if p.unit == "1" else f" {p.unit}"
                raise ValueError(f"{name}.{k} = {v:g}{u} outside the effect's bounds "
                                 f"{p.lower:g}..{p.upper:g}{u}")
        out[name] = {**eff.defaults(), **params}
    return out


def runup_with_effects(engine, rpm, scenario: dict, **options):
    r"""Run-up of ``engine`` with the effects of ``scenario``, through the normal run-up.

    Every effect goes through :func:`powertrain.runup.run_runup` (either solver, all
    outputs: displacement, velocity, acceleration, mount forces):

    * engine-model effects (``base_compliance``, ``mount_stiffness``, ``balancer_error``,
      ``cylinder_imbalance``) change the engine (``Effect.apply``), applied in that order;
    * ``amplitude_stiffness``: the factors :math:`g(a_n)` of the equivalent linearisation
      are converged at each speed on the frequency-domain model
      (:func:`predict`); then each speed step runs with every network's springs and dampers
      scaled by its factor at that speed. ``meta["amplitude_factors"]`` holds them
      (n_r, n_net); the rigid-body modes reported are those at the reference amplitude;
    * ``sensor_error``: the channels' displacement, velocity and acceleration are read
      through :func:`sensor_reading` (the transmitted forces are not sensor readings and
      stay as they are).

    Parameters
    ----------
    engine : Engine
    rpm : array_like
        Speed steps [rpm].
    scenario : dict
        ``{effect: {parameter: value}}`` (SI, :data:`EFFECTS` units).
    **options
        Keyword arguments of :func:`~powertrain.runup.run_runup` (``solver``...).

    Returns
    -------
    RunupResult
        ``settings["effects"]`` records the scenario.
    """
    from powertrain.runup import run_runup
    sc = check_scenario(scenario)
    rpm = np.atleast_1d(np.asarray(rpm, float))
    for name in ("base_compliance", "mount_stiffness", "balancer_error", "cylinder_imbalance"):
        if name in sc:
            engine = EFFECTS[name].apply(engine, **sc[name])
    amp = sc.get("amplitude_stiffness")
    if amp is not None and amp["kappa"] != 0.0:
        hm = HarmonicModel(engine, rpm)
        g = predict(hm, {"amplitude_stiffness": amp}).factors
        parts = []
        for i, r in enumerate(rpm):
            parts.append(run_runup(with_network_elastomer(engine, g[i]), [r], **options))
        result = _concatenate(parts)
        result.rigid_body_modes_hz = run_runup(engine, rpm[:1], solver="harmonic"
                                               ).rigid_body_modes_hz
        result.meta["amplitude_factors"] = g.tolist()
    else:
        result = run_runup(engine, rpm, **options)
    if "sensor_error" in sc:
        for attr in ("displacement", "velocity", "acceleration"):
            setattr(result, attr, apply_sensor_error(getattr(result, attr),
                                                     sc["sensor_error"]))
    result.settings["effects"] = sc
    return result


def _concatenate(parts):
    """One RunupResult from single-speed results (same channels and orders)."""
    first = parts[0]
    out = dataclasses.replace(first)
    for attr in ("rpm", "displacement", "velocity", "acceleration", "mount_force",
                 "mean_mount_force", "periodicity"):
        setattr(out, attr, np.concatenate([getattr(p, attr) for p in parts], axis=0))
    out.solver_seconds = float(sum(p.solver_seconds for p in parts))
    out.settings = dict(first.settings)
    out.meta = dict(first.meta)
    return out


# ----------------------------------------------------------------------- time-domain check
def time_domain_amplitude_check(engine, rpm, kappa, a_c, *, cycles=40, angle_step_deg=1.0):
    r"""Amplitude-dependent mounts in the time domain, for checking the linearisation.

    The assembled 33-DOF model is integrated by Newmark (average acceleration) cycle by
    cycle; at the start of each engine cycle every network's springs and dampers are
    rescaled by :math:`g(a_n)` (masses kept) (under-relaxed by 0.7 like the frequency-domain iteration)
    with :math:`a_n = \sqrt2\,\mathrm{RMS}` of its engine-side
    displacement over the previous cycle (the mean removed) — a quasi-static amplitude
    memory, the time-domain counterpart of the equivalent linearisation. After ``cycles``
    cycles the last cycle is order-analysed.

    Returns
    -------
    velocity : ndarray (n_ch, 16) complex
        Order amplitudes of the last cycle [m/s].
    factors : ndarray (n_net,)
        Stiffness factors used in the last cycle.
    periodicity : float
        Max change of the channel velocities between the last two cycles, relative.
    """
    from powertrain.analysis.orders import order_spectrum
    from powertrain.assembly import assemble
    from powertrain.solvers.newmark import newmark
    n_cycle = int(round(720.0 / angle_step_deg))
    omega = rpm * 2 * np.pi / 60.0
    h = np.deg2rad(angle_step_deg) / omega
    theta = np.arange(n_cycle) * (4 * np.pi / n_cycle)
    load = np.asarray(engine.generalized_load(rpm, theta), float)
    b = engine.body
    g = np.ones(3 * len(engine.mounts))
    state = None
    prev_v = None
    for _ in range(cycles):
        eng_g = with_network_elastomer(engine, g)
        system = assemble(b.mass, b.cg, b.inertia, eng_g.mounts)
        F = np.zeros((n_cycle + 1, system.n_dof))
        F[:, :6] = np.concatenate([load, load[:1]])
        if state is None:
            from powertrain.analysis.fourier import harmonic_amplitudes
            from powertrain.solvers.harmonic import harmonic_response
            fh = harmonic_amplitudes(load, axis=0)[: n_cycle // 2]
            om = 0.5 * omega * np.arange(fh.shape[0])
            qh = harmonic_response(system, fh, om)
            state = (qh.real.sum(0), (1j * om[:, None] * qh).real.sum(0),
                     (-(om ** 2)[:, None] * qh).real.sum(0))
        X, V, A = newmark(system.M, system.C, system.K, F, h, *state)
        state = (X[-1], V[-1], A[-1])
        xe = X[:-1, :6] @ _rows(engine).T                     # (n_cycle, n_net)
        a = np.sqrt(2.0) * np.std(xe, axis=0)
        last_v = V[:-1] @ system.channel_matrix.T
        g_used = g
        g = g + 0.7 * (amplitude_factor(a, kappa, a_c) - g)
        per = float("nan")
        if prev_v is not None:
            per = np.max(np.abs(last_v - prev_v)) / np.max(np.abs(last_v))
        prev_v = last_v
    return order_spectrum(last_v, 2).T, g_used, per


def _rows(engine):
    from powertrain.assembly import DIRECTIONS
    from powertrain.physics.rigid_body import direction_row
    cg = np.asarray(engine.body.cg, float)
    return np.array([direction_row(np.asarray(m.position, float) - cg,
                                   np.asarray(m.rotation, float)[:, i])
                     for m in engine.mounts for i, _ in enumerate(DIRECTIONS)])
