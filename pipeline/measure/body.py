"""The actuator's own centre line, for photos without a drawn line (``target: body``).

Any curve parallel to the inextensible layer turns through the same total angle, so the centre
line of the body between its two long edges gives psi.  Steps:

1. segmentation (:func:`body_mask`): the body is what lies in ``line_color`` (when given) and
   differs from the background: from a ``background`` photo of the empty scene when there is one,
   else from the backdrop, modelled as a smooth colour field (a quadratic in x and y per Lab
   channel, fitted robustly to the pixels that look like backdrop, starting from the border of
   the ``roi``); ``roi`` and ``exclude`` restrict it; a clear body whose edges differ clearly
   and whose inside only faintly is what its outline encloses (:func:`fill_outlined`);
2. clean-up: a closing as wide as the texture (fibre winding, ribs, pleats, dots and highlights
   leave gaps and holes), holes filled unless they are large (the inside of a ring), specks
   opened away, and the component at the fixed end (else the largest) kept;
3. centre line: the path between the fixed end and the farthest point that keeps farthest from
   the edges (a minimal path weighted by the distance transform), so it runs along the ridge of
   the body and ignores texture; each point is then moved to the middle of the two edges
   measured along the normal (sub-pixel), and the caps at both ends (one half-width) dropped,
   where "between the two edges" no longer holds.

The result is a :class:`pipeline.measure.extract.LineExtraction` (with the body's widths), so
the estimators and quality checks of the drawn line apply unchanged.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import cv2
import numpy as np
import pandas as pd
from scipy.sparse.csgraph import dijkstra

from pipeline.measure.colors import color_mask
from pipeline.measure.estimators import TANGENT_WINDOW_FRACTION, end_tangents
from pipeline.measure.extract import LineExtraction, NoLineFound, _pixel_graph, region_mask
from pipeline.measure.quality import FAINT_BODY_SHARE
from pipeline.measure.settings import MeasureSettings, Polygon

#: the body must differ from the backdrop by at least this many noise sigmas (robust, Lab units)
NOISE_SIGMAS = 6.0
#: ... and by at least this colour distance (Lab, L weighted by LIGHTNESS_WEIGHT)
MIN_DIFFERENCE = 12.0
#: ... while fainter differences (a translucent body's edges) count when they touch a clear one,
#: within this fraction of the photo's size of it
WEAK_SIGMAS = 3.0
GROW_FRACTION = 0.012
#: where the shadows are told apart (or, without an empty scene, lighter than the backdrop), a
#: faint side counts too: a difference whose median over FAINT_MEDIAN_PX px is at least
#: FAINT_SIGMAS of that median's own noise and FAINT_DIFFERENCE, within FAINT_REACH times the
#: weak reach of a clear one,
#: when what it adds lies at FAINT_CLEAR times that threshold or more (median): customer 55's
#: translucent body lit from one side differed by 5-6 on its shaded half, under the weak
#: threshold's floor of 6, and half its rows were lost one grey level below customer 53's scene
FAINT_MEDIAN_PX, FAINT_SIGMAS, FAINT_DIFFERENCE, FAINT_REACH, FAINT_CLEAR = 5, 6.0, 3.0, 3, 1.5
#: ... each connected region of it on its own (the review of stop 61: light bounced onto the
#: backdrop beside the lit side, alone under FAINT_CLEAR, came in on a faint half's median and
#: gave rows ok 5.6-10.5 deg off); and not at all where FAINT_MARGINAL_SHARE or more of what it
#: adds lies within FAINT_MARGINAL times the threshold: a side at the edge of being selected (the
#: review's shaded side fading from 14 to 6 grey levels along the body, taken in part at the tip,
#: read rows 5-18 deg off, ok; a bench set's translucent body without its empty scene, 8-9 deg
#: off on a tip's speckled rim; 0.05-0.87 of theirs lay there, 0.00-0.01 of customer 55's and
#: 56's faint halves)
FAINT_MARGINAL, FAINT_MARGINAL_SHARE = 1.25, 0.03
#: lightness counts this much in the colour distance (shadows change lightness most)
LIGHTNESS_WEIGHT = 0.6
#: holes larger than this fraction of the body's area stay open (the inside of a ring)
MAX_HOLE_FRACTION = 0.04
#: a region enclosed by the selection (and the region left out: a clamp plate under ``exclude``)
#: is the inside of a clear body when it differs from the background by more than this many
#: noise sigmas (median over it) and the selection runs along at least this share of its rim;
#: it is never larger than this share of the photo, and at least this many times as long as it
#: is wide (area over the square of its widest inscribed disc's diameter)
OUTLINE_FILL_SIGMAS, OUTLINE_RIM_SHARE, OUTLINE_MAX_SHARE = 3.0, 0.8, 0.25
OUTLINE_MIN_ELONGATION = 3.0
#: a long region the selection outlines and leaves out is a clear body seen by its rims when it
#: is at least this many times as wide as what is measured (a rim: a few px)
HOLLOW_WIDTHS = 4.0
#: the centre line is smoothed over this many half-widths (ragged, textured edges)
SMOOTH_HALF_WIDTHS = 0.6


@dataclass(frozen=True)
class EndFace:
    """A direction the body is read to have at one of its ends: at the free end the outward
    normal of the flat face ending it (:func:`tip_face_normal`), at the fixed end the way a
    chambered body leaves the clamp, on its strip's edge (:func:`base_edge_direction`).

    Attributes
    ----------
    direction_rad : float
        The direction (rad, image axes: y down): the tip's, or the body's out of the clamp.
    middle_px : (float, float)
        Where it is read (x, y), px: the face's middle, or the strip edge's first point.
    """

    direction_rad: float
    middle_px: tuple[float, float]


@dataclass(frozen=True)
class BodyExtraction:
    """What the body segmentation found, beyond the centre line (for quality and previews).

    Attributes
    ----------
    line : LineExtraction
        The centre line and its quality facts.
    mask : ndarray (H, W) uint8
        The chosen body (work image pixels).
    widths_px : ndarray
        Edge-to-edge width along the centre line (original px).
    selected_fraction : float
        Fraction of the allowed region that the selection (before choosing a component) covers.
    continues : bool
        More of the selection lies just beyond the free end, along its course: the body may go
        on past a gap (a faint or hidden stretch), so its end, and psi, may be wrong.
    start_gap_px : float
        How far the body's centre line starts from the given fixed end (original px; 0 without).
    end_short_px : float
        How much of the body's ridge, at the free end, the centre line does not cover (original
        px): where the outline was too uneven to find the middle between two edges.
    ridge_tip_deg : float
        How much the free end's direction changes (deg, image axes) when the centre line is
        carried on along the selection's ridge over that uncovered part: what the uncovered
        part may hide.
    free_end_width_ratio : float
        The body's width near its free end over its median width: well below 1 when one side of
        the tip was not selected (a faint, translucent side), which shifts the tip's direction.
    side_on_border : bool
        A side of the body (not its free end) runs along the image border: the centre line
        there lies half the body's width from the other edge.  (At the free end the border is
        ``line.touches_border``: the tip may be outside the photo.)
    tip_at_region_edge : bool
        The free end reaches the edge of the ``roi`` or of an ``exclude`` polygon: the body may
        go on where it is not looked at.
    tip_face_px : float
        How far the tip's face (the body's last pixel on the centre line's course, cap included)
        lies beyond the centre line's free end (original px); computed only when
        ``sealed_end_mm`` is given or the free end is capped (0 otherwise).
    tip_capped : bool
        The centre line stopped at the free end where the body goes on wider, centred on its
        course: a rigid cap, over which the body does not bend.
    chambered : bool
        The gaps between a row of chambers were filled (:func:`fill_chamber_gaps`): the centre
        line's course is a polygon, one side per chamber, and its start the first chamber's.
    tip_face : EndFace or None
        The square, flat face ending the body (original px), None where the end is not one
        (:func:`tip_face_normal`).
    base_edge : EndFace or None
        A chambered body's direction out of the clamp, from its strip's edge there (original
        px; :func:`base_edge_direction`); None where it is not read.
    excluded_start_px : float
        How much of the stretch the centre line is carried back over to the given fixed end
        lies under ``exclude`` or outside ``roi`` (original px): a bend there is not seen.
    faint_taken : bool
        :attr:`BodySelection.faint_taken`.
    faint_share : float
        The share of the body's pixels that differ from the background by less than the clear
        threshold (0 for a colour-only selection): a translucent body's.
    hollow_outline : bool
        The selection outlines a long region whose inside does not differ from the background
        (:attr:`BodySelection.hollow_width_px`), at least :data:`HOLLOW_WIDTHS` times as wide as
        the body measured: a clear body seen by its rims (an opaque body's hairpin closing a
        pocket of backdrop against the clamp is as wide as the pocket's width over its own).
    """

    line: LineExtraction
    mask: np.ndarray
    widths_px: np.ndarray
    selected_fraction: float
    continues: bool = False
    start_gap_px: float = 0.0
    end_short_px: float = 0.0
    ridge_tip_deg: float = 0.0
    free_end_width_ratio: float = 1.0
    tip_face_px: float = 0.0
    tip_capped: bool = False
    side_on_border: bool = False
    tip_at_region_edge: bool = False
    hollow_outline: bool = False
    tip_face: EndFace | None = None
    chambered: bool = False
    base_edge: EndFace | None = None
    excluded_start_px: float = 0.0
    faint_share: float = 0.0
    faint_taken: bool = False


def _lab(image_bgr: np.ndarray) -> np.ndarray:
    lab = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2LAB).astype(np.float32)
    lab[:, :, 0] *= LIGHTNESS_WEIGHT
    return lab


#: sums an image's three channels (cv2.transform): far faster than numpy's sum over a last axis
_SUM_CHANNELS = np.ones((1, 3), np.float32)


def lab_distance(lab: np.ndarray, ref: np.ndarray) -> np.ndarray:
    """Euclidean distance of every pixel of ``lab`` (H, W, 3 float32) from ``ref``: an image of
    the same shape or one colour (3,), as float32 (H, W); OpenCV's per-pixel arithmetic, about
    6x faster than numpy's for a photo.

    Examples
    --------
    >>> lab = np.array([[[3.0, 4.0, 0.0], [1.0, 1.0, 1.0]]], np.float32)
    >>> lab_distance(lab, np.zeros(3)).tolist()
    [[5.0, 1.7320507764816284]]
    >>> lab_distance(lab, lab).tolist()
    [[0.0, 0.0]]
    """
    d = lab - np.asarray(ref, np.float32)
    summed = cv2.transform(cv2.multiply(d, d), _SUM_CHANNELS)
    return np.asarray(cv2.sqrt(summed), np.float32).reshape(lab.shape[:2])


def _design(xs: np.ndarray, ys: np.ndarray, w: int, h: int) -> np.ndarray:
    u, v = xs / max(w, 1) - 0.5, ys / max(h, 1) - 0.5
    return np.c_[np.ones_like(u), u, v, u * u, u * v, v * v]


#: the backdrop fits use about this many pixels of the photo, its colour groups this many
FIT_PIXELS, KMEANS_PIXELS = 8000, 3000
#: a colour seen on this fraction of the region's border (or more) is backdrop too ...
BACKDROP_CLASS_FRACTION = 0.15
#: ... and so is a colour covering this fraction of the whole region (the actuator never does)
DOMINANT_FRACTION = 0.35


def kmeans3(points: np.ndarray, iterations: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """Deterministic k-means with 3 groups (labels, centres): seeded at the 10th, 50th and 90th
    percentile of the first coordinate (lightness), so the same photo always gives the same groups.

    Examples
    --------
    >>> pts = np.r_[np.zeros((10, 3)), np.full((10, 3), 50.0), np.full((10, 3), 100.0)]
    >>> labels, centres = kmeans3(pts)
    >>> sorted(np.bincount(labels).tolist()), centres[:, 0].round().tolist()
    ([10, 10, 10], [0.0, 50.0, 100.0])
    """
    pts = points.astype(np.float64)
    order = np.argsort(pts[:, 0], kind="stable")
    centres = pts[order[(np.array([0.1, 0.5, 0.9]) * (len(pts) - 1)).astype(int)]].copy()
    labels = np.zeros(len(pts), int)
    for _ in range(iterations):
        d = ((pts[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
        labels = np.argmin(d, axis=1)
        for k in range(3):
            if (labels == k).any():
                centres[k] = pts[labels == k].mean(axis=0)
    return labels, centres


def _ring(allowed: np.ndarray) -> np.ndarray:
    h, w = allowed.shape
    k = max(3, int(0.04 * max(h, w)))
    inner = cv2.erode(
        allowed, np.ones((k, k), np.uint8), borderType=cv2.BORDER_CONSTANT, borderValue=0
    )
    return cv2.subtract(allowed, inner) > 0


#: an underexposed photo is brightened until the brightest 0.5 % of the allowed region reach this
#: grey level (at most 4x): the colour differences a body must show (:data:`MIN_DIFFERENCE`) then
#: mean the same at any exposure.  Rendered analogues at 0.45x exposure: 49 of 60 photos within
#: 10 deg before, 58 after (59 at full exposure, which this leaves unchanged)
EXPOSED_TOP_GREY = 200.0
MAX_EXPOSURE_GAIN = 4.0
#: ... and only when that takes more than this gain: a photo exposed about right is left as it is
MIN_EXPOSURE_GAIN = 1.5


def exposed(image_bgr: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """The photo brightened to :data:`EXPOSED_TOP_GREY` when underexposed, else itself.

    Examples
    --------
    >>> dark = np.full((20, 20, 3), 40, np.uint8); dark[5:8, 5:8] = 100
    >>> int(exposed(dark, np.ones((20, 20), np.uint8)).max())
    200
    >>> bright = dark * 2
    >>> exposed(bright, np.ones((20, 20), np.uint8)) is bright
    True
    """
    grey = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2GRAY)
    top = float(np.percentile(grey[allowed > 0], 99.5)) if allowed.any() else 255.0
    gain = min(EXPOSED_TOP_GREY / max(top, 1.0), MAX_EXPOSURE_GAIN)
    if gain <= MIN_EXPOSURE_GAIN:  # exposed well enough: unchanged
        return image_bgr
    return cv2.convertScaleAbs(image_bgr, alpha=gain)


def backdrop_difference(
    image_bgr: np.ndarray, allowed: np.ndarray
) -> tuple[np.ndarray, float, tuple[np.ndarray, ...]]:
    """Colour distance of each pixel from the backdrop, the backdrop's noise and its colours.

    The colours along the border of the allowed region are the backdrop's: they are grouped
    (k-means, 3 groups) and every group seen on at least :data:`BACKDROP_CLASS_FRACTION` of the
    border is a backdrop colour (a table and the dark corners of a vignetted or cropped photo,
    say), and so is a colour covering :data:`DOMINANT_FRACTION` of the whole region (a backdrop
    that the border does not show, inside a circular crop).  The most common border colour is
    modelled as a smooth field -- a quadratic in x and y per Lab channel, refitted twice to every
    allowed pixel that still looks like it (uneven light) -- the others as constant colours.  The
    difference is the distance to the nearest of them.

    Parameters
    ----------
    image_bgr : ndarray (H, W, 3) uint8
    allowed : ndarray (H, W) uint8
        Where the actuator may be (1) -- the roi minus the excluded polygons.

    Returns
    -------
    difference : ndarray (H, W) float32
        Colour distance (Lab, lightness weighted).
    sigma : float
        Robust spread of the difference over backdrop pixels.
    backdrop_lab : tuple of ndarray
        The backdrop's colours (Lab, lightness weighted): the main one's smooth field (H, W, 3),
        then the others (3,) (:func:`backdrop_shadows`).
    """
    lab = _lab(image_bgr)
    model, centres, order, ring, grid = _main_backdrop(lab, allowed)
    diff = lab_distance(lab, model)
    others = [centres[c] for c in order[1:]]
    gy, gx = np.nonzero((allowed > 0) & grid)
    lab_grid = lab[gy, gx]
    region_px = lab_grid[:: max(1, len(lab_grid) // KMEANS_PIXELS)]
    if len(region_px) >= 3:
        glabels, gcentres = kmeans3(region_px)
        gshare = np.bincount(glabels, minlength=3) / len(glabels)
        others += [gcentres[c] for c in range(3) if gshare[c] >= DOMINANT_FRACTION]
    for centre in others:
        diff = np.minimum(diff, lab_distance(lab, centre))
    vals = diff[ring & grid] if (ring & grid).sum() >= 12 else diff[(allowed > 0) & grid]
    if vals.size < 3:  # a region smaller than the grid's step
        vals = diff[allowed > 0]
    med = float(np.median(vals))
    sigma = max(1.4826 * float(np.median(np.abs(vals - med))), 0.5)
    return diff, sigma, (model, *others)


def _bgr_of(lab: np.ndarray) -> np.ndarray:
    """Lightness-weighted Lab colours (..., 3) as uint8 BGR (N, 1, 3): an image for OpenCV."""
    unweighted = np.asarray(lab, np.float32).reshape(-1, 1, 3) / [LIGHTNESS_WEIGHT, 1.0, 1.0]
    return cv2.cvtColor(np.clip(unweighted, 0, 255).astype(np.uint8), cv2.COLOR_LAB2BGR)


def backdrop_shadows(
    image_bgr: np.ndarray,
    backdrop_lab: tuple[np.ndarray, ...],
    where: np.ndarray,
    clear: np.ndarray,
) -> tuple[np.ndarray, float]:
    """Where (among ``where``) the photo is one of the backdrop's colours in shadow, and how
    coloured the clear differences (``clear``, a subset of ``where``) outside it are.

    The body's shadow without an empty scene: a pixel that is one of the backdrop's colours
    (:func:`backdrop_difference`) darker by one factor in every channel, no darker than
    :data:`SHADOW_DARKEST_NO_BACKGROUND` (:func:`shadow_mask`).  Only ``where`` is looked at (the
    pixels that differ at all: a tenth of the photo, not all of it).

    Returns
    -------
    shade : ndarray (H, W) bool
    chroma : float
        Median distance (Lab a, b; 8-bit units) of the pixels of ``clear`` not in shadow from the
        backdrop colour nearest each: a neutral body on a neutral backdrop has ~0, and its
        shaded side looks like a shadow (:data:`BODY_CHROMA`).  (The faint differences of
        ``where`` are mostly the backdrop's own texture and neutral.)

    Examples
    --------
    >>> grey = np.full((1, 4, 3), 128, np.uint8)
    >>> photo = grey.copy(); photo[0, 1] = (60, 60, 200); photo[0, 2] = (90, 90, 90)
    >>> where = np.array([[0, 1, 1, 0]], bool)
    >>> shade, chroma = backdrop_shadows(photo, (_lab(grey),), where, where)
    >>> shade.tolist(), chroma > BODY_CHROMA
    ([[False, False, True, False]], True)
    """
    ys, xs = np.nonzero(where)
    shade = np.zeros(where.shape, bool)
    if not len(ys):
        return shade, 0.0
    px = image_bgr[ys, xs].reshape(-1, 1, 3)
    hit = np.zeros(len(ys), bool)
    chroma = np.full(len(ys), np.inf, np.float32)
    ab = cv2.cvtColor(px, cv2.COLOR_BGR2LAB).reshape(-1, 3)[:, 1:].astype(np.float32)
    main, *others = backdrop_lab
    for ref in [main[ys, xs], *(np.broadcast_to(c, (len(ys), 3)) for c in others)]:
        ref_bgr = _bgr_of(ref)
        hit |= shadow_mask(px, ref_bgr, darkest=SHADOW_DARKEST_NO_BACKGROUND).ravel()
        ref_ab = np.asarray(ref, np.float32)[:, 1:]
        chroma = np.minimum(chroma, np.hypot(*(ab - ref_ab).T))
    shade[ys, xs] = hit
    body = chroma[~hit & clear[ys, xs]]
    return shade, float(np.median(body)) if len(body) else 0.0


def light_falloff(image_bgr: np.ndarray, allowed: np.ndarray) -> float:
    """How far the backdrop's light falls off across the allowed region: the spread (2nd to 98th
    percentile) of its fitted lightness over the median (rendered lamp-lit scenes 0.2-0.45; one
    darkened to 0.6 of the middle at a corner, 0.66).

    Examples
    --------
    >>> even = np.full((60, 80, 3), 150, np.uint8)
    >>> ramp = (even * np.linspace(0.5, 1.0, 80)[None, :, None]).astype(np.uint8)
    >>> allowed = np.ones((60, 80), np.uint8)
    >>> round(light_falloff(even, allowed), 2), light_falloff(ramp, allowed) > 0.5
    (0.0, True)
    >>> light_falloff(even, np.zeros((60, 80), np.uint8))  # roi / exclude leave nothing
    0.0
    """
    if not allowed.any():
        return 0.0
    model = _main_backdrop(_lab(image_bgr), allowed)[0]
    light = model[:, :, 0][allowed > 0] / LIGHTNESS_WEIGHT
    lo, mid, hi = (float(v) for v in np.percentile(light, [2, 50, 98]))
    return (hi - lo) / mid if mid > 1.0 else 0.0


def _main_backdrop(
    lab: np.ndarray, allowed: np.ndarray
) -> tuple[np.ndarray, np.ndarray, list[int], np.ndarray, np.ndarray]:
    """The backdrop's main colour as a smooth field over the image (H, W, 3 Lab, lightness
    weighted), the colour groups of the region's border and those that are backdrop (most common
    first), the border ring and the sparse grid the fits use."""
    h, w = allowed.shape
    ring = _ring(allowed)
    step = max(1, int(np.sqrt(max(h * w, 1) / FIT_PIXELS)))  # the fits use a sparse grid of pixels
    grid = np.zeros((h, w), bool)
    grid[::step, ::step] = True
    sample = ring & grid
    if sample.sum() < 12:
        sample = (allowed > 0) & grid
    if sample.sum() < 3:  # a region smaller than the grid's step (a roi of a few pixels)
        sample = allowed > 0
    ring_px = lab[sample]
    labels, centres = kmeans3(ring_px[:: max(1, len(ring_px) // KMEANS_PIXELS)])
    d_ring = ((ring_px[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
    labels = np.argmin(d_ring, axis=1)
    share = np.bincount(labels, minlength=3) / max(len(labels), 1)
    order = [int(i) for i in np.argsort(-share) if share[i] >= BACKDROP_CLASS_FRACTION]
    # smooth field of the main backdrop colour, fitted on the grid, evaluated on a coarse one
    ry, rx = np.nonzero(sample)
    main = labels == order[0]
    a_ring = _design(rx[main].astype(np.float32), ry[main].astype(np.float32), w, h)
    gy, gx = np.nonzero((allowed > 0) & grid)
    a_grid = _design(gx.astype(np.float32), gy.astype(np.float32), w, h)
    lab_grid = lab[gy, gx]
    fit_a, fit_v = a_ring, ring_px[main]
    coef = np.zeros((6, 3))
    for _ in range(3):
        if len(fit_v) < 12:
            break
        coef, *_ = np.linalg.lstsq(fit_a, fit_v, rcond=None)
        on_ring = np.sqrt(((ring_px[main] - a_ring @ coef) ** 2).sum(axis=1))
        med = float(np.median(on_ring))
        spread = max(1.4826 * float(np.median(np.abs(on_ring - med))), 0.5)
        like = np.sqrt(((lab_grid - a_grid @ coef) ** 2).sum(axis=1)) < med + 3.0 * spread + 2.0
        # every allowed pixel that looks like it (uneven light)
        fit_a, fit_v = a_grid[like], lab_grid[like]
    cy, cx = np.mgrid[0 : h + 7 : 8, 0 : w + 7 : 8].astype(np.float32)
    coarse = (
        (_design(cx.ravel(), cy.ravel(), w, h) @ coef)
        .reshape(cy.shape[0], cy.shape[1], 3)
        .astype(np.float32)
    )
    model = cv2.resize(coarse, (cx.shape[1] * 8, cy.shape[0] * 8), interpolation=cv2.INTER_LINEAR)[
        :h, :w
    ]
    return model, centres, order, ring, grid


#: where the ramp's estimate of the empty scene differs from the backdrop by at least this
#: fraction of the selection threshold it still shows the body (a part that stayed put): there
#: only the difference from the backdrop counts
ESTIMATE_SHOWS_BODY = 0.5


def _threshold(sigma: float) -> float:
    """The selection threshold of a difference whose noise is ``sigma``."""
    return max(NOISE_SIGMAS * sigma, MIN_DIFFERENCE)


def _weak_threshold(sigma: float) -> float:
    """The threshold of a faint difference next to a clear one (:func:`_hysteresis`)."""
    return max(WEAK_SIGMAS * sigma, 0.5 * MIN_DIFFERENCE)


@functools.lru_cache(maxsize=4)
def estimate_looks_like_backdrop(
    path: str, shape: tuple[int, int], roi: Polygon | None, exclude: tuple[Polygon, ...],
    scale: float,
) -> np.ndarray:
    """Where the ramp's estimate of the empty scene (the file at ``path``, resized to the work
    image's ``shape``) looks like the backdrop itself (uint8 0/1): not where it still shows the
    body (a part that stayed put over most of the ramp).  Computed once per estimate in a worker.
    """
    read = cv2.imread(path)
    if read is None:  # gone: the backdrop alone decides
        return np.zeros(shape, np.uint8)
    estimate = cv2.resize(read, (shape[1], shape[0]), interpolation=cv2.INTER_AREA)
    region = region_mask((*shape, 3), roi, exclude, scale)
    allowed = np.ones(shape, np.uint8) if region is None else region
    shows_body, sigma, _ = backdrop_difference(exposed(estimate, allowed), allowed)
    return cv2.erode(
        (shows_body < ESTIMATE_SHOWS_BODY * _threshold(sigma)).astype(np.uint8),
        np.ones((5, 5), np.uint8),
    )


def estimated_background_difference(
    image_bgr: np.ndarray, estimate_bgr: np.ndarray, allowed: np.ndarray, backdrop_like: np.ndarray
) -> tuple[np.ndarray, float]:
    """Difference of each pixel from the empty scene estimated from the ramp's photos (already
    at the photo's exposure, :func:`matched_exposure`), joined with its difference from the
    backdrop (:func:`backdrop_difference`), and that noise.

    Both differences are scaled so that their selection thresholds (``NOISE_SIGMAS`` times each
    one's noise, at least ``MIN_DIFFERENCE``) meet at ``MIN_DIFFERENCE``, and the larger counts.
    The estimate counts only where it looks like the backdrop itself (``backdrop_like``,
    :func:`estimate_looks_like_backdrop`): where the body stayed put over most of the ramp (its
    base) the estimate shows it, and the backdrop alone decides.

    Returns
    -------
    difference : ndarray (H, W) float32
    sigma : float
        The noise that puts the threshold at ``MIN_DIFFERENCE``.
    """
    from_backdrop, s_backdrop, _ = backdrop_difference(exposed(image_bgr, allowed), allowed)
    from_estimate, s_estimate = background_difference(image_bgr, estimate_bgr)
    joined = np.maximum(
        np.where(backdrop_like > 0, from_estimate / _threshold(s_estimate), 0.0),
        from_backdrop / _threshold(s_backdrop),
    )
    return (MIN_DIFFERENCE * joined).astype(np.float32), MIN_DIFFERENCE / NOISE_SIGMAS


#: the exposure gains are measured on about this many pixels, neither near black nor saturated
GAIN_PIXELS, GAIN_DARKEST, GAIN_BRIGHTEST = 20000, 12, 245


def matched_exposure(background_bgr: np.ndarray, image_bgr: np.ndarray) -> np.ndarray:
    """The empty-scene photo with each colour channel scaled to the photo's exposure.

    A camera that sets its own exposure or white balance takes the empty scene a little darker
    or lighter than the photos (the actuator is not in it); 10 % is enough to make the whole
    backdrop differ from it.  The gain of each channel is the median ratio photo / empty scene
    over the pixels of both that are neither near black nor saturated: most of them are
    backdrop, which the actuator covers only in part.

    Examples
    --------
    >>> bg = np.full((20, 20, 3), 100, np.uint8)
    >>> photo = (bg * np.array([1.1, 1.0, 0.9])).astype(np.uint8)
    >>> photo[0, 0] = 250
    >>> matched_exposure(bg, photo)[1, 1].tolist()
    [110, 100, 90]
    """
    gain = exposure_gains(background_bgr, image_bgr)
    if (gain == 1.0).all():
        return background_bgr
    return cv2.convertScaleAbs(background_bgr.astype(np.float32) * gain)


def exposure_gains(
    reference_bgr: np.ndarray, image_bgr: np.ndarray, where: np.ndarray | None = None
) -> np.ndarray:
    """Per colour channel, how much brighter ``image_bgr`` is exposed than ``reference_bgr`` (a
    photo of the same scene): the median ratio over the pixels of both that are neither near
    black nor saturated, most of them backdrop (float32, shape (3,); ones when too few pixels
    are usable).  ``where`` (bool, the images' height and width) keeps only those pixels.

    Examples
    --------
    >>> ref = np.full((20, 20, 3), 100, np.uint8)
    >>> [round(float(g), 2) for g in exposure_gains(ref, (ref * [1.1, 1.0, 0.9]).astype(np.uint8))]
    [1.1, 1.0, 0.9]
    """
    step = max(1, int(np.sqrt(image_bgr.shape[0] * image_bgr.shape[1] / GAIN_PIXELS)))
    a = image_bgr[::step, ::step].reshape(-1, 3).astype(np.float32)
    b = reference_bgr[::step, ::step].reshape(-1, 3).astype(np.float32)
    usable = ((a > GAIN_DARKEST) & (a < GAIN_BRIGHTEST) & (b > GAIN_DARKEST)
              & (b < GAIN_BRIGHTEST)).all(axis=1)
    if where is not None:
        usable &= where[::step, ::step].reshape(-1)
    if usable.sum() < 100:
        return np.ones(3, np.float32)
    return np.asarray(np.median(a[usable] / b[usable], axis=0), np.float32)


#: a photo and its empty scene that differ by more than this noise (robust sigma of the colour
#: distance, Lab with lightness weighted) are both smoothed (Gaussian, NOISY_BLUR_PX) first
NOISY_SIGMA, NOISY_BLUR_PX = 2.0, 1.0


def background_difference(
    image_bgr: np.ndarray, background_bgr: np.ndarray
) -> tuple[np.ndarray, float]:
    """Colour distance of each pixel from the same pixel of the empty-scene photo (matched to the
    photo's exposure: :func:`matched_exposure`), and its noise.

    Both photos carry their own sensor noise, so their difference is noisier than either; where
    it is high (sigma over :data:`NOISY_SIGMA`: about 8 grey levels of noise per photo) both are
    smoothed over :data:`NOISY_BLUR_PX` first.  On the rendered analogues with that noise and
    their background photos, 49 of 60 were ``ok`` and right and 10 ``ok`` but wrong unsmoothed
    (the translucent body's faint side lost in the noise), 55 and 5 smoothed.
    """
    lab, ref = _lab(image_bgr), _lab(background_bgr)
    for smooth in (False, True):
        if smooth:
            lab = cv2.GaussianBlur(lab, (0, 0), NOISY_BLUR_PX)
            ref = cv2.GaussianBlur(ref, (0, 0), NOISY_BLUR_PX)
        diff = lab_distance(lab, ref)
        med = float(np.median(diff))
        sigma = max(1.4826 * float(np.median(np.abs(diff - med))), 0.5)
        if sigma <= NOISY_SIGMA:
            break
    return diff, sigma


#: a pixel darker than the empty scene by the same factor in B, G and R (within this spread of
#: the three ratios), between these factors, is a shadow the body casts, not the body
SHADOW_RATIO_SPREAD = 0.12
SHADOW_DARKEST, SHADOW_LIGHTEST = 0.3, 0.97
#: ... and without an empty scene, against the backdrop's own colour, no darker than this: a
#: grey clamp a third as bright as the backdrop is not the body's shadow (taken for one, the
#: clamp left the selection and the drawn bodies of the tests read 4-13 deg off)
SHADOW_DARKEST_NO_BACKGROUND = 0.5
#: ... unless leaving the shadows out would lose this share of the selection (a neutral grey body
#: darker than a neutral backdrop looks like a shadow; it is then all kept).  Without an empty
#: scene only a coloured body's shadow is left out (:data:`BODY_CHROMA`), and a soft shadow can
#: be most of what differs (customer 34's blue body on white paper kept 0.33-0.44 of it: with
#: half, the shadow was selected with the body and 12 ``ok`` rows read 5-14 deg off), so there
#: the share is lower; it still keeps a grey body whose colour test a blue tube or red markers
#: passed (they kept 0.08-0.12 of the selection, and the tube was measured for the body)
SHADOW_KEEP, SHADOW_KEEP_NO_BACKGROUND = 0.5, 0.2


def shadow_mask(
    image_bgr: np.ndarray, background_bgr: np.ndarray, darkest: float = SHADOW_DARKEST
) -> np.ndarray:
    """Where the photo is the empty scene in shadow: darker by one factor in every channel.

    A shadow dims the backdrop and keeps its colour; the body, even translucent, changes the
    colour (a red body on green) or brightens it.  ``darkest``: the darkest shadow, as a fraction
    of the empty scene's brightness.  On rendered ramp sets with a background photo
    the body's shadow was selected with it, widening the body on one side and round its tip
    (|psi| > 150 deg read 5-14 deg high, all ``ok``).

    Examples
    --------
    >>> bg = np.full((1, 4, 3), 200, np.uint8)
    >>> photo = np.array([[[150, 150, 150], [60, 60, 200], [200, 200, 200], [40, 40, 40]]],
    ...                  np.uint8)
    >>> shadow_mask(photo, bg).tolist()
    [[True, False, False, False]]
    """
    ratio = (image_bgr.astype(np.float32) + 4.0) / (background_bgr.astype(np.float32) + 4.0)
    b, g, r = cv2.split(ratio)  # per channel with OpenCV: the mask took 16 ms on a 1280x960
    mean = (b + g + r) / np.float32(3.0)  # photo, 34 with numpy's reductions over the last axis
    spread = cv2.max(cv2.max(b, g), r) - cv2.min(cv2.min(b, g), r)
    return (mean > darkest) & (mean < SHADOW_LIGHTEST) & (spread < SHADOW_RATIO_SPREAD)


def noisy_shadow_mask(image_bgr: np.ndarray, background_bgr: np.ndarray) -> np.ndarray:
    """:func:`shadow_mask`, also where it holds once both photos are smoothed (sigma
    :data:`SHADOW_SMOOTH_PX`): on a dark backdrop each channel's noise moves the three ratios
    apart."""
    image_smooth, background_smooth = (
        cv2.GaussianBlur(im, (0, 0), SHADOW_SMOOTH_PX) for im in (image_bgr, background_bgr)
    )
    return shadow_mask(image_bgr, background_bgr) | shadow_mask(image_smooth, background_smooth)


#: see noisy_shadow_mask
SHADOW_SMOOTH_PX = 1.5


#: a body is told from its shadow without an empty scene only when its colour differs from the
#: backdrop's by at least this chroma (Lab a, b: 8-bit units) over most of it
BODY_CHROMA = 8.0


def faint_differences(diff: np.ndarray) -> np.ndarray:
    """A difference from the empty scene, median-filtered, in units of its faint threshold.

    Over :data:`FAINT_MEDIAN_PX` px the median keeps a body's edges where they are (a Gaussian
    blur spread the clear sides' edges a pixel outwards) and takes most of the noise out; the
    threshold is :data:`FAINT_SIGMAS` of the filtered image's own noise (robust, over the whole
    photo: mostly backdrop), never below :data:`FAINT_DIFFERENCE`.  A camera's noise sets
    :func:`_weak_threshold` at its floor on most photos: the filtered difference is clear at
    half of it.

    Examples
    --------
    >>> d = np.zeros((40, 40), np.float32)
    >>> d[10:30, 10:30] = 4.5
    >>> f = faint_differences(d)
    >>> float(f[20, 20]), float(f[2, 2])
    (1.5, 0.0)
    """
    filtered = cv2.medianBlur(diff.astype(np.float32), FAINT_MEDIAN_PX)
    med = float(np.median(filtered))
    sigma = 1.4826 * float(np.median(np.abs(filtered - med)))
    return np.asarray(filtered / max(FAINT_SIGMAS * sigma, FAINT_DIFFERENCE), np.float32)


def clear_regions(added: np.ndarray, faint: np.ndarray) -> np.ndarray:
    """Where ``added`` (bool) lies in a connected region (8-connected) of it whose median of
    ``faint`` is at least :data:`FAINT_CLEAR` (bool).

    Examples
    --------
    >>> added = np.array([[1, 1, 0, 1, 1]], bool)
    >>> clear_regions(added, np.float32([[2.0, 1.8, 0, 1.1, 1.2]])).tolist()
    [[True, True, False, False, False]]
    """
    n, labels = cv2.connectedComponents(added.astype(np.uint8), connectivity=8)
    if n <= 1:
        return np.zeros(added.shape, bool)
    region, value = labels[added], faint[added]
    order = np.lexsort((value, region))
    counts = np.bincount(region, minlength=n)
    middle = np.cumsum(counts) - counts + (counts - 1) // 2  # each region's median, sorted
    clear = np.zeros(n, bool)
    present = counts > 0
    clear[present] = value[order][middle[present]] >= FAINT_CLEAR
    clear[0] = False
    return clear[labels] & added


def _hysteresis(
    diff: np.ndarray, high: float, low: float, faint: np.ndarray | None = None
) -> np.ndarray:
    """0/1 mask of the pixels above ``low`` connected to a pixel above ``high`` (as Canny's edges).

    ``faint`` (:func:`faint_differences`) adds the pixels over 1 in it within
    :data:`FAINT_REACH` times the reach of a clear pixel, each connected region of them where
    its median is at least :data:`FAINT_CLEAR`: where it is lower, they are speckle of a side at
    the threshold (which made the centre line wobble where leaving the side out altogether
    measured the body right), or light bounced onto the backdrop.

    Examples
    --------
    >>> d = np.array([[0, 5, 9, 5, 0, 5, 0]], np.float32)
    >>> _hysteresis(d, 8.0, 4.0).tolist()
    [[0, 1, 1, 1, 0, 0, 0]]
    >>> _hysteresis(d, 8.0, 4.0, np.float32([[0, 0, 0, 0, 2, 2, 0]])).tolist()
    [[0, 1, 1, 1, 1, 1, 0]]
    >>> _hysteresis(d, 8.0, 4.0, np.float32([[0, 0, 0, 0, 1.2, 1.2, 0]])).tolist()
    [[0, 1, 1, 1, 0, 0, 0]]

    Faint pixels count only within a few pixels of a clear one (:data:`GROW_FRACTION`).
    """
    strong = (diff > high).astype(np.uint8)
    # faint pixels next to clear ones only
    reach = max(3, round(GROW_FRACTION * max(diff.shape)))
    near = cv2.dilate(strong, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1,) * 2))
    above = (diff > low) & (near > 0)
    if faint is not None:
        # as far from a clear pixel as FAINT_REACH reaches (a distance: a dilation that wide
        # doubled the selection's time at 2000 px)
        far = cv2.distanceTransform(1 - strong, cv2.DIST_L2, 3) <= FAINT_REACH * reach
        added = (faint > 1.0) & far & ~above
        above |= added & clear_regions(added, faint)
    weak = above.astype(np.uint8)
    n, labels = cv2.connectedComponents(weak, connectivity=8)
    seeded = np.zeros(n, bool)
    seeded[np.unique(labels[diff > high])] = True
    seeded[0] = False
    return seeded[labels].astype(np.uint8)


@dataclass(frozen=True, eq=False)
class BodySelection:
    """What the settings select in a photo, before one component is chosen (:func:`body_mask`).

    Attributes
    ----------
    mask : ndarray (H, W) uint8 0/1
    strength : ndarray (H, W) float32
        How clearly each pixel differs (for previews), 0 where not computed.
    contrast : float
        Median difference of the selected pixels in backdrop-noise sigmas (inf for colour only).
    hollow_width_px : float
        The width (work px) of a long region the selection outlines, larger than its walls, whose
        inside does not differ from the background (:func:`fill_outlined`; 0 for none): a clear
        body seen by its rims only, when far wider than what is measured.
    faint_taken : bool
        A faint side was taken into the selection (:func:`faint_differences`).
    """

    mask: np.ndarray
    strength: np.ndarray
    contrast: float
    hollow_width_px: float = 0.0
    faint_taken: bool = False


def faint_share(selection: BodySelection, comp: np.ndarray) -> float:
    """The share of the body ``comp`` (0/1) that differs from the background by less than the
    clear threshold (:attr:`BodyExtraction.faint_share`; 0 for a colour-only selection)."""
    if not np.isfinite(selection.contrast) or not comp.any():
        return 0.0
    return float(np.mean(selection.strength[comp > 0] < 1.0))


def body_mask(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    *,
    scale: float = 1.0,
    background_bgr: np.ndarray | None = None,
    faint_sides: bool = True,
) -> BodySelection:
    """The pixels of the actuator body (before choosing one component).

    Parameters
    ----------
    image_bgr : ndarray (H, W, 3) uint8
        The photo, reduced by ``scale``.
    settings : MeasureSettings
        ``color``, ``roi``, ``exclude`` are used.
    scale : float
        Original px per px of ``image_bgr``.
    background_bgr : ndarray, optional
        The empty-scene photo at the same size.
    faint_sides : bool
        Take a faint side in (:func:`faint_differences`); False: what was selected before faint
        sides were (a reading with one that is not ``ok`` is read again so).

    Returns
    -------
    BodySelection
    """
    h, w = image_bgr.shape[:2]
    region = region_mask(image_bgr.shape, settings.roi, settings.exclude, scale)
    allowed = np.ones((h, w), np.uint8) if region is None else region
    strength: np.ndarray = np.zeros((h, w), np.float32)
    contrast = float("inf")
    hollow, taken_any = 0.0, False
    if not allowed.any():  # roi / exclude leave nothing to look at (the backdrop model crashed)
        return BodySelection(allowed.copy(), strength, contrast)
    mask = allowed.copy()
    if settings.color is not None:
        mask &= color_mask(image_bgr, settings.color)
    if settings.color is None or background_bgr is not None:
        shade = None  # the body's shadow on the empty scene: it differs from it too
        keep = SHADOW_KEEP  # ... left out unless that loses this share of the selection
        if background_bgr is not None and settings.background_estimated:
            assert settings.background_path is not None
            like = estimate_looks_like_backdrop(
                settings.background_path, (h, w), settings.roi, settings.exclude, scale
            )
            estimate = matched_exposure(background_bgr, image_bgr)
            diff, sigma = estimated_background_difference(image_bgr, estimate, allowed, like)
            # where the estimate is the backdrop (elsewhere it shows the body itself): left in,
            # the shadow widened the body on one side and |psi| near 215 deg read 5-9 deg high
            shade = noisy_shadow_mask(image_bgr, estimate) & (like > 0)
        elif background_bgr is not None:
            background_bgr = matched_exposure(background_bgr, image_bgr)
            diff, sigma = background_difference(image_bgr, background_bgr)
            shade = noisy_shadow_mask(image_bgr, background_bgr)
        else:
            seen = exposed(image_bgr, allowed)
            diff, sigma, backdrop = backdrop_difference(seen, allowed)
            # the body's shadow on the backdrop, against the backdrop's own colours: selected
            # with the body, it widened it on one side; a neutral body's shaded side would look
            # like one, so only a coloured body's is left out
            shade, chroma = backdrop_shadows(
                seen, backdrop, diff > _weak_threshold(sigma), diff > _threshold(sigma)
            )
            if chroma < BODY_CHROMA:
                shade = None
            keep = SHADOW_KEEP_NO_BACKGROUND
        # any clear difference is body: a translucent body differs faintly (splitting the
        # differences in two, faint vs strong, cut translucent bodies down to their highlights)
        thr, low = _threshold(sigma), _weak_threshold(sigma)
        differs = _hysteresis(diff, thr, low)
        unlit = None
        if shade is not None:
            lit = _hysteresis(np.where(shade, 0.0, diff), thr, low)
            if lit.sum() >= keep * differs.sum():
                differs, unlit = lit, shade
        if (
            faint_sides
            and (unlit is not None or shade is None)
            and not settings.background_estimated
        ):
            # a faint side counts too, where the shadows are told apart or none is looked for
            # (a neutral body without an empty scene): where the body is not told from its
            # shadow, a faint margin is its shadow's (customer 55's strong shadow gave more rows
            # ok 5-14 deg off); against the empty scene estimated from a ramp, 8 of a bench set's
            # 42 second looks were lost
            out = np.zeros(diff.shape, bool) if unlit is None else unlit
            faint = np.where(out, 0.0, faint_differences(diff))
            if background_bgr is None:
                # against the backdrop's colour, only where lighter than it: a neutral body's
                # shadow is not told apart there (taken in, 4 of customer 55's ramps without
                # their empty scene had rows ok 5-18 deg off)
                faint = np.where(_lab(seen)[:, :, 0] > backdrop[0][:, :, 0], faint, 0.0)
            taking = _hysteresis(np.where(out, 0.0, diff), thr, low, faint)
            taken = (taking > 0) & (differs == 0)
            if taken.any() and np.mean(faint[taken] <= FAINT_MARGINAL) < FAINT_MARGINAL_SHARE:
                differs, taken_any = taking, True
        if background_bgr is None or not settings.background_estimated:
            differs, hollow = fill_outlined(differs, diff, allowed, OUTLINE_FILL_SIGMAS * sigma)
        mask &= differs
        strength = diff / max(thr, 1e-6)
        if unlit is not None:
            # the shadow does not place the body's edges either: beside a clamp's shadow the
            # edge crept out by a fraction of a pixel, enough to turn the base by 1 deg (customer
            # 34's straight body read -0.9 deg at its clamp; its ramps' median error 1.4-2.6)
            strength[unlit & (mask == 0)] = 0.0
        sel = diff[mask > 0]
        contrast = float(np.median(sel) / sigma) if sel.size else 0.0
    return BodySelection(mask, strength, contrast, hollow, taken_any)


def _texture_disc(shape: tuple[int, ...]) -> np.ndarray:
    """The structuring element as wide as a body's texture gaps in a photo of ``shape``."""
    k = max(3, round(0.006 * max(shape[:2])) | 1)
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))


def fill_outlined(
    differs: np.ndarray, diff: np.ndarray, allowed: np.ndarray, faint: float
) -> tuple[np.ndarray, float]:
    """``differs`` (0/1) with the inside of a clear body its outline encloses added, and the
    width (px, 0 for none) of a long region it outlines and left out, larger than its walls,
    where nothing was taken in (a clear body whose inside does not differ, seen by its rims).

    A clear silicone body on a backdrop of its grey shows its edges brightly (they refract the
    light) and its inside only a few levels off the backdrop seen through it: customer 33's,
    8 Lab units off its empty scene, was selected as its two edges, read as two bodies, and 0 of
    68 photos were ``ok`` (4 with the empty scene).  A region that the selection, closed over
    texture gaps, encloses, together with the region left out (``allowed`` 0: the clamp plate
    under ``exclude``, where the outline is open), is taken in when its median ``diff`` is over
    ``faint`` (the backdrop inside a ring is not), the selection runs along at least
    :data:`OUTLINE_RIM_SHARE` of its rim (a pocket of backdrop between a body and the plate is
    bounded by the plate) and it is elongated (:data:`OUTLINE_MIN_ELONGATION`: the face of a
    clamp block outlined at the fixed end is not; taken in, it moved the base of rendered
    translucent bodies and read one 5.6 deg off), or is compact in a photo where an elongated
    one is taken in (a tip cap outlined on its own: left out, customer 33's tips read 6-11 deg
    low, ``ok``).  Regions that reach the photo's border or are
    larger than :data:`OUTLINE_MAX_SHARE` of the allowed area are never taken in.

    Where nothing passes and the selection is the outline of a long region larger than its walls,
    that region is taken in when its median ``diff`` is over nine in ten of the backdrop's (the
    regions that reach the photo's border) and over half ``faint``: customer 36's clear body on
    grey differed 2.3-2.6 noise sigmas inside, the backdrop 1.8 at its ninth tenth, and was
    read as its rims (no photo ``ok``).  Smaller regions are not: a sliver between a highlight
    and an edge, taken in so, brought the clamp block's face in with it (a compact region) and
    a rendered body read 6.4 deg high, ``ok``.  Left out, the outline is said to be hollow.

    Examples
    --------
    >>> differs = np.zeros((60, 80), np.uint8)
    >>> differs[8:10, 5:45] = 1; differs[20:22, 5:45] = 1; differs[8:22, 43:45] = 1  # an outline
    >>> allowed = np.ones_like(differs); allowed[:, :6] = 0                        # a plate
    >>> diff = np.zeros((60, 80), np.float32); diff[10:20, 6:43] = 5.0          # a faint inside
    >>> filled, hollow = fill_outlined(differs, diff, allowed, 3.0)
    >>> int(filled[15, 20]), hollow
    (1, 0.0)
    >>> filled, hollow = fill_outlined(differs, 0.4 * diff, allowed, 3.0)  # over the backdrop's
    >>> int(filled[15, 20]), hollow
    (1, 0.0)
    >>> filled, hollow = fill_outlined(differs, 0 * diff, allowed, 3.0)  # the backdrop's own
    >>> int(filled[15, 20]), round(hollow)                     # left out: 10 px wide
    (0, 10)
    """
    h, w = differs.shape
    disc = _texture_disc(differs.shape)
    wall = cv2.morphologyEx(
        ((differs > 0) | (allowed == 0)).astype(np.uint8), cv2.MORPH_CLOSE, disc
    )
    n, labels, stats, _ = cv2.connectedComponentsWithStats(1 - wall, connectivity=4)
    near = cv2.dilate(differs, disc)
    long_fill = np.zeros_like(differs)
    compact: list[tuple[tuple[slice, slice], np.ndarray]] = []
    largest = OUTLINE_MAX_SHARE * float(allowed.sum())
    # long regions whose inside is fainter, larger than their walls: (area, median, box,
    # inside, widest)
    hollow: list[tuple[int, float, tuple[slice, slice], np.ndarray, float]] = []
    for lab in range(1, n):
        x, y, bw, bh, area = (int(v) for v in stats[lab])
        if x == 0 or y == 0 or x + bw == w or y + bh == h or area > largest:
            continue
        box = (slice(y - 1, y + bh + 1), slice(x - 1, x + bw + 1))
        inside = (labels[box] == lab).astype(np.uint8)
        rim = cv2.dilate(inside, np.ones((3, 3), np.uint8)) - inside
        on_outline = float((rim & near[box]).sum()) / max(1.0, float(rim.sum()))
        if on_outline < OUTLINE_RIM_SHARE:
            continue
        widest = 2.0 * float(cv2.distanceTransform(inside, cv2.DIST_L2, 3).max())
        elongated = area >= OUTLINE_MIN_ELONGATION * widest**2
        median = float(np.median(diff[box][inside > 0]))
        if median > faint:
            if elongated:
                long_fill[box][inside > 0] = 1
            else:
                compact.append((box, inside))
        elif elongated and area > _walls_px(labels, lab, (x, y, bw, bh), differs, widest):
            hollow.append((area, median, box, inside, widest))
    if long_fill.any():
        hollow = []  # the body's inside is found: a long pocket of backdrop is no outline
    elif hollow:
        # all the selection is the outline: its inside is taken in when it differs more than
        # nine in ten of the backdrop's pixels do (the regions reaching the photo's border)
        border = np.unique(np.r_[labels[0], labels[-1], labels[:, 0], labels[:, -1]])
        backdrop = diff[np.isin(labels, border[border > 0]) & (allowed > 0)]
        level = max(float(np.percentile(backdrop, 90)) if backdrop.size else np.inf, 0.5 * faint)
        for region in sorted(hollow, key=lambda r: -r[1]):  # the clearest first
            if region[1] > level:
                long_fill[region[2]][region[3] > 0] = 1
                hollow = []
                break
    out = differs | long_fill
    if long_fill.any():  # with the body's inside: its tip cap, outlined on its own
        for box, inside in compact:
            out[box][inside > 0] = 1
    return out, max((r[4] for r in hollow), default=0.0)


def _walls_px(
    labels: np.ndarray,
    lab: int,
    box_xywh: tuple[int, int, int, int],
    differs: np.ndarray,
    reach_px: float,
) -> int:
    """How many selected pixels lie within ``reach_px`` (the width of region ``lab``) of it: its
    walls, not all of the photo's selection (a ruler or a second object in view turned the fill
    of a clear body's faint inside off).  A clear body's rims are a few px thick; the arms of
    an opaque body's hairpin that close a pocket of backdrop are as large as the pocket."""
    x, y, bw, bh = box_xywh
    k = max(int(np.ceil(reach_px)), 1)
    box = (slice(max(y - k, 0), y + bh + k), slice(max(x - k, 0), x + bw + k))
    region = (labels[box] == lab).astype(np.uint8)
    band = cv2.dilate(region, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * k + 1,) * 2))
    return int((band & (1 - region) & differs[box]).sum())


