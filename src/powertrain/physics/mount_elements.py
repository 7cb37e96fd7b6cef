r"""Mount elements: one mount direction as the assembled model and its solvers see it.

A :class:`MountElement` is a linear network (:mod:`powertrain.physics.mount_network`) and,
optionally, a *port law* in parallel on the relative displacement :math:`u = x_E - x_B`
(``docs/extending.md``). In the frequency domain it is an equivalent-linear two-port (the
law's describing function :math:`k_{eq}(A)` added at every :math:`s \ne 0`; no mean force),
in the time domain the law's kernel arrays (:class:`PortForces`). A port law has ``kind``,
``parameters()``, ``initial_state(u0, f0)``, ``describing_stiffness(amplitude)`` and
``steady_state(amplitude, centre=0)`` (its memory at the lower tip of the steady loop,
moving up).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.kernels.port_forces import JENKINS, NONE, port_forces_at
from powertrain.physics.mount_network import (
    PackedNetworks,
    laplace_two_port,
    laplace_two_ports,
    network_matrices,
)


@dataclass(frozen=True)
class JenkinsFriction:
    r"""A spring :math:`k` in series with a Coulomb slider of slip force :math:`F_s`:
    :math:`f = k(u - z)`, :math:`|f| \le F_s`, the slider position :math:`z` its memory.

    Describing function (Caughey 1960), :math:`\delta = F_s/(kA)`: :math:`k_{eq} = k` for
    :math:`\delta \ge 1`, otherwise

    .. math:: k_{eq} = \frac{k}{\pi}\left(\varphi - \tfrac12\sin 2\varphi\right)
              + i\,\frac{4k}{\pi}\,\delta(1 - \delta), \qquad \cos\varphi = 1 - 2\delta.

    Parameters
    ----------
    stiffness : float
        k [N/m] (> 0).
    slip_force : float
        F_s [N] (>= 0).
    """

    stiffness: float
    slip_force: float
    kind = JENKINS

    def parameters(self) -> np.ndarray:
        return np.array([self.stiffness, self.slip_force], float)

    def initial_state(self, u0: float, f0: float = 0.0) -> np.ndarray:
        """Slider where the element carries ``f0`` (clipped to the slip force) at ``u0``."""
        if self.stiffness <= 0:
            return np.array([u0], float)
        return np.array([u0 - np.clip(f0, -self.slip_force, self.slip_force) / self.stiffness])

    def steady_state(self, amplitude: float, centre: float = 0.0) -> np.ndarray:
        """Slider at the lower tip of the steady loop of ``amplitude`` [m] about ``centre`` [m]."""
        return np.array([centre - amplitude + min(self.stiffness * amplitude, self.slip_force)
                         / self.stiffness])

    def describing_stiffness(self, amplitude) -> np.ndarray:
        """Equivalent complex stiffness [N/m] at the displacement amplitude [m]."""
        amplitude = np.asarray(amplitude, float)
        k = self.stiffness
        with np.errstate(divide="ignore", invalid="ignore"):
            delta = np.where(amplitude > 0, self.slip_force / (k * amplitude), np.inf)
        d = np.minimum(delta, 1.0)
        phi = np.arccos(1.0 - 2.0 * d)
        slip = k / np.pi * (phi - 0.5 * np.sin(2 * phi)) + 4j * k / np.pi * d * (1 - d)
        return np.where(delta >= 1.0, k + 0j, slip)


def describing_stiffnesses(elements, amplitudes) -> list:
    """Each element's port-law describing stiffness at its amplitude [m] (None without a port
    law), one vectorised call per distinct law."""
    out = [None] * len(elements)
    for law, index in _by_law(elements, "port_law").items():
        values = law.describing_stiffness(np.array([amplitudes[k] for k in index], float))
        for k, value in zip(index, values):
            out[k] = value
    return out


def _by_law(elements, kind) -> dict:
    """``{law: [indices of the elements holding it]}`` of their ``kind`` law (not None)."""
    groups = {}
    for k, el in enumerate(elements):
        if getattr(el, kind) is not None:
            groups.setdefault(getattr(el, kind), []).append(k)
    return groups


def element_two_ports(elements, s, amplitudes, packed=None):
    r""":meth:`MountElement.two_port` of several elements, each ``s.shape + (n_el,)``: element
    k at ``amplitudes[..., k]`` [m], the networks condensed in one kernel call (``packed``:
    the networks packed once by the caller, :class:`PackedNetworks`)."""
    lam = np.asarray(s, complex)
    A = np.asarray(amplitudes, float)
    scales = np.ones((2,) + A.shape)
    for law, index in _by_law(elements, "amplitude_law").items():   # one call per law
        ks, ds = law.scales(A[..., index])
        scales[0][..., index], scales[1][..., index] = ks, ds
    for k, el in enumerate(elements):
        scales[:, ..., k] *= el.static_factor
    if packed is None:
        packed = PackedNetworks.of([el.lumped for el in elements])
    a, b, c = laplace_two_ports(lam, packed, *scales)
    for k, el in enumerate(elements):
        if el.port_law is not None:
            kd = np.where(lam == 0, 0.0, el.port_law.describing_stiffness(A[..., k]))
            a[..., k] += kd
            b[..., k] -= kd
            c[..., k] += kd
    return a, b, c


@dataclass(frozen=True, eq=False)
class MountElement:
    """One mount direction: a linear network, scaled by its amplitude law and its static
    factor, and an optional port law in parallel.

    Parameters
    ----------
    lumped : tuple
        The linear network ``(masses, elem_nodes, c, d)``
        (:mod:`powertrain.physics.mount_network`).
    port_law : object, optional
        Nonlinear force between the engine-side and base nodes, e.g.
        :class:`powertrain.physics.mount_laws.BergFriction`.
    amplitude_law : object, optional
        ``scales(A) -> (stiffness factor, damping factor)`` on every spring and damper at the
        relative-displacement amplitude A [m] (:class:`~powertrain.physics.mount_laws.PowerLaw`,
        ``TableLaw``); masses unscaled.
    static_factor : float
        Factor on every spring and damper from the static curve at the operating point [-].
    """

    lumped: tuple
    port_law: object = None
    amplitude_law: object = None
    static_factor: float = 1.0

    @property
    def nonlinear(self) -> bool:
        """True when the element depends on its amplitude (port law or amplitude law)."""
        law = self.amplitude_law
        return self.port_law is not None or (law is not None and not law.constant)

    def scales(self, amplitude=0.0):
        """``(stiffness factor, damping factor)`` of the network at the amplitude [m]."""
        if self.amplitude_law is None:
            return self.static_factor, self.static_factor
        ks, ds = self.amplitude_law.scales(amplitude)
        return self.static_factor * float(ks), self.static_factor * float(ds)

    def scale_arrays(self, amplitude):
        """:meth:`scales` at an array of amplitudes [m] (the static factor may be an array)."""
        if self.amplitude_law is None:
            return self.static_factor * 1.0, self.static_factor * 1.0
        ks, ds = self.amplitude_law.scales(amplitude)
        return self.static_factor * ks, self.static_factor * ds

    def at_operating_point(self, static_factor: float) -> MountElement:
        """A copy with the static curve's factor at an operating point."""
        return MountElement(self.lumped, self.port_law, self.amplitude_law, float(static_factor))

    def as_measured(self) -> MountElement:
        """The network at the static factor, without amplitude law or port law (the linear
        view of :func:`powertrain.physics.condensation.condense`)."""
        return MountElement(self.lumped, static_factor=self.static_factor)

    def scaled(self, stiffness: float, damping: float) -> MountElement:
        """A copy with every spring times ``stiffness`` and every damper times ``damping``."""
        masses, nodes, c, d = self.lumped
        return MountElement((masses, nodes, c * stiffness, d * damping), self.port_law,
                            self.amplitude_law, self.static_factor)

    def network(self, amplitude=0.0):
        """``(masses, elem_nodes, c, d)`` of the linear network at the amplitude [m]."""
        masses, nodes, c, d = self.lumped
        ks, ds = self.scales(amplitude)
        if ks == 1.0 and ds == 1.0:
            return masses, nodes, c, d
        return masses, nodes, c * ks, d * ds

    def matrices(self, include_ground=False, amplitude=0.0):
        """``(M, C, K)`` of the linear network at the amplitude (without the port law)."""
        return network_matrices(*self.network(amplitude), include_ground=include_ground)

    def two_port(self, s, amplitude=0.0, internal=False, describing=None):
        """Equivalent-linear two-port ``(a, b, c)`` at ``s`` [1/s] and the amplitude [m]
        (scalar or broadcasting to ``s``); the internal motions too when ``internal``.
        ``describing``: the port law's describing stiffness, when the caller has it."""
        lam = np.asarray(s, complex)
        if np.ndim(amplitude) == 0:
            res = laplace_two_port(lam, *self.network(amplitude), internal=internal)
        else:
            amplitude = np.broadcast_to(np.asarray(amplitude, float), lam.shape)
            res = laplace_two_port(lam, *self.lumped, *self.scale_arrays(amplitude),
                                   internal=internal)
        if self.port_law is None:
            return res
        if describing is None:
            describing = self.port_law.describing_stiffness(amplitude)
        k = np.where(lam == 0, 0.0, describing)
        return (res[0] + k, res[1] - k, res[2] + k) + res[3:]

    def linear_two_port(self, s, internal=False):
        """The network's two-port at ``s`` without the port law; None with an amplitude law."""
        if self.amplitude_law is not None:
            return None
        return laplace_two_port(np.asarray(s, complex), *self.network(0.0), internal=internal)

    def cross_point_stiffness(self, frequency_hz, amplitude=0.0) -> np.ndarray:
        """Equivalent-linear cross-point dynamic stiffness K*(f, A) [N/m] at ``frequency_hz``
        [Hz] and ``amplitude`` [m], base grounded."""
        s = 2j * np.pi * np.asarray(frequency_hz, float)
        return -self.two_port(s, amplitude)[1]

