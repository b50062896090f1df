"""Issue 17: a checkerboard photo in the photo set makes psi the physical angle under a tilted
camera and a real lens; bad board photos are refused or flagged; calibrate / check / preview /
report."""

from __future__ import annotations

import dataclasses
import json
import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from pipeline.errors import UserInputError
from pipeline.measure.calibration import (
    STORE,
    CalibrationCache,
    PlaneCalibration,
    calibrate_views,
    find_board,
    read_store,
)
from pipeline.measure.core import measure_image, plane_centreline
from pipeline.measure.extract import LineExtraction
from pipeline.measure.settings import SettingsError, resolve_settings
from pipeline.photoset import load_photoset, validate_photoset, write_settings
from pipeline.photoset_measure import measure_photoset
from pipeline.synth import make_camera, scene_from
from pipeline.synth.board import render_board
from pipeline.synth.photoset_writer import render_photoset

#: a camera 7 deg off nadir with a barrel lens, at half the lab resolution (fast)
POSE = {"width": 640, "height": 480, "tilt_deg": 7.0, "lens_k1": -0.1, "tilt_azimuth_deg": 50.0}


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "pipeline", *args], capture_output=True, text=True, check=False
    )


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, pd.DataFrame]:
    """A rendered ramp (7 photos) with its board photo: camera tilted 7 deg, k1 = -0.1."""
    folder = tmp_path_factory.mktemp("calibrated")
    truth = render_photoset(
        folder,
        "DS20",
        actuators=1,
        trials=1,
        seed=4,
        scene="lab",
        step_kpa=40.0,
        scene_overrides=POSE,
        board=True,
    )
    return folder, truth


def _copy(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst)
    (dst / STORE).unlink(missing_ok=True)
    return dst


def _yaml(folder: Path) -> dict:
    return yaml.safe_load((folder / "photoset.yaml").read_text())


# --------------------------------------------------------------------------------------------
# the virtual rig: lens and board with exact truth


def test_lens_distortion_is_exact_and_invertible() -> None:
    scene = scene_from("clean", width=640, height=480, tilt_deg=6.0, lens_k1=0.1)
    cam = make_camera(scene, rotation_deg=30.0, fixed_end_px=(200.0, 300.0))
    # the fixed end is where it was asked, as seen
    assert np.allclose(cam.fixed_end_px, (200.0, 300.0), atol=1e-6)
    world = np.array([[0.0, 0.0], [50.0, 20.0], [-80.0, 60.0], [120.0, -40.0]])
    assert np.allclose(cam.from_px(cam.to_px(world)), world, atol=1e-6)
    ideal = dataclasses.replace(cam, k1=0.0).to_px(world)
    shift = np.hypot(*(cam.to_px(world) - ideal).T)
    assert shift.max() > 2.0  # the lens moves points by pixels ...
    centre = np.array([320.0, 240.0])
    radial = np.einsum("ij,ij->i", cam.to_px(world) - ideal, ideal - centre)
    assert (radial[shift > 0.1] > 0).all()  # ... outwards for k1 > 0 (pincushion)


def test_board_photo_corners_are_found_where_they_were_drawn() -> None:
    scene = scene_from("lab", **POSE)
    board = render_board(
        scene, make_camera(scene, rotation_deg=10.0, fixed_end_px=(300.0, 250.0)), seed=2
    )
    found = find_board(cv2.cvtColor(board.image, cv2.COLOR_BGR2GRAY), board.inner_corners)
    assert found is not None and found.shape == (54, 2)
    err = min(
        np.hypot(*(found - board.corners_px).T).max(),
        np.hypot(*(found[::-1] - board.corners_px).T).max(),
    )
    assert err < 0.3


