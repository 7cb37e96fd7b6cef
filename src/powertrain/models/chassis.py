r"""The vehicle body (chassis) the mounts stand on: rigid, modal or measured receptances.

``rigid`` (body side still), ``modal`` (body modes, receptance
:math:`\mathbf H_{PQ}(\omega) = \sum_k \boldsymbol\psi_k(P)\boldsymbol\psi_k(Q)^T /
\big(m_k(\omega_k^2 - \omega^2 + 2i\zeta_k\omega_k\omega)\big)`) or ``frf`` (measured
receptances, coupled by admittance); ``docs/guide/chassis.md``. Body points carry no load.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.errors import InputError


@dataclass(frozen=True, eq=False)
class BodyMode:
    """One body mode: natural frequency [Hz], damping ratio [-], modal mass [kg] and the
    dimensionless shape vector (engine axes) at each attachment point and body point."""

    frequency: float
    damping_ratio: float
    modal_mass: float
    shapes: dict

    @property
    def omega(self) -> float:
        return 2.0 * np.pi * self.frequency


@dataclass(frozen=True, eq=False)
class MeasuredReceptance:
    """Measured receptances [m/N]: ``values[(resp, rdir, exc, edir)]`` complex over
    ``frequency_hz`` [Hz]; names are mounts or body points, directions engine x/y/z."""

    frequency_hz: np.ndarray
    values: dict
    file: str = ""

    def at(self, omega, responses, excitations) -> np.ndarray:
        """Receptance matrix (3 len(responses), 3 len(excitations)) at ``omega`` [rad/s],
        linearly interpolated in frequency; reciprocity fills a missing pair."""
        f = omega / (2 * np.pi)
        out = np.zeros((3 * len(responses), 3 * len(excitations)), complex)
        for i, r in enumerate(responses):
            for a, rd in enumerate("xyz"):
                for j, e in enumerate(excitations):
                    for b, ed in enumerate("xyz"):
                        h = self.values.get((r, rd, e, ed))
                        if h is None:
                            h = self.values[(e, ed, r, rd)]
                        out[3 * i + a, 3 * j + b] = (np.interp(f, self.frequency_hz, h.real)
                                                     + 1j * np.interp(f, self.frequency_hz,
                                                                      h.imag))
        return out


@dataclass(frozen=True, eq=False)
class Chassis:
    """The body under the mounts; ``Chassis(model=...)`` makes :class:`RigidChassis`,
    :class:`ModalChassis` or :class:`MeasuredChassis`.

    Attributes
    ----------
    model : str
        ``rigid``, ``modal`` or ``frf``.
    modes : tuple of BodyMode
        ``modal`` only.
    points : tuple of str
        Body points of interest.
    receptance : MeasuredReceptance or None
        ``frf`` only.
    """

    model: str = "rigid"
    modes: tuple = ()
    points: tuple = ()
    receptance: MeasuredReceptance | None = None
    file: str = ""
    notes: dict = field(default_factory=dict)

    is_rigid = False
    #: coupled by its receptances in the frequency domain only
    coupled_by_admittance = False

    def __new__(cls, model="rigid", *args, **kwargs):
        if cls is Chassis:
            if model not in CHASSIS_CLASSES:
                raise ValueError(f"unknown chassis model {model!r}")
            cls = CHASSIS_CLASSES[model]
        return object.__new__(cls)

    @property
    def body_modes(self) -> tuple:
        """Body modes that become coordinates of the assembled model (none by default)."""
        return ()

    def shape_matrix(self, name) -> np.ndarray:
        """(3, n_modes): the shape of every mode at attachment point or body point ``name``."""
        return np.array([m.shapes[name] for m in self.modes], float).reshape(-1, 3).T

    def body_rows(self, name) -> np.ndarray:
        """Rows (3, n_body_modes) from the body coordinates to the motion at ``name``."""
        return np.zeros((3, len(self.body_modes)))

    def require_time_domain(self) -> None:
        """Raise InputError when the body cannot be integrated in time."""

    def receptances(self, omegas, responses, excitations) -> np.ndarray:
        """Receptance matrices (n_omega, 3 n_resp, 3 n_exc) [m/N] at ``omegas`` [rad/s]."""
        omegas = np.asarray(omegas, float).ravel()
        return np.array([self.receptance_at(w, responses, excitations) for w in omegas])

    def receptance_at(self, omega, responses, excitations) -> np.ndarray:
        """Receptance matrix [m/N] of the body at ``omega`` [rad/s] (rigid: zero)."""
        return np.zeros((3 * len(responses), 3 * len(excitations)), complex)


class RigidChassis(Chassis):
    """The mounts stand on rigid ground."""

    is_rigid = True


class ModalChassis(Chassis):
    """Body modes, coordinates of the assembled model."""

    @property
    def body_modes(self) -> tuple:
        return tuple(self.modes)

    def body_rows(self, name) -> np.ndarray:
        return self.shape_matrix(name)

    def receptances(self, omegas, responses, excitations) -> np.ndarray:
        omegas = np.asarray(omegas, float).ravel()
        P = np.vstack([self.shape_matrix(r) for r in responses])        # (3 nr, k)
        Q = np.vstack([self.shape_matrix(e) for e in excitations])      # (3 ne, k)
        wk = np.array([m.omega for m in self.modes])
        mk = np.array([m.modal_mass for m in self.modes])
        zk = np.array([m.damping_ratio for m in self.modes])
        w = omegas[:, None]
        d = mk * (wk**2 - w**2 + 2j * zk * wk * w)                       # (n_w, k)
        return np.einsum("ik,wk,jk->wij", P, 1.0 / d, Q)

    def receptance_at(self, omega, responses, excitations) -> np.ndarray:
        return self.receptances([omega], responses, excitations)[0]


class MeasuredChassis(Chassis):
    """Measured receptances, coupled by admittance in the frequency domain."""

    coupled_by_admittance = True

    def require_time_domain(self) -> None:
        raise InputError("a measured-receptance chassis (model = \"frf\") is coupled in the "
                         "frequency domain only: use the harmonic solver",
                         file=self.file or None, key="chassis.model")

    def receptance_at(self, omega, responses, excitations) -> np.ndarray:
        return self.receptance.at(omega, responses, excitations)


#: The chassis class of each ``[chassis] model`` name.
CHASSIS_CLASSES = {"rigid": RigidChassis, "modal": ModalChassis, "frf": MeasuredChassis}
MODELS = tuple(CHASSIS_CLASSES)
