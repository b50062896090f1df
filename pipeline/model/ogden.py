"""Ogden hyperelastic stress (paper Eqs. 8-11) with sigma_3 = 0."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]


def axial_stress_mpa(
    lam1: FloatArray, lam2: FloatArray, mu_mpa: Sequence[float], alpha: Sequence[float]
) -> FloatArray:
    """Axial Cauchy stress sigma_1 of Eqs. 9 and 11 (radial stress sigma_3 = 0).

    sigma_1 = sum_p mu_p (lambda_1^alpha_p - (lambda_1 lambda_2)^-alpha_p), where the second term
    is the Lagrange multiplier p of Eq. 11 and lambda_3 = 1/(lambda_1 lambda_2) (incompressible).

    Parameters
    ----------
    lam1, lam2 : ndarray
        Axial and circumferential stretch ratios (> 0), broadcastable.
    mu_mpa, alpha : sequence of float
        Ogden coefficients (MPa) and exponents of Eq. 8, one per term; terms are evaluated
        separately (no merging here).

    Returns
    -------
    ndarray
        Axial stress in MPa.

    Examples
    --------
    >>> import numpy as np
    >>> float(axial_stress_mpa(np.array(1.0), np.array(1.0), [0.24], [2.0]))
    0.0
    """
    if all(a == 2.0 for a in alpha):  # neo-Hookean: avoid exp/log
        lam3 = 1.0 / (lam1 * lam2)
        return float(sum(mu_mpa)) * (lam1 * lam1 - lam3 * lam3)
    log1 = np.log(lam1)
    log3 = -(log1 + np.log(lam2))
    out = np.zeros(np.broadcast_shapes(np.shape(lam1), np.shape(lam2)))
    for mu, a in zip(mu_mpa, alpha, strict=True):
        out = out + mu * (np.exp(a * log1) - np.exp(a * log3))
    return out


def strain_energy_mpa(
    lam1: FloatArray, lam2: FloatArray, mu_mpa: Sequence[float], alpha: Sequence[float]
) -> FloatArray:
    """Ogden strain-energy density W of Eq. 8 (MPa), lambda_3 = 1/(lambda_1 lambda_2)."""
    lam3 = 1.0 / (lam1 * lam2)
    out = np.zeros(np.broadcast_shapes(np.shape(lam1), np.shape(lam2)))
    for mu, a in zip(mu_mpa, alpha, strict=True):
        out = out + mu / a * (lam1**a + lam2**a + lam3**a - 3.0)
    return out
