r"""Assembly of the powertrain model: a 6-DOF rigid body on its mounts' networks (three per mount).

Each mount has a position (its engine-side point, which is also the measurement point) and a
rotation whose columns are the mount's local x, y, z axes in engine axes. In each local
direction a lumped network (e.g. the triple mass oscillator) joins the engine-side point to
the rigid ground. The engine-side node of the network moves with the body along that
direction, :math:`x_E = \mathbf e\cdot(\mathbf u + \boldsymbol\theta\times\mathbf r)`, and its
internal masses are extra degrees of freedom (27 for the default engine's nine triple mass
oscillators). With the map :math:`\mathbf L` from global coordinates to network nodes, every network adds
:math:`\mathbf L^T\mathbf K_n\mathbf L` (and likewise C, M) to the global matrices.

Outputs are linear maps of the state: the velocity of each mount point in engine X/Y/Z (three
channels per mount) and the force each mount transmits to ground, in engine axes.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.physics.mount_network import ground_force_rows
from powertrain.physics.rigid_body import direction_row, point_motion_matrix, rigid_body_mass_matrix

DIRECTIONS = ("x", "y", "z")


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
        Force transmitted by each mount to ground in engine axes:
        F = force_matrix_k @ q + force_matrix_d @ q'.
    dof_labels : list of str
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    channels: list
    channel_matrix: np.ndarray
    force_matrix_k: np.ndarray
    force_matrix_d: np.ndarray
    dof_labels: list = field(default_factory=list)
    #: per network: (row (6,) mapping q_rb to the engine-side node, first internal dof,
    #: number of internal dofs, MountModel)
    networks: list = field(default_factory=list)

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    def load_matrix(self) -> np.ndarray:
        """B (n×6): the generalized load acts on the rigid-body coordinates only."""
        B = np.zeros((self.n_dof, 6))
        B[:6, :6] = np.eye(6)
        return B

    def static_displacement(self, load6) -> np.ndarray:
        """Static solution K q = B f for a constant 6-vector load [N, N·m]."""
        return np.linalg.solve(self.K, self.load_matrix() @ np.asarray(load6, float))

    def static_stiffness_6(self) -> np.ndarray:
        """6×6 static stiffness of the body on its mounts, internal nodes condensed
        statically [N/m, N, N·m/rad]."""
        K = self.K
        if self.n_dof == 6:
            return K[:6, :6].copy()
        Kbb, Kbi, Kii = K[:6, :6], K[:6, 6:], K[6:, 6:]
        return Kbb - Kbi @ np.linalg.solve(Kii, Kbi.T)

    def rigid_body_modes(self):
        """Natural frequencies [Hz] and mode shapes of the 6-DOF body on the mounts'
        static (0 Hz) cross-point stiffness, internal masses condensed statically."""
        import scipy.linalg as sla
        w2, vec = sla.eigh(self.static_stiffness_6(), self.M[:6, :6])
        return np.sqrt(np.clip(w2, 0, None)) / (2 * np.pi), vec


def assemble(mass, cg, inertia, mounts) -> AssembledSystem:
    """Assemble the rigid body and its mounts.

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
    """
    cg = np.asarray(cg, float)
    blocks = []   # (row 1x6, M_net, C_net, K_net, kg, dg, mount index, local axis)
    n_int_total = 0
    labels = ["u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z"]
    for mi, mount in enumerate(mounts):
        r = np.asarray(mount.position, float) - cg
        R = np.asarray(mount.rotation, float)
        for ai, axis in enumerate(DIRECTIONS):
            model = mount.directions[axis]
            e = R[:, ai]
            Mn, Cn, Kn = model.matrices()
            masses, elem_nodes, c, d = model.network()
            kg, dg = ground_force_rows(masses.size, elem_nodes, c, d)
            blocks.append((direction_row(r, e), Mn, Cn, Kn, kg, dg, mi, ai))
            labels += [f"{mount.name}.{axis}.m{j + 1}" for j in range(masses.size)]
            n_int_total += masses.size
    n = 6 + n_int_total
    M = np.zeros((n, n))
    C = np.zeros((n, n))
    K = np.zeros((n, n))
    M[:6, :6] = rigid_body_mass_matrix(mass, inertia)
    n_m = len(mounts)
    Fk = np.zeros((3 * n_m, n))
    Fd = np.zeros((3 * n_m, n))
    start = 6
    networks = []
    for row, Mn, Cn, Kn, kg, dg, mi, ai in blocks:
        ni = Mn.shape[0] - 1
        L = np.zeros((ni + 1, n))
        L[0, :6] = row
        L[1:, start:start + ni] = np.eye(ni)
        M += L.T @ Mn @ L
        C += L.T @ Cn @ L
        K += L.T @ Kn @ L
        # force on ground along the local axis, expressed in engine axes
        e = np.asarray(mounts[mi].rotation, float)[:, ai]
        Fk[3 * mi:3 * mi + 3] += np.outer(e, kg @ L)
        Fd[3 * mi:3 * mi + 3] += np.outer(e, dg @ L)
        networks.append((row, start, ni, mounts[mi].directions[DIRECTIONS[ai]]))
        start += ni
    channels = [(m.name, a) for m in mounts for a in DIRECTIONS]
    Cm = np.zeros((3 * n_m, n))
    for mi, mount in enumerate(mounts):
        Cm[3 * mi:3 * mi + 3, :6] = point_motion_matrix(np.asarray(mount.position, float) - cg)
    return AssembledSystem(M, C, K, channels, Cm, Fk, Fd, labels, networks)
