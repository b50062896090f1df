"""psi from one photo: extraction + estimator + quality (see the package docstring).

Sign convention (DESIGN.md): walking along the line from the fixed end to the free end, a turn
in the ``positive_turn`` direction *as seen on screen* counts positive.  Image y points down, so
the centre line is mirrored to a y-up frame (``y -> -y``) before the estimators, whose ccw is
then the on-screen ccw; ``positive_turn="cw"`` flips the sign.

psi = mean curvature x l0 when ``mm_per_px`` is known, else the total turning angle over the
measured line (mean curvature x measured length).
"""

from __future__ import annotations

import functools
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Literal

import cv2
import numpy as np
from numpy.typing import NDArray

from pipeline.measure.calibration import CalibrationMismatch, check_size
from pipeline.measure.estimators import (
    METHODS,
    TANGENT_WINDOW_FRACTION,
    CurveEstimate,
    auto_choice,
    end_curvature,
    end_tangents,
    hyper,
    straight_end,
    tangents,
    turning,
    turning_quick,
)
from pipeline.measure.extract import LineExtraction, NoLineFound, extract_centreline, region_mask
from pipeline.measure.formats import decode_image, read_image, undecodable
from pipeline.measure.quality import (
    Quality,
    assess,
    assess_body,
    start_seen,
    tip_out_of_reach,
    tip_seen_whole,
    tip_turn_deg,
)
from pipeline.measure.refine import refine_centreline
from pipeline.measure.settings import MeasureSettings

if TYPE_CHECKING:
    from pipeline.measure.body import EndFace

#: default estimator (see the package docstring for the measurements behind the choice)
DEFAULT_METHOD = "auto"
#: work on images whose longer side is at least this long (px); larger ones are decoded / reduced
#: by 2, 4 or 8 (the longer side, not the width: a photo taken upright is measured at the
#: resolution of the same photo taken across, as it is the same scene)
WORK_WIDTH_PX = 640
#: re-decode at twice the resolution when the line is thinner than this in the work image (px)
MIN_WORK_LINE_WIDTH_PX = 2.5
#: grey photos: the extraction runs on a further halved copy when that is at least this wide (px);
#: the centre line is then refined on the decoded image (:mod:`pipeline.measure.refine`)
COARSE_WIDTH_PX = 320
#: ... provided the line is at least this wide there (coarse px); else the decoded image is used
MIN_COARSE_LINE_WIDTH_PX = 1.2
#: seed of the random places of the ``paper`` estimators (deterministic output)
SEED = 20240


@dataclass(frozen=True)
class AngleResult:
    """The bending angle measured on one photo.

    Attributes
    ----------
    psi_deg : float
        Signed bending angle (deg); NaN when failed.
    kappa_per_mm : float
        Signed mean curvature (1/mm) = psi / l0; NaN when failed.
    length_mm : float
        Measured line length (mm); NaN without ``mm_per_px`` or when failed.
    method : str
        Estimator name.
    residual_px : float
        RMS misfit of the estimator's model (px, original image); NaN when it has none.
    status : str
        ``ok``, ``flagged`` or ``failed``.
    reason : str
        Why flagged / failed ('' when ok), '; '-separated.
    centreline_px : ndarray, shape (N, 2)
        Centre line (x right, y down, original px), fixed end first; empty when failed.
    line_width_px : float
        Width of the extracted line (original px); NaN when failed.
    length_px : float
        Measured line length (original px); NaN when failed.
    degree : int
        Complexity of the curve model the estimator used: 1 for a circular arc (constant
        curvature, also the ``paper`` averages), higher for the turning-angle series actually
        chosen (``turning``, and ``auto`` when it switched to it); 0 when failed.
    base_direction_deg : float
        A body's measured direction where it leaves the fixed end (deg, counter-clockwise from
        +x on screen, clockwise with ``positive_turn: cw``, so that psi is the free end's
        direction minus it; on the plane when calibrated): what
        :func:`pipeline.ramp_check.share_base_direction` compares across a ramp.  With
        ``fixed_direction_deg`` given psi is not measured from it, but it is still read where
        the body's start is seen (the ramp check compares the two).  NaN for a line, a body
        whose start is not seen with the direction given, or when failed.
    base_side_split_deg : float
        A body's two sides, where it leaves the fixed end, diverge by this (deg, + widening):
        :func:`pipeline.measure.body.base_side_split_deg`.  NaN for a line or when failed.
    tip_px : (float, float) or None
        A body's point where its free end's tangent was read (x right, y down, original px):
        the centre line's end, moved back along it or on along the tangent by what the tangent
        was carried (to the tip's face, or back to where a sealed end starts); None for a line or
        when failed.  The overlays draw the tip's direction from it.
    straight_end_mm : float
        A capped body's straight end seen on its centre line, with the tip's face beyond it (mm,
        :func:`~pipeline.measure.estimators.straight_end`): NaN where none shows, for a line,
        for ``free_end: bends`` and when failed.
    past_l0_mm : float
        How far a capped body, from its centre line's start to its tip's face, runs past
        ``l0_mm`` at the scale given (mm): its centre line's stretch as it bends plus the end
        that does not bend, which :func:`pipeline.sealed_end_check.end_past_l0_mm` tells apart
        over an actuator's photos.  NaN without ``mm_per_px`` (or a calibration), for a line,
        for ``free_end: bends`` and when failed.
    body_width_px : float
        A body's width, edge to edge across its centre line (median, original px): what
        ``body_width_mm`` is checked against; NaN for a line and when failed.
    """

    psi_deg: float
    kappa_per_mm: float
    length_mm: float
    method: str
    residual_px: float
    status: str
    reason: str
    centreline_px: np.ndarray
    line_width_px: float = float("nan")
    degree: int = 0
    length_px: float = float("nan")
    base_direction_deg: float = float("nan")
    base_side_split_deg: float = float("nan")
    tip_px: tuple[float, float] | None = None
    straight_end_mm: float = float("nan")
    past_l0_mm: float = float("nan")
    body_width_px: float = float("nan")


#: no actuator turns further than this (deg): a psi beyond it is a line that is not its own
MAX_PSI_DEG = 400.0


def failed(method: str, reason: str) -> AngleResult:
    """An :class:`AngleResult` for a photo that could not be measured."""
    nan = float("nan")
    return AngleResult(nan, nan, nan, method, nan, "failed", reason, np.empty((0, 2)))


