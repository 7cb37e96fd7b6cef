r"""Cached frequency-domain model for many cheap re-solves (diagnosis, truth generation).

:class:`HarmonicModel` caches the load harmonics :math:`\hat{\mathbf f}_{r,h}` (speed r,
harmonic h = 0..16: orders 0..8) [N, N·m] and each network's two-port :math:`(a, b, c)`,
internal masses condensed (:math:`a = K_{IP}`, :math:`b = -K_{CP}` on a rigid ground; scaling
springs, dampers and masses by :math:`s` scales it by :math:`s`), and solves at once

.. math:: \Big(-\omega_h^2\mathbf M_{rb} + \sum_n K_{IP,n}(\omega_h)\,
          \mathbf r_n\mathbf r_n^T\Big)\hat{\mathbf q}_{r,h} = \hat{\mathbf f}_{r,h},

channel velocities :math:`\hat{\mathbf v} = i\omega_h\mathbf C\hat{\mathbf q}` (the numbers of
:func:`powertrain.workflows.runup.run_runup` with ``solver="harmonic"``, tests/test_diagnose.py).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from powertrain.analysis.channel import DIRECTIONS
from powertrain.analysis.fourier import harmonic_amplitudes
from powertrain.physics import balancer as bal
from powertrain.physics.condensation import harmonic_solve
from powertrain.physics.mount_elements import element_two_ports
from powertrain.physics.mount_network import PackedNetworks, laplace_two_ports
from powertrain.solvers.body_coupling import (
    ModalBody,
    coupled_rows,
    coupled_solve,
    one_more_mode,
    one_more_mode_basis,
)
from powertrain.solvers.operating_point import has_static_curves, static_factors

#: Harmonics of the engine cycle solved: h = 1..16 are orders 0.5..8.
N_HARMONICS = 17
#: Samples per engine cycle for the load harmonics (1° like the run-up default).
N_ANGLE = 720


def static_factor_table(engine, rpm):
    """Static factors (n_r, n_net) of every network of ``engine`` at the speeds ``rpm``
    [rpm], or None when no mount direction has a static curve."""
    if not has_static_curves(engine):
        return None
    return np.array([static_factors(engine, r) for r in np.atleast_1d(rpm)])


def shaft_load(engine, shaft, rpm, theta):
    """Generalized load (n, 6) [N, N·m] about the CG of the balancer ``shaft``'s centrifugal
    force at ``rpm`` [rpm] and crank angles ``theta`` (n,) [rad], balancer enabled or not."""
    ct = engine.crank
    omega = rpm * 2 * np.pi / 60.0
    f_u, f_s = bal.shaft_force(theta, omega, shaft.mass_radius, shaft.phase, shaft.sense,
                               engine.balancer.ratio)
    F = f_u[:, None] * ct.cylinder_axis + f_s[:, None] * ct.lateral_axis
    Mo = np.cross(np.asarray(shaft.position, float) - engine.body.cg, F)
    return np.hstack([F, Mo])


#: Prefix of the cached velocities of load parts in ``HarmonicModel._extra``.
_VELOCITY_OF = "velocity of "
#: Cache keys of :meth:`HarmonicModel.solve_one_more_mode`'s basis.
_ONE_MORE_MODE = tuple(f"one more mode {k}" for k in ("x0", "W", "P", "G", "c"))


class HarmonicModel:
    """Frequency-domain model of an engine at fixed speeds, with cached load harmonics.

    Parameters
    ----------
    engine : Engine
    rpm : array_like
        Speeds [rpm] (inside the engine's range).
    n_angle : int
        Samples per engine cycle for the load harmonics.
    system : AssembledSystem, optional
        The system this is a frequency view of; default ``engine.assemble()``.

    Attributes
    ----------
    omega : ndarray (n_r, 17)
        Angular frequency of harmonic h at each speed, :math:`h\\Omega/2` [rad/s].
    rows : ndarray (n_net, 6)
        Network direction rows :math:`\\mathbf r_n`.
    channel_matrix : ndarray (n_ch, 6)
        Rigid-body coordinates to mount-point motion in engine X/Y/Z.
    networks : list of (mount index, axis name, MountModel)
    elements : list of MountElement
        One per network (nonlinear ones: :meth:`two_ports_at`).
    packed : PackedNetworks
    """

    def __init__(self, engine, rpm, n_angle=N_ANGLE, system=None):
        self.engine = engine
        self.rpm = np.atleast_1d(np.asarray(rpm, float))
        self.n_angle = int(n_angle)
        self.theta = 4 * np.pi * np.arange(self.n_angle) / self.n_angle
        Omega = self.rpm * 2 * np.pi / 60.0
        self.omega = 0.5 * Omega[:, None] * np.arange(N_HARMONICS)[None, :]
        self.system = engine.assemble() if system is None else system
        ports = self.system.ports()
        self.M = ports.frame[0][:6, :6]
        self.rows = ports.engine_rows[:, :6]
        self.networks = [(mi, axis, m.directions[axis]) for mi, m in enumerate(engine.mounts)
                         for axis in DIRECTIONS]
        self.elements = list(ports.elements)
        self.packed = PackedNetworks.of([el.lumped for el in self.elements])
        #: static factor (n_r, n_net) of every network per speed; None without curves
        self.static_scale = static_factor_table(engine, self.rpm)
        n_a = self.system.n_mount_channels
        self.channel_matrix = self.system.channel_matrix[:n_a, :6]
        self.channels = list(self.system.channels[:n_a])
        self.mount_names = list(self.system.mount_names)
        self._load = None
        self._abc = None
        self._extra = {}
        self._scaled = {}
        self._scaled_last = None
        self._packed_of = {}
        self._one_more_mode_at = None
        self._effect_defaults = {}
        self._body_setup(engine, ports)

    def _body_setup(self, engine, ports):
        """The modal body under the mounts and its passive-side and body-point channels."""
        self.body = ModalBody.of(engine)
        self._body_memo = {}
        #: indices of the channels :meth:`velocity` returns (None: all of ``channels``)
        self.output = None
        if self.body is None:
            return
        self.mount_axes = list(self.system.mount_axes)
        self.body_shapes = ports.base_rows[:, 6:]
        self.channels = list(self.system.channels)
        self.output_matrix = self.system.channel_matrix[:, ports.retained]

    def use_channels(self, channels):
        """Let :meth:`velocity` return ``channels`` (names as :attr:`channels`) only."""
        self.output = np.array([self.channels.index(tuple(c)) for c in channels], int)
        self._extra = {k: v for k, v in self._extra.items() if not k.startswith(_VELOCITY_OF)}

    def load_of(self, engine) -> np.ndarray:
        """Load harmonics (n_r, 17, 6) complex [N, N·m] of ``engine`` at the model's speeds
        (:meth:`Engine.load_table <powertrain.models.engine.Engine.load_table>`)."""
        table = np.asarray(engine.load_table(self.rpm, self.theta), float)
        return harmonic_amplitudes(table, axis=1)[:, :N_HARMONICS]

    @property
    def load(self) -> np.ndarray:
        """Load harmonics of the nominal engine, (n_r, 17, 6) complex [N, N·m]."""
        if self._load is None:
            self._load = self.load_of(self.engine)
        return self._load

    def effect_defaults(self, effect) -> dict:
        """``effect.defaults(engine)`` of the :class:`~powertrain.effects.base.Effect`
        ``effect`` for the model's engine, kept per effect."""
        kept = self._effect_defaults.get(effect.name)
        if kept is None:
            kept = self._effect_defaults[effect.name] = effect.defaults(self.engine)
        return dict(kept)

    def shaft_loads(self) -> np.ndarray:
        """Per balancer shaft load harmonics (n_shafts, n_r, 17, 6), nominal unbalance."""
        if "shafts" not in self._extra:
            sh = self.engine.balancer.shafts
            out = np.zeros((len(sh), self.rpm.size, N_HARMONICS, 6), complex)
            for k, s in enumerate(sh):
                for i, r in enumerate(self.rpm):
                    out[k, i] = harmonic_amplitudes(shaft_load(self.engine, s, r, self.theta),
                                                    axis=0)[:N_HARMONICS]
            self._extra["shafts"] = out
        return self._extra["shafts"]

    def two_ports(self, models=None):
        """``(a, b, c)`` of every network at every speed and harmonic, each (n_r, 17, n_net);
        ``models`` (MountModel per network) default the engine's own (cached)."""
        if models is None and self._abc is not None:
            return self._abc
        mods = [n[2] for n in self.networks] if models is None else models
        static = self._statics(range(len(mods)))
        nets = self.packed if models is None else [m.network() for m in mods]
        abc = laplace_two_ports(1j * self.omega, nets, static, static)
        if models is None:
            self._abc = abc
        return abc

    def two_ports_scaled(self, scale, damper_scale=None, harmonics=None):
        r"""``(a, b, c)`` of every network with its elastomer scaled, each (n_r, 17, n_net):
        :math:`s\,\mathbf K + i\omega d\,\mathbf C - \omega^2\mathbf M` condensed
        (:func:`powertrain.physics.mount_network.laplace_two_ports`), ``s = scale`` and
        ``d = damper_scale`` (default ``scale``) broadcast to (n_r, 17, n_net). With one
        factor pair per network only the ``harmonics`` (indices 0..16, optional) are
        condensed, the others zero."""
        n_net = len(self.networks)
        scale = np.asarray(scale, float)
        damper = scale if damper_scale is None else np.asarray(damper_scale, float)
        if scale.size == n_net and damper.size == n_net:  # one pair per network: cached
            return self._scaled_networks(list(zip(scale.flat, damper.flat)), harmonics)
        shape = self.omega.shape + (n_net,)
        statics = self._statics(range(n_net))
        return laplace_two_ports(1j * self.omega, self.packed,
                                 np.broadcast_to(scale, shape) * statics,
                                 np.broadcast_to(damper, shape) * statics)

    def _scaled_networks(self, factors, harmonics=None):
        """Two-ports with (spring, damper) ``factors`` per network; the last two per network kept."""
        h = None if harmonics is None else tuple(int(i) for i in harmonics)
        keys = [(float(k), float(d), h) for k, d in factors]
        kept = [self._scaled.setdefault(k, {}) for k in range(len(keys))]
        missing = [k for k, f in enumerate(keys) if f not in kept[k]]
        if missing:
            statics = self._statics(missing)
            spring = np.array([keys[k][0] for k in missing]) * statics
            damper = np.array([keys[k][1] for k in missing]) * statics
            at = slice(None) if h is None else list(h)
            packed = self._packed_of.get(tuple(missing))
            if packed is None:
                packed = self._packed_of[tuple(missing)] = PackedNetworks.of(
                    [self.networks[k][2].network() for k in missing])
            res = laplace_two_ports(1j * self.omega[:, at], packed, spring, damper)
            if h is not None:                      # zero at the harmonics not asked for
                full = [np.zeros(self.omega.shape + (len(missing),), complex) for _ in res]
                for f, r in zip(full, res):
                    f[:, list(h)] = r
                res = full
            for j, k in enumerate(missing):
                if len(kept[k]) >= 2:
                    del kept[k][next(iter(kept[k]))]
                kept[k][keys[k]] = tuple(r[..., j] for r in res)
        return self._assembled(keys, kept)

    def _assembled(self, keys, kept):
        """Read-only two-ports of ``keys``: the last result with the changed networks replaced."""
        last = self._scaled_last
        if last is None or len(last[0]) != len(keys):
            out = tuple(np.empty(self.omega.shape + (len(keys),), complex) for _ in range(3))
            changed = range(len(keys))
        else:
            out = tuple(x.copy() for x in last[1])
            changed = [k for k, key in enumerate(keys) if key != last[0][k]]
        for k in changed:
            for j in range(3):
                out[j][..., k] = kept[k][keys[k]][j]
        for x in out:
            x.setflags(write=False)
        self._scaled_last = (keys, out)
        return out

    def two_ports_at(self, amplitudes, elements=None, packed=None):
        r"""``(a, b, c)`` of every network's element, each (n_r, 17, n_net), at the
        relative-displacement ``amplitudes`` (n_r, n_net) [m]: :meth:`MountElement.two_port
        <powertrain.physics.mount_elements.MountElement.two_port>` at :math:`s = i\omega`.
        ``elements`` default :attr:`elements`; ``packed`` their networks packed (default:
        packed here, :attr:`packed` for :attr:`elements`)."""
        els = self.elements if elements is None else elements
        if elements is None:
            packed = self.packed
        if self.static_scale is not None:
            els = [dataclasses.replace(el, static_factor=self.static_scale[:, k:k + 1])
                   for k, el in enumerate(els)]
        return element_two_ports(els, 1j * self.omega, np.asarray(amplitudes, float)[:, None], packed)

    def two_ports_on_base(self, abc, mass, stiffness, zeta):
        r"""The two-ports ``abc`` (each (n_r, 17, n_net)) on a base of ``mass`` [kg],
        ``stiffness`` [N/m] and damping ratio ``zeta`` [1], condensed exactly: with
        :math:`k_b = c_b + i\omega\,2\zeta\sqrt{c_b m_b}`, :math:`z = c + k_b - \omega^2 m_b`,
        :math:`a' = a - b^2/z`, :math:`b' = b\,k_b/z`, :math:`c' = k_b - k_b^2/z`
        (as :func:`powertrain.models.extensions.with_base_compliance`)."""
        a, b, c = abc
        w = self.omega[..., None]
        kb = stiffness + 1j * w * 2 * zeta * np.sqrt(stiffness * mass)
        z = c + kb - w ** 2 * mass
        return a - b ** 2 / z, b * kb / z, kb - kb ** 2 / z

    def _statics(self, index):
        """Static factors (n_r, 1, len(index)) of the networks ``index`` (1.0 without curves)."""
        if self.static_scale is None:
            return 1.0
        return self.static_scale[:, None, list(index)]

    def solve(self, kip, load=None, harmonics=slice(1, N_HARMONICS), abc=None, body=None) -> np.ndarray:
        r"""Amplitudes :math:`\hat{\mathbf q}` (n_r, n_h, 6 [+ K], body modes last) at the
        input-point stiffnesses ``kip`` (n_r, 17, n_net) [N/m] under ``load`` (default
        nominal) at the ``harmonics``; a modal body (``body``, default :attr:`body`) couples
        through the two-ports ``abc`` (default nominal,
        :func:`powertrain.solvers.body_coupling.coupled_solve`)."""
        load = self.load if load is None else load
        w = self.omega[:, harmonics]
        K = kip[:, harmonics]
        if self.body is not None:
            abc = self.two_ports() if abc is None else abc
            body = self.body if body is None else body
            shapes = self._network_shapes(body)
            rows_on = self._of_shapes("own rows" if body is self.body else "rows", body,
                                      lambda: coupled_rows(self.rows, shapes))
            return coupled_solve(self.M, w, self.rows, shapes,
                                 tuple(x[:, harmonics] for x in abc), K, body,
                                 load[:, harmonics], rows_on)
        frame = (self.M, np.zeros((6, 6)), np.zeros((6, 6)))
        return harmonic_solve(frame, self.rows, None, (K, None, None), 1j * w, load[:, harmonics])

    def solve_one_more_mode(self, body, harmonics=slice(1, N_HARMONICS)) -> np.ndarray:
        """:meth:`solve`'s amplitudes (n_r, n_h, 6 + K + 1) of the nominal model at the
        ``harmonics`` on ``body``, the model's body with one more mode
        (:meth:`ModalBody.adds_one_mode_to
        <powertrain.solvers.body_coupling.ModalBody.adds_one_mode_to>`): the nominal system
        solved once (cached, :func:`~powertrain.solvers.body_coupling.one_more_mode_basis`),
        each mode by :func:`~powertrain.solvers.body_coupling.one_more_mode`."""
        if _ONE_MORE_MODE[0] not in self._extra:
            abc = self.two_ports()
            h = slice(1, N_HARMONICS)
            basis = one_more_mode_basis(self.M, self.omega[:, h], self.rows, self.body_shapes,
                                        tuple(x[:, h] for x in abc), abc[0][:, h],
                                        self.body, self.load[:, h])
            self._extra.update({k: v[None] for k, v in zip(_ONE_MORE_MODE, basis)})
        j = np.arange(N_HARMONICS)[harmonics] - 1
        last = self._one_more_mode_at
        if last is None or not np.array_equal(last[0], j):     # the fit's orders: once
            last = self._one_more_mode_at = (j, tuple(self._extra[k][0][:, j] for k in _ONE_MORE_MODE))
        basis = last[1]
        shape = body.network_shapes(self.networks, self.mount_axes)[:, -1]
        w = self.omega[:, harmonics]
        wk, m, z = 2 * np.pi * body.frequency_hz[-1], body.modal_mass[-1], body.damping_ratio[-1]
        return one_more_mode(basis, shape, m * (wk ** 2 - w ** 2 + 2j * z * wk * w))

    def load_response(self, load) -> np.ndarray:
        """:meth:`solve`'s amplitudes (n_r, 16, 6 [+ K]) of the nominal model for the load
        harmonics ``load`` (n_r, 17, 6): the unit responses solved once (cached), combined."""
        if "load_transfer" not in self._extra:
            abc = self.two_ports()
            unit = np.zeros(self.omega.shape + (6,), complex)
            cols = []
            for j in range(6):
                unit[..., :] = 0.0
                unit[..., j] = 1.0
                cols.append(self.solve(abc[0], unit, abc=abc))
            self._extra["load_transfer"] = np.stack(cols)
        return np.einsum("jrhq,rhj->rhq", self._extra["load_transfer"], load[:, 1:])

    def load_velocity(self, name, loads) -> np.ndarray:
        """Channel velocities (n_b, n_r, n_ch, 16) [m/s] of the nominal model under each of
        ``loads`` (n_b, n_r, 17, 6), kept under ``name``: linear in the load, so a load of
        these parts has the weighted sum of their velocities."""
        key = _VELOCITY_OF + name
        if key not in self._extra:
            self._extra[key] = np.stack([self.velocity(self.load_response(x)) for x in loads])
        return self._extra[key]

    def velocity(self, q, harmonics=slice(1, N_HARMONICS), body=None) -> np.ndarray:
        """Complex peak channel velocities (n_r, n_ch, n_h) [m/s] of :meth:`solve`'s ``q`` at
        the ``harmonics``, solved with ``body`` (default :attr:`body`)."""
        w = self.omega[:, harmonics]
        C = self.channel_matrix if self.body is None else self.output_matrix
        if body is not None and body is not self.body:     # its modes' output rows
            C = self._of_shapes("output", body, lambda: np.hstack(
                [C[:, :6], np.vstack([np.zeros((self.channel_matrix.shape[0], body.n_modes)),
                                      body.output_rows()])]))
        if self.output is not None:
            C = C[self.output]
        return np.swapaxes(q @ C.T, -1, -2) * (1j * w)[:, None, :]

    def network_amplitude(self, q) -> np.ndarray:
        r"""Engine-side peak displacement (n_r, n_net) [m] of each network for :meth:`solve`'s
        ``q``, :math:`a_n = \sqrt{\sum_h |\mathbf r_n\cdot\hat{\mathbf q}_h|^2}`."""
        x = q[..., :6] @ self.rows.T
        return np.sqrt(np.sum(np.abs(x) ** 2, axis=1))

    def _network_shapes(self, body):
        """Mode shapes (n_net, K) of ``body`` along each network's direction."""
        if body is self.body:
            return self.body_shapes
        return self._of_shapes("network shapes", body, lambda: body.network_shapes(
            self.networks, self.mount_axes))

    def _of_shapes(self, name, body, make):
        """``make()``, kept under ``name`` while ``body`` has the same shape arrays."""
        kept = self._body_memo.get(name)
        if (kept is None or kept[0] is not body.mount_shapes or kept[1] is not body.point_shapes):
            kept = self._body_memo[name] = (body.mount_shapes, body.point_shapes, make())
        return kept[2]

    def relative_amplitude(self, q, body=None) -> np.ndarray:
        r"""Relative-displacement amplitude (n_r, n_net) [m] across each network of
        :meth:`solve`'s ``q`` (solved with ``body``, default :attr:`body`),
        :math:`A_n = \sqrt{\sum_h |\mathbf r_n\cdot\hat{\mathbf q}_h - \mathbf s_n\cdot
        \hat{\boldsymbol\eta}_h|^2}`; the base term only with a modal body."""
        x = q[..., :6] @ self.rows.T
        if self.body is not None:
            shapes = self._network_shapes(self.body if body is None else body)
            x = x - q[..., 6:] @ shapes.T
        return np.sqrt(np.sum(np.abs(x) ** 2, axis=1))

    def subset(self, index) -> HarmonicModel:
        """The model at the speeds ``rpm[index]``, sharing the cached parts computed so far."""
        index = np.asarray(index)
        new = object.__new__(HarmonicModel)
        new.__dict__.update(self.__dict__)
        new.rpm = self.rpm[index]
        new.omega = self.omega[index]
        new._load = None if self._load is None else self._load[index]
        new._abc = None if self._abc is None else tuple(x[index] for x in self._abc)
        if self.static_scale is not None:
            new.static_scale = self.static_scale[index]
        new._extra = {k: v[:, index] for k, v in self._extra.items()}
        new._scaled = {}
        new._scaled_last = None
        new._packed_of = {}
        new._one_more_mode_at = None
        new._body_memo = {}
        return new
