r"""Part of step 1 (where): does the gap live in the body, in the mounts or in the excitation?

Used when body-side (``NAME/passive``) channels are measured. With each point's scatter σ
(:func:`powertrain.diagnosis.noise_model.point_sigma_db`), the **excess over noise** of a set
of gaps :math:`\Delta L` [dB] is

.. math:: E^2 = \frac{\sum_i w_i(\Delta L_i^2 - \sigma_i^2)}{\sum_i w_i},\quad
          w_i = \sigma_i^{-2},

(0 when negative), resolved above :math:`\delta^2 = Z\sqrt{2n}/\sum_i w_i`
(:data:`Z_RESOLUTION`). The ratio :math:`R = E_p/\max(E_a, \delta_a)` of body side to engine
side is about 1 for an excitation change, 3-7 for a mount change and ≥ 15 for a body mode;
a mount change also moves its own engine-side channels (:data:`MOUNT_ENGINE_DB`), a body
change does not. Thresholds: :func:`_location`; rationale: docs/guide/diagnose.md, "Both
sides of the mounts".
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.channel import split_side
from powertrain.diagnosis.data import gap_data, model_levels, residuals_db
from powertrain.diagnosis.noise_model import point_sigma_db
from powertrain.effects import predict
from powertrain.effects.missing_body_mode import body_side_engine, mode_arrays
from powertrain.solvers.fast_harmonic import HarmonicModel

#: Body when R reaches this [1]: between mount changes (≤ 6.8) and body modes (≥ 15).
BODY_RATIO = 10.0
#: Mounts when R reaches this [1]: between excitation (≤ 0.91) and mount changes (≥ 3.1).
MOUNT_RATIO = 1.7
#: A mount's own engine-side excess that points at the mounts [dB]: between body changes
#: (≤ 0.55) and one-mount stiffness changes (≥ 0.7).
MOUNT_ENGINE_DB = 0.65
#: Body-side excess for a body answer [dB] (twice the 0.5 dB a model may miss by).
BODY_MIN_DB = 1.0
#: Body-side excess of an off mount base [dB] (a lab's run-to-run repeatability).
MOUNT_OFF_DB = 0.5
#: Mount bases that must be off for a shared (body) resonance [1].
MIN_SHARED_MOUNTS = 2
#: Standard errors of the squared excess under noise that resolve an excess [1].
Z_RESOLUTION = 3.0


def excess(gap, sigma) -> tuple:
    """``(E, δ)`` [dB]: excess RMS over noise of the finite ``gap`` and its resolution;
    ``sigma`` [dB] broadcasts to ``gap``."""
    g = np.asarray(gap, float)
    s = np.broadcast_to(np.asarray(sigma, float), g.shape)
    ok = np.isfinite(g) & np.isfinite(s)
    if not ok.any():
        return float("nan"), float("nan")
    g, v = g[ok], np.maximum(s[ok] ** 2, 1e-12)
    w = 1.0 / v
    e2 = float(np.sum(w * (g ** 2 - v)) / np.sum(w))
    d2 = float(Z_RESOLUTION * np.sqrt(2.0 * g.size) / np.sum(w))
    return float(np.sqrt(max(e2, 0.0))), float(np.sqrt(d2))


def _pairs(channels):
    """(engine-side index, body-side index, mount) of every direction measured on both sides."""
    index = {c: i for i, c in enumerate(channels)}
    out = []
    for i, (m, d) in enumerate(channels):
        base, side = split_side(m)
        if side == "passive" and (base, d) in index:
            out.append((index[(base, d)], i, base))
    return out


def _band(gap, sig, data, cols, n_bins=24):
    """Band [Hz] of the bins around the largest mean squared gap beyond noise, ≥ half of it."""
    f = np.broadcast_to(data.order_hz[:, None, :], gap.shape)
    g = gap[:, cols][:, :, data.order_mask]
    v = sig[:, cols][:, :, data.order_mask] ** 2
    f = f[:, cols][:, :, data.order_mask]
    ok = np.isfinite(g) & np.isfinite(v)
    if not ok.any():
        return None
    g, v, f = g[ok], v[ok], f[ok]
    edges = np.geomspace(f.min(), f.max() * 1.0001, n_bins + 1)
    k = np.clip(np.searchsorted(edges, f, side="right") - 1, 0, n_bins - 1)
    ms = np.array([max(np.mean(g[k == j] ** 2 - v[k == j]), 0.0) if np.any(k == j) else 0.0
                   for j in range(n_bins)])
    top = int(np.argmax(ms))
    lo, hi = top, top
    while lo > 0 and ms[lo - 1] >= 0.5 * ms[top]:
        lo -= 1
    while hi < n_bins - 1 and ms[hi + 1] >= 0.5 * ms[top]:
        hi += 1
    return [float(edges[lo]), float(edges[hi + 1])]


def _location(ea, da, ep, dp, a_mount):
    """``(side, R)`` from the excesses, resolutions and largest mount excess ``a_mount``."""
    a_on = np.isfinite(ea) and ea > da
    p_on = np.isfinite(ep) and ep > dp
    if not (a_on or p_on):
        return "none", 0.0
    ratio = (ep if p_on else 0.0) / max(ea if a_on else 0.0, da)
    if not (p_on and ratio >= MOUNT_RATIO):
        return "engine side or excitation", ratio
    if a_mount < MOUNT_ENGINE_DB and (ep >= BODY_MIN_DB or ratio >= BODY_RATIO):
        return "body", ratio
    return "mounts", ratio


def _per_mount(gap, sig, cols_of, om):
    """``{mount: (excess, resolution)}`` of each mount's channels ``cols_of[mount]``."""
    return {m: excess(gap[:, cols][:, :, om], sig[:, cols][:, :, om]) for m, cols in cols_of.items()}


