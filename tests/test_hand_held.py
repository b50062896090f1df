"""Photos from a phone held by hand (customer 34): between photos the camera turns by up to 3 deg
and shifts by up to 15 px.  The ramp check measured every body from the ramp's one base direction
and a ``fixed_direction_deg`` is one on-screen direction, so every psi was off by its photo's
turn (14 of 100 rows ``ok`` 5-7 deg off).  Measured as a user measures it (the real pipeline)."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from pipeline.photoset_measure import measure_photoset

W, H = 800, 600
FIXED_END = (260.0, 330.0)
PSI = (0.0, 20.0, 45.0, 75.0, 110.0, 150.0, 190.0, 150.0, 100.0, 40.0, 0.0)
#: the bending length (l0, 100 mm) and the straight sealed end past it (10 mm), px
LENGTH_PX, SEALED_PX = 380.0, 38.0
#: each photo's camera: the scene's turn on screen (deg, counter-clockwise) and shift (px)
POSES = [(float(t), float(x), float(y)) for t, x, y in np.random.default_rng(7).uniform(
    [-3.0, -15.0, -15.0], [3.0, 15.0, 15.0], (len(PSI), 3))]


def hand_held_photo(
    psi_deg: float, pose: tuple[float, float, float], seed: int, tube_sway_px: float = 0.0
) -> np.ndarray:
    """A blue body of constant curvature leaving a dark clamp plate to the right on a mottled
    grey backdrop, its supply tube leaving the plate to the left (swaying by ``tube_sway_px``),
    seen by a camera turned and shifted by ``pose``."""
    mottle = np.random.default_rng(5).normal(0.0, 1.0, (12, 16)).astype(np.float32)
    mottle = cv2.resize(mottle, (W, H), interpolation=cv2.INTER_CUBIC)
    img = np.full((H, W, 3), 150.0, np.float32) + 5.0 * mottle[..., None]
    img[230:430, 140:260] = 30.0
    for x, y in ((170, 260), (230, 260), (170, 400), (230, 400)):
        cv2.circle(img, (x, y), 9, (90.0, 90.0, 90.0), -1)
    cv2.line(img, (0, round(300 + tube_sway_px)), (140, 330), (235.0, 235.0, 235.0), 14)
    length, width = LENGTH_PX, 50.0
    s = np.linspace(0.0, length + SEALED_PX, 300)
    th = np.deg2rad(psi_deg) / length * np.minimum(s, length)  # y up: bends, then a sealed end
    c = np.c_[np.cumsum(np.cos(th)), np.cumsum(np.sin(th))] * (s[1] - s[0])
    n = np.c_[-np.sin(th), np.cos(th)]
    outline = np.r_[c + n * width / 2, (c - n * width / 2)[::-1]]
    outline = np.c_[outline[:, 0], -outline[:, 1]] + FIXED_END
    cv2.fillPoly(img, [np.round(outline * 8).astype(np.int32)], (170.0, 95.0, 40.0),
                 cv2.LINE_AA, 3)
    turn, dx, dy = pose
    camera = cv2.getRotationMatrix2D((W / 2, H / 2), turn, 1.0)
    camera[:, 2] += (dx, dy)
    img = cv2.warpAffine(img, camera, (W, H), borderMode=cv2.BORDER_REFLECT)
    img += np.random.default_rng(seed).normal(0, 2.0, img.shape)
    return np.clip(img, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("direction_given", [False, True], ids=["ramp-base", "direction-given"])
def test_photos_from_a_turning_camera_are_lined_up_with_the_ramps_first(
    tmp_path, ramp_set_writer, direction_given
):
    photos = [hand_held_photo(psi, pose, seed=i)
              for i, (psi, pose) in enumerate(zip(PSI, POSES, strict=True))]
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}",
                "exclude: [[130, 220, 258, 440], [0, 270, 140, 350]]"]
    if direction_given:  # read off the first photo, as a user does
        settings.append(f"fixed_direction_deg: {POSES[0][0]:.2f}")
    angles = measure_photoset(ramp_set_writer(tmp_path / "set", photos, settings))
    turns = np.array([t for t, _, _ in POSES]) - POSES[0][0]
    shown = angles[["image", "psi_deg", "camera_turn_deg", "status", "reason"]]
    np.testing.assert_allclose(angles["camera_turn_deg"], turns, atol=0.2)
    error = (angles["psi_deg"] - np.array(PSI)).abs()
    assert (angles["status"] == "ok").sum() >= 9, shown
    # the ramp's own base reads about a degree off here (the clamp's face); the direction given
    # is exact: before, each psi was off by its photo's turn against the ramp's median (up to 4)
    limit = 1.0 if direction_given else 2.0
    assert error[angles["status"] == "ok"].max() < limit, shown.assign(error=error)


def test_a_still_camera_reads_no_turn_though_the_tube_sways(tmp_path, ramp_set_writer):
    # the review: a tube swaying 10 px under an exclude box at the photo's edge read turns of
    # 0.3-0.7 deg and moved every psi of a tripod's ramp
    still = (0.0, 0.0, 0.0)
    photos = [hand_held_photo(psi, still, seed=i, tube_sway_px=10.0 * (-1) ** i)
              for i, psi in enumerate(PSI)]
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}",
                "exclude: [[130, 220, 258, 440], [0, 270, 140, 350]]"]
    angles = measure_photoset(ramp_set_writer(tmp_path / "set", photos, settings))
    assert (angles["camera_turn_deg"] == 0.0).all(), angles["camera_turn_deg"].tolist()
