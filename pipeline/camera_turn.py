"""How far the camera turned between the photos of a ramp (a phone held by hand).

A body's psi is its free end's direction less the direction in which it leaves the clamp; the
ramp check measures every body of a ramp from the ramp's one base direction
(:func:`pipeline.ramp_check.share_base_direction`), and a ``fixed_direction_deg`` is one
direction for every photo.  Both hold on screen only while the camera stands still.  Turned by a
hand by up to 3 deg between photos, every psi was off by its photo's turn (customer 34: 14 rows
``ok`` 5-7 deg off).  Each photo is registered to its ramp's first photo (OpenCV's ECC, a
rotation and a shift, on a reduced grey copy, every body of the ramp and the ``exclude`` regions
away from the clamp left out: :func:`ramp_turns`), and the turn is the rotation of the scene on
screen: a direction of the first photo is that much further counter-clockwise in this one.

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
from pipeline.measure.extract import region_mask
from pipeline.measure.settings import Polygon

#: photos are registered at about this width (px): a turn of 0.05 deg moves their corners by
#: a fifth of a pixel
REGISTER_WIDTH_PX = 640
#: a ramp fewer of whose photos than MIN_TURNED_SHARE turned by this (deg) stood still (a
#: tripod): nothing changes.  A phone held by hand turns by 1-3 deg; a still camera's photos
#: read up to 0.7 where a tube swayed with the pressure (the review)
TURN_MIN_DEG = 1.0
#: a registration whose correlation is below this did not find the scene again: no turn is taken
MIN_CORRELATION = 0.8
#: each body is left out of the registration over this many of its widths (its shadow beside it)
BODY_MARGIN_WIDTHS = 2.0
#: a ramp whose bodies (and exclude) leave less than this share of the photo is not registered
MIN_SCENE_SHARE = 0.1
#: the bodies are left out over this share of the photo's width more (the camera moved them)
MOTION_MARGIN = 0.02
#: an exclude region this near the fixed end (a share of the diagonal) covers the clamp
CLAMP_REACH = 0.05
#: the camera turned when at least this share of a ramp's photos (and two) turned
MIN_TURNED_SHARE = 0.25
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
    """The photos of one ramp in the order taken, each one's measured body in its own pixels (a
    None centre line or a NaN width where none was found), and the set's ``exclude`` regions and
    ``fixed_end`` (original pixels)."""

    paths: tuple[str, ...]
    centrelines_px: tuple[np.ndarray | None, ...]
    widths_px: tuple[float, ...]
    exclude: tuple[Polygon, ...] = ()
    fixed_end_px: tuple[float, float] | None = None


def _loose_parts(
    ramp: RampPhotos, shape: tuple[int, ...], factor: int, small: tuple[int, int]
) -> np.ndarray:
    """The ``exclude`` regions that reach no nearer the fixed end than :data:`CLAMP_REACH` of the
    photo's diagonal, 0/1 at ``small``: a supply tube, which sways with the pressure (swaying
    10-20 px at a still camera's edge it read turns of 0.3-1.4 deg), or a ruler; a region over
    the clamp stays in, the steadiest part of the scene (without it a plate's mottled backdrop
    could not be lined up)."""
    loose = np.zeros((small[1], small[0]), np.uint8)
    for polygon in ramp.exclude:
        inside = region_mask(shape, None, (polygon,), float(factor))
        assert inside is not None
        part = (1 - inside).astype(np.uint8)
        if ramp.fixed_end_px is not None:
            fx, fy = ((v - (factor - 1) / 2) / factor for v in ramp.fixed_end_px)
            x = int(np.clip(round(fx), 0, shape[1] - 1))
            y = int(np.clip(round(fy), 0, shape[0] - 1))
            gap = float(cv2.distanceTransform(1 - part, cv2.DIST_L2, 3)[y, x])
            if gap <= CLAMP_REACH * float(np.hypot(shape[0], shape[1])):
                continue
        loose = np.maximum(loose, cv2.resize(part, small, interpolation=cv2.INTER_NEAREST))
    return loose


def ramp_turns(ramp: RampPhotos) -> np.ndarray:
    """Each photo's scene turn against the ramp's first photo with a body found (deg,
    counter-clockwise on screen; NaN where unknown), all 0 unless the camera turned.

    What is lined up is the scene without any of the ramp's bodies (each over
    :data:`BODY_MARGIN_WIDTHS` of its width, and :data:`MOTION_MARGIN` of the photo's width
    more, as the camera moves: with only the two photos' bodies left out, a body's shadow read
    a still camera's turn as 0.7 deg) and without the ``exclude`` regions away from the fixed
    end (:func:`_loose_parts`).  Each photo is registered roughly first
    (:func:`scene_turn_deg` without ``fine``); only when at least :data:`MIN_TURNED_SHARE` of
    them (and two) turned by half of :data:`TURN_MIN_DEG` are they registered in full, and the
    turns are kept only when as many reach :data:`TURN_MIN_DEG`: a tube that sways with the
    pressure read a still camera's turn as 0.3-1.4 deg (on rendered still ramps the full
    registration took a quarter of the measurement's time).
    """
    n = len(ramp.paths)
    turns = np.full(n, np.nan)
    found = [
        c is not None and np.isfinite(w) for c, w in zip(ramp.centrelines_px, ramp.widths_px,
                                                         strict=True)
    ]
    images: list[np.ndarray | None] = []
    bodies: list[np.ndarray | None] = []
    small: tuple[int, int] | None = None
    shape: tuple[int, ...] | None = None
    shape_factor = 1
    for i, path in enumerate(ramp.paths):
        img, factor = _reduced(path)
        if img is None or (shape is not None and img.shape != shape) or (
            shape is None and not found[i]
        ):
            images.append(None)
            bodies.append(None)
            continue
        if shape is None:
            shape, shape_factor = img.shape, factor
            scale = min(1.0, REGISTER_WIDTH_PX / img.shape[1])
            small = (round(img.shape[1] * scale), round(img.shape[0] * scale))
        assert small is not None
        images.append(cv2.resize(img, small, interpolation=cv2.INTER_AREA))
        body = None
        if found[i]:
            line = (np.asarray(ramp.centrelines_px[i], float).reshape(-1, 2) - (factor - 1) / 2)
            mask = np.zeros(img.shape[:2], np.uint8)
            thick = max(3, round(BODY_MARGIN_WIDTHS * float(ramp.widths_px[i]) / factor))
            cv2.polylines(mask, [np.round(line / factor).astype(np.int32)], False, 1,
                          thickness=thick)
            body = cv2.resize(mask, small, interpolation=cv2.INTER_NEAREST)
        bodies.append(body)
    reference = next((i for i in range(n) if images[i] is not None and found[i]), None)
    if reference is None or small is None:
        return turns
    assert shape is not None
    union = _loose_parts(ramp, shape, shape_factor, small)  # the same in every photo of a size
    for body in bodies:
        if body is not None:
            union = np.maximum(union, body)
    margin = max(3, round(MOTION_MARGIN * small[0])) | 1
    disc = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (margin, margin))
    keep = (1 - cv2.dilate(union, disc)).astype(np.uint8)
    if keep.mean() < MIN_SCENE_SHARE:
        return turns
    ref = images[reference]
    assert ref is not None
    turns[reference] = 0.0
    others = [i for i in range(n) if i != reference and images[i] is not None]
    least = max(2, MIN_TURNED_SHARE * len(others))
    for fine, threshold in ((False, TURN_MIN_DEG / 2), (True, TURN_MIN_DEG)):
        for i in others:
            photo = images[i]
            assert photo is not None
            turns[i] = scene_turn_deg(ref, photo, keep, fine=fine)
        if (np.abs(turns[others]) >= threshold).sum() < least:  # a camera that stood still
            return np.where(np.isfinite(turns), 0.0, np.nan)
    return turns
