"""The empty scene of a ramp, estimated from its own photos.

Along a ramp the camera stands still and the body sweeps across the scene, so each pixel shows
the backdrop in most photos.  Its median over the photos whose body, as first measured, lies
away from it is the empty scene there; where the body stayed put (its base, by the clamp) no
photo is free of it and the plain median shows the body, which
:func:`pipeline.measure.body.estimated_background_difference` recognises and leaves to the
backdrop.  A translucent body on a backdrop of its own grey, whose faint parts the backdrop
model misses, stands out against this estimate as against a photo of the empty scene.  A camera
left on automatic exposes each photo and balances its colours a little differently; each photo is
brought to the ramp's typical exposure first, or the median would join patches of different
exposures.

Examples
--------
>>> scene = np.full((40, 60, 3), 120, np.uint8)
>>> photos = []
>>> for x in (10, 25, 40, 50):
...     p = scene.copy(); p[5:35, x:x + 4] = 200; photos.append(p)
>>> covers = [covered(p.shape[:2], np.array([[x + 2.0, 5.0], [x + 2.0, 35.0]]), 4.0)
...           for p, x in zip(photos, (10, 25, 40, 50))]
>>> est = estimate_background(photos, covers)
>>> int(np.abs(est.astype(int) - scene).max())
0
"""

from __future__ import annotations

import warnings

import cv2
import numpy as np

from pipeline.measure.body import exposure_gains
from pipeline.measure.settings import MeasureSettings

#: a ramp of at least this many measured body photos gets its empty scene estimated
RAMP_BACKGROUND_MIN_PHOTOS = 8
#: a pixel's estimate is the median over the photos free of the body there when at least this
#: many are, else over all photos
MIN_FREE_PHOTOS = 3
#: a body covers its centre line to this many of its widths on either side (a faint side or tip
#: the first measurement missed lies within it), and this many beyond the line's ends
COVER_WIDTHS = 1.0
#: the estimate is taken over bands of rows holding about this many values of all the photos
BAND_VALUES = 4_000_000


def covered(shape: tuple[int, int], centreline_px: np.ndarray, width_px: float) -> np.ndarray:
    """Where a body with this centre line and width may lie (bool, ``shape``).

    Examples
    --------
    >>> c = covered((20, 30), np.array([[5.0, 10.0], [25.0, 10.0]]), 2.0)
    >>> bool(c[10, 15]), bool(c[10, 28]), bool(c[2, 15])
    (True, True, False)
    """
    mask = np.zeros(shape, np.uint8)
    pts = np.asarray(centreline_px, float)
    if len(pts) < 2 or not np.isfinite(pts).all() or not np.isfinite(width_px):
        return np.ones(shape, bool)  # unknown: the photo says nothing of the scene
    thick = max(1, round((1.0 + 2.0 * COVER_WIDTHS) * float(width_px)))
    line = np.round(pts).astype(np.int32)
    cv2.polylines(mask, [line], False, 1, thickness=thick)
    for end in (line[0], line[-1]):
        cv2.circle(mask, (int(end[0]), int(end[1])), thick, 1, -1)
    return mask > 0


def estimate_background(images: list[np.ndarray], covers: list[np.ndarray]) -> np.ndarray:
    """The empty scene (uint8, as ``images``): per pixel the median over the images whose body
    does not cover it (``covers``), over all of them where fewer than :data:`MIN_FREE_PHOTOS`
    are free there; each image first scaled to the images' median exposure, per colour channel
    (:func:`pipeline.measure.body.exposure_gains` over the pixels free of the body in it and in
    the first image)."""
    gains = np.stack(
        [exposure_gains(images[0], im, ~(covers[0] | c)) for im, c in zip(images, covers)]
    )
    gains /= np.median(gains, axis=0)
    h = images[0].shape[0]
    out = np.empty(images[0].shape, np.uint8)
    # a band of rows at a time: the working copies stay near BAND_VALUES floats whatever the
    # photos' number and size
    rows = max(1, BAND_VALUES // max(1, len(images) * images[0][0].size))
    for top in range(0, h, rows):
        band = np.stack([im[top : top + rows] for im in images]).astype(np.float32)
        band /= gains[:, None, None, :]
        cover = np.stack([c[top : top + rows] for c in covers])
        plain = np.median(band, axis=0)
        band[np.broadcast_to(cover[..., None], band.shape)] = np.nan
        with warnings.catch_warnings():  # all-NaN pixels are replaced by the plain median
            warnings.simplefilter("ignore", RuntimeWarning)
            masked = np.nanmedian(band, axis=0)
        free = (~cover).sum(axis=0)[..., None] >= MIN_FREE_PHOTOS
        out[top : top + rows] = np.clip(np.round(np.where(free, masked, plain)), 0, 255)
    return out


def estimates_background(settings: MeasureSettings | None) -> bool:
    """Whether a row's body may be measured again against its ramp's estimate of the empty
    scene: a body told from the backdrop (no colour) without a photo of the empty scene, whose
    free end is known (``sealed_end_mm`` given, or ``free_end: bends``).  A tip seen whole
    against the estimate but read over its sealed end swung (up to 16 deg on rendered
    translucent ramps), so without that length the backdrop alone decides, as before.
    """
    return (
        settings is not None
        and settings.target == "body"
        and settings.color is None
        and settings.background_path is None
        and (settings.sealed_end_mm is not None or settings.free_end == "bends")
    )
