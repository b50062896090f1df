"""Synthetic bodies without a drawn line (target: body): truth against the rendered geometry,
shapes, appearance (no line, dots, texture, clamps), photo sets and determinism."""

from __future__ import annotations

import hashlib
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.ndimage import map_coordinates

from pipeline.errors import UserInputError
from pipeline.measure.colors import parse_color
from pipeline.photoset import load_photoset, validate_photoset
from pipeline.synth import make_backdrop, make_camera, render_actuator, render_curve, scene_from
from pipeline.synth.centreline import (
    actuator_centreline_mm,
    curvature_weights,
    peak_curvature_per_mm,
)
from pipeline.synth.photoset_writer import BACKGROUND_IMAGE, render_photoset
from pipeline.synth.scene import render_background, world_extent_mm

BODY_PRESETS = ("green_fibre", "grey_dots", "grey_dots_clear", "dark_translucent")
L0 = 160.0
#: small photos, a field of view of 288 x 216 mm
VIEW = {"width": 640, "height": 480, "mm_per_px": 0.45}


def toy_psi(material: str, p, branch: str = "loading"):
    """A smooth decreasing loading curve standing in for the model (200 deg at rest)."""
    p = np.asarray(p, float)
    return 200.0 - 400.0 * (1 - np.exp(-p / 150.0)) / (1 - np.exp(-1.0))


def psi_from_points(points: np.ndarray, y_down: bool) -> float:
    """Total turning recomputed independently: unwrapped chord directions, end to end."""
    d = np.diff(points, axis=0)
    ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    turn = np.degrees(ang[-1] - ang[0]) * (len(points) - 1) / (len(points) - 2)
    return -turn if y_down else turn


def render_with_empty(
    preset: str, psi: float, *, rotation: float = 25.0, seed: int = 3, **overrides
):
    """A photo and the same scene without the actuator (one backdrop, no noise)."""
    scene = scene_from(preset, **{**VIEW, "noise_sigma": 0.0, **overrides})
    pts = actuator_centreline_mm(psi, L0, scene)
    camera = make_camera(
        scene,
        rotation_deg=rotation,
        extent_mm=world_extent_mm(pts, scene.body_width_mm, scene.tip_cap_mm),
    )
    backdrop = make_backdrop(scene, camera, seed=seed, keepout_mm=[pts])
    r = render_curve(pts, scene, seed=seed + 1, backdrop=backdrop)
    return scene, r, render_background(backdrop, scene, seed=0)


def normals_px(curve: np.ndarray) -> np.ndarray:
    t = np.gradient(curve, axis=0)
    t /= np.hypot(t[:, 0], t[:, 1])[:, None]
    return np.column_stack([-t[:, 1], t[:, 0]])


def edges_across(
    mask: np.ndarray, curve: np.ndarray, half_px: float, fractions: np.ndarray
) -> np.ndarray:
    """For points of ``curve`` at ``fractions`` of its samples: the two edges of ``mask`` along the
    normal.

    Returns (k, 2) offsets (px, along the normal) of the last masked sample on each side of the
    curve, walking out from it (bilinear mask >= 0.5).
    """
    idx = np.round(fractions * (len(curve) - 1)).astype(int)
    c, n = curve[idx], normals_px(curve)[idx]
    offs = np.arange(-1.6 * half_px, 1.6 * half_px + 1e-9, 0.05)
    xs = c[:, None, 0] + offs[None, :] * n[:, None, 0]
    ys = c[:, None, 1] + offs[None, :] * n[:, None, 1]
    inside = (
        map_coordinates(mask.astype(float), [ys.ravel(), xs.ravel()], order=1).reshape(xs.shape)
        >= 0.5
    )
    zero = np.argmin(np.abs(offs))
    out = []
    for row in inside:
        assert row[zero], "the truth centre line leaves the drawn body"
        lo = zero
        while lo > 0 and row[lo - 1]:
            lo -= 1
        hi = zero
        while hi < len(row) - 1 and row[hi + 1]:
            hi += 1
        out.append((offs[lo], offs[hi]))
    return np.array(out)


