r"""Assembly of the powertrain model: a 6-DOF rigid body on its mounts' networks (three per mount).

Each mount has a position (its engine-side point, also the measurement point) and a rotation
whose columns are its local x, y, z axes in engine axes. In each local direction a lumped
network (e.g. the triple mass oscillator) joins the engine-side point to the ground; its
engine-side node moves with the body, :math:`x_E = \mathbf e\cdot(\mathbf u +
\boldsymbol\theta\times\mathbf r)`, its internal masses are extra degrees of freedom. With
the map :math:`\mathbf L` from global coordinates to network nodes, each network adds
:math:`\mathbf L^T\mathbf K_n\mathbf L` (likewise C, M) to the global matrices. Outputs are
linear maps of the state: each mount point's motion and transmitted force, in engine axes.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from powertrain.analysis.channel import DIRECTIONS, passive_name
from powertrain.physics.condensation import NetworkPorts, condense
from powertrain.physics.mount_elements import PortForces, port_forces
from powertrain.physics.mount_network import ground_force_rows, network_matrices
from powertrain.physics.rigid_body import direction_row, point_motion_matrix, rigid_body_mass_matrix


@dataclass
class AssembledSystem:
    """Linear powertrain model  M q'' + C q' + K q = B f  (f = 6-vector load about the CG).

    Attributes
    ----------
    M, C, K : ndarray (n, n)
        Global matrices; the first six coordinates are the rigid body (SI).
    channels : list of (mount, direction)
        Output channels, three per mount (engine axes).
    channel_matrix : ndarray (3 n_mounts, n)
        Maps q (or q', q'') to the motion of the mount points in engine X/Y/Z.
    force_matrix_k, force_matrix_d : ndarray (3 n_mounts, n)
        Force transmitted to ground in engine axes: F = force_matrix_k @ q +
        force_matrix_d @ q' (+ ``port_force_map`` @ the port laws' forces).
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    channels: list
    channel_matrix: np.ndarray
    force_matrix_k: np.ndarray
    force_matrix_d: np.ndarray
    #: per network: (row (6,) mapping q_rb to the engine-side node, first internal dof,
    #: number of internal dofs, MountElement)
    networks: list = field(default_factory=list)
    #: the body under the mounts (None or rigid: fixed base)
    chassis: object = None
    #: first coordinate of the body modes (modal chassis; n_dof otherwise)
    body_start: int = 0
    #: names of the mounts, in order (their engine-side channels come first)
    mount_names: list = field(default_factory=list)
    #: rotation (3, 3) of every mount (columns = local axes in engine axes)
    mount_axes: list = field(default_factory=list)
    #: the networks on the retained coordinates (None: nothing to condense)
    network_ports: NetworkPorts | None = None
    #: per network: relative displacement engine side minus base per unit q, (n_net, n)
    port_rows: np.ndarray | None = None
    #: transmitted-force channels per unit force across each network, (n_ch, n_net)
    port_force_map: np.ndarray | None = None
    #: per network: its node map L (network nodes per unit q) and its base row (n,)
    network_maps: list = field(default_factory=list)

    def __post_init__(self):
        if not self.body_start:
            self.body_start = self.M.shape[0]
        if not self.mount_names:
            self.mount_names = list(dict.fromkeys(m for m, _ in self.channels))

    @property
    def n_mount_channels(self) -> int:
        """Engine-side channels (the first rows of the output matrices)."""
        return 3 * len(self.mount_names)

    def add_body_side(self, chassis, mount_names, body0):
        """Append the body-side channels of every mount (``NAME/passive``, force rows: the
        mount's transmitted force) and of the body points (force rows 0)."""
        self.chassis = chassis
        self.body_start = body0
        self.mount_names = list(mount_names)
        n = self.n_dof
        rows, frows_k, frows_d, names = [], [], [], []
        for mi, name in enumerate(mount_names):
            names += [(passive_name(name), a) for a in DIRECTIONS]
            rows.append(self._body_rows(chassis, name, n))
            frows_k.append(self.force_matrix_k[3 * mi:3 * mi + 3])
            frows_d.append(self.force_matrix_d[3 * mi:3 * mi + 3])
        for p in chassis.points:
            names += [(p, a) for a in DIRECTIONS]
            rows.append(self._body_rows(chassis, p, n))
            frows_k.append(np.zeros((3, n)))
            frows_d.append(np.zeros((3, n)))
        self.channels = self.channels + names
        self.channel_matrix = np.vstack([self.channel_matrix] + rows)
        self.force_matrix_k = np.vstack([self.force_matrix_k] + frows_k)
        self.force_matrix_d = np.vstack([self.force_matrix_d] + frows_d)
        if self.port_force_map is not None:
            Pf = self.port_force_map
            self.port_force_map = np.vstack([Pf, Pf, np.zeros((3 * len(chassis.points),
                                                               Pf.shape[1]))])

    def _body_rows(self, chassis, name, n):
        rows = np.zeros((3, n))
        rows[:, self.body_start:] = chassis.body_rows(name)
        return rows

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    @property
    def network_names(self) -> list:
        """``mount.direction`` of every network, in order."""
        return [f"{m}.{a}" for m in self.mount_names for a in DIRECTIONS]

    def port_forces(self) -> PortForces | None:
        """The nonlinear elements' port laws as kernel arrays; None for a linear model."""
        if self.port_rows is None:
            return None
        return port_forces([el for *_, el in self.networks], self.port_rows,
                           self.port_force_map, self.network_names)

    def network_parts(self):
        r"""Each network's contribution at unit scale, stacked: ``(C_k, K_k, gk_k, gd_k)``,
        :math:`\mathbf L^T\mathbf C_n\mathbf L` (n_net, n, n), likewise K, and the
        transmitted-force rows (n_net, n); a network scaled by ``(ks, ds)`` adds ``ds C_k``,
        ``ks K_k``, ``ks gk_k``, ``ds gd_k``."""
        parts = [[], [], [], []]
        for (*_, element), (L, base) in zip(self.networks, self.network_maps):
            network = element.lumped
            _, Cn, Kn = network_matrices(*network, include_ground=L.shape[0] >
                                         network[0].size + 1)
            kg, dg = ground_force_rows(network[0].size, *network[1:])
            for out, value in zip(parts, (L.T @ Cn @ L, L.T @ Kn @ L, _force_row(kg, L, base),
                                          _force_row(dg, L, base))):
                out.append(value)
        return tuple(np.array(p) for p in parts)

    def ports(self) -> NetworkPorts:
        """The networks on the retained coordinates (:mod:`powertrain.physics.condensation`);
        without them every coordinate is kept."""
        if self.network_ports is not None:
            return self.network_ports
        n = self.n_dof
        return NetworkPorts(np.arange(n), (self.M, self.C, self.K), np.zeros((0, n)),
                            np.zeros((0, n)), [], [])

    @property
    def retained(self) -> np.ndarray:
        """Coordinates kept by the condensation: the rigid body and the body modes."""
        return self.ports().retained

    def static_stiffness_6(self) -> np.ndarray:
        """6×6 static stiffness of the body on its mounts, the rest condensed [N/m, N, N·m/rad]."""
        return condense(self, np.arange(6), 0.0).real

    def rigid_body_modes(self):
        """Natural frequencies [Hz] and mode shapes of the 6-DOF body on the mounts'
        static (0 Hz) cross-point stiffness, internal masses condensed statically."""
        w2, vec = sla.eigh(self.static_stiffness_6(), self.M[:6, :6])
        return np.sqrt(np.clip(w2, 0, None)) / (2 * np.pi), vec


