r"""Port laws: nonlinear forces across a mount network, evaluated from plain arrays.

A port law acts in parallel with a mount network, between its engine-side node and its base
node, on the relative displacement :math:`u = x_E - x_B` and velocity :math:`\dot u`. Numba
cannot call Python objects fast, so every law is a kind code, a row of parameters and a row
of state (its memory, e.g. the friction element's reversal point), dispatched here by code:

* :func:`port_force` gives the trial force :math:`f` (on the base; :math:`-f` on the engine
  side), the tangent stiffness :math:`\partial f/\partial u` and the tangent damping
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


@njit(cache=True, nogil=True)
def _berg_branch(u, par, state):
    """``(direction, x_s, F_s)`` of the branch the point ``u`` lies on: the committed one
    while the motion keeps its direction, else a new one from the last committed point."""
    du = u - state[3]
    d = 1.0 if du > 0 else (-1.0 if du < 0 else state[2])
    if d == state[2]:
        return d, state[0], state[1]
    return d, state[3], state[4]


@njit(cache=True, nogil=True)
def _berg(u, par, state):
    """Berg's force and tangent stiffness at ``u`` from the committed ``state``."""
    fm = par[0]
    x2 = par[1]
    if fm <= 0.0:
        return 0.0, 0.0
    d, xs, fs = _berg_branch(u, par, state)
    if d == 0.0:
        return state[4], fm / x2
    y = u - xs
    if d > 0:
        a = x2 * (1.0 - fs / fm)
        if y < 0.0:
            y = 0.0
        return fs + y / (a + y) * (fm - fs), a * (fm - fs) / ((a + y) * (a + y))
    b = x2 * (1.0 + fs / fm)
    if y > 0.0:
        y = 0.0
    return fs + y / (b - y) * (fm + fs), b * (fm + fs) / ((b - y) * (b - y))


@njit(cache=True, nogil=True)
def port_force(kind, u, v, par, state):
    """``(f, df/du, df/dv)`` of the port law ``kind`` at ``(u, v)`` from the committed
    ``state`` (unchanged) [N, N/m, N·s/m]."""
    if kind == JENKINS:
        k = par[0]
        fs = par[1]
        f = k * (u - state[0])
        if f > fs:
            return fs, 0.0, 0.0
        if f < -fs:
            return -fs, 0.0, 0.0
        return f, k, 0.0
    if kind == BERG:
        f, kt = _berg(u, par, state)
        return f, kt, 0.0
    return 0.0, 0.0, 0.0


@njit(cache=True, nogil=True)
def commit_state(kind, u, v, par, state):
    """Update ``state`` in place after a converged step ending at ``(u, v)``."""
    if kind == JENKINS:
        k = par[0]
        fs = par[1]
        f = k * (u - state[0])
        if f > fs:
            state[0] = u - fs / k
        elif f < -fs:
            state[0] = u + fs / k
    elif kind == BERG:
        f = _berg(u, par, state)[0]
        d, xs, fsr = _berg_branch(u, par, state)
        state[0] = xs
        state[1] = fsr
        state[2] = d
        state[3] = u
        state[4] = f


@njit(cache=True, nogil=True)
def port_force_loop(kinds, par, state, U, V, F):
    """Forces ``F`` (n_t, m) of the port laws along prescribed motions ``U``, ``V``
    (n_t, m), committing the state after every point (a displacement-driven test)."""
    for t in range(U.shape[0]):
        for e in range(kinds.shape[0]):
            F[t, e] = port_force(kinds[e], U[t, e], V[t, e], par[e], state[e])[0]
            commit_state(kinds[e], U[t, e], V[t, e], par[e], state[e])


