r"""Rigid-body modes of the powertrain on its mounts: frequencies, damping, energy, torque roll.

``static``: the six undamped modes on the mounts' static stiffness, internal nodes condensed,
:math:`\mathbf K_{6}\boldsymbol\varphi = \omega^2\mathbf M_{6}\boldsymbol\varphi`.
``dynamic`` (default): the eigenvalues :math:`s` of the full assembled model in first-order
form (:func:`state_space_eigenvalues`, networks' internal DOFs and body modes included), exact
for lumped networks (a root of :math:`(s^2\mathbf M_R + \mathbf K_R(s))\boldsymbol\varphi = 0`,
:func:`powertrain.physics.condensation.condense`); each static mode takes the root nearest in
natural frequency and shape, one to one (:func:`_damped_roots`). Natural frequency
:math:`|s|/2\pi`, damping ratio :math:`-\mathrm{Re}\,s/|s|`, damped frequency
:math:`\mathrm{Im}\,s/2\pi`.

Kinetic-energy shares over ``x, y, z, rx, ry, rz`` (at the CG, engine axes):
:math:`E_j = \mathrm{Re}(\bar\varphi_j(\mathbf M\boldsymbol\varphi)_j) /
\mathrm{Re}(\boldsymbol\varphi^H\mathbf M\boldsymbol\varphi)` [%], signed (products of
inertia and complex shapes give slightly negative shares).

Torque-roll axis: :math:`\mathbf d = \mathbf I^{-1}\mathbf e_x/|\mathbf I^{-1}\mathbf e_x|`
through the CG (Jeong & Singh, J. Sound Vib. 234(1), 2000, sec. 2); each mode's rotation axis
is the direction of its rotational part, the angle between them reported in 0..90°.
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
#: Share of a mode's kinetic energy in the powertrain's coordinates below which its energy
#: distribution and axis are undefined (NaN).
STILL = 1e-20


def torque_roll_axis(inertia, crank_axis=(1.0, 0.0, 0.0)) -> np.ndarray:
    """Unit direction of the torque-roll axis, :math:`\\mathbf I^{-1}\\mathbf e` normalised, of
    the ``inertia`` (3, 3) [kg·m²] and the ``crank_axis`` (3,)."""
    d = np.linalg.solve(np.asarray(inertia, float), np.asarray(crank_axis, float))
    d = d / np.linalg.norm(d)
    return d if d @ np.asarray(crank_axis, float) >= 0 else -d


def kinetic_energy_percent(M6, phi) -> np.ndarray:
    """Kinetic-energy share [%] per coordinate of the mode ``phi`` (n,) or each column of
    ``phi`` (n, k), mass matrix ``M6``."""
    phi = np.asarray(phi, complex)
    e = (np.conj(phi) * (M6 @ phi)).real
    return 100.0 * e / e.sum(axis=0)


def number_or_null(value):
    """``value`` as a float, or None (JSON null) where it is NaN."""
    return float(value) if np.isfinite(value) else None


def _axis_angles_deg(A, b) -> np.ndarray:
    """Angle [deg, 0..90] between each column of ``A`` (3, k) and ``b``; NaN where one is zero."""
    norms = np.sqrt((A * A).sum(axis=0)) * np.sqrt(b @ b)
    cosine = np.divide(np.abs(b @ A), norms, out=np.zeros(norms.shape), where=norms > 0)
    return np.where(norms > 0, np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0))), np.nan)


def _normalise(M, phi):
    """Each column of ``phi`` with unit modal mass, its largest-energy entry real positive."""
    phi = np.asarray(phi, complex)
    j = np.argmax((np.conj(phi) * (M @ phi)).real, axis=0)
    phi = phi * np.exp(-1j * np.angle(phi[j, np.arange(phi.shape[1])]))
    return phi / np.sqrt(np.einsum("ij,ij->j", np.conj(phi), M @ phi).real)


def _mac_matrix(P, Q, M) -> np.ndarray:
    """Mass-weighted MAC of every column of ``P`` with every column of ``Q``."""
    MQ = M @ Q
    num = np.abs(np.conj(P).T @ MQ) ** 2
    return num / np.outer(np.einsum("ij,ij->j", np.conj(P), M @ P).real,
                          np.einsum("ij,ij->j", np.conj(Q), MQ).real)


def state_space_eigenvalues(system) -> np.ndarray:
    r"""Eigenvalues of :math:`\mathbf M\ddot{\mathbf q} + \mathbf C\dot{\mathbf q} + \mathbf
    K\mathbf q = 0` in first-order form, every coordinate included; with a singular
    :math:`\mathbf M` the generalized problem, infinite eigenvalues dropped.

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
    r"""The shape of ``system`` at each of its eigenvalues ``roots`` (k,) [1/s]: the null
    vector of :math:`\mathbf K + s\mathbf C + s^2\mathbf M` by one inverse iteration from a
    distinct start vector per root (a repeated root gets independent shapes).

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
    r"""``(s, phi)``: the damped root (k,) of each static mode at ``omegas`` [rad/s] and its
    shape on the retained coordinates (n_R, k).

    Candidates: eigenvalues with positive imaginary part below three times the highest static
    frequency (else all with imaginary part >= 0) that move the retained coordinates. Each
    static mode gets one (:func:`scipy.optimize.linear_sum_assignment`) at least total cost
    :math:`|\ln(\omega_i/|s|)| + 1 - \mathrm{MAC}`. ValueError for fewer candidates than
    modes or a root with damping ratio below -:data:`UNSTABLE`.
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
    """``(static mode index, MAC)`` per column of ``shapes``, paired one to one by largest MAC."""
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
    chassis (kind ``chassis`` where most kinetic energy is in the body modes).

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
    s, phi = (1j * omegas, vec.astype(complex)) if static else _damped_roots(system, MR, omegas, vec)
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
    """Fields of a :class:`powertrain.results.modes.Mode` per root ``s`` and shape ``phi``."""
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
    """``(system, note)``: a nonlinear model with its networks as measured, and its note."""
    if system.port_forces() is None:
        return system, ""
    return NetworkScaling(system).as_measured(), "; " + AS_MEASURED
