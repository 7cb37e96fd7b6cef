r"""Port laws: nonlinear forces across a mount network, evaluated from plain arrays.

A port law acts in parallel with a mount network, between its engine-side node and its base
node, on the relative displacement :math:`u = x_E - x_B` and velocity :math:`\dot u`. Numba
cannot call Python objects fast, so every law is a kind code, a row of parameters and a row
of state (its memory, e.g. the friction element's reversal point), dispatched here by code:

* :func:`law_force` (:func:`port_force` for one law's rows) gives the trial force
  :math:`f` (on the base; :math:`-f` on the engine side), the tangent stiffness
  :math:`\partial f/\partial u` and the tangent damping
  :math:`\partial f/\partial\dot u` at :math:`(u, \dot u)` from the committed state, without
  changing it (Newton iterates on it);
* :func:`commit_state` updates the state once the step has converged.

A new law adds its code, one branch in each of the two functions and its Python element type
(:mod:`powertrain.physics.mount_elements`); the Newmark kernel with port laws
(:func:`newmark_port_kernel`, here because kernels import no other kernel) does not change.
"""

import numpy as np
from numba import njit

#: No force (a linear element has no port law; kept so that code 0 is harmless).
NONE = 0
#: Jenkins element: spring ``k = par[0]`` in series with a Coulomb slider of slip force
#: ``F_s = par[1]``; state ``z = state[0]``, the slider's position.
JENKINS = 1
#: Berg's friction element: ``F_max = par[0]``, ``x2 = par[1]``; state ``[x_s, F_s,
#: direction, u_last, F_last]``: the last reversal point, the direction of motion since it
#: (+1, -1; 0 before any motion) and the last committed point (a reversal, when the next
#: step turns back). Formula: :mod:`powertrain.physics.mount_laws`.
BERG = 2


@njit(cache=True, nogil=True, inline="always")
def _berg_branch(u, state, e):
    """``(direction, x_s, F_s)`` of the branch the point ``u`` lies on: the committed one
    while the motion keeps its direction, else a new one from the last committed point."""
    du = u - state[e, 3]
    d = 1.0 if du > 0 else (-1.0 if du < 0 else state[e, 2])
    if d == state[e, 2]:
        return d, state[e, 0], state[e, 1]
    return d, state[e, 3], state[e, 4]


@njit(cache=True, nogil=True, inline="always")
def _berg(u, par, state, e):
    """Berg's force and tangent stiffness at ``u`` from the committed ``state``."""
    fm = par[e, 0]
    x2 = par[e, 1]
    if fm <= 0.0:
        return 0.0, 0.0
    d, xs, fs = _berg_branch(u, state, e)
    if d == 0.0:
        return state[e, 4], fm / x2
    y = u - xs
    if d > 0:
        a = x2 * (1.0 - fs / fm)
        if y < 0.0:
            y = 0.0
        w = (fm - fs) / (a + y)
        return fs + y * w, a * w / (a + y)
    b = x2 * (1.0 + fs / fm)
    if y > 0.0:
        y = 0.0
    w = (fm + fs) / (b - y)
    return fs + y * w, b * w / (b - y)


@njit(cache=True, nogil=True, inline="always")
def law_force(kind, u, v, par, state, e):
    """``(f, df/du, df/dv)`` of the port law ``kind`` at ``(u, v)`` from the committed
    state, row ``e`` of ``par`` and ``state`` (unchanged) [N, N/m, N·s/m] (2-D arrays and a
    row index: no array view per call in the kernels' loops)."""
    if kind == JENKINS:
        k = par[e, 0]
        fs = par[e, 1]
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
    """:func:`law_force` of one law, its parameters ``par`` and ``state`` as rows."""
    return law_force(kind, u, v, par.reshape((1, par.size)), state.reshape((1, state.size)),
                     0)


@njit(cache=True, nogil=True, inline="always")
def commit_state(kind, u, v, par, state, e, f):
    """Update row ``e`` of ``state`` in place after a converged step ending at ``(u, v)``,
    where the law gives the force ``f`` (:func:`law_force`)."""
    if kind == JENKINS:
        k = par[e, 0]
        fs = par[e, 1]
        f = k * (u - state[e, 0])
        if f > fs:
            state[e, 0] = u - fs / k
        elif f < -fs:
            state[e, 0] = u + fs / k
    elif kind == BERG:
        d, xs, fsr = _berg_branch(u, state, e)
        state[e, 0] = xs
        state[e, 1] = fsr
        state[e, 2] = d
        state[e, 3] = u
        state[e, 4] = f


