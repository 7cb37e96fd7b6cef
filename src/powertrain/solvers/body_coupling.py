r"""A modal body under the mounts on the fast cached path (:mod:`.fast_harmonic`).

Network n joins its engine-side node (:math:`\mathbf r_n\cdot\mathbf q`) to its base node on
the body, :math:`x_{B,n} = \mathbf s_n\cdot\boldsymbol\eta`, :math:`\mathbf s_n =
\boldsymbol\Psi_{m(n)}^T\mathbf e_n` (:math:`\boldsymbol\Psi_m` (3 × K) the mode shapes at
mount m), through its two-port :math:`F_E = a x_E + b x_B`, :math:`F_B = b x_E + c x_B`;
with :math:`Z_k = m_k(\omega_k^2 - \omega^2 + 2i\zeta_k\omega_k\omega)` the (6 + K) system

.. math:: \begin{bmatrix} -\omega^2\mathbf M + \sum_n a_n\mathbf r_n\mathbf r_n^T &
          \sum_n b_n\mathbf r_n\mathbf s_n^T \\ \sum_n b_n\mathbf s_n\mathbf r_n^T &
          \mathrm{diag}(Z_k) + \sum_n c_n\mathbf s_n\mathbf s_n^T \end{bmatrix}
          \begin{bmatrix}\hat{\mathbf q}\\ \hat{\boldsymbol\eta}\end{bmatrix} =
          \begin{bmatrix}\hat{\mathbf f}\\ \mathbf 0\end{bmatrix}

is solved per speed and harmonic: the modal model of :func:`powertrain.assembly.assemble`
with the networks' internal masses condensed exactly (tests/test_body_coupling.py).
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
        """The modal body of ``engine``; None for a rigid, absent or measured-receptance chassis."""
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
        """The same shapes with other ``frequency_hz`` [Hz], ``modal_mass`` [kg] and
        ``damping_ratio`` [1] (None: kept)."""
        return replace(self,
                       frequency_hz=self.frequency_hz if frequency_hz is None
                       else np.asarray(frequency_hz, float),
                       modal_mass=self.modal_mass if modal_mass is None
                       else np.asarray(modal_mass, float),
                       damping_ratio=self.damping_ratio if damping_ratio is None
                       else np.asarray(damping_ratio, float))

    def with_extra_mode(self, frequency_hz, modal_mass, damping_ratio, mount_shape) -> ModalBody:
        """The body with one more mode (last) of ``frequency_hz`` [Hz], ``modal_mass`` [kg],
        ``damping_ratio`` [1] and shape ``mount_shape`` (n_mounts, 3) at the mounts, zero at
        the body points."""
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
        """True when this body is the body ``base`` with one more mode (last), zero at the
        body points (:meth:`with_extra_mode`)."""
        k = base.n_modes
        return (self.n_modes == k + 1 and self.points == base.points
                and np.array_equal(self.frequency_hz[:k], base.frequency_hz)
                and np.array_equal(self.modal_mass[:k], base.modal_mass)
                and np.array_equal(self.damping_ratio[:k], base.damping_ratio)
                and np.array_equal(self.mount_shapes[..., :k], base.mount_shapes)
                and np.array_equal(self.point_shapes[..., :k], base.point_shapes)
                and not np.any(self.point_shapes[..., k]))

    def network_shapes(self, networks, axes) -> np.ndarray:
        r""":math:`\mathbf s_n = \boldsymbol\Psi_{m(n)}^T\mathbf e_n`, (n_net, K), for the
        ``networks`` ``[(mount index, axis name, model)]`` and mount rotations ``axes``."""
        return np.array([self.mount_shapes[mi].T @ np.asarray(axes[mi], float)[:, DIRECTIONS.index(ax)]
                         for mi, ax, _ in networks])

    def output_rows(self) -> np.ndarray:
        """Body coordinates to the passive channels (mount-major x, y, z), then the body
        points', (3 (n_mounts + n_points), K)."""
        return np.vstack([s for s in self.mount_shapes] + [s for s in self.point_shapes])


def body_channels(mount_names, body: ModalBody) -> list:
    """Body-side channel names: ``(NAME/passive, x|y|z)`` for each of ``mount_names``, then
    ``(POINT, x|y|z)`` for the points of ``body``."""
    return ([(passive_name(m), a) for m in mount_names for a in DIRECTIONS]
            + [(p, a) for p in body.points for a in DIRECTIONS])


