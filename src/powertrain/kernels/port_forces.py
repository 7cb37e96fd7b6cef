r"""Port laws: nonlinear forces in parallel with a mount network on the relative motion
:math:`u = x_E - x_B`, :math:`\dot u` of its engine-side and base nodes, and the Newmark
kernels with them. A law is a kind code, a row of parameters and a row of state:
:func:`law_force` gives the force (on the base; :math:`-f` on the engine side) and its
tangents, :func:`commit_state` updates the state after a converged step. A new law adds a
code, a branch in each and its element type in :mod:`powertrain.physics.mount_elements`.
"""

import numpy as np
from numba import njit

#: No force (code 0 is harmless).
NONE = 0
#: Jenkins element: spring ``k = par[0]`` in series with a Coulomb slider of slip force
#: ``F_s = par[1]``; state ``z = state[0]``, the slider's position.
JENKINS = 1
#: Berg's friction element: ``F_max = par[0]``, ``x2 = par[1]``; state ``[x_s, F_s,
#: direction, u_last, F_last]``: the last reversal point, the direction since it (+1, -1;
#: 0 before any motion), the last committed point. Formula: :mod:`powertrain.physics.mount_laws`.
BERG = 2


@njit(cache=True, nogil=True, inline="always")
def _berg_branch(u, state, e):
    """``(direction, x_s, F_s)`` of the branch through ``u`` from the committed ``state``."""
    du = u - state[e, 3]
    d = 1.0 if du > 0 else (-1.0 if du < 0 else state[e, 2])
    if d == state[e, 2]:
        return d, state[e, 0], state[e, 1]
    return d, state[e, 3], state[e, 4]


@njit(cache=True, nogil=True, inline="always")
def _berg(u, par, state, e):
    """Berg's force and tangent stiffness at ``u`` from the committed ``state``."""
    fm, x2 = par[e, 0], par[e, 1]
    if fm <= 0.0:
        return 0.0, 0.0
    d, xs, fs = _berg_branch(u, state, e)
    if d == 0.0:
        return state[e, 4], fm / x2
    y = u - xs                  # force fs + y (fm - d fs) / (a + y), a = x2 (1 - d fs / fm)
    if d * y < 0.0:
        y = 0.0
    g = fm - d * fs
    inv = 1.0 / (x2 * g + d * fm * y)                 # one division: 1 / (fm (a + y) / d)
    w = g * inv
    return fs + y * fm * w, x2 * fm * w * w


@njit(cache=True, nogil=True, inline="always")
def law_force(kind, u, v, par, state, e):
    """``(f, df/du, df/dv)`` [N, N/m, N·s/m] of the port law ``kind`` at ``(u, v)`` [m, m/s]
    from row ``e`` of ``par`` and ``state`` (unchanged)."""
    if kind == JENKINS:
        k, fs = par[e, 0], par[e, 1]
        f = k * (u - state[e, 0])
        if f > fs:
            return fs, 0.0, 0.0
        if f < -fs:
            return -fs, 0.0, 0.0
        return f, k, 0.0
    if kind == BERG:
        f, kt = _berg(u, par, state, e)
        return f, kt, 0.0
    return 0.0, 0.0, 0.0


@njit(cache=True, nogil=True)
def port_force(kind, u, v, par, state):
    """:func:`law_force` of one law ``kind`` at ``(u, v)``, ``par`` and ``state`` 1-D."""
    return law_force(kind, u, v, par.reshape((1, par.size)), state.reshape((1, state.size)), 0)


@njit(cache=True, nogil=True, inline="always")
def commit_state(kind, u, v, par, state, e, f):
    """Update row ``e`` of ``state`` after a converged step ending at ``(u, v)`` with force
    ``f``; ``kind``, ``par`` as :func:`law_force`."""
    if kind == JENKINS:
        k, fs = par[e, 0], par[e, 1]
        f = k * (u - state[e, 0])
        if f > fs:
            state[e, 0] = u - fs / k
        elif f < -fs:
            state[e, 0] = u + fs / k
    elif kind == BERG:
        d, xs, fsr = _berg_branch(u, state, e)
        state[e, 0], state[e, 1], state[e, 2], state[e, 3], state[e, 4] = xs, fsr, d, u, f