def side_attribution(gap, data, sigma_db=None) -> dict | None:
    """Which side carries the order gap; None without body-side pairs.

    Parameters
    ----------
    gap : ndarray (n_r, n_ch, n_q)
        Gap map [dB], NaN where censored or not measured.
    data : GapData
    sigma_db : float or ndarray, optional
        Scatter [dB, 1σ], one or per point (default: :mod:`.noise_model`).
    """
    pairs = _pairs(data.channels)
    if not pairs:
        return None
    if sigma_db is None:
        sigma_db = point_sigma_db(data)
    sig = np.broadcast_to(np.asarray(sigma_db, float), gap.shape)
    om = data.order_mask
    a_idx, p_idx = [a for a, _, _ in pairs], [p for _, p, _ in pairs]
    both = np.isfinite(gap[:, a_idx]) & np.isfinite(gap[:, p_idx])
    ga = np.where(both, gap[:, a_idx], np.nan)[:, :, om]
    gp = np.where(both, gap[:, p_idx], np.nan)[:, :, om]
    sa, sp = sig[:, a_idx][:, :, om], sig[:, p_idx][:, :, om]
    ea, da = excess(ga, sa)
    ep, dp = excess(gp, sp)
    iso, _ = excess(ga - gp, np.sqrt(sa ** 2 + sp ** 2))
    body_cols, engine_cols = {}, {}
    for (a, p, base) in pairs:
        body_cols.setdefault(base, []).append(p)
        engine_cols.setdefault(base, []).append(a)
    engine = _per_mount(gap, sig, engine_cols, om)
    a_mount = max([e for e, d in engine.values() if np.isfinite(e) and e > d], default=0.0)
    where, ratio = _location(ea, da, ep, dp, a_mount)
    off = [m for m, (e, d) in _per_mount(gap, sig, body_cols, om).items()
           if np.isfinite(e) and e >= MOUNT_OFF_DB and e > d]
    cols = [p for m in off for p in body_cols[m]]
    return {"location": where, "engine_side_rms_db": ea, "body_side_rms_db": ep,
            "isolation_change_rms_db": iso, "body_to_engine_ratio": ratio,
            "engine_side_resolution_db": da, "body_side_resolution_db": dp,
            "largest_mount_engine_side_db": a_mount,
            "mounts_off_body_side": off, "shared": len(off) >= MIN_SHARED_MOUNTS,
            "noise_sigma_db": float(np.nanmedian(sig)) if np.isfinite(sig).any() else float("nan"),
            "band_hz": _band(gap, sig, data, cols) if (where == "body" and cols) else None}


def measured_sides(measured, engine, noise_floor) -> dict | None:
    """:func:`side_attribution` of ``measured`` against ``engine`` without effects (no fit);
    ``noise_floor`` [m/s]."""
    engine = with_measured_body_side(engine, measured)
    d = gap_data(measured, engine, noise_floor)
    hm = HarmonicModel(engine, d.rpm)
    hm.use_channels(d.channels)
    g = residuals_db(model_levels(predict(hm, {}).velocity, d), d.level, d.floor)
    return side_attribution(np.where(d.censored, np.nan, g), d)


