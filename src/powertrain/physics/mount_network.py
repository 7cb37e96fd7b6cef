r"""Lumped mount networks: point masses joined by Kelvin–Voigt elements.

Every lumped mount model of Kovarik (2016), Table 2, is a small linear network. Its nodes are
the engine-side node (index 0), ``n`` internal point masses (indices ``1..n``) and the ground
node (index ``GROUND = -1``, the chassis side). Each element ``e`` joins two nodes with a spring
``c_e`` [N/m] and a viscous damper ``d_e`` [N·s/m] in parallel (Kelvin–Voigt).

With harmonic motion :math:`x = \hat X e^{i\omega t}` (eq. 10–12) each element has the complex
stiffness :math:`k_e = c_e + i\omega d_e` and the network the dynamic stiffness matrix

.. math:: \mathbf D(\omega) = \mathbf K + i\omega\mathbf C - \omega^2\mathbf M .

Prescribing the engine-side displacement :math:`\hat X_1` with the base grounded, the internal
masses follow from :math:`\mathbf D_{ii}\hat{\mathbf X}_i = -\mathbf D_{i1}\hat X_1`, and

* the cross-point dynamic stiffness is the force transmitted to ground per unit engine-side
  displacement, :math:`K_{CP} = F_T/\hat X_1 = \sum_{e\,\in\,\text{ground}} k_e\,\hat X_{e}/\hat X_1`
  (eq. 1, 24 and 39 in general form);
* the input-point dynamic stiffness is the force needed at the engine-side node,
  :math:`K_{IP} = \mathbf D_{11} + \mathbf D_{1i}\hat{\mathbf X}_i/\hat X_1` (eq. 2, 3), plus
  :math:`-\omega^2 m_e` when an engine mass rides on the node.

For the triple mass oscillator in parallel connection this is exactly eq. 29–39.

References
----------
.. [1] B. Kovarik, *Modeling of the Nonlinear Frequency Dependent Engine Mount Dynamic
   Stiffness*, Master's thesis, University of Zagreb, 2016.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from powertrain.kernels import kernel_input
from powertrain.kernels.two_port import kcp_gradient_kernel, two_port_kernel, two_ports_kernel

#: Index of the ground (chassis) node in ``elem_nodes``.
GROUND = -1
#: Index of the engine-side node.
ENGINE = 0


def network_matrices(masses, elem_nodes, c, d, *, include_ground=False):
    r"""Mass, damping and stiffness matrices of a mount network.

    Parameters
    ----------
    masses : array_like, shape (n,)
        Internal point masses [kg] (zero allowed: a massless node).
    elem_nodes : array_like of int, shape (n_el, 2)
        Node pairs of the elements; 0 = engine side, 1..n = internal, -1 = ground.
    c : array_like, shape (n_el,)
        Element stiffnesses [N/m].
    d : array_like, shape (n_el,)
        Element damping coefficients [N·s/m].
    include_ground : bool
        If False (default) the ground is fixed and the matrices have size ``n + 1``
        (engine-side node first). If True the ground node is kept as the last degree of
        freedom (size ``n + 2``), for assembly on a compliant body.

    Returns
    -------
    M, C, K : ndarray, shape (n + 1, n + 1) or (n + 2, n + 2)
        The engine-side node carries no mass of its own [kg, N·s/m, N/m].
    """
    masses = np.asarray(masses, dtype=float)
    n = masses.size
    B = incidence_matrix(n, elem_nodes)
    keep = slice(None) if include_ground else slice(0, n + 1)
    M = np.zeros((n + 2, n + 2))
    M[1:n + 1, 1:n + 1] = np.diag(masses)
    C, K = (B.T @ (np.asarray(v, dtype=float)[:, None] * B) for v in (d, c))
    return M[keep, keep], C[keep, keep], K[keep, keep]


def ground_force_rows(n_internal, elem_nodes, c, d):
    r"""Rows giving the force transmitted to ground from the network state.

    :math:`F_T = \mathbf k_g \cdot \mathbf x + \mathbf d_g \cdot \dot{\mathbf x}` with the
    state ordered as in :func:`network_matrices` (ground fixed). Eq. 24 in general form.

    Returns
    -------
    kg, dg : ndarray, shape (n_internal + 1,)
        [N/m] and [N·s/m].
    """
    _, C, K = network_matrices(np.zeros(n_internal), elem_nodes, c, d, include_ground=True)
    return -K[:-1, -1], -C[:-1, -1]


def two_port(omega, masses, elem_nodes, c, d, spring_scale=1.0, damper_scale=None, *,
             internal=False):
    r"""Two-port dynamic stiffness ``(a, b, c)`` between the engine-side node and the ground
    node at angular frequencies ``omega`` [rad/s]: :func:`laplace_two_port` at
    :math:`s = i\omega`.

    .. math:: \begin{pmatrix} F_E \\ F_B \end{pmatrix} =
              \begin{pmatrix} a & b \\ b & c \end{pmatrix}
              \begin{pmatrix} x_E \\ x_B \end{pmatrix},
              \qquad a = K_{IP},\; b = -K_{CP}\ \text{(ground fixed)}.
    """
    return laplace_two_port(1j * np.asarray(omega, float), masses, elem_nodes, c, d,
                            spring_scale, damper_scale, internal=internal)


def laplace_two_port(s, masses, elem_nodes, c, d, spring_scale=1.0, damper_scale=None, *,
                     internal=False):
    r"""The one mount two-port condensation
    (:func:`powertrain.kernels.two_port.two_port_kernel`, pivot checked): the network's
    :math:`\mathbf D(s) = \mathbf K + s\mathbf C + s^2\mathbf M` with its internal nodes
    eliminated, grounded (``a``) and ungrounded (``a, b, c``).

    Parameters
    ----------
    s : array_like complex
        Laplace variable [1/s], any shape (:math:`i\omega` harmonic, 0 static, complex for a
        damped mode).
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`.
    spring_scale, damper_scale : float or array_like
        Factors on every spring and damper (broadcast to ``s``; dampers default to the
        springs' factor), masses kept.
    internal : bool
        Also return the internal nodes' motion per unit engine-side motion (ground held) and
        per unit ground-node motion (engine side held), shape ``s.shape + (n_internal, 2)``.

    Returns
    -------
    a, b, c : ndarray complex, shape of ``s`` [N/m]
        (and ``X`` when ``internal``).

    Raises
    ------
    FloatingPointError
        The network is singular at some ``s`` (a pivot below the kernel's tolerance).
    """
    lam = np.asarray(s, complex)
    sc = np.broadcast_to(np.asarray(spring_scale, float), lam.shape)
    t = sc if damper_scale is None else np.broadcast_to(np.asarray(damper_scale, float),
                                                        lam.shape)
    flat = [kernel_input(x.reshape(-1), x.dtype) for x in (lam, sc, t)]
    masses = kernel_input(np.reshape(masses, -1))
    out = [np.empty(flat[0].size, complex) for _ in range(3)]
    x = np.empty((flat[0].size if internal else 0, masses.size, 2), complex)
    status = two_port_kernel(*flat, masses,
                             kernel_input(np.reshape(elem_nodes, (-1, 2)), np.int64),
                             kernel_input(c), kernel_input(d), *out, x)
    if status:
        raise FloatingPointError("mount network singular at some frequency (two-port pivot "
                                 "below tolerance)")
    res = tuple(v.reshape(lam.shape) for v in out)
    return res + (x.reshape(lam.shape + x.shape[1:]),) if internal else res


def laplace_two_ports(s, networks, spring_scales, damper_scales):
    r""":func:`laplace_two_port` of several networks in one kernel call
    (:func:`powertrain.kernels.two_port.two_ports_kernel`, the same elimination per network).

    Parameters
    ----------
    s : array_like complex
        Laplace variable [1/s], any shape.
    networks : list of tuple or PackedNetworks
        ``(masses, elem_nodes, c, d)`` per network (:func:`network_matrices`), or the same
        packed once (:meth:`PackedNetworks.of`) by a caller that condenses them many times.
    spring_scales, damper_scales : array_like float
        Factors on network k's springs and dampers at ``[..., k]``, broadcast to
        ``s.shape + (n_net,)``.

    Returns
    -------
    a, b, c : ndarray complex, each ``s.shape + (n_net,)`` [N/m]

    Raises
    ------
    FloatingPointError
        A network is singular at some ``s``.
    """
    packed = networks if isinstance(networks, PackedNetworks) else PackedNetworks.of(networks)
    lam = np.asarray(s, complex)
    n = packed.n_networks
    shape = lam.shape + (n,)
    scales = [kernel_input(np.broadcast_to(np.asarray(x, float), shape).reshape(-1, n).T)
              for x in (spring_scales, damper_scales)]
    out = [np.empty((n, lam.size), complex) for _ in range(3)]
    if two_ports_kernel(kernel_input(lam.reshape(-1), complex), *scales, *packed.arrays(),
                        *out):
        raise FloatingPointError("mount network singular at some frequency (two-port pivot "
                                 "below tolerance)")
    return tuple(v.T.reshape(shape) for v in out)


@dataclass(frozen=True, eq=False)
class PackedNetworks:
    """Several networks concatenated as :func:`laplace_two_ports` hands them to
    :func:`powertrain.kernels.two_port.two_ports_kernel`: network k's masses are
    ``masses[mass_ptr[k]:mass_ptr[k + 1]]``, its elements (node pairs ``elem_nodes``,
    springs ``c`` [N/m], dampers ``d`` [N·s/m]) rows ``el_ptr[k]:el_ptr[k + 1]``."""

    mass_ptr: np.ndarray
    masses: np.ndarray
    el_ptr: np.ndarray
    elem_nodes: np.ndarray
    c: np.ndarray
    d: np.ndarray

    @classmethod
    def of(cls, networks) -> PackedNetworks:
        """Pack ``(masses, elem_nodes, c, d)`` per network."""
        ptr = [np.cumsum([0] + [len(net[i]) for net in networks]) for i in (0, 2)]
        arrays = [np.concatenate([np.asarray(net[i], float).reshape(-1) for net in networks])
                  for i in (0, 2, 3)]
        nodes = np.concatenate([np.asarray(net[1], np.int64).reshape(-1, 2)
                                for net in networks])
        return cls(*(kernel_input(a, a.dtype) for a in (ptr[0], arrays[0], ptr[1], nodes,
                                                        arrays[1], arrays[2])))

    @property
    def n_networks(self) -> int:
        """Number of networks packed."""
        return self.mass_ptr.size - 1

    def arrays(self) -> tuple:
        """The kernel's arguments ``(mass_ptr, masses, el_ptr, elem_nodes, c, d)`` (read-only
        and contiguous since :meth:`of`)."""
        return self.mass_ptr, self.masses, self.el_ptr, self.elem_nodes, self.c, self.d


def cross_point_stiffness(omega, masses, elem_nodes, c, d):
    r"""Cross-point dynamic stiffness :math:`K_{CP}(\omega) = F_T/\hat X_1` [N/m].

    Base grounded, engine-side displacement prescribed; internal masses condensed
    (Kovarik 2016, eq. 1 and the general form of eq. 39).

    Parameters
    ----------
    omega : float or array_like
        Angular frequency [rad/s].
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`.

    Returns
    -------
    ndarray of complex, shape (n_freq,)
    """
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    return -two_port(omega, masses, elem_nodes, c, d)[1]


def input_point_stiffness(omega, masses, elem_nodes, c, d, engine_mass=0.0):
    r"""Input-point dynamic stiffness :math:`K_{IP}(\omega) = F_1/\hat X_1` [N/m].

    The force needed at the engine-side node per unit displacement, with the base grounded
    (Kovarik 2016, eq. 2–3). With ``engine_mass`` :math:`m_e` [kg] the inertia term
    :math:`-\omega^2 m_e` is included, so that :math:`\hat X_1 = F/K_{IP}` for a force
    :math:`F` on the engine mass.
    """
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    return two_port(omega, masses, elem_nodes, c, d)[0] - omega**2 * engine_mass


def forced_engine_mass_response(omega, masses, elem_nodes, c, d, engine_mass, force):
    r"""Engine mass on the mount under a harmonic force: the thesis's verification set-up.

    A force :math:`F e^{i\omega t}` acts on a mass :math:`m_e` carried by the mount
    (Kovarik 2016, sec. 3.2, Appendix A). The engine mass moves under the input-point
    stiffness, the ground sees the cross-point one:

    .. math:: \hat X_1 = \frac{F}{K_{IP}(\omega) - \omega^2 m_e}, \qquad
              F_T = K_{CP}(\omega)\,\hat X_1 .

    Parameters
    ----------
    omega : array_like
        Angular frequency [rad/s].
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`.
    engine_mass : float
        [kg]
    force : float
        Force amplitude [N].

    Returns
    -------
    x1 : ndarray of complex
        Engine-mass displacement amplitude [m].
    ft : ndarray of complex
        Force transmitted to ground [N].
    """
    kip = input_point_stiffness(omega, masses, elem_nodes, c, d, engine_mass)
    kcp = cross_point_stiffness(omega, masses, elem_nodes, c, d)
    x1 = force / kip
    return x1, kcp * x1


def incidence_matrix(n_internal, elem_nodes):
    r"""Element incidence over the extended node set (engine side, internal masses, ground).

    Row ``e`` has ``+1`` at node ``a`` and ``-1`` at node ``b`` of element ``e``; the nodes are
    ordered engine side (0), internal masses (``1..n``), ground (``n + 1``). The extended
    dynamic stiffness matrix is then
    :math:`\mathbf D = \mathbf B^T \operatorname{diag}(c + i\omega d)\,\mathbf B -
    \omega^2 \operatorname{diag}(0, \mathbf m, 0)`.

    Parameters
    ----------
    n_internal : int
        Number of internal nodes ``n``.
    elem_nodes : array_like of int, shape (n_el, 2)
        Node pairs, see :func:`network_matrices`.

    Returns
    -------
    ndarray, shape (n_el, n_internal + 2)
    """
    elem_nodes = np.asarray(elem_nodes, dtype=int).reshape(-1, 2)
    B = np.zeros((elem_nodes.shape[0], n_internal + 2))
    for e, (a, b) in enumerate(elem_nodes):
        B[e, n_internal + 1 if a == GROUND else a] += 1.0
        B[e, n_internal + 1 if b == GROUND else b] -= 1.0
    return B


def cross_point_stiffness_gradient(omega, masses, elem_nodes, c, d):
    r"""Cross-point stiffness and its derivatives with respect to every c, d and m.

    Two static condensations share one factorisation per frequency: the internal motion
    :math:`\hat{\mathbf X}` for a unit engine-side displacement with the ground held (the
    state behind :func:`cross_point_stiffness`), and the internal motion :math:`\hat{\mathbf Y}`
    for a unit ground displacement with the engine side held. Extending both over all nodes
    (:math:`X_E = 1, X_G = 0`; :math:`Y_E = 0, Y_G = 1`), the symmetric network gives

    .. math::
        K_{CP} = -\hat{\mathbf Y}^T \mathbf D(\omega)\,\hat{\mathbf X}, \qquad
        \frac{\partial K_{CP}}{\partial p} = -\hat{\mathbf Y}^T
        \frac{\partial \mathbf D}{\partial p}\hat{\mathbf X}

    (the second because :math:`\mathbf D\hat{\mathbf X}` and
    :math:`\mathbf D\hat{\mathbf Y}` vanish at the internal nodes), so with the element
    elongations :math:`u_e = X_a - X_b`, :math:`v_e = Y_a - Y_b`

    .. math::
        \frac{\partial K_{CP}}{\partial c_e} = -u_e v_e, \quad
        \frac{\partial K_{CP}}{\partial d_e} = -i\omega\,u_e v_e, \quad
        \frac{\partial K_{CP}}{\partial m_j} = \omega^2 X_j Y_j ,

    and :math:`K_{CP}` is homogeneous of degree one in the parameters,
    :math:`K_{CP} = \sum_p p\,\partial K_{CP}/\partial p`. This is the analytic Jacobian
    used for parameter identification (Kovarik 2016, sec. 2.2, eq. 19).

    Parameters
    ----------
    omega : float or array_like
        Angular frequency [rad/s].
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`: masses [kg], c [N/m], d [N·s/m].

    Returns
    -------
    kcp : ndarray of complex, shape (n_freq,)
        Cross-point dynamic stiffness [N/m].
    dk_dm : ndarray of complex, shape (n_freq, n_internal)
        [N/(m·kg)]
    dk_dc : ndarray of complex, shape (n_freq, n_el)
        [1]
    dk_dd : ndarray of complex, shape (n_freq, n_el)
        [1/s]
    """
    omega = kernel_input(np.atleast_1d(np.asarray(omega, dtype=float)))
    masses, c, d = (kernel_input(x) for x in (masses, c, d))
    n = masses.size
    B = kernel_input(incidence_matrix(n, elem_nodes))
    nf, n_el = omega.size, c.size
    kcp = np.empty(nf, dtype=complex)
    dk_dm = np.empty((nf, n), dtype=complex)
    dk_dc = np.empty((nf, n_el), dtype=complex)
    dk_dd = np.empty((nf, n_el), dtype=complex)
    kcp_gradient_kernel(omega, B, masses, c, d, kcp, dk_dm, dk_dc, dk_dd)   # NaN if singular
    return kcp, dk_dm, dk_dc, dk_dd
