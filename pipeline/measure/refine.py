"""Sub-pixel refinement of a coarse centre line on a finer grey image (dark marker lines).

The extraction (mask, components, clamp cut, geodesic ordering) runs on a small image, which is
cheap; its ordered centre line is then moved onto the darkness ridge of the line in a finer
decoding of the same photo.  For every centre-line point the grey values across the line (along
the normal) are sampled by one :func:`cv2.remap`, and the point is shifted to the centroid of
the profile's darkness (darkness above a fraction of its peak, so that the background does not
pull it).  Two passes, the second centred on the first result, remove the truncation bias of a
window that was off-centre.  A profile with too little darkness keeps its coarse point.
"""

from __future__ import annotations

import cv2
import numpy as np

#: profile samples per fine pixel across the line
SAMPLES_PER_PX = 2
#: darkness below this fraction of the profile's peak darkness does not count
FLOOR_FRACTION = 0.35
#: profiles with a peak darkness below this (grey levels) keep their coarse point
MIN_DARKNESS = 12.0


def _normals(points: np.ndarray, window: int = 3) -> np.ndarray:
    """Unit normals of a polyline, from tangents over +-``window`` points (smooth)."""
    n = len(points)
    i = np.arange(n)
    lo, hi = np.clip(i - window, 0, n - 1), np.clip(i + window, 0, n - 1)
    t = points[hi] - points[lo]
    t = t / np.maximum(np.hypot(t[:, 0], t[:, 1]), 1e-9)[:, None]
    return np.c_[-t[:, 1], t[:, 0]]


def _profile_shift(
    fine: np.ndarray, q: np.ndarray, nrm: np.ndarray, half_range: float
) -> tuple[np.ndarray, np.ndarray]:
    """Darkness centroid offset (fine px, along ``nrm``) of the profile at each point."""
    k = int(np.ceil(half_range * SAMPLES_PER_PX))
    off = np.arange(-k, k + 1, dtype=np.float32) / SAMPLES_PER_PX
    mapx = (q[:, 0:1] + nrm[:, 0:1] * off).astype(np.float32)
    mapy = (q[:, 1:2] + nrm[:, 1:2] * off).astype(np.float32)
    prof = cv2.remap(fine, mapx, mapy, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE).astype(
        np.float32
    )
    dark = prof.max(axis=1, keepdims=True) - prof
    peak = dark.max(axis=1, keepdims=True)
    wt = np.maximum(dark - FLOOR_FRACTION * peak, 0.0)
    tot = wt.sum(axis=1)
    good = (peak[:, 0] >= MIN_DARKNESS) & (tot > 0)
    shift = np.where(good, (wt * off).sum(axis=1) / np.maximum(tot, 1e-9), 0.0)
    return shift, good


def refine_centreline(
    fine: np.ndarray, centreline_px: np.ndarray, *, scale: float, half_width_px: float
) -> np.ndarray:
    """Move a coarse centre line onto the darkness ridge of the line in a finer grey image.

    Parameters
    ----------
    fine : ndarray, shape (H, W), uint8
        Grey (luma) image, reduced by ``scale`` from the original.
    centreline_px : ndarray, shape (N, 2)
        Ordered centre line in original pixels (x right, y down).
    scale : float
        Original pixels per pixel of ``fine``.
    half_width_px : float
        Half the line width (original px); sets the profile length.

    Returns
    -------
    ndarray, shape (N, 2)
        Refined centre line in original pixels, same order (and count) as the input.

    Examples
    --------
    >>> import cv2, numpy as np
    >>> y = np.arange(60.0)[:, None] + np.zeros((1, 200))
    >>> img = (200 - 170 * np.exp(-(((y - 30.3) / 1.5) ** 2))).astype(np.uint8)   # line at y = 30.3
    >>> coarse = np.c_[np.arange(20.0, 180.0, 4.0), np.full(40, 29.0)]              # 1.3 px off
    >>> fine = refine_centreline(img, coarse, scale=1.0, half_width_px=1.5)
    >>> print(round(float(np.median(fine[:, 1])), 2))
    30.3
    """
    q = (centreline_px - (scale - 1) / 2) / scale
    hw = max(half_width_px / scale, 0.75)
    nrm = _normals(q)
    shift, _ = _profile_shift(fine, q, nrm, 2.0 * hw + 2.5)
    q = q + shift[:, None] * nrm
    shift2, good2 = _profile_shift(fine, q, nrm, 1.5 * hw + 1.5)
    q = q + (shift2 * good2)[:, None] * nrm
    return q * scale + (scale - 1) / 2