def _clean(mask: np.ndarray) -> np.ndarray:
    """Close texture gaps, fill small holes, open away specks."""
    disc = _texture_disc(mask.shape)
    m = cv2.morphologyEx(mask, cv2.MORPH_CLOSE, disc)
    m = cv2.morphologyEx(m, cv2.MORPH_OPEN, disc)
    contours, hier = cv2.findContours(m, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
    if hier is not None:
        area = float(m.sum())
        holes = [
            c
            for c, hh in zip(contours, hier[0])
            if hh[3] != -1 and cv2.contourArea(c) < MAX_HOLE_FRACTION * area
        ]
        if holes:
            cv2.drawContours(m, holes, -1, 1, cv2.FILLED)
    return m


#: a PneuNet's chambers: the gaps between them are closed over up to this many half-widths wide
#: (the chambers' own half-height, as the ridge through them reads it) ...
CHAMBER_GAP_HALF_WIDTHS = 1.5
#: ... where at least CHAMBER_GAPS_MIN of them, each a slot at least CHAMBER_GAP_DEPTH
#: half-widths long, twice as long as it is wide and at least CHAMBER_GAP_AREA square
#: half-widths large (a translucent body's faint patches and dots leave smaller ones)
CHAMBER_GAPS_MIN, CHAMBER_GAP_DEPTH, CHAMBER_GAP_AREA = 3, 0.5, 0.2


def fill_chamber_gaps(comp: np.ndarray, half: float) -> np.ndarray:
    """``comp`` with the gaps between a row of chambers filled (a PneuNet seen from the side: a
    comb of chambers on the layer that does not stretch), or ``comp`` itself where it shows no
    such row.

    The body of a chambered actuator is the envelope of its chambers: its centre line runs
    between the layer and the chambers' tops.  Unfilled, the ridge of the selection zig-zagged
    into every chamber and out through the strip below each gap (customer 48's PneuNets, 20 mm
    high with 1.6 mm gaps: no photo above 10 kPa `ok`).  A closing as wide as
    :data:`CHAMBER_GAP_HALF_WIDTHS` half-widths fills the gaps; it is kept where it fills at least
    :data:`CHAMBER_GAPS_MIN` slots at least :data:`CHAMBER_GAP_DEPTH` half-widths long, twice as
    long as wide and :data:`CHAMBER_GAP_AREA` large (which side of the body they open to is not
    checked), and where the body filled has no more holes than before (two arms of a curl
    bridged enclose backdrop; earlier clean-up has filled the body's own small holes).

    Examples
    --------
    >>> comb = np.zeros((60, 200), np.uint8)
    >>> comb[35:45, 10:190] = 1  # the layer
    >>> for x in range(10, 190, 20):
    ...     comb[15:35, x : x + 16] = 1  # chambers 16 px wide, 4 px gaps
    >>> filled = fill_chamber_gaps(comb, 14.0)
    >>> int(comb[25, 26:30].sum()), int(filled[25, 26:30].sum())
    (0, 4)
    >>> solid = np.zeros((60, 200), np.uint8); solid[15:45, 10:190] = 1
    >>> fill_chamber_gaps(solid, 15.0) is solid
    True
    """
    d = max(5, round(float(CHAMBER_GAP_HALF_WIDTHS * half)) | 1)
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (d, d))
    # on the body's box alone, with a margin the closing cannot reach past (the whole photo's
    # took 0.1-0.4 s at 1280x960)
    x, y, w, h = cv2.boundingRect(comp)
    if w == 0 or h == 0:
        return comp
    x0, y0 = max(0, x - d), max(0, y - d)
    box = comp[y0 : y + h + d, x0 : x + w + d]
    added = (cv2.morphologyEx(box, cv2.MORPH_CLOSE, disc) > 0) & (box == 0)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(added.astype(np.uint8), connectivity=8)
    slots = []
    for i in range(1, n):
        if stats[i, cv2.CC_STAT_AREA] < max(4.0, CHAMBER_GAP_AREA * half * half):
            continue
        ys, xs = np.nonzero(labels == i)
        (_, _), (a, b), _ = cv2.minAreaRect(np.c_[xs, ys].astype(np.float32))
        if max(a, b) >= CHAMBER_GAP_DEPTH * half and max(a, b) >= 2.0 * min(a, b):
            slots.append(i)
    if len(slots) < CHAMBER_GAPS_MIN:
        return comp
    out = comp.copy()
    out[y0 : y + h + d, x0 : x + w + d] |= np.isin(labels, slots).astype(np.uint8)

    def holes(m: np.ndarray) -> int:
        _, hier = cv2.findContours(m, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
        return 0 if hier is None else int((hier[0][:, 3] != -1).sum())

    return out if holes(out) <= holes(comp) else comp


#: a hole in the body is its inside, not the space a curl encloses, where the body filled is no
#: thicker over it than this many of the body's half-widths
INNER_HOLE_HALF_WIDTHS = 1.25


def fill_inner_holes(comp: np.ndarray, half: float) -> np.ndarray:
    """``comp`` with the holes inside the body's own outline filled, or ``comp`` itself where
    there are none.

    A translucent body's faint stretch beside a highlight leaves a slot in the selection too large
    for :func:`_clean`'s :data:`MAX_HOLE_FRACTION` (customer 53: a slot 6 % of the body, between a
    specular streak and a dot; the profiles across the body stopped at it, the centre line ran
    along the inner half and stopped 55 % along, and six right photos at 100-120 kPa were
    flagged).  A hole is filled where the body, filled, is no thicker over it than
    :data:`INNER_HOLE_HALF_WIDTHS` half-widths (``half``: where the body is not beside a hole):
    the inside of a ring, or the backdrop between two arms of a curl, makes it thicker.

    Examples
    --------
    >>> comp = np.zeros((40, 200), np.uint8); comp[10:30, 10:190] = 1
    >>> comp[14:18, 40:160] = 0  # a slot inside a body 20 px wide
    >>> int(fill_inner_holes(comp, 10.0)[14:18, 40:160].min())
    1
    >>> ring = np.zeros((100, 100), np.uint8)
    >>> _ = cv2.circle(ring, (50, 50), 40, 1, 12)  # a ring 12 px wide round a hole 68 px across
    >>> fill_inner_holes(ring, 6.0) is ring
    True
    """
    contours, hier = cv2.findContours(comp, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
    if hier is None or not (hier[0][:, 3] != -1).any():
        return comp
    holes = [c for c, hh in zip(contours, hier[0]) if hh[3] != -1]
    filled = comp.copy()
    cv2.drawContours(filled, holes, -1, 1, cv2.FILLED)
    thick = cv2.distanceTransform(filled, cv2.DIST_L2, 5)
    inner = []
    for c in holes:
        x, y, w, h = cv2.boundingRect(c)  # the hole's own box, not the whole photo per hole
        one = np.zeros((h, w), np.uint8)
        cv2.drawContours(one, [c], -1, 1, cv2.FILLED, offset=(-x, -y))
        if float(thick[y : y + h, x : x + w][one > 0].max()) <= INNER_HOLE_HALF_WIDTHS * half:
            inner.append(c)
    if not inner:
        return comp
    out = comp.copy()
    cv2.drawContours(out, inner, -1, 1, cv2.FILLED)
    return out


def _component(
    mask: np.ndarray, fixed_xy: tuple[float, float] | None
) -> tuple[np.ndarray, int, bool]:
    """The body component: nearest the fixed end (among large ones), else the largest.

    Returns (component mask, number of rival components of comparable size, fixed end reached).
    """
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask, connectivity=8)
    if n <= 1:
        raise NoLineFound("nothing selected")
    areas = stats[1:, cv2.CC_STAT_AREA].astype(float)
    order = np.argsort(-areas)
    big = [int(i) + 1 for i in order if areas[i] >= 0.25 * areas[order[0]]]
    pick, reached = big[0], fixed_xy is None
    if fixed_xy is not None:
        h, w = mask.shape
        fx, fy = (
            int(np.clip(round(fixed_xy[0]), 0, w - 1)),
            int(np.clip(round(fixed_xy[1]), 0, h - 1)),
        )
        best = None
        for lab in big + [int(i) + 1 for i in order if int(i) + 1 not in big][:5]:
            comp = (labels == lab).astype(np.uint8)
            d = cv2.distanceTransform(1 - comp, cv2.DIST_L2, 3)[fy, fx]
            if best is None or d < best[0]:
                best = (d, lab)
        assert best is not None
        near = 0.05 * float(np.hypot(h, w))
        if best[0] <= near:
            pick, reached = best[1], True
    rivals = sum(1 for lab in big if lab != pick)
    return (labels == pick).astype(np.uint8), rivals, reached


#: another selection smaller than the body that reaches the fixed end given, and farther from
#: it than this fraction of the photo's diagonal, is no rival body (a label or a ruler in a
#: corner: customer 49's 15 of 84 right rows flagged "2 candidate bodies")
RIVAL_FAR_FRACTION = 0.1


def _rivals(others: np.ndarray, comp: np.ndarray, *, far_apart: bool) -> int:
    """How many components of ``others`` (the selection less the body ``comp``) are a quarter
    of the body's area or more: rival bodies.  With ``far_apart`` (the body reaches the fixed
    end given) one smaller than the body lying farther than :data:`RIVAL_FAR_FRACTION` of the
    photo's diagonal from it is not counted: a part of this body beyond a gap lies nearer, or
    ahead of its free end (``BodyExtraction.continues``), and a larger one still counts (the
    body may be a stub at the clamp).

    Examples
    --------
    >>> comp = np.zeros((100, 200), np.uint8); comp[40:50, 10:150] = 1
    >>> others = np.zeros_like(comp); others[85:99, 170:199] = 1  # a label in a corner
    >>> _rivals(others, comp, far_apart=True), _rivals(others, comp, far_apart=False)
    (0, 1)
    >>> others[55:60, 10:150] = 1  # a ruler beside the body
    >>> _rivals(others, comp, far_apart=True)
    1
    """
    n, labels, stats, _ = cv2.connectedComponentsWithStats(others, connectivity=8)
    area = float(comp.sum())
    big = [i for i in range(1, n) if stats[i, cv2.CC_STAT_AREA] >= 0.25 * area]
    if not far_apart or not big:
        return len(big)
    away = cv2.distanceTransform((1 - comp).astype(np.uint8), cv2.DIST_L2, 3)
    far = RIVAL_FAR_FRACTION * float(np.hypot(*comp.shape))
    return sum(
        1
        for i in big
        if stats[i, cv2.CC_STAT_AREA] >= area or float(away[labels == i].min()) <= far
    )


#: the ridge's far end is not one reached only across a block: when the widest point on the way
#: to the selection's farthest pixel is more than :data:`BLOB_THICKNESS` times the ridge's median
#: thickness, the way crosses a clamp block or plate that the selection took in, with the tube
#: behind it (in a view that shows more of the rig the tube is the farthest part: 12 and 16 of 60
#: rendered bodies ok and within 5 deg at 0.6 mm/px, seeds 30 and 77).  The far end is then the
#: farthest pixel reached without crossing anything within this factor of that width ...
CROSSING_MARGIN = 1.15
#: ... provided that part is long: at least this fraction of the way to the farthest pixel ...
OTHER_BRANCH_FRACTION = 0.25
#: ... and this many times the widest point on its own way (a body, not a stub of the outline)
OTHER_BRANCH_HALF_WIDTHS = 8.0
#: ... and when that block lies by the fixed end: within this fraction of the way to the other
#: part's end (a clamp and its tube; a dot on a highlight stripe lies where the other part stops)
BLOCK_NEAR_START_FRACTION = 0.5
#: a way to the farthest pixel shorter than this many times the median thickness along its ridge
#: runs through a plate that reaches the photo's border, not along a body (the rendered bodies
#: are 18-40 times as long as their half-width); the other, long part is taken instead when its
#: ridge is more than :data:`BLOB_THICKNESS` times thinner
PLATE_HALF_WIDTHS = 10.0


def _max_along(values: np.ndarray, pred: np.ndarray) -> np.ndarray:
    """Largest of ``values`` on each node's way back to the root of a shortest-path tree
    (``pred``: each node's predecessor, negative at the root and unreached nodes).

    Examples
    --------
    >>> _max_along(np.array([1.0, 5.0, 2.0, 3.0]), np.array([-9999, 0, 1, 0])).tolist()
    [1.0, 5.0, 5.0, 3.0]
    """
    m = values.astype(float).copy()
    p = np.where(pred < 0, np.arange(len(pred)), pred)
    while True:  # pointer doubling: each pass looks twice as far back
        m2, p2 = np.maximum(m, m[p]), p[p]
        if np.array_equal(p2, p) and np.array_equal(m2, m):
            return m
        m, p = m2, p2


def _walk(pred: np.ndarray, start: int, end: int) -> list[int]:
    """Nodes from ``start`` back along ``pred`` (a tree rooted at ``end``) to ``end``."""
    path = [start]
    while path[-1] != end and pred[path[-1]] >= 0:
        path.append(int(pred[path[-1]]))
    return path


def _ridge_path(
    comp: np.ndarray, dt: np.ndarray, start_xy: tuple[float, float] | None
) -> tuple[np.ndarray, bool]:
    """Pixel path (x, y) along the body's ridge from the fixed end (or an end) to the far end.

    The far end is the pixel farthest from the start within the selection, unless the way there
    crosses a block by the start or runs through a plate (see :data:`CROSSING_MARGIN`,
    :data:`BLOCK_NEAR_START_FRACTION` and :data:`PLATE_HALF_WIDTHS`).
    """
    ys, xs = np.nonzero(comp)
    graph = _pixel_graph(ys, xs, comp.shape)
    # edge cost: length / (distance to the edge)^2 -> the path keeps to the middle of the body
    cost = 1.0 / np.maximum(dt[ys, xs], 0.5) ** 2
    graph = graph.tocoo()
    graph.data = graph.data * 0.5 * (cost[graph.row] + cost[graph.col])
    graph = graph.tocsr()
    plain = _pixel_graph(ys, xs, comp.shape)
    guessed = start_xy is None
    if start_xy is None:
        d0 = dijkstra(plain, directed=True, indices=int(np.argmax(dt[ys, xs])))
        d0[~np.isfinite(d0)] = -1
        seed = int(np.argmax(d0))
    else:
        seed = int(np.argmin((xs - start_xy[0]) ** 2 + (ys - start_xy[1]) ** 2))
    geo, way = dijkstra(plain, directed=True, indices=seed, return_predecessors=True)
    geo[~np.isfinite(geo)] = -1
    far = int(np.argmax(geo))
    _, pred = dijkstra(graph, directed=True, indices=far, return_predecessors=True)
    path = _walk(pred, seed, far)
    if not guessed:
        crossed = _max_along(dt[ys, xs], way)
        thin = (crossed <= crossed[far] / CROSSING_MARGIN) & (geo >= 0)
        alt = int(np.flatnonzero(thin)[np.argmax(geo[thin])]) if thin.any() else far
        if geo[alt] >= max(
            OTHER_BRANCH_FRACTION * geo[far], OTHER_BRANCH_HALF_WIDTHS * crossed[alt]
        ):
            along = float(np.median(dt[ys[path], xs[path]]))
            way_far = np.array(_walk(way, far, seed))
            widest = way_far[int(np.argmax(dt[ys[way_far], xs[way_far]]))]
            # a block on the way (to the tube), by the fixed end: not a wider part further along
            # the body (a marker dot on a stripe of it) just past where the other part stops
            block = (
                crossed[far] > BLOB_THICKNESS * along
                and geo[widest] <= BLOCK_NEAR_START_FRACTION * geo[alt]
            )
            plate = geo[far] < PLATE_HALF_WIDTHS * along  # the way runs through a plate
            if block or plate:
                _, pred = dijkstra(graph, directed=True, indices=alt, return_predecessors=True)
                other = _walk(pred, seed, alt)
                if block or along > BLOB_THICKNESS * float(np.median(dt[ys[other], xs[other]])):
                    path = other
    idx = np.array(path)
    return np.c_[xs[idx], ys[idx]].astype(float), guessed


def _resample(points: np.ndarray, step: float) -> np.ndarray:
    seg = np.hypot(*np.diff(points, axis=0).T)
    s = np.concatenate(([0.0], np.cumsum(seg)))
    if s[-1] <= step:
        return points
    u = np.arange(0.0, s[-1] + 1e-9, step)
    return np.c_[np.interp(u, s, points[:, 0]), np.interp(u, s, points[:, 1])]


def _smooth(points: np.ndarray, sigma: float) -> np.ndarray:
    """Smooth a 1-px-spaced polyline over about ``sigma`` px with local quadratic fits.

    Savitzky-Golay (order 2, ends fitted, not mirrored) keeps the curvature at the ends, where
    a mirrored Gaussian would straighten them and bias the end tangents.
    """
    from scipy.signal import savgol_filter

    win = int(2 * round(1.5 * sigma) + 1)
    if sigma <= 0 or len(points) < max(win, 5):
        return points
    return np.c_[
        savgol_filter(points[:, 0], win, 2, mode="interp"),
        savgol_filter(points[:, 1], win, 2, mode="interp"),
    ]


def _normals(points: np.ndarray) -> np.ndarray:
    t = np.gradient(points, axis=0)
    t /= np.maximum(np.hypot(t[:, 0], t[:, 1]), 1e-9)[:, None]
    return np.c_[-t[:, 1], t[:, 0]]


#: edge-to-edge width outside [END_WIDTH_LOW, END_WIDTH_HIGH] x the median at an end of the centre
#: line: the normal there runs into the clamp or round the tip, and that end is dropped
END_WIDTH_LOW, END_WIDTH_HIGH = 0.8, 1.2
#: ... and at the fixed end, the first points whose width is more than this times the body's:
#: a clamp block hardly wider than a fat body (25-30 mm wide) is not cut off as a blob, and where
#: a profile there reaches into it, its middle slides off towards the block's side, more so with
#: each pass (the centre line hooked 4-8 px over its first 15 and read the base 5-8 deg off,
#: either way; such profiles are 1.13-1.18x the body's width, those of a body without a block
#: at most 1.07x in the rendered photos looked at)
FACE_WIDTH_HIGH = 1.1
#: the centre line holds where the body is at least this fraction of its usual half-width ...
TIP_THICKNESS = 0.95
#: ... and at most this multiple of it (thicker: the clamp or a blob the body runs into)
BLOB_THICKNESS = 1.6
#: a taper is judged against the thickness this far (half-widths) inside the end
LOCAL_FROM_END_HALF_WIDTHS = (3.0, 10.0)
#: ... but not below this fraction of the whole body's half-width (a long taper is still a tip)
LOCAL_THICKNESS_FLOOR = 0.7
#: widths are judged against their running median over this many half-widths of the line
LOCAL_WIDTH_HALF_WIDTHS = 12.0


def _trim_by_thickness(
    path: np.ndarray, dt: np.ndarray, half: float
) -> tuple[np.ndarray, tuple[float, float]]:
    """Drop the path's ends where the body tapers (tips, corners) or thickens (clamp, blobs).

    A taper is judged against the body's own thickness just inside that end (a body that is
    thinner towards its tip, or whose faint side fades there, is not cut in half), but never
    against less than :data:`LOCAL_THICKNESS_FLOOR` of ``half``; a thickening against the whole
    body's half-width ``half``.  Returns the kept path and the length dropped at
    each end (px): the line goes on that far.
    """
    xi, yi = np.round(path[:, 0]).astype(int), np.round(path[:, 1]).astype(int)
    thick = dt[yi, xi]
    s = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
    not_blob = thick <= BLOB_THICKNESS * half
    ends = []
    for from_end in (s, s[-1] - s):
        near = (
            (from_end >= LOCAL_FROM_END_HALF_WIDTHS[0] * half)
            & (from_end <= LOCAL_FROM_END_HALF_WIDTHS[1] * half)
            & not_blob
        )
        ref = float(np.median(thick[near])) if near.sum() >= 3 else half
        ends.append(
            (thick >= TIP_THICKNESS * float(np.clip(ref, LOCAL_THICKNESS_FLOOR * half, half)))
            & not_blob
        )
    good_start, good_end = ends
    if good_start.sum() < 8 or good_end.sum() < 8:
        return path, (0.0, 0.0)
    i0, i1 = int(np.argmax(good_start)), len(path) - 1 - int(np.argmax(good_end[::-1]))
    if i1 - i0 < 8:
        return path, (0.0, 0.0)
    # a tapering tip ends about one half-width beyond the last thick point
    return path[i0 : i1 + 1], (float(s[i0]), float(s[-1] - s[i1]))


def base_side_split_deg(
    centreline_px: np.ndarray, widths_px: np.ndarray, window_fraction: float
) -> float:
    """The angle (deg) between the body's two sides where it leaves the fixed end: how fast its
    measured width changes along the first ``window_fraction`` of its centre line (the stretch
    its base direction is read over), signed (+ widening).

    Where only one side moves (a faint or shaded side whose edge is found further in where the
    light is dimmer, or a bulge at the clamp on one side) the centre line between them turns by
    half of it, and the base direction with it: a white body on grey lit from one side, its
    shaded side barely brighter than the backdrop and lit more strongly by the clamp, read
    widths falling 3 deg and its base 8 deg off (customer 31).  NaN for fewer than 3 points.

    Examples
    --------
    >>> s = np.linspace(0.0, 200.0, 201)
    >>> line = np.c_[np.zeros_like(s), s]
    >>> abs(round(base_side_split_deg(line, np.full(201, 20.0), 0.15), 3))
    0.0
    >>> round(base_side_split_deg(line, 30.0 - np.tan(np.deg2rad(3.0)) * s, 0.15), 2)
    -3.0
    """
    pts = np.asarray(centreline_px, float)
    w = np.asarray(widths_px, float)
    if len(pts) < 3 or len(w) != len(pts):
        return float("nan")
    s = np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]
    win = (s <= window_fraction * s[-1]) & np.isfinite(w)
    if win.sum() < 3:
        return float("nan")
    return float(np.rad2deg(np.arctan(np.polyfit(s[win], w[win], 1)[0])))


