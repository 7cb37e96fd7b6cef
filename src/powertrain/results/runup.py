"""Run-up results: order spectra of the mount channels (three per mount) against speed.

Channels: every mount's engine side (``left``), with a modal or measured chassis also its
body side (``left/passive``) and the body points of interest (``seat_rail``). Files: HDF5
(``runup --out``, SI with a ``unit`` attribute per dataset; docs/reference/outputs.md,
docs/guide/chassis.md) and long-format CSV (``runup --csv``, :data:`CSV_HEADER`, also the
measured-data format of :mod:`powertrain.iotools.measured`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from powertrain.analysis.channel import Channel, passive_name, split_side
from powertrain.analysis.orders import order_label, order_rms, synthesis_rms
from powertrain.analysis.phase import phase_deg
from powertrain.analysis.text_table import format_table
from powertrain.outputs import atomic_path, write_csv
from powertrain.plotting import plot_runup
from powertrain.plotting.body import plot_path_contributions, plot_runup_both_sides
from powertrain.plotting.style import is_axes, target_and_path
from powertrain.provenance import provenance as record
from powertrain.provenance import stamp_hdf5
from powertrain.results.base import HDF5_SUFFIXES, Result
from powertrain.solvers.modes import AS_MEASURED

QUANTITIES = {"displacement": "m", "velocity": "m/s", "acceleration": "m/s^2",
              "mount_force": "N"}
#: What the run-up's rigid-body mode frequencies are (printed by ``runup`` and ``whatif``).
RIGID_BODY_MODES_LABEL = "rigid-body modes, undamped, mounts at their static stiffness [Hz]"
#: The same for an engine with amplitude laws or friction
#: (:func:`powertrain.physics.condensation.condense`).
RIGID_BODY_MODES_LABEL_AS_MEASURED = \
    f"rigid-body modes, undamped, {AS_MEASURED} at their static stiffness [Hz]"
#: Columns written by :meth:`RunupResult.csv_text` (files with only the first five stay valid).
CSV_HEADER = ("mount,direction,quantity,rpm,side,velocity_rms_mm_per_s,"
              "acceleration_rms_m_per_s2,force_rms_n,phase_deg")


@dataclass(frozen=True)
class RunupResult(Result):
    """Order spectra of a run-up (complex peak amplitudes, SI).

    ``displacement``, ``velocity``, ``acceleration``, ``mount_force`` have shape
    (n_rpm, n_channels, n_orders); ``channels`` lists (mount, direction) in engine axes.
    ``save(path)`` writes ``.csv``, ``.h5`` or ``.png``.
    """

    rpm: np.ndarray
    orders: np.ndarray
    channels: list
    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    mount_force: np.ndarray
    mean_mount_force: np.ndarray
    periodicity: np.ndarray
    settings: dict = field(default_factory=dict)
    solver_seconds: float = 0.0
    rigid_body_modes_hz: np.ndarray = field(default_factory=lambda: np.zeros(0))
    meta: dict = field(default_factory=dict)
    #: velocity at every body-point channel per path (mount × local direction), shape
    #: (n_rpm, 3 n_points, 3 n_mounts, n_orders) [m/s]; None without body points
    path_contribution: np.ndarray | None = None
    #: the static operating point per speed (:class:`~powertrain.results.static.StaticResult`)
    operating_point: object = None
    #: the engine that ran (balancers as run, before effects); its file and mounts go into
    #: the HDF5 file
    engine: object = field(default=None, repr=False, compare=False)
    #: changes made to the engine (``balancer shafts switched off``), for the provenance
    modifications: list = field(default_factory=list)

    @property
    def mounts(self) -> list:
        """Mount names (engine-side channels), in order."""
        names = [m for m, _ in self.channels if split_side(m)[1] == "active"]
        points = set(self.points)
        return [m for m in dict.fromkeys(names) if m not in points]

    @property
    def points(self) -> list:
        """Body points of interest (modal or measured chassis)."""
        return list(self.meta.get("points", []))

    def side(self, name) -> str:
        """``active`` (engine side of a mount), ``passive`` (body side or body point)."""
        return "passive" if name in self.points else split_side(name)[1]

    def isolation_db(self, mount, direction, quantity="synthesis") -> np.ndarray:
        """20 log10(engine-side / body-side RMS velocity) of a mount per speed [dB]."""
        a = self.curve(mount, direction, quantity)
        b = self.curve(passive_name(mount), direction, quantity)
        tiny = np.finfo(float).tiny
        return 20 * np.log10(np.maximum(a, tiny) / np.maximum(b, tiny))

    @property
    def paths(self) -> list:
        """(mount, local direction) of every transfer path, in path-contribution order."""
        return [(m, d) for m in self.mounts for d in ("x", "y", "z")]

    def path_contributions(self, point, direction, order) -> np.ndarray:
        """Velocity at body ``point`` along engine ``direction`` carried by each path for
        ``order``, (n_rpm, n_paths) [m/s]; sums to the point's velocity."""
        if self.path_contribution is None:
            raise KeyError("no path contributions (no body points in the chassis)")
        row = self.points.index(point) * 3 + "xyz".index(direction)
        return self.path_contribution[:, row, :, self.order_index(order)]

    def order_rms(self, quantity="velocity") -> np.ndarray:
        """RMS value per rpm, channel and order [SI]."""
        return order_rms(getattr(self, quantity))

    def synthesis_rms(self, quantity="velocity") -> np.ndarray:
        """RMS sum over orders 0.5..8 per rpm and channel [SI]."""
        return synthesis_rms(getattr(self, quantity), axis=-1)

    def order_index(self, order: float) -> int:
        idx = np.flatnonzero(np.isclose(self.orders, order))
        if idx.size == 0:
            raise KeyError(f"order {order} not in result")
        return int(idx[0])

    def channel_index(self, mount: str, direction: str) -> int:
        return self.channels.index((mount, direction))

    def curve(self, mount, direction, quantity="synthesis", signal="velocity") -> np.ndarray:
        """RMS curve against rpm: ``quantity`` = ``synthesis`` or ``order_2`` etc. [SI]."""
        c = self.channel_index(mount, direction)
        if quantity == "synthesis":
            return self.synthesis_rms(signal)[:, c]
        order = float(quantity.split("_", 1)[1])
        return self.order_rms(signal)[:, c, self.order_index(order)]

    def to_text(self) -> str:
        """What ``powertrain runup`` prints: engine, rigid-body modes, effects, synthesis RMS
        velocity per speed and channel [mm/s], periodicity of a time integration."""
        name, file = self.meta.get("engine", ""), self.meta.get("engine_file", "")
        lines = [f"engine: {name} ({file})" if file else f"engine: {name}",
                 f"{self.modes_label}: {self._labelled_modes()} (damped, at the "
                 "mounts' dynamic stiffness: 'powertrain modes')"]
        if self.settings.get("effects"):
            lines.append("effects: " + effects_text(self.settings["effects"]))
        syn = self.synthesis_rms("velocity") * 1e3
        header = ["rpm"] + [Channel.of_node(m, d).label for m, d in self.channels]
        rows = [[f"{r:g}"] + [float(v) for v in syn[i]] for i, r in enumerate(self.rpm)]
        lines += ["synthesis RMS velocity (orders 0.5-8) [mm/s]:",
                  format_table(header, rows, "{:.3f}")]
        if self.settings.get("cycles"):
            lines.append("periodicity of processed windows: max "
                         f"{100 * np.max(self.periodicity):.2g} %")
        return "\n".join(lines)

    @property
    def modes_label(self) -> str:
        """What the printed rigid-body modes are (as measured for nonlinear mounts)."""
        return RIGID_BODY_MODES_LABEL_AS_MEASURED if self.meta.get("nonlinear_mounts") \
            else RIGID_BODY_MODES_LABEL

    def _labelled_modes(self) -> str:
        """``5.9 (y), 6.7 (z), ...``: each mode with its dominant coordinate, where known."""
        coords = list(self.meta.get("rigid_body_mode_dominant", []))
        coords += [""] * (len(self.rigid_body_modes_hz) - len(coords))
        return ", ".join(f"{f:.1f} ({c})" if c else f"{f:.1f}"
                         for f, c in zip(self.rigid_body_modes_hz, coords))

    def synthetic_comments(self, provenance=None) -> list:
        """``#`` lines of a CSV of a run-up with added effects: the SYNTHETIC label and the
        ``provenance`` line; none without effects."""
        effects = self.settings.get("effects")
        if not effects:
            return []
        return [f"SYNTHETIC: simulated run-up with added effects {effects_text(effects)}; "
                "not measured"] + ([f"provenance: {provenance.line()}"] if provenance else [])

    def csv_text(self, comments=()) -> str:
        """Long-format CSV: RMS velocity [mm/s], acceleration [m/s²], transmitted force [N]
        and velocity phase [deg] per channel, side, order and speed (body points: no force,
        synthesis rows: no phase). ``comments`` become ``#`` lines above the header."""
        phase = phase_deg(self.velocity)
        lines = [f"# {' '.join(str(c).split())}" for c in comments] + [CSV_HEADER]
        values = [(self.order_rms("velocity") * 1e3, self.synthesis_rms("velocity") * 1e3),
                  (self.order_rms("acceleration"), self.synthesis_rms("acceleration")),
                  (self.order_rms("mount_force"), self.synthesis_rms("mount_force"))]
        points = set(self.points)
        labels = [order_label(o) for o in self.orders] + ["synthesis"]
        for c, (name, direction) in enumerate(self.channels):
            base, side = split_side(name)
            if name in points:
                side = "passive"
            for k, q in enumerate(labels):
                for i, r in enumerate(self.rpm):
                    cells = [(rms[i, c, k] if k < len(self.orders) else syn[i, c])
                             for rms, syn in values]
                    force = "" if name in points else f"{cells[2]:.8g}"
                    angle = phase[i, c, k] if k < len(self.orders) else np.nan
                    angle = f"{angle:.6g}" if np.isfinite(angle) else ""
                    lines.append(f"{base},{direction},{q},{r:g},{side},{cells[0]:.8g},"
                                 f"{cells[1]:.8g},{force},{angle}")
        return "\n".join(lines) + "\n"

    def to_csv(self, path, comments=()) -> None:
        """Write :meth:`csv_text` atomically."""
        write_csv(path, self.csv_text(comments))

    def writers(self) -> dict:
        """``.csv``, ``.h5``/``.hdf5``, ``.png``."""
        return {".csv": self.to_csv, **dict.fromkeys(HDF5_SUFFIXES, self.to_hdf5),
                **super().writers()}

    def to_hdf5(self, path, *, engine_snapshot: str | None = None,
                mount_snapshots: dict | None = None, synthetic: bool = False,
                description: str | None = None, provenance: dict | None = None) -> None:
        """Write the HDF5 layout atomically: ``engine_snapshot`` (engine file as read),
        ``mount_snapshots`` (mount models as run) and ``provenance``
        (:func:`powertrain.provenance.provenance`) default to :attr:`engine`'s."""
        import h5py  # deferred: heavy optional package

        snapshot, mount_snapshots, description, provenance = self._run_record(
            engine_snapshot, mount_snapshots, description, provenance)
        with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
            a = h5.attrs
            stamp_hdf5(a, "powertrain-runup")
            a["settings"] = json.dumps(self.settings)
            a["meta"] = json.dumps(self.meta)
            a["engine_snapshot"] = snapshot
            a["mount_snapshots"] = json.dumps(mount_snapshots or {})
            a["synthetic"] = bool(synthetic)
            a["description"] = description
            if provenance:
                a["provenance"] = json.dumps(provenance, allow_nan=False)
                a["command_line"] = provenance.get("command_line", "")
                a["engine_as_run"] = json.dumps(provenance.get("engine_as_run", {}),
                                                allow_nan=False)
            for key, data, unit in self._datasets():
                h5.create_dataset(key, data=data).attrs["unit"] = unit
            for key, names in self._names().items():
                h5.create_dataset(key, data=np.array(names, dtype="S"))
            h5["channels"].attrs["axes"] = "engine coordinate system (Kovarik 2016, sec. 4.1)"
            if self.path_contribution is not None:
                h5["path_contribution/velocity"].attrs["axes"] = \
                    "rpm, point channel, path (mount x local direction), order"
            if self.operating_point is not None:
                write_operating_point(h5.create_group("operating_point"), self.operating_point)

    def _run_record(self, snapshot, mounts, description, provenance):
        """The HDF5 file's run record: as given, else from :attr:`engine`."""
        e = self.engine
        if e is None:
            return snapshot or "", mounts, description or "", provenance
        if snapshot is None:
            snapshot = Path(e.file).read_text(encoding="utf-8") if e.file else ""
        if mounts is None:
            mounts = {"mounts": json.dumps({
                f"{m.name}.{a}": {"model": mdl.topology.name, "params_si": mdl.params,
                                  "source": mdl.source}
                for m in e.mounts for a, mdl in m.directions.items()})}
        if description is None:
            description = f"run-up {self.rpm[0]:g}-{self.rpm[-1]:g} rpm, {e.name}"
        if provenance is None:
            provenance = record(e, engine_file=e.file, modifications=self.modifications,
                                effects=self.settings.get("effects"))
        return snapshot, mounts, description, provenance

    def _datasets(self) -> list:
        """``(path, array, unit)`` of every numeric HDF5 dataset but the operating point's."""
        out = [("rpm", self.rpm, "rpm"), ("orders", self.orders, "1")]
        for name, unit in QUANTITIES.items():
            arr = getattr(self, name)
            out += [(f"{name}/amplitude", arr, unit), (f"{name}/order_rms", order_rms(arr), unit),
                    (f"{name}/synthesis_rms", synthesis_rms(arr, axis=-1), unit)]
        out += [("mount_force/mean", self.mean_mount_force, "N"),
                ("diagnostics/periodicity", self.periodicity, "1"),
                ("diagnostics/rigid_body_modes_hz", self.rigid_body_modes_hz, "Hz"),
                ("diagnostics/solver_seconds", self.solver_seconds, "s")]
        if self.path_contribution is not None:
            out.append(("path_contribution/velocity", self.path_contribution, "m/s"))
        return out

    def _names(self) -> dict:
        """Path -> names of the string datasets (channels; points and paths)."""
        out = {"channels/mount": [m for m, _ in self.channels],
               "channels/direction": [d for _, d in self.channels],
               "channels/side": [self.side(m) for m, _ in self.channels],
               "channels/location": [split_side(m)[0] for m, _ in self.channels]}
        if self.path_contribution is not None:
            out["path_contribution/points"] = [f"{p}.{d}" for p in self.points for d in "xyz"]
            out["path_contribution/paths"] = [f"{m}.{d}" for m, d in self.paths]
        return out

    def plot_paths(self, ax=None, *, path=None, order=2.0, provenance=None):
        """Path contributions at the body points; returns the figure."""
        ax, path = target_and_path(ax, path)
        return plot_path_contributions(self, path, order, ax=ax, provenance=provenance)

    def plot(self, ax=None, *, path=None, quantities=("synthesis", "order_2", "order_4"),
             signal="velocity", others=None, channel=None, quantity=None, provenance=None):
        """The thesis's figure set (Figs 45–71): a row per mount and direction, a column per
        one of ``quantities``, RMS ``signal`` against rpm; returns the figure
        (:func:`powertrain.plotting.plot_runup`).

        ``ax``: None, a Figure or SubFigure, or one Axes where ``channel`` ((mount,
        direction)) and ``quantity`` leave one panel. ``others``: (label, RunupResult)
        overlaid. With body-side channels, no ``others`` and no panel chosen: both sides of
        each mount and the body points
        (:func:`powertrain.plotting.body.plot_runup_both_sides`).
        """
        ax, path = target_and_path(ax, path)
        if (not others and not is_axes(ax) and channel is None and quantity is None
                and any(self.side(m) == "passive" for m, _ in self.channels)):
            return plot_runup_both_sides(self, path, quantities, signal, ax=ax,
                                         provenance=provenance)
        return plot_runup([("simulation", self)] + list(others or []), path, quantities,
                          signal, ax=ax, channel=channel, quantity=quantity,
                          provenance=provenance)


