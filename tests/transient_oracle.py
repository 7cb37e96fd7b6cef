"""An independent integration of a transient on a 6-DOF body whose mounts are Kelvin-Voigt
networks, one direction of one mount with a static curve, an amplitude law and Berg's
friction: ``scipy.integrate.solve_ivp`` (Radau) on the first-order form, the laws written
out here from their definitions (:mod:`powertrain.physics.mount_laws`) and the stretch rule
of :mod:`powertrain.solvers.transient`:

* every stretch (the transient's, ``every`` steps) starts with the curve's force at the
  deflection there, :math:`S = F(\\delta_c) - F(\\delta_0)`, and the network's tangent
  :math:`k = f\\,s_k(A)\\,k_0` (static factor :math:`f = F'(\\delta_c)/F'(\\delta_{ref})`,
  the power law's factor :math:`s_k(A) = \\mathrm{clip}((A_{ref}/A)^n, lo, hi)` at the
  amplitude :math:`A = \\sqrt2\\,\\mathrm{std}(u)` of the stretch before, 0 at the start),
  damper :math:`f\\,s_d(A)\\,c_0`; inside it the network's force is
  :math:`S + k(u - u_c) + c\\dot u`;
* Berg's element in parallel, its force a state: on a branch from its reversal point
  :math:`(x_s, F_s)` in direction :math:`d`, :math:`dF/du = F_m (F_m - dF)^2 / (x_2 (F_m -
  dF_s)^2)`; a reversal (:math:`\\dot u = 0`) is a terminal event that starts the next
  branch (tests/test_transient.py; the peer of scripts/bench_transient.py).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

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


class StretchODE:
    """The first-order form ``(x, v, z)`` of the case (module docstring)."""

    def __init__(self, engine, system, load_t, load_F, network):
        support = StaticSupport.of(engine)
        self.n = network
        self.rows = system.port_rows[:, :6]
        self.Minv = np.linalg.inv(system.M[:6, :6])
        lin = np.ones(self.rows.shape[0], bool)
        lin[network] = False
        el = system.networks[network][3]
        self.k0, self.c0 = support.stiffness[network], el.lumped[3][0]
        c_lin = np.array([e[3].lumped[3][0] for e in system.networks])
        R = self.rows[lin]
        self.K = R.T @ (support.stiffness[lin][:, None] * R)
        self.C = R.T @ (c_lin[lin][:, None] * R)
        self.curve, self.law, self.berg = support.curves[network], el.amplitude_law, el.port_law
        rpm = engine.speed_range_rpm()[0]
        self.d0 = operating_point(engine, rpm, support, mean_torque=0.0).deflection.ravel()[network]
        self.t, self.F = load_t, load_F
        self.stretch = (0.0, 0.0, 0.0, 0.0)            # S, k, c, u_c
        self.Fs, self.d = 0.0, 1.0

    def begin(self, x, amplitude):
        """Set the stretch's curve force, tangent and damper at the state ``x``."""
        u = float(self.rows[self.n] @ x)
        d = self.d0 + u
        f = float(self.curve.factor(d))
        ks, ds = self.law.scales(amplitude)
        S = float(self.curve.force_at(d) - self.curve.force_at(self.d0))
        self.stretch = (S, f * float(ks) * self.k0, f * float(ds) * self.c0, u)

    def network_force(self, y):
        S, k, c, uc = self.stretch
        r = self.rows[self.n]
        return S + k * (r @ y[:6] - uc) + c * (r @ y[6:12]) + y[12]

    def __call__(self, t, y):
        x, v, z = y[:6], y[6:12], y[12]
        i = min(max(int(np.searchsorted(self.t, t, side="right")) - 1, 0), self.t.size - 2)
        w = min(max((t - self.t[i]) / (self.t[i + 1] - self.t[i]), 0.0), 1.0)
        load = self.F[i] * (1.0 - w) + self.F[i + 1] * w
        r = self.rows[self.n]
        a = self.Minv @ (load - self.K @ x - self.C @ v - r * self.network_force(y))
        fm, x2 = self.berg.max_force, self.berg.half_displacement
        kt = fm * (fm - self.d * z) ** 2 / (x2 * (fm - self.d * self.Fs) ** 2)
        return np.concatenate([v, a, [kt * (r @ v)]])

    def reversal(self):
        def event(t, y):
            return self.rows[self.n] @ y[6:12]
        event.terminal = True
        event.direction = -self.d
        return event


def integrate(ode, every, rtol=1e-8, method="Radau"):
    """Deflection and force of the nonlinear network at the load's times, stretch by
    stretch from rest (``solve_ivp``'s ``method``)."""
    t_all = ode.t
    bounds = list(range(0, t_all.size - 1, every)) + [t_all.size - 1]
    y = np.zeros(13)
    u, force = np.empty(t_all.size), np.empty(t_all.size)
    amplitude = 0.0
    for lo, hi in zip(bounds[:-1], bounds[1:]):
        ode.begin(y[:6], amplitude)
        t, t_end, grid = t_all[lo], t_all[hi], t_all[lo:hi + 1]
        Y = [y]
        while True:
            sol = solve_ivp(ode, (t, t_end), y, method=method, rtol=rtol, atol=1e-14,
                            dense_output=True, events=ode.reversal())
            inside = grid[(grid > t) & (grid <= sol.t[-1])]
            Y += list(sol.sol(inside).T) if inside.size else []
            y = sol.y[:, -1]
            if sol.status != 1:
                break
            t = sol.t[-1]
            ode.Fs, ode.d = y[12], -ode.d
        Y = np.array(Y)
        u[lo:hi + 1] = Y @ np.r_[ode.rows[ode.n], np.zeros(7)]
        force[lo:hi + 1] = [ode.network_force(row) for row in Y]
        amplitude = np.sqrt(2.0) * np.std(u[lo:hi])
    return u, force