def _measured(
    psi: float,
    est: CurveEstimate,
    line: LineExtraction,
    quality: Quality,
    settings: MeasureSettings,
    method: str,
) -> AngleResult:
    """The :class:`AngleResult` of a measured photo: psi, the fit ``est`` of ``line`` and its
    quality.

    ``settings`` are those the fit used (on a calibrated plane: the plane's ``mm_per_px``).
    A psi beyond :data:`MAX_PSI_DEG` is ``failed``: no actuator turns so far, the line measured
    is not its own (customer 36's clear body read -2006 deg, flagged, its "line length -283 %
    of its ramp's median").

    Examples
    --------
    >>> from pipeline.measure.quality import Quality
    >>> from pipeline.measure.settings import resolve_settings
    >>> est = CurveEstimate(0.0, 0.0, 100.0, 1.0, 1, 0.0)
    >>> line = LineExtraction(np.zeros((2, 2)), 5.0, False, 1, 100.0, 0.0, 0.0, False, False)
    >>> r = _measured(-2006.5, est, line, Quality("flagged", "wobbles"),
    ...               resolve_settings({"l0_mm": 100}), "tangents")
    >>> r.status, r.psi_deg, r.reason[:50]
    ('failed', nan, 'psi read -2006 deg, more than a full turn: the lin')
    """
    mm_per_px = settings.mm_per_px
    if abs(psi) > MAX_PSI_DEG:
        what = "body" if settings.target == "body" else "drawn line"
        return replace(
            failed(
                method,
                f"psi read {psi:+.0f} deg, more than a full turn: the line measured is not the "
                f"{what}'s (photoset preview shows what the settings select)"
                + (f"; {quality.reason}" if quality.reason else ""),
            ),
            centreline_px=line.centreline_px,
        )
    return AngleResult(
        psi_deg=psi,
        kappa_per_mm=float(np.deg2rad(psi) / settings.l0_mm),
        length_mm=float(est.length_px * mm_per_px) if mm_per_px else float("nan"),
        method=method,
        residual_px=est.residual_px,
        status=quality.status,
        reason=quality.reason,
        centreline_px=line.centreline_px,
        line_width_px=line.width_px,
        degree=int(est.degree),
        length_px=float(est.length_px),
    )


def reduction_for(size_px: Sequence[int], work_width_px: int = WORK_WIDTH_PX) -> int:
    """Largest factor in (1, 2, 4, 8) keeping the work image's longer side at least
    ``work_width_px`` long; ``size_px`` is the photo's (width, height) or (height, width).

    Examples
    --------
    >>> reduction_for((4000, 3000)), reduction_for((1280, 960)), reduction_for((960, 1280))
    (4, 2, 2)
    >>> reduction_for((640, 480)), reduction_for((4000, 3000), 320)
    (1, 8)
    """
    long_side = max(size_px[:2])
    f = 1
    while f < 8 and long_side / (2 * f) >= work_width_px:
        f *= 2
    return f


def _psi_from(
    est: CurveEstimate, sign: float, l0_mm: float, mm_per_px: float | None, length_px: float
) -> float:
    if mm_per_px:
        return float(np.rad2deg(sign * est.kappa_per_px / mm_per_px * l0_mm))
    return float(np.rad2deg(sign * est.kappa_per_px * length_px))


#: a body fewer than this many px across in the work image is measured again at other sizes ...
STEADY_WIDTH_PX = 12.0
#: ... these fractions of the work image's (INTER_AREA down, INTER_CUBIC up) ...
STEADY_RESIZES = (0.8, 1.25)
#: ... and flagged where psi moves more than this (deg) at one of them: on the real strips
#: (tests/data/xia2023_strips, the red layer 4-6 px across) shrunk to 0.75 or given noise, psi
#: moved 9-14 deg and stayed ok 12.5 deg off; so measured again, those rows moved 8.8-15 deg
STEADY_DEG = 5.0
#: a reading at another size whose line is more than this factor wider or narrower, or longer or
#: shorter, is of another object, and not compared
STEADY_SAME_WIDTH = 1.3
#: the words of that flag (a reduced photo is measured again finer where a row says them)
UNSTEADY = "too few for a steady reading"


def steady_reading(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    res: AngleResult,
    *,
    scale: float,
    method: str = DEFAULT_METHOD,
) -> AngleResult:
    """``res`` (an ``ok`` body measured on ``image_bgr``), flagged where the body is too few
    pixels across for a steady reading: measured again on the image resized to each of
    :data:`STEADY_RESIZES`, psi moves more than :data:`STEADY_DEG`, or the body is not found.

    A body a few pixels across is read from its outline's pixel steps: on real photos of thin
    strips a change of size, JPEG or noise that leaves the strip as it is moved psi 9-14 deg,
    with every check passed.  Rows not ``ok``, bodies at least :data:`STEADY_WIDTH_PX` across
    in the work image and drawn lines (refined on the finer image) are returned as they are.

    Examples
    --------
    A red arc of 90 deg, 8 px across (so measured again at 80 % and 125 %), reads steadily:

    >>> import cv2, numpy as np
    >>> from pipeline.measure.settings import resolve_settings
    >>> img = np.full((240, 320, 3), 40, np.uint8)
    >>> t = np.linspace(0.0, np.pi / 2, 100)
    >>> pts = np.c_[60 + 150 * np.sin(t), 200 - 150 * (1 - np.cos(t))]
    >>> _ = cv2.polylines(img, [np.round(pts * 16).astype(np.int32)], False, (40, 40, 220),
    ...                   5, cv2.LINE_AA, 4)
    >>> s = resolve_settings({"l0_mm": 50, "target": "body", "line_color": "red",
    ...                       "fixed_end": [60, 200], "free_end": "bends"})
    >>> r = measure_work_image(img, s, scale=1.0)
    >>> r.status, round(r.psi_deg), round(r.line_width_px) < STEADY_WIDTH_PX
    ('ok', 89, True)
    """
    if res.status != "ok" or image_bgr is None or res.line_width_px / scale >= STEADY_WIDTH_PX:
        return res
    moved: dict[float, float] = {}  # psi's move at each size compared (NaN: not found there)
    for k in STEADY_RESIZES:
        resized = cv2.resize(
            image_bgr, None, fx=k, fy=k, interpolation=cv2.INTER_AREA if k < 1 else cv2.INTER_CUBIC
        )
        again = measure_body(resized, settings, scale=scale / k, method=method)
        if again.status == "failed":
            moved[k] = float("nan")
        elif all(
            abs(np.log(a / b)) <= np.log(STEADY_SAME_WIDTH)
            for a, b in (
                (again.line_width_px, res.line_width_px),
                (again.length_px, res.length_px),
            )
        ):
            moved[k] = again.psi_deg - res.psi_deg
        # else another object was read there (the review: at 80 % the clamp block, 31 px wide
        # for a body of 8, "psi moves 71-171 deg" on 10 right rows): no evidence either way
    found = all(np.isfinite(list(moved.values())))
    worst = max((abs(m) for m in moved.values()), default=0.0)
    if found and worst <= STEADY_DEG:
        return res
    sizes = " / ".join(f"{100 * k:.0f}%" for k in moved)
    readings = ", ".join(
        "not found" if not np.isfinite(m) else f"{m:+.0f}" for m in moved.values()
    )
    what = (
        f"psi moves {worst:.0f} deg when the photo is measured at {sizes} of its size"
        if found
        else f"the body is not found when the photo is measured at {sizes} of its size"
    )
    flag = (
        f"{what} ({readings}): the body is only {res.line_width_px / scale:.0f} px across "
        f"here, {UNSTEADY}; photograph it larger (closer, or at a higher resolution)"
    )
    return replace(res, status="flagged", reason=flag + (f"; {res.reason}" if res.reason else ""))


