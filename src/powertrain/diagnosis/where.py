r"""Step 1 of the diagnosis: where the gap lies, and what kind of error it looks like.

The gap map, its regions beyond ±3 dB, and a decomposition of the order gaps into smooth
parts fitted by penalised least squares (hat bases: 32 knots in log f, 8 in rpm),

.. math:: \Delta L_{c,o}(n) \approx g_c + \Delta H_c\!\big(f = o\,n/60\big)
          + \Delta F_o(n),

a channel constant (sensor gain), a frequency-tied part (structure) and an order-tied part
(excitation). :func:`attribute` names the part that explains most when fitted alone, and
where (orders, band or channels); :func:`rigid_span_gap` is the gap outside rigid-body motion.
"""

from __future__ import annotations

import numpy as np
from scipy import sparse
from scipy.sparse.linalg import spsolve

from powertrain.diagnosis.data import GapData
from powertrain.diagnosis.sides import side_text

#: Gap beyond which a region is listed [dB].
REGION_DB = 3.0
#: Knots of the structure (frequency) and excitation (speed) bases.
N_FREQ_KNOTS = 32
N_RPM_KNOTS = 8
#: Second-difference smoothing and ridge weights of the decomposition.
LAM_SMOOTH, LAM_RIDGE = 3.0, 0.3
#: Share of their part's largest RMS the orders (band, channels) named must carry.
NAME_FRACTION = 0.5
KIND_LABEL = {"structure": "structural (tied to frequency)", "excitation": "excitation (tied to order/speed)",
              "const": "sensor gain (constant per channel)", "residual": "local/unexplained by smooth parts"}


def _hat_basis(x, knots):
    """Piecewise-linear (hat) basis on ``knots``, (n, n_knots); x clipped to the range."""
    x = np.clip(x, knots[0], knots[-1])
    B = np.zeros((x.size, knots.size))
    j = np.clip(np.searchsorted(knots, x) - 1, 0, knots.size - 2)
    t = (x - knots[j]) / (knots[j + 1] - knots[j])
    B[np.arange(x.size), j] = 1 - t
    B[np.arange(x.size), j + 1] = t
    return B


def _design(data: GapData, mask, n_ch, n_q):
    """Design matrix of the three parts, their column blocks and knots."""
    r_i, c_i, q_i = np.nonzero(mask)
    f = data.order_hz[r_i, q_i]
    fk = np.geomspace(max(f.min(), 1.0), f.max() * 1.0001, N_FREQ_KNOTS)
    rk = np.linspace(data.rpm.min(), data.rpm.max() * 1.0001 + 1e-6, N_RPM_KNOTS)
    Bf = _hat_basis(np.log(f), np.log(fk))
    Br = _hat_basis(data.rpm[r_i], rk)
    nf, nr = fk.size, rk.size
    p_c, p_h, p_f = n_ch, n_ch * nf, n_q * nr
    X = np.zeros((r_i.size, p_c + p_h + p_f))
    rows = np.arange(r_i.size)
    X[rows, c_i] = 1.0
    for j in range(nf):
        X[rows, p_c + c_i * nf + j] = Bf[:, j]
    for j in range(nr):
        X[rows, p_c + p_h + q_i * nr + j] = Br[:, j]
    blocks = {"const": slice(0, p_c), "structure": slice(p_c, p_c + p_h),
              "excitation": slice(p_c + p_h, p_c + p_h + p_f)}
    return X, blocks, fk, rk


def _penalties(blocks, n_ch, n_q, nf, nr, n_col):
    """Second-difference smoothing rows per curve and a small ridge on the curves."""
    pen = []
    for start, n_curves, n_knots in ((blocks["structure"].start, n_ch, nf),
                                     (blocks["excitation"].start, n_q, nr)):
        for c in range(n_curves):
            for j in range(1, n_knots - 1):
                row = np.zeros(n_col)
                row[start + c * n_knots + j - 1:start + c * n_knots + j + 2] = LAM_SMOOTH * \
                    np.array([1, -2, 1])
                pen.append(row)
    ridge = np.zeros((n_col, n_col))
    idx = np.arange(blocks["const"].stop, n_col)
    ridge[idx, idx] = LAM_RIDGE
    return np.vstack([np.array(pen).reshape(-1, n_col), ridge])


