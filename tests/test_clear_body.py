"""A clear silicone body on a backdrop of its own grey (customer 33): its edges refract the light
and show brightly, its inside is the backdrop seen through it, a few levels darker and a little
blue.  The selection was its two edges, read as two bodies; with or without a photo of the empty
scene hardly a photo was ``ok`` (0 and 4 of 68).  Measured as a user measures it (the real
pipeline), with the clamp plate under ``exclude``."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from pipeline.photoset_measure import measure_photoset

W, H = 800, 600
FIXED_END = (260.0, 330.0)
PLATE = (140, 230, 260, 430)  # x0, y0, x1, y1: a black clamp plate
#: a ramp up and back down, its psi (deg)
PSI = (0.0, 20.0, 45.0, 75.0, 110.0, 150.0, 190.0, 150.0, 100.0, 40.0, 0.0)
#: the bending length (l0, 100 mm) and the straight sealed end past it (10 mm), px
LENGTH_PX, SEALED_PX = 380.0, 38.0


def _backdrop() -> np.ndarray:
    """The grey backdrop (BGR float), lit from the top, with a soft mottle of its own."""
    mottle = np.random.default_rng(5).normal(0.0, 1.0, (9, 12)).astype(np.float32)
    mottle = cv2.resize(mottle, (W, H), interpolation=cv2.INTER_CUBIC)
    light = 1.08 - 0.16 * np.arange(H, dtype=np.float32)[:, None] / H
    grey = np.array([124.0, 127.0, 131.0], np.float32)
    return (light * np.ones((H, W), np.float32))[..., None] * grey + 2.0 * mottle[..., None]


def clear_photo(psi_deg: float | None, *, seed: int, length: float = LENGTH_PX,
                width: float = 60.0) -> np.ndarray:
    """The scene (``psi_deg`` None: the empty scene): a body of constant curvature leaving the
    plate to the right, then a straight sealed end; its inside the backdrop tinted blue (-3.5 %
    red), bright bands (+55 grey levels) just inside its outline and a darker rim on it; each
    photo its own sensor noise (sigma 2.5 grey levels, a slight blur and JPEG at quality 85, as
    a camera gives it)."""
    img = _backdrop()
    if psi_deg is not None:
        s = np.linspace(0.0, length + SEALED_PX, 300)
        th = np.deg2rad(psi_deg) / length * np.minimum(s, length)  # y up
        c = np.c_[np.cumsum(np.cos(th)), np.cumsum(np.sin(th))] * (s[1] - s[0])
        n = np.c_[-np.sin(th), np.cos(th)]
        outline = np.r_[c + n * width / 2, (c - n * width / 2)[::-1]]
        outline = np.c_[outline[:, 0], -outline[:, 1]] + FIXED_END
        inside = np.zeros((H, W), np.uint8)
        cv2.fillPoly(inside, [np.round(outline * 8).astype(np.int32)], 1, cv2.LINE_8, 3)
        depth = cv2.distanceTransform(inside, cv2.DIST_L2, 5)
        body = img * np.array([1.01, 0.99, 0.965], np.float32) + [3.0, 0.0, -2.0]
        body += (55.0 * np.exp(-(((depth - 4.0) / 1.8) ** 2)))[..., None]
        body -= (12.0 * np.exp(-(((depth - 1.0) / 1.0) ** 2)))[..., None]
        img = np.where(inside[..., None] > 0, body, img)
    x0, y0, x1, y1 = PLATE
    img[y0:y1, x0:x1] = 25.0
    img = img + np.random.default_rng(seed).normal(0, 2.5, img.shape)
    img = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (0, 0), 0.6)
    return cv2.imdecode(cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 85])[1], 1)


@pytest.mark.parametrize("empty_scene", [True, False], ids=["empty-scene", "backdrop-only"])
def test_a_clear_body_is_measured_between_its_bright_edges(tmp_path, ramp_set_writer, empty_scene):
    x0, y0, x1, y1 = PLATE
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "fixed_direction_deg: 0", "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}",
                f"exclude: [[{x0 - 2}, {y0 - 2}, {x1}, {y1 + 2}]]"]
    folder = ramp_set_writer(
        tmp_path / "clear", [clear_photo(psi, seed=i) for i, psi in enumerate(PSI)], settings,
        clear_photo(None, seed=99) if empty_scene else None,
    )
    angles = measure_photoset(folder)
    angles = angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())
    ok = angles["status"] == "ok"
    shown = angles[["image", "psi_deg", "error_deg", "status", "reason"]]
    assert not (ok & (angles["error_deg"] > 5.0)).any(), shown
    assert ok.sum() >= 9, shown
    assert angles.loc[ok, "error_deg"].median() < 2.0, shown