def measure_work_image(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    *,
    scale: float,
    method: str = DEFAULT_METHOD,
    fine: np.ndarray | None = None,
    fine_scale: float = 1.0,
) -> AngleResult:
    """Measure an image already reduced by ``scale`` (original px per work px).

    Same parameters and result as :func:`measure_image`; used by :func:`measure_file`, which
    decodes JPEGs directly at reduced size.  With ``fine`` (a grey image reduced by
    ``fine_scale`` < ``scale``) the centre line extracted from ``image_bgr`` is refined on it
    before the curvature fit.
    """
    method = settings.method or method
    if method not in METHODS:
        raise ValueError(f"unknown method {method!r}; use one of {sorted(METHODS)}")
    if settings.target == "body":
        return steady_reading(
            image_bgr, settings, measure_body(image_bgr, settings, scale=scale, method=method),
            scale=scale, method=method,
        )
    l0_mm, mm_per_px = settings.l0_mm, settings.mm_per_px
    assert settings.color is not None
    region = (
        None
        if image_bgr is None
        else region_mask(image_bgr.shape, settings.roi, settings.exclude, scale)
    )
    try:
        line: LineExtraction = extract_centreline(
            image_bgr,
            color=settings.color,
            fixed_end_px=settings.fixed_end_px,
            scale=scale,
            region=region,
        )
    except NoLineFound as exc:
        return failed(method, str(exc))
    if fine is not None:
        refined = refine_centreline(
            fine, line.centreline_px, scale=fine_scale, half_width_px=0.5 * line.width_px
        )
        line = replace(line, centreline_px=refined)
    try:  # y-up: on-screen ccw is positive; calibrated: undistorted, on the plane (plane px)
        pts, ends, settings = plane_centreline(line, settings, image_bgr.shape, scale)
    except CalibrationMismatch as exc:
        return failed(method, str(exc))
    mm_per_px = settings.mm_per_px
    rng = np.random.default_rng(SEED)
    sign = settings.sign
    try:
        # the arc and quick turning fits serve the quality check
        arc = hyper(pts, rng, ends_px=ends)
        trn = turning_quick(pts, rng, ends_px=ends)
        if method == "hyper":
            est = arc
        elif method == "auto":
            est = auto_choice(pts, rng, arc, trn, ends_px=ends)
        else:
            est = METHODS[method](pts, rng, ends_px=ends)
    except (ValueError, np.linalg.LinAlgError) as exc:
        return failed(method, f"curvature fit failed: {exc}")
    length_px = est.length_px
    psi = _psi_from(est, sign, l0_mm, mm_per_px, length_px)
    if method in ("turning", "auto") and est is not arc and np.isfinite(est.neighbour_turning_rad):
        # the full turning fit was run: its quick linear proxy is too crude a check (it
        # extrapolates a polynomial to the ends); the fit with one term more or less is the check
        trn = CurveEstimate(
            est.neighbour_turning_rad / est.length_px,
            est.neighbour_turning_rad,
            est.length_px,
            est.residual_px,
            est.degree,
        )
    quality = assess(
        line,
        method=method,
        psi_deg=psi,
        length_px=length_px,
        expected_length_px=(l0_mm / mm_per_px) if mm_per_px else None,
        psi_turning_deg=_psi_from(trn, sign, l0_mm, mm_per_px, length_px),
        psi_arc_deg=_psi_from(arc, sign, l0_mm, mm_per_px, length_px),
        turning_degree=trn.degree,
    )
    return _measured(psi, est, line, quality, settings, method)


def _extended_ends(
    points: NDArray[np.float64], trimmed_px: tuple[float, float]
) -> NDArray[np.float64]:
    """The two ends of the measured line: the first/last point carried on by the trimmed lengths."""
    out = []
    for end, nxt, trim in ((points[0], points[min(3, len(points) - 1)], trimmed_px[0]),
                           (points[-1], points[max(len(points) - 4, 0)], trimmed_px[1])):
        d = end - nxt
        n = float(np.hypot(*d))
        out.append(end + (d / n * trim if n > 0 else 0.0))
    return np.asarray(out)


def plane_centreline(
    line: LineExtraction, settings: MeasureSettings, shape: Sequence[int], scale: float
) -> tuple[NDArray[np.float64], tuple[float, float], MeasureSettings]:
    """The centre line as the estimators take it: y up, and on the plane when the photo is
    calibrated.

    Parameters
    ----------
    line : LineExtraction
        The extracted (and refined) centre line, original image px.
    settings : MeasureSettings
        The photo's settings.
    shape : sequence of int
        Shape of the work image (rows, columns, ...).
    scale : float
        Original px per work px.

    Returns
    -------
    points : ndarray (N, 2)
        Centre line in a y-up frame: image px, or plane px when calibrated.
    ends_px : (float, float)
        Length of the line beyond the first and the last point, in the same units.
    settings : MeasureSettings
        Unchanged without a calibration; else with ``mm_per_px`` the plane px size and
        ``fixed_direction_deg`` turned to the plane.

    Raises
    ------
    CalibrationMismatch
        When the photo has another resolution than the board photo.
    """
    flip = np.array([1.0, -1.0])
    cal = settings.calibration
    if cal is None or cal.plane is None:
        return line.centreline_px * flip, line.trimmed_px, settings
    plane = cal.plane
    check_size(plane, shape, scale, f"the board photo {Path(cal.boards[0]).name}")
    pts = line.centreline_px
    q = plane.to_plane(pts)
    ends_img = _extended_ends(pts, line.trimmed_px)
    ends_q = plane.to_plane(ends_img)
    ends = (float(np.hypot(*(ends_q[0] - q[0]))), float(np.hypot(*(ends_q[1] - q[-1]))))
    direction = settings.fixed_direction_deg
    if direction is not None:
        a = np.deg2rad(direction)
        d = plane.to_plane([pts[0], pts[0] + 10.0 * np.array([np.cos(a), -np.sin(a)])])
        direction = float(np.rad2deg(np.arctan2(-(d[1, 1] - d[0, 1]), d[1, 0] - d[0, 0])))
    return (
        q * flip,
        ends,
        replace(settings, mm_per_px=plane.mm_per_px, fixed_direction_deg=direction),
    )


def load_background(path: str, shape: tuple[int, int]) -> np.ndarray | str:
    """The empty-scene photo, resized to the work image (cached per worker: one decode, again
    when the file changes), or why it cannot be used."""
    try:
        stamp = os.stat(path)
        return _load_background(path, shape, (stamp.st_mtime_ns, stamp.st_size))
    except OSError:
        return _load_background(path, shape, None)


@functools.lru_cache(maxsize=4)
def _load_background(
    path: str, shape: tuple[int, int], stamp: tuple[int, int] | None
) -> np.ndarray | str:
    """:func:`load_background` of the file as it was at ``stamp`` (its mtime and size): a photo
    of the empty scene replaced between two measurements in one process was read as the old one
    (and, with ``measure --cache``, stored as measured against the new one)."""
    img = read_image(path)
    name = Path(path).name
    if img is None:
        return "background photo {} cannot be decoded ({}; {})".format(name, *undecodable(name))
    bh, bw = img.shape[:2]
    if not same_aspect((bw, bh), (shape[1], shape[0])):
        return (
            f"background photo {name} is {bw}x{bh} px, another shape than the photo"
            + (
                " (turned by 90 deg: an orientation tag lost?)"
                if turned_by_90((bw, bh), (shape[1], shape[0]))
                else ""
            )
            + ": take the empty scene with the camera, resolution and orientation of the photos"
        )
    return cv2.resize(img, (shape[1], shape[0]), interpolation=cv2.INTER_AREA)


