r"""Truth generator: synthetic "measured" run-ups with hidden effects, for blind tests.

A case is the default (or any) engine plus zero, one or two hidden *truth* effects with
random parameters, then measurement noise, on a dense speed grid. The truth effects are of
higher fidelity than, and parametrised differently from, the diagnosis candidates of
:mod:`powertrain.effects`, so a blind test is not circular:

=====================  ==================  =====================================================
truth effect           library match       truth model (candidate model)
=====================  ==================  =====================================================
``body_modes``         base_compliance     a chassis body with 3 modes (20–80 Hz, ζ 3–8 %,
                                           modal mass 1.5–10 kg, random shapes) under *all* nine
                                           mount networks, coupling them (candidate: one local
                                           base mass/spring per network, all alike)
``mount_temperature``  mount_stiffness     per mount *and direction* spring factors s·e^{N(0,
                                           0.05)}, dampers s^0.7, masses unchanged (candidate:
                                           one elastomer factor per mount, springs and
                                           dampers alike)
``amplitude_power``    amplitude_stiffness springs only times (a/a_ref)^(−β), β per mount type
                                           (hydraulic, elastomeric) 0.08–0.25, a ≥ 1 µm;
                                           equivalent linearisation (candidate: rational law
                                           on the whole dynamic stiffness, one for all)
``balancer_error``     balancer_error      per-shaft unbalance 0.75–1.25 and common drive lag
                                           ±0.35 rad plus per-shaft ±0.05 rad (candidate: gain,
                                           shaft asymmetry, one common lag)
``cylinder_combustion`` cylinder_imbalance per-cylinder IMEP ±12 % *and* start of combustion
                                           ±2°, exact pressure model (candidate: IMEP factors,
                                           load linearised)
``sensor_triads``      sensor_error        per-channel gain ±5 dB and 1–3 % cross-axis
                                           sensitivity within each triad, a random 3×3
                                           matrix (candidate: gains and a rotation of
                                           each triad)
``powertrain_bending`` (none: outside)     engine–gearbox bending mode 50–140 Hz amplifying the
                                           gearbox mount point, factor 1 + κω²/(ω_b² − ω² +
                                           2iζω_bω), κ 0.15–0.5
``torsional_driveline`` (none: outside)    roll-moment (torque reaction) filtered by a
                                           driveline torsional mode 40–120 Hz, factor on M_x
                                           1 + κω²/(ω_t² − ω² + 2iζω_tω)
=====================  ==================  =====================================================

Effects are redrawn (up to 40 times) until their noise-free gap is at least
:data:`MIN_EFFECT_DB` RMS over the written order points or reaches :data:`MIN_EFFECT_MAX_DB`
somewhere: smaller effects are not worth diagnosing at 0.5–1 dB measurement noise (chassis
modes rarely reach 0.5 dB RMS on the engine-side velocities, which are mass-controlled
above the rigid-body modes, so for them the local criterion is what counts). Noise: each order level times
:math:`10^{\epsilon/20}`, :math:`\epsilon\sim N(0,\sigma)`, σ uniform in 0.5–1.0 dB, then a
noise floor :data:`FLOOR` added in power with exponential power (complex Gaussian noise);
the synthesis is the RMS sum of all 16 noisy orders. Orders :data:`WRITTEN_ORDERS` and the
synthesis of the nine channels are kept.

Detectability: :attr:`SynthCase.heldout_effect_db` is the hidden effect's noise-free gap
RMS on the diagnosis' held-out speeds; :func:`is_detectable` calls a case detectable when
it reaches :data:`DETECT_DB` or :data:`DETECT_NOISE` × the noise. Below that no diagnosis can
name the effect, and the blind test expects "no effect" (no claim) there.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from powertrain.effects import A_REF
from powertrain.solvers.fast_harmonic import N_HARMONICS, HarmonicModel

TRUTH_EFFECTS = {
    "body_modes": "base_compliance",
    "mount_temperature": "mount_stiffness",
    "amplitude_power": "amplitude_stiffness",
    "balancer_error": "balancer_error",
    "cylinder_combustion": "cylinder_imbalance",
    "sensor_triads": "sensor_error",
    "powertrain_bending": None,
    "torsional_driveline": None,
}
#: Former names still accepted (scripts written before the names were made one with the
#: diagnosis library's): old name -> truth effect.
TRUTH_ALIASES = {"balancer_shafts": "balancer_error"}
IN_LIBRARY = [k for k, v in TRUTH_EFFECTS.items() if v]
OUT_OF_LIBRARY = [k for k, v in TRUTH_EFFECTS.items() if not v]
#: RMS noise floor per order [m/s].
FLOOR = 1.0e-6
#: Orders written (0.5, 1, 1.5 carry cylinder differences; 2, 4, 6 the mass forces).
WRITTEN_ORDERS = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 6.0)
#: Smallest noise-free gap of a hidden effect [dB RMS over the written order points].
MIN_EFFECT_DB = 0.5
#: ... or this largest noise-free gap [dB].
MIN_EFFECT_MAX_DB = 4.0
#: A hidden effect is *detectable* when its noise-free gap RMS on the held-out speeds of the
#: diagnosis' split reaches this [dB] ...
DETECT_DB = 1.5
#: ... or this multiple of the case's measurement noise (1 sigma) [1].
DETECT_NOISE = 2.0


def is_detectable(gap_rms_db, noise_db) -> bool:
    """Detectability rule: noise-free held-out gap RMS ≥ :data:`DETECT_DB` or ≥
    :data:`DETECT_NOISE` × the noise (1σ, dB)."""
    return bool(gap_rms_db >= DETECT_DB or gap_rms_db >= DETECT_NOISE * noise_db)


def heldout_gap_db(rpm, reference_velocity, true_velocity) -> float:
    """Noise-free gap RMS [dB] between two velocity sets (n_r, 9, 16) on the held-out speeds of
    :func:`powertrain.diagnosis.split_rpm` (a function of the speed grid only), written
    orders, :data:`FLOOR` added in power, points where both are below 3 × floor left out."""
    from powertrain.diagnosis import split_rpm
    held = split_rpm(np.asarray(rpm, float))[1]
    idx = [int(round(2 * o)) - 1 for o in WRITTEN_ORDERS]

    def lev(v):
        return np.sqrt((np.abs(v[held][..., idx]) / np.sqrt(2)) ** 2 + FLOOR ** 2)

    a, b = lev(reference_velocity), lev(true_velocity)
    keep = np.maximum(a, b) >= 3 * FLOOR
    if not keep.any():
        return 0.0
    return float(np.sqrt(np.mean((20 * np.log10(a / b))[keep] ** 2)))


@dataclass
class SynthCase:
    """A synthetic measurement and its hidden truth.

    Attributes
    ----------
    measured : MeasuredRunup
    truth : list of (truth effect name, parameters dict)
    noise_db : float
    rpm : ndarray
    clean_velocity : ndarray (n_r, 9, 16) complex
        Noise-free truth [m/s].
    effect_rms_db : float
        Noise-free gap between truth and baseline [dB RMS, written orders].
    heldout_effect_db : float
        The same on the diagnosis' held-out speeds only (:func:`heldout_gap_db`); decides
        :attr:`detectable`.
    """

    measured: object
    truth: list
    noise_db: float
    rpm: np.ndarray
    clean_velocity: np.ndarray
    effect_rms_db: float = 0.0
    seed: int = 0
    meta: dict = field(default_factory=dict)
    heldout_effect_db: float = 0.0
    member_effect_db: dict = field(default_factory=dict)

    @property
    def detectable_library_effects(self) -> set:
        """Library matches of the hidden effects that are detectable *alone* (each one's
        noise-free held-out gap, :attr:`member_effect_db`); for a single effect the same as
        :attr:`library_effects` when :attr:`detectable`."""
        if not self.detectable:
            return set()
        if len(self.truth) == 1:
            return self.library_effects
        return {TRUTH_EFFECTS[t] for t, _ in self.truth
                if is_detectable(self.member_effect_db.get(t, 0.0), self.noise_db)}

    @property
    def detectable(self) -> bool:
        """Whether the hidden effect can be identified at all (:func:`is_detectable`);
        False for effect-free cases."""
        return bool(self.truth) and is_detectable(self.heldout_effect_db, self.noise_db)

    @property
    def library_effects(self) -> set:
        return {TRUTH_EFFECTS[t] for t, _ in self.truth}

    @property
    def kind(self) -> str:
        if not self.truth:
            return "none"
        if any(TRUTH_EFFECTS[t] is None for t, _ in self.truth):
            return "out"
        return "in"

    def csv_text(self) -> str:
        """The measured CSV; with a body under the mounts (channels ``NAME/passive`` and
        body points) with the ``side`` column."""
        from powertrain.assembly import split_side
        names = {m for m, _, _ in self.measured.curves}
        bases = {split_side(m)[0] for m in names if split_side(m)[1] == "passive"}
        lines = [f"# SYNTHETIC measured run-up (powertrain synth, seed {self.seed}); the hidden "
                 "effect is not stated here",
                 "mount,direction,quantity,rpm,side,velocity_rms_mm_per_s" if bases else
                 "mount,direction,quantity,rpm,velocity_rms_mm_per_s"]
        for (m, d, q), (r, v) in self.measured.curves.items():
            base, side = split_side(m)
            if bases and side == "active" and base not in bases:
                side = "passive"                     # a body point of interest
            col = f",{side}" if bases else ""
            for ri, vi in zip(r, v):
                lines.append(f"{base},{d},{q},{ri:g}{col},{vi * 1e3:.6g}")
        return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------- truth models
def _two_port_springs(omega, model, s):
    """Two-port (a, b, c) with the network's springs times s (n_r,) per speed (dampers and
    masses kept): the one condensation, :func:`powertrain.physics.mount_network.two_port`."""
    from powertrain.physics.mount_network import two_port
    return two_port(omega, *model.network(), spring_scale=np.asarray(s, float)[:, None],
                    damper_scale=1.0)


def _solve_body(hm, abc, load, body):
    """Rigid body + flexible chassis body (modal) under all networks; q (n_r, 16, 6)."""
    a, b, c = (x[:, 1:] for x in abc)
    w = hm.omega[:, 1:]
    Phi = body["shapes"]                                    # (n_net, K)
    wk = 2 * np.pi * body["freq"]
    mk = body["mass"]
    zk = body["zeta"]
    K = Phi.shape[1]
    R = hm.rows
    D = np.zeros(w.shape + (6 + K, 6 + K), complex)
    D[..., :6, :6] = (-(w ** 2))[..., None, None] * hm.M + np.einsum("rhn,ni,nj->rhij", a, R, R)
    D[..., :6, 6:] = np.einsum("rhn,ni,nk->rhik", b, R, Phi)
    D[..., 6:, :6] = np.einsum("rhn,nk,ni->rhki", b, Phi, R)
    modal = mk * (wk ** 2 - w[..., None] ** 2 + 2j * zk * wk * w[..., None])
    D[..., 6:, 6:] = np.einsum("rhn,nk,nl->rhkl", c, Phi, Phi)
    D[..., np.arange(6, 6 + K), np.arange(6, 6 + K)] += modal
    rhs = np.zeros(w.shape + (6 + K,), complex)
    rhs[..., :6] = load[:, 1:]
    return np.linalg.solve(D, rhs[..., None])[..., 0][..., :6]


class _PerCylinderCombustion:
    """Single-zone combustion with per-cylinder IMEP factor and start of combustion."""

    def __init__(self, base, factors, start_shift):
        self.base = base
        self.imep_factors = np.asarray(factors, float)
        self.shift = np.asarray(start_shift, float)
        self.model = "single-zone"

    def speed_range(self):
        return self.base.speed_range()

    def cycle_pressures(self, crank, omega, load=1.0):
        rows, info0, theta = [], None, None
        for i, (f, dsh) in enumerate(zip(self.imep_factors, self.shift)):
            comb = dataclasses.replace(self.base, start=self.base.start + dsh,
                                       imep_factors=np.full(self.imep_factors.size, f))
            theta, p, info = comb.cycle_pressures(crank, omega, load)
            rows.append(p[i])
            info0 = info0 or info
        return theta, np.array(rows), info0


def truth_velocity(engine, hm: HarmonicModel, truth) -> np.ndarray:
    """Noise-free channel velocities (n_r, 9, 16) of ``engine`` with the truth effects."""
    nets = [n[2] for n in hm.networks]
    load = hm.load
    names = dict(truth)
    if "cylinder_combustion" in names:
        p = names["cylinder_combustion"]
        eng = engine.replace(combustion=_PerCylinderCombustion(
            engine.combustion, np.asarray(engine.combustion.imep_factors) * (1 + np.array(
                p["imep_dev"])), np.deg2rad(p["start_shift_deg"])))
        load = hm.load_of(eng)
    if "balancer_error" in names:
        p = names["balancer_error"]
        sh = hm.shaft_loads()
        on = 1.0 if engine.balancer.enabled else 0.0
        for k in range(sh.shape[0]):
            load = load + (p["gain"][k] * np.exp(-1j * (p["lag"] + p["lag_shaft"][k])) - on
                           ) * sh[k]
    if "torsional_driveline" in names:
        p = names["torsional_driveline"]
        w, wt = hm.omega, 2 * np.pi * p["freq"]
        fac = 1 + p["kappa"] * w ** 2 / (wt ** 2 - w ** 2 + 2j * p["zeta"] * wt * w)
        load = load.copy()
        load[..., 3] = load[..., 3] * fac
    spring = np.ones(len(nets))
    damp = np.ones(len(nets))
    if "mount_temperature" in names:
        p = names["mount_temperature"]
        spring = np.asarray(p["spring"], float)
        damp = np.asarray(p["damper"], float)
    models = [m.with_params(**{k: v * (sf if k[0] == "c" else df if k[0] == "d" else 1.0)
                               for k, v in m.params.items()})
              for m, sf, df in zip(nets, spring, damp)]
    n_r = hm.rpm.size

    def abc_for(s):                         # s (n_r, n_net) spring factors
        out = [np.empty(hm.omega.shape + (len(models),), complex) for _ in range(3)]
        for k, m in enumerate(models):
            res = _two_port_springs(hm.omega, m, s[:, k])
            for j in range(3):
                out[j][..., k] = res[j]
        return out

    def solve(abc):
        if "body_modes" in names:
            return _solve_body(hm, abc, load, names["body_modes"])
        return hm.solve(abc[0], load, abc=abc)

    s = np.ones((n_r, len(models)))
    if "amplitude_power" in names:
        p = names["amplitude_power"]
        last = len(hm.mount_names) - 1          # engine mounts hydraulic, last elastomeric
        beta = np.array([p["beta"][0] if hm.networks[k][0] < last else p["beta"][1]
                         for k in range(len(models))])
        for _ in range(60):
            q = solve(abc_for(s))
            a = np.maximum(hm.network_amplitude(q), 1e-6)
            s_new = (a / A_REF) ** (-beta[None, :])
            change = np.max(np.abs(s_new - s))
            s = s + 0.7 * (s_new - s)
            if change < 1e-6:
                break
    q = solve(abc_for(s))
    v = hm.velocity(q)
    if "powertrain_bending" in names:
        p = names["powertrain_bending"]
        w, wb = hm.omega[:, 1:N_HARMONICS], 2 * np.pi * p["freq"]
        fac = 1 + p["kappa"] * w ** 2 / (wb ** 2 - w ** 2 + 2j * p["zeta"] * wb * w)
        gb = [i for i, (m, _) in enumerate(hm.channels) if m == hm.mount_names[-1]]
        v = v.copy()
        v[:, gb, :] *= fac[:, None, :]
    if "sensor_triads" in names:
        p = names["sensor_triads"]
        T = np.asarray(p["matrix"])                         # (9, 9) block diagonal
        v = np.einsum("cd,rdh->rch", T, v)
    return v


def truth_effect_name(name: str) -> str:
    """The truth effect's name, former names (:data:`TRUTH_ALIASES`) resolved."""
    return TRUTH_ALIASES.get(name, name)