def local_widths(widths: np.ndarray, window: int) -> np.ndarray:
    """Running median of the body's width along its centre line (``window`` points), NaNs ignored.

    The reference a width is judged against at each point: real bodies thin towards the tip, and
    a faint side fades in one part of a photo, so one median for the whole body would call a
    whole stretch "too thin".

    Examples
    --------
    >>> local_widths(np.array([10.0, 10, np.nan, 10, 6, 6, 6, 6]), 3).tolist()
    [10.0, 10.0, 10.0, 8.0, 6.0, 6.0, 6.0, 6.0]
    """
    w = pd.Series(widths, dtype=float)
    ref = w.rolling(max(1, window), center=True, min_periods=1).median()
    return ref.fillna(
        float(np.nanmedian(widths)) if np.isfinite(widths).any() else np.nan
    ).to_numpy()


def _soft_body(comp: np.ndarray, strength: np.ndarray) -> np.ndarray:
    """The body as a 0..1 field whose 0.5 level is its sub-pixel edge.

    Inside and outside it is the chosen component; in a band along its outline it is the colour
    difference scaled so that the body's typical difference is 1 (the 0.5 crossing of a blurred
    step is the edge), which follows the true, anti-aliased outline instead of the mask's pixel
    staircase.  Without a difference (a colour-only selection) the mask is blurred instead.
    """
    body = comp.astype(np.float32)
    inner = cv2.erode(comp, np.ones((5, 5), np.uint8))
    level = float(np.median(strength[inner > 0])) if inner.any() else 0.0
    if level <= 1.0:  # no difference image, or too faint to locate edges by
        return cv2.GaussianBlur(body, (0, 0), 0.7)
    band = (cv2.dilate(comp, np.ones((5, 5), np.uint8)) > 0) & (inner == 0)
    soft = body.copy()
    soft[band] = np.clip(strength[band] / level, 0.0, 1.0)
    return soft


