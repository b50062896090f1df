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
from collections.abc import Callable
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.model.forward import as_numbers, pressure_core, psi_grid_rad
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


def _bracketed_root(
    mat: Material,
    opts: ModelOptions,
    target: FloatArray,
    a: FloatArray,
    fa: FloatArray,
    b: FloatArray,
    fb: FloatArray,
    c: FloatArray,
    fc: FloatArray,
    x0: FloatArray | None = None,
    tol_kpa: float = 1e-7,
    max_iter: int = 60,
) -> FloatArray:
    """Vectorised bracketed root of P(psi) = target (inverse quadratic interpolation + Illinois).

    ``[a, b]`` brackets the root (``fa = P(a) - target`` and ``fb`` of opposite sign or zero);
    ``(c, fc)`` is a third grid point; ``x0`` an optional first guess inside the bracket.
    Each iteration tries inverse quadratic interpolation through (a, b, c) and falls back to an
    Illinois (modified regula falsi) step when that leaves the bracket, so the root stays in [a, b].
    """
    a, fa, b, fb, c, fc = (v.astype(float, copy=True) for v in (a, fa, b, fb, c, fc))
    wa = np.ones_like(a)  # Illinois weight of fa in the fallback secant
    x = np.where(np.abs(fa) <= np.abs(fb), a, b)
    active = (np.abs(fa) > tol_kpa) & (np.abs(fb) > tol_kpa)
    with np.errstate(all="ignore"):
        for it in range(max_iter):
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            ai, bi, ci, fai, fbi, fci = a[idx], b[idx], c[idx], fa[idx], fb[idx], fc[idx]
            iqi = (
                ai * fbi * fci / ((fai - fbi) * (fai - fci))
                + bi * fai * fci / ((fbi - fai) * (fbi - fci))
                + ci * fai * fbi / ((fci - fai) * (fci - fbi))
            )
            lo, hi = np.minimum(ai, bi), np.maximum(ai, bi)
            fw = wa[idx] * fai
            secant = (ai * fbi - bi * fw) / (fbi - fw)
            use_iqi = np.isfinite(iqi) & (iqi > lo) & (iqi < hi)
            xi = np.where(use_iqi, iqi, secant)
            if it == 0 and x0 is not None:
                x0i = x0[idx]
                xi = np.where((x0i > lo) & (x0i < hi), x0i, xi)
            fx, _ = pressure_core(mat, xi, opts)
            fx = fx - target[idx]
            same = np.sign(fx) == np.sign(fbi)
            # the new point replaces b; a stays if x fell on b's side (Illinois: halve its weight)
            a[idx] = np.where(same, ai, bi)
            fa[idx] = np.where(same, fai, fbi)
            wa[idx] = np.where(same, 0.5 * wa[idx], 1.0)
            c[idx], fc[idx] = np.where(same, bi, ai), np.where(same, fbi, fai)
            b[idx], fb[idx] = xi, fx
            x[idx] = xi
            done = (np.abs(fx) <= tol_kpa) | (np.abs(bi - ai) <= 1e-15) | ~np.isfinite(fx)
            active[idx[done]] = False
    return x


def _hermite_guess(
    x: FloatArray, f: FloatArray, j: NDArray[np.intp], target: FloatArray
) -> FloatArray:
    """Root of the cubic Hermite interpolant of the grid P(psi) on [x[j-1], x[j]] (first guess)."""
    slope = np.gradient(f, x)
    h = x[j] - x[j - 1]
    f0, f1 = f[j - 1], f[j]
    m0, m1 = slope[j - 1] * h, slope[j] * h
    with np.errstate(all="ignore"):
        s = np.clip((target - f0) / (f1 - f0), 0.0, 1.0)
        for _ in range(4):  # Newton on the cubic in s (no model evaluations)
            s2, s3 = s * s, s * s * s
            p = (
                (2 * s3 - 3 * s2 + 1) * f0
                + (s3 - 2 * s2 + s) * m0
                + (-2 * s3 + 3 * s2) * f1
                + (s3 - s2) * m1
            )
            dp = (
                (6 * s2 - 6 * s) * f0
                + (3 * s2 - 4 * s + 1) * m0
                + (-6 * s2 + 6 * s) * f1
                + (3 * s2 - 2 * s) * m1
            )
            s = np.clip(s - (p - target) / dp, 0.0, 1.0)
    return x[j - 1] + np.where(np.isfinite(s), s, 0.5) * h


