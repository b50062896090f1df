"""Inverse model psi(P) along the loading and unloading branches, and snap-through regions.

P(psi) may be non-monotonic.  Loading (pressure rising) starts at psi0 and walks down in psi:
the angle reached at pressure P is the *first* crossing P(psi) = P going down from psi0, i.e. the
pressure needed to reach an angle is the running maximum of P.  Unloading walks up from the most
negative angle of the reachable range (``psi_min_deg``): the first crossing going up, i.e. the
running minimum.  Where the running extremum is flat the actuator snaps; :func:`snap_regions`
lists those jumps.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.model.forward import pressure_core, psi_grid_rad
from pipeline.model.materials import Material, resolve_material
from pipeline.model.options import ModelOptions, make_options

FloatArray = NDArray[np.float64]
BRANCHES = ("loading", "unloading")


def _reachable_grid(mat: Material, opts: ModelOptions) -> tuple[FloatArray, FloatArray]:
    """Grid angles (rad, decreasing from psi0) and pressures, cut at the first undefined angle."""
    grid = psi_grid_rad(mat, opts)
    p, _ = pressure_core(mat, grid, opts)
    bad = ~np.isfinite(p)
    n = int(np.argmax(bad)) if bad.any() else len(p)
    return grid[:n], p[:n]


def _illinois(
    mat: Material,
    opts: ModelOptions,
    target: FloatArray,
    a: FloatArray,
    fa: FloatArray,
    b: FloatArray,
    fb: FloatArray,
    tol_kpa: float = 1e-9,
    max_iter: int = 60,
) -> FloatArray:
    """Vectorised Illinois (modified regula falsi) for P(psi) = target on brackets [a, b].

    ``fa`` and ``fb`` are P - target at the ends, of opposite sign (or zero).
    """
    a, fa, b, fb = a.copy(), fa.copy(), b.copy(), fb.copy()
    x = np.where(np.abs(fa) <= np.abs(fb), a, b)
    active = (np.abs(fa) > tol_kpa) & (np.abs(fb) > tol_kpa)
    for _ in range(max_iter):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        ai, bi, fai, fbi = a[idx], b[idx], fa[idx], fb[idx]
        xi = (ai * fbi - bi * fai) / (fbi - fai)
        fx, _ = pressure_core(mat, xi, opts)
        fx = fx - target[idx]
        same = np.sign(fx) == np.sign(fbi)
        # Illinois: keep the old end and halve its residual when the new point lands on b's side
        new_a = np.where(same, ai, bi)
        new_fa = np.where(same, 0.5 * fai, fbi)
        a[idx], fa[idx], b[idx], fb[idx] = new_a, new_fa, xi, fx
        x[idx] = xi
        done = (np.abs(fx) <= tol_kpa) | (np.abs(bi - ai) <= 1e-15) | ~np.isfinite(fx)
        active[idx[done]] = False
    return x


def psi_rad_core(mat: Material, p_kpa: FloatArray, opts: ModelOptions, branch: str) -> FloatArray:
    """Bending angle (rad) reached at each pressure on ``branch``; NaN outside the modelled range."""
    grid, p = _reachable_grid(mat, opts)
    out = np.full(p_kpa.shape, np.nan)
    if grid.size < 2:
        return out
    target = p_kpa
    finite = np.isfinite(target) & (target >= 0)
    if branch == "loading":
        x, f = grid, p
        env = np.maximum.accumulate(f)
        i = np.searchsorted(env, np.where(finite, target, np.inf), side="left")
    else:
        x, f = grid[::-1], p[::-1]
        env = np.minimum.accumulate(f)
        i = np.searchsorted(-env, np.where(finite, -target, np.inf), side="left")
    inside = finite & (i < len(x))
    at_start = inside & (i == 0)
    out[at_start] = x[0] if branch == "loading" else np.nan
    if branch == "unloading":  # exactly the pressure at the most negative angle
        out[at_start & (target == f[0])] = x[0]
    sel = np.flatnonzero(inside & (i > 0))
    if sel.size:
        j = i[sel]
        tgt = target[sel]
        out[sel] = _illinois(mat, opts, tgt, x[j - 1], f[j - 1] - tgt, x[j], f[j] - tgt)
    return out


def psi_deg(
    material: str | Material, pressure_kpa: ArrayLike, branch: str = "loading", **options: Any
) -> FloatArray:
    """Bending angle reached at each input pressure: the inverse of :func:`pressure_kpa`.

    Parameters
    ----------
    material : str or Material
        ``"DS20"``, ``"DS30"``, ``"SS40"``, ``"SS50"`` or a :class:`Material`.
    pressure_kpa : array_like
        Input pressures (kPa), any shape.
    branch : {"loading", "unloading"}
        ``"loading"``: rising pressure from psi0 (first crossing going down from psi0, so the
        angle jumps across snap-through regions).  ``"unloading"``: falling pressure from the most
        negative modelled angle ``psi_min_deg``.
    **options
        See :class:`pipeline.model.options.ModelOptions`.

    Returns
    -------
    ndarray
        Angles in degrees, same shape as ``pressure_kpa``; NaN for negative or non-finite
        pressures and beyond the modelled range (below ``psi_min_deg`` or past an undefined angle).

    Examples
    --------
    >>> from pipeline.model import psi_deg
    >>> float(psi_deg("SS50", 0.0))
    210.0
    """
    if branch not in BRANCHES:
        raise UserInputError(f"psi_deg: branch={branch!r} is not one of {BRANCHES}")
    mat = resolve_material(material)
    opts = make_options(**options)
    p = np.asarray(pressure_kpa, dtype=float)
    out = psi_rad_core(mat, p.ravel(), opts, branch)
    return np.degrees(out).reshape(p.shape)


def snap_regions(material: str | Material, **options: Any) -> pd.DataFrame:
    """Snap-through jumps of P(psi) on both branches, at the resolution of the inverse grid.

    Parameters
    ----------
    material : str or Material
    **options
        See :class:`pipeline.model.options.ModelOptions` (``n_grid`` sets the resolution).

    Returns
    -------
    pandas.DataFrame
        One row per jump: ``material``, ``branch``, ``pressure_kpa`` (pressure at which the
        actuator jumps), ``psi_from_deg`` (local extremum of P), ``psi_to_deg`` (where P regains
        that pressure, linear interpolation on the grid; NaN if never within the range).  Empty
        when P(psi) is monotonic.
    """
    mat = resolve_material(material)
    opts = make_options(**options)
    grid, p = _reachable_grid(mat, opts)
    rows: list[dict[str, Any]] = []
    for branch in BRANCHES:
        x, f = (grid, p) if branch == "loading" else (grid[::-1], -p[::-1])
        k = 1
        while k < len(f):
            if f[k] < f[k - 1]:  # local extremum at k-1 (max of P on loading, min on unloading)
                peak = f[k - 1]
                later = np.flatnonzero(f[k:] >= peak)
                if later.size:
                    j = k + int(later[0])
                    w = (peak - f[j - 1]) / (f[j] - f[j - 1])
                    to = x[j - 1] + w * (x[j] - x[j - 1])
                else:
                    j, to = len(f), math.nan
                rows.append(
                    {
                        "material": mat.name,
                        "branch": branch,
                        "pressure_kpa": peak if branch == "loading" else -peak,
                        "psi_from_deg": math.degrees(x[k - 1]),
                        "psi_to_deg": math.degrees(to),
                    }
                )
                k = j + 1
            else:
                k += 1
    return pd.DataFrame(rows, columns=["material", "branch", "pressure_kpa", "psi_from_deg", "psi_to_deg"])