@njit(cache=True, nogil=True)
def port_force_loop(kinds, par, state, U, V, F):
    """Forces ``F`` (n_t, m) of the port laws along prescribed motions ``U``, ``V``
    (n_t, m), committing the state after every point (a displacement-driven test)."""
    for t in range(U.shape[0]):
        for e in range(kinds.shape[0]):
            F[t, e] = law_force(kinds[e], U[t, e], V[t, e], par, state, e)[0]
            commit_state(kinds[e], U[t, e], V[t, e], par, state, e, F[t, e])


@njit(cache=True, nogil=True, inline="always")
def _dot(a, b):
    """Dot product of two short vectors (a loop: no BLAS call per step)."""
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s


@njit(cache=True, nogil=True)
def _solve_in_place(J, r):
    """Solve ``J x = r`` (small, dense) by Gaussian elimination with partial pivoting;
    ``x`` overwrites ``r``, ``J`` is destroyed (no allocation per call)."""
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
    r"""Newmark average acceleration with port laws in parallel with the linear model:
    :math:`\mathbf M\ddot{\mathbf x} + \mathbf C\dot{\mathbf x} + \mathbf K\mathbf x
    + \mathbf P^T\mathbf z = \mathbf f`, :math:`z_e = f_e(\mathbf p_e\cdot\mathbf x,
    \mathbf p_e\cdot\dot{\mathbf x})` (:mod:`powertrain.kernels.port_forces`).

    The linear step gives :math:`\ddot{\mathbf x}_{lin}` as in
    :func:`powertrain.kernels.newmark.newmark_kernel`; with
    the port forces :math:`\ddot{\mathbf x} = \ddot{\mathbf x}_{lin} - \mathbf W\mathbf z`,
    :math:`\mathbf W = \mathbf S^{-1}\mathbf P^T`, so the port motions are
    :math:`\mathbf u = \mathbf u_{lin} - \tfrac{h^2}{4}\mathbf Q\mathbf z`,
    :math:`\dot{\mathbf u} = \dot{\mathbf u}_{lin} - \tfrac h2\mathbf Q\mathbf z`,
    :math:`\mathbf Q = \mathbf P\mathbf W`. Newton solves the m equations
    :math:`z_e = f_e(u_e, \dot u_e)` per step (Jacobian
    :math:`\mathbf I + \mathrm{diag}(\tfrac{h^2}{4}k_t + \tfrac h2 c_t)\mathbf Q`; its
    diagonal first, :func:`_port_forces_step`), from the tangent at the previous step; the
    states are committed once it has converged.

    Arguments: ``G, H, Fs, h, x0, v0, a0, X, V, A`` as :func:`newmark_kernel`; ``W`` (n, m)
    = S^-1 P^T; ``P`` (m, n) the port rows (relative displacement across each port law per
    unit coordinate); ``Q`` (m, m) = P S^-1 P^T; ``kinds`` (m,) int64 the port-law codes,
    ``par`` (m, n_par) their parameters, ``state`` (m, n_state) their state (updated in
    place to the state after the last step); output ``Z`` (n_steps + 1, m) the port forces
    at every time point [N]; Newton stops when every residual is below ``tol`` times (1 +
    the largest force), or after ``max_iter`` iterations. Returns the number of steps at
    which Newton did not converge (0 on success).
    """
    n = x0.shape[0]
    m = kinds.shape[0]
    ns = Fs.shape[0]
    hh = 0.25 * h * h
    hv = 0.5 * h
    xt = np.empty(n)
    vt = np.empty(n)
    ul = np.empty(m)
    vl = np.empty(m)
    z = np.empty(m)
    r = np.empty(m)
    J = np.empty((m, m))
    coupled = _coupling(hh * Q, hv * Q)
    last = np.zeros((6, m))
    failed = 0
    for j in range(n):
        X[0, j] = x0[j]
        V[0, j] = v0[j]
        A[0, j] = a0[j]
    for e in range(m):
        z[e] = law_force(kinds[e], _dot(P[e], x0), _dot(P[e], v0), par, state, e)[0]
        Z[0, e] = z[e]
    for k in range(1, ns):
        for j in range(n):
            xt[j] = X[k - 1, j] + h * V[k - 1, j] + hh * A[k - 1, j]
            vt[j] = V[k - 1, j] + hv * A[k - 1, j]
        Ak = A[k]
        for i in range(n):
            s = Fs[k, i]
            Gi = G[i]            # row views: 2-D indexing in the inner loop is slower
            Hi = H[i]
            for j in range(n):
                s -= Gi[j] * vt[j] + Hi[j] * xt[j]
            Ak[i] = s
        for e in range(m):
            Pe = P[e]
            su = 0.0
            sv = 0.0
            for j in range(n):
                su += Pe[j] * (xt[j] + hh * Ak[j])
                sv += Pe[j] * (vt[j] + hv * Ak[j])
            ul[e] = su
            vl[e] = sv
        if not _port_forces_step(kinds, par, state, ul, vl, coupled, z, last, r, J, tol,
                                 max_iter):
            failed += 1
        for e in range(m):
            Z[k, e] = z[e]
        for j in range(n):
            A[k, j] -= _dot(W[j], z)
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]
    return failed