def turned_by_90(size_a: Sequence[int], size_b: Sequence[int]) -> bool:
    """Whether an image (width, height) ``size_a`` has the shape of ``size_b`` turned by 90 deg
    (an orientation tag lost, or applied to one and not the other); a near-square one says
    nothing.

    Examples
    --------
    >>> turned_by_90((3024, 4032), (4032, 3024)), turned_by_90((1000, 990), (990, 1000))
    (True, False)
    """
    return same_aspect((size_a[1], size_a[0]), size_b) and not same_aspect(
        size_a, (size_a[1], size_a[0]), 0.04
    )


def same_aspect(size_a: Sequence[int], size_b: Sequence[int], tolerance: float = 0.02) -> bool:
    """Whether two images (width, height) have the same shape up to ``tolerance`` (relative; a
    reduced work image loses up to a pixel of each side).

    Examples
    --------
    >>> same_aspect((4000, 3000), (1000, 750)), same_aspect((1920, 1080), (1280, 960))
    (True, False)
    >>> same_aspect((3000, 4000), (4000, 3000))
    False
    """
    ra, rb = size_a[0] / max(size_a[1], 1), size_b[0] / max(size_b[1], 1)
    return abs(ra - rb) <= tolerance * rb


def measure_body(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    *,
    scale: float,
    method: str = DEFAULT_METHOD,
    faint_sides: bool = True,
) -> AngleResult:
    """psi of the actuator's body (``target: body``): its centre line's total turning.

    ``auto`` is :func:`~pipeline.measure.estimators.tangents` here (the tip angle: a body is
    rarely an arc); any other method may be asked for.  A known ``fixed_direction_deg`` replaces
    the measured base tangent.  ``faint_sides``: see :func:`pipeline.measure.body.body_mask`; a
    reading that took a faint side in and is not ``ok`` gives way to the one without it, unless
    that fails (what was read before faint sides were taken in: a small patch of a faint side
    taken in at the tip alone made a hook, and customer 56 lost 2 rows right before).
    """
    from pipeline.measure.body import base_side_split_deg, extract_body

    background = None
    if settings.background_path is not None and image_bgr is not None:
        loaded = load_background(settings.background_path, image_bgr.shape[:2])
        if isinstance(loaded, str):
            return failed(method, loaded)
        background = loaded
    try:
        body = extract_body(
            image_bgr, settings, scale=scale, background_bgr=background, faint_sides=faint_sides
        )
    except NoLineFound as exc:
        return failed(method, str(exc))
    line = body.line
    # ends: the tangents are carried to the clamp face and to the tip (not over a cap); calibrated:
    # on the plane
    try:
        pts, ends, settings = plane_centreline(line, settings, image_bgr.shape, scale)
    except CalibrationMismatch as exc:
        return failed(method, str(exc))
    per_image_px = _work_per_image_px(line, pts)
    # edge to edge across the centre line (the ridge's distance to the edge reads a px or two
    # wide: 16 px for a body 12 across)
    body_width_px = (
        float(np.nanmedian(body.widths_px)) if np.isfinite(body.widths_px).any() else float("nan")
    )
    # the body from the fixed end to its tip's face, in the units of pts
    seen_work_px = float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))
    body_work_px = seen_work_px + body.tip_face_px * per_image_px
    # ... and how far that runs past l0_mm at the scale given, from the centre line's start (not
    # carried back to fixed_end: clicked 2.8 mm inside the clamp, customer 53's right 4 mm end
    # read 7, and 11 rows were flagged, 6 of them right) to the tip's face
    past_l0_mm = (
        body_work_px * settings.mm_per_px - settings.l0_mm
        if settings.mm_per_px and settings.free_end == "capped"
        else float("nan")
    )
    mm_per_work_px = settings.mm_per_px or length_scale_mm_per_px(
        body_work_px, settings.l0_mm + (settings.sealed_end_mm or 0.0)
    )
    # the straight end seen on the centre line, and the tip's face beyond it (mm): checked
    # against sealed_end_mm over the actuator's photos (pipeline.sealed_end_check)
    straight_px = straight_end(pts) if settings.free_end == "capped" else float("nan")
    straight_px += body.tip_face_px * per_image_px
    straight_end_mm = straight_px * (
        mm_per_work_px
        if settings.mm_per_px or settings.sealed_end_mm is not None
        # l0_mm is the body's length less the straight end
        else length_scale_mm_per_px(body_work_px - straight_px, settings.l0_mm)
    )
    sealed_px = 0.0  # the known sealed end, image px
    if settings.sealed_end_mm is not None:
        sealed_px = settings.sealed_end_mm / mm_per_work_px / per_image_px
        ends = _read_before_sealed_end(body.tip_face_px, ends, sealed_px, per_image_px)
        if body.tip_capped:
            # the centre line stopped at a cap, which does not bend: a sealed end given shorter
            # than the cap (the cap forgotten) carried the tip's tangent on over it (|psi| 6-12
            # deg high on rendered capped bodies at psi ~ 215 deg)
            ends = (ends[0], min(ends[1], 0.0))
    # the part of the body past the centre line's end, less what is not bend (half a width of
    # cap, the stretch already carried on to a cut end, the sealed end), turned through at the
    # free end's curvature (image axes, deg)
    missed_tip_deg = float(
        np.rad2deg(end_curvature(line.centreline_px))
        * max(0.0, body.end_short_px - max(0.5 * line.width_px, line.trimmed_px[1], sealed_px))
    )
    out_of_reach = tip_out_of_reach(body.end_short_px, line.width_px)
    if settings.sealed_end_mm is not None and tip_turn_deg(
        body.ridge_tip_deg, missed_tip_deg, out_of_reach=out_of_reach
    ):
        # psi is carried on over the tip the centre line stops short of (carried_on_psi_deg,
        # below): its tangent is not also carried on to where the bending stops (twice the turn)
        ends = (ends[0], min(ends[1], 0.0))
    if seen_work_px + ends[0] + ends[1] <= 0.0:
        # read before a sealed end longer than the centre line found: nothing of the bending part
        # is seen, and its length read negative (customer 33's clear body: -8 px, psi -222)
        return failed(
            method,
            "no body found: what is selected is shorter than the sealed end (sealed_end_mm), a "
            "piece of the body, not all of it; check with photoset preview (a clear or faint body "
            "needs its empty scene: background)",
        )
    rng = np.random.default_rng(SEED)
    base = (
        None if settings.fixed_direction_deg is None else np.deg2rad(settings.fixed_direction_deg)
    )
    # a chambered body's own start is its first chamber's side: it leaves the clamp along its
    # strip's edge (customer 48's PneuNets, by their centre lines: 16 of 22 rows "-20 to -42 deg
    # off fixed_direction_deg", right ones among them), which checks a direction given.  Not
    # psi's base without one: read on one edge, carried back to the clamp, it read psi 8-27
    # deg off, ok, in the review (a fixed end clicked inside the clamp, a bend of 240 deg)
    strip = _face_direction(body.base_edge, settings) if body.chambered else float("nan")
    try:
        tip = tangents(pts, rng, ends_px=ends, base_rad=base)
        free = tangents(pts, rng, ends_px=ends) if base is not None else tip
        est = (
            tip
            if method in ("auto", "tangents") or base is not None
            else METHODS[method](pts, rng, ends_px=line.trimmed_px)
        )
    except (ValueError, np.linalg.LinAlgError) as exc:
        return failed(method, f"curvature fit failed: {exc}")
    sign = settings.sign
    # a flat end face's normal is the tip's direction, where the centre line stops short of it
    start, end, _ = end_tangents(pts, ends_px=ends)
    face_turn = float("nan")
    if body.tip_face is not None:
        seen_px = float(np.sum(np.hypot(*np.diff(line.centreline_px, axis=0).T)))
        # the way the body bends (its turning's sign: a hooked centre line's end may curve either
        # way) at the free end's curvature, or the body's mean where that is more (a tip the
        # centre line follows badly reads straight)
        curvature = np.sign(tip.turning_rad) * max(
            abs(end_curvature(line.centreline_px)), abs(tip.turning_rad) / max(seen_px, 1.0)
        )
        face_turn = tip_face_turn_rad(
            _face_direction(body.tip_face, settings) - end,
            curvature * (body.end_short_px + 0.5 * line.width_px),
        )
    # ... where that face is the body's own end, not where the selection fades, and the end
    # that does not bend is not given (the tip is then read where it begins; not on a row of
    # chambers, whose centre line's end is a chamber's side)
    face_used = (
        est is tip
        and (settings.sealed_end_mm is None or body.chambered)
        and bool(np.isfinite(face_turn))
        and tip_seen_whole(
            body.end_short_px, line.width_px, body.free_end_width_ratio, body.ridge_tip_deg
        )
    )
    if face_used:
        # the check of the tip's window is moot with the tip read on its face: the fixed end's
        # alone stays (the change of its direction over a window twice as long)
        base_shift = start - end_tangents(
            pts, ends_px=ends, window_fraction=2 * TANGENT_WINDOW_FRACTION
        )[0]
        turned = _turned(tip, face_turn, 0.0 if base is not None else base_shift)
        free = turned if free is tip else _turned(free, face_turn, base_shift)
        est = tip = turned
    # the same turning from a smooth fit of the whole centre line: the check of a wobbly line.
    # With the base known psi does not depend on the fixed end, so neither reading is carried
    # back over a stretch the centre line stops short of there (on a long one a fit runs away)
    check_ends = ends if base is None else (0.0, ends[1])
    check_start, check_end, _ = end_tangents(pts, ends_px=check_ends)
    try:
        smooth_turning = turning(pts, np.random.default_rng(SEED), ends_px=check_ends).turning_rad
    except (ValueError, np.linalg.LinAlgError):
        smooth_turning = check_end - check_start  # too short a line for the fit: no check
    psi = float(np.rad2deg(sign * est.turning_rad))
    mismatch = None if base is None else float(np.rad2deg(free.turning_rad - tip.turning_rad))
    own_start = start  # what psi is measured from without a direction given
    if body.chambered and base is not None:  # its own is its strip's, which checks the one given
        own_start = strip
        mismatch = (
            float(np.rad2deg(np.angle(np.exp(1j * (base - strip))))) if np.isfinite(strip) else 0.0
        )
    # each end fitted over half its window: a hook in its last pixels (the clamp, the tip)
    start_short, end_short, _ = end_tangents(
        pts, ends_px=ends, window_fraction=0.5 * TANGENT_WINDOW_FRACTION
    )
    short_shift = (
        0.0 if base is not None else float(np.rad2deg(start_short - start)),
        0.0 if face_used else float(np.rad2deg(end_short - end)),
    )
    if face_used:  # the tip is read on its face: the turn of what the centre line misses is moot
        missed_tip_deg = 0.0
    quality = assess_body(
        line,
        psi_deg=psi,
        psi_check_deg=float(
            np.rad2deg(sign * (tip.neighbour_turning_rad if est is tip else est.turning_rad))
        ),
        widths_px=body.widths_px,
        expected_length_px=settings.l0_mm / settings.mm_per_px if settings.mm_per_px else None,
        length_px=est.length_px,
        base_mismatch_deg=mismatch,
        fixed_direction_deg=settings.fixed_direction_deg,
        selected_fraction=body.selected_fraction,
        continues=body.continues,
        start_gap_px=body.start_gap_px,
        end_short_px=body.end_short_px,
        ridge_tip_deg=body.ridge_tip_deg,
        free_end_width_ratio=body.free_end_width_ratio,
        side_on_border=body.side_on_border,
        tip_at_region_edge=body.tip_at_region_edge,
        background_estimated=settings.background_estimated,
        background_given=settings.background_path is not None and not settings.background_estimated,
        video_frame=settings.video_frame,
        missed_tip_deg=missed_tip_deg,
        # with the base given and the tip read on its face psi does not depend on the centre
        # line's course (a chambered body's is a polygon, one side per chamber)
        smooth_mismatch_deg=0.0
        if face_used and base is not None
        else float(np.rad2deg(sign * (smooth_turning - (check_end - check_start)))),
        short_end_shift_deg=short_shift,
        excluded=bool(settings.exclude),
        hollow_outline=body.hollow_outline,
        sealed_end_unknown=settings.sealed_end_mm is None
        and settings.free_end == "capped"
        and not face_used,
        tip_face_turn_deg=float(np.rad2deg(sign * face_turn)) if face_used else None,
        chambered=body.chambered,
        sealed_end_px=(settings.sealed_end_mm or 0.0) / settings.mm_per_px
        if settings.mm_per_px
        else 0.0,
        method=method,
        psi_tip_deg=None if est is tip else float(np.rad2deg(sign * tip.turning_rad)),
        excluded_start_deg=float(
            np.rad2deg(abs(end_curvature(pts[::-1])) * body.excluded_start_px * per_image_px)
        )
        if base is None and body.excluded_start_px > 0
        else 0.0,
        excluded_start_px=body.excluded_start_px,
        faint_share=body.faint_share,
        width_mm=(body_width_px * settings.mm_per_px, settings.body_width_mm)
        if settings.body_width_mm and settings.mm_per_px and settings.calibration is None
        else None,
    )
    used = "tangents" if method == "auto" or base is not None else method
    # carried on over a tip the selection fades at, not past an uneven outline (unless along
    # the selection's ridge)
    measured = _measured(
        carried_on_psi_deg(
            psi, body.ridge_tip_deg, missed_tip_deg, sign, out_of_reach=out_of_reach
        ),
        est, line, quality, settings, used,
    )
    own_base_deg = float(np.rad2deg(sign * own_start))
    measured = replace(
        measured,
        # a chambered body's own base is its strip's edge alone (its other side a comb)
        base_side_split_deg=float("nan")
        if body.chambered
        else base_side_split_deg(line.centreline_px, body.widths_px, TANGENT_WINDOW_FRACTION),
        straight_end_mm=straight_end_mm if measured.status != "failed" else float("nan"),
        past_l0_mm=past_l0_mm if measured.status != "failed" else float("nan"),
        body_width_px=body_width_px if measured.status != "failed" else float("nan"),
    )
    if est is tip:
        tip_px = (
            body.tip_face.middle_px
            if face_used and body.tip_face is not None
            else read_point_px(line.centreline_px, ends[1] / _work_per_image_px(line, pts))
        )
        # the body's own base, beside the one given: where its start is seen
        seen = base is None or start_seen(body.start_gap_px, line.width_px) or body.chambered
        measured = replace(
            measured, base_direction_deg=own_base_deg if seen else float("nan"), tip_px=tip_px
        )
    if measured.status == "ok" or not body.faint_taken:
        return measured
    plain = measure_body(image_bgr, settings, scale=scale, method=method, faint_sides=False)
    return measured if plain.status == "failed" else plain


