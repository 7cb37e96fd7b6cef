r"""A transient manoeuvre stretch by stretch (:func:`transient_kernel`; formulas in
:mod:`powertrain.solvers.transient`): each stretch's amplitude-law scales from the last one's
amplitudes; per piece of ``sub`` steps the curves' static factors and loads at its predicted
middle (:func:`curve_state`); per step a sparse LU solve of :math:`\mathbf S\ddot{\mathbf x} =
\mathbf f - \mathbf C\tilde{\mathbf v} - \mathbf K\tilde{\mathbf x}`
(:mod:`powertrain.kernels.sparse_lu`) and the port laws by Newton.

Numba caches a kernel by its own file: after editing a kernel this one calls, touch this file.
"""

import numpy as np
from numba import njit

from powertrain.kernels.port_forces import (
    law_force,
    port_coupling,
    port_forces_at,
    port_forces_step,
    short_dot,
)
from powertrain.kernels.sparse_lu import (
    factor,
    factor_on_pattern,
    lu_solve,
    lu_solve_rows,
    product,
    row_product,
    sparse_factors,
    subtract_products,
)
from powertrain.kernels.static_curve import curve_point

#: Amplitude-law kinds (:func:`amplitude_scales`): none, :class:`~powertrain.physics.mount_laws.PowerLaw`,
#: :class:`~powertrain.physics.mount_laws.TableLaw`.
NO_LAW, POWER_LAW, TABLE_LAW = 0, 1, 2
#: Returned where S needs a row swap and the model has no pivoting (:func:`_piece`).
NEEDS_PIVOTING = -1
#: The smallest amplitude a power law reads [m].
TINY = np.finfo(np.float64).tiny


@njit(cache=True, nogil=True)
def _interp(x, xp, fp, count):
    """``np.interp(x, xp[:count], fp[:count])``: linear, flat beyond the ends."""
    if x <= xp[0]:
        return fp[0]
    if x >= xp[count - 1]:
        return fp[count - 1]
    j = 0
    while xp[j + 1] < x:
        j += 1
    return (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]) * (x - xp[j]) + fp[j]


@njit(cache=True, nogil=True)
def amplitude_scales(laws, amplitudes, law):
    """Fill ``law`` (n_net, 2) with each network's ``(stiffness, damping)`` scales at
    ``amplitudes`` (n_net,) [m], 1 without a law. ``laws = (kind (n_net,), power (n_net, 5) =
    (reference [m], exponent, lowest, highest factor, damping exponent), table (n_net, 3, T) =
    (log amplitudes, stiffness, damping factors), its points (n_net,))``; a table reads its
    first factors below ``power[r, 0]``."""
    kind, power, table, count = laws
    for r in range(kind.shape[0]):
        if kind[r] == POWER_LAW:
            f = (power[r, 0] / max(amplitudes[r], TINY)) ** power[r, 1]
            f = min(max(f, power[r, 2]), power[r, 3])
            law[r, 0] = f
            law[r, 1] = f if power[r, 4] == 1.0 else f ** power[r, 4]
        elif kind[r] == TABLE_LAW:
            la = np.log(max(amplitudes[r], power[r, 0]))
            law[r, 0] = _interp(la, table[r, 0], table[r, 1], count[r])
            law[r, 1] = _interp(la, table[r, 0], table[r, 2], count[r])
        else:
            law[r, 0] = law[r, 1] = 1.0


@njit(cache=True, nogil=True)
def _row_motion(A, e, X, lo, hi, u):
    """Row ``e`` of ``A`` (compressed) times rows ``lo:hi`` of ``X`` into ``u``; returns the mean."""
    starts, columns, values = A
    mean = 0.0
    for k in range(lo, hi):
        s = 0.0
        for t in range(starts[e], starts[e + 1]):
            s += values[t] * X[k, columns[t]]
        u[k - lo] = s
        mean += s
    return mean / (hi - lo)


