"""Body mode (``target: body``): the actuator's own centre line, without a drawn line."""

from __future__ import annotations

import re

import cv2
import numpy as np
import pytest

from pipeline.measure import measure_image
from pipeline.measure.quality import NOTE_TIP_FACE
from pipeline.measure.settings import SettingsError, resolve_settings

W, H = 1280, 960


def body_photo(
    psi_deg,
    *,
    length=600.0,
    width=46.0,
    clamp=True,
    backdrop=(190, 196, 200),
    body=(90, 140, 200),
    noise=2.0,
    texture=False,
    seed=0,
    shift=(0.0, 0.0),
    tip_width=None,
    lost_side_from=None,
    tip_slant_deg=0.0,
):
    """A thick arc-shaped body (square ends) leaving a dark clamp along +x, with its exact psi.

    The inextensible layer is the body's lower edge (walking from the clamp); the body lies on
    its left.  ``tip_width``: the width tapers linearly to it at the free end (the centre line
    still turns through psi).  ``lost_side_from``: from this fraction of the length on, only the
    inner half of the width is drawn (a faint side the segmentation cannot see).
    ``tip_slant_deg``: the end face is cut at this slant (the far edge runs on past the square).
    Returns (image, fixed end pixel, clamp polygon in px).
    """
    k = np.deg2rad(psi_deg) / length
    s = np.linspace(0.0, length, 3000)
    x, y = (s, 0 * s) if abs(k) < 1e-12 else (np.sin(k * s) / k, (1 - np.cos(k * s)) / k)
    pts = np.c_[x, y]
    n = np.c_[-np.sin(k * s), np.cos(k * s)]
    w = width + (s / length) * ((width if tip_width is None else tip_width) - width)
    if lost_side_from is not None:
        w = np.where(s >= lost_side_from * length, 0.5 * w, w)
    outline = np.r_[pts, (pts + n * w[:, None])[::-1]]
    if tip_slant_deg:
        s_far = np.linspace(0.0, length + width * np.tan(np.deg2rad(tip_slant_deg)), 3000)
        far = np.c_[np.sin(k * s_far) / k, (1 - np.cos(k * s_far)) / k]
        far += np.c_[-np.sin(k * s_far), np.cos(k * s_far)] * width
        outline = np.r_[pts, far[::-1]]
    mid = pts + n * width / 2
    off = np.array([W / 2 - mid[:, 0].mean() + shift[0], H / 2 + mid[:, 1].mean() + shift[1]])

    def to_px(q):
        return np.c_[q[:, 0], -q[:, 1]] + off

    rng = np.random.default_rng(seed)
    img = np.empty((H, W, 3), np.uint8)
    img[:] = backdrop
    cv2.fillPoly(img, [np.round(to_px(outline) * 16).astype(np.int32)], body, cv2.LINE_AA, 4)
    if texture:  # fibre winding: thin darker strands across the body
        for t in np.arange(0.0, length, 14.0):
            i = int(t / length * (len(s) - 1))
            a, b = (
                to_px(pts[i : i + 1])[0],
                to_px((pts + n * width)[min(i + 40, len(s) - 1) : min(i + 40, len(s) - 1) + 1])[0],
            )
            cv2.line(
                img,
                tuple(np.round(a).astype(int)),
                tuple(np.round(b).astype(int)),
                tuple(int(0.7 * c) for c in body),
                2,
                cv2.LINE_AA,
            )
    clamp_px = to_px(
        np.array([[-60.0, -20.0], [0.0, -20.0], [0.0, width + 20.0], [-60.0, width + 20.0]])
    )
    if clamp:
        cv2.fillPoly(img, [np.round(clamp_px * 16).astype(np.int32)], (60, 60, 66), cv2.LINE_AA, 4)
    img = np.clip(img + rng.normal(0.0, noise, img.shape), 0, 255).astype(np.uint8)
    _ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 90])
    img = cv2.imdecode(buf, cv2.IMREAD_COLOR)
    return img, tuple(to_px(pts[:1])[0]), [tuple(map(float, p)) for p in clamp_px]


def settings_for(fixed_end, **kw):
    return resolve_settings(
        **{"l0_mm": 180.0, **kw}, target="body", fixed_end=[float(v) for v in fixed_end]
    )


@pytest.mark.parametrize("psi", [210.0, 120.0, 45.0, 3.0, -60.0, -150.0, -225.0])
def test_body_psi_is_the_total_turning(psi):
    img, fe, _ = body_photo(psi, seed=int(abs(psi)))
    res = measure_image(img, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.method == "tangents"
    assert res.psi_deg == pytest.approx(psi, abs=2.5)


@pytest.mark.parametrize("psi", [240.0, 120.0, 30.0, -200.0])
@pytest.mark.parametrize("width", [46.0, 24.0])
def test_a_free_strip_that_bends_to_its_cut_end(psi, width):
    # no clamp, no sealed end: the strip's centre line turns through psi right to its end face
    img, fe, _ = body_photo(psi, width=width, clamp=False, seed=5)
    res = measure_image(img, settings_for(fe, free_end="bends"))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=2.0)


@pytest.mark.parametrize("psi", [240.0, 210.0, 120.0, -150.0, -225.0])
@pytest.mark.parametrize("inside_px", [5.0, 10.0, 15.0, 30.0])
def test_a_fixed_end_clicked_inside_the_clamp_adds_no_bend(psi, inside_px):
    # fixed_end inside the clamp block: the base's curvature was carried on over the clamp,
    # which does not bend (30 px in: 5-10 deg off, ok; 5-15 px in, short of where the block
    # was looked for: 2-6 deg off at psi 240, ok, the review of stop 57)
    img, fe, _ = body_photo(psi, seed=int(abs(psi)))
    res = measure_image(img, settings_for((fe[0] - inside_px, fe[1])))
    assert res.psi_deg == pytest.approx(psi, abs=1.6), res.reason


@pytest.mark.parametrize("psi", [240.0, -200.0])
@pytest.mark.parametrize("inside_px", [10.0, 30.0])
def test_a_fixed_end_inside_an_excluded_clamp_is_flagged_not_an_ok_psi(psi, inside_px):
    # the clamp plate under exclude and the fixed end clicked inside it: the base's curvature
    # is carried on to the click over the plate (psi 240 read 245 at 10 px in, 249 at 20, ok).
    # Stopping at the box instead read a box drawn onto the body 8-20 deg low (the review of
    # stop 60): what is under the box is not seen either way, so the row says so
    img, fe, clamp = body_photo(psi, seed=int(abs(psi)))
    res = measure_image(img, settings_for((fe[0] - inside_px, fe[1]), exclude=[clamp]))
    assert res.status == "flagged" and "inside what exclude / roi leave out" in res.reason
    onto = [(x + inside_px if x >= fe[0] - 1 else x, y) for x, y in clamp]
    res = measure_image(img, settings_for(fe, exclude=[onto]))
    assert res.status == "flagged" and "inside what exclude / roi leave out" in res.reason
    # with the clamp's direction given psi does not depend on it
    given = settings_for((fe[0] - inside_px, fe[1]), exclude=[clamp], fixed_direction_deg=0.0)
    assert measure_image(img, given).status == "ok"


@pytest.mark.parametrize("psi", [240.0, 120.0, -200.0])
def test_an_excluded_clamp_does_not_carry_the_body_past_its_face(psi):
    # the clamp excluded and the fixed end on its face: the clamp's strong difference beside the
    # body's end let the centre line march 2 px on over it, hooking its start (psi 240 read
    # 5.5 deg high, ok; now 1.7: that difference still softens the edge beside the face)
    img, fe, clamp = body_photo(psi, seed=int(abs(psi)))
    res = measure_image(img, settings_for(fe, exclude=[clamp]))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=2.0)


def test_a_label_in_a_far_corner_is_no_rival_body():
    # customer 49: a paper label in a corner, never touching the body, flagged 15 of 84 right
    # rows "2 candidate bodies"; with the fixed end reached, a smaller selection far from the
    # body is no rival, and one beside it (a ruler along it) still is
    img, fe, _ = body_photo(150.0, seed=4)
    labelled = img.copy()
    cv2.rectangle(labelled, (W - 170, H - 100), (W - 20, H - 20), (250, 250, 250), -1)
    res = measure_image(labelled, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(150.0, abs=2.5)
    beside = img.copy()
    cv2.rectangle(beside, (int(fe[0]) - 10, int(fe[1]) + 40), (int(fe[0]) + 500, int(fe[1]) + 70),
                  (250, 250, 250), -1)
    assert "candidate bodies" in measure_image(beside, settings_for(fe)).reason


@pytest.mark.parametrize("psi", [150.0, -120.0])
def test_textured_body_and_excluded_clamp(psi):
    img, fe, clamp = body_photo(psi, texture=True, seed=3)
    res = measure_image(img, settings_for(fe, exclude=[clamp]))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=3.0)


def test_fixed_direction_gives_psi_against_the_known_clamp_direction():
    img, fe, _ = body_photo(100.0, seed=5)
    res = measure_image(img, settings_for(fe, fixed_direction_deg=0.0))
    # no note saying so on every row (angles.csv's fixed_direction_deg column does; customer 29
    # found the note on all 46 rows hid the ones that matter)
    assert res.status == "ok" and res.reason == ""
    assert res.psi_deg == pytest.approx(100.0, abs=2.5)
    # a clamp direction that disagrees with the photo by 30 deg is used, and said to be doubtful
    off = measure_image(img, settings_for(fe, fixed_direction_deg=30.0))
    assert off.status == "flagged" and "off fixed_direction_deg" in off.reason
    # the body's own against the one given: it leaves 30 deg below it (customer 35 read the sign
    # reversed, "-24 deg off" for a body leaving 24 deg above the direction given)
    assert "leaves the clamp -30 deg off fixed_direction_deg" in off.reason, off.reason
    assert off.psi_deg == pytest.approx(res.psi_deg - 30.0, abs=1.0)
    # the body's own base direction is still read, beside the one given (the ramp check
    # compares them), and is the same whichever was given
    assert res.base_direction_deg == pytest.approx(0.0, abs=2.5)
    assert off.base_direction_deg == pytest.approx(res.base_direction_deg, abs=1e-6)


def test_nothing_selected_fails_naming_the_setting_and_the_preview():
    img, fe, _ = body_photo(80.0)
    res = measure_image(img, settings_for(fe, line_color="green"))
    assert res.status == "failed" and np.isnan(res.psi_deg)
    assert "line_color green" in res.reason and "photoset preview" in res.reason


def test_a_selection_covering_the_photo_fails():
    img, fe, _ = body_photo(80.0)
    res = measure_image(img, settings_for(fe, line_color="0,0,0-179,255,255"))
    assert res.status == "failed" and "of the photo is selected" in res.reason


def test_a_body_leaving_the_photo_is_flagged():
    img, fe, _ = body_photo(20.0, shift=(420.0, 0.0))
    res = measure_image(img, settings_for(fe))
    assert res.status == "flagged" and "border at its free end" in res.reason


@pytest.mark.parametrize("psi", [45.0, 150.0])
def test_a_hand_joined_to_the_tip_is_named_not_a_tip_outside_the_photo(psi):
    # customer 42's finger touching the tip ran the selection to the image border: "body touches
    # the image border at its free end: the tip may be outside", the tip well in view
    img, fe, _ = body_photo(psi)
    k = np.deg2rad(psi) / 600.0
    tip = np.array(fe) + np.array([np.sin(k * 600.0) / k, -(1 - np.cos(k * 600.0)) / k])
    tip += 23.0 * np.array([-np.sin(k * 600.0), -np.cos(k * 600.0)])  # to the body's middle
    x, y = np.round(tip).astype(int)
    cv2.line(img, (x, y), (x + 60, -10), (120, 150, 215), 40, cv2.LINE_AA)  # a finger
    res = measure_image(img, settings_for(fe, mm_per_px=0.3))  # l0 is 600 px, as drawn
    assert res.status == "flagged", res.reason
    assert res.reason.startswith(
        "the selection runs on from the body's free end to the image border"
    ), res.reason
    assert "body touches the image border at its free end" not in res.reason
    # a tip outside the photo is still said so, and where l0 given short (a capped body's line
    # runs on over its cap) may make it look long, the reason names that too
    img, fe, _ = body_photo(20.0, shift=(420.0, 0.0))
    res = measure_image(img, settings_for(fe, mm_per_px=0.3))
    assert "body touches the image border at its free end: the tip may be outside" in res.reason
    res = measure_image(img, settings_for(fe, mm_per_px=0.3, l0_mm=110.0))
    assert "or those settings are off, or the tip is outside the photo" in res.reason, res.reason
    res = measure_image(img, settings_for(fe, mm_per_px=0.3, l0_mm=110.0, sealed_end_mm=70.0))
    assert "the tip may be outside" in res.reason, res.reason  # the body's whole length


