r"""An independent integration of a transient on the assembled model (6-DOF body, every
mount network with its internal coordinates), any mount direction with a static curve, the
power amplitude law and Berg's friction: ``scipy.integrate.solve_ivp`` on the first-order
form, the three laws written out here from their published formulas (none of
:mod:`powertrain.physics.mount_laws` is called: only the laws' parameters are read):

* the static curve :math:`F(\delta)`: the monotone piecewise-cubic Hermite interpolant of
  Fritsch and Carlson with the derivatives of Fritsch and Butland (weighted harmonic mean
  inside, the shape-preserving three-point formula at the ends; Moler, *Numerical Computing
  with MATLAB*, sec. 3.4), straight beyond its points with the end slope; static factor
  :math:`f = F'(\delta)/F'(\delta_{ref})`;
* the power law: stiffness and damping factor :math:`s(A) = \mathrm{clip}((A_{ref}/A)^n,
  lo, hi)` at the amplitude :math:`A = \sqrt2\,\mathrm{std}(u)` of the deflection over the
  stretch before (the load's samples; 0 at a start from rest);
* Berg's element (Berg 1998, Vehicle System Dynamics 30) in parallel with the network: from
  the last reversal :math:`(x_s, F_s)` in the direction :math:`d`, :math:`F = F_s + y(F_m -
  dF_s)/(x_2(1 - dF_s/F_m) + dy)`, :math:`y = u - x_s`; from the unloaded start :math:`F =
  F_m y/(x_2 + |y|)`; a reversal (:math:`\dot u = 0`) is a terminal event that starts the
  next branch.

Each network :math:`n` (deflection :math:`u = \mathbf r^T\mathbf x` from the zero-torque
static point, where its curve deflection is :math:`\delta_0`) has its springs scaled by
:math:`\kappa = f(\delta)\,s(A)` and its dampers by :math:`f(\delta)\,s(A)` and is loaded
at its port by :math:`c = F(\delta) - F(\delta_0) - f k_0 (u - \bar u) - \kappa k_0 \bar u`
(:math:`k_0` its static stiffness at unit scale, :math:`\bar u` its centre: the mean of
:math:`u` over the stretch before, the deflection itself at the first), so that its static
force is the curve plus :math:`(\kappa - f) k_0 (u - \bar u)`: the amplitude law on the
motion about the centre. ``continuous=True``
evaluates :math:`f` and :math:`c` at every instant (the curve itself); ``continuous=False``
freezes them at every curve update (``integrate``'s ``curve_every``: the stretch rule of
:mod:`powertrain.solvers.transient`). The linear network matrices at unit scale are the
assembled model's (:meth:`AssembledSystem.network_parts`). Used by tests/test_transient.py
and scripts/bench_transient.py.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
from scipy.integrate import solve_ivp

from powertrain.models.mount import MountModel
from powertrain.physics.mount_laws import StaticCurve
from powertrain.solvers.operating_point import StaticSupport, operating_point

KV = """[mount]
name = "Kelvin-Voigt test mount"
model = "kelvin-voigt"
[units]
c = "N/mm"
d = "N*s/mm"
x = "mm"
F = "N"
[parameters]
c1 = 123.0
d1 = 0.4
"""
#: The nonlinear direction's laws (mount-file units): power law, Berg friction, static curve.
LAWS = """[amplitude]
law = "power"
reference = 0.1
exponent = 0.15
[friction]
max_force = 40.0
half_displacement = 0.05
[static]
deflection = [-12.0, -9.0, -7.0, -5.0, -3.0, 0.0, 3.0, 6.0, 9.0]
force = [-2743.42, -1419.01, -851.41, -586.52, -359.48, 0.0, 312.18, 662.2, 1419.01]
reference_deflection = -5.0
"""


def write_case(folder, default_engine_text, nonlinear="left.z"):
    """An engine file in ``folder`` whose mounts are all ``KV``, the direction
    ``nonlinear`` with ``LAWS`` too; returns its path."""
    (folder / "kv.toml").write_text(KV, encoding="utf-8")
    (folder / "kv-nl.toml").write_text(KV + LAWS, encoding="utf-8")
    mount, direction = nonlinear.split(".")
    lines = []
    current = None
    for line in default_engine_text.splitlines():
        if line.startswith("[mounts."):
            current = line.strip()[len("[mounts."):-1]
        if line.startswith("files = {") and current is not None:
            files = {d: "kv-nl.toml" if (current, d) == (mount, direction) else "kv.toml"
                     for d in "xyz"}
            line = "files = {" + ", ".join(f'{d} = "{f}"' for d, f in files.items()) + "}"
        lines.append(line)
    path = folder / "engine.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


#: The z-nonlinear mount's static curve shape [mm, N] (its tangent at 0 set to each
#: direction's static stiffness by :func:`with_curve_laws`).
SHAPE_MM = (-12.0, -9.0, -7.0, -5.0, -3.0, 0.0, 3.0, 6.0, 9.0)
SHAPE_N = (-2743.42, -1419.01, -851.41, -586.52, -359.48, 0.0, 312.18, 662.2, 1419.01)


def with_curve_laws(engine, **laws):
    """``engine`` with every mount direction on a static curve (:data:`SHAPE_N` scaled to
    its static stiffness at 0, reference deflection 0) and ``laws`` (``port_law``,
    ``amplitude_law``)."""
    x = np.array(SHAPE_MM) * 1e-3
    tangent0 = pchip_slopes(x, np.array(SHAPE_N))[list(SHAPE_MM).index(0.0)]

    def model(mod):
        k0 = mod.static_stiffness()
        curve = StaticCurve(tuple(x), tuple(f * k0 / tangent0 for f in SHAPE_N), 0.0)
        return MountModel(mod.topology, dict(mod.params), name=mod.name, static_curve=curve,
                          **laws)
    mounts = [dataclasses.replace(m, directions={a: model(mod) for a, mod in
                                                 m.directions.items()})
              for m in engine.mounts]
    return dataclasses.replace(engine, mounts=mounts)


def pchip_slopes(x, y):
    """Derivatives at the points of the monotone cubic through ``(x, y)`` (module
    docstring)."""
    h, m = np.diff(x), np.diff(y) / np.diff(x)
    d = np.zeros(x.size)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    same = (m[:-1] * m[1:]) > 0
    d[1:-1][same] = (w1 + w2)[same] / (w1[same] / m[:-1][same] + w2[same] / m[1:][same])
    for e, (h0, h1, m0, m1) in ((0, (h[0], h[1], m[0], m[1])), (-1, (h[-1], h[-2], m[-1],
                                                                      m[-2]))):
        end = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
        if np.sign(end) != np.sign(m0):
            end = 0.0
        elif np.sign(m0) != np.sign(m1) and abs(end) > abs(3 * m0):
            end = 3 * m0
        d[e] = end
    return d


class Curves:
    """Static curves of some networks, evaluated together: force and tangent at the
    deflections (one per curve), the Hermite cubic inside, straight outside."""

    def __init__(self, curves):
        self.x = np.array([np.asarray(c.deflection, float) for c in curves])
        self.y = np.array([np.asarray(c.force, float) for c in curves])
        self.d = np.array([pchip_slopes(x, y) for x, y in zip(self.x, self.y)])
        self.rows = np.arange(len(curves))
        ref = np.array([c.reference_deflection for c in curves], float)
        self.ref_tangent = self(ref)[1]

    def __call__(self, delta):
        """``(force [N], tangent [N/m])`` at the deflections ``delta`` [m]."""
        x, y, d, r = self.x, self.y, self.d, self.rows
        j = np.clip((x <= delta[:, None]).sum(1) - 1, 0, x.shape[1] - 2)
        h = x[r, j + 1] - x[r, j]
        t = np.clip((delta - x[r, j]) / h, 0.0, 1.0)
        y0, y1, d0, d1 = y[r, j], y[r, j + 1], d[r, j] * h, d[r, j + 1] * h
        f = ((2 * t**3 - 3 * t**2 + 1) * y0 + (t**3 - 2 * t**2 + t) * d0
             + (-2 * t**3 + 3 * t**2) * y1 + (t**3 - t**2) * d1)
        k = ((6 * t**2 - 6 * t) * y0 + (3 * t**2 - 4 * t + 1) * d0
             + (-6 * t**2 + 6 * t) * y1 + (3 * t**2 - 2 * t) * d1) / h
        lo, hi = delta < x[:, 0], delta > x[:, -1]
        f = np.where(lo, y[:, 0] + d[:, 0] * (delta - x[:, 0]),
                     np.where(hi, y[:, -1] + d[:, -1] * (delta - x[:, -1]), f))
        k = np.where(lo, d[:, 0], np.where(hi, d[:, -1], k))
        return f, k


def power_scale(law, amplitude):
    """The power law's factor at the amplitudes [m] (module docstring)."""
    a = np.maximum(amplitude, np.finfo(float).tiny)
    with np.errstate(over="ignore"):
        return np.clip((law.reference / a) ** law.exponent, *law.limits)


