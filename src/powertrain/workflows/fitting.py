r"""Mount parameter identification: fit a lumped mount model to a measured K*(f).

Kovarik (2016), sec. 2.2, eq. 17–19: minimise, over parameters >= 0,

.. math::
    f_{obj} = \Bigl(\sum_{i=1}^{N} \bigl|K_{CP}(\omega_i;\,\mathbf p) - K_m(\omega_i)\bigr|^2
              \Bigr)^{1/2} \cdot 1\,\mathrm{mm} \qquad [\mathrm N],

equivalently the relative RMS error
:math:`\varepsilon = \sqrt{\sum_i |K_{CP} - K_m|^2 / \sum_i |K_m|^2}`, on log-parameters
(soft wall outside :func:`parameter_box`) with the analytic Jacobian, from seeded starts
screened, polished, then hopped (:func:`fit_mount`). Method: docs/guide/fit-mount.md.

References
----------
.. [1] B. Kovarik, *Modeling of the Nonlinear Frequency Dependent Engine Mount Dynamic
   Stiffness*, Master's thesis, University of Zagreb, 2016, sec. 2.2, eq. 17–19.
"""

from __future__ import annotations

import dataclasses
import math
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from powertrain.errors import InputError
from powertrain.iotools.stiffness_csv import FREQUENCY, read_stiffness_csv
from powertrain.kernels import kernel_input
from powertrain.kernels.two_port import kcp_gradient_kernel
from powertrain.models.mount import DEFAULT_TOPOLOGY, TOPOLOGIES, MountModel, Topology
from powertrain.physics.mount_network import incidence_matrix
from powertrain.results.fit import FitResult
from powertrain.workflows.arguments import integer, real

#: Random starting points screened, screened starts polished, and their seed by default.
DEFAULT_STARTS = 24
DEFAULT_POLISH = 4
DEFAULT_SEED = 0
#: Levenberg–Marquardt function evaluations per start in the screening phase.
SCREEN_NFEV = 100
#: Hops (perturbations of the incumbent) by default, and the fraction of it a hop replaces.
DEFAULT_HOPS = 16
HOP_FRACTION = 0.3
#: Function evaluations of a promising hop, of each polishing run, of the best one's last run.
HOP_NFEV = 300
POLISH_NFEV = 500
FINAL_NFEV = 1000

_DISPLACEMENT = 1e-3  # eq. 18-19: 1 mm displacement [m]


def objective_n(kcp_model, kcp_measured) -> float:
    r"""Thesis objective :math:`f_{obj} = \lVert k_t - k_m\rVert \cdot 1\,\mathrm{mm}` [N]
    (Kovarik 2016, eq. 18–19).

    Parameters
    ----------
    kcp_model, kcp_measured : array_like of complex
        Cross-point dynamic stiffness [N/m] at the same frequencies.

    Returns
    -------
    float
        [N]
    """
    diff = np.asarray(kcp_model) - np.asarray(kcp_measured)
    return float(np.sqrt(np.sum(np.abs(diff) ** 2)) * _DISPLACEMENT)


def relative_rms_error(kcp_model, kcp_measured) -> float:
    r"""Relative RMS error :math:`\sqrt{\sum|K - K_m|^2 / \sum|K_m|^2}` [1] (one global
    normalisation: :math:`f_{obj} / (\lVert K_m\rVert\cdot 1\,\mathrm{mm})`).

    Parameters
    ----------
    kcp_model, kcp_measured : array_like of complex
        Cross-point dynamic stiffness [N/m] at the same frequencies.
    """
    km = np.asarray(kcp_measured)
    diff = np.asarray(kcp_model) - km
    return float(np.sqrt(np.sum(np.abs(diff) ** 2) / np.sum(np.abs(km) ** 2)))


