r"""Continuous run-up simulation: one linear speed ramp, integrated in time.

The speed rises linearly, :math:`n(t) = n_0 + \dot n\,t`, so the crank angle is
:math:`\theta(t) = \tfrac{2\pi}{60}(n_0 t + \tfrac12\dot n t^2)`. The load is read
bilinearly from a table every :data:`LOAD_RPM_STEP` rpm and :data:`LOAD_ANGLE_STEP_DEG`° of
the cycle (:meth:`Engine.load_table`). The run-up's assembled model is integrated by Newmark
average acceleration (modal, :class:`~powertrain.solvers.newmark.ModalNewmark`, for a linear
model) at a multiple of the output rate (at least :data:`STEPS_PER_DEGREE` step per crank
degree at the top speed) from the periodic steady state at the first speed. Mount-point
accelerations are decimated to ``sample_rate`` by a zero-phase polyphase FIR (Kaiser, beta 8)
into a synthetic :class:`~powertrain.models.recording.RawRecording` with the speed, a tacho
and a cycle reference (:func:`crank_pulses`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import firwin

from powertrain.analysis.channel import Channel
from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.analysis.speed import TRIGGER_HIGH
from powertrain.errors import InputError
from powertrain.kernels.speed_ramp import fir_decimate, modal_ramp_kernel, ramp_loads
from powertrain.models.recording import RawChannel, RawRecording
from powertrain.parallel import single_blas_thread
from powertrain.solvers.cycle_newmark import CycleIntegrator, cycle_amplitudes, no_ports, start_state
from powertrain.solvers.newmark import ModalNewmark, ModalPortNewmark
from powertrain.solvers.steppers import Cycles, DenseNewmarkStepper

#: Load table spacing: speed [rpm] and crank angle [deg].
LOAD_RPM_STEP = 25.0
LOAD_ANGLE_STEP_DEG = 0.5
#: Internal steps per crank degree at the top speed (at least).
STEPS_PER_DEGREE = 1.0
#: Output samples per integration chunk.
CHUNK_OUT = 8192
#: Half-length of the decimation FIR in output samples.
FIR_HALF = 10
#: Bounds of a sweep, checked before any work: output samples and internal steps.
MIN_SWEEP_SAMPLES = 1024
MAX_SWEEP_SAMPLES = 2 ** 22
MAX_SWEEP_STEPS = 2 ** 24
#: Highest output sampling rate [Hz].
MAX_SAMPLE_RATE = 2 ** 20
#: Simulated tacho and cycle reference: pulse level [V], rising and falling flank [deg of
#: crank angle], and the cycle reference's edge before cylinder-1 firing TDC [deg].
PULSE_VOLTS = 5.0
PULSE_FLANK_DEG = 30.0
CYCLE_LEAD_DEG = 90.0


def _load_table(engine, rpm_from, rpm_to):
    speeds = np.arange(rpm_from, rpm_to + LOAD_RPM_STEP, LOAD_RPM_STEP)
    speeds = np.clip(speeds, rpm_from, rpm_to)
    n_theta = int(round(720.0 / LOAD_ANGLE_STEP_DEG))
    theta = np.arange(n_theta) * (4 * np.pi / n_theta)
    table = engine.load_table(speeds, theta)                       # (n_rpm, n_theta, 6)
    table = np.concatenate([table, table[:, :1]], axis=1)           # periodic wrap
    return speeds, table, n_theta


def _ramp_rows(load, ramp, lo, rows):
    """Loads (rows, 6) [N] of the ramp ``(rpm_from, rate, h, steps)`` at steps ``lo`` on."""
    speeds, table, _ = load
    rpm_from, rate, h, _ = ramp
    F = np.empty((rows, 6))
    ramp_loads(np.ascontiguousarray(table), float(speeds[0]), LOAD_RPM_STEP, float(rpm_from),
               float(rate), float(h), lo, F)
    return F


def simulate_sweep(engine, rpm_from, rpm_to, rate_rpm_per_s, sample_rate=8192.0, *,
                   system=None, progress=False, static_factors=None) -> RawRecording:
    """Simulate a continuous run-up; mount-point accelerations as raw time data.

    Parameters
    ----------
    engine : Engine
    rpm_from, rpm_to : float
        Start and end speed [rpm], ``rpm_from < rpm_to``.
    rate_rpm_per_s : float
        Sweep rate [rpm/s] > 0.
    sample_rate : float
        Output sampling rate [Hz].
    system : AssembledSystem, optional
        Default ``engine.assemble()``.
    progress : bool
        tqdm bar on stderr (hidden when not a terminal).
    static_factors : callable, optional
        ``static_factors(rpm) -> (n_net,)``, applied per engine cycle.

    Returns
    -------
    RawRecording
        Three engine-side acceleration channels [m/s^2] per mount, the speed [rpm], the
        tacho and the cycle reference [V].
    """
    _check(engine, rpm_from, rpm_to, rate_rpm_per_s, sample_rate)
    m, n_steps = sweep_steps(rpm_from, rpm_to, rate_rpm_per_s, sample_rate)
    h = 1.0 / (m * sample_rate)
    system = engine.assemble() if system is None else system
    if system.chassis is not None:
        system.chassis.require_time_domain()
    load = _load_table(engine, rpm_from, rpm_to)
    n_ch = system.n_mount_channels
    dofs, to_channels = _channel_dofs(system.channel_matrix[:n_ch])
    decimator = _Decimator(m, dofs.size)
    ramp = (rpm_from, rate_rpm_per_s, h, n_steps)
    with single_blas_thread():
        y, method = _integrate_ramp(engine, system, load, ramp, dofs, decimator, progress, static_factors)
        block = to_channels @ y.T                           # (n_ch, n_out), contiguous
    t_out = (decimator.first_output_index + np.arange(y.shape[0])) / sample_rate
    rpm_out = rpm_from + rate_rpm_per_s * t_out
    chans = [RawChannel(Channel(mnt, "active", d).label, mnt, "active", d, "acceleration",
                        block[c], "m/s^2") for c, (mnt, d) in enumerate(system.channels[:n_ch])]
    note = (f"SYNTHETIC: simulated continuous run-up {rpm_from:g}->{rpm_to:g} rpm at "
            f"{rate_rpm_per_s:g} rpm/s ({getattr(engine, 'name', '')}; Newmark average "
            f"acceleration, {method}, {m * sample_rate:g} Hz internal, decimated to "
            f"{sample_rate:g} Hz)")
    tacho, cycle = crank_pulses(t_out, rpm_from, rate_rpm_per_s)
    return RawRecording(t_out, chans, rpm_out, tacho, "simulated sweep", [note], cycle).validate()


def crank_pulses(time, rpm_from, rate_rpm_per_s):
    r"""Tacho and cycle reference [V] at ``time`` [s] of the ramp from ``rpm_from`` [rpm] at
    ``rate_rpm_per_s``: one pulse per revolution rising at cylinder-1 firing TDC
    (:math:`\theta = 0` mod :math:`2\pi`), one per cycle rising :data:`CYCLE_LEAD_DEG` before
    the TDC at :math:`\theta = 0` mod :math:`4\pi` (:func:`~powertrain.analysis.phase.cycle_origin`)."""
    theta = (2 * np.pi / 60.0) * (rpm_from * time + 0.5 * rate_rpm_per_s * time ** 2)
    return (_pulse_train(theta, 2 * np.pi, 0.0), _pulse_train(theta, 4 * np.pi, -np.radians(CYCLE_LEAD_DEG)))


def _pulse_train(theta, period, edge):
    """Pulses [V] at ``theta`` [rad], one per ``period``, crossing the trigger level at ``edge``."""
    flank = np.radians(PULSE_FLANK_DEG)
    phi = np.mod(theta - edge + TRIGGER_HIGH * flank, period)
    rise = phi / flank
    np.clip(rise, 0.0, 1.0, out=rise)
    fall = np.subtract(0.5 * period, phi, out=phi)         # in place: fewer temporaries
    np.divide(fall, flank, out=fall)
    np.clip(fall, 0.0, 1.0, out=fall)
    np.minimum(rise, fall, out=rise)
    rise *= PULSE_VOLTS
    return rise


def _channel_dofs(channel_matrix):
    """The coordinates the channels read and the map (n_ch, n_read) from them to the channels."""
    dofs = np.flatnonzero(np.any(channel_matrix != 0, axis=0))
    return dofs, np.ascontiguousarray(channel_matrix[:, dofs])


def _integrate_ramp(engine, system, load, ramp, dofs, decimator, progress, static_factors):
    """Decimated accelerations of the coordinates ``dofs`` over the ramp and the method's name."""
    if system.port_forces() is None and static_factors is None:
        modal = ModalNewmark(system.M, system.C, system.K, load_dofs=6)
        return _integrate(modal, dofs, load, ramp, _initial_state(engine, modal, ramp[0]),
                          decimator, progress), "modal"
    return _integrate_nonlinear(engine, system, load, ramp, dofs, decimator, static_factors)