@njit(cache=True, nogil=True)
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
    :math:`\mathbf I + \mathrm{diag}(\tfrac{h^2}{4}k_t + \tfrac h2 c_t)\mathbf Q`), from the
    previous step's forces; the states are committed once it has converged.

    Parameters
    ----------
    G, H, Fs, h, x0, v0, a0, X, V, A
        As :func:`newmark_kernel`.
    W : ndarray (n, m)
        S^-1 P^T.
    P : ndarray (m, n)
        Port rows: relative displacement across each port law per unit coordinate.
    Q : ndarray (m, m)
        P S^-1 P^T.
    kinds : ndarray int64 (m,)
        Port-law codes.
    par : ndarray (m, n_par)
        Their parameters.
    state : ndarray (m, n_state)
        Their state, updated in place (the state after the last step).
    Z : ndarray (n_steps + 1, m)
        Output: port forces at every time point [N].
    tol : float
        Newton stops when every residual is below ``tol`` times (1 + the largest force).
    max_iter : int

    Returns
    -------
    int
        Steps at which Newton did not converge (0 on success).
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
    failed = 0
    for j in range(n):
        X[0, j] = x0[j]
        V[0, j] = v0[j]
        A[0, j] = a0[j]
    for e in range(m):
        z[e] = port_force(kinds[e], _dot(P[e], x0), _dot(P[e], v0), par[e], state[e])[0]
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
        converged = False
        for _ in range(max_iter):
            big = 1.0
            worst = 0.0
            for e in range(m):
                qz = _dot(Q[e], z)
                f, kt, ct = port_force(kinds[e], ul[e] - hh * qz, vl[e] - hv * qz, par[e],
                                       state[e])
                r[e] = f - z[e]
                big = max(big, abs(z[e]))
                worst = max(worst, abs(r[e]))
                for j in range(m):
                    J[e, j] = (hh * kt + hv * ct) * Q[e, j]
                J[e, e] += 1.0
            if worst <= tol * big:
                converged = True
                break
            _solve_in_place(J, r)
            for e in range(m):
                z[e] += r[e]
        if not converged:
            failed += 1
        for e in range(m):
            qz = _dot(Q[e], z)
            commit_state(kinds[e], ul[e] - hh * qz, vl[e] - hv * qz, par[e], state[e])
            Z[k, e] = z[e]
        for j in range(n):
            A[k, j] -= _dot(W[j], z)
            X[k, j] = xt[j] + hh * A[k, j]
            V[k, j] = vt[j] + hv * A[k, j]
    return failed


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _modal_load(Lr, Li, f, n_re, n_im):
    """Modal load ``n = L f`` (real and imaginary parts) of the load ``f``."""
    for j in range(n_re.shape[0]):
        n_re[j] = 0.0
        n_im[j] = 0.0
    for c in range(f.shape[0]):
        fc = f[c]
        Lrc = Lr[c]
        Lic = Li[c]
        for j in range(n_re.shape[0]):
            n_re[j] += Lrc[j] * fc
            n_im[j] += Lic[j] * fc


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _modal_predictor(lr, li, gr, gi, g_re, g_im, n_re, n_im, er, ei):
    """``eta <- lam_d eta + gain (g + n)`` in place: the step without the new port forces."""
    for j in range(er.shape[0]):
        sr = g_re[j] + n_re[j]
        si = g_im[j] + n_im[j]
        a = lr[j] * er[j] - li[j] * ei[j] + gr[j] * sr - gi[j] * si
        ei[j] = lr[j] * ei[j] + li[j] * er[j] + gr[j] * si + gi[j] * sr
        er[j] = a


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _real_rows(Wr, Wi, er, ei, out):
    """``out = Re(W eta)`` for the rows of ``W`` (real and imaginary parts)."""
    for c in range(out.shape[0]):
        Wrc = Wr[c]
        Wic = Wi[c]
        y = 0.0
        for j in range(er.shape[0]):
            y += Wrc[j] * er[j] - Wic[j] * ei[j]
        out[c] = y


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _port_load(Br, Bi, z, n_re, n_im, g_re, g_im):
    """Modal load of the step ``g = n + B z`` (external and port forces)."""
    for j in range(g_re.shape[0]):
        g_re[j] = n_re[j]
        g_im[j] = n_im[j]
    for e in range(z.shape[0]):
        ze = z[e]
        Bre = Br[e]
        Bie = Bi[e]
        for j in range(g_re.shape[0]):
            g_re[j] += Bre[j] * ze
            g_im[j] += Bie[j] * ze


@njit(cache=True, nogil=True, fastmath=True, inline="always")
def _port_correction(gr, gi, g_re, g_im, n_re, n_im, er, ei):
    """``eta += gain (g - n)``: the port forces' part of the step."""
    for j in range(er.shape[0]):
        br = g_re[j] - n_re[j]
        bi = g_im[j] - n_im[j]
        er[j] += gr[j] * br - gi[j] * bi
        ei[j] += gr[j] * bi + gi[j] * br


@njit(cache=True, nogil=True)
def _port_newton(kinds, par, state, ul, vl, Qu, Qv, z, r, J, tol, max_iter):
    """Newton on the port forces ``z`` (in place) of one step: ``z_e = f_e(ul_e - (Qu z)_e,
    vl_e - (Qv z)_e)``, from the given ``z``; the states are committed. True on success."""
    m = z.shape[0]
    converged = False
    for _ in range(max_iter):
        big = 1.0
        worst = 0.0
        for e in range(m):
            f, kt, ct = port_force(kinds[e], ul[e] - _dot(Qu[e], z), vl[e] - _dot(Qv[e], z),
                                   par[e], state[e])
            r[e] = f - z[e]
            big = max(big, abs(z[e]))
            worst = max(worst, abs(r[e]))
            for j in range(m):
                J[e, j] = kt * Qu[e, j] + ct * Qv[e, j]
            J[e, e] += 1.0
        if worst <= tol * big:
            converged = True
            break
        _solve_in_place(J, r)
        for e in range(m):
            z[e] += r[e]
    for e in range(m):
        commit_state(kinds[e], ul[e] - _dot(Qu[e], z), vl[e] - _dot(Qv[e], z), par[e],
                     state[e])
    return converged


