r"""Rigid-body modes of the powertrain on its mounts: frequencies, damping, energy, torque roll.

Two methods:

* ``static`` — the six undamped modes of the body on the mounts' static (0 Hz) cross-point
  stiffness, the networks' internal nodes condensed statically:
  :math:`\mathbf K_{6}\boldsymbol\varphi = \omega^2\mathbf M_{6}\boldsymbol\varphi`.
* ``dynamic`` (default) — each mode with the mount networks' dynamic stiffness at its own
  (complex) frequency: the eigenvalues :math:`s` of the assembled model
  :math:`\mathbf M\ddot{\mathbf q} + \mathbf C\dot{\mathbf q} + \mathbf K\mathbf q = 0` with
  the networks' internal degrees of freedom (and the body modes of a modal chassis), in
  first-order form, all found by one eigensolve (:func:`state_space_eigenvalues`), with the
  shapes of those near the static modes (:func:`root_shapes`). Lumped networks
  make this exact: a root is a root of the condensed problem
  :math:`\big(s^2\mathbf M_R + \mathbf K_R(s)\big)\boldsymbol\varphi = 0` on the retained
  coordinates (rigid body, body modes; every network through its two-port at :math:`s`,
  :func:`powertrain.physics.condensation.condense`) and the retained part of its eigenvector
  is :math:`\boldsymbol\varphi`. The full model has more roots than modes (the networks' own
  modes); each static mode takes the root nearest to it in natural frequency and shape, one
  to one (:func:`_damped_roots`). Natural frequency :math:`|s|/2\pi`, damping ratio
  :math:`-\mathrm{Re}\,s/|s|`, damped frequency :math:`\mathrm{Im}\,s/2\pi`.

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
from scipy.optimize import linear_sum_assignment

from powertrain.assembly import NetworkScaling
from powertrain.physics.condensation import condense

#: What the modes of a model with amplitude laws or friction take (printed with them).
AS_MEASURED = ("mounts as measured (networks as in their mount files: amplitude laws at "
               "factor 1, no friction)")

COORDINATES = ("x", "y", "z", "rx", "ry", "rz")
#: Damping ratio below -UNSTABLE of a damped root: not a root of the passive model.
UNSTABLE = 1e-8
#: Share of a mode's kinetic energy in the powertrain's coordinates below which the mode does
#: not move the powertrain (round-off): its energy distribution and axis are undefined (NaN).
STILL = 1e-20


# ---------------------------------------------------------------------------- physics
def torque_roll_axis(inertia, crank_axis=(1.0, 0.0, 0.0)) -> np.ndarray:
    """Unit direction of the torque-roll axis, :math:`\\mathbf I^{-1}\\mathbf e` normalised."""
    d = np.linalg.solve(np.asarray(inertia, float), np.asarray(crank_axis, float))
    d = d / np.linalg.norm(d)
    return d if d @ np.asarray(crank_axis, float) >= 0 else -d


def kinetic_energy_percent(M6, phi) -> np.ndarray:
    """:math:`100\\,\\mathrm{Re}(\\bar\\varphi_j(\\mathbf M\\varphi)_j)/\\mathrm{Re}(\\varphi^H
    \\mathbf M\\varphi)` per coordinate [%] of the mode ``phi`` (n,), or of each column of
    ``phi`` (n, k)."""
    phi = np.asarray(phi, complex)
    e = (np.conj(phi) * (M6 @ phi)).real
    return 100.0 * e / e.sum(axis=0)


def number_or_null(value):
    """``value`` as a float, or None (JSON null) where it is undefined (NaN: the rotation
    axis of a mode without rotation)."""
    return float(value) if np.isfinite(value) else None


def _axis_angles_deg(A, b) -> np.ndarray:
    """Angle [deg, 0..90] between the axis of each column of ``A`` (3, k) and the axis ``b``;
    NaN where either is zero."""
    norms = np.sqrt((A * A).sum(axis=0)) * np.sqrt(b @ b)
    cosine = np.divide(np.abs(b @ A), norms, out=np.zeros(norms.shape), where=norms > 0)
    return np.where(norms > 0, np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0))), np.nan)


def _normalise(M, phi):
    """Each column of ``phi`` with unit modal mass, its phase such that its largest-energy
    entry is real positive."""
    phi = np.asarray(phi, complex)
    j = np.argmax((np.conj(phi) * (M @ phi)).real, axis=0)
    phi = phi * np.exp(-1j * np.angle(phi[j, np.arange(phi.shape[1])]))
    return phi / np.sqrt(np.einsum("ij,ij->j", np.conj(phi), M @ phi).real)


def _mac_matrix(P, Q, M) -> np.ndarray:
    r"""Modal assurance criterion of every column of ``P`` with every column of ``Q``,
    :math:`|\mathbf p^H\mathbf M\mathbf q|^2 / (\mathbf p^H\mathbf M\mathbf p\;
    \mathbf q^H\mathbf M\mathbf q)`, shape (P columns, Q columns)."""
    MQ = M @ Q
    num = np.abs(np.conj(P).T @ MQ) ** 2
    return num / np.outer(np.einsum("ij,ij->j", np.conj(P), M @ P).real,
                          np.einsum("ij,ij->j", np.conj(Q), MQ).real)


def state_space_eigenvalues(system) -> np.ndarray:
    r"""Eigenvalues of the assembled model's equations of motion
    :math:`\mathbf M\ddot{\mathbf q} + \mathbf C\dot{\mathbf q} + \mathbf K\mathbf q = 0`
    in first-order form, every coordinate included (rigid body, the networks' internal
    degrees of freedom, body modes).

    With :math:`\mathbf M` invertible the standard eigenproblem of
    :math:`\begin{bmatrix}\mathbf 0 & \mathbf I\\ -\mathbf M^{-1}\mathbf K &
    -\mathbf M^{-1}\mathbf C\end{bmatrix}`; otherwise (a massless node) the generalized
    one with :math:`\mathrm{diag}(\mathbf I, \mathbf M)`, its infinite eigenvalues dropped.

    Parameters
    ----------
    system : AssembledSystem
        ``M``, ``C``, ``K`` (n, n) in SI units.

    Returns
    -------
    ndarray complex (m,)
        The finite eigenvalues :math:`s` [1/s] (m = 2n without massless nodes).
    """
    n = system.n_dof
    try:
        inverse = np.linalg.inv(system.M)
    except np.linalg.LinAlgError:
        zero, eye = np.zeros((n, n)), np.eye(n)
        lam = sla.eig(np.block([[zero, eye], [-system.K, -system.C]]),
                      np.block([[eye, zero], [zero, system.M]]), right=False)
        return lam[np.isfinite(lam)]
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:] = -inverse @ np.hstack([system.K, system.C])
    return np.linalg.eigvals(A)


def root_shapes(system, roots) -> np.ndarray:
    r"""The shape of the assembled model at each of its eigenvalues ``roots`` (k,) [1/s]: the
    null vector of :math:`\mathbf K + s\mathbf C + s^2\mathbf M`, by one step of inverse
    iteration from a generic start vector of its own for each root (so that a repeated root
    gets independent shapes). For a root accurate to round-off the error of its shape is
    round-off over the relative distance to the next root.

    Returns
    -------
    ndarray complex (n, k)
        One shape per column, every coordinate, any scale.
    """
    s = np.asarray(roots, complex)[:, None, None]
    start = np.cos(np.outer(np.arange(1, s.shape[0] + 1), np.arange(1, system.n_dof + 1)))
    try:
        x = np.linalg.solve(_dynamic_stiffness(system, s), start[..., None])
    except np.linalg.LinAlgError:                 # a root exact to the last bit: shift off it
        x = np.linalg.solve(_dynamic_stiffness(system, s * (1.0 + 1e-13)), start[..., None])
    return x[..., 0].T


def _dynamic_stiffness(system, s):
    """:math:`\\mathbf K + s\\mathbf C + s^2\\mathbf M` at each ``s`` (k, 1, 1)."""
    D = s * system.M
    D += system.C
    D *= s
    D += system.K
    return D


def _damped_roots(system, MR, omegas, vec):
    r"""The damped mode of each static mode: ``(s, phi)``, the roots (k,) and their shapes on
    the retained coordinates (n_R, k) in the order of ``omegas`` [rad/s], from the eigenvalues
    of the full model (:func:`state_space_eigenvalues`) and their shapes
    (:func:`root_shapes`).

    Candidates are the eigenvalues with positive imaginary part and a modulus below three
    times the highest static angular frequency (if these are fewer than the modes: every
    eigenvalue with imaginary part >= 0, overdamped ones included), without those that leave
    the retained coordinates still (a network's own mode, decoupled from the body). Each
    static mode i gets its own candidate (:func:`scipy.optimize.linear_sum_assignment`) at
    the least total cost :math:`|\ln(\omega_i/|s|)| + 1 - \mathrm{MAC}(\boldsymbol\varphi_i,
    \boldsymbol\varphi_s)`: nearest in natural frequency and in shape.

    Raises
    ------
    ValueError
        Fewer candidates than modes, or a picked root with a damping ratio below
        -:data:`UNSTABLE` (matrices beyond what the eigensolve resolves in floating point).
    """
    lam = state_space_eigenvalues(system)
    top = 3.0 * max(omegas.max(), 1e-9)
    pick = (lam.imag > 0) & (np.abs(lam) < top)
    if np.count_nonzero(pick) < omegas.size:
        pick = lam.imag >= 0
    lam = lam[pick]
    full = root_shapes(system, lam)
    phi = full[system.retained]
    moving = (np.einsum("ij,ij->j", np.conj(phi), MR @ phi).real
              > 1e-12 * np.einsum("ij,ij->j", np.conj(full), system.M @ full).real)
    lam, phi = lam[moving], phi[:, moving]
    if lam.size < omegas.size:
        raise ValueError(f"{lam.size} damped roots for {omegas.size} modes")
    with np.errstate(divide="ignore", invalid="ignore"):
        cost = (np.abs(np.log(omegas[:, None] / np.abs(lam)[None, :]))
                + 1.0 - _mac_matrix(vec.astype(complex), phi, MR))
    _, cols = linear_sum_assignment(np.nan_to_num(cost, nan=1e300, posinf=1e300))
    if np.any(lam[cols].real > UNSTABLE * np.abs(lam[cols])):
        raise ValueError("a root with positive real part (no passive model has one): beyond "
                         "floating-point range")
    return lam[cols], phi[:, cols]


def _pair_with_static(M, shapes, static_shapes) -> list:
    """``(index of the static mode, MAC)`` for each column of ``shapes``: the one-to-one
    pairing of largest total MAC (:func:`scipy.optimize.linear_sum_assignment`)."""
    mac = _mac_matrix(shapes, static_shapes.astype(complex), M)
    rows, cols = linear_sum_assignment(-mac)
    pair = dict(zip(rows, cols))
    return [(int(pair[i]), float(mac[i, pair[i]])) for i in range(shapes.shape[1])]


def _static_condensed(system, keep) -> np.ndarray:
    """Static stiffness on the kept coordinates, the others condensed."""
    Kr = condense(system, keep, 0.0).real
    return 0.5 * (Kr + Kr.T)


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
    s, phi = (1j * omegas, vec.astype(complex)) if static else \
        _damped_roots(system, MR, omegas, vec)
    modes = _mode_fields(MR, s, phi, omegas, vec, tra, static)
    modes.sort(key=lambda m: m["frequency_hz"])
    crank = np.asarray(crank_axis, float)
    tra_info = {"direction": [float(v) for v in tra],
                "angle_to_crank_axis_deg": float(_axis_angles_deg(tra[:, None], crank)[0]),
                "angles_to_mode_rotation_axes_deg": [
                    number_or_null(m["angle_to_torque_roll_axis_deg"]) for m in modes],
                "through": "centre of gravity"}
    method = ("static: static stiffness, undamped" if static else
              "dynamic: network dynamic stiffness at each mode's complex frequency "
              "(eigenvalues of the full model with the networks' internal degrees of "
              "freedom)")
    return {"modes": modes, "torque_roll_axis": tra_info, "method": method + note}


def _mode_fields(MR, s, phi, omegas, static_shapes, tra, static) -> list:
    """The fields of a :class:`powertrain.results.modes.Mode` for each root ``s`` (k,) with
    its shape ``phi`` (n_R, k) on the retained coordinates (any scale), in that order."""
    pairs = _pair_with_static(MR, phi, static_shapes)
    phi = _normalise(MR, phi)
    e = (np.conj(phi) * (MR @ phi)).real
    body_share = (100.0 * e[6:].sum(axis=0) / e.sum(axis=0)).tolist()
    ked = kinetic_energy_percent(MR[:6, :6], phi[:6])
    still = e[:6].sum(axis=0) <= STILL * e.sum(axis=0)
    ked[:, still] = np.nan
    angles = np.where(still, np.nan, _axis_angles_deg(phi[3:6].real, tra)).tolist()
    f = (np.abs(s) / (2 * np.pi)).tolist()
    zeta = np.zeros(s.size).tolist() if static else (-s.real / np.abs(s)).tolist()
    f_damped = (s.imag / (2 * np.pi)).tolist()
    f_static = (omegas / (2 * np.pi)).tolist()
    return [{"frequency_hz": f[i], "damping_ratio": zeta[i], "damped_frequency_hz": f_damped[i],
             "shape": phi[:6, i], "ked_percent": ked[:, i],
             "angle_to_torque_roll_axis_deg": angles[i],
             "kind": "rigid-body" if body_share[i] < 50.0 else "chassis",
             "body_energy_percent": body_share[i], "static_frequency_hz": f_static[k],
             "static_mac": mac}
            for i, (k, mac) in enumerate(pairs)]


def _as_measured(system):
    """``(system, note)``: a model with amplitude laws or friction with every network as
    measured (:meth:`NetworkScaling.as_measured`, the view of
    :func:`~powertrain.physics.condensation.condense`) and the note its method gets; a
    linear model as it is."""
    if system.port_forces() is None:
        return system, ""
    return NetworkScaling(system).as_measured(), "; " + AS_MEASURED