def _integrate(modal, dofs, load, ramp, eta, decimator, progress):
    """Decimated accelerations (n_out, n_read) of ``dofs`` over the ramp from the modal state ``eta``."""
    rpm_from, rate_rpm_per_s, h, n_steps = ramp
    speeds, table, _ = load
    read = np.eye(modal.n)[dofs]
    Z = np.zeros_like(read)
    (w_re, w_im), w_load = modal.output_map(Z, Z, read)
    lam = modal.lam_r
    lam_d = (1 + 0.5 * h * lam) / (1 - 0.5 * h * lam)
    gain = (0.5 * h) / (1 - 0.5 * h * lam)
    chunk = CHUNK_OUT * decimator.m         # a multiple of m keeps the decimation aligned
    starts = range(0, n_steps, chunk)
    if progress:
        from tqdm import tqdm  # deferred: heavy optional package
        starts = tqdm(starts, desc="sweep", unit="chunk", leave=False, disable=None)
    x = modal.real_form(eta)
    arrays = ((lam_d.real.copy(), lam_d.imag[:modal.n_complex].copy()),
              modal.real_form((gain[:, None] * modal.load_map_r).T),
              modal.real_form(w_re.T - 1j * w_im.T), np.ascontiguousarray(w_load),
              np.ascontiguousarray(table))
    outputs = []
    for s in starts:
        acc = np.empty((min(s + chunk, n_steps) - s, w_re.shape[1]))
        modal_ramp_kernel(*arrays, float(speeds[0]), LOAD_RPM_STEP, float(rpm_from),
                          float(rate_rpm_per_s), float(h), s, x, acc)
        outputs.append(decimator.push(acc))
    return np.concatenate(outputs)


