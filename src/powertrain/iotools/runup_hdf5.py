"""Reader of the run-up HDF5 layout (:mod:`powertrain.results.runup` documents it and
writes it): a result file back into a :class:`~powertrain.results.runup.RunupResult`."""

from __future__ import annotations

import json

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.textfile import check_regular_file
from powertrain.results.runup import OPERATING_POINT, RunupResult
from powertrain.results.static import StaticResult
from powertrain.solvers.operating_point import OperatingPoint


def read_runup_hdf5(path) -> RunupResult:
    """Read a run-up HDF5 file (layout: :mod:`powertrain.results.runup`), every dataset's type
    and shape checked."""
    import h5py  # deferred: heavy package, loaded only when this format is used
    check_regular_file(path)
    try:
        h5 = h5py.File(path, "r")
    except (OSError, FileNotFoundError) as exc:
        raise InputError(f"cannot open HDF5 file ({exc})", file=path) from None
    try:
        with h5:
            return _read_open(h5, path)
    except InputError:
        raise
    except (OSError, RuntimeError, KeyError, ValueError, TypeError) as exc:
        raise InputError(f"damaged or not in the run-up layout ({type(exc).__name__}: "
                         f"{str(exc)[:120]})", file=path) from None


def _read_open(h5, path) -> RunupResult:
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
    return RunupResult(
        rpm=rpm, orders=orders, channels=list(zip(mounts, directions)), **amp,
        mean_mount_force=_h5_array(h5, "mount_force/mean", path, "f", 2, n[:2]),
        periodicity=_h5_array(h5, "diagnostics/periodicity", path, "f", 1, n[:1]),
        settings=_h5_json(h5, "settings", path),
        solver_seconds=float(_h5_array(h5, "diagnostics/solver_seconds", path, "f", 0)),
        rigid_body_modes_hz=_h5_array(h5, "diagnostics/rigid_body_modes_hz", path, "f", 1),
        meta=_h5_json(h5, "meta", path), path_contribution=_h5_paths(h5, path, n),
        operating_point=_h5_operating_point(h5, path, rpm))


def _h5_operating_point(h5, path, rpm):
    """/operating_point as a :class:`~powertrain.results.static.StaticResult`, or None."""
    if "operating_point" not in h5:
        return None
    mounts = _h5_names(h5, "operating_point/mounts", path)
    n, m = rpm.size, len(mounts)
    shapes = {"mean_torque": (n,), "body": (n, 6), "deflection": (n, m, 3),
              "force": (n, m, 3), "tangent_stiffness": (n, m, 3), "static_factor": (n, 3 * m),
              "iterations": (n,), "residual": (n, 2)}
    d = {k: _h5_array(h5, f"operating_point/{k}", path, "f", len(shapes[k]), shapes[k])
         for k in OPERATING_POINT}
    ratio = float(h5["operating_point"].attrs.get("gear_ratio", 1.0))
    points = [OperatingPoint(float(rpm[i]), float(d["mean_torque"][i]), ratio, d["body"][i],
                             d["deflection"][i], d["force"][i], d["tangent_stiffness"][i],
                             d["static_factor"][i], int(d["iterations"][i]),
                             tuple(d["residual"][i])) for i in range(n)]
    return StaticResult(points, mounts)


def _h5_array(h5, key, path, kinds, ndim, shape=None):
    """Dataset ``key`` as an array of dtype kind in ``kinds`` ("f": real, "c": complex),
    ``ndim`` dimensions and, if given, ``shape``."""
    import h5py  # deferred: heavy package, loaded only when this format is used
    obj = h5.get(key)
    if not isinstance(obj, h5py.Dataset):
        raise InputError("missing dataset", file=path, key=key)
    kind = obj.dtype.kind
    if not (kind in kinds or (kind in "iu" and "f" in kinds)):
        raise InputError(f"expected numbers, got dtype {obj.dtype}", file=path, key=key)
    if obj.ndim != ndim or (shape is not None and obj.shape != tuple(shape)):
        want = shape if shape is not None else f"{ndim} dimensions"
        raise InputError(f"shape {obj.shape}, expected {want}", file=path, key=key)
    return np.asarray(obj[()], dtype=complex if kind == "c" else float)


def _h5_paths(h5, path, n):
    """/path_contribution/velocity (n_rpm, 3 n_points, 3 n_mounts, n_orders) or None."""
    if "path_contribution" not in h5:
        return None
    key = "path_contribution/velocity"
    data = _h5_array(h5, key, path, "c", 4)
    if data.shape[0] != n[0] or data.shape[3] != n[2] or data.shape[1] % 3 or data.shape[2] % 3:
        raise InputError(f"shape {data.shape} does not fit the speeds and orders", file=path, key=key)
    return data


def _h5_names(h5, key, path) -> list[str]:
    """1-D dataset of strings (bytes or str)."""
    import h5py  # deferred: heavy package, loaded only when this format is used
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