#: a flat end face's normal is taken for the tip's direction when it turns the centre line's
#: tip direction on the way the body bends by no more than the part of the body the centre line
#: does not cover turns at the free end's curvature, plus FACE_AGREE_DEG, and back by no more
#: than FACE_BACK_DEG: past the centre line's end a body bends on or runs straight (a sealed
#: end, a cap).  Else the face is not square to the body (a slanted cut, a dot or a shadow on
#: it, a clear body's faint corner: rendered clear bodies' faces turned psi back 2-8 deg) and the
#: centre line's direction stands
FACE_AGREE_DEG, FACE_BACK_DEG = 3.0, 1.0


def tip_face_turn_rad(turn_rad: float, expected_rad: float) -> float:
    """The turn from the centre line's tip direction to the end face's normal (rad, wrapped to
    +-pi), when it is one the uncovered tip can make: between 0 and ``expected_rad`` (the turn of
    the uncovered part at the free end's curvature, signed) within :data:`FACE_AGREE_DEG` past
    it and :data:`FACE_BACK_DEG` back; NaN otherwise (and where there is no flat face:
    ``turn_rad`` NaN).

    Examples
    --------
    >>> round(tip_face_turn_rad(np.deg2rad(14.0 - 360.0), np.deg2rad(15.0)), 4)
    0.2443
    >>> tip_face_turn_rad(np.deg2rad(19.0), np.deg2rad(15.0))  # more than 15 + 3 deg
    nan
    >>> tip_face_turn_rad(np.deg2rad(-4.0), np.deg2rad(15.0))  # back against the bend
    nan
    """
    turn = float((turn_rad + np.pi) % (2.0 * np.pi) - np.pi)
    agree, back = np.deg2rad(FACE_AGREE_DEG), np.deg2rad(FACE_BACK_DEG)
    low, high = (-back, expected_rad + agree) if expected_rad >= 0 else (expected_rad - agree, back)
    return turn if low <= turn <= high else float("nan")


