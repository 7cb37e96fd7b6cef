"""Dynamic stiffness K*(f) of a mount model, file or engine mount direction (:func:`stiffness`)."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np

from powertrain.errors import InputError, require_finite, solved
from powertrain.iotools.engine_file import engine_or_default, read_engine
from powertrain.iotools.mount_file import read_mount
from powertrain.iotools.tomlfile import read_toml
from powertrain.models.mount import MountModel
from powertrain.physics.mount_elements import MountElement
from powertrain.results.stiffness import AmplitudeStiffnessResult, StiffnessResult
from powertrain.solvers.mount_time_domain import time_cross_point_stiffness, time_forced_response
from powertrain.units import to_si
from powertrain.workflows.arguments import choice, frequencies, real

#: Solution methods of :func:`stiffness` (``--method``).
METHODS = ("frequency", "time")
#: Frequencies of :func:`stiffness` by default (``powertrain stiffness --freq 1:400:1``) [Hz].
DEFAULT_FREQUENCIES_HZ = np.arange(1.0, 401.0)


def stiffness(mount, *, engine=None, freq=None, method="frequency", force=None,
              engine_mass=None, steps_per_period=None, amplitude=None):
    """Cross-point dynamic stiffness K*(f) of a mount model (``powertrain stiffness``).

    Parameters
    ----------
    mount : MountModel, str or path
        The model, a mount file, or with ``engine`` a direction ``"MOUNT.DIR"``.
    engine : Engine, str or path, optional
        Engine (file) whose mount ``mount`` names.
    freq : array_like or str, optional
        Strictly increasing frequencies [Hz], or as ``--freq`` writes them (default
        :data:`DEFAULT_FREQUENCIES_HZ`).
    method : {"frequency", "time"}
        Condensed network (eq. 39) or Newmark integration processed by FFT.
    force, engine_mass : float, optional
        Together: the thesis's verification set-up, a harmonic force [N] on an engine mass
        [kg] (adds x1 and F_T).
    steps_per_period : int, optional
        Newmark steps per excitation period for the time method.
    amplitude : array_like or str, optional
        Test amplitudes X [m], or as ``--amplitude`` writes them (mount file's unit, mm by
        default): K*(f, X) with the amplitude law and friction (:func:`amplitude_stiffness`).

    Returns
    -------
    StiffnessResult, or AmplitudeStiffnessResult with ``amplitude``
    """
    choice(method, METHODS, "--method")
    engine_mass = real(engine_mass, "--engine-mass", unit="kg", optional=True)
    force = real(force, "--force", unit="N", optional=True)
    _check_set_up(engine_mass, force)
    f = DEFAULT_FREQUENCIES_HZ if freq is None else frequencies(freq)
    if method == "time" and f[0] <= 0:
        raise InputError("the time method needs frequencies > 0 Hz", key="--freq")
    model, label = mount_model(mount, engine)
    if amplitude is not None and engine_mass is not None:
        raise InputError("--amplitude is the displacement test, without --engine-mass", key="--amplitude")
    amps = _amplitude_argument(amplitude, mount if engine is None else None)

    def compute():
        if amps is None:
            return stiffness_table(model, f, method, engine_mass, force, steps_per_period)
        return amplitude_stiffness(model, f, amps, method, steps_per_period)
    source, key = _source(mount, engine)
    result = solved(compute, source, key)
    require_finite(result.columns(), source, key)
    return replace(result, label=model.name or label)


def _amplitude_argument(amplitude, mount_file):
    """``amplitude`` of :func:`stiffness` in [m]."""
    if amplitude is None:
        return None
    if isinstance(amplitude, str):
        return parse_amplitudes(amplitude, mount_file)
    return _amplitudes(amplitude)


def _source(mount, engine):
    """The file and key an error of the computation names."""
    if engine is None:
        return (str(mount) if isinstance(mount, (str, os.PathLike)) else None), "parameters"
    where = engine if isinstance(engine, (str, os.PathLike)) else getattr(engine, "file", None)
    return (None if where is None else str(where)), f"--mount {mount}"


def _check_set_up(engine_mass, force) -> None:
    if (engine_mass is None) != (force is None):
        raise InputError("--engine-mass and --force go together", key="--engine-mass")
    if engine_mass is not None and not 0 < engine_mass < float("inf"):
        raise InputError(f"must be positive and finite, got {engine_mass}", key="--engine-mass")
    if force is not None and not abs(force) < float("inf"):
        raise InputError(f"must be a finite force [N], got {force}", key="--force")


def mount_model(mount, engine=None):
    """``(model, label)`` of :func:`stiffness`'s ``mount`` and ``engine``."""
    if engine is None:
        if isinstance(mount, (str, os.PathLike)):
            return read_mount(mount), str(mount)
        if isinstance(mount, MountModel):
            return mount, "model"
        if mount is None:
            raise InputError("give either MOUNT_FILE or --engine with --mount", key="MOUNT_FILE")
        raise InputError(f"expected a MountModel or a mount file, got {type(mount).__name__}",
                         key="MOUNT_FILE")
    if isinstance(engine, (str, os.PathLike)):
        engine, where = read_engine(engine), str(engine)
    else:
        engine = engine_or_default(engine)
        where = str(getattr(engine, "file", None) or engine.name)
    parts = str(mount or "").split(".")
    names = engine.mount_names
    if len(parts) != 2 or parts[0] not in names or parts[1] not in ("x", "y", "z"):
        raise InputError(f"expected MOUNT.DIR with MOUNT one of {', '.join(names)} and DIR "
                         f"x/y/z, got {mount!r}", key="--mount")
    return engine.mount(parts[0]).directions[parts[1]], f"{parts[0]} {parts[1]} ({where})"