def parameter_box(topology: Topology, frequency_hz, kcp_measured, max_mass=None):
    r"""Wide box of plausible log-parameters, scaled to the data.

    With :math:`K_s` the RMS of :math:`|K_m|` [N/m] and :math:`\omega_{lo}, \omega_{hi}` the
    lowest non-zero and the highest angular frequency [rad/s]: springs
    :math:`K_s\,[10^{-8}, 10^{4}]`, dampers :math:`[10^{-8} K_s/\omega_{hi}, 10^{3}
    K_s/\omega_{lo}]`, masses :math:`[10^{-8} K_s/\omega_{hi}^2, 10^{3} K_s/\omega_{lo}^2]`;
    lower ends mean "absent". ``max_mass`` [kg] caps every internal mass (K_CP does not
    identify them).

    Returns
    -------
    lo, hi : ndarray
        Natural logarithms of the SI bounds, in the topology's parameter order.
    """
    ks, wlo, whi = _scales(frequency_hz, kcp_measured)
    lo, hi = [], []
    for p in topology.parameters:
        if p[0] == "c":
            lo.append(ks * 1e-8)
            hi.append(ks * 1e4)
        elif p[0] == "d":
            lo.append(ks / whi * 1e-8)
            hi.append(ks / wlo * 1e3)
        else:
            m_hi = ks / wlo**2 * 1e3 if max_mass is None else float(max_mass)
            lo.append(min(ks / whi**2 * 1e-8, m_hi * 1e-6))
            hi.append(m_hi)
    return np.log(lo), np.log(hi)


def _scales(frequency_hz, kcp_measured):
    f = np.asarray(frequency_hz, float)
    ks = float(np.sqrt(np.mean(np.abs(kcp_measured) ** 2)))
    positive = f[f > 0]
    wlo = 2 * np.pi * (positive.min() if positive.size else 1.0)
    whi = 2 * np.pi * max(f.max(), positive.min() * 2 if positive.size else 2.0)
    return ks, wlo, whi


def starting_points(topology: Topology, frequency_hz, kcp_measured, n: int, seed=DEFAULT_SEED, max_mass=None):
    r"""``n`` random starting log-parameter vectors (seeded), scaled to the data.

    Springs :math:`K_s 10^{U(-2, 1)}`; dampers :math:`K_s/\omega_c \cdot 10^{U(-2, 0)}`;
    masses :math:`K_s/\omega_n^2 \cdot 10^{U(-1, 1)}`, with :math:`\omega_c, \omega_n`
    log-uniform over the measured band (:math:`K_s`, band: see :func:`parameter_box`).

    Returns
    -------
    ndarray, shape (n, n_parameters)
    """
    rng = np.random.default_rng(seed)
    ks, wlo, whi = _scales(frequency_hz, kcp_measured)
    lo, hi = parameter_box(topology, frequency_hz, kcp_measured, max_mass)
    out = np.empty((n, len(topology.parameters)))
    for i in range(n):
        for j, p in enumerate(topology.parameters):
            if p[0] == "c":
                v = ks * 10 ** rng.uniform(-2, 1)
            elif p[0] == "d":
                v = ks / np.exp(rng.uniform(np.log(wlo), np.log(whi))) * 10 ** rng.uniform(-2, 0)
            else:
                wn = np.exp(rng.uniform(np.log(wlo), np.log(whi)))
                v = ks / wn**2 * 10 ** rng.uniform(-1, 1)
            out[i, j] = np.log(v)
    return np.clip(out, lo, hi)


