"""A body with a faint side near its clamp (customer 31): a white body hanging on grey, lit from
one side, its shaded side barely brighter than the backdrop except before the clamp's shadow,
where the empty scene is darker.  The shaded side is found there and lost further on, so the
centre line leaves the clamp turned and every base read 11 deg off: the ramp's rows were ``ok``
up to 10 deg off.  Measured as a user measures it (the real pipeline, an empty-scene photo)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.photoset_measure import measure_photoset

W, H = 800, 600
BACKDROP = 170.0
FIXED_END = (W / 2, 60.0)
#: a ramp up and back down, its psi (deg)
PSI = (0.0, 20.0, 45.0, 75.0, 110.0, 150.0, 190.0, 150.0, 100.0, 40.0, 0.0)


def faint_photo(
    psi_deg: float | None, *, seed: int, length: float = 380.0, width: float = 56.0,
    shaded_half: float | tuple[float, float] | None = None, glow: float = 0.0,
):
    """The scene (``psi_deg`` None: the empty scene): a body of constant curvature leaving the
    clamp straight down, its lit side 60 grey levels above the backdrop and its shaded side 5, its
    soft shadow beside it, and the clamp's shadow darkening the backdrop below the clamp.

    ``shaded_half`` (grey levels): the body's lit half is 60 levels above the backdrop and its
    shaded half this many (a pair: at the clamp and at the tip, fading along the body), instead
    of the one fading into the other across the body.  ``glow`` (grey levels): light bounced
    from the body brightens the backdrop that much in a 14 px band beside its lit side, over the
    half of it nearer the tip."""
    rng = np.random.default_rng(seed)
    img = np.full((H, W), BACKDROP)
    fe = np.array(FIXED_END)
    body = np.zeros((H, W), bool)
    if psi_deg is not None:
        s = np.linspace(0.0, length, 240)
        th = -np.pi / 2 + np.deg2rad(psi_deg) / length * s  # y up
        c = np.c_[np.cumsum(np.cos(th)), np.cumsum(np.sin(th))] * (s[1] - s[0])
        n = np.c_[-np.sin(th), np.cos(th)]

        def px(q: np.ndarray) -> np.ndarray:
            return np.c_[q[:, 0], -q[:, 1]] + fe

        shadow = np.zeros((H, W), np.uint8)
        outline = np.r_[px(c + n * width / 2), px(c - n * width / 2)[::-1]] + [10, 8]
        cv2.fillPoly(shadow, [np.round(outline).astype(np.int32)], 1)
        img -= 25 * cv2.GaussianBlur(shadow.astype(float), (0, 0), 6)
        if glow:
            tip = slice(len(s) // 2, None)
            band = np.zeros((H, W), np.uint8)
            side = c[tip] + n[tip] * width / 2
            poly = np.r_[px(side), px(side + n[tip] * 14)[::-1]]
            cv2.fillPoly(band, [np.round(poly * 8).astype(np.int32)], 1, cv2.LINE_AA, 3)
            img += glow * cv2.GaussianBlur(band.astype(float), (0, 0), 2.0)
        strips = 14
        for i in range(len(s) - 1):
            for j in range(strips):
                a, b = j / strips - 0.5, (j + 1) / strips - 0.5
                u = (j + 0.5) / strips  # 0: the lit side .. 1: the shaded side
                quad = np.r_[
                    px(c[i : i + 2] - n[i : i + 2] * a * width),
                    px(c[i : i + 2][::-1] - n[i : i + 2][::-1] * b * width),
                ]
                pts = [np.round(quad * 8).astype(np.int32)]
                shaded = shaded_half
                if isinstance(shaded_half, tuple):  # at the clamp, at the tip
                    shaded = shaded_half[0] + (shaded_half[1] - shaded_half[0]) * i / (len(s) - 2)
                level = 60 * (1 - u) + 5 * u if shaded is None else (60.0 if u < 0.5 else shaded)
                cv2.fillPoly(img, pts, BACKDROP + level, cv2.LINE_AA, 3)
                m = np.zeros((H, W), np.uint8)
                cv2.fillPoly(m, pts, 1, cv2.LINE_8, 3)
                body |= m > 0
    clamp = np.zeros((H, W))
    clamp[: int(fe[1]), int(fe[0] - 45) : int(fe[0] + 45)] = 1.0
    shade = cv2.GaussianBlur(np.roll(clamp, (30, 12), axis=(0, 1)), (0, 0), 14)
    img = np.where(body, img, img - 35 * shade)
    img = np.where(clamp > 0, 150.0, img)
    img = cv2.GaussianBlur(img, (0, 0), 1.2) + rng.normal(0, 1.5, img.shape)
    return np.repeat(np.clip(img, 0, 255).astype(np.uint8)[:, :, None], 3, axis=2)


@pytest.fixture(scope="module")
def faint_sets(tmp_path_factory, ramp_set_writer) -> tuple[Path, Path]:
    root = tmp_path_factory.mktemp("faint")
    photos = [faint_photo(psi, seed=i) for i, psi in enumerate(PSI)]
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]"]
    empty = faint_photo(None, seed=99)
    return (ramp_set_writer(root / "own", photos, settings, empty),
            ramp_set_writer(root / "given", photos, [*settings, "fixed_direction_deg: -90"], empty))


def _measured(folder: Path) -> pd.DataFrame:
    angles = measure_photoset(folder)
    return angles.assign(error_deg=(angles["psi_deg"] - np.array(PSI)).abs())


def test_bodies_whose_sides_diverge_at_the_clamp_are_never_ok_and_wrong(faint_sets):
    angles = _measured(faint_sets[0])
    wrong_ok = angles[(angles["status"] == "ok") & (angles["error_deg"] > 5.0)]
    assert wrong_ok.empty, wrong_ok[["image", "psi_deg", "error_deg", "reason"]]
    # the sides' split, or (where some photos took their faint side in and some did not) the
    # bases' scatter, is named with the fix: the clamp's direction
    named = angles["reason"].str.contains(
        "the body's two sides diverge by|leave its one fixed_end in directions that scatter"
    ) & angles["reason"].str.contains("ive fixed_direction_deg, the clamp's direction")
    assert named.sum() >= 9, angles[["image", "base_side_split_deg", "reason"]]
    assert (angles["base_side_split_deg"].abs() > 2.0).sum() >= 9


def test_with_the_clamps_direction_given_they_are_measured_from_it(faint_sets):
    angles = _measured(faint_sets[1])
    # the bodies' own direction, 11 deg off, no longer doubts the right one given
    assert not angles["reason"].str.contains("psi may be").any(), angles["reason"].iloc[0]
    assert (angles["status"] == "ok").sum() >= 9
    assert angles["error_deg"].median() < 3.0


@pytest.mark.parametrize(("background", "shaded_half", "edge_px"), [
    (True, 6.0, 400), (True, 10.0, 372), (True, 14.0, 372),
    (False, 6.0, 400), (False, 14.0, 372), (False, 20.0, 372),
])
def test_a_side_fainter_than_the_weak_threshold_is_selected_whole_or_left_out_whole(
    background, shaded_half, edge_px
):
    # customer 55: a translucent body lit from one side, its shaded half 9-10 grey levels above
    # the empty scene (5-6 in the colour distance, under the weak threshold's floor of 6), was
    # selected as speckle: the centre line wobbled and half the rows were flagged.  The faint
    # half counts, median-filtered, when clearly above that filter's own threshold: its edge is
    # the body's (x 372: the body spans 372-428); a side at that threshold is left out whole (its
    # lit half, from x 400, measures psi as well), never selected in part.  Without the empty
    # scene only what is lighter than the backdrop counts (a neutral body's shadow is not told
    # apart there)
    from pipeline.measure.body import body_mask
    from pipeline.measure.settings import resolve_settings

    photo = faint_photo(0.0, seed=1, shaded_half=shaded_half)
    mask = body_mask(photo, resolve_settings(l0_mm=100.0, target="body"),
                     background_bgr=faint_photo(None, seed=99) if background else None).mask
    edges = [int(np.flatnonzero(mask[row])[0]) for row in (150, 250, 350)]
    assert all(abs(e - edge_px) <= 3 for e in edges), edges


def test_a_ramp_of_a_body_with_a_faint_half_is_measured_ok(tmp_path, ramp_set_writer):
    # the same body over a ramp, its shaded half 10 grey levels above the empty scene: 4 of 11
    # rows were flagged (the selection took the faint half in part), now 1 (that photo's faint
    # half lies near its threshold, and is left out) and the rest ok and right
    photos = [faint_photo(psi, seed=i, shaded_half=10.0) for i, psi in enumerate(PSI)]
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "fixed_direction_deg: -90"]
    angles = _measured(ramp_set_writer(tmp_path / "half", photos, settings,
                                       faint_photo(None, seed=99)))
    ok = angles[angles["status"] == "ok"]
    assert len(ok) >= 10, angles["reason"].tolist()
    assert ok["error_deg"].max() < 3.0, ok["error_deg"].round(2).tolist()


@pytest.mark.parametrize(("shaded_half", "glow"), [(10.0, 8.0), ((14.0, 6.0), 0.0)])
def test_what_lies_at_a_faint_sides_threshold_is_never_an_ok_psi_off(
    tmp_path, ramp_set_writer, shaded_half, glow
):
    # the review of stop 61: light bounced onto the backdrop beside the lit side (8 levels), too
    # faint alone, came in on the faint half's median and gave rows ok 5.6-10.5 deg off; a shaded
    # half fading from 14 levels at the clamp to 6 at the tip was taken in near the clamp and in
    # part at the tip, and rows read 5-18 deg off, ok.  Each region added is judged on its own,
    # and a reading whose faint side lies near its threshold is read again with it higher:
    # where psi moves, the faint side is left out (the lit half reads psi as well)
    photos = [faint_photo(psi, seed=i, shaded_half=shaded_half, glow=glow)
              for i, psi in enumerate(PSI)]
    settings = ["l0_mm: 100", "target: body", f"fixed_end: [{FIXED_END[0]}, {FIXED_END[1]}]",
                "fixed_direction_deg: -90"]
    angles = _measured(ramp_set_writer(tmp_path / "s", photos, settings,
                                       faint_photo(None, seed=99)))
    ok = angles[angles["status"] == "ok"]
    assert len(ok) >= 8, angles[["image", "status", "error_deg", "reason"]]
    assert ok["error_deg"].max() < 3.0, ok[["image", "psi_deg", "error_deg"]]
