r"""Mount parameter identification: fit a lumped mount model to a measured K*(f).

Kovarik (2016), sec. 2.2, identifies the parameters of every model of Table 2 by minimising
the Euclidean norm of the difference between the theoretical and the measured cross-point
dynamic stiffness (eq. 17–19), with the parameters constrained to be non-negative:

.. math::
    f_{obj} = \lVert k_t - k_m \rVert \cdot 1\,\mathrm{mm}
            = \Bigl(\sum_{i=1}^{N} \bigl|K_{CP}(\omega_i;\,\mathbf p) - K_m(\omega_i)\bigr|^2
              \Bigr)^{1/2} \cdot 1\,\mathrm{mm} \qquad [\mathrm N]

with :math:`K` in N/mm and a 1 mm displacement (eq. 18–19), the norm taken over the complex
values at the N measured frequencies. The thesis used SQP (``fmincon``) and found the larger
models "not robust" (sec. 2.3.5). This module solves the same problem more robustly:

* **log-parameters** :math:`q_j = \ln p_j`: every parameter stays positive without
  constraints, and stiffness [N/m], damping [N·s/m] and mass [kg] values spanning many
  decades get comparable steps. A soft wall (an extra residual growing linearly outside a
  wide box scaled to the data, see :func:`parameter_box`) keeps the search finite.
* **analytic Jacobian** of :math:`K_{CP}` with respect to every parameter
  (:func:`powertrain.physics.mount_network.cross_point_stiffness_gradient`), evaluated by a
  compiled kernel, with residuals normalised by :math:`\lVert K_m\rVert` so that the cost is
  the relative RMS error :math:`\varepsilon` (below).
* **many starts**, screened then polished: ``starts`` random starting points (seeded;
  springs around the data's stiffness level, each damper a loss factor at a random
  frequency, each mass resonating at a random frequency in the band); each start is rescaled
  by the optimal overall factor (:math:`K_{CP}` is homogeneous of degree one in the
  parameters), run for a few Levenberg–Marquardt iterations
  (:func:`scipy.optimize.least_squares`, ``method="lm"``), and the best ``polish`` of them are
  run to convergence. The best is returned.

Relative RMS error used throughout (one global normalisation, so that minimising it is
minimising :math:`f_{obj}`):

.. math:: \varepsilon = \sqrt{\frac{\sum_i |K_{CP}(\omega_i) - K_m(\omega_i)|^2}
                               {\sum_i |K_m(\omega_i)|^2}} .

References
----------
.. [1] B. Kovarik, *Modeling of the Nonlinear Frequency Dependent Engine Mount Dynamic
   Stiffness*, Master's thesis, University of Zagreb, 2016, sec. 2.2, eq. 17–19.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from powertrain.models.mount import DEFAULT_TOPOLOGY, TOPOLOGIES, MountModel, Topology
from powertrain.physics.mount_network import incidence_matrix

#: Number of random starting points screened by default.
DEFAULT_STARTS = 24
#: Number of screened starts run further by default.
DEFAULT_POLISH = 4
#: Seed of the starting points by default (the fit is deterministic for given data).
DEFAULT_SEED = 0
#: Levenberg–Marquardt function evaluations per start in the screening phase.
SCREEN_NFEV = 100
#: Perturbations ("hops") of the incumbent by default.
DEFAULT_HOPS = 16
#: Fraction of the log-parameters replaced in a hop.
HOP_FRACTION = 0.3
#: Further function evaluations of a promising hop.
HOP_NFEV = 300
#: Function evaluations of each polishing run.
POLISH_NFEV = 500
#: Further function evaluations allowed to the best polished start.
FINAL_NFEV = 1000

_DISPLACEMENT = 1e-3  # eq. 18-19: 1 mm displacement [m]


def objective_n(kcp_model, kcp_measured) -> float:
    r"""Thesis objective :math:`f_{obj} = \lVert k_t - k_m\rVert \cdot 1\,\mathrm{mm}` [N].

    Euclidean norm over the frequencies of the complex stiffness difference, times the
    1 mm displacement of Kovarik (2016), eq. 18–19.

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
    r"""Relative RMS error :math:`\sqrt{\sum|K - K_m|^2 / \sum|K_m|^2}` [1].

    One global normalisation (not per point), so it is :math:`f_{obj}` divided by
    :math:`\lVert K_m\rVert\cdot 1\,\mathrm{mm}`.

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
    K_s/\omega_{lo}]`, masses :math:`[10^{-8} K_s/\omega_{hi}^2, 10^{3} K_s/\omega_{lo}^2]`.
    The lower ends stand for "absent" (a zero in a thesis parameter list). ``max_mass``
    [kg], when given, caps every internal mass: K_CP alone does not identify the internal
    masses (the engine, which feels K_IP, does), so a physically known bound helps.

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


def starting_points(topology: Topology, frequency_hz, kcp_measured, n: int, seed=DEFAULT_SEED,
                    max_mass=None):
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


class _Problem:
    """Normalised complex residual and its Jacobian in log-parameters, with a soft wall."""

    def __init__(self, topology: Topology, frequency_hz, kcp_measured, max_mass=None):
        self.topology = topology
        self.frequency_hz = np.asarray(frequency_hz, float)
        self.max_mass = max_mass
        self.omega = 2 * np.pi * self.frequency_hz
        self.km = np.asarray(kcp_measured, complex)
        self.norm = float(np.sqrt(np.sum(np.abs(self.km) ** 2)))
        self.lo, self.hi = parameter_box(topology, frequency_hz, kcp_measured, max_mass)
        names = topology.parameters
        n_el, n = len(topology.elements), topology.n_internal
        self.B = incidence_matrix(n, topology.elem_nodes)
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
        from powertrain.kernels.two_port import kcp_gradient_kernel
        kcp_gradient_kernel(self.omega, self.B, self.to_m @ p, self.to_c @ p, self.to_d @ p,
                            self._kcp, self._dm, self._dc, self._dd)
        return self._kcp

    def _evaluate(self, q):
        if self._q is not None and np.array_equal(self._q, q):
            return
        self.nfev += 1
        p = np.exp(np.clip(q, self.lo - 30.0, self.hi + 30.0))
        kcp = self.kcp(p)
        jac = (self._dc @ self.to_c + self._dd @ self.to_d + self._dm @ self.to_m) \
            * (p / self.norm)[None, :]
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
        from scipy.optimize import least_squares
        r = least_squares(self.residual, q0, jac=self.jacobian, method="lm", x_scale="jac",
                          ftol=tol, xtol=tol, gtol=1e-12, max_nfev=max_nfev)
        return r.x, self.rel_rms(r.x), bool(r.status > 0)


@dataclass(frozen=True)
class FitResult:
    """Outcome of :func:`fit_mount`.

    Attributes
    ----------
    model : MountModel
        Fitted model (SI parameters).
    frequency_hz : ndarray
        Frequencies of the fitted data [Hz].
    kcp_measured : ndarray of complex
        Measured cross-point stiffness [N/m].
    objective_n : float
        Thesis objective :math:`f_{obj}` (eq. 19) of the fitted model [N].
    rel_rms : float
        Relative RMS error :math:`\\varepsilon` of the fitted model [1].
    n_starts : int
        Starting points screened.
    n_polished : int
        Screened starts run to convergence.
    success : bool
        The best polishing run met a convergence tolerance (not the evaluation limit).
    polish_success : tuple of bool
        Convergence flag of each polishing run.
    polish_rel_rms : tuple of float
        :math:`\\varepsilon` reached by each polishing run (spread = multi-modality).
    n_hops : int
        Perturbations of the incumbent tried.
    hops_accepted : int
        Perturbations that improved the fit.
    time_s : float
        Wall-clock time of the fit [s].
    nfev : int
        Model evaluations (K_CP and Jacobian together).
    """

    model: MountModel
    frequency_hz: np.ndarray
    kcp_measured: np.ndarray
    objective_n: float
    rel_rms: float
    n_starts: int
    n_polished: int
    success: bool
    polish_success: tuple
    polish_rel_rms: tuple
    n_hops: int
    hops_accepted: int
    time_s: float
    nfev: int

    @property
    def kcp_fitted(self) -> np.ndarray:
        """Cross-point stiffness of the fitted model at the data frequencies [N/m]."""
        return self.model.cross_point_stiffness(self.frequency_hz)

    def summary(self) -> str:
        """A few lines: objective, error, effort."""
        return (f"model {self.model.topology.name}: f_obj = {self.objective_n:.4g} N "
                f"(eq. 19, |k_t - k_m| in N/mm x 1 mm over {self.frequency_hz.size} "
                f"frequencies), relative RMS error = {100 * self.rel_rms:.3g} %\n"
                f"{self.n_starts} starts screened, {self.n_polished} polished, "
                f"{self.hops_accepted} of {self.n_hops} hops accepted, "
                f"{'converged' if self.success else 'evaluation limit reached'}, "
                f"{self.nfev} evaluations, "
                f"{self.time_s:.2f} s")

    def plot(self, ax=None, path=None, *, form="magnitude-phase", freq_axis="log",
             provenance=None):
        """Measured and fitted K*(f) [N/mm]: |K*| and loss angle (datasheets, ISO 10846) or
        real and imaginary part (``form="real-imag"``, the thesis), over ``log`` or
        ``linear`` frequency; returns the figure (see
        :func:`powertrain.plotting.plot_mount_fit`)."""
        from powertrain.plotting import plot_mount_fit
        return plot_mount_fit(self.frequency_hz, self.kcp_measured, self.kcp_fitted,
                              label=f"{self.model.topology.name} fit",
                              title=f"f_obj = {self.objective_n:.4g} N, "
                                    f"rel. RMS error = {100 * self.rel_rms:.3g} %",
                              ax=ax, path=path, form=form, freq_axis=freq_axis,
                              provenance=provenance)


def fit_mount(frequency_hz, kcp_measured, model: str | Topology = DEFAULT_TOPOLOGY, *,
              starts: int = DEFAULT_STARTS, seed=DEFAULT_SEED, polish: int = DEFAULT_POLISH,
              hops: int = DEFAULT_HOPS, name: str = "", source: str = "",
              max_mass: float | None = None) -> FitResult:
    """Identify the parameters of a lumped mount model from a measured K*(f) (sec. 2.2).

    Minimises :math:`f_{obj}` (Kovarik 2016, eq. 19) over non-negative parameters; see the
    module docstring for the method.

    Parameters
    ----------
    frequency_hz : array_like, shape (n,)
        Strictly increasing, non-negative frequencies [Hz].
    kcp_measured : array_like of complex, shape (n,)
        Measured cross-point dynamic stiffness [N/m].
    model : str or Topology
        A preset of :data:`powertrain.models.mount.TOPOLOGIES` (default triple-parallel).
    starts : int
        Random starting points screened (>= 1).
    seed : int or None
        Seed of the starting points.
    polish : int
        Best screened starts run further (>= 1).
    hops : int
        Perturbations of the incumbent (>= 0): a random ~30 % of its log-parameters are
        replaced by fresh starting values and the result kept when better.
    name, source : str
        Metadata for the returned model.
    max_mass : float, optional
        Upper bound of every internal mass [kg] (default: the data-scaled box of
        :func:`parameter_box`). K_CP does not identify the internal masses, but the engine
        feels them through K_IP: bound them when their physical size is known.

    Returns
    -------
    FitResult

    Raises
    ------
    ValueError
        Unknown model, mismatched or non-finite data, too few frequencies.
    """
    t0 = time.perf_counter()
    topology = _topology(model)
    f = np.asarray(frequency_hz, dtype=float).ravel()
    km = np.asarray(kcp_measured, dtype=complex).ravel()
    _check_fit_input(f, km, len(topology.parameters), starts, polish, hops, max_mass)
    starts, polish, hops = int(starts), min(int(polish), int(starts)), int(hops)
    prob = _Problem(topology, f, km, max_mass)
    with np.errstate(all="ignore"):
        q_best, ok_best, polished, accepted = _search(prob, starts, polish, hops, seed)
    q_best = np.clip(q_best, prob.lo, prob.hi)
    fitted = MountModel.from_values(topology, np.exp(q_best), name=name, source=source)
    kfit = fitted.cross_point_stiffness(f)
    return FitResult(model=fitted, frequency_hz=f, kcp_measured=km,
                     objective_n=objective_n(kfit, km), rel_rms=relative_rms_error(kfit, km),
                     n_starts=starts, n_polished=len(polished), success=ok_best,
                     polish_success=tuple(p[2] for p in polished),
                     polish_rel_rms=tuple(p[1] for p in polished), n_hops=hops,
                     hops_accepted=accepted, time_s=time.perf_counter() - t0, nfev=prob.nfev)


def _topology(model) -> Topology:
    if isinstance(model, str):
        if model not in TOPOLOGIES:
            raise ValueError(f"unknown model {model!r} (known: {', '.join(TOPOLOGIES)})")
        return TOPOLOGIES[model]
    return model


def _check_fit_input(f, km, n_par, starts, polish, hops, max_mass) -> None:
    """ValueError for data or settings :func:`fit_mount` cannot fit."""
    if f.size != km.size:
        raise ValueError("frequency_hz and kcp_measured differ in length")
    if not (np.all(np.isfinite(f)) and np.all(np.isfinite(km))):
        raise ValueError("data must be finite")
    if np.any(f < 0) or np.any(np.diff(f) <= 0):
        raise ValueError("frequencies must be non-negative and strictly increasing")
    if 2 * f.size < n_par:
        raise ValueError(f"{n_par} parameters need at least {(n_par + 1) // 2} frequencies")
    if not np.any(np.abs(km) > 0):
        raise ValueError("measured stiffness is zero everywhere")
    if int(starts) < 1 or int(polish) < 1 or int(hops) < 0:
        raise ValueError("starts and polish must be >= 1, hops >= 0")
    if max_mass is not None and not max_mass > 0:
        raise ValueError("max_mass must be positive")


def _search(prob, starts, polish, hops, seed):
    """Screen ``starts`` random points, polish the best ``polish``, then hop ``hops`` times
    from the incumbent; ``(q_best, ok_best, polished, hops accepted)``."""
    rng = np.random.default_rng(seed)
    fresh = starting_points(prob.topology, prob.frequency_hz, prob.km, starts + hops, rng,
                            prob.max_mass)
    screened = []
    for q0 in fresh[:starts]:
        q, err, _ = prob.solve(prob.rescale(q0), SCREEN_NFEV, 1e-6)
        screened.append((err, q))
    screened.sort(key=lambda t: t[0])
    polished = [prob.solve(q, POLISH_NFEV, 1e-10) for _, q in screened[:polish]]
    q_best, err_best, ok_best = min(polished, key=lambda t: t[1])
    accepted = 0
    for q_new in fresh[starts:]:
        # hop: replace a random ~30 % of the parameters by fresh start values
        mask = rng.random(q_best.size) < HOP_FRACTION
        if not mask.any():
            mask[rng.integers(q_best.size)] = True
        q, err, _ = prob.solve(prob.rescale(np.where(mask, q_new, q_best)),
                               SCREEN_NFEV, 1e-6)
        if err < 1.5 * err_best:
            q, err, ok = prob.solve(q, HOP_NFEV, 1e-10)
            if err < err_best:
                q_best, err_best, ok_best = q, err, ok
                accepted += 1
    if not ok_best:
        q_best, err_best, ok_best = prob.solve(q_best, FINAL_NFEV, 1e-10)
    return q_best, ok_best, polished, accepted