def draw_truth(name, rng, n_net=9):
    """Random parameters of a truth effect (``n_net`` mount networks, three per mount: one per
    local direction; the engine has as many measured channels)."""
    u = rng.uniform
    n_m = n_net // 3
    if name == "body_modes":
        K = 3
        shapes = rng.normal(size=(n_net, K))
        shapes /= np.max(np.abs(shapes), axis=0)
        return {"freq": np.sort(u(20, 80, K)), "zeta": u(0.03, 0.08, K),
                "mass": np.exp(u(np.log(1.5), np.log(10), K)), "shapes": shapes}
    if name == "mount_temperature":
        s_m = np.exp(rng.choice([-1, 1], n_m) * u(np.log(1.3), np.log(2.2), n_m))
        sp = np.repeat(s_m, 3) * np.exp(rng.normal(0, 0.05, 3 * n_m))
        return {"mount_factor": s_m, "spring": sp, "damper": sp ** 0.7}
    if name == "amplitude_power":
        return {"beta": u(0.08, 0.25, 2)}
    if name == "balancer_error":
        return {"gain": u(0.75, 1.25, 2), "lag": u(-0.35, 0.35),
                "lag_shaft": u(-0.05, 0.05, 2)}
    if name == "cylinder_combustion":
        return {"imep_dev": u(-0.12, 0.12, 4), "start_shift_deg": u(-2, 2, 4)}
    if name == "sensor_triads":
        g = np.clip(rng.normal(0, 2.5, 3 * n_m), -5, 5)
        T = np.zeros((3 * n_m, 3 * n_m))
        for m in range(n_m):
            blk = u(0.01, 0.03, (3, 3)) * rng.choice([-1, 1], (3, 3))
            np.fill_diagonal(blk, 1.0)
            T[3 * m:3 * m + 3, 3 * m:3 * m + 3] = blk
        T = (10 ** (g / 20))[:, None] * T
        return {"gain_db": g, "matrix": T}
    if name == "powertrain_bending":
        return {"freq": u(50, 140), "kappa": u(0.15, 0.5), "zeta": u(0.03, 0.08)}
    if name == "torsional_driveline":
        return {"freq": u(40, 120), "kappa": u(0.2, 0.6), "zeta": u(0.05, 0.1)}
    raise KeyError(name)


