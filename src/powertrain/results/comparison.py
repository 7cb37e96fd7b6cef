"""Result of ``powertrain compare``: per-channel level gaps and correlation metrics of a
simulated run-up against a measured one, as text, JSON and figure."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from powertrain.analysis import compare as cm
from powertrain.analysis.noise_floor import NOISE_FLOOR_MARGIN, censoring_level
from powertrain.analysis.orders import quantity_sort_key
from powertrain.analysis.text_table import format_table
from powertrain.plotting import plot_comparison
from powertrain.plotting.style import target_and_path
from powertrain.results.base import JsonResult
from powertrain.results.html import fragment
from powertrain.results.html_tables import comparison_html

#: Quantities always expected (thesis sec. 4.4); any other measured order is compared too.
EXPECTED_QUANTITIES = ("synthesis", "order_2", "order_4")
#: CSAC and CSF are computed at a speed only if at least this many channels are compared there.
MIN_CHANNELS_CSAC = 3
#: The JSON's ``definitions`` (with the metrics' sources).
DEFINITIONS = {
    "gap_db": "20*log10(v_sim/v_meas) at each compared measured speed; positive = "
              "simulation higher",
    "interpolation": "simulation taken at the measured speeds: exact where simulated there "
                     "(simulated_at_measured_speeds), otherwise interpolated linearly in rpm "
                     "and linearly in log level; no extrapolation (points outside the "
                     "simulated speed range are not compared)",
    "rms_db": "sqrt(mean(gap_db^2)) over the compared speeds of the channel",
    "bias_db": "mean(gap_db) over the compared speeds of the channel",
    "max_abs_db": "max |gap_db| over the compared speeds, at rpm_at_max_abs_db",
    "frac": "(sum_n s_n m_n)^2 / (sum_n s_n^2 * sum_n m_n^2), summed over the compared speeds "
            "n of one channel and quantity; RMS magnitudes; 1 = same shape, blind to a "
            "common scale (Heylen et al. 1997; Allemang 2003)",
    "csac": "(sum_j s_j m_j)^2 / (sum_j s_j^2 * sum_j m_j^2), summed over the channels j "
            "compared at one speed and quantity; RMS magnitudes; shape across the channels, "
            "sensitive to mass/stiffness errors (Zang, Grafe & Imregun 2001)",
    "csf": "2|sum_j s_j m_j| / (sum_j s_j^2 + sum_j m_j^2), summed over the channels j at "
           "one speed and quantity; RMS magnitudes; also sensitive to level, i.e. damping "
           "and level errors (Zang, Grafe & Imregun 2001)",
    "frfsm": "mean over the compared speeds of exp(-gap_db^2 / (2 sigma^2)), sigma = "
             "frfsm_sigma_db; our simplified score following the idea of the FRF similarity "
             "metric of Lee, Ahn & Kim (JSV 436, 2018): likelihood of the level error under "
             "a normal distribution, normalised to 0..1",
    "noise_floor": "measured points below noise_floor_margin * noise_floor "
                   "(noise_floor_exclusion_m_per_s) are excluded and counted "
                   "(n_excluded_noise_floor), never scored",
    "measured_not_modelled": "simulation below noise_floor while the measurement is not "
                             "excluded: the model predicts nothing measurable there; counted "
                             "(n_measured_not_modelled), listed in measured_not_modelled, "
                             "never scored; n_simulation_zero counts those where the "
                             "simulation is exactly zero",
    "overall_rms_db": "sqrt(mean(gap_db^2)) pooled over every compared point of every "
                      "channel and quantity (not the measured-not-modelled points)",
    "phase_gap_deg": "phase_sim - phase_meas at each compared speed, wrapped to (-180, 180]; "
                     "phase re cylinder-1 firing TDC (order component sqrt2*RMS*cos(k*theta "
                     "+ phase)); null where a side gives no phase; only for channels with "
                     "phase on both sides; phase_rms_deg its RMS, phase_bias_deg the angle of "
                     "its mean phasor, n_phase_compared the points with both phases",
    "complex_gap": "complex_gap_db = 20*log10|a|, complex_gap_deg = arg a, a = sum(S conj(M)) "
                   "/ sum(|M|^2) over the points with both phases, S and M the complex RMS "
                   "amplitudes (level * exp(i phase)) of simulation and measurement: the "
                   "least-squares complex ratio sim/measured",
}


@dataclass(frozen=True)
class ChannelComparison:
    """Comparison of one channel (mount, direction) and quantity.

    Arrays cover all measured speeds of the channel, ``scored`` marks the compared ones;
    levels [m/s RMS], speeds [rpm], gaps [dB].
    """

    mount: str
    direction: str
    quantity: str
    rpm: np.ndarray
    measured: np.ndarray
    simulated: np.ndarray          # interpolated, NaN outside the simulated range
    outside: np.ndarray            # bool: outside the simulated speed range
    at_floor: np.ndarray           # bool: at or near the noise floor (inside the range)
    sim_zero: np.ndarray           # bool: simulation exactly zero (cannot be scored in dB)
    not_modelled: np.ndarray       # bool: simulation below the floor, measurement above
    interpolated: np.ndarray       # bool: inside the range but not at a simulated speed
    scored: np.ndarray             # bool
    gap_db: np.ndarray             # at the scored speeds
    stats: dict = field(default_factory=dict)
    #: phase gap sim - measured [deg] at the scored speeds, NaN where a side has no phase;
    #: None when a side gives no phase for this channel and quantity
    phase_gap_deg: np.ndarray | None = None

    def to_dict(self) -> dict:
        r = self.rpm[self.scored]
        d = {"mount": self.mount, "direction": self.direction, "quantity": self.quantity}
        d.update({k: json_number(v) for k, v in self.stats.items()})
        d.update({"n_measured": int(self.rpm.size), "n_compared": int(self.scored.sum()),
                  "n_excluded_noise_floor": int(self.at_floor.sum()),
                  "n_outside_simulated_range": int(self.outside.sum()),
                  "n_simulation_zero": int(self.sim_zero.sum()),
                  "n_measured_not_modelled": int(self.not_modelled.sum()),
                  "rpm_compared": [json_number(x) for x in r],
                  "measured_m_per_s": [json_number(x) for x in self.measured[self.scored]],
                  "simulated_m_per_s": [json_number(x) for x in self.simulated[self.scored]],
                  "gap_db": [json_number(x) for x in self.gap_db]})
        if self.phase_gap_deg is not None:
            d["phase_gap_deg"] = [json_number(x) for x in self.phase_gap_deg]
        return d


def json_number(x):
    """``float(x)``, or None if not finite (JSON has no NaN)."""
    x = float(x)
    return x if np.isfinite(x) else None


@dataclass(frozen=True)
class ComparisonResult(JsonResult):
    """Outcome of :func:`compare_runup`: per-channel gaps and metrics, per-speed CSAC/CSF.

    Attributes
    ----------
    channels : list of ChannelComparison
        Channels and quantities compared (at least one scored point each).
    per_rpm : list of dict
        ``{"quantity", "rpm", "n_channels", "csac", "csf"}`` per quantity and speed.
    missing : list of dict
        ``{"mount", "direction", "quantity", "reason"}``: not compared, and why.
    measured, simulated : MeasuredRunup
        The curves compared (SI).
    noise_floor : float
        RMS noise floor of the measurement [m/s].
    sim_rpm : ndarray
        Simulated speeds [rpm].
    not_modelled : list of dict
        Measured-not-modelled points per channel and quantity: ``{"mount", "direction",
        "quantity", "rpm", "measured_m_per_s", "simulated_m_per_s"}``.
    run : dict
        What ran: ``engine``, ``engine_file``, ``solver``, ``simulation_file``,
        ``simulation_seconds``, ``seconds`` (wall clock).
    """

    #: Quantities every comparison reports (plots draw them even when none was measured).
    EXPECTED_QUANTITIES: ClassVar[tuple] = EXPECTED_QUANTITIES

    def requested_quantities(self) -> list:
        """The default three and every measured or compared quantity, in file order."""
        qs = set(EXPECTED_QUANTITIES) | set(self.measured.quantities)
        qs |= {c.quantity for c in self.channels}
        return sorted(qs, key=quantity_sort_key)

    channels: list
    per_rpm: list
    missing: list
    measured: object            # MeasuredRunup
    simulated: object           # MeasuredRunup
    noise_floor: float
    sim_rpm: np.ndarray
    sigma_db: float = cm.FRFSM_SIGMA_DB
    info: dict = field(default_factory=dict)
    not_modelled: list = field(default_factory=list)
    run: dict = field(default_factory=dict)

    @property
    def exclusion_limit(self) -> float:
        """Measured levels below this are excluded [m/s]
        (:func:`~powertrain.analysis.noise_floor.censoring_level`)."""
        return censoring_level(self.noise_floor)

    @property
    def n_not_modelled(self) -> int:
        """Measured-not-modelled points over every channel and quantity."""
        return sum(len(e["rpm"]) for e in self.not_modelled)

    @property
    def n_interpolated(self) -> int:
        """Compared points whose simulated level was interpolated between simulated speeds."""
        return int(sum((c.interpolated & c.scored).sum() for c in self.channels))

    @property
    def overall_rms_db(self) -> float:
        """RMS of every scored gap, pooled over channels and quantities [dB]."""
        g = np.concatenate([c.gap_db for c in self.channels]) if self.channels else np.zeros(0)
        return float(np.sqrt(np.mean(g ** 2))) if g.size else float("nan")

    def channel(self, mount, direction, quantity) -> ChannelComparison:
        """The comparison of one channel and quantity (KeyError if not compared)."""
        for c in self.channels:
            if (c.mount, c.direction, c.quantity) == (mount, direction, quantity):
                return c
        raise KeyError((mount, direction, quantity))

    def per_quantity(self) -> list:
        """Pooled gap RMS and CSAC/CSF summary per quantity."""
        out = []
        for q in sorted({c.quantity for c in self.channels}, key=quantity_sort_key):
            g = np.concatenate([c.gap_db for c in self.channels if c.quantity == q])
            rows = [r for r in self.per_rpm if r["quantity"] == q and r["csac"] is not None]
            entry = {"quantity": q, "rms_db": json_number(np.sqrt(np.mean(g ** 2))),
                     "bias_db": json_number(np.mean(g)), "n_compared": int(g.size),
                     "n_rpm_with_csac": len(rows)}
            if rows:
                csac = np.array([r["csac"] for r in rows])
                csf = np.array([r["csf"] for r in rows])
                entry.update({"csac_mean": json_number(csac.mean()), "csac_min": json_number(csac.min()),
                              "rpm_at_csac_min": rows[int(np.argmin(csac))]["rpm"],
                              "csf_mean": json_number(csf.mean()), "csf_min": json_number(csf.min()),
                              "rpm_at_csf_min": rows[int(np.argmin(csf))]["rpm"]})
            out.append(entry)
        return out

    def to_dict(self) -> dict:
        n_total = sum(c.rpm.size for c in self.channels)
        return {
            "format": "powertrain-compare", "format_version": 1,
            "measured": self.measured.source, "measured_synthetic": self.measured.synthetic,
            "measured_comments": list(self.measured.comments),
            "simulated": self.simulated.source, "simulated_rpm": [float(r) for r in self.sim_rpm],
            "notes": list(self.measured.notes) + list(self.info.get("notes", [])),
            "noise_floor_m_per_s": self.noise_floor, "noise_floor_margin": NOISE_FLOOR_MARGIN,
            "noise_floor_exclusion_m_per_s": self.exclusion_limit,
            "simulated_at_measured_speeds": self.n_interpolated == 0,
            "frfsm_sigma_db": self.sigma_db, "min_channels_csac": MIN_CHANNELS_CSAC,
            "overall_rms_db": json_number(self.overall_rms_db),
            "compared": {
                "n_channel_quantities": len(self.channels),
                "quantities": sorted({c.quantity for c in self.channels}, key=quantity_sort_key),
                "n_points_measured": int(n_total),
                **{f"n_points_{key}": int(sum(getattr(c, flag).sum() for c in self.channels))
                   for key, flag in (("compared", "scored"), ("excluded_noise_floor", "at_floor"),
                                     ("outside_simulated_range", "outside"),
                                     ("simulation_zero", "sim_zero"))},
                "n_points_measured_not_modelled": self.n_not_modelled,
                "n_points_interpolated": self.n_interpolated},
            "missing": list(self.missing), "measured_not_modelled": list(self.not_modelled),
            "per_quantity": self.per_quantity(), "channels": [c.to_dict() for c in self.channels],
            "per_rpm": list(self.per_rpm), "definitions": dict(DEFINITIONS)}

    def worst_first(self) -> list:
        """The compared channels and quantities by RMS gap, largest first."""
        return sorted(self.channels, key=lambda c: -c.stats["rms_db"])

    def table(self) -> str:
        """Text table of the channels, worst (largest RMS gap) first."""
        header = ["mount", "dir", "quantity", "n", "rms dB", "bias dB", "max|dB|", "@rpm",
                  "FRAC", "FRFSM", "floor", "outside"]
        rows = []
        for c in self.worst_first():
            s = c.stats
            rows.append([c.mount, c.direction, c.quantity, int(c.scored.sum()),
                         f"{s['rms_db']:.2f}", f"{s['bias_db']:+.2f}", f"{s['max_abs_db']:.2f}",
                         f"{s['rpm_at_max_abs_db']:g}", f"{s['frac']:.3f}",
                         f"{s['frfsm']:.3f}", int(c.at_floor.sum()), int(c.outside.sum())])
        return format_table(header, rows)

    def summary(self) -> str:
        """The one-line result (``compare --quiet`` prints only this)."""
        c = self.to_dict()["compared"]
        return (f"overall RMS gap {self.overall_rms_db:.2f} dB over {c['n_points_compared']} "
                f"points ({c['n_channel_quantities']} channel-quantities); "
                f"{c['n_points_excluded_noise_floor']} at the noise floor, "
                f"{self.n_not_modelled} measured but not modelled, "
                f"{c['n_points_outside_simulated_range']} outside the simulated range; "
                f"{len(self.missing)} missing; {self.run.get('seconds', 0.0):.2f} s")

    def to_text(self, written=()) -> str:
        """What ``powertrain compare`` prints, naming the files ``written``."""
        lines = self._sources() + ["", "per channel, worst first:", self.table(), "",
                                   "per quantity (CSAC/CSF across the channels at each "
                                   "speed, RMS magnitudes):"]
        lines += [_quantity_line(pq) for pq in self.per_quantity()]
        lines += self._phase_lines()
        lines += self._not_modelled_lines()
        if self.missing:
            lines += ["", "not compared:"] + [f"  {x}" for x in missing_lines(self.missing)]
        t_sim = self.run.get("simulation_seconds", 0.0)
        lines += ["", self.summary() + f" (simulation {t_sim:.2f} s)"
                  + "".join(f"; wrote {p}" for p in written if p)]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        return fragment(comparison_html(self))

    def _sources(self) -> list:
        """What was compared with what, and the rules."""
        meas = self.measured
        lines = [f"measured: {meas.source}{' [SYNTHETIC]' if meas.synthetic else ''}",
                 f"simulated: {self.simulated.source}"] + [f"note: {n}" for n in meas.notes]
        how = ("simulated at the measured speeds" if self.n_interpolated == 0 else
               "simulation interpolated linearly in rpm and log level at "
               f"{self.n_interpolated} of them, never extrapolated")
        lines.append(f"gap = 20 log10(sim/measured) [dB] at the measured speeds; {how}; noise "
                     f"floor {self.noise_floor * 1e3:g} mm/s (measured points below "
                     f"{self.exclusion_limit * 1e3:g} mm/s excluded)")
        return lines

    def _phase_lines(self) -> list:
        """The phase and complex gaps of the channels with phase on both sides."""
        phased = [c for c in self.worst_first() if c.stats.get("n_phase_compared")]
        if not phased:
            return []
        rows = [[c.mount, c.direction, c.quantity, c.stats["n_phase_compared"],
                 f"{c.stats['phase_rms_deg']:.1f}", f"{c.stats['phase_bias_deg']:+.1f}",
                 f"{c.stats['complex_gap_db']:+.2f}", f"{c.stats['complex_gap_deg']:+.1f}"]
                for c in phased]
        return ["", "phase where given on both sides (gap = sim - measured, wrapped to ±180°; "
                "complex gap = least-squares complex ratio sim/measured):",
                format_table(["mount", "dir", "quantity", "n", "rms °", "bias °",
                               "complex dB", "complex °"], rows)]

    def _not_modelled_lines(self) -> list:
        """The measured-not-modelled points, per channel and quantity."""
        if not self.not_modelled:
            return []
        lines = ["", f"measured, not modelled (simulation below the {self.noise_floor * 1e3:g} "
                 "mm/s floor, measurement above the exclusion limit; not in any dB gap):"]
        for e in self.not_modelled:
            r, m = e["rpm"], e["measured_m_per_s"]
            lines.append(f"  {e['mount']} {e['direction']} {e['quantity']}: {len(r)} points "
                         f"{min(r):g}..{max(r):g} rpm, measured up to {max(m) * 1e3:.3g} mm/s")
        return lines

    def plot(self, ax=None, *, path=None, quantities=None, channel=None, quantity=None,
             provenance=None, phase=True):
        """Measured vs simulated curves, gap shaded (thesis Figs 45-71), a row per channel, a
        column per quantity (default: every measured one), the phase below where both sides
        give it (``phase``); returns the figure (:func:`powertrain.plotting.plot_comparison`).
        ``ax``: None, a Figure or SubFigure, or one Axes where ``channel`` and ``quantity``
        leave one panel and ``phase=False``."""
        ax, path = target_and_path(ax, path)
        return plot_comparison(self, path, quantities, ax=ax, channel=channel,
                               quantity=quantity, phase=phase, provenance=provenance)


def _quantity_line(pq) -> str:
    """One line of the per-quantity summary."""
    line = f"  {pq['quantity']:<10} rms {pq['rms_db']:.2f} dB, bias {pq['bias_db']:+.2f} dB"
    if pq["n_rpm_with_csac"]:
        return line + (f"; CSAC mean {pq['csac_mean']:.3f} (min {pq['csac_min']:.3f} at "
                       f"{pq['rpm_at_csac_min']:g} rpm); CSF mean {pq['csf_mean']:.3f} (min "
                       f"{pq['csf_min']:.3f} at {pq['rpm_at_csf_min']:g} rpm)")
    return line + "; CSAC/CSF: fewer than 3 channels at every speed"


def missing_lines(missing) -> list:
    """``MOUNT DIRS: QUANTITIES: reason`` lines; directions with the same quantities and
    reason share a line (``missing``: ``{"mount", "direction", "quantity", "reason"}``)."""
    groups = {}                                     # (mount, reason, direction) -> quantities
    for m in missing:
        groups.setdefault((m["mount"], m["reason"], m["direction"]), []).append(m["quantity"])
    merged = {}                                     # (mount, reason, quantities) -> directions
    for (mount, reason, direction), qs in groups.items():
        key = (mount, reason, tuple(sorted(qs, key=quantity_sort_key)))
        merged.setdefault(key, []).append(direction)
    return [f"{mount} {', '.join(sorted(dirs))}: {', '.join(qs)}: {reason}"
            for (mount, reason, qs), dirs in merged.items()]