def test_a_body_shorter_than_l0_with_its_tip_in_view_is_said_to_maybe_bend_out_of_the_plane():
    # customer 38's chambers bending 120 deg round from the photo's plane looked short: "body
    # partly hidden: 69% of l0 visible" with the whole body in view
    img, fe, _ = body_photo(60.0)
    res = measure_image(img, settings_for(fe, mm_per_px=0.2))  # l0 is 900 px: 600 are seen
    assert res.status == "flagged"
    assert ("body short of l0 with its tip in view (64% of l0): it may bend out of the "
            "photo's plane (towards or away from the camera") in res.reason, res.reason
    # its tip out of the photo: hidden indeed
    img, fe, _ = body_photo(20.0, shift=(420.0, 0.0))
    res = measure_image(img, settings_for(fe, mm_per_px=0.2))
    assert "body partly hidden" in res.reason and "tip in view" not in res.reason, res.reason
    # psi changing smoothly along its ramp does not lift it (as it lifts "partly hidden")
    from pipeline.measure.quality import COSMETIC_FLAGS

    assert not "body short of l0 with its tip in view".startswith(COSMETIC_FLAGS)


@pytest.mark.parametrize(("scene", "i"), [("dark_translucent", 9), ("lab", 9), ("green_fibre", 9)])
def test_a_side_along_the_image_border_is_measured_from_the_other_edge(scene, i):
    # 720p frames with the clamp at the top edge: the body's upper side runs out of the photo
    # near the clamp.  Taking the middle of what is seen there tilted the base tangent (11 deg
    # off for the translucent body); half the body's width in from the seen edge is right, and
    # since the free end is inside the photo, it is a note, not a flag.
    from pipeline.synth import render_actuator, scene_from

    psi = float(np.linspace(215.0, -220.0, 12)[i])
    overrides = {"line_contrast": 0.0, "body_translucency": 0.0} if scene == "lab" else {}
    r = render_actuator(
        psi, 270.0, scene_from(scene, width=1280, height=720, **overrides), seed=30 + i,
        bulge=0.4 if i % 2 else 0.0,
    )
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    if scene != "green_fibre":  # its side stays inside: its shadow, selected with it until
        # shadows were left out without an empty scene, ran out of the photo (2.4 -> 0.2 deg)
        assert "a side runs along the image border" in res.reason
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=2.5)


def test_a_body_cut_off_by_an_exclude_polygon_is_flagged_not_an_ok_psi():
    # an exclude box drawn over the clamp plate that also covers the curled-back tip: the rest of
    # the body was measured as if it ended there, ok at 33 deg off
    from pipeline.synth import render_actuator, scene_from

    r = render_actuator(215.0, 270.0, scene_from("dark_translucent", width=1280, height=960),
                        seed=30)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    box = [0.0, 0.0, float(r.fixed_end_px[0]) - 3.0, float(H)]
    res = measure_image(img, settings_for(r.fixed_end_px, exclude=[box]))
    assert abs(res.psi_deg - r.psi_image_deg) > 20.0  # the tip is not seen: psi cannot be right
    assert res.status == "flagged" and "edge of roi / exclude" in res.reason, res.reason
    # without the box, nothing is said of it
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert "edge of roi / exclude" not in res.reason


def test_roi_restricts_the_search():
    img, fe, _ = body_photo(60.0)
    # a second thing of the body's colour
    cv2.rectangle(img, (20, 20), (400, 90), (90, 140, 200), -1)
    plain = measure_image(img, settings_for(fe))
    boxed = measure_image(img, settings_for(fe, roi=[0, 120, W, H]))
    assert boxed.status == "ok" and boxed.psi_deg == pytest.approx(60.0, abs=2.5)
    assert plain.psi_deg == pytest.approx(60.0, abs=2.5)  # the fixed end already picks the body


def test_body_mode_is_deterministic_whatever_opencvs_global_rng():
    img, fe, _ = body_photo(140.0, texture=True, seed=9)
    first = measure_image(img, settings_for(fe))
    cv2.setRNGSeed(12345)
    cv2.randu(np.empty((50, 50), np.float32), 0, 1)  # move OpenCV's global random state on
    again = measure_image(img, settings_for(fe))
    assert again.psi_deg == first.psi_deg and again.reason == first.reason


@pytest.mark.parametrize("psi", [150.0, -100.0])
def test_a_body_thinning_towards_its_tip_is_measured_to_its_end(psi):
    # its width judged against the whole body's, the thinner half would be cut away as "tip"
    img, fe, _ = body_photo(psi, width=46.0, tip_width=33.0, seed=3)
    res = measure_image(img, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=3.0)


def test_the_centre_line_stops_at_a_rigid_cap_wider_than_the_body():
    # the translucent ribbed body on black with a white cap 15-20 % wider than its last rib: the
    # centre line marched on into the cap read psi 5 deg high (the tangent window carried the
    # body's curvature on through the cap, which does not bend)
    from pipeline.synth import render_actuator, scene_from

    r = render_actuator(215.0, 270.0, scene_from("dark_translucent", width=2000, height=1500),
                        seed=30)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=3.5)


def test_a_wobbly_centre_line_is_flagged_not_an_ok_psi():
    # the translucent body with dots on grey at 720p: its faint side makes the centre line wobble
    # near both ends, and the end tangents read -32.7 deg for -22.3 (it was ok); a smooth fit of
    # the whole centre line's turning disagrees, and says so (seed 36, the first such photo,
    # reads -20.1 and ok since the inside its outline encloses is taken in: fill_outlined)
    from pipeline.synth import render_actuator, scene_from

    psi = float(np.linspace(215.0, -220.0, 12)[6])
    r = render_actuator(psi, 270.0, scene_from("grey_dots_clear", width=1280, height=720), seed=39)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.status == "flagged" and "smooth fit of the whole centre line" in res.reason


def test_a_free_end_with_one_side_lost_is_flagged():
    img, fe, _ = body_photo(-120.0, width=46.0, lost_side_from=0.8, seed=4)
    res = measure_image(img, settings_for(fe))
    assert res.status == "flagged"
    assert "free end" in res.reason, res.reason


@pytest.mark.parametrize("body", ["pink", "grey"])
def test_a_hook_where_the_body_meets_the_clamp_is_flagged_not_an_ok_psi(body):
    # silicone with dots on grey, saved again at JPEG quality 40: the selection ran into the
    # body's shadow and the plate's edge at the clamp and the centre line's first pixels hooked
    # towards them; a fit over the usual end window smoothed the hook into the base tangent (ok
    # at 16 deg off), a fit over half that window turns 13 deg: flagged.  The pink body's shadow
    # is now left out without an empty scene (backdrop_shadows), and it reads right; a grey
    # body's cannot be told from it (its shaded side looks like a shadow too), and the check
    # still flags its hook
    from pipeline.synth import render_actuator, scene_from

    psi = float(np.linspace(215.0, -220.0, 12)[6])
    colour = {"pink": {}, "grey": {"body_bgr": (150, 150, 150)}}[body]
    scene = scene_from("grey_dots", width=1280, height=960, **colour)
    r = render_actuator(psi, 270.0, scene, seed=36)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    _ok, buf = cv2.imencode(".jpg", img, [cv2.IMWRITE_JPEG_QUALITY, 40])
    res = measure_image(cv2.imdecode(buf, cv2.IMREAD_COLOR), settings_for(r.fixed_end_px))
    if body == "pink":
        assert res.status == "ok" and abs(res.psi_deg - r.psi_image_deg) < 5.0, res.reason
    else:
        assert abs(res.psi_deg - r.psi_image_deg) > 10.0
        assert res.status == "flagged" and "the fixed end's direction turns" in res.reason
        assert "the clamp or its tube selected with the body (an exclude box" in res.reason


def _paint_gap(img, psi, gap_px, at=0.6, length=600.0, width=46.0, backdrop=(190, 196, 200)):
    """Paint a band of backdrop ``gap_px`` long across the body of :func:`body_photo` (defaults)
    at fraction ``at`` of its length: a stretch of the body that the selection cannot see."""
    k = np.deg2rad(psi) / length
    s = np.linspace(0.0, length, 3000)
    mid = np.c_[np.sin(k * s) / k, (1 - np.cos(k * s)) / k] + np.c_[
        -np.sin(k * s), np.cos(k * s)
    ] * (width / 2)
    off = np.array([W / 2 - mid[:, 0].mean(), H / 2 + mid[:, 1].mean()])
    i = int(at * (len(s) - 1))
    c = np.array([mid[i, 0], -mid[i, 1]]) + off
    t = np.array([np.cos(k * s[i]), -np.sin(k * s[i])])
    n = np.array([-t[1], t[0]])
    g, w = gap_px / 2, width
    band = np.array([c - t * g - n * w, c + t * g - n * w, c + t * g + n * w, c - t * g + n * w])
    cv2.fillPoly(img, [np.round(band).astype(np.int32)], backdrop)
    return img


def _paint_slot(img, psi, start, end, across, length=600.0, backdrop=(190, 196, 200)):
    """Paint a slot of backdrop inside the body of :func:`body_photo` (defaults): from fraction
    ``start`` to ``end`` of its length, between the fractions ``across`` of its width from the
    layer: a faint stretch beside a highlight that the selection leaves out."""
    k = np.deg2rad(psi) / length
    s = np.linspace(start * length, end * length, 400)
    pts = np.c_[np.sin(k * s) / k, (1 - np.cos(k * s)) / k]
    n = np.c_[-np.sin(k * s), np.cos(k * s)]
    whole = np.linspace(0.0, length, 3000)
    mid = np.c_[np.sin(k * whole) / k, (1 - np.cos(k * whole)) / k] + np.c_[
        -np.sin(k * whole), np.cos(k * whole)
    ] * (46.0 / 2)
    off = np.array([W / 2 - mid[:, 0].mean(), H / 2 + mid[:, 1].mean()])
    side = np.r_[pts + n * across[0] * 46.0, (pts + n * across[1] * 46.0)[::-1]]
    cv2.fillPoly(img, [np.round(np.c_[side[:, 0], -side[:, 1]] + off).astype(np.int32)], backdrop)
    return img


@pytest.mark.parametrize("psi", [200.0, 45.0])
def test_a_body_read_wider_or_narrower_than_body_width_mm_is_flagged(psi):
    # customer 55: a translucent body with a strong shadow was read 17.5 mm wide for its 13 (its
    # shadow taken in) and three rows were ok 6-10 deg off; its width given is a witness
    img, fe, _ = body_photo(psi, seed=7)  # 46 px wide: 13.8 mm at 0.3 mm/px
    right = measure_image(img, settings_for(fe, mm_per_px=0.3, body_width_mm=13.8))
    assert right.status == "ok", right.reason
    wide = measure_image(img, settings_for(fe, mm_per_px=0.3, body_width_mm=10.0))
    assert wide.status == "flagged"
    read = re.match(r"body read ([\d.]+) mm wide where body_width_mm is 10: its shad", wide.reason)
    assert read and float(read.group(1)) == pytest.approx(13.8, abs=0.6), wide.reason
    narrow = measure_image(img, settings_for(fe, mm_per_px=0.3, body_width_mm=20.0))
    assert narrow.status == "flagged" and "a side of it is not selected" in narrow.reason
    # without the scale there is nothing to compare: no flag
    assert measure_image(img, settings_for(fe, body_width_mm=10.0)).status == "ok"


