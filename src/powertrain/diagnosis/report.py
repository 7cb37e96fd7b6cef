"""Step 5 of the diagnosis, in words and figures: ``summary.txt`` and the report folder."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from powertrain.diagnosis.sides import side_text
from powertrain.diagnosis.where import REGION_DB, attribution_text
from powertrain.effects import EFFECTS
from powertrain.outputs import atomic_write
from powertrain.plotting import plot_diagnosis_overlay, plot_gap_frequency, plot_gap_map
from powertrain.plotting.style import close_figure

_PHASE_WORDS = {"all": "order phases measured, half orders too",
                "whole": "whole-order phases only (no cycle reference)"}


def _header(r) -> list:
    d, p = r.data, r.parts
    lines = [f"measured: {r.source}{' [SYNTHETIC]' if r.synthetic else ''}", f"engine: {r.engine_name}",
             f"data: {d.rpm.size} speeds {d.rpm[0]:g}..{d.rpm[-1]:g} rpm, "
             f"{len(d.channels)} channels, quantities {', '.join(d.quantities)}; "
             f"noise estimate {r.noise_db:.2f} dB (1 sigma)", f"split: {r.split['description']}"]
    if r.runs:
        lines.append(f"plan: {len(r.runs)} runs diagnosed together (one set of effect "
                     f"parameters; speeds held out within each run): " + "; ".join(
                         run_text(k, run) for k, run in enumerate(r.runs, start=1))
                     + "; WHERE and the figures describe run 1, data and split above too")
    ph = r.phase or {}
    if ph.get("measured", "none") != "none":
        offs = ", ".join(f"{o:+.2f}" for o in ph["crank_offset_deg_per_run"] if o is not None)
        lines.append(f"phase: {_PHASE_WORDS[ph['measured']]}; {ph['scored_points']} phase "
                     f"points scored as complex residuals; crank-angle offset estimated {offs} deg")
    lines += ["", "1. WHERE", f"  decomposition of the order gaps (share of sum of squares, each part "
             f"alone): structure/frequency {p['share_alone']['structure']:.0%}, excitation/order "
             f"{p['share_alone']['excitation']:.0%}, channel constant {p['share_alone']['const']:.0%}; all "
             f"together {p['r2_full']:.0%}, residual {p['residual_rms_db']:.2f} dB RMS",
             f"  attribution (each part fitted alone): {attribution_text(p['attribution'])}"]
    if p.get("sides"):
        lines.append(f"  sides: {side_text(p['sides'])}")
    rg = r.rigid_gap[np.isfinite(r.rigid_gap)]
    if rg.size:
        lines.append(f"  outside the rigid-body span: median {np.median(rg):.2f} dB RMS "
                     f"over channels (90 % {np.percentile(rg, 90):.2f} dB)")
    lines.append(f"  regions beyond +-{REGION_DB:g} dB: {len(r.regions)}")
    for g in r.regions[:12]:
        fq = f" ({g['frequency_hz_at_max']:.0f} Hz)" if g["frequency_hz_at_max"] else ""
        lines.append(f"    {g['mount']:>7} {g['direction']} {g['quantity']:<10} "
                     f"{g['rpm_from']:>6g}-{g['rpm_to']:<6g} rpm  max {g['gap_at_max_db']:+.1f} "
                     f"dB{fq}  {g['kind']}")
    if len(r.regions) > 12:
        lines.append(f"    ... {len(r.regions) - 12} more in the JSON")
    return lines


def _which(r) -> list:
    b = r.baseline
    lines = ["", "2. WHICH (fitted on the training speeds, scored on the held-out ones)",
             f"  {'candidate':<40} {'p':>2} {'held-out dB':>11} {'t':>6} {'dBIC':>8} "
             f"{'expl.':>6} {'struct dB':>9}  status",
             f"  {'(baseline)':<40} {0:>2} {b.heldout_rms_db:>11.2f} {'':>6} {'':>8} "
             f"{'':>6} {b.struct_db:>9.2f}"]
    for o in r.outcomes:
        expl = f"{o.explained:>6.0%}" if np.isfinite(o.explained) else f"{'-':>6}"
        lines.append(f"  {o.label:<40} {o.n_params:>2} {o.heldout_rms_db:>11.2f} "
                     f"{o.t_stat:>6.1f} {o.bic_gain:>8.1f} {expl} {o.struct_db:>9.2f}  {o.status}")
    if r.chosen is not None:
        lines.append("  parameters (1 sigma and 95 % interval, cell-clustered: docs/guide/diagnose.md):")
        for e, ps in r.chosen.params.items():
            unit = r.chosen.units.get(e, {})
            txt = ", ".join(f"{k} = {v:.4g} +- {r.chosen.sigma[e][k]:.2g}"
                            f"{_interval_text(r.chosen.interval.get(e, {}).get(k))} "
                            f"{unit.get(k, '')}" for k, v in ps.items())
            lines.append(f"    {e}: {txt}")
            said = EFFECTS[e].summary(ps)
            if said:
                lines.append(f"    = {said}")
    for eq in r.equivalents:
        lines.append(f"  equivalent explanation: {eq['text']}")
    if r.band_check:
        lines.append("  confounding check (refit on speed bands):")
        for bnd in r.band_check:
            txt = ", ".join(f"{k}={v:.3g}" for k, v in bnd["parameters"].items())
            lines.append(f"    {bnd['rpm_from']:g}-{bnd['rpm_to']:g} rpm: {txt}")
    return lines


def _interval_text(iv) -> str:
    """`` (95 % 70.1..79.3)``, or "" without a finite interval."""
    if not iv or None in iv:
        return ""
    return f" (95 % {iv[0]:.4g}..{iv[1]:.4g})"


def run_text(k, run) -> str:
    """Plan run ``k``'s entry ``run`` in words: ``run 2 part.csv (load 0.4)``."""
    how = f"traces {Path(run['traces']).name}" if run.get("traces") else f"load {run['load']:g}"
    return f"run {k} {Path(run['file']).name} ({how})"