#: an edge this close to the image border (px) is the border's, not the body's
BORDER_PX = 1.0
#: the free end, for "the tip may be outside the photo": the last this many half-widths of the
#: centre line (at least a tenth of it) and the length carried on beyond it
TIP_BORDER_HALF_WIDTHS = 4.0
#: the ridge's last this many half-widths are a tip's corners or its cap, not its course
RIDGE_TIP_HALF_WIDTHS = 2.0
#: the march goes on while the body's width stays within these fractions of its width near that
#: end: a cap 15-20 % wider than the body is not the body (marching into it turned the tip by
#: 5-7 deg at |psi| ~ 220 on rendered capped bodies); a blurred, rounded tip is (1.1 stopped short
#: of a faint translucent tip)
MARCH_WIDTH_LOW, MARCH_WIDTH_HIGH = 0.8, 1.15
#: ... and it stops at a step both wider than this times that width and more than
#: MARCH_SWING_DEG off its course: a profile reaching into a cap or across an oblique end face,
#: whose middle slides sideways (a fat body's tip swung 5-10 deg off over its last few steps;
#: a faint tip narrows, and noise alone swings at the body's own width)
MARCH_SWING_WIDTH, MARCH_SWING_DEG = 1.05, 8.0
#: ... or at a step whose width differs from the last one's by more than this times that width
#: and which swings that far: the last profile cut short by an oblique end face
MARCH_WIDTH_STEP = 0.15
#: the centre line is marched on at most this many half-widths beyond the ridge path's ends ...
MARCH_HALF_WIDTHS = 2.0
#: ... in steps of this length (px)
MARCH_STEP_PX = 2.0
#: the selection is a clamp, not the body, where it is wider than this many of the body's widths
CLAMP_WIDTH_RATIO = 1.3
#: a clamp block's face found this far (px) or less before the fixed end given is the same face
CLAMP_FACE_SLACK_PX = 1.0
#: a free end that bends (``free_end: bends``) is carried on to the last body pixel within this
#: many half-widths of the centre line's course (the middle of its end face, not a corner)
FREE_TIP_ACROSS = 0.3