def _branch_table(
    mat: Material, opts: ModelOptions, branch: str
) -> tuple[FloatArray, FloatArray, FloatArray, float | None]:
    """Grid angles x and pressures f in the order the branch walks them, and its envelope.

    Returns ``x, f, env, peak`` where ``env`` is the running max (loading) or min (unloading)
    of ``f`` and ``peak`` the highest pressure the branch accepts (``None``: no limit).
    """
    grid, p = _reachable_grid(mat, opts)
    if branch == "loading":
        return grid, p, np.maximum.accumulate(p), None
    x, f, peak = grid[::-1], p[::-1], None
    if opts.unload_from_kpa is not None and grid.size >= 2:  # from the loading state at the peak
        peak = float(opts.unload_from_kpa)
        start = psi_rad_core(mat, np.array([peak]), opts, "loading")[0]
        if not np.isfinite(start):
            return grid[:0], p[:0], p[:0], peak
        keep = grid > start
        x = np.concatenate([[start], grid[keep][::-1]])
        f = np.concatenate([[peak], p[keep][::-1]])
    return x, f, np.minimum.accumulate(f), peak


def _locate(
    x: FloatArray,
    f: FloatArray,
    env: FloatArray,
    peak: float | None,
    target: FloatArray,
    branch: str,
) -> tuple[FloatArray, NDArray[np.intp], NDArray[np.intp]]:
    """Grid bracket of the first crossing of every target on the branch.

    Returns ``out`` (angles already known: the start point; NaN elsewhere), ``sel`` (indices of
    targets still to solve) and ``j`` (their brackets are ``[x[j-1], x[j]]``).
    """
    out = np.full(target.shape, np.nan)
    if x.size < 2:
        return out, np.zeros(0, np.intp), np.zeros(0, np.intp)
    finite = np.isfinite(target) & (target >= 0)
    if peak is not None:
        finite &= target <= peak
    if branch == "loading":
        i = np.searchsorted(env, np.where(finite, target, np.inf), side="left")
    else:
        i = np.searchsorted(-env, np.where(finite, -target, np.inf), side="left")
    inside = finite & (i < len(x))
    at_start = inside & (i == 0)
    if branch == "loading":
        out[at_start] = x[0]
    else:  # exactly the pressure at the start of the unloading walk
        out[at_start & (target == f[0])] = x[0]
    sel = np.flatnonzero(inside & (i > 0))
    return out, sel, i[sel]


def psi_rad_core(mat: Material, p_kpa: FloatArray, opts: ModelOptions, branch: str) -> FloatArray:
    """Angle (rad) reached at each pressure on ``branch``; NaN outside the modelled range."""
    x, f, env, peak = _branch_table(mat, opts, branch)
    out, sel, j = _locate(x, f, env, peak, p_kpa, branch)
    if sel.size:
        tgt = p_kpa[sel]
        k = np.where(j + 1 < len(x), j + 1, j - 2)  # third point for the first quadratic step
        k = np.clip(k, 0, len(x) - 1)
        guess = _hermite_guess(x, f, j, tgt)
        out[sel] = _bracketed_root(
            mat, opts, tgt, x[j - 1], f[j - 1] - tgt, x[j], f[j] - tgt, x[k], f[k] - tgt, guess
        )
    return out


def grid_inverse(
    mat: Material, opts: ModelOptions, branch: str
) -> Callable[[FloatArray], FloatArray]:
    """Cheap approximate inverse: cubic Hermite interpolation of the grid, no model evaluations.

    Used inside fitting loops (:func:`pipeline.model.fit_k_p`), where P = k_P P_1(psi) shares one
    grid for every k_P.  Accuracy is that of the first guess of :func:`psi_rad_core` (about
    1e-3 kPa, i.e. well under 0.01 deg on the default grid).

    Returns
    -------
    callable
        ``p_kpa -> psi_rad`` with the same NaN rules as :func:`psi_rad_core`.
    """
    x, f, env, peak = _branch_table(mat, opts, branch)

    def inverse(p_kpa: FloatArray) -> FloatArray:
        out, sel, j = _locate(x, f, env, peak, p_kpa, branch)
        if sel.size:
            out[sel] = _hermite_guess(x, f, j, p_kpa[sel])
        return out

    return inverse


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
        negative modelled angle ``psi_min_deg``, or from the loading state at the peak pressure
        ``unload_from_kpa=`` when given.
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
    >>> round(float(psi_deg("SS50", 0.0)), 9)
    210.0
    """
    if branch not in BRANCHES:
        raise UserInputError(f"psi_deg: branch={branch!r} is not one of {BRANCHES}")
    mat = resolve_material(material)
    opts = make_options(**options)
    p = as_numbers(pressure_kpa, "pressure_kpa")
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
    return pd.DataFrame(
        rows, columns=["material", "branch", "pressure_kpa", "psi_from_deg", "psi_to_deg"]
    )