def test_calibration_maps_the_image_to_the_physical_plane() -> None:
    scene = scene_from("lab", **POSE)
    cam = make_camera(scene, rotation_deg=0.0, fixed_end_px=(320.0, 240.0))
    board = render_board(scene, cam, seed=3)
    found = find_board(cv2.cvtColor(board.image, cv2.COLOR_BGR2GRAY), board.inner_corners)
    cal = calibrate_views([found], (640, 480), board.inner_corners, board.square_mm)
    assert cal.rms_px < 0.2 and not cal.doubtful
    assert abs(cal.k1 - scene.lens_k1) < 0.02
    # distances on the plane are the world's, anywhere in the frame (not only on the board)
    world = cam.from_px(
        [[40.0, 40.0], [600.0, 60.0], [620.0, 450.0], [30.0, 440.0], [320.0, 240.0]]
    )
    mm = cal.to_mm(cam.to_px(world))
    d_true = np.hypot(*(world[:, None] - world[None]).transpose(2, 0, 1))
    d_cal = np.hypot(*(mm[:, None] - mm[None]).transpose(2, 0, 1))
    # mm, over up to 440 mm (the frame corners lie beyond the board)
    assert np.abs(d_cal - d_true).max() < 0.5
    assert np.allclose(cal.to_image(cal.to_plane(board.corners_px)), board.corners_px, atol=1e-4)
    # and without the lens model the corners of the frame would be millimetres off
    flat = dataclasses.replace(cal, dist_coeffs=(0.0,) * 5).to_mm(cam.to_px(world))
    assert np.abs(np.hypot(*(flat[:, None] - flat[None]).transpose(2, 0, 1)) - d_true).max() > 2.0


def test_noisy_corners_give_a_doubtful_calibration() -> None:
    scene = scene_from("lab", **POSE)
    board = render_board(
        scene, make_camera(scene, rotation_deg=0.0, fixed_end_px=(320.0, 240.0)), seed=3
    )
    noisy = board.corners_px + np.random.default_rng(0).normal(0, 2.0, board.corners_px.shape)
    cal = calibrate_views([noisy], (640, 480), board.inner_corners, board.square_mm)
    assert cal.rms_px > 1.0 and cal.doubtful


# --------------------------------------------------------------------------------------------
# measuring a calibrated photo set


def test_calibrated_psi_is_the_physical_angle(calibrated) -> None:
    folder, truth = calibrated
    ps = load_photoset(folder)
    cal = ps.rows[0].calibration
    assert cal is not None and cal.plane is not None and not cal.stored
    assert _yaml(folder).get("mm_per_px") is None  # the board gives the scale (not written)
    angles = measure_photoset(folder)
    err = (angles["psi_deg"] - truth["psi_deg"]).abs()
    assert (angles["status"] != "failed").all()
    assert err.max() < 0.5 and err.median() < 0.2, err.tolist()
    l0 = _yaml(folder)["l0_mm"]
    assert ((angles["length_mm"] - l0).abs() < l0 * 0.02).all()  # plane mm
    assert (
        np.allclose(angles["calibration_px"], cal.plane.rms_px)
        and (angles["calibration_mm"] > 0).all()
    )
    from pipeline.photoset_measure import _tasks

    # overlays say so
    assert all(
        f"calibrated ({cal.plane.rms_px:.2f} px)" in t.title for t in _tasks(ps, "auto", None)
    )
    # the same photos measured in the image (today's way) are degrees off the physical angle
    plain = []
    for i, image in enumerate(ps.manifest["image"]):
        s = dataclasses.replace(
            ps.rows[i], calibration=None, mm_per_px=float(truth["mm_per_px"].iloc[0])
        )
        plain.append(measure_image(cv2.imread(str(folder / image)), s).psi_deg)
    plain_err = (np.asarray(plain) - truth["psi_deg"]).abs()
    assert plain_err.median() > 1.0 and plain_err.median() > 5 * err.median()