def _cycle_bounds(rpm_from, rate, h, n_steps):
    """Step indices (n_c + 1,) where the ramp's engine cycles begin, and the last step."""
    t_end = n_steps * h
    cycles = (np.pi / 30.0) * (rpm_from * t_end + 0.5 * rate * t_end ** 2) / (4 * np.pi)
    angle = 4 * np.pi * np.arange(1, int(np.ceil(cycles)))
    t = (np.sqrt(rpm_from ** 2 + 2 * rate * angle * 30.0 / np.pi) - rpm_from) / rate
    inner = np.unique(np.clip(np.ceil(t / h - 1e-9).astype(np.int64), 1, n_steps - 1))
    return np.r_[0, inner, n_steps]


def _integrate_nonlinear(engine, system, load, ramp, dofs, decimator, static_factors):
    """Decimated accelerations of ``dofs`` with nonlinear mount elements and the method's name."""
    rpm_from, rate, h, n_steps = ramp
    x, state, amplitudes, stepper = _nonlinear_start(engine, system, rpm_from, static_factors)
    integrator = CycleIntegrator(stepper.scaling, stepper.ports, h, x[3])
    if not integrator.varying and static_factors is None and integrator.laws.kinds.size:
        return _integrate_ports(integrator, load, ramp, (x, state, amplitudes), dofs,
                                decimator), "modal with the port laws, Newton per step"
    bounds = _cycle_bounds(rpm_from, rate, h, n_steps)
    rows = _Rows(decimator)
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        F = np.zeros((hi + 1 - lo, system.n_dof))
        F[:, :6] = _ramp_rows(load, ramp, lo, hi + 1 - lo)
        factors = stepper.factors_at((rpm_from + rate * 0.5 * (lo + hi) * h) * np.pi / 30.0)
        (X, V, A, _), _ = integrator.run(F, x[:3], amplitudes, state, factors)
        rows.push(A[:-1, dofs])
        amplitudes = cycle_amplitudes(X[:-1] @ stepper.ports.rows.T)
        x = (X[-1], V[-1], A[-1], x[3])
    return rows.done(), "dense, nonlinear mount elements cycle by cycle"