def _face_direction(face: EndFace | None, settings: MeasureSettings) -> float:
    """The tip face's normal as the estimators take directions: y up, on the plane when the
    photo is calibrated (rad; NaN without a face)."""
    if face is None:
        return float("nan")
    cal = settings.calibration
    if cal is None or cal.plane is None:
        return -face.direction_rad
    at = np.asarray(face.middle_px, float)
    out = np.array([np.cos(face.direction_rad), np.sin(face.direction_rad)])
    d = cal.plane.to_plane([at, at + 10.0 * out])
    return float(np.arctan2(-(d[1, 1] - d[0, 1]), d[1, 0] - d[0, 0]))


def _turned(est: CurveEstimate, turn_rad: float, base_shift_rad: float) -> CurveEstimate:
    """``est`` with its free end turned on by ``turn_rad`` to the face's direction, and its
    check the same turning from the fixed end's direction over a longer window (shifted by
    ``base_shift_rad``)."""
    turning = est.turning_rad + turn_rad
    return replace(
        est,
        turning_rad=turning,
        kappa_per_px=turning / est.length_px if est.length_px else est.kappa_per_px,
        neighbour_turning_rad=turning + base_shift_rad,
    )


def read_point_px(centreline_px: NDArray[np.float64], beyond_px: float) -> tuple[float, float]:
    """The point ``beyond_px`` past a centre line's last point: back along the line when
    negative, on along its last direction (over its last 10 px) when positive (image px).

    Examples
    --------
    >>> line = np.c_[np.arange(0.0, 101.0), np.zeros(101)]
    >>> read_point_px(line, -30.0), read_point_px(line, 12.0), read_point_px(line, -500.0)
    ((70.0, 0.0), (112.0, 0.0), (0.0, 0.0))
    """
    pts = np.asarray(centreline_px, float)
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    if beyond_px <= 0:
        at = max(s[-1] + beyond_px, 0.0)
        return float(np.interp(at, s, pts[:, 0])), float(np.interp(at, s, pts[:, 1]))
    back = np.array([np.interp(s[-1] - 10.0, s, pts[:, 0]), np.interp(s[-1] - 10.0, s, pts[:, 1])])
    step = pts[-1] - back
    unit = step / max(float(np.hypot(*step)), 1e-9)
    x, y = pts[-1] + beyond_px * unit
    return float(x), float(y)


def carried_on_psi_deg(
    psi_deg: float,
    ridge_tip_deg: float,
    missed_tip_deg: float,
    sign: float,
    *,
    out_of_reach: bool = False,
) -> float:
    """psi with the free end carried on over the part of the body the centre line stops short
    of (the row is flagged for either; else ``psi_deg`` unchanged).

    Along the selection's ridge, when the ridge turns on by more than
    :data:`~pipeline.measure.quality.RIDGE_TIP_DEG`
    (``ridge_tip_deg``: on the rendered analogues, 384 photos over three sizes and four camera
    faults, it moved 13 flagged rows from a total of 370 deg off to 120); the ridge is followed
    only to :data:`~pipeline.measure.body.RIDGE_TIP_HALF_WIDTHS` half-widths short of its end, so
    where the free end's curvature turns the whole uncovered part further the same way
    (``missed_tip_deg``), that turn is taken (:func:`~pipeline.measure.quality.tip_turn_deg`).
    Else at the free end's curvature, when that turns the uncovered part by more than
    :data:`~pipeline.measure.quality.TIP_UNSTABLE_DEG` and the tip is within reach
    (``out_of_reach``: see :func:`~pipeline.measure.quality.tip_out_of_reach`; a faint tip the
    selection does not reach, whose ridge is lost with it).  Both turns are in image axes (y
    down), ``sign`` the photo's ``+1``/``-1`` (``positive_turn``).

    Examples
    --------
    >>> carried_on_psi_deg(-56.0, 39.0, 0.0, 1.0), carried_on_psi_deg(-56.0, 3.0, 0.0, 1.0)
    (-95.0, -56.0)
    >>> carried_on_psi_deg(56.0, 39.0, 0.0, -1.0), carried_on_psi_deg(-188.0, 0.0, 13.0, 1.0)
    (95.0, -201.0)
    >>> carried_on_psi_deg(-160.0, 13.0, 32.0, 1.0), carried_on_psi_deg(-188.0, 0.0, 13.0, 1.0,
    ...                                                                   out_of_reach=True)
    (-192.0, -188.0)
    """
    return psi_deg - sign * tip_turn_deg(ridge_tip_deg, missed_tip_deg, out_of_reach=out_of_reach)


def _work_per_image_px(line: LineExtraction, points: NDArray[np.float64]) -> float:
    """Length units of ``points`` (the centre line as the estimators take it: image px, or plane
    px when calibrated) per image px of ``line``.

    Examples
    --------
    >>> from pipeline.measure.extract import LineExtraction
    >>> line = LineExtraction(np.c_[np.arange(10.0), np.zeros(10)], 4.0, False, 1, 100.0, 9.0,
    ...                       0.0, False, True, (0.0, 0.0))
    >>> _work_per_image_px(line, 2.0 * line.centreline_px * [1, -1])
    2.0
    """
    image_len = float(np.sum(np.hypot(*np.diff(line.centreline_px, axis=0).T)))
    work_len = float(np.sum(np.hypot(*np.diff(points, axis=0).T)))
    return work_len / image_len if image_len > 0 else 1.0