def test_calibrate_stores_and_measuring_reads_it(calibrated, tmp_path: Path) -> None:
    folder = _copy(calibrated[0], tmp_path / "set")
    before = validate_photoset(folder, warnings=True)
    assert any("not stored" in p.message for p in before)
    run = _run("photoset", "calibrate", str(folder))
    assert run.returncode == 0, run.stderr
    assert (
        "reprojection error" in run.stdout
        and " px, " in run.stdout
        and " mm on the plane" in run.stdout
    )
    stored = read_store(folder)
    assert len(stored) == 1
    ps = load_photoset(folder)
    assert ps.rows[0].calibration.stored and ps.rows[0].calibration.plane == next(
        iter(stored.values())
    )
    assert not any("not stored" in p.message for p in validate_photoset(folder, warnings=True))
    assert _run("photoset", "check", str(folder)).returncode == 0
    # a warning above the threshold
    strict = _run("photoset", "calibrate", str(folder), "--max-error-px", "0.001")
    assert strict.returncode == 0 and "warning: reprojection error above 0.001 px" in strict.stdout
    # a changed board photo is never measured with the old calibration
    img = cv2.imread(str(folder / "board.jpg"))
    cv2.imwrite(str(folder / "board.jpg"), cv2.GaussianBlur(img, (0, 0), 0.7))
    assert not load_photoset(folder).rows[0].calibration.stored


def test_board_not_found_is_refused_naming_the_file_and_the_board_size(
    calibrated, tmp_path: Path
) -> None:
    folder = _copy(calibrated[0], tmp_path / "set")
    first = str(pd.read_csv(folder / "manifest.csv")["image"].iloc[0])
    shutil.copy(folder / first, folder / "board.jpg")  # a photo without a board
    problems = validate_photoset(folder)
    text = "\n".join(map(str, problems))
    assert "board.jpg" in text and "9x6 inner corners" in text and "fix:" in text
    with pytest.raises(UserInputError, match="9x6 inner corners"):
        load_photoset(folder)
    run = _run("photoset", "check", str(folder))
    assert run.returncode == 1 and "board.jpg" in run.stderr and "9x6 inner corners" in run.stderr
    bad = _run("photoset", "calibrate", str(folder))
    assert bad.returncode == 2 and "9x6 inner corners" in bad.stderr  # as its --help says
    assert "2 if one cannot be computed" in " ".join(
        _run("photoset", "calibrate", "--help").stdout.split()
    )


def test_a_pose_photo_without_the_board_may_be_left_out(calibrated, tmp_path: Path) -> None:
    # one blurred pose photo stopped the calibration of a whole set; the fix names leaving it out
    folder = _copy(calibrated[0], tmp_path / "set")
    first = str(pd.read_csv(folder / "manifest.csv")["image"].iloc[0])
    shutil.copy(folder / first, folder / "pose.jpg")  # a photo without a board
    settings = _yaml(folder)
    settings["calibration"]["board"] = ["board.jpg", "pose.jpg"]
    write_settings(folder, settings)
    text = "\n".join(map(str, validate_photoset(folder)))
    assert "'pose.jpg'" in text and "leave pose.jpg out of board" in text, text
    settings["calibration"]["board"] = ["board.jpg"]
    write_settings(folder, settings)
    assert not validate_photoset(folder)


def test_wrong_inner_corner_count_is_refused(calibrated, tmp_path: Path) -> None:
    folder = _copy(calibrated[0], tmp_path / "set")
    settings = _yaml(folder)
    settings["calibration"]["inner_corners"] = [7, 5]
    write_settings(folder, settings)
    text = "\n".join(map(str, validate_photoset(folder)))
    assert "board.jpg" in text and "7x5 inner corners" in text


def test_a_square_size_ten_times_too_small_is_named_by_check(calibrated, tmp_path: Path) -> None:
    # customer 32 gave square_mm 2.5 for 25 mm squares: calibrate and check said nothing, and
    # every row read "line partly hidden: 10% of l0 visible"
    from pipeline.photoset_check import check_photoset

    folder = _copy(calibrated[0], tmp_path / "set")
    assert not [p for p in check_photoset(folder, warnings=True) if "mm per px" in p.message]
    settings = _yaml(folder)
    settings["calibration"]["square_mm"] = settings["calibration"]["square_mm"] / 10
    write_settings(folder, settings)
    (scale,) = [p for p in check_photoset(folder, warnings=True) if "mm per px" in p.message]
    assert "more than the photo could hold even curled into a ring" in scale.message
    assert scale.fix.startswith("check the calibration's square_mm")