#: the tip's end face: its contour within this many half-widths of the centre line's course ...
FACE_ACROSS_HALF_WIDTHS = 0.6
#: ... and within this many half-widths of the farthest of it along that course is fitted with a
#: straight line; it counts as a flat face when it spans at least FACE_MIN_SPAN half-widths
#: across, the body is at least FACE_MIN_HALF_PX px wide a half-width, and the fit's RMS is at
#: most FACE_MAX_RMS half-widths (a rounded tip: about 0.07)
FACE_DEPTH_HALF_WIDTHS = 0.5
FACE_MIN_SPAN, FACE_MIN_HALF_PX, FACE_MAX_RMS = 0.9, 6.0, 0.04
#: the face is square to the body when its normal lies within this (deg) of the body's direction
#: there, from the two long edges next to it (each from FACE_EDGE_FROM to FACE_EDGE_TO
#: half-widths along the outline from its corner: an arc, or a straight body, fitted to both)
FACE_SQUARE_DEG = 4.0
FACE_EDGE_FROM, FACE_EDGE_TO = 0.4, 2.5
#: ... where those edges fit the arc (or the lines) within this many half-widths RMS; where they
#: do not (a chamber's gap, a dot, a faint side beside the face) they cannot say
FACE_EDGE_RMS = 0.02


def tip_face_normal(
    comp: np.ndarray, soft: np.ndarray, pts: np.ndarray, half: float
) -> EndFace | None:
    """The square, flat face ending the body at its free end: its outward normal and middle;
    None where the end is not one (rounded, ragged, too narrow, or cut at a slant).

    A square end, and a rigid cap's end, is square to the body's last direction: the face's
    normal is the tip's direction wherever the centre line stops short of the face (a thick
    body bent tightly: its profiles stop about a half-width before the face, where "between the
    two long edges" no longer holds).  The face is found on ``comp``'s outline and located to a
    fraction of a pixel where ``soft`` crosses 0.5 along the centre line's course; it counts as
    square when its normal is the body's direction at the face from the two long edges beside
    it (:func:`_edges_direction`; a face cut 10-20 deg aslant read as the tip turned psi by up to
    29 deg, `ok`), or the one of them that is smooth (a PneuNet's strip, beside the gap before
    its last chamber).  Where neither says (dots, a faint side), the face is not taken (a
    translucent body's read psi 3-7 deg high, `ok`).

    Parameters
    ----------
    comp : ndarray (H, W) uint8
        The body.
    soft : ndarray (H, W) float32
        The body as a 0..1 field whose 0.5 level is its edge (:func:`_soft_body`).
    pts : ndarray (N, 2)
        Its centre line (x, y), fixed end first.
    half : float
        The body's half-width (px).

    Examples
    --------
    >>> comp = np.zeros((80, 140), np.uint8)
    >>> comp[20:60, 10:110] = 1  # a straight body 40 px wide, its face at x = 109.5
    >>> pts = np.c_[np.arange(10.0, 90.0), np.full(80, 39.5)]
    >>> face = tip_face_normal(comp, comp.astype(np.float32), pts, 20.0)
    >>> abs(round(float(np.rad2deg(face.direction_rad)), 1)), np.round(face.middle_px, 1).tolist()
    (0.0, [109.5, 39.5])
    >>> slant = comp.copy()
    >>> slant[:, 100:] = 0
    >>> _ = cv2.fillPoly(slant, [np.array([[100, 20], [117, 20], [103, 59], [100, 59]])], 1)
    >>> print(tip_face_normal(slant, slant.astype(np.float32), pts, 20.0))  # cut 20 deg aslant
    None
    >>> comp[:, 90:] = 0
    >>> _ = cv2.circle(comp, (90, 40), 20, 1, -1)  # a rounded tip
    >>> print(tip_face_normal(comp, comp.astype(np.float32), pts, 20.0))
    None
    """
    found = _end_face(comp, soft, pts, half)
    if found is None:
        return None
    world, middle, c, near = found
    body = _edges_direction(c, near, middle, world, half, soft)
    if body is None:
        return None
    if float(np.degrees(np.arccos(np.clip(abs(world @ body), -1.0, 1.0)))) > FACE_SQUARE_DEG:
        return None
    return EndFace(float(np.arctan2(world[1], world[0])), (float(middle[0]), float(middle[1])))


#: a chambered body's strip is the side of its centre line whose edge (the last crossing of
#: the body's outline within STRIP_REACH half-widths along the normals) lies within
#: STRIP_EDGE_OFF half-widths of its own running median over STRIP_MEDIAN half-widths at no
#: more than STRIP_ROUGH of the points (on the chambers' side a gap takes every one in it)
STRIP_REACH, STRIP_EDGE_OFF, STRIP_MEDIAN, STRIP_ROUGH = 2.5, 0.1, 3.0, 0.05
#: ... cast from the centre line smoothed over this many half-widths; read at the clamp where
#: it is found smooth over the first STRIP_LEAD half-widths from there (its first points hooked
#: back and jumped: psi -180 read -339.5, ok, in the review) from at most STRIP_LEAD half-widths
#: out, and taken where it leaves the clamp within STRIP_CENTRE_DEG of the centre line's start
#: (which its first chamber turns)
STRIP_GUIDE = 0.75
STRIP_LEAD, STRIP_CENTRE_DEG = 1.0, 60.0


def strip_edge(comb: np.ndarray, soft: np.ndarray, pts: np.ndarray, half: float) -> np.ndarray:
    """The edge of a chambered body's strip (the layer that does not stretch), from the fixed
    end on: one point (x, y) per point of the centre line, NaN where it is not found; all NaN
    where neither side of the body runs smooth.

    A PneuNet's filled row of chambers (:func:`fill_chamber_gaps`) starts where its first
    chamber does, so its centre line's start does not say how it leaves the clamp; the strip
    does, and any curve along it turns through the body's psi.

    Parameters
    ----------
    comb : ndarray (H, W) uint8
        The body, its chambers' gaps not filled.
    soft : ndarray (H, W) float32
        ``comb`` as a 0..1 field whose 0.5 level is its edge (:func:`_soft_body`).
    pts : ndarray (N, 2)
        The filled body's centre line (x, y), fixed end first, about 1 px apart.
    half : float
        The body's half-width (px).

    Examples
    --------
    >>> comb = np.zeros((90, 240), np.uint8)
    >>> comb[55:65, 20:220] = 1  # the strip, leaving the clamp (x < 20) along +x
    >>> for x in range(20, 220, 25):
    ...     comb[25:55, x : x + 20] = 1  # chambers 20 px wide, 5 px gaps
    >>> pts = np.c_[np.arange(20.0, 200.0), np.full(180, 45.0)]
    >>> edge = strip_edge(comb, comb.astype(np.float32), pts, 20.0)
    >>> len(edge), np.round(edge[0], 1).tolist(), round(float(np.nanstd(edge[:, 1])), 6)
    (180, [20.0, 64.5], 0.0)
    """
    # along normals of the centre line smoothed over STRIP_GUIDE half-widths: the filled
    # chambers' centre line zig-zags, one side per chamber, and its own normals swept the edge
    # points back and forth
    pts = _smooth(pts, STRIP_GUIDE * half)
    n = _normals(pts)
    u = np.arange(0.0, STRIP_REACH * half, 0.25)
    window = max(3, int(round(STRIP_MEDIAN * half)) | 1)  # noqa: RUF046 (numpy scalar)
    best: tuple[float, np.ndarray] | None = None
    for sense in (1.0, -1.0):
        xy = pts[:, None, :] + sense * u[None, :, None] * n[:, None, :]
        prof = cv2.remap(soft, xy[..., 0].astype(np.float32), xy[..., 1].astype(np.float32),
                         cv2.INTER_LINEAR, borderValue=0.0)
        leaves = (prof[:, :-1] >= 0.5) & (prof[:, 1:] < 0.5)
        j = leaves.shape[1] - 1 - np.argmax(leaves[:, ::-1], axis=1)  # the last crossing out
        rows = np.arange(len(pts))
        p0, p1 = prof[rows, j], prof[rows, j + 1]
        off = u[j] + 0.25 * (p0 - 0.5) / np.maximum(p0 - p1, 1e-6)
        off[~leaves.any(axis=1)] = np.nan
        steady = pd.Series(off).rolling(window, center=True, min_periods=1).median().to_numpy()
        smooth = np.abs(off - steady) <= STRIP_EDGE_OFF * half
        rough = 1.0 - float(smooth.mean())
        if rough <= STRIP_ROUGH and (best is None or rough < best[0]):
            best = (rough, np.where(smooth[:, None], pts + sense * off[:, None] * n, np.nan))
    return best[1] if best is not None else np.full(pts.shape, np.nan)


def base_edge_direction(
    comb: np.ndarray, soft: np.ndarray, pts: np.ndarray, half: float, reach_px: float = 0.0
) -> EndFace | None:
    """The direction in which a chambered body leaves the clamp: its strip's edge's
    (:func:`strip_edge`) start tangent, read as the centre line's is (carried back ``reach_px``
    to the clamp face, as far as the centre line stops short of it); None without a strip.

    Examples
    --------
    >>> t = np.linspace(0.0, np.pi, 400)  # a strip bent through 180 deg, leaving along +x
    >>> comb = np.zeros((260, 260), np.uint8)
    >>> outer = np.c_[30 + 100 * np.sin(t), 230 - 100 * (1 - np.cos(t))]
    >>> inner = np.c_[30 + 90 * np.sin(t), 230 - 90 * (1 - np.cos(t)) - 10]
    >>> _ = cv2.fillPoly(comb, [np.round(np.r_[outer, inner[::-1]]).astype(np.int32)], 1)
    >>> for a in np.arange(0.1, 3.0, 0.3):  # chambers on the inside
    ...     c = (30 + 78 * np.sin(a), 230 - 78 * (1 - np.cos(a)) - 22)
    ...     _ = cv2.circle(comb, (int(c[0]), int(c[1])), 13, 1, -1)
    >>> mid = np.c_[30 + 85 * np.sin(t), 230 - 85 * (1 - np.cos(t)) - 15]
    >>> soft = cv2.GaussianBlur(comb.astype(np.float32), (0, 0), 0.7)
    >>> face = base_edge_direction(comb, soft, mid, 15.0)
    >>> round(float(np.rad2deg(face.direction_rad)), 1)
    -0.3
    """
    edge = strip_edge(comb, soft, pts, half)
    lead = max(2, int(round(STRIP_LEAD * half)))  # noqa: RUF046 (numpy scalar)
    found = np.isfinite(edge[:, 0])
    first = int(np.argmax(found))
    if len(edge) < first + 2 * lead or first > lead or not found[first : first + 2 * lead].all():
        return None  # not smooth from near the clamp on: a hook, the clamp, a gap
    # carried back over as much of the strip as the centre line misses there, and the stretch
    # before its first point found (the strip on the inside of the bend is shorter: carried
    # back the centre line's length it turned 8-11 deg too far at psi 240, the review)
    steps = np.hypot(*np.diff(pts[: first + 2 * lead], axis=0).T)
    ratio = np.hypot(*np.diff(edge[first : first + 2 * lead], axis=0).T).sum() / max(
        float(steps[first:].sum()), 1e-9
    )
    back = (reach_px + float(steps[:first].sum())) * ratio
    edge = edge[found]
    start = end_tangents(np.c_[edge[:, 0], -edge[:, 1]], ends_px=(back, 0.0))[0]
    own = end_tangents(np.c_[pts[:, 0], -pts[:, 1]])[0]
    if abs(np.angle(np.exp(1j * (start - own)))) > np.deg2rad(STRIP_CENTRE_DEG):
        return None  # the strip's edge runs off the body's course: not the strip
    return EndFace(float(-start), (float(edge[0, 0]), float(edge[0, 1])))


