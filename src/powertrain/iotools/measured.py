r"""Measured run-up order curves from the long-format CSV or the run-up HDF5 layout, in SI.

CSV layout: docs/reference/csv-formats.md and raw-data.md. ``passive`` rows of mount ``left``
become channel ``left/passive`` (another passive name is a body point); peak levels become RMS
by :math:`1/\sqrt2`; acceleration and displacement become velocity order by order
(:func:`to_velocity`). Every problem is an :class:`~powertrain.errors.InputError` naming file,
line and column.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from powertrain.analysis.channel import DIRECTIONS, SIDES, Channel, passive_name, split_side
from powertrain.analysis.orders import order_label, quantity_sort_key
from powertrain.analysis.phase import phase_deg, wrap_deg
from powertrain.errors import InputError
from powertrain.iotools.raw import detect_format
from powertrain.iotools.runup_hdf5 import read_runup_hdf5
from powertrain.iotools.textfile import check_regular_file, parse_number, read_text

#: Recognised level columns: name -> (factor to SI, statistic).
LEVEL_COLUMNS = {
    "velocity_rms_mm_per_s": (1e-3, "rms"),
    "velocity_rms_m_per_s": (1.0, "rms"),
    "velocity_peak_mm_per_s": (1e-3, "peak"),
    "velocity_peak_m_per_s": (1.0, "peak"),
    "acceleration_rms_m_per_s2": (1.0, "rms"),
    "displacement_rms_mm": (1e-3, "rms"),
    "force_rms_n": (1.0, "rms"),
}
KEY_COLUMNS = ("mount", "direction", "quantity", "rpm")
#: Optional columns: ``side`` (``active`` engine side, default; ``passive`` body side or a
#: body point) and further value columns (checked, not compared).
OPTIONAL_COLUMNS = ("side", "acceleration_rms_m_per_s2", "force_rms_n", "phase_deg")
#: Highest plausible order level [m/s RMS]: above 1 km/s it is a unit or export error.
MAX_LEVEL_M_PER_S = 1e3
#: Highest plausible engine speed [rpm].
MAX_RPM = 1e5


def _check_level(level_si: float, path, line, key) -> None:
    if level_si > MAX_LEVEL_M_PER_S:
        raise InputError(f"level {level_si:.3g} m/s above the plausible {MAX_LEVEL_M_PER_S:g} "
                         "m/s (unit error?)", file=path, line=line, key=key)


def normalise_quantity(text: str) -> str:
    """``synthesis`` or ``order_<n>`` with n > 0 written without trailing zeros (else ValueError)."""
    text = text.strip()
    if text == "synthesis":
        return text
    if text.startswith("order_"):
        try:
            order = float(text[6:])
        except ValueError:
            order = float("nan")
        if math.isfinite(order) and order > 0:
            return order_label(order)
    raise ValueError(f"unknown quantity {text!r} (expected 'synthesis' or 'order_<n>', e.g. order_2)")


@dataclass
class MeasuredRunup:
    """Order curves of a run-up: RMS velocity against speed per channel and quantity.

    Attributes
    ----------
    curves : dict
        ``(mount, direction, quantity) -> (rpm [rpm], level [m/s RMS])``, speeds increasing.
    source, notes, comments : str, list of str, list of str
        File read, conversions applied, the file's comment lines (without ``#``).
    signal : str
        ``velocity`` (levels in m/s) or ``mount_force`` (levels in N).
    phases : dict
        ``(mount, direction, quantity) -> phase [deg]`` at that curve's speeds (NaN where
        undefined), order curves with a phase only. Order k is √2·RMS·cos(kθ + φ), θ the
        crank angle from cylinder-1 firing TDC (:mod:`powertrain.analysis.phase`).
    """

    curves: dict
    source: str = ""
    notes: list = field(default_factory=list)
    comments: list = field(default_factory=list)
    signal: str = "velocity"
    phases: dict = field(default_factory=dict)

    @property
    def channels(self) -> list:
        """(mount, direction) pairs present, in order of first appearance."""
        return list(dict.fromkeys((m, d) for m, d, _ in self.curves))

    @property
    def quantities(self) -> list:
        """Quantities present, ``synthesis`` first, then orders ascending."""
        return sorted({q for _, _, q in self.curves}, key=quantity_sort_key)

    @property
    def synthetic(self) -> bool:
        """True if a comment line says the data are synthetic."""
        return any("synthetic" in c.lower() for c in self.comments)

    def curve(self, mount: str, direction: str, quantity: str):
        """``(rpm [rpm], level [m/s RMS])`` of one channel and quantity (KeyError if absent)."""
        return self.curves[(mount, direction, quantity)]

    def rpm_range(self):
        """Lowest and highest speed of all curves [rpm]."""
        return (min(float(r[0]) for r, _ in self.curves.values()),
                max(float(r[-1]) for r, _ in self.curves.values()))

    @classmethod
    def from_result(cls, result, source: str = "", signal: str = "velocity") -> MeasuredRunup:
        """RMS curves and phases of a :class:`~powertrain.results.runup.RunupResult`'s
        ``signal`` (``velocity`` or ``mount_force``), synthesis and every order."""
        rpm = np.asarray(result.rpm, float)
        order_idx = np.argsort(rpm)
        rms = result.order_rms(signal)[order_idx]
        syn = result.synthesis_rms(signal)[order_idx]
        phase = phase_deg(getattr(result, signal)[order_idx])
        rpm = rpm[order_idx]
        curves, phases = {}, {}
        for c, (m, d) in enumerate(result.channels):
            curves[(m, d, "synthesis")] = (rpm.copy(), syn[:, c].copy())
            for k, order in enumerate(result.orders):
                curves[(m, d, order_label(order))] = (rpm.copy(), rms[:, c, k].copy())
                if np.any(np.isfinite(phase[:, c, k])):
                    phases[(m, d, order_label(order))] = phase[:, c, k].copy()
        return cls(curves, source=str(source), signal=signal, phases=phases)


def read_measured(path, mounts=None, points=None) -> MeasuredRunup:
    """Read measured (or simulated) run-up order curves from CSV or HDF5.

    Parameters
    ----------
    path : str or Path
        Long-format CSV (docs/reference/csv-formats.md) or run-up HDF5 file.
    mounts : sequence of str, optional
        Mount names allowed (those of the model compared with); None accepts any name.
    points : sequence of str, optional
        Body points of interest allowed on ``passive`` rows; None accepts any name.

    Returns
    -------
    MeasuredRunup
        Levels in m/s RMS (:class:`InputError` naming file, line and column on a problem).
    """
    check_regular_file(path)
    path = str(path)
    mounts, points = _names(mounts, "mounts"), _names(points, "points")
    if detect_format(path) == "hdf5":
        return _read_hdf5(path, mounts)
    return _read_csv(path, mounts, points)


def _names(names, key):
    """``mounts`` or ``points`` of :func:`read_measured` as a list of str (None stays)."""
    if names is None:
        return None
    items = [names] if isinstance(names, str) else names
    try:
        items = list(items)
    except TypeError:
        items = [items]
    if not all(isinstance(n, str) for n in items):
        raise InputError(f"expected names (str), got {names!r}"[:200], key=key)
    return items


def _read_hdf5(path, mounts):
    try:
        result = read_runup_hdf5(path)
    except KeyError as exc:
        raise InputError(f"not in the run-up HDF5 layout (missing {exc})", file=path) from None
    if mounts is not None:
        for m, _ in result.channels:
            base, side = split_side(m)
            if base not in mounts and side == "active" and not _is_point(result, m):
                raise InputError(f"unknown mount {m!r} (known: {', '.join(mounts)})",
                                 file=path, key="channels/mount")
    for _, d in result.channels:
        if d not in DIRECTIONS:
            raise InputError(f"unknown direction {d!r} (expected x, y, z)", file=path,
                             key="channels/direction")
    rpm = np.asarray(result.rpm, float)
    if not np.all(np.isfinite(rpm)) or np.any(rpm <= 0):
        raise InputError("speeds must be finite and > 0", file=path, key="rpm")
    if np.unique(rpm).size != rpm.size:
        raise InputError("duplicate speed", file=path, key="rpm")
    if np.any(rpm > MAX_RPM):
        raise InputError(f"speed above {MAX_RPM:g} rpm", file=path, key="rpm")
    if not np.all(np.isfinite(result.velocity)):
        raise InputError("NaN or infinite velocity", file=path, key="velocity/amplitude")
    worst = float(np.max(np.abs(result.velocity), initial=0.0))
    _check_level(worst, path, None, "velocity/amplitude")
    return MeasuredRunup.from_result(result, source=path)


def _is_point(result, name) -> bool:
    """True if ``name`` is a body point of a result (meta ``points``)."""
    return name in result.meta.get("points", [])


def _read_csv(path, mounts, points=None):
    comments, header, layout = [], None, None
    rows, order = {}, []          # key -> {rpm: (level, line)}; keys in file order
    for lineno, raw in enumerate(read_text(path, "CSV").splitlines(), start=1):
        text = raw.strip()
        if not text:
            continue
        if text.startswith("#"):
            comments.append(text[1:].strip())
            continue
        fields = [f.strip() for f in text.split(",")]
        if header is None:
            header, layout = fields, _csv_layout(fields, path, lineno)
            continue
        if len(fields) != len(header):
            raise InputError(f"{len(fields)} fields, header has {len(header)}", file=path,
                             line=lineno, key=header[min(len(fields), len(header)) - 1])
        row = _csv_row(fields, layout, path, lineno, mounts, points)
        if row is not None:
            _add_row(rows, order, row, path, lineno)
    if header is None:
        raise InputError("no header line (expected "
                         "mount,direction,quantity,rpm,velocity_rms_mm_per_s)", file=path)
    if not rows:
        raise InputError("no data rows", file=path)
    return _measured_runup(rows, order, layout, path, comments)


@dataclass(frozen=True)
class _Layout:
    """Header of a measured CSV: column index by name and the level column read."""

    col: dict
    level_col: str

    @property
    def scale(self) -> float:
        """Factor from the level column to SI RMS."""
        factor, statistic = LEVEL_COLUMNS[self.level_col]
        return factor / (math.sqrt(2.0) if statistic == "peak" else 1.0)


def _csv_layout(header, path, lineno) -> _Layout:
    known = set(KEY_COLUMNS) | set(LEVEL_COLUMNS) | set(OPTIONAL_COLUMNS)
    for name in header:
        if name not in known:
            raise InputError(
                f"unknown column {name!r} (expected {', '.join(KEY_COLUMNS)} and one "
                f"level column: {', '.join(LEVEL_COLUMNS)})", file=path, line=lineno, key=name or "(empty)")
        if header.count(name) > 1:
            raise InputError(f"column {name!r} appears twice", file=path, line=lineno, key=name)
    for name in KEY_COLUMNS:
        if name not in header:
            raise InputError(f"header lacks column {name!r}", file=path, line=lineno, key=name)
    levels = [n for n in header if n in LEVEL_COLUMNS]
    velocity_levels = [n for n in levels if n.startswith("velocity_")]
    if len(levels) > 1 and len(velocity_levels) == 1:
        # both-sides run-up CSV: velocity is the level, the rest are extra values
        levels = velocity_levels
    if len(levels) != 1:
        raise InputError(
            f"header needs exactly one level column with its unit ({', '.join(LEVEL_COLUMNS)}); found "
            f"{', '.join(levels) if levels else 'none'}", file=path, line=lineno, key="header")
    return _Layout({n: i for i, n in enumerate(header)}, levels[0])


def _csv_row(fields, layout, path, lineno, mounts, points):
    """``(node, direction, quantity, rpm, level, phase)`` of a data row (level in the column's
    unit, phase [deg] or NaN); None for an ``overall`` row."""
    col, level_col = layout.col, layout.level_col
    side = fields[col["side"]].lower() if "side" in col else "active"
    if side not in SIDES:
        raise InputError(f"unknown side {fields[col['side']]!r} (expected active or "
                         "passive)", file=path, line=lineno, key="side")
    for extra in ("acceleration_rms_m_per_s2", "force_rms_n"):
        if extra in col and extra != level_col and fields[col[extra]]:
            parse_number(fields[col[extra]], path, lineno, extra, nonneg=True)
    node = _csv_node(fields[col["mount"]], side, path, lineno, mounts, points)
    direction = fields[col["direction"]].lower()
    if direction not in DIRECTIONS:
        raise InputError(f"unknown direction {fields[col['direction']]!r} "
                         "(expected x, y or z)", file=path, line=lineno, key="direction")
    if fields[col["quantity"]].strip() == "overall":
        return None                       # track --overall: the raw signal's, not modelled
    try:
        quantity = normalise_quantity(fields[col["quantity"]])
    except ValueError as exc:
        raise InputError(str(exc), file=path, line=lineno, key="quantity") from None
    rpm = parse_number(fields[col["rpm"]], path, lineno, "rpm")
    if not 0 < rpm <= MAX_RPM:
        raise InputError(f"speed must be > 0 and <= {MAX_RPM:g} rpm, got {rpm:g}",
                         file=path, line=lineno, key="rpm")
    level = parse_number(fields[col[level_col]], path, lineno, level_col)
    if level < 0:
        raise InputError(f"negative level {level:g}", file=path, line=lineno, key=level_col)
    _check_level(level * layout.scale, path, lineno, level_col)
    return node, direction, quantity, rpm, level, _row_phase(fields, col, quantity, path, lineno)


def _row_phase(fields, col, quantity, path, lineno) -> float:
    """The ``phase_deg`` cell of a row [deg], wrapped; NaN where absent or empty."""
    text = fields[col["phase_deg"]] if "phase_deg" in col else ""
    if not text:
        return math.nan
    if quantity == "synthesis":
        raise InputError("a synthesis row has no phase (a sum of orders): leave it empty",
                         file=path, line=lineno, key="phase_deg")
    return float(wrap_deg(parse_number(text, path, lineno, "phase_deg")))


def _csv_node(mount, side, path, lineno, mounts, points) -> str:
    """Node of a row: ``left``, ``left/passive`` (body side of a mount) or a body point."""
    if side == "passive" and mount and (mounts is None or mount in mounts):
        return passive_name(mount)                    # body side of that mount
    if side == "passive" and mount and (points is None or mount in points):
        return mount                                  # a body point of interest
    if not mount or (mounts is not None and mount not in mounts):
        known_txt = f" (known: {', '.join(mounts)})" if mounts is not None else ""
        raise InputError(f"unknown mount {mount!r}{known_txt}", file=path, line=lineno, key="mount")
    return mount


def _add_row(rows, order, row, path, lineno) -> None:
    node, direction, quantity, rpm, level, phase = row
    key = (node, direction, quantity)
    if key not in rows:
        rows[key] = {}
        order.append(key)
    if rpm in rows[key]:
        raise InputError(f"duplicate row: {node},{direction},{quantity} at {rpm:g} rpm "
                         f"already on line {rows[key][rpm][1]}", file=path, line=lineno, key="rpm")
    rows[key][rpm] = (level, lineno, phase)


def _measured_runup(rows, order, layout, path, comments) -> MeasuredRunup:
    """The curves of the rows in SI, converted to velocity (or kept as forces)."""
    curves, phases = {}, {}
    for key in order:
        speeds = np.array(sorted(rows[key]))
        curves[key] = (speeds, np.array([rows[key][r][0] for r in speeds]) * layout.scale)
        phase = np.array([rows[key][r][2] for r in speeds])
        if np.any(np.isfinite(phase)):
            phases[key] = phase
    notes, signal, level_col = [], "velocity", layout.level_col
    kind = level_col.split("_", 1)[0]
    if kind in ("acceleration", "displacement"):
        curves = to_velocity(curves, kind, notes)
        turn = -90.0 if kind == "acceleration" else 90.0      # v = a/(i w), v = i w x
        phases = {key: wrap_deg(p + turn) for key, p in phases.items()}
    elif kind == "force":
        signal = "mount_force"
        notes.append("force curves: compared with the simulated mount forces [N]")
    if LEVEL_COLUMNS[level_col][1] == "peak":
        notes.append(f"levels read from peak column {level_col!r} and converted to RMS by "
                     "1/sqrt(2) (exact for a sinusoidal order; synthesis read as the "
                     "root-sum-square of the order peaks)")
    return MeasuredRunup(curves, source=path, notes=notes, comments=comments, signal=signal, phases=phases)


def to_velocity(curves, kind, notes):
    r"""Convert acceleration or displacement order curves to velocity, order by order.

    :math:`v_o = a_o/\omega_o` or :math:`v_o = \omega_o x_o`, :math:`\omega_o = 2\pi o n/60`;
    a channel's synthesis becomes the RMS sum of its converted orders where all are present.
    """
    out, dropped = {}, []
    channels = {(m, d) for m, d, _ in curves}
    for m, d in sorted(channels):
        orders = {q: v for (mm, dd, q), v in curves.items() if (mm, dd) == (m, d) and q != "synthesis"}
        for q, (rpm, level) in orders.items():
            w = 2 * math.pi * float(q.split("_", 1)[1]) * rpm / 60.0
            out[(m, d, q)] = (rpm, level / w if kind == "acceleration" else level * w)
        if (m, d, "synthesis") in curves:
            common = None
            for rpm, _ in orders.values():
                common = set(rpm.tolist()) if common is None else common & set(rpm.tolist())
            if not common:
                dropped.append(Channel.of_node(m, d).label)
                continue
            speeds = np.array(sorted(common))
            total = np.zeros(speeds.size)
            for q in orders:
                rpm, level = out[(m, d, q)]
                total += np.interp(speeds, rpm, level) ** 2
            out[(m, d, "synthesis")] = (speeds, np.sqrt(total))
    how = "divided by omega_o" if kind == "acceleration" else "times omega_o"
    notes.append(f"{kind} order curves converted to velocity order by order ({how})")
    notes.append("synthesis recomputed as the RMS sum of the converted orders")
    if dropped:
        notes.append("synthesis dropped (no order curves to convert): " + ", ".join(dropped))
    return out
