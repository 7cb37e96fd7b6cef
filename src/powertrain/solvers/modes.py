r"""Rigid-body modes of the powertrain on its mounts: frequencies, damping, energy, torque roll.

Two methods:

* ``static`` — the six undamped modes of the body on the mounts' static (0 Hz) cross-point
  stiffness, the networks' internal nodes condensed statically:
  :math:`\mathbf K_{6}\boldsymbol\varphi = \omega^2\mathbf M_{6}\boldsymbol\varphi`.
* ``dynamic`` (default) — each mode with the mount networks' dynamic stiffness at its own
  (complex) frequency. The networks' internal degrees of freedom are condensed exactly at the
  complex eigenvalue :math:`s`: every network adds :math:`K_{IP}(s)\,\mathbf r\mathbf r^T`
  with :math:`K_{IP}(s) = D_{EE} - \mathbf D_{Ei}\mathbf D_{ii}^{-1}\mathbf D_{iE}`,
  :math:`\mathbf D(s) = \mathbf K + s\mathbf C + s^2\mathbf M` of the network. The nonlinear
  eigenproblem :math:`\big(s^2\mathbf M_6 + \sum K_{IP}(s)\mathbf r\mathbf r^T\big)\boldsymbol
  \varphi = 0` is solved per mode by a secant iteration on :math:`s` starting from the static
  mode (the branch is followed by the modal assurance criterion); every root is an eigenvalue
  of the full state-space model with the internal degrees of freedom, which is checked.
  Natural frequency :math:`|s|/2\pi`, damping ratio :math:`-\mathrm{Re}\,s/|s|`, damped
  frequency :math:`\mathrm{Im}\,s/2\pi`.

Kinetic-energy distribution of mode :math:`\boldsymbol\varphi` over the coordinates
``x, y, z, rx, ry, rz`` (CG translations and rotations about axes through the CG parallel to
the engine axes): :math:`E_j = \mathrm{Re}\big(\bar\varphi_j(\mathbf M\boldsymbol\varphi)_j\big)
/ \mathrm{Re}\big(\boldsymbol\varphi^H\mathbf M\boldsymbol\varphi\big)`, in percent (sums to
100). The shares are signed: the products of inertia couple rx, ry and rz in
:math:`\mathbf M`, and a damped mode's shape is complex, so a coordinate moving against the
energy flow of its coupled partner has a slightly negative share (a few tenths of a percent);
the text output says so whenever one is printed.

Torque-roll axis: the axis about which the free body turns under a torque about the crank axis
(engine X), :math:`\mathbf d = \mathbf I^{-1}\mathbf e_x/|\mathbf I^{-1}\mathbf e_x|` through
the CG (Jeong & Singh, J. Sound Vib. 234(1), 2000, sec. 2). Each mode's rotation axis is the
direction of its rotational part; the angle between the two axes is reported in 0..90°.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from powertrain.assembly import NetworkScaling
from powertrain.physics.condensation import condense

#: What the modes of a model with amplitude laws or friction take (printed with them).
AS_MEASURED = ("mounts as measured (networks as in their mount files: amplitude laws at "
               "factor 1, no friction)")

COORDINATES = ("x", "y", "z", "rx", "ry", "rz")
#: Relative change of s at which the secant iteration stops.
TOLERANCE = 1e-12
MAX_ITERATIONS = 60


# ---------------------------------------------------------------------------- physics
def torque_roll_axis(inertia, crank_axis=(1.0, 0.0, 0.0)) -> np.ndarray:
    """Unit direction of the torque-roll axis, :math:`\\mathbf I^{-1}\\mathbf e` normalised."""
    d = np.linalg.solve(np.asarray(inertia, float), np.asarray(crank_axis, float))
    d = d / np.linalg.norm(d)
    return d if d @ np.asarray(crank_axis, float) >= 0 else -d


def kinetic_energy_percent(M6, phi) -> np.ndarray:
    """:math:`100\\,\\mathrm{Re}(\\bar\\varphi_j(\\mathbf M\\varphi)_j)/\\mathrm{Re}(\\varphi^H
    \\mathbf M\\varphi)` per coordinate [%]."""
    phi = np.asarray(phi, complex)
    e = (np.conj(phi) * (M6 @ phi)).real
    return 100.0 * e / e.sum()


def number_or_null(value):
    """``value`` as a float, or None (JSON null) where it is undefined (NaN: the rotation
    axis of a mode without rotation)."""
    return float(value) if np.isfinite(value) else None


def _axis_angle_deg(a, b) -> float:
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return float("nan")
    return float(np.degrees(np.arccos(np.clip(abs(a @ b) / (na * nb), 0.0, 1.0))))


def _normalise(M6, phi):
    """Unit modal mass, phase so that the largest-energy entry is real positive."""
    phi = np.asarray(phi, complex)
    j = int(np.argmax((np.conj(phi) * (M6 @ phi)).real))
    phi = phi * np.exp(-1j * np.angle(phi[j]))
    return phi / np.sqrt((np.conj(phi) @ M6 @ phi).real)


def _condensed_stiffness(system, s):
    r""":math:`\mathbf D_R(s) - s^2\mathbf M_R` on the retained coordinates (rigid body, body
    modes), the networks condensed exactly at complex ``s``
    (:func:`powertrain.physics.condensation.condense`)."""
    keep = system.retained
    return condense(system, keep, s) - s * s * system.M[np.ix_(keep, keep)]


def _mac(a, b, M6) -> float:
    num = abs(np.conj(a) @ M6 @ b) ** 2
    return float(num / ((np.conj(a) @ M6 @ a).real * (np.conj(b) @ M6 @ b).real))


def _follow(system, M6, s0, phi0):
    """Secant iteration on s for the branch through (s0, phi0)."""
    def step(s, phi_ref):
        mu, vec = sla.eig(_condensed_stiffness(system, s), M6)
        k = int(np.argmax([_mac(vec[:, j], phi_ref, M6) for j in range(mu.size)]))
        return 1j * np.sqrt(mu[k]), vec[:, k]

    s_prev, phi = s0, phi0
    f_prev, phi = step(s_prev, phi)
    s = f_prev
    g_prev = f_prev - s_prev
    for it in range(1, MAX_ITERATIONS + 1):
        f, phi_new = step(s, phi)
        g = f - s
        if abs(g) <= TOLERANCE * abs(s):
            return f, phi_new, it
        phi = phi_new
        denom = g - g_prev
        s_next = f if denom == 0 else s - g * (s - s_prev) / denom
        s_prev, g_prev, s = s, g, s_next
    return s, phi, MAX_ITERATIONS


def _null_vector(system, M6, s):
    """Shape of a root s: null vector of s²M_R + K_R(s) (condensed)."""
    _, _, vh = np.linalg.svd(s * s * M6 + _condensed_stiffness(system, s))
    return np.conj(vh[-1])


def _body_roots(system, M6, cand):
    """The candidate roots with their shapes, without the networks' own internal roots (where
    a network's internal block is singular and the condensation has a pole)."""
    kept, shapes = [], []
    for c in cand:
        try:
            shapes.append(_null_vector(system, M6, c))
        except FloatingPointError:
            continue
        kept.append(c)
    return np.array(kept, complex), shapes


