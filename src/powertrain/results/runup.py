"""Run-up results: order spectra of the mount channels (three per mount) against speed.

HDF5 layout (all arrays SI, units in each dataset's ``unit`` attribute)::

    /                      attrs: format="powertrain-runup", format_version, powertrain_version,
                                  created (UTC ISO 8601), solver settings (JSON), engine name,
                                  engine_snapshot (the engine file text), mount_snapshots (JSON
                                  {path: text}), synthetic (bool), description
    /rpm                   (n_rpm,)                       rpm
    /orders                (n_orders,)                    1 (orders 0.5 ... 8)
    /channels/mount        (n_ch,) str                    mount names (left/right/gearbox ...)
    /channels/direction    (n_ch,) str                    x/y/z (engine axes)
    /velocity/amplitude    (n_rpm, n_ch, n_orders) complex   m/s   (peak complex amplitude)
    /velocity/order_rms    (n_rpm, n_ch, n_orders)           m/s
    /velocity/synthesis_rms (n_rpm, n_ch)                  m/s   (RMS sum, orders <= 8)
    /displacement/...      same, m
    /acceleration/...      same, m/s^2
    /mount_force/...       same, N (force transmitted to ground, engine axes)
    /mount_force/mean      (n_rpm, n_ch)                   N (static preload part, no gravity)
    /diagnostics/periodicity        (n_rpm,)              1 (cycle-to-cycle, Newmark)
    /diagnostics/rigid_body_modes_hz (6,)                 Hz
    /diagnostics/solver_seconds     ()                    s

    /channels/side         (n_ch,) str                    active (engine side) / passive (body)
    /channels/location     (n_ch,) str                    mount or body-point name
    /path_contribution/velocity (n_rpm, 3 n_points, 3 n_mounts, n_orders) complex  m/s
                           (with body points: velocity at each body-point channel carried
                           by each path mount × local direction; /points, /paths name them)

Channels: every mount's engine side (``left``), with a modal or measured chassis also its
body side (``left/passive``) and the body points of interest (``seat_rail``).

Long-format CSV (also the measured-data format): columns
``mount,direction,quantity,rpm,side,velocity_rms_mm_per_s,acceleration_rms_m_per_s2,
force_rms_n`` with ``quantity`` = ``order_0.5``, ``order_1``, ... ``order_8`` or
``synthesis``, ``side`` = ``active`` or ``passive``; ``force_rms_n`` is the force the mount
transmits to the body (empty for body points). Files with only the first four columns and
``velocity_rms_mm_per_s`` stay valid input.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.orders import order_label, order_rms, synthesis_rms

QUANTITIES = {
    "displacement": "m",
    "velocity": "m/s",
    "acceleration": "m/s^2",
    "mount_force": "N",
}
#: Columns written by :meth:`RunupResult.csv_text` (files with only the first five stay valid).
CSV_HEADER = ("mount,direction,quantity,rpm,side,velocity_rms_mm_per_s,"
              "acceleration_rms_m_per_s2,force_rms_n")


@dataclass
class RunupResult:
    """Order spectra of a run-up (complex peak amplitudes, SI).

    Arrays ``displacement``, ``velocity``, ``acceleration``, ``mount_force`` have shape
    (n_rpm, n_channels, n_orders); ``channels`` lists (mount, direction) in engine axes.
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
    #: complex velocity at every body-point channel per mount path (mount × local
    #: direction), shape (n_rpm, 3 n_points, 3 n_mounts, n_orders) [m/s]; None without
    #: body points (see :func:`powertrain.workflows.runup.path_contributions`)
    path_contribution: np.ndarray | None = None

    # ----------------------------------------------------------------- both sides
    @property
    def mounts(self) -> list:
        """Mount names (engine-side channels), in order."""
        from powertrain.analysis.channel import split_side
        names = [m for m, _ in self.channels if split_side(m)[1] == "active"]
        points = set(self.points)
        return [m for m in dict.fromkeys(names) if m not in points]

    @property
    def points(self) -> list:
        """Body points of interest (modal or measured chassis)."""
        return list(self.meta.get("points", []))

    def side(self, name) -> str:
        """``active`` (engine side of a mount), ``passive`` (body side or body point)."""
        from powertrain.analysis.channel import split_side
        return "passive" if name in self.points else split_side(name)[1]

    def isolation_db(self, mount, direction, quantity="synthesis") -> np.ndarray:
        """Isolation of a mount: 20 log10(engine-side / body-side RMS velocity) [dB]
        per speed (needs a non-rigid chassis)."""
        from powertrain.analysis.channel import passive_name
        a = self.curve(mount, direction, quantity)
        b = self.curve(passive_name(mount), direction, quantity)
        tiny = np.finfo(float).tiny
        return 20 * np.log10(np.maximum(a, tiny) / np.maximum(b, tiny))

    @property
    def paths(self) -> list:
        """(mount, local direction) of every transfer path, in path-contribution order."""
        return [(m, d) for m in self.mounts for d in ("x", "y", "z")]

    def path_contributions(self, point, direction, order) -> np.ndarray:
        """Complex velocity at body point ``point`` along engine ``direction`` carried by each
        path, for ``order``: shape (n_rpm, n_paths) [m/s]; sums to the point's velocity."""
        if self.path_contribution is None:
            raise KeyError("no path contributions (no body points in the chassis)")
        row = self.points.index(point) * 3 + "xyz".index(direction)
        return self.path_contribution[:, row, :, self.order_index(order)]

    # ----------------------------------------------------------------- accessors
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

    # ----------------------------------------------------------------- writers
    def csv_text(self, comments=()) -> str:
        """Long-format CSV text: RMS velocity [mm/s], acceleration [m/s²] and the force the
        mount transmits to the body [N] per channel, side, order and speed (body points
        have no force: empty cell). ``comments`` become ``#`` lines above the header (a
        SYNTHETIC label, the provenance)."""
        from powertrain.analysis.channel import split_side
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
                    lines.append(f"{base},{direction},{q},{r:g},{side},{cells[0]:.8g},"
                                 f"{cells[1]:.8g},{force}")
        return "\n".join(lines) + "\n"

    def to_csv(self, path, comments=()) -> None:
        """Write :meth:`csv_text` atomically."""
        from powertrain.outputs import atomic_write
        text = self.csv_text(comments)
        with atomic_write(path) as fh:
            fh.write(text)

    def to_hdf5(self, path, *, engine_snapshot: str = "", mount_snapshots: dict | None = None,
                synthetic: bool = False, description: str = "",
                provenance: dict | None = None) -> None:
        """Write the documented HDF5 layout atomically.

        ``engine_snapshot`` is the engine file as read; ``provenance``
        (:func:`powertrain.provenance.provenance`) records the engine as it ran (e.g. the
        balancers off), the effects applied, the command line, the version and the time.
        """
        import h5py

        from powertrain.outputs import atomic_path
        from powertrain.provenance import stamp_hdf5
        with atomic_path(path) as tmp:
            with h5py.File(tmp, "w") as h5:
                a = h5.attrs
                stamp_hdf5(a, "powertrain-runup")
                a["settings"] = json.dumps(self.settings)
                a["meta"] = json.dumps(self.meta)
                a["engine_snapshot"] = engine_snapshot
                a["mount_snapshots"] = json.dumps(mount_snapshots or {})
                a["synthetic"] = bool(synthetic)
                a["description"] = description
                if provenance:
                    a["provenance"] = json.dumps(provenance, allow_nan=False)
                    a["command_line"] = provenance.get("command_line", "")
                    a["engine_as_run"] = json.dumps(provenance.get("engine_as_run", {}),
                                                    allow_nan=False)
                ds = h5.create_dataset("rpm", data=self.rpm)
                ds.attrs["unit"] = "rpm"
                ds = h5.create_dataset("orders", data=self.orders)
                ds.attrs["unit"] = "1"
                g = h5.create_group("channels")
                g.create_dataset("mount", data=np.array([m for m, _ in self.channels], dtype="S"))
                g.create_dataset("direction",
                                 data=np.array([d for _, d in self.channels], dtype="S"))
                g.attrs["axes"] = "engine coordinate system (Kovarik 2016, sec. 4.1)"
                for name, unit in QUANTITIES.items():
                    g = h5.create_group(name)
                    arr = getattr(self, name)
                    for key, data in (("amplitude", arr), ("order_rms", order_rms(arr)),
                                      ("synthesis_rms", synthesis_rms(arr, axis=-1))):
                        ds = g.create_dataset(key, data=data)
                        ds.attrs["unit"] = unit
                ds = h5["mount_force"].create_dataset("mean", data=self.mean_mount_force)
                ds.attrs["unit"] = "N"
                g = h5.create_group("diagnostics")
                g.create_dataset("periodicity", data=self.periodicity).attrs["unit"] = "1"
                g.create_dataset("rigid_body_modes_hz",
                                 data=self.rigid_body_modes_hz).attrs["unit"] = "Hz"
                g.create_dataset("solver_seconds", data=self.solver_seconds).attrs["unit"] = "s"
                self._write_sides(h5)

    def _write_sides(self, h5):
        """/channels/side and /channels/location; /path_contribution with body points."""
        from powertrain.analysis.channel import split_side
        g = h5["channels"]
        g.create_dataset("side", data=np.array([self.side(m) for m, _ in self.channels],
                                               dtype="S"))
        g.create_dataset("location", data=np.array([split_side(m)[0] for m, _ in
                                                    self.channels], dtype="S"))
        if self.path_contribution is not None:
            pg = h5.create_group("path_contribution")
            ds = pg.create_dataset("velocity", data=self.path_contribution)
            ds.attrs["unit"] = "m/s"
            ds.attrs["axes"] = "rpm, point channel, path (mount x local direction), order"
            pg.create_dataset("points", data=np.array(
                [f"{p}.{d}" for p in self.points for d in "xyz"], dtype="S"))
            pg.create_dataset("paths", data=np.array([f"{m}.{d}" for m, d in self.paths],
                                                     dtype="S"))

    @classmethod
    def from_hdf5(cls, path) -> RunupResult:
        """Read a run-up HDF5 file; every dataset's type and shape is checked (errors name
        the file and the dataset or attribute)."""
        import h5py

        from powertrain.errors import InputError
        from powertrain.iotools.textfile import check_regular_file
        check_regular_file(path)
        try:
            h5 = h5py.File(path, "r")
        except (OSError, FileNotFoundError) as exc:
            raise InputError(f"cannot open HDF5 file ({exc})", file=path) from None
        try:
            with h5:
                return cls._from_open_hdf5(h5, path)
        except InputError:
            raise
        except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
            raise InputError(f"damaged or not in the run-up layout ({type(exc).__name__}: "
                             f"{str(exc)[:120]})", file=path) from None

    @classmethod
    def _from_open_hdf5(cls, h5, path) -> RunupResult:
        from powertrain.errors import InputError
        if h5.attrs.get("format") != "powertrain-runup":
            raise InputError("not a powertrain run-up result", file=path, key="format")
        rpm = _h5_array(h5, "rpm", path, "f", 1)
        orders = _h5_array(h5, "orders", path, "f", 1)
        mounts = _h5_names(h5, "channels/mount", path)
        directions = _h5_names(h5, "channels/direction", path)
        if len(mounts) != len(directions):
            raise InputError(f"{len(mounts)} mounts but {len(directions)} directions",
                             file=path, key="channels/direction")
        n = (rpm.size, len(mounts), orders.size)
        amp = {q: _h5_array(h5, f"{q}/amplitude", path, "fc", 3, n)
               for q in ("displacement", "velocity", "acceleration", "mount_force")}
        return cls(rpm=rpm, orders=orders, channels=list(zip(mounts, directions)), **amp,
                   mean_mount_force=_h5_array(h5, "mount_force/mean", path, "f", 2, n[:2]),
                   periodicity=_h5_array(h5, "diagnostics/periodicity", path, "f", 1, n[:1]),
                   settings=_h5_json(h5, "settings", path),
                   solver_seconds=float(_h5_array(h5, "diagnostics/solver_seconds", path,
                                                  "f", 0)),
                   rigid_body_modes_hz=_h5_array(h5, "diagnostics/rigid_body_modes_hz", path,
                                                 "f", 1),
                   meta=_h5_json(h5, "meta", path),
                   path_contribution=_h5_paths(h5, path, n))

    # ----------------------------------------------------------------- plots
    def plot_paths(self, ax=None, *, path=None, order=2.0, provenance=None):
        """Path contributions at the body points (see
        :func:`powertrain.plotting.body.plot_path_contributions`)."""
        from powertrain.plotting.body import plot_path_contributions
        from powertrain.plotting.style import target_and_path
        ax, path = target_and_path(ax, path)
        return plot_path_contributions(self, path, order, ax=ax,
                                       provenance=provenance or getattr(self, "provenance",
                                                                        None))

    def plot(self, ax=None, *, path=None, quantities=("synthesis", "order_2", "order_4"),
             signal="velocity", others=None, channel=None, quantity=None, provenance=None):
        """The thesis's figure set (Figs 45–71): one row per mount and direction, one column
        per quantity (every one of ``quantities`` is drawn), RMS ``signal`` against rpm.

        ``ax``: None (new figure), a Figure/SubFigure (the grid) or an Axes (the one panel
        ``channel``/``quantity``); ``others``: optional list of (label, RunupResult)
        overlaid; ``provenance``: foot line (default: ``self.provenance`` if set). Returns the
        figure; see :func:`powertrain.plotting.plot_runup`. With a body model (body-side
        channels), no ``others`` and no single panel: both sides of each mount in one panel,
        and the body points (:func:`powertrain.plotting.body.plot_runup_both_sides`).
        """
        from powertrain.plotting import plot_runup
        from powertrain.plotting.style import is_axes, target_and_path
        ax, path = target_and_path(ax, path)
        if (not others and not is_axes(ax)
                and any(self.side(m) == "passive" for m, _ in self.channels)):
            from powertrain.plotting.body import plot_runup_both_sides
            return plot_runup_both_sides(self, path, quantities, signal, ax=ax,
                                         provenance=provenance or getattr(self, "provenance",
                                                                          None))
        return plot_runup([("simulation", self)] + list(others or []), path, quantities,
                          signal, ax=ax, channel=channel, quantity=quantity,
                          provenance=provenance or getattr(self, "provenance", None))


