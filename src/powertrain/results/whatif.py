"""Result of ``powertrain whatif`` (docs/guide/whatif.md): baseline and variant run-ups and
the change 20 log10(v_variant / v_baseline) of the RMS velocity (or another ``signal``) per
channel, quantity and speed, its mean (``mean_delta_db``) and largest magnitude
(``max_abs_delta_db``). Speeds where both levels are below :data:`FLOOR_REL` of the
baseline maximum (a cancelled order) are left out.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain import __version__
from powertrain.analysis.channel import Channel
from powertrain.errors import InputError
from powertrain.plotting import plot_whatif
from powertrain.plotting.style import target_and_path
from powertrain.results.base import JsonResult
from powertrain.results.html import fragment
from powertrain.results.html_tables import whatif_html

#: Quantities reported by default.
QUANTITIES = ("synthesis", "order_2", "order_4")
#: Levels below this fraction of the baseline curve's maximum are not compared (both sides).
FLOOR_REL = 1e-9


@dataclass(frozen=True)
class VariantRun:
    """One variant: name, the operations' specs and its run-up."""

    name: str
    specs: list
    result: object


def delta_db(base, variant, floor_rel=FLOOR_REL) -> np.ndarray:
    """:math:`20\\log_{10}(v/v_0)` [dB]; NaN where both are below the floor.

    Parameters
    ----------
    base, variant : array_like
        Levels (any consistent unit), same shape.
    floor_rel : float
        Floor relative to ``max(base)``.
    """
    b = np.asarray(base, float)
    v = np.asarray(variant, float)
    floor = floor_rel * (np.max(b) if b.size else 0.0)
    tiny = np.finfo(float).tiny
    out = 20 * np.log10(np.maximum(v, tiny) / np.maximum(b, tiny))
    out[(b <= floor) & (v <= floor)] = np.nan
    return out


