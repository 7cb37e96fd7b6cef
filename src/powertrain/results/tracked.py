"""Order-tracked run-up: complex order amplitudes per speed and channel, and their files.

Long-format CSV (level column per quantity: :data:`LEVEL_COLUMNS`), order-spectrum CSV
(``track --spectrum-at``) and HDF5 (``format = "powertrain-tracked"``): see
docs/reference/raw-data.md and csv-formats.md. ``synthesis`` is the RMS sum over the orders,
``overall`` the band RMS of the raw signal (:mod:`powertrain.analysis.overall`),
``phase_deg`` the phase re cylinder-1 firing TDC (:mod:`powertrain.analysis.phase`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace

import numpy as np

from powertrain.analysis.channel import ChannelFields
from powertrain.analysis.orders import order_label
from powertrain.analysis.phase import phase_deg
from powertrain.analysis.text_table import format_table
from powertrain.errors import InputError
from powertrain.models.recording import QUANTITIES
from powertrain.outputs import atomic_path, write_csv
from powertrain.plotting.orders import DISPLAY, plot_maps, plot_tracked
from powertrain.plotting.style import target_and_path
from powertrain.provenance import stamp_hdf5
from powertrain.results.base import HDF5_SUFFIXES, Result

#: quantity -> (level column, factor from SI to the column's unit).
LEVEL_COLUMNS = {"acceleration": ("acceleration_rms_m_per_s2", 1.0),
                 "velocity": ("velocity_rms_mm_per_s", 1e3),
                 "displacement": ("displacement_rms_mm", 1e3), "force": ("force_rms_n", 1.0)}


def _phase_cell(phase, index) -> list:
    """The ``phase_deg`` cell of an order row: none without the column, empty if undefined."""
    if phase is None:
        return []
    value = phase[index]
    return [f"{value:.6g}" if np.isfinite(value) else ""]


@dataclass
class TrackedChannel(ChannelFields):
    """Identity of a tracked channel (no samples)."""

    name: str
    mount: str
    side: str
    direction: str
    quantity: str


@dataclass(frozen=True)
class TrackedOrders(Result):
    """Complex order amplitudes of a tracked run-up.

    Attributes
    ----------
    rpm : ndarray (k,)
        Speeds [rpm].
    orders : ndarray (n_o,)
    channels : list of TrackedChannel
    amplitude : ndarray complex (k, n_ch, n_o)
        Peak complex amplitude [SI of each channel's quantity].
    method : str
        ``cot`` or ``vkf``.
    source : str
    settings : dict
    comments : list of str
    overall : ndarray (k, n_ch) or None
        Raw-signal RMS per speed in ``settings["overall_band_hz"]`` [SI].
    """

    rpm: np.ndarray
    orders: np.ndarray
    channels: list
    amplitude: np.ndarray
    method: str = "cot"
    source: str = ""
    settings: dict = field(default_factory=dict)
    comments: list = field(default_factory=list)
    overall: np.ndarray | None = None
    #: the recording tracked: ``synthetic``, ``n_channels``, ``sample_rate_hz``, ``seconds``
    recording: dict = field(default_factory=dict)
    #: order spectra at single speeds (``track(spectrum_at=...)``), or None
    spectra: TrackedOrders | None = None
    #: Campbell and rpm-frequency maps of one channel (``track(maps=True)``), or None
    maps: dict | None = None

    def order_rms(self) -> np.ndarray:
        """RMS per speed, channel and order [SI]."""
        return np.abs(self.amplitude) / np.sqrt(2.0)

    def synthesis_rms(self) -> np.ndarray:
        """RMS sum over the tracked orders per speed and channel [SI]."""
        return np.sqrt(np.sum(self.order_rms() ** 2, axis=-1))

    def phase_deg(self) -> np.ndarray | None:
        """Phase per speed, channel and order re cylinder-1 firing TDC [deg]; NaN where
        undefined, None when not measured."""
        ref = self.settings.get("phase")
        if not ref:
            return None
        defined = np.isin(np.round(self.orders, 9), np.round(ref["orders"], 9))
        return np.where(defined, phase_deg(self.amplitude), np.nan)

    @property
    def quantity(self) -> str:
        """The one quantity of all channels (InputError if mixed)."""
        qs = sorted({c.quantity for c in self.channels})
        if len(qs) != 1:
            raise InputError(f"channels measure {', '.join(qs)}: one level column per CSV; "
                             "select one with --quantity (or convert with --as velocity)",
                             file=self.source, key="quantity")
        return qs[0]

    def as_velocity(self) -> TrackedOrders:
        r"""Convert every channel to velocity, order by order: :math:`\hat v = \hat a/(i\omega_o)`
        and :math:`\hat v = i\omega_o \hat x`, :math:`\omega_o = 2\pi o n/60`."""
        if self.overall is not None and self.settings.get("overall_quantity") != "velocity":
            raise InputError("the overall level cannot be converted after tracking (track "
                             "with the overall level computed as velocity)",
                             file=self.source, key="overall")
        w = 2 * np.pi * self.orders[None, :] * self.rpm[:, None] / 60.0      # (k, n_o)
        amp = self.amplitude.copy()
        chans = []
        for c, ch in enumerate(self.channels):
            if ch.quantity == "acceleration":
                amp[:, c, :] /= 1j * w
            elif ch.quantity == "displacement":
                amp[:, c, :] *= 1j * w
            elif ch.quantity == "force":
                raise InputError("a force cannot be converted to velocity", file=self.source,
                                 key=ch.name)
            chans.append(replace(ch, quantity="velocity"))
        return replace(self, channels=chans, amplitude=amp,
                       settings={**self.settings, "converted_to": "velocity"})

    def _csv_head(self, title: str, columns: list) -> tuple:
        """``(head lines, level factor, key per channel)`` of a CSV."""
        col, factor = LEVEL_COLUMNS[self.quantity]
        with_side = any(c.side != "active" for c in self.channels)
        lines = [f"# {title}"] + [f"# {c}" for c in self.comments]
        lines.append(",".join(["mount"] + (["side"] if with_side else []) + ["direction"]
                              + [col if c == "LEVEL" else c for c in columns]))
        keys = [[ch.mount] + ([ch.side] if with_side else []) + [ch.direction]
                for ch in self.channels]
        return lines, factor, keys

    def _tag(self) -> str:
        return " [SYNTHETIC]" if any("synthetic" in c.lower() for c in self.comments) else ""

    def csv_text(self) -> str:
        """Long-format CSV text (docs/reference/raw-data.md)."""
        phase = self.phase_deg()
        tail = [] if phase is None else [""]
        lines, factor, keys = self._csv_head(
            f"tracked by powertrain track ({self.method}) from {self.source}{self._tag()}",
            ["quantity", "rpm", "LEVEL"] + ([] if phase is None else ["phase_deg"]))
        rms = self.order_rms() * factor
        syn = self.synthesis_rms() * factor
        for c, key in enumerate(keys):
            for k, order in enumerate(self.orders):
                q = order_label(order)
                lines += [",".join(key + [q, f"{r:g}", f"{rms[i, c, k]:.8g}"]
                                   + _phase_cell(phase, (i, c, k)))
                          for i, r in enumerate(self.rpm)]
            lines += [",".join(key + ["synthesis", f"{r:g}", f"{syn[i, c]:.8g}"] + tail)
                      for i, r in enumerate(self.rpm)]
            if self.overall is not None:
                lines += [",".join(key + ["overall", f"{r:g}",
                                          f"{self.overall[i, c] * factor:.8g}"] + tail)
                          for i, r in enumerate(self.rpm)]
        return "\n".join(lines) + "\n"

    def spectrum_csv_text(self) -> str:
        """Order spectrum CSV text: RMS against order per speed (docs/reference/csv-formats.md)."""
        s = self.settings
        lines, factor, keys = self._csv_head(
            f"order spectrum by powertrain track from {self.source}{self._tag()}: COT block of "
            f"{s['block_revolutions']} revolutions, Hann window, orders in steps of "
            f"{s['order_resolution']:g}", ["rpm", "order", "LEVEL"])
        rms = self.order_rms() * factor
        for c, key in enumerate(keys):
            lines += [",".join(key + [f"{r:g}", f"{o:g}", f"{rms[i, c, k]:.8g}"])
                      for i, r in enumerate(self.rpm) for k, o in enumerate(self.orders)]
        return "\n".join(lines) + "\n"

    def to_csv(self, path) -> None:
        """Write :meth:`csv_text` atomically."""
        write_csv(path, self.csv_text())

    def writers(self) -> dict:
        """``.csv``, ``.h5``/``.hdf5``, ``.png``."""
        return {".csv": self.to_csv, **dict.fromkeys(HDF5_SUFFIXES, self.to_hdf5),
                **super().writers()}

    def to_hdf5(self, path) -> None:
        """Write the HDF5 layout (docs/reference/raw-data.md) atomically."""
        import h5py  # deferred: heavy optional package

        with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
            a = h5.attrs
            stamp_hdf5(a, "powertrain-tracked")
            a["source"] = self.source
            a["method"] = self.method
            a["settings"] = json.dumps(self.settings)
            a["comments"] = json.dumps(self.comments)
            h5.create_dataset("rpm", data=self.rpm).attrs["unit"] = "rpm"
            h5.create_dataset("orders", data=self.orders).attrs["unit"] = "1"
            g = h5.create_group("channels")
            for key in ("name", "mount", "side", "direction", "quantity"):
                g.create_dataset(key, data=np.array([getattr(c, key) for c in self.channels],
                                                    dtype="S"))
            g.create_dataset("unit", data=np.array([QUANTITIES[c.quantity]
                                                    for c in self.channels], dtype="S"))
            h5.create_dataset("amplitude", data=self.amplitude)
            h5.create_dataset("order_rms", data=self.order_rms())
            h5.create_dataset("synthesis_rms", data=self.synthesis_rms())
            if self.overall is not None:
                h5.create_dataset("overall_rms", data=self.overall)
            if self.phase_deg() is not None:
                h5.create_dataset("phase_deg", data=self.phase_deg()).attrs["unit"] = "deg"

    @classmethod
    def from_hdf5(cls, path) -> TrackedOrders:
        import h5py  # deferred: heavy optional package
        with h5py.File(path, "r") as h5:
            if h5.attrs.get("format") != "powertrain-tracked":
                raise InputError("not a powertrain tracked-orders file", file=path,
                                 key="format")
            g = h5["channels"]
            cols = {k: [v.decode() for v in g[k][()]]
                    for k in ("name", "mount", "side", "direction", "quantity")}
            chans = [TrackedChannel(*row) for row in zip(*cols.values())]
            overall = h5["overall_rms"][()] if "overall_rms" in h5 else None
            return cls(h5["rpm"][()], h5["orders"][()], chans, h5["amplitude"][()],
                       str(h5.attrs["method"]), str(h5.attrs["source"]),
                       json.loads(h5.attrs["settings"]), json.loads(h5.attrs["comments"]),
                       overall)

    def curve(self, label: str, quantity: str = "synthesis") -> np.ndarray:
        """RMS curve [SI] of the channel ``mount[.side].direction`` (synthesis or order_<n>)."""
        c = [ch.label for ch in self.channels].index(label)
        if quantity == "synthesis":
            return self.synthesis_rms()[:, c]
        o = float(quantity.split("_", 1)[1])
        return self.order_rms()[:, c, int(np.argmin(np.abs(self.orders - o)))]

    def to_text(self, written=()) -> str:
        """What ``powertrain track`` prints, naming the files ``written``."""
        r, s = self.recording, self.settings
        lines = [f"raw: {self.source}{' [SYNTHETIC]' if r.get('synthetic') else ''}: "
                 f"{r.get('n_channels')} channel(s), {r.get('sample_rate_hz'):g} Hz, "
                 f"{r.get('seconds'):.3g} s",
                 f"speed: {s['speed_source']}; tracked ({self.method}) at {self.rpm.size} "
                 f"speeds {self.rpm[0]:g}..{self.rpm[-1]:g} rpm (step {s['rpm_step']:g}) of "
                 f"the measured {s['measured_rpm'][0]:.0f}..{s['measured_rpm'][1]:.0f} rpm"]
        lines += self._phase_lines()
        if "ends_dropped_s" in s:
            (lo, hi), (start, end) = s["bandwidth_hz_range"], s["ends_dropped_s"]
            lines.append(f"Vold-Kalman bandwidth {lo:.3g}..{hi:.3g} Hz ({s['bandwidth_rule']}); "
                         f"not reported: the first {start:.3g} s and the last {end:.3g} s "
                         f"({100 * (start + end) / r.get('seconds'):.1f} % of the record, "
                         "filter end transient)")
        lines += ["tracked RMS over the speed grid:",
                  format_table(["channel", "quantity", "order", "median", "min", "max", "unit"],
                               self._rms_rows(), "{:.6g}")]
        written = [p for p in written if p]
        if written:
            lines.append("wrote " + ", ".join(written))
        return "\n".join(lines)

    def _phase_lines(self) -> list:
        """What the phases refer to and why half orders have none without a cycle reference."""
        ref = self.settings.get("phase")
        if not ref:
            return []
        after = ("the first tacho reference pulse after each cycle-reference edge"
                 if ref["cycle_reference"] else "the tacho reference pulse")
        lines = [f"phase: re cylinder-1 firing TDC, {ref['tdc_offset_deg']:g}° after {after}; "
                 f"defined for {len(ref['orders'])} of {self.orders.size} orders"]
        if not ref["cycle_reference"] and any(abs(2 * o - round(2 * o)) < 1e-9
                                              and o % 1 for o in self.orders):
            lines.append("half-order phases empty: one crank revolution cannot tell firing "
                         "from gas-exchange TDC (give --cycle-reference COL, a cam or "
                         "injection signal)")
        return lines

    def _rms_rows(self) -> list:
        """Median, min and max over the speeds per channel and order, synthesis, overall."""
        rows, rms, syn = [], self.order_rms(), self.synthesis_rms()
        for c, ch in enumerate(self.channels):
            unit, f = DISPLAY[ch.quantity]
            label = ch.mount + ("" if ch.side == "active" else f".{ch.side}") + f".{ch.direction}"
            curves = [(f"{o:.6g}", rms[:, c, k]) for k, o in enumerate(self.orders)]
            curves.append(("synthesis", syn[:, c]))
            if self.overall is not None:
                curves.append(("overall", self.overall[:, c]))
            rows += [[label, ch.quantity, name, float(np.median(v * f)), float((v * f).min()),
                      float((v * f).max()), unit] for name, v in curves]
        return rows

    def write_spectra(self, path) -> None:
        """Write the order spectra (:attr:`spectra`) as CSV, atomically."""
        write_csv(path, self.spectra.spectrum_csv_text())

    def plot_maps(self, ax=None, *, path=None, provenance=None):
        """The Campbell and rpm-frequency maps (:attr:`maps`); returns the figure."""
        ax, path = target_and_path(ax, path)
        return plot_maps(**self.maps, path=path, ax=ax, provenance=provenance)

    def plot(self, ax=None, *, path=None, quantities=None, provenance=None):
        """Order curves (RMS against rpm), one panel per channel; returns the figure. ``ax``:
        None, a Figure or SubFigure, or one Axes for one channel."""
        ax, path = target_and_path(ax, path)
        return plot_tracked(self, path, quantities, ax=ax, provenance=provenance)