def with_measured_body_side(engine, measured):
    """``engine``, with a rigid chassis whose body side is in ``measured`` made a modal body
    without modes (so a missing body mode can move it)."""
    ch = getattr(engine, "chassis", None)
    if ch is not None and not ch.is_rigid:
        return engine
    names = {m.name for m in engine.mounts}
    sides = {split_side(m) for m, _, _ in measured.curves}
    if any(side == "passive" and base in names for base, side in sides):
        return body_side_engine(engine)
    return engine


#: Share of the mode's largest shape component a base needs to take part [1].
SHAPE_SHARED = 0.5


def fitted_shape(effect, params, engine) -> dict | None:
    """The body mode answer ``effect`` (``params``) names, by its shape over the mount bases:
    ``{"effect", "mode", "frequency_hz", "bases", "shape", "shared"}``; None for other
    answers. ``chassis_modes``: the file mode changed most, its shape from ``engine``."""
    names = [m.name for m in engine.mounts]
    if effect == "missing_body_mode":
        mode = mode_arrays(params, len(names))
        if mode is None:
            return None
        f, shape, what, source = mode[0], mode[3], "the missing mode", "fitted shape"
    elif effect == "chassis_modes" and getattr(engine, "chassis", None) is not None:
        modes = engine.chassis.body_modes
        if not modes:
            return None
        moved = [abs(np.log(params[f"f{k + 1}"] / m.frequency))
                 + abs(np.log(params[f"m{k + 1}"] / m.modal_mass)) for k, m in enumerate(modes)]
        k = int(np.argmax(moved))
        shape = np.array([modes[k].shapes[n] for n in names], float)
        f, what = params[f"f{k + 1}"], f"body mode {k + 1} of the engine file"
        source = "shape (engine file)"
    else:
        return None
    top = np.abs(shape).max(axis=1)
    top = top / top.max() if top.max() > 0 else top
    bases = {n: float(v) for n, v in zip(names, top)}
    return {"effect": effect, "mode": what, "frequency_hz": float(f), "bases": bases,
            "shape": source, "shared": int(np.sum(top >= SHAPE_SHARED)) >= MIN_SHARED_MOUNTS}


def _shape_phrase(fs) -> str:
    """'body mode 2 of the engine file near 45 Hz, shared by the bases of left, ...'."""
    on = [m for m, v in fs["bases"].items() if v >= SHAPE_SHARED]
    quoted = ", ".join(f"{m} {v:.1f}" for m, v in fs["bases"].items())
    where = (f"shared by the bases of {', '.join(on)}" if fs["shared"] else f"local to the base of {on[0]}")
    return (f"{fs['mode']} near {fs['frequency_hz']:.0f} Hz, {where} (its {fs['shape']}, "
            f"largest component at each base: {quoted})")


def side_text(s) -> str:
    """One phrase for side attribution ``s`` ('' without body-side channels)."""
    if not s:
        return ""
    nums = (f"excess over noise: body side {s['body_side_rms_db']:.1f} dB RMS vs engine side "
            f"{s['engine_side_rms_db']:.2f} dB (ratio {s['body_to_engine_ratio']:.1f}), "
            f"isolation changed by {s['isolation_change_rms_db']:.1f} dB RMS")
    if s["location"] == "body":
        band = s.get("band_hz")
        at = f" near {band[0]:.0f}-{band[1]:.0f} Hz" if band else ""
        off = ", ".join(s["mounts_off_body_side"]) or "none"
        what = (f"a resonance shared by the bases of {off}{at}" if s["shared"] else
                f"local to the base of {off}{at}, not a mode shared by several bases")
        if s.get("fitted_shape"):
            what = _shape_phrase(s["fitted_shape"])
        return f"the gap lives in the body: {what} ({nums})"
    if s["location"] == "mounts":
        return f"the body side is off several times more than the engine side: the gap " \
               f"lives in the mounts ({nums})"
    if s["location"] == "none":
        return f"neither side of the mounts is off beyond the noise ({nums})"
    return (f"both sides of the mounts are off alike: the gap lives on the engine side or in "
            f"the excitation, not in the body or the mounts ({nums})")