def _written_levels(v):
    rms = np.abs(v) / np.sqrt(2.0)
    idx = [int(round(2 * o)) - 1 for o in WRITTEN_ORDERS]
    return rms, idx


def make_case(engine, truth_names, seed, *, rpm=None, hm=None, noise_db=None,
              params=None) -> SynthCase:
    """One synthetic measurement with the named truth effects (random parameters).

    Parameters
    ----------
    engine : Engine
        Baseline model.
    truth_names : sequence of str
        Names from :data:`TRUTH_EFFECTS` or :data:`TRUTH_ALIASES` (empty: effect-free).
    seed : int
    rpm : array_like, optional
        Speeds [rpm] (default 1000..6000 step 50).
    hm : HarmonicModel, optional
        Cached model of ``engine`` at ``rpm`` (reused across cases).
    noise_db : float, optional
        Measurement scatter [dB, 1σ] (default uniform 0.5–1.0).
    params : dict, optional
        ``{truth name: parameters}`` fixing some truth effects' parameters instead of
        drawing them (tests); missing keys of a given effect are drawn.
    """
    from powertrain.analysis.orders import order_label
    from powertrain.iotools.measured import MeasuredRunup
    truth_names = [truth_effect_name(n) for n in truth_names]
    params = {truth_effect_name(k): v for k, v in (params or {}).items()}
    rng = np.random.default_rng(seed)
    rpm = np.arange(1000.0, 6000.1, 50.0) if rpm is None else np.asarray(rpm, float)
    hm = HarmonicModel(engine, rpm) if hm is None else hm
    base = hm.velocity(hm.solve(hm.two_ports()[0]))
    rms0, idx = _written_levels(base)
    truth, v, eff_db = [], base, 0.0
    if truth_names:
        for _ in range(40):
            truth = [(n, {**draw_truth(n, rng, len(hm.networks)), **(params or {}).get(n, {})})
                     for n in truth_names]
            v = truth_velocity(engine, hm, truth)
            rms1, _ = _written_levels(v)
            a = np.sqrt(rms1[..., idx] ** 2 + FLOOR ** 2)
            b = np.sqrt(rms0[..., idx] ** 2 + FLOOR ** 2)
            keep = np.maximum(a, b) >= 2 * FLOOR
            dd = (20 * np.log10(a / b))[keep]
            eff_db = float(np.sqrt(np.mean(dd ** 2)))
            if eff_db >= MIN_EFFECT_DB or np.max(np.abs(dd)) >= MIN_EFFECT_MAX_DB:
                break
    sigma = float(rng.uniform(0.5, 1.0)) if noise_db is None else float(noise_db)
    rms = np.abs(v) / np.sqrt(2.0)
    gain = 10 ** (rng.normal(0, sigma, rms.shape) / 20)
    meas = np.sqrt((gain * rms) ** 2 + FLOOR ** 2 * rng.exponential(1.0, rms.shape))
    syn = np.sqrt(np.sum(meas ** 2, axis=-1))
    curves = {}
    for c, (m, d) in enumerate(hm.channels):
        for o, h in zip(WRITTEN_ORDERS, idx):
            curves[(m, d, order_label(o))] = (rpm.copy(), meas[:, c, h].copy())
        curves[(m, d, "synthesis")] = (rpm.copy(), syn[:, c].copy())
    mr = MeasuredRunup(curves, source=f"synthetic case seed {seed}",
                       comments=["SYNTHETIC"])
    held_db = heldout_gap_db(rpm, base, v) if truth else 0.0
    members = {}
    if len(truth) > 1:
        for t in truth:
            members[t[0]] = heldout_gap_db(rpm, base, truth_velocity(engine, hm, [t]))
    elif truth:
        members[truth[0][0]] = held_db
    return SynthCase(mr, truth, sigma, rpm, v, eff_db, seed, heldout_effect_db=held_db,
                     member_effect_db=members)