def _db(value) -> str:
    """A channel's held-out RMS [dB], or "-" without a held-out point."""
    return f"{value:.2f}" if np.isfinite(value) else "-"


def fit_notes(chosen, outcomes, bands, budget) -> list:
    """Sentences on how far the fits can be trusted: the answer ``chosen``'s second minimum,
    intervals and parameters at a bound; the ``outcomes`` and band refits ``bands`` stopped
    at their ``budget``."""
    out = []
    if chosen is not None and len(chosen.effects) == 1:
        eff = EFFECTS[chosen.effects[0]]
        ps = chosen.params[chosen.effects[0]]
        for alt in chosen.alternatives:
            out.append(eff.alternative_text(ps, alt["parameters"][chosen.effects[0]], alt["delta_chi2"]))
        said = eff.interval_text(chosen.interval.get(chosen.effects[0], {}))
        out += ([said] if said else []) + eff.bound_warnings(ps)
    if chosen is not None and chosen.budget_hit:
        out.append(f"the {chosen.label} fit stopped at its evaluation budget ({budget}): its "
                   f"parameters are the best point found, not a converged optimum (the "
                   f"verdict rests on that point's held-out scores)")
    others = [o.label for o in outcomes if o.budget_hit and o is not chosen]
    if others:
        out.append(f"{len(others)} other fit(s) stopped at their evaluation budget ({', '.join(others)}): "
                   f"scored at their best point so far, they may fit better than ranked")
    n_band = sum(bool(b.get("budget_hit")) for b in bands)
    if n_band:
        out.append(f"{n_band} of {len(bands)} speed-band refits stopped at their budget: "
                   f"those bands do not pin the parameters down (e.g. a mode refitted away "
                   f"from its resonance), so their trend with speed says nothing")
    return out


def summary(r) -> str:
    """The plain-text report of result ``r``: where, which, how far, verdict."""
    b, d = r.baseline, r.data
    lines = _header(r) + _which(r)
    lines += ["", "3. HOW FAR (held-out speeds)"]
    after = r.chosen or b
    lines.append(f"  {'mount':>7} {'dir':>3} {'before dB':>9} {'after dB':>8}")
    for c, (m, di) in enumerate(d.channels):
        lines.append(f"  {m:>7} {di:>3} {_db(b.heldout_channel_rms[c]):>9} "
                     f"{_db(after.heldout_channel_rms[c]):>8}")
    lines.append(f"  overall {b.heldout_rms_db:.2f} -> {after.heldout_rms_db:.2f} dB RMS"
                 + (" (all runs; phase gaps included)" if r.phase.get("scored_points") else
                    " (all runs)" if r.runs else ""))
    for k, run in enumerate(r.runs, start=1):
        lines.append(f"  run {k}: {run['heldout_rms_db_before']:.2f} -> "
                     f"{run['heldout_rms_db_after']:.2f} dB RMS")
    lines += ["", f"VERDICT: {r.verdict_text}", f"({r.seconds:.1f} s)"]
    return "\n".join(lines)


#: The files of a report folder (:func:`write_report`), in the order written.
REPORT_FILES = ("summary.txt", "diagnosis.json", "gap_map.png", "gap_vs_frequency.png", "overlay.png")


def write_report(r, directory, provenance=None) -> list:
    """Write result ``r``'s :data:`REPORT_FILES` into ``directory`` (created if missing);
    ``provenance`` stamps the figures. Returns the paths."""
    out = Path(directory)
    with atomic_write(out / "summary.txt") as fh:
        fh.write(r.to_text() + "\n")
    r.to_json(out / "diagnosis.json")
    files = [out / "summary.txt", out / "diagnosis.json"]
    for name, fn in zip(REPORT_FILES[2:], (plot_gap_map, plot_gap_frequency, plot_diagnosis_overlay)):
        close_figure(fn(r, out / name, provenance=provenance))
        files.append(out / name)
    return files
