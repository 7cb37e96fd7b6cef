"""What drives the powertrain at one engine speed (``powertrain excitation``)."""

from __future__ import annotations

import math

from powertrain.errors import InputError
from powertrain.iotools.engine_file import engine_or_default
from powertrain.results.excitation import ExcitationResult
from powertrain.workflows.arguments import flag, real

#: Fewest crank-angle steps of one engine cycle (720 deg).
MIN_STEPS = 32


def excitation(engine=None, rpm=None, *, load=1.0, balancers=True, angle_step_deg=0.5) -> ExcitationResult:
    """Cylinder pressures, gas and inertia forces, crank torque and load over one cycle.

    Parameters
    ----------
    engine : Engine, str or Path, optional
        The engine, or its file (default: the shipped ``engines/default.toml``).
    rpm : float or str
        Engine speed [rpm] (a number, or as ``--rpm`` writes it).
    load : float
        Fraction of the full-load torque [-] (single-zone model).
    balancers : bool
        False switches the balancer shafts off.
    angle_step_deg : float
        Crank-angle step [deg]; must divide 720 into at least 32 steps.

    Returns
    -------
    ExcitationResult
        ``to_text()`` is what ``powertrain excitation`` prints.
    """
    rpm = real(rpm, "--rpm", unit="rpm", optional=True)
    load = real(load, "--load")
    angle_step_deg = real(angle_step_deg, "--step", unit="deg")
    balancers = flag(balancers, "--no-balancers")
    if rpm is None or not math.isfinite(rpm) or rpm <= 0:
        raise InputError(f"must be a positive speed, got {rpm}", key="--rpm")
    if not math.isfinite(load) or load <= 0:
        raise InputError(f"must be positive, got {load}", key="--load")
    n = 720.0 / angle_step_deg if angle_step_deg > 0 else float("nan")
    if not math.isfinite(n) or abs(n - round(n)) > 1e-9 or round(n) < MIN_STEPS:
        raise InputError(f"must divide 720 deg into at least {MIN_STEPS} steps, got "
                         f"{angle_step_deg}", key="--step")
    engine = engine_or_default(engine)
    if not balancers:
        engine = engine.with_balancers(enabled=False)
    try:
        exc = engine.excitation(rpm, n_points=int(round(n)), load=load)
    except ValueError as err:
        if isinstance(err, InputError):
            raise
        raise InputError(str(err), file=engine.file, key="combustion") from None
    return ExcitationResult(excitation=exc, engine=engine)