def _end_face(
    comp: np.ndarray, soft: np.ndarray, pts: np.ndarray, half: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """The flat face ending ``comp`` past the end ``pts[-1]`` of its centre line: its outward
    normal, its middle (sub-pixel, where ``soft`` crosses 0.5 along the centre line's course),
    the outline it lies on and a mask of the outline's points on it; None where that end is not
    flat (see :func:`tip_face_normal`)."""
    if half < FACE_MIN_HALF_PX or len(pts) < 6:
        return None
    t = pts[-1] - pts[-6]
    t = t / max(float(np.hypot(*t)), 1e-9)
    n = np.array([-t[1], t[0]])
    contours, _ = cv2.findContours(comp, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    best: tuple[int, np.ndarray, np.ndarray] | None = None
    for k in contours:
        c = k[:, 0, :].astype(float)
        d = c - pts[-1]
        along, across = d @ t, d @ n
        near = (np.abs(across) <= FACE_ACROSS_HALF_WIDTHS * half) & (along > 0)
        if near.any():
            near &= along >= along[near].max() - FACE_DEPTH_HALF_WIDTHS * half
        if best is None or near.sum() > best[0]:
            best = (int(near.sum()), c, near)
    if best is None or best[0] < 5:
        return None
    _, c, near = best
    face = float(((c[near] - pts[-1]) @ t).max())
    # along rays parallel to the course, across the face's middle: where soft falls through 0.5
    u = np.arange(-FACE_ACROSS_HALF_WIDTHS * half, FACE_ACROSS_HALF_WIDTHS * half + 1e-9, 1.0)
    a = np.arange(face - FACE_DEPTH_HALF_WIDTHS * half - 2.0, face + 3.0, 0.25)
    xy = pts[-1] + a[None, :, None] * t + u[:, None, None] * n
    prof = cv2.remap(
        soft, xy[..., 0].astype(np.float32), xy[..., 1].astype(np.float32), cv2.INTER_LINEAR,
        borderValue=0.0,
    )
    inside = prof >= 0.5
    found = inside[:, 0] & ~inside[:, -1]
    last = inside.shape[1] - 1 - np.argmax(inside[:, ::-1], axis=1)  # last inside sample
    rows = np.flatnonzero(found & (last < inside.shape[1] - 1))
    if len(rows) < 5:
        return None
    p0, p1 = prof[rows, last[rows]], prof[rows, last[rows] + 1]
    cross = a[last[rows]] + 0.25 * np.clip((p0 - 0.5) / np.maximum(p0 - p1, 1e-6), 0.0, 1.0)
    q = np.c_[cross, u[rows]]
    centred = q - q.mean(axis=0)
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    span = float(np.ptp(centred @ vt[0]))
    rms = float(sv[1] / np.sqrt(len(q)))
    if span < FACE_MIN_SPAN * half or rms > FACE_MAX_RMS * half:
        return None
    normal = np.array([vt[0][1], -vt[0][0]])  # in (along, across)
    if normal[0] < 0:
        normal = -normal
    world = normal[0] * t + normal[1] * n
    middle = pts[-1] + q.mean(axis=0)[0] * t + q.mean(axis=0)[1] * n
    return world, middle, c, near


def _in_original_px(face: EndFace | None, scale: float) -> EndFace | None:
    """``face`` found on the work image (reduced by ``scale``), in the original's px."""
    if face is None:
        return None
    x, y = face.middle_px
    return EndFace(face.direction_rad, (x * scale + (scale - 1) / 2, y * scale + (scale - 1) / 2))


def _on_edge(soft: np.ndarray, walk: np.ndarray) -> np.ndarray:
    """The points of an outline stretch ``walk`` (in order along it) moved across it to where
    ``soft`` crosses 0.5 (sub-pixel; a point without a crossing within 2 px is dropped)."""
    if len(walk) < 5:
        return walk
    smooth = cv2.GaussianBlur(walk.reshape(-1, 1, 2).astype(np.float32), (1, 5), 0).reshape(-1, 2)
    tangent = np.gradient(smooth, axis=0)
    tangent /= np.maximum(np.hypot(*tangent.T), 1e-9)[:, None]
    normal = np.c_[-tangent[:, 1], tangent[:, 0]]
    offs = np.arange(-2.5, 2.51, 0.25)
    xy = smooth[:, None, :] + offs[None, :, None] * normal[:, None, :]
    prof = cv2.remap(soft, xy[..., 0].astype(np.float32), xy[..., 1].astype(np.float32),
                     cv2.INTER_LINEAR, borderValue=0.0)
    inside = prof >= 0.5
    out = []
    for i in range(len(walk)):
        f = np.flatnonzero(inside[i, :-1] != inside[i, 1:])
        if len(f) != 1:
            continue
        j = int(f[0])
        p0, p1 = prof[i, j], prof[i, j + 1]
        at = offs[j] + 0.25 * (p0 - 0.5) / (p0 - p1) if p0 != p1 else offs[j]
        out.append(smooth[i] + at * normal[i])
    return np.array(out).reshape(-1, 2)


def _edges_direction(
    contour: np.ndarray,
    face: np.ndarray,
    middle: np.ndarray,
    normal: np.ndarray,
    half: float,
    soft: np.ndarray,
) -> np.ndarray | None:
    """The body's direction (unit vector, either sense) at the point ``middle`` of its end face,
    from the two long edges beside the face: the stretches of the closed ``contour`` from
    :data:`FACE_EDGE_FROM` to :data:`FACE_EDGE_TO` half-widths along it from either corner (where
    the outline, followed on from the face's middle run ``face``, a mask of its points, leaves
    the face's line through ``middle`` square to ``normal``), put on the edge to a fraction of
    a pixel (:func:`_on_edge`) and fitted with two concentric circles (a bent body: the
    direction square to the radius through ``middle``), or two parallel lines where that is as
    good (a straight one).  None where the face's run is not one piece or an edge is too short.
    """
    m = len(contour)
    idx = np.flatnonzero(face)
    if m < 8 or len(idx) < 2:
        return None
    gaps = np.diff(np.r_[idx, idx[0] + m])
    k = int(np.argmax(gaps))  # the run is what lies outside the largest gap between face points
    if (gaps > 1).sum() > 1 and np.sort(gaps)[-2] > 0.5 * half:
        return None
    off_face = np.abs((contour - middle) @ normal) > max(1.0, 0.1 * half)

    corners = []

    def stretch(run_end: int, sense: int) -> np.ndarray:
        walk_at = (run_end + sense * np.arange(m // 2)) % m
        corner = int(np.argmax(off_face[walk_at]))  # the first point off the face's line
        walk = contour[walk_at[corner:]]
        corners.append(walk[0])
        walked = np.r_[0.0, np.cumsum(np.hypot(*np.diff(walk, axis=0).T))]
        return walk[(walked >= FACE_EDGE_FROM * half) & (walked <= FACE_EDGE_TO * half)]

    start, end = idx[(k + 1) % len(idx)], idx[k]
    side_a, side_b = _on_edge(soft, stretch(start, -1)), _on_edge(soft, stretch(end, +1))
    if min(len(side_a), len(side_b)) < 4:
        return None
    both = np.r_[side_a, side_b]
    # two concentric circles: x^2 + y^2 = 2 a x + 2 b y + c_side
    design = np.c_[2.0 * both, np.r_[np.ones(len(side_a)), np.zeros(len(side_b))],
                   np.r_[np.zeros(len(side_a)), np.ones(len(side_b))]]
    rhs = (both**2).sum(axis=1)
    sol, *_ = np.linalg.lstsq(design, rhs, rcond=None)
    centre = sol[:2]
    radii = np.hypot(*(both - centre).T)
    fit_arc = float(np.mean((radii - np.r_[np.full(len(side_a), radii[: len(side_a)].mean()),
                                           np.full(len(side_b), radii[len(side_a):].mean())]) ** 2))
    # two parallel lines: a common direction through both sides' own centres
    centred = np.r_[side_a - side_a.mean(axis=0), side_b - side_b.mean(axis=0)]
    _, sv, vt = np.linalg.svd(centred, full_matrices=False)
    fit_line = float(sv[1] ** 2 / len(centred))
    radius = float(np.hypot(*(middle - centre)))
    if np.sqrt(min(fit_line, fit_arc)) > FACE_EDGE_RMS * half:
        # the two edges neither an arc nor straight there: one of them may be (a PneuNet's strip
        # beside the gap before its last chamber)
        sides = [
            d
            for d in (
                _side_direction(side_a, corners[0], half),
                _side_direction(side_b, corners[1], half),
            )
            if d
        ]
        return min(sides, key=lambda d: d[1])[0] if sides else None
    if fit_line <= 1.5 * fit_arc or radius > 40.0 * half:
        return np.asarray(vt[0])
    radial = (middle - centre) / max(radius, 1e-9)
    return np.array([-radial[1], radial[0]])


def _side_direction(
    side: np.ndarray, corner: np.ndarray, half: float
) -> tuple[np.ndarray, float] | None:
    """One long edge's direction at the ``corner`` its stretch (of :func:`_edges_direction`)
    starts from, from a circle (or a line, where that fits as well) fitted to it, with the fit's
    RMS (px); None where neither fits within :data:`FACE_EDGE_RMS` half-widths."""
    if len(side) < 4:
        return None
    sol, *_ = np.linalg.lstsq(np.c_[2.0 * side, np.ones(len(side))], (side**2).sum(axis=1),
                              rcond=None)
    centre = sol[:2]
    radii = np.hypot(*(side - centre).T)
    fit_arc = float(np.sqrt(np.mean((radii - radii.mean()) ** 2)))
    _, sv, vt = np.linalg.svd(side - side.mean(axis=0), full_matrices=False)
    fit_line = float(sv[1] / np.sqrt(len(side)))
    if min(fit_arc, fit_line) > FACE_EDGE_RMS * half:
        return None
    if fit_line <= 1.5 * fit_arc or radii.mean() > 40.0 * half:
        return np.asarray(vt[0]), fit_line
    radial = (corner - centre) / max(float(np.hypot(*(corner - centre))), 1e-9)
    return np.array([-radial[1], radial[0]]), fit_arc


def _uncovered(ridge: np.ndarray, end: np.ndarray) -> float:
    """Length of the ridge path beyond the point nearest ``end`` (px)."""
    seg = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(ridge, axis=0).T))))
    i = int(np.argmin(np.hypot(*(ridge - end).T)))
    return float(seg[-1] - seg[i])


def _continues(others: np.ndarray, pts: np.ndarray, half: float) -> bool:
    """Whether other selected pixels lie just ahead of the centre line's free end, on its course."""
    if not others.any() or len(pts) < 8:
        return False
    t = pts[-1] - pts[-6]
    t = t / max(float(np.hypot(*t)), 1e-9)
    ys, xs = np.nonzero(others)
    d = np.c_[xs, ys].astype(float) - pts[-1]
    along = d @ t
    across = np.abs(d[:, 0] * t[1] - d[:, 1] * t[0])
    ahead = (along > 0) & (along <= 6.0 * half + 10.0) & (across <= half + 0.6 * along)
    return int(ahead.sum()) >= max(10, int(half * half))


def _leading_run(flags: np.ndarray) -> int:
    """How many of ``flags`` are True before the first False.

    Examples
    --------
    >>> _leading_run(np.array([True, True, False, True]))
    2
    """
    return len(flags) if flags.all() else int(np.argmin(flags))


def _good_span(good: np.ndarray, run: int) -> tuple[int, int] | None:
    """First and last index of the part between the first and the last run of ``run`` good points.

    Examples
    --------
    >>> _good_span(np.array([1, 0, 1, 1, 1, 1, 0, 1, 1, 1, 0, 1], bool), 3)
    (2, 9)
    """
    if good.sum() < max(run, 8):
        return None
    ok = np.convolve(good.astype(int), np.ones(run, int), mode="valid") == run  # a run starts here
    if not ok.any():
        return None
    first = int(np.argmax(ok))
    last = len(ok) - 1 - int(np.argmax(ok[::-1])) + run - 1
    return first, last


#: a cap ahead of the march: the body goes on wider for three of the next this many of its
#: steps (all but one missed the cap in 7 of 14 frames at rest of a blurred 720p video), its
#: middle within this fraction of the width of the course (both sides overhang alike)
CAP_PROBE_STEPS, CAP_OFF_COURSE = 5, 0.1


def _cap_ahead(
    soft: np.ndarray, cur: np.ndarray, course: np.ndarray, half: float, width: float
) -> bool:
    """Whether the selection ahead of ``cur`` along the unit ``course`` is wider than ``width``
    at three of the next :data:`CAP_PROBE_STEPS` march steps, centred on the course: a rigid
    cap wider than the body, not a dot, a blob or the body's own other limb beside its tip (one
    side), nor a faint side showing at the end face for a step.

    Examples
    --------
    >>> soft = np.zeros((40, 80), np.float32)
    >>> soft[14:26, :50] = 1.0; soft[12:28, 50:60] = 1.0  # a body 12 px wide, a cap 16 px
    >>> _cap_ahead(soft, np.array([49.0, 19.5]), np.array([1.0, 0.0]), 6.0, 13.8)
    True
    >>> for x in (52, 56):  # blurred: its overhang lost at two of the five steps
    ...     soft[12:14, x:x + 2] = 0.0; soft[26:28, x:x + 2] = 0.0
    >>> _cap_ahead(soft, np.array([49.0, 19.5]), np.array([1.0, 0.0]), 6.0, 13.8)
    True
    >>> soft[26:34, 50:60] = 1.0; soft[12:14, 50:60] = 0.0  # widening to one side only
    >>> _cap_ahead(soft, np.array([49.0, 19.5]), np.array([1.0, 0.0]), 6.0, 13.8)
    False
    """
    ahead = cur + np.outer(np.arange(1, CAP_PROBE_STEPS + 1) * MARCH_STEP_PX, course)
    mid, wid, _ = _midpoints(soft, np.vstack([cur, ahead]), reach=3.0 * half + 4.0)
    off = np.abs((mid[1:] - ahead) @ np.array([-course[1], course[0]]))
    wider = np.isfinite(wid[1:]) & (wid[1:] > width) & (off < CAP_OFF_COURSE * width)
    return bool(wider.sum() >= CAP_PROBE_STEPS - 2)


def _march(
    soft: np.ndarray,
    pts: np.ndarray,
    widths: np.ndarray,
    half: float,
    end_med: tuple[float, float],
    region: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, bool]:
    """Carry the centre line on towards both ends, 1 px at a time, while it is still "between two
    edges": each new point is the middle of the profile across the body ahead, kept while the
    body's width there is within [MARCH_WIDTH_LOW, MARCH_WIDTH_HIGH] of its median near that end
    (``end_med``: start, end), and not at a step both wider than :data:`MARCH_SWING_WIDTH` of
    it, or :data:`MARCH_WIDTH_STEP` of it wider or narrower than the step before, and more than
    :data:`MARCH_SWING_DEG` off the course (into a cap or across an end face).

    The ridge path stops about a half-width short of each end (there the medial axis forks into
    the corners); marching recovers that part, so a tip that curls to its end is measured to its
    end, and a straight sealed cap is followed to its end face.  Also returns whether the march
    at the free end stopped at a cap (:func:`_cap_ahead`).  It does not step out of ``region``
    (the pixels looked at, 1): an excluded clamp's strong difference beside the body's end
    carried the centre line 2 px on over the clamp's face, hooking its start (psi 240 read 5.5
    deg high, ok, the fixed end on the face).
    """
    k = 6
    ends = []
    for forward, med in zip((False, True), end_med, strict=True):
        line = pts if forward else pts[::-1]
        new: list[np.ndarray] = []
        new_w: list[float] = []
        capped = False
        cur = line[-1]
        prev = line[max(len(line) - 1 - k, 0)]
        last_w = med
        for _ in range(int(MARCH_HALF_WIDTHS * half / MARCH_STEP_PX) + 2):
            t = cur - prev
            t = t / max(float(np.hypot(*t)), 1e-9)
            ahead = cur + MARCH_STEP_PX * t
            mid, wid, _ = _midpoints(soft, np.array([cur, ahead]), reach=3.0 * half + 4.0)
            if not (
                np.isfinite(wid[1]) and MARCH_WIDTH_LOW * med <= wid[1] <= MARCH_WIDTH_HIGH * med
            ):
                capped = bool(np.isfinite(wid[1]) and wid[1] > MARCH_WIDTH_HIGH * med) and (
                    _cap_ahead(soft, cur, t, half, MARCH_WIDTH_HIGH * med)
                )
                break
            step = mid[1]
            if region is not None:
                x, y = round(float(step[0])), round(float(step[1]))
                h, w = region.shape
                if not (0 <= y < h and 0 <= x < w) or not region[y, x]:
                    break  # into what is not looked at
            d = step - prev  # the course over the last few points, not one step's jitter
            off_deg = float(np.rad2deg(np.arccos(np.clip(
                float(d @ t) / max(float(np.hypot(*d)), 1e-9), -1.0, 1.0
            ))))
            if np.hypot(*(step - cur)) < 0.5 * MARCH_STEP_PX or off_deg > 25.0:
                break  # not moving on, or turning off the line's course (a corner, a cap)
            if off_deg > MARCH_SWING_DEG and (
                wid[1] > MARCH_SWING_WIDTH * med
                or abs(wid[1] - last_w) > MARCH_WIDTH_STEP * med
            ):
                capped = bool(wid[1] > MARCH_SWING_WIDTH * med) and (
                    _cap_ahead(soft, cur, t, half, MARCH_WIDTH_HIGH * med)
                )
                break  # widening, or a width jump, swinging off the course: into a cap or across
                # an end face
            last_w = float(wid[1])
            new.append(step)
            new_w.append(float(wid[1]))
            hist = np.vstack([line[-k:], np.array(new)])
            prev, cur = hist[max(len(hist) - 1 - k, 0)], step
        ends.append((np.array(new).reshape(-1, 2), np.array(new_w), capped))
    (head, head_w, _), (tail, tail_w, tip_capped) = ends
    pts = np.vstack([head[::-1], pts, tail])
    widths = np.concatenate([head_w[::-1], widths, tail_w])
    return pts, widths, tip_capped


def _follow_ridge(ridge: np.ndarray, pts: np.ndarray, half: float) -> np.ndarray:
    """The centre line carried on along the mask's ridge where the march between two edges stopped
    short of the free end (an outline too uneven to find its middle: a faint side, a tip the light
    leaves).  The ridge is only the middle of what was selected, so this is a check of the tip's
    direction, not the measurement.  The ridge's last :data:`RIDGE_TIP_HALF_WIDTHS` half-widths
    (where it forks into the tip's corners, or runs into a rounded cap) are left out."""
    seg = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(ridge, axis=0).T))))
    i = int(np.argmin(np.hypot(*(ridge - pts[-1]).T)))
    rest = (seg > seg[i] + MARCH_STEP_PX) & (seg <= seg[-1] - RIDGE_TIP_HALF_WIDTHS * half)
    if rest.sum() < half:
        return pts
    tail = _smooth(
        _resample(np.vstack([pts[-1:], ridge[rest]]), 1.0), max(1.0, SMOOTH_HALF_WIDTHS * half)
    )[1:]
    return np.vstack([pts, tail])


