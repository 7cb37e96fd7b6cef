r"""A modal body under the mounts on the fast cached path (:mod:`.fast_harmonic`).

The rigid powertrain (6 coordinates :math:`\mathbf q`) stands on its mount networks; every
network n joins its engine-side node (motion :math:`\mathbf r_n\cdot\mathbf q`) to its base
node, which moves with the body at the mount's attachment point along the network's local
axis :math:`\mathbf e_n`: :math:`x_{B,n} = \mathbf s_n\cdot\boldsymbol\eta`,
:math:`\mathbf s_n = \boldsymbol\Psi_{m(n)}^T\mathbf e_n`, with :math:`\boldsymbol\Psi_m`
(3 × K) the shapes of the K body modes at mount m (:class:`~powertrain.models.chassis.Chassis`,
``model = "modal"``). Each network is the one two-port condensation
(:func:`powertrain.physics.mount_network.two_port`, :math:`F_E = a x_E + b x_B`,
:math:`F_B = b x_E + c x_B`), assembled by the one condensation
(:func:`powertrain.physics.condensation.condensed_matrix`); each body mode
:math:`Z_k(\omega) = m_k(\omega_k^2 - \omega^2 + 2i\zeta_k\omega_k\omega)`; per speed and
harmonic the (6 + K) complex system

.. math:: \begin{bmatrix} -\omega^2\mathbf M + \sum_n a_n\mathbf r_n\mathbf r_n^T &
          \sum_n b_n\mathbf r_n\mathbf s_n^T \\ \sum_n b_n\mathbf s_n\mathbf r_n^T &
          \mathrm{diag}(Z_k) + \sum_n c_n\mathbf s_n\mathbf s_n^T \end{bmatrix}
          \begin{bmatrix}\hat{\mathbf q}\\ \hat{\boldsymbol\eta}\end{bmatrix} =
          \begin{bmatrix}\hat{\mathbf f}\\ \mathbf 0\end{bmatrix}

is solved. The body side of mount m moves by :math:`\boldsymbol\Psi_m\hat{\boldsymbol\eta}`
(channels ``m/passive``), a body point P by :math:`\boldsymbol\Psi_P\hat{\boldsymbol\eta}`.
This is the assembled modal model of :func:`powertrain.assembly.assemble` with the networks'
internal masses condensed exactly (tests/test_body_coupling.py checks both solvers).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from powertrain.analysis.channel import DIRECTIONS, passive_name
from powertrain.kernels.small_solve import batched_solve
from powertrain.physics.condensation import condensed_matrix


@dataclass(frozen=True)
class ModalBody:
    """Body modes as plain arrays for the fast path.

    Attributes
    ----------
    frequency_hz, modal_mass, damping_ratio : ndarray (K,)
        [Hz], [kg], [1].
    mount_shapes : ndarray (n_mounts, 3, K)
        Shape of every mode at each mount's attachment point, engine axes [1].
    point_shapes : ndarray (n_points, 3, K)
        Shapes at the body points of interest [1].
    points : tuple of str
    """

    frequency_hz: np.ndarray
    modal_mass: np.ndarray
    damping_ratio: np.ndarray
    mount_shapes: np.ndarray
    point_shapes: np.ndarray
    points: tuple = ()

    @classmethod
    def of(cls, engine):
        """The modal body of ``engine`` (None for a rigid, absent or measured-receptance
        chassis: the fast path predicts body-side motion only for a modal body; a modal
        chassis without modes is a body side held still, K = 0)."""
        ch = getattr(engine, "chassis", None)
        if ch is None or ch.is_rigid or ch.coupled_by_admittance:
            return None
        ms = np.array([ch.shape_matrix(m.name) for m in engine.mounts], float)
        ps = np.array([ch.shape_matrix(p) for p in ch.points], float).reshape(
            len(ch.points), 3, len(ch.modes))
        return cls(np.array([m.frequency for m in ch.modes], float),
                   np.array([m.modal_mass for m in ch.modes], float),
                   np.array([m.damping_ratio for m in ch.modes], float), ms, ps,
                   tuple(ch.points))

    @property
    def n_modes(self) -> int:
        return self.frequency_hz.size

    def with_modes(self, frequency_hz=None, modal_mass=None, damping_ratio=None) -> ModalBody:
        """The same shapes with other modal parameters (None: kept)."""
        return replace(self,
                       frequency_hz=self.frequency_hz if frequency_hz is None
                       else np.asarray(frequency_hz, float),
                       modal_mass=self.modal_mass if modal_mass is None
                       else np.asarray(modal_mass, float),
                       damping_ratio=self.damping_ratio if damping_ratio is None
                       else np.asarray(damping_ratio, float))

    def with_extra_mode(self, frequency_hz, modal_mass, damping_ratio, mount_shape) -> ModalBody:
        """The body with one more mode (last): ``mount_shape`` (n_mounts, 3) its shape at
        the mount attachment points, zero at the body points."""
        shape = np.asarray(mount_shape, float).reshape(self.mount_shapes.shape[0], 3, 1)
        return replace(self,
                       frequency_hz=np.append(self.frequency_hz, float(frequency_hz)),
                       modal_mass=np.append(self.modal_mass, float(modal_mass)),
                       damping_ratio=np.append(self.damping_ratio, float(damping_ratio)),
                       mount_shapes=np.concatenate([self.mount_shapes, shape], axis=2),
                       point_shapes=np.concatenate(
                           [self.point_shapes, np.zeros(self.point_shapes.shape[:2] + (1,))],
                           axis=2))

    def impedance(self, omega) -> np.ndarray:
        r"""Modal dynamic stiffness :math:`Z_k(\omega)` (omega.shape + (K,)) [N/m]."""
        w = np.asarray(omega, float)[..., None]
        wk = 2 * np.pi * self.frequency_hz
        return self.modal_mass * (wk ** 2 - w ** 2 + 2j * self.damping_ratio * wk * w)

    def network_shapes(self, networks, axes) -> np.ndarray:
        r""":math:`\mathbf s_n = \boldsymbol\Psi_{m(n)}^T\mathbf e_n`, (n_net, K), for the
        networks ``[(mount index, axis name, model)]`` and mount rotations ``axes``."""
        return np.array([self.mount_shapes[mi].T @ np.asarray(axes[mi], float)[:, DIRECTIONS.index(ax)]
                         for mi, ax, _ in networks])

    def output_rows(self) -> np.ndarray:
        """Body coordinates to the passive channels (mount-major x, y, z), then the body
        points', (3 (n_mounts + n_points), K)."""
        return np.vstack([s for s in self.mount_shapes] + [s for s in self.point_shapes])


