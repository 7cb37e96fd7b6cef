r"""Uncertainty of the fitted parameters (:func:`powertrain.diagnosis.fit.fit_candidate`).

From the residuals :math:`r` [dB] and Jacobian :math:`J` at the optimum (fitted coordinates,
data rows then the priors' rows :math:`J_p`), :math:`A = J^TJ`:

* Gauss–Newton, :math:`C_{GN} = \hat s^2 A^{+}`, :math:`\hat s^2 = \mathrm{RSS}/(n - p)`
  (residuals taken as independent);
* cluster-robust (sandwich; Liang & Zeger 1986, Biometrika 73; Cameron & Miller 2015,
  J. Human Resources 50), clusters the (channel, order) cells, whose residuals are
  correlated along speed when the model differs smoothly from the data:

  .. math:: C_{CR} = \frac{G}{G-1}\,A^{+}\Big(\sum_g J_g^T r_g\, r_g^T J_g\Big)A^{+}
            + \hat s^2 A^{+} J_p^T J_p A^{+}.

The 1σ is the larger of the two; for the parameters in ``Effect.model_floor`` the relative
model-discrepancy floor :data:`MODEL_FLOOR` is added in quadrature (JCGM 100:2008 §5.1.2),
:math:`\sigma^2 = \max(\sigma_{GN}^2, \sigma_{CR}^2) + (\epsilon\,\theta)^2`. The 95 % interval
is :math:`x \pm z\,\sigma_x` (:data:`Z_95`) mapped back and clipped to the bounds.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.effects import EFFECTS

#: Relative model-discrepancy floor of the parameters in ``Effect.model_floor`` [1]
#: (calibrated on draws kept apart from the coverage's: docs/validation/diagnosis.md).
MODEL_FLOOR = 0.025
#: Two-sided 95 % normal quantile [1].
Z_95 = 1.959964


def cluster_ids(valid, phase_on=None) -> np.ndarray:
    """Cluster of each training residual: the level points ``valid`` (n_r, n_ch, n_o) and
    phase points ``phase_on`` by (channel, order) cell, then the offset prior's row (-1)."""
    n_o = valid.shape[2]
    cells = [np.nonzero(valid)[1] * n_o + np.nonzero(valid)[2]]
    if phase_on is not None:
        _, c, q = np.nonzero(phase_on)
        cells += [c * n_o + q, np.array([-1])]
    return np.concatenate(cells).astype(int)


def parameter_sd(J, r, n_data, clusters, s2) -> np.ndarray:
    """1σ of the fitted coordinates: the larger of the Gauss–Newton and cluster-robust values.

    Parameters
    ----------
    J : ndarray (n_data + n_prior, p)
        Jacobian of the residuals at the optimum [dB per fitted unit].
    r : ndarray (n_data + n_prior,)
        Residuals [dB]; the prior rows last.
    n_data : int
        Number of data rows (level, phase and the crank offset's prior).
    clusters : ndarray (n_data,) of int or None
        Cluster of each data row (:func:`cluster_ids`); None: Gauss–Newton only.
    s2 : float
        :math:`\\hat s^2` [dB²].

    Returns
    -------
    ndarray (p,)
        1σ in fitted coordinates (NaN where the covariance cannot be formed).
    """
    p = J.shape[1]
    try:
        a_inv = np.linalg.pinv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.full(p, np.nan)
    var = s2 * np.diag(a_inv)
    if clusters is not None and clusters.size == n_data:
        ids, inv = np.unique(clusters, return_inverse=True)
        score = np.zeros((ids.size, p))
        np.add.at(score, inv, J[:n_data] * r[:n_data, None])
        g = ids.size
        meat = score.T @ score * (g / (g - 1) if g > 1 else 1.0)
        jp = J[n_data:]
        meat = meat + s2 * (jp.T @ jp)
        var = np.maximum(var, np.diag(a_inv @ meat @ a_inv))
    return np.sqrt(np.clip(var, 0, None))


def with_model_floor(pack, x, sd, floor=None) -> np.ndarray:
    """``sd`` at ``x`` (``pack``'s coordinates) with the relative floor (:data:`MODEL_FLOOR`
    unless ``floor``) added in quadrature for the parameters in ``Effect.model_floor``."""
    eps = MODEL_FLOOR if floor is None else floor
    out = np.array(sd, float)
    for j, (e, name) in enumerate(pack.names):
        if name in EFFECTS[e].model_floor:
            add = math.log1p(eps) if pack.log[j] else eps * abs(x[j])
            out[j] = math.hypot(out[j], add)
    return out


def intervals(pack, x, sd, z=Z_95) -> dict:
    """``{effect: {parameter: [lo, hi]}}`` (SI): ``x ± z sd`` in ``pack``'s coordinates,
    mapped back and clipped to the bounds; ``[None, None]`` where ``sd`` is not finite."""
    out = {}
    lo = np.clip(x - z * sd, pack.lower, pack.upper)
    hi = np.clip(x + z * sd, pack.lower, pack.upper)
    for j, (e, name) in enumerate(pack.names):
        if not np.isfinite(sd[j]):
            out.setdefault(e, {})[name] = [None, None]
            continue
        ends = np.exp([lo[j], hi[j]]) if pack.log[j] else np.array([lo[j], hi[j]])
        out.setdefault(e, {})[name] = [float(ends[0]), float(ends[1])]
    return out