@njit(cache=True, nogil=True, fastmath=True)
def modal_port_kernel(lam_d, gain, L, B, Up, Vp, Qu, Qv, W, Wl, Wz, F, eta, z, kinds, par,
                      state, out, tol, max_iter):
    r"""Newmark average acceleration with port laws in modal coordinates: the trapezoidal
    modal recurrence :math:`\eta_{k+1} = \lambda_d\eta_k + \gamma(g_k + g_{k+1})` of the linear
    model (:class:`~powertrain.solvers.newmark.ModalNewmark`) with the modal load
    :math:`g = \mathbf L\mathbf f + \mathbf B\mathbf z` of the external load and of the port
    forces :math:`\mathbf z` (``B`` the modal map of :math:`-\mathbf P^T\mathbf z`). The port
    motions are :math:`\mathbf u = \mathrm{Re}(\mathbf U_p\eta)`,
    :math:`\dot{\mathbf u} = \mathrm{Re}(\mathbf V_p\eta)`, so with the predictor
    :math:`\eta^*` (the step without the new port forces)
    :math:`\mathbf u = \mathrm{Re}(\mathbf U_p\eta^*) - \mathbf Q_u\mathbf z`,
    :math:`\mathbf Q_u = -\mathrm{Re}(\mathbf U_p\,\mathrm{diag}\gamma\,\mathbf B)`
    (:math:`= \tfrac{h^2}4\mathbf Q` of :func:`newmark_port_kernel`; :math:`\mathbf Q_v` with
    :math:`\mathbf V_p`, :math:`= \tfrac h2\mathbf Q`), and Newton solves the m port equations
    per step as there.

    Modal arrays are split into real and imaginary parts, rows per load, port or output
    (``L = (Lr, Li)`` (n_load, n_modes), ``B`` (m, n_modes), ``Up``, ``Vp`` (m, n_modes),
    ``W`` (n_out, n_modes)). Outputs ``out`` (n_rows, n_out) at steps 0 .. n_rows - 1 of the
    loads ``F`` (n_rows + 1, n_load): ``y = Re(W eta) + Wl f + Wz z``. ``eta`` (n_modes,)
    complex and the port forces ``z`` (m,) are the state at step 0 on entry and at step
    n_rows on return; ``state`` the port laws' (updated in place). Returns the number of
    steps at which Newton did not converge.
    """
    Lr, Li = L
    Br, Bi = B
    n_modes = eta.shape[0]
    m = z.shape[0]
    lr, li, gr, gi = lam_d.real.copy(), lam_d.imag.copy(), gain.real.copy(), gain.imag.copy()
    er, ei = eta.real.copy(), eta.imag.copy()
    n_re, n_im = np.zeros(n_modes), np.zeros(n_modes)
    g_re, g_im = np.zeros(n_modes), np.zeros(n_modes)
    _modal_load(Lr, Li, F[0], n_re, n_im)
    _port_load(Br, Bi, z, n_re, n_im, g_re, g_im)
    ul, vl, r, y = np.empty(m), np.empty(m), np.empty(m), np.empty(out.shape[1])
    J = np.empty((m, m))
    failed = 0
    for k in range(out.shape[0]):
        _real_rows(W[0], W[1], er, ei, y)
        for c in range(y.shape[0]):
            out[k, c] = y[c] + _dot(Wl[c], F[k]) + _dot(Wz[c], z)
        _modal_load(Lr, Li, F[k + 1], n_re, n_im)
        _modal_predictor(lr, li, gr, gi, g_re, g_im, n_re, n_im, er, ei)
        _real_rows(Up[0], Up[1], er, ei, ul)
        _real_rows(Vp[0], Vp[1], er, ei, vl)
        if not _port_newton(kinds, par, state, ul, vl, Qu, Qv, z, r, J, tol, max_iter):
            failed += 1
        _port_load(Br, Bi, z, n_re, n_im, g_re, g_im)
        _port_correction(gr, gi, g_re, g_im, n_re, n_im, er, ei)
    for j in range(n_modes):
        eta[j] = er[j] + 1j * ei[j]
    return failed