def assemble(mass, cg, inertia, mounts, chassis=None, static_factors=None) -> AssembledSystem:
    """Assemble the rigid body, its mounts and (optionally) a modal body under them.

    Parameters
    ----------
    mass : float
        Powertrain mass [kg].
    cg : array_like (3,)
        Centre of gravity in engine axes [m].
    inertia : array_like (3, 3)
        Inertia tensor about the CG in engine axes [kg·m²].
    mounts : sequence
        Objects with ``name``, ``position`` (3,) [m, engine axes], ``rotation`` (3, 3)
        (columns = local x, y, z in engine axes) and ``directions`` {"x"|"y"|"z": MountModel}.
    chassis : Chassis, optional
        ``modal``: body modes appended as coordinates, each network's base node moving with
        the body; ``frf``: coupled in the harmonic solver only; ``rigid`` or None: fixed base.
    static_factors : array_like (3 n_mounts,), optional
        Each network's static factor at an operating point, scaling its springs and dampers
        (None: unscaled).

    Outputs: every mount's engine-side point; with a non-rigid chassis also its body side
    (``NAME/passive``) and the body points.
    """
    cg = np.asarray(cg, float)
    body_modes = chassis.body_modes if chassis is not None else ()
    modal = bool(body_modes)
    blocks = _network_blocks(mounts, cg, modal, static_factors)
    body0 = 6 + sum(b[4].size - 1 for b in blocks)
    n = body0 + len(body_modes)
    retained = np.r_[np.arange(6), np.arange(body0, n)].astype(int)
    frame = _frame(mass, inertia, body_modes)
    M, C, K = (np.zeros((n, n)) for _ in range(3))
    n_m = len(mounts)
    Fk, Fd = np.zeros((3 * n_m, n)), np.zeros((3 * n_m, n))
    shapes = {m.name: chassis.body_rows(m.name) for m in mounts} if modal else {}
    networks, maps, port_rows, port_map = _add_networks((M, C, K, Fk, Fd), blocks, mounts,
                                                        shapes, body0)
    base_rows = [base for _, base in maps]
    for X, X0 in zip((M, C, K), frame):
        X[np.ix_(retained, retained)] += X0
    channels = [(m.name, a) for m in mounts for a in DIRECTIONS]
    Cm = np.zeros((3 * n_m, n))
    for mi, mount in enumerate(mounts):
        Cm[3 * mi:3 * mi + 3, :6] = point_motion_matrix(np.asarray(mount.position, float) - cg)
    system = AssembledSystem(M, C, K, channels, Cm, Fk, Fd, networks,
                             port_rows=port_rows, port_force_map=port_map, network_maps=maps)
    system.mount_axes = [np.asarray(m.rotation, float) for m in mounts]
    system.network_ports = NetworkPorts(
        retained, frame, np.array([np.r_[b[0], np.zeros(len(body_modes))] for b in blocks]
                                  ).reshape(-1, retained.size),
        np.array(base_rows)[:, retained].reshape(-1, retained.size),
        [(st, ni) for _, st, ni, _ in networks], [el for *_, el in networks])
    if chassis is not None and not chassis.is_rigid:
        system.add_body_side(chassis, [m.name for m in mounts], body0)
    return system


