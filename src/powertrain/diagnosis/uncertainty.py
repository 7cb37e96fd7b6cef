r"""Uncertainty of the fitted parameters (:func:`powertrain.diagnosis.fit.fit_candidate`).

Two covariances of the fitted coordinates :math:`x` (log space for scale-like parameters)
are formed at the optimum from the residuals :math:`r` [dB] and their Jacobian :math:`J`
(data rows, then the parameter priors' rows :math:`J_p`):

* Gauss–Newton, :math:`C_{GN} = \hat s^2 A^{+}`, :math:`A = J^TJ`, :math:`\hat s^2 =
  \mathrm{RSS}/(n - p)` (at least the measured scatter squared when priors enter);
  it takes the residuals as independent, which they are not when the model differs from
  the data's source a little: the difference is smooth along speed in every (channel,
  order) cell, so the residuals of a cell are correlated at all lags and pull the
  parameters together;
* cluster-robust (sandwich; Liang & Zeger 1986, Biometrika 73; Cameron & Miller 2015,
  "A practitioner's guide to cluster-robust inference", J. Human Resources 50),
  clusters the (channel, order) cells (level and phase residuals of a cell over all
  training speeds, and over all runs of a plan; the crank offset's prior row a cluster of
  its own):

  .. math:: C_{CR} = \frac{G}{G-1}\,A^{+}\Big(\sum_g J_g^T r_g\, r_g^T J_g\Big)A^{+}
            + \hat s^2 A^{+} J_p^T J_p A^{+},

  :math:`G` the number of clusters, :math:`J_g, r_g` a cluster's rows (the prior rows, pseudo
  data of known scatter, enter with their model variance). It measures the scatter of the
  pull each cell exerts on the parameters: cells that disagree on the frequency of a mode
  (one pulls it up, another down) widen it, whatever the size of the residuals.

The reported 1σ is the larger of the two per parameter, and for the parameters an effect
names in ``Effect.model_floor`` (a missing body mode's frequency and modal mass) a
model-discrepancy term is added in quadrature, the relative floor :data:`MODEL_FLOOR`
(a systematic standard uncertainty combined with the statistical one, JCGM 100:2008
§5.1.2): :math:`\sigma^2 = \max(\sigma_{GN}^2, \sigma_{CR}^2) + (\epsilon\,\theta)^2`
(:math:`\epsilon^2` in log coordinates). Neither covariance sees a difference between the
model and the data's source that every cell shares (a mode's resonance placed a little
higher by the model on all channels and orders alike): the data cannot measure it, so it is
a stated constant. The 95 % interval is
:math:`x \pm z\,\sigma_x` in fitted coordinates (:data:`Z_95`), mapped back (asymmetric for
log-scale parameters) and clipped to the parameter's bounds.
"""

from __future__ import annotations

import math

import numpy as np

from powertrain.effects import EFFECTS

#: Relative model-discrepancy floor of the parameters named in ``Effect.model_floor`` [1]
#: (chosen on a calibration set of draws kept apart from those the coverage is measured on:
#: docs/validation/diagnosis.md, issue 37).
MODEL_FLOOR = 0.025
#: Two-sided 95 % normal quantile [1].
Z_95 = 1.959964


def cluster_ids(valid, phase_on=None) -> np.ndarray:
    """Cluster of each residual of :meth:`Problem.vector <powertrain.diagnosis.fit.Problem.
    vector>` on the training speeds: the level points (``valid`` (n_r, n_ch, n_o), in the
    order of ``array[valid]``) and the phase points (``phase_on``, same shape) by their
    (channel, order) cell, then with phase the crank offset's prior row (a cluster of its
    own, -1 - its run; :meth:`JointProblem.clusters <powertrain.diagnosis.plan.JointProblem.
    clusters>` numbers runs)."""
    n_o = valid.shape[2]
    cells = [np.nonzero(valid)[1] * n_o + np.nonzero(valid)[2]]
    if phase_on is not None:
        _, c, q = np.nonzero(phase_on)
        cells += [c * n_o + q, np.array([-1])]
    return np.concatenate(cells).astype(int)


def parameter_sd(J, r, n_data, clusters, s2) -> np.ndarray:
    """1σ of the fitted coordinates: the larger of the Gauss–Newton and the cluster-robust
    value (module docstring).

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
    """``sd`` (fitted coordinates) with the relative model-discrepancy floor (:data:`
    MODEL_FLOOR` unless ``floor``) added in quadrature for the parameters of ``pack`` that
    their effect names in ``Effect.model_floor``."""
    eps = MODEL_FLOOR if floor is None else floor
    out = np.array(sd, float)
    for j, (e, name) in enumerate(pack.names):
        if name in EFFECTS[e].model_floor:
            add = math.log1p(eps) if pack.log[j] else eps * abs(x[j])
            out[j] = math.hypot(out[j], add)
    return out


def intervals(pack, x, sd, z=Z_95) -> dict:
    """``{effect: {parameter: [lo, hi]}}`` (SI): :math:`x \\pm z\\sigma_x` in the fitted
    coordinates of ``pack`` (a :class:`~powertrain.diagnosis.packing.Packing`), mapped back
    and clipped to the bounds; ``[None, None]`` where σ is not finite."""
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