@njit(cache=True, nogil=True)
def _port_newton(kinds, par, state, ul, vl, Qu, Qv, z, r, J, tol, max_iter):
    """Newton on the port forces ``z`` (in place) of one step: ``z_e = f_e(ul_e - (Qu z)_e,
    vl_e - (Qv z)_e)``, from the given ``z``. True on success."""
    m = z.shape[0]
    for _ in range(max_iter):
        big = 1.0
        worst = 0.0
        for e in range(m):
            f, kt, ct = law_force(kinds[e], ul[e] - _dot(Qu[e], z), vl[e] - _dot(Qv[e], z),
                                  par, state, e)
            r[e] = f - z[e]
            big = max(big, abs(z[e]))
            worst = max(worst, abs(r[e]))
            for j in range(m):
                J[e, j] = kt * Qu[e, j] + ct * Qv[e, j]
            J[e, e] += 1.0
        if worst <= tol * big:
            return True
        _solve_in_place(J, r)
        for e in range(m):
            z[e] += r[e]
    return False


#: Iterations of the diagonal Newton before full Newton takes over (:func:`_port_forces_step`).
JACOBI_ITER = 8


@njit(cache=True, nogil=True, inline="always")
def _port_forces_step(kinds, par, state, ul, vl, Q, z, last, r, J, tol, max_iter):
    """The port forces ``z`` (in place, from the last step's) of one step, ``z_e =
    f_e(ul_e - (Qu z)_e, vl_e - (Qv z)_e)``, ``Q = (Qu, Qv, row sums of |Qu|, |Qv|)``
    (:func:`_coupling`), and the states committed. True on success.

    The ports are coupled only through the body's motion within one step (``Qu``, ``Qv`` of
    the order h^2/mass: ``|k_t Qu|`` ~ 1e-5 for the default engine's friction at 40 kHz): the
    forces ``f`` the laws give at the motion of forces ``z`` are those of the solution to
    within ``rho |f - z|``, ``rho = max_e |k_t,e| sum_j |Qu_ej| + |c_t,e| sum_j |Qv_ej|``
    (first order). So from a predictor on the tangent of the last committed point,
    ``last`` (6, m) = ``(u, v, df/du, df/dv)`` and two rows of work space (updated here;
    zeros: from ``z``), one
    evaluation mostly suffices: ``z = f`` is accepted when ``rho |f - z|`` is below ``tol``
    times (1 + the largest force) (the tolerance of :func:`_port_newton`, which takes over
    after :data:`JACOBI_ITER` iterations of Newton with the Jacobian's diagonal), and the
    states are committed at that evaluation."""
    Qu, Qv, qa = Q
    m = z.shape[0]
    _port_motions(ul, vl, Qu, Qv, z, last, 4)
    for e in range(m):
        z[e] += last[2, e] * (last[4, e] - last[0, e]) + last[3, e] * (last[5, e] - last[1, e])
    for _ in range(JACOBI_ITER):
        big, worst, rho = _port_residual(kinds, par, state, ul, vl, Qu, Qv, qa, z, last, r)
        if rho < 1.0 and rho * worst <= tol * big:
            for e in range(m):
                z[e] += r[e]
            _commit(kinds, par, state, last, z)
            return True
        for e in range(m):
            z[e] += r[e] / (1.0 + last[2, e] * Qu[e, e] + last[3, e] * Qv[e, e])
    converged = _port_newton(kinds, par, state, ul, vl, Qu, Qv, z, r, J, tol, max_iter)
    _port_residual(kinds, par, state, ul, vl, Qu, Qv, qa, z, last, r)
    for e in range(m):
        z[e] += r[e]
    _commit(kinds, par, state, last, z)
    return converged


@njit(cache=True, nogil=True)
def _coupling(Qu, Qv):
    """``(Qu, Qv, qa)`` of :func:`_port_forces_step`: ``qa`` (2, m) row sums of |Qu|, |Qv|."""
    qa = np.zeros((2, Qu.shape[0]))
    for e in range(Qu.shape[0]):
        for j in range(Qu.shape[1]):
            qa[0, e] += abs(Qu[e, j])
            qa[1, e] += abs(Qv[e, j])
    return Qu, Qv, qa


