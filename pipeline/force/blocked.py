"""Measure the eccentricity of the blocked marker line in every photo of a blocked-force set.

Per photo: the marker line's ordered sub-pixel centre line is extracted exactly as for the
bending angle (:func:`pipeline.measure.extract.extract_centreline`), an ellipse is fitted to it
(:func:`pipeline.force.ellipse.fit_ellipse`: direct fit, geometric refinement on partial arcs)
and ``e = sqrt(1 - b**2/a**2)`` is reported with the same status semantics as the angle:

``ok``
    A trustworthy number.
``flagged``
    A number with every reason it may be wrong: from the line (touches the image border, partly
    hidden or too long for ``l0``, several candidate lines, low contrast, closes on itself or
    branches -- the thresholds of :mod:`pipeline.measure.quality`) and from the fit (arc too
    short, e uncertain, the line is not an ellipse).
``failed``
    No number (NaN): unreadable image, no line found, no ellipse could be fitted.

One bad photo never stops the set.  The output table (``eccentricity.csv``) has one row per
manifest row, same order: :data:`RESULT_COLUMNS`, then the manifest's pressure/force columns
carried over, then ``image_path`` (the photo's path as the photo set folder was given, for report
overlays; not resolved, so that the table does not depend on where the working directory lies).
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.force.ellipse import EllipseFit, Refine, fit_ellipse
from pipeline.measure.colors import BLACK, ColorSpec
from pipeline.measure.formats import read_image
from pipeline.measure.settings import MeasureSettings

RESULT_COLUMNS: tuple[str, ...] = (
    "image",
    "eccentricity",
    "eccentricity_sd",
    "semi_major_px",
    "semi_minor_px",
    "semi_major_mm",
    "semi_minor_mm",
    "centre_x_px",
    "centre_y_px",
    "angle_deg",
    "arc_fraction",
    "residual_px",
    "length_px",
    "method",
    "status",
    "reason",
    "seconds",
)
CARRIED_COLUMNS: tuple[str, ...] = (
    "pressure_kpa",
    "direction",
    "material",
    "actuator",
    "trial",
    "step",
    "measured_pressure_kpa",
    "force_n",
    "force_sd_n",
    "force_samples",
    "timestamp",
)


@dataclass(frozen=True)
class EccentricityResult:
    """Eccentricity of the marker line in one photo.

    Attributes
    ----------
    fit : EllipseFit
        The ellipse (px) with eccentricity, its sd, arc fraction, residual and method.
    length_px : float
        Length of the extracted centre line (px), NaN when no line.
    mm_per_px : float
        Scale used for the mm columns (NaN when unknown).
    status : str
        ``ok``, ``flagged`` or ``failed`` (line and fit combined).
    reason : str
        Every reason, ``; ``-separated ("" when ok).
    centreline_px : ndarray
        The extracted centre line (N, 2), empty when none.
    """

    fit: EllipseFit
    length_px: float
    mm_per_px: float
    status: str
    reason: str
    centreline_px: np.ndarray = field(repr=False)

    @property
    def eccentricity(self) -> float:
        """The eccentricity (NaN when failed)."""
        return self.fit.eccentricity

    def row(self) -> dict[str, Any]:
        """The result as an ``eccentricity.csv`` row (without image/seconds)."""
        f = self.fit
        return {
            "eccentricity": f.eccentricity,
            "eccentricity_sd": f.eccentricity_sd,
            "semi_major_px": f.semi_major_px,
            "semi_minor_px": f.semi_minor_px,
            "semi_major_mm": f.semi_major_px * self.mm_per_px,
            "semi_minor_mm": f.semi_minor_px * self.mm_per_px,
            "centre_x_px": f.centre_x_px,
            "centre_y_px": f.centre_y_px,
            "angle_deg": f.angle_deg,
            "arc_fraction": f.arc_fraction,
            "residual_px": f.residual_px,
            "length_px": self.length_px,
            "method": f.method,
            "status": self.status,
            "reason": self.reason,
        }


def _failed(reason: str) -> EccentricityResult:
    from pipeline.force.ellipse import failed_fit

    return EccentricityResult(
        failed_fit(reason), float("nan"), float("nan"), "failed", reason, np.empty((0, 2))
    )


def line_flags(line: Any, length_px: float, expected_length_px: float | None) -> list[str]:
    """Reasons to distrust an extracted line (same thresholds as the angle measurement).

    Parameters
    ----------
    line : pipeline.measure.extract.LineExtraction
    length_px : float
        Measured centre-line length (px).
    expected_length_px : float or None
        ``l0_mm / mm_per_px`` when the scale is known.

    Returns
    -------
    list of str
    """
    from pipeline.measure.quality import line_flags as extraction_flags

    flags = extraction_flags(line, length_px, expected_length_px)
    if line.branched_fraction > 0.05:
        flags.append("line closes on itself or branches")
    return flags


def blank_thick_blobs(image_bgr: np.ndarray, color: ColorSpec = BLACK) -> tuple[np.ndarray, int]:
    """Paint over blobs of the line colour much thicker than the line (a dark clamp).

    The marker line is thin; a clamp of the same dark colour is a thick blob whose lighter
    details (frame, screw heads) can leave thin dark bits attached to the line end, which the
    centre-line extraction would follow.  Each thick core (distance to the background above
    ``r = max(2.5 w, w + 3)`` px, ``w`` the line's half width, after a morphological closing of
    size ``4 r`` that fills the blob's light details), its convex hull grown by ``r`` plus a line
    width, is filled with the image's median colour.

    Parameters
    ----------
    image_bgr : ndarray (H, W, 3) uint8
    color : ColorSpec
        Marker colour.

    Returns
    -------
    image : ndarray
        A copy with the blobs painted over (the input itself when there is none).
    n_blobs : int
        How many blobs were painted over.
    """
    import cv2

    from pipeline.measure.extract import clamp_radius_px, line_mask

    mask = (line_mask(image_bgr, color)[0] > 0).astype(np.uint8)
    if not mask.any():
        return image_bgr, 0
    dt = cv2.distanceTransform(mask, cv2.DIST_L2, 3)
    ridge = (dt > 0) & (dt >= cv2.dilate(dt, np.ones((3, 3), np.uint8)))
    half_width = float(np.median(dt[ridge])) if ridge.any() else 0.5
    radius = clamp_radius_px(half_width)
    # close the blob's lighter details (frame, screw heads) so it reads as one solid thick blob
    k = 2 * int(np.ceil(2.0 * radius)) + 1
    solid = cv2.morphologyEx(
        mask, cv2.MORPH_CLOSE, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))
    )
    dt = cv2.distanceTransform(solid, cv2.DIST_L2, 3)
    n, labels = cv2.connectedComponents((dt > radius).astype(np.uint8), connectivity=8)
    if n <= 1:
        return image_bgr, 0
    out = image_bgr.copy()
    fill = np.median(image_bgr.reshape(-1, 3), axis=0).astype(np.uint8)
    grow = int(np.ceil(radius + 2.0 * half_width + 4.0))
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1))
    for k in range(1, n):
        ys, xs = np.nonzero(labels == k)
        hull = cv2.convexHull(np.c_[xs, ys].astype(np.int32))
        blob = np.zeros(mask.shape, np.uint8)
        cv2.fillConvexPoly(blob, hull, 1)
        out[cv2.dilate(blob, disc) > 0] = fill
    return out, n - 1


def measure_blocked_image(
    image_bgr: np.ndarray | None,
    settings: MeasureSettings,
    *,
    refine: Refine = "auto",
    blank_clamp: bool = True,
    **fit_options: Any,
) -> EccentricityResult:
    """Eccentricity of the marker line in one blocked-force photo.

    Parameters
    ----------
    image_bgr : ndarray (H, W, 3) uint8 or None
        The photo (None: unreadable, gives ``failed``).
    settings : MeasureSettings
        The photo's settings: ``l0_mm`` with ``mm_per_px`` lets a partly hidden line be
        flagged, ``mm_per_px`` gives the mm columns, ``color`` the marker, ``fixed_end_px``
        only helps the extraction pick the line's ends.
    refine : {"auto", "always", "never"}
        Geometric refinement of the ellipse (see :func:`pipeline.force.ellipse.fit_ellipse`).
    blank_clamp : bool
        Paint over thick blobs of the line colour (a dark clamp) first, see
        :func:`blank_thick_blobs`.
    **fit_options
        Further thresholds of :func:`~pipeline.force.ellipse.fit_ellipse`.

    Returns
    -------
    EccentricityResult
    """
    from pipeline.measure.extract import NoLineFound, extract_centreline

    if image_bgr is None:
        return _failed("unreadable image (cannot be decoded)")
    color = settings.color or BLACK
    if blank_clamp:
        image_bgr = blank_thick_blobs(image_bgr, color)[0]
    try:
        line = extract_centreline(image_bgr, color=color, fixed_end_px=settings.fixed_end_px)
    except NoLineFound as exc:
        return _failed(str(exc))
    pts = line.centreline_px
    length = float(np.sum(np.hypot(*np.diff(pts, axis=0).T))) if len(pts) > 1 else 0.0
    mm_per_px = settings.mm_per_px
    expected = settings.l0_mm / mm_per_px if mm_per_px else None
    scale = float(mm_per_px) if mm_per_px is not None else float("nan")
    fit = fit_ellipse(pts, refine=refine, **fit_options)
    if not fit:
        return EccentricityResult(fit, length, scale, "failed", fit.reason, pts)
    reasons = line_flags(line, length, expected) + ([fit.reason] if fit.reason else [])
    return EccentricityResult(
        fit=fit,
        length_px=length,
        mm_per_px=scale,
        status="flagged" if reasons else "ok",
        reason="; ".join(reasons),
        centreline_px=pts,
    )


@dataclass(frozen=True)
class _Task:
    path: str
    settings: MeasureSettings | None
    reason: str
    refine: Refine
    fit_options: dict[str, Any]


def _measure_row(task: _Task) -> dict[str, Any]:
    t0 = time.perf_counter()
    p = Path(task.path)
    if task.settings is None:
        result = _failed(task.reason)
    elif not p.is_file():
        result = _failed(f"image file {p.name} not found")
    else:
        result = measure_blocked_image(
            read_image(p), task.settings, refine=task.refine, **task.fit_options
        )
    row = result.row()
    row["seconds"] = round(time.perf_counter() - t0, 4)
    return row


def measure_blocked_photoset(
    folder: str | os.PathLike[str],
    *,
    jobs: int = 1,
    refine: Refine = "auto",
    **fit_options: Any,
) -> pd.DataFrame:
    """Measure the eccentricity of every photo of a blocked-force photo set.

    Parameters
    ----------
    folder : path
        Photo-set folder (manifest.csv + photoset.yaml + images).
    jobs : int
        Worker processes.
    refine : {"auto", "always", "never"}
        Geometric refinement of the ellipse fit.
    **fit_options
        Thresholds of :func:`pipeline.force.ellipse.fit_ellipse`.

    Returns
    -------
    pandas.DataFrame
        ``eccentricity.csv``: one row per manifest row (see module docstring).

    Raises
    ------
    UserInputError
        When the photo set itself is not valid.
    """
    from pipeline.photoset import load_photoset
    from pipeline.pool import map_photos

    ps = load_photoset(folder)
    m = ps.manifest
    tasks = [
        _Task(
            str(ps.image_path(str(image))), ps.rows[i], ps.row_reason(i), refine, dict(fit_options)
        )
        for i, image in enumerate(m["image"])
    ]
    rows = map_photos(_measure_row, tasks, jobs=jobs, preload=["pipeline.force.blocked"])
    out = pd.DataFrame(rows)
    out.insert(0, "image", m["image"].astype(str).to_numpy())
    out = out[list(RESULT_COLUMNS)]
    for c in CARRIED_COLUMNS:
        if c in m.columns:
            out[c] = m[c].to_numpy()
    out["image_path"] = [t.path for t in tasks]
    return out
