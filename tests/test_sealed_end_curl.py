"""A body that curls tightest at its tip, then a straight sealed end (customer 36).  The smooth
fit that checks a centre line for wobbles is made of the whole line, sealed end included, and
right readings near 200 deg disagree with it by 8-12 deg: flagged "the centre line wobbles"
(customer 36: 6 of 42 right photos).  Fitting only the part before the sealed end was tried:
those came out ``ok``, but so did this scene's psi 200, read 7.8 deg high (the curl's inner
side half a width across): this test keeps that from passing as ``ok``."""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from pipeline.measure import measure_image
from pipeline.measure.settings import resolve_settings

W, H = 1000, 800
FIXED_END = (300.0, 560.0)
LENGTH_PX, SEALED_PX, WIDTH_PX = 560.0, 60.0, 80.0
MM_PER_PX = 0.2


def curl_photo(psi_deg: float) -> np.ndarray:
    """An orange body on grey leaving a black plate to the right, its curvature growing from
    nothing at the plate to its most at the sealed end (the tangent angle psi (s/L)^2), then
    straight; noise and JPEG as a camera gives them."""
    s = np.linspace(0.0, LENGTH_PX + SEALED_PX, 800)
    th = np.deg2rad(psi_deg) * np.minimum(s / LENGTH_PX, 1.0) ** 2  # y up
    step = s[1] - s[0]
    c = np.c_[np.cumsum(np.cos(th)), np.cumsum(np.sin(th))] * step
    n = np.c_[-np.sin(th), np.cos(th)]
    outline = np.r_[c + n * WIDTH_PX / 2, (c - n * WIDTH_PX / 2)[::-1]]
    outline = np.c_[outline[:, 0], -outline[:, 1]] + FIXED_END
    img = np.full((H, W, 3), (118.0, 120.0, 122.0), np.float32)
    body = np.zeros((H, W), np.uint8)
    cv2.fillPoly(body, [np.round(outline * 8).astype(np.int32)], 1, cv2.LINE_8, 3)
    img[body > 0] = (60.0, 120.0, 200.0)
    img[480:640, 180:300] = 25.0  # the plate
    img += np.random.default_rng(int(psi_deg)).normal(0.0, 2.0, img.shape)
    img = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (0, 0), 0.7)
    return cv2.imdecode(cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 90])[1], 1)


@pytest.mark.parametrize("psi_deg", [150.0, 180.0, 200.0, 215.0])
def test_a_curl_tightest_at_the_sealed_end_is_never_an_ok_wrong_psi(psi_deg):
    settings = resolve_settings(
        {"l0_mm": LENGTH_PX * MM_PER_PX, "target": "body", "fixed_end": list(FIXED_END),
         "mm_per_px": MM_PER_PX, "sealed_end_mm": SEALED_PX * MM_PER_PX,
         "exclude": [[170, 470, 298, 650]]}
    )
    res = measure_image(curl_photo(psi_deg), settings)
    assert res.psi_deg == pytest.approx(psi_deg, abs=10.0), res.reason
    if abs(res.psi_deg - psi_deg) > 5.0:
        assert res.status == "flagged", res.reason