def length_scale_mm_per_px(body_px: float, body_mm: float) -> float:
    """The scale of a photo without ``mm_per_px``: the body's length along its centre line, from
    the fixed end to its tip's face, against its length in mm (``l0_mm + sealed_end_mm``).

    The centre line runs half the body's width beside the layer that does not stretch, so as the
    body bends it is shorter (bending towards its own side) or longer than that layer: by 10 %
    for a body 1/20 as wide as it is long at psi = 220 deg. The scale is used for the sealed end
    only, whose read-off place it moves by as much (a pixel or two).

    Examples
    --------
    >>> length_scale_mm_per_px(1000.0, 300.0)
    0.3
    """
    return body_mm / body_px if body_px > 0 else float("nan")


def _read_before_sealed_end(
    tip_face_px: float, ends: tuple[float, float], sealed_px: float, per_image_px: float = 1.0
) -> tuple[float, float]:
    """The end lengths with the free end's moved to where the bending stops: ``sealed_px`` (image
    px) back from the tip's face, which lies ``tip_face_px`` (image px) beyond the centre line's
    end.

    The free end's tangent is then read there: inside the centre line when it runs on into the
    sealed end (its last pixels carry the curvature on over a part that does not bend: 5-7 deg
    high at |psi| > 150 deg for a 12 mm sealed end on rendered bodies), carried on when it stops
    short of where the bending stops.  ``ends`` and the result are in the estimators' units,
    ``per_image_px`` of them per image px.

    Examples
    --------
    >>> _read_before_sealed_end(10.0, (3.0, 0.0), 16.0)
    (3.0, -6.0)
    >>> _read_before_sealed_end(10.0, (6.0, 0.0), 16.0, per_image_px=2.0)
    (6.0, -12.0)
    """
    return ends[0], (tip_face_px - sealed_px) * per_image_px


def measure_image(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    *,
    method: str = DEFAULT_METHOD,
    work_width_px: int = WORK_WIDTH_PX,
) -> AngleResult:
    """Measure the signed bending angle psi of the marker line in one photo.

    Parameters
    ----------
    image_bgr : ndarray, shape (H, W, 3), uint8
        The photo (OpenCV BGR).
    settings : MeasureSettings
        How to measure it (l0, scale, colour, fixed end, sign, ...), see
        :func:`pipeline.measure.settings.resolve_settings`.
    method : str
        Estimator, a key of :data:`pipeline.measure.METHODS`.
    work_width_px : int
        Images at least twice this wide are reduced (INTER_AREA) by 2, 4 or 8 before the work
        (less when the line would come out thinner than ``MIN_WORK_LINE_WIDTH_PX``).

    Returns
    -------
    AngleResult
        Never raises on a bad photo: ``status="failed"`` with the reason instead.

    Examples
    --------
    >>> import cv2, numpy as np
    >>> from pipeline.measure.settings import resolve_settings
    >>> img = np.full((480, 640, 3), 200, np.uint8)
    >>> t = np.linspace(0, np.pi, 200)                      # half circle, radius 150 px
    >>> pts = np.c_[320 + 150 * np.cos(t), 300 - 150 * np.sin(t)]
    >>> line = [np.round(pts * 16).astype(np.int32)]
    >>> _ = cv2.polylines(img, line, False, (20, 20, 20), 5, cv2.LINE_AA, 4)
    >>> s = resolve_settings(l0_mm=150 * np.pi, mm_per_px=1.0, fixed_end=[470, 300])
    >>> r = measure_image(img, s)
    >>> print(round(r.psi_deg), r.status)
    180 ok
    """
    if image_bgr is None or image_bgr.ndim != 3:
        return measure_work_image(image_bgr, settings, scale=1.0, method=method)
    f = reduction_for(image_bgr.shape, work_width_px)
    res = measure_work_image(reduce_image(image_bgr, f), settings, scale=float(f), method=method)
    return _refined(
        res,
        f,
        lambda finer: (
            measure_work_image(
                reduce_image(image_bgr, finer), settings, scale=float(finer), method=method
            ),
            finer,
        ),
        body=settings.target == "body",
    )


_REDUCED = {
    1: cv2.IMREAD_COLOR,
    2: cv2.IMREAD_REDUCED_COLOR_2,
    4: cv2.IMREAD_REDUCED_COLOR_4,
    8: cv2.IMREAD_REDUCED_COLOR_8,
}
_REDUCED_GREY = {
    1: cv2.IMREAD_GRAYSCALE, 2: cv2.IMREAD_REDUCED_GRAYSCALE_2, 4: cv2.IMREAD_REDUCED_GRAYSCALE_4,
    8: cv2.IMREAD_REDUCED_GRAYSCALE_8,
}


def jpeg_size(data: bytes | np.ndarray) -> tuple[int, int] | None:
    """(width, height) of a JPEG as OpenCV decodes it, from its headers; None if not a JPEG.

    The frame header gives the stored size; an EXIF orientation that turns the picture by 90 deg
    (5-8: how a phone stores a portrait photo) swaps it, since OpenCV decodes the photo turned
    upright (so the pixel coordinates a user reads off an image viewer are that size's).  The
    headers are walked to the frame header however long the metadata before it (EXIF with a
    thumbnail, ICC profiles and maker notes often pass 64 KB).

    Examples
    --------
    >>> import cv2, numpy as np
    >>> ok, buf = cv2.imencode(".jpg", np.zeros((30, 40, 3), np.uint8))
    >>> jpeg_size(buf.tobytes())
    (40, 30)
    """
    b = (
        np.ascontiguousarray(data, dtype=np.uint8).reshape(-1).data
        if isinstance(data, np.ndarray)
        else memoryview(data)
    )
    if bytes(b[:2]) != b"\xff\xd8":
        return None
    orientation = 1
    i = 2
    while i + 9 < len(b):
        if b[i] != 0xFF:
            return None
        marker = b[i + 1]
        if marker == 0xFF:
            i += 1
            continue
        seg = int.from_bytes(b[i + 2 : i + 4], "big")
        if marker == 0xE1 and bytes(b[i + 4 : i + 10]) == b"Exif\x00\x00":
            orientation = _exif_orientation(bytes(b[i + 10 : i + 2 + seg]))
        if 0xC0 <= marker <= 0xCF and marker not in (0xC4, 0xC8, 0xCC):
            h = int.from_bytes(b[i + 5 : i + 7], "big")
            w = int.from_bytes(b[i + 7 : i + 9], "big")
            return (h, w) if orientation in (5, 6, 7, 8) else (w, h)
        i += 2 + seg
    return None


def _exif_orientation(tiff: bytes) -> int:
    """The EXIF orientation tag (0x0112) of IFD0 in a TIFF block; 1 (upright) if absent."""
    if tiff[:2] not in (b"II", b"MM") or len(tiff) < 8:
        return 1
    order: Literal["little", "big"] = "little" if tiff[:2] == b"II" else "big"
    ifd = int.from_bytes(tiff[4:8], order)
    if ifd + 2 > len(tiff):
        return 1
    for k in range(int.from_bytes(tiff[ifd : ifd + 2], order)):
        e = ifd + 2 + 12 * k
        if e + 12 > len(tiff):
            break
        if int.from_bytes(tiff[e : e + 2], order) == 0x0112:
            return int.from_bytes(tiff[e + 8 : e + 10], order)
    return 1