@njit(cache=True, nogil=True)
def stretch_motion(rows, network, X, lo, hi, amplitudes, centres):
    """Over rows ``lo:hi`` of ``X``: each port's amplitude, √2 times the RMS about the mean of
    its motion (``rows[0]`` compressed), into ``amplitudes`` (n_net,) at its ``network`` (m,)
    unless ``amplitudes`` is empty; each network's mean deflection (``rows[1]``) into ``centres``."""
    u = np.empty(hi - lo)
    if amplitudes.shape[0]:
        for e in range(rows[0][0].shape[0] - 1):
            mean = _row_motion(rows[0], e, X, lo, hi, u)
            square = 0.0
            for k in range(hi - lo):
                square += (u[k] - mean) * (u[k] - mean)
            amplitudes[network[e]] = np.sqrt(2.0) * np.sqrt(square / (hi - lo))
    for e in range(rows[1][0].shape[0] - 1):
        centres[e] = _row_motion(rows[1], e, X, lo, hi, u)


@njit(cache=True, nogil=True)
def network_force_change(on_x, on_v, scales, assembled, loads):
    """Each network's force less that of its ``assembled`` (n_net, 2) scales, in place of
    ``on_x`` (n_t, n_net): the unit-scale forces ``on_x``, ``on_v`` of the displacements and
    velocities times ``scales`` (n_t, n_net, 2) less ``assembled``, plus ``loads`` [N]."""
    for t in range(on_x.shape[0]):
        for e in range(on_x.shape[1]):
            on_x[t, e] = (on_x[t, e] * (scales[t, e, 0] - assembled[e, 0])
                          + on_v[t, e] * (scales[t, e, 1] - assembled[e, 1]) + loads[t, e])


@njit(cache=True, nogil=True)
def curve_state(x, curves, law, centres, factors, c):
    r"""Static factor ``factors`` and curve load ``c`` (n_net,) [N] of every network at the
    state ``x`` (n,), amplitude-law scales ``law`` (n_net, 2) and ``centres`` (n_net,) [m]:
    :math:`c = F(\delta) - F(\delta_0) - f k_0 (u - \bar u) - s f k_0\bar u`, :math:`u` the
    deflection, :math:`\delta = \delta_0 + u`, :math:`f = F'(\delta)/F'(\delta_{ref})`; no
    curve: the assembled factor, no load. ``curves = (rows, d0, f0, breaks, coefficients,
    count, reference tangent, has, base, stiffness)``."""
    rows, d0, f0, breaks, coefficients, count, ref, has, base, stiffness = curves
    for r in range(rows.shape[0]):
        if not has[r]:
            factors[r], c[r] = base[r], 0.0
            continue
        u = short_dot(rows[r], x)
        force, tangent = curve_point(breaks, coefficients, count, r, d0[r] + u)
        f = tangent / ref[r]
        factors[r] = f
        k0 = f * stiffness[r]
        c[r] = force - f0[r] - k0 * (u - centres[r]) - law[r, 0] * k0 * centres[r]


@njit(cache=True, nogil=True)
def _scaled(fixed, change):
    """The compressed assembled matrix plus each network's ``change`` of scale times its part."""
    starts, columns, base, (net, position, value) = fixed
    out = base.copy()
    for e in range(value.shape[0]):
        out[position[e]] += change[net[e]] * value[e]
    return starts, columns, out


@njit(cache=True, nogil=True)
def _dense(A, n):
    """The compressed ``A`` as an (n, n) array."""
    starts, columns, values = A
    out = np.zeros((n, n))
    for i in range(n):
        for k in range(starts[i], starts[i + 1]):
            out[i, columns[k]] = values[k]
    return out


