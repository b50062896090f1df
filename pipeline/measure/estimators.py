"""Curvature estimators: one interface, several methods (``--method`` selects one).

Every estimator takes the ordered centre-line points of the marker line (``(N, 2)`` array, fixed
end first, in pixels, in a **y-up** frame so that a counter-clockwise turn *as seen on screen* is
positive) and returns a :class:`CurveEstimate` whose ``kappa_per_px`` is the signed *mean*
curvature over the measured line.  The caller turns it into psi (``kappa * l0``).

Methods
-------
``paper``
    Faithful to the paper (Section II.C): curvature at 100 random places along the curve,
    each from three *nearby* centre-line points (2 % of the line apart), unsigned, averaged (the
    overall sign is taken from the turning direction, otherwise negative angles could not be
    reported). Pixel noise makes each nearby-triple curvature large and of random sign, so the
    unsigned average is biased upwards: a straight line never reads 0 deg.  Kept to show the trap.
``paper_corrected``
    Same sampling idea, but signed three-point (Menger) curvature over *widely spaced* triples
    (spacing a quarter to a half of the line): unbiased, and exact for any three points of an
    arc, including arcs past 180 deg.
``pratt``, ``taubin``, ``hyper``
    Algebraic circle fits (Chernov's formulation: minimise ``A^T M A`` subject to a quadratic
    constraint ``A^T N A = 1`` on the circle ``A (x^2 + y^2) + B x + C y + D = 0``).  They stay
    regular at zero curvature (``A -> 0`` is a straight line), unlike Kasa, which over-reads
    curvature on short arcs.  Hyper is unbiased to second order in the noise.
``turning``
    Tangent angle theta(s) against arc length s: a smooth model (cosine series of the
    curvature, up to 9 terms) whose integrated curve is fitted to the centre line, the number
    of terms chosen by BIC (constant curvature unless the photo demands more);
    psi = theta(L) - theta(0).  Right when curvature is not constant.
``tangents``
    The tip angle: tangent direction at the free end minus that at the fixed end, each from a
    straight-line fit of the tangent angle against arc length over an end window (15 % of the
    line), extrapolated to the line's very ends; turns between them are counted along the line.
    psi is the total turning whatever the shape, without assuming any model between the ends:
    the default for an actuator's body (``target: body``) and whenever the direction the
    actuator leaves the clamp is given (``fixed_direction_deg``).
``auto``
    ``hyper``, switching to ``turning`` only when the curvature is visibly not constant.

Examples
--------
>>> import numpy as np
>>> t = np.linspace(0.0, np.deg2rad(250.0), 400)
>>> pts = np.c_[100 * np.sin(t), 100 * (1 - np.cos(t))]   # ccw arc, radius 100 px
>>> print(round(METHODS["hyper"](pts, np.random.default_rng(0)).kappa_per_px * 100, 6))
1.0
>>> print(round(np.rad2deg(METHODS["turning"](pts, np.random.default_rng(0)).turning_rad), 1))
250.0
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy import linalg

#: paper: number of random places along the curve
N_SAMPLES = 100
#: paper: spacing of the "nearby" triples, as a fraction of the line
NEARBY_FRACTION = 0.02
#: turning: information criterion choosing the degree ("bic" or "aic")
CRITERION = "bic"
#: turning: most terms of the curvature series tried (and highest degree of turning_quick)
MAX_DEGREE = 9


@dataclass(frozen=True)
class CurveEstimate:
    """Result of one curvature estimator.

    Attributes
    ----------
    kappa_per_px : float
        Signed mean curvature (1/px), counter-clockwise in a y-up frame positive.
    turning_rad : float
        Signed total turning angle over the measured line (rad) = kappa * length.
    length_px : float
        Arc length of the measured line (px).
    residual_px : float
        RMS distance of the points from the fitted model (px); NaN when the method has none.
    degree : int
        Model complexity used (1 for a circle / constant curvature).
    neighbour_turning_rad : float
        :func:`turning` only: the turning angle of the fit with one term more (one less when the
        most terms were chosen), a stability check; NaN otherwise.
    """

    kappa_per_px: float
    turning_rad: float
    length_px: float
    residual_px: float
    degree: int = 1
    neighbour_turning_rad: float = float("nan")


class Estimator(Protocol):
    """``estimator(points, rng, *, ends_px=(0.0, 0.0)) -> CurveEstimate``.

    ``ends_px`` is the length of the line beyond the first and the last point (px), e.g. where
    the extraction trimmed the ends: it counts in ``length_px`` and the turning method
    extrapolates the tangent angle over it.
    """

    def __call__(
        self,
        points: np.ndarray,
        rng: np.random.Generator,
        *,
        ends_px: tuple[float, float] = (0.0, 0.0),
    ) -> CurveEstimate: ...


# ---------------------------------------------------------------------------------------------
# helpers


def arc_length(points: np.ndarray) -> np.ndarray:
    """Cumulative arc length of a polyline, starting at 0.

    Parameters
    ----------
    points : ndarray, shape (N, 2)

    Returns
    -------
    ndarray, shape (N,)
    """
    seg = np.hypot(*np.diff(points, axis=0).T)
    return np.concatenate(([0.0], np.cumsum(seg)))


def chunk_means(points: np.ndarray, n_chunks: int | None = None) -> tuple[np.ndarray, float]:
    """Average a polyline over ``n_chunks`` equal arc-length pieces.

    The polyline is resampled at about 0.5 px, cut into equal pieces, and each piece replaced by
    its mean.  On an arc the means lie on a concentric circle at equal angular steps, so chord
    directions between consecutive means are exact tangent angles while pixel noise is averaged.

    Parameters
    ----------
    points : ndarray, shape (N, 2)
    n_chunks : int, optional
        Default: about one piece per 3 px, between 8 and 64.

    Returns
    -------
    means : ndarray, shape (n_chunks, 2)
    piece_px : float
        Arc length of one piece (px).
    """
    s = arc_length(points)
    total = float(s[-1])
    if n_chunks is None:
        n_chunks = int(np.clip(total / 3.0, 8, 64))
    per = max(int(np.ceil(total / n_chunks / 0.5)), 1)
    u = (np.arange(n_chunks * per) + 0.5) * (total / (n_chunks * per))
    fine = np.c_[np.interp(u, s, points[:, 0]), np.interp(u, s, points[:, 1])]
    return fine.reshape(n_chunks, per, 2).mean(axis=1), total / n_chunks


def smooth_length(points: np.ndarray) -> float:
    """Arc length of a noisy polyline, free of the zig-zag inflation of the raw polyline (px)."""
    means, piece = chunk_means(points)
    return float(arc_length(means)[-1] + piece)


def _turn_sign(points: np.ndarray) -> float:
    """+1 when the line as a whole turns counter-clockwise (y-up), -1 otherwise."""
    d = np.diff(points, axis=0)
    ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    k = max(len(ang) // 10, 1)
    return 1.0 if ang[-k:].mean() - ang[:k].mean() >= 0 else -1.0


def menger_curvature(p1: np.ndarray, p2: np.ndarray, p3: np.ndarray) -> np.ndarray:
    """Signed curvature of the circle through three points (ccw positive), vectorised.

    ``kappa = 2 * cross(p2 - p1, p3 - p2) / (|p2 - p1| |p3 - p2| |p3 - p1|)``.
    """
    a, b = p2 - p1, p3 - p2
    cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    den = np.hypot(*a.T) * np.hypot(*b.T) * np.hypot(*(p3 - p1).T)
    return np.divide(2.0 * cross, den, out=np.zeros_like(cross, dtype=float), where=den > 0)


def _estimate(
    kappa: float, points: np.ndarray, residual: float, ends_px: tuple[float, float], degree: int = 1
) -> CurveEstimate:
    length = smooth_length(points) + ends_px[0] + ends_px[1]
    return CurveEstimate(float(kappa), float(kappa * length), length, float(residual), degree)


# ---------------------------------------------------------------------------------------------
# paper (faithful) and corrected


def paper(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """The paper's estimator: unsigned curvature of neighbouring triples at 100 random places.

    Biased upwards by pixel noise (a straight line never reads 0); see the module docstring.
    """
    n = len(points)
    if n < 5:
        raise ValueError("need at least 5 centre-line points")
    m = max(round(NEARBY_FRACTION * n), 1)
    i = rng.integers(m, n - m, size=N_SAMPLES)
    k = np.abs(menger_curvature(points[i - m], points[i], points[i + m]))
    return _estimate(_turn_sign(points) * float(k.mean()), points, np.nan, ends_px)


def paper_corrected(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Signed three-point curvature over widely spaced triples at 100 random places.

    Each triple is ``(i, i + m, i + 2 m)`` with ``m`` between a quarter and a half of the line.
    """
    n = len(points)
    if n < 5:
        raise ValueError("need at least 5 centre-line points")
    m = rng.integers(max(n // 4, 1), max((n - 1) // 2, 1) + 1, size=N_SAMPLES)
    i = (rng.random(N_SAMPLES) * (n - 2 * m)).astype(int)
    k = menger_curvature(points[i], points[i + m], points[i + 2 * m])
    return _estimate(float(k.mean()), points, np.nan, ends_px)


# ---------------------------------------------------------------------------------------------
# algebraic circle fits (Chernov & Lesort)


def _constraint(kind: str, zbar: float, xbar: float, ybar: float) -> np.ndarray:
    pratt = np.array([[0, 0, 0, -2], [0, 1, 0, 0], [0, 0, 1, 0], [-2, 0, 0, 0]], float)
    taubin = np.array(
        [[4 * zbar, 2 * xbar, 2 * ybar, 0], [2 * xbar, 1, 0, 0], [2 * ybar, 0, 1, 0], [0, 0, 0, 0]],
        float,
    )
    return {"pratt": pratt, "taubin": taubin, "hyper": 2 * taubin - pratt}[kind]


def algebraic_circle(points: np.ndarray, kind: str = "hyper") -> tuple[np.ndarray, float]:
    """Fit ``A (x^2 + y^2) + B x + C y + D = 0`` with the Pratt, Taubin or Hyper constraint.

    Parameters
    ----------
    points : ndarray, shape (N, 2)
    kind : {"pratt", "taubin", "hyper"}

    Returns
    -------
    coef : ndarray, shape (4,)
        ``(A, B, C, D)`` in the coordinates ``(points - origin) / scale``.
    scale : float
        Normalising scale (px); the origin is the centroid of ``points``.
    """
    origin = points.mean(axis=0)
    q = points - origin
    scale = float(np.sqrt((q**2).sum(axis=1).mean())) or 1.0
    q = q / scale
    z = (q**2).sum(axis=1)
    design = np.c_[z, q, np.ones(len(q))]
    m = design.T @ design / len(q)
    m += np.eye(4) * 1e-12 * np.trace(m)  # exact data: keep M positive definite
    cons = _constraint(kind, z.mean(), q[:, 0].mean(), q[:, 1].mean())
    # N a = lambda M a  (lambda = 1 / eta): the wanted eta is the smallest positive one
    lam, vec = linalg.eigh(cons, m)
    coef = vec[:, int(np.argmax(lam))]
    return coef, scale


def _circle_estimate(points: np.ndarray, kind: str, ends_px: tuple[float, float]) -> CurveEstimate:
    coef, scale = algebraic_circle(points, kind)
    a, b, c, d = coef
    q = (points - points.mean(axis=0)) / scale
    grad = 2 * a * q + np.array([b, c])
    disc = b * b + c * c - 4 * a * d
    if disc <= 0:
        raise ValueError("degenerate circle fit")
    t = np.gradient(q, axis=0)
    side = np.sign(np.sum(t[:, 0] * grad[:, 1] - t[:, 1] * grad[:, 0])) or 1.0
    kappa = -2.0 * a * side / np.sqrt(disc) / scale
    f = a * (q**2).sum(axis=1) + q @ np.array([b, c]) + d
    resid = f / np.maximum(np.hypot(*grad.T), 1e-12) * scale
    return _estimate(kappa, points, float(np.sqrt(np.mean(resid**2))), ends_px)


def pratt(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Pratt algebraic circle fit (constraint ``B^2 + C^2 - 4 A D = 1``)."""
    return _circle_estimate(points, "pratt", ends_px)


def taubin(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Taubin algebraic circle fit (gradient-weighted)."""
    return _circle_estimate(points, "taubin", ends_px)


def hyper(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Hyper algebraic circle fit (Al-Sharadqah & Chernov 2009: no essential bias)."""
    return _circle_estimate(points, "hyper", ends_px)


# ---------------------------------------------------------------------------------------------
# turning angle


def turning_fit(
    points: np.ndarray, max_degree: int = MAX_DEGREE
) -> tuple[np.ndarray, np.ndarray, int, float]:
    """Fit tangent angle against arc length with a polynomial degree chosen by BIC.

    The tangent angle is taken from chords between consecutive points (pass the output of
    :func:`chunk_means` so that chord angles are nearly independent and noise is averaged).

    Returns
    -------
    s_mid : ndarray
        Arc length at the chord midpoints (px).
    coef : ndarray
        Legendre coefficients of theta(u), ``u = 2 s / L - 1``.
    degree : int
        Chosen degree.
    rss : float
        Residual sum of squares of the chosen fit (rad^2).
    """
    d = np.diff(points, axis=0)
    seg = np.hypot(d[:, 0], d[:, 1])
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    s = np.concatenate(([0.0], np.cumsum(seg)))
    s_mid = 0.5 * (s[1:] + s[:-1])
    u = 2.0 * s_mid / s[-1] - 1.0
    n = len(theta)
    top = min(max_degree, n - 2)
    # one weighted QR of the Legendre Vandermonde gives the RSS of every nested degree
    wt = np.sqrt(seg / seg.mean())
    vand = np.polynomial.legendre.legvander(u, top) * wt[:, None]
    q, r = np.linalg.qr(vand)
    proj = q.T @ (theta * wt)
    total = float(np.sum((theta * wt) ** 2))
    # RSS of degree d = total - sum of the first d + 1 squared projections (nested fits)
    degs = np.arange(1, top + 1)
    rss = np.maximum(total - np.cumsum(proj**2)[1 : top + 1], 1e-300)
    bic = n * np.log(rss / n) + (degs + 1) * np.log(n)
    k = int(np.argmin(bic))  # first minimum: the simplest of equally good degrees
    deg = int(degs[k])
    coef = linalg.solve_triangular(r[: deg + 1, : deg + 1], proj[: deg + 1])
    return s_mid, coef, deg, float(rss[k])


def _theta_basis(u: np.ndarray, n_coef: int) -> np.ndarray:
    """Columns ``1, u, sin(k pi u) / (k pi)`` (k = 1 .. n_coef - 2): theta(u) is linear in them.

    Examples
    --------
    >>> _theta_basis(np.array([0.0, 0.5, 1.0]), 3).round(3).tolist()
    [[1.0, 0.0, 0.0], [1.0, 0.5, 0.318], [1.0, 1.0, 0.0]]
    """
    k = np.arange(1, n_coef - 1) * np.pi
    return np.column_stack([np.ones_like(u), u, np.sin(np.outer(u, k)) / k])


def _shape_model(
    params: np.ndarray, n: int, q: int, span: float, ends: tuple[float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Chunk means of the curve p(s) = p0 + stretch * int (cos theta, sin theta) ds, and their
    derivatives by ``params``.

    ``params`` are p0 (x, y), log stretch and the coefficients of theta(u) = theta0 + psi u +
    sum_k b_k sin(k pi u) / (k pi).  ``u`` runs over the whole line, [0, 1] from the fixed end to
    the free end; the data (the ``n`` chunk means, ``q`` fine points each) cover its part
    ``[ends[0], ends[0] + span]``.

    Returns
    -------
    means : ndarray (n, 2)
    jacobian : ndarray (2 n, len(params))
        d means.ravel() / d params, exact (theta is linear in its coefficients).
    """
    p0, stretch, coef = params[:2], np.exp(params[2]), params[3:]
    total = span + ends[0] + ends[1]
    ds = span / (n * q)
    s_f = (np.arange(n * q) + 0.5) * ds
    basis = _theta_basis((s_f + ends[0]) / total, len(coef))
    theta = basis @ coef
    cos, sin = np.cos(theta), np.sin(theta)
    step = np.c_[cos, sin] * (ds * stretch)
    pos = p0 + np.cumsum(step, axis=0) - 0.5 * step
    means = pos.reshape(n, q, 2).mean(axis=1)
    # a coefficient turns every step by its basis value: d step = (-sin, cos) ds stretch basis
    d_step = np.stack([-sin, cos], axis=1)[:, :, None] * (ds * stretch) * basis[:, None, :]
    d_pos = np.cumsum(d_step, axis=0) - 0.5 * d_step
    d_coef = d_pos.reshape(n, q, 2, len(coef)).mean(axis=1).reshape(2 * n, len(coef))
    d_p0 = np.tile(np.eye(2), (n, 1))
    d_stretch = (means - p0).reshape(2 * n, 1)
    return means, np.hstack([d_p0, d_stretch, d_coef])


def turning(
    points: np.ndarray,
    rng: np.random.Generator,
    *,
    ends_px: tuple[float, float] = (0.0, 0.0),
    max_degree: int | None = None,
) -> CurveEstimate:
    """Total turning angle theta(L) - theta(0) from a BIC-chosen smooth model of the curvature.

    The curvature along the line is a cosine series, ``kappa(u) = (psi + sum_k b_k cos(k pi u))
    / L`` with ``u = s / L`` in [0, 1] (a DCT basis: smooth, no polynomial blow-up at the ends),
    so the tangent angle is ``theta(u) = theta0 + psi u + sum_k b_k sin(k pi u) / (k pi)`` and
    ``theta(1) - theta(0) = psi`` exactly, whatever the shape terms.  For K = 0, 1, ... terms
    the curve it defines (integrated tangent, free start point and length scale) is fitted to
    the centre line's chunk means by Levenberg-Marquardt (:func:`scipy.optimize.least_squares`,
    with the model's exact Jacobian: half the time of finite differences);
    the K with the lowest BIC on the positional residuals wins: K = 0 is a circular arc, more
    terms only when the photo demands them.  Fitting positions (an integral of theta) rather than
    noisy chord angles, and reading psi as the mean curvature rather than from the end
    tangents, keeps psi stable.  ``degree`` in the result is K + 1.
    """
    from scipy.optimize import least_squares  # lazy: only this method needs it

    if len(points) < 4:
        raise ValueError("need at least 4 centre-line points")
    means, piece = chunk_means(points)
    n, q = len(means), 6
    span = n * piece
    total = span + ends_px[0] + ends_px[1]
    d = np.diff(means, axis=0)
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    u_mid = ((np.arange(1, n) * piece) + ends_px[0]) / total
    slope, theta0 = np.polyfit(u_mid, theta, 1)
    start = means[0] - 0.5 * piece * np.array([np.cos(theta0), np.sin(theta0)])
    x0 = np.r_[start, 0.0, theta0, slope]
    best: tuple[float, np.ndarray, int, float] | None = None
    psi_of: dict[int, float] = {}
    worse = 0
    for k in range(min(MAX_DEGREE if max_degree is None else max_degree, n - 4)):
        fit = least_squares(
            lambda p: (_shape_model(p, n, q, span, ends_px)[0] - means).ravel(),
            x0,
            jac=lambda p: _shape_model(p, n, q, span, ends_px)[1],
            method="lm",
            xtol=1e-10,
            ftol=1e-10,
        )
        rss = float(np.sum(fit.fun**2))
        psi_of[k + 1] = float(fit.x[4])
        m = 2 * n
        bic = m * np.log(max(rss, 1e-300) / m) + (k + 5) * (
            np.log(m) if CRITERION == "bic" else 2.0
        )
        if best is None or bic < best[0]:
            best, worse = (bic, fit.x, k + 1, rss), 0
        else:
            worse += 1
            if worse >= 2:
                break
        x0 = np.r_[fit.x, 0.0]
    assert best is not None
    _, params, deg, rss = best
    psi = float(params[4])
    length = total * float(np.exp(params[2]))
    resid_px = float(np.sqrt(rss / n))
    # one term more (one less when the cap stopped the search): psi should barely move
    neighbour = psi_of.get(deg + 1, psi_of.get(deg - 1, float("nan")))
    return CurveEstimate(psi / length, psi, length, resid_px, deg, neighbour)


def turning_quick(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Linear variant of :func:`turning`: the BIC-chosen polynomial fitted to chord angles.

    Cheaper (no iterations) and used by the quality check for non-constant curvature.
    """
    if len(points) < 4:
        raise ValueError("need at least 4 centre-line points")
    means, piece = chunk_means(points)
    _s_mid, coef, deg, rss = turning_fit(means)
    span = float(arc_length(means)[-1])
    length = span + piece + ends_px[0] + ends_px[1]
    # u = 2 s / span - 1 runs from the first mean to the last; the line ends lie beyond them
    u0 = -1.0 - 2.0 * (piece / 2 + ends_px[0]) / span
    u1 = 1.0 + 2.0 * (piece / 2 + ends_px[1]) / span
    psi = float(np.polynomial.legendre.legval(u1, coef) - np.polynomial.legendre.legval(u0, coef))
    n = len(means) - 1
    # chord-angle RMS residual -> positional scale (angle noise ~ sqrt(2) sigma / spacing)
    resid_px = float(np.sqrt(rss / n) * piece / np.sqrt(2.0))
    return CurveEstimate(psi / length, psi, length, resid_px, deg)


#: tangents: each end's tangent is fitted over this fraction of the line
TANGENT_WINDOW_FRACTION = 0.15


#: tangents: polynomial degree of the tangent angle against arc length in each end window
TANGENT_DEGREE = 1


def _end_angle(
    s_mid: np.ndarray, theta: np.ndarray, at: float, window: float, from_start: bool
) -> tuple[float, float]:
    """Tangent angle at arc length ``at`` from a fit over the first/last ``window``; and its RMS.

    ``s_mid`` are the chords' places (between two chunk means, one chunk apart: each chord holds
    the line one chunk either side of it)."""
    piece = float(s_mid[1] - s_mid[0]) if len(s_mid) > 1 else 1.0
    weights = None
    if not from_start and at < s_mid[-1] + piece:  # read inside the line (before a sealed end):
        # the window ends there, over the part that bends only.  A chord counts by the share of
        # the two chunks it joins that lies before ``at`` (below), so that what lies beyond (a
        # hook where a cap begins) counts less the further it is, and psi moves smoothly with
        # ``at``, on into the fit over the line's last ``window`` at its end: with
        # chords cut at their middles a read point moved 7 px by a rough mm_per_px let a hooked
        # last chord in and psi moved 2.4 deg (a 12 MP ribbed body with an 8 mm cap)
        weights = np.clip((at - s_mid + piece) / (2.0 * piece), 0.0, 1.0) * np.clip(
            (s_mid - (at - piece - window)) / piece + 0.5, 0.0, 1.0
        )
        sel = weights > 0.0
    else:
        sel = s_mid <= s_mid[0] + window if from_start else s_mid >= s_mid[-1] - window
    if sel.sum() < 3:
        sel = np.zeros_like(sel)
        sel[:3] = bool(from_start)
        if not from_start:
            sel[-3:] = True
    deg = min(TANGENT_DEGREE, int(sel.sum()) - 2)
    w = np.ones(int(sel.sum())) if weights is None or not weights[sel].all() else weights[sel]
    # polyfit weighs the residuals: each chord's square residual counts by the square of its
    # share, so that one mostly beyond ``at`` counts little (by its share alone, the test's 30 deg
    # hook beyond the read point moved psi up to 1.1 deg, so 0.8); the RMS is weighed the same
    coef = np.polyfit(s_mid[sel], theta[sel], deg, w=w)
    resid = theta[sel] - np.polyval(coef, s_mid[sel])
    return float(np.polyval(coef, at)), float(np.sqrt(np.average(resid**2, weights=w**2)))


def end_tangents(
    points: np.ndarray,
    *,
    ends_px: tuple[float, float] = (0.0, 0.0),
    window_fraction: float | None = None,
) -> tuple[float, float, float]:
    """Tangent angles (rad, y-up, unwrapped along the line) at both ends of the whole line.

    Parameters
    ----------
    points : ndarray, shape (N, 2)
        Ordered centre line (y up), fixed end first.
    ends_px : (float, float)
        Length of the line beyond the first and the last point (px): the tangent is
        extrapolated to the line's true ends.
    window_fraction : float, optional
        Fraction of the line each end's fit uses (default :data:`TANGENT_WINDOW_FRACTION`).

    Returns
    -------
    theta_start, theta_end : float
    rms_rad : float
        RMS misfit of the chord angles in the two windows (rad).

    Examples
    --------
    >>> t = np.linspace(0.0, np.deg2rad(300.0), 500)
    >>> pts = np.c_[np.sin(t), 1 - np.cos(t)] * 100.0
    >>> a, b, _ = end_tangents(pts)
    >>> print(round(float(np.rad2deg(b - a)), 2))
    300.0

    Read inside the line (a negative free end: where a straight sealed end begins), the window
    ends there, so the straight part does not pull the tangent back (it read 196.0 here; a 10 mm
    sealed end at 12 MP read |psi| near 200 deg up to 5 deg low):

    >>> arc = np.c_[np.sin(t), 1 - np.cos(t)][:334] * 100.0  # 200.2 deg
    >>> sealed = arc[-1] + np.outer(np.linspace(0.5, 30.0, 60), [np.cos(t[333]), np.sin(t[333])])
    >>> a, b, _ = end_tangents(np.r_[arc, sealed], ends_px=(0.0, -30.0))
    >>> print(round(float(np.rad2deg(b - a)), 1))
    200.1
    """
    if window_fraction is None:
        window_fraction = TANGENT_WINDOW_FRACTION
    means, piece = chunk_means(points)
    d = np.diff(means, axis=0)
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    # chords between means: tangent at the chunk boundary
    s_mid = (np.arange(1, len(means)) * piece).astype(float)
    total = len(means) * piece
    window = max(window_fraction * total, 3.0 * piece)
    a, ra = _end_angle(s_mid, theta, -ends_px[0], window, True)
    b, rb = _end_angle(s_mid, theta, total + ends_px[1], window, False)
    return a, b, float(np.hypot(ra, rb) / np.sqrt(2.0))


#: straight_end: the last this fraction of the line is searched for a straight end ...
STRAIGHT_END_WINDOW = 0.35
#: ... which turns at most this fraction of the rate of the part before it
STRAIGHT_END_TURN_RATIO = 0.25
#: ... and fits this fraction or less of the square misfit of one constant turning rate
STRAIGHT_END_FIT_RATIO = 0.3


def straight_end(points: np.ndarray, window_fraction: float = STRAIGHT_END_WINDOW) -> float:
    """Length of a straight stretch ending the line (its units), where the line bends up to it: a
    sealed end seen on the centre line; NaN where none shows.

    Over the last ``window_fraction`` (its last chord left out), the tangent angle against arc
    length is fitted with two joined straight pieces; the stretch after the join counts as
    straight when it turns at most :data:`STRAIGHT_END_TURN_RATIO` of the rate before it and the
    two pieces fit much better than one (:data:`STRAIGHT_END_FIT_RATIO`).  The join is sought
    up to three chunks (:func:`chunk_means`, about 3/64 of the line) before the end, so a
    shorter straight end does not show, however many pixels the photo has.  A line bending to
    its end, or one whose end is too little bent for a join to show, gives NaN.

    Examples
    --------
    >>> t = np.linspace(0.0, np.deg2rad(200.0), 800)
    >>> arc = np.c_[np.sin(t), 1.0 - np.cos(t)] * 100.0  # 349 units long
    >>> tail = arc[-1] + np.outer(np.linspace(0.5, 30.0, 60), [np.cos(t[-1]), np.sin(t[-1])])
    >>> round(straight_end(np.r_[arc, tail]))
    30
    >>> bool(np.isnan(straight_end(arc)))
    True
    """
    means, piece = chunk_means(points)
    d = np.diff(means, axis=0)
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    s = np.arange(1, len(means)) * piece
    total = len(means) * piece
    # not the last chord: where a cap begins, the centre line's last chunk may hook either way
    # (a ribbed body's turned back 1.3 deg after turning 2-3 a chunk, read as the start of a
    # straight end 11 mm long)
    near = (s >= total * (1.0 - window_fraction)) & (s < s[-1])
    s, theta = s[near], theta[near]
    if len(s) < 6:
        return float("nan")
    one = np.c_[np.ones_like(s), s]
    misfit_one = float(np.sum((one @ np.linalg.lstsq(one, theta, rcond=None)[0] - theta) ** 2))
    best = (np.inf, 0.0, np.zeros(3))
    for join in s[3:-1]:
        two = np.c_[np.ones_like(s), np.minimum(s, join), np.maximum(s - join, 0.0)]
        coef = np.linalg.lstsq(two, theta, rcond=None)[0]
        misfit = float(np.sum((two @ coef - theta) ** 2))
        if misfit < best[0]:
            best = (misfit, float(join), coef)
    misfit, join, (_, before, after) = best
    straight = (
        abs(after) <= STRAIGHT_END_TURN_RATIO * abs(before)
        and misfit <= STRAIGHT_END_FIT_RATIO * misfit_one
    )
    return float(total - join) if straight else float("nan")


def end_curvature(points: np.ndarray, window_fraction: float = TANGENT_WINDOW_FRACTION) -> float:
    """Curvature (rad per px, signed as the turning of ``points``) over the last
    ``window_fraction`` of the line: the slope of its tangent angle against arc length there.

    Examples
    --------
    >>> t = np.linspace(0.0, np.pi, 400)
    >>> pts = np.c_[np.cos(t), np.sin(t)] * 50.0  # ccw, radius 50
    >>> round(end_curvature(pts) * 50.0, 3)
    1.0
    """
    s = arc_length(points)
    tail = points[s >= s[-1] * (1.0 - window_fraction)]
    if len(tail) < 4:
        return 0.0
    d = np.diff(tail, axis=0)
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    along = np.cumsum(np.hypot(d[:, 0], d[:, 1]))
    return float(np.polyfit(along, theta, 1)[0])


def tangents(
    points: np.ndarray,
    rng: np.random.Generator,
    *,
    ends_px: tuple[float, float] = (0.0, 0.0),
    base_rad: float | None = None,
) -> CurveEstimate:
    """psi as the free end's tangent minus the fixed end's (or minus ``base_rad`` when known).

    ``base_rad`` is the known direction the line leaves the clamp (y-up, rad); it is taken on the
    branch nearest the measured start tangent.  ``neighbour_turning_rad`` holds the same estimate
    with end windows twice as long: a stability check (they differ on a wobbly or hooked end);
    with ``base_rad`` only the free end's window doubles, as psi does not depend on the fixed
    end's tangent then.

    Examples
    --------
    >>> t = np.linspace(0.0, np.pi, 200)
    >>> arc = np.c_[np.sin(t), 1.0 - np.cos(t)] * 100.0  # leaves at 0 rad, turns 180 deg ccw
    >>> hooked = np.vstack([arc[:1] + [[-30.0, 30.0], [-20.0, 20.0], [-10.0, 10.0]], arc])
    >>> est = tangents(hooked, np.random.default_rng(0), base_rad=0.0)
    >>> print(round(float(np.rad2deg(est.turning_rad)), 1),
    ...       round(float(np.rad2deg(est.neighbour_turning_rad)), 1))
    180.0 180.0
    """
    if len(points) < 4:
        raise ValueError("need at least 4 centre-line points")
    a, b, rms = end_tangents(points, ends_px=ends_px)
    # the check
    a2, b2, _ = end_tangents(points, ends_px=ends_px, window_fraction=2 * TANGENT_WINDOW_FRACTION)
    if base_rad is not None:
        base = base_rad + 2 * np.pi * np.round((a - base_rad) / (2 * np.pi))
        a2 = a = base
    length = smooth_length(points) + ends_px[0] + ends_px[1]
    psi, check = b - a, b2 - a2
    # angle misfit as a sideways offset
    resid_px = float(rms * length * TANGENT_WINDOW_FRACTION / np.sqrt(12.0))
    return CurveEstimate(psi / length, psi, length, resid_px, 1, check)


#: auto: switch from the arc to the turning model beyond this turning-vs-arc difference (deg)
AUTO_SWITCH_DEG = 1.5


def auto(
    points: np.ndarray, rng: np.random.Generator, *, ends_px: tuple[float, float] = (0.0, 0.0)
) -> CurveEstimate:
    """Hyper circle fit, unless the curvature is visibly not constant: then :func:`turning`.

    "Visibly": the linear tangent-angle fit (:func:`turning_quick`) needs degree >= 2 by BIC
    *and* its psi differs from the arc's by more than ``AUTO_SWITCH_DEG``.
    """
    arc = hyper(points, rng, ends_px=ends_px)
    quick = turning_quick(points, rng, ends_px=ends_px)
    return auto_choice(points, rng, arc, quick, ends_px=ends_px)


def auto_choice(
    points: np.ndarray,
    rng: np.random.Generator,
    arc: CurveEstimate,
    quick: CurveEstimate,
    *,
    ends_px: tuple[float, float] = (0.0, 0.0),
) -> CurveEstimate:
    """The ``auto`` decision given the Hyper and quick turning estimates already computed."""
    if (
        quick.degree >= 2
        and abs(np.rad2deg(quick.kappa_per_px - arc.kappa_per_px) * arc.length_px) > AUTO_SWITCH_DEG
    ):
        return turning(points, rng, ends_px=ends_px)
    return arc


#: name -> estimator; every entry has the same signature
METHODS: dict[str, Estimator] = {
    "paper": paper,
    "paper_corrected": paper_corrected,
    "pratt": pratt,
    "taubin": taubin,
    "hyper": hyper,
    "turning": turning,
    "tangents": tangents,
    "auto": auto,
}
