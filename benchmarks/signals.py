r"""Synthetic run-up time data with known order content (test oracles; labelled SYNTHETIC).

A linear sweep :math:`n(t) = n_0 + (n_1 - n_0)\,t/T` has the crank angle
:math:`\theta(t) = \tfrac{2\pi}{60}\left(n_0 t + \tfrac{n_1 - n_0}{2T}t^2\right)` in closed
form, so a sum of orders :math:`\sum_o A_o\cos(o\theta + \varphi_o)` is exact at every
sample; its derivative :math:`-\sum_o A_o\,o\,\omega(t)\sin(o\theta + \varphi_o)` is the
matching acceleration. None of this passes through the tracker's speed estimate.

Phases follow :mod:`powertrain.analysis.phase`: :math:`\theta` here is the crank angle from
cylinder-1 firing TDC, so :math:`\varphi_o` is the phase the tracker should report. The tacho's
reference pulse sits ``tdc_offset_deg`` before that TDC (TDC lies that far after it), and a
once-per-cycle pulse (:func:`cycle_pulse`) marks the 720° cycle.
"""

from __future__ import annotations

import numpy as np

from powertrain.models.recording import RawChannel, RawRecording


def linear_sweep(fs, duration, rpm0, rpm1, *, endpoint=False):
    """Time [s], speed [rpm] and crank angle [rad] of a linear sweep."""
    n = int(round(fs * duration)) + (1 if endpoint else 0)
    t = np.arange(n) / fs
    rpm = rpm0 + (rpm1 - rpm0) * t / duration
    theta = (2 * np.pi / 60.0) * (rpm0 * t + 0.5 * (rpm1 - rpm0) / duration * t * t)
    return t, rpm, theta


def order_sum(theta, orders, amplitudes, phases=None):
    """:math:`\\sum_o A_o \\cos(o\\theta + \\varphi_o)`."""
    phases = np.zeros(len(orders)) if phases is None else phases
    return sum(a * np.cos(o * theta + p) for o, a, p in zip(orders, amplitudes, phases))


def order_sum_derivative(theta, rpm, orders, amplitudes, phases=None):
    """Time derivative of :func:`order_sum` along the sweep."""
    phases = np.zeros(len(orders)) if phases is None else phases
    omega = rpm * (2 * np.pi / 60.0)
    return sum(-a * o * omega * np.sin(o * theta + p)
               for o, a, p in zip(orders, amplitudes, phases))


def tacho(theta, pulses_per_rev, *, high=5.0, duty=0.5, rise_deg=0.0, missing_teeth=0):
    """Tacho pulse train, ``pulses_per_rev`` pulses per revolution [V], rising at ``theta``
    = 0, 2π/N, ...: rectangular, or with ``rise_deg`` > 0 a linear rise over that crank
    angle that passes the tracker's trigger level (:data:`~powertrain.analysis.speed.
    TRIGGER_HIGH` of the swing) exactly there, as a sensor with a finite slope would (a
    rectangular edge is only known to within a sample interval). ``missing_teeth``: the
    last pulses of each revolution left out (a 60-2 wheel), so the pulse at 0 follows the
    gap."""
    from powertrain.analysis.speed import TRIGGER_HIGH
    rise = max(rise_deg, 0.0) * pulses_per_rev / 360.0              # fraction of a pulse
    x = theta * pulses_per_rev / (2 * np.pi) + TRIGGER_HIGH * rise  # the rise starts at 0
    tooth, x = np.mod(np.floor(x), pulses_per_rev), np.mod(x, 1.0)
    if rise > 0:
        level = np.clip(np.minimum(x / rise, (duty + rise - x) / rise), 0.0, 1.0)
    else:
        level = (x < duty).astype(float)
    return high * np.where(tooth < pulses_per_rev - missing_teeth, level, 0.0)


def cycle_pulse(theta, at_deg, *, width_deg=30.0, high=5.0):
    """Once-per-cycle pulse [V] (cam or injection signal): rising edge at cycle angle
    ``at_deg`` (crank angle from cylinder-1 firing TDC, modulo 720°)."""
    cycle = np.mod(np.degrees(theta) - at_deg, 720.0)
    return np.where(cycle < width_deg, high, 0.0)


#: Published order-tracking example of a commercial signal-processing toolbox: 600 Hz,
#: 5 s, 600 -> 2400 rpm, orders 1, 1/2, sqrt(2), 2 with amplitudes 1, 1/2, sqrt(2), 2.
TOOLBOX_ORDERS = np.array([1.0, 0.5, np.sqrt(2.0), 2.0])
TOOLBOX_AMPLITUDES = np.array([1.0, 0.5, np.sqrt(2.0), 2.0])


