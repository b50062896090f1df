"""Cross-section of the actuator: stretches and deformed section (paper Eqs. 1-7).

All lengths in mm, angles in radians.  Arrays broadcast as ``(n_psi, n_tau, n_phi)``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pipeline.model.materials import Material
from pipeline.model.options import ModelOptions

FloatArray = NDArray[np.float64]

#: gauge pressure of absolute vacuum (kPa): no pressure below it exists
ABSOLUTE_VACUUM_KPA = -101.325

#: reason codes attached to NaN results
OK, BAD_STRETCH, BAD_THICKNESS, NO_EQ5_ROOT, NAN_PSI, INF_PSI, BELOW_VACUUM = range(7)
REASONS: dict[int, str] = {
    OK: "",
    BAD_STRETCH: "a stretch ratio (Eqs. 1-3) would be <= 0",
    BAD_THICKNESS: "scaled wall thickness t (Eq. 4 with k_t) would be <= 0",
    NO_EQ5_ROOT: "Eq. 5 has no root phi_m for this wall thickness",
    NAN_PSI: "psi is NaN",
    INF_PSI: "psi is infinite",
    BELOW_VACUUM: "the pressure would be below absolute vacuum (-101.3 kPa gauge)",
}


@functools.lru_cache(maxsize=64)
def gauss_nodes(n: int, lo: float, hi: float) -> tuple[FloatArray, FloatArray]:
    """Gauss-Legendre nodes and weights on ``[lo, hi]``.

    Parameters
    ----------
    n : int
        Number of nodes.
    lo, hi : float
        Interval.

    Returns
    -------
    x, w : ndarray
        Read-only arrays of nodes and weights.
    """
    x, w = np.polynomial.legendre.leggauss(n)
    half = 0.5 * (hi - lo)
    xs, ws = lo + half * (x + 1.0), half * w
    xs.flags.writeable = False
    ws.flags.writeable = False
    return xs, ws


def axial_stretch_base(mat: Material, beta: FloatArray, psi: FloatArray, l0: float) -> FloatArray:
    """Eq. 1: axial stretch of the base at distance ``beta`` from the inextensible layer."""
    return (l0 - beta * psi) / (l0 - beta * mat.psi0_rad)


def rest_heights(mat: Material, tau: FloatArray, phi: FloatArray) -> FloatArray:
    """Height b + (a0 + tau) cos(phi) of a wall point above the inextensible layer, at rest."""
    return mat.b_mm + (mat.a0_mm + tau) * np.cos(phi)


def wall_thickness(
    mat: Material,
    psi: FloatArray,
    l0: float,
    opts: ModelOptions,
    sec: Section | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Eq. 4 plus the k_t scaling: deformed wall thickness t for each angle.

    Without ``sec`` the axial stretch inside Eq. 4 is taken on the undeformed section (first
    pass, as printed); with ``sec`` (``thickness_pass="recalculated"``) it is the stretch of
    Eq. 2 on that deformed section, lambda_2 still 1 as in Eq. 4.  ``thickness_phi`` chooses
    whether 1/lambda is averaged over phi or taken at the crown phi = 0.

    Parameters
    ----------
    mat : Material
    psi : ndarray, shape (n,)
        Bending angles (rad).
    l0 : float
        Length of the inextensible layer (mm).
    opts : ModelOptions
    sec : Section, optional
        Deformed section of a previous pass (one per angle).

    Returns
    -------
    t_mm : ndarray, shape (n,)
        Wall thickness (NaN where undefined).
    reason : ndarray of int, shape (n,)
    """
    tau, w_tau = gauss_nodes(opts.n_tau, 0.0, mat.t0_mm)
    if opts.thickness_phi == "crown":
        phi, w_phi = np.zeros(1), np.ones(1)
    else:
        phi, w_phi = gauss_nodes(opts.n_phi, 0.0, 0.5 * math.pi)
        w_phi = w_phi / (0.5 * math.pi)
    h0 = rest_heights(mat, tau[:, None], phi[None, :])  # (n_tau, n_phi)
    den = l0 - h0 * mat.psi0_rad
    height = h0[None] if sec is None else wall_coordinates(mat, sec, tau, phi, opts)[2]
    lam = (l0 - height * psi[:, None, None]) / den[None]
    bad = (lam <= 0).any(axis=(1, 2)) | (den <= 0).any()
    t = np.einsum("nij,i,j->n", 1.0 / lam, w_tau, w_phi)
    reason = np.where(bad, BAD_STRETCH, OK)
    if mat.k_t is not None and opts.kt_scaling != "none":
        frac = np.abs(psi - mat.psi0_rad) / mat.psi0_rad
        if opts.kt_scaling == "as_printed":
            t = t * mat.k_t * (1.0 - frac)
        else:
            t = t * (1.0 - mat.k_t * frac)
    reason = np.where((reason == OK) & ~(t > 0), BAD_THICKNESS, reason)
    return np.where(reason == OK, t, np.nan), reason