def _integrate_ports(integrator, load, ramp, start, dofs, decimator):
    """Decimated accelerations of ``dofs`` by modal Newmark with the port laws from ``start``."""
    _, _, h, n_steps = ramp
    (x0, v0, *_), state, amplitudes = start
    s, laws = integrator.scaling, integrator.laws
    C, K, _, _ = s.matrices(s.scales(integrator.ports.network_amplitudes(amplitudes)))
    run = ModalPortNewmark(ModalNewmark(s.system.M, C, K, load_dofs=6), laws, h, Wa=np.eye(C.shape[0])[dofs])
    eta = run.modal_state(x0, v0)
    z = laws.forces(laws.rows @ x0, laws.rows @ v0, state)
    chunk = CHUNK_OUT * decimator.m         # a multiple of m keeps the decimation aligned
    outputs = []
    for lo in range(0, n_steps, chunk):
        F = _ramp_rows(load, ramp, lo, min(lo + chunk, n_steps) + 1 - lo)
        outputs.append(decimator.push(run.run(F, eta, z, state)))
    return np.concatenate(outputs)


def _nonlinear_start(engine, system, rpm, static_factors):
    """State, port-law states and amplitudes of the harmonic fixed point at ``rpm``, and its stepper."""
    grid = Cycles(1440, 0.5, 1, 1)
    stepper = DenseNewmarkStepper(system, grid)
    stepper.static_factors = static_factors
    omega = rpm * np.pi / 30.0
    theta = np.arange(grid.n_cycle) * (4 * np.pi / grid.n_cycle)
    fh, omegas = stepper.harmonics(np.asarray(engine.generalized_load(rpm, theta), float), omega, 40.0)
    qh, A = stepper.harmonic_state(fh, omegas, omega, stepper.system_at(stepper.factors_at(omega)))
    x = (qh.real.sum(0), (1j * omegas[:, None] * qh).real.sum(0),
         (-(omegas ** 2)[:, None] * qh).real.sum(0), qh[0].real)
    if stepper.ports is None:                 # linear, static factors only
        stepper.ports, A = no_ports(system), np.zeros(0)
    return x, start_state(stepper.ports, qh, grid.n_cycle), A, stepper


class _Rows:
    """Rows for a :class:`_Decimator` arriving in any lengths, pushed in multiples of m."""

    def __init__(self, decimator):
        self.decimator, self.pending, self.out = decimator, [], []

    def push(self, rows):
        self.pending.append(rows)
        if sum(r.shape[0] for r in self.pending) >= CHUNK_OUT * self.decimator.m:
            self._flush()

    def _flush(self, last=False):
        buf = np.concatenate(self.pending)
        k = buf.shape[0] if last else buf.shape[0] - buf.shape[0] % self.decimator.m
        self.out.append(self.decimator.push(buf[:k]))
        self.pending = [buf[k:]]

    def done(self):
        self._flush(last=True)
        return np.concatenate(self.out)