def modal_frame(M, frequency_hz, modal_mass, damping_ratio):
    r"""Frame :math:`(\mathbf M_0, \mathbf C_0, \mathbf K_0)`, each (6 + K, 6 + K), of the rigid
    powertrain (mass ``M`` (6, 6)) and K body modes (``frequency_hz`` [Hz], ``modal_mass``
    [kg], ``damping_ratio`` [1]) as single-DOF oscillators."""
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
    r"""Solve the (6 + K) system of the module docstring for all speeds and harmonics
    (:func:`powertrain.physics.condensation.harmonic_solve`).

    Parameters
    ----------
    M : ndarray (6, 6)
        Rigid-body mass matrix [kg, kg·m²].
    omega : ndarray (n_r, n_h) [rad/s]
    rows, shapes : ndarray (n_net, 6), (n_net, K)
        Network rows :math:`\mathbf r_n` and body shapes :math:`\mathbf s_n`.
    abc : tuple of ndarray (n_r, n_h, n_net)
        The networks' two-ports (only ``b`` and ``c`` are read).
    kip : ndarray (n_r, n_h, n_net)
        Engine-side term ``a`` [N/m].
    body : ModalBody
        Or anything with ``frequency_hz``, ``modal_mass``, ``damping_ratio``.
    load : ndarray (n_r, n_h, 6)
    rows_on : tuple, optional
        :func:`coupled_rows` of ``rows``, ``shapes``.

    Returns
    -------
    ndarray (n_r, n_h, 6 + K) complex: :math:`\hat{\mathbf q}` then :math:`\hat{\boldsymbol\eta}`.
    """
    frame, E, B = coupled_frame(M, rows, shapes, body, rows_on)
    return harmonic_solve(frame, E, B, (kip, abc[1], abc[2]), 1j * np.asarray(omega, float), load)


def coupled_frame(M, rows, shapes, body, rows_on=None):
    """``(frame, E, B)``: the retained coordinates' frame and the networks' engine and base
    rows on them (arguments as :func:`coupled_solve`)."""
    E, B = coupled_rows(rows, shapes) if rows_on is None else rows_on
    return modal_frame(M, body.frequency_hz, body.modal_mass, body.damping_ratio), E, B


def coupled_rows(rows, shapes):
    """The networks' engine and base rows ``(E, B)``, each (n_net, 6 + K), from the network
    ``rows`` (n_net, 6) and body ``shapes`` (n_net, K)."""
    K = shapes.shape[1]
    return (np.hstack([rows, np.zeros((rows.shape[0], K))]), np.hstack([np.zeros_like(rows), shapes]))


def coupled_matrix(M, omega, rows, shapes, abc, kip, body):
    """The (6 + K) matrix of the module docstring, (..., 6 + K, 6 + K) (arguments as
    :func:`coupled_solve`)."""
    frame, E, B = coupled_frame(M, rows, shapes, body)
    return condensed_matrix(frame, E, B, (kip, abc[1], abc[2]), 1j * np.asarray(omega, float))


def one_more_mode_basis(M, omega, rows, shapes, abc, kip, body, load):
    r"""``(x0, W, P, G, c)`` of the (6 + K) system (arguments as :func:`coupled_solve`) for
    :func:`one_more_mode`: with :math:`\mathbf U` the columns :math:`[b_n\mathbf r_n;
    c_n\mathbf s_n]`, :math:`\mathbf x_0 = \mathbf D^{-1}\mathbf f`, :math:`\mathbf W =
    \mathbf D^{-1}\mathbf U`, :math:`\mathbf P = \mathbf U^T\mathbf x_0`, :math:`\mathbf G =
    \mathbf U^T\mathbf W`, and the base terms ``c``."""
    D = coupled_matrix(M, omega, rows, shapes, abc, kip, body)
    U = np.concatenate([abc[1][..., None, :] * rows.T, abc[2][..., None, :] * shapes.T],
                       axis=-2)                                    # (..., 6 + K, n_net)
    f = np.zeros(U.shape[:-1] + (1,), complex)
    f[..., :6, 0] = load
    X = np.linalg.solve(D, np.concatenate([f, U], axis=-1))
    x0, W = X[..., 0], X[..., 1:]
    return (x0, W, np.einsum("...in,...i->...n", U, x0), np.einsum("...in,...im->...nm", U, W), abc[2])


def one_more_mode(basis, shape, impedance):
    r"""Amplitudes (..., 6 + K + 1) of the system of ``basis`` (:func:`one_more_mode_basis`)
    with one more mode of shape ``shape`` (n_net,) along the networks and modal dynamic
    stiffness ``impedance`` (...) [N/m], exactly by the Schur complement: with
    :math:`z = Z + \sum_n c_n s_n'^2`, :math:`\eta = -\mathbf s'\cdot\mathbf P/(z -
    \mathbf s'^T\mathbf G\mathbf s')`, :math:`\mathbf x = \mathbf x_0 - \eta\,\mathbf W\mathbf s'`
    (tests/test_missing_body_mode.py)."""
    x0, W, P, G, c = basis
    s = np.asarray(shape, float)
    z = impedance + (c * s ** 2).sum(axis=-1) - np.einsum("n,...nm,m->...", s, G, s)
    eta = -(P @ s) / z
    return np.concatenate([x0 - (W @ s) * eta[..., None], eta[..., None]], axis=-1)