def body_channels(mount_names, body: ModalBody) -> list:
    """Channel names of the body side: ``(NAME/passive, x|y|z)`` per mount, then the body
    points ``(POINT, x|y|z)``."""
    return ([(passive_name(m), a) for m in mount_names for a in DIRECTIONS]
            + [(p, a) for p in body.points for a in DIRECTIONS])


def modal_frame(M, frequency_hz, modal_mass, damping_ratio):
    r"""Frame of the rigid powertrain (mass ``M`` (6, 6)) and K body modes as single-DOF
    oscillators: :math:`(\mathbf M_0, \mathbf C_0, \mathbf K_0)`, each (6 + K, 6 + K), so
    that :math:`\mathbf K_0 + i\omega\mathbf C_0 - \omega^2\mathbf M_0` holds
    :math:`Z_k(\omega)` on the body modes."""
    wk = 2 * np.pi * np.asarray(frequency_hz, float)
    mk = np.asarray(modal_mass, float)
    n = 6 + wk.size
    M0, C0, K0 = (np.zeros((n, n)) for _ in range(3))
    M0[:6, :6] = M
    idx = np.arange(6, n)
    M0[idx, idx] = mk
    C0[idx, idx] = 2.0 * np.asarray(damping_ratio, float) * wk * mk
    K0[idx, idx] = wk ** 2 * mk
    return M0, C0, K0


def coupled_solve(M, omega, rows, shapes, abc, kip, body, load):
    r"""Solve the (6 + K) system of the module docstring for all speeds and harmonics through
    the one condensation (:func:`powertrain.physics.condensation.condensed_matrix`).

    Parameters
    ----------
    M : ndarray (6, 6)
    omega : ndarray (n_r, n_h) [rad/s]
    rows, shapes : ndarray (n_net, 6), (n_net, K)
        Network rows :math:`\mathbf r_n` and body shapes :math:`\mathbf s_n`
        (:meth:`ModalBody.network_shapes`).
    abc : tuple of ndarray (n_r, n_h, n_net)
        The networks' two-ports (only ``b`` and ``c`` are read).
    kip : ndarray (n_r, n_h, n_net)
        Engine-side term ``a`` (with the effects' input-point changes).
    body : ModalBody
        Or anything with ``frequency_hz``, ``modal_mass``, ``damping_ratio``.
    load : ndarray (n_r, n_h, 6)

    Returns
    -------
    ndarray (n_r, n_h, 6 + K) complex: :math:`\hat{\mathbf q}` then :math:`\hat{\boldsymbol\eta}`.
    """
    K = shapes.shape[1]
    E = np.hstack([rows, np.zeros((rows.shape[0], K))])
    B = np.hstack([np.zeros_like(rows), shapes])
    frame = modal_frame(M, body.frequency_hz, body.modal_mass, body.damping_ratio)
    D = condensed_matrix(frame, E, B, (kip, abc[1], abc[2]), 1j * np.asarray(omega, float))
    rhs = np.zeros(omega.shape + (6 + K,), complex)
    rhs[..., :6] = load
    return batched_solve(D, rhs)