def _h5_array(h5, key, path, kinds, ndim, shape=None):
    """Dataset ``key`` as an array of dtype kind in ``kinds`` ("f": real, "c": complex),
    ``ndim`` dimensions and, if given, ``shape``."""
    import h5py

    from powertrain.errors import InputError
    obj = h5.get(key)
    if not isinstance(obj, h5py.Dataset):
        raise InputError("missing dataset", file=path, key=key)
    kind = obj.dtype.kind
    if not (kind in kinds or (kind in "iu" and "f" in kinds)):
        raise InputError(f"expected numbers, got dtype {obj.dtype}", file=path, key=key)
    if obj.ndim != ndim or (shape is not None and obj.shape != tuple(shape)):
        want = shape if shape is not None else f"{ndim} dimensions"
        raise InputError(f"shape {obj.shape}, expected {want}", file=path, key=key)
    data = obj[()]
    return np.asarray(data, dtype=complex if kind == "c" else float)


def _h5_paths(h5, path, n):
    """/path_contribution/velocity (n_rpm, 3 n_points, 3 n_mounts, n_orders) or None."""
    from powertrain.errors import InputError
    if "path_contribution" not in h5:
        return None
    key = "path_contribution/velocity"
    data = _h5_array(h5, key, path, "c", 4)
    if data.shape[0] != n[0] or data.shape[3] != n[2] or data.shape[1] % 3 or data.shape[2] % 3:
        raise InputError(f"shape {data.shape} does not fit the speeds and orders", file=path,
                         key=key)
    return data