def _add_networks(matrices, blocks, mounts, shapes, body0):
    """Add every network to M, C, K and its transmitted force to ``Fk``, ``Fd`` (in place)."""
    M, C, K, Fk, Fd = matrices
    n = M.shape[0]
    start, networks, maps = 6, [], []
    port_map = np.zeros((Fk.shape[0], len(blocks)))
    for k, (row, Mn, Cn, Kn, kg, dg, mi, ai, element) in enumerate(blocks):
        ni = kg.size - 1
        e = np.asarray(mounts[mi].rotation, float)[:, ai]
        L = np.zeros((Mn.shape[0], n))
        L[0, :6] = row
        L[1:ni + 1, start:start + ni] = np.eye(ni)
        if shapes:
            L[ni + 1, body0:] = e @ shapes[mounts[mi].name]       # base node on the body
        for X, Xn in ((M, Mn), (C, Cn), (K, Kn)):
            X += L.T @ Xn @ L
        # force on the base along the local axis, expressed in engine axes
        base = L[ni + 1] if shapes else np.zeros(n)
        Fk[3 * mi:3 * mi + 3] += np.outer(e, _force_row(kg, L, base))
        Fd[3 * mi:3 * mi + 3] += np.outer(e, _force_row(dg, L, base))
        port_map[3 * mi:3 * mi + 3, k] = e
        networks.append((row, start, ni, element))
        maps.append((L, base))
        start += ni
    port_rows = np.zeros((len(blocks), n))
    port_rows[:, :6] = [b[0] for b in blocks]
    base_rows = np.array([base for _, base in maps]).reshape(-1, n)
    return networks, maps, port_rows - base_rows, port_map


def _force_row(g, L, base):
    """Force on a network's base along its axis per unit q, from its ground-force row ``g``."""
    ni = g.size - 1
    return g @ L[:ni + 1] - g.sum() * base