def test_board_of_another_resolution_is_refused_and_its_rows_fail(
    calibrated, tmp_path: Path
) -> None:
    folder = _copy(calibrated[0], tmp_path / "set")
    img = cv2.imread(str(folder / "board.jpg"))
    cv2.imwrite(
        str(folder / "board.jpg"), cv2.resize(img, (800, 600), interpolation=cv2.INTER_CUBIC)
    )
    problems = [p for p in validate_photoset(folder) if "800x600" in p.message]
    n = len(pd.read_csv(folder / "manifest.csv"))
    assert len(problems) == n and all(
        p.line is not None and "640x480" in p.message for p in problems
    )
    angles = measure_photoset(folder)  # never a silently wrong number: each photo is a failed row
    assert (angles["status"] == "failed").all() and angles["reason"].str.contains(
        "800x600 px"
    ).all()


def test_a_large_reprojection_error_flags_every_row_using_it(calibrated, tmp_path: Path) -> None:
    folder = _copy(calibrated[0], tmp_path / "set")
    assert _run("photoset", "calibrate", str(folder)).returncode == 0
    store = json.loads((folder / STORE).read_text())
    store["calibrations"][0]["rms_px"] = 1.6  # as a warped or blurred board would give
    (folder / STORE).write_text(json.dumps(store))
    warnings = [p for p in validate_photoset(folder, warnings=True) if "1.60 px" in p.message]
    n = len(pd.read_csv(folder / "manifest.csv"))
    assert len(warnings) == n and all(p.warning and p.line is not None for p in warnings)
    angles = measure_photoset(folder)
    measured = angles["status"] != "failed"
    assert measured.all() and (angles["status"] == "flagged").all()
    assert angles["reason"].str.contains("calibration reprojection error 1.60 px > 1 px").all()


def test_per_row_calibration_for_sets_of_several_sessions(calibrated, tmp_path: Path) -> None:
    """Two sessions with different camera poses in one set, each row naming its own board photo."""
    folder = _copy(calibrated[0], tmp_path / "set")
    other = tmp_path / "other"
    truth2 = render_photoset(
        other,
        "DS20",
        actuators=1,
        trials=1,
        seed=9,
        scene="lab",
        step_kpa=80.0,
        scene_overrides={**POSE, "tilt_deg": 4.0, "lens_k1": 0.08, "tilt_azimuth_deg": 140.0},
        board=True,
    )
    m1 = pd.read_csv(folder / "manifest.csv", dtype=str)
    m2 = pd.read_csv(other / "manifest.csv", dtype=str)
    m2["trial"] = "2"
    m2["image"] = "s2_" + m2["image"]
    for name in truth2["image"]:
        shutil.copy(other / name, folder / f"s2_{name}")
    shutil.copy(other / "board.jpg", folder / "board_s2.jpg")
    m1["calibration"] = "board.jpg"  # a name only: square size and corners from photoset.yaml
    # that print's squares; corners from photoset.yaml
    square = _yaml(other)["calibration"]["square_mm"]
    m2["calibration"] = f"{{board: board_s2.jpg, square_mm: {square}}}"
    # the clamp is elsewhere in the second session's photos
    for m, f in ((m1, folder), (m2, other)):
        m["fixed_end_x"], m["fixed_end_y"] = _yaml(f)["fixed_end"]
    pd.concat([m1, m2]).to_csv(folder / "manifest.csv", index=False)
    ps = load_photoset(folder)
    boards = {Path(r.calibration.boards[0]).name for r in ps.rows}
    assert boards == {"board.jpg", "board_s2.jpg"}
    angles = measure_photoset(folder)
    truth = np.r_[calibrated[1]["psi_deg"], truth2["psi_deg"]]
    err = np.abs(angles["psi_deg"] - truth)
    assert err.max() < 0.6, err.tolist()


def test_without_calibration_the_line_is_measured_in_the_image() -> None:
    pts = np.array([[10.0, 20.0], [11.0, 22.0], [13.0, 23.0]])
    line = LineExtraction(pts, 3.0, False, 1, 100.0, 50.0, 0.0, False, True, (1.5, 2.5))
    s = resolve_settings(l0_mm=100.0, mm_per_px=0.2)
    out, ends, same = plane_centreline(line, s, (480, 640), 1.0)
    np.testing.assert_array_equal(out, pts * [1.0, -1.0])
    assert ends == (1.5, 2.5) and same is s