@njit(cache=True, nogil=True)
def port_forces_at(kinds, par, state, u, v, out):
    """Forces ``out`` (m,) of the laws ``kinds``, ``par`` at ``u``, ``v`` (m,) from ``state``."""
    for e in range(kinds.shape[0]):
        out[e] = law_force(kinds[e], u[e], v[e], par, state, e)[0]


@njit(cache=True, nogil=True)
def port_force_loop(kinds, par, state, U, V, F):
    """Forces ``F`` (n_t, m) of the laws ``kinds``, ``par`` along the motions ``U``, ``V``
    (n_t, m), ``state`` committed after every point."""
    for t in range(U.shape[0]):
        for e in range(kinds.shape[0]):
            F[t, e] = law_force(kinds[e], U[t, e], V[t, e], par, state, e)[0]
            commit_state(kinds[e], U[t, e], V[t, e], par, state, e, F[t, e])


@njit(cache=True, nogil=True, inline="always")
def short_dot(a, b):
    """Dot product of two short vectors (no BLAS call)."""
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s


@njit(cache=True, nogil=True)
def _solve_in_place(J, r):
    """Solve ``J x = r`` in place (``x`` into ``r``) by elimination with partial pivoting."""
    m = r.shape[0]
    for c in range(m):
        p = c
        for i in range(c + 1, m):
            if abs(J[i, c]) > abs(J[p, c]):
                p = i
        if p != c:
            for j in range(c, m):
                J[c, j], J[p, j] = J[p, j], J[c, j]
            r[c], r[p] = r[p], r[c]
        for i in range(c + 1, m):
            f = J[i, c] / J[c, c]
            for j in range(c, m):
                J[i, j] -= f * J[c, j]
            r[i] -= f * r[c]
    for i in range(m - 1, -1, -1):
        s = r[i]
        for j in range(i + 1, m):
            s -= J[i, j] * r[j]
        r[i] = s / J[i, i]


@njit(cache=True, nogil=True)
def newmark_port_kernel(G, H, Fs, h, x0, v0, a0, W, P, Q, kinds, par, state, X, V, A, Z,
                        tol, max_iter):
    r"""Newmark average acceleration of :math:`\mathbf M\ddot{\mathbf x} + \mathbf
    C\dot{\mathbf x} + \mathbf K\mathbf x + \mathbf P^T\mathbf z = \mathbf f`,
    :math:`z_e = f_e(\mathbf p_e\cdot\mathbf x, \mathbf p_e\cdot\dot{\mathbf x})`.

    With :math:`\ddot{\mathbf x} = \ddot{\mathbf x}_{lin} - \mathbf W\mathbf z` the port
    motions are :math:`\mathbf u = \mathbf u_{lin} - \tfrac{h^2}{4}\mathbf Q\mathbf z`,
    :math:`\dot{\mathbf u} = \dot{\mathbf u}_{lin} - \tfrac h2\mathbf Q\mathbf z`; Newton
    solves :math:`z_e = f_e(u_e, \dot u_e)` per step (:func:`port_forces_step`), then the
    states are committed.

    ``G, H, Fs, h, x0, v0, a0, X, V, A`` as :func:`powertrain.kernels.newmark.newmark_kernel`;
    ``W`` (n, m) = S^-1 P^T; ``P`` (m, n) the port rows; ``Q`` (m, m) = P S^-1 P^T; ``kinds``
    (m,) int64 the law codes, ``par`` (m, n_par) their parameters, ``state`` (m, n_state)
    their state (updated in place); output ``Z`` (n_steps + 1, m) the port forces [N]; Newton
    stops when every residual is below ``tol`` times (1 + the largest force), or after
    ``max_iter`` iterations. Returns the number of steps where Newton did not converge.
    """
    n, m, ns, hh, hv = x0.shape[0], kinds.shape[0], Fs.shape[0], 0.25 * h * h, 0.5 * h
    xt, vt = np.empty(n), np.empty(n)
    ul, vl, z, r = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    J, last = np.empty((m, m)), np.zeros((7, m))
    coupled, failed = port_coupling(hh * Q, hv / hh), 0
    for j in range(n):
        X[0, j], V[0, j], A[0, j] = x0[j], v0[j], a0[j]
    for e in range(m):
        z[e] = law_force(kinds[e], short_dot(P[e], x0), short_dot(P[e], v0), par, state, e)[0]
        Z[0, e] = z[e]
    for k in range(1, ns):
        for j in range(n):
            xt[j] = X[k - 1, j] + h * V[k - 1, j] + hh * A[k - 1, j]
            vt[j] = V[k - 1, j] + hv * A[k - 1, j]
        Ak = A[k]
        for i in range(n):
            s = Fs[k, i]
            Gi, Hi = G[i], H[i]            # row views: 2-D indexing in the inner loop is slower
            for j in range(n):
                s -= Gi[j] * vt[j] + Hi[j] * xt[j]
            Ak[i] = s
        for e in range(m):
            Pe = P[e]
            su, sv = 0.0, 0.0
            for j in range(n):
                su += Pe[j] * (xt[j] + hh * Ak[j])
                sv += Pe[j] * (vt[j] + hv * Ak[j])
            ul[e], vl[e] = su, sv
        if not port_forces_step(kinds, par, state, ul, vl, coupled, z, last, r, J, tol, max_iter):
            failed += 1
        for e in range(m):
            Z[k, e] = z[e]
        for j in range(n):
            A[k, j] -= short_dot(W[j], z)
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]
    return failed


