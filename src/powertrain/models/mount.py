r"""Mount model objects: a topology from thesis Table 2 plus its parameter values.

A :class:`Topology` names the point masses and Kelvin–Voigt elements of a lumped network
(nodes ``E`` engine side, ``G`` ground, named masses); a :class:`MountModel` adds SI values.
Topologies of Kovarik (2016), Table 2 (where the table gives only a name and a parameter
count, the project's documented choice matching the count), as ``node–node (c, d)``:

=====================  ===  ==========================================================
preset                 n    elements
=====================  ===  ==========================================================
``kelvin-voigt``        2   E–G (c1, d1)
``sls``                 3   E–G (c1), Maxwell branch E–n (c2) in series with n–G (d2),
                            n massless
``single``              7   E–G (c1,d1), E–m1 (c2,d2), m1–G (c3,d3)  [eq. 8–9]
``dual``               10   E–G (c1,d1), E–m1 (c2,d2), m1–m2 (c3,d3), m2–G (c4,d4)
``triple-series``      13   E–G (c1,d1), E–m1 (c2,d2), m1–m2 (c3,d3), m2–m3 (c4,d4),
                            m3–G (c5,d5)
``triple-parallel``    15   E–G (c1,d1), E–m1 (c2,d2), m1–G (c3,d3), E–m2 (c4,d4),
                            m2–m3 (c5,d5), m3–G (c6,d6)  [eq. 20–24; default]
``quad``               18   E–G (c1,d1), E–m1 (c2,d2), m1–m2 (c3,d3), m2–G (c4,d4),
                            E–m3 (c5,d5), m3–m4 (c6,d6), m4–G (c7,d7)
``penta``              23   triple-parallel plus E–m4 (c7,d7), m4–m5 (c8,d8), m5–G (c9,d9)
                            (parameter order of thesis Fig. 29)
``single-extra``       12   single plus an additional mass hung on m1: m1–m2 (c4,d4),
                            m2–G (c5,d5)
``dual-extra``         16   dual plus an additional mass hung on m1: m1–m3 (c5,d5),
                            m3–G (c6,d6), and an additional damper E–m2 (d7)
=====================  ===  ==========================================================
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

import numpy as np

from powertrain.physics import mount_network as net
from powertrain.physics.mount_elements import MountElement


@dataclass(frozen=True)
class Topology:
    """Structure of a lumped mount network.

    Attributes
    ----------
    name : str
        Preset name (``triple-parallel``...).
    description : str
        Field name of the model.
    parameters : tuple of str
        Parameter names in datasheet order (c*, d* and m*).
    masses : tuple of str or None
        Parameter name of each internal mass in node order; ``None``: massless node.
    elements : tuple of (str, str, str or None, str or None)
        ``(node_a, node_b, c_name, d_name)``, nodes ``"E"``, ``"G"``, ``"n1"``...; ``None``:
        that part absent.
    """

    name: str
    description: str
    parameters: tuple[str, ...]
    masses: tuple[str | None, ...]
    elements: tuple[tuple[str, str, str | None, str | None], ...]

    def __post_init__(self):
        used = {p for p in self.masses if p} | {
            p for e in self.elements for p in e[2:] if p}
        if used != set(self.parameters) or len(self.parameters) != len(set(self.parameters)):
            raise ValueError(f"topology {self.name}: parameter list does not match the network")

    @property
    def n_internal(self) -> int:
        return len(self.masses)

    @property
    def elem_nodes(self) -> np.ndarray:
        def idx(label):
            if label == "E":
                return net.ENGINE
            if label == "G":
                return net.GROUND
            return int(label[1:])
        return np.array([[idx(a), idx(b)] for a, b, _, _ in self.elements], dtype=int)


def _t(name, description, order, masses, elements):
    return Topology(name, description, tuple(order.split()), tuple(masses), tuple(elements))


TOPOLOGIES: dict[str, Topology] = {t.name: t for t in [
    _t("kelvin-voigt", "Kelvin-Voigt element", "c1 d1", [], [("E", "G", "c1", "d1")]),
    _t("sls", "Standard linear solid (Zener)", "c1 c2 d2", [None],
       [("E", "G", "c1", None), ("E", "n1", "c2", None), ("n1", "G", None, "d2")]),
    _t("single", "Single mass oscillator", "c1 d1 c2 d2 m1 c3 d3", ["m1"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "G", "c3", "d3")]),
    _t("dual", "Dual mass oscillator", "c1 d1 c2 d2 m1 c3 d3 m2 c4 d4", ["m1", "m2"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "n2", "c3", "d3"),
        ("n2", "G", "c4", "d4")]),
    _t("triple-series", "Triple mass oscillator - series connection",
       "c1 d1 c2 d2 m1 c3 d3 m2 c4 d4 m3 c5 d5", ["m1", "m2", "m3"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "n2", "c3", "d3"),
        ("n2", "n3", "c4", "d4"), ("n3", "G", "c5", "d5")]),
    _t("triple-parallel", "Triple mass oscillator - parallel connection",
       "c1 d1 c2 d2 m1 c3 d3 c4 d4 m2 c5 d5 m3 c6 d6", ["m1", "m2", "m3"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "G", "c3", "d3"),
        ("E", "n2", "c4", "d4"), ("n2", "n3", "c5", "d5"), ("n3", "G", "c6", "d6")]),
    _t("quad", "Quad mass oscillator",
       "c1 d1 c2 d2 m1 c3 d3 m2 c4 d4 c5 d5 m3 c6 d6 m4 c7 d7", ["m1", "m2", "m3", "m4"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "n2", "c3", "d3"),
        ("n2", "G", "c4", "d4"), ("E", "n3", "c5", "d5"), ("n3", "n4", "c6", "d6"),
        ("n4", "G", "c7", "d7")]),
    _t("penta", "Penta mass oscillator",
       "c1 d1 c2 d2 m1 c3 d3 c4 d4 m2 c5 d5 c6 d6 m3 m4 c7 d7 c8 d8 m5 c9 d9",
       ["m1", "m2", "m3", "m4", "m5"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "G", "c3", "d3"),
        ("E", "n2", "c4", "d4"), ("n2", "n3", "c5", "d5"), ("n3", "G", "c6", "d6"),
        ("E", "n4", "c7", "d7"), ("n4", "n5", "c8", "d8"), ("n5", "G", "c9", "d9")]),
    _t("single-extra", "Single mass oscillator - additional mass and damping",
       "c1 d1 c2 d2 m1 c3 d3 c4 d4 m2 c5 d5", ["m1", "m2"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "G", "c3", "d3"),
        ("n1", "n2", "c4", "d4"), ("n2", "G", "c5", "d5")]),
    _t("dual-extra", "Dual mass oscillator - additional mass and damping",
       "c1 d1 c2 d2 m1 c3 d3 m2 c4 d4 c5 d5 m3 c6 d6 d7", ["m1", "m2", "m3"],
       [("E", "G", "c1", "d1"), ("E", "n1", "c2", "d2"), ("n1", "n2", "c3", "d3"),
        ("n2", "G", "c4", "d4"), ("n1", "n3", "c5", "d5"), ("n3", "G", "c6", "d6"),
        ("E", "n2", None, "d7")]),
]}

#: The thesis's chosen model (sec. 2.3.6, eq. 20–24).
DEFAULT_TOPOLOGY = "triple-parallel"


@dataclass(frozen=True)
class MountModel:
    """A lumped mount model for one direction: topology plus parameters in SI.

    Parameters
    ----------
    topology : Topology
    params : dict of str to float
        Parameter values in SI: c [N/m], d [N·s/m], m [kg].
    name, source, notes : str
        Metadata carried from the mount file.
    port_law : object, optional
        Nonlinear force in parallel with the network (``[friction]``,
        :class:`~powertrain.physics.mount_laws.BergFriction`); None: linear.
    amplitude_law : object, optional
        The ``[amplitude]`` section (``PowerLaw`` or ``TableLaw``); None: amplitude independent.
    static_curve : StaticCurve, optional
        The ``[static]`` section; None: the static stiffness acts at any deflection.
    """

    topology: Topology
    params: dict = field(default_factory=dict)
    name: str = ""
    source: str = ""
    notes: str = ""
    port_law: object = None
    amplitude_law: object = None
    static_curve: object = None

    def __post_init__(self):
        missing = [p for p in self.topology.parameters if p not in self.params]
        if missing:
            raise ValueError(f"missing parameters {missing} for {self.topology.name}")

    @classmethod
    def from_values(cls, topology: str | Topology, values, **meta) -> MountModel:
        """Build from a sequence of SI values in the topology's parameter order."""
        topo = TOPOLOGIES[topology] if isinstance(topology, str) else topology
        values = np.asarray(values, dtype=float)
        return cls(topo, dict(zip(topo.parameters, values.tolist())), **meta)

    @property
    def values(self) -> np.ndarray:
        """Parameter values in SI, in the topology's parameter order."""
        return np.array([self.params[p] for p in self.topology.parameters], dtype=float)

    def network(self):
        """``(masses, elem_nodes, c, d)`` arrays (read-only, made once per model)."""
        return self._network

    @functools.cached_property
    def _network(self):
        t = self.topology
        arrays = (np.array([self.params[m] if m else 0.0 for m in t.masses], dtype=float),
                  t.elem_nodes,
                  np.array([self.params[e[2]] if e[2] else 0.0 for e in t.elements], float),
                  np.array([self.params[e[3]] if e[3] else 0.0 for e in t.elements], float))
        for array in arrays:
            array.setflags(write=False)
        return arrays

    def element(self) -> MountElement:
        """The element the assembled model holds for this direction."""
        return MountElement(self.network(), self.port_law, self.amplitude_law)

    @property
    def linear(self) -> bool:
        """True without amplitude law, friction and static curve."""
        return self.port_law is None and self.amplitude_law is None and \
            self.static_curve is None

    def cross_point_stiffness(self, frequency_hz) -> np.ndarray:
        """Cross-point dynamic stiffness K_CP [N/m] at ``frequency_hz`` [Hz] (eq. 39)."""
        return net.cross_point_stiffness(2 * np.pi * np.asarray(frequency_hz, float),
                                         *self.network())

    def input_point_stiffness(self, frequency_hz, engine_mass=0.0) -> np.ndarray:
        """Input-point dynamic stiffness K_IP [N/m], with ``engine_mass`` [kg] (eq. 2–3)."""
        return net.input_point_stiffness(2 * np.pi * np.asarray(frequency_hz, float),
                                         *self.network(), engine_mass=engine_mass)

    def forced_engine_mass_response(self, frequency_hz, engine_mass, force):
        """Engine mass [kg] on this mount under a harmonic force [N]: ``(x1 [m], F_T [N])``."""
        return net.forced_engine_mass_response(2 * np.pi * np.asarray(frequency_hz, float),
                                               *self.network(), engine_mass, force)

    def matrices(self, include_ground=False):
        """``(M, C, K)`` of the network, engine-side node first."""
        return net.network_matrices(*self.network(), include_ground=include_ground)

    def static_stiffness(self) -> float:
        """Cross-point stiffness at zero frequency [N/m]."""
        return float(self.cross_point_stiffness(0.0)[0].real)

    def with_params(self, **changes) -> MountModel:
        """A copy with some parameters replaced (SI)."""
        return replace(self, params={**self.params, **changes})

    def scaled(self, stiffness: float = 1.0, damping: float = 1.0) -> MountModel:
        """A copy with every spring times ``stiffness`` and every damper times ``damping``."""
        new = {p: v * (stiffness if p[0] == "c" else damping if p[0] == "d" else 1.0)
               for p, v in self.params.items()}
        return replace(self, params=new)

    def scaled_dynamic_stiffness(self, factor: float) -> MountModel:
        """A copy whose K_CP(ω) is ``factor`` times this one's (every c, d and m scaled)."""
        return replace(self, params={p: v * factor for p, v in self.params.items()})