def _extensions(
    comp: np.ndarray,
    dt: np.ndarray,
    pts: np.ndarray,
    half: float,
    fixed_xy: tuple[float, float] | None,
    free_end_bends: bool = False,
) -> tuple[float, float]:
    """How far the body bends on beyond each end of the centre line, along the end tangents (px).

    The fixed end: to the given fixed-end point (the clamp face), else to the body's last pixel:
    the body bends right from the clamp.  Not into a clamp that is part of the selection, though
    (:func:`_clamp_distance`): the clamp does not bend, and a fixed end clicked inside it (20-40
    px at 1280x960) carried the base's curvature on over the clamp (5-14 deg off on rendered
    analogues).  With ``free_end_bends`` (a free strip: the end walked from is a cut end too)
    the given point is reached whatever lies there.  Over an excluded part (a clamp plate under
    ``exclude``) it is carried on too: what lies there is not seen (:func:`_region_distance`).

    The free end (``free_end: capped``): 0.  Past the centre line's last point lies the actuator's
    sealed end (a cap), which does not bend, so the tip's direction is the centre line's own at
    its end; carrying the curvature on over the cap read |psi| 5 % high on rendered capped
    bodies.  With ``free_end_bends`` (``free_end: bends``: a free strip, cut, with no sealed end)
    the free end is carried on to the body's last pixel like an unclamped fixed end: the centre
    line stops about a half-width short of the end face, and the strip bends through that part
    too.
    """
    ys, xs = np.nonzero(comp)
    q = np.c_[xs, ys].astype(float)
    out = []
    k = min(len(pts) - 1, 5)
    for end, inner in ((0, k), (-1, -1 - k)):
        p = pts[end]
        t = pts[end] - pts[inner]
        t = t / max(float(np.hypot(*t)), 1e-9)  # outward tangent
        if end == 0 and fixed_xy is not None:
            reach = face_reach(pts, np.asarray(fixed_xy, float))
            if not free_end_bends:
                reach = min(reach, _clamp_distance(comp, dt, p, t, half, reach))
            out.append(reach)
            continue
        if end == -1 and not free_end_bends:
            out.append(0.0)
            continue
        d = q - p
        along, across = d @ t, np.abs(d[:, 0] * t[1] - d[:, 1] * t[0])
        # this end's tip, not what lies beyond a gap
        sel = (across <= (FREE_TIP_ACROSS * half if end == -1 else half)) & (along > 0) & (
            along <= 2.5 * half + 2.0
        )
        if sel.any():  # the tip's pixels run on from the end without a gap
            a = np.sort(along[sel])
            gap = np.nonzero(np.diff(np.r_[0.0, a]) > 2.0)[0]
            out.append(
                float(a[gap[0] - 1])
                if gap.size and gap[0] > 0
                else (0.0 if gap.size else float(a[-1]))
            )
        else:
            out.append(0.0)
    return out[0], out[1]


def _region_distance(
    region: np.ndarray | None, start: np.ndarray, direction: np.ndarray, reach: float
) -> float:
    """How far (px, up to ``reach``) from ``start`` along ``direction`` the pixels looked at
    (``region``, 1; None: all) go on: where the ray first leaves them, the edge of an
    ``exclude`` polygon or the ``roi``, less half a pixel.  A ray leaving the photo, or one that
    starts outside them, goes on to ``reach``.

    Examples
    --------
    >>> region = np.ones((20, 60), np.uint8); region[:, 40:] = 0  # a clamp plate excluded
    >>> _region_distance(region, np.array([30.0, 10.0]), np.array([1.0, 0.0]), 25.0)
    9.5
    >>> _region_distance(region, np.array([30.0, 10.0]), np.array([-1.0, 0.0]), 25.0)
    25.0
    >>> _region_distance(None, np.array([30.0, 10.0]), np.array([1.0, 0.0]), 25.0)
    25.0
    """
    if region is None or not np.isfinite(reach) or reach <= 0:
        return reach
    h, w = region.shape
    for a in np.arange(0.0, reach + 1.0, 1.0):
        x, y = np.round(start + a * direction).astype(int)
        if not (0 <= x < w and 0 <= y < h):
            return reach
        if not region[y, x]:
            return reach if a == 0 else min(reach, float(a) - 0.5)
    return reach


def face_reach(pts: np.ndarray, fixed_xy: np.ndarray) -> float:
    """How far the centre line's first point lies from the face through ``fixed_xy`` (px): the
    face is square to the body's direction there, which is the start's direction turned back at
    the start's curvature over that distance.

    The fixed end is often given on an edge, half a width beside the centre line; measured along
    the start's own direction, a body that bends right from the clamp took in half its width
    times the sine of its turn over that stretch (its base read 2-5 deg off on a body 50 px wide
    at psi 200 over 250 px).

    Examples
    --------
    >>> k = 1.0 / 60.0  # an arc of radius 60 leaving the face x = 0 along +x, begun 8 px in
    >>> s = np.arange(8.0, 200.0)
    >>> pts = np.c_[np.sin(k * s), 1.0 - np.cos(k * s)] / k
    >>> round(face_reach(pts, np.array([0.0, 25.0])), 1), round(face_reach(pts, np.zeros(2)), 1)
    (8.0, 8.0)
    """
    seg = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    head = pts[seg <= max(TANGENT_WINDOW_FRACTION * seg[-1], 6.0)]
    if len(head) < 4:
        return max(0.0, float((pts[0] - fixed_xy) @ (pts[-1] - pts[0])) / max(seg[-1], 1e-9))
    d = np.diff(head, axis=0)
    theta = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    along = np.cumsum(np.hypot(d[:, 0], d[:, 1])) - 0.5 * np.hypot(d[:, 0], d[:, 1])
    kappa, theta0 = np.polyfit(along, theta, 1)
    off = pts[0] - fixed_xy
    reach = 0.0
    for _ in range(40):  # the distance along the direction it gives, at half steps
        a = theta0 - kappa * reach
        reach = 0.5 * (reach + max(0.0, float(off @ np.array([np.cos(a), np.sin(a)]))))
    return reach


def _clamp_distance(
    comp: np.ndarray,
    dt: np.ndarray,
    start: np.ndarray,
    direction: np.ndarray,
    half: float,
    reach: float,
) -> float:
    """How far (px, up to ``reach``) from ``start`` along ``direction`` the selection ``comp``
    stays no wider than the body: where its distance transform ``dt`` first exceeds
    :data:`CLAMP_WIDTH_RATIO` times the body's half-width, the ray has entered a wider block (a
    clamp plate or bracket that the selection took in), whose face lies a little before.  A
    faint, unselected stretch of body does not stop it.

    The block is looked for as far past ``reach`` as that, and its face taken where it lies
    more than :data:`CLAMP_FACE_SLACK_PX` before ``reach``: a fixed end clicked 5-15 px inside
    a clamp block, short of where ``dt`` rises, carried the base's curvature on over it (2-6
    deg off, ok, at psi 240), and one on the face stays where it was given.  The face is
    located on the selection's run across the ray, half-way from where it first widens past
    the body's width to where it reaches the block's (the corners where the body meets the
    block are rounded: either alone read the face 1-2 px off); ``dt`` alone read it up to 2 px
    early, and the run alone, cut aslant across a body bending from the clamp, took the body
    for a block.

    Examples
    --------
    >>> comp = np.zeros((40, 120), np.uint8); comp[15:25, 20:80] = 1; comp[0:40, 80:110] = 1
    >>> dt = cv2.distanceTransform(comp, cv2.DIST_L2, 5)
    >>> round(_clamp_distance(comp, dt, np.array([50.0, 20.0]), np.array([1.0, 0.0]), 5.0, 60.0), 1)
    29.3
    >>> _clamp_distance(comp, dt, np.array([50.0, 20.0]), np.array([1.0, 0.0]), 5.0, 30.0)
    30.0
    >>> _clamp_distance(comp, dt, np.array([50.0, 20.0]), np.array([-1.0, 0.0]), 5.0, 20.0)
    20.0
    """
    if not np.isfinite(reach) or reach <= 0:
        return reach
    h, w = comp.shape
    past = float(np.sqrt(CLAMP_WIDTH_RATIO**2 - 1.0)) * half
    normal = np.array([-direction[1], direction[0]])
    u = np.arange(-3.0 * half, 3.0 * half + 0.5, 1.0)
    centre = int(np.argmin(np.abs(u)))

    def run(a: float) -> int:
        """The selection's run across the ray, through it, ``a`` px along (0 off it)."""
        xy = np.round(start + a * direction + u[:, None] * normal).astype(int)
        seen = (xy[:, 0] >= 0) & (xy[:, 0] < w) & (xy[:, 1] >= 0) & (xy[:, 1] < h)
        inside = np.zeros(len(u), bool)
        inside[seen] = comp[xy[seen, 1], xy[seen, 0]] > 0
        if not inside[centre]:
            return 0
        lo = centre - int(np.argmin(inside[centre::-1])) if not inside[: centre + 1].all() else 0
        hi = centre + int(np.argmin(inside[centre:])) if not inside[centre:].all() else len(u)
        return hi - lo

    for a in np.arange(0.0, reach + past + 1.0, 1.0):
        x, y = np.round(start + a * direction).astype(int)
        if not (0 <= x < w and 0 <= y < h):
            break
        if dt[y, x] > CLAMP_WIDTH_RATIO * half:
            steps = np.arange(max(0.0, a - past - 2.0), a + half + 1.0, 1.0)
            runs = np.array([run(b) for b in steps])
            wide = runs > CLAMP_WIDTH_RATIO * 2.0 * half
            if not wide.any():
                face = a - past
            else:
                rise = int(np.argmax(wide))
                full = rise + int(np.argmax(runs[rise:] >= runs[-1] - 2))
                face = 0.5 * (steps[rise] + steps[full]) - 0.5
            face = max(0.0, float(face))
            return face if face < reach - CLAMP_FACE_SLACK_PX else reach
    return reach


def _on_border(
    comp: np.ndarray, points: np.ndarray, half: float, region: np.ndarray | None = None
) -> bool:
    """Whether the body ``comp`` reaches the image border within about a width of ``points``;
    with ``region`` (the allowed pixels, 1), whether it reaches that region's edge there instead:
    an ``roi`` or ``exclude`` polygon that cuts the body off."""
    h, w = comp.shape
    near = np.zeros_like(comp)
    cv2.polylines(
        near,
        [np.round(points * 16).astype(np.int32)],
        False,
        1,
        max(3, int(2 * half)) * 2 + 1,
        cv2.LINE_8,
        4,
    )
    if region is not None:
        outside = cv2.dilate((region == 0).astype(np.uint8), np.ones((3, 3), np.uint8))
        return bool((near & comp & outside).any())
    ys, xs = np.nonzero(near & comp)
    return bool(len(xs)) and bool(
        xs.min() <= 0 or ys.min() <= 0 or xs.max() >= w - 1 or ys.max() >= h - 1
    )


#: a side standing out from its own course by more than this fraction of the body's width ...
BUMP_WIDTH_FRACTION = 0.05
#: ... beyond its running median over this many widths along the body, while the other side does
#: not, is a bump on that side (a marker dot standing half out of the outline, a speck of dirt
#: on the edge), and is set back to that median ...
BUMP_WINDOW_WIDTHS = 2.0
#: ... where it stands out by at least this many px (a body a few px across has no bumps but
#: pixel steps: the real strips' ring, 6 px across, read 21 deg less so) ...
BUMP_MIN_PX = 2.0
#: ... and only where the selection differs from the backdrop by at least this many of its noise
#: sigmas (:attr:`BodySelection.contrast`; rendered opaque bodies 34-100, the translucent body on
#: grey without its empty scene 16-18, whose wandering edges this read 6-8 deg off)
BUMP_MIN_CONTRAST = 25.0
#: ... and by more than this many sigmas of that side's own wander from its course, but by no
#: more than this fraction of the width (a marker stands half its own size out, 10-20 % of a
#: body's width; a PneuNet's chamber crests 20-90 %: set back, its ramp check no longer saw a
#: direction given 10 deg off, 15 rows ok 10 deg off)
BUMP_WANDER_SIGMAS, BUMP_MAX_WIDTH_FRACTION = 4.0, 0.25


def _without_bumps(
    left: np.ndarray, right: np.ndarray, good: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The two edges' offsets along the normals (``left`` negative, ``right`` positive), each
    set back to its running median where it alone bulges out: a bump on one side (a motion-capture
    dot standing half out of the outline) does not pull the middle towards it.

    Customer 50's opaque body, 15 mm wide with 3 mm dots half out of its sides: a dot near the tip
    turned the end's direction 5-7 deg (3 rows ok 5.7-6.8 deg off with every setting right at
    2000x1500); the body widening on both sides (a cap, the clamp) is left as it is.

    Examples
    --------
    >>> left, right = np.full(60, -10.0), np.full(60, 10.0)
    >>> right[30:34] = 13.0  # a dot on the right side
    >>> l2, r2 = _without_bumps(left, right, np.ones(60, bool))
    >>> float(r2.max()), float(l2.min())
    (10.0, -10.0)
    >>> left[30:34] = -13.0  # both sides: the body widens
    >>> float(_without_bumps(left, right, np.ones(60, bool))[1].max())
    13.0
    """
    if good.sum() <= 10:
        return left, right
    from scipy.ndimage import median_filter

    width = float(np.median((right - left)[good]))
    size = max(5, round(BUMP_WINDOW_WIDTHS * width) | 1)
    out_l = np.where(good, -left, np.nan)
    out_r = np.where(good, right, np.nan)
    course_l, course_r = (
        median_filter(np.where(good, d, np.nanmedian(d)), size=size, mode="nearest")
        for d in (out_l, out_r)
    )
    limit = max(BUMP_WIDTH_FRACTION * width, BUMP_MIN_PX)
    # ... and well clear of the side's own wander (a faint side's edge: the translucent body on
    # grey, 13 px across, wandered 2-5 px, and set back only where out, read 7 deg low)
    wander = [
        BUMP_WANDER_SIGMAS * 1.4826 * float(np.nanmedian(np.abs(out - course)))
        for out, course in ((out_l, course_l), (out_r, course_r))
    ]
    # not touching the ends, where the window is cut short and the outline turns round the tip
    # (a wider margin, a quarter of the width, let customer 50's dot near the tip turn it again)
    inner = np.zeros(len(left), bool)
    inner[1:-1] = True
    bulge_l, bulge_r = (
        _short_runs(
            out - course, max(limit, spread), width, BUMP_MAX_WIDTH_FRACTION * width, inner
        )
        for out, course, spread in ((out_l, course_l, wander[0]), (out_r, course_r, wander[1]))
    )
    return (
        np.where(good & bulge_l & ~bulge_r, -course_l, left),
        np.where(good & bulge_r & ~bulge_l, course_r, right),
    )


def _short_runs(
    excess: np.ndarray, limit: float, longest: float, tallest: float, within: np.ndarray
) -> np.ndarray:
    """Where ``excess`` is over ``limit``, in runs at most ``longest`` long, at most ``tallest``
    high and all ``within``.

    Examples
    --------
    >>> e = np.array([3, 3, 0, 3, 3, 3, 3, 0, 9, 9, 0, 3], float)
    >>> _short_runs(e, 1.0, 3, 5.0, np.r_[np.ones(11, bool), False]).astype(int)
    array([1, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0])
    """
    flags = np.nan_to_num(excess) > limit
    edges = np.diff(np.r_[0, flags.astype(np.int8), 0])
    starts, stops = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    out = np.zeros_like(flags, dtype=bool)
    for a, b in zip(starts, stops):
        out[a:b] = b - a <= longest and excess[a:b].max() <= tallest and bool(within[a:b].all())
    return out


def _midpoints(
    soft: np.ndarray,
    points: np.ndarray,
    reach: float,
    expected_width: float | np.ndarray | None = None,
    without_bumps: bool = False,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Move each point to the middle of the two edges along its normal; return points, widths
    and where one side is the image border.

    With ``without_bumps`` a bump on one side is left out first (:func:`_without_bumps`).

    An "edge" on the image border is not the body's: the body goes on outside the photo.  Where
    one side ends there, the point is put half ``expected_width`` (the body's width nearby) in
    from the other, real edge, and that width is returned (NaN where what is seen is wider than
    the body: the profile runs along something else); without ``expected_width`` the width there
    is NaN (unknown).  A body whose side runs along the border (a clamp at the photo's
    edge) is so not pulled off its middle by the border.
    """
    n = _normals(points)
    k = int(np.ceil(reach * 2))
    off = np.arange(-k, k + 1, dtype=np.float32) / 2.0
    mx = (points[:, 0:1] + n[:, 0:1] * off).astype(np.float32)
    my = (points[:, 1:2] + n[:, 1:2] * off).astype(np.float32)
    prof = cv2.remap(
        soft, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0.0
    )
    c = k  # the centre sample
    inside = prof >= 0.5
    # the run of inside samples around the centre
    left = np.full(len(points), np.nan)
    right = np.full(len(points), np.nan)
    for side, out in ((-1, left), (1, right)):
        idx = np.arange(c, -1, -1) if side < 0 else np.arange(c, 2 * k + 1)
        run = np.cumprod(inside[:, idx], axis=1)
        last = run.sum(axis=1) - 1  # steps the run lasts
        ok = (last >= 0) & (last < len(idx) - 1)
        j0 = idx[np.clip(last, 0, len(idx) - 1)]
        j1 = idx[np.clip(last + 1, 0, len(idx) - 1)]
        rows = np.arange(len(points))
        p0, p1 = prof[rows, j0], prof[rows, j1]
        frac = np.clip((p0 - 0.5) / np.maximum(p0 - p1, 1e-6), 0.0, 1.0)
        out[ok] = (off[j0] + frac * (off[j1] - off[j0]))[ok]
    good = np.isfinite(left) & np.isfinite(right) & inside[:, c]
    if without_bumps:
        left, right = _without_bumps(left, right, good)
    mid = np.where(good, 0.5 * (left + right), 0.0)
    width = np.where(good, right - left, np.nan)
    h, w = soft.shape[:2]
    cut = []
    for off_side in (left, right):
        e = points + np.nan_to_num(off_side)[:, None] * n
        cut.append(
            good
            & (
                (e[:, 0] < BORDER_PX)
                | (e[:, 1] < BORDER_PX)
                | (e[:, 0] > w - 1 - BORDER_PX)
                | (e[:, 1] > h - 1 - BORDER_PX)
            )
        )
    one = cut[0] ^ cut[1]
    width[cut[0] | cut[1]] = np.nan
    if expected_width is not None:
        exp = np.broadcast_to(np.asarray(expected_width, dtype=float), (len(points),))
        # what is seen of the body there is no wider than the body (else the profile runs along
        # something else: a clamp face, the tip)
        fix = one & np.isfinite(exp) & (right - left <= END_WIDTH_HIGH * exp)
        # half the expected width in from the side that is a real edge
        mid = np.where(fix & cut[0], right - 0.5 * exp, mid)
        mid = np.where(fix & cut[1], left + 0.5 * exp, mid)
        width = np.where(fix, exp, width)
    return points + mid[:, None] * n, width, one