@njit(cache=True, nogil=True)
def _less(F, k, load, out):
    """Row ``k`` of ``F`` (zero beyond its columns) less ``load`` (n,) into ``out``, returned."""
    nf = F.shape[1]
    for j in range(nf):
        out[j] = F[k, j] - load[j]
    for j in range(nf, load.shape[0]):
        out[j] = 0.0 - load[j]
    return out


@njit(cache=True, nogil=True)
def _start_acceleration(model, laws, C, K, f, x, v):
    """The acceleration [m/s²] at ``(x, v)`` under ``f`` and the port laws (0 on massless nodes)."""
    r = f.copy()
    subtract_products(C, v, K, x, r)
    if laws is not None:
        _, kinds, par, state, (starts, columns, values), _ = laws
        m = kinds.shape[0]
        u, du, z0 = np.empty(m), np.empty(m), np.zeros(m)
        product(laws[4], x, u)
        product(laws[4], v, du)
        port_forces_at(kinds, par, state, u, du, z0)
        back = np.zeros(x.shape[0])
        for e in range(m):
            for k in range(starts[e], starts[e + 1]):
                back[columns[k]] += values[k] * z0[e]
        for j in range(x.shape[0]):
            r[j] -= back[j]
    out = np.empty(x.shape[0])
    product(model[2], r, out)
    return out


@njit(cache=True, nogil=True)
def _piece(model, laws, h, C, K, F, load, x, v, a, X, V, A, Z, tol, max_iter, work, pivoting):
    """Newmark over one piece; the steps where Newton failed, or :data:`NEEDS_PIVOTING`."""
    M, Ms, perm, where, pattern = model[0], model[1], model[6], model[7], model[8]
    if a.shape[0] == 0:
        a = _start_acceleration(model, laws, C, K, _less(F, 0, load, np.empty(x.shape[0])), x, v)
    B, factors = work
    if factor_on_pattern(((Ms, 1.0), (C, 0.5 * h), (K, 0.25 * h * h)), where, pattern, B, factors):
        lu = (factors, perm, perm)
    elif pivoting is None:
        return NEEDS_PIVOTING
    else:
        n = x.shape[0]
        ok, B, rows = factor(M, _dense(C, n), _dense(K, n), 0.5 * h, 0.25 * h * h, perm)
        if not ok:
            raise FloatingPointError("the Newmark matrix M + h/2 C + h^2/4 K is singular (a "
                                     "mount network without stiffness and damping?)")
        lu = (sparse_factors(B), rows, perm)
    return _sparse_steps(lu, laws, h, C, K, F, load, x, v, a, X, V, A, Z, tol, max_iter)


@njit(cache=True, nogil=True)
def _port_setup(laws, lu, h, x, v, Z):
    """``(W, coupling, P compressed, z, work)`` of the port laws; sets ``Z[0]`` and ``last``'s coupling."""
    if laws is None:
        return None
    P, kinds, par, state, (starts, columns, values), last = laws
    n, m, hh = x.shape[0], kinds.shape[0], 0.25 * h * h
    W, Q, z = np.empty((n, m)), np.zeros((m, m)), np.empty(m)
    lu_solve_rows(lu[0], lu[1], lu[2], P, np.empty((n, m)), W)
    for e in range(m):
        for i in range(m):
            for k in range(starts[i], starts[i + 1]):
                Q[i, e] += hh * values[k] * W[columns[k], e]
    for e in range(m):
        z[e] = law_force(kinds[e], short_dot(P[e], x), short_dot(P[e], v), par, state, e)[0]
        Z[0, e] = z[e]
    for e in range(m):
        last[6, e] = short_dot(Q[e], z)
    return (W, port_coupling(Q, 2.0 / h), laws[4], z,
            (np.empty(m), np.empty(m), np.empty(m), np.empty((m, m)), last))