# ------------------------------------------------------------------ truth against the drawn body


@pytest.mark.parametrize("psi", [-200.0, -60.0, 0.0, 90.0, 180.0])
@pytest.mark.parametrize("preset", BODY_PRESETS)
def test_truth_is_the_centre_line_of_the_drawn_body_and_turns_through_psi(preset, psi):
    # a black table so that every part of the body differs from the empty scene (a translucent
    # body's
    # shaded edge can match a grey backdrop: realistic, but this test is about geometry)
    scene, r, empty = render_with_empty(preset, psi, tilt_deg=0.0, shadow=0.0, table_bgr="black")
    assert r.target == "body"
    # the curve the truth is computed on turns through psi (independent recount)
    assert psi_from_points(r.centreline_px, y_down=True) == pytest.approx(psi, abs=0.05)
    assert r.psi_image_deg == pytest.approx(psi, abs=0.05)
    # ... and it runs midway between the two long edges of what was drawn (the outline mask)
    mask = np.abs(r.image.astype(np.int16) - empty.astype(np.int16)).max(axis=2) > 6
    half = scene.body_width_mm / 2 / scene.mm_per_px
    # clamp face to free end
    e = edges_across(mask, r.centreline_px, half, np.linspace(0.01, 0.99, 50))
    mid, width = e.mean(axis=1), e[:, 1] - e[:, 0]
    assert np.abs(mid).mean() < 0.3 and np.abs(mid).max() < 1.0
    # the width drawn: the body's, ribs bulging up to 5 % a side, the mask's threshold catching the
    # blur
    assert 2 * half - 2 < np.median(width) < 2 * half * 1.1 + 4
    # the body leaves the clamp at the fixed end in the direction stated
    assert r.fixed_end_px == pytest.approx(tuple(r.centreline_px[0]))
    assert r.fixed_direction_deg == pytest.approx(25.0, abs=1e-3)


def test_tilted_camera_truth_is_the_projected_body_centre_line():
    _scene, r, _ = render_with_empty("grey_dots", 120.0, tilt_deg=3.0)
    assert psi_from_points(r.centreline_px, y_down=True) == pytest.approx(r.psi_image_deg, abs=0.05)
    assert 0 < abs(r.psi_image_deg - 120.0) < 1.5


def test_line_target_is_unchanged_and_body_target_follows_the_body():
    line = render_actuator(100.0, L0, scene_from("clean", **VIEW), seed=1)
    body = render_actuator(100.0, L0, scene_from("clean", target="body", **VIEW), seed=1)
    assert line.target == "line" and body.target == "body"
    assert np.array_equal(line.centreline_px, line.layer_px)
    # same layer, the body's centre line half a width (7 mm) to its left
    assert np.allclose(line.layer_px, body.layer_px)
    d = np.hypot(*(body.centreline_px - body.layer_px).T) * 0.45
    assert np.allclose(d, 7.0, atol=0.02)
    assert line.image.tobytes() == body.image.tobytes()


# ------------------------------------------------------------------ shapes


@pytest.mark.parametrize("psi", [-300.0, -90.0, 0.0, 45.0, 210.0])
@pytest.mark.parametrize("shape,extra", [("arc", {}), ("distal", {"straight_base_fraction": 0.4}),
                                         ("chambers", {"chamber_bend": (0.0, 1.0, 0.5)}),
                                         ("chambers", {"chamber_bend": (1.0, 0.0, 1.0)})])
def test_shapes_turn_through_psi_over_l0(shape, extra, psi):
    scene = scene_from("clean", shape=shape, **extra)
    pts = actuator_centreline_mm(psi, 195.0, scene)
    first_chord = np.arctan2(*(pts[1] - pts[0])[::-1])  # half a chord's turn off the tangent (+x)
    assert (
        np.allclose(pts[0], 0) and abs(first_chord) <= np.radians(abs(psi)) / (len(pts) - 1) + 1e-12
    )
    assert psi_from_points(pts, y_down=False) == pytest.approx(psi, abs=0.05)
    assert np.hypot(*np.diff(pts, axis=0).T).sum() == pytest.approx(195.0, rel=1e-6)