@dataclass(frozen=True)
class WhatIfResult(JsonResult):
    """Baseline and variant run-ups with their changes in dB.

    Attributes
    ----------
    baseline : RunupResult
    variants : list of VariantRun
    description : dict
        Baseline description (engine, file, solver, speeds, mounts...).
    quantities : tuple of str
    measured : MeasuredRunup or None
        Overlaid measurement.
    target_fits : list of TargetFit
    signal : str
        ``velocity`` (default), ``mount_force``, ``displacement`` or ``acceleration``.
    """

    baseline: object
    variants: list
    description: dict = field(default_factory=dict)
    quantities: tuple = QUANTITIES
    measured: object = None
    target_fits: list = field(default_factory=list)
    signal: str = "velocity"
    #: optional response to minimise: (channel, direction, quantity, rpm_lo, rpm_hi)
    objective: tuple | None = None
    #: speed step of the grid [rpm] (None: one speed)
    rpm_step: float | None = None

    JSON_INDENT = 2

    def to_text(self, written=()) -> str:
        """What ``powertrain whatif`` prints, naming the files ``written``."""
        d, rpm = self.description, self.baseline.rpm
        modes = ", ".join(f"{f:.2f}" for f in self.baseline.rigid_body_modes_hz)
        step = "" if self.rpm_step is None else f" step {self.rpm_step:g}"
        lines = [f"baseline: {d.get('engine')} ({d.get('engine_file')}), solver "
                 f"{d.get('solver')}, {rpm[0]:g}-{rpm[-1]:g} rpm{step}",
                 f"baseline {self.baseline.modes_label}: {modes}"]
        lines += [tf.summary() for tf in self.target_fits]
        lines += [f"change of RMS {self.signal.replace('_', ' ')} vs baseline, 20 log10(v/v0) "
                  "[dB]: mean over speeds / max |d|", self.table()]
        if self.objective is not None:
            lines.append(self.objective_text())
        written = [p for p in written if p]
        if written:
            lines.append(f"wrote {', '.join(written)}")
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        return fragment(whatif_html(self))

    def target_fit(self, key: str = "target"):
        """The one retune (:class:`~powertrain.workflows.retune.TargetFit`); InputError naming
        ``key`` unless exactly one target was given."""
        if len(self.target_fits) != 1:
            raise InputError(f"needs exactly one target, {len(self.target_fits)} given",
                             key=key)
        return self.target_fits[0]

    def objective_changes(self) -> list:
        """Variants by mean change of the objective over its band [dB], best first: ``name``,
        ``mean_delta_db``, ``baseline_rms_si``, ``variant_rms_si`` (band means, SI)."""
        if self.objective is None:
            return []
        name, d, q, lo, hi = self.objective
        rpm = np.asarray(self.baseline.rpm, float)
        band = (rpm >= lo - 1e-9) & (rpm <= hi + 1e-9)
        base = self.baseline.curve(name, d, q, self.signal)
        out = []
        for v in self.variants:
            var = v.result.curve(name, d, q, self.signal)
            dd = delta_db(base, var)[band]
            ok = np.isfinite(dd)
            out.append({"name": v.name,
                        "mean_delta_db": float(np.mean(dd[ok])) if ok.any() else None,
                        "baseline_rms_si": float(np.mean(base[band])),
                        "variant_rms_si": float(np.mean(var[band]))})
        return sorted(out, key=lambda r: np.inf if r["mean_delta_db"] is None
                      else r["mean_delta_db"])

    def objective_text(self) -> str:
        if self.objective is None:
            return ""
        name, d, q, lo, hi = self.objective
        label = Channel.of_node(name, d).label
        lines = [f"objective: minimise {label} {q} RMS {self.signal.replace('_', ' ')} at "
                 f"{lo:g}-{hi:g} rpm (mean change over the band, best first)"]
        for r in self.objective_changes():
            val = "-" if r["mean_delta_db"] is None else f"{r['mean_delta_db']:+.2f} dB"
            lines.append(f"  {val:>10}  {r['name']}")
        return "\n".join(lines)

    def variant(self, name: str) -> VariantRun:
        for v in self.variants:
            if v.name == name:
                return v
        raise KeyError(name)

    def delta_db(self, name: str, mount: str, direction: str, quantity: str = "synthesis"):
        """Change of a variant against the baseline per speed step [dB]."""
        res = self.variant(name).result
        return delta_db(self.baseline.curve(mount, direction, quantity, self.signal),
                        res.curve(mount, direction, quantity, self.signal))

    def channel_changes(self, name: str) -> list:
        """Per channel and quantity: ``mount``, ``direction``, ``quantity``,
        ``mean_delta_db``, ``max_abs_delta_db``, ``rpm_at_max_abs``, ``delta_db`` (list)
        and, with a measurement, ``mean_gap_to_measured_db``."""
        res = self.variant(name).result
        rpm = np.asarray(self.baseline.rpm, float)
        out = []
        for mount, direction in self.baseline.channels:
            for q in self.quantities:
                d = self.delta_db(name, mount, direction, q)
                ok = np.isfinite(d)
                row = {"mount": mount, "direction": direction, "quantity": q,
                       "mean_delta_db": float(np.mean(d[ok])) if ok.any() else None,
                       "max_abs_delta_db": float(np.max(np.abs(d[ok]))) if ok.any() else None,
                       "rpm_at_max_abs": float(rpm[ok][np.argmax(np.abs(d[ok]))])
                       if ok.any() else None,
                       "delta_db": [None if not np.isfinite(x) else float(x) for x in d]}
                if self.measured is not None and self.signal == "velocity":
                    row["mean_gap_to_measured_db"] = _gap_to_measured(
                        res, self.measured, mount, direction, q)
                out.append(row)
        return out

    def baseline_gaps(self) -> list:
        """Mean gap baseline vs measurement per channel and quantity [dB] (or empty)."""
        if self.measured is None or self.signal != "velocity":
            return []
        return [{"mount": m, "direction": d, "quantity": q,
                 "mean_gap_to_measured_db": _gap_to_measured(self.baseline, self.measured,
                                                             m, d, q)}
                for m, d in self.baseline.channels for q in self.quantities]

    def to_dict(self) -> dict:
        base = dict(self.description)
        base.setdefault("rpm", [float(r) for r in self.baseline.rpm])
        base["rigid_body_modes_hz"] = [float(f) for f in self.baseline.rigid_body_modes_hz]
        if self.measured is not None:
            base["measured"] = {"file": self.measured.source,
                                "synthetic": bool(self.measured.synthetic),
                                "channels": self.baseline_gaps()}
        return {"format": "powertrain-whatif", "format_version": 1,
                "powertrain_version": __version__, "signal": self.signal,
                "definition": f"delta_db = 20 log10(v_variant / v_baseline), v = RMS "
                              f"{self.signal}; "
                              "mean_delta_db = mean over the speed steps; max_abs_delta_db = "
                              "largest |delta_db|",
                "quantities": list(self.quantities), "baseline": base,
                "targets": [tf.to_dict() for tf in self.target_fits],
                "objective": None if self.objective is None else {
                    "channel": self.objective[0], "direction": self.objective[1],
                    "quantity": self.objective[2], "rpm": list(self.objective[3:]),
                    "ranking": self.objective_changes()},
                "variants": [{"name": v.name, "operations": list(v.specs),
                              "rigid_body_modes_hz": [float(f) for f in
                                                      v.result.rigid_body_modes_hz],
                              "channels": self.channel_changes(v.name)}
                             for v in self.variants]}

    def table(self) -> str:
        """Text table per variant: rows = channels, columns = mean / max |Δ| [dB] per quantity."""
        blocks = []
        for v in self.variants:
            rows = {}
            for r in self.channel_changes(v.name):
                key = f"{r['mount']}.{r['direction']}"
                cell = ("-" if r["mean_delta_db"] is None else
                        f"{r['mean_delta_db']:+.2f} / {r['max_abs_delta_db']:.2f}")
                rows.setdefault(key, [key]).append(cell)
            header = ["channel"] + [f"{q} mean/max|d| [dB]" for q in self.quantities]
            modes = ", ".join(f"{f:.2f}" for f in v.result.rigid_body_modes_hz)
            blocks.append(f"variant {v.name!r} ({'; '.join(v.specs)}) vs baseline\n"
                          f"{v.result.modes_label}: {modes}\n"
                          + _format_table(header, list(rows.values())))
        return "\n\n".join(blocks)

    def plot(self, ax=None, *, path=None, channel=None, quantity=None, provenance=None,
             view="levels"):
        """Levels of baseline, variants and measurement (``view="levels"``) or each variant's
        Δ dB (``"delta"``); returns the figure (:func:`powertrain.plotting.plot_whatif`).
        ``ax``: None, a Figure or SubFigure, or one Axes where ``channel`` and ``quantity``
        leave one panel."""
        ax, path = target_and_path(ax, path)
        return plot_whatif(self, path, ax=ax, channel=channel, quantity=quantity,
                           provenance=provenance, view=view)


