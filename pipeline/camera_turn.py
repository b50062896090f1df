"""How far the camera turned between the photos of a ramp (a phone held by hand).

A body's psi is its free end's direction less the direction in which it leaves the clamp; the
ramp check measures every body of a ramp from the ramp's one base direction
(:func:`pipeline.ramp_check.share_base_direction`), and a ``fixed_direction_deg`` is one
direction for every photo.  Both hold on screen only while the camera stands still.  Turned by a
hand by up to 3 deg between photos, every psi was off by its photo's turn (customer 34: 14 rows
``ok`` 5-7 deg off).  Each photo is registered to its ramp's first photo (OpenCV's ECC, a
rotation and a shift, on a reduced grey copy, the bodies of both left out), and the turn is the
rotation of the scene on screen: a direction of the first photo is that much further
counter-clockwise in this one.

Examples
--------
>>> rng = np.random.default_rng(0)
>>> scene = cv2.GaussianBlur((rng.random((240, 320)) * 255).astype(np.float32), (0, 0), 3)
>>> turned = cv2.warpAffine(scene, cv2.getRotationMatrix2D((160, 120), 2.0, 1.0), (320, 240),
...                         borderMode=cv2.BORDER_REFLECT)
>>> round(scene_turn_deg(scene, turned, np.ones(scene.shape, np.uint8)), 2)
2.0
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from pipeline.measure.core import decode_for_work

#: photos are registered at about this width (px): a turn of 0.05 deg moves their corners by
#: a fifth of a pixel
REGISTER_WIDTH_PX = 640
#: a ramp whose photos all turned less than this (deg) stood still (a tripod): nothing changes
TURN_MIN_DEG = 0.3
#: a registration whose correlation is below this did not find the scene again: no turn is taken
MIN_CORRELATION = 0.8
#: each body is left out of the registration over this many of its widths (its shadow beside it)
BODY_MARGIN_WIDTHS = 2.0
#: a photo of which less than this share is left (the two bodies cover the rest) is not registered
MIN_SCENE_SHARE = 0.1
#: ECC stops after this many iterations or once a step changes the warp by less than this
ECC_ITERATIONS, ECC_EPS = 50, 1e-4
#: ... first on the photos reduced by this factor
COARSE = 4


def scene_turn_deg(
    reference: np.ndarray, photo: np.ndarray, mask: np.ndarray, *, fine: bool = True
) -> float:
    """The rotation of ``photo``'s scene against ``reference`` (float32 grey images of one
    size), counter-clockwise on screen in deg, over the pixels where ``mask`` is set; NaN where
    the registration fails or (``fine``) correlates less than :data:`MIN_CORRELATION`.
    Registered at a quarter of the size first (a turn of 4.7 deg with a 26 px shift did not
    converge within :data:`ECC_ITERATIONS` at full size), then, when ``fine``, at full size
    from there; without, the quarter size's rough turn (a tenth of the time)."""
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, ECC_ITERATIONS, ECC_EPS)
    warp: np.ndarray = np.eye(2, 3, dtype=np.float32)
    h, w = reference.shape
    small = (max(8, w // COARSE), max(8, h // COARSE))
    levels = [
        (cv2.resize(reference, small, interpolation=cv2.INTER_AREA),
         cv2.resize(photo, small, interpolation=cv2.INTER_AREA),
         cv2.resize(mask, small, interpolation=cv2.INTER_NEAREST), w / small[0]),
        (reference, photo, mask, 1.0),
    ][: 2 if fine else 1]
    correlation = 0.0
    for ref, img, keep, factor in levels:
        warp[:, 2] /= factor
        try:
            correlation, warp = cv2.findTransformECC(
                ref, img, warp, cv2.MOTION_EUCLIDEAN, criteria, keep, 5 if factor == 1 else 3
            )
        except cv2.error:
            return float("nan")
        warp[:, 2] *= factor
    if fine and not correlation >= MIN_CORRELATION:
        return float("nan")
    # the warp maps the reference onto the photo; y points down on screen
    return float(-np.degrees(np.arctan2(warp[1, 0], warp[0, 0])))


def _reduced(path: str) -> tuple[np.ndarray | None, int]:
    """The photo as ``measure`` reads it (:func:`decode_for_work`), grey, float32, and the factor
    it was reduced by."""
    img, factor = decode_for_work(np.fromfile(path, np.uint8), grey=True)
    if img is None:
        return None, factor
    return img.astype(np.float32), factor


@dataclass(frozen=True)
class RampPhotos:
    """The photos of one ramp in the order taken, and each one's measured body in its own
    pixels (a None centre line or a NaN width where none was found)."""

    paths: tuple[str, ...]
    centrelines_px: tuple[np.ndarray | None, ...]
    widths_px: tuple[float, ...]


def ramp_turns(ramp: RampPhotos) -> np.ndarray:
    """Each photo's scene turn against the first (deg, counter-clockwise on screen; 0 for the
    first; NaN where unknown), all 0 when none reaches :data:`TURN_MIN_DEG`.  Each photo's body
    and the first photo's are left out of the registration.  Each photo is first registered
    roughly (:func:`scene_turn_deg` without ``fine``); only when one of them turned by half of
    :data:`TURN_MIN_DEG` or more are they all registered in full (on rendered still ramps the
    full registration took a quarter of the measurement's time)."""
    paths, centrelines_px, widths_px = ramp.paths, ramp.centrelines_px, ramp.widths_px
    first, first_factor = _reduced(paths[0])
    turns = np.full(len(paths), np.nan)
    if first is None:
        return turns
    turns[0] = 0.0

    def body(i: int, factor: int, shape: tuple[int, ...]) -> np.ndarray:
        size = (shape[0], shape[1])
        line = centrelines_px[i]
        if line is None or not np.isfinite(widths_px[i]):
            return np.ones(size, bool)  # unknown: the whole photo may be the body
        line = (np.asarray(line, float).reshape(-1, 2) - (factor - 1) / 2) / factor
        mask = np.zeros(size, np.uint8)
        thick = max(3, round(BODY_MARGIN_WIDTHS * float(widths_px[i]) / factor))
        cv2.polylines(mask, [np.round(line).astype(np.int32)], False, 1, thickness=thick)
        return mask > 0

    scale = min(1.0, REGISTER_WIDTH_PX / first.shape[1])
    small = (round(first.shape[1] * scale), round(first.shape[0] * scale))
    ref = cv2.resize(first, small, interpolation=cv2.INTER_AREA)
    ref_body = cv2.resize(body(0, first_factor, first.shape).astype(np.uint8), small)
    for fine in (False, True):
        for i in range(1, len(paths)):
            img, factor = _reduced(paths[i])
            if img is None or img.shape != first.shape:
                continue
            mine = cv2.resize(body(i, factor, img.shape).astype(np.uint8), small)
            keep = ((ref_body == 0) & (mine == 0)).astype(np.uint8)
            if keep.mean() < MIN_SCENE_SHARE:
                continue
            photo = cv2.resize(img, small, interpolation=cv2.INTER_AREA)
            turns[i] = scene_turn_deg(ref, photo, keep, fine=fine)
        if not fine and not (np.abs(turns[np.isfinite(turns)]) >= TURN_MIN_DEG / 2).any():
            return np.where(np.isfinite(turns), 0.0, np.nan)  # a camera that stood still
    if not (np.abs(turns[np.isfinite(turns)]) >= TURN_MIN_DEG).any():
        return np.where(np.isfinite(turns), 0.0, np.nan)
    return turns