class Berg:
    """Berg's elements of some networks: branch states and force (module docstring)."""

    def __init__(self, laws):
        self.fm = np.array([law.max_force for law in laws], float)
        self.x2 = np.array([law.half_displacement for law in laws], float)
        self.xs, self.fs, self.d = (np.zeros(len(laws)) for _ in range(3))

    def force(self, u):
        """``(force [N], tangent [N/m])`` at the deflections ``u`` [m]."""
        y, fm, fs, d, x2 = u - self.xs, self.fm, self.fs, self.d, self.x2
        virgin = d == 0
        den = np.where(virgin, x2 + np.abs(y), x2 * (1 - d * fs / fm) + d * y)
        num = np.where(virgin, fm, fm - d * fs)
        f = fs + y * num / den
        k = np.where(virgin, fm * x2, num * x2 * (1 - d * fs / fm)) / den ** 2
        return f, k

    def reverse(self, e, u):
        """Start element ``e``'s next branch at the deflection ``u`` [m]."""
        f = self.force(np.full(self.fm.size, u))[0][e]
        self.d[e] = -np.sign(u - self.xs[e]) if self.d[e] == 0 else -self.d[e]
        self.xs[e], self.fs[e] = u, f


class Oracle:
    """The first-order form ``(x, v)`` of the assembled model under a load (module
    docstring); ``self(t, y)`` is the right-hand side, :meth:`jac` its Jacobian (exact but
    for the static factors' slope)."""

    def __init__(self, engine, system, load_t, load_F, continuous=True, deadline=None):
        """``deadline``: ``time.process_time()`` after which a call raises TimeoutError."""
        els = [n[3] for n in system.networks]
        self.n, self.R = system.n_dof, system.port_rows
        self.Minv = np.linalg.inv(system.M)
        self.Cp, self.Kp, self.gk, self.gd = system.network_parts()
        self.fmap = system.port_force_map
        support = StaticSupport.of(engine)
        self.k0 = support.stiffness
        rpm = engine.speed_range_rpm()[0]
        self.d0 = operating_point(engine, rpm, support,
                                  mean_torque=0.0).deflection.ravel()
        self.ic = np.array([k for k, c in enumerate(support.curves) if c is not None], int)
        self.curves = Curves([support.curves[k] for k in self.ic]) if self.ic.size else None
        self.f0 = self.curves(self.d0[self.ic])[0] if self.ic.size else None
        self.ia = [k for k, el in enumerate(els) if el.amplitude_law is not None]
        self.amp_laws = [els[k].amplitude_law for k in self.ia]
        self.ib = np.array([k for k, el in enumerate(els) if el.port_law is not None], int)
        self.berg = Berg([els[k].port_law for k in self.ib])
        self.t, self.F = load_t, np.zeros((load_t.size, self.n))
        self.F[:, :6] = load_F
        self.continuous, self.deadline = continuous, deadline
        self.scale, self.centre = np.ones(len(els)), np.zeros(len(els))
        self.frozen = None

    def set_stretch(self, y, amplitudes, centres, half):
        """The amplitude scales and centres of the stretch (None: the deflection at the
        state ``y``) and, for the stretch rule, the first piece's static factors and curve
        loads (:meth:`freeze`)."""
        self.scale = np.ones(self.k0.size)
        for k, law in zip(self.ia, self.amp_laws):
            self.scale[k] = power_scale(law, amplitudes[k])
        self.centre = self.R @ y[:self.n] if centres is None else np.asarray(centres, float)
        self.freeze(y, half)

    def freeze(self, y, half):
        """For the stretch rule, the static factors and curve loads of a piece starting at
        the state ``y`` (positions, velocities): at its positions ``half`` [s] (half the
        piece) on at its velocities, the piece's predicted middle."""
        x, v = y[:self.n], y[self.n:]
        self.frozen = None if self.continuous else self.static(self.R @ (x + half * v))

    def static(self, u):
        """Static factors (n_net,) and curve loads c (n_net,) [N] at the deflections u."""
        f, c = np.ones(u.size), np.zeros(u.size)
        if self.ic.size:
            i, ub = self.ic, self.centre[self.ic]
            force, tangent = self.curves(self.d0[i] + u[i])
            f[i] = tangent / self.curves.ref_tangent
            kap = f[i] * self.scale[i] * self.k0[i]
            c[i] = force - self.f0 - f[i] * self.k0[i] * (u[i] - ub) - kap * ub
        return f, c

    def parts(self, y):
        """``(kappa, c, z, dz/du, dF/du of the curves)`` at the state ``y``."""
        u = self.R @ y[:self.n]
        f, c = self.static(u) if self.frozen is None else self.frozen
        kap = f * self.scale
        z, kz = np.zeros(u.size), np.zeros(u.size)
        if self.ib.size:
            z[self.ib], kz[self.ib] = self.berg.force(u[self.ib])
        return kap, c, z, kz

    def __call__(self, t, y):
        if self.deadline is not None and time.process_time() > self.deadline:
            raise TimeoutError("solve_ivp attempt over its CPU-time cap")
        x, v = y[:self.n], y[self.n:]
        kap, c, z, _ = self.parts(y)
        i = min(max(int(np.searchsorted(self.t, t, side="right")) - 1, 0), self.t.size - 2)
        w = min(max((t - self.t[i]) / (self.t[i + 1] - self.t[i]), 0.0), 1.0)
        load = self.F[i] * (1.0 - w) + self.F[i + 1] * w
        inner = (np.tensordot(kap, self.Kp, 1) @ x + np.tensordot(kap, self.Cp, 1) @ v
                 + self.R.T @ (c + z))
        return np.concatenate([v, self.Minv @ (load - inner)])

    def jac(self, t, y):
        kap, _, _, kz = self.parts(y)
        K = np.tensordot(kap, self.Kp, 1) + self.R.T @ (kz[:, None] * self.R)
        if self.ic.size and self.frozen is None:
            u = self.R @ y[:self.n]
            tangent = self.curves(self.d0[self.ic] + u[self.ic])[1]
            dc = np.zeros(u.size)
            dc[self.ic] = tangent - tangent / self.curves.ref_tangent * self.k0[self.ic]
            K += self.R.T @ (dc[:, None] * self.R)
        J = np.zeros((2 * self.n, 2 * self.n))
        J[:self.n, self.n:] = np.eye(self.n)
        J[self.n:, :self.n] = -self.Minv @ K
        J[self.n:, self.n:] = -self.Minv @ np.tensordot(kap, self.Cp, 1)
        return J

    def outputs(self, Y):
        """Network deflections (m, n_net) [m] and channel forces (m, n_ch) [N] of the
        states ``Y`` (m, 2n)."""
        U, out = Y[:, :self.n] @ self.R.T, []
        for y in Y:
            kap, c, z, _ = self.parts(y)
            per = kap * (self.gk @ y[:self.n] + self.gd @ y[self.n:]) + c + z
            out.append(self.fmap @ per)
        return U, np.array(out)

    def reverse(self, fired, t, y):
        """Start the next branch of each element at ``(t, y)`` whose event ``fired`` or
        whose velocity is already against its branch (two reversals in one step), when
        its acceleration turns it back (not where its velocity only grazes zero)."""
        acc = self.R[self.ib] @ self(t, y)[self.n:]
        for e, g in enumerate(self.events):
            u = float(self.R[self.ib[e]] @ y[:self.n])
            back = -np.sign(u - self.berg.xs[e]) if self.berg.d[e] == 0 else -self.berg.d[e]
            if (fired[e].size or g(t, y) < 0) and np.sign(acc[e]) == back:
                self.berg.reverse(e, u)

    def reversals(self):
        """One terminal event per Berg element: its velocity against its direction (from
        the unloaded start: the deflection's distance from the start shrinking)."""
        def event(e):
            row = self.R[self.ib[e]]

            def g(t, y):
                ud = row @ y[self.n:]
                d = self.berg.d[e]
                return ud * (row @ y[:self.n] - self.berg.xs[e]) if d == 0 else d * ud
            g.terminal, g.direction = True, -1
            return g
        self.events = [event(e) for e in range(self.ib.size)]
        return self.events