@njit(cache=True, nogil=True, inline="always")
def _port_motions(ul, vl, Qu, Qv, z, out, row):
    """Port motions ``u = ul - Qu z``, ``v = vl - Qv z`` into rows ``row``, ``row + 1`` of
    ``out`` (independent sums: no chain of dependent additions per port)."""
    for e in range(z.shape[0]):
        out[row, e] = ul[e]
        out[row + 1, e] = vl[e]
    for j in range(z.shape[0]):
        zj = z[j]
        for e in range(z.shape[0]):
            out[row, e] -= Qu[e, j] * zj
            out[row + 1, e] -= Qv[e, j] * zj


@njit(cache=True, nogil=True, inline="always")
def _port_residual(kinds, par, state, ul, vl, Qu, Qv, qa, z, last, r):
    """Residuals ``r = f(u, v) - z`` of the port forces ``z`` and the points ``last`` (4, m)
    = ``(u, v, df/du, df/dv)``; returns (1 + the largest force, the largest residual, the
    coupling bound rho of :func:`_port_forces_step`)."""
    _port_motions(ul, vl, Qu, Qv, z, last, 0)
    big = 1.0
    worst = 0.0
    rho = 0.0
    for e in range(z.shape[0]):
        f, last[2, e], last[3, e] = law_force(kinds[e], last[0, e], last[1, e], par, state,
                                              e)
        r[e] = f - z[e]
        big = max(big, abs(z[e]))
        worst = max(worst, abs(r[e]))
        rho = max(rho, abs(last[2, e]) * qa[0, e] + abs(last[3, e]) * qa[1, e])
    return big, worst, rho


@njit(cache=True, nogil=True, inline="always")
def _commit(kinds, par, state, last, f):
    """Commit the states at the points ``last`` where the laws give the forces ``f``."""
    for e in range(f.shape[0]):
        commit_state(kinds[e], last[0, e], last[1, e], par, state, e, f[e])


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _read_rows(R, x, out):
    """``out = R x``: rows of the modal state's real form (:func:`_advance`)."""
    for c in range(out.shape[0]):
        y = 0.0
        for j in range(x.shape[0]):
            y += R[c, j] * x[j]
        out[c] = y


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _body_force(load_at, T, F, k, z, p):
    """Generalized force ``p`` (q,) on the reduced coordinates: the load ``F[k]`` placed at
    ``load_at`` minus the port forces ``T^T z``."""
    for c in range(p.shape[0]):
        p[c] = 0.0
    for c in range(F.shape[1]):
        p[load_at[c]] += F[k, c]
    for e in range(z.shape[0]):
        ze = z[e]
        for c in range(p.shape[0]):
            p[c] -= T[e, c] * ze


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _write_outputs(W, Wd, Wz, x, p, z, row):
    """One row of outputs ``W x + Wd p + Wz z`` into ``row``."""
    _read_rows(W, x, row)
    for c in range(row.shape[0]):
        o = row[c]
        for d in range(p.shape[0]):
            o += Wd[c, d] * p[d]
        for e in range(z.shape[0]):
            o += Wz[c, e] * z[e]
        row[c] = o


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _linear_port_motions(R, D, T, x, s, y, ul, vl):
    """Port motions ``ul``, ``vl`` (m,) without the step's new port forces: the reduced ones
    ``y = R x + (Dx s; Dv s)`` (2 q,) through the port rows ``T``."""
    Dx, Dv = D
    q = Dx.shape[0]
    _read_rows(R, x, y)
    for c in range(q):
        for d in range(q):
            y[c] += Dx[c, d] * s[d]
            y[q + c] += Dv[c, d] * s[d]
    for e in range(ul.shape[0]):
        ul[e] = _dot(T[e], y[:q])
        vl[e] = _dot(T[e], y[q:])


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _advance(lam_d, G, s, x):
    """The modal recurrence ``eta = lambda_d eta + G s`` in place, in real form: ``x`` holds
    the real parts of the n modes, then the imaginary parts of the complex ones, which come
    first (a real mode's is zero but for round-off); ``lam_d = (real parts (n,), imaginary
    parts (n_c,))``."""
    lr, li = lam_d
    n = lr.shape[0]
    for j in range(li.shape[0]):
        a = lr[j] * x[j] - li[j] * x[n + j]
        x[n + j] = lr[j] * x[n + j] + li[j] * x[j]
        x[j] = a
    for j in range(li.shape[0], n):
        x[j] *= lr[j]
    for c in range(s.shape[0]):
        sc = s[c]
        for j in range(x.shape[0]):
            x[j] += G[c, j] * sc


