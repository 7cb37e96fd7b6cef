r"""Part of step 1 (where): does the gap live in the body, in the mounts or in the excitation?

Used when the measured file carries body-side (passive) channels the model predicts (a
modal body under the mounts, or a rigid chassis whose body side the model holds still).
With the gap :math:`\Delta L` [dB] (+ = simulation higher) on the engine side (a) and the
body side (p) of every mount direction measured on both sides, each point carrying its own
scatter σ (:func:`powertrain.diagnosis.noise_model.point_sigma_db`: per channel and level),
the **excess over noise** of a set of points is

.. math:: E^2 = \frac{\sum_i w_i(\Delta L_i^2 - \sigma_i^2)}{\sum_i w_i},\quad
          w_i = \sigma_i^{-2},

(0 when negative) and its resolution :math:`\delta^2 = Z\sqrt{2n}/\sum_i w_i` (Z =
:data:`Z_RESOLUTION` standard errors of :math:`E^2` under noise alone). The side is read
from the **ratio of the body-side to the engine-side excess**,
:math:`R = E_p/\max(E_a, \delta_a)`:

* a changed **excitation** (balancer, combustion) moves both sides alike through the same
  transfer: R about 1 (0.65-0.91 for balancer errors);
* a changed **mount** moves the engine side directly and the body side more, through the
  changed isolation: R 3.1-6.8 (mount stiffness and amplitude-dependent mounts);
* a changed or missing **body** mode reaches the engine side only through the bases'
  motion (0.06-0.3 dB for several dB on the body side): R ≥ 15, unbounded.

A ratio of several times does not yet tell body from mounts: with the noise left, the
engine-side excess of a mount change often stays below its resolution, as a body change's
does. What tells them apart is the engine side of **one mount**: a changed mount moves its
own engine-side channels (0.7-1.5 dB in development draws of the two-sided plan), a body
change moves none of them by more than about 0.55 dB. So: **engine side or excitation**
when either side's excess is resolved and R < :data:`MOUNT_RATIO`; with R ≥
:data:`MOUNT_RATIO` (body side resolved), **mounts** when the largest engine-side excess of
one mount, A, reaches :data:`MOUNT_ENGINE_DB` (and its resolution), **body** when it does
not and :math:`E_p` ≥ :data:`BODY_MIN_DB`, or whenever R ≥ :data:`BODY_RATIO` with A below
:data:`MOUNT_ENGINE_DB`; **mounts** otherwise; **none** when neither side is resolved. A
body-side gap is *shared* by several bases when the excess at :data:`MIN_SHARED_MOUNTS` or
more mount bases reaches :data:`MOUNT_OFF_DB` and its resolution (its band: the
frequencies where the body-side gap is largest). The isolation change
:math:`\Delta L_a - \Delta L_p` is reported (its excess, with :math:`\sigma_a^2 +
\sigma_p^2`).
"""

from __future__ import annotations

import numpy as np

from powertrain.analysis.channel import split_side
from powertrain.diagnosis.data import gap_data, model_levels, residuals_db
from powertrain.diagnosis.noise_model import point_sigma_db
from powertrain.effects import predict
from powertrain.effects.missing_body_mode import body_side_engine, mode_arrays
from powertrain.solvers.fast_harmonic import HarmonicModel

#: Body when the body-side excess is at least this multiple of the engine side's [1]: the
#: geometric middle between mount changes (≤ 6.8) and body modes (≥ 15).
BODY_RATIO = 10.0
#: Mounts when the ratio is at least this [1]: the geometric middle between excitation
#: changes (≤ 0.91) and mount changes (≥ 3.1).
MOUNT_RATIO = 1.7
#: A mount's own engine-side excess that points at the mounts [dB]: between the largest
#: of body changes (about 0.55) and the smallest of one-mount stiffness changes (about 0.7)
#: in development draws of the two-sided plan.
MOUNT_ENGINE_DB = 0.65
#: ... and the body side carries at least this much [dB] for a body answer (twice the
#: 0.5 dB by which a model may miss).
BODY_MIN_DB = 1.0
#: A mount base counts as off when its body-side excess reaches this [dB] (a test lab's
#: run-to-run repeatability of order levels) and its resolution.
MOUNT_OFF_DB = 0.5
#: Mount bases that must be off for a shared (body) resonance [1].
MIN_SHARED_MOUNTS = 2
#: Standard errors of the squared excess under noise alone that resolve an excess [1].
Z_RESOLUTION = 3.0