def _h5_names(h5, key, path) -> list[str]:
    """1-D dataset of strings (bytes or str)."""
    import h5py

    from powertrain.errors import InputError
    obj = h5.get(key)
    if not isinstance(obj, h5py.Dataset) or obj.ndim != 1 or obj.dtype.kind not in "SOU":
        raise InputError("expected a 1-D dataset of names", file=path, key=key)
    names = []
    for v in obj[()]:
        if isinstance(v, bytes):
            try:
                v = v.decode("utf-8")
            except UnicodeDecodeError:
                raise InputError("names must be UTF-8", file=path, key=key) from None
        if not isinstance(v, str):
            raise InputError("expected names (strings)", file=path, key=key)
        names.append(v)
    return names


def _h5_json(h5, attr, path) -> dict:
    """Attribute ``attr`` holding a JSON object."""
    from powertrain.errors import InputError
    raw = h5.attrs.get(attr)
    if raw is None:
        raise InputError("missing attribute", file=path, key=attr)
    if isinstance(raw, bytes):
        raw = raw.decode("utf-8", errors="replace")
    try:
        value = json.loads(str(raw))
    except ValueError:
        raise InputError("attribute is not JSON", file=path, key=attr) from None
    if not isinstance(value, dict):
        raise InputError("expected a JSON object", file=path, key=attr)
    return value
