r"""Comparison of a simulated run-up with a measured one (``powertrain compare``).

:func:`compare_runup` scores, for every mount, direction and quantity (synthesis and each
order) present on both sides, the level gap :math:`20\log_{10}(v_\mathrm{sim}/v_\mathrm{meas})`
[dB] at the measured speeds, and the correlation metrics of :mod:`powertrain.analysis.compare`
(FRAC over speed per channel, CSAC and CSF across the channels at each speed, an FRFSM-like
score).

Rules:

* The simulation is taken at the measured speeds: exactly where it was simulated there
  (``powertrain compare`` simulates at the measured speeds by default), otherwise
  interpolated linearly in rpm and linearly in log level
  (:func:`~powertrain.analysis.compare.interpolate_log`); measured points outside the
  simulated speed range are not compared (never extrapolated) and are counted.
* Measured points at or near the noise floor (below ``NOISE_FLOOR_MARGIN`` × floor, i.e.
  within 9.5 dB of it; :mod:`powertrain.analysis.noise_floor`) are excluded and counted,
  never scored as gaps.
* Points where the simulation is below the noise floor itself while the measurement is above
  the exclusion limit are "measured, not modelled": the model predicts nothing measurable
  there (e.g. tracker leakage into an order the model does not excite). They are listed
  apart (:attr:`ComparisonResult.not_modelled`) and never enter a dB gap.
* Channels or quantities present on one side only are listed as missing, never scored as a
  zero level; so are channels with no scoreable point.
* CSAC and CSF need at least :data:`MIN_CHANNELS_CSAC` channels at a speed (counted otherwise).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from powertrain.analysis import compare as cm
from powertrain.analysis.noise_floor import at_floor, below_floor, censoring_level
from powertrain.iotools.measured import MeasuredRunup, quantity_sort_key

#: Quantities always expected (the thesis's comparison, sec. 4.4); any other measured order is
#: compared too.
EXPECTED_QUANTITIES = ("synthesis", "order_2", "order_4")
#: Default RMS noise floor of the measured order curves [m/s] (0.001 mm/s, see README).
DEFAULT_NOISE_FLOOR = 1e-6
#: CSAC and CSF are computed at a speed only if at least this many channels are compared there.
MIN_CHANNELS_CSAC = 3
#: Speeds closer than this are the same speed when pooling channels [rpm].
RPM_TOL = 1e-6

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
            "n of one channel and quantity; RMS magnitudes (no phase in measured order "
            "curves); 1 = same shape, blind to a common scale (Heylen et al. 1997; "
            "Allemang 2003)",
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
}


@dataclass
class ChannelComparison:
    """Comparison of one channel (mount, direction) and quantity.

    Arrays cover all measured speeds of the channel; ``scored`` marks the compared ones.
    Levels in m/s RMS, speeds in rpm, gaps in dB.
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

    def to_dict(self) -> dict:
        r = self.rpm[self.scored]
        d = {"mount": self.mount, "direction": self.direction, "quantity": self.quantity}
        d.update({k: _num(v) for k, v in self.stats.items()})
        d.update({
            "n_measured": int(self.rpm.size),
            "n_compared": int(self.scored.sum()),
            "n_excluded_noise_floor": int(self.at_floor.sum()),
            "n_outside_simulated_range": int(self.outside.sum()),
            "n_simulation_zero": int(self.sim_zero.sum()),
            "n_measured_not_modelled": int(self.not_modelled.sum()),
            "rpm_compared": [_num(x) for x in r],
            "measured_m_per_s": [_num(x) for x in self.measured[self.scored]],
            "simulated_m_per_s": [_num(x) for x in self.simulated[self.scored]],
            "gap_db": [_num(x) for x in self.gap_db],
        })
        return d


def _format_table(header, rows) -> str:
    cells = [[str(v) for v in row] for row in rows]
    widths = [max([len(h)] + [len(r[i]) for r in cells]) for i, h in enumerate(header)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(header, widths)),
             "  ".join("-" * w for w in widths)]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in cells]
    return "\n".join(lines)


def _num(x):
    x = float(x)
    return x if np.isfinite(x) else None


