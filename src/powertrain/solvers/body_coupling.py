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
from powertrain.physics.condensation import condensed_matrix, harmonic_solve


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

    def adds_one_mode_to(self, base) -> bool:
        """True when this body is ``base`` with one more mode (last) that is zero at the
        body points (:meth:`with_extra_mode`): its response is :func:`one_more_mode`'s."""
        k = base.n_modes
        return (self.n_modes == k + 1 and self.points == base.points
                and np.array_equal(self.frequency_hz[:k], base.frequency_hz)
                and np.array_equal(self.modal_mass[:k], base.modal_mass)
                and np.array_equal(self.damping_ratio[:k], base.damping_ratio)
                and np.array_equal(self.mount_shapes[..., :k], base.mount_shapes)
                and np.array_equal(self.point_shapes[..., :k], base.point_shapes)
                and not np.any(self.point_shapes[..., k]))

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


def coupled_solve(M, omega, rows, shapes, abc, kip, body, load, rows_on=None):
    r"""Solve the (6 + K) system of the module docstring for all speeds and harmonics by the
    one harmonic solve (:func:`powertrain.physics.condensation.harmonic_solve`).

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
    rows_on : tuple, optional
        :func:`coupled_rows` of ``rows``, ``shapes``, if at hand.

    Returns
    -------
    ndarray (n_r, n_h, 6 + K) complex: :math:`\hat{\mathbf q}` then :math:`\hat{\boldsymbol\eta}`.
    """
    frame, E, B = coupled_frame(M, rows, shapes, body, rows_on)
    return harmonic_solve(frame, E, B, (kip, abc[1], abc[2]), 1j * np.asarray(omega, float),
                          load)


def coupled_frame(M, rows, shapes, body, rows_on=None):
    """The retained coordinates' frame (rigid body, body modes) and the networks' engine and
    base rows on them, ``(frame, E, B)`` (arguments as :func:`coupled_solve`)."""
    E, B = coupled_rows(rows, shapes) if rows_on is None else rows_on
    return modal_frame(M, body.frequency_hz, body.modal_mass, body.damping_ratio), E, B


def coupled_rows(rows, shapes):
    """The networks' engine and base rows ``(E, B)`` on the retained coordinates (rigid
    body, body modes), each (n_net, 6 + K), from the network rows ``rows`` (n_net, 6) and
    body shapes ``shapes`` (n_net, K)."""
    K = shapes.shape[1]
    return (np.hstack([rows, np.zeros((rows.shape[0], K))]),
            np.hstack([np.zeros_like(rows), shapes]))


def coupled_matrix(M, omega, rows, shapes, abc, kip, body):
    """The (6 + K) matrix of the module docstring per speed and harmonic, (..., 6 + K,
    6 + K), through the one condensation (arguments as :func:`coupled_solve`)."""
    frame, E, B = coupled_frame(M, rows, shapes, body)
    return condensed_matrix(frame, E, B, (kip, abc[1], abc[2]), 1j * np.asarray(omega, float))


def one_more_mode_basis(M, omega, rows, shapes, abc, kip, body, load):
    r"""What :func:`one_more_mode` needs of the (6 + K) system of :func:`coupled_solve`
    (its matrix :math:`\mathbf D`, load :math:`\mathbf f`), solved once: one more body mode
    couples to it through :math:`\mathbf u = \mathbf U\mathbf s'`, :math:`\mathbf s'`
    (n_net,) the new mode's shape along each network and :math:`\mathbf U` the columns
    :math:`[b_n\mathbf r_n; c_n\mathbf s_n]`. Returns ``(x0, W, P, G, c)``:
    :math:`\mathbf x_0 = \mathbf D^{-1}\mathbf f`, :math:`\mathbf W = \mathbf D^{-1}\mathbf U`,
    :math:`\mathbf P = \mathbf U^T\mathbf x_0`, :math:`\mathbf G = \mathbf U^T\mathbf W`
    and the networks' base terms ``c``, per speed and harmonic (arguments as
    :func:`coupled_solve`)."""
    D = coupled_matrix(M, omega, rows, shapes, abc, kip, body)
    U = np.concatenate([abc[1][..., None, :] * rows.T, abc[2][..., None, :] * shapes.T],
                       axis=-2)                                    # (..., 6 + K, n_net)
    f = np.zeros(U.shape[:-1] + (1,), complex)
    f[..., :6, 0] = load
    X = np.linalg.solve(D, np.concatenate([f, U], axis=-1))
    x0, W = X[..., 0], X[..., 1:]
    return (x0, W, np.einsum("...in,...i->...n", U, x0), np.einsum("...in,...im->...nm", U, W),
            abc[2])


def one_more_mode(basis, shape, impedance):
    r"""Amplitudes (..., 6 + K + 1) of the system of :func:`one_more_mode_basis` with one
    more body mode, its shape along each network ``shape`` (n_net,) and its modal dynamic
    stiffness ``impedance`` (...): the bordered system :math:`[[\mathbf D, \mathbf u];
    [\mathbf u^T, z]]` with :math:`z = Z + \sum_n c_n s_n'^2` solved by its Schur
    complement, :math:`\eta = -\mathbf s'\cdot\mathbf P/(z - \mathbf s'^T\mathbf G
    \mathbf s')`, :math:`\mathbf x = \mathbf x_0 - \eta\,\mathbf W\mathbf s'` — exact,
    the same as :func:`coupled_solve` on the body with the mode
    (tests/test_missing_body_mode.py)
    at a few products per speed and harmonic instead of a solve."""
    x0, W, P, G, c = basis
    s = np.asarray(shape, float)
    z = impedance + (c * s ** 2).sum(axis=-1) - np.einsum("n,...nm,m->...", s, G, s)
    eta = -(P @ s) / z
    return np.concatenate([x0 - (W @ s) * eta[..., None], eta[..., None]], axis=-1)