def _solve(X, P, y, cols):
    """Penalised least squares on the columns ``cols`` (others and empty columns zero)."""
    cols = np.asarray(cols)
    A = sparse.csc_matrix(np.vstack([X[:, cols], P[:, cols]]))
    used = np.flatnonzero(np.diff(A.indptr))
    A = A[:, used]
    b = np.concatenate([y, np.zeros(P.shape[0])])
    beta = np.zeros(X.shape[1])
    beta[cols[used]] = spsolve((A.T @ A).tocsc(), A.T @ b)
    return beta


def decompose_gap(gap, data: GapData, mask):
    r"""Fit :math:`g_c + \Delta H_c(f) + \Delta F_o(n)` to the order gaps [dB].

    Parameters
    ----------
    gap : ndarray (n_r, n_ch, n_q)
        Gap map [dB].
    data : GapData
    mask : ndarray bool, same shape
        Points used (finite, not censored, orders only).

    Returns
    -------
    dict
        Parts at every point (``const``, ``structure``, ``excitation``, ``residual``), each
        part's share (``share_alone``) and R² alone (``r2_alone``), ``r2_full``,
        ``residual_rms_db``, the fitted curves and the ``attribution``.
    """
    y = gap[mask]
    n_ch, n_q = gap.shape[1], gap.shape[2]
    X, blocks, fk, rk = _design(data, mask, n_ch, n_q)
    P = _penalties(blocks, n_ch, n_q, fk.size, rk.size, X.shape[1])
    beta = _solve(X, P, y, np.arange(X.shape[1]))
    parts = {k: X[:, s] @ beta[s] for k, s in blocks.items()}
    fit = sum(parts.values())
    ss = float(np.sum(y ** 2)) or 1.0
    out = {k: _on(mask, v) for k, v in parts.items()}
    out["residual"] = _on(mask, y - fit)
    share, alone, alone_fit, b_alone = {}, {}, {}, {}
    for k, v in parts.items():
        den = float(np.sum(v ** 2)) or 1.0
        s = float(np.dot(v, y)) / den
        share[k] = max(0.0, 1.0 - float(np.sum((y - s * v) ** 2)) / ss)
        b_alone[k] = _solve(X, P, y, np.arange(X.shape[1])[blocks[k]])
        xb = X @ b_alone[k]
        alone[k] = max(0.0, 1.0 - float(np.sum((y - xb) ** 2)) / ss)
        alone_fit[k] = _on(mask, xb)
    out.update(share_alone=share, r2_alone=alone, r2_full=1.0 - float(np.sum((y - fit) ** 2)) / ss,
               residual_rms_db=float(np.sqrt(np.mean((y - fit) ** 2))))
    out["structure_curves"] = {"frequency_hz": fk.tolist(),
                               "by_channel": beta[blocks["structure"]].reshape(n_ch, -1).tolist()}
    out["excitation_curves"] = {"rpm": rk.tolist(),
                                "by_quantity": beta[blocks["excitation"]].reshape(n_q, -1).tolist()}
    out["channel_const_db"] = beta[blocks["const"]].tolist()
    out["attribution"] = attribute(out, alone_fit, data, gap.shape[2], fk,
                                   beta_alone=b_alone["structure"][blocks["structure"]])
    return out


def _on(mask, v):
    """``v`` at the points ``mask``, NaN elsewhere."""
    a = np.full(mask.shape, np.nan)
    a[mask] = v
    return a


def attribute(parts, alone_fit, data: GapData, n_q, fk, beta_alone):
    """Kind of the gap (largest R² alone in ``parts``) and where it lives in that part's own
    fit ``alone_fit`` (n_q quantities): orders, band (``beta_alone`` on the knots ``fk``
    [Hz]) or channels carrying :data:`NAME_FRACTION` of its largest RMS."""
    alone = parts["r2_alone"]
    kind = max(("structure", "excitation", "const"), key=lambda k: alone[k])
    out = {"kind": kind, "label": KIND_LABEL[kind], "r2_alone": alone[kind]}
    fit = alone_fit[kind]
    if kind == "excitation":
        rms = np.array([np.sqrt(np.nanmean(fit[:, :, k] ** 2))
                        if np.isfinite(fit[:, :, k]).any() else 0.0 for k in range(n_q)])
        top = np.flatnonzero(rms >= NAME_FRACTION * rms.max()) if rms.max() > 0 else []
        out["orders"] = [float((data.harmonic[k] + 1) / 2.0) for k in top]
    elif kind == "structure":
        level = np.sqrt(np.mean(np.abs(beta_alone.reshape(-1, fk.size)) ** 2, axis=0))
        hot = np.flatnonzero(level >= NAME_FRACTION * level.max()) if level.max() > 0 else [0]
        out["band_hz"] = [float(fk[hot[0]]), float(fk[hot[-1]])]
    else:
        rms = np.array([np.sqrt(np.nanmean(fit[:, c] ** 2)) if np.isfinite(fit[:, c]).any()
                        else 0.0 for c in range(fit.shape[1])])
        top = np.flatnonzero(rms >= NAME_FRACTION * rms.max()) if rms.max() > 0 else []
        out["channels"] = [list(data.channels[c]) for c in top]
    return out


