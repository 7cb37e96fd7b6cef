r"""Small-rotation rigid-body kinematics of the powertrain.

Generalized coordinates :math:`\mathbf q = (u_x, u_y, u_z, \theta_x, \theta_y, \theta_z)`:
translation of the centre of gravity and small rotations, in engine axes. A point at
:math:`\mathbf r` from the CG moves by :math:`\mathbf u + \boldsymbol\theta\times\mathbf r
= \mathbf u - [\mathbf r]_\times \boldsymbol\theta`.
"""

from __future__ import annotations

import numpy as np


def skew(r) -> np.ndarray:
    """Cross-product matrix: ``skew(r) @ a == np.cross(r, a)``."""
    x, y, z = np.asarray(r, float)
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def point_motion_matrix(r) -> np.ndarray:
    r"""3×6 matrix mapping :math:`\mathbf q` to the motion of a point at ``r`` [m] from the CG.

    :math:`\mathbf x_P = [\,\mathbf I \;\; -[\mathbf r]_\times\,]\,\mathbf q`.
    """
    return np.hstack([np.eye(3), -skew(r)])


def direction_row(r, e) -> np.ndarray:
    r"""1×6 row giving the motion of point ``r`` along unit vector ``e``:
    :math:`\mathbf e\cdot(\mathbf u + \boldsymbol\theta\times\mathbf r)
    = [\,\mathbf e^T \;\; (\mathbf r\times\mathbf e)^T\,]\,\mathbf q`."""
    (r0, r1, r2), (e0, e1, e2) = (np.asarray(v, float).tolist() for v in (r, e))
    return np.array([e0, e1, e2, r1 * e2 - r2 * e1, r2 * e0 - r0 * e2, r0 * e1 - r1 * e0])


def rigid_body_mass_matrix(mass, inertia) -> np.ndarray:
    """6×6 mass matrix about the CG: diag(m, m, m) and the inertia tensor [kg, kg·m²]."""
    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = np.asarray(inertia, float)
    return M
