"""The rigid-body modes of an engine on its mounts (``powertrain modes``), checked finite."""

from __future__ import annotations

import numpy as np

from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.results.modes import Mode, ModesResult
from powertrain.solvers.modes import rigid_body_modes
from powertrain.workflows.arguments import flag


def modes(engine=None, *, static=False) -> ModesResult:
    """The six rigid-body modes of ``engine`` (plus the body modes of a modal chassis).

    Parameters
    ----------
    engine : Engine, str or Path, optional
        The engine, or its file (default: the shipped ``engines/default.toml``).
    static : bool
        Static (0 Hz) mount stiffness, undamped (default: dynamic stiffness at each mode's
        frequency, damped).

    Returns
    -------
    ModesResult
        ``to_text()`` is what ``powertrain modes`` prints.
    """
    static = flag(static, "--static")
    engine = engine_or_default(engine)
    b = engine.body
    try:
        with np.errstate(all="ignore"):
            result = ModesResult.from_solution(
                rigid_body_modes(engine.assemble(), b.inertia, static=static),
                engine=engine.name, cg_m=[float(v) for v in b.cg], mounts=engine.mount_names)
    except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
        raise InputError(f"the modes cannot be computed ({type(exc).__name__}: "
                         f"{str(exc)[:100]}): mount, body or chassis values out of any "
                         "physical range", file=engine.file, key="mounts") from None
    for i, mode in enumerate(result.modes, 1):
        if not _finite(mode):
            key = "chassis.modes" if mode.kind == "chassis" else "mounts"
            raise InputError(f"mode {i} ({mode.kind}) is not finite (NaN or inf): values out "
                             "of any physical range, or a body mode whose shape is zero at "
                             "every mount", file=engine.file, key=key)
    return result


def _finite(mode: Mode) -> bool:
    numbers = [mode.frequency_hz, mode.damping_ratio, mode.damped_frequency_hz,
               mode.body_energy_percent]          # the axis angle may be NaN
    return bool(np.all(np.isfinite(numbers)) and np.all(np.isfinite(mode.shape))
                and np.all(np.isfinite(mode.ked_percent)))
