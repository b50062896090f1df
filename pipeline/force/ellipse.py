"""Fit an ellipse to the centre-line points of the marked line and report its eccentricity.

When both ends of the actuator are held (blocked-force test, paper Section III.B) the
inextensible layer forms an ellipse; the paper reports its eccentricity
``e = sqrt(1 - b**2 / a**2)`` (a >= b the semi-axes) at the maximum pressure (Fig. 7B).

How the fit works
-----------------
1. **Direct fit.**  :func:`cv2.fitEllipseDirect` (Fitzgibbon, Pilu & Fisher 1999): an algebraic
   least-squares fit constrained to be an ellipse, one linear-algebra solve, no start value.
   It always returns an ellipse, even for a short arc, but the algebraic distance it minimises
   weights points unequally, so on a *partial* arc (only part of the ellipse visible) it is
   biased -- towards a smaller, more eccentric ellipse.
2. **Arc coverage.**  The points are projected onto that ellipse; the largest gap between
   their parametric angles is the part of the ellipse not seen.  ``arc_fraction`` is the
   fraction of the perimeter (by arc length) the points cover: 1 for a closed ellipse,
   about 0.58 for a blocked actuator whose line turns through 210 deg.
3. **Geometric refinement** (``refine="auto"``: when ``arc_fraction < refine_below``;
   ``"always"`` / ``"never"`` force it).  :func:`scipy.optimize.least_squares` minimises the
   sum of squared *orthogonal* distances of the points to the ellipse over its five
   parameters (centre, semi-axes, angle), starting from the direct fit.  Each residual's foot
   point is found by Newton iteration on the parametric angle, and the Jacobian uses the
   envelope theorem (d distance / d parameter = -normal . d X / d parameter at the foot
   point), so the problem stays 5-dimensional.  This is the maximum-likelihood fit under
   isotropic pixel noise and removes the direct fit's short-arc bias.
4. **Outliers.**  Points far off the fitted ellipse (a dark clamp or a stray mark joined to
   the line) are trimmed by a robust threshold and the fit repeated (``trim_rounds``).
5. **Trust.**  From the Jacobian at the solution, ``eccentricity_sd`` = the standard error of
   e (residual variance x (J^T J)^-1, propagated to e).  The result is ``flagged`` when the arc
   covers less than ``min_arc_fraction`` of the perimeter, when ``eccentricity_sd`` exceeds
   ``max_eccentricity_sd`` (the shape does not pin e down: short or flat arc, noisy line),
   or when the RMS orthogonal residual exceeds ``max_residual_px`` (the line is not an
   ellipse).  It is ``failed`` (falsy, NaN numbers) with too few points or a degenerate fit.

Near-circular lines
-------------------
``e = sqrt(1 - (b/a)**2)`` is very sensitive to the axis ratio near a circle (a 1 % difference
between the axes already gives e = 0.14), so pixel noise biases e of a near-circle *upwards*:
a rendered circle reads e ~ 0.02-0.05.  Below e ~ 0.2 read e as "about circular".  The target
range of the benchmark is e = 0.3-0.8.

Examples
--------
>>> import numpy as np
>>> t = np.linspace(0.0, 1.2 * np.pi, 200)
>>> pts = np.c_[300 + 200 * np.cos(t), 240 + 160 * np.sin(t)]
>>> fit = fit_ellipse(pts)
>>> round(fit.eccentricity, 3), fit.status
(0.6, 'ok')
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares
from scipy.special import ellipe

Refine = Literal["auto", "always", "never"]

#: points are thinned (evenly along the line) to at most this many before fitting
MAX_FIT_POINTS = 400


@dataclass(frozen=True)
class EllipseFit:
    """An ellipse fitted to line points (image pixels, x right, y down).

    A failed fit is falsy and carries NaN numbers, ``status="failed"`` and a ``reason``.

    Attributes
    ----------
    centre_x_px, centre_y_px : float
        Centre of the ellipse (px).
    semi_major_px, semi_minor_px : float
        Semi-axes a >= b (px).
    angle_deg : float
        Direction of the major axis, degrees in [0, 180), measured from the image x axis
        towards the image y axis (clockwise on screen).
    eccentricity : float
        ``sqrt(1 - b**2 / a**2)``, 0 for a circle.
    eccentricity_sd : float
        Standard error of the eccentricity from the fit (NaN when not estimable).
    arc_fraction : float
        Fraction of the perimeter (arc length) covered by the points, 0..1.
    residual_px : float
        RMS orthogonal distance of the points to the ellipse (px).
    n_points : int
        Number of line points considered (after thinning).
    n_outliers : int
        Points left out of the fit as off the ellipse (see ``trim_rounds``).
    method : str
        ``"direct"`` (Fitzgibbon) or ``"geometric"`` (direct, then orthogonal-distance refinement).
    status : str
        ``"ok"``, ``"flagged"`` or ``"failed"``.
    reason : str
        Why the fit is flagged or failed ("" when ok).
    """

    centre_x_px: float
    centre_y_px: float
    semi_major_px: float
    semi_minor_px: float
    angle_deg: float
    eccentricity: float
    eccentricity_sd: float
    arc_fraction: float
    residual_px: float
    n_points: int
    n_outliers: int
    method: str
    status: str
    reason: str

    def __bool__(self) -> bool:
        return self.status != "failed"

    def points(self, n: int = 200) -> NDArray[np.float64]:
        """``n`` points on the fitted ellipse (px), for drawing overlays."""
        return ellipse_points(
            (
                self.centre_x_px,
                self.centre_y_px,
                self.semi_major_px,
                self.semi_minor_px,
                np.deg2rad(self.angle_deg),
            ),
            np.linspace(0.0, 2.0 * np.pi, n),
        )


def failed_fit(reason: str, n_points: int = 0, method: str = "direct") -> EllipseFit:
    """A falsy :class:`EllipseFit` with NaN numbers and the given reason."""
    nan = float("nan")
    return EllipseFit(
        nan, nan, nan, nan, nan, nan, nan, nan, nan, n_points, 0, method, "failed", reason
    )


def eccentricity(semi_major: float, semi_minor: float) -> float:
    """Eccentricity ``sqrt(1 - b**2/a**2)`` of an ellipse (axes in either order).

    Examples
    --------
    >>> round(eccentricity(5.0, 4.0), 12)
    0.6
    """
    a, b = max(semi_major, semi_minor), min(semi_major, semi_minor)
    return float(np.sqrt(max(0.0, 1.0 - (b / a) ** 2)))


def perimeter(semi_major: float, semi_minor: float) -> float:
    """Perimeter of an ellipse, ``4 a E(e**2)`` with the complete elliptic integral E.

    Examples
    --------
    >>> round(perimeter(1.0, 1.0), 6) == round(2 * np.pi, 6)
    True
    """
    a, b = max(semi_major, semi_minor), min(semi_major, semi_minor)
    return float(4.0 * a * ellipe(1.0 - (b / a) ** 2))


def ellipse_points(params: ArrayLike, t: ArrayLike) -> NDArray[np.float64]:
    """Points ``(n, 2)`` of the ellipse ``(xc, yc, a, b, theta_rad)`` at parametric angles ``t``."""
    xc, yc, a, b, th = (float(v) for v in np.asarray(params, dtype=float))
    t = np.asarray(t, dtype=float)
    c, s = np.cos(th), np.sin(th)
    return np.c_[
        xc + a * np.cos(t) * c - b * np.sin(t) * s, yc + a * np.cos(t) * s + b * np.sin(t) * c
    ]


def fit_ellipse(
    points_px: ArrayLike,
    *,
    refine: Refine = "auto",
    refine_below: float = 0.75,
    min_points: int = 20,
    min_arc_fraction: float = 0.4,
    max_eccentricity_sd: float = 0.02,
    max_residual_px: float = 3.0,
    trim_rounds: int = 3,
    outlier_sigma: float = 4.0,
    min_outlier_px: float = 2.0,
    max_outlier_fraction: float = 0.1,
) -> EllipseFit:
    """Fit an ellipse to line points; report its eccentricity, arc coverage and trust.

    Parameters
    ----------
    points_px : array_like, shape (n, 2)
        Centre-line points of the marked line (px), in any order.
    refine : {"auto", "always", "never"}
        Geometric (orthogonal-distance) refinement of the direct fit: when the arc covers
        less than ``refine_below`` of the perimeter, always, or never.
    refine_below : float
        Arc fraction below which ``refine="auto"`` refines (0..1).
    min_points : int
        Fewer usable points than this: ``failed``.
    min_arc_fraction : float
        Arc covering less of the perimeter than this: ``flagged`` (e not trustworthy).
    max_eccentricity_sd : float
        Standard error of e above this: ``flagged``.
    max_residual_px : float
        RMS orthogonal residual above this (px): ``flagged`` (the line is not an ellipse).
    trim_rounds : int
        Rounds of outlier trimming (0: none).  After each fit, points farther from the ellipse
        than ``max(outlier_sigma * 1.4826 * MAD, min_outlier_px)`` are left out and the fit is
        repeated, so a clamp or a stray mark joined to the line does not pull the ellipse.
    outlier_sigma, min_outlier_px : float
        Trimming threshold (robust sigmas, and a floor in px).
    max_outlier_fraction : float
        More of the points trimmed than this: ``flagged``.

    Returns
    -------
    EllipseFit
        Falsy (``status="failed"``) when no ellipse could be fitted.

    Examples
    --------
    A quarter of an ellipse is too little to trust:

    >>> t = np.linspace(0.0, 0.5 * np.pi, 100)
    >>> fit_ellipse(np.c_[200 * np.cos(t), 120 * np.sin(t)]).status
    'flagged'
    """
    pts = np.asarray(points_px, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2:
        return failed_fit(f"points must have shape (n, 2), got {pts.shape}")
    pts = pts[np.isfinite(pts).all(axis=1)]
    pts = _thin(pts, MAX_FIT_POINTS)
    n = len(pts)
    if n < max(min_points, 6):
        return failed_fit(f"only {n} line points (need {max(min_points, 6)})", n)
    if np.linalg.matrix_rank(pts - pts.mean(axis=0), tol=1e-6 * max(1.0, float(np.ptp(pts)))) < 2:
        return failed_fit("line points are collinear", n)
    inlier = np.ones(n, dtype=bool)
    params: NDArray[np.float64] | None = None
    method, fraction = "direct", float("nan")
    for _ in range(1 + max(0, trim_rounds)):
        params = _direct_fit(pts[inlier])
        if params is None:
            return failed_fit("direct ellipse fit is degenerate", n)
        method = "direct"
        fraction = _arc_fraction(pts[inlier], params)
        if refine == "always" or (refine == "auto" and fraction < refine_below):
            refined = _geometric_fit(pts[inlier], params)
            if refined is not None:
                params, method = refined, "geometric"
                fraction = _arc_fraction(pts[inlier], params)
        if trim_rounds <= 0:
            break
        d_all = np.abs(_signed_distances(pts, _canonical(params))[0])
        sigma = 1.4826 * float(np.median(d_all[inlier]))
        keep = d_all <= max(outlier_sigma * sigma, min_outlier_px)
        if np.array_equal(keep, inlier) or keep.sum() < max(min_points, 6):
            break
        inlier = keep
    assert params is not None
    params = _canonical(params)
    n_outliers = int(n - inlier.sum())
    pts = pts[inlier]
    dist = _signed_distances(pts, params)[0]
    residual = float(np.sqrt(np.mean(dist**2)))
    e_sd = _eccentricity_sd(pts, params, dist)
    xc, yc, a, b, th = params
    e = eccentricity(a, b)
    reasons = []
    if fraction < min_arc_fraction:
        reasons.append(
            f"arc covers {fraction:.0%} of the ellipse (< {min_arc_fraction:.0%}): e not "
            "trustworthy"
        )
    if not np.isfinite(e_sd) or e_sd > max_eccentricity_sd:
        reasons.append(f"eccentricity uncertain (sd {e_sd:.3f} > {max_eccentricity_sd})")
    if residual > max_residual_px:
        reasons.append(
            f"line is not an ellipse (RMS residual {residual:.1f} px > {max_residual_px})"
        )
    if n_outliers > max_outlier_fraction * n:
        reasons.append(
            f"{n_outliers / n:.0%} of the line points are off the ellipse (ignored in the fit)"
        )
    return EllipseFit(
        centre_x_px=float(xc),
        centre_y_px=float(yc),
        semi_major_px=float(a),
        semi_minor_px=float(b),
        angle_deg=float(np.rad2deg(th)),
        eccentricity=e,
        eccentricity_sd=e_sd,
        arc_fraction=fraction,
        residual_px=residual,
        n_points=n,
        n_outliers=n_outliers,
        method=method,
        status="flagged" if reasons else "ok",
        reason="; ".join(reasons),
    )


# --------------------------------------------------------------------------------------------
# internals


def _thin(pts: NDArray[np.float64], n_max: int) -> NDArray[np.float64]:
    if len(pts) <= n_max:
        return pts
    idx = np.round(np.linspace(0, len(pts) - 1, n_max)).astype(int)
    return pts[idx]


def _direct_fit(pts: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """Fitzgibbon direct fit via OpenCV, as ``(xc, yc, a, b, theta_rad)``; None if degenerate."""
    import cv2

    shift = pts.mean(axis=0)  # fit in centred coordinates: better conditioned in float32
    (cx, cy), (w, h), ang = cv2.fitEllipseDirect((pts - shift).astype(np.float32))
    params = np.array(
        [cx + shift[0], cy + shift[1], w / 2.0, h / 2.0, np.deg2rad(ang)], dtype=float
    )
    if not np.all(np.isfinite(params)) or params[2] <= 0 or params[3] <= 0:
        return None
    return _canonical(params)


def _canonical(params: NDArray[np.float64]) -> NDArray[np.float64]:
    """Semi-axes positive, a >= b, theta in [0, pi)."""
    xc, yc, a, b, th = params
    a, b = abs(a), abs(b)
    if b > a:
        a, b, th = b, a, th + np.pi / 2.0
    return np.array([xc, yc, a, b, np.mod(th, np.pi)])


def _foot_angles(
    pts: NDArray[np.float64], params: NDArray[np.float64], iterations: int = 12
) -> NDArray[np.float64]:
    """Parametric angle of each point's orthogonal foot on the ellipse (Newton on t)."""
    xc, yc, a, b, th = params
    c, s = np.cos(th), np.sin(th)
    dx, dy = pts[:, 0] - xc, pts[:, 1] - yc
    u, v = dx * c + dy * s, -dx * s + dy * c  # point in the ellipse frame
    t = np.arctan2(a * v, b * u)  # start: angle on the scaled circle
    for _ in range(iterations):
        ct, st = np.cos(t), np.sin(t)
        # f(t) = (p - X(t)) . X'(t) in the ellipse frame
        f = (u - a * ct) * (-a * st) + (v - b * st) * (b * ct)
        df = (
            (a * st) * (-a * st)
            + (u - a * ct) * (-a * ct)
            + (-b * ct) * (b * ct)
            + (v - b * st) * (-b * st)
        )
        step = np.where(np.abs(df) > 1e-12, f / df, 0.0)
        t = t - np.clip(step, -0.5, 0.5)
    return t