def test_body_width_mm_without_a_scale_is_warned_of(tmp_path):
    from pipeline.photoset import body_width_problems, load_photoset

    img, fe, _ = body_photo(90.0, seed=7)
    cv2.imwrite(str(tmp_path / "a.jpg"), img)
    (tmp_path / "manifest.csv").write_text(
        "image,pressure_kpa,direction,material,actuator,trial\na.jpg,0,up,M,A,1\n"
    )
    (tmp_path / "photoset.yaml").write_text(
        f"l0_mm: 180\ntarget: body\nfixed_end: [{fe[0]:.1f}, {fe[1]:.1f}]\nbody_width_mm: 14\n"
    )
    [warning] = body_width_problems(load_photoset(tmp_path))
    assert warning.warning and "without mm_per_px" in warning.message
    with open(tmp_path / "photoset.yaml", "a") as f:
        f.write("mm_per_px: 0.3\n")
    assert body_width_problems(load_photoset(tmp_path)) == []


def test_body_width_mm_is_for_a_body_and_a_width():
    for raw, what in (({"target": "line"}, "drawn line"), ({"target": "body"}, "> 0")):
        with pytest.raises(SettingsError) as err:
            resolve_settings(l0_mm=100.0, body_width_mm=-3.0 if "body" in raw.values() else 12.0,
                             **raw)
        assert "body_width_mm" in str(err.value) and what in str(err.value)


@pytest.mark.parametrize("psi", [200.0, -150.0])
def test_a_slot_inside_the_body_does_not_stop_its_centre_line(psi):
    # customer 53: a translucent body's faint stretch between a specular streak and a dot left a
    # slot in the selection, 6 % of the body: the profiles across the body stopped at it, the
    # centre line ran along one side and stopped half-way (six right photos flagged, "body short
    # of l0 ... out of the photo's plane"); the body's inside is filled, a curl's is not
    img, fe, _ = body_photo(psi, seed=5)
    res = measure_image(_paint_slot(img, psi, 0.35, 0.8, (0.55, 0.8)), settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=2.5)


def test_two_actuators_in_one_photo_are_flagged_with_the_roi_fix_and_measured_with_it():
    # a lab photographs several actuators at once: each row's body is then one of two, which is
    # flagged, the reason saying how to tell them apart; a roi per row measures each alone
    a, fe_a, _ = body_photo(120.0, seed=3)
    b, fe_b, _ = body_photo(-150.0, seed=4)
    both = np.vstack([a, b])
    h, w = a.shape[:2]
    fe_b = (fe_b[0], fe_b[1] + h)
    res = measure_image(both, settings_for(fe_a))
    assert res.status == "flagged" and res.reason.startswith("2 candidate bodies"), res.reason
    assert "a roi around this actuator" in res.reason
    rows = ((fe_a, [0, 0, w - 1, h - 1], 120.0), (fe_b, [0, h, w - 1, 2 * h - 1], -150.0))
    for fe, roi, psi in rows:
        res = measure_image(both, settings_for(fe, roi=roi))
        assert res.status == "ok", res.reason
        assert res.psi_deg == pytest.approx(psi, abs=2.5)


def test_a_ruler_in_view_is_flagged_with_the_exclude_fix_and_measured_with_it():
    # customer 30 laid a ruler along the bottom of the frame, as the README suggests for the
    # scale: every row was flagged 'another actuator in view ... set roi', which a ruler is not.
    # Far from the body that reaches the fixed end, and smaller, it is no rival (customer 49);
    # beside the body it is, and the reason says what to do
    img, fe, _ = body_photo(120.0, seed=3)
    h, w = img.shape[:2]
    far = img.copy()
    far[h - 40 : h - 16, 20 : w - 20] = (90, 140, 200)  # as the body differs from the backdrop
    res = measure_image(far, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(120.0, abs=2.5)
    near = img.copy()
    y = int(fe[1]) + 60  # clear of the clamp (30 px below, touching it, it joins the body)
    near[y : y + 24, 20 : w - 20] = (90, 140, 200)
    res = measure_image(near, settings_for(fe))
    assert res.status == "flagged" and res.reason.startswith("2 candidate bodies"), res.reason
    assert "such as a ruler" in res.reason and "give exclude (a box over it)" in res.reason
    res = measure_image(near, settings_for(fe, exclude=[[10, y - 6, w - 10, y + 30]]))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(120.0, abs=2.5)


@pytest.mark.parametrize("psi", [150.0, -120.0, 200.0])
@pytest.mark.parametrize("gap", [20, 40])
def test_a_stretch_the_selection_misses_is_bridged_along_the_body(psi, gap):
    # a faint stretch (dim light on a translucent body, a shadow) splits the selection: the piece
    # at the clamp stopped at the gap (50-69 deg off, flagged); the piece ahead of its free end,
    # on its course, is joined and the centre line walked on to the tip
    img, fe, _ = body_photo(psi, seed=3)
    res = measure_image(_paint_gap(img, psi, gap), settings_for(fe))
    assert res.psi_deg == pytest.approx(psi, abs=2.5)
    assert res.status == "flagged" and "body partly hidden" in res.reason, res.reason
    assert "candidate bodies" not in res.reason


@pytest.mark.parametrize(("camera", "mm_per_px"), [("blur", 0.3), ("jpeg40", 0.3), ("clean", 0.4)])
def test_the_tip_of_a_faint_body_beyond_a_gap_is_joined_to_it(camera, mm_per_px):
    # the translucent body on grey without its empty scene, curled to 136 deg: a faint stretch cuts
    # the selection a few px before its tip, and the tip alone (about one half-width squared) was
    # too small a piece to bridge to; the centre line stopped there and psi read 23-32 deg low
    # (flagged); the tip piece right ahead of the free end is now joined (still flagged).  Within
    # 8 deg, not 5: at 0.4 mm/px (a clean photo, its outline clear enough for bumps on one side to
    # be left out) the edge of its faint outer side stands out 2-5 px in three short places; set
    # back to that side's course, psi reads 6.7 deg low where it read 1.2 high (customer 50's
    # dots on a clear outline: 3 rows ok 5.7-6.8 deg off before, none after)
    from pipeline.bench.realscenes import through_camera
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("grey_dots_clear", width=1280, height=960, mm_per_px=mm_per_px)
    r = render_actuator(float(np.linspace(215.0, -220.0, 12)[2]), 270.0, scene, seed=32)
    img = through_camera(cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR),
                         camera, 2)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=8.0), (res.psi_deg, res.reason)
    assert res.status == "flagged" and "body partly hidden" in res.reason, res.reason


@pytest.mark.parametrize(("width_mm", "seed"), [(30.0, 38), (25.0, 85)])
def test_a_tip_carried_on_along_the_selection_is_carried_to_its_end(width_mm, seed):
    # a fat translucent body on grey without its empty scene, at -102 deg: the centre line stops
    # short of a faint tip, and psi was carried on along the selection's ridge only, which stops
    # two half-widths short of the ridge's end: 12-14 deg short (flagged); the free end's
    # curvature, which turns the whole uncovered part further the same way, now carries it on
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("grey_dots_clear", body_width_mm=width_mm)
    r = render_actuator(float(np.linspace(215.0, -220.0, 12)[8]), 270.0, scene, seed=seed)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=4.0), (res.psi_deg, res.reason)
    assert res.status == "flagged" and "and on at the free end's curvature" in res.reason


def test_a_faint_tip_the_centre_line_stops_short_of_is_flagged_not_an_ok_psi(tmp_path):
    # a ramp of the translucent body on grey without its empty scene: at -93 and -97 deg the
    # centre line stops about 1.5 widths short of a tip whose selection is narrower than the body
    # (a faint side); at the free end's curvature the part missed turns 7.5 and 6.6 deg, under the
    # 8 deg that flags and carries on, but the tip curls harder: psi read 15.9 and 8.4 deg off,
    # ok; now flagged (as a faint tip, or since the march stops before an oblique end face as
    # one whose outline is uneven there, or carried on: 16.4 and 3.0 deg off)
    from pipeline.measure import measure_file
    from pipeline.photoset import load_photoset
    from pipeline.synth.photoset_writer import render_photoset

    folder = tmp_path / "s"
    render_photoset(folder, "DS20", actuators=1, trials=2, seed=1, scene="grey_dots_clear",
                    step_kpa=20)
    yaml = (folder / "photoset.yaml").read_text()
    (folder / "photoset.yaml").write_text(
        "".join(line for line in yaml.splitlines(keepends=True) if "background" not in line)
    )
    ps = load_photoset(folder)
    for trial in (1, 2):
        image = f"DS20_A1_t{trial}_s015_down_60kPa.jpg"
        res, _ = measure_file(folder / image, ps.rows[list(ps.manifest["image"]).index(image)])
        assert res.status == "flagged", (image, res.psi_deg, res.reason)
        assert "short of the body's" in res.reason, res.reason


def test_with_its_base_known_a_ramp_is_not_flagged_for_what_psi_does_not_depend_on(tmp_path):
    # a 720p ramp of the translucent body on grey without its empty scene, fixed_direction_deg
    # given: the selection misses the faint stretch by the clamp, so the centre line starts
    # 100-200 px from fixed_end.  psi is the free end's tangent against the known direction, but
    # the start gap, the fixed end's tangent (its window doubled, carried back over the gap) and a
    # smooth fit carried back over it (run away: "more than a full turn") flagged 33 of 40 photos,
    # 28 of them within 10 deg.  Lifting those flags let two tips through at 10.1 and 11.3 deg
    # off: their lines stop a full width short of a faint tip that still turns 7 deg, now
    # flagged as a faint tip
    import pandas as pd

    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth.photoset_writer import render_photoset

    folder = tmp_path / "s"
    truth = render_photoset(folder, "DS20", actuators=1, trials=2, seed=35,
                            scene="grey_dots_clear", step_kpa=20,
                            scene_overrides={"width": 1280, "height": 720})
    yaml = (folder / "photoset.yaml").read_text()
    (folder / "photoset.yaml").write_text(
        "".join(line for line in yaml.splitlines(keepends=True) if "background" not in line)
    )
    out = measure_photoset(folder, jobs=2)
    assert len(out) == len(truth) == 40
    err = (out["psi_deg"] - out["image"].map(truth.set_index("image")["psi_deg"])).abs()
    ok = out["status"] == "ok"
    assert ok.sum() >= 25 and (err[ok] <= 10.0).all(), out.loc[ok & (err > 10.0)]
    assert not out.loc[ok, "reason"].str.contains("the end tangents and a smooth fit").any()
    assert not out["reason"].str.contains("the body starts", regex=False).any()
    # the table says which direction psi was measured from; the body's own is not read where
    # its start is missed (nor compared with the one given)
    given = out["image"].map(truth.set_index("image")["fixed_direction_deg"])
    np.testing.assert_allclose(out["fixed_direction_deg"], given, atol=1e-3)  # as written
    assert out["base_direction_deg"].isna().sum() >= 30
    assert not out["reason"].str.contains("leave the clamp at").any()
    faint = out.set_index("image").loc[
        ["DS20_A1_t1_s012_down_120kPa.jpg", "DS20_A1_t2_s011_down_180kPa.jpg"]
    ]
    assert (faint["status"] == "flagged").all() and faint["reason"].str.contains(
        "a faint tip?"
    ).all(), faint["reason"].tolist()
    # with the sealed end's length given, a tip carried on over the faint part the centre line
    # stops short of was also carried on, at its curvature, to where the bending stops: twice
    # the turn (35 of 40 within 10 deg, 13-29 deg over on a customer's trial); now once (39)
    settings = (folder / "photoset.yaml").read_text()
    (folder / "photoset.yaml").write_text(settings + "sealed_end_mm: 4\n")
    sealed = measure_photoset(folder, jobs=2)
    err = (sealed["psi_deg"] - sealed["image"].map(truth.set_index("image")["psi_deg"])).abs()
    assert (err <= 10.0).sum() >= 38 and not ((sealed["status"] == "ok") & (err > 10.0)).any()
    (folder / "photoset.yaml").write_text(settings)
    # without the clamp's direction psi does depend on the missed stretch: flagged, naming the fix
    manifest = pd.read_csv(folder / "manifest.csv")
    manifest.drop(columns="fixed_direction_deg").to_csv(folder / "manifest.csv", index=False)
    alone = measure_photoset(folder, jobs=2, ramp_check=False)
    gap = alone["reason"].str.contains("the body starts", regex=False)
    assert gap.sum() >= 20 and (alone.loc[gap, "status"] == "flagged").all()
    assert alone.loc[gap, "reason"].str.contains("give fixed_direction_deg", regex=False).all()
    assert alone["fixed_direction_deg"].isna().all()