def _curvature(pts: np.ndarray) -> np.ndarray:
    d = np.diff(pts, axis=0)
    return np.diff(np.unwrap(np.arctan2(d[:, 1], d[:, 0]))) / np.hypot(*d.T)[1:]


def test_distal_shape_has_a_straight_base_and_curls_towards_the_tip():
    scene = scene_from("clean", shape="distal", straight_base_fraction=0.35)
    pts = actuator_centreline_mm(150.0, 200.0, scene, n=4001)
    u = np.linspace(0, 1, 4001)
    assert np.abs(pts[u <= 0.35, 1]).max() < 1e-9  # the base stays on the clamp axis
    k = _curvature(pts)
    assert k[-50:].mean() > 1.5 * np.radians(150.0) / 200.0  # tip curls more than an arc would
    assert peak_curvature_per_mm(150.0, 200.0, scene) == pytest.approx(k.max(), rel=0.01)


def test_chambers_bend_only_where_weighted():
    scene = scene_from("clean", shape="chambers", chamber_bend=(1.0, 0.0, 1.0))
    pts = actuator_centreline_mm(-120.0, 180.0, scene, n=3001)
    k = _curvature(pts)
    u = np.linspace(0, 1, 3001)[1:-1]
    middle = (u > 1 / 3 + 0.03) & (u < 2 / 3 - 0.03)
    assert np.abs(k[middle]).max() < 1e-6
    # 2/3 of l0 bends
    assert k[u < 0.3].mean() == pytest.approx(np.radians(-120.0) / 120.0, rel=0.02)
    w = curvature_weights(np.array([0.1, 0.5, 0.9]), "chambers", chamber_bend=(1.0, 0.0, 1.0))
    assert w.tolist() == [1.0, 0.0, 1.0]


def test_folding_body_is_refused_before_anything_is_written(tmp_path):
    scene = scene_from("grey_dots", body_width_mm=25.0, **VIEW)
    with pytest.raises(UserInputError, match="fold"):
        render_actuator(330.0, 100.0, scene, seed=1)
    out = tmp_path / "folded"
    with pytest.raises(UserInputError, match="fold"):
        render_photoset(
            out,
            "DS20",
            actuators=1,
            trials=1,
            step_kpa=200,
            scene="grey_dots",
            l0_mm=100.0,
            scene_overrides={"body_width_mm": 25.0, "width": 320, "height": 240},
            psi_fn=lambda m, p, branch="loading": 330.0 - np.asarray(p, float),
        )
    assert not out.exists() or not list(out.glob("*.jpg"))


# ------------------------------------------------------------------ appearance


@pytest.mark.parametrize("preset", BODY_PRESETS)
def test_no_line_is_drawn_unless_asked(preset):
    hsv_of = lambda img: cv2.cvtColor(img, cv2.COLOR_BGR2HSV)
    red = parse_color("red")
    fractions = {}
    for drawn in (False, True):
        scene = scene_from(preset, marker_line=drawn, line_color="red", line_width_px=5.0, **VIEW)
        r = render_actuator(120.0, L0, scene, seed=2)
        hsv = hsv_of(r.image)
        mask = np.zeros(hsv.shape[:2], np.uint8)
        for lo, hi in red.ranges:
            mask |= cv2.inRange(hsv, np.array(lo), np.array(hi))
        pts = np.round(r.layer_px[200:-200:100]).astype(int)
        fractions[drawn] = mask[pts[:, 1], pts[:, 0]].mean() / 255
    assert fractions[False] < 0.02 and fractions[True] > 0.9


