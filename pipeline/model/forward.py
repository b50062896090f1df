"""Forward model: pressure P (kPa) needed for each bending angle psi (Eq. 12 = Eq. 13, x k_P)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.model.geometry import OK, REASONS, deformed_section
from pipeline.model.materials import Material, resolve_material
from pipeline.model.moments import pressure_area_mm3, stress_moment_nmm
from pipeline.model.options import ModelOptions, make_options

FloatArray = NDArray[np.float64]


def pressure_core(
    mat: Material, psi_rad: FloatArray, opts: ModelOptions
) -> tuple[FloatArray, FloatArray]:
    """Pressure (kPa) and reason code for a 1-D array of angles in radians (no validation).

    Returns
    -------
    p_kpa : ndarray
        NaN where undefined.
    reason : ndarray of int
        See :data:`pipeline.model.geometry.REASONS`.
    """
    l0 = mat.l0_mm if opts.l0_mm is None else float(opts.l0_mm)
    k_p = mat.k_p if opts.k_p is None else float(opts.k_p)
    with np.errstate(all="ignore"):
        sec = deformed_section(mat, psi_rad, l0, opts)
        moment, reason = stress_moment_nmm(mat, psi_rad, sec, l0, opts)
        area = pressure_area_mm3(mat, sec, opts)
        p = k_p * 1000.0 * moment / area  # MPa -> kPa
    reason = np.where((reason == OK) & ~np.isfinite(p), 1, reason)
    return np.where(reason == OK, p, np.nan), reason


def pressure_kpa(material: str | Material, psi_deg: ArrayLike, **options: Any) -> FloatArray:
    """Input pressure needed to hold each bending angle: the paper's model, Eqs. 1-13 times k_P.

    Parameters
    ----------
    material : str or Material
        ``"DS20"``, ``"DS30"``, ``"SS40"``, ``"SS50"`` or a :class:`Material` (e.g. from your own
        YAML via :func:`load_materials`).
    psi_deg : array_like
        Bending angles in degrees (psi0 = 210 at rest, 0 straight, negative curled back);
        any shape, typically -360..210.
    **options
        Readings and numerics, see :class:`pipeline.model.options.ModelOptions`.

    Returns
    -------
    ndarray
        Pressure in kPa, same shape as ``psi_deg``; NaN where the model is undefined
        (see :func:`model_curve` for the reason).

    Examples
    --------
    >>> from pipeline.model import pressure_kpa
    >>> bool(abs(pressure_kpa("SS50", 210.0)) < 1e-9)  # no pressure at rest, psi0 = 210 deg
    True
    """
    mat = resolve_material(material)
    opts = make_options(**options)
    psi = np.asarray(psi_deg, dtype=float)
    p, _ = pressure_core(mat, np.radians(psi.ravel()), opts)
    return p.reshape(psi.shape)


def model_curve(
    material: str | Material, psi_deg: ArrayLike | None = None, **options: Any
) -> pd.DataFrame:
    """P(psi) table with the reason for every NaN.

    Parameters
    ----------
    material : str or Material
    psi_deg : array_like, optional
        Angles (deg); 400 angles from psi0 down to ``psi_min_deg`` when omitted.
    **options
        See :class:`pipeline.model.options.ModelOptions`.

    Returns
    -------
    pandas.DataFrame
        Columns ``material``, ``psi_deg``, ``pressure_kpa``, ``reason`` (empty when defined).
    """
    mat = resolve_material(material)
    opts = make_options(**options)
    if psi_deg is None:
        psi = np.linspace(mat.psi0_deg, opts.psi_min_deg, opts.n_grid)
    else:
        psi = np.asarray(psi_deg, dtype=float).ravel()
    p, reason = pressure_core(mat, np.radians(psi), opts)
    return pd.DataFrame(
        {
            "material": mat.name,
            "psi_deg": psi,
            "pressure_kpa": p,
            "reason": [REASONS[int(r)] for r in reason],
        }
    )


def psi_grid_rad(mat: Material, opts: ModelOptions) -> FloatArray:
    """Decreasing grid of ``opts.n_grid`` angles (rad) from psi0 to ``opts.psi_min_deg``."""
    return np.linspace(mat.psi0_rad, math.radians(opts.psi_min_deg), opts.n_grid)
