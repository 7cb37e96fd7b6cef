r"""Public Newmark average-acceleration integrator and its periodic steady state.

:func:`newmark` validates, allocates and calls :func:`powertrain.kernels.newmark.newmark_kernel`;
:func:`newmark_ports` the same with nonlinear port laws in parallel with the linear model
(:mod:`powertrain.physics.mount_elements`), Newton per step inside the kernel.
:func:`periodic_state` finds the exactly periodic steady state of the *discrete* Newmark
recurrence under a periodic load (shooting: the one-period map :math:`z \mapsto \Phi z + g`
is affine, so :math:`z_0 = (I-\Phi)^{-1} g`), so time-domain results need no transient to die
out and do not borrow anything from the frequency-domain solution.
"""

from __future__ import annotations

import copy
import threading

import numpy as np

from powertrain.kernels.newmark import modal_trapezoid_kernel, newmark_kernel
from powertrain.kernels.port_forces import modal_port_kernel, newmark_port_kernel


def _prepare(M, C, K, h):
    M = np.ascontiguousarray(M, dtype=float)
    C = np.ascontiguousarray(C, dtype=float)
    K = np.ascontiguousarray(K, dtype=float)
    n = M.shape[0]
    if M.shape != (n, n) or C.shape != (n, n) or K.shape != (n, n):
        raise ValueError("M, C, K must be square and of equal size")
    if not (np.isfinite(h) and h > 0):
        raise ValueError("time step must be positive")
    S = M + 0.5 * h * C + 0.25 * h * h * K
    Sinv = np.linalg.inv(S)
    return Sinv, np.ascontiguousarray(Sinv @ C), np.ascontiguousarray(Sinv @ K)