def test_dots_are_drawn_where_the_truth_puts_them():
    kw = {"tilt_deg": 0.0, "shadow": 0.0}
    _, with_dots, _ = render_with_empty("grey_dots", 140.0, **kw)
    _, without, _ = render_with_empty("grey_dots", 140.0, dots=0, **kw)
    assert len(with_dots.dots_px) == 8 and len(without.dots_px) == 0
    diff = (
        np.abs(with_dots.image.astype(np.int16) - without.image.astype(np.int16)).max(axis=2) > 25
    )
    n, _, _, centroids = cv2.connectedComponentsWithStats(diff.astype(np.uint8))
    assert n - 1 == 8
    near = np.hypot(
        *(centroids[1:, None, :] - with_dots.dots_px[None, :, :]).transpose(2, 0, 1)
    ).min(axis=1)
    assert near.max() < 1.0
    # white markers are bright; on the centre line (layout 'centre') they lie within 1 mm of it
    px = np.round(with_dots.dots_px).astype(int)
    assert with_dots.image[px[:, 1], px[:, 0]].min() > 180
    to_line = np.hypot(
        *(with_dots.dots_px[:, None, :] - with_dots.centreline_px[None, ::20, :]).transpose(2, 0, 1)
    ).min(axis=1)
    assert to_line.max() * 0.45 < 1.0


@pytest.mark.parametrize("layout,from_line_half_widths", [("edges", 0.55), ("outline", 1.0)])
def test_dots_of_an_edge_layout_lie_off_the_centre_line_and_outline_ones_stand_out_of_the_body(
    layout, from_line_half_widths
):
    kw = {"tilt_deg": 0.0, "shadow": 0.0, "dot_layout": layout, "dot_diameter_mm": 6.0}
    scene, r, _ = render_with_empty("grey_dots", 140.0, **kw)
    half_px = 0.5 * scene.body_width_mm / VIEW["mm_per_px"]
    gaps = r.dots_px[:, None, :] - r.centreline_px[None, :, :]
    nearest = np.argmin(np.hypot(*gaps.transpose(2, 0, 1)), axis=1)
    outward = r.dots_px - r.centreline_px[nearest]
    from_line = np.hypot(*outward.T)
    assert np.allclose(from_line / half_px, from_line_half_widths, atol=0.15)
    # the dots alternate sides
    side = np.sign(np.cross(np.gradient(r.centreline_px, axis=0)[nearest], outward))
    assert set(side[::2]) != set(side[1::2]) and len(set(side[::2])) == 1
    # a white marker's outer rim: on the body (edges) or on the backdrop past its edge (outline)
    rim = r.dots_px + outward / from_line[:, None] * 0.4 * scene.dot_diameter_mm / VIEW["mm_per_px"]
    rim_from_line = np.hypot(*(rim - r.centreline_px[nearest]).T) / half_px
    px = np.round(rim).astype(int)
    assert r.image[px[:, 1], px[:, 0]].min(axis=1).min() > 180
    if layout == "outline":
        assert rim_from_line.min() > 1.1
    else:
        assert rim_from_line.max() < 1.0


@pytest.mark.parametrize("preset,texture", [("green_fibre", "fibre"), ("dark_translucent", "ribs")])
def test_texture_repeats_along_the_body_at_its_pitch(preset, texture):
    def spectrum(**kw):
        scene = scene_from(
            preset,
            width=800,
            height=600,
            mm_per_px=0.25,
            noise_sigma=0.0,
            specular=0.0,
            chamber_bend=(1.0,),
            texture_pitch_mm=3.0,
            tilt_deg=0.0,
            **kw,
        )
        r = render_actuator(60.0, 120.0, scene, seed=5)
        grey = cv2.cvtColor(r.image, cv2.COLOR_BGR2GRAY).astype(float)
        c = r.centreline_px
        arc = np.concatenate([[0], np.cumsum(np.hypot(*np.diff(c, axis=0).T))]) * scene.mm_per_px
        s = np.arange(0.15 * arc[-1], 0.85 * arc[-1], 0.1)
        xy = np.column_stack([np.interp(s, arc, c[:, 0]), np.interp(s, arc, c[:, 1])])
        v = map_coordinates(grey, [xy[:, 1], xy[:, 0]], order=1)
        power = np.abs(np.fft.rfft((v - v.mean()) * np.hanning(len(v)))) ** 2
        freq = np.fft.rfftfreq(len(v), d=0.1)
        band = (freq > 1 / 9.0) & (freq < 1 / 1.2)
        return freq[band], power[band]

    f, p = spectrum()
    peak = f[np.argmax(p)]
    assert 1 / peak == pytest.approx(3.0, rel=0.12)
    assert p.max() > 8 * np.median(p)
    _, p_plain = spectrum(texture="none")
    assert p_plain.max() < 0.05 * p.max()


