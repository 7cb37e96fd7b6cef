r"""Amplitude, preload and friction laws of a mount direction (SI).

A mount file's ``[amplitude]``, ``[friction]`` and ``[static]`` sections become
:class:`PowerLaw` or :class:`TableLaw` (every spring and damper times a factor of the
amplitude :math:`A` across the mount, masses never scaled), :class:`BergFriction` (Berg 1998,
*A non-linear rubber spring model for rail vehicle dynamics analysis*, Vehicle System
Dynamics 30) and :class:`StaticCurve`; the thesis (Kovarik 2016, sec. 6) names amplitude
dependence as its model's main limitation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import PPoly

from powertrain.kernels.port_forces import BERG
from powertrain.kernels.transient import POWER_LAW, TABLE_LAW

#: Gauss–Legendre nodes per loop branch of Berg's describing function (the branch is smooth:
#: 48 nodes give the first harmonic to round-off).
_GAUSS_NODES = 48


def _read_only(*arrays):
    for a in arrays:
        a.setflags(write=False)
    return arrays


#: Gauss–Legendre nodes and weights on [-1, 1] (read-only).
_GAUSS_LEGENDRE = _read_only(*np.polynomial.legendre.leggauss(_GAUSS_NODES))


def _berg_rule():
    """1 + sin θ at the nodes on [-π/2, π/2] and the weights times sin θ and cos θ."""
    t, w = _GAUSS_LEGENDRE
    theta, wq = 0.5 * np.pi * t, 0.5 * np.pi * w
    return _read_only(1.0 + np.sin(theta), wq * np.sin(theta), wq * np.cos(theta))


_BERG_RULE = _berg_rule()


@dataclass(frozen=True)
class PowerLaw:
    r"""Factor :math:`f = \mathrm{clip}((A_{ref}/A)^{n}, lo, hi)` on every spring and
    :math:`f^{\gamma}` on every damper.

    Parameters
    ----------
    reference : float
        :math:`A_{ref}` [m]: the amplitude the network was measured and fitted at (> 0).
    exponent : float
        :math:`n` (0: amplitude independent).
    limits : tuple of float
        ``(lo, hi)``, 0 < lo <= 1 <= hi.
    damping_exponent : float
        :math:`\gamma` (1: constant loss factor; 0: dampers unchanged).
    """

    reference: float
    exponent: float
    limits: tuple = (0.2, 5.0)
    damping_exponent: float = 1.0

    @property
    def constant(self) -> bool:
        """True when the factor is 1 at every amplitude."""
        return self.exponent == 0.0

    def factor(self, amplitude) -> np.ndarray:
        """The factor at the amplitude(s) [m] (A = 0 counts as the smallest positive)."""
        a = np.maximum(np.asarray(amplitude, float), np.finfo(float).tiny)
        with np.errstate(over="ignore"):
            raw = (self.reference / a) ** self.exponent
        return np.clip(raw, *self.limits)

    def scales(self, amplitude):
        """``(stiffness factor, damping factor)`` at the amplitude [m]."""
        f = self.factor(amplitude)
        return f, (f if self.damping_exponent == 1.0 else f ** self.damping_exponent)

    def kernel_law(self):
        """``(kind, parameters, table)`` of :func:`powertrain.kernels.transient.amplitude_scales`."""
        return (POWER_LAW, (self.reference, self.exponent, *self.limits,
                            self.damping_exponent), ())


@dataclass(frozen=True)
class TableLaw:
    """Factors tabulated against amplitude, interpolated in log amplitude, flat outside.

    Parameters
    ----------
    amplitudes : tuple of float
        Strictly increasing, > 0 [m].
    stiffness_scale, damping_scale : tuple of float
        Factors (> 0) at those amplitudes; ``damping_scale`` defaults to ``stiffness_scale``.
    """

    amplitudes: tuple
    stiffness_scale: tuple
    damping_scale: tuple | None = None

    @property
    def constant(self) -> bool:
        d = self.stiffness_scale if self.damping_scale is None else self.damping_scale
        return all(v == 1.0 for v in self.stiffness_scale) and all(v == 1.0 for v in d)

    def scales(self, amplitude):
        """``(stiffness factor, damping factor)`` at the amplitude(s) [m]."""
        la = np.log(np.maximum(np.asarray(amplitude, float), self.amplitudes[0]))
        xp = np.log(np.asarray(self.amplitudes, float))
        ks = np.interp(la, xp, self.stiffness_scale)
        d = self.stiffness_scale if self.damping_scale is None else self.damping_scale
        return ks, np.interp(la, xp, d)

    def kernel_law(self):
        """``(kind, parameters, table)`` of :func:`powertrain.kernels.transient.amplitude_scales`."""
        d = self.stiffness_scale if self.damping_scale is None else self.damping_scale
        return (TABLE_LAW, (self.amplitudes[0], 0.0, 0.0, 0.0, 0.0),
                (np.log(np.asarray(self.amplitudes, float)), self.stiffness_scale, d))


@dataclass(frozen=True)
class StaticCurve:
    """A static force–deflection curve: the monotone cubic (PCHIP) through its points, straight
    beyond them; the network scales with its tangent stiffness relative to that at
    ``reference_deflection``.

    Parameters
    ----------
    deflection, force : tuple of float
        Datasheet points [m], [N], both strictly increasing.
    reference_deflection : float
        Where the dynamic data were measured [m].
    """

    deflection: tuple
    force: tuple
    reference_deflection: float = 0.0

    def force_at(self, x) -> np.ndarray:
        """Force [N] at the deflection(s) ``x`` [m]."""
        return CurveReader(self).force_at(x)

    def tangent_at(self, x) -> np.ndarray:
        """Tangent stiffness dF/dx [N/m] at the deflection(s) ``x`` [m]."""
        return CurveReader(self).tangent_at(x)

    def factor(self, x) -> np.ndarray:
        """Tangent stiffness at ``x`` over that at ``reference_deflection``."""
        return CurveReader(self).factor(x)


def pchip_cubic(x, y):
    """``(breaks, coefficients (n - 1, 4))`` of the monotone piecewise cubic Hermite
    interpolant through ``(x, y)`` in :class:`scipy.interpolate.PPoly`'s layout; the same
    operations as :class:`scipy.interpolate.PchipInterpolator` (Fritsch & Butland 1984, SIAM
    J. Sci. Stat. Comput. 5; end slopes: Moler 2004, *Numerical Computing with MATLAB*, §3.6)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    h = x[1:] - x[:-1]
    m = (y[1:] - y[:-1]) / h
    d = np.empty_like(y)
    if y.size == 2:
        d[:] = m[0]
    else:
        w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
        flat = (np.sign(m[1:]) != np.sign(m[:-1])) | (m[1:] == 0) | (m[:-1] == 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            d[1:-1] = np.where(flat, 0.0, 1.0 / ((w1 / m[:-1] + w2 / m[1:]) / (w1 + w2)))
        d[0] = _pchip_end(h[0], h[1], m[0], m[1])
        d[-1] = _pchip_end(h[-1], h[-2], m[-1], m[-2])
    t = (d[:-1] + d[1:] - 2 * m) / h
    return x, np.column_stack([t / h, (m - d[:-1]) / h - t, d[:-1], y[:-1]])


def _pchip_end(h0, h1, m0, m1):
    """Slope at an end from its segment ``h0``, ``m0`` and the next ``h1``, ``m1``."""
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return d


def curve_pchip(curve) -> PPoly:
    """The PCHIP (no extrapolation) force [N] of deflection [m] of a :class:`StaticCurve`."""
    x, c = pchip_cubic(curve.deflection, curve.force)
    return PPoly(c.T, x, extrapolate=False)


class CurveReader:
    """A :class:`StaticCurve` read many times: its PCHIP, derivative and ends built once."""

    def __init__(self, curve):
        x = np.asarray(curve.deflection, float)
        self.curve = curve
        self.pchip = curve_pchip(curve)
        self.slope = d = self.pchip.derivative()
        self.ends = (x[0], x[-1], float(self.pchip(x[0])), float(self.pchip(x[-1])),
                     float(d(x[0])), float(d(x[-1])))

    def force_at(self, x) -> np.ndarray:
        """Force [N] at the deflection(s) ``x`` [m]."""
        x0, x1, f0, f1, k0, k1 = self.ends
        x = np.asarray(x, float)
        inside = np.nan_to_num(self.pchip(np.clip(x, x0, x1)))
        return np.where(x < x0, f0 + k0 * (x - x0), np.where(x > x1, f1 + k1 * (x - x1), inside))

    def tangent_at(self, x) -> np.ndarray:
        """Tangent stiffness dF/dx [N/m] at the deflection(s) ``x`` [m]."""
        x0, x1, _, _, k0, k1 = self.ends
        x = np.asarray(x, float)
        inside = np.nan_to_num(self.slope(np.clip(x, x0, x1)))
        return np.where(x < x0, k0, np.where(x > x1, k1, inside))

    def factor(self, x) -> np.ndarray:
        """Tangent stiffness at ``x`` over that at the curve's ``reference_deflection``."""
        return self.tangent_at(x) / self.tangent_at(self.curve.reference_deflection)


@dataclass(frozen=True)
class BergFriction:
    r"""Berg's friction element in parallel with the network (a port law). From the last
    reversal point :math:`(x_s, F_s)`, with :math:`\alpha = F_s/F_{max}`, :math:`y = x - x_s`,

    .. math:: F = F_s + \frac{y}{x_2(1-\alpha) + y}(F_{max} - F_s)\ (y \ge 0),\qquad
              F = F_s + \frac{y}{x_2(1+\alpha) - y}(F_{max} + F_s)\ (y \le 0),

    Parameters
    ----------
    max_force : float
        :math:`F_{max}` [N] (>= 0; 0: no friction).
    half_displacement : float
        :math:`x_2` [m] (> 0): displacement from the unloaded state to half of ``max_force``.
    """

    max_force: float
    half_displacement: float
    kind = BERG

    def parameters(self) -> np.ndarray:
        return np.array([self.max_force, self.half_displacement], float)

    def initial_state(self, u0: float, f0: float = 0.0) -> np.ndarray:
        """State ``[x_s, F_s, direction, u_last, F_last]`` at ``u0`` on the virgin curve
        carrying ``f0`` (clipped inside ±max_force)."""
        fm = self.max_force
        f = float(np.clip(f0, -0.999 * fm, 0.999 * fm)) if fm > 0 else 0.0
        if f == 0.0:
            return np.array([u0, 0.0, 0.0, u0, 0.0])
        # virgin branch from (x_s, 0): f = y/(x2 + y) fm (y > 0), f = y/(x2 - y) fm (y < 0)
        x2 = self.half_displacement
        y = f * x2 / (fm - abs(f))
        return np.array([u0 - y, 0.0, np.sign(f), u0, f])

    def steady_state(self, amplitude: float, centre: float = 0.0) -> np.ndarray:
        """State just reversed at the lower tip of the steady loop of ``amplitude`` [m] about
        ``centre`` [m], moving up."""
        fr = float(self.loop_amplitude_force(amplitude))
        low = centre - amplitude
        return np.array([low, -fr, 1.0, low, -fr])

    @property
    def initial_stiffness(self) -> float:
        """Tangent stiffness at a reversal point [N/m]: F_max / x2."""
        return self.max_force / self.half_displacement

    def loop_amplitude_force(self, amplitude) -> np.ndarray:
        r"""Force at the tips :math:`\pm A` of the symmetric steady loop [N]: the root of
        :math:`(x_2/F_{max})F_r^2 + (x_2 + A)F_r - A F_{max} = 0`."""
        A = np.asarray(amplitude, float)
        fm, x2 = self.max_force, self.half_displacement
        if fm <= 0:
            return np.zeros_like(A)
        b = x2 + A
        return 2 * A * fm / (b + np.sqrt(b * b + 4 * x2 * A))

    def describing_stiffness(self, amplitude) -> np.ndarray:
        r"""Equivalent complex stiffness [N/m] at the amplitude [m]: the first harmonic
        :math:`k_{eq} = \frac{2}{\pi A}\int_{-\pi/2}^{\pi/2} F_\uparrow(\theta)
        (\sin\theta + i\cos\theta)\,d\theta` of the steady loop."""
        A = np.atleast_1d(np.asarray(amplitude, float))
        out = np.full(A.shape, self.initial_stiffness + 0j if self.max_force > 0 else 0j)
        big = A > 1e-12 * self.half_displacement
        if self.max_force <= 0 or not big.any():
            return out.reshape(np.shape(amplitude))
        a = A[big][:, None]
        one_plus_sin, w_sin, w_cos = _BERG_RULE
        fr = self.loop_amplitude_force(a)
        fm, x2 = self.max_force, self.half_displacement
        y = a * one_plus_sin                                # from the reversal at -A
        fs = -fr
        f = fs + y / (x2 * (1 - fs / fm) + y) * (fm - fs)
        scale = 2 / (np.pi * a[:, 0])
        out[big] = scale * (f @ w_sin) + 1j * (scale * (f @ w_cos))
        return out.reshape(np.shape(amplitude))

    def energy_per_cycle(self, amplitude) -> np.ndarray:
        """Energy dissipated per cycle of the steady loop at the amplitude [J]."""
        A = np.asarray(amplitude, float)
        return np.pi * A ** 2 * np.imag(self.describing_stiffness(A))