@njit(cache=True, nogil=True)
def _port_newton(kinds, par, state, ul, vl, Q, z, r, J, tol, max_iter):
    """Newton on one step's port forces ``z`` (in place); True on success."""
    Qu, qv, m = Q[0], Q[1], z.shape[0]
    for _ in range(max_iter):
        big, worst = 1.0, 0.0
        for e in range(m):
            c = short_dot(Qu[e], z)
            f, kt, ct = law_force(kinds[e], ul[e] - c, vl[e] - qv * c, par, state, e)
            r[e] = f - z[e]
            big = max(big, abs(z[e]))
            worst = max(worst, abs(r[e]))
            for j in range(m):
                J[e, j] = (kt + qv * ct) * Qu[e, j]
            J[e, e] += 1.0
        if worst <= tol * big:
            return True
        _solve_in_place(J, r)
        for e in range(m):
            z[e] += r[e]
    return False


#: Iterations of the diagonal Newton before full Newton (:func:`port_forces_step`).
JACOBI_ITER = 8


@njit(cache=True, nogil=True, inline="always")
def port_forces_step(kinds, par, state, ul, vl, Q, z, last, r, J, tol, max_iter):
    """One step's port forces ``z`` (in place) of ``z_e = f_e(ul_e - (Qu z)_e, vl_e - qv (Qu
    z)_e)``, ``Q = (Qu, qv, row sums of |Qu|)``, the states committed. True on success.

    The ports couple only through the body's motion within a step (``Qu`` ~ h²/mass): the
    laws' forces ``f`` at the motion of ``z`` are the solution's to within ``rho |f - z|``,
    ``rho = max_e (|k_t,e| + qv |c_t,e|) sum_j |Qu_ej|``. From a tangent predictor
    (``last`` (7, m) = ``(u, v, df/du, df/dv)``, the point before, ``Qu z``), ``z = f`` is
    accepted when ``rho |f - z|`` <= ``tol`` (1 + max |z|); else :data:`JACOBI_ITER`
    diagonal Newton iterations, then full Newton (``r``, ``J`` work space, ``max_iter``);
    ``kinds``, ``par``, ``state`` as :func:`law_force`."""
    Qu, qv, m = Q[0], Q[1], z.shape[0]
    _predict(ul, vl, qv, last, z)
    for _ in range(JACOBI_ITER):
        big, worst, rho = _port_residual(kinds, par, state, ul, vl, Q, z, last, r)
        if rho < 1.0 and rho * worst <= tol * big:
            for e in range(m):
                z[e] += r[e]
            _commit(kinds, par, state, last, z)
            return True
        for e in range(m):
            z[e] += r[e] / (1.0 + (last[2, e] + qv * last[3, e]) * Qu[e, e])
    converged = _port_newton(kinds, par, state, ul, vl, Q, z, r, J, tol, max_iter)
    _port_residual(kinds, par, state, ul, vl, Q, z, last, r)
    for e in range(m):
        z[e] += r[e]
    _commit(kinds, par, state, last, z)
    return converged