@dataclass(frozen=True)
class PortForces:
    """The port laws of an assembled model as kernel arrays.

    Attributes
    ----------
    rows : ndarray (m, n)
        Relative displacement across each port law per unit coordinate.
    kinds : ndarray int64 (m,); parameters : ndarray (m, n_par)
    laws : list
        The port-law objects.
    force_map : ndarray (n_ch, m)
        Transmitted-force channels per unit port force (engine axes).
    names : list of str
        ``mount.direction`` of each port law.
    index : ndarray int (m,)
        Each port law's network among the assembled networks.
    n_networks : int
        Networks in the model.
    """

    rows: np.ndarray
    kinds: np.ndarray
    parameters: np.ndarray
    laws: list
    force_map: np.ndarray
    names: list = field(default_factory=list)
    index: np.ndarray = field(default_factory=lambda: np.zeros(0, int))
    n_networks: int = 0

    def network_amplitudes(self, amplitudes) -> np.ndarray:
        """Amplitudes of every network (n_networks,) [m], zero at the linear ones."""
        out = np.zeros(self.n_networks)
        out[self.index] = amplitudes
        return out

    def describing_forces(self, amplitudes, relative) -> np.ndarray:
        """Equivalent-linear port forces (n_h, m) [N] of the relative-motion harmonics
        ``relative`` (n_h, m) at the ``amplitudes`` (m,) [m]."""
        k = np.array([0j if law is None else law.describing_stiffness(a)
                      for law, a in zip(self.laws, amplitudes)])
        z = relative * k[None, :]
        z[0] = 0.0                                    # a port law carries no mean force
        return z

    def initial_state(self, x0, f0=None) -> np.ndarray:
        """State rows (m, n_state) at the coordinates ``x0`` carrying the forces ``f0`` (m,) [N]
        (default: unloaded)."""
        u0 = self.rows @ np.asarray(x0, float)
        f0 = np.zeros(u0.size) if f0 is None else f0
        return _state_rows([np.zeros(1) if law is None else law.initial_state(u, f)
                            for law, u, f in zip(self.laws, u0, f0)])

    def steady_states(self, amplitudes, centres) -> np.ndarray:
        """State rows (m, n_state) at the lower tip of each steady loop of ``amplitudes`` [m]
        about ``centres`` [m]."""
        return _state_rows([np.zeros(1) if law is None else law.steady_state(a, c)
                            for law, a, c in zip(self.laws, amplitudes, centres)])

    def select(self, keep) -> PortForces:
        """The port laws where the boolean mask ``keep`` (m,) is true."""
        keep = np.asarray(keep, bool)
        return PortForces(self.rows[keep], self.kinds[keep], self.parameters[keep],
                          [law for law, k in zip(self.laws, keep) if k],
                          np.ascontiguousarray(self.force_map[:, keep]),
                          [name for name, k in zip(self.names, keep) if k], self.index[keep],
                          self.n_networks)

    def forces(self, u, v, state) -> np.ndarray:
        """Port forces (m,) [N] at the relative motions ``u``, ``v`` (m,) from ``state``."""
        out = np.empty(self.kinds.size)
        port_forces_at(self.kinds, self.parameters, np.ascontiguousarray(state, float),
                       np.ascontiguousarray(u, float), np.ascontiguousarray(v, float), out)
        return out


def port_forces(elements, rows, force_map, names) -> PortForces | None:
    """The port laws among ``elements`` (per network: its port row, force-map column and
    name) as kernel arrays; None when every element is linear."""
    idx = [k for k, el in enumerate(elements) if el.nonlinear]
    if not idx:
        return None
    laws = [elements[k].port_law for k in idx]
    par = _state_rows([np.zeros(1) if law is None else law.parameters() for law in laws])
    kinds = np.array([NONE if law is None else law.kind for law in laws], np.int64)
    return PortForces(np.ascontiguousarray(rows[idx]), kinds, par, laws,
                      np.ascontiguousarray(force_map[:, idx]), [names[k] for k in idx],
                      np.array(idx, int), len(elements))


def _state_rows(states) -> np.ndarray:
    """1-D arrays of any length as zero-padded rows (m, n)."""
    states = [np.atleast_1d(st) for st in states]
    out = np.zeros((len(states), max(st.size for st in states)))
    for e, st in enumerate(states):
        out[e, :st.size] = st
    return out