@njit(cache=True, nogil=True)
def _port_step(laws, ports, h, xt, vt, a, z_out, tol, max_iter):
    """One step's port forces into ``z_out``, taken off the linear acceleration ``a``. True on success."""
    _, kinds, par, state, _, _ = laws
    W, coupled, (starts, columns, values), z, (ul, vl, r, J, last) = ports
    hh, hv = 0.25 * h * h, 0.5 * h
    for e in range(z.shape[0]):
        su, sv = 0.0, 0.0
        for k in range(starts[e], starts[e + 1]):
            j = columns[k]
            su += values[k] * (xt[j] + hh * a[j])
            sv += values[k] * (vt[j] + hv * a[j])
        ul[e], vl[e] = su, sv
    ok = port_forces_step(kinds, par, state, ul, vl, coupled, z, last, r, J, tol, max_iter)
    for e in range(z.shape[0]):
        z_out[e] = z[e]
    for j in range(a.shape[0]):
        a[j] -= short_dot(W[j], z)
    return ok


@njit(cache=True, nogil=True)
def _sparse_steps(lu, laws, h, C, K, F, load, x, v, a, X, V, A, Z, tol, max_iter):
    """:func:`_piece`'s steps by S's factors ``lu = (factors, rows, perm)``."""
    n, hh, hv = x.shape[0], 0.25 * h * h, 0.5 * h
    xt, vt, r, y = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for j in range(n):
        X[0, j], V[0, j], A[0, j] = x[j], v[j], a[j]
    ports, failed = _port_setup(laws, lu, h, x, v, Z), 0
    for k in range(1, F.shape[0]):
        for j in range(n):
            xt[j] = X[k - 1, j] + h * V[k - 1, j] + hh * A[k - 1, j]
            vt[j] = V[k - 1, j] + hv * A[k - 1, j]
        _less(F, k, load, r)
        subtract_products(C, vt, K, xt, r)
        lu_solve(lu[0], lu[1], lu[2], r, y, A[k])
        if laws is not None and not _port_step(laws, ports, h, xt, vt, A[k], Z[k], tol, max_iter):
            failed += 1
        for j in range(n):
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]
    return failed


@njit(cache=True, nogil=True)
def _piece_curves(middle, curves, law, centres, assembled, work, scales, loads, load):
    """:func:`curve_state` at ``middle`` into the piece's ``scales``, ``loads``, ``load``."""
    rows, n_net = curves[0], law.shape[0]
    factors, c, change = work
    curve_state(middle, curves, law, centres, factors, c)
    for r in range(n_net):
        for s in range(2):
            scales[:, r, s] = law[r, s] * factors[r]
            change[r, s] = law[r, s] * factors[r] - assembled[r, s]
        loads[:, r] = c[r]
    load[:] = 0.0
    for r in range(n_net):
        for j in range(load.shape[0]):
            load[j] += rows[r, j] * c[r]