def _dynamic_roots(system, M6, omegas, vec):
    """Roots followed from each static mode, made unique against the exact eigenvalues.

    Each static mode is followed by :func:`_follow`. The full state-space eigenvalues near
    the rigid-body band are the candidates; static modes are assigned to distinct candidates
    (nearest root and shape, :func:`scipy.optimize.linear_sum_assignment`), so two branches
    can never land on the same eigenvalue.
    """
    from scipy.optimize import linear_sum_assignment
    followed = [_follow(system, M6, 1j * w, vec[:, i].astype(complex))
                for i, w in enumerate(omegas)]
    lam = _state_space_eigenvalues(system)
    top = 3.0 * max(omegas.max(), 1e-9)
    cand, shapes = _body_roots(system, M6, lam[(lam.imag > 0) & (np.abs(lam) < top)])
    if cand.size < len(followed):
        return followed
    cost = np.array([[abs(s - c) / abs(s) + 1.0 - _mac(phi, shapes[j], M6)
                      for j, c in enumerate(cand)] for s, phi, _ in followed])
    rows, cols = linear_sum_assignment(cost)
    out = []
    for i, j in zip(rows, cols):
        s, phi, its = followed[i]
        if abs(s - cand[j]) > 1e-6 * abs(s):           # branch lost: take the exact root
            s, phi = cand[j], shapes[j]
        out.append((s, phi, its))
    return out


def _pair_with_static(M, shapes, static_shapes) -> list:
    """``(index of the static mode, MAC)`` for each shape: the one-to-one pairing of largest
    total MAC (:func:`scipy.optimize.linear_sum_assignment`)."""
    from scipy.optimize import linear_sum_assignment
    mac = np.array([[_mac(phi, static_shapes[:, j].astype(complex), M)
                     for j in range(static_shapes.shape[1])] for phi in shapes])
    rows, cols = linear_sum_assignment(-mac)
    pair = dict(zip(rows, cols))
    return [(int(pair[i]), float(mac[i, pair[i]])) for i in range(len(shapes))]