class NetworkProblem:
    """Normalised complex residual and its Jacobian in log-parameters, with a soft wall."""

    def __init__(self, topology: Topology, frequency_hz, kcp_measured, max_mass=None):
        self.topology = topology
        self.omega = kernel_input(2 * np.pi * np.asarray(frequency_hz, float))
        self.km = np.asarray(kcp_measured, complex)
        self.norm = float(np.sqrt(np.sum(np.abs(self.km) ** 2)))
        self.lo, self.hi = parameter_box(topology, frequency_hz, kcp_measured, max_mass)
        names = topology.parameters
        n_el, n = len(topology.elements), topology.n_internal
        self.B = kernel_input(incidence_matrix(n, topology.elem_nodes))
        self.to_c = np.zeros((n_el, len(names)))
        self.to_d = np.zeros((n_el, len(names)))
        self.to_m = np.zeros((n, len(names)))
        for e, (_, _, cn, dn) in enumerate(topology.elements):
            if cn:
                self.to_c[e, names.index(cn)] = 1.0
            if dn:
                self.to_d[e, names.index(dn)] = 1.0
        for j, mn in enumerate(topology.masses):
            if mn:
                self.to_m[j, names.index(mn)] = 1.0
        nf = self.omega.size
        self._kcp = np.empty(nf, complex)
        self._dm = np.empty((nf, n), complex)
        self._dc = np.empty((nf, n_el), complex)
        self._dd = np.empty((nf, n_el), complex)
        self._q = None
        self.nfev = 0

    def kcp(self, p):
        """K_CP [N/m] for SI parameters ``p`` (and fill the derivative buffers)."""
        kcp_gradient_kernel(self.omega, self.B,
                            *(kernel_input(T @ p) for T in (self.to_m, self.to_c, self.to_d)),
                            self._kcp, self._dm, self._dc, self._dd)
        return self._kcp

    def gradient(self, p):
        """``(K_CP [N/m], dK_CP/dp (n_freq, n_parameters))`` at SI parameters ``p``."""
        kcp = self.kcp(p)
        return kcp, self._dc @ self.to_c + self._dd @ self.to_d + self._dm @ self.to_m

    def _evaluate(self, q):
        if self._q is not None and np.array_equal(self._q, q):
            return
        self.nfev += 1
        p = np.exp(np.clip(q, self.lo - 30.0, self.hi + 30.0))
        kcp, grad = self.gradient(p)
        jac = grad * (p / self.norm)[None, :]
        r = (kcp - self.km) / self.norm
        wall = q - np.clip(q, self.lo, self.hi)
        res = np.concatenate([r.real, r.imag, wall])
        J = np.concatenate([jac.real, jac.imag, np.diag((wall != 0).astype(float))])
        if not (np.all(np.isfinite(res)) and np.all(np.isfinite(J))):
            res = np.full_like(res, 1e6)
            J = np.zeros_like(J)
        self._res, self._jac = res, J
        self._q = q.copy()

    def residual(self, q):
        self._evaluate(q)
        return self._res

    def jacobian(self, q):
        self._evaluate(q)
        return self._jac

    def rel_rms(self, q):
        self._evaluate(q)
        return float(np.sqrt(np.sum(self._res[:2 * self.omega.size] ** 2)))

    def rescale(self, q):
        """Shift ``q`` by the log of the overall factor that best fits the data."""
        k = self.kcp(np.exp(q))
        den = float(np.vdot(k, k).real)
        if not np.isfinite(den) or den == 0:
            return q
        s = float(np.vdot(k, self.km).real) / den
        return q + np.log(s) if s > 0 else q

    def solve(self, q0, max_nfev, tol):
        r = least_squares(self.residual, q0, jac=self.jacobian, method="lm", x_scale="jac",
                          ftol=tol, xtol=tol, gtol=1e-12, max_nfev=max_nfev)
        return r.x, self.rel_rms(r.x), bool(r.status > 0)


def fit_mount(measured, kcp_measured=None, model: str | Topology = DEFAULT_TOPOLOGY, *,
              starts: int = DEFAULT_STARTS, seed=DEFAULT_SEED, polish: int = DEFAULT_POLISH,
              hops: int = DEFAULT_HOPS, name: str = "", source: str = "",
              max_mass: float | None = None, fmin=None, fmax=None) -> FitResult:
    """Identify a lumped mount model's parameters from a measured K*(f): minimise
    :math:`f_{obj}` (Kovarik 2016, sec. 2.2, eq. 19) over parameters >= 0.

    Parameters
    ----------
    measured : array_like, shape (n,), or str or path
        Strictly increasing, non-negative frequencies [Hz] (with ``kcp_measured``), or a
        dynamic-stiffness CSV (``powertrain fit-mount``; :func:`fit_mount_file`).
    kcp_measured : array_like of complex, shape (n,)
        Measured cross-point dynamic stiffness [N/m] (None with a file).
    model : str or Topology
        A preset of :data:`powertrain.models.mount.TOPOLOGIES` (default triple-parallel).
    starts, polish : int
        Random starting points screened, and the best of them run further (>= 1 each).
    seed : int or None
        Seed of the starting points.
    hops : int
        Perturbations of the incumbent (>= 0), ~30 % of its log-parameters redrawn.
    name, source : str
        Metadata for the returned model.
    max_mass : float, optional
        Upper bound of every internal mass [kg] (default :func:`parameter_box`'s).
    fmin, fmax : float, optional
        With a file: fit only the frequencies in ``fmin..fmax`` [Hz].

    Raises
    ------
    InputError
        Bad model or data, naming the option or argument (and file).
    """
    if kcp_measured is None:
        return fit_mount_file(measured, model, starts=starts, seed=seed, max_mass=max_mass,
                              fmin=fmin, fmax=fmax, polish=polish, hops=hops)
    return _fit_arrays(measured, kcp_measured, _topology(model), starts=starts, seed=seed,
                       polish=polish, hops=hops, name=name, source=source, max_mass=max_mass)