def decode_for_work(
    data: np.ndarray,
    work_width_px: int = WORK_WIDTH_PX,
    factor: int | None = None,
    grey: bool = False,
) -> tuple[np.ndarray | None, int]:
    """Decode image bytes, directly at reduced size for large JPEGs (DCT scaling: much faster).

    Parameters
    ----------
    data : ndarray of uint8
        The file's bytes.
    work_width_px : int
        See :func:`reduction_for`.
    factor : int, optional
        Force this reduction (1, 2, 4 or 8) for a JPEG.
    grey : bool
        Decode only the luma (enough for a black line; skips chroma and colour conversion).

    Returns
    -------
    image : ndarray or None
        BGR image, None if it cannot be decoded.
    factor : int
        Original px per decoded px.
    """
    size = jpeg_size(data)
    if size is not None:
        f = factor if factor is not None else reduction_for(size, work_width_px)
        return cv2.imdecode(data, (_REDUCED_GREY if grey else _REDUCED)[f]), f
    img = decode_image(data, grey)
    if img is None:
        return None, 1
    f = factor if factor is not None else reduction_for(img.shape, work_width_px)
    return reduce_image(img, f), f


def reduce_image(image: np.ndarray, factor: int) -> np.ndarray:
    """``image`` reduced ``factor`` times in each direction (INTER_AREA); itself for ``factor`` <=
    1."""
    if factor <= 1:
        return image
    return cv2.resize(
        image, (image.shape[1] // factor, image.shape[0] // factor), interpolation=cv2.INTER_AREA
    )


def decodes_grey(settings: MeasureSettings) -> bool:
    """Whether a grey (luma) decoding is enough: a black drawn line, nothing needing colour."""
    return settings.target == "line" and settings.color is not None and settings.color.dark_line


def measure_file(
    path: str | Path,
    settings: MeasureSettings,
    *,
    method: str = DEFAULT_METHOD,
    work_width_px: int = WORK_WIDTH_PX,
) -> tuple[AngleResult, float]:
    """Read and measure one image file; never raises on a bad image.

    Returns
    -------
    result : AngleResult
    seconds : float
        Wall time of reading + measuring.
    """
    t0 = time.perf_counter()
    try:
        data = np.fromfile(str(path), dtype=np.uint8)
    except OSError as exc:
        return failed(method, f"unreadable image: {exc.strerror or exc}"), time.perf_counter() - t0
    img, f = (
        decode_for_work(data, work_width_px, grey=decodes_grey(settings))
        if data.size
        else (None, 1)
    )
    if img is None:
        return failed(
            method, f"unreadable image: {Path(path).name} cannot be decoded"
        ), time.perf_counter() - t0
    return measure_decoded(data, img, f, settings, method=method), time.perf_counter() - t0


def _refined(
    res: AngleResult,
    factor: int,
    finer_reading: Callable[[int], tuple[AngleResult, int] | None],
    *,
    body: bool = False,
) -> AngleResult:
    """``res``, read on a photo reduced by ``factor``, or the reading ``finer_reading`` (half the
    factor: the result and the factor it used, None where the photo cannot be had finer) gives
    while the reading is too coarse (:func:`_too_coarse`).  Once a reading was not steady, it
    is refined on while not ``ok``, and kept where nothing finer is: a finer one flagged for
    another reason read psi 30-170 deg off (the review's 22 px body on 3200x2400 photos, right
    at full size).  A ``body`` not found at half size is not looked for at full size
    (:func:`_too_coarse`).
    """
    unsteady: AngleResult | None = None
    while factor > 1 and (
        _too_coarse(res, factor, body=body) or (unsteady is not None and res.status != "ok")
    ):
        if unsteady is None and _unsteady(res):
            unsteady = res
        finer = finer_reading(factor // 2)
        if finer is None:
            break
        res, factor = finer
    return unsteady if unsteady is not None and res.status != "ok" else res


def _too_coarse(res: AngleResult, factor: int, *, body: bool = False) -> bool:
    """Whether a photo measured reduced by ``factor`` is measured again finer: not found, a line
    narrower than :data:`MIN_WORK_LINE_WIDTH_PX` there, or a body's reading not steady
    (:func:`steady_reading`).  Not a ``body`` not found at half size: one that is not would be
    too few pixels across at full size for a steady reading, and the look at full size took
    2.5-5 s a photo (customer 52's pale body without its empty scene, "nothing differs from the
    backdrop" at each size: 52 photos of 3000x2000 in 70 s, 6 s with the empty scene).

    Examples
    --------
    >>> lost = failed("auto", "no body found: nothing differs from the backdrop")
    >>> _too_coarse(lost, 4, body=True), _too_coarse(lost, 2, body=True), _too_coarse(lost, 2)
    (True, False, True)
    """
    if body and res.status == "failed" and factor <= 2:
        return False
    return (
        res.status == "failed"
        or res.line_width_px / factor < MIN_WORK_LINE_WIDTH_PX
        or _unsteady(res)
    )


def _unsteady(res: AngleResult) -> bool:
    """Whether :func:`steady_reading` flagged ``res``."""
    return res.status == "flagged" and UNSTEADY in res.reason


def measure_decoded(
    data: np.ndarray | None,
    img: np.ndarray,
    factor: int,
    settings: MeasureSettings,
    *,
    method: str = DEFAULT_METHOD,
    full: np.ndarray | None = None,
) -> AngleResult:
    """Measure an image decoded at reduced size; re-decode finer when the line came out too thin.

    ``data`` are the file's bytes, ``img`` their decoding reduced by ``factor``; or, for a frame
    already decoded at full size (a video that is not MJPEG), ``full`` is that frame (grey or BGR as
    ``img``), ``data`` is unused and finer images are reduced from ``full``.  A grey image whose
    longer side is at least ``2 * COARSE_WIDTH_PX`` is first measured on a halved copy with the
    centre line refined on ``img`` (3x less work); that result is kept only when its status is
    ``ok``.  While the line is narrower than :data:`MIN_WORK_LINE_WIDTH_PX` work pixels (or not
    found) and the image was reduced, it is decoded again at twice the resolution: thin lines cost a
    second decode, the usual photo only one small one.
    """
    if img.ndim == 2 and max(img.shape) >= 2 * COARSE_WIDTH_PX:
        coarse = reduce_image(img, 2)
        res = measure_work_image(
            coarse, settings, scale=2.0 * factor, method=method, fine=img, fine_scale=float(factor)
        )
        # anything doubtful (gaps, rivals, border, ...) is measured again at the decoded size
        if res.status == "ok" and res.line_width_px / (2 * factor) >= MIN_COARSE_LINE_WIDTH_PX:
            return res
    res = measure_work_image(img, settings, scale=float(factor), method=method)

    def finer_reading(finer: int) -> tuple[AngleResult, int] | None:
        decoded: np.ndarray | None
        if full is not None:
            decoded = reduce_image(full, finer)
        else:
            assert data is not None
            decoded, finer = decode_for_work(data, factor=finer, grey=img.ndim == 2)
        if decoded is None:
            return None
        return measure_work_image(decoded, settings, scale=float(finer), method=method), finer

    return _refined(res, factor, finer_reading, body=settings.target == "body")