def stiffness_table(model, frequency_hz, method="frequency", engine_mass=None, force=None,
                    steps_per_period=None) -> StiffnessResult:
    """Compute K*(f) (and x1, F_T when ``engine_mass`` and ``force`` are given).

    Parameters
    ----------
    model : MountModel
        The mount model.
    frequency_hz : ndarray
        Frequencies [Hz].
    method : {"frequency", "time"}
        Condensed network (eq. 39) or Newmark integration processed by FFT.
    engine_mass, force : float, optional
        Engine mass [kg] and harmonic force [N] of the verification set-up.
    steps_per_period : int, optional
        Newmark steps per excitation period for the time method.
    """
    f = np.asarray(frequency_hz, float)
    kw = {} if steps_per_period is None else {"steps_per_period": steps_per_period}
    if method == "frequency":
        forced = () if engine_mass is None else model.forced_engine_mass_response(f, engine_mass, force)
        return StiffnessResult(f, model.cross_point_stiffness(f), method, *forced)
    if method == "time":
        if engine_mass is None:
            r = time_cross_point_stiffness(MountElement(model.network()), f, **kw)
            return StiffnessResult(f, r.kcp, method, periodicity=r.periodicity)
        r = time_forced_response(model, f, engine_mass, force, **kw)
        return StiffnessResult(f, r.kcp, method, r.x1, r.ft, periodicity=r.periodicity)
    raise ValueError(f"unknown method {method!r}")


def _amplitudes(amplitude, unit="m") -> np.ndarray:
    """The amplitudes as an array: positive, finite and distinct."""
    try:
        a = np.atleast_1d(np.asarray(amplitude, float)).ravel()
    except (TypeError, ValueError):
        raise InputError(f"cannot read amplitudes {str(amplitude)[:60]!r} [{unit}] (use "
                         "numbers, e.g. 0.05,0.1,0.5)", key="--amplitude") from None
    if a.size == 0 or not np.all(np.isfinite(a)) or np.any(a <= 0):
        raise InputError(f"amplitudes [{unit}] must be positive and finite, got "
                         f"{a.tolist()}", key="--amplitude")
    if np.unique(a).size != a.size:
        raise InputError(f"duplicate amplitudes [{unit}] in {a.tolist()}", key="--amplitude")
    return a


def amplitude_stiffness(model, frequency_hz, amplitude_m, method="frequency",
                        steps_per_period=None) -> AmplitudeStiffnessResult:
    """K*(f, X) of the sinusoidal displacement test (Kovarik 2016, Fig. 13: engine side
    driven with x = X sin 2πft, base force measured) at each amplitude X.

    Parameters
    ----------
    model : MountModel or MountElement
        With its amplitude law and friction.
    frequency_hz : ndarray
        Frequencies [Hz] (> 0 for the time method).
    amplitude_m : array_like
        Test amplitudes X [m].
    method : {"frequency", "time"}
        Equivalent-linear two-port, or integration with the friction law, first harmonic
        (:func:`powertrain.solvers.mount_time_domain.time_cross_point_stiffness`).
    steps_per_period : int, optional
        Newmark steps per period of the time method.
    """
    element = model.element() if hasattr(model, "element") else model
    f = np.asarray(frequency_hz, float)
    curves = []
    for a in np.asarray(amplitude_m, float):
        if method == "frequency":
            curves.append(StiffnessResult(f, element.cross_point_stiffness(f, a), method))
        elif method == "time":
            kw = {} if steps_per_period is None else {"steps_per_period": steps_per_period}
            r = time_cross_point_stiffness(element, f, a, **kw)
            curves.append(StiffnessResult(f, r.kcp, method, periodicity=r.periodicity))
        else:
            raise ValueError(f"unknown method {method!r}")
    return AmplitudeStiffnessResult(np.asarray(amplitude_m, float), curves, method)


def parse_amplitudes(text: str, mount_file=None) -> np.ndarray:
    """``--amplitude``'s comma list in the mount file's ``[units] x`` (default mm), in [m]."""
    unit = _length_unit(mount_file) if isinstance(mount_file, (str, os.PathLike)) else "mm"
    try:
        values = [float(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise InputError(f"cannot read {text!r} (use a comma list, e.g. 0.05,0.1,0.5)",
                         key="--amplitude") from None
    where = {"file": str(mount_file), "key": "units.x"} if isinstance(mount_file, (str, os.PathLike)) else {}
    return to_si(_amplitudes(values, unit), unit, "length", **where)


def _length_unit(mount_file) -> str:
    units = read_toml(str(mount_file)).get("units", {})
    return str(units.get("x", "mm")) if isinstance(units, dict) else "mm"