def _fit_arrays(frequency_hz, kcp_measured, topology, *, starts, seed, polish, hops, name,
                source, max_mass) -> FitResult:
    t0 = time.perf_counter()
    f, km = _checked_data(frequency_hz, kcp_measured, topology)
    starts = _starts(starts)
    polish = min(integer(polish, "polish", minimum=1), starts)
    hops = integer(hops, "hops", minimum=0)
    if not isinstance(seed, np.random.Generator):
        seed = integer(seed, "--seed", optional=True)
    max_mass = real(max_mass, "--max-mass", unit="kg", optional=True)
    if max_mass is not None and not max_mass > 0:
        raise InputError(f"must be positive, got {max_mass}", key="--max-mass")
    prob = NetworkProblem(topology, f, km, max_mass)
    rng = np.random.default_rng(seed)
    fresh = starting_points(topology, f, km, starts + hops, rng, max_mass)
    with np.errstate(all="ignore"):
        polished = _screen_and_polish(prob, fresh[:starts], polish)
        q_best, err_best, ok_best = min(polished, key=lambda t: t[1])
        q_best, err_best, ok_best, accepted = _hop(prob, rng, fresh[starts:], (q_best, err_best, ok_best))
        if not ok_best:
            q_best, err_best, ok_best = prob.solve(q_best, FINAL_NFEV, 1e-10)
    q_best = np.clip(q_best, prob.lo, prob.hi)
    fitted = MountModel.from_values(topology, np.exp(q_best), name=name, source=source)
    kfit = fitted.cross_point_stiffness(f)
    return FitResult(model=fitted, frequency_hz=f, kcp_measured=km,
                     objective_n=objective_n(kfit, km), rel_rms=relative_rms_error(kfit, km),
                     n_starts=starts, n_polished=len(polished),
                     success=ok_best, polish_success=tuple(p[2] for p in polished),
                     polish_rel_rms=tuple(p[1] for p in polished), n_hops=hops, hops_accepted=accepted,
                     time_s=time.perf_counter() - t0, nfev=prob.nfev, seed=seed)


def _topology(model) -> Topology:
    if isinstance(model, Topology):
        return model
    if not isinstance(model, str) or model not in TOPOLOGIES:
        raise InputError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})", key="--model")
    return TOPOLOGIES[model]


def _checked_data(frequency_hz, kcp_measured, topology):
    """Frequencies [Hz] and K_CP [N/m] as flat arrays, refused when they cannot be fitted."""
    try:
        f = np.asarray(frequency_hz, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError("must be numbers [Hz]", key="frequency_hz") from None
    try:
        km = np.asarray(kcp_measured, dtype=complex).ravel()
    except (TypeError, ValueError):
        raise InputError("must be numbers [N/m]", key="kcp_measured") from None
    if f.size != km.size:
        raise InputError(f"{km.size} values for {f.size} frequencies", key="kcp_measured")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(km))):
        raise InputError("data must be finite", key="kcp_measured" if np.all(np.isfinite(f))
                         else "frequency_hz")
    if np.any(f < 0) or np.any(np.diff(f) <= 0):
        raise InputError("frequencies must be non-negative and strictly increasing", key="frequency_hz")
    n_par = len(topology.parameters)
    if 2 * f.size < n_par:
        raise InputError(f"{n_par} parameters need at least {(n_par + 1) // 2} frequencies",
                         key="frequency_hz")
    if not np.any(np.abs(km) > 0):
        raise InputError("measured stiffness is zero everywhere", key="kcp_measured")
    return f, km


def _screen_and_polish(prob, starts, polish) -> list:
    """Screen every start, polish the best ``polish``: ``[(q, rel. RMS error, ok)]``."""
    screened = []
    for q0 in starts:
        q, err, _ = prob.solve(prob.rescale(q0), SCREEN_NFEV, 1e-6)
        screened.append((err, q))
    screened.sort(key=lambda t: t[0])
    return [prob.solve(q, POLISH_NFEV, 1e-10) for _, q in screened[:polish]]


