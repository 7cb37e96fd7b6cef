r"""Retune a mount direction to a desired change of its dynamic stiffness over a band
(``--target left.z:+20%:100-300Hz``, :func:`powertrain.workflows.variants.parse_target`).

With :math:`a = \ln(\text{factor})`, :math:`f_1, f_2` the band and :math:`h` the transition
width in octaves (default 0.5), the requested curve is :math:`K_t = K_0\,g\,e^{i\varphi}`:

.. math::
    \ln g(f) = a\,w(f), \qquad
    w(f) = \begin{cases} 1 & f_1 \le f \le f_2 \\
             \tfrac12\bigl(1 + \cos \pi\delta\bigr) & 0 < \delta < 1 \\
             0 & \delta \ge 1 \end{cases}, \qquad
    \delta = \frac{\max(\log_2(f_1/f),\ \log_2(f/f_2))}{h},

    \varphi(f_0) = \frac1\pi \int_{-\infty}^{\infty} \frac{d \ln g}{du}\,
                   \ln\coth\frac{|u|}{2}\, du, \qquad u = \ln(f / f_0),

the minimum-phase phase (Bode's gain-phase relation). Stage one fits the baseline topology
to :math:`K_t` (:func:`~powertrain.workflows.fitting.fit_mount`); stage two refines by joint
least squares the relative errors of :math:`K_{CP}` against :math:`K_t` and of :math:`K_{IP}`
against :math:`K_{IP,0} + (K_t - K_0)`, from that fit and from the baseline (lower cost
wins). At an amplitude :math:`K_0` is the equivalent-linear K_CP there (:func:`network_at`).
docs/guide/whatif.md (*Retune to a target*).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from powertrain.models.mount import MountModel
from powertrain.plotting import plot_retune
from powertrain.plotting.style import target_and_path
from powertrain.results.base import Result
from powertrain.workflows.fitting import fit_mount, relative_rms_error
from powertrain.workflows.operations import Origin, Swap, Target

#: Log-spaced fit frequencies above 0 Hz.
N_FREQUENCIES = 120
#: Lowest non-zero fit frequency [Hz].
F_MIN_HZ = 1.0
#: Highest fit frequency at least [Hz] (covers order 8 at 6000 rpm).
F_MAX_HZ = 1000.0
#: Midpoints per transition zone of the Bode phase integral.
_BODE_POINTS = 4000


def band_weight(frequency_hz, f_lo, f_hi, blend_octaves=0.5) -> np.ndarray:
    """Raised-cosine band weight :math:`w(f)` in [0, 1] (module docstring) [1].

    Parameters
    ----------
    frequency_hz : array_like
        [Hz]; 0 Hz gives 0.
    f_lo, f_hi : float
        Band edges [Hz].
    blend_octaves : float
        Transition width on each side [octaves].
    """
    f = np.maximum(np.asarray(frequency_hz, float), 1e-300)
    delta = np.maximum(np.log2(f_lo / f), np.log2(f / f_hi)) / blend_octaves
    return np.where(delta <= 0, 1.0,
                    np.where(delta >= 1, 0.0, 0.5 * (1 + np.cos(np.pi * np.clip(delta, 0, 1)))))


def _dlog_weight_dlnf(x, f_lo, f_hi, h):
    """d w / d ln f at ln-frequencies ``x`` (non-zero only in the transition zones)."""
    f = np.exp(x)
    below = np.log2(f_lo / f) / h
    above = np.log2(f / f_hi) / h
    out = np.zeros_like(x)
    lo = (below > 0) & (below < 1)
    hi = (above > 0) & (above < 1)
    # d delta / d ln f = -1/(h ln2) below, +1/(h ln2) above
    out[lo] = 0.5 * np.pi * np.sin(np.pi * below[lo]) / (h * np.log(2))
    out[hi] = -0.5 * np.pi * np.sin(np.pi * above[hi]) / (h * np.log(2))
    return out


def bode_phase(frequency_hz, log_factor, f_lo, f_hi, blend_octaves=0.5) -> np.ndarray:
    r"""Minimum-phase phase [rad] of the gain :math:`\ln g = a\,w(f)` (Bode gain-phase).

    Midpoint rule over the two transition zones (:data:`_BODE_POINTS` points each; the
    kernel's log singularity is integrable).

    Parameters
    ----------
    frequency_hz : array_like
        [Hz]; 0 Hz gives 0.
    log_factor : float
        :math:`a = \ln(\text{factor})` [1].
    f_lo, f_hi, blend_octaves : float
        See :func:`band_weight`.
    """
    f0 = np.atleast_1d(np.asarray(frequency_hz, float))
    h = blend_octaves * np.log(2.0)
    zones = [(np.log(f_lo) - h, np.log(f_lo)), (np.log(f_hi), np.log(f_hi) + h)]
    xs, dxs = [], []
    for a, b in zones:
        dx = (b - a) / _BODE_POINTS
        xs.append(a + dx * (np.arange(_BODE_POINTS) + 0.5))
        dxs.append(np.full(_BODE_POINTS, dx))
    x = np.concatenate(xs)
    dx = np.concatenate(dxs)
    slope = log_factor * _dlog_weight_dlnf(x, f_lo, f_hi, blend_octaves) * dx
    out = np.zeros(f0.shape)
    pos = f0 > 0
    u = np.abs(x[None, :] - np.log(f0[pos])[:, None])
    kernel = np.log(1.0 / np.tanh(np.maximum(u, 1e-12) / 2.0))
    out[pos] = kernel @ slope / np.pi
    return out


def _gain(target: Target, frequency_hz) -> np.ndarray:
    r""":math:`g\,e^{i\varphi}` of the module docstring at ``frequency_hz`` [Hz]."""
    f = np.asarray(frequency_hz, float)
    a = np.log(target.factor)
    lng = a * band_weight(f, target.f_lo, target.f_hi, target.blend_octaves)
    return np.exp(lng + 1j * bode_phase(f, a, target.f_lo, target.f_hi, target.blend_octaves))


def network_at(model, target: Target, frequency_hz):
    """What a target retunes: ``(network, friction [N/m] per frequency, (ks, ds))``: at the
    target's amplitude the network scaled by its amplitude law and Berg's describing
    stiffness (0 at 0 Hz); without one ``model``, 0, factors 1."""
    f = np.asarray(frequency_hz, float)
    if target.amplitude is None:
        return model, np.zeros(f.shape), (1.0, 1.0)
    el = model.element()
    if not el.nonlinear:
        raise target.origin.error(f"{target.spec!r}: {target.mount}.{target.direction} has "
                                  "no amplitude law or friction: its K_CP does not depend on the amplitude")
    ks, ds = el.scales(target.amplitude)
    law = el.port_law
    k = 0.0 if law is None else complex(law.describing_stiffness(target.amplitude))
    return model.scaled(ks, ds), np.where(f == 0, 0.0, k), (ks, ds)


def fit_frequencies(target: Target) -> np.ndarray:
    """0 Hz plus :data:`N_FREQUENCIES` log-spaced from 1 Hz to max(1 kHz, 2^(h+1) f_hi) [Hz]."""
    f_max = max(F_MAX_HZ, 2.0 ** (target.blend_octaves + 1) * target.f_hi)
    return np.concatenate([[0.0], np.geomspace(F_MIN_HZ, f_max, N_FREQUENCIES)])


@dataclass(frozen=True)
class TargetFit(Result):
    r"""Outcome of a retune: ``baseline`` and retuned ``model``; K_CP (baseline, target,
    fitted) and K_IP (target, fitted) [N/m] at ``frequency_hz`` [Hz]; relative RMS errors
    ``rel_rms`` (K_CP) and ``kip_rel_rms`` [1]; in the band the largest
    :math:`|K_{fit}-K_t|/|K_t|` and the mean :math:`|K_{fit}|/|K_0| - 1` [1]; the refinement's
    ``start`` (``baseline`` or ``fit_mount``) and stage one's summary."""

    target: Target
    baseline: object
    model: object
    frequency_hz: np.ndarray
    kcp_baseline: np.ndarray
    kcp_target: np.ndarray
    kcp_fitted: np.ndarray
    kip_target: np.ndarray
    kip_fitted: np.ndarray
    rel_rms: float
    kip_rel_rms: float
    max_band_error: float
    mean_band_change: float
    start: str
    fit_summary: str

    @property
    def band(self) -> np.ndarray:
        """Mask of the fit frequencies inside the band."""
        f = self.frequency_hz
        return (f >= self.target.f_lo) & (f <= self.target.f_hi)

    def to_dict(self) -> dict:
        """JSON-ready summary (SI and percent)."""
        t = self.target
        return {"spec": t.spec, "mount": t.mount, "direction": t.direction,
                "requested_change_pct": 100 * (t.factor - 1), "band_hz": [t.f_lo, t.f_hi],
                "blend_octaves": t.blend_octaves, "model": self.model.topology.name,
                "kcp_rel_rms_pct": 100 * self.rel_rms, "kip_rel_rms_pct": 100 * self.kip_rel_rms,
                "max_band_error_pct": 100 * self.max_band_error,
                "achieved_mean_band_change_pct": 100 * self.mean_band_change, "refinement_start": self.start,
                "amplitude_mm": None if t.amplitude is None else 1e3 * t.amplitude,
                "fitted_params_si": dict(self.model.params)}

    def to_text(self) -> str:
        """:meth:`summary` (what ``powertrain whatif`` prints of the target)."""
        return self.summary()

    def summary(self) -> str:
        """The fit in one line: its errors over the range and in the band, the change."""
        t = self.target
        return (f"target {t.spec}: retuned {self.model.topology.name} (from the {self.start} "
                f"start): K_CP rel. RMS error {100 * self.rel_rms:.2f} %, K_IP "
                f"{100 * self.kip_rel_rms:.2f} % over {self.frequency_hz[1]:g}-"
                f"{self.frequency_hz[-1]:g} Hz; in the band max K_CP error "
                f"{100 * self.max_band_error:.2f} %, mean |K_CP| change "
                f"{100 * self.mean_band_change:+.2f} % (requested {100 * (t.factor - 1):+.2f} %)")

    def plot(self, ax=None, *, path=None, form="magnitude-phase", freq_axis="log", provenance=None):
        """Baseline, requested and fitted K_CP (:func:`powertrain.plotting.plot_retune`);
        returns the figure."""
        ax, path = target_and_path(ax, path)
        return plot_retune(self, path, ax=ax, form=form, freq_axis=freq_axis, provenance=provenance)


def _refine(topology, p0, free, f, kt_cp, kt_ip):
    """Joint least squares of K_CP and K_IP relative errors over log-factors of the free
    parameters of ``p0``; returns (parameters [SI], cost)."""
    w_cp, w_ip = 1.0 / np.abs(kt_cp), 1.0 / np.abs(kt_ip)

    def params(q):
        p = p0.copy()
        p[free] = p0[free] * np.exp(q)
        return p

    def residual(q):
        m = MountModel.from_values(topology, params(q))
        r1 = (m.cross_point_stiffness(f) - kt_cp) * w_cp
        r2 = (m.input_point_stiffness(f) - kt_ip) * w_ip
        return np.concatenate([r1.real, r1.imag, r2.real, r2.imag]) / np.sqrt(f.size)

    bound = np.log(REFINE_RANGE)
    with np.errstate(all="ignore"):
        r = least_squares(residual, np.zeros(int(free.sum())), bounds=(-bound, bound),
                          xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=REFINE_NFEV)
    return params(r.x), float(r.cost)


#: Range of each parameter's factor in the refinement: [1/R, R].
REFINE_RANGE = 1e3
#: Function evaluations of each refinement run.
REFINE_NFEV = 3000


def retune(model, target: Target, **fit_kwargs) -> TargetFit:
    """Retune ``model`` (same topology, laws kept) to the requested curve of ``target``.

    Parameters
    ----------
    model : MountModel
        Baseline model of the mount direction (SI).
    target : Target
        The requested change.
    **fit_kwargs
        Passed to :func:`powertrain.workflows.fitting.fit_mount`.

    Returns
    -------
    TargetFit
        Curves at the target's amplitude (with the friction).
    """
    f = fit_frequencies(target)
    net, k_fr, (ks, ds) = network_at(model, target, f)
    k0 = net.cross_point_stiffness(f) + k_fr
    kt = k0 * _gain(target, f)
    kip_t = net.input_point_stiffness(f) + k_fr + (kt - k0)
    fit = fit_mount(f, kt - k_fr, net.topology, **fit_kwargs)
    candidates = []
    for label, p0 in (("baseline", net.values), ("fit_mount", fit.model.values)):
        p, cost = _refine(net.topology, p0, p0 > 0, f, kt - k_fr, kip_t - k_fr)
        candidates.append((cost, label, p))
    cost, start, p = min(candidates, key=lambda c: c[0])
    at = MountModel.from_values(net.topology, p)
    fitted = dataclasses.replace(
        model, params=at.scaled(1.0 / ks, 1.0 / ds).params,
        name=f"{model.name or model.topology.description} retuned {target.spec}",
        source=f"powertrain whatif --target {target.spec}",
        notes=f"retuned from the baseline: K_CP changed by {target.spec} (Bode phase), "
              "K_IP by the same amount; joint K_CP/K_IP least squares")
    return _target_fit(target, model, fitted, f, k0, kt, kip_t,
                       at.cross_point_stiffness(f) + k_fr, at.input_point_stiffness(f) + k_fr,
                       start, fit.summary())


def _target_fit(target, model, fitted, f, k0, kt, kip_t, kf, kip_f, start, summary):
    band = (f >= target.f_lo) & (f <= target.f_hi)
    return TargetFit(target=target, baseline=model, model=fitted, frequency_hz=f,
                     kcp_baseline=k0, kcp_target=kt, kcp_fitted=kf, kip_target=kip_t,
                     kip_fitted=kip_f, rel_rms=relative_rms_error(kf, kt),
                     kip_rel_rms=relative_rms_error(kip_f, kip_t),
                     max_band_error=float(np.max(np.abs(kf[band] - kt[band]) / np.abs(kt[band]))),
                     mean_band_change=float(np.mean(np.abs(kf[band]) / np.abs(k0[band])) - 1),
                     start=start, fit_summary=summary)


def retuned_swap(engine, target: Target, **fit_kwargs):
    """Retune ``target``'s mount direction of ``engine``: ``(Swap, TargetFit)``."""
    target.check(engine)
    tf = retune(engine.mount(target.mount).directions[target.direction], target, **fit_kwargs)
    return Swap(target.mount, target.direction, tf.model, path=f"<fitted: {target.spec}>",
                spec=target.spec, origin=target.origin or Origin("--target")), tf