#: /operating_point datasets: (result attribute, unit); shapes (n_rpm, ...) as in the result.
OPERATING_POINT = {"mean_torque": "N*m", "body": "m, m, m, rad, rad, rad",
                   "deflection": "m", "force": "N", "tangent_stiffness": "N/m",
                   "static_factor": "1", "iterations": "1", "residual": "1"}


def write_operating_point(g, static) -> None:
    """Write the ``static`` operating point per speed into the HDF5 group ``g``."""
    g.attrs["gear_ratio"] = float(static.points[0].gear_ratio) if static.points else 1.0
    g.create_dataset("mounts", data=np.array(static.mounts, dtype="S"))
    for name, unit in OPERATING_POINT.items():
        g.create_dataset(name, data=static.stack(name)).attrs["unit"] = unit


def effects_text(scenario) -> str:
    """``name(param=value, ...); ...`` of the effects added [SI]."""
    return "; ".join(f"{name}(" + ", ".join(f"{k}={v:g}" for k, v in p.items()) + ")"
                     for name, p in scenario.items())


@dataclass(frozen=True)
class SweepRunup(Result):
    """A continuous run-up (one time-integrated speed ramp): the raw recording and its
    tracked order curves.

    Attributes
    ----------
    recording : Recording
        Mount-point accelerations and speed against time (SYNTHETIC; raw HDF5 layout of
        :func:`powertrain.iotools.raw_hdf5.write_raw_hdf5`).
    tracked : TrackedOrders
        Order curves tracked from it (COT, orders 0.5..8, velocity).
    rate_rpm_per_s : float
        Speed ramp [rpm/s].
    engine : Engine, optional
    """

    recording: object
    tracked: object
    rate_rpm_per_s: float
    engine: object = field(default=None, repr=False, compare=False)

    def to_text(self) -> str:
        """What ``powertrain runup --sweep`` prints (about 12 speeds)."""
        tracked = self.tracked
        syn = tracked.synthesis_rms() * 1e3
        labels = [f"{c.mount}.{c.direction}" for c in tracked.channels]
        step = max(1, len(tracked.rpm) // 12)
        rows = [[f"{r:g}"] + [float(v) for v in syn[i]]
                for i, r in list(enumerate(tracked.rpm))[::step]]
        return "\n".join([self.recording.comments[0],
                          "tracked synthesis RMS velocity (orders 0.5-8) [mm/s]:",
                          format_table(["rpm"] + labels, rows, "{:.3f}")])

    def plot(self, ax=None, *, path=None, provenance=None):
        """The tracked order curves (:meth:`TrackedOrders.plot`); returns the figure."""
        return self.tracked.plot(ax, path=path, provenance=provenance)

    def to_csv(self, path) -> None:
        """The tracked curves as long-format CSV."""
        self.tracked.to_csv(path)

    def to_hdf5(self, path) -> None:
        """The tracked curves as HDF5."""
        self.tracked.to_hdf5(path)

    def writers(self) -> dict:
        """``.csv``, ``.h5``/``.hdf5`` (the tracked curves), ``.png``."""
        return {".csv": self.to_csv, **dict.fromkeys(HDF5_SUFFIXES, self.to_hdf5),
                **super().writers()}