class _Decimator:
    """Zero-phase decimation by ``m`` (centred Kaiser FIR) of ``n_ch`` signals in chunks of k m."""

    def __init__(self, m, n_ch):
        self.m = m
        self.L = FIR_HALF * m if m > 1 else 0          # m = 1: nothing to decimate
        self.fir = firwin(2 * self.L + 1, 1.0 / m, window=("kaiser", 8.0)) if m > 1 else np.ones(1)
        self.tail = np.zeros((n_ch, 0))          # the last input rows, transposed

    @property
    def first_output_index(self) -> int:
        """Output sample index of the first row returned."""
        return (-(-(2 * self.L) // self.m) * self.m - self.L) // self.m

    def push(self, rows):
        buf = np.empty((rows.shape[1], self.tail.shape[1] + rows.shape[0]))   # (n_ch, n)
        buf[:, :self.tail.shape[1]] = self.tail
        buf[:, self.tail.shape[1]:] = rows.T
        i_lo = -(-(2 * self.L) // self.m)
        i_hi = (buf.shape[1] - 1) // self.m
        self.tail = buf[:, max(0, buf.shape[1] - 2 * self.L):].copy()
        out = np.empty((max(0, i_hi - i_lo + 1), buf.shape[0]))
        fir_decimate(self.fir, buf, self.m, i_lo, out)
        return out


def _check(engine, rpm_from, rpm_to, rate, sample_rate):
    if not (math.isfinite(rpm_from + rpm_to) and 0 < rpm_from < rpm_to):
        raise InputError("a sweep needs 0 < --from < --to", key="--from/--to")
    if not (math.isfinite(rate) and rate > 0):
        raise InputError("must be > 0 [rpm/s]", key="--sweep")
    if not (256 <= sample_rate <= MAX_SAMPLE_RATE):
        raise InputError(f"must be 256..{MAX_SAMPLE_RATE:g} [Hz]", key="--sample-rate")
    lo, hi = engine.speed_range_rpm()
    if rpm_from < lo - 1e-6 or rpm_to > hi + 1e-6:
        raise InputError(f"sweep {rpm_from:g}..{rpm_to:g} rpm outside the engine's range "
                         f"{lo:g}..{hi:g} rpm", key="--from/--to")


def sweep_steps(rpm_from, rpm_to, rate, sample_rate) -> tuple[int, int]:
    """(internal steps per output sample, internal steps) of a sweep from ``rpm_from`` to
    ``rpm_to`` [rpm] at ``rate`` [rpm/s] and ``sample_rate`` [Hz], within
    :data:`MIN_SWEEP_SAMPLES`, :data:`MAX_SWEEP_SAMPLES` and :data:`MAX_SWEEP_STEPS`."""
    rpm_from, rpm_to, rate = float(rpm_from), float(rpm_to), float(rate)   # no NumPy scalars:
    m = max(1, math.ceil(6.0 * rpm_to * STEPS_PER_DEGREE / sample_rate))  # inf, not a warning
    duration = (rpm_to - rpm_from) / rate
    n_out = duration * sample_rate
    if not n_out >= MIN_SWEEP_SAMPLES:
        raise InputError(f"a {duration:.3g} s sweep gives {n_out:.3g} samples at "
                         f"{sample_rate:g} Hz; at least {MIN_SWEEP_SAMPLES} needed (a slower "
                         "sweep)", key="--sweep")
    if not (n_out <= MAX_SWEEP_SAMPLES and n_out * m <= MAX_SWEEP_STEPS):
        raise InputError(f"a {duration:.3g} s sweep: {n_out:.3g} samples at {sample_rate:g} "
                         f"Hz and {n_out * m:.3g} integration steps; at most "
                         f"{MAX_SWEEP_SAMPLES} and {MAX_SWEEP_STEPS} (a faster sweep, a "
                         "narrower speed range or a lower --sample-rate)", key="--sweep")
    return m, int(math.floor(n_out * m))


def _initial_state(engine, modal, rpm):
    """Modal state at t = 0 of the periodic steady state at ``rpm`` (orders up to 40)."""
    n = 1440
    theta = np.arange(n) * (4 * np.pi / n)
    fh = harmonic_amplitudes(np.asarray(engine.generalized_load(rpm, theta), float))[:81]
    omegas = 0.5 * (rpm * 2 * np.pi / 60.0) * np.arange(fh.shape[0])
    x0, v0 = modal.harmonic_state(fh, omegas)
    return modal.Psi_inv_r @ np.concatenate([x0, v0]).astype(complex)