def test_a_centre_line_stopping_short_of_a_tip_that_still_turns_is_flagged_and_carried_on():
    # the translucent body on grey, curled to 215 deg, saved at JPEG quality 40: the centre line
    # stops a body width short of the tip while the body there turns 0.6 deg per px (the turning
    # of the last part is not seen); it was ok at 15 deg off, then flagged at 15 deg off; psi is
    # now carried on over that part at the tip's curvature (still flagged): 2.5 deg off
    from pipeline.bench.realscenes import through_camera
    from pipeline.synth import render_actuator, scene_from

    r = render_actuator(215.0, 270.0, scene_from("grey_dots_clear", width=1280, height=960),
                        seed=30)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(through_camera(img, "jpeg40", 0), settings_for(r.fixed_end_px))
    assert abs(res.psi_deg - r.psi_image_deg) < 5.0
    assert res.status == "flagged" and "where the body still turns" in res.reason, res.reason
    assert "psi is carried on over that part at the free end's curvature" in res.reason


def test_an_underexposed_photo_is_measured_like_a_well_exposed_one():
    # the translucent body on grey at 0.45x exposure: its faint differences from the backdrop fell
    # below the least colour difference a body must show, and 11 of 12 photos were lost
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("grey_dots_clear", width=1280, height=960)
    rows = []
    for i, psi in enumerate(np.linspace(215.0, -220.0, 12)):
        r = render_actuator(float(psi), 270.0, scene, seed=30 + i, bulge=0.4 if i % 2 else 0.0)
        img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
        res = measure_image((img * 0.45).astype(np.uint8), settings_for(r.fixed_end_px))
        rows.append((abs(res.psi_deg - r.psi_image_deg), res.status))
    within = [err <= 10.0 for err, _ in rows]
    assert sum(within) >= 9, rows
    assert all(err <= 10.0 for err, status in rows if status == "ok"), rows


def test_a_photo_taken_upright_is_measured_like_the_same_photo_taken_across():
    # a camera held upright (a body hanging from its clamp) gives a portrait photo: it was
    # measured at full size, as the work image was chosen by the width alone (960 px < 2 x 640),
    # where the same photo taken across was halved; on the translucent body on grey at psi -220
    # that read -228.7, ok; on rendered analogues turned by 90 deg (5 scenes, seeds 30 and 77,
    # 240 photos) ok but more than 5 deg off went from 18 to 7
    from pipeline.measure.core import decode_for_work, measure_decoded
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("grey_dots_clear", width=1280, height=960)
    r = render_actuator(-220.0, 270.0, scene, seed=77 + 11, bulge=0.4)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    upright = cv2.rotate(img, cv2.ROTATE_90_COUNTERCLOCKWISE)
    x, y = r.fixed_end_px
    data = np.frombuffer(cv2.imencode(".png", upright)[1].tobytes(), np.uint8)
    work, f = decode_for_work(data)
    assert f == decode_for_work(np.frombuffer(r.jpeg_bytes, np.uint8))[1] == 2
    res = measure_decoded(data, work, f, settings_for((y, img.shape[1] - 1 - x)))
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=5.0), (res.psi_deg, res.reason)


def test_the_ridge_does_not_run_through_the_clamp_to_the_tube_behind_it():
    # a selection holding the body (a band leaving the clamp face at x = 300), the clamp block
    # behind the face and the tube behind the block, longer than the body: the farthest pixel is
    # the tube's end, reached only across the block; the ridge follows the body
    from pipeline.measure.body import _ridge_path

    comp = np.zeros((300, 700), np.uint8)
    comp[140:160, 300:520] = 1  # the body, 220 px
    comp[80:220, 220:300] = 1  # the block behind the face
    comp[145:155, 0:220] = 1  # the tube: 220 px + the block's 80
    path, guessed = _ridge_path(comp, cv2.distanceTransform(comp, cv2.DIST_L2, 5), (300.0, 150.0))
    assert not guessed
    assert path[:, 0].min() >= 295 and path[-1, 0] >= 515, (path[0], path[-1])
    # where the tube is the body (no block on the way), the farthest part is taken as before
    comp[80:220, 220:300] = 0
    comp[140:160, 220:300] = 1
    path, _ = _ridge_path(comp, cv2.distanceTransform(comp, cv2.DIST_L2, 5), (300.0, 150.0))
    assert path[-1, 0] <= 5


def test_the_ridge_does_not_run_into_a_plate_that_reaches_the_border():
    # a black plate whose face holds the body and which runs out of the photo at the top and the
    # bottom: its far corners are farther from the fixed end than the body's tip; the ridge
    # follows the body
    from pipeline.measure.body import _ridge_path

    comp = np.zeros((600, 700), np.uint8)
    comp[:, 40:300] = 1  # the plate, its face at x = 300
    comp[290:310, 300:660] = 1  # the body, 360 px
    path, _ = _ridge_path(comp, cv2.distanceTransform(comp, cv2.DIST_L2, 5), (300.0, 300.0))
    assert path[:, 0].min() >= 295 and path[-1, 0] >= 655, (path[0], path[-1])


def test_the_ridge_runs_on_through_a_dot_on_a_stripe_of_the_body():
    # a colour range picked on a translucent body's highlight selects a thin stripe of it, wider
    # where a marker dot sits on it: the widest point on the way to the tip was taken for a
    # clamp block, and the ridge stopped before the dot (a customer's preview read +48.8 deg,
    # ok, for a body curled to 206.6); a block is one by the fixed end
    from pipeline.measure.body import _ridge_path

    comp = np.zeros((300, 400), np.uint8)
    t = np.linspace(0.0, 1.5 * np.pi, 400)
    arc = np.c_[200 + 100 * np.cos(t), 150 - 100 * np.sin(t)]  # from (300, 150), 3/4 of a turn
    cv2.polylines(comp, [np.round(arc).astype(np.int32)], False, 1, 8)
    for a in (2.8, 3.6):  # two dots, 2.75 times as wide as the stripe
        cv2.circle(comp, (int(200 + 100 * np.cos(a)), int(150 - 100 * np.sin(a))), 11, 1, -1)
    path, _ = _ridge_path(comp, cv2.distanceTransform(comp, cv2.DIST_L2, 5), (300.0, 150.0))
    assert np.hypot(*(path[-1] - arc[-1])) <= 6.0, path[-1]


def test_the_march_stops_where_an_oblique_end_face_cuts_the_profile_short():
    # a body's end face at a slant: the last profile crossing it is 15-20 % narrower and its
    # middle slides sideways by 2 px in one 2-px step, a hook that read a 12 MP tip 6 deg high;
    # the march stops at such a step
    from pipeline.measure.body import _march

    soft = np.zeros((100, 300), np.float32)
    face = np.array([[0, 40], [200, 40], [208, 60], [0, 60]], np.float32)  # 20 px wide
    cv2.fillPoly(soft, [np.round(face * 16).astype(np.int32)], 1.0, cv2.LINE_AA, 4)
    pts = np.c_[np.arange(20.0, 181.0), np.full(161, 50.0)]
    out, _, capped = _march(soft, pts, np.full(len(pts), 20.0), 10.0, (20.0, 20.0))
    assert out[-1, 0] >= 196.0 and abs(out[-1, 1] - 50.0) <= 0.5, out[-5:]
    assert not capped  # an end face, not a cap


@pytest.mark.parametrize(
    ("scene", "mm_per_px"), [("grey_dots", 0.6), ("green_fibre", 0.6), ("grey_dots", 0.4)]
)
def test_a_body_in_a_view_that_shows_the_clamp_and_the_tube_is_measured(scene, mm_per_px):
    # the camera further back (0.6 mm/px): the black plate or the white clamp, and the tube
    # behind it, are in the selection, and the tube's end is its farthest point; the centre line
    # ran from the clamp face back through the clamp along the tube (-9 and -10 deg for 215,
    # flagged; 12-19 of 60 rendered photos within 5 deg; now 57-58); at 0.4 mm/px the plate's
    # far corner was the farthest point (-0.9 deg, flagged)
    from pipeline.synth import render_actuator, scene_from

    r = render_actuator(215.0, 270.0, scene_from(scene, mm_per_px=mm_per_px), seed=30)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=5.0), (res.psi_deg, res.reason)


@pytest.mark.parametrize(("psi", "seed"), [(17.3, 35), (-22.3, 36), (-62.0, 37)])
def test_a_fat_body_is_read_from_its_own_middle_at_the_clamp_face(psi, seed):
    # a translucent body 25 mm wide in a clamp block hardly wider: profiles at the clamp face
    # reached into the block and the centre line hooked towards its side, so the base was read
    # 6-8 deg off either way (10.0, -15.9 and -69.6 deg, all ok)
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("dark_translucent", body_width_mm=25.0)
    r = render_actuator(psi, 270.0, scene, seed=seed, bulge=0.4 if seed % 2 else 0.0)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert abs(res.base_direction_deg) <= 2.0, (res.base_direction_deg, res.reason)
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=2.5), (res.psi_deg, res.reason)


@pytest.mark.parametrize(("psi", "seed"), [(175.6, 31), (135.9, 32)])
def test_a_fat_bodys_march_stops_where_it_swings_into_the_cap(psi, seed):
    # a translucent body 25 mm wide: the last steps of the march to the free end reached into
    # the cap's profile, widened and swung sideways, and the tip read 6-7 deg high (182.5 and
    # 141.7 deg, both ok)
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("dark_translucent", body_width_mm=25.0)
    r = render_actuator(psi, 270.0, scene, seed=seed, bulge=0.4 if seed % 2 else 0.0)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
    res = measure_image(img, settings_for(r.fixed_end_px))
    assert res.psi_deg == pytest.approx(r.psi_image_deg, abs=3.0), (res.psi_deg, res.reason)


@pytest.mark.parametrize(
    ("length", "psi"),
    [(250.0, 150.0), (250.0, -150.0), (300.0, -150.0), (300.0, 220.0), (300.0, -220.0),
     (200.0, 120.0)],
)
def test_a_short_thick_body_bent_tightly_is_read_to_its_square_end(length, psi):
    # a body 50 px wide and 4-6 widths long (a PneuNet): its profiles stop about half a width
    # short of the square end face, over which it still turns 5-15 deg, and a fixed end given on
    # its edge measured its base 2-5 deg off: psi read 4-11 deg off, all ok.  The face's normal
    # is the tip's direction (noted), the base is measured square to the face through fixed_end
    seed = 1 + int(psi) % 7
    img, fe, _ = body_photo(psi, length=length, width=50.0, seed=seed)
    res = measure_image(img, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=2.5), res.reason
    assert NOTE_TIP_FACE in res.reason


@pytest.mark.parametrize("slant", [-20.0, -10.0, 10.0, 20.0])
def test_an_end_face_cut_at_a_slant_is_not_taken_for_the_tips_direction(slant):
    # its normal is the tip's direction turned by the slant: taken for it, psi read up to 29 deg
    # off, ok; the two long edges beside it show it is not square to the body
    img, fe, _ = body_photo(-150.0, length=300.0, width=50.0, seed=1, tip_slant_deg=slant)
    res = measure_image(img, settings_for(fe))
    assert NOTE_TIP_FACE not in res.reason, res.reason