@dataclass
class ComparisonResult:
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
    """

    #: Quantities every comparison reports (plots draw them even when none was measured).
    EXPECTED_QUANTITIES: ClassVar[tuple] = EXPECTED_QUANTITIES

    def requested_quantities(self) -> list:
        """Every quantity requested: the default three and all measured or compared ones,
        in the measured-file order (synthesis first, then orders ascending)."""
        qs = set(EXPECTED_QUANTITIES) | set(self.measured.quantities)
        qs |= {c.quantity for c in self.channels}
        return sorted(qs, key=quantity_sort_key)


    channels: list
    per_rpm: list
    missing: list
    measured: MeasuredRunup
    simulated: MeasuredRunup
    noise_floor: float
    sim_rpm: np.ndarray
    sigma_db: float = cm.FRFSM_SIGMA_DB
    info: dict = field(default_factory=dict)
    not_modelled: list = field(default_factory=list)

    @property
    def exclusion_limit(self) -> float:
        """Measured levels below this are excluded [m/s]: the one noise-floor rule,
        :func:`~powertrain.analysis.noise_floor.censoring_level` of the floor."""
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
            entry = {"quantity": q, "rms_db": _num(np.sqrt(np.mean(g ** 2))),
                     "bias_db": _num(np.mean(g)), "n_compared": int(g.size),
                     "n_rpm_with_csac": len(rows)}
            if rows:
                csac = np.array([r["csac"] for r in rows])
                csf = np.array([r["csf"] for r in rows])
                entry.update({"csac_mean": _num(csac.mean()), "csac_min": _num(csac.min()),
                              "rpm_at_csac_min": rows[int(np.argmin(csac))]["rpm"],
                              "csf_mean": _num(csf.mean()), "csf_min": _num(csf.min()),
                              "rpm_at_csf_min": rows[int(np.argmin(csf))]["rpm"]})
            out.append(entry)
        return out

    def to_dict(self) -> dict:
        n_total = sum(c.rpm.size for c in self.channels)
        return {
            "format": "powertrain-compare",
            "format_version": 1,
            "measured": self.measured.source,
            "measured_synthetic": self.measured.synthetic,
            "measured_comments": list(self.measured.comments),
            "simulated": self.simulated.source,
            "simulated_rpm": [float(r) for r in self.sim_rpm],
            "notes": list(self.measured.notes) + list(self.info.get("notes", [])),
            "noise_floor_m_per_s": self.noise_floor,
            "noise_floor_margin": cm.NOISE_FLOOR_MARGIN,
            "noise_floor_exclusion_m_per_s": self.exclusion_limit,
            "simulated_at_measured_speeds": self.n_interpolated == 0,
            "frfsm_sigma_db": self.sigma_db,
            "min_channels_csac": MIN_CHANNELS_CSAC,
            "overall_rms_db": _num(self.overall_rms_db),
            "compared": {
                "n_channel_quantities": len(self.channels),
                "quantities": sorted({c.quantity for c in self.channels},
                                     key=quantity_sort_key),
                "n_points_measured": int(n_total),
                "n_points_compared": int(sum(c.scored.sum() for c in self.channels)),
                "n_points_excluded_noise_floor": int(sum(c.at_floor.sum()
                                                         for c in self.channels)),
                "n_points_outside_simulated_range": int(sum(c.outside.sum()
                                                            for c in self.channels)),
                "n_points_simulation_zero": int(sum(c.sim_zero.sum() for c in self.channels)),
                "n_points_measured_not_modelled": self.n_not_modelled,
                "n_points_interpolated": self.n_interpolated,
            },
            "missing": list(self.missing),
            "measured_not_modelled": list(self.not_modelled),
            "per_quantity": self.per_quantity(),
            "channels": [c.to_dict() for c in self.channels],
            "per_rpm": list(self.per_rpm),
            "definitions": dict(DEFINITIONS),
        }

    def to_json(self, path=None) -> str:
        """JSON text of :meth:`to_dict`; written atomically to ``path`` if given."""
        text = json.dumps(self.to_dict(), indent=1) + "\n"
        if path is not None:
            from powertrain.outputs import atomic_write
            with atomic_write(path) as fh:
                fh.write(text)
        return text

    def worst_first(self) -> list:
        """Channels sorted by RMS gap, largest first."""
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
        return _format_table(header, rows)

    def plot(self, ax=None, *, path=None, quantities=None, channel=None, quantity=None,
             provenance=None):
        """Measured vs simulated curves, gap shaded (thesis layout, Figs 45-71); every
        measured quantity is drawn unless ``quantities`` says otherwise. Returns the figure.

        See :func:`powertrain.plotting.plot_comparison`.
        """
        from powertrain.plotting import plot_comparison
        from powertrain.plotting.style import target_and_path
        ax, path = target_and_path(ax, path)
        return plot_comparison(self, path, quantities, ax=ax, channel=channel,
                               quantity=quantity,
                               provenance=provenance or getattr(self, "provenance", None))


def compare_runup(simulated, measured: MeasuredRunup, *, noise_floor=DEFAULT_NOISE_FLOOR,
                  sigma_db=cm.FRFSM_SIGMA_DB) -> ComparisonResult:
    """Compare simulated with measured run-up order curves.

    Parameters
    ----------
    simulated : RunupResult or MeasuredRunup
        The simulation (a result object, or curves read from a result CSV/HDF5).
    measured : MeasuredRunup
        Measured curves [m/s RMS].
    noise_floor : float
        RMS noise floor of the measured curves [m/s]; points below
        ``NOISE_FLOOR_MARGIN * noise_floor`` are excluded and counted.
    sigma_db : float
        Kernel width of the FRFSM-like score [dB].

    Returns
    -------
    ComparisonResult
    """
    if not isinstance(simulated, MeasuredRunup):
        simulated = MeasuredRunup.from_result(simulated, source="simulation",
                                              signal=measured.signal)
    if not (np.isfinite(noise_floor) and noise_floor >= 0):
        raise ValueError("noise floor must be finite and >= 0")
    channel_order = list(simulated.channels)
    channel_order += [c for c in measured.channels if c not in channel_order]
    quantities = sorted(set(EXPECTED_QUANTITIES) | set(measured.quantities),
                        key=quantity_sort_key)
    sim_rpm = np.unique(np.concatenate([r for r, _ in simulated.curves.values()]))
    channels, missing, not_modelled = [], [], []
    for mount, direction in channel_order:
        for q in quantities:
            where = {"mount": mount, "direction": direction, "quantity": q}
            key = (mount, direction, q)
            if key not in measured.curves or key not in simulated.curves:
                side = "measured data" if key not in measured.curves else "simulation"
                missing.append({**where, "reason": f"not in the {side}"})
                continue
            c = _compare_channel(where, measured.curves[key], simulated.curves[key],
                                 noise_floor, sigma_db)
            if c.not_modelled.any():
                not_modelled.append({**where, **_points(c, c.not_modelled)})
            if c.scored.any():
                channels.append(c)
            elif not c.not_modelled.any():
                missing.append({**where, "reason":
                                f"no comparable point ({int(c.outside.sum())} outside the "
                                f"simulated range, {int(c.at_floor.sum())} at the noise "
                                "floor)"})
    per_rpm = _per_rpm(channels)
    return ComparisonResult(channels, per_rpm, missing, measured, simulated,
                            float(noise_floor), sim_rpm, sigma_db, not_modelled=not_modelled)


def _compare_channel(where, measured_curve, simulated_curve, noise_floor, sigma_db):
    """Classify and score the measured points of one channel and quantity."""
    rpm_m, lev_m = measured_curve
    rpm_s, lev_s = simulated_curve
    sim, inside = cm.interpolate_log(rpm_s, lev_s, rpm_m)
    floor = inside & at_floor(lev_m, noise_floor)
    unmodelled = inside & ~floor & below_floor(sim, noise_floor)
    zero = unmodelled & ~(sim > 0)
    scored = inside & ~floor & ~unmodelled
    at_node = np.isin(np.round(rpm_m / RPM_TOL), np.round(np.asarray(rpm_s) / RPM_TOL))
    gap = cm.level_gap_db(sim[scored], lev_m[scored])
    stats = cm.gap_statistics(rpm_m[scored], gap)
    if scored.any():
        stats["frac"] = cm.frac(sim[scored], lev_m[scored])
        stats["frfsm"] = cm.frfsm_score(gap, sigma_db)
    return ChannelComparison(where["mount"], where["direction"], where["quantity"], rpm_m,
                             lev_m, sim, ~inside, floor, zero, unmodelled, inside & ~at_node,
                             scored, gap, stats)


def _points(c: ChannelComparison, mask) -> dict:
    """Speeds and both levels of the points of ``c`` selected by ``mask`` (JSON-ready)."""
    return {"rpm": [_num(x) for x in c.rpm[mask]],
            "measured_m_per_s": [_num(x) for x in c.measured[mask]],
            "simulated_m_per_s": [_num(x) for x in c.simulated[mask]]}


def _per_rpm(channels) -> list:
    """CSAC and CSF across the channels at each compared speed, per quantity."""
    out = []
    for q in sorted({c.quantity for c in channels}, key=quantity_sort_key):
        pts = {}   # rounded rpm -> list of (s, m)
        for c in (c for c in channels if c.quantity == q):
            for r, s, m in zip(c.rpm[c.scored], c.simulated[c.scored], c.measured[c.scored]):
                pts.setdefault(round(float(r) / RPM_TOL) * RPM_TOL, []).append((s, m))
        for r in sorted(pts):
            sm = np.array(pts[r])
            entry = {"quantity": q, "rpm": round(r, 6), "n_channels": int(sm.shape[0]),
                     "csac": None, "csf": None}
            if sm.shape[0] >= MIN_CHANNELS_CSAC:
                entry["csac"] = _num(cm.csac(sm[:, 0], sm[:, 1]))
                entry["csf"] = _num(cm.csf(sm[:, 0], sm[:, 1]))
            out.append(entry)
    return out