@njit(cache=True, nogil=True)
def transient_stretch_kernel(model, curves, laws, h, F, law, centres, lo, hi, sub, a0, X, V,
                             acceleration, Z, scales, loads, tol, max_iter):
    """Integrate steps ``lo`` to ``hi`` (module docstring).

    Parameters
    ----------
    model : tuple
        ``(M, M compressed, inverse of M compressed (zero on massless nodes), C, K, assembled
        scales (n_net, 2), perm, where, pattern, pivoting)``: C and K as :func:`_scaled` takes
        them, the elimination order, each coordinate's position in it, the factors' pattern
        (:mod:`powertrain.kernels.sparse_lu`); ``pivoting`` None forbids row swaps.
    curves : tuple
        :func:`curve_state`'s.
    laws : tuple or None
        ``(P, kinds, par, state, P compressed, last)`` of the m port laws, ``state`` and the
        predictor's ``last`` (7, m) updated in place; None without port laws.
    h : float
        Time step [s].
    F : ndarray (n_t, n_f)
        Load on the first n_f ≤ n coordinates [N].
    law : ndarray (n_net, 2)
        The amplitude laws' stiffness and damping scales.
    centres : ndarray (n_net,)
        The networks' centres [m].
    lo, hi, sub : int
        First and last step, steps per piece.
    a0 : ndarray (n,) or (0,)
        Acceleration at ``lo`` [m/s²], or empty: solved.
    X, V, Z, scales, loads : ndarray
        Outputs over every step, row ``lo`` the start (X, V read from it).
    acceleration : tuple
        ``(A, rows compressed, out)``: work space (sub + 1, n) and the rows whose product with
        the accelerations fills ``out`` (n_t, n_rows).
    tol, max_iter : float, int
        Newton's tolerance and iteration limit.

    Returns
    -------
    int
        Steps at which Newton did not converge, or :data:`NEEDS_PIVOTING`.
    """
    C0, K0, assembled = model[3], model[4], model[5]
    n_net, n = law.shape[0], X.shape[1]
    (lp, li), _, (up, ui) = model[8]           # _piece's work space: S, its factors
    work = np.empty((n, n)), ((lp, li, np.empty(li.shape[0])), (up, ui, np.empty(ui.shape[0])), np.empty(n))
    middle, load, change = np.empty(n), np.empty(n), np.empty((n_net, 2))
    curve_work = np.empty(n_net), np.empty(n_net), change
    A, out_rows, out = acceleration
    failed, a = 0, a0
    for p in range(lo, hi, sub):
        q = min(p + sub, hi)
        x, v = X[p].copy(), V[p].copy()
        for j in range(x.shape[0]):       # the piece's predicted middle
            middle[j] = x[j] + 0.5 * (q - p) * h * v[j]
        _piece_curves(middle, curves, law, centres, assembled, curve_work, scales[p:q + 1],
                      loads[p:q + 1], load)
        got = _piece(model, laws, h, _scaled(C0, change[:, 1]), _scaled(K0, change[:, 0]),
                     F[p:q + 1], load, x, v, a, X[p:q + 1], V[p:q + 1], A[:q - p + 1],
                     Z[p:q + 1], tol, max_iter, work, model[9])
        if got == NEEDS_PIVOTING:
            return got
        for k in range(q - p + 1):
            for i in range(out.shape[1]):
                out[p + k, i] = row_product(out_rows, i, A[k])
        failed += got
        # solved from the next piece's laws, or the jump would persist as an undamped alternation
        a = np.empty(0)
    return failed


@njit(cache=True, nogil=True)
def transient_kernel(model, curves, laws, motion, h, F, steps, a0, amplitudes, centres, X, V,
                     acceleration, Z, scales, loads, tol, max_iter):
    """Integrate the whole manoeuvre by :func:`transient_stretch_kernel`, ``steps = (every,
    sub)`` steps per stretch and per piece, each stretch's scales from the last one's
    amplitudes and its centres their mean deflections (:func:`stretch_motion`). ``motion =
    (amplitude laws, (port rows, network rows) compressed, each port's network, varying)``;
    ``amplitudes``, ``centres`` (n_net,) [m] the start's, updated in place; the rest as
    :func:`transient_stretch_kernel`. Returns the steps where Newton did not converge, or
    :data:`NEEDS_PIVOTING`."""
    amplitude_laws, rows, network, varying = motion
    every, sub = steps
    n_t, law, none = F.shape[0], np.empty((amplitudes.shape[0], 2)), np.empty(0)
    failed, a = 0, a0
    for lo in range(0, n_t - 1, every):
        hi = min(lo + every, n_t - 1)
        amplitude_scales(amplitude_laws, amplitudes, law)
        got = transient_stretch_kernel(model, curves, laws, h, F, law, centres, lo, hi, sub, a,
                                       X, V, acceleration, Z, scales, loads, tol, max_iter)
        if got == NEEDS_PIVOTING:
            return got
        failed += got
        a = none
        if hi < n_t - 1:
            stretch_motion(rows, network, X, lo, hi, amplitudes if varying else none, centres)
    return failed