def toolbox_example() -> RawRecording:
    """The toolbox example as a one-channel recording (acceleration, m/s^2) with rpm."""
    t, rpm, theta = linear_sweep(600.0, 5.0, 600.0, 2400.0, endpoint=True)
    x = order_sum(theta, TOOLBOX_ORDERS, TOOLBOX_AMPLITUDES)
    return RawRecording(t, [RawChannel("left.z", "left", "active", "z", "acceleration", x,
                                       "m/s^2")], rpm, None, "toolbox example",
                        ["SYNTHETIC: order-tracking example of a signal-processing toolbox "
                         "(600 Hz, 5 s, 600->2400 rpm, orders 1, 1/2, sqrt2, 2)"])


#: Analytic sweep: orders 0.5..8 step 0.5, amplitudes and phases.
ANALYTIC_ORDERS = np.arange(1, 17) * 0.5
ANALYTIC_VELOCITY = 1e-3 * (1.0 + 0.25 * np.arange(16))          # [m/s] peak
ANALYTIC_PHASES = 0.4 * np.arange(16)


def analytic_sweep(fs=8192.0, duration=20.0, rpm0=1000.0, rpm1=6000.0,
                   pulses_per_rev=4, *, tdc_offset_deg=0.0, cycle_at_deg=None,
                   tacho_rise_deg=0.0, missing_teeth=0) -> RawRecording:
    """Velocity channel ``right.z`` [mm/s] with known orders (phases
    :data:`ANALYTIC_PHASES` re cylinder-1 firing TDC), the matching acceleration ``left.z``
    [g], the rpm and a tacho (:func:`tacho`, ``tacho_rise_deg``, ``missing_teeth``) whose
    reference pulse lies ``tdc_offset_deg`` before TDC; with ``cycle_at_deg`` also a
    once-per-cycle pulse there (:func:`cycle_pulse`)."""
    t, rpm, theta = linear_sweep(fs, duration, rpm0, rpm1)
    v = order_sum(theta, ANALYTIC_ORDERS, ANALYTIC_VELOCITY, ANALYTIC_PHASES)
    a = order_sum_derivative(theta, rpm, ANALYTIC_ORDERS, ANALYTIC_VELOCITY, ANALYTIC_PHASES)
    chans = [RawChannel("left.z", "left", "active", "z", "acceleration", a, "g"),
             RawChannel("right.z", "right", "active", "z", "velocity", v, "mm/s")]
    cycle = None if cycle_at_deg is None else cycle_pulse(theta, cycle_at_deg)
    pulses = tacho(theta + np.radians(tdc_offset_deg), pulses_per_rev, rise_deg=tacho_rise_deg,
                   missing_teeth=missing_teeth)
    return RawRecording(t, chans, rpm, pulses, "analytic sweep",
                        [f"SYNTHETIC: analytic linear sweep {rpm0:g}->{rpm1:g} rpm in "
                         f"{duration:g} s, orders 0.5..8"], cycle)


def crossing(fs=4096.0, duration=10.0, tone_hz=100.0, tone_amplitude=0.5) -> RawRecording:
    """Order 2 (amplitude 1) crossing a fixed-frequency tone during 1000 -> 6000 rpm."""
    t, rpm, theta = linear_sweep(fs, duration, 1000.0, 6000.0)
    x = np.cos(2 * theta) + tone_amplitude * np.cos(2 * np.pi * tone_hz * t)
    return RawRecording(t, [RawChannel("left.z", "left", "active", "z", "acceleration", x,
                                       "m/s^2")], rpm, None, "crossing",
                        [f"SYNTHETIC: order 2 crossing a {tone_hz:g} Hz tone"])


def swept_resonance(fs, duration, rpm0, rpm1, order, fn, zeta):
    """Single-DOF resonance (static gain 1) driven by ``cos(order * crank angle)`` along a
    linear sweep, started in its steady state; exact for the piecewise-linear input on the
    sample grid (scipy ``lsim``). Returns the recording and the envelope of the complex
    response (cos and sin drives) at every sample: the fine-grid reference."""
    from scipy.signal import StateSpace, lsim
    t, rpm, th = linear_sweep(fs, duration, rpm0, rpm1)
    wn = 2 * np.pi * fn
    system = StateSpace([[0, 1], [-wn ** 2, -2 * zeta * wn]], [[0], [wn ** 2]], [[1, 0]], [[0]])
    w0 = 2 * np.pi * order * rpm0 / 60
    h0 = 1 / (1 - (w0 / wn) ** 2 + 2j * zeta * w0 / wn)
    z = [lsim(system, drive(order * th), t, X0=[part(h0), part(1j * w0 * h0)])[1]
         for drive, part in ((np.cos, np.real), (np.sin, np.imag))]
    rec = RawRecording(t, [RawChannel("x", "left", "active", "z", "displacement", z[0], "m")],
                       rpm, source="swept resonance",
                       comments=[f"SYNTHETIC: order {order:g} through a {fn:g} Hz resonance "
                                 f"(damping {zeta:g}), {rpm0:g}->{rpm1:g} rpm in "
                                 f"{duration:g} s"]).validate()
    return rec, np.abs(z[0] + 1j * z[1])
