r"""Condensation of the assembled model: the mount networks' internal coordinates eliminated
through their two-ports, at any Laplace variable :math:`s`.

The retained coordinates R (rigid body, body modes) have
:math:`\mathbf D_0(s) = \mathbf K_0 + s\mathbf C_0 + s^2\mathbf M_0`; network n joins its
engine-side motion :math:`\mathbf p_{E,n}\cdot\mathbf q_R` to its base motion
:math:`\mathbf p_{B,n}\cdot\mathbf q_R` through the two-port
:math:`\mathbf T_n = [[a_n, b_n]; [b_n, c_n]]`
(:func:`powertrain.physics.mount_network.laplace_two_port`), so exactly

.. math:: \mathbf D_R(s) = \mathbf D_0(s) + \sum_n \mathbf P_n^T\mathbf T_n(s)\mathbf P_n,
          \qquad \mathbf P_n = [\mathbf p_{E,n}; \mathbf p_{B,n}].
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from powertrain.kernels import kernel_input
from powertrain.kernels.condensation import condensed_matrix_kernel
from powertrain.kernels.small_solve import batched_solve_kernel
from powertrain.physics.mount_elements import describing_stiffnesses


@dataclass(frozen=True)
class NetworkPorts:
    """How the networks sit on the retained coordinates R.

    Attributes
    ----------
    retained : ndarray int (n_R,)
        Indices of R in the full coordinates.
    frame : tuple of ndarray (n_R, n_R)
        :math:`\\mathbf M_0, \\mathbf C_0, \\mathbf K_0` of R without the networks.
    engine_rows, base_rows : ndarray (n_net, n_R)
        :math:`\\mathbf p_E`, :math:`\\mathbf p_B` per network (base rows zero: ground).
    internal : list of (start, n_internal)
        Each network's internal coordinates in the full numbering.
    elements : list
        Each network's :class:`~powertrain.physics.mount_elements.MountElement`.
    """

    retained: np.ndarray
    frame: tuple
    engine_rows: np.ndarray
    base_rows: np.ndarray
    internal: list
    elements: list

    @property
    def grounded(self) -> bool:
        return not np.any(self.base_rows)


def two_ports(ports: NetworkPorts, s, internal=False, amplitudes=None, linear=None):
    """Equivalent-linear two-ports ``(a, b, c)``, each ``s.shape + (n_net,)`` [N/m], of every
    network at ``s`` [1/s] and its ``amplitudes`` (n_net,) [m] (None: zero); also the internal
    motions when ``internal``. ``linear`` (:func:`linear_two_ports`): reused, only the port
    laws' describing stiffnesses added."""
    s = np.asarray(s, complex)
    amplitudes = np.zeros(len(ports.elements)) if amplitudes is None else amplitudes
    if linear is not None:
        return _with_port_laws(ports, s, internal, amplitudes, linear)
    abc = [np.empty(s.shape + (len(ports.elements),), complex) for _ in range(3)]
    shapes = []
    describing = [None] * len(ports.elements) if any(np.ndim(a) for a in amplitudes) \
        else describing_stiffnesses(ports.elements, amplitudes)
    for k, element in enumerate(ports.elements):
        res = element.two_port(s, amplitudes[k], internal=internal, describing=describing[k])
        for j in range(3):
            abc[j][..., k] = res[j]
        if internal:
            shapes.append(res[3])
    return (tuple(abc), shapes) if internal else tuple(abc)


@dataclass(frozen=True)
class LinearTwoPorts:
    """The networks' linear two-ports ``abc`` (each ``s.shape + (n_net,)``) and internal
    motions ``shapes`` at some ``s``."""

    abc: tuple
    shapes: list

    def first(self, k) -> LinearTwoPorts:
        """The same at the first ``k`` values of a one-dimensional ``s``."""
        return LinearTwoPorts(tuple(x[:k] for x in self.abc), [x[:k] for x in self.shapes])


def linear_two_ports(ports: NetworkPorts, s) -> LinearTwoPorts | None:
    """Each network's linear two-port and internal motions at ``s`` [1/s]; None when an
    amplitude law makes one depend on the amplitude."""
    s = np.asarray(s, complex)
    res = [element.linear_two_port(s, internal=True) for element in ports.elements]
    if any(r is None for r in res):
        return None
    return LinearTwoPorts(tuple(np.stack([r[j] for r in res], axis=-1) for j in range(3)),
                          [r[3] for r in res])