def _hop(prob, rng, fresh, best):
    """Hop from ``best = (q, err, ok)`` once per row of ``fresh``: best and hops accepted."""
    q_best, err_best, ok_best = best
    accepted = 0
    for q_new in fresh:
        mask = rng.random(q_best.size) < HOP_FRACTION
        if not mask.any():
            mask[rng.integers(q_best.size)] = True
        q, err, _ = prob.solve(prob.rescale(np.where(mask, q_new, q_best)), SCREEN_NFEV, 1e-6)
        if err < 1.5 * err_best:
            q, err, ok = prob.solve(q, HOP_NFEV, 1e-10)
            if err < err_best:
                q_best, err_best, ok_best = q, err, ok
                accepted += 1
    return q_best, err_best, ok_best, accepted


#: Most starting points :func:`fit_mount_file` accepts.
MAX_STARTS = 10_000


def fit_mount_file(measured, model: str = DEFAULT_TOPOLOGY, *, starts: int = DEFAULT_STARTS,
                   seed=DEFAULT_SEED, max_mass=None, fmin=None, fmax=None, **options) -> FitResult:
    """:func:`fit_mount` on the CSV ``measured`` in ``fmin..fmax`` [Hz] (``powertrain
    fit-mount``); ``options``: ``polish``, ``hops``."""
    starts, seed, max_mass, fmin, fmax = check_options(measured, model, starts, seed, max_mass, fmin, fmax)
    data = read_stiffness_csv(measured).select(fmin, fmax)
    topo = TOPOLOGIES[model]
    need = (len(topo.parameters) + 1) // 2
    if data.frequency_hz.size < need:
        limits = "/".join(n for n, v in (("--fmin", fmin), ("--fmax", fmax)) if v is not None)
        raise InputError(f"{data.frequency_hz.size} frequencies in range"
                         + (f" of {limits}" if limits else "") + f", the "
                         f"{len(topo.parameters)} parameters of {model} need at least {need}",
                         file=measured, key=limits or FREQUENCY)
    if not (abs(data.kcp) > 0).any():
        raise InputError("stiffness is zero everywhere", file=measured, key=FREQUENCY)
    file = Path(measured).name
    result = fit_mount(data.frequency_hz, data.kcp, model, starts=starts, seed=seed,
                       max_mass=max_mass, name=f"{topo.description} fitted to {file}",
                       source=f"powertrain fit-mount {file} --model {model}", **options)
    return dataclasses.replace(result, data_name=file, synthetic=data.synthetic)


def _starts(starts) -> int:
    """``--starts`` as an int in 1..:data:`MAX_STARTS`."""
    starts = integer(starts, "--starts")
    if not 1 <= starts <= MAX_STARTS:
        raise InputError(f"must be 1..{MAX_STARTS}, got {starts}", key="--starts")
    return starts


def check_options(measured, model, starts, seed, max_mass, fmin, fmax) -> tuple:
    """The options of :func:`fit_mount_file` checked: ``(starts, seed, max_mass, fmin, fmax)``."""
    starts, seed = integer(starts, "--starts"), integer(seed, "--seed", optional=True)
    max_mass, fmin, fmax = (real(v, k, optional=True) for v, k in (
        (max_mass, "--max-mass"), (fmin, "--fmin"), (fmax, "--fmax")))
    if not isinstance(model, str) or model not in TOPOLOGIES:
        raise InputError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})",
                         file=measured, key="--model")
    if max_mass is not None and not max_mass > 0:
        raise InputError(f"must be positive, got {max_mass}", key="--max-mass")
    _starts(starts)
    if seed is not None and not 0 <= seed < 2 ** 63:
        raise InputError(f"must be an integer 0..2^63-1, got {seed}", key="--seed")
    for name, value in (("--fmin", fmin), ("--fmax", fmax), ("--max-mass", max_mass)):
        if value is not None and not math.isfinite(value):
            raise InputError(f"must be a finite number, got {value}", key=name)
    if fmin is not None and fmax is not None and not fmin < fmax:
        raise InputError(f"--fmin {fmin:g} must be below --fmax {fmax:g}", key="--fmin")
    return starts, seed, max_mass, fmin, fmax