def _static_condensed(system, keep) -> np.ndarray:
    """Static stiffness on the kept coordinates, the others condensed."""
    Kr = condense(system, keep, 0.0).real
    return 0.5 * (Kr + Kr.T)


def _state_space_eigenvalues(system) -> np.ndarray:
    """Finite eigenvalues of the full model (internal degrees of freedom included)."""
    n = system.n_dof
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-system.K, -system.C]])
    B = np.block([[np.eye(n), np.zeros((n, n))], [np.zeros((n, n)), system.M]])
    lam = sla.eig(A, B, right=False)
    return lam[np.isfinite(lam)]


def rigid_body_modes(system, inertia, *, static=False, crank_axis=(1.0, 0.0, 0.0)) -> dict:
    """The six rigid-body modes of an assembled powertrain, plus the body modes of a modal
    chassis (coupled through the mounts).

    Kinetic-energy shares are over the powertrain's six coordinates; a mode whose kinetic
    energy lies mostly in the body modes is of kind ``chassis``.

    Parameters
    ----------
    system : AssembledSystem
        The body on its mounts (:func:`powertrain.assembly.assemble`).
    inertia : array_like (3, 3)
        Inertia tensor about the CG [kg·m²] (for the torque-roll axis).
    static : bool
        Static stiffness, undamped (else: dynamic stiffness at each mode's own frequency).
    crank_axis : array_like (3,)
        Unit vector of the crank axis in engine axes (engine X).

    Returns ``{"modes": [fields of a powertrain.results.modes.Mode, by frequency],
    "torque_roll_axis": {...}, "method": str}``.
    """
    system, note = _as_measured(system)
    keep = system.retained
    MR = system.M[np.ix_(keep, keep)]
    w2, vec = sla.eigh(_static_condensed(system, keep), MR)
    tra = torque_roll_axis(inertia, crank_axis)
    omegas = np.sqrt(np.clip(w2, 0.0, None))
    roots = [(1j * w, vec[:, i].astype(complex), 0) for i, w in enumerate(omegas)]
    if not static:
        roots = _dynamic_roots(system, MR, omegas, vec)
    M6 = MR[:6, :6]
    modes = []
    pairs = _pair_with_static(MR, [phi for _, phi, _ in roots], vec)
    for (s, phi, its), (k, mac) in zip(roots, pairs):
        phi = _normalise(MR, phi)
        e = (np.conj(phi) * (MR @ phi)).real
        body_share = 100.0 * e[6:].sum() / e.sum()
        ked = kinetic_energy_percent(M6, phi[:6])
        rot = phi[3:6].real
        modes.append({"frequency_hz": abs(s) / (2 * np.pi),
                      "damping_ratio": 0.0 if static else float(-s.real / abs(s)),
                      "damped_frequency_hz": float(s.imag / (2 * np.pi)), "shape": phi[:6],
                      "ked_percent": ked, "iterations": its,
                      "angle_to_torque_roll_axis_deg": _axis_angle_deg(rot, tra),
                      "kind": "rigid-body" if body_share < 50.0 else "chassis",
                      "body_energy_percent": float(body_share),
                      "static_frequency_hz": float(omegas[k] / (2 * np.pi)),
                      "static_mac": mac})
    modes.sort(key=lambda m: m["frequency_hz"])
    crank = np.asarray(crank_axis, float)
    tra_info = {"direction": [float(v) for v in tra],
                "angle_to_crank_axis_deg": _axis_angle_deg(tra, crank),
                "angles_to_mode_rotation_axes_deg": [
                    number_or_null(m["angle_to_torque_roll_axis_deg"]) for m in modes],
                "through": "centre of gravity"}
    method = ("static: static stiffness, undamped" if static else
              "dynamic: network dynamic stiffness at each mode's complex frequency "
              "(internal degrees of freedom condensed exactly, secant iteration)")
    return {"modes": modes, "torque_roll_axis": tra_info, "method": method + note}


def _as_measured(system):
    """``(system, note)``: a model with amplitude laws or friction with every network as
    measured (:meth:`NetworkScaling.as_measured`, the view of
    :func:`~powertrain.physics.condensation.condense`) and the note its method gets; a
    linear model as it is."""
    if system.port_forces() is None:
        return system, ""
    return NetworkScaling(system).as_measured(), "; " + AS_MEASURED