def chambered_photo(psi_deg, *, length=320.0, width=64.0, chambers=8, gap=8.0, seed=0):
    """A PneuNet seen from the side: a strip (the layer that does not stretch, a quarter of the
    width) carrying ``chambers`` blocks on the outside of the bend, ``gap`` px apart along the
    layer (their gaps open towards the top as the body bends), leaving a dark clamp along +x.
    Returns (image, fixed end pixel: the layer at the clamp face)."""
    k = np.deg2rad(psi_deg) / length
    side = -1.0 if k > 0 else 1.0  # the chambers lie away from the bend's centre

    def at(s, off):
        s = np.asarray(s, float)
        x, y = (s, 0 * s) if abs(k) < 1e-12 else (np.sin(k * s) / k, (1 - np.cos(k * s)) / k)
        n = np.c_[-np.sin(k * s), np.cos(k * s)]
        return np.c_[x, y] + side * n * off

    layer = 0.25 * width
    s = np.linspace(0.0, length, 600)
    polys = [np.r_[at(s, 0.0), at(s[::-1], layer)]]
    pitch = (length + gap) / chambers  # the last chamber's end wall is the strip's end
    for i in range(chambers):
        ss = np.linspace(i * pitch, (i + 1) * pitch - gap, 60)
        polys.append(np.r_[at(ss, 0.8 * layer), at(ss[::-1], width)])
    off = np.array([W / 2 - length / 2, H / 2])

    def to_px(q):
        return np.c_[q[:, 0], -q[:, 1]] + off

    img = np.empty((H, W, 3), np.uint8)
    img[:] = (190, 196, 200)
    pink = (150, 90, 210)
    for q in polys:
        cv2.fillPoly(img, [np.round(to_px(q) * 16).astype(np.int32)], pink, cv2.LINE_AA, 4)
    clamp = to_px(np.array([[-60.0, -width - 20], [0.0, -width - 20], [0.0, width + 20],
                            [-60.0, width + 20]]))
    cv2.fillPoly(img, [np.round(clamp * 16).astype(np.int32)], (40, 40, 44), cv2.LINE_AA, 4)
    rng = np.random.default_rng(seed)
    img = np.clip(img + rng.normal(0.0, 2.0, img.shape), 0, 255).astype(np.uint8)
    return img, tuple(to_px(np.zeros((1, 2)))[0])


@pytest.mark.parametrize("psi", [180.0, 240.0, -240.0])
def test_a_pneunets_chambers_are_measured_as_one_body(psi):
    # customer 48: the gaps between a PneuNet's chambers reach down to the strip under them, and
    # the ridge of the selection zig-zagged into every chamber and out through the strip (no
    # photo above 10 kPa ok, psi up to +1162 deg; these read -19.9, -145.5 and +405.0 deg off).
    # The gaps are filled, the tip is read on the last chamber's flat end face and the base is
    # the direction given
    img, fe = chambered_photo(psi, seed=int(abs(psi)))
    res = measure_image(img, settings_for(fe, fixed_direction_deg=0.0))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=2.0), res.reason
    assert NOTE_TIP_FACE in res.reason


@pytest.mark.parametrize("psi", [180.0, 240.0, -240.0])
def test_a_pneunet_leaves_the_clamp_along_its_strip(psi):
    # the review of stop 56: a chambered body's own base was not read (its centre line starts
    # on its first chamber), so a fixed_direction_deg 25 deg off gave rows ok and 25 deg off.
    # The strip's edge says how it leaves the clamp, and checks the direction given
    for seed in (int(abs(psi)),):
        img, fe = chambered_photo(psi, seed=seed)
        right = measure_image(img, settings_for(fe, fixed_direction_deg=0.0))
        assert right.status == "ok", right.reason
        assert right.base_direction_deg == pytest.approx(0.0, abs=3.0)
        off = measure_image(img, settings_for(fe, fixed_direction_deg=25.0))
        assert off.status == "flagged", off.reason
        assert "leaves the clamp" in off.reason and "off fixed_direction_deg" in off.reason
        # without the direction the row says to give it
        assert measure_image(img, settings_for(fe)).status == "flagged"


def test_a_pneunet_is_never_an_ok_psi_far_off():
    # where the centre line of the filled chambers stops more than a width short of the tip,
    # the face is not taken (a faint tip ends the same way) and the row is flagged, as is one
    # whose tip face is not shown square; before, 60 and -60 read -4.8 and +3.1 deg off, ok
    for psi in (30.0, 60.0, 90.0, 120.0, 150.0, 200.0, -60.0, -90.0, -120.0, -150.0, -200.0):
        img, fe = chambered_photo(psi, seed=int(abs(psi)))
        res = measure_image(img, settings_for(fe, fixed_direction_deg=0.0))
        assert res.status != "ok" or abs(res.psi_deg - psi) <= 2.5, (psi, res.psi_deg, res.reason)


def test_the_realscenes_bench_turns_its_analogues_upright():
    # bench realscenes --upright: the photos turned to portrait with their fixed ends and empty
    # scenes, psi unchanged (a fixed end left where it was would land off the body)
    from pipeline.bench.realscenes import body_cases

    df = body_cases(2, scenes=("lab_body",), upright=True, background=True, shared_base=False)
    assert (df["error_deg"].abs() <= 5.0).all() and (df["status"] == "ok").all(), df
    # and the clamp's known direction turned with them
    df = body_cases(2, scenes=("lab_body",), upright=True, fixed_direction=True, shared_base=False)
    assert (df["error_deg"].abs() <= 5.0).all(), df


def test_the_realscenes_bench_measures_from_the_direction_given_as_measure_does():
    # with fixed_direction_deg given, psi is measured from it and the ramp's shared base only
    # compares (ramp_check._compare_given); the bench left the column out, and its shared base
    # re-measured the analogue at +96 deg from the others' median: 106.8 (ok) where measure
    # reads 99.2
    from pipeline.bench.realscenes import body_cases
    from pipeline.ramp_check import share_base_direction

    # body_cases(shared_base=True) is these photos measured once, then this step
    own = body_cases(12, scenes=("grey_dots_clear",), fixed_direction=True, camera="auto",
                     shared_base=False)
    shared = share_base_direction(own, keys=("scene",))
    assert shared["psi_deg"].tolist() == own["psi_deg"].tolist(), (shared, own)


def test_translucent_body_on_grey_without_a_background_photo():
    # the rendered analogue of silicone with dots on a grey backdrop, no empty-scene photo: the
    # faint side of the body fades towards the tip; measured to its end, not cut where it thins
    # (each photo on its own: the ramp's shared base direction is tested on its own)
    from pipeline.bench.realscenes import body_cases

    d = body_cases(12, scenes=("grey_dots_clear",), shared_base=False)
    ok = d[d["status"] == "ok"]
    assert int((ok["error_deg"].abs() <= 5.0).sum()) >= 6, d.to_string()
    assert ok["error_deg"].abs().max() <= 8.0, d.to_string()
    # where the centre line stops short of a fading tip, psi is carried on along the selection
    # (the row stays flagged): the photo at -102 deg read -56 before, now within 10 deg
    carried = d[d["reason"].str.contains("psi is carried on along the selection")]
    assert len(carried) and (carried["status"] == "flagged").all(), d.to_string()
    assert d["error_deg"].abs().max() <= 10.0, d.to_string()


TUBE_PX = 330


@pytest.mark.parametrize("psi", [120.0, -200.0])
def test_a_long_thin_tube_through_the_clamp_does_not_set_the_body_width(psi):
    # the tube, the clamp and the body are one selected component; the body's half-width is read
    # along its own ridge, not over the whole component (where the tube's would win)
    img, fe, clamp = body_photo(psi, length=500.0, width=46.0, seed=5)
    (x0, y0), (x3, y3) = clamp[0], clamp[3]
    y_mid = round((y0 + y3) / 2)
    x_clamp = int(min(x0, x3))
    cv2.line(img, (x_clamp, y_mid), (x_clamp - TUBE_PX, y_mid), (90, 140, 200), 9, cv2.LINE_AA)
    res = measure_image(img, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=3.0), res.reason


def test_a_tube_longer_than_the_body_is_never_an_ok_psi():
    # the farthest point from the fixed end is then the tube's end: flagged, not measured as psi
    img, fe, clamp = body_photo(120.0, length=300.0, width=46.0, seed=5, shift=(250.0, 0.0))
    (x0, y0), (x3, y3) = clamp[0], clamp[3]
    y_mid = round((y0 + y3) / 2)
    cv2.line(img, (int(min(x0, x3)), y_mid), (0, y_mid), (90, 140, 200), 12, cv2.LINE_AA)
    res = measure_image(img, settings_for(fe))
    assert res.status != "ok" or res.psi_deg == pytest.approx(120.0, abs=5.0), res.reason


def test_realscenes_bench_prints_its_tables_at_the_size_asked(capsys):
    from pipeline.bench.realscenes import main

    args = ["--n", "1", "--size", "640x360", "--no-fixed-direction", "--dev-set", "/nonexistent"]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "median time per 640x360 photo" in out
    assert "fixed_direction_deg given" not in out
    for scene in ("green_fibre", "grey_dots", "grey_dots_clear", "dark_translucent", "lab_body"):
        assert scene in out
    with pytest.raises(SystemExit):
        main(["--size", "wide"])
    with pytest.raises(SystemExit):
        main(["--fixed-end-offset", "left"])
    assert main(args + ["--camera", "dark", "--fixed-end-offset=-20,0"]) == 0
    out = capsys.readouterr().out
    assert "camera dark, fixed end moved by (-20, 0) px" in out
    assert main(args + ["--sealed-end-mm", "8", "--give-sealed-end"]) == 0
    out = capsys.readouterr().out
    assert "sealed end 8 mm, sealed_end_mm given" in out and "median signed error" in out


def test_a_fixed_end_moved_into_the_clamp_moves_the_bench_cases():
    # the bench's --fixed-end-offset reaches the measurement (a user's click into the clamp)
    from pipeline.bench.realscenes import body_cases

    at_face = body_cases(1, scenes=("lab_body",), width=640, height=480)
    moved = body_cases(1, scenes=("lab_body",), width=640, height=480,
                       fixed_end_offset_px=(-200.0, 0.0))
    assert at_face["status"].iloc[0] == "ok"
    assert moved["status"].iloc[0] == "flagged"
    assert "no body reaches fixed_end" in moved["reason"].iloc[0]


def _long_sealed_end_cases(give: bool, scale: bool = True):
    from pipeline.bench.realscenes import body_cases

    return body_cases(
        4, scenes=("grey_dots", "lab_body"), sealed_end_mm=12.0, give_sealed_end=give, seed=31,
        give_scale=scale,
    )


def test_a_long_sealed_end_read_where_the_bending_stops_when_its_length_is_given():
    # a 12 mm sealed end: the centre line runs on into it and its tangent carries the curvature on
    # over a part that does not bend (|psi| > 150 read 5-14 deg high, ok); given sealed_end_mm,
    # the tip is read where the bending stops
    unknown, given = _long_sealed_end_cases(False), _long_sealed_end_cases(True)
    big = unknown["psi_true_deg"].abs() > 150
    over = unknown["error_deg"] * np.sign(unknown["psi_true_deg"])
    assert over[big].median() > 4.0
    # each such row says so (customer 37: 36 of 116 rows ok 5-7 deg off, their reasons empty);
    # given, none does
    assert unknown.loc[big, "reason"].str.startswith("no sealed_end_mm: psi read where").all()
    assert not given["reason"].fillna("").str.contains("no sealed_end_mm").any()
    assert (given["status"] == "ok").all(), given["reason"].tolist()
    # the tangent is fitted over the part that bends, up to where it stops: over a window
    # reaching into the straight sealed end it read up to 4.9 deg low (customer 17: 5.0)
    assert given["error_deg"].abs().max() < 2.5 and given["error_deg"].abs().median() < 2.0
    # without mm_per_px it is turned into pixels with the body's length against l0_mm +
    # sealed_end_mm (it was refused: "needs the image scale")
    unscaled = _long_sealed_end_cases(True, scale=False)
    assert (unscaled["status"] == "ok").all(), unscaled["reason"].tolist()
    assert unscaled["error_deg"].abs().max() < 5.5 and unscaled["error_deg"].abs().median() < 2.0


def test_the_bodys_shadow_is_not_selected_with_a_background_photo(tmp_path):
    # a rendered green_fibre ramp with its empty-scene photo: the shadow the body casts differs
    # from the empty scene too, and was selected with the body, widening it on one side and round
    # its tip (ok rows up to 15 deg off, the median 5.4); a shadow dims the backdrop and keeps its
    # colour, so it is left out
    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth.photoset_writer import render_photoset

    truth = render_photoset(
        tmp_path / "s", "DS20", actuators=1, trials=1, seed=2, scene="green_fibre", step_kpa=45,
        max_kpa=180, scene_overrides={"width": 1280, "height": 960},
    )
    settings = tmp_path / "s" / "photoset.yaml"  # its sealed end and cap (else flagged for it)
    settings.write_text(settings.read_text() + "sealed_end_mm: 10\n")
    got = measure_photoset(tmp_path / "s", ramp_check=False).merge(
        truth[["image", "psi_image_deg"]], on="image"
    )
    err = (got["psi_deg"] - got["psi_image_deg"]).abs()
    assert (got["status"] == "ok").all(), got["reason"].tolist()
    assert err.max() < 7.5 and err.median() < 3.5, err.round(1).tolist()


