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
(:mod:`powertrain.physics.mount_elements`); the Newmark kernel
(:func:`powertrain.kernels.newmark.newmark_port_kernel`) does not change.
"""

from numba import njit

#: No force (a linear element has no port law; kept so that code 0 is harmless).
NONE = 0
#: Jenkins element: spring ``k = par[0]`` in series with a Coulomb slider of slip force
#: ``F_s = par[1]``; state ``z = state[0]``, the slider's position.
JENKINS = 1


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


@njit(cache=True, nogil=True)
def port_force_loop(kinds, par, state, U, V, F):
    """Forces ``F`` (n_t, m) of the port laws along prescribed motions ``U``, ``V``
    (n_t, m), committing the state after every point (a displacement-driven test)."""
    for t in range(U.shape[0]):
        for e in range(kinds.shape[0]):
            F[t, e] = port_force(kinds[e], U[t, e], V[t, e], par[e], state[e])[0]
            commit_state(kinds[e], U[t, e], V[t, e], par[e], state[e])