def newmark(M, C, K, F, h, x0=None, v0=None, a0=None):
    """Integrate M x'' + C x' + K x = f(t) with constant step ``h`` [s].

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m] (or consistent generalized units).
    F : ndarray (n_steps + 1, n)
        Load at every time point t_k = k h [N].
    h : float
        Time step [s].
    x0, v0, a0 : ndarray (n,), optional
        Initial state; zeros by default. When ``a0`` is omitted and M is regular it is made
        consistent: a0 = M^-1 (f0 - C v0 - K x0).

    Returns
    -------
    X, V, A : ndarray (n_steps + 1, n)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    Fs, x0, v0, a0 = _start(M, C, K, F, Sinv, x0, v0, a0)
    X = np.empty_like(Fs)
    V = np.empty_like(Fs)
    A = np.empty_like(Fs)
    newmark_kernel(G, H, Fs, float(h), x0, v0, a0, X, V, A)
    return X, V, A


def _start(M, C, K, F, Sinv, x0, v0, a0, port_force=None):
    """Pre-multiplied loads and the initial state (``a0`` consistent when omitted, with
    the port forces ``port_force`` (n,) on the left-hand side)."""
    F = np.asarray(F, dtype=float)
    n = Sinv.shape[0]
    if F.ndim != 2 or F.shape[1] != n:
        raise ValueError("F must have shape (n_steps + 1, n)")
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float).copy()
    v0 = np.zeros(n) if v0 is None else np.asarray(v0, float).copy()
    if a0 is None:
        inner = 0.0 if port_force is None else port_force
        try:
            a0 = np.linalg.solve(M, F[0] - C @ v0 - K @ x0 - inner)
        except np.linalg.LinAlgError:
            a0 = np.zeros(n)
    return np.ascontiguousarray(F @ Sinv.T), x0, v0, np.asarray(a0, float).copy()


#: Newton tolerance of the port laws per step (relative to 1 + the largest port force [N])
#: and its iteration limit; a piecewise-linear law converges in a few iterations.
PORT_TOL = 1e-10
PORT_MAX_ITER = 50


def newmark_ports(M, C, K, F, h, ports, x0=None, v0=None, a0=None, z0=None, state=None):
    """:func:`newmark` with the port laws ``ports``
    (:class:`~powertrain.physics.mount_elements.PortForces`) in parallel with the linear
    model: :func:`powertrain.kernels.port_forces.newmark_port_kernel`, Newton per step. The
    laws start from ``state`` (m, n_state), updated in place to the state after the last
    step, or else from the state carrying the forces ``z0`` (m,) [N] (default: unloaded).

    Returns
    -------
    X, V, A : ndarray (n_steps + 1, n)
    Z : ndarray (n_steps + 1, m)
        Port forces [N] (positive: pushing the base along the port row).

    Raises
    ------
    FloatingPointError
        Newton did not converge at some step (the names of the port laws are given).
    """
    Sinv, G, H = _prepare(M, C, K, h)
    P = np.ascontiguousarray(ports.rows, float)
    x0 = np.zeros(P.shape[1]) if x0 is None else x0
    v0 = np.zeros(P.shape[1]) if v0 is None else v0
    if state is None:
        state = ports.initial_state(x0, z0)
    z0 = ports.forces(P @ x0, P @ v0, state)
    Fs, x0, v0, a0 = _start(M, C, K, F, Sinv, x0, v0, a0, P.T @ z0)
    W = np.ascontiguousarray(Sinv @ P.T)
    X, V, A = (np.empty_like(Fs) for _ in range(3))
    Z = np.empty((Fs.shape[0], P.shape[0]))
    failed = newmark_port_kernel(G, H, Fs, float(h), x0, v0, a0, W, P,
                                 np.ascontiguousarray(P @ W), ports.kinds, ports.parameters,
                                 state, X, V, A, Z, PORT_TOL, PORT_MAX_ITER)
    if failed:
        raise FloatingPointError(f"port laws {', '.join(ports.names)}: Newton did not converge "
                                 f"at {failed} of {Fs.shape[0] - 1} steps")
    return X, V, A, Z


def periodic_state(M, C, K, F_period, h):
    """Initial state (x0, v0, a0) of the periodic steady state of the Newmark recurrence.

    Parameters
    ----------
    M, C, K : ndarray (n, n)
        [kg], [N·s/m], [N/m].
    F_period : ndarray (N + 1, n)
        Load over exactly one period, ``F_period[N] == F_period[0]``.
    h : float
        Time step [s]; N h is the period.

    Returns
    -------
    x0, v0, a0 : ndarray (n,)
    """
    Sinv, G, H = _prepare(M, C, K, h)
    F_period = np.asarray(F_period, float)
    n = G.shape[0]
    N = F_period.shape[0] - 1
    zero = np.zeros((N + 1, n))
    Fs = np.ascontiguousarray(F_period @ Sinv.T)
    X = np.empty_like(Fs)
    V = np.empty_like(Fs)
    A = np.empty_like(Fs)
    # forced response from rest -> g
    newmark_kernel(G, H, Fs, float(h), np.zeros(n), np.zeros(n), np.zeros(n), X, V, A)
    g = np.concatenate([X[-1], V[-1], A[-1]])
    # free response of each unit state -> columns of Phi
    Phi = np.empty((3 * n, 3 * n))
    e = np.zeros(3 * n)
    for col in range(3 * n):
        e[:] = 0.0
        e[col] = 1.0
        newmark_kernel(G, H, zero, float(h), e[:n].copy(), e[n:2 * n].copy(), e[2 * n:].copy(),
                       X, V, A)
        Phi[:, col] = np.concatenate([X[-1], V[-1], A[-1]])
    z0 = np.linalg.lstsq(np.eye(3 * n) - Phi, g, rcond=None)[0]
    return z0[:n], z0[n:2 * n], z0[2 * n:]


class ModalNewmark:
    r"""Newmark average acceleration for a linear time-invariant model, in modal coordinates.

    Average acceleration (β = 1/4, γ = 1/2) is the trapezoidal rule applied to the
    first-order form :math:`\dot{\mathbf z} = \mathbf A\mathbf z + \mathbf b`,
    :math:`\mathbf z = (\mathbf x, \dot{\mathbf x})`,
    :math:`\mathbf A = \begin{bmatrix}0 & I\\ -M^{-1}K & -M^{-1}C\end{bmatrix}`, so its
    propagator :math:`(I - \tfrac h2 A)^{-1}(I + \tfrac h2 A)` shares the eigenvectors of
    :math:`\mathbf A`. One eigendecomposition per model (independent of the step) turns every
    step into a diagonal complex recurrence (:func:`~powertrain.kernels.newmark.modal_trapezoid_kernel`)
    that reproduces :func:`newmark` to round-off (tests/test_runup.py checks it) at a fraction
    of the cost. Needs a regular mass matrix; use :func:`newmark` otherwise, and for nonlinear
    elements.

    Parameters
    ----------
    M, C, K : ndarray (n, n)
    load_dofs : int
        The load acts on the first ``load_dofs`` coordinates (6: the rigid body).
    """

    def __init__(self, M, C, K, load_dofs=None):
        M = np.asarray(M, float)
        n = M.shape[0]
        Minv = np.linalg.inv(M)
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -Minv @ K
        A[n:, n:] = -Minv @ np.asarray(C, float)
        lam, Psi = np.linalg.eig(A)
        self.n = n
        self.lam = lam
        self.Psi = Psi
        self.Psi_inv = np.linalg.inv(Psi)
        nl = n if load_dofs is None else int(load_dofs)
        self.load_dofs = nl
        self.M, self.C, self.K, self.Minv = M, np.asarray(C, float), np.asarray(K, float), Minv
        err = np.linalg.norm(Psi @ np.diag(lam) @ self.Psi_inv - A) / np.linalg.norm(A)
        if not err < 1e-8:
            raise np.linalg.LinAlgError(f"state matrix not safely diagonalisable ({err:.1e})")
        #: modal load per unit generalized load: Psi^-1 [0; M^-1 B]
        self.load_map = self.Psi_inv[:, n:] @ Minv[:, :nl]
        # For real loads and states the modal coordinates of a conjugate pair of modes are
        # conjugate: step one of each pair and count it twice in z = Re(sum Psi eta).
        scale = np.abs(lam).max()
        real_mode = np.abs(lam.imag) <= 1e-12 * scale
        keep = real_mode | (lam.imag > 0)
        if not np.isclose(2 * np.count_nonzero(lam.imag > 0) + np.count_nonzero(real_mode),
                          lam.size):
            raise np.linalg.LinAlgError("eigenvalues not in conjugate pairs")
        # the kept modes, complex ones first (:meth:`real_form`)
        order = np.r_[np.flatnonzero(keep & ~real_mode), np.flatnonzero(real_mode)]
        #: kept modes with a complex eigenvalue (the first ones)
        self.n_complex = int(np.count_nonzero(keep & ~real_mode))
        weight = np.where(real_mode[order], 1.0, 2.0)
        self._work = threading.local()   # per-thread output buffers, see run_outputs
        self.lam_r = lam[order]
        self.Psi_r = Psi[:, order] * weight[None, :]
        self.Psi_inv_r = self.Psi_inv[order]
        self.load_map_r = self.load_map[order]

    def real_form(self, a) -> np.ndarray:
        """``a`` (..., kept modes) complex in the kernels' real form: the real parts, then
        the imaginary parts of the complex modes (a real mode's is zero but for round-off),
        contiguous (:func:`powertrain.kernels.port_forces.modal_port_kernel`). A row ``r`` read as
        ``Re(r eta)`` is ``real_form(conj(r))``."""
        a = np.asarray(a)
        return np.ascontiguousarray(np.concatenate([a.real, a.imag[..., :self.n_complex]],
                                                   axis=-1))

    def run(self, F, h, x0, v0, keep_from=0):
        """Integrate with the load ``F`` (n_steps + 1, load_dofs) [N] from (x0, v0).

        Returns
        -------
        X, V, A : ndarray (n_steps + 1 - keep_from, n)
            States from time index ``keep_from`` on (A from the equation of motion).
        """
        F = np.asarray(F, float)
        lam_d = (1 + 0.5 * h * self.lam) / (1 - 0.5 * h * self.lam)
        gain = (0.5 * h) / (1 - 0.5 * h * self.lam)
        G = np.ascontiguousarray(F @ self.load_map.T)
        eta0 = self.Psi_inv @ np.concatenate([x0, v0]).astype(complex)
        shape = (F.shape[0] - keep_from, self.lam.size)
        out_re, out_im = np.empty(shape), np.empty(shape)
        modal_trapezoid_kernel(lam_d, gain, G, F.shape[0] - 1, eta0, int(keep_from),
                               out_re, out_im)
        Z = out_re @ self.Psi.T.real - out_im @ self.Psi.T.imag
        X, V = Z[:, :self.n], Z[:, self.n:]
        f_full = np.zeros((F.shape[0] - keep_from, self.n))
        f_full[:, :self.load_dofs] = F[keep_from:]
        A = (f_full - V @ self.C.T - X @ self.K.T) @ self.Minv.T
        return X, V, A

    def output_map(self, Wx, Wv, Wa=None):
        """Modal map of outputs ``y = Wx x + Wv v (+ Wa a)`` (rows = outputs).

        Returns ``(W_modal, W_load)``: ``y = Re(eta @ W_modal.T) + F @ W_load.T``, the second
        term being the direct load part of the acceleration, a = M^-1 (f - C v - K x).
        ``W_modal`` is returned as the pair (Re W^T, Im W^T) used by :meth:`run_outputs`.
        """
        n = self.n
        Wm = np.asarray(Wx, float) @ self.Psi_r[:n] + np.asarray(Wv, float) @ self.Psi_r[n:]
        W_load = np.zeros((Wm.shape[0], self.load_dofs))
        if Wa is not None:
            Wa = np.asarray(Wa, float)
            Wm = Wm + Wa @ (self.Psi_r[n:] * self.lam_r[None, :])
            W_load = Wa @ self.Minv[:, :self.load_dofs]
        return (np.ascontiguousarray(Wm.real.T), np.ascontiguousarray(Wm.imag.T)), W_load

    def harmonic_state(self, load_harmonics, omegas):
        """Steady state (x, v) at t = 0 of the harmonic load sum, in modal coordinates:
        eta_j = (Psi^-1 b_j) / (i w_j - lambda), z(0) = Re sum_j Psi eta_j."""
        g = np.asarray(load_harmonics, complex) @ self.load_map.T          # (n_h, m)
        eta = g / (1j * np.asarray(omegas, float)[:, None] - self.lam[None, :])
        z0 = (self.Psi @ eta.sum(axis=0)).real
        return z0[:self.n], z0[self.n:]

    def port_modes(self, rows):
        """``(Pm, Bp, K)`` of the port rows ``rows`` (m, n) (:meth:`port_harmonics`): the
        rows read off the modes, ``Pm`` (m, 2 n), the modal load of a unit force along
        each row pushing the model by minus the row, ``Bp`` (2 n, m), and each mode's
        part of the rows' response to the forces, ``K`` (2 n, m m) = ``Pm[:, j] Bp[j]``."""
        n = self.n
        Pm, Bp = rows @ self.Psi[:n], self.Psi_inv[:, n:] @ (self.Minv @ rows.T)
        return Pm, Bp, (Pm.T[:, :, None] * Bp[:, None, :]).reshape(Bp.shape[0], -1)

    def port_harmonics(self, modes, load_harmonics, omegas):
        """Per harmonic of the load (n_h, load_dofs) [N] at ``omegas`` (n_h,) [rad/s]:
        ``g`` (n_h, 2 n) = 1 / (i omega - lambda), the modal amplitudes under the load
        ``ef`` (n_h, 2 n), the relative motions along the port rows of ``modes``
        (:meth:`port_modes`) under the load, ``uf`` (n_h, m) [m], and per unit force along
        each row, ``Hp`` (n_h, m, m) [m/N]. Under port forces ``z`` (n_h, m) [N] the modal
        amplitudes are ``ef - g (z Bp^T)``, the coordinates' ``Psi[:n]`` times them."""
        Pm, _, K = modes
        g = 1.0 / (1j * np.asarray(omegas, float)[:, None] - self.lam[None, :])
        ef = g * (np.asarray(load_harmonics, complex) @ self.load_map.T)
        return g, ef, ef @ Pm.T, (g @ K).reshape(-1, Pm.shape[0], Pm.shape[0])

    def run_outputs(self, F_cycle, cycles, h, x0, v0, keep_from, W_modal, W_load):
        """Integrate ``cycles`` repetitions of the one-cycle load ``F_cycle`` (N, load_dofs)
        and return only the outputs ``y`` (rows from time index ``keep_from``).

        The modal and output arrays are work buffers reused from call to call (per thread):
        the returned array is valid until the next call from the same thread. Reuse matters:
        allocating ~0.5 MB per call lets the allocator hand the pages back to the system and
        fault them in again, which doubled the cost per speed step.
        """
        F_cycle = np.asarray(F_cycle, float)
        N = F_cycle.shape[0]
        lam_d = (1 + 0.5 * h * self.lam_r) / (1 - 0.5 * h * self.lam_r)
        gain = (0.5 * h) / (1 - 0.5 * h * self.lam_r)
        rows = cycles * N + 1 - keep_from
        out_re, out_im, Y, tmp, G = self._buffers(rows, W_modal[0].shape[1], N)
        np.matmul(F_cycle, self.load_map_r.T, out=G)
        eta0 = self.Psi_inv_r @ np.concatenate([x0, v0]).astype(complex)
        modal_trapezoid_kernel(lam_d, gain, G, cycles * N, eta0, int(keep_from), out_re, out_im)
        # Re(eta W^T) as two real products
        np.matmul(out_re, W_modal[0], out=Y)
        np.matmul(out_im, W_modal[1], out=tmp)
        Y -= tmp
        if np.any(W_load):
            idx = (np.arange(keep_from, cycles * N + 1)) % N
            np.matmul(F_cycle[idx], W_load.T, out=tmp)
            Y += tmp
        return Y

    def _buffers(self, rows, n_out, n_load):
        """Thread-local work arrays (modal real/imag parts, outputs, scratch, modal load)."""
        key = (rows, n_out, n_load)
        work = self._work
        if getattr(work, "key", None) != key:
            m = self.lam_r.size
            work.key = key
            work.arrays = (np.empty((rows, m)), np.empty((rows, m)), np.empty((rows, n_out)),
                           np.empty((rows, n_out)), np.empty((n_load, m), dtype=complex))
        return work.arrays


class ModalPortNewmark:
    r""":func:`newmark_ports` in modal coordinates, for a model whose matrices stay fixed:
    the port laws ``ports`` in parallel with the linear model of ``modal``
    (:class:`ModalNewmark`), the port forces solved per step
    (:func:`powertrain.kernels.port_forces.modal_port_kernel`; equal to
    :func:`newmark_ports` to round-off and the Newton tolerance,
    tests/test_time_domain_laws.py). The recurrence is written on the reduced coordinates
    the load and the port rows touch (the body's six: a port row is a rigid body's motion at
    a mount): the port motions are read from their motions (per step their accelerations
    off the modes, displacements and velocities by Newmark's kinematics, read off the modes
    again at each call), the port forces act through their generalized force. Outputs:
    ``y = Wx x + Wv v + Wa a + Wz z`` (rows over the coordinates, and over the port forces
    for ``Wz``; None: no such term).

    Parameters
    ----------
    modal : ModalNewmark
    ports : PortForces
        The port laws (every row with a law; ``ports.select(ports.kinds != NONE)``).
    h : float
        Time step [s].
    Wx, Wv, Wa : ndarray (n_out, n), optional
    Wz : ndarray (n_out, m), optional
    """

    def __init__(self, modal, ports, h, Wx=None, Wv=None, Wa=None, Wz=None):
        n = modal.n
        self.modal, self.ports = modal, ports
        P = np.asarray(ports.rows, float)
        self.reduced = r = np.union1d(np.arange(modal.load_dofs),
                                      np.flatnonzero(np.any(P != 0, 0)))
        #: rows reading the reduced state (x, v, a) off the modal state (a less M^-1 p)
        self._reduced_rows = modal.real_form(np.conj(np.vstack(
            [modal.Psi_r[r], modal.Psi_r[n + r], modal.Psi_r[n + r] * modal.lam_r])))
        self.outputs = self._output_arrays(Wx, Wv, Wa, Wz)
        self.silent = self._output_arrays(np.zeros((0, n)))
        #: what the step does not change: the port rows on the reduced coordinates, the
        #: modal map of the reduced forces, the modes' reduced accelerations, M^-1 there
        #: and where the load sits among the reduced coordinates
        self._fixed = (np.ascontiguousarray(P[:, r]), modal.Psi_inv_r[:, n:] @ modal.Minv[:, r],
                       modal.Psi_r[n + r] * modal.lam_r, modal.Minv[np.ix_(r, r)],
                       np.searchsorted(r, np.arange(modal.load_dofs)).astype(np.int64))
        self._set_step(h)

    def at_step(self, h) -> ModalPortNewmark:
        """The same model, port laws and outputs at the time step ``h`` [s] (the output
        arrays, which do not depend on the step, shared)."""
        other = copy.copy(self)
        other._set_step(h)
        return other

    def _set_step(self, h):
        """The kernel's arrays that depend on the time step ``h`` [s]."""
        modal = self.modal
        T, load_map, Pa, Minv_r, load_at = self._fixed
        self.h = float(h)
        lam = modal.lam_r
        lam_d = (1 + 0.5 * h * lam) / (1 - 0.5 * h * lam)
        G = ((0.5 * h) / (1 - 0.5 * h * lam))[:, None] * load_map          # (n_modes, q)
        Da = (Pa @ G).real
        S = Da + Minv_r
        self.modal_arrays = ((lam_d.real.copy(), lam_d.imag[:modal.n_complex].copy()),
                             modal.real_form(G.T), modal.real_form(np.conj(Pa * lam_d)),
                             (np.ascontiguousarray(Da), np.ascontiguousarray(S)), self.h)
        self.port_arrays = (T, load_at, np.ascontiguousarray(0.25 * h * h * (T @ S @ T.T)))

    def _output_arrays(self, Wx=None, Wv=None, Wa=None, Wz=None):
        """``((Wyz, y_cols, z_cols), w_rows, W, Wd)`` of :func:`modal_port_kernel` for
        the output rows: ``Wyz`` over the reduced state's columns ``y_cols`` and then the
        port forces' ``z_cols`` (the columns they read, :func:`_read_columns`); the rows
        ``w_rows`` that read other coordinates also through the modal state,
        ``Re(W eta) + Wd p`` (``Wd`` the direct part of the acceleration,
        a = M^-1 (p - C v - K x))."""
        modal, n, r = self.modal, self.modal.n, self.reduced
        off = np.setdiff1d(np.arange(n), r)
        rows = next(w.shape[0] for w in (Wx, Wv, Wa, Wz) if w is not None)
        W = np.zeros((rows, self.modal.lam_r.size), complex)
        Wd = np.zeros((rows, r.size))
        Wy = np.zeros((rows, 3, r.size))
        for i, (Wk, Psi) in enumerate(((Wx, modal.Psi_r[:n]), (Wv, modal.Psi_r[n:]),
                                       (Wa, modal.Psi_r[n:] * modal.lam_r[None, :]))):
            if Wk is not None:
                Wk = np.asarray(Wk, float)
                Wy[:, i] = Wk[:, r]
                W += Wk[:, off] @ Psi[off]
        if Wa is not None:
            Wd = np.asarray(Wa, float)[:, off] @ modal.Minv[np.ix_(off, r)]
        Wz = np.zeros((rows, self.ports.kinds.size)) if Wz is None else np.asarray(Wz, float)
        w_rows = np.flatnonzero(np.any(W != 0, 1) | np.any(Wd != 0, 1))
        (Wy, y_cols), (Wz, z_cols) = _read_columns(Wy.reshape(rows, 3 * r.size)), \
            _read_columns(Wz)
        return ((np.ascontiguousarray(np.hstack([Wy, Wz])), y_cols, z_cols),
                w_rows.astype(np.int64), modal.real_form(np.conj(W[w_rows])),
                np.ascontiguousarray(Wd[w_rows]))

    def modal_state(self, x, v) -> np.ndarray:
        """Modal coordinates of the state ``(x, v)`` in the kernel's real form
        (:meth:`ModalNewmark.real_form`)."""
        return self.modal.real_form(self.modal.Psi_inv_r @ np.concatenate([x, v]))

    def run(self, F, eta, z, state, outputs=True) -> np.ndarray:
        """Outputs (n_rows, n_out) at steps 0 .. n_rows - 1 of the loads ``F``
        (n_rows + 1, load_dofs) [N] (``outputs`` False: none, (n_rows, 0)); the modal state
        ``eta`` (:meth:`modal_state`), the port forces ``z`` (m,) [N] and the laws'
        ``state`` are the state at step 0 and are updated in place to step n_rows.

        Raises
        ------
        FloatingPointError
            Newton did not converge at some step (the names of the port laws are given).
        """
        arrays = self.outputs if outputs else self.silent
        out = np.empty((F.shape[0] - 1, arrays[0][0].shape[0]))
        laws = (self.ports.kinds, self.ports.parameters, state)
        F = np.ascontiguousarray(F, float)
        T, load_at = self.port_arrays[:2]
        p = -T.T @ z
        p[load_at] += F[0]
        y = self._reduced_rows @ eta
        y[2 * p.size:] += self._fixed[3] @ p
        failed = modal_port_kernel(self.modal_arrays, arrays, self.port_arrays, laws, F, eta,
                                   y, z, out, PORT_TOL, PORT_MAX_ITER)
        if failed:
            raise FloatingPointError(f"port laws {', '.join(self.ports.names)}: Newton did "
                                     f"not converge at {failed} of {out.shape[0]} steps")
        return out


def _read_columns(W):
    """``(W[:, cols], cols)``: the columns of the output rows ``W`` that are not all zero
    (the kernel reads only those)."""
    cols = np.flatnonzero(np.any(W != 0, 0))
    return np.ascontiguousarray(W[:, cols]), cols
