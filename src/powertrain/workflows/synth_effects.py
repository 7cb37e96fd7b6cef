r"""The truth effects of ``powertrain synth`` on the harmonic model: :func:`truth_velocity`,
the noise-free channel velocities with hidden effects. Models and ranges: docs/guide/synth.md.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np

from powertrain.effects import A_REF
from powertrain.physics.mount_network import two_port
from powertrain.solvers.body_coupling import coupled_solve
from powertrain.solvers.fast_harmonic import N_HARMONICS, HarmonicModel


def _solve_body(hm, abc, load, body):
    """Rigid body + flexible chassis body (modal) under all networks; q (n_r, 16, 6)."""
    modes = SimpleNamespace(frequency_hz=body["freq"], modal_mass=body["mass"], damping_ratio=body["zeta"])
    return coupled_solve(hm.M, hm.omega[:, 1:], hm.rows, body["shapes"],
                         tuple(x[:, 1:] for x in abc), abc[0][:, 1:], modes, load[:, 1:])[..., :6]


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
    names = dict(truth)
    load = _truth_load(engine, hm, names)
    models = _truth_networks(hm, names)

    def abc_for(s):                         # s (n_r, n_net) spring factors
        out = [np.empty(hm.omega.shape + (len(models),), complex) for _ in range(3)]
        for k, m in enumerate(models):
            res = two_port(hm.omega, *m.network(), spring_scale=np.asarray(s[:, k], float)[:, None],
                           damper_scale=1.0)      # springs times s (n_r,) per speed
            for j in range(3):
                out[j][..., k] = res[j]
        return out

    def solve(abc):
        if "body_modes" in names:
            return _solve_body(hm, abc, load, names["body_modes"])
        return hm.solve(abc[0], load, abc=abc)

    s = np.ones((hm.rpm.size, len(models)))
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
    return _truth_readings(hm, hm.velocity(solve(abc_for(s))), names)


def _truth_load(engine, hm, names):
    """Load harmonics with the load-side truth effects (combustion, balancer, driveline)."""
    load = hm.load
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
            load = load + (p["gain"][k] * np.exp(-1j * (p["lag"] + p["lag_shaft"][k])) - on) * sh[k]
    if "torsional_driveline" in names:
        p = names["torsional_driveline"]
        w, wt = hm.omega, 2 * np.pi * p["freq"]
        fac = 1 + p["kappa"] * w ** 2 / (wt ** 2 - w ** 2 + 2j * p["zeta"] * wt * w)
        load = load.copy()
        load[..., 3] = load[..., 3] * fac
    return load


def _truth_networks(hm, names) -> list:
    """The mount networks with the ``mount_temperature`` truth's spring and damper factors."""
    nets = [n[2] for n in hm.networks]
    spring = np.ones(len(nets))
    damp = np.ones(len(nets))
    if "mount_temperature" in names:
        p = names["mount_temperature"]
        spring = np.asarray(p["spring"], float)
        damp = np.asarray(p["damper"], float)
    return [m.with_params(**{k: v * (sf if k[0] == "c" else df if k[0] == "d" else 1.0)
                             for k, v in m.params.items()}) for m, sf, df in zip(nets, spring, damp)]


def _truth_readings(hm, v, names):
    """Channel velocities as read: the powertrain's bending and the sensor triads' truths."""
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