def _signed_distances(
    pts: NDArray[np.float64], params: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Signed orthogonal distances (positive outside) and the Jacobian (n, 5) w.r.t. params."""
    xc, yc, a, b, th = params
    t = _foot_angles(pts, params)
    c, s = np.cos(th), np.sin(th)
    ct, st = np.cos(t), np.sin(t)
    foot = np.c_[xc + a * ct * c - b * st * s, yc + a * ct * s + b * st * c]
    # outward normal: rotate the tangent X'(t) by -90 deg in the ellipse's own frame
    nu, nv = b * ct, a * st
    norm = np.hypot(nu, nv)
    nu, nv = nu / norm, nv / norm
    nx, ny = nu * c - nv * s, nu * s + nv * c
    d = (pts[:, 0] - foot[:, 0]) * nx + (pts[:, 1] - foot[:, 1]) * ny
    # envelope theorem: dd/dp = -n . dX/dp at fixed t
    dX = np.stack(
        [
            np.c_[np.ones_like(t), np.zeros_like(t)],
            np.c_[np.zeros_like(t), np.ones_like(t)],
            np.c_[ct * c, ct * s],
            np.c_[-st * s, st * c],
            np.c_[-(foot[:, 1] - yc), foot[:, 0] - xc],
        ],
        axis=1,
    )  # (n, 5, 2)
    jac = -(dX[:, :, 0] * nx[:, None] + dX[:, :, 1] * ny[:, None])
    return d, jac


def _geometric_fit(
    pts: NDArray[np.float64], start: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    """Orthogonal-distance least squares from ``start``; None when it does not converge sanely."""
    scale = float(max(start[2], 1.0))
    x0 = start.copy()
    res = least_squares(
        lambda p: _signed_distances(pts, p)[0],
        x0,
        jac=lambda p: _signed_distances(pts, p)[1],
        method="lm",
        x_scale=np.array([scale, scale, scale, scale, 1.0]),
        xtol=1e-10,
        ftol=1e-10,
        max_nfev=200,
    )
    p = res.x
    if not np.all(np.isfinite(p)) or min(abs(p[2]), abs(p[3])) <= 0:
        return None
    # a runaway towards a huge, nearly flat ellipse is not a refinement
    if max(abs(p[2]), abs(p[3])) > 50.0 * max(float(np.ptp(pts[:, 0])), float(np.ptp(pts[:, 1]))):
        return None
    return _canonical(p)


def _arc_fraction(pts: NDArray[np.float64], params: NDArray[np.float64]) -> float:
    """Fraction of the perimeter (by arc length) covered by the points' foot angles."""
    a, b = params[2], params[3]
    t = np.sort(np.mod(_foot_angles(pts, params), 2.0 * np.pi))
    gaps = np.diff(np.r_[t, t[0] + 2.0 * np.pi])
    i = int(np.argmax(gaps))
    start, span = t[(i + 1) % len(t)], 2.0 * np.pi - gaps[i]
    tt = start + np.linspace(0.0, span, 2001)
    speed = np.hypot(a * np.sin(tt), b * np.cos(tt))
    covered = float(np.sum((speed[1:] + speed[:-1]) / 2.0 * np.diff(tt)))
    return float(np.clip(covered / perimeter(a, b), 0.0, 1.0))


def _eccentricity_sd(
    pts: NDArray[np.float64], params: NDArray[np.float64], dist: NDArray[np.float64]
) -> float:
    """Standard error of e: residual variance x (J^T J)^-1 propagated through e(a, b)."""
    n = len(pts)
    if n <= 5:
        return float("nan")
    jac = _signed_distances(pts, params)[1]
    sigma2 = float(np.sum(dist**2) / (n - 5))
    try:
        cov = sigma2 * np.linalg.inv(jac.T @ jac)
    except np.linalg.LinAlgError:
        return float("nan")
    a, b = params[2], params[3]
    e = eccentricity(a, b)
    if e < 1e-9:
        return float("nan")
    grad = np.zeros(5)
    grad[2] = b**2 / a**3 / e
    grad[3] = -b / a**2 / e
    var = float(grad @ cov @ grad)
    return float(np.sqrt(var)) if var >= 0 and np.isfinite(var) else float("nan")
