"""A coloured body on white paper under a soft lamp, without a photo of the empty scene
(customer 34): the shadows it, the clamp block and the tube cast are wide and soft, and more of
the photo differs from the paper as shadow than as body.  Leaving them out was then refused (it
lost more than half of the selection), the shadow was selected with the body and widened it on
one side: 12 of 100 ``ok`` rows read 5-14 deg off, here every photo flagged, up to 41 deg off."""

from __future__ import annotations

import cv2
import numpy as np

from pipeline.photoset_measure import measure_photoset

W, H = 800, 600
FIXED_END = (260.0, 330.0)
BLOCK = (200, 290, 260, 370)  # x0, y0, x1, y1: the white clamp block the body leaves
TUBE = np.array([[200, 330], [150, 340], [60, 400], [0, 470]], np.int32)
PSI = (0.0, 20.0, 45.0, 75.0, 110.0, 150.0, 190.0, 150.0, 100.0, 40.0, 0.0)
PAPER, GREEN_CLOTH = (236.0, 240.0, 244.0), (48.0, 118.0, 38.0)  # BGR
BLUE, GREY = (190.0, 100.0, 40.0), (160.0, 160.0, 160.0)
#: the bending length (l0, 100 mm) and the straight sealed end past it (10 mm), px
LENGTH_PX, SEALED_PX = 380.0, 38.0


def body_outline(psi_deg: float, width: float = 60.0) -> np.ndarray:
    """Outline (N, 2 px, y down) of a body of constant curvature leaving the block to the right,
    then a straight sealed end."""
    s = np.linspace(0.0, LENGTH_PX + SEALED_PX, 300)
    th = np.deg2rad(psi_deg) / LENGTH_PX * np.minimum(s, LENGTH_PX)  # y up
    c = np.c_[np.cumsum(np.cos(th)), np.cumsum(np.sin(th))] * (s[1] - s[0])
    n = np.c_[-np.sin(th), np.cos(th)]
    outline = np.r_[c + n * width / 2, (c - n * width / 2)[::-1]]
    return np.c_[outline[:, 0], -outline[:, 1]] + FIXED_END


def soft_shadow_photo(
    psi_deg: float | None, *, seed: int, backdrop_bgr: tuple[float, float, float] = PAPER,
    noise: float = 2.0, body_bgr: tuple[float, float, float] = BLUE,
    tube_bgr: tuple[float, float, float] = (200.0, 202.0, 204.0),
) -> np.ndarray:
    """The scene (``psi_deg`` None: the empty scene): a backdrop (mottled), a blue body shaded
    across its width, a white block and a grey tube; everything casts a shadow 12 px down and
    right, blurred by 20 px, a third dark; each photo its own sensor noise (sigma ``noise``), a
    slight blur and JPEG at quality 88."""
    mottle = np.random.default_rng(5).normal(0.0, 1.0, (9, 12)).astype(np.float32)
    mottle = cv2.resize(mottle, (W, H), interpolation=cv2.INTER_CUBIC)
    img = np.ones((H, W, 1), np.float32) * backdrop_bgr + 1.5 * mottle[..., None]
    x0, y0, x1, y1 = BLOCK
    body = np.zeros((H, W), np.uint8)
    if psi_deg is not None:
        outline = np.round(body_outline(psi_deg) * 8).astype(np.int32)
        cv2.fillPoly(body, [outline], 1, cv2.LINE_8, 3)
    tube = cv2.polylines(np.zeros((H, W), np.uint8), [TUBE], False, 1, 16)
    casts = np.maximum(body, tube).astype(np.float32)
    casts[y0:y1, x0:x1] = 1.0
    moved = cv2.warpAffine(casts, np.float32([[1, 0, 12], [0, 1, 12]]), (W, H))
    img *= (1.0 - 0.35 * cv2.GaussianBlur(moved, (0, 0), 20.0))[..., None]
    img[tube > 0] = tube_bgr
    img[y0:y1, x0:x1] = (245, 246, 247)
    depth = cv2.distanceTransform(body, cv2.DIST_L2, 5)
    shaded = np.float32(body_bgr) * (0.8 + 0.2 * np.minimum(depth / 15.0, 1.0))[..., None]
    img = np.where(body[..., None] > 0, shaded, img)
    img = img + np.random.default_rng(seed).normal(0, noise, img.shape)
    img = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (0, 0), 0.6)
    return cv2.imdecode(cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 88])[1], 1)


def test_a_soft_shadow_wider_than_the_body_is_left_out_without_an_empty_scene(
    tmp_path, ramp_set_writer
):
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}",
                "exclude: [[0, 280, 258, 600]]"]  # the block and the tube, not their shadows
    folder = ramp_set_writer(
        tmp_path / "shadow", [soft_shadow_photo(psi, seed=i) for i, psi in enumerate(PSI)],
        settings,
    )
    angles = measure_photoset(folder)
    angles = angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())
    ok = angles["status"] == "ok"
    shown = angles[["image", "psi_deg", "error_deg", "width_px", "status", "reason"]]
    assert not (ok & (angles["error_deg"] > 5.0)).any(), shown
    assert ok.sum() >= 10, shown
    assert angles["error_deg"].max() < 2.0, shown
    # the body's own width (60 px), not widened by its shadow (104 px)
    assert angles["width_px"].between(56.0, 66.0).all(), shown


def test_the_shadow_on_a_dark_backdrop_is_left_out_against_its_empty_scene(
    tmp_path, ramp_set_writer
):
    # customer 35's green cloth, its empty scene given: on a dark backdrop each channel's noise
    # moves the three ratios of a shadowed pixel apart, and a speckle of the shadow was taken
    # for body, widening it on its shadow side (its centre line in the lower half: 104 of 2100
    # video frames ok 5-20 deg off)
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}"]
    photos = [soft_shadow_photo(psi, seed=i, backdrop_bgr=GREEN_CLOTH, noise=4.0)
              for i, psi in enumerate(PSI)]
    empty = soft_shadow_photo(None, seed=99, backdrop_bgr=GREEN_CLOTH, noise=4.0)
    angles = measure_photoset(ramp_set_writer(tmp_path / "cloth", photos, settings, empty))
    angles = angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())
    shown = angles[["image", "psi_deg", "error_deg", "width_px", "status", "reason"]]
    assert (angles["status"] == "ok").sum() >= 10, shown  # 5 (6 flagged, up to 4 deg off)
    assert angles["error_deg"].max() < 3.5, shown
    assert angles["width_px"].between(56.0, 68.0).all(), shown


def test_a_grey_body_beside_a_blue_tube_is_not_taken_for_shadow(tmp_path, ramp_set_writer):
    # review: a grey body on white paper looks like a shadow all over; a blue tube in view passed
    # the colour test, and with no share of the selection kept the body was left out and the tube
    # measured (psi ~36 deg for every photo).  Left out of the exclude region here
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}"]
    photos = [soft_shadow_photo(psi, seed=i, body_bgr=GREY, tube_bgr=BLUE)
              for i, psi in enumerate(PSI)]
    angles = measure_photoset(ramp_set_writer(tmp_path / "grey", photos, settings))
    angles = angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())
    shown = angles[["image", "psi_deg", "error_deg", "width_px", "status", "reason"]]
    assert not ((angles["status"] == "ok") & (angles["error_deg"] > 5.0)).any(), shown
    # the body is measured, not the tube (16 px wide): with its shadow (about 100 px), flagged,
    # as before; an empty scene is the fix for a neutral body
    assert (angles["width_px"] > 40.0).all(), shown
