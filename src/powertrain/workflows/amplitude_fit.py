r"""Fit a mount to K*(f) measured at several amplitudes (``powertrain fit-mount`` on a CSV
with an ``amplitude_mm`` column; Kovarik 2016, Fig. 14).

Model (:class:`~powertrain.physics.mount_elements.MountElement`): a network at the reference
amplitude :math:`A_{ref}`, springs and dampers times :math:`\mathrm{clip}((A_{ref}/A)^n, lo,
hi)` (:data:`LIMITS`) and, with ``friction``, Berg's element in parallel. Stage one fits the
network (:func:`powertrain.workflows.fitting.fit_mount`), stage two all together by bounded
least squares, each amplitude normalised by its :math:`\lVert K_m\rVert`.
Method: docs/guide/amplitude-and-preload.md.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from powertrain.errors import InputError
from powertrain.iotools.mount_file import MAX_SI
from powertrain.iotools.stiffness_csv import AMPLITUDE, read_stiffness_csv
from powertrain.models.mount import TOPOLOGIES, MountModel
from powertrain.physics.mount_laws import BergFriction, PowerLaw
from powertrain.results.amplitude_fit import AmplitudeFitResult
from powertrain.workflows import fitting
from powertrain.workflows.arguments import flag, real
from powertrain.workflows.fitting import (
    DEFAULT_POLISH,
    DEFAULT_SEED,
    DEFAULT_STARTS,
    NetworkProblem,
    check_options,
    fit_mount_file,
    parameter_box,
    relative_rms_error,
    starting_points,
)

#: Limits of the fitted power law (fixed).
LIMITS = PowerLaw(1.0, 0.0).limits
#: Bounds of the fitted exponent.
EXPONENT_BOUNDS = (-1.0, 2.0)
#: Function evaluations of each joint start screened, and of the best one's final run.
SCREEN_NFEV, JOINT_NFEV = 40, 400


def fit_mount(measured, kcp_measured=None, model="triple-parallel", *, friction=False,
              reference=None, starts=DEFAULT_STARTS, seed=DEFAULT_SEED, max_mass=None,
              fmin=None, fmax=None, **options):
    """Fit a mount model to a measured K*(f), as ``powertrain fit-mount`` does.

    Parameters
    ----------
    measured : str, path or array_like
        Dynamic-stiffness CSV (several amplitudes: joint fit, :func:`fit_amplitudes`), or
        the frequencies [Hz] of ``kcp_measured``.
    kcp_measured : array_like of complex, optional
        Measured cross-point dynamic stiffness [N/m] at ``measured`` (arrays only).
    model : str
        A preset of :data:`powertrain.models.mount.TOPOLOGIES` (``--model``).
    friction : bool
        Several amplitudes: fit Berg's friction element too.
    reference : float, optional
        Several amplitudes: reference amplitude [m], one of the data's (default smallest).
    starts, seed, max_mass, fmin, fmax
        As :func:`powertrain.workflows.fitting.fit_mount` (``max_mass`` [kg], ``fmin``,
        ``fmax`` [Hz]).
    options
        ``polish``, ``hops``, ``name``, ``source`` of that function (arrays only).

    Returns
    -------
    FitResult, or AmplitudeFitResult for data at several amplitudes
        ``to_text()`` is what the command prints; ``plot(ax=None)``, ``save(path)``.

    Raises
    ------
    InputError
        Naming the file and key, or the option, of bad input.
    """
    if kcp_measured is None:
        return fit_mount_csv(measured, model, friction=friction, reference=reference,
                             starts=starts, seed=seed, max_mass=max_mass, fmin=fmin, fmax=fmax)
    _one_amplitude_options(friction, reference)
    return fitting.fit_mount(measured, kcp_measured, model, starts=starts, seed=seed,
                             max_mass=max_mass, fmin=fmin, fmax=fmax, **options)


def fit_mount_csv(measured, model="triple-parallel", *, friction=False, reference=None,
                  starts=DEFAULT_STARTS, seed=DEFAULT_SEED, max_mass=None, fmin=None, fmax=None):
    """``powertrain fit-mount`` on a CSV: single-amplitude fit, or :func:`fit_amplitudes`.

    Parameters
    ----------
    measured : str or path
        Dynamic-stiffness CSV (:mod:`powertrain.iotools.stiffness_csv`).
    friction : bool
        Fit Berg's friction element too (multi-amplitude data only).
    reference : float, optional
        Reference amplitude [m], one of the data's (default: the smallest).
    model, starts, seed, max_mass, fmin, fmax
        As :func:`powertrain.workflows.fitting.fit_mount_file`.
    """
    starts, seed, max_mass, fmin, fmax = check_options(measured, model, starts, seed, max_mass, fmin, fmax)
    friction = flag(friction, "--friction")
    reference = real(reference, "--reference", unit="m", optional=True)
    data = read_stiffness_csv(measured).select(fmin, fmax)
    if data.amplitudes.size < 2:
        _one_amplitude_options(friction, reference, measured)
        return fit_mount_file(measured, model, starts=starts, seed=seed, max_mass=max_mass,
                              fmin=fmin, fmax=fmax)
    name = Path(measured).name
    return fit_amplitudes(data, model, friction=friction, reference=reference, starts=starts,
                          seed=seed, max_mass=max_mass, data_name=name,
                          source=f"powertrain fit-mount {name} --model {model}"
                          + (" --friction" if friction else ""))


def _one_amplitude_options(friction, reference, file=None) -> None:
    """Refuse ``--friction`` and ``--reference`` on data at one amplitude."""
    for option, value in (("--friction", friction), ("--reference", reference)):
        if value:
            raise InputError(f"{option} needs data at two or more amplitudes (a column "
                             f"{AMPLITUDE})", file=file, key=option)


def fit_amplitudes(data, model="triple-parallel", *, friction=False, reference=None,
                   starts=DEFAULT_STARTS, seed=DEFAULT_SEED, max_mass=None, data_name="",
                   source="") -> AmplitudeFitResult:
    """Fit network, power law and (``friction``) Berg's element to ``data`` (two or more
    amplitudes); see the module docstring."""
    t0 = time.perf_counter()
    max_mass = MAX_SI["m"] if max_mass is None else max_mass   # what a mount file holds
    topology = TOPOLOGIES[model] if isinstance(model, str) else model
    amps = data.amplitudes
    a_ref = _reference(amps, reference, data.source)
    problem = _Joint(topology, [data.at(a) for a in amps], a_ref, friction, max_mass)
    ref = data.at(a_ref)
    guess = problem.friction_guess() if friction else None
    k_ref = ref.kcp - (guess.describing_stiffness(a_ref) if friction else 0.0)
    network = fitting.fit_mount(ref.frequency_hz, k_ref, topology, starts=starts, seed=seed,
                        max_mass=max_mass)
    rng = np.random.default_rng(seed)
    q_nets = [np.log(network.model.values),
              *starting_points(topology, ref.frequency_hz, k_ref, starts, rng, max_mass)]
    net = NetworkProblem(topology, ref.frequency_hz, k_ref, max_mass)
    runs = [problem.solve(problem.start(net.rescale(q), guess), SCREEN_NFEV) for q in q_nets]
    runs.sort(key=lambda r: r.cost)
    polished = [problem.solve(r.x, JOINT_NFEV) for r in runs[:DEFAULT_POLISH]]
    best = min(polished, key=lambda r: r.cost)
    runs += polished
    fitted = problem.model(best.x, name=f"{topology.description} fitted to {data_name} "
                           "at several amplitudes", source=source)
    element = fitted.element()
    errors = tuple(relative_rms_error(element.cross_point_stiffness(c.frequency_hz, a), c.kcp)
                   for a, c in zip(amps, problem.curves))
    return AmplitudeFitResult(
        model=fitted, reference_m=a_ref, amplitude_m=amps, curves=problem.curves,
        rel_rms=errors, network_fit=network, friction=friction, success=bool(best.success),
        n_joint_starts=len(q_nets), nfev=int(sum(r.nfev for r in runs)),
        time_s=time.perf_counter() - t0, seed=seed, data_name=data_name)


def _reference(amplitudes, reference, path) -> float:
    if reference is None:
        return float(amplitudes[0])
    near = np.isclose(amplitudes, reference, rtol=1e-9, atol=0.0)
    if not near.any():
        listed = ", ".join(f"{a * 1e3:g}" for a in amplitudes)
        raise InputError(f"{reference * 1e3:g} mm is not one of the data's amplitudes "
                         f"({listed} mm)", file=path, key="--reference")
    return float(amplitudes[near][0])


class _Joint:
    r"""Stage two: residual over every amplitude and its Jacobian in
    ``q = [ln p, n, (ln F_max, ln x2)]``; the exponent's column is the scaled columns times
    :math:`\ln(A_{ref}/A)` (zero where clipped), :math:`x_2`'s is numerical."""

    def __init__(self, topology, curves, a_ref, friction, max_mass):
        self.topology, self.curves, self.a_ref, self.friction = topology, curves, a_ref, friction
        self.amplitudes = np.array([c.amplitude_m[0] for c in curves])
        self.nets = [NetworkProblem(topology, c.frequency_hz, c.kcp, max_mass) for c in curves]
        self.scaled = np.array([p[0] in "cd" for p in topology.parameters], float)
        f = np.concatenate([c.frequency_hz for c in curves])
        k = np.concatenate([c.kcp for c in curves])
        lo, hi = parameter_box(topology, f, k, max_mass)
        level = float(np.sqrt(np.mean(np.abs(k) ** 2)))               # [N/m]
        lo, hi = [*lo, EXPONENT_BOUNDS[0]], [*hi, EXPONENT_BOUNDS[1]]
        if friction:
            a_lo, a_hi = self.amplitudes[0], self.amplitudes[-1]
            lo += [np.log(1e-6 * level * a_hi), np.log(1e-3 * a_lo)]
            hi += [np.log(1e2 * level * a_hi), np.log(1e3 * a_hi)]
        self.lo, self.hi = np.array(lo), np.array(hi)
        self.norms = [float(np.linalg.norm(c.kcp)) * np.sqrt(len(curves)) for c in curves]
        self._q = None

    def model(self, q, **meta) -> MountModel:
        n_p = len(self.topology.parameters)
        law = PowerLaw(self.a_ref, float(q[n_p]), LIMITS)
        port = BergFriction(float(np.exp(q[n_p + 1])), float(np.exp(q[n_p + 2]))) if self.friction else None
        return MountModel.from_values(self.topology, np.exp(q[:n_p]), amplitude_law=law,
                                      port_law=port, **meta)

    def _evaluate(self, q):
        if self._q is not None and np.array_equal(self._q, q):
            return
        model = self.model(q)
        p, law, port = model.values, model.amplitude_law, model.port_law
        friction = self._friction(port)
        res, jac = [], []
        for j, (a, net, c, norm) in enumerate(zip(self.amplitudes, self.nets, self.curves, self.norms)):
            s = float(law.factor(a))
            ps = p * (1.0 + (s - 1.0) * self.scaled)
            k, grad = net.gradient(ps)
            cols = grad * ps[None, :]
            clipped = s in law.limits and law.exponent != 0.0
            dn = 0.0 if clipped else cols @ self.scaled * np.log(self.a_ref / a)
            cols = np.column_stack([cols, dn + 0j * k])
            k = k.copy()
            if port is not None:
                kf, dx2 = friction[:, j]
                k += kf
                cols = np.column_stack([cols, np.full(k.size, kf), np.full(k.size, dx2)])
            res.append((k - c.kcp) / norm)
            jac.append(cols / norm)
        r, J = np.concatenate(res), np.vstack(jac)
        self._res = np.concatenate([r.real, r.imag])
        self._jac = np.vstack([J.real, J.imag])
        if not (np.all(np.isfinite(self._res)) and np.all(np.isfinite(self._jac))):
            self._res, self._jac = np.full_like(self._res, 1e6), np.zeros_like(self._jac)
        self._q = q.copy()

    def _friction(self, port):
        """Berg's stiffness per amplitude and its derivative in ``ln x2``: (2, n_a)."""
        if port is None:
            return None
        kf = port.describing_stiffness(self.amplitudes)
        step = 1e-6
        wider = BergFriction(port.max_force, port.half_displacement * np.exp(step))
        return np.array([kf, (wider.describing_stiffness(self.amplitudes) - kf) / step])

    def residual(self, q) -> np.ndarray:
        self._evaluate(q)
        return self._res

    def jacobian(self, q) -> np.ndarray:
        self._evaluate(q)
        return self._jac

    def friction_guess(self) -> BergFriction:
        """Berg's element matching the data's loss at each amplitude's lowest frequency
        (where viscous loss is smallest)."""
        a = self.amplitudes
        loss = np.array([max(c.kcp[0].imag, 0.0) for c in self.curves])
        scale = float(np.max(loss)) or 1.0

        def misfit(q):
            law = BergFriction(float(np.exp(q[0])), float(np.exp(q[1])))
            return (law.describing_stiffness(a).imag - loss) / scale

        q0 = [np.log(scale * a[-1]), np.log(self.a_ref)]
        q = least_squares(misfit, q0, bounds=(self.lo[-2:], self.hi[-2:])).x
        return BergFriction(float(np.exp(q[0])), float(np.exp(q[1])))

    def start(self, q_network, friction):
        """Start from ``q_network``, a guessed exponent and ``friction`` (None: without)."""
        if friction is None:
            return self._inside(np.r_[q_network, self._exponent_guess()])
        rest = [c.kcp - friction.describing_stiffness(a) for a, c in zip(self.amplitudes, self.curves)]
        return self._inside(np.r_[q_network, self._exponent_guess(rest), np.log(friction.max_force),
                                  np.log(friction.half_displacement)])

    def _exponent_guess(self, kcp=None) -> float:
        """Minus the slope of ln(mean |K*|) against ln A, inside :data:`EXPONENT_BOUNDS`."""
        kcp = [c.kcp for c in self.curves] if kcp is None else kcp
        level = [np.log(np.mean(np.abs(k))) for k in kcp]
        slope = np.polyfit(np.log(self.amplitudes / self.a_ref), level, 1)[0]
        return float(np.clip(-slope, *EXPONENT_BOUNDS))

    def _inside(self, q):
        return np.clip(q, self.lo + 1e-9, self.hi - 1e-9)

    def solve(self, q0, max_nfev):
        with np.errstate(all="ignore"):
            return least_squares(self.residual, q0, jac=self.jacobian,
                                 bounds=(self.lo, self.hi), method="trf", x_scale="jac",
                                 ftol=1e-12, xtol=1e-12, gtol=1e-12, max_nfev=max_nfev)