@njit(cache=True, nogil=True, inline="always")
def _predict(ul, vl, qv, last, z):
    """Move the last step's forces ``z`` along the laws' tangents to this step's motions."""
    for e in range(z.shape[0]):
        du = ul[e] - last[6, e] - last[0, e]
        kt = last[2, e]
        if du * (last[0, e] - last[4, e]) > 0.0:
            kt += 0.5 * (kt - last[5, e])
        z[e] += kt * du + last[3, e] * (vl[e] - qv * last[6, e] - last[1, e])
        last[4, e], last[5, e] = last[0, e], last[2, e]


@njit(cache=True, nogil=True)
def port_coupling(Qu, qv):
    """``(Qu, qv, qa)``, ``qa`` the row sums of |Qu|."""
    qa = np.zeros(Qu.shape[0])
    for i, j in np.ndindex(Qu.shape):
        qa[i] += abs(Qu[i, j])
    return Qu, qv, qa


@njit(cache=True, nogil=True, inline="always")
def _port_residual(kinds, par, state, ul, vl, Q, z, last, r):
    """Residuals ``r = f(u, v) - z`` into ``r`` and ``last``; ``(1 + max |z|, max |r|, rho)``."""
    Qu, qv, qa = Q
    big, worst, rho = 1.0, 0.0, 0.0
    for e in range(z.shape[0]):
        c = 0.0
        for j in range(z.shape[0]):
            c += Qu[e, j] * z[j]
        u = ul[e] - c
        v = vl[e] - qv * c
        f, kt, ct = law_force(kinds[e], u, v, par, state, e)
        last[0, e], last[1, e], last[2, e], last[3, e], last[6, e] = u, v, kt, ct, c
        r[e] = f - z[e]
        big = max(big, abs(z[e]))
        worst = max(worst, abs(r[e]))
        rho = max(rho, (abs(kt) + qv * abs(ct)) * qa[e])
    return big, worst, rho


@njit(cache=True, nogil=True, inline="always")
def _commit(kinds, par, state, last, f):
    """Commit the states at the points ``last`` with the forces ``f``."""
    for e in range(f.shape[0]):
        commit_state(kinds[e], last[0, e], last[1, e], par, state, e, f[e])


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _load_less_ports(load_at, T, F, k, z, p):
    """``p`` (q,) = the load ``F[k]`` placed at ``load_at`` minus ``T^T z``."""
    for c in range(p.shape[0]):
        p[c] = 0.0
    for c in range(F.shape[1]):
        p[load_at[c]] += F[k, c]
    for e in range(z.shape[0]):
        ze = z[e]
        for c in range(p.shape[0]):
            p[c] -= T[e, c] * ze


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _write_outputs(outputs, x, y, p, z, out, k, g):
    """Row ``k`` of ``out``: ``Wyz [y[y_cols], z[z_cols]]`` plus ``Re(W eta) + Wd p`` on ``w_rows``."""
    (Wyz, y_cols, z_cols), w_rows, W, Wd = outputs
    ny = y_cols.shape[0]
    for d in range(ny):
        g[d] = y[y_cols[d]]
    for d in range(z_cols.shape[0]):
        g[ny + d] = z[z_cols[d]]
    for c in range(out.shape[1]):
        s = 0.0
        for d in range(g.shape[0]):
            s += Wyz[c, d] * g[d]
        out[k, c] = s
    for i in range(w_rows.shape[0]):
        s = 0.0
        for j in range(x.shape[0]):
            s += W[i, j] * x[j]
        for j in range(p.shape[0]):
            s += Wd[i, j] * p[j]
        out[k, w_rows[i]] += s


