"""HTML tables of the comparison, what-if, modes and transient results (``_repr_html_`` and
the study report): the numbers of ``to_text()``, worst first."""

from __future__ import annotations

import numpy as np

from powertrain.analysis.orders import quantity_sort_key
from powertrain.results.html import esc, number, paragraph, synthetic_mark, table
from powertrain.solvers.modes import COORDINATES


def comparison_html(r) -> str:
    """A :class:`~powertrain.results.comparison.ComparisonResult`: sources, summary,
    per-channel gaps worst first, per-quantity metrics, phases, what was not compared."""
    meas = r.measured
    parts = [f"<p>measured: <code>{esc(meas.source)}</code>{synthetic_mark(meas.synthetic)}"
             f"<br>simulated: <code>{esc(r.simulated.source)}</code></p>",
             paragraph(r.summary())]
    rows = [[c.mount, c.direction, c.quantity, int(c.scored.sum()),
             number(c.stats["rms_db"]), number(c.stats["bias_db"], "+.2f"),
             number(c.stats["max_abs_db"]), number(c.stats["rpm_at_max_abs_db"], "g"),
             number(c.stats["frac"], ".3f"), number(c.stats["frfsm"], ".3f"),
             int(c.at_floor.sum()), int(c.outside.sum())] for c in r.worst_first()]
    parts.append(table(["mount", "dir", "quantity", "points", "RMS gap [dB]", "bias [dB]",
                        "max |gap| [dB]", "at [rpm]", "FRAC", "FRFSM", "at floor",
                        "outside"], rows,
                       "Per channel and quantity, worst (largest RMS gap) first; gap = "
                       "20 log10(sim/measured) at the measured speeds"))
    parts.append(table(["quantity", "RMS gap [dB]", "bias [dB]", "CSAC mean", "CSAC min",
                        "CSF mean", "CSF min"], [_quantity_row(pq) for pq in r.per_quantity()],
                       "Per quantity (CSAC and CSF across the channels at each speed)"))
    parts += _phase_table(r)
    notes = [f"{e['mount']} {e['direction']} {e['quantity']}: {len(e['rpm'])} points measured "
             "but not modelled (simulation below the noise floor)" for e in r.not_modelled]
    notes += _missing(r.missing)
    if notes:
        parts.append("<p>Not compared:</p><ul>" + "".join(f"<li>{esc(n)}</li>" for n in notes)
                     + "</ul>")
    return "".join(parts)


def _quantity_row(pq) -> list:
    head = [pq["quantity"], number(pq["rms_db"]), number(pq["bias_db"], "+.2f")]
    if not pq["n_rpm_with_csac"]:
        return head + ["-"] * 4
    return head + [number(pq["csac_mean"], ".3f"),
                   f"{number(pq['csac_min'], '.3f')} at {pq['rpm_at_csac_min']:g} rpm",
                   number(pq["csf_mean"], ".3f"),
                   f"{number(pq['csf_min'], '.3f')} at {pq['rpm_at_csf_min']:g} rpm"]


def _phase_table(r) -> list:
    phased = [c for c in r.worst_first() if c.stats.get("n_phase_compared")]
    if not phased:
        return []
    rows = [[c.mount, c.direction, c.quantity, c.stats["n_phase_compared"],
             number(c.stats["phase_rms_deg"], ".1f"), number(c.stats["phase_bias_deg"], "+.1f"),
             number(c.stats["complex_gap_db"], "+.2f"), number(c.stats["complex_gap_deg"], "+.1f")]
            for c in phased]
    return [table(["mount", "dir", "quantity", "points", "phase RMS [°]", "phase bias [°]",
                   "complex gap [dB]", "complex gap [°]"], rows,
                  "Phase where both sides give it (sim - measured, wrapped to ±180°)")]


def _missing(missing) -> list:
    groups = {}
    for m in missing:
        groups.setdefault((m["mount"], m["direction"], m["reason"]), []).append(m["quantity"])
    return [f"{mount} {direction}: {', '.join(sorted(qs, key=quantity_sort_key))}: {reason}"
            for (mount, direction, reason), qs in groups.items()]


def whatif_html(r) -> str:
    """A :class:`~powertrain.results.whatif.WhatIfResult`: baseline, one row per variant, then
    every channel-quantity's change per variant, largest first."""
    d, rpm = r.description, r.baseline.rpm
    modes = ", ".join(f"{f:.2f}" for f in r.baseline.rigid_body_modes_hz)
    parts = [paragraph(f"baseline: {d.get('engine')} ({d.get('engine_file')}), solver "
                       f"{d.get('solver')}, {rpm[0]:g}-{rpm[-1]:g} rpm; "
                       f"{r.baseline.modes_label}: {modes} Hz")]
    parts += [paragraph(tf.summary()) for tf in r.target_fits]
    changes = {v.name: r.channel_changes(v.name) for v in r.variants}
    parts.append(_variants_table(r, changes))
    signal = r.signal.replace("_", " ")
    keys = [(c["mount"], c["direction"], c["quantity"]) for c in changes[r.variants[0].name]]
    cells = {name: {(c["mount"], c["direction"], c["quantity"]): c for c in rows}
             for name, rows in changes.items()}
    largest = {key: max((_abs(cells[n][key]["max_abs_delta_db"]) for n in cells), default=0)
               for key in keys}
    rows = [[*key] + [f"{number(cells[n][key]['mean_delta_db'], '+.2f')} / "
                      f"{number(cells[n][key]['max_abs_delta_db'])}" for n in cells]
            for key in sorted(keys, key=lambda key: -largest[key])]
    parts.append(table(["mount", "dir", "quantity"] + [f"{n}: mean / max |Δ| [dB]"
                                                      for n in cells], rows,
                       f"Change of the RMS {signal} against the baseline, Δ = 20 log10(v/v0): "
                       "mean over the speeds / largest |Δ|, per variant; the largest change "
                       "first"))
    return "".join(parts)