def _band_photo(body_bgr, shadow_bgr=None):
    """A 200-grey empty scene and the same with a horizontal body band (rows 40-59) and, below
    it, a band of ``shadow_bgr`` (rows 60-74)."""
    empty = np.full((120, 300, 3), 200, np.uint8)
    photo = empty.copy()
    photo[40:60, 30:270] = body_bgr
    if shadow_bgr is not None:
        photo[60:75, 30:270] = shadow_bgr
    return photo, empty


def test_a_shadow_beside_the_body_is_left_out_but_a_neutral_grey_body_is_kept():
    from pipeline.measure.body import body_mask

    settings = settings_for((30.0, 50.0))
    photo, empty = _band_photo((60, 60, 200), shadow_bgr=(150, 150, 150))
    mask = body_mask(photo, settings, background_bgr=empty).mask
    assert mask[40:60, 40:260].all() and not mask[62:75, 40:260].any()
    # a neutral grey body darker than a neutral backdrop looks like a shadow all over: kept
    photo, empty = _band_photo((110, 110, 110))
    mask = body_mask(photo, settings, background_bgr=empty).mask
    assert mask[40:60, 40:260].all()


def test_a_shadow_is_left_out_against_the_empty_scene_estimated_from_the_ramp(tmp_path):
    # the second look measures a doubtful body against the empty scene estimated from its
    # ramp's photos; the body's shadow was kept there (customer 23's opaque body curled to
    # +213 deg read 6.8 deg high, ok), so it is told from the body as against an empty-scene
    # photo, where the estimate shows the backdrop
    import dataclasses

    import cv2

    from pipeline.measure.body import body_mask

    photo, empty = _band_photo((60, 60, 200), shadow_bgr=(150, 150, 150))
    estimate = tmp_path / "estimate.png"
    cv2.imwrite(str(estimate), empty)
    settings = dataclasses.replace(
        settings_for((30.0, 50.0)), background_path=str(estimate), background_estimated=True
    )
    mask = body_mask(photo, settings, background_bgr=empty).mask
    assert mask[40:60, 40:260].all() and not mask[62:75, 40:260].any()


def test_the_realscenes_bench_gives_each_analogue_its_empty_scene_when_asked():
    # --background: the translucent body on grey is found whole against its empty scene (without
    # it 2 of these 4 photos are flagged, up to 10.6 deg off).  Since its faint side is taken in
    # (stop 61) two of them read 1.3-1.7 deg further off at this small size (69.8 as 74.7, -220
    # as -224.6; max 3.65 before), still under 5; at 1280x960 the bench's --background column
    # went from 1 row ok over 5 deg off to 0
    from pipeline.bench.realscenes import body_cases

    d = body_cases(4, scenes=("grey_dots_clear",), width=640, height=480, background=True)
    assert (d["status"] == "ok").all(), d["reason"].tolist()
    assert d["error_deg"].abs().max() < 5.0, d["error_deg"].tolist()


def test_a_noisy_photo_and_its_noisy_empty_scene_are_smoothed_before_they_are_compared():
    # sensor noise of 8 grey levels in the photo and in its empty scene: their difference is
    # noisier than either, and the translucent body's faint side was lost in it (ok rows 8.5 and
    # 9 deg off); both are smoothed first when the difference is that noisy
    from pipeline.bench.realscenes import body_cases

    d = body_cases(6, scenes=("grey_dots_clear",), background=True, camera="noise")
    ok = d[d["status"] == "ok"]
    assert len(ok) >= 5 and ok["error_deg"].abs().max() < 6.5, d.to_string()


@pytest.mark.parametrize("exposure", [0.9, 1.15])
def test_an_empty_scene_taken_at_another_exposure_is_matched_to_the_photo(exposure):
    # a camera that sets its own exposure takes the empty scene 10-15 % darker or lighter: the
    # whole backdrop then differed from it (20-28 of 60 analogues right; here 3 and 6 of 9 ok,
    # up to 102 deg off); its channels are scaled to the photo's exposure first
    from pipeline.bench.realscenes import body_cases

    d = body_cases(3, scenes=("grey_dots", "dark_translucent", "green_fibre"), width=800,
                   height=600, background=True, background_exposure=exposure)
    # at 800x600 the bodies' ends at +-220 deg read up to 5.6 deg high at the same exposure
    assert (d["status"] == "ok").all(), d["reason"].tolist()
    assert d["error_deg"].abs().max() < 8.0, d["error_deg"].tolist()


def test_a_ramps_bodies_are_measured_from_its_one_base_direction(tmp_path):
    # a rendered 720p green_fibre ramp without its empty scene: the start of the centre line,
    # next to the clamp, is tilted by the body's shadow and bulge by up to 3 deg in one photo
    # and not the next, and 5 of 38 photos were `ok` but more than 5 deg off; the clamp holds
    # the base in one direction, so the ramp check measures every photo from the ramp's median
    # (4 -> 1 of them; since the clamp face's profiles are left out, FACE_WIDTH_HIGH, 3 -> 2:
    # the base is steadier by itself, and the two left are off at their free ends, which the
    # check cannot mend).  Since a line stopping a width short of a tip that still turns is
    # flagged as a faint tip (FAINT_TIP_SHORT_WIDTHS), two right rows here are (2.9 and 3.7 deg
    # off, where the cap hides the tip): the rule's cost, 1 more in 170 other photos of 4 ramps
    from pipeline.photoset_measure import measure_photoset
    from pipeline.ramp_check import check_ramps
    from pipeline.synth.photoset_writer import render_photoset

    folder = tmp_path / "s"
    truth = render_photoset(
        folder, "DS20", actuators=1, trials=2, seed=2, scene="green_fibre", step_kpa=20,
        max_kpa=180, scene_overrides={"width": 1280, "height": 720},
    )
    yaml = (folder / "photoset.yaml").read_text()
    (folder / "photoset.yaml").write_text(
        "".join(line for line in yaml.splitlines(keepends=True) if "background" not in line)
        + "sealed_end_mm: 10\n"  # its sealed end and cap (else the bent rows are flagged for it)
    )
    scores = {}
    measured = measure_photoset(folder, ramp_check=False)  # measure_photoset's check is this
    for ramp_check in (False, True):
        got = (check_ramps(measured) if ramp_check else measured).merge(
            truth[["image", "psi_image_deg"]], on="image"
        )
        wrong = (got["psi_deg"] - got["psi_image_deg"]).abs() > 5.0
        scores[ramp_check] = int(((got["status"] == "ok") & wrong).sum())
        if ramp_check:
            assert got.groupby("trial")["base_direction_deg"].nunique().eq(1).all()  # one clamp
            assert got["reason"].str.contains("deg against its ramp's base direction").any()
            short = got["reason"].str.contains("short of the body's free end", regex=False)
            assert ((got["status"] == "ok") | short).all(), got["reason"].tolist()
            assert short.sum() <= 2, got.loc[short, "reason"].tolist()
    # since the body's shadow is left out without an empty scene (backdrop_shadows) its bases
    # agree by themselves: 3 -> 1 wrong `ok` row before the check, 2 -> 1 after it; the one
    # left is off at its free end, which the check cannot mend
    assert scores[True] <= scores[False] <= 1, scores


def test_a_camera_turned_mid_ramp_is_not_measured_from_the_ramps_first_direction(tmp_path):
    # the last 4 photos of a ramp were taken after the camera turned by 9 deg about the clamp:
    # psi is unchanged by that, but measured against the first photos' base direction it would
    # read 9 deg off, `ok`; the ramp check splits the ramp where its base direction moved
    import pandas as pd

    from pipeline.photoset import write_manifest
    from pipeline.photoset_measure import measure_photoset

    psis = np.linspace(150.0, -150.0, 11)
    rows = []
    for i, psi in enumerate(psis):
        img, fe, _ = body_photo(float(psi), seed=i)
        if i >= 7:
            turn = cv2.getRotationMatrix2D(fe, 9.0, 1.0)
            img = cv2.warpAffine(img, turn, (W, H), borderMode=cv2.BORDER_REPLICATE)
        cv2.imwrite(str(tmp_path / f"p{i:02d}.png"), img)
        rows.append({"image": f"p{i:02d}.png", "pressure_kpa": 10 * i, "direction": "up",
                     "material": "DS20", "actuator": "A1", "trial": 1, "step": i,
                     "fixed_end_x": fe[0], "fixed_end_y": fe[1]})
    write_manifest(tmp_path, pd.DataFrame(rows))
    (tmp_path / "photoset.yaml").write_text("l0_mm: 180\ntarget: body\n")
    got = measure_photoset(tmp_path)
    assert (got["status"] == "ok").all(), got["reason"].tolist()
    assert (got["psi_deg"] - psis).abs().max() < 2.5, (got["psi_deg"] - psis).round(1).tolist()
    moved = got["reason"].iloc[7:].str.contains("+9 deg off the ramp's first photos", regex=False)
    assert moved.all(), got["reason"].tolist()


@pytest.mark.parametrize("case", ["one clamp", "one clamp, a bad row", "free strips"])
def test_bodies_leaving_one_clamp_in_scattered_directions_are_flagged(tmp_path, case):
    # customer 42's pale body lost its shaded side at the clamp in some photos against its
    # empty scene: the bases of its ramps scattered by 3.1-3.6 deg (median absolute deviation)
    # under one clamp, and each psi, measured from its own, was `ok` up to 10 deg off.  Here the
    # bodies leave the clamp turned by up to 7 deg: under one fixed end that is no base to
    # measure from; free strips (a fixed end per row) are each measured from their own
    import pandas as pd

    from pipeline.photoset import write_manifest
    from pipeline.photoset_measure import measure_photoset

    one_fixed_end = case != "free strips"
    psis = np.linspace(120.0, -120.0, 8)
    turns = [0.0, 6.0, -5.0, 7.0, -6.0, 5.0, -7.0, 0.5]
    rows = []
    for i, (psi, turn) in enumerate(zip(psis, turns, strict=True)):
        img, fe, clamp = body_photo(float(psi), seed=i, clamp=False)
        if one_fixed_end:  # the clamp where the straight body's is; else where each is centred
            shift = np.array([W / 2 - 300.0, H / 2 - 23.0]) - np.array(fe)
            img, fe, clamp = body_photo(float(psi), seed=i, clamp=False, shift=tuple(shift))
            fe = (fe[0] + 0.3 * (i % 2), fe[1])  # clicked on each photo: a fraction of a px off
        img = cv2.warpAffine(img, cv2.getRotationMatrix2D(fe, turn, 1.0), (W, H),
                             borderMode=cv2.BORDER_REPLICATE)
        cv2.fillPoly(img, [np.round(np.array(clamp) * 16).astype(np.int32)], (60, 60, 66),
                     cv2.LINE_AA, 4)
        cv2.imwrite(str(tmp_path / f"p{i:02d}.png"), img)
        rows.append({"image": f"p{i:02d}.png", "pressure_kpa": 10 * i, "direction": "up",
                     "material": "DS20", "actuator": "A1", "trial": 1, "step": i,
                     "fixed_end_x": fe[0], "fixed_end_y": fe[1]})
    if case == "one clamp, a bad row":  # a typo: that row fails, the ramp is checked still
        cv2.imwrite(str(tmp_path / "p08.png"), img)
        rows.append({**rows[-1], "image": "p08.png", "pressure_kpa": "8O", "step": 8})
    write_manifest(tmp_path, pd.DataFrame(rows))
    (tmp_path / "photoset.yaml").write_text("l0_mm: 180\ntarget: body\n")
    got = measure_photoset(tmp_path)
    measured = got.iloc[:8]
    assert (measured["psi_deg"] - psis).abs().max() < 2.5, (measured["psi_deg"] - psis).tolist()
    scattered = measured["reason"].str.startswith(
        "the bodies of this ramp leave its one fixed_end in directions that scatter by"
    )
    if one_fixed_end:
        assert (measured["status"] == "flagged").all() and scattered.all(), got["reason"].tolist()
        assert "Give fixed_direction_deg, the clamp's direction" in got["reason"].iloc[0]
        assert got["status"].iloc[8:].eq("failed").all()
    else:
        assert (got["status"] == "ok").all() and not scattered.any(), got["reason"].tolist()


