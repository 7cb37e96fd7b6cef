"""The diagnosis in HTML (``_repr_html_``, the study report's section): the verdict, then
where, which and how far as tables, worst first."""

from __future__ import annotations

import numpy as np

from powertrain.diagnosis.report import run_text
from powertrain.diagnosis.sides import side_text
from powertrain.diagnosis.where import REGION_DB, attribution_text
from powertrain.effects import EFFECTS
from powertrain.results.html import esc, number, paragraph, synthetic_mark, table

#: Regions listed in the table (the rest are counted; every one is in the JSON).
MAX_REGIONS = 12


def diagnosis_html(r) -> str:
    """A :class:`~powertrain.diagnosis.result.DiagnosisResult` as HTML."""
    d = r.data
    head = (f"<p>measured: <code>{esc(r.source)}</code>{synthetic_mark(r.synthetic)}<br>engine: "
            f"{esc(r.engine_name)}<br>data: {d.rpm.size} speeds {d.rpm[0]:g}...{d.rpm[-1]:g} rpm, "
            f"{len(d.channels)} channels, quantities {esc(', '.join(d.quantities))}; noise estimate "
            f"{r.noise_db:.2f} dB (1 sigma)<br>split: {esc(r.split['description'])}</p>")
    if r.runs:
        head += paragraph("plan: " + "; ".join(run_text(k, run) for k, run in enumerate(r.runs, start=1))
                          + " (one set of effect parameters; where and the figures describe run 1)")
    return (paragraph(f"VERDICT: {r.verdict_text}", "verdict") + head + _where(r) + _which(r) + _how_far(r))


def _where(r) -> str:
    p = r.parts
    share = p["share_alone"]
    text = (f"Decomposition of the order gaps (share of the sum of squares, each part alone): "
            f"structure/frequency {share['structure']:.0%}, excitation/order {share['excitation']:.0%}, "
            f"channel constant {share['const']:.0%}; all together {p['r2_full']:.0%}, residual "
            f"{p['residual_rms_db']:.2f} dB RMS. Attribution: {attribution_text(p['attribution'])}.")
    if p.get("sides"):
        text += f" Sides: {side_text(p['sides'])}."
    regions = sorted(r.regions, key=lambda g: -abs(g["gap_at_max_db"]))
    rows = [[g["mount"], g["direction"], g["quantity"], f"{g['rpm_from']:g}-{g['rpm_to']:g}",
             number(g["gap_at_max_db"], "+.1f"),
             number(g["frequency_hz_at_max"], ".0f") if g["frequency_hz_at_max"] else "-",
             g["kind"]] for g in regions[:MAX_REGIONS]]
    more = len(regions) - MAX_REGIONS
    caption = (f"Regions beyond ±{REGION_DB:g} dB, largest first"
               + (f" ({more} more in the JSON)" if more > 0 else ""))
    body = (table(["mount", "dir", "quantity", "speeds [rpm]", "max gap [dB]", "at [Hz]",
                   "kind"], rows, caption) if rows
            else paragraph(f"No region beyond ±{REGION_DB:g} dB."))
    return "<h4>1. Where</h4>" + paragraph(text) + body


def _which(r) -> str:
    b = r.baseline
    rows = [["(baseline)", 0, number(b.heldout_rms_db), "-", "-", "-", number(b.struct_db), ""]]
    for o in r.outcomes:
        rows.append([o.label, o.n_params, number(o.heldout_rms_db), number(o.t_stat, ".1f"),
                     number(o.bic_gain, ".1f"), number(100 * o.explained, ".0f") + " %"
                     if np.isfinite(o.explained) else "-", number(o.struct_db),
                     o.status + (" [evaluation budget hit]" if o.budget_hit else "")])
    out = ("<h4>2. Which (fitted on the training speeds, scored on the held-out ones)</h4>"
           + table(["candidate", "parameters", "held-out RMS [dB]", "t", "ΔBIC",
                    "explained", "structured residual [dB]", "status"], rows))
    if r.chosen is not None:
        items = []
        for e, ps in r.chosen.params.items():
            unit = r.chosen.units.get(e, {})
            txt = ", ".join(f"{k} = {v:.4g} ± {r.chosen.sigma[e][k]:.2g} {unit.get(k, '')}"
                            for k, v in ps.items())
            said = EFFECTS[e].summary(ps)
            items.append(f"<li>{esc(e)}: {esc(txt)}" + (f" = {esc(said)}" if said else "") + "</li>")
        out += "<p>Parameters (1 sigma, cell-clustered):</p><ul>" + "".join(items) \
            + "</ul>"
    out += "".join(paragraph(f"Equivalent explanation: {eq['text']}") for eq in r.equivalents)
    return out


def _how_far(r) -> str:
    b, d = r.baseline, r.data
    after = r.chosen or b
    rows = [[m, di, number(b.heldout_channel_rms[c]), number(after.heldout_channel_rms[c])]
            for c, (m, di) in enumerate(d.channels)]
    rows.sort(key=lambda row: -_value(row[2]))
    text = f"Overall held-out RMS gap {b.heldout_rms_db:.2f} -> {after.heldout_rms_db:.2f} dB"
    text += "".join(f"; run {k}: {run['heldout_rms_db_before']:.2f} -> "
                    f"{run['heldout_rms_db_after']:.2f} dB" for k, run in enumerate(r.runs, 1))
    return ("<h4>3. How far (held-out speeds)</h4>" + paragraph(text + ".")
            + table(["mount", "dir", "before [dB]", "after [dB]"], rows,
                    "Held-out RMS gap per channel before and after the chosen effect, worst first"))


def _value(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return -np.inf
