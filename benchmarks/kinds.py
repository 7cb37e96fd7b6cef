r"""Truth effects of the blind benchmark: how each is drawn and applied.

**Truth effects** (:data:`KINDS`; physics in :mod:`benchmarks.truth`), each with
the diagnosis candidate it should be found as (``library``; ``None`` = outside the library):

======================= ==================== ==============================================
truth effect            library match        drawn parameters
======================= ==================== ==============================================
``mount_temperature``   mount_stiffness      one mount 0.5–0.8× or 1.25–2× as stiff
                                             (direction exponents 1 ± 0.1), the others
                                             ± 3 %; dampers × factor^0.7
``amplitude_elastomer`` amplitude_stiffness  springs × (a/0.1 mm)^(−β), β 0.12–0.3 per
                                             mount type
``balancer_shafts``     balancer_error       unbalance of both shafts ± 15–35 %, or drive
                                             timing ± 0.15–0.4 rad, or one shaft mis-timed
                                             10–25° (per-shaft ± 2 % and ± 0.02 rad spread)
``weak_cylinder``       cylinder_imbalance   one cylinder's IMEP −6…−12 % (combustion part
                                             of its trace scaled) and 0–2° later
``sensor_triads``       sensor_error         1–3 channels ± 1.5–4 dB (others 0.2 dB 1σ),
                                             one triad rotated 3–8°, 2 % cross-axis
``chassis_base``        base_compliance      base 5–20 kg under each mount on springs
                                             tuned to 35–100 Hz (± 20 % per direction), two
                                             global chassis modes 22–70 Hz
``sensor_bracket``      (outside)            one or two channels of a triad on a bracket
                                             resonating at 120–350 Hz, ζ 3–7 %
``powertrain_bending``  (outside)            gearbox-part bending mode 80–180 Hz, ζ 2–5 %
``body_modes``          chassis_modes        passive-side plan only: the modal body's modes
                                             (one or two shifted 12–25 % in frequency, their
                                             mass and damping changed, all ± a few %,
                                             shape components ± 5 %)
``missing_mode``        missing_body_mode    passive-side plan only: one more body mode,
                                             20–150 Hz, 5–40 kg (shape U(−1, 1) at every
                                             base and direction, normalised to its
                                             largest component), ζ 2–6 %
======================= ==================== ==============================================

Cases, measurement noise and detectability: :mod:`benchmarks.cases`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks import truth as tr


@dataclass(frozen=True)
class TruthKind:
    """One kind of hidden truth effect: name, matching candidate, parameter draw, model."""

    name: str
    library: str | None
    draw: object          # (rng, engine) -> dict
    apply: object         # (params, parts: dict) -> None, mutating parts


def _draw_mount_temperature(rng, engine):
    n_m = len(engine.mounts)
    f = np.exp(rng.normal(0, 0.03, (n_m, 3)))
    m = int(rng.integers(n_m))
    target = rng.uniform(0.5, 0.8) if rng.random() < 0.5 else rng.uniform(1.25, 2.0)
    f[m] = target ** (1 + rng.normal(0, 0.1, 3))
    return {"spring_factors": f, "mount": m, "factor": float(target)}


def _apply_mount_temperature(p, parts):
    parts["mounts"] = [tr.mount_with_elastomer(mt, p["spring_factors"][m])
                       for m, mt in enumerate(parts["mounts"])]


def _draw_amplitude(rng, engine):
    types = [mt.directions["z"].name for mt in engine.mounts]
    beta = {t: rng.uniform(0.12, 0.3) for t in sorted(set(types))}
    return {"beta": np.array([beta[t] for t in types])}


def _apply_amplitude(p, parts):
    parts["amplitude_beta"] = p["beta"]


def _draw_balancer(rng, engine):
    n_s = len(engine.balancer.shafts)
    gains = 1 + rng.normal(0, 0.02, n_s)
    angles = rng.normal(0, 0.02, n_s)
    variant = ("unbalance", "drive_timing", "one_shaft")[int(rng.integers(3))]
    sign = 1 if rng.random() < 0.5 else -1
    if variant == "unbalance":
        gains = gains * (1 + sign * rng.uniform(0.15, 0.35))
    elif variant == "drive_timing":
        angles = angles + sign * rng.uniform(0.15, 0.4)
    else:
        angles[int(rng.integers(n_s))] += sign * np.deg2rad(rng.uniform(10, 25))
    return {"variant": variant, "gains": gains, "angle_errors": angles}


def _apply_balancer(p, parts):
    parts["engine"] = tr.engine_with_shaft_errors(parts["engine"], p["gains"],
                                                  p["angle_errors"])


def _draw_weak_cylinder(rng, engine):
    return {"cylinder": int(rng.integers(engine.crank.n_cylinders)),
            "deficit": float(rng.uniform(0.06, 0.12)),
            "retard": float(np.deg2rad(rng.uniform(0.0, 2.0)))}


def _apply_weak_cylinder(p, parts):
    e = parts["engine"]
    parts["engine"] = e.replace(combustion=tr.WeakCylinder(e.combustion, p["cylinder"],
                                                           p["deficit"], p["retard"]))


def _rotation(axis_angle):
    th = float(np.linalg.norm(axis_angle))
    k = axis_angle / th
    Kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(th) * Kx + (1 - np.cos(th)) * Kx @ Kx


def _draw_sensor(rng, engine):
    n_m = len(engine.mounts)
    g = rng.normal(0, 0.2, 3 * n_m)
    off = rng.choice(3 * n_m, int(rng.integers(1, 4)), replace=False)
    g[off] += rng.choice([-1, 1], off.size) * rng.uniform(1.5, 4.0, off.size)
    axis = rng.normal(size=3)
    rot_mount = int(rng.integers(n_m))
    phi = np.deg2rad(rng.uniform(3, 8)) * axis / np.linalg.norm(axis)
    mats = []
    for m in range(n_m):
        cross = np.eye(3) + rng.normal(0, 0.02, (3, 3)) * (1 - np.eye(3))
        R = _rotation(phi) if m == rot_mount else np.eye(3)
        mats.append(np.diag(10 ** (g[3 * m:3 * m + 3] / 20)) @ R @ cross)
    return {"gain_db": g, "rotated_mount": rot_mount, "matrices": mats}


def _apply_sensor(p, parts):
    parts["sensor"] += [tr.triad_reading(m, T) for m, T in enumerate(p["matrices"])]


def _draw_chassis(rng, engine):
    n_m = len(engine.mounts)
    mass = rng.uniform(5, 20, n_m)
    f = rng.uniform(35, 100, n_m)
    k = (mass * (2 * np.pi * f) ** 2)[:, None] * np.exp(rng.normal(0, 0.2, (n_m, 3)))
    shapes = rng.normal(size=(2, n_m, 3))
    shapes /= np.abs(shapes).max(axis=(1, 2), keepdims=True)
    return {"chassis": tr.ChassisBase(mass, k, float(rng.uniform(0.03, 0.08)),
                                      np.array([rng.uniform(22, 40), rng.uniform(40, 70)]),
                                      rng.uniform(20, 60, 2), shapes, 0.04)}


def _apply_chassis(p, parts):
    parts["chassis"] = p["chassis"]


def _draw_bracket(rng, engine):
    m = int(rng.integers(len(engine.mounts)))
    chans = 3 * m + rng.choice(3, int(rng.integers(1, 3)), replace=False)
    return {"channels": [int(c) for c in chans], "frequency_hz": float(rng.uniform(120, 350)),
            "zeta": float(rng.uniform(0.03, 0.07))}


def _apply_bracket(p, parts):
    parts["sensor"].append(tr.bracket_reading(p["channels"], p["frequency_hz"], p["zeta"]))


def _draw_bending(rng, engine):
    pos = np.array([np.asarray(mt.position, float) for mt in engine.mounts])
    far = int(np.argmax(np.abs(pos[:, 0] - engine.body.cg[0])))
    ang = rng.uniform(0, np.pi)
    shape = np.array([0.0, np.cos(ang), np.sin(ang)])
    mounts = np.array([shape if m == far else -0.15 * shape for m in range(len(pos))])
    return {"bending": tr.BendingMode(float(rng.uniform(80, 180)), float(rng.uniform(0.02, 0.05)),
                                      float(rng.uniform(8, 16)), pos[far], shape, mounts)}


def _apply_bending(p, parts):
    parts["bending"] = p["bending"]


KINDS = {k.name: k for k in [
    TruthKind("mount_temperature", "mount_stiffness", _draw_mount_temperature,
              _apply_mount_temperature),
    TruthKind("amplitude_elastomer", "amplitude_stiffness", _draw_amplitude, _apply_amplitude),
    TruthKind("balancer_shafts", "balancer_error", _draw_balancer, _apply_balancer),
    TruthKind("weak_cylinder", "cylinder_imbalance", _draw_weak_cylinder, _apply_weak_cylinder),
    TruthKind("sensor_triads", "sensor_error", _draw_sensor, _apply_sensor),
    TruthKind("chassis_base", "base_compliance", _draw_chassis, _apply_chassis),
    TruthKind("sensor_bracket", None, _draw_bracket, _apply_bracket),
    TruthKind("powertrain_bending", None, _draw_bending, _apply_bending),
]}
IN_LIBRARY = [k for k, v in KINDS.items() if v.library]
OUT_OF_LIBRARY = [k for k, v in KINDS.items() if not v.library]


# ----------------------------------------------------------------------- passive-side cases
def _draw_body_modes(rng, engine):
    """The vehicle body differs from the engine file's modal body: every mode ± 2 % in
    frequency, ± 5 % in modal mass, ± 10 % in damping, shape components ± 5 %; one or two modes
    0.75-0.88x or 1.12-1.3x in frequency with modal mass x e^N(0, 0.3) and damping
    x e^U(-0.7, 0.7)."""
    modes = engine.chassis.modes
    n_k = len(modes)
    f = np.array([m.frequency for m in modes]) * np.exp(rng.normal(0, 0.02, n_k))
    mu = np.array([m.modal_mass for m in modes]) * np.exp(rng.normal(0, 0.05, n_k))
    z = np.array([m.damping_ratio for m in modes]) * np.exp(rng.normal(0, 0.1, n_k))
    changed = rng.choice(n_k, int(rng.integers(1, 3)), replace=False)
    for k in changed:
        f[k] *= rng.uniform(0.75, 0.88) if rng.random() < 0.5 else rng.uniform(1.12, 1.3)
        mu[k] *= np.exp(rng.normal(0, 0.3))
        z[k] *= np.exp(rng.uniform(-0.7, 0.7))
    shapes = np.array([[m.shapes[mt.name] for mt in engine.mounts] for m in modes], float)
    shapes = shapes * np.exp(rng.normal(0, 0.05, shapes.shape))
    return {"body": tr.BodyModes(f, mu, z, shapes), "changed": [int(k) for k in changed]}


def _apply_body_modes(p, parts):
    parts["body"] = p["body"]


def _draw_missing_mode(rng, engine):
    """One body mode the file lacks, as wide as the physics: frequency U(20, 150) Hz, modal
    mass U(5, 40) kg for the shape normalised to its largest component, damping
    U(0.02, 0.06); shape components U(-1, 1) at every mount base and direction, normalised so
    that the largest is ±1 (no base or direction made dominant)."""
    n_m = len(engine.mounts)
    shape = rng.uniform(-1.0, 1.0, (n_m, 3))
    shape /= np.abs(shape).max()
    return {"frequency_hz": float(rng.uniform(20, 150)), "modal_mass": float(rng.uniform(5, 40)),
            "zeta": float(rng.uniform(0.02, 0.06)), "shape": shape}


def _apply_missing_mode(p, parts):
    b = parts["body"]
    parts["body"] = tr.BodyModes(np.append(b.mode_hz, p["frequency_hz"]),
                                 np.append(b.modal_mass, p["modal_mass"]),
                                 np.append(b.zeta, p["zeta"]),
                                 np.concatenate([b.shapes, p["shape"][None]], axis=0))


#: Truth kinds of the passive-side plan only (:mod:`benchmarks.passive`); kept out
#: of :data:`IN_LIBRARY`, so the default plan's draws are unchanged.
PASSIVE_KINDS = {"body_modes": TruthKind("body_modes", "chassis_modes", _draw_body_modes,
                                         _apply_body_modes),
                 "missing_mode": TruthKind("missing_mode", "missing_body_mode",
                                           _draw_missing_mode, _apply_missing_mode)}
KINDS.update(PASSIVE_KINDS)