def test_clamp_styles_plate_reaches_the_border_white_clamp_is_white():
    scene, r, _ = render_with_empty("grey_dots", 60.0, rotation=0.0)
    camera = make_camera(scene, rotation_deg=0.0, extent_mm=world_extent_mm(
        actuator_centreline_mm(60.0, L0, scene), scene.body_width_mm))
    behind = np.round(camera.to_px([[-60.0, scene.body_width_mm / 2 + 40.0]])[0]).astype(int)
    dark = (r.image.max(axis=2) < 75).astype(np.uint8)
    assert dark[behind[1], behind[0]]
    _, labels = cv2.connectedComponents(dark)
    plate = labels == labels[behind[1], behind[0]]
    assert plate[:, 0].any() or plate[0].any() or plate[-1].any()
    assert plate.mean() > 0.15
    scene, r, _ = render_with_empty("green_fibre", 60.0, rotation=0.0)
    camera = make_camera(scene, rotation_deg=0.0, extent_mm=world_extent_mm(
        actuator_centreline_mm(60.0, L0, scene), scene.body_width_mm, scene.tip_cap_mm))
    at = np.round(camera.to_px([[-12.0, scene.body_width_mm / 2]])[0]).astype(int)
    assert r.image[at[1] - 2:at[1] + 3, at[0] - 2:at[0] + 3].min() > 190
    g = r.image[5:40, 5:40].reshape(-1, 3).mean(axis=0)  # the chroma backdrop is green
    assert g[1] > 1.8 * g[0] and g[1] > 1.8 * g[2]


@pytest.mark.parametrize("preset", BODY_PRESETS)
def test_body_renders_are_deterministic(preset):
    scene = scene_from(preset, width=320, height=240)
    a = render_actuator(-80.0, L0, scene, seed=9)
    b = render_actuator(-80.0, L0, scene, seed=9)
    c = render_actuator(-80.0, L0, scene, seed=10)
    assert a.jpeg_bytes == b.jpeg_bytes and a.jpeg_bytes != c.jpeg_bytes


def test_new_scene_knobs_are_validated_and_parsed():
    s = scene_from("lab", table_bgr="green", chamber_bend="0,1,1", shape="chambers", texture="ribs",
                   marker_line="false", target="body", dots="6", clamp_style="plate")
    assert s.table_bgr == (58, 160, 40) and s.chamber_bend == (0.0, 1.0, 1.0) and s.dots == 6
    assert not s.marker_line and not s.plain_body
    assert scene_from("lab").plain_body
    for bad in (
        {"texture": "knit"},
        {"clamp_style": "vice"},
        {"marker_line": False},
        {"chamber_bend": "-1,1"},
        {"chamber_bend": "0,0"},
        {"dot_color": "red"},
        {"body_width_mm": 80},
        {"table_bgr": "mauve"},
        {"specular": 1.5},
        {"straight_base_fraction": 0.95},
        {"shape": "spiral"},
        {"dots": -1},
    ):
        with pytest.raises(UserInputError):
            scene_from("lab", **bad)


# ------------------------------------------------------------------ photo sets


def body_set(tmp_path: Path, preset: str, name: str = "set", **kw) -> tuple[Path, pd.DataFrame]:
    args = {
        "actuators": 1,
        "trials": 2,
        "seed": 4,
        "scene": preset,
        "step_kpa": 110,
        "psi_fn": toy_psi,
        "scene_overrides": {"width": 480, "height": 360},
        "l0_mm": 195.0,
    }
    args.update(kw)
    out = tmp_path / name
    return out, render_photoset(out, "DS20", **args)