@njit(cache=True, nogil=True, fastmath=True)
def modal_port_kernel(modal, outputs, ports, laws, F, x, z, out, tol, max_iter):
    r"""Newmark average acceleration with port laws in modal coordinates: the trapezoidal
    modal recurrence of the linear model (:class:`~powertrain.solvers.newmark.ModalNewmark`)
    :math:`\eta_{k+1} = \lambda_d\eta_k + \mathbf G(\mathbf p_k + \mathbf p_{k+1})`, the
    generalized force :math:`\mathbf p` on the q reduced coordinates :math:`\mathbf y` (those
    the load or a port row touches: the body's six) being the load minus the port forces,
    :math:`\mathbf p = \mathbf E\mathbf f - \mathbf T^T\mathbf z` (port rows
    :math:`\mathbf P = \mathbf T\,\partial\mathbf y/\partial\mathbf x`), and
    :math:`\mathbf G = \mathrm{diag}\gamma\,\Psi^{-1}[0; \mathbf M^{-1}]` on them.

    Per step: the outputs :math:`\mathrm{Re}(\mathbf W\eta_k) + \mathbf W_d\mathbf p_k +
    \mathbf W_z\mathbf z_k`; the reduced motions of the next step without its new port
    forces, :math:`\mathbf y^* = \mathrm{Re}(\Psi_y\lambda_d\eta_k) + \mathbf D_x\mathbf s`,
    :math:`\mathbf s = \mathbf p_k + \mathbf E\mathbf f_{k+1}`,
    :math:`\mathbf D_x = \mathrm{Re}(\Psi_y\mathbf G)` (velocities alike); the port motions
    :math:`\mathbf u = \mathbf T\mathbf y^* - \mathbf Q_u\mathbf z`, :math:`\mathbf Q_u =
    \mathbf T\mathbf D_x\mathbf T^T` (the :math:`\tfrac{h^2}4\mathbf P\mathbf S^{-1}\mathbf
    P^T` of :func:`newmark_port_kernel`), solved for :math:`\mathbf z`
    (:func:`_port_forces_step`); then the recurrence. Arguments (modal arrays in the real
    form of :func:`_advance`, n_x columns): ``modal = (lam_d, G, R, (Dx, Dv))``, ``G``
    (q, n_x) (the map's columns as rows), ``R`` (2 q, n_x) the rows reading
    :math:`\mathrm{Re}(\Psi_y\lambda_d\eta)`, :math:`\mathrm{Re}(\Psi_{\dot
    y}\lambda_d\eta)`; ``outputs = (W, Wd, Wz)`` (n_out rows), ``out``
    (n_rows, n_out) gets them at steps 0 .. n_rows - 1 of the loads ``F`` (n_rows + 1,
    n_load); ``ports = (T, load_at, Qu, Qv)``, ``laws = (kinds, par, state)``. The modal
    state ``x`` (n_x,) and the port forces ``z`` (m,) are the state at step 0 on entry and
    at step n_rows on return, ``state`` is updated in place. Returns the number of steps at
    which Newton did not converge.
    """
    lam_d, G, R, D = modal
    W, Wd, Wz = outputs
    T, load_at, Qu, Qv = ports
    kinds, par, state = laws
    m = z.shape[0]
    q = T.shape[1]
    y = np.empty(2 * q)
    p, p_next, s = np.empty(q), np.empty(q), np.empty(q)
    ul, vl, r = np.empty(m), np.empty(m), np.empty(m)
    J = np.empty((m, m))
    last = np.zeros((6, m))
    coupled = _coupling(Qu, Qv)
    _body_force(load_at, T, F, 0, z, p)
    failed = 0
    for k in range(out.shape[0]):
        _write_outputs(W, Wd, Wz, x, p, z, out[k])
        for c in range(q):
            s[c] = p[c]
        for c in range(F.shape[1]):
            s[load_at[c]] += F[k + 1, c]
        _linear_port_motions(R, D, T, x, s, y, ul, vl)
        if not _port_forces_step(kinds, par, state, ul, vl, coupled, z, last, r, J, tol,
                                 max_iter):
            failed += 1
        _body_force(load_at, T, F, k + 1, z, p_next)
        for c in range(q):
            s[c] = p[c] + p_next[c]
            p[c] = p_next[c]
        _advance(lam_d, G, s, x)
    return failed

