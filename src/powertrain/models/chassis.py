r"""The vehicle body (chassis) the mounts stand on: rigid, modal or measured receptances.

* ``rigid`` — the mounts' body side does not move (the thesis's set-up).
* ``modal`` — body modes shared by the mount attachment points:
  :math:`\mathbf x_B(P) = \sum_k \boldsymbol\psi_k(P)\,\eta_k`, each mode a single-DOF
  oscillator :math:`m_k(\ddot\eta_k + 2\zeta_k\omega_k\dot\eta_k + \omega_k^2\eta_k) =
  \sum_P \boldsymbol\psi_k(P)\cdot\mathbf f_P`. Shapes are dimensionless vectors in engine
  axes, one per mount attachment point and body point of interest; the modal mass belongs to
  that scaling. Receptance from a force at Q to the motion at P:
  :math:`\mathbf H_{PQ}(\omega) = \sum_k \boldsymbol\psi_k(P)\boldsymbol\psi_k(Q)^T /
  \big(m_k(\omega_k^2 - \omega^2 + 2i\zeta_k\omega_k\omega)\big)`.
* ``frf`` — measured receptances between the attachment points (and to the body points),
  coupled by admittance in the harmonic solver.

Body points of interest (``[chassis.points.NAME]``) are places where the body's response is
wanted (seat rail, steering wheel); they carry no load.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from powertrain.assembly import PASSIVE, passive_name, split_side  # noqa: F401 (re-export)

MODELS = ("rigid", "modal", "frf")


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
    """Measured receptances [m/N] on a frequency grid [Hz].

    ``values[(resp, rdir, exc, edir)]`` is a complex array over ``frequency_hz``; names are
    mounts (their body-side attachment points) or body points, directions engine x/y/z.
    """

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
    """The body under the mounts.

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

    @property
    def is_rigid(self) -> bool:
        return self.model == "rigid"

    def shape_matrix(self, name) -> np.ndarray:
        """(3, n_modes): the shape of every mode at attachment point or body point ``name``."""
        return np.array([m.shapes[name] for m in self.modes], float).reshape(-1, 3).T

    def modal_receptance(self, omega, responses, excitations) -> np.ndarray:
        """Modal receptance matrix (3 n_resp, 3 n_exc) [m/N] at ``omega`` [rad/s]."""
        P = np.vstack([self.shape_matrix(r) for r in responses])        # (3 nr, k)
        Q = np.vstack([self.shape_matrix(e) for e in excitations])      # (3 ne, k)
        d = np.array([m.modal_mass * (m.omega**2 - omega**2
                                      + 2j * m.damping_ratio * m.omega * omega)
                      for m in self.modes])
        return (P / d[None, :]) @ Q.T

    def receptances(self, omegas, responses, excitations) -> np.ndarray:
        """Receptance matrices (n_omega, 3 n_resp, 3 n_exc) [m/N] at every ``omegas``
        [rad/s] (vectorised for the modal body)."""
        omegas = np.asarray(omegas, float).ravel()
        if self.model != "modal":
            return np.array([self.receptance_at(w, responses, excitations) for w in omegas])
        P = np.vstack([self.shape_matrix(r) for r in responses])        # (3 nr, k)
        Q = np.vstack([self.shape_matrix(e) for e in excitations])      # (3 ne, k)
        wk = np.array([m.omega for m in self.modes])
        mk = np.array([m.modal_mass for m in self.modes])
        zk = np.array([m.damping_ratio for m in self.modes])
        w = omegas[:, None]
        d = mk * (wk**2 - w**2 + 2j * zk * wk * w)                       # (n_w, k)
        return np.einsum("ik,wk,jk->wij", P, 1.0 / d, Q)

    def receptance_at(self, omega, responses, excitations) -> np.ndarray:
        """Receptance matrix [m/N] of the body (modal or measured) at ``omega`` [rad/s]."""
        if self.model == "modal":
            return self.modal_receptance(omega, responses, excitations)
        if self.model == "frf":
            return self.receptance.at(omega, responses, excitations)
        return np.zeros((3 * len(responses), 3 * len(excitations)), complex)