def test_the_plane_turns_the_fixed_direction_and_scales_the_line() -> None:
    """A plane rotated 30 deg ccw (on screen) against the photo at 0.5 mm per plane px."""
    a = np.deg2rad(30.0)
    # y down
    rot = np.array([[np.cos(a), np.sin(a), 0.0], [-np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    plane = PlaneCalibration((640, 480), (600.0, 0, 319.5, 0, 600.0, 239.5, 0, 0, 1), (0.0,) * 5,
                             tuple(rot.ravel()), 0.5, 0.1, 0.05, 1, 54)
    from pipeline.measure.calibration import Calibration

    s = dataclasses.replace(resolve_settings(l0_mm=100.0, fixed_direction_deg=10.0),
                            calibration=Calibration(("b.jpg",), 20.0, (9, 6), plane))
    pts = np.array([[100.0, 100.0], [110.0, 100.0], [120.0, 100.0], [130.0, 100.0], [140.0, 100.0]])
    line = LineExtraction(pts, 3.0, False, 1, 100.0, 50.0, 0.0, False, True, (4.0, 6.0))
    q, ends, s2 = plane_centreline(line, s, (240, 320), 2.0)
    assert s2.mm_per_px == 0.5 and abs(s2.fixed_direction_deg - 40.0) < 1e-6
    np.testing.assert_allclose(ends, (4.0, 6.0), atol=1e-6)
    np.testing.assert_allclose(np.hypot(*np.diff(q, axis=0).T), 10.0, atol=1e-6)
    with pytest.raises(
        ValueError, match="the photo is 640x360 px but the board photo b.jpg is 640x480 px"
    ):
        plane_centreline(line, s, (180, 320), 2.0)


# --------------------------------------------------------------------------------------------
# settings, preview, report


def test_calibration_settings_are_validated_once_with_every_problem(tmp_path: Path) -> None:
    (tmp_path / "b.jpg").write_bytes(b"")
    with pytest.raises(SettingsError) as err:
        resolve_settings(
            l0_mm=100,
            calibration={"board": "nope.jpg", "inner_corners": [9], "colour": 1},
            folder=tmp_path,
        )
    text = str(err.value)
    assert "'nope.jpg' does not exist" in text and "square_mm is missing" in text
    assert "inner_corners = [9]" in text and "['colour'] unknown" in text
    with pytest.raises(SettingsError, match="must be a positive number"):
        resolve_settings(
            l0_mm=100,
            calibration={"board": "b.jpg", "square_mm": -2, "inner_corners": "9x6"},
            folder=tmp_path,
        )
    with pytest.raises(SettingsError, match="cannot be decoded"):
        resolve_settings(
            l0_mm=100,
            calibration={"board": "b.jpg", "square_mm": 20, "inner_corners": "9x6"},
            folder=tmp_path,
        )


def test_one_board_is_calibrated_once_per_load(calibrated, monkeypatch) -> None:
    from pipeline.measure import calibration

    calls = []
    real = calibration.calibrate_files
    monkeypatch.setattr(calibration, "calibrate_files", lambda *a: calls.append(a) or real(*a))
    folder = calibrated[0]
    ps = load_photoset(folder)
    assert len(calls) == 1 and len({id(r.calibration.plane) for r in ps.rows}) == 1
    cache = CalibrationCache(None)
    spec = ps.rows[0].calibration
    assert cache.resolve(dataclasses.replace(spec, plane=None)).plane == spec.plane


def test_preview_shows_the_rectified_photo(calibrated, tmp_path: Path) -> None:
    from pipeline.preview import TILE_WIDTH_PX, preview_tile

    folder = calibrated[0]
    ps = load_photoset(folder)
    image = ps.image_path(str(ps.manifest["image"].iloc[0]))
    tile = preview_tile(image, ps.rows[0], title="t")
    plain = preview_tile(image, dataclasses.replace(ps.rows[0], calibration=None), title="t")
    assert tile.shape[1] == 3 * TILE_WIDTH_PX and plain.shape[1] == 2 * TILE_WIDTH_PX
    # the rectified photo differs
    assert not np.array_equal(tile[:, 2 * TILE_WIDTH_PX:], tile[:, :TILE_WIDTH_PX])
    run = _run("photoset", "preview", str(folder), "--out", str(tmp_path / "p.jpg"))
    assert run.returncode == 0 and cv2.imread(str(tmp_path / "p.jpg")).shape[1] >= 6 * TILE_WIDTH_PX


def test_report_states_which_sets_are_calibrated(tmp_path: Path) -> None:
    from pipeline.layout.style import report_style
    from pipeline.report.data import Dataset, ReportInputs, load_report_data
    from pipeline.report.summary import calibration_summary, summary_page

    datasets = []
    for name, err in (("bench", 0.05), ("old", None), ("shaky", 1.4)):
        rows = [
            {
                "image": f"{name}{i}.jpg",
                "psi_deg": 200.0 - 30 * i,
                "kappa_per_mm": 0.01,
                "length_mm": 195.0,
                "method": "auto",
                "residual_px": 0.3,
                "status": "ok",
                "reason": "",
                "seconds": 0.1,
                "pressure_kpa": 10.0 * i,
                "direction": "up",
                "material": "DS20",
                "actuator": "A1",
                "trial": "1",
                "step": i,
                "calibration_px": err,
                "calibration_mm": None if err is None else err / 3,
            }
            for i in range(4)
        ]
        path = tmp_path / f"{name}.csv"
        pd.DataFrame(rows).to_csv(path, index=False)
        datasets.append(Dataset(name, path))
    data = load_report_data(ReportInputs(datasets=tuple(datasets)))
    lines = calibration_summary(data)  # page 1's "Camera calibration" lines
    assert lines[0] == (
        "b",
        "bench: calibrated, 4 of 4 photos; reprojection error 0.05 px (0.017 mm on the plane)",
    )
    assert lines[1][1].startswith("old: not calibrated")
    assert lines[2][0] == "w" and "1.40 px" in lines[2][1] and "flagged" in lines[2][1]
    with report_style():
        page1 = " ".join(t.get_text() for t in summary_page(data, "x", [], []).texts)
    assert "Camera calibration" in page1 and "bench: calibrated, 4 of 4 photos" in page1


def test_body_mode_on_a_calibrated_plane_keeps_the_clamp_direction() -> None:
    """Body mode's one hook: the centre line and ``fixed_direction_deg`` are both taken to the
    plane."""
    from test_body import body_photo

    from pipeline.measure.calibration import Calibration

    img, fe, _ = body_photo(100.0, seed=5)
    base = resolve_settings(
        l0_mm=180.0, target="body", fixed_end=[float(v) for v in fe], fixed_direction_deg=0.0
    )
    a = np.deg2rad(30.0)  # the plane turned 30 deg against the photo, 0.3 mm per plane px
    rot = np.array([[np.cos(a), np.sin(a), 0.0], [-np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    plane = PlaneCalibration((1280, 960), (1500.0, 0, 639.5, 0, 1500.0, 479.5, 0, 0, 1), (0.0,) * 5,
                             tuple(rot.ravel()), 0.3, 0.05, 0.01, 1, 54)
    calibrated = dataclasses.replace(base, calibration=Calibration(("b.jpg",), 20.0, (9, 6), plane))
    # body.backdrop_difference's cv2.kmeans (KMEANS_PP_CENTERS) draws from OpenCV's global RNG, so a
    # body result depends on what ran before in the process: seed it to compare the two runs exactly
    cv2.setRNGSeed(0)
    plain = measure_image(img, base)
    cv2.setRNGSeed(0)
    cal = measure_image(img, calibrated)
    assert plain.status == cal.status == "ok", (plain.reason, cal.reason)
    assert cal.psi_deg == pytest.approx(plain.psi_deg, abs=0.05) and cal.psi_deg == pytest.approx(
        100.0, abs=2.5
    )
    assert cal.length_mm == pytest.approx(0.3 * plain.length_px, rel=0.01)  # plane mm
    # overlays stay in the photo's pixels
    np.testing.assert_array_equal(cal.centreline_px, plain.centreline_px)