@pytest.mark.parametrize("turn, base", [("ccw", 90.0), ("cw", -90.0)])
def test_a_body_reports_the_direction_it_leaves_the_fixed_end_in_psis_sense(turn, base):
    # the photo turned a quarter counter-clockwise: the body leaves its clamp upwards on screen
    img, fe, _ = body_photo(120.0, seed=3)
    turned = cv2.rotate(img, cv2.ROTATE_90_COUNTERCLOCKWISE)
    fixed_end = (fe[1], img.shape[1] - 1 - fe[0])
    res = measure_image(turned, settings_for(fixed_end, positive_turn=turn))
    assert res.status == "ok", res.reason
    assert res.base_direction_deg == pytest.approx(base, abs=2.0)
    assert res.psi_deg == pytest.approx(120.0 if turn == "ccw" else -120.0, abs=2.5)
    # with the direction given psi is measured from it, and the body's own is still reported
    # (in psi's sense: it leaves upwards, +90 on screen, read -90 with positive_turn cw)
    given = measure_image(
        turned, settings_for(fixed_end, positive_turn=turn, fixed_direction_deg=90.0)
    )
    assert given.base_direction_deg == pytest.approx(res.base_direction_deg, abs=1e-6)


@pytest.mark.parametrize("bits", [10, 12, 16])
def test_a_scientific_cameras_16_bit_photo_is_measured_and_picked_like_its_8_bit_export(
    tmp_path, capsys, bits
):
    # a 16-bit PNG holding 10 or 12 bits: OpenCV's 8-bit decoding keeps the top 8 of 16 bits, so
    # 12-bit data came out in grey levels 0-15 (on a rendered 720p ramp set: 37 ok and right of 38
    # as 8-bit JPEGs, 27 as 12-bit PNGs with 10 flagged; now 36)
    from pipeline.cli import main
    from pipeline.measure.core import measure_file

    img, fe, _ = body_photo(-120.0, texture=True, seed=4)
    cv2.imwrite(str(tmp_path / "eight.png"), img)
    scale = ((1 << bits) - 1) / 255.0
    cv2.imwrite(str(tmp_path / "wide.png"), np.round(img * scale).astype(np.uint16))
    eight, _ = measure_file(tmp_path / "eight.png", settings_for(fe))
    wide, _ = measure_file(tmp_path / "wide.png", settings_for(fe))
    assert eight.status == wide.status == "ok", (eight.reason, wide.reason)
    assert abs(wide.psi_deg - eight.psi_deg) < 0.5 and abs(wide.psi_deg + 120.0) < 2.5
    on_body = f"{fe[0] + 40:.0f},{fe[1] - 23:.0f}"
    picked = []
    for name in ("eight.png", "wide.png"):
        assert main(["photoset", "pick-color", str(tmp_path / name), "--at", on_body]) == 0
        picked.append(capsys.readouterr().out.splitlines()[0])
    assert picked[0] == picked[1] and picked[0].startswith("line_color:"), picked


def test_measure_says_which_method_auto_took_for_a_body(tmp_path, capsys):
    # a customer's body set printed "method auto" while every row said tangents
    from pipeline.cli import main

    img, fe, _ = body_photo(100.0, seed=5)
    cv2.imwrite(str(tmp_path / "p.png"), img)
    (tmp_path / "photoset.yaml").write_text(
        f"l0_mm: 180\ntarget: body\nfixed_end: [{fe[0]:.1f}, {fe[1]:.1f}]\n"
    )
    (tmp_path / "manifest.csv").write_text(
        "image,pressure_kpa,direction,material,actuator,trial\np.png,0,up,DS20,A1,1\n"
    )
    assert main(["measure", str(tmp_path), "--out", str(tmp_path / "a.csv")]) == 0
    assert "method auto (rows say which it took: tangents) ->" in capsys.readouterr().out


def _centre_point_back_from_face(psi, back_px, length=600.0, width=46.0):
    """The point ``back_px`` back along the centre line from the end face of :func:`body_photo`'s
    body (world frame: y up, fixed end at the origin)."""
    k = np.deg2rad(psi) / length
    stretch = 1.0 - k * width / 2  # the centre line's length per unit of the lower edge's
    s = length - back_px / stretch
    p = np.array([np.sin(k * s) / k, (1 - np.cos(k * s)) / k])
    return p + np.array([-np.sin(k * s), np.cos(k * s)]) * width / 2


@pytest.mark.parametrize("psi", [120.0, -200.0])
def test_a_body_says_where_and_in_which_direction_its_tip_was_read(psi):
    # the overlays draw psi's two directions: the base's and the tip's, from where the tip was
    # read, so that a user sees psi as the turn between two lines (and a sealed_end_mm given too
    # short as a tip read inside the cap)
    from pipeline.measure.overlay import screen_directions

    img, fe, _ = body_photo(psi, seed=3)

    def on_screen(p):
        return np.array([p[0], -p[1]]) + fe

    cut = measure_image(img, settings_for(fe, free_end="bends"))
    base, tip = screen_directions(cut, settings_for(fe))
    assert cut.status == "ok", cut.reason
    assert base == pytest.approx(0.0, abs=2.5) and tip == pytest.approx(psi, abs=3.0)
    face = on_screen(_centre_point_back_from_face(psi, 0.0))
    assert np.hypot(*(np.asarray(cut.tip_px) - face)) < 6.0, (cut.tip_px, face)
    # a sealed end of 20 mm at 0.5 mm per px: read 40 px back from the face (its flat face is
    # not read where the end that does not bend is given)
    sealed = measure_image(img, settings_for(fe, sealed_end_mm=20.0, mm_per_px=0.5))
    back = on_screen(_centre_point_back_from_face(psi, 40.0))
    assert np.hypot(*(np.asarray(sealed.tip_px) - back)) < 6.0, (sealed.tip_px, back)
    _, tip = screen_directions(sealed, settings_for(fe))
    assert tip is not None and tip - psi == pytest.approx(-40.0 / 600.0 * psi, abs=3.0)
    assert NOTE_TIP_FACE not in sealed.reason


def test_the_overlay_draws_the_tip_direction_from_where_it_was_read(tmp_path):
    from pipeline.measure.worker import write_overlay

    img, fe, _ = body_photo(120.0, seed=3)
    settings = settings_for(fe, free_end="bends")
    res = measure_image(img, settings)
    write_overlay(str(tmp_path / "o.jpg"), img, 1, res, "t", settings)
    drawn = cv2.imread(str(tmp_path / "o.jpg")).astype(int)
    k = drawn.shape[1] / img.shape[1]  # the overlay is reduced
    band = drawn.shape[0] - round(img.shape[0] * k)  # the text above the photo
    a = np.deg2rad(120.0)
    for along in (15.0, 40.0):  # px of the overlay along the tip's line
        x, y = np.asarray(res.tip_px) * k + along * np.array([np.cos(a), -np.sin(a)])
        near = drawn[band + round(y) - 1 : band + round(y) + 2, round(x) - 1 : round(x) + 2]
        blue = (near[..., 0] - near[..., 2] > 80) & (near[..., 0] - near[..., 1] > 40)
        assert blue.any(), (x, y, near.tolist())


