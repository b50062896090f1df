"""From a photo to the ordered sub-pixel centre line of the marker line (paper, Section II.C).

Steps (all vectorised OpenCV / numpy / scipy, no per-pixel Python loops):

1. colour mask: for the colour name ``black`` a black-hat filter of the value channel (thin dark
   strokes, whatever the lighting), otherwise exactly the colour's HSV ranges
   (:mod:`pipeline.measure.colors`); pixels outside ``roi`` or inside ``exclude`` are dropped;
2. connected components; each large one is scored by its length (area / width, the width from
   the distance transform), so the clamp (thick), glare (not in the colour range), short
   distractor marks and specks lose to the long thin marker line;
3. thick parts touching the line (a dark clamp) are cut off by a morphological opening whose disc
   is wider than the line;
4. the pixels of the line are ordered by their geodesic (Dijkstra, 8-neighbour) distance from one
   end, found by a double sweep; the centroids of equal-distance bands are the sub-pixel centre
   line, ordered along the line itself (never by angle around a centre), so arcs past 180 deg
   whose ends approach each other are ordered correctly;
5. the line starts at ``fixed_end_px`` (what lies geodesically beyond it is dropped), or with
   ``auto`` at the end with the darker surroundings (the clamp block).

Coordinates are image pixels (x right, y down) of the *original* image, even when the work is done
on a reduced image (``scale`` > 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import dijkstra

from pipeline.measure.colors import ColorSpec, color_mask
from pipeline.measure.settings import Polygon

#: components shorter than this (work px) are never the marker line
MIN_LENGTH_PX = 25.0
#: another component at least this fraction of the chosen line's length is a rival candidate
RIVAL_FRACTION = 0.4
CLAMP_DARK_V = 110  # V (max of B, G, R) at or below which a block is a dark clamp


class NoLineFound(Exception):
    """No marker line could be extracted; the message is the reason reported in angles.csv."""


@dataclass(frozen=True)
class LineExtraction:
    """The extracted marker line and what is known about its quality.

    Attributes
    ----------
    centreline_px : ndarray, shape (N, 2)
        Sub-pixel centre-line points, fixed end first, original-image pixels (x right, y down).
    width_px : float
        Line width (original px).
    touches_border : bool
        The line reaches the image border (it may continue outside the photo).
    n_candidates : int
        Line-like components found (1 = unambiguous).
    contrast : float
        Colour distance between the line and its surroundings (0-441, BGR units).
    ends_gap_px : float
        Straight distance between the two ends of the line (original px).
    branched_fraction : float
        Fraction of equal-distance bands split in separate pieces (a line closing on itself or
        crossing something).
    fixed_end_auto : bool
        The fixed end was guessed (``fixed_end: auto``).
    clamp_removed : bool
        A clamp was seen: a thick blob touching the line was cut off, or (``auto``) one end
        has clearly darker surroundings.
    trimmed_px : (float, float)
        Length cut from the fixed and the free end of ``centreline_px`` (original px): the
        measured line extends this far beyond the first and the last point.
    gap_bridged : bool
        A fragment beyond a gap (glare, occlusion) was joined to the line.
    fixed_end_found : bool
        A candidate line reaches the given fixed end (else the longest line was used).
    """

    centreline_px: np.ndarray
    width_px: float
    touches_border: bool
    n_candidates: int
    contrast: float
    ends_gap_px: float
    branched_fraction: float
    fixed_end_auto: bool
    clamp_removed: bool
    trimmed_px: tuple[float, float] = (0.0, 0.0)
    gap_bridged: bool = False
    fixed_end_found: bool = True


# ---------------------------------------------------------------------------------------------
# colour mask


def _kernel_px(shape: tuple[int, ...]) -> int:
    """Side of the black-hat square: wider than any marker line, narrower than the clamp."""
    return int(max(11, max(shape[:2]) // 40) | 1)


def line_mask(image_bgr: np.ndarray, color: ColorSpec) -> tuple[np.ndarray, np.ndarray]:
    """Binary mask of the marker line's pixels and per-pixel weights for sub-pixel centroids.

    For the colour name ``black`` (``color.dark_line``) the mask is a black-hat (closing minus
    image) of the value channel ``V = max(B, G, R)`` with a square wider than the line,
    thresholded at 35 % of its strong response: thin dark strokes stand out whatever the
    lighting gradient, vignetting or faded ink, while large dark things (clamp block, shadows) do
    not.  For any other colour the HSV ranges themselves are the mask.

    Parameters
    ----------
    image_bgr : ndarray, shape (H, W, 3) or (H, W), uint8
        Colour photo, or its grey (luma) decoding for ``black``.
    color : ColorSpec
        See :mod:`pipeline.measure.colors`.

    Returns
    -------
    mask : ndarray, shape (H, W), uint8 (0 / 1)
    weight : ndarray, shape (H, W), uint8
        Line strength (black-hat response, or the mask for colour ranges).
    """
    if color.dark_line:
        v = (
            image_bgr
            if image_bgr.ndim == 2
            else cv2.max(cv2.max(image_bgr[:, :, 0], image_bgr[:, :, 1]), image_bgr[:, :, 2])
        )
        k = _kernel_px(image_bgr.shape)
        bh = cv2.morphologyEx(
            v, cv2.MORPH_BLACKHAT, cv2.getStructuringElement(cv2.MORPH_RECT, (k, k))
        )
        hist = cv2.calcHist([bh], [0], None, [256], [0, 256]).ravel()
        cum = np.cumsum(hist[::-1])  # pixels at or above each level, from 255 down
        peak = 255 - int(np.searchsorted(cum, 0.001 * bh.size))
        thr = max(20, int(0.35 * peak))
        mask = (bh >= thr).astype(np.uint8)
        return mask, bh
    mask = color_mask(image_bgr, color)
    return mask, mask


def region_mask(
    shape: tuple[int, ...], roi: Polygon | None, exclude: tuple[Polygon, ...], scale: float = 1.0
) -> np.ndarray | None:
    """0/1 mask of where the actuator may be (inside ``roi``, outside every ``exclude``), or None.

    Polygons are in original pixels; ``scale`` is original px per px of ``shape``.

    Examples
    --------
    >>> m = region_mask((10, 10), ((0, 0), (5, 0), (5, 10), (0, 10)), ())
    >>> bool(m.sum() > 0 and m[5, 8] == 0)
    True
    """
    if roi is None and not exclude:
        return None
    h, w = shape[:2]

    def px(poly: Polygon) -> np.ndarray:
        q = (np.asarray(poly, float) - (scale - 1) / 2) / scale
        return np.round(q * 16).astype(np.int32)

    out = np.ones((h, w), np.uint8) if roi is None else np.zeros((h, w), np.uint8)
    if roi is not None:
        cv2.fillPoly(out, [px(roi)], 1, cv2.LINE_8, 4)
    for poly in exclude:
        cv2.fillPoly(out, [px(poly)], 0, cv2.LINE_8, 4)
    return out


# ---------------------------------------------------------------------------------------------
# components


@dataclass(frozen=True)
class _Candidate:
    x0: int
    y0: int
    sub: np.ndarray  # uint8 0/1 mask of the component in its bounding box (1 px margin)
    half_width: float
    length: float  # half the outer perimeter: the length of a thin line, small for blobs
    dist_fixed: float  # nearest pixel to the fixed end (work px), inf when unknown


def clamp_radius_px(half_width_px: float) -> float:
    """Thickness (px from the edge) above which a blob of the line's colour is a clamp, not line.

    Examples
    --------
    >>> clamp_radius_px(1.0), clamp_radius_px(4.0)
    (4.0, 10.0)
    """
    return max(2.5 * half_width_px, half_width_px + 3.0)


def _ridge_half_width(sub: np.ndarray) -> float:
    dt = cv2.distanceTransform(sub, cv2.DIST_L2, 3)
    ridge = (dt > 0) & (dt >= cv2.dilate(dt, np.ones((3, 3), np.uint8)))
    vals = dt[ridge]
    return float(np.median(vals)) if vals.size else 0.5


def _candidates(
    mask: np.ndarray, fixed_xy: tuple[float, float] | None, max_candidates: int = 10
) -> list[_Candidate]:
    # external contours are ~50x cheaper than connectedComponentsWithStats on a full frame
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE)
    h, w = mask.shape
    boxes = []
    for c in contours:
        x, y, bw, bh = cv2.boundingRect(c)
        if max(bw, bh) >= MIN_LENGTH_PX:
            boxes.append((0.5 * cv2.arcLength(c, True), c, x, y, bw, bh))
    boxes.sort(key=lambda b: -b[0])
    out = []
    for length, c, x, y, bw, bh in boxes[:max_candidates]:
        x0, y0 = max(x - 1, 0), max(y - 1, 0)
        x1, y1 = min(x + bw + 1, w), min(y + bh + 1, h)
        sub = np.zeros((y1 - y0, x1 - x0), np.uint8)
        cv2.drawContours(sub, [c], -1, 1, cv2.FILLED, offset=(-x0, -y0))
        sub &= mask[y0:y1, x0:x1]
        dist = np.inf
        if fixed_xy is not None:
            pts = c.reshape(-1, 2).astype(float)
            dist = float(
                np.sqrt(np.min((pts[:, 0] - fixed_xy[0]) ** 2 + (pts[:, 1] - fixed_xy[1]) ** 2))
            )
        out.append(_Candidate(x0, y0, sub, float("nan"), float(length), dist))
    return out


def _with_width(c: _Candidate) -> _Candidate:
    """The candidate with its line half-width measured (distance transform; only when needed)."""
    if np.isfinite(c.half_width):
        return c
    return _Candidate(c.x0, c.y0, c.sub, _ridge_half_width(c.sub), c.length, c.dist_fixed)


def _choose(cands: list[_Candidate], near_px: float) -> tuple[_Candidate, bool]:
    """The marker line: the longest candidate reaching the fixed end (else the longest)."""
    near = [c for c in cands if c.dist_fixed <= near_px]
    if near:
        return max(near, key=lambda c: c.length), True
    return max(cands, key=lambda c: c.length), False


def line_component(
    mask: np.ndarray, fixed_end_px: tuple[float, float] | None, near_px: float
) -> tuple[int, int, np.ndarray]:
    """The component of a line mask that :func:`extract_centreline` starts from.

    The longest line-like component reaching ``fixed_end_px`` (within ``near_px``), else the
    longest; as ``(x0, y0, sub)``: its 0/1 mask ``sub`` in its bounding box (1 px margin) at
    ``(x0, y0)`` of ``mask``.  Pixels of the work image throughout.

    Raises
    ------
    NoLineFound
        When ``mask`` holds nothing line-like.
    """
    cands = _candidates(mask, fixed_end_px)
    if not cands:
        raise NoLineFound("no line found: nothing long and thin in the mask")
    best, _ = _choose(cands, near_px)
    return best.x0, best.y0, best.sub


def _fill_small_holes(sub: np.ndarray, max_fraction: float = 0.1) -> np.ndarray:
    """Fill holes smaller than ``max_fraction`` of the box (a clamp's frame becomes a block).

    Large holes (the inside of an actuator curled into a closed loop) are kept open.
    """
    contours, hier = cv2.findContours(sub, cv2.RETR_CCOMP, cv2.CHAIN_APPROX_SIMPLE)
    if hier is None:
        return sub
    holes = [
        c
        for c, h in zip(contours, hier[0])
        if h[3] != -1 and cv2.contourArea(c) < max_fraction * sub.size
    ]
    if not holes:
        return sub
    filled = sub.copy()
    cv2.drawContours(filled, holes, -1, 1, cv2.FILLED)
    return filled


def _cut_thick_parts(sub: np.ndarray, half_width: float) -> tuple[np.ndarray, np.ndarray | None]:
    """Remove blobs much thicker than the line (a clamp); return (line, removed blob or None)."""
    filled = _fill_small_holes(sub)
    dt = cv2.distanceTransform(filled, cv2.DIST_L2, 3)
    radius = int(np.ceil(clamp_radius_px(half_width)))
    if dt.max() <= radius:
        return sub, None
    k = 2 * radius + 1
    thick = cv2.morphologyEx(
        filled, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))
    )
    # everything within a disc radius of the thick part belongs to it (clamp frames, edges)
    thick = cv2.dilate(thick, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 5,) * 2))
    line = sub & (1 - thick)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(line, connectivity=8)
    if n <= 1:
        return sub, None
    keep = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return (labels == keep).astype(np.uint8), thick


# ---------------------------------------------------------------------------------------------
# ordering


#: the 8 neighbours (dy, dx) and their distances
_NEIGHBOURS = np.array([(-1, -1), (-1, 0), (-1, 1), (0, -1), (0, 1), (1, -1), (1, 0), (1, 1)])
_NEIGHBOUR_PX = np.hypot(_NEIGHBOURS[:, 0], _NEIGHBOURS[:, 1])


def _pixel_graph(ys: np.ndarray, xs: np.ndarray, shape: tuple[int, int]) -> csr_matrix:
    """8-neighbour graph of the pixels ``(ys, xs)``, both directions stored, built as CSR
    directly."""
    idx = np.full((shape[0] + 2, shape[1] + 2), -1, np.int32)
    idx[ys + 1, xs + 1] = np.arange(len(ys), dtype=np.int32)
    nb = idx[ys[:, None] + 1 + _NEIGHBOURS[:, 0], xs[:, None] + 1 + _NEIGHBOURS[:, 1]]  # (n, 8)
    ok = nb >= 0
    indptr = np.zeros(len(ys) + 1, np.int32)
    np.cumsum(ok.sum(axis=1), out=indptr[1:])
    data = np.broadcast_to(_NEIGHBOUR_PX, nb.shape)[ok]
    return csr_matrix((data, nb[ok], indptr), shape=(len(ys), len(ys)))


def order_pixels(
    sub: np.ndarray, weight: np.ndarray, start_xy: tuple[float, float] | None, band_px: float
) -> tuple[np.ndarray, float, np.ndarray]:
    """Centre line of one thin component as band centroids of the geodesic distance from an end.

    Parameters
    ----------
    sub : ndarray of 0/1
        The component.
    weight : ndarray
        Per-pixel weights (line strength) for the centroids, same shape as ``sub``.
    start_xy : (x, y) or None
        The fixed end (in ``sub`` coordinates); pixels geodesically beyond it are dropped.
    band_px : float
        Band width along the line (px).

    Returns
    -------
    points : ndarray, shape (N, 2)
        Ordered weighted centroids (x, y) in ``sub`` coordinates, from the end nearer
        ``start_xy`` (else from an arbitrary end).
    branched_fraction : float
        Fraction of bands whose pixels are spread wider than the line (loops, branches).
    ends : ndarray, shape (2, 2)
        The two end pixels (x, y), in the order of ``points``.
    """
    ys, xs = np.nonzero(sub)
    graph = _pixel_graph(ys, xs, sub.shape)
    seed = (
        0 if start_xy is None else int(np.argmin((xs - start_xy[0]) ** 2 + (ys - start_xy[1]) ** 2))
    )
    d0 = dijkstra(graph, directed=True, indices=seed)
    d0[~np.isfinite(d0)] = -1.0
    a = int(np.argmax(d0))  # the far (free) end
    da = dijkstra(graph, directed=True, indices=a)
    reach = np.isfinite(da)
    if start_xy is not None:
        # the line ends at the fixed end: drop what lies beyond it (clamp outline, tube edge)
        reach &= da <= da[seed] + 0.5
    b = int(np.argmax(np.where(reach, da, -1.0)))
    ea, eb = np.array([xs[a], ys[a]], float), np.array([xs[b], ys[b]], float)
    s = da[reach]
    x, y = xs[reach].astype(float), ys[reach].astype(float)
    wt = weight[ys[reach], xs[reach]].astype(float) + 1e-3
    band = (s / band_px).astype(np.int64)
    nb = int(band.max()) + 1
    cnt = np.bincount(band, wt, nb)
    good = cnt > 0
    sx, sy = np.bincount(band, wt * x, nb), np.bincount(band, wt * y, nb)
    sxx, syy = np.bincount(band, wt * x * x, nb), np.bincount(band, wt * y * y, nb)
    cnt_g = cnt[good]
    cx, cy = sx[good] / cnt_g, sy[good] / cnt_g
    spread = np.sqrt(np.maximum(sxx[good] / cnt_g - cx**2 + syy[good] / cnt_g - cy**2, 0.0))
    points = np.c_[cx, cy][::-1]  # from b (fixed end side when start_xy is given) to a
    ends = np.array([eb, ea])
    return points, float(np.mean(spread > 2.0 * band_px + 1.0)), ends


# ---------------------------------------------------------------------------------------------
# whole extraction


def _contrast(image: np.ndarray, points: np.ndarray, half_width: float) -> float:
    """Colour distance between the line and the background beside it, sampled across the line."""
    points = points[:: max(len(points) // 60, 1)]
    d = np.gradient(points, axis=0)
    n = np.c_[-d[:, 1], d[:, 0]] / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-9)[:, None]
    off = 2.0 * half_width + 3.0
    h, w = image.shape[:2]

    def sample(p: np.ndarray) -> np.ndarray:
        xi = np.clip(np.round(p[:, 0]).astype(int), 0, w - 1)
        yi = np.clip(np.round(p[:, 1]).astype(int), 0, h - 1)
        return image[yi, xi].astype(float)

    inside = np.median(sample(points), axis=0)
    outside = np.median(np.r_[sample(points + off * n), sample(points - off * n)], axis=0)
    return float(np.linalg.norm(inside - outside))


def _value(image: np.ndarray) -> np.ndarray:
    """V = max(B, G, R) of a colour image; a grey image is its own value."""
    return image if image.ndim == 2 else image.max(axis=2)


def _cut_dark_blocks(
    image: np.ndarray,
    cand: _Candidate,
    line: np.ndarray,
    at: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """Cut the line where it runs into a dark block (a clamp the black-hat mask left out).

    With ``fixed_end: auto`` every dark block cuts. With a given fixed end ``at`` (work px) only
    the block holding it does: the fixed end was given inside a dark clamp, and the black-hat mask
    follows the clamp's edge to it (a line at psi 150 with its fixed end 12 % of its length inside
    the clamp read 98, ok).
    """
    h, w = line.shape
    pad = int(6 * cand.half_width + 8)
    y0, x0 = max(cand.y0 - pad, 0), max(cand.x0 - pad, 0)
    y1, x1 = min(cand.y0 + h + pad, image.shape[0]), min(cand.x0 + w + pad, image.shape[1])
    roi = image[y0:y1, x0:x1]
    v = cv2.blur(_value(roi), (5, 5))
    dark = (v <= CLAMP_DARK_V).astype(np.uint8)
    radius = int(np.ceil(clamp_radius_px(cand.half_width)))
    k = 2 * radius + 1
    block = cv2.morphologyEx(
        dark, cv2.MORPH_OPEN, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (k, k))
    )
    if at is not None:
        ax, ay = int(round(at[0])) - x0, int(round(at[1])) - y0  # noqa: RUF046 (numpy)
        if not (0 <= ay < block.shape[0] and 0 <= ax < block.shape[1]) or not block[ay, ax]:
            return line, None
        _, blocks = cv2.connectedComponents(block, connectivity=8)
        block = (blocks == blocks[ay, ax]).astype(np.uint8)
        if block.sum() > 0.5 * block.size:  # a dark backdrop, not a clamp
            return line, None
        inside = block[cand.y0 - y0 : cand.y0 - y0 + h, cand.x0 - x0 : cand.x0 - x0 + w] & line
        if inside.sum() <= 2.0 * cand.half_width * (radius + 2):
            return line, None  # at the face: the cut would take more line than the clamp hides
    if not block.any():
        return line, None
    block = cv2.dilate(block, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 5,) * 2))
    block = block[cand.y0 - y0 : cand.y0 - y0 + h, cand.x0 - x0 : cand.x0 - x0 + w]
    cut = line & (1 - block)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(cut, connectivity=8)
    if n <= 1 or not block[line > 0].any():
        return line, None
    keep = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return (labels == keep).astype(np.uint8), block


def _dark_at(image: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Whether the photo is as dark as a clamp (V <= ``CLAMP_DARK_V``) at each point (N, 2)."""
    h, w = image.shape[:2]
    p = np.round(xy).astype(int)
    xs, ys = np.clip(p[:, 0], 0, w - 1), np.clip(p[:, 1], 0, h - 1)
    v = image[ys, xs] if image.ndim == 2 else image[ys, xs].max(axis=1)
    return np.asarray(v <= CLAMP_DARK_V)