def _with_port_laws(ports, s, internal, amplitudes, linear):
    """:func:`two_ports` from ``linear`` plus the port laws' describing stiffnesses at s != 0."""
    kd = np.zeros(len(ports.elements), complex)
    for k, d in enumerate(describing_stiffnesses(ports.elements, amplitudes)):
        if d is not None:
            kd[k] = d
    kd = np.where(s[..., None] == 0, 0.0, kd)
    a, b, c = linear.abc
    abc = (a + kd, b - kd, c + kd)
    return (abc, linear.shapes) if internal else abc


def condensed_matrix(frame, engine_rows, base_rows, abc, s):
    r""":math:`\mathbf D_R(s)`, shape ``s.shape + (n_R, n_R)``, for two-port values ``abc``
    (each ``s.shape + (n_net,)``); ``base_rows`` None: every base grounded."""
    s = np.asarray(s, complex)
    M0, C0, K0 = (kernel_input(x) for x in frame)
    n, n_net = M0.shape[0], engine_rows.shape[0]
    B = np.zeros((0, n)) if base_rows is None else base_rows
    a, b, c = (kernel_input(np.reshape(abc[0] if x is None else x, (s.size, n_net)), complex)
               for x in abc)
    D = np.empty((s.size, n, n), complex)
    condensed_matrix_kernel(kernel_input(s.reshape(-1), complex), M0, C0, K0,
                            kernel_input(engine_rows), kernel_input(B), a, b, c, D)
    return D.reshape(s.shape + (n, n))


def condense(system, keep, s):
    r"""Dynamic stiffness :math:`\mathbf K + s\mathbf C + s^2\mathbf M` of ``system`` on
    ``keep``, all other coordinates eliminated exactly, every network as measured
    (:meth:`~powertrain.physics.mount_elements.MountElement.as_measured`).

    Parameters
    ----------
    system : AssembledSystem
    keep : array_like int
        Kept coordinates; a subset of the retained ones (rigid body, body modes).
    s : complex or array_like
        Laplace variable [1/s].

    Returns
    -------
    ndarray complex, ``shape(s) + (n_keep, n_keep)``
    """
    ports = system.ports()
    ports = replace(ports, elements=[element.as_measured() for element in ports.elements])
    s = np.asarray(s, complex)
    D = condensed_matrix(ports.frame, ports.engine_rows,
                         None if ports.grounded else ports.base_rows, two_ports(ports, s), s)
    pos = {int(j): i for i, j in enumerate(ports.retained)}
    if any(int(j) not in pos for j in keep):
        raise ValueError("condense keeps only retained coordinates (rigid body, body modes)")
    k = np.array([pos[int(j)] for j in keep], int)
    rest = np.setdiff1d(np.arange(ports.retained.size), k)
    Dk = D[..., k[:, None], k[None, :]]
    if rest.size:
        Dkr = D[..., k[:, None], rest[None, :]]
        Dk = Dk - Dkr @ np.linalg.solve(D[..., rest[:, None], rest[None, :]],
                                        D[..., rest[:, None], k[None, :]])
    return Dk


def harmonic_solve(frame, engine_rows, base_rows, abc, s, load):
    r"""Harmonic steady state :math:`\mathbf D_R(s)\hat{\mathbf q}_R = \hat{\mathbf f}`,
    the load on the rigid body's six coordinates, for every ``s`` at once.

    Parameters
    ----------
    frame, engine_rows, base_rows, abc, s
        As :func:`condensed_matrix` (``s`` = :math:`i\omega` [1/s]).
    load : ndarray ``s.shape + (6,)`` complex
        Amplitudes of the 6-vector load about the CG [N, N·m].

    Returns
    -------
    ndarray ``s.shape + (n_R,)`` complex
        Amplitudes of the retained coordinates [m, rad, modal].
    """
    D = condensed_matrix(frame, engine_rows, base_rows, abc, s)
    rhs = np.zeros(D.shape[:-1], complex)
    rhs[..., :6] = load
    return batched_solve(D, rhs)


def batched_solve(D, b):
    """Solutions ``x`` (..., n) of ``D x = b`` for a stack ``D`` (..., n, n); raises
    ``numpy.linalg.LinAlgError`` on a singular matrix."""
    D = np.asarray(D)
    b = np.asarray(b)
    n = D.shape[-1]
    shape = np.broadcast_shapes(D.shape[:-2], b.shape[:-1]) + (n,)
    Df = kernel_input(np.broadcast_to(D, shape[:-1] + (n, n)), np.complex128)
    bf = kernel_input(np.broadcast_to(b, shape), np.complex128)
    x = np.empty(shape, np.complex128)
    if batched_solve_kernel(Df.reshape(-1, n, n), bf.reshape(-1, n), x.reshape(-1, n)):
        raise np.linalg.LinAlgError("Singular matrix")
    return x