@pytest.mark.parametrize("preset", BODY_PRESETS)
def test_body_photoset_is_a_valid_body_photoset(tmp_path, preset):
    out, truth = body_set(tmp_path, preset)
    scene = scene_from(preset)
    assert validate_photoset(out) == []
    raw = yaml.safe_load((out / "photoset.yaml").read_text())
    assert raw["target"] == "body" and "line_color" not in raw
    ps = load_photoset(out)
    assert all(row is not None and row.target == "body" and row.color is None for row in ps.rows)
    assert truth["target"].eq("body").all() and truth["line_in_frame"].all()
    assert (truth["psi_deg"] - truth["psi_image_deg"]).abs().max() < 0.6  # 1 deg camera tilt
    # the fixed end: the body's centre line at the clamp face (ramps differ by the mounting jitter)
    assert (
        np.hypot(
            truth["fixed_end_x"] - raw["fixed_end"][0], truth["fixed_end_y"] - raw["fixed_end"][1]
        ).max()
        < 1.0
    )
    manifest = pd.read_csv(out / "manifest.csv")
    if scene.known_fixed_direction:
        assert np.allclose(manifest["fixed_direction_deg"], truth["fixed_direction_deg"], atol=1e-3)
        assert [row.fixed_direction_deg for row in ps.rows] == pytest.approx(
            list(truth["fixed_direction_deg"]), abs=1e-3
        )
        # per ramp
        assert truth.groupby("trial")["fixed_direction_deg"].first().diff().abs().max() > 0.01
    else:
        assert "fixed_direction_deg" not in manifest
    if scene.background_photo:
        assert raw["background"] == BACKGROUND_IMAGE
        assert Path(ps.rows[0].background_path).name == BACKGROUND_IMAGE
        empty = cv2.imread(str(out / BACKGROUND_IMAGE)).astype(np.int16)
        for image in truth["image"]:
            photo = cv2.imread(str(out / image)).astype(np.int16)
            diff = np.abs(photo - empty).max(axis=2)
            assert np.median(diff) < 8  # the same scene: noise and JPEG apart
            assert (diff > 30).mean() > 0.005  # but the actuator is only in the photos
    else:
        assert "background" not in raw and not (out / BACKGROUND_IMAGE).exists()


def test_body_photosets_same_seed_same_bytes_whatever_the_jobs(tmp_path):
    def sha(folder: Path) -> dict[str, str]:
        return {
            p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())
        }

    a, _ = body_set(tmp_path, "green_fibre", "a", jobs=1)
    b, _ = body_set(tmp_path, "green_fibre", "b", jobs=2)
    c, _ = body_set(tmp_path, "green_fibre", "c", seed=5)
    ha, hb, hc = sha(a), sha(b), sha(c)
    assert BACKGROUND_IMAGE in ha and ha == hb
    assert (
        sum(ha[k] != hc.get(k) for k in ha if k.endswith(".jpg"))
        >= len([k for k in ha if k.endswith(".jpg")]) - 1
    )


def test_cli_renders_a_body_preset_with_shape_knobs(tmp_path, capsys):
    from pipeline.cli import main

    out = tmp_path / "cli"
    rc = main(
        [
            "synth",
            str(out),
            "--material",
            "SS50",
            "--actuators",
            "1",
            "--trials",
            "1",
            "--step-kpa",
            "150",
            "--max-kpa",
            "150",
            "--scene",
            "green_fibre",
            "--set",
            "width=320",
            "--set",
            "height=240",
            "--set",
            "chamber_bend=0,0,1",
            "--set",
            "known_fixed_direction=true",
        ]
    )
    assert rc == 0 and "scene green_fibre" in capsys.readouterr().out
    assert validate_photoset(out) == []
    truth = pd.read_csv(out / "truth.csv")
    assert truth["shape"].eq("chambers").all() and "fixed_direction_deg" in pd.read_csv(
        out / "manifest.csv"
    )