def _inside_dark(image: np.ndarray, xy: tuple[float, float], radius: float) -> bool:
    """Whether ``xy`` lies inside something dark wider than a line: at least 7 of 8 points on a
    circle of ``radius`` around it are dark (a point on a dark line has 2, one at a clamp's face
    about 4)."""
    a = np.arange(8) * (np.pi / 4)
    ring = np.asarray(xy, float) + radius * np.c_[np.cos(a), np.sin(a)]
    return int(np.count_nonzero(_dark_at(image, ring))) >= 7


def _back_tangent(points: np.ndarray) -> np.ndarray:
    """Unit vector from the line's start backwards, towards the clamp (its first 5 %)."""
    k = min(len(points) - 1, max(len(points) // 20, 3))
    t = points[0] - points[k]
    return np.asarray(t / max(float(np.hypot(*t)), 1e-9))


def _dark_between(image: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the straight path from ``a`` to ``b`` runs in the dark for 80 % of its length:
    both lie in one dark clamp (its bolts and marks may be lighter)."""
    return bool(np.mean(_dark_at(image, a + np.linspace(0.0, 1.0, 24)[:, None] * (b - a))) >= 0.8)


def _face_distance(image: np.ndarray, points: np.ndarray, half_width: float) -> float:
    """Distance (work px) back from the line's first point, along its start tangent, to the face of
    the clamp that was cut off (0 when no clear face is seen).

    Beside the line, on both sides, the photo goes from table to clamp at the face: the two side
    profiles are sampled (sub-pixel) and the face is where their mean crosses halfway between
    the table's and the clamp's brightness.
    """
    t = _back_tangent(points)
    nrm = np.array([-t[1], t[0]])
    steps = np.arange(0.0, 14.0 * half_width + 14.0, 0.25, dtype=np.float32)
    side = 2.0 * half_width + 3.0
    # only the square the profiles run in (the whole photo's value cost a millisecond a photo)
    reach = int(np.ceil(float(steps[-1]) + side)) + 2
    x0 = max(int(points[0, 0]) - reach, 0)
    y0 = max(int(points[0, 1]) - reach, 0)
    v = _value(image[y0 : int(points[0, 1]) + reach + 1, x0 : int(points[0, 0]) + reach + 1])
    v = v.astype(np.float32)
    prof = np.zeros_like(steps)
    for sgn in (-1.0, 1.0):
        cx = (points[0, 0] - x0 + steps * t[0] + sgn * side * nrm[0]).astype(np.float32)[None, :]
        cy = (points[0, 1] - y0 + steps * t[1] + sgn * side * nrm[1]).astype(np.float32)[None, :]
        prof += 0.5 * cv2.remap(v, cx, cy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE)[0]
    table = float(np.median(prof[: max(4, len(prof) // 12)]))
    dark = float(prof.min())
    if table - dark < 25.0:
        return 0.0
    below = np.nonzero(prof <= 0.5 * (table + dark))[0]
    if not below.size or below[0] == 0:
        return 0.0
    j = int(below[0])
    a, b = prof[j - 1], prof[j]
    frac = (a - 0.5 * (table + dark)) / max(a - b, 1e-6)
    return float(steps[j - 1] + frac * (steps[j] - steps[j - 1]))


def _surround_darkness(image: np.ndarray, xy: np.ndarray, half_width: float) -> float:
    """Mean darkness (255 - V) in a square around a line end: high next to a dark clamp."""
    r = int(6 * half_width + 8)
    h, w = image.shape[:2]
    x, y = int(round(xy[0])), int(round(xy[1]))  # noqa: RUF046 (numpy scalar)
    roi = image[max(y - r, 0) : min(y + r + 1, h), max(x - r, 0) : min(x + r + 1, w)]
    if roi.size == 0:
        return 0.0
    return float(255.0 - _value(roi).mean())


def _bridge(
    line: np.ndarray,
    points: np.ndarray,
    others: list[_Candidate],
    best: _Candidate,
    max_gap_px: float,
) -> tuple[np.ndarray, int, int, int] | None:
    """Join a fragment continuing the line past a gap (glare, occlusion) with a straight bridge.

    Returns the union mask and its box offset / or None when no fragment continues the line.
    """
    end = points[-1] + np.array([best.x0, best.y0])
    k = max(len(points) // 15, 3)
    tangent = points[-1] - points[-k]
    tangent = tangent / max(np.hypot(*tangent), 1e-9)
    for c in others:
        ys, xs = np.nonzero(c.sub)
        gx, gy = xs + c.x0, ys + c.y0
        d2 = (gx - end[0]) ** 2 + (gy - end[1]) ** 2
        i = int(np.argmin(d2))
        gap = float(np.sqrt(d2[i]))
        if gap > max_gap_px or gap < 1.0:
            continue
        direction = np.array([gx[i] - end[0], gy[i] - end[1]]) / gap
        if float(direction @ tangent) < np.cos(np.deg2rad(35.0)):
            continue
        # the fragment itself must run on in the same direction near its end
        near = (gx - gx[i]) ** 2 + (gy - gy[i]) ** 2 <= (4.0 * best.half_width + 6.0) ** 2
        if near.sum() >= 3:
            cov = np.cov(np.c_[gx[near], gy[near]].T.astype(float))
            axis = np.linalg.eigh(cov)[1][:, -1]
            if abs(float(axis @ tangent)) < np.cos(np.deg2rad(35.0)):
                continue
        x0, y0 = min(best.x0, c.x0), min(best.y0, c.y0)
        x1 = max(best.x0 + line.shape[1], c.x0 + c.sub.shape[1])
        y1 = max(best.y0 + line.shape[0], c.y0 + c.sub.shape[0])
        union = np.zeros((y1 - y0, x1 - x0), np.uint8)
        union[
            best.y0 - y0 : best.y0 - y0 + line.shape[0], best.x0 - x0 : best.x0 - x0 + line.shape[1]
        ] |= line
        union[c.y0 - y0 : c.y0 - y0 + c.sub.shape[0], c.x0 - x0 : c.x0 - x0 + c.sub.shape[1]] |= (
            c.sub
        )
        thick = max(int(round(2 * best.half_width)), 1)  # noqa: RUF046 (numpy scalar)
        p0 = (int(round(end[0] - x0)), int(round(end[1] - y0)))  # noqa: RUF046 (numpy scalar)
        cv2.line(union, p0, (int(gx[i] - x0), int(gy[i] - y0)), 1, thick)
        others.remove(c)
        return union, x0, y0, int(np.count_nonzero(c.sub))
    return None


def extract_centreline(
    image_bgr: np.ndarray,
    *,
    color: ColorSpec,
    fixed_end_px: tuple[float, float] | None = None,
    scale: float = 1.0,
    region: np.ndarray | None = None,
) -> LineExtraction:
    """Extract the ordered sub-pixel centre line of the marker line.

    Parameters
    ----------
    image_bgr : ndarray, shape (H, W, 3), uint8
        The photo, possibly reduced by ``scale`` from the original.
    color : ColorSpec
        Marker colour.
    fixed_end_px : (x, y) or None
        The clamped end of the line in *original* pixels; None: guess it.
    scale : float
        Original pixels per pixel of ``image_bgr``.
    region : ndarray of 0/1, optional
        Where the line may be (:func:`region_mask`, same size as ``image_bgr``).

    Returns
    -------
    LineExtraction

    Raises
    ------
    NoLineFound
        If no line-like component of the colour exists.
    """
    if image_bgr is None or not (
        image_bgr.ndim == 2 or (image_bgr.ndim == 3 and image_bgr.shape[2] == 3)
    ):
        raise NoLineFound("unreadable image (not a colour or grey image)")
    if image_bgr.ndim == 2 and not color.dark_line:
        raise NoLineFound(
            f"a grey image cannot show line_color {color.describe()}; decode it in colour"
        )
    h, w = image_bgr.shape[:2]
    fe = None
    if fixed_end_px is not None and np.all(np.isfinite(fixed_end_px)):
        fe = (
            (fixed_end_px[0] - (scale - 1) / 2) / scale,
            (fixed_end_px[1] - (scale - 1) / 2) / scale,
        )
    mask, weight = line_mask(image_bgr, color)
    if region is not None:
        mask &= region
    cands = _candidates(mask, fe)
    if not cands:
        where = " inside roi / outside exclude" if region is not None else ""
        raise NoLineFound(
            f"no line found: nothing long and thin of line_color {color.describe()}{where}; "
            "check line_color (python -m pipeline photoset preview shows what it selects)"
        )
    diag = float(np.hypot(h, w))
    best, at_fixed = _choose(cands, near_px=0.03 * diag)
    others = [c for c in cands if c is not best]
    best = _with_width(best)
    others = [_with_width(c) if c.length >= RIVAL_FRACTION * best.length else c for c in others]
    rivals = sum(
        1
        for c in others
        if c.length >= RIVAL_FRACTION * best.length and c.half_width < 2.0 * best.half_width
    )
    line, thick = _cut_thick_parts(best.sub, best.half_width)
    if fe is None and thick is None:
        line, thick = _cut_dark_blocks(image_bgr, best, line)
    elif (
        thick is None
        and color.dark_line
        and fe is not None
        and _inside_dark(image_bgr, fe, clamp_radius_px(best.half_width) + 2.0)
    ):
        line, _ = _cut_dark_blocks(image_bgr, best, line, at=fe)
    band = max(1.0, min(2.0, best.half_width))
    fe_sub = None if fe is None else (fe[0] - best.x0, fe[1] - best.y0)
    x0, y0 = best.x0, best.y0
    points, branched, ends = order_pixels(
        line, weight[y0 : y0 + line.shape[0], x0 : x0 + line.shape[1]], fe_sub, band
    )
    bridged = 0
    for _ in range(3):
        if len(points) < 4:
            break
        max_gap = 0.25 * float(np.sum(np.hypot(*np.diff(points, axis=0).T)))
        joined = _bridge(
            line,
            points,
            others,
            _Candidate(x0, y0, line, best.half_width, best.length, 0.0),
            max_gap,
        )
        if joined is None:
            break
        line, x0, y0, n_px = joined
        bridged += n_px
        fe_sub = None if fe is None else (fe[0] - x0, fe[1] - y0)
        points, branched, ends = order_pixels(
            line, weight[y0 : y0 + line.shape[0], x0 : x0 + line.shape[1]], fe_sub, band
        )
    if bridged:
        rivals = sum(
            1
            for c in others
            if c.length >= RIVAL_FRACTION * best.length and c.half_width < 2.0 * best.half_width
        )
    if len(points) < 8:
        raise NoLineFound(f"no line found: the longest candidate is only {len(points)} bands long")
    fixed_auto = fe is None
    clamp_seen = thick is not None
    clamp_face: np.ndarray | None = None  # (x, y) pixels of the clamp's face, work image
    if fixed_auto:
        ends_g = ends + np.array([x0, y0], float)
        clamp_end = None
        if thick is not None:
            # the clamp that was cut off sits at the fixed end: the end nearer to it
            ty, tx = np.nonzero(thick)
            face = np.c_[tx + best.x0, ty + best.y0].astype(float)
            d = [float(np.min(np.hypot(*(face - e).T))) for e in ends_g]
            if min(d) < 0.5 * max(d):
                clamp_end, clamp_face = int(np.argmin(d)), face
        if clamp_end is None:
            darkness = [_surround_darkness(image_bgr, e, best.half_width) for e in ends_g]
            clamp_seen = clamp_seen or abs(darkness[0] - darkness[1]) >= 20.0
            # the clamp (dark block) sits at the fixed end
            clamp_end = 1 if darkness[1] > darkness[0] else 0
        if clamp_end == 1:
            points, ends = points[::-1], ends[::-1]
    ys, xs = np.nonzero(line)
    touches = bool(
        xs.min() + x0 <= 0 or ys.min() + y0 <= 0 or xs.max() + x0 >= w - 1 or ys.max() + y0 >= h - 1
    )
    gpts = points + np.array([x0, y0], float)
    # drop about one line width at each end: the band centroids bend towards the corner pixel
    # where the geodesic sweep starts, which would tilt the end tangents
    seg = np.hypot(*np.diff(gpts, axis=0).T)
    s_along = np.concatenate(([0.0], np.cumsum(seg)))
    trim = max(2.0 * best.half_width, 2.0 * band)
    keep = (s_along >= trim) & (s_along <= s_along[-1] - trim)
    if keep.sum() >= 8:
        i0, i1 = int(np.argmax(keep)), len(keep) - 1 - int(np.argmax(keep[::-1]))
        gpts = gpts[i0 : i1 + 1]
    else:
        i0, i1 = 0, len(s_along) - 1
    # the end bands' centroids lie about a quarter band inside the line's ends (measured on
    # synthetic lines of known length)
    trimmed = ((s_along[i0] + band / 4) * scale, (s_along[-1] - s_along[i1] + band / 4) * scale)
    if fe is not None or clamp_face is not None:
        # the line starts at the given fixed end (or, guessed, at the face of the clamp that was cut
        # off), also where the clamp cut removed a piece of it
        if fe is not None:
            gap_fixed = float(np.hypot(*(gpts[0] - np.asarray(fe)))) * scale
            face = (
                _face_distance(image_bgr, gpts, best.half_width) * scale
                if gap_fixed > trimmed[0]  # else the face would change nothing
                else 0.0
            )
            if face > 0.0:
                # not on into the clamp: a fixed end given inside it (a camera held by hand
                # moved the clamp 100-200 px off customer 46's one fixed end, and psi, the
                # line's curvature times its length, read up to 9 % high, ok)
                gap_fixed = min(gap_fixed, face)
                # a line running out of the clamp that holds the fixed end, near it, reaches it
                face_xy = gpts[0] + (face / scale + 2.0) * _back_tangent(gpts)
                at_fixed = at_fixed or (
                    float(np.hypot(*(face_xy - np.asarray(fe)))) <= 0.15 * s_along[-1]
                    and _dark_between(image_bgr, face_xy, np.asarray(fe))
                )
        else:
            gap_fixed = _face_distance(image_bgr, gpts, best.half_width) * scale
        if gap_fixed < 0.15 * s_along[-1] * scale:
            trimmed = (max(trimmed[0], gap_fixed), trimmed[1])
    centre = gpts * scale + (scale - 1) / 2
    return LineExtraction(
        centreline_px=centre,
        width_px=float(2.0 * best.half_width * scale),
        touches_border=touches,
        n_candidates=1 + rivals,
        contrast=_contrast(image_bgr, gpts, best.half_width),
        ends_gap_px=float(np.hypot(*(ends[0] - ends[1])) * scale),
        branched_fraction=branched,
        fixed_end_auto=fixed_auto,
        clamp_removed=clamp_seen,
        trimmed_px=(float(trimmed[0]), float(trimmed[1])),
        gap_bridged=bridged > 0,
        fixed_end_found=at_fixed or fe is None,
    )