@njit(cache=True, nogil=True, fastmath=True, error_model="numpy")
def modal_port_kernel(modal, outputs, ports, laws, F, x, y, z, out, tol, max_iter):
    r"""Newmark average acceleration with port laws in modal coordinates: the recurrence
    :math:`\eta_{k+1} = \lambda_d\eta_k + \mathbf G(\mathbf p_k + \mathbf p_{k+1})`
    (:class:`~powertrain.solvers.newmark.ModalNewmark`), :math:`\mathbf p = \mathbf E\mathbf f
    - \mathbf T^T\mathbf z` the load less the port forces on the q reduced coordinates
    :math:`\mathbf y` (those the load or a port row touches).

    Each step reads the next reduced accelerations :math:`\ddot{\mathbf y}_{k+1} =
    \mathrm{Re}(\Psi_a\lambda_d\eta_k) + \mathbf D_a\mathbf p_k + \mathbf S\mathbf p_{k+1}`;
    displacements and velocities follow by Newmark's kinematics, which the recurrence satisfies
    exactly. The port motions :math:`\mathbf u = \mathbf u_{lin} - \mathbf Q_u\mathbf z`,
    :math:`\mathbf Q_u = \tfrac{h^2}4\mathbf T\mathbf S\mathbf T^T`, are solved for
    :math:`\mathbf z` (:func:`port_forces_step`).

    Modal arrays in real form (n_x columns: the real parts of the n modes, then the imaginary
    parts of the n_c complex ones, which come first): ``modal = (lam_d, G, Ra, (Da, S), h)``,
    ``lam_d = (real parts (n,), imaginary parts (n_c,))``, ``G``, ``Ra`` (q, n_x). ``out``
    (n_rows, n_out) gets the ``outputs`` (:func:`_write_outputs`) at steps 0 .. n_rows - 1 of
    the loads ``F`` (n_rows + 1, n_load); ``ports = (T, load_at, Qu)``, ``laws = (kinds, par,
    state)``; ``tol``, ``max_iter`` as :func:`newmark_port_kernel`. ``x`` (n_x,), ``y`` (3 q,)
    (displacements, velocities, accelerations) and ``z`` (m,) are the state at step 0 on entry,
    at step n_rows on return; ``state`` is updated. Returns the steps where Newton failed.
    """
    (lr, li), G, Ra, (Da, S), h = modal
    T, load_at, Qu = ports
    kinds, par, state = laws
    (m, q), n, nc, nx, hh, hv = T.shape, lr.shape[0], li.shape[0], x.shape[0], 0.25 * h * h, 0.5 * h
    p, p_next, base, wu, wv = np.empty(q), np.empty(q), np.empty(q), np.empty(q), np.empty(q)
    ul, vl, r, J, last = np.empty(m), np.empty(m), np.empty(m), np.empty((m, m)), np.zeros((7, m))
    g = np.empty(outputs[0][0].shape[1])
    coupled, failed = port_coupling(Qu, 2.0 / h), 0
    _load_less_ports(load_at, T, F, 0, z, p)
    for k in range(out.shape[0]):
        if out.shape[1]:
            _write_outputs(outputs, x, y, p, z, out, k, g)
        _load_less_ports(load_at, T, F, k + 1, z[:0], p_next)       # the load alone
        for c in range(q):      # the reduced accelerations: the modal read, the forces
            s = 0.0
            for j in range(nx):
                s += Ra[c, j] * x[j]
            for d in range(q):
                s += Da[c, d] * p[d]
            base[c] = s
        for c in range(q):
            s = base[c]
            for d in range(q):
                s += S[c, d] * p_next[d]
            s += y[2 * q + c]   # the port motions at the load alone: Newmark's kinematics
            wu[c] = y[c] + h * y[q + c] + hh * s
            wv[c] = y[q + c] + hv * s
        for e in range(m):
            su, sv = 0.0, 0.0
            for c in range(q):
                su += T[e, c] * wu[c]
                sv += T[e, c] * wv[c]
            ul[e], vl[e] = su, sv
        if not port_forces_step(kinds, par, state, ul, vl, coupled, z, last, r, J, tol, max_iter):
            failed += 1
        _load_less_ports(load_at, T, F, k + 1, z, p_next)
        for c in range(q):
            s = base[c]
            for d in range(q):
                s += S[c, d] * p_next[d]
            s2 = y[2 * q + c] + s
            y[c] += h * y[q + c] + hh * s2
            y[q + c] += hv * s2
            y[2 * q + c] = s
            p[c] += p_next[c]
        for j in range(nc):     # the modal recurrence, in real form
            t = lr[j] * x[j] - li[j] * x[n + j]
            x[n + j] = lr[j] * x[n + j] + li[j] * x[j]
            x[j] = t
        for j in range(nc, n):
            x[j] *= lr[j]
        for c in range(q):
            sc = p[c]
            for j in range(nx):
                x[j] += G[c, j] * sc
        for c in range(q):
            p[c] = p_next[c]
    return failed
