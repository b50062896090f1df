"""Forward model: pressure P (kPa) needed for each bending angle psi (Eq. 12 = Eq. 13, x k_P)."""

from __future__ import annotations

import functools
import math
from dataclasses import replace
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.model.anchors import MODEL_ANCHORS
from pipeline.model.geometry import (
    ABSOLUTE_VACUUM_KPA,
    BAD_STRETCH,
    BELOW_VACUUM,
    INF_PSI,
    NAN_PSI,
    OK,
    REASONS,
    deformed_section,
)
from pipeline.model.materials import Material, load_materials, resolve_material
from pipeline.model.moments import pressure_area_mm3, stress_moment_nmm
from pipeline.model.options import PSI_LIMIT_DEG, ModelOptions, make_options

FloatArray = NDArray[np.float64]


def as_numbers(values: ArrayLike, what: str) -> FloatArray:
    """``values`` as a float array; text is refused (``"10"`` is not silently an angle).

    Raises
    ------
    pipeline.errors.UserInputError
        If any value is a string or not a number.

    Examples
    --------
    >>> as_numbers(["10"], "psi_deg")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pipeline.errors.UserInputError: psi_deg must be numbers, got the text '10'; pass numbers ...
    """
    arr = np.asarray(values)
    if arr.dtype.kind in "USO":
        for v in arr.ravel():
            if isinstance(v, (str, bytes)):
                raise UserInputError(
                    f"{what} must be numbers, got the text {str(v)!r}; pass numbers (not quoted)"
                )
        try:
            return arr.astype(float)
        except (TypeError, ValueError):
            raise UserInputError(f"{what} must be numbers, got {values!r}") from None
    return arr.astype(float, copy=False)


def l0_in_use(mat: Material, opts: ModelOptions) -> float:
    """The l0 (mm) of a model evaluation: the override or the material's."""
    if opts.l0_mm is None:
        return mat.l0_mm
    return mat.check_l0(float(opts.l0_mm))


@functools.lru_cache(maxsize=256)
def scale_fitted_to_anchors(
    ss50: Material, ss40: Material, opts: ModelOptions, l0_mm: float | None
) -> float:
    """Dimensionless Eq. 12 prefactor fitted to the paper's two model results (``fitted_scale``).

    Least squares on the log ratios with the prefactor dropped: the geometric mean of paper / ours
    over SS50 at psi = 0 (674 kPa) and SS40 at -psi0 (378 kPa), each at ``l0_mm`` (or its own l0
    when ``None``).  One number on two anchors: the fit is exact up to their ratio.
    """
    raw = replace(opts, l0_factor="none", eq12_scale=None, k_p=None, l0_mm=l0_mm)
    logs = []
    for anchor in MODEL_ANCHORS:
        mat = ss50 if anchor.material == "SS50" else ss40
        p, _ = pressure_core(mat, np.radians([anchor.at]), raw)
        logs.append(math.log(anchor.paper / float(p[0])))
    return math.exp(float(np.mean(logs)))


def resolve_scale(opts: ModelOptions, l0_mm: float) -> ModelOptions:
    """``opts`` with ``eq12_scale`` filled in when ``fitted_scale`` is asked without a number."""
    if opts.l0_factor != "fitted_scale" or opts.eq12_scale is not None:
        return opts
    table = load_materials()
    scale = scale_fitted_to_anchors(table["SS50"], table["SS40"], opts, l0_mm)
    return replace(opts, eq12_scale=scale)


def pressure_core(
    mat: Material, psi_rad: FloatArray, opts: ModelOptions
) -> tuple[FloatArray, FloatArray]:
    """Pressure (kPa) and reason code for a 1-D array of angles in radians.

    Validates only l0 against the section (cheap); options are validated by
    :func:`pipeline.model.make_options`.

    Returns
    -------
    p_kpa : ndarray
        NaN where undefined, with the reason: a stretch <= 0, no section, psi NaN or infinite,
        or a pressure below absolute vacuum (:data:`pipeline.model.geometry.ABSOLUTE_VACUUM_KPA`).
    reason : ndarray of int
        See :data:`pipeline.model.geometry.REASONS`.
    """
    l0 = l0_in_use(mat, opts)
    opts = resolve_scale(opts, l0)
    k_p = mat.k_p if opts.k_p is None else float(opts.k_p)
    with np.errstate(all="ignore"):
        sec = deformed_section(mat, psi_rad, l0, opts)
        moment, reason = stress_moment_nmm(mat, psi_rad, sec, l0, opts)
        area = pressure_area_mm3(mat, sec, opts)
        p = k_p * 1000.0 * moment / area  # MPa -> kPa
    reason = np.where((reason == OK) & ~np.isfinite(p), BAD_STRETCH, reason)
    reason = np.where((reason == OK) & (p < ABSOLUTE_VACUUM_KPA), BELOW_VACUUM, reason)
    reason = np.where(np.isnan(psi_rad), NAN_PSI, np.where(np.isinf(psi_rad), INF_PSI, reason))
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
        (see :func:`model_curve` for the reason), e.g. where holding the angle would need a
        pressure below absolute vacuum (psi well above psi0).

    Raises
    ------
    pipeline.errors.UserInputError
        For text angles, a bad option, or an l0 shorter than the section allows.

    Examples
    --------
    >>> from pipeline.model import pressure_kpa
    >>> bool(abs(pressure_kpa("SS50", 210.0)) < 1e-9)  # no pressure at rest, psi0 = 210 deg
    True
    """
    mat = resolve_material(material)
    opts = make_options(**options)
    psi = as_numbers(psi_deg, "psi_deg")
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
        Columns ``material``, ``psi_deg``, ``pressure_kpa``, ``reason`` (empty when defined),
        ``l0_mm`` (the l0 the curve used).
    """
    mat = resolve_material(material)
    opts = make_options(**options)
    if psi_deg is None:
        check_psi_min(mat, opts)
        psi = np.linspace(mat.psi0_deg, opts.psi_min_deg, opts.n_grid)
    else:
        psi = as_numbers(psi_deg, "psi_deg").ravel()
    p, reason = pressure_core(mat, np.radians(psi), opts)
    return pd.DataFrame(
        {
            "material": mat.name,
            "psi_deg": psi,
            "pressure_kpa": p,
            "reason": [REASONS[int(r)] for r in reason],
            "l0_mm": l0_in_use(mat, opts),
        }
    )


def check_psi_min(mat: Material, opts: ModelOptions) -> None:
    """Raise :class:`UserInputError` unless -360 <= ``opts.psi_min_deg`` < psi0 of ``mat``."""
    if not -PSI_LIMIT_DEG <= opts.psi_min_deg < mat.psi0_deg:
        raise UserInputError(
            f"model options: psi_min_deg = {opts.psi_min_deg:g} deg must lie in "
            f"[-{PSI_LIMIT_DEG:g}, psi0 = {mat.psi0_deg:g}) for {mat.name}: the inverse walks "
            "from psi0 down to it; pass e.g. -360 (the default) or -210"
        )


def psi_grid_rad(mat: Material, opts: ModelOptions) -> FloatArray:
    """Decreasing grid of ``opts.n_grid`` angles (rad) from psi0 to ``opts.psi_min_deg``.

    Raises
    ------
    pipeline.errors.UserInputError
        If ``psi_min_deg`` is not below the material's psi0.
    """
    check_psi_min(mat, opts)
    return np.linspace(mat.psi0_rad, math.radians(opts.psi_min_deg), opts.n_grid)
