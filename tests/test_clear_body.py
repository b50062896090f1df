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


#: the inside of the clear body: the backdrop seen through it times these (B, G, R) plus those
BLUE_TINT = ((1.01, 0.99, 0.965), (3.0, 0.0, -2.0))


def clear_photo(psi_deg: float | None, *, seed: int, length: float = LENGTH_PX,
                width: float = 60.0, tint: tuple[tuple[float, float, float],
                                                   tuple[float, float, float]] = BLUE_TINT,
                noise: float = 2.5) -> np.ndarray:
    """The scene (``psi_deg`` None: the empty scene): a body of constant curvature leaving the
    plate to the right, then a straight sealed end; its inside the backdrop tinted (``tint``;
    by default blue, -3.5 % red), bright bands (+55 grey levels) just inside its outline and a
    darker rim on it; each photo its own sensor noise (sigma ``noise`` grey levels, a slight
    blur and JPEG at quality 85, as a camera gives it)."""
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
        body = img * np.array(tint[0], np.float32) + np.array(tint[1], np.float32)
        body += (55.0 * np.exp(-(((depth - 4.0) / 1.8) ** 2)))[..., None]
        body -= (12.0 * np.exp(-(((depth - 1.0) / 1.0) ** 2)))[..., None]
        img = np.where(inside[..., None] > 0, body, img)
    x0, y0, x1, y1 = PLATE
    img[y0:y1, x0:x1] = 25.0
    img = img + np.random.default_rng(seed).normal(0, noise, img.shape)
    img = cv2.GaussianBlur(np.clip(img, 0, 255).astype(np.uint8), (0, 0), 0.6)
    return cv2.imdecode(cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 85])[1], 1)


def _measured_ramp(folder, ramp_set_writer, empty_scene: bool, **scene):
    """The ramp (and its empty scene) photographed with ``scene``'s clear_photo arguments,
    measured as a user measures it, with each row's error against its psi."""
    x0, y0, x1, y1 = PLATE
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "fixed_direction_deg: 0", "sealed_end_mm: 10", f"mm_per_px: {100 / LENGTH_PX}",
                f"exclude: [[{x0 - 2}, {y0 - 2}, {x1}, {y1 + 2}]]"]
    folder = ramp_set_writer(
        folder, [clear_photo(psi, seed=i, **scene) for i, psi in enumerate(PSI)], settings,
        clear_photo(None, seed=99, **scene) if empty_scene else None,
    )
    angles = measure_photoset(folder)
    return angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())


#: customer 36's clear body on grey card, 12 MP reduced to a quarter for the work (its noise
#: averaged away): 2.3-2.6 noise sigmas inside, under the 3 a clear body's inside had to differ,
#: so it was read as its rims (7 candidate bodies, none ok); here 2 grey levels over the
#: backdrop with a sensor noise of 1 (before: 0 ok, 1 within 5 deg)
FAINT_INSIDE = {"tint": ((1.0, 1.0, 1.0), (2.0, 2.0, 2.0)), "noise": 1.0}


@pytest.mark.parametrize(
    ("empty_scene", "scene"), [(True, {}), (False, {}), (True, FAINT_INSIDE)],
    ids=["empty-scene", "backdrop-only", "inside-two-grey-levels-off"],
)
def test_a_clear_body_is_measured_between_its_bright_edges(tmp_path, ramp_set_writer,
                                                            empty_scene, scene):
    angles = _measured_ramp(tmp_path / "clear", ramp_set_writer, empty_scene, **scene)
    ok = angles["status"] == "ok"
    shown = angles[["image", "psi_deg", "error_deg", "status", "reason"]]
    assert not (ok & (angles["error_deg"] > 5.0)).any(), shown
    assert ok.sum() >= 9, shown
    assert angles.loc[ok, "error_deg"].median() < 2.0, shown


def test_a_clear_body_whose_inside_is_the_backdrop_is_flagged_as_seen_by_its_rims(
    tmp_path, ramp_set_writer
):
    # its inside the backdrop exactly: nothing tells it from the backdrop a curled body
    # encloses, so it stays its outline; each row says so and how to photograph it, where it
    # said "7 candidate bodies ... another object in view, such as a ruler"
    angles = _measured_ramp(tmp_path / "same", ramp_set_writer, True,
                            tint=((1.0, 1.0, 1.0), (0.0, 0.0, 0.0)), noise=1.0)
    shown = angles[["image", "psi_deg", "status", "reason"]]
    assert (angles["status"] == "flagged").all(), shown
    rims = angles["reason"].str.contains("the selection is the outline of a long region",
                                         regex=False)
    assert rims.sum() >= 9, shown
    assert not angles.loc[rims, "reason"].str.contains("candidate bodies", regex=False).any()


def _hairpin(inside_diff: float):
    """A clear body bent into a hairpin by a clamp plate (x < 40): its outline (7 px rims), and
    the difference from the empty scene (noise, its inside ``inside_diff`` more)."""
    from pipeline.measure.body import fill_outlined

    noise = np.abs(np.random.default_rng(0).normal(0.0, 1.0, (300, 400))).astype(np.float32)
    allowed = np.ones((300, 400), np.uint8)
    allowed[:, :40] = 0
    body = np.zeros((300, 400), np.uint8)
    body[60:220, 38:370] = 1
    body[100:180, :330] = 0  # the pocket of backdrop between its arms, closed by the plate
    rim = body - cv2.erode(body, np.ones((7, 7), np.uint8))
    rim[:, :40] = body[:, :40]
    diff = noise + inside_diff * ((body > 0) & (rim == 0))
    return fill_outlined(rim, diff, allowed, 3.0)


@pytest.mark.parametrize("inside_diff", [5.0, 2.2], ids=["clear-inside", "faint-inside"])
def test_a_clear_hairpins_inside_is_taken_in_and_the_pocket_it_closes_is_not_called_hollow(
    inside_diff,
):
    # from the review: the pocket of backdrop between a hairpin's arms, larger than its rims,
    # was reported as a hollow outline although the inside was taken in (the row flagged "a
    # clear body seen only by its rims"); and the faint inside (2.2 sigmas) was measured
    # against a backdrop sample that held the inside itself, and never taken in
    filled, hollow_width = _hairpin(inside_diff)
    assert filled[80, 200] and filled[200, 200]  # both arms' insides
    assert not filled[140, 200]  # the pocket
    assert hollow_width == 0.0


def test_a_faint_clear_body_is_taken_in_with_another_object_in_view():
    # from the review: the region had to be larger than the whole photo's selection, so a
    # ruler or a second object in view turned the fill of a faint inside off; it is now
    # weighed against its own walls (before: not taken in)
    from pipeline.measure.body import fill_outlined

    noise = np.abs(np.random.default_rng(0).normal(0.0, 1.0, (500, 520))).astype(np.float32)
    allowed = np.ones((500, 520), np.uint8)
    allowed[:, :40] = 0
    body = np.zeros((500, 520), np.uint8)
    body[60:100, 38:440] = 1
    rim = body - cv2.erode(body, np.ones((7, 7), np.uint8))
    rim[:, :40] = body[:, :40]
    diff = noise + 2.2 * ((body > 0) & (rim == 0))
    rim[300:400, 100:300] = 1  # an opaque object, larger than the body's inside
    diff[300:400, 100:300] = 20.0
    filled, hollow_width = fill_outlined(rim, diff, allowed, 3.0)
    assert filled[80, 200] and hollow_width == 0.0
