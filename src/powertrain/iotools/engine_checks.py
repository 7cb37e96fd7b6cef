"""Physical plausibility of an engine read from a file, so that an absurd file fails at the
input, not in a solver: the mounts carry the body (rigid-body modes :data:`MIN_MODE_HZ` to
:data:`MAX_MODE_HZ`) and the excitation is finite and below :data:`MAX_FORCE_N`.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.errors import InputError

#: Lowest acceptable rigid-body mode [Hz]: 1 Hz is a static sag of g / (2 pi)^2 = 0.25 m.
MIN_MODE_HZ = 1.0
#: Highest acceptable rigid-body mode [Hz]: engine mounts put them at 5-30 Hz; 10 kHz means
#: the stiffness is off by orders of magnitude (a unit error).
MAX_MODE_HZ = 1e4
#: Largest acceptable excitation force [N] (a 2 L engine at full load: ~1e4 N).
MAX_FORCE_N = 1e9
#: Crank-angle samples of the excitation check per cycle.
CHECK_SAMPLES = 720
_G = 9.80665


def check_engine(engine, path) -> None:
    """Raise :class:`InputError` if ``engine`` (read from ``path``) is physically absurd."""
    check_support(engine, path)
    if getattr(engine, "crank", None) is not None and getattr(engine, "combustion", None) is not None:
        check_excitation(engine, path)


def check_support(engine, path) -> None:
    """The mounts carry the body: a static stiffness in all six directions and finite
    rigid-body modes of at least :data:`MIN_MODE_HZ` (mounts on rigid ground)."""
    system = engine.assemble(rigid_ground=True)
    _check_static_stiffness(system, engine.mounts, path)
    try:
        with np.errstate(all="ignore"):
            modes, _ = system.rigid_body_modes()
    except (np.linalg.LinAlgError, ValueError, ArithmeticError):
        modes = np.array([np.nan])
    if not np.all(np.isfinite(modes)) or not np.all(np.isfinite(system.K)):
        raise InputError("the mounts do not hold the body: its static stiffness matrix is "
                         "singular or not finite (mounts all at one point, or all zero?)",
                         file=path, key="mounts")
    low, high = float(np.min(modes)), float(np.max(modes))
    if high > MAX_MODE_HZ:
        raise InputError(f"the mounts are implausibly stiff: a rigid-body mode at {high:.3g} Hz "
                         f"(more than {MAX_MODE_HZ:g} Hz; unit error?); stiffest: "
                         f"{extreme_mount(engine.mounts, max)}", file=path, key="mounts")
    if low < 1e-3:
        raise InputError("the mounts cannot carry the body: a rigid-body mode at 0 Hz (no "
                         f"static stiffness in some direction); softest: "
                         f"{extreme_mount(engine.mounts, min)}", file=path, key="mounts")
    if low < MIN_MODE_HZ:
        sag = _G / (2 * math.pi * max(low, 1e-9)) ** 2
        raise InputError(f"the mounts cannot carry the body: lowest rigid-body mode "
                         f"{low:.3g} Hz, a static sag of about {sag:.3g} m under its weight "
                         f"(need >= {MIN_MODE_HZ:g} Hz); softest: "
                         f"{extreme_mount(engine.mounts, min)}", file=path, key="mounts")


def _check_static_stiffness(system, mounts, path) -> None:
    """The 6×6 static stiffness of the body on its mounts is positive definite."""
    try:
        kr = np.linalg.eigvalsh(system.static_stiffness_6())
    except np.linalg.LinAlgError:
        kr = np.zeros(1)
    except ArithmeticError:                  # a mount network singular at 0 Hz
        raise InputError("a mount network is singular at 0 Hz (a stiffness or damping out "
                         "of range?)", file=path, key="mounts") from None
    if kr.min() <= 1e-9 * max(kr.max(), 1e-300):
        raise InputError("the mounts' static stiffness does not hold the body in every "
                         "direction (a rigid-body mode at 0 Hz); softest: "
                         f"{extreme_mount(mounts)}", file=path, key="mounts")


def extreme_mount(mounts, pick=min) -> str:
    """``mount.direction (file, static stiffness)`` of the softest (``pick=min``) or stiffest
    (``pick=max``) mount direction."""
    entries = []
    for m in mounts:
        for d, mdl in m.directions.items():
            try:
                k = float(mdl.static_stiffness())
            except (ValueError, ArithmeticError, np.linalg.LinAlgError):
                k = math.nan
            entries.append((k if math.isfinite(k) else -1.0, m.name, d, m.files.get(d, "")))
    if not entries:
        return "no mount"
    k, name, d, file = pick(entries)
    where = f", {file}" if file else ""
    return f"{name}.{d} ({k / 1e3:.3g} N/mm static{where})"


def check_excitation(engine, path) -> None:
    """Finite excitation below :data:`MAX_FORCE_N` at the lowest and highest speed."""
    theta = np.arange(CHECK_SAMPLES) * (4 * math.pi / CHECK_SAMPLES)
    key = "crank_train"
    try:
        lo, hi = engine.speed_range_rpm()
        for rpm in (lo, hi):
            with np.errstate(all="ignore"):
                load = np.asarray(engine.generalized_load(rpm, theta), float)
            if not np.all(np.isfinite(load)):
                raise InputError(f"the excitation at {rpm:g} rpm is not finite (NaN or "
                                 "infinite gas or inertia forces)", file=path, key=key)
            peak = float(np.max(np.abs(load[:, :3])))
            if peak > MAX_FORCE_N:
                raise InputError(f"excitation force {peak:.3g} N at {rpm:g} rpm, more than "
                                 f"the plausible {MAX_FORCE_N:g} N", file=path, key=key)
    except InputError:
        raise
    except (ArithmeticError, ValueError) as exc:
        raise InputError(f"no excitation can be computed from these values "
                         f"({type(exc).__name__}: {str(exc)[:120]})", file=path,
                         key="crank_train/combustion") from None