def integrate(ode, every, rtol=1e-8, method="Radau", atol=None, curve_every=None):
    """Network deflections and channel forces (n_t, n_net), (n_t, n_ch) at the load's
    times, stretch by stretch from rest (``solve_ivp``'s ``method``; ``atol`` default
    ``1e-3 rtol``, a millimetre's share; :meth:`Oracle.jac` for the implicit methods); for
    the stretch rule the curves frozen anew every ``curve_every`` steps (default: each
    stretch's start)."""
    t_all = ode.t
    bounds = list(range(0, t_all.size - 1, every)) + [t_all.size - 1]
    y = np.zeros(2 * ode.n)
    U, force = np.empty((t_all.size, ode.R.shape[0])), np.empty((t_all.size,
                                                                  ode.fmap.shape[0]))
    amplitudes, centres = np.zeros(ode.R.shape[0]), None
    options = {"jac": ode.jac} if method in ("Radau", "BDF", "LSODA") else {}
    solver = dict(method=method, rtol=rtol, atol=1e-3 * rtol if atol is None else atol,
                  events=ode.reversals() or None, **options)
    sub = every if curve_every is None else curve_every
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        cuts = list(range(lo, hi, sub)) + [hi]
        ode.set_stretch(y, amplitudes, centres, 0.5 * (t_all[cuts[1]] - t_all[lo]))
        rows = [ode.outputs(y[None, :])]
        for p, q in zip(cuts[:-1], cuts[1:]):
            if p != lo:             # the update's instant reported with the new curve loads
                ode.freeze(y, 0.5 * (t_all[q] - t_all[p]))
                u_last, f_last = rows[-1]
                rows[-1] = (u_last, np.vstack([f_last[:-1], ode.outputs(y[None, :])[1]]))
            y = _piece(ode, t_all[p:q + 1], y, solver, rows)
        U[lo:hi + 1] = np.vstack([r[0] for r in rows])
        force[lo:hi + 1] = np.vstack([r[1] for r in rows])
        amplitudes = np.sqrt(2.0) * np.std(U[lo:hi], axis=0)
        centres = U[lo:hi].mean(0)
    return U, force


def _piece(ode, grid, y, solver, rows):
    """Integrate from ``grid[0]`` to ``grid[-1]`` through the Berg reversals, appending the
    outputs at ``grid[1:]`` to ``rows``; the end state."""
    t = grid[0]
    while True:
        try:
            sol = solve_ivp(ode, (t, grid[-1]), y, dense_output=True, **solver)
        except ValueError as exc:          # an event's root outside its bracket
            raise RuntimeError(f"solve_ivp {solver['method']}: {exc}") from exc
        inside = grid[(grid > t) & (grid <= sol.t[-1])]
        if inside.size:
            rows.append(ode.outputs(sol.sol(inside).T))
        y = sol.y[:, -1]
        if sol.status == -1:
            raise RuntimeError(f"solve_ivp {solver['method']}: {sol.message}")
        if sol.status != 1:
            return y
        t = sol.t[-1]
        ode.reverse(sol.t_events, t, y)