def test_the_preview_shows_a_bodys_ends_enlarged(tmp_path):
    # a sealed end or a clamp's direction on a 12 MP photo is a few pixels of the preview's
    # tile: two more panels show the fixed end (its mark and the base's line) and the free end
    # (the dot where its tangent was read) enlarged, each in the middle
    from pipeline.preview import TILE_WIDTH_PX, preview_tile, write_preview

    img, fe, _ = body_photo(150.0, seed=5)
    cv2.imwrite(str(tmp_path / "b.jpg"), img)
    settings = settings_for(fe, sealed_end_mm=20.0, mm_per_px=0.5)
    tile = preview_tile(tmp_path / "b.jpg", settings, title="t")
    assert tile.shape[1] == 4 * TILE_WIDTH_PX
    height = TILE_WIDTH_PX * H // W
    fixed, free = (tile[-height:, k * TILE_WIDTH_PX : (k + 1) * TILE_WIDTH_PX].astype(int)
                   for k in (2, 3))

    def blue(part):
        return (part[..., 0] > 200) & (part[..., 2] < 60)

    c = (height // 2, TILE_WIDTH_PX // 2)
    assert blue(free[c[0] - 2 : c[0] + 3, c[1] - 2 : c[1] + 3]).any()  # the dot
    # the mark, a ring about the fixed end, and the base's line from it along the body (+x)
    assert blue(fixed[c[0] - 1 : c[0] + 2, c[1] - 8 : c[1] - 3]).any()
    assert blue(fixed[c[0] - 1 : c[0] + 2, c[1] + 40 : c[1] + 60]).any()
    # the body fills them: 5 of its widths across (46 px of 1280), not the whole photo
    for panel in (fixed, free):
        body = (np.abs(panel - np.array([90, 140, 200])).sum(axis=2) < 60).mean()
        assert 0.1 < body < 0.7, body
    # a sheet of such tiles has one to a row
    (tmp_path / "manifest.csv").write_text(
        "image,pressure_kpa,direction,material,actuator,trial\nb.jpg,0,up,DS20,A1,1\n"
    )
    (tmp_path / "photoset.yaml").write_text(
        f"l0_mm: 180\ntarget: body\nfixed_end: [{fe[0]:.1f}, {fe[1]:.1f}]\n"
    )
    path, n = write_preview(tmp_path, tmp_path / "p.png")
    assert n == 1 and cv2.imread(str(path)).shape[1] == 4 * TILE_WIDTH_PX


def test_a_sealed_end_given_without_its_cap_is_not_carried_on_over_the_cap():
    # the fibre-wound body's sealed end is 4 mm and its white cap 6 mm: given as 4 (the cap
    # forgotten), the tip's tangent was carried on over the cap, which does not bend (psi 12 deg
    # high, ok); the centre line stops where the body widens into the cap, and psi is not
    # carried past it: as if no sealed end had been given.  Given cap included, it is right.
    from pipeline.measure.body import extract_body
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("green_fibre", width=1600, height=1200)
    r = render_actuator(215.0, 200.0, scene, seed=3)
    img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)

    def error(**kw):
        settings = resolve_settings(l0_mm=200.0, target="body", fixed_end=list(r.fixed_end_px),
                                    mm_per_px=scene.mm_per_px, **kw)
        res = measure_image(img, settings)
        assert res.status == "ok", res.reason
        return res.psi_deg - r.psi_image_deg

    forgotten, none = error(sealed_end_mm=scene.sealed_end_mm), error()
    assert abs(forgotten - none) < 0.5 and abs(forgotten) < 8.0, (forgotten, none)
    assert abs(error(sealed_end_mm=scene.sealed_end_mm + scene.tip_cap_mm)) < 3.0
    # no cap where a body ends without one (the dots scene) or curls its tip by its own middle
    settings = settings_for(r.fixed_end_px)
    assert extract_body(img, settings, scale=1.0).tip_capped
    dots = scene_from("grey_dots", width=1600, height=1200)
    for psi in (215.0, -300.0):
        plain = render_actuator(psi, 200.0, dots, seed=4)
        bare = cv2.imdecode(np.frombuffer(plain.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
        assert not extract_body(bare, settings_for(plain.fixed_end_px), scale=1.0).tip_capped


def test_a_body_lost_to_light_that_falls_off_says_so_and_names_the_empty_scene(tmp_path):
    # a translucent body on grey, no empty scene, the photo darkened to 0.6 of its middle at one
    # corner (a lamp to a side): the body's faint parts are lost where it is darker and every
    # photo is flagged, for a rival selection by the clamp or a gap, whose fixes (roi, exclude)
    # do not help; the reason now says what does (with the empty scene: all within 5 deg)
    from pipeline.measure.body import light_falloff
    from pipeline.photoset_measure import UNEVEN_LIGHT_FALLOFF, measure_photoset
    from pipeline.synth.photoset_writer import render_photoset

    folder = tmp_path / "s"
    render_photoset(folder, "DS30", actuators=1, trials=1, seed=17, scene="grey_dots_clear",
                    step_kpa=50, max_kpa=200, scene_overrides={"width": 1280, "height": 960})
    first = folder / "DS30_A1_t1_s000_up_0kPa.jpg"
    allowed = np.ones((960, 1280), np.uint8)
    assert light_falloff(cv2.imread(str(first)), allowed) < UNEVEN_LIGHT_FALLOFF  # as rendered
    y, x = np.mgrid[0:960, 0:1280].astype(np.float32)
    gain = (1 - 0.15 * (((x - 640) / 640) ** 2 + ((y - 480) / 480) ** 2)) * (0.85 + 0.3 * x / 1280)
    for photo in folder.glob("DS30_*.jpg"):
        img = cv2.imread(str(photo)).astype(np.float32) * gain[..., None]
        cv2.imwrite(str(photo), np.clip(img, 0, 255).astype(np.uint8))
    assert light_falloff(cv2.imread(str(first)), allowed) > UNEVEN_LIGHT_FALLOFF
    settings = (folder / "photoset.yaml").read_text()
    (folder / "photoset.yaml").write_text(
        "".join(line for line in settings.splitlines(True) if "background" not in line)
        + "sealed_end_mm: 4\n"  # the scene's (10 was given here: the sealed-end check says so)
    )
    out = measure_photoset(folder)
    assert (out["status"] != "ok").all()
    assert out["reason"].str.contains(
        "the backdrop's light falls off by 6[0-9] % across the photo .*take a photo of the empty "
        "scene and name it as background in photoset.yaml"
    ).all(), out["reason"].tolist()
    # with the empty scene (darkened alike) the same photos are measured, and nothing is said
    (folder / "photoset.yaml").write_text(settings + "sealed_end_mm: 4\n")
    empty = folder / "background.jpg"
    img = cv2.imread(str(empty)).astype(np.float32) * gain[..., None]
    cv2.imwrite(str(empty), np.clip(img, 0, 255).astype(np.uint8))
    seen = measure_photoset(folder)
    assert (seen["status"] == "ok").sum() >= 7, seen["reason"].tolist()
    assert not seen["reason"].fillna("").str.contains("light falls off").any()


def test_a_capped_tip_reads_the_same_with_a_rough_scale_as_with_the_exact_one():
    # customer 28: translucent ribbed bodies with an 8 mm tip cap; a rough mm_per_px (or none)
    # moved the read point before the sealed end a few px and single photos by up to 4 deg; on
    # this analogue at 1280x960 by up to 2.6 deg, median error 1.4 deg (now 0.5)
    from pipeline.bench.realscenes import body_cases

    scaled, derived = (
        body_cases(8, scenes=("dark_translucent",), give_sealed_end=True, give_scale=scale,
                   seed=28)
        for scale in (True, False)
    )
    assert (scaled["status"] == "ok").all() and (derived["status"] == "ok").all()
    assert np.abs(scaled["psi_deg"].to_numpy() - derived["psi_deg"].to_numpy()).max() < 1.0
    for cases in (scaled, derived):
        assert cases["error_deg"].abs().median() < 1.0, cases["error_deg"].round(1).tolist()
        assert cases["error_deg"].abs().max() < 2.0, cases["error_deg"].round(1).tolist()


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("roi", [[100, 100, 103, 102], [100, 100, 101, 101]])
def test_a_roi_of_a_few_pixels_is_a_failed_row_not_a_crash(roi):
    # found beside the exclude over a whole photo (which crashed check and measure): a region
    # smaller than the backdrop model's sparse grid left it no pixel (IndexError in kmeans3)
    img = np.full((960, 1280, 3), 120, np.uint8)
    res = measure_image(img, resolve_settings(l0_mm=200.0, target="body", roi=roi,
                                              sealed_end_mm=4.0))
    assert res.status == "failed" and "no body found" in res.reason


@pytest.mark.parametrize("given", [False, True])
def test_a_faint_tips_fix_names_the_empty_scene_only_where_none_was_given(given):
    # customer 31 gave its empty scene and was told "or give the empty scene (background)"
    from pipeline.measure.extract import LineExtraction
    from pipeline.measure.quality import assess_body

    pts = np.c_[np.zeros(200), np.arange(200.0)]
    line = LineExtraction(pts, 20.0, False, 1, 100.0, 200.0, 0.0, False, True, (0.0, 0.0))
    quality = assess_body(
        line, psi_deg=10.0, psi_check_deg=10.0, widths_px=np.full(200, 20.0),
        expected_length_px=None, length_px=200.0, base_mismatch_deg=None,
        selected_fraction=0.05, end_short_px=25.0, missed_tip_deg=6.0, free_end_width_ratio=0.7,
        background_given=given,
    )
    assert "a faint tip?" in quality.reason, quality.reason
    assert ("or give the empty scene (background)" in quality.reason) is not given


@pytest.mark.parametrize(("share", "candidates", "said"), [
    (0.83, 3, True), (0.2, 3, False), (0.83, 1, False),
])
def test_a_faint_bodys_selection_flags_say_first_that_it_is_faint(share, candidates, said):
    # customer 55: a translucent body one grey level fainter than customer 53's was flagged as a
    # PneuNet, a ring, rival bodies or an uneven outline, its mask speckled on its shaded half;
    # the reason now says first that the body is faint, and only on a flag about its selection
    from pipeline.measure.extract import LineExtraction
    from pipeline.measure.quality import assess_body

    pts = np.c_[np.zeros(200), np.arange(200.0)]
    line = LineExtraction(pts, 20.0, False, candidates, 100.0, 200.0, 0.0, False, True,
                          (0.0, 0.0))
    quality = assess_body(
        line, psi_deg=10.0, psi_check_deg=10.0, widths_px=np.full(200, 20.0),
        expected_length_px=None, length_px=200.0, base_mismatch_deg=None,
        selected_fraction=0.05, background_given=True, faint_share=share,
    )
    assert quality.status == ("flagged" if candidates > 1 else "ok"), quality.reason
    assert quality.reason.startswith(
        "the body differs only faintly from the empty scene over 83% of it"
    ) is said, quality.reason


def test_a_selection_shorter_than_the_sealed_end_is_a_failed_row_not_a_negative_length():
    # customer 33's clear body: only bright edges were selected, shorter than the 7 mm sealed
    # end, and the rows read lengths of -8 px, "-3% of l0 visible" and psi -222 deg
    img, fe, _ = body_photo(90.0, seed=2)
    res = measure_image(img, settings_for(fe, mm_per_px=0.3, sealed_end_mm=200.0))
    assert res.status == "failed", (res.psi_deg, res.length_px, res.reason)
    assert "shorter than the sealed end (sealed_end_mm)" in res.reason
    ok = measure_image(img, settings_for(fe, mm_per_px=0.3, sealed_end_mm=5.0))
    assert ok.status == "ok" and ok.length_px > 0


@pytest.mark.parametrize("method", ["hyper", "paper_corrected"])
def test_a_circle_fit_on_a_body_that_is_not_an_arc_is_flagged_not_an_ok_psi(method):
    # a body is rarely an arc: asked for with `method:`, a circle fit read the rendered bulged
    # lab body (psi 175.6) as 216, ok, and 61 of 109 ok rows of the realscenes analogues more
    # than 5 deg off; the tip angle reads it right, and the circle fit where it agrees with it
    from pipeline.synth import render_with_background, scene_from

    scene = scene_from("lab", line_contrast=0.0, body_translucency=0.0, body_bgr=(90, 140, 200))
    for psi, bulge in ((175.6, 0.4), (56.7, 0.0)):
        r, _ = render_with_background(psi, 270.0, scene, seed=31, bulge=bulge)
        img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
        fe = [float(v) for v in r.fixed_end_px]
        tip = measure_image(img, resolve_settings(l0_mm=270.0, target="body", fixed_end=fe))
        assert tip.status == "ok", tip.reason
        assert tip.psi_deg == pytest.approx(r.psi_image_deg, abs=3.0)
        arc = measure_image(
            img, resolve_settings(l0_mm=270.0, target="body", fixed_end=fe, method=method)
        )
        assert arc.method == method
        if bulge:  # the circle fit is far off, and says why
            assert abs(arc.psi_deg - r.psi_image_deg) > 10.0
            assert arc.status == "flagged"
            assert "the body is not an arc" in arc.reason and "leave method out" in arc.reason
            # one cause in the report's counts (a ';' in it made two)
            import pandas as pd

            from pipeline.report.reasons import top_reasons

            table = pd.DataFrame({"dataset": ["d"], "status": ["flagged"], "reason": [arc.reason]})
            causes = [c for c, _ in top_reasons(table, limit=10)["d"]]
            assert "method reads a body as an arc, which it is not" in causes, causes
            assert not [c for c in causes if "leave method out" in c], causes
        else:  # a body bent as an arc: the circle fit agrees with the tip angle
            assert arc.psi_deg == pytest.approx(tip.psi_deg, abs=3.0)
            assert "not an arc" not in arc.reason


def dotted_body_photo(psi_deg, *, seed, at=(0.5, 0.86, 0.94), sides=(-1, 1, -1), radius=8.0):
    """:func:`body_photo` (46 px wide, 600 long) with white motion-capture dots centred on its
    edges (so half out of the outline) at the fractions ``at`` of its length, on the side given
    by ``sides`` (1: the edge away from the inextensible layer)."""
    img, fe, _ = body_photo(psi_deg, seed=seed)
    length, width = 600.0, 46.0
    k = np.deg2rad(psi_deg) / length
    s = np.linspace(0.0, length, 3000)
    pts = np.c_[np.sin(k * s) / k, (1 - np.cos(k * s)) / k]
    n = np.c_[-np.sin(k * s), np.cos(k * s)]
    mid = pts + n * width / 2
    off = np.array([W / 2 - mid[:, 0].mean(), H / 2 + mid[:, 1].mean()])
    for a, side in zip(at, sides):
        i = int(a * (len(s) - 1))
        p = pts[i] + n[i] * (width if side > 0 else 0.0)
        q = np.round((np.array([p[0], -p[1]]) + off) * 16).astype(int)
        white = (250, 250, 250)
        cv2.circle(img, (int(q[0]), int(q[1])), int(radius * 16), white, -1, cv2.LINE_AA, 4)
    return img, fe


def test_dots_standing_half_out_of_the_outline_do_not_turn_the_tip():
    # customer 50: 3 mm dots on a 15 mm body's sides, one near the tip, turned the end's
    # direction 5-7 deg (3 rows ok 5.7-6.8 deg off, every setting right; 15 of 60 flagged, 8 of
    # them right).  A side bulging alone is set back to its own course: here 5 of 10 were ok
    # (one 4.2 deg off) and 5 flagged up to 13 deg off; now 8 ok, all within 3 deg
    errors, ok = [], 0
    for psi in (240.0, 150.0, 60.0, -120.0, -210.0):
        for seed in (1, 2):
            img, fe = dotted_body_photo(psi, seed=seed)
            res = measure_image(img, settings_for(fe, free_end="bends"))
            if res.status == "ok":
                ok += 1
                errors.append(abs(res.psi_deg - psi))
    assert ok >= 7 and max(errors) < 3.5, (ok, errors)


def test_a_row_of_chamber_crests_is_no_bump():
    # customer 48's PneuNet (83 px wide) given a direction 10 deg off: its chamber crests stood
    # out of the comb side's running median by 15-72 px, were set back as marker bumps, and the
    # ramp check no longer saw the direction (15 rows ok 10 deg off); a marker stands out half its
    # own size, 10-20 % of a body's width
    from pipeline.measure.body import _without_bumps

    n, width = 400, 80.0
    left = np.full(n, -width / 2)
    comb = np.full(n, width / 2)
    for start in range(20, n - 40, 60):  # chambers 40 px long, 20 px apart, half the strip high
        comb[start : start + 40] += 0.5 * width
    good = np.ones(n, bool)
    assert (_without_bumps(left, comb, good)[1] == comb).all()
    dot = np.full(n, width / 2)
    dot[200:210] += 0.12 * width  # a marker dot half out of the outline
    assert (_without_bumps(left, dot, good)[1] == width / 2).all()
