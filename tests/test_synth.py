"""Tests of the synthetic renderer (pipeline.synth): exact truth, protocol, hysteresis,
determinism."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
from scipy.ndimage import map_coordinates

from pipeline.errors import UserInputError
from pipeline.measure.colors import parse_color
from pipeline.photoset import load_photoset, validate_photoset
from pipeline.synth import SCENE_PRESETS, centreline_mm, render_actuator, render_curve, scene_from
from pipeline.synth.actuator import (
    BEHAVIOURS,
    TrialActuator,
    behaviour_for,
    loading_curve,
    plan_ramp,
    ramp_pressures,
)
from pipeline.synth.photoset_writer import render_photoset

REPO = Path(__file__).resolve().parent.parent
SMALL = {"width": 480, "height": 360}


def toy_psi(material: str, p, branch: str = "loading"):
    """A smooth decreasing loading curve standing in for the model (210 deg at rest)."""
    p = np.asarray(p, float)
    return 210.0 - 420.0 * (1 - np.exp(-p / 150.0)) / (1 - np.exp(-1.0))


def psi_from_points(points: np.ndarray, y_down: bool) -> float:
    """Total turning angle recomputed independently: unwrapped chord directions, end to end."""
    d = np.diff(points, axis=0)
    ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    # chords turn by psi/(n-1) each; the first and last chords miss half a chord at each end
    turn = np.degrees(ang[-1] - ang[0]) * (len(points) - 1) / (len(points) - 2)
    return -turn if y_down else turn


def sha(folder: Path) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir())}


# ------------------------------------------------------------------ centreline


@pytest.mark.parametrize("psi", [-360.0, -225.0, -30.0, 0.0, 1e-4, 90.0, 210.0, 359.9, 360.0])
@pytest.mark.parametrize("bulge", [0.0, 0.35])
def test_centreline_total_turning_and_length(psi, bulge):
    pts = centreline_mm(psi, 195.0, bulge=bulge)
    assert np.allclose(pts[0], 0)
    assert psi_from_points(pts, y_down=False) == pytest.approx(psi, abs=0.02)
    length = np.hypot(*np.diff(pts, axis=0).T).sum()
    assert length == pytest.approx(195.0, rel=1e-6)


def test_constant_curvature_arc_is_a_circle():
    pts = centreline_mm(150.0, 120.0, n=501)
    r = 120.0 / np.radians(150.0)
    assert np.allclose(np.hypot(pts[:, 0], pts[:, 1] - r), r, atol=1e-9)


def test_bulge_curves_the_middle_more_than_the_ends():
    pts = centreline_mm(-200.0, 195.0, bulge=0.4, n=2001)
    d = np.diff(pts, axis=0)
    k = np.diff(np.unwrap(np.arctan2(d[:, 1], d[:, 0])))
    mid, ends = np.abs(k[900:1100]).mean(), np.abs(np.r_[k[:100], k[-100:]]).mean()
    assert mid / ends == pytest.approx(1.4 / 0.6, rel=0.02)


@pytest.mark.parametrize("kwargs", [{"bulge": 1.0}, {"bulge": -0.1}, {"n": 1}])
def test_centreline_rejects_bad_input(kwargs):
    with pytest.raises(UserInputError):
        centreline_mm(100.0, 195.0, **kwargs)
    with pytest.raises(UserInputError):
        centreline_mm(100.0, -1.0)


# ------------------------------------------------------------------ rendering


@pytest.mark.parametrize("psi", [-360.0, -210.0, -45.0, 0.0, 30.0, 210.0, 360.0])
def test_rendered_centreline_matches_truth(psi):
    r = render_actuator(
        psi, 195.0, scene_from("clean", **SMALL), seed=1, bulge=0.2 if psi < 0 else 0.0
    )
    assert psi_from_points(r.centreline_px, y_down=True) == pytest.approx(psi, abs=0.05)
    assert r.psi_image_deg == pytest.approx(psi, abs=0.05)
    assert r.line_in_frame
    assert r.fixed_end_px == pytest.approx(tuple(r.centreline_px[0]))


def test_tilted_camera_truth_is_the_projected_turning_angle():
    r = render_actuator(150.0, 195.0, scene_from("hard", **SMALL), seed=2)
    assert psi_from_points(r.centreline_px, y_down=True) == pytest.approx(r.psi_image_deg, abs=0.05)
    assert 0 < abs(r.psi_image_deg - 150.0) < 1.0  # 3 deg of tilt shows, slightly


def test_positive_psi_turns_counter_clockwise_on_screen():
    r = render_actuator(90.0, 195.0, scene_from("clean", **SMALL), seed=1, rotation_deg=0.0)
    start, end = r.centreline_px[0], r.centreline_px[-1]
    # leaves the clamp towards +x and ends above it (image y smaller): a ccw turn as seen
    assert end[0] > start[0] and end[1] < start[1] - 50


def test_drawn_line_is_centred_on_the_truth():
    scene = scene_from(
        "clean",
        width=640,
        height=480,
        body_translucency=1.0,
        clamp=False,
        tube=False,
        line_width_px=5.0,
    )
    for psi in (-250.0, 75.0):
        r = render_actuator(psi, 195.0, scene, seed=3)
        grey = r.image[..., 1].astype(float)
        darkness = scene.table_bgr[1] - grey
        c = r.centreline_px[2000:-2000:50]
        t = np.gradient(r.centreline_px, axis=0)[2000:-2000:50]
        t /= np.hypot(t[:, 0], t[:, 1])[:, None]
        n = np.column_stack([-t[:, 1], t[:, 0]])
        offs = np.linspace(-6, 6, 121)
        xs = c[:, None, 0] + offs[None, :] * n[:, None, 0]
        ys = c[:, None, 1] + offs[None, :] * n[:, None, 1]
        prof = map_coordinates(darkness, [ys.ravel(), xs.ravel()], order=1).reshape(xs.shape)
        centroid = (prof * offs).sum(axis=1) / prof.sum(axis=1)
        assert abs(centroid.mean()) < 0.03
        assert np.abs(centroid).max() < 0.15
        width = prof.sum(axis=1) * (offs[1] - offs[0]) / darkness.max()
        assert np.median(width) == pytest.approx(5.0, abs=0.6)


@pytest.mark.parametrize("colour", ["black", "blue", "red", "green"])
@pytest.mark.parametrize("preset", ["clean", "lab"])
def test_line_colour_is_inside_the_photoset_hsv_range(colour, preset):
    r = render_actuator(
        120.0, 195.0, scene_from(preset, line_color=colour, line_width_px=5.0, **SMALL), seed=4
    )
    hsv = cv2.cvtColor(r.image, cv2.COLOR_BGR2HSV)
    mask = np.zeros(hsv.shape[:2], np.uint8)
    for lo, hi in parse_color(colour).ranges:
        mask |= cv2.inRange(hsv, np.array(lo), np.array(hi))
    pts = np.round(r.centreline_px[::200]).astype(int)
    assert mask[pts[:, 1], pts[:, 0]].mean() / 255 > 0.95
    # and the table is not that colour
    assert mask.mean() / 255 < 0.05


def test_render_curve_accepts_any_curve_and_is_deterministic():
    t = np.linspace(0, np.pi, 400)
    ellipse = np.column_stack([60 * np.sin(t), 40 * (1 - np.cos(t))])
    scene = scene_from("lab", **SMALL)
    a = render_curve(ellipse, scene, seed=7, fixed_end_px=(200.0, 300.0), rotation_deg=90.0)
    b = render_curve(ellipse, scene, seed=7, fixed_end_px=(200.0, 300.0), rotation_deg=90.0)
    c = render_curve(ellipse, scene, seed=8, fixed_end_px=(200.0, 300.0), rotation_deg=90.0)
    assert a.fixed_end_px == pytest.approx((200.0, 300.0), abs=1e-6)
    assert a.jpeg_bytes == b.jpeg_bytes and a.jpeg_bytes != c.jpeg_bytes
    assert cv2.imdecode(np.frombuffer(a.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR).shape == (
        360,
        480,
        3,
    )


def test_scene_from_overrides_and_errors():
    s = scene_from("lab", width="640", height=480, noise_sigma="4", clamp="false")
    assert (s.width, s.noise_sigma, s.clamp) == (640, 4.0, False)
    assert s.mm_per_px == pytest.approx(SCENE_PRESETS["lab"].mm_per_px * 2)
    for bad in (
        {"nope": 1},
        {"noise_sigma": "x"},
        {"line_contrast": 2.0},
        {"line_color": "purple"},
    ):
        with pytest.raises(UserInputError):
            scene_from("lab", **bad)
    with pytest.raises(UserInputError):
        scene_from("studio")


# ------------------------------------------------------------------ virtual actuator and protocol


def trial_of(material="DS20", psi_fn=toy_psi, **kw) -> TrialActuator:
    curve = loading_curve(material, max_kpa=500, psi_fn=psi_fn)
    return TrialActuator(
        material,
        curve,
        psi0_deg=kw.get("psi0", 210.0),
        stiffness=kw.get("k", 1.0),
        behaviour=behaviour_for(material),
    )


def test_ramp_stops_at_minus_psi0_then_returns():
    trial = trial_of()
    up, reason = ramp_pressures(trial, step_kpa=10, max_kpa=260)
    assert reason == "minus_psi0"
    assert trial.psi_loading_deg(up[-1]) <= -210 < trial.psi_loading_deg(up[-2])
    ramp = plan_ramp(trial, step_kpa=10, max_kpa=260, rng=np.random.default_rng(0))
    p = ramp["pressure_kpa"].to_numpy()
    assert p[0] == 0 and p[-1] == 0 and p.max() == up[-1]
    assert list(ramp["direction"]) == ["up"] * len(up) + ["down"] * (len(up) - 1)
    assert np.array_equal(p[len(up):], up[:-1][::-1])


def test_ramp_stops_at_max_pressure_including_a_partial_last_step():
    trial = trial_of(
        "SS50", psi_fn=lambda m, p, branch="loading": 210.0 - 0.2 * np.asarray(p, float)
    )
    up, reason = ramp_pressures(trial, step_kpa=30, max_kpa=100)
    assert reason == "max_pressure" and up.tolist() == [0, 30, 60, 90, 100]


def test_ramp_stops_where_the_model_ends():
    nan_tail = lambda m, p, branch="loading": np.where(
        np.asarray(p) > 45, np.nan, 210.0 - np.asarray(p, float)
    )
    up, reason = ramp_pressures(trial_of(psi_fn=nan_tail), step_kpa=10, max_kpa=260)
    assert reason == "model_limit" and up.tolist() == [0, 10, 20, 30, 40]


@pytest.mark.parametrize("material", sorted(BEHAVIOURS))
def test_unloading_needs_less_pressure_for_the_same_angle(material):
    trial = trial_of(material)
    ramp = plan_ramp(
        trial, step_kpa=10, max_kpa=260, rng=np.random.default_rng(0), photo_noise=False
    )
    up = ramp[ramp.direction == "up"].set_index("pressure_kpa")["psi_deg"]
    down = ramp[ramp.direction == "down"].set_index("pressure_kpa")["psi_deg"]
    inner = down.index[(down.index > 0)]
    # smaller angle at the same pressure = less pressure for the angle
    assert (down[inner] < up[inner]).all()
    assert down[0.0] == pytest.approx(up[0.0])


def test_softer_silicones_show_more_hysteresis():
    widths = {}
    for material in ("DS20", "SS50"):
        ramp = plan_ramp(
            trial_of(material),
            step_kpa=10,
            max_kpa=260,
            rng=np.random.default_rng(0),
            photo_noise=False,
        )
        up = ramp[ramp.direction == "up"].set_index("pressure_kpa")["psi_deg"]
        down = ramp[ramp.direction == "down"].set_index("pressure_kpa")["psi_deg"]
        widths[material] = float((up[down.index] - down).abs().mean())
    assert widths["DS20"] > 2 * widths["SS50"] > 0


def test_bulge_only_past_zero_and_only_for_soft_silicones():
    assert trial_of("DS20").bulge([100.0, 0.0, -105.0, -210.0]).tolist() == pytest.approx(
        [0, 0, 0.175, 0.35]
    )
    assert trial_of("SS50").bulge([-210.0]).tolist() == [0.0]


# ------------------------------------------------------------------ photo sets


def small_set(tmp_path: Path, name: str, **kw) -> tuple[Path, pd.DataFrame]:
    args = {
        "actuators": 2,
        "trials": 2,
        "seed": 5,
        "scene": "lab",
        "step_kpa": 40,
        "scene_overrides": SMALL,
        "psi_fn": toy_psi,
    }
    args.update(kw)
    out = tmp_path / name
    return out, render_photoset(out, "DS20", **args)


def test_photoset_is_valid_and_consistent_with_truth(tmp_path):
    out, truth = small_set(tmp_path, "a")
    assert validate_photoset(out) == []
    ps = load_photoset(out)
    assert ps.settings["positive_turn"] == "ccw" and ps.settings["mm_per_px"] > 0
    assert list(ps.manifest["image"]) == list(truth["image"])
    assert truth["line_in_frame"].all()
    assert (truth["psi_deg"] - truth["psi_image_deg"]).abs().max() < 0.6  # 1 deg camera tilt
    assert {
        "material",
        "actuator",
        "trial",
        "pressure_kpa",
        "direction",
        "bulge",
        "scene",
        "noise_sigma",
    } <= set(truth)
    saved = pd.read_csv(out / "truth.csv")
    assert np.allclose(saved["psi_deg"], truth["psi_deg"], rtol=1e-5)
    assert ps.settings["fixed_end"] == pytest.approx(
        [truth["fixed_end_x"][0], truth["fixed_end_y"][0]], abs=0.01
    )
    img = cv2.imread(str(out / truth["image"][0]))
    assert img.shape == (360, 480, 3)


def test_same_seed_same_bytes_whatever_the_jobs(tmp_path):
    a, _ = small_set(tmp_path, "a", jobs=1)
    b, _ = small_set(tmp_path, "b", jobs=2)
    c, _ = small_set(tmp_path, "c", seed=6)
    ha, hb, hc = sha(a), sha(b), sha(c)
    assert ha == hb
    assert ha["truth.csv"] != hc["truth.csv"]
    assert sum(ha[k] != hc.get(k) for k in ha if k.endswith(".jpg")) > 0.9 * (len(ha) - 3)


def test_default_loading_curve_is_the_model():
    from pipeline import model

    curve = loading_curve("DS20", max_kpa=150)
    p = np.array([0.0, 30.0, 60.0])
    assert np.allclose(curve(p), model.psi_deg("DS20", p), atol=0.5)


def test_cli_writes_a_photoset_and_rejects_bad_keys(tmp_path, capsys):
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
            "130",
            "--set",
            "width=320",
            "--set",
            "height=240",
            "--scene",
            "clean",
        ]
    )
    assert rc == 0 and "images of SS50" in capsys.readouterr().out
    assert validate_photoset(out) == []
    assert main(["synth", str(out), "--material", "SS50", "--set", "colour=red"]) == 2
    assert main(["synth", str(out), "--material", "SS50", "--behaviour", "hysteresis=0.9"]) == 2


def test_ctrl_c_mid_synth_leaves_no_partial_set_and_keeps_the_previous_one(
    sigint_as_in_a_terminal, tmp_path
):
    """SIGINT to the process group (Ctrl-C in a terminal) while `synth` renders with two workers."""
    out = tmp_path / "set"
    cmd = [
        sys.executable,
        "-m",
        "pipeline",
        "synth",
        str(out),
        "--material",
        "SS50",
        "--actuators",
        "2",
        "--trials",
        "1",
        "--step-kpa",
        "20",
        "--scene",
        "clean",
        "--set",
        "width=320",
        "--set",
        "height=240",
        "--jobs",
        "2",
    ]
    render_photoset(
        out,
        "SS50",
        actuators=1,
        trials=1,
        step_kpa=130,
        scene="clean",
        scene_overrides=SMALL,
        psi_fn=toy_psi,
    )  # a previous set in the same place
    previous = sha(out)
    proc = subprocess.Popen(
        cmd,
        cwd=REPO,
        start_new_session=True,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    partial = tmp_path / ".set.partial"
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (partial.is_dir() and any(partial.glob("*.jpg"))):
        time.sleep(0.01)
    assert proc.poll() is None, "synth finished before it could be interrupted"
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and err.rstrip().endswith("synth: interrupted"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]  # no partial set beside it
    assert sha(out) == previous  # the previous set is untouched


def test_committed_sample_images():
    folder = REPO / "sample_images"
    assert validate_photoset(folder) == []
    truth = pd.read_csv(folder / "truth.csv", dtype={"trial": str})
    manifest = load_photoset(folder).manifest
    assert list(truth["image"]) == list(manifest["image"])
    assert (
        truth["scene"].eq("lab").all()
        and truth["psi_deg"].min() < -150 < 150 < truth["psi_deg"].max()
    )
    assert sum(p.stat().st_size for p in folder.iterdir()) < 5 * 2**20