def excess(gap, sigma) -> tuple:
    r"""``(E, δ)`` [dB]: the excess RMS over noise of the finite gaps and its resolution
    (module docstring); ``(nan, nan)`` without points. ``sigma`` broadcasts to ``gap``."""
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
    """(engine-side index, body-side index, mount) of every mount direction measured on
    both sides."""
    index = {c: i for i, c in enumerate(channels)}
    out = []
    for i, (m, d) in enumerate(channels):
        base, side = split_side(m)
        if side == "passive" and (base, d) in index:
            out.append((index[(base, d)], i, base))
    return out


def _band(gap, sig, data, cols, n_bins=24):
    """Frequency band [Hz] of the passive gap: mean squared gap *beyond the noise* (each
    point's σ² from the noise model taken off: points near the floor scatter most, and a
    plain mean squared gap peaks where they lie, not at the resonance) in log-spaced
    frequency bins (f = order × rpm / 60), the run of bins around the largest with at least
    half its value."""
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
    """The side from the two excesses, their resolutions and the largest resolved
    engine-side excess of one mount ``a_mount`` (module docstring)."""
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
    return {m: excess(gap[:, cols][:, :, om], sig[:, cols][:, :, om])
            for m, cols in cols_of.items()}


def side_attribution(gap, data, sigma_db=None) -> dict | None:
    """Which side carries the order gap (module docstring); None without body-side pairs.

    Parameters
    ----------
    gap : ndarray (n_r, n_ch, n_q)
        Gap map [dB], NaN where censored or not measured.
    data : GapData
    sigma_db : float or ndarray, optional
        Scatter [dB, 1σ]: one number for every point, or per point like ``gap`` (default:
        the noise model per channel and level, :mod:`powertrain.diagnosis.noise_model`).
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
            "noise_sigma_db": float(np.nanmedian(sig)) if np.isfinite(sig).any() else
            float("nan"),
            "band_hz": _band(gap, sig, data, cols) if (where == "body" and cols) else None}


def measured_sides(measured, engine, noise_floor) -> dict | None:
    """The side attribution of a measured run-up alone: the diagnosis' "where" step on the
    gap against the model without effects, no fit (cheap; the validation's side rate)."""
    engine = with_measured_body_side(engine, measured)
    d = gap_data(measured, engine, noise_floor)
    hm = HarmonicModel(engine, d.rpm)
    hm.use_channels(d.channels)
    g = residuals_db(model_levels(predict(hm, {}).velocity, d), d.level, d.floor)
    return side_attribution(np.where(d.censored, np.nan, g), d)


def with_measured_body_side(engine, measured):
    """``engine`` as the diagnosis models it: a rigid chassis whose body side is measured
    (channels ``NAME/passive`` of its mounts) is a modal body without modes — the body side
    predicted still, so that a missing body mode can give it motion
    (:func:`powertrain.effects.missing_body_mode.body_side_engine`); else unchanged."""
    ch = getattr(engine, "chassis", None)
    if ch is not None and not ch.is_rigid:
        return engine
    names = {m.name for m in engine.mounts}
    sides = {split_side(m) for m, _, _ in measured.curves}
    if any(side == "passive" and base in names for base, side in sides):
        return body_side_engine(engine)
    return engine


#: A base takes part in a fitted body mode when its largest shape component reaches this
#: share of the mode's largest [1] (half: the base moves at least half as much).
SHAPE_SHARED = 0.5


def fitted_shape(effect, params, engine) -> dict | None:
    """The body mode an answer names, by its shape over the mount bases: ``{"effect",
    "mode", "frequency_hz", "bases": {mount: largest |shape component| at its base,
    normalised to the mode's largest}, "shape": where the shape comes from, "shared": two or
    more bases at least :data:`SHAPE_SHARED`}``; None for other answers.
    ``missing_body_mode``: its fitted shape; ``chassis_modes``: the file mode changed most
    (frequency and modal mass, in log), with its shape from the engine file."""
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
    """'body mode 2 of the engine file near 45 Hz, shared by the bases of left, gearbox
    (its shape (engine file), largest component at each base: left 0.6, right 0.2, gearbox
    1.0)'."""
    on = [m for m, v in fs["bases"].items() if v >= SHAPE_SHARED]
    quoted = ", ".join(f"{m} {v:.1f}" for m, v in fs["bases"].items())
    where = (f"shared by the bases of {', '.join(on)}" if fs["shared"] else
             f"local to the base of {on[0]}")
    return (f"{fs['mode']} near {fs['frequency_hz']:.0f} Hz, {where} (its {fs['shape']}, "
            f"largest component at each base: {quoted})")


def side_text(s) -> str:
    """One phrase for the where step ('' without body-side channels)."""
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