def _format_table(header, rows) -> str:
    """Fixed-width text table of strings, first column left-aligned."""
    widths = [max(len(h), *(len(r[i]) for r in rows)) if rows else len(h)
              for i, h in enumerate(header)]

    def line(cells):
        return "  ".join(c.ljust(w) if i == 0 else c.rjust(w)
                         for i, (c, w) in enumerate(zip(cells, widths)))
    return "\n".join([line(header), line(["-" * w for w in widths])]
                     + [line(r) for r in rows])


def _gap_to_measured(result, measured, mount, direction, quantity):
    """Mean 20 log10(sim/measured) [dB] at the measured speeds in the simulated range (log
    level interpolated linearly); None if not available."""
    try:
        rpm_m, lev_m = measured.curve(mount, direction, quantity)
    except KeyError:
        return None
    rpm_s = np.asarray(result.rpm, float)
    sim = result.curve(mount, direction, quantity)
    order = np.argsort(rpm_s)
    rpm_s, sim = rpm_s[order], sim[order]
    inside = (rpm_m >= rpm_s[0]) & (rpm_m <= rpm_s[-1]) & (lev_m > 0)
    if not inside.any() or np.any(sim <= 0):
        return None
    s = np.exp(np.interp(rpm_m[inside], rpm_s, np.log(sim)))
    return float(np.mean(20 * np.log10(s / lev_m[inside])))