def attribution_text(att) -> str:
    """One phrase for attribution ``att``: the kind of gap and where it lives."""
    txt = f"the gap looks mostly like {att['label']} error ({att['r2_alone']:.0%} of it)"
    if att.get("orders"):
        txt += " at orders " + ", ".join(f"{o:g}" for o in att["orders"])
    if att.get("band_hz"):
        txt += f" in the band {att['band_hz'][0]:.0f}-{att['band_hz'][1]:.0f} Hz"
    if att.get("channels"):
        txt += " on " + ", ".join(f"{m} {d}" for m, d in att["channels"])
    return txt


def rigid_span_gap(velocity, data: GapData, channel_matrix):
    r"""Gap left outside the rigid-body span [dB], (n_r, n_q_orders) RMS over channels.

    Measured magnitudes with simulated phases ``velocity``, :math:`\tilde v_c = m_c\,e^{i\angle
    s_c}`, projected on the span of ``channel_matrix`` (n_ch×6); RMS over channels of
    :math:`20\log_{10}(|P\tilde v|_c/m_c)` where all channels are measured.
    """
    qs = np.flatnonzero(data.order_mask)
    out = np.full((data.rpm.size, qs.size), np.nan)
    pinv = channel_matrix @ np.linalg.pinv(channel_matrix)
    usable = data.usable
    for j, k in enumerate(qs):
        h = data.harmonic[k]
        m = data.level[:, :, k]
        ok = np.all(usable[:, :, k], axis=1)
        if not ok.any():
            continue
        vt = m[ok] * np.exp(1j * np.angle(velocity[ok][:, :, h]))
        proj = vt @ pinv.T
        out[ok, j] = np.sqrt(np.mean((20 * np.log10(np.abs(proj) / m[ok])) ** 2, axis=1))
    return out


def _runs(over):
    """(start, stop) of the runs of True in a bool vector (stop inclusive)."""
    d = np.diff(np.concatenate([[0], over.astype(int), [0]]))
    return [(int(a), int(b) - 1) for a, b in zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1))]


def regions(gap, data: GapData, parts):
    """Contiguous speed ranges with |``gap``| > REGION_DB per channel and quantity, kinds
    from the decomposition ``parts``; largest first."""
    found = []
    for c, (mount, direction) in enumerate(data.channels):
        for k, q in enumerate(data.quantities):
            g = gap[:, c, k]
            for i, j in _runs(np.isfinite(g) & (np.abs(g) > REGION_DB)):
                seg = g[i:j + 1]
                h = data.harmonic[k]
                kind = "synthesis (see orders)" if h < 0 else _region_kind(parts, slice(i, j + 1), c, k)
                worst = i + int(np.nanargmax(np.abs(seg)))
                found.append({"mount": mount, "direction": direction, "quantity": q,
                              "rpm_from": float(data.rpm[i]), "rpm_to": float(data.rpm[j]),
                              "n_points": int(j - i + 1), "max_abs_db": float(np.nanmax(np.abs(seg))),
                              "gap_at_max_db": float(g[worst]),
                              "frequency_hz_at_max": float(data.rpm[worst] * (h + 1) / 120.0)
                              if h >= 0 else None,
                              "kind": kind})
    found.sort(key=lambda r: -r["max_abs_db"])
    return found


def _region_kind(parts, sl, c, k):
    ss = {label: float(np.nansum(parts[name][sl, c, k] ** 2)) for name, label in KIND_LABEL.items()}
    return max(ss, key=ss.get)


def where_text(found, parts):
    """The 'where' phrase of an unexplained verdict from regions ``found`` and ``parts``."""
    txt = attribution_text(parts["attribution"])
    if parts.get("sides"):
        txt += "; " + side_text(parts["sides"])
    if found:
        r = found[0]
        txt += (f"; worst at {r['mount']} {r['direction']} {r['quantity']} "
                f"{r['rpm_from']:g}-{r['rpm_to']:g} rpm ({r['gap_at_max_db']:+.1f} dB)")
    return txt