#: a gap in the selection along the body's course is bridged when the selection goes on within
#: this many half-widths beyond the free end of the part found ...
BRIDGE_HALF_WIDTHS = 6.0
#: ... in a piece at least this many half-widths squared in area (a stretch of body, not a speck)
BRIDGE_MIN_AREA_HALF2 = 8.0
#: ... or, within this many half-widths of the free end, a piece of at least this many: the tip
#: of a translucent body beyond a faint stretch (on the analogue without its empty scene, 1.0-1.4
#: half-widths squared, 0.3-0.6 half-widths ahead)
TIP_PIECE_HALF_WIDTHS, TIP_PIECE_AREA_HALF2 = 1.0, 1.0
#: at most this many gaps are bridged
MAX_BRIDGES = 3


def _bridge_gaps(
    mask: np.ndarray,
    comp: np.ndarray,
    fixed_xy: tuple[float, float] | None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[float]]:
    """Join pieces of the selection that carry the body on past a gap at its free end.

    A faint stretch (a translucent body where the light is dim, a highlight, a shadow) splits the
    selection; the piece at the fixed end then stops short and the rest is a rival.  While
    another piece of at least :data:`BRIDGE_MIN_AREA_HALF2` half-widths squared lies ahead of the
    free end of the ridge path, on its course, within :data:`BRIDGE_HALF_WIDTHS` half-widths
    (or a smaller one, down to :data:`TIP_PIECE_AREA_HALF2`, within
    :data:`TIP_PIECE_HALF_WIDTHS`: the tip itself, past the last faint stretch), the gap is
    filled with a band of the body's width and the ridge is walked again.

    Returns
    -------
    comp : ndarray
        The body, with the pieces and bridges joined.
    dt : ndarray
        Its distance transform.
    path : ndarray
        Its ridge path (x, y) from the fixed end.
    gaps_px : list of float
        Length of each gap bridged (work px).
    """
    gaps: list[float] = []
    while True:
        dt = cv2.distanceTransform(comp, cv2.DIST_L2, 5)
        path, _ = _ridge_path(comp, dt, fixed_xy)
        if len(gaps) >= MAX_BRIDGES or len(path) < 8:
            return comp, dt, path, gaps
        xi, yi = np.round(path[:, 0]).astype(int), np.round(path[:, 1]).astype(int)
        half = max(float(np.median(dt[yi, xi])), 1.0)
        seg = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))))
        back = path[int(np.searchsorted(seg, seg[-1] - max(3.0 * half, 4.0)))]
        t = path[-1] - back
        if float(np.hypot(*t)) < 1e-6:
            return comp, dt, path, gaps
        t = t / float(np.hypot(*t))
        others = (mask > 0) & (comp == 0)
        _, labels, stats, _ = cv2.connectedComponentsWithStats(
            others.astype(np.uint8), connectivity=8
        )
        ys, xs = np.nonzero(others)
        d = np.c_[xs, ys].astype(float) - path[-1]
        along = d @ t
        across = np.abs(d[:, 0] * t[1] - d[:, 1] * t[0])
        ahead = (along > 0) & (along <= BRIDGE_HALF_WIDTHS * half) & (across <= half + 0.5 * along)
        area = stats[labels[ys, xs], cv2.CC_STAT_AREA]
        ahead &= (area >= BRIDGE_MIN_AREA_HALF2 * half * half) | (
            (area >= TIP_PIECE_AREA_HALF2 * half * half) & (along <= TIP_PIECE_HALF_WIDTHS * half)
        )
        if not ahead.any():
            return comp, dt, path, gaps
        k = int(np.flatnonzero(ahead)[np.argmin(np.hypot(along[ahead], across[ahead]))])
        piece = (labels == labels[ys[k], xs[k]]).astype(np.uint8)
        # the bridge ends in the middle of the piece's near end, not on its nearest corner
        near = np.hypot(d[:, 0], d[:, 1])
        inner = cv2.distanceTransform(piece, cv2.DIST_L2, 5)[ys, xs]
        sel = (piece[ys, xs] > 0) & (near <= near[k] + 2.0 * half)
        k = int(np.flatnonzero(sel)[np.argmax(inner[sel])])
        q = (int(xs[k]), int(ys[k]))
        p = (int(np.round(path[-1][0])), int(np.round(path[-1][1])))
        comp = comp.copy()
        comp[piece > 0] = 1
        cv2.line(comp, p, q, 1, max(1, round(2.0 * half)), cv2.LINE_8)
        gaps.append(float(np.hypot(q[0] - p[0], q[1] - p[1])))


#: a photo with this much more of it white (every channel at least SATURATED) than its empty
#: scene (or than this share, without one) is overexposed
OVEREXPOSED_SHARE, SATURATED = 0.2, 250


def overexposed(
    image_bgr: np.ndarray, region: np.ndarray | None, background_bgr: np.ndarray | None
) -> str:
    """Why nothing may be found in a photo: ``"N% of the photo is white ...; "`` where it is
    overexposed (a lamp switched on, the exposure changed: customer 31's read only "nothing
    differs from the background photo"), or its empty scene is, else ``""``.

    Examples
    --------
    >>> img = np.full((10, 10, 3), 120, np.uint8)
    >>> overexposed(img, None, None)
    ''
    >>> img[:6] = 255
    >>> overexposed(img, None, img[:, :, :] * 0 + 120)
    '60% of the photo is white (overexposed: a lamp switched on, or the exposure changed?); '
    >>> print(overexposed(img[:, :, :] * 0 + 120, None, img))  # doctest: +NORMALIZE_WHITESPACE
    60% of the background photo is white, 0% of this photo (the empty scene overexposed: take it
    at the photos' exposure);
    """

    share = white_share(image_bgr, region)
    before = white_share(background_bgr, region) if background_bgr is not None else 0.0
    if before - share >= OVEREXPOSED_SHARE:  # customer 52's empty scene at 1.25 the exposure
        return (
            f"{100 * before:.0f}% of the background photo is white, {100 * share:.0f}% of this "
            "photo (the empty scene overexposed: take it at the photos' exposure); "
        )
    if share - before < OVEREXPOSED_SHARE:
        return ""
    return (
        f"{100 * share:.0f}% of the photo is white (overexposed: a lamp switched on, or the "
        "exposure changed?); "
    )


def white_share(image_bgr: np.ndarray, region: np.ndarray | None = None) -> float:
    """The share of ``image_bgr`` (within ``region``, 1, where given) that is white: every
    channel at :data:`SATURATED` or more.

    Examples
    --------
    >>> img = np.full((10, 10, 3), 120, np.uint8)
    >>> img[:3] = 252
    >>> white_share(img)
    0.3
    """
    hit = (
        (image_bgr.min(axis=2) >= SATURATED) if image_bgr.ndim == 3 else image_bgr >= SATURATED
    )
    return float(hit[region > 0].mean() if region is not None else hit.mean())


def extract_body(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    *,
    scale: float = 1.0,
    background_bgr: np.ndarray | None = None,
    faint_sides: bool = True,
) -> BodyExtraction:
    """Segment the actuator body and return its centre line (see the module docstring).

    Parameters
    ----------
    image_bgr : ndarray (H, W, 3) uint8
        The photo, reduced by ``scale`` from the original.
    settings : MeasureSettings
        ``target: body`` settings (colour, background, roi, exclude, fixed end).
    scale : float
        Original px per px of ``image_bgr``.
    background_bgr : ndarray, optional
        Empty-scene photo at the size of ``image_bgr``.
    faint_sides : bool
        See :func:`body_mask`.

    Returns
    -------
    BodyExtraction

    Raises
    ------
    NoLineFound
        When the selection is empty, covers most of the photo, or holds nothing elongated.
    """
    if image_bgr is None or image_bgr.ndim != 3:
        raise NoLineFound("unreadable image (not a colour image)")
    h, w = image_bgr.shape[:2]
    selection = body_mask(
        image_bgr, settings, scale=scale, background_bgr=background_bgr, faint_sides=faint_sides
    )
    raw = selection.mask
    region = region_mask(image_bgr.shape, settings.roi, settings.exclude, scale)
    allowed_px = float(h * w if region is None else region.sum())
    if allowed_px == 0:
        raise NoLineFound(
            "no body found: roi / exclude leave nothing of the photo to look at; fix them "
            "(python -m pipeline photoset preview shows their outlines)"
        )
    selected = float(raw.sum()) / max(allowed_px, 1.0)
    what = settings.describe_color()
    if raw.sum() < 20:
        raise NoLineFound(
            f"no body found: nothing {what}; "
            + overexposed(image_bgr, region, background_bgr)
            + "check line_color / background / roi (python -m pipeline photoset preview shows "
            "what they select)"
        )
    if selected > 0.6:
        raise NoLineFound(
            f"no body found: {100 * selected:.0f}% of the photo is selected ({what}); narrow "
            "line_color or roi (python -m pipeline photoset preview)"
        )
    mask = _clean(raw)
    fe = None
    if settings.fixed_end_px is not None:
        fe = (
            (settings.fixed_end_px[0] - (scale - 1) / 2) / scale,
            (settings.fixed_end_px[1] - (scale - 1) / 2) / scale,
        )
    try:
        comp, rivals, reached = _component(mask, fe)
    except NoLineFound:
        raise NoLineFound(
            f"no body found: nothing {what} survives the clean-up; check line_color / background / "
            "roi (python -m pipeline photoset preview)"
        ) from None
    comp, dt, path, gaps = _bridge_gaps(mask, comp, fe if reached else None)
    guessed = not reached or fe is None
    if gaps or (rivals and reached and fe is not None):  # the pieces joined are no longer rivals
        rivals = _rivals(mask & (1 - comp), comp, far_apart=reached and fe is not None)
    # the body's half-width along its own ridge (not over the whole component: a tube or a clamp
    # joined to it would pull a component-wide figure far off)
    xi, yi = np.round(path[:, 0]).astype(int), np.round(path[:, 1]).astype(int)
    half = float(np.median(dt[yi, xi])) if len(path) else 0.0
    # the body's own thickness where the ridge is not beside the hole (which thins it there)
    whole = fill_inner_holes(comp, float(np.percentile(dt[yi, xi], 90)) if len(path) else half)
    if whole is not comp:  # the profiles across the body run through its inside
        comp = whole
        dt = cv2.distanceTransform(comp, cv2.DIST_L2, 5)
        path, _ = _ridge_path(comp, dt, fe if reached else None)
        xi, yi = np.round(path[:, 0]).astype(int), np.round(path[:, 1]).astype(int)
        half = float(np.median(dt[yi, xi])) if len(path) else 0.0
    filled = fill_chamber_gaps(comp, half)
    chambered = filled is not comp
    comb = comp  # the chambers with their gaps
    if chambered:  # a row of chambers: the body is their envelope
        comp = filled
        dt = cv2.distanceTransform(comp, cv2.DIST_L2, 5)
        path, _ = _ridge_path(comp, dt, fe if reached else None)
        xi, yi = np.round(path[:, 0]).astype(int), np.round(path[:, 1]).astype(int)
        half = float(np.median(dt[yi, xi])) if len(path) else 0.0
    length = float(np.sum(np.hypot(*np.diff(path, axis=0).T))) if len(path) > 1 else 0.0
    if length < max(4.0 * half, 10.0):
        faint = faint_share(selection, comp) >= FAINT_BODY_SHARE
        raise NoLineFound(
            f"no body found: the selection ({what}) is a blob, not an elongated actuator "
            f"({length:.0f} px long, {2 * half:.0f} px wide)"
            + ("; it differs only faintly: the body may be selected in pieces (light its shaded "
               "side too, or use a backdrop it stands out against)" if faint else "")
        )
    ridge = path  # the whole ridge, end to end: what the centre line should cover
    path, _ = _trim_by_thickness(path, dt, half)
    soft = _soft_body(comp, selection.strength)
    pts = _smooth(_resample(path, 1.0), max(1.0, 0.5 * half))
    widths = np.full(len(pts), np.nan)
    window = int(round(LOCAL_WIDTH_HALF_WIDTHS * half))  # noqa: RUF046 (numpy scalar)
    reach = 3.0 * half + 4.0
    # a bump on one side (a marker dot) is left out where the outline is clear: a faint one's
    # edges wander as much (the translucent body on grey, without its empty scene); not on a row
    # of chambers, whose comb side is all bumps (customer 48's PneuNet given a direction 10 deg
    # off: its ramp check no longer saw it, 15 rows ok 10 deg off)
    clear_outline = selection.contrast >= BUMP_MIN_CONTRAST and not chambered
    for _ in range(2):
        moved, wid, cut = _midpoints(soft, pts, reach=reach, without_bumps=clear_outline)
        if cut.any():
            # a side is the image border there: along the middle of what is seen (its normals
            # follow the body, those of a ridge hugging the border need not), each point half
            # the body's width in from the side that is a real edge
            pts = _smooth(np.where(cut[:, None], moved, pts), max(1.0, SMOOTH_HALF_WIDTHS * half))
            moved, wid, _ = _midpoints(
                soft,
                pts,
                reach=reach,
                expected_width=local_widths(wid, window),
                without_bumps=clear_outline,
            )
        med = float(np.nanmedian(wid)) if np.isfinite(wid).any() else 2.0 * half
        ref = local_widths(wid, window)
        bad = ~np.isfinite(wid) | (wid > END_WIDTH_HIGH * ref) | (wid < END_WIDTH_LOW * ref)
        if fe is not None and reached:
            bad[: _leading_run(wid > FACE_WIDTH_HIGH * ref)] = True
        moved[bad] = pts[bad]  # where the normal does not span the body, keep the ridge point
        span = _good_span(~bad, max(3, int(round(half))))  # noqa: RUF046 (numpy scalar)
        # the ends where the profile runs into the clamp or round the tip: dropped
        if span is not None:
            i0, i1 = span
            moved, wid = moved[i0 : i1 + 1], wid[i0 : i1 + 1]
        pts = _smooth(_resample(moved, 1.0), max(1.0, SMOOTH_HALF_WIDTHS * half))
        fill = np.nan_to_num(wid, nan=med)
        widths = np.interp(np.linspace(0, 1, len(pts)), np.linspace(0, 1, len(fill)), fill)
    reach = max(3, int(round(LOCAL_WIDTH_HALF_WIDTHS * half / 2)))  # noqa: RUF046 (numpy scalar)
    end_med = (
        (float(np.median(widths[:reach])), float(np.median(widths[-reach:])))
        if len(widths)
        else (2.0 * half,) * 2
    )
    body_width = float(np.nanmedian(widths)) if np.isfinite(widths).any() else 2.0 * half
    pts, widths, tip_capped = _march(soft, pts, widths, half, end_med, region)
    along_ridge = _follow_ridge(ridge, pts, half)
    ridge_tip_deg = 0.0
    if len(along_ridge) > len(pts) and len(pts) >= 8:
        ridge_tip_deg = float(np.rad2deg(end_tangents(along_ridge)[1] - end_tangents(pts)[1]))
    trimmed = _extensions(
        comp,
        dt,
        pts,
        half,
        fe if reached else None,
        free_end_bends=settings.free_end == "bends",
    )
    # the body proper (not the tube or a plate joined to it at the clamp) at the border: at its
    # free end the tip may be outside the photo; along a side the middle was taken from the
    # other edge (see _midpoints)
    s_pts = np.concatenate(([0.0], np.cumsum(np.hypot(*np.diff(pts, axis=0).T))))
    tip = pts[s_pts >= s_pts[-1] - max(TIP_BORDER_HALF_WIDTHS * half, 0.1 * s_pts[-1])]
    if len(pts) >= 2:
        t = pts[-1] - pts[-2]
        t = t / max(float(np.hypot(*t)), 1e-9)
        tip = np.vstack([tip, pts[-1] + t * (trimmed[1] + half)])
    touches_tip = _on_border(comp, tip, half)
    tip_at_region_edge = region is not None and _on_border(comp, tip, half, region)
    side_on_border = not touches_tip and _on_border(comp, pts, half)
    contours, hier = cv2.findContours(comp, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_NONE)
    holes = [c for c, hh in zip(contours, hier[0]) if hh[3] != -1] if hier is not None else []
    loop = bool(holes) and max(cv2.contourArea(c) for c in holes) > 4.0 * half * half
    ends_gap = float(np.hypot(*(path[0] - path[-1])))
    line = LineExtraction(
        centreline_px=pts * scale + (scale - 1) / 2,
        width_px=float(2.0 * half * scale),
        touches_border=touches_tip,
        n_candidates=1 + rivals,
        contrast=float(min(selection.contrast * 10.0, 441.0)),
        ends_gap_px=ends_gap * scale,
        branched_fraction=1.0 if loop else 0.0,
        fixed_end_auto=guessed,
        clamp_removed=not guessed,
        trimmed_px=(trimmed[0] * scale, trimmed[1] * scale),
        gap_bridged=bool(gaps),
        fixed_end_found=reached,
    )
    gap = float(np.hypot(*(pts[0] - np.asarray(fe)))) if fe is not None and reached else 0.0
    excluded_start = 0.0
    if fe is not None and reached and len(pts) >= 2 and trimmed[0] > 0:
        out = pts[0] - pts[min(len(pts) - 1, 5)]
        out = out / max(float(np.hypot(*out)), 1e-9)
        excluded_start = trimmed[0] - _region_distance(region, pts[0], out, trimmed[0])
    return BodyExtraction(
        line=line, mask=comp, widths_px=widths * scale, selected_fraction=selected,
        continues=_continues(mask & (1 - comp), pts, half), start_gap_px=gap * scale,
        excluded_start_px=excluded_start * scale,
        faint_taken=selection.faint_taken,
        faint_share=faint_share(selection, comp),
        end_short_px=_uncovered(ridge, pts[-1]) * scale, ridge_tip_deg=ridge_tip_deg,
        free_end_width_ratio=end_med[1] / max(body_width, 1e-6), side_on_border=side_on_border,
        tip_at_region_edge=tip_at_region_edge,
        tip_capped=tip_capped,
        hollow_outline=selection.hollow_width_px >= HOLLOW_WIDTHS * 2.0 * half,
        tip_face_px=(
            0.0
            if settings.sealed_end_mm is None and settings.free_end != "capped"
            else _extensions(comp, dt, pts, half, None, free_end_bends=True)[1] * scale
        ),
        # the face is not read where the end that does not bend is given (but on chambers)
        tip_face=_in_original_px(tip_face_normal(comp, soft, pts, half), scale)
        if settings.sealed_end_mm is None or chambered
        else None,
        chambered=chambered,
        # a row of chambers leaves the clamp along its strip (its centre line starts on its
        # first chamber)
        base_edge=_in_original_px(
            base_edge_direction(
                comb, _soft_body(comb, selection.strength), pts, half, trimmed[0]
            ),
            scale,
        )
        if chambered and settings.fixed_direction_deg is not None  # what it checks
        else None,
    )