def _eq5_area_residual(
    mat: Material, phi_m: FloatArray, t: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """F(phi_m) = 2 phi_m t (a0/sin(phi_m) + t/2) - A0 and dF/dphi_m (arc-length reading of Eq. 5).

    F = 0 is Eq. 5 multiplied by 2 phi_m t; F is increasing and convex on (0, pi), so Newton's
    method started right of the root decreases monotonically to it.
    """
    s, c = np.sin(phi_m), np.cos(phi_m)
    r = mat.a0_mm / s + 0.5 * t
    f = 2.0 * phi_m * t * r - mat.area0_mm2
    df = 2.0 * t * r - 2.0 * phi_m * t * mat.a0_mm * c / (s * s)
    return f, df


def solve_phi_m(
    mat: Material, t: FloatArray, opts: ModelOptions, max_iter: int = 60
) -> tuple[FloatArray, FloatArray]:
    """Eq. 5: half angle phi_m of the deformed wall arc for each wall thickness ``t``.

    ``eq5="as_printed"`` solves sin(phi_m) = (A0/t - 2 a0)/t on the branch phi_m >= pi/2 (no root
    when the right side exceeds 1, which is the case for every t <= t0).  ``"arc_length"`` solves
    A0/(2 phi_m t) - t/2 = a0/sin(phi_m) by monotone Newton iteration (exactly pi/2 at rest); it
    has a root for 0 < t < A0/(2 a0).

    Returns
    -------
    phi_m : ndarray
        Radians, NaN where there is no root (or ``t`` is NaN).
    reason : ndarray of int
    """
    valid = np.isfinite(t)
    tt = np.where(valid, t, mat.t0_mm)
    if opts.eq5 == "as_printed":
        x = (mat.area0_mm2 / tt - 2.0 * mat.a0_mm) / tt
        ok = valid & (x > 0) & (x <= 1)
        phi_m = np.where(ok, math.pi - np.arcsin(np.clip(x, 0.0, 1.0)), np.nan)
        return phi_m, np.where(ok | ~valid, OK, NO_EQ5_ROOT)
    ok = valid & (tt > 0) & (2.0 * mat.a0_mm * tt < mat.area0_mm2)
    tt = np.where(ok, tt, mat.t0_mm)
    half = np.full_like(tt, 0.5 * math.pi)
    f_half, df_half = _eq5_area_residual(mat, half, tt)
    # start: the root of the second-order Taylor expansion of F about pi/2 (F'' = pi t a0), or
    # for thin walls the asymptote sin(phi_m) = a0 / (A0/(2 pi t) - t/2), whichever is smaller
    curv = math.pi * tt * mat.a0_mm
    disc = df_half**2 - 2.0 * curv * f_half
    theta = np.where(disc >= 0, (np.sqrt(np.maximum(disc, 0.0)) - df_half) / curv, 0.0)
    with np.errstate(all="ignore"):
        r_pi = mat.area0_mm2 / (2.0 * math.pi * tt) - 0.5 * tt
        thin = math.pi - np.arcsin(np.clip(mat.a0_mm / r_pi, 0.0, 1.0))
    x = np.clip(np.minimum(half + theta, np.where(r_pi > 0, thin, math.pi)), 1e-9, math.pi - 1e-12)
    # Newton on G = sin(phi_m) (A0/(2 phi_m t) - t/2) - a0 (Eq. 5 times sin phi_m): nearly linear
    # near pi, smooth at pi/2; converges in 3-4 steps from this start
    with np.errstate(all="ignore"):
        for _ in range(8):
            s_, c_ = np.sin(x), np.cos(x)
            r = mat.area0_mm2 / (2.0 * x * tt) - 0.5 * tt
            g = s_ * r - mat.a0_mm
            dg = c_ * r - s_ * mat.area0_mm2 / (2.0 * x * x * tt)
            x_new = np.clip(x - g / dg, 1e-9, math.pi - 1e-12)
            done = np.max(np.abs(x_new - x), initial=0.0, where=ok) < 1e-12
            x = x_new
            if done:
                break
    f, _ = _eq5_area_residual(mat, x, tt)
    slow = ok & ~(np.abs(f) <= 1e-9 * mat.area0_mm2)
    if slow.any():  # safeguard: monotone Newton on F from a point right of the root
        x[slow] = _solve_monotone(mat, tt[slow], f_half[slow], df_half[slow])
    phi_m = np.where(ok, x, np.nan)
    return phi_m, np.where(ok | ~valid, OK, NO_EQ5_ROOT)


def _solve_monotone(
    mat: Material, tt: FloatArray, f_half: FloatArray, df_half: FloatArray, max_iter: int = 100
) -> FloatArray:
    """Newton on the increasing convex F from a start right of the root (always converges)."""
    half = np.full_like(tt, 0.5 * math.pi)
    theta_up = np.arccos(np.clip(math.pi * tt * mat.a0_mm / mat.area0_mm2, 0.0, 1.0))
    x = np.where(f_half >= 0, half, np.minimum(half + theta_up, half - f_half / df_half))
    x = np.clip(x, 1e-12, math.pi - 1e-12)
    for _ in range(max_iter):
        f, df = _eq5_area_residual(mat, x, tt)
        x_new = np.clip(x - f / df, 1e-12, math.pi - 1e-12)
        done = np.max(np.abs(x_new - x), initial=0.0) < 1e-13
        x = x_new
        if done:
            break
    return x


@dataclass(frozen=True)
class Section:
    """Deformed cross-section for each angle (Eqs. 4-7); arrays of shape (n,), lengths in mm.

    Attributes
    ----------
    t : ndarray
        Wall thickness.
    phi_m : ndarray
        Half angle of the wall arc (rad).
    a : ndarray
        Inner radius (Eq. 6).
    q : ndarray
        Offset of the arc centre from the top of the base (Eq. 7).
    reason : ndarray of int
        Reason code (see :data:`REASONS`), 0 where the section is defined.
    """

    t: FloatArray
    phi_m: FloatArray
    a: FloatArray
    q: FloatArray
    reason: FloatArray


def _section_from_thickness(
    mat: Material, t: FloatArray, reason_t: FloatArray, opts: ModelOptions
) -> Section:
    """Eqs. 5-7 for given wall thicknesses (and the reason codes of the thickness step)."""
    phi_m, reason_p = solve_phi_m(mat, t, opts)
    reason = np.where(reason_t != OK, reason_t, reason_p)
    a = mat.area0_mm2 / (2.0 * t * phi_m) - 0.5 * t
    reason = np.where((reason == OK) & ~(a > 0), NO_EQ5_ROOT, reason)
    q = -a * np.cos(phi_m)
    return Section(t=t, phi_m=phi_m, a=a, q=q, reason=reason)


def deformed_section(mat: Material, psi: FloatArray, l0: float, opts: ModelOptions) -> Section:
    """Deformed cross-section for bending angles ``psi`` (rad): Eqs. 4-7.

    ``opts.thickness_pass="recalculated"`` repeats Eq. 4 once on the first deformed section
    (more passes change P by < 0.2 %; feeding lambda_2 back as well diverges, docs/model.md).
    """
    t, reason_t = wall_thickness(mat, psi, l0, opts)
    sec = _section_from_thickness(mat, t, reason_t, opts)
    if opts.thickness_pass == "recalculated":
        t, reason_t = wall_thickness(mat, psi, l0, opts, sec)
        reason_t = np.where(sec.reason != OK, sec.reason, reason_t)
        sec = _section_from_thickness(mat, t, reason_t, opts)
    return sec


def wall_coordinates(
    mat: Material, sec: Section, tau: FloatArray, phi: FloatArray, opts: ModelOptions
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Deformed radius a + tau', angle phi' and height of wall points (tau, phi) of the rest shape.

    ``opts.wall_coords="scaled"``: tau' = tau t/t0, phi' = phi 2 phi_m/pi (the text's
    definitions); ``"unscaled"``: tau' = tau, phi' = phi (diagnostic only).

    Parameters
    ----------
    mat : Material
    sec : Section
        One deformed section per angle, shape (n,).
    tau, phi : ndarray
        Undeformed wall coordinates (mm, rad), 1-D.
    opts : ModelOptions

    Returns
    -------
    r_def, phi_def, height : ndarray, broadcastable to shape (n, n_tau, n_phi)
        a + tau', phi' and the height b + q + (a + tau') cos(phi') above the inextensible layer.
    """
    a = sec.a[:, None, None]
    tt = tau[None, :, None]
    pp = phi[None, None, :]
    if opts.wall_coords == "unscaled":
        r_def = a + tt
        phi_def = pp
    else:
        r_def = a + tt * (sec.t[:, None, None] / mat.t0_mm)
        phi_def = pp * (2.0 * sec.phi_m[:, None, None] / math.pi)
    height = mat.b_mm + sec.q[:, None, None] + r_def * np.cos(phi_def)
    return r_def, phi_def, height