def _network_blocks(mounts, cg, with_ground, static_factors=None):
    """Per network: (engine-side row, M, C, K, kg, dg, mount index, axis index, element)."""
    blocks = []
    for mi, mount in enumerate(mounts):
        r = np.asarray(mount.position, float) - cg
        R = np.asarray(mount.rotation, float)
        for ai, axis in enumerate(DIRECTIONS):
            element = mount.directions[axis].element()
            if static_factors is not None:
                element = element.at_operating_point(static_factors[3 * mi + ai])
            Mn, Cn, Kn = element.matrices(include_ground=with_ground)
            masses, elem_nodes, c, d = element.network()
            kg, dg = ground_force_rows(masses.size, elem_nodes, c, d)
            blocks.append((direction_row(r, R[:, ai]), Mn, Cn, Kn, kg, dg, mi, ai, element))
    return blocks


def _frame(mass, inertia, body_modes):
    """M, C, K of the retained coordinates without networks: rigid-body mass and each body
    mode's single-DOF oscillator."""
    n = 6 + len(body_modes)
    M0, C0, K0 = (np.zeros((n, n)) for _ in range(3))
    M0[:6, :6] = rigid_body_mass_matrix(mass, inertia)
    for k, mode in enumerate(body_modes):
        j = 6 + k
        M0[j, j] = mode.modal_mass
        C0[j, j] = 2.0 * mode.damping_ratio * mode.omega * mode.modal_mass
        K0[j, j] = mode.omega ** 2 * mode.modal_mass
    return M0, C0, K0


class NetworkScaling:
    """The assembled model's damping, stiffness and force rows at other network scales
    (amplitude laws, static operating point, networks as measured).

    Parameters
    ----------
    system : AssembledSystem
    """

    def __init__(self, system):
        self.system = system
        self.elements = [el for *_, el in system.networks]
        self.C_parts, self.K_parts, self.gk, self.gd = system.network_parts()
        laws = {}
        for k, el in enumerate(self.elements):
            if el.amplitude_law is not None:
                laws.setdefault(el.amplitude_law, []).append(k)
        self._laws = {law: np.array(index) for law, index in laws.items()}
        #: every network's static factor as assembled (1 without a static curve)
        self.static_factors = np.array([el.static_factor for el in self.elements], float)
        #: the scales the assembled matrices hold (every element at amplitude 0)
        self.assembled = self.scales(np.zeros(len(self.elements)))
        #: True when some network's scale follows its amplitude
        self.varying = any(el.amplitude_law is not None and not el.amplitude_law.constant
                           for el in self.elements)

    def scales(self, amplitudes, factors=None) -> np.ndarray:
        """``(stiffness, damping)`` factor (n_net, 2) of every network at its ``amplitudes``
        (n_net,) [m] and static ``factors`` (default: as assembled)."""
        out = np.ones((len(self.elements), 2))
        a = np.asarray(amplitudes, float)
        for law, index in self._laws.items():
            out[index, 0], out[index, 1] = law.scales(a[index])
        f = self.static_factors if factors is None else np.asarray(factors, float)
        return out * f[:, None]

    def matrices(self, scales):
        """``(C, K, force_matrix_k, force_matrix_d)`` at the network ``scales`` (n_net, 2);
        the assembled arrays themselves if no scale changed."""
        s = self.system
        dk, dd = (np.asarray(scales, float) - self.assembled).T
        if not (dk.any() or dd.any()):
            return s.C, s.K, s.force_matrix_k, s.force_matrix_d
        fmap = s.port_force_map
        return (s.C + np.tensordot(dd, self.C_parts, 1), s.K + np.tensordot(dk, self.K_parts, 1),
                s.force_matrix_k + (fmap * dk) @ self.gk,
                s.force_matrix_d + (fmap * dd) @ self.gd)

    def at_operating_point(self, factors):
        """The model with its elements at the static ``factors`` (n_net,)."""
        return self.with_elements([el.at_operating_point(f)
                                   for el, f in zip(self.elements, factors)])

    def as_measured(self):
        """The model with every network as measured (the linear view of the modes)."""
        return self.with_elements([el.as_measured() for el in self.elements])

    def with_elements(self, elements):
        """The model with ``elements`` (one per network, at amplitude 0): elements, C, K and
        force rows replaced."""
        s = self.system
        C, K, Fk, Fd = self.matrices(np.array([el.scales(0.0) for el in elements],
                                              float).reshape(-1, 2))
        ports = dataclasses.replace(s.network_ports, elements=elements)
        return dataclasses.replace(s, C=C, K=K, force_matrix_k=Fk, force_matrix_d=Fd,
                                   networks=[(*n[:3], el) for n, el in zip(s.networks,
                                                                           elements)],
                                   network_ports=ports)
