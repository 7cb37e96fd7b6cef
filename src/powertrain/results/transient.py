"""A transient manoeuvre's result (``powertrain transient``): time histories, per-channel
peaks and the seat's ISO 2631-1 values, as text, CSV, JSON (docs/reference/json.md), HDF5
and figure.

CSV: one row per time step; columns ``time_s``, ``rpm``, ``engine_torque_nm``,
``starter_torque_nm``, ``driveline_torque_nm``, ``body_x_mm`` .. ``body_rz_deg``, per
channel ``CH_displacement_mm``, ``CH_velocity_mm_per_s``, ``CH_acceleration_m_per_s2``,
``CH_force_n``, per mount direction ``NET_deflection_mm``. Displacements, deflections and
forces are changes from the static operating point at zero mean torque. A body point (neither
side of a mount, e.g. ``seat_rail.z``) transmits no force: peak force NaN, ``n/a`` in the
text, null in the JSON, empty ``CH_force_n`` cells.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.channel import Channel
from powertrain.analysis.text_table import format_table
from powertrain.errors import InputError
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.outputs import atomic_path, atomic_write
from powertrain.plotting.style import target_and_path
from powertrain.plotting.transient import plot_overlay, plot_ranking, plot_transient
from powertrain.results.base import JsonResult
from powertrain.results.html import fragment
from powertrain.results.html_tables import transient_html
from powertrain.units import from_si

_BODY = ("x_mm", "y_mm", "z_mm", "rx_deg", "ry_deg", "rz_deg")


#: The HDF5 file's datasets and their units (``body``: per column, x y z then rx ry rz).
HDF5_UNITS = {"time": "s", "rpm": "rpm", "body": "m, m, m, rad, rad, rad",
              "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2", "force": "N",
              "deflection": "m"}


@dataclass(frozen=True)
class TransientResult(JsonResult):
    """Time histories of a manoeuvre (SI; module docstring for the files).

    Attributes
    ----------
    name, file, engine : str
        Manoeuvre, its file, the engine that ran.
    time, rpm : ndarray (n,)
        Time [s], crank speed [rpm].
    torques : dict of str -> ndarray (n,)
        ``engine``, ``starter``, ``driveline`` torque [N·m].
    body : ndarray (n, 6)
        Displacement [m] and rotation [rad] at the CG.
    channels : list of str
        ``mount.direction`` (engine side, then body side and body points).
    displacement, velocity, acceleration, force : ndarray (n, n_ch)
    networks : list of str
    deflection : ndarray (n, n_net) [m]
    seat : dict or None
        ``point``, per axis ``rms`` [m/s²], ``vdv`` [m/s^1.75] and ``weighting``.
    method : str
    solver_seconds : float
    notes : list of str
    speed_source : str
        Origin and alignment of a recorded crank speed ("" for the manoeuvre's own).
    trigger_time : float
        Manoeuvre time at which a recording's trigger rises [s].
    """

    name: str
    file: str
    engine: str
    time: np.ndarray
    rpm: np.ndarray
    torques: dict
    body: np.ndarray
    channels: list
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    force: np.ndarray
    networks: list
    deflection: np.ndarray
    seat: dict | None = None
    method: str = ""
    solver_seconds: float = 0.0
    notes: list = field(default_factory=list)
    speed_source: str = ""
    trigger_time: float = 0.0

    def channel(self, label) -> int:
        """Column of the channel ``label`` (``"left.z"``)."""
        return self.channels.index(label)

    def transmits_force(self) -> np.ndarray:
        """Per channel: True for either side of a mount, False for a body point."""
        mounts = {n.rpartition(".")[0] for n in self.networks}
        return np.array([c.rpartition(".")[0].split("/")[0] in mounts for c in self.channels],
                        bool)

    def peaks(self) -> dict:
        """Per channel: peak-to-peak displacement [m], peak force [N] (NaN at a body point),
        maximum acceleration [m/s²] and its time [s]."""
        a = np.abs(self.acceleration)
        i = np.argmax(a, axis=0)
        force = np.max(np.abs(self.force), axis=0)
        return {"peak_to_peak": np.ptp(self.displacement, axis=0),
                "peak_force": np.where(self.transmits_force(), force, np.nan),
                "max_acceleration": a[i, np.arange(a.shape[1])],
                "time_of_max_acceleration": self.time[i]}

    def recording(self) -> RawRecording:
        """Every channel's acceleration [m/s²] and the crank speed [rpm] as a raw recording
        (labelled SYNTHETIC)."""
        chans = []
        for k, label in enumerate(self.channels):
            node, _, d = label.rpartition(".")
            c = Channel.of_node(node, d)
            chans.append(RawChannel(c.label, c.mount, c.side, d, "acceleration",
                                    self.acceleration[:, k], "m/s^2"))
        note = f"SYNTHETIC: simulated transient '{self.name}' ({self.method})"
        return RawRecording(self.time, chans, self.rpm, None, "simulated transient", [note],
                            trigger=self.trigger_signal()).validate()

    def trigger_signal(self) -> np.ndarray | None:
        """Trigger channel [V]: 0 V before :attr:`trigger_time`, 5 V after, one sample
        between placing the linear 2.5 V crossing at :attr:`trigger_time` exactly; None
        when the trigger is at the first sample."""
        t, when = self.time, float(self.trigger_time)
        if when <= t[0]:
            return None
        x = np.where(t >= when, 5.0, 0.0)
        i = int(np.searchsorted(t, when)) - 1             # t[i] < when <= t[i + 1]
        h = t[i + 1] - t[i]
        if when - t[i] >= 0.5 * h:
            x[i + 1] = 2.5 * h / (when - t[i])
        else:
            x[i] = 5.0 - 2.5 * h / (t[i + 1] - when)
        return x

    def to_dict(self) -> dict:
        """The JSON document (docs/reference/json.md)."""
        p = self.peaks()
        chans = {c: {"peak_to_peak_displacement_mm": float(from_si(p["peak_to_peak"][k], "mm")),
                     "peak_force_n": _finite(p["peak_force"][k]),
                     "max_acceleration_m_per_s2": float(p["max_acceleration"][k]),
                     "time_of_max_acceleration_s": float(p["time_of_max_acceleration"][k])}
                 for k, c in enumerate(self.channels)}
        d = from_si(self.deflection, "mm")
        mounts = {n: {"peak_to_peak_deflection_mm": float(np.ptp(d[:, k])),
                      "max_deflection_mm": float(np.max(np.abs(d[:, k])))}
                  for k, n in enumerate(self.networks)}
        seat = None if self.seat is None else {
            "point": self.seat["point"], "weighted_rms_m_per_s2": self.seat["rms"],
            "vdv_m_per_s1_75": self.seat["vdv"], "weighting": self.seat["weighting"]}
        return {"manoeuvre": self.name, "file": self.file, "engine": self.engine,
                "duration_s": float(self.time[-1]), "steps": int(self.time.size - 1),
                "method": self.method, "channels": chans, "mounts": mounts, "seat": seat,
                "speed_from": self.speed_source or None,
                "trigger_time_s": float(self.trigger_time)}

    def columns(self) -> dict:
        """CSV column name -> values (n,) (module docstring)."""
        cols = {"time_s": self.time, "rpm": self.rpm}
        cols.update({f"{k}_torque_nm": v for k, v in self.torques.items()})
        body = np.hstack([from_si(self.body[:, :3], "mm"), np.rad2deg(self.body[:, 3:])])
        cols.update({f"body_{n}": body[:, k] for k, n in enumerate(_BODY)})
        for k, c in enumerate(self.channels):
            cols[f"{c}_displacement_mm"] = from_si(self.displacement[:, k], "mm")
            cols[f"{c}_velocity_mm_per_s"] = from_si(self.velocity[:, k], "mm/s")
            cols[f"{c}_acceleration_m_per_s2"] = self.acceleration[:, k]
            cols[f"{c}_force_n"] = self.force[:, k]
        cols.update({f"{n}_deflection_mm": from_si(self.deflection[:, k], "mm")
                     for k, n in enumerate(self.networks)})
        return cols

    def to_csv(self, path) -> None:
        """Write the time histories as CSV, atomically (module docstring)."""
        cols = self.columns()
        names = list(cols)
        blank = [names.index(f"{c}_force_n") for c, f in
                 zip(self.channels, self.transmits_force()) if not f]
        rows = np.column_stack(list(cols.values())).tolist()
        for row in rows if blank else ():
            for j in blank:
                row[j] = ""
        with atomic_write(path, newline="") as fh:
            fh.write(f"# {self.name}: transient simulated by powertrain ({self.method})\n")
            writer = csv.writer(fh)
            writer.writerow(names)
            writer.writerows(rows)

    def to_hdf5(self, path) -> None:
        """Write the time histories (SI, ``unit`` attribute per dataset), the summary JSON and
        per-channel ``transmits_force`` as attributes, atomically."""
        import h5py  # deferred: heavy optional package
        with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
            h5.attrs["summary"] = self.to_json()
            for name, unit in HDF5_UNITS.items():
                h5.create_dataset(name, data=getattr(self, name)).attrs["unit"] = unit
            for k, v in self.torques.items():
                h5.create_dataset(f"torque/{k}", data=v).attrs["unit"] = "N*m"
            h5.attrs["channels"] = list(self.channels)
            h5.attrs["networks"] = list(self.networks)
            h5.attrs["transmits_force"] = self.transmits_force()

    def writers(self) -> dict:
        """``.csv``, ``.json``, ``.h5``/``.hdf5``, ``.png``."""
        return {".csv": self.to_csv, ".json": self.to_json, ".h5": self.to_hdf5,
                ".hdf5": self.to_hdf5, **super().writers()}

    def plot(self, ax=None, *, path=None, channels=None, quantity="acceleration",
             provenance=None):
        """Crank speed and torque above the ``quantity`` (``acceleration``, ``displacement``,
        ``force``) of ``channels`` (default :meth:`default_channels`), peaks marked; returns
        the figure (:func:`powertrain.plotting.transient.plot_transient`). ``ax``: None, a
        Figure or SubFigure (not one Axes), or a path."""
        ax, path = target_and_path(ax, path)
        return plot_transient(self, channels or self.default_channels(), path, ax=ax,
                              provenance=provenance, quantity=quantity)

    def _repr_html_(self) -> str:
        return fragment(transient_html(self))

    def default_channels(self) -> list:
        """The seat's moving axes (all three if none moves), else up to three engine-side z
        channels."""
        if self.seat is not None:
            axes = [f"{self.seat['point']}.{a}" for a in "xyz"]
            moving = [c for c in axes if np.any(self.acceleration[:, self.channel(c)])]
            return moving or axes
        return [c for c in self.channels if c.endswith(".z") and "/" not in c][:3]

    def to_text(self) -> str:
        """Header, per channel peaks, seat values."""
        p = self.peaks()
        head = (f"transient '{self.name}' on {self.engine}: {self.time[-1]:g} s, "
                f"{self.time.size - 1} steps ({self.method})")
        rows = [[c, float(from_si(p["peak_to_peak"][k], "mm")),
                 "n/a" if np.isnan(p["peak_force"][k]) else float(p["peak_force"][k]),
                 float(p["max_acceleration"][k]), float(p["time_of_max_acceleration"][k])]
                for k, c in enumerate(self.channels)]
        text = head + "\n" + format_table(
            ["channel", "p-p displ. [mm]", "peak force [N]", "max accel. [m/s^2]",
             "at [s]"], rows)
        if self.seat is not None:
            s = self.seat
            text += (f"\nseat {s['point']} (ISO 2631-1): weighted RMS "
                     + ", ".join(f"{a} {s['rms'][a]:.4f}" for a in "xyz")
                     + " m/s^2; VDV " + ", ".join(f"{a} {s['vdv'][a]:.4f}" for a in "xyz")
                     + " m/s^1.75")
        if self.speed_source:
            text += "\n" + self.speed_source
        return text


def _finite(value):
    """``value`` as a float, None (JSON null) where NaN."""
    return None if np.isnan(value) else float(value)


def _relative(part, whole):
    """``100 part / whole`` [%], NaN where ``whole`` is 0."""
    safe = np.where(whole > 0, whole, 1.0)
    return np.where(whole > 0, 100.0 * part / safe, np.nan)


def _percent(value, spec):
    """A percentage for a table, ``n/a`` where NaN."""
    return "n/a" if np.isnan(value) else format(float(value), spec)


@dataclass(frozen=True)
class TransientRanking(JsonResult):
    """Baseline and variants over one manoeuvre (``powertrain whatif --manoeuvre``), ranked
    by the peak seat acceleration (largest of its three axes) where there is a seat point,
    else by the peak mount deflection.

    Attributes
    ----------
    manoeuvre : str
    names : list of str
        ``baseline`` first, then the variants.
    runs : list of TransientResult
    """

    manoeuvre: str
    names: list
    runs: list = field(repr=False)

    def peak_seat(self):
        """Peak seat acceleration [m/s²] per run, or None without a seat."""
        if self.runs[0].seat is None:
            return None
        return np.array([max(float(np.max(np.abs(r.acceleration[:, r.channel(c)])))
                             for c in r.default_channels()) for r in self.runs])

    def peak_deflection(self):
        """Largest mount deflection magnitude [m] per run and its mount direction."""
        k = [int(np.argmax(np.max(np.abs(r.deflection), axis=0))) for r in self.runs]
        return (np.array([float(np.max(np.abs(r.deflection[:, j])))
                          for r, j in zip(self.runs, k)]),
                [r.networks[j] for r, j in zip(self.runs, k)])

    def ranked_by(self) -> str:
        """``peak_seat_acceleration`` (with a seat) or ``peak_mount_deflection``."""
        return "peak_mount_deflection" if self.peak_seat() is None else "peak_seat_acceleration"

    def ranking(self) -> list:
        """Indices of the runs, best (smallest) first."""
        seat = self.peak_seat()
        key = seat if seat is not None else self.peak_deflection()[0]
        return [int(i) for i in np.argsort(key, kind="stable")]

    def to_dict(self) -> dict:
        seat = self.peak_seat()
        defl, where = self.peak_deflection()
        return {"manoeuvre": self.manoeuvre, "ranked_by": self.ranked_by(),
                "ranking": [self.names[i] for i in self.ranking()],
                "runs": {n: {"peak_seat_acceleration_m_per_s2":
                             None if seat is None else float(seat[k]),
                             "peak_mount_deflection_mm": float(from_si(defl[k], "mm")),
                             "peak_mount_deflection_at": where[k]}
                         for k, n in enumerate(self.names)}}

    def target_fit(self, key):
        raise InputError("a retune target's files come with a run-up what-if, not with "
                         "--manoeuvre", key=key)

    def plot(self, ax=None, *, path=None, provenance=None, view="levels"):
        """Bars in rank order: ``view="levels"`` peak seat acceleration [m/s²] (if any) and
        peak mount deflection [mm], ``"delta"`` each variant's change against the baseline
        [%]; returns the figure (:func:`powertrain.plotting.transient.plot_ranking`). ``ax``:
        None, a Figure or SubFigure, or one Axes when there is no seat."""
        ax, path = target_and_path(ax, path)
        return plot_ranking(self, path, ax=ax, provenance=provenance, view=view)

    def to_text(self, written=()) -> str:
        seat = self.peak_seat()
        defl, where = self.peak_deflection()
        rows = [[rank + 1, self.names[k], "-" if seat is None else f"{seat[k]:.4g}",
                 "-" if seat is None else f"{100 * (seat[k] / seat[0] - 1):+.1f}",
                 float(from_si(defl[k], "mm")), where[k],
                 f"{100 * (defl[k] / defl[0] - 1):+.1f}"]
                for rank, k in enumerate(self.ranking())]
        head = (f"what-if over '{self.manoeuvre}': ranked by "
                + ("peak seat acceleration" if seat is not None else "peak mount deflection"))
        text = head + "\n" + format_table(
            ["rank", "run", "seat peak [m/s^2]", "vs base [%]", "max deflection [mm]",
             "at", "vs base [%]"], rows)
        files = [str(w) for w in written if w]
        return text + (f"\nwrote {', '.join(files)}" if files else "")


@dataclass(frozen=True)
class TransientComparison(JsonResult):
    """A simulated manoeuvre against its recording (``powertrain transient --compare``).

    Attributes
    ----------
    name, raw : str
        Manoeuvre name, the recording's file.
    shift : float
        Time of the simulation's start in the recording [s].
    time : ndarray (n,)
        Simulated times the recording covers [s].
    channels : list of str
    measured, simulated : ndarray (n, k)
        Accelerations at those times [m/s²].
    aligned_on : str
        ``crank speed`` or ``trigger 'NAME'``.
    event : tuple of float
        First and last time of the simulated event [s] (default: those compared).
    not_compared : dict of str -> str
        The recording's other channels and why each was not compared.
    shift_error : float
        Standard error of ``shift`` [s] (:mod:`powertrain.analysis.alignment`,
        :func:`~powertrain.analysis.trigger.trigger_crossing`).
    """

    name: str
    raw: str
    shift: float
    time: np.ndarray
    channels: list
    measured: np.ndarray
    simulated: np.ndarray
    aligned_on: str = "crank speed"
    event: tuple = ()
    not_compared: dict = field(default_factory=dict)
    shift_error: float = 0.0

    def span(self) -> tuple:
        """First and last time compared, first and last time of the event [s]."""
        first, last = float(self.time[0]), float(self.time[-1])
        return (first, last) + (tuple(self.event) if self.event else (first, last))

    def errors(self) -> dict:
        """Per channel: peaks [m/s²], peak error [%], RMS of the difference [m/s²] and
        relative to the measured RMS [%] (relative ones NaN where the measurement is 0)."""
        pm, ps = np.max(np.abs(self.measured), 0), np.max(np.abs(self.simulated), 0)
        rms = np.sqrt(np.mean((self.simulated - self.measured) ** 2, axis=0))
        base = np.sqrt(np.mean(self.measured ** 2, axis=0))
        return {"peak_measured": pm, "peak_simulated": ps,
                "peak_error_percent": _relative(ps - pm, pm), "rms_difference": rms,
                "rms_difference_percent": _relative(rms, base)}

    def to_dict(self) -> dict:
        e = self.errors()
        first, last, t0, t1 = self.span()
        return {"manoeuvre": self.name, "recording": self.raw, "shift_s": self.shift,
                "shift_standard_error_s": self.shift_error,
                "channels": {c: {k: _finite(v[j]) for k, v in e.items()}
                             for j, c in enumerate(self.channels)},
                "aligned_on": self.aligned_on, "compared_from_s": first,
                "compared_to_s": last, "event_from_s": t0, "event_to_s": t1,
                "compared_percent": 100.0 * (last - first) / (t1 - t0),
                "not_compared": dict(self.not_compared)}

    def plot(self, ax=None, *, path=None, provenance=None):
        """Measured and simulated acceleration per channel, overlaid, headed by the errors;
        returns the figure (:func:`powertrain.plotting.transient.plot_overlay`). ``ax``:
        None, a Figure or SubFigure, or one Axes for one channel."""
        ax, path = target_and_path(ax, path)
        return plot_overlay(self, path, ax=ax, provenance=provenance)

    def to_text(self) -> str:
        e = self.errors()
        rows = [[c, float(e["peak_measured"][j]), float(e["peak_simulated"][j]),
                 _percent(e["peak_error_percent"][j], "+.1f"), float(e["rms_difference"][j]),
                 _percent(e["rms_difference_percent"][j], ".1f")]
                for j, c in enumerate(self.channels)]
        first, last, t0, t1 = self.span()
        text = (f"compared with {self.raw} (aligned on the {self.aligned_on}: the simulation "
                f"starts at {self.shift:.4f} s of the recording, standard error "
                f"{self.shift_error * 1e3:.2g} ms) over {first:.4f} to {last:.4f} s"
                f" of the {t1 - t0:g} s event ({100.0 * (last - first) / (t1 - t0):.0f} %)\n"
                + format_table(["channel", "measured peak [m/s^2]", "simulated peak",
                                "peak error [%]", "RMS of difference", "of measured RMS [%]"],
                               rows))
        by_reason = {}
        for name, reason in self.not_compared.items():
            by_reason.setdefault(reason, []).append(name)
        for reason, names in by_reason.items():
            text += f"\nnot compared: {', '.join(names)}: {reason}"
        return text
