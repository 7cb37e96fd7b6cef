r"""Lumped mount networks: point masses joined by Kelvin–Voigt elements.

Every lumped mount model of Kovarik (2016), Table 2, is a small linear network: the
engine-side node (0), ``n`` internal point masses (``1..n``) and the ground (``GROUND = -1``);
element ``e`` is a spring ``c_e`` [N/m] and a damper ``d_e`` [N·s/m] in parallel. Under
harmonic motion (eq. 10–12) :math:`\mathbf D(\omega) = \mathbf K + i\omega\mathbf C -
\omega^2\mathbf M`; with the internal masses condensed, the cross-point stiffness
:math:`K_{CP} = F_T/\hat X_1` (eq. 1, 24, 39) and the input-point stiffness
:math:`K_{IP} = F_1/\hat X_1` (eq. 2, 3) follow, exactly eq. 29–39 for the triple mass
oscillator in parallel connection.

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
_SINGULAR = "mount network singular at some frequency (two-port pivot below tolerance)"


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
        Keep the ground node as the last degree of freedom (size ``n + 2``, for a compliant
        body); else the ground is fixed (size ``n + 1``).

    Returns
    -------
    M, C, K : ndarray, shape (n + 1, n + 1) or (n + 2, n + 2)
        [kg, N·s/m, N/m]; the engine-side node carries no mass.
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
    r"""Rows ``kg`` [N/m], ``dg`` [N·s/m] (n_internal + 1,) of the force to ground
    :math:`F_T = \mathbf k_g \cdot \mathbf x + \mathbf d_g \cdot \dot{\mathbf x}` (Kovarik 2016,
    eq. 24), state as :func:`network_matrices`."""
    _, C, K = network_matrices(np.zeros(n_internal), elem_nodes, c, d, include_ground=True)
    return -K[:-1, -1], -C[:-1, -1]


def two_port(omega, masses, elem_nodes, c, d, spring_scale=1.0, damper_scale=None, *,
             internal=False):
    r"""Two-port dynamic stiffness ``(a, b, c)`` between engine side and ground at ``omega``
    [rad/s]: :func:`laplace_two_port` at :math:`s = i\omega`; :math:`a = K_{IP}`,
    :math:`b = -K_{CP}` (ground fixed)."""
    return laplace_two_port(1j * np.asarray(omega, float), masses, elem_nodes, c, d,
                            spring_scale, damper_scale, internal=internal)


def laplace_two_port(s, masses, elem_nodes, c, d, spring_scale=1.0, damper_scale=None, *,
                     internal=False):
    r"""Two-port of :math:`\mathbf D(s) = \mathbf K + s\mathbf C + s^2\mathbf M` with the
    internal nodes eliminated (:func:`powertrain.kernels.two_port.two_port_kernel`).

    Parameters
    ----------
    s : array_like complex
        Laplace variable [1/s], any shape.
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`.
    spring_scale, damper_scale : float or array_like
        Factors on every spring and damper (broadcast to ``s``; dampers default to springs').
    internal : bool
        Also return the internal motion per unit engine-side and per unit ground motion,
        shape ``s.shape + (n_internal, 2)``.

    Returns
    -------
    a, b, c : ndarray complex, shape of ``s`` [N/m]
        (and ``X`` when ``internal``); raises ``FloatingPointError`` where singular.
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
        raise FloatingPointError(_SINGULAR)
    res = tuple(v.reshape(lam.shape) for v in out)
    return res + (x.reshape(lam.shape + x.shape[1:]),) if internal else res


def laplace_two_ports(s, networks, spring_scales, damper_scales):
    r""":func:`laplace_two_port` of several networks in one kernel call.

    Parameters
    ----------
    s : array_like complex
        Laplace variable [1/s], any shape.
    networks : list of tuple or PackedNetworks
        ``(masses, elem_nodes, c, d)`` per network, or packed once (:meth:`PackedNetworks.of`).
    spring_scales, damper_scales : array_like float
        Factors on network k's springs and dampers at ``[..., k]``, broadcast to
        ``s.shape + (n_net,)``.

    Returns
    -------
    a, b, c : ndarray complex, each ``s.shape + (n_net,)`` [N/m]
        Raises ``FloatingPointError`` where a network is singular.
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
        raise FloatingPointError(_SINGULAR)
    return tuple(v.T.reshape(shape) for v in out)


@dataclass(frozen=True, eq=False)
class PackedNetworks:
    """Several networks concatenated for the kernel: network k's masses [kg] are
    ``masses[mass_ptr[k]:mass_ptr[k + 1]]``, its elements (``elem_nodes``, ``c`` [N/m],
    ``d`` [N·s/m]) rows ``el_ptr[k]:el_ptr[k + 1]``."""

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
        """The kernel's arguments ``(mass_ptr, masses, el_ptr, elem_nodes, c, d)``."""
        return self.mass_ptr, self.masses, self.el_ptr, self.elem_nodes, self.c, self.d


def cross_point_stiffness(omega, masses, elem_nodes, c, d):
    r"""Cross-point dynamic stiffness :math:`K_{CP}(\omega) = F_T/\hat X_1` [N/m], complex
    (n_freq,), base grounded (Kovarik 2016, eq. 1 and 39).

    Parameters
    ----------
    omega : float or array_like
        Angular frequency [rad/s].
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`.
    """
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    return -two_port(omega, masses, elem_nodes, c, d)[1]


def input_point_stiffness(omega, masses, elem_nodes, c, d, engine_mass=0.0):
    r"""Input-point dynamic stiffness :math:`K_{IP}(\omega) = F_1/\hat X_1` [N/m], base
    grounded (Kovarik 2016, eq. 2–3), less :math:`\omega^2 m_e` for ``engine_mass`` [kg]."""
    omega = np.atleast_1d(np.asarray(omega, dtype=float))
    return two_port(omega, masses, elem_nodes, c, d)[0] - omega**2 * engine_mass


def forced_engine_mass_response(omega, masses, elem_nodes, c, d, engine_mass, force):
    r"""Engine mass on the mount under a harmonic force (Kovarik 2016, sec. 3.2, App. A):
    :math:`\hat X_1 = F/(K_{IP} - \omega^2 m_e)`, :math:`F_T = K_{CP}\,\hat X_1`.

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
    x1, ft : ndarray of complex
        Engine-mass displacement amplitude [m] and force transmitted to ground [N].
    """
    kip = input_point_stiffness(omega, masses, elem_nodes, c, d, engine_mass)
    kcp = cross_point_stiffness(omega, masses, elem_nodes, c, d)
    x1 = force / kip
    return x1, kcp * x1


def incidence_matrix(n_internal, elem_nodes):
    r"""Element incidence over engine side (0), internal masses (``1..n``), ground (``n + 1``):
    row ``e`` has ``+1`` at node ``a`` and ``-1`` at node ``b``.

    Parameters
    ----------
    n_internal : int
        Number of internal nodes ``n``.
    elem_nodes : array_like of int, shape (n_el, 2)
        Node pairs, see :func:`network_matrices`.
    """
    elem_nodes = np.asarray(elem_nodes, dtype=int).reshape(-1, 2)
    B = np.zeros((elem_nodes.shape[0], n_internal + 2))
    for e, (a, b) in enumerate(elem_nodes):
        B[e, n_internal + 1 if a == GROUND else a] += 1.0
        B[e, n_internal + 1 if b == GROUND else b] -= 1.0
    return B


def cross_point_stiffness_gradient(omega, masses, elem_nodes, c, d):
    r"""Cross-point stiffness and its derivatives with respect to every c, d and m.

    With :math:`\hat{\mathbf X}` the motion for a unit engine-side displacement (ground held)
    and :math:`\hat{\mathbf Y}` for a unit ground displacement (engine side held),
    :math:`K_{CP} = -\hat{\mathbf Y}^T \mathbf D\,\hat{\mathbf X}` and, with the elongations
    :math:`u_e = X_a - X_b`, :math:`v_e = Y_a - Y_b`:
    :math:`\partial K_{CP}/\partial c_e = -u_e v_e`,
    :math:`\partial K_{CP}/\partial d_e = -i\omega\,u_e v_e`,
    :math:`\partial K_{CP}/\partial m_j = \omega^2 X_j Y_j` (Kovarik 2016, sec. 2.2, eq. 19).

    Parameters
    ----------
    omega : float or array_like
        Angular frequency [rad/s].
    masses, elem_nodes, c, d
        Network, see :func:`network_matrices`: masses [kg], c [N/m], d [N·s/m].

    Returns
    -------
    kcp, dk_dm, dk_dc, dk_dd : ndarray of complex
        :math:`K_{CP}` (n_freq,) [N/m] and its derivatives (n_freq, n_internal) [N/(m·kg)],
        (n_freq, n_el) [1] and (n_freq, n_el) [1/s].
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