def _variants_table(r, changes) -> str:
    gap = r.measured is not None and r.signal == "velocity"
    header = ["variant", "operations", "modes [Hz]", "mean Δ [dB]", "largest |Δ| [dB]",
              "where"] + (["mean |gap to measured| [dB]"] if gap else [])
    rows = []
    if gap:
        base = _mean_abs([g["mean_gap_to_measured_db"] for g in r.baseline_gaps()])
        rows.append(["baseline", "", ", ".join(f"{f:.2f}" for f in
                                              r.baseline.rigid_body_modes_hz),
                     "", "", "", number(base)])
    for v in r.variants:
        ch = changes[v.name]
        worst = max(ch, key=lambda c: _abs(c["max_abs_delta_db"]))
        means = [c["mean_delta_db"] for c in ch if c["mean_delta_db"] is not None]
        rows.append([v.name, "; ".join(v.specs),
                     ", ".join(f"{f:.2f}" for f in v.result.rigid_body_modes_hz),
                     number(np.mean(means) if means else None, "+.2f"),
                     number(worst["max_abs_delta_db"]),
                     f"{worst['mount']} {worst['direction']} {worst['quantity']} at "
                     f"{number(worst['rpm_at_max_abs'], 'g')} rpm"]
                    + ([number(_mean_abs([c.get("mean_gap_to_measured_db") for c in ch]))]
                       if gap else []))
    return table(header, rows, "Variants: mean change over every channel, quantity and speed, "
                 "the largest change and where"
                 + ("; mean |gap| to the measurement over the channel-quantities" if gap
                    else ""))


def _abs(value) -> float:
    return abs(value) if value is not None else -np.inf


def _mean_abs(values) -> float | None:
    ok = [abs(v) for v in values if v is not None]
    return float(np.mean(ok)) if ok else None


def modes_html(r) -> str:
    """A :class:`~powertrain.results.modes.ModesResult`: modes by frequency with damping and
    kinetic-energy distribution, and the torque-roll axis."""
    static = r.is_static()
    header = ["mode", "f [Hz]", "ζ"] + ([] if static else ["static f [Hz]", "MAC"]) \
        + ["dominant"] + [f"{c} [%]" for c in COORDINATES] + ["TRA angle [°]", "kind"]
    rows = [[i, number(m.frequency_hz, ".3f"), number(m.damping_ratio, ".3f")]
            + ([] if static else [number(m.static_frequency_hz, ".3f"),
                                  number(m.static_mac)])
            + [m.dominant] + [number(v, ".1f") for v in m.ked_percent]
            + [number(m.angle_to_torque_roll_axis_deg, ".1f"), m.kind]
            for i, m in enumerate(r.modes, 1)]
    t = r.torque_roll_axis
    axis = ", ".join(f"{v:.4f}" for v in t["direction"])
    return (paragraph(r.title().replace("\n", " "))
            + table(header, rows, "Modes by frequency; kinetic energy per coordinate")
            + paragraph(f"torque-roll axis through the CG, direction [{axis}] (engine axes), "
                        f"{t['angle_to_crank_axis_deg']:.2f}° from the crank axis"))


def transient_html(r) -> str:
    """A :class:`~powertrain.results.transient.TransientResult`: per-channel peaks (largest
    acceleration first) and the seat's ISO 2631-1 values."""
    p = r.peaks()
    order = np.argsort(-p["max_acceleration"], kind="stable")
    rows = [[r.channels[k], number(p["max_acceleration"][k], ".2f"),
             number(p["time_of_max_acceleration"][k], ".3f"),
             number(p["peak_to_peak"][k] * 1e3, ".2f"),
             "n/a" if np.isnan(p["peak_force"][k]) else number(p["peak_force"][k], ".0f")]
            for k in order]
    head = paragraph(f"manoeuvre {r.name} ({r.file}): {r.time[-1]:g} s, {r.time.size - 1} "
                     f"steps ({r.method}); peak crank speed {np.max(r.rpm):.0f} rpm")
    out = head + table(["channel", "max accel. [m/s²]", "at [s]", "p-p displ. [mm]",
                        "peak force [N]"], rows, "Per channel, largest acceleration first")
    if r.seat is not None:
        s = r.seat
        out += table(["seat axis", "weighted RMS [m/s²]", "VDV [m/s^1.75]", "weighting"],
                     [[a, number(s["rms"][a], ".4f"), number(s["vdv"][a], ".4f"),
                       s["weighting"][a] if isinstance(s["weighting"], dict) else s["weighting"]]
                      for a in "xyz"], f"Seat {s['point']}: ISO 2631-1")
    return out
