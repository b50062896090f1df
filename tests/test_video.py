"""Video photo sets: every frame measured against a synthetic video's truth, timing, bad input."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from pipeline import photoset
from pipeline.errors import UserInputError
from pipeline.photoset_check import check_photoset
from pipeline.photoset_measure import measure_photoset
from pipeline.synth.video import Dynamics, render_video, simulate, toy_actuator
from pipeline.video import measure as video_measure
from pipeline.video.clips import resolve_clips
from pipeline.video.profile import PressureProfile
from pipeline.video.reader import probe_video, read_frames
from pipeline.video.timeline import (
    PressureLog,
    frame_conditions,
    read_pressure_log,
    step_times,
    turning_points,
)

SCENE = {"width": 320, "height": 240, "tilt_deg": 0.0}
MEASURED = ["psi_deg", "status", "reason", "frame", "time_s", "pressure_kpa", "direction", "step"]


def _copy(video_set: Path, tmp_path: Path) -> Path:
    out = tmp_path / "copy"
    shutil.copytree(video_set, out)
    return out


def _video(folder: Path) -> Path:
    return folder / pd.read_csv(folder / "manifest.csv")["video"].iloc[0]


def test_every_frame_is_a_row_with_its_time_pressure_and_direction(video_set, measured):
    truth = pd.read_csv(video_set / "truth.csv")
    assert len(measured) == len(truth) == 135
    assert {
        "frame",
        "time_s",
        "pressure_kpa",
        "measured_pressure_kpa",
        "direction",
        "step",
        "since_step_s",
    } <= set(measured.columns)
    m = measured.merge(truth, on=["image", "frame"], suffixes=("", "_true"), validate="one_to_one")
    # frame k at 0.7 + k / 10 s on the log clock
    assert np.allclose(m["time_s"], m["time_s_true"], atol=1e-6)
    ok = m[m["status"] == "ok"]
    assert len(ok) >= 130
    err = (ok["psi_deg"] - ok["psi_image_deg"]).abs()
    assert err.median() < 0.1 and err.max() < 2.0
    # the setpoint is interpolated from the log; the measured pressure follows the true one
    assert np.allclose(m["pressure_kpa"], m["setpoint_kpa"], atol=1e-6)
    assert (m["measured_pressure_kpa"] - m["pressure_true_kpa"]).abs().median() < 0.5
    # up until the top step is left (its hold included), then down; 4 steps
    top_left = 0.7 + 0.5 + 3 * 2.5
    assert (m.loc[m["time_s"] < top_left - 1e-6, "direction"] == "up").all()
    assert (m.loc[m["time_s"] > top_left + 1e-6, "direction"] == "down").all()
    assert sorted(m["step"].unique()) == [0, 1, 2, 3, 4]
    first = m[m["step"] == 1]
    assert np.isclose(first["since_step_s"].min(), 0.0, atol=0.05)


def test_chunks_in_workers_give_the_same_rows_as_one_pass(video_set, measured, monkeypatch):
    monkeypatch.setattr(
        video_measure,
        "chunk_ranges",
        lambda n, seekable, jobs: [(a, min(16, n - a)) for a in range(0, n, 16)],
    )
    serial = measure_photoset(video_set, jobs=1)
    pd.testing.assert_frame_equal(serial[MEASURED], measured[MEASURED])


def test_truncated_video_keeps_the_frames_it_could_read_and_fails_the_rest(video_set, tmp_path):
    folder = _copy(video_set, tmp_path)
    path = _video(folder)
    data = path.read_bytes()
    path.write_bytes(data[: int(len(data) * 0.6)])
    out = measure_photoset(folder, jobs=2)
    assert len(out) == 135  # the container still announces 135 frames: none disappears
    failed = out[out["status"] == "failed"]
    read = out[out["status"] != "failed"]
    assert 50 < len(read) < 110 and read["frame"].max() < failed["frame"].min()
    assert failed["reason"].str.contains("truncated or corrupt").all()
    assert failed["time_s"].notna().all() and failed["pressure_kpa"].notna().all()
    # frames read after the unusable index (packets skipped from the start) are the same frames
    intact = measure_photoset(video_set, jobs=1).set_index("frame")
    assert np.allclose(read.set_index("frame")["psi_deg"], intact.loc[read["frame"], "psi_deg"])
    text = "\n".join(map(str, check_photoset(folder)))
    assert f"only frames 0-{len(read) - 1} of the 135 of video {path.name} can be read" in text


def test_unreadable_video_is_one_failed_row_or_one_per_listed_frame(video_set, tmp_path):
    folder = _copy(video_set, tmp_path)
    _video(folder).write_bytes(b"\x00" * 5000)
    out = measure_photoset(folder)
    assert len(out) == 1 and out["status"].iloc[0] == "failed" and pd.isna(out["frame"].iloc[0])
    assert "cannot be opened" in out["reason"].iloc[0]
    pd.DataFrame({"frame": range(12), "time_s": np.arange(12) / 10}).to_csv(
        folder / "frames.csv", index=False
    )
    m = pd.read_csv(folder / "manifest.csv")
    m["frame_times"] = "frames.csv"
    m.to_csv(folder / "manifest.csv", index=False)
    out = measure_photoset(folder)
    assert list(out["frame"]) == list(range(12)) and (out["status"] == "failed").all()
    assert np.allclose(out["time_s"], 0.7 + np.arange(12) / 10)


def test_a_log_not_covering_the_video_is_refused_naming_both_spans(video_set, tmp_path):
    folder = _copy(video_set, tmp_path)
    log_path = folder / pd.read_csv(folder / "manifest.csv")["pressure_log"].iloc[0]
    log = pd.read_csv(log_path)
    log[log["time_s"] <= 5.0].to_csv(log_path, index=False)
    problems = [p for p in check_photoset(folder) if not p.warning]
    assert len(problems) == 1 and problems[0].line == 2
    assert "spans 0.70-14.10 s on the log clock" in problems[0].message
    assert "covers 0.00-5.00 s" in problems[0].message
    cli = subprocess.run(
        [sys.executable, "-m", "pipeline", "photoset", "check", str(folder)],
        capture_output=True,
        text=True, check=False,
    )
    assert cli.returncode == 1 and "covers 0.00-5.00 s" in cli.stderr
    out = measure_photoset(folder)
    outside = out["time_s"] > 5.0
    assert (out.loc[outside, "status"] == "failed").all() and out.loc[
        outside, "psi_deg"
    ].isna().all()
    assert out.loc[outside, "reason"].str.contains("outside the pressure log").all()
    assert (out.loc[~outside, "status"] != "failed").all()


def test_frame_times_file_replaces_the_container_times(video_set, tmp_path):
    folder = _copy(video_set, tmp_path)
    jitter = np.random.default_rng(0).uniform(-0.02, 0.02, 135)
    times = np.arange(135) / 10 + jitter
    pd.DataFrame({"frame": range(135), "time_s": times}).to_csv(folder / "frames.csv", index=False)
    m = pd.read_csv(folder / "manifest.csv")
    m["frame_times"] = "frames.csv"
    m.to_csv(folder / "manifest.csv", index=False)
    out = measure_photoset(folder)
    assert np.allclose(out["time_s"], times + 0.7, atol=1e-9)


def test_manifest_rows_of_videos_name_their_problems(video_set, tmp_path):
    folder = _copy(video_set, tmp_path)
    m = pd.read_csv(folder / "manifest.csv", dtype=str)
    bad = pd.concat(
        [m, m.assign(clock_offset_s="soon", pressure_log=""), m.assign(video="", trial="2")],
        ignore_index=True,
    )
    bad.to_csv(folder / "manifest.csv", index=False)
    text = "\n".join(str(p) for p in photoset.load_photoset(folder).problems)
    assert "line 3: video 'SS40_A1_t1_steps.avi' is listed twice (also line 2)" in text
    assert "line 3: pressure_log is empty" in text
    assert "line 3: clock_offset_s 'soon' is not a number" in text
    assert "line 3: material SS40, actuator A1, trial 1 is also line 2" in text
    assert "line 4: video name is empty" in text
    out = measure_photoset(folder)
    assert len(out) == 135 + 135 + 1  # line 4 names no video: one row says why
    assert (out.iloc[:135]["status"] != "failed").all() and (
        out.iloc[135:]["status"] == "failed"
    ).all()
    assert out.iloc[140]["reason"].startswith(
        "manifest line 3: video 'SS40_A1_t1_steps.avi' is listed twice"
    )
    with pytest.raises(UserInputError, match="missing column"):
        pd.DataFrame({"video": ["a.avi"], "material": ["SS40"]}).to_csv(
            folder / "manifest.csv", index=False
        )
        photoset.read_manifest(folder)


def test_mpeg4_frames_are_read_decoded_and_measured_the_same_way(tmp_path):
    folder = tmp_path / "mp4v"
    truth = render_video(
        folder,
        "SS40",
        profile=PressureProfile("ramp", max_kpa=60, rate_kpa_s=60),
        fps=10,
        rest_s=0.2,
        scene="lab",
        scene_overrides=SCENE,
        seed=4,
        codec="mp4v",
    )
    info = probe_video(_video(folder))
    assert info.fourcc in ("FMP4", "mp4v") and not info.packets and info.seekable
    out = measure_photoset(folder, jobs=2)
    m = out.merge(truth, on=["image", "frame"], suffixes=("", "_true"))
    ok = m[m["status"] == "ok"]
    assert len(ok) >= len(m) - 1 and (ok["psi_deg"] - ok["psi_image_deg"]).abs().median() < 0.2


def test_a_video_of_a_body_without_a_line_is_a_body_set_and_measured_as_one(tmp_path):
    # a step response filmed at 720p, as the held-back green-backdrop frames are: the set says
    # target: body (it said line_color: black, and every frame was flagged with a wrong angle)
    folder = tmp_path / "body"
    truth = render_video(
        folder,
        "DS20",
        profile=PressureProfile("steps", max_kpa=80, step_kpa=40, hold_s=0.5),
        fps=6,
        rest_s=0.3,
        scene="green_fibre",
        scene_overrides={"width": 1280, "height": 720},
        seed=2,
    )
    settings = photoset.load_photoset(folder).rows[0]
    assert settings.target == "body" and Path(settings.background_path).is_file()
    out = measure_photoset(folder, jobs=1)
    m = out.merge(truth, on=["image", "frame"], suffixes=("", "_true"))
    err = (m["psi_deg"] - m["psi_image_deg"]).abs()
    ok = m["status"] == "ok"
    # the centre line runs on into the sealed end and the white cap, which its length at
    # mm_per_px shows (10 mm for 10): the frames it reads high (2-4 deg at psi 210) say so
    said = m["reason"].fillna("").str.startswith(
        "sealed end not given, and this actuator's last 10 mm run past l0_mm"
    )
    assert (m.loc[said, "status"] == "flagged").all() and said[m["psi_image_deg"] > 150].all()
    assert (ok | said).mean() >= 0.8 and err[ok].median() < 5.0
    assert truth["psi_image_deg"].max() - truth["psi_image_deg"].min() > 150  # a real step
    assert (err[ok] < 5.0).all()
    # ... unless the actuator's end that does not bend is given (4 mm sealed + 6 mm cap)
    raw = yaml.safe_load((folder / "photoset.yaml").read_text())
    (folder / "photoset.yaml").write_text(yaml.safe_dump({**raw, "sealed_end_mm": 10.0}))
    measured = measure_photoset(folder, jobs=1, overlays_dir=tmp_path / "ov")
    m = measured.merge(truth, on=["image", "frame"], suffixes=("", "_t"))
    err = (m["psi_deg"] - m["psi_image_deg"]).abs()
    ok = m["status"] == "ok"
    assert ok.mean() >= 0.8 and err[ok & (m["psi_image_deg"].abs() >= 180)].max() < 5.0
    assert err[ok].max() < 6.5
    # a frame's overlay draws what a photo's does: the fixed end as given and psi's two
    # directions in blue (customer 15's had only the centre line: the frame's settings were not
    # passed on)
    drawn = [cv2.imread(str(p)) for p in sorted((tmp_path / "ov").glob("*_f*.jpg"))]
    assert drawn
    for img in drawn:
        b, g, r = (img[..., i].astype(int) for i in range(3))
        k = img.shape[1] / 1280  # the overlay is reduced, below a band of text
        fx, fy = np.asarray(settings.fixed_end_px) * k + [0.0, img.shape[0] - 720 * k]
        ys, xs = np.nonzero((b > 200) & (g < 120) & (r < 60))
        away = np.hypot(xs - fx, ys - fy) > 15.0  # not the fixed end's mark
        assert away.sum() > 10, away.sum()


def test_h264_is_written_when_the_build_can_and_refused_by_name_when_not(tmp_path):
    profile = PressureProfile("ramp", max_kpa=20, rate_kpa_s=40)
    try:
        render_video(tmp_path / "h264", "SS40", profile=profile, fps=5, rest_s=0.1, scene="clean",
                     scene_overrides=SCENE, codec="h264")
    except UserInputError as exc:
        assert "cannot encode h264" in str(exc) and "mjpg" in str(exc)
        assert not list((tmp_path / "h264").glob("*.mp4"))
    else:
        assert probe_video(_video(tmp_path / "h264")).frame_count == 6


def test_rendering_is_deterministic(tmp_path):
    kw = {
        "profile": PressureProfile("ramp", max_kpa=30, rate_kpa_s=60),
        "fps": 5,
        "rest_s": 0.2,
        "scene": "lab",
        "scene_overrides": SCENE,
        "seed": 9,
    }
    render_video(tmp_path / "a", "SS40", **kw)
    render_video(tmp_path / "b", "SS40", **kw)
    for name in (
        "manifest.csv",
        "truth.csv",
        "SS40_A1_t1_ramp.avi",
        "SS40_A1_t1_ramp_pressure.csv",
    ):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


# --- the pieces -----------------------------------------------------------------------------


def test_direction_turns_at_confirmed_extremes_only():
    rng = np.random.default_rng(1)
    p = np.concatenate(
        [np.linspace(0, 100, 101), np.full(20, 100.0), np.linspace(100, 0, 101)]
    ) + rng.normal(0, 0.2, 222)
    tp = turning_points(p)
    assert len(tp) == 1 and 100 <= tp[0] <= 121  # at the top hold, not at a noise wiggle
    log = PressureLog("log.csv", np.arange(222) * 0.1, p)
    d = frame_conditions(log, log.time_s)["direction"]
    assert (d[:100] == "up").all() and (d[125:] == "down").all()


def test_steps_are_jumps_followed_by_a_hold_not_a_fast_ramp():
    t = np.arange(0, 20, 0.05)
    steps = PressureProfile("steps", max_kpa=40, step_kpa=20, hold_s=4)
    log = PressureLog("s.csv", t, steps.setpoint_kpa(t))
    assert np.allclose(step_times(log), steps.step_times_s(), atol=0.051)
    # 3 kPa per log row: fast, but no hold
    ramp = PressureProfile("ramp", max_kpa=200, rate_kpa_s=60)
    assert step_times(PressureLog("r.csv", t, ramp.setpoint_kpa(t))).size == 0


def test_a_frame_within_a_steps_log_interval_has_the_setpoint_in_force_not_one_never_set():
    # customer 27's 720p step response: frames between the log's last row at 120 kPa and its
    # first at 160 kPa (20 Hz) read 133.3 kPa, a pressure never asked for
    t = np.arange(0, 20, 0.05)
    steps = PressureProfile("steps", max_kpa=160, step_kpa=40, hold_s=2)
    log = PressureLog("s.csv", t, steps.setpoint_kpa(t), steps.setpoint_kpa(t) + 0.3)
    frames = np.arange(0.5, 19.5, 1 / 30)
    c = frame_conditions(log, frames)
    assert set(np.round(c["pressure_kpa"], 6)) <= {0.0, 40.0, 80.0, 120.0, 160.0}
    # the step itself is where step_times puts it: the frame just before still has the old level
    (j,) = np.flatnonzero(np.isclose(t, step_times(log)[1]))
    before = frame_conditions(log, np.array([t[j] - 0.01, t[j]]))["pressure_kpa"]
    assert before.tolist() == [log.pressure_kpa[j - 1], log.pressure_kpa[j]]
    # the gauge's reading stays interpolated, and so does a continuous ramp's setpoint
    assert not set(np.round(c["measured_pressure_kpa"], 6)) <= {0.3, 40.3, 80.3, 120.3, 160.3}
    ramp = PressureLog("r.csv", np.array([0.0, 1.0, 2.0]), np.array([0.0, 10.0, 20.0]))
    assert frame_conditions(ramp, np.array([0.5, 1.25]))["pressure_kpa"].tolist() == [5.0, 12.5]


def test_every_frame_of_a_stepped_ramps_top_hold_is_rising_and_every_one_after_it_falling():
    # the frames after the log's last row at the top (and before its first a step lower) held
    # the top's setpoint but were called 'down': one 160 kPa frame in the falling leg's loop
    t = np.arange(0, 20, 0.05)
    steps = PressureProfile("steps", max_kpa=160, step_kpa=40, hold_s=2)
    log = PressureLog("s.csv", t, steps.setpoint_kpa(t))
    c = frame_conditions(log, np.arange(0.5, 17.5, 1 / 30))
    top = c["pressure_kpa"] == 160.0
    assert top.sum() > 50 and (c.loc[top, "direction"] == "up").all()
    after = c.index > c.index[top][-1]
    assert (c.loc[after, "direction"] == "down").all() and after.sum() > 100


def test_pressure_log_problems_name_the_line(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("time_s,pressure_kpa\n0,0\n1,x\n")
    assert read_pressure_log(path)[1] == ["log.csv line 3: pressure_kpa 'x' is not a number"]
    path.write_text("time_s,kpa\n0,0\n")
    (problem,) = read_pressure_log(path)[1]
    assert "lacks column(s) ['pressure_kpa'] (its header is ['time_s', 'kpa'])" in problem
    path.write_text("time_s,pressure_kpa,measured_kpa\n0,0,0\n1,10,-200\n")
    assert "below absolute vacuum" in read_pressure_log(path)[1][0]


def test_a_loggers_own_header_with_units_is_read_and_init_says_when_a_log_cannot_be(tmp_path):
    # customer 20: a regulator's log headed 't (s), setpoint (kPa), sensor (kPa)' was accepted by
    # init and refused by check ('lacks column(s)', fix: 'fix the file named'); the user renamed
    # a copy by hand. Its own names with units are read; a header without units still is not
    # (1.2 may be kPa or bar), and init says so at once, naming the video
    from pipeline.errors import UserInputError
    from pipeline.photoset_init import init_video_photoset

    path = tmp_path / "log.csv"
    path.write_text("t (s),setpoint (kPa),sensor (kPa)\n0,0,0.1\n0.05,12.5,11.9\n")
    log, problems = read_pressure_log(path)
    assert problems == [] and log is not None
    assert log.pressure_kpa.tolist() == [0.0, 12.5] and log.measured_kpa.tolist() == [0.1, 11.9]
    # check says which column was read as what (customer 27: nothing confirmed that its sensor
    # column was the measured pressure)
    assert log.read_from == ("t (s)", "setpoint (kPa)", "sensor (kPa)")
    path.write_text("Time [ms],P set (bar),note\n0,0,a\n500,0.8,b\n")
    log, problems = read_pressure_log(path)
    assert problems == [] and log.time_s.tolist() == [0.0, 0.5]
    assert log.pressure_kpa.tolist() == [0.0, 80.0]
    assert log.describe_columns() == (
        "time from 'Time [ms]', setpoint from 'P set (bar)', no measured pressure"
    )
    path.write_text("time,setpoint\n0,0\n1,10\n")
    (problem,) = read_pressure_log(path)[1]
    assert "'Setpoint (kPa)'" in problem
    (tmp_path / "ramp.avi").write_bytes(b"")
    with pytest.raises(UserInputError, match=r"ramp.avi: pressure log log.csv lacks column"):
        init_video_photoset(tmp_path, "*.avi", "log.csv", defaults={"material": "DS20"})
    assert not (tmp_path / "manifest.csv").exists()


def test_a_pressure_log_saved_by_a_european_spreadsheet_is_read(tmp_path):
    # a logger's export opened and saved in Excel where the decimal mark is a comma: ';' between
    # the fields, '0,05' for 0.05 s; it was 'lacks column(s) [time_s, pressure_kpa]'
    path = tmp_path / "log.csv"
    # with the ';;' rows Excel leaves under the data (they were 'time_s ... is not a number')
    path.write_bytes(
        "time_s;pressure_kpa;measured_kpa\r\n0;0;0,1\r\n0,05;12,5;11,9\r\n;;\r\n;;\r\n".encode(
            "utf-8-sig"
        )
    )
    log, problems = read_pressure_log(path)
    assert problems == [] and log is not None
    assert log.time_s.tolist() == [0.0, 0.05] and log.pressure_kpa.tolist() == [0.0, 12.5]
    assert log.measured_kpa is not None and log.measured_kpa.tolist() == [0.1, 11.9]


def test_a_pressure_log_in_bar_or_psi_is_read_as_kpa(video_set, tmp_path):
    # a regulator that logs bar: the set was refused, 'lacks column(s) ['pressure_kpa']'
    folder = tmp_path / "steps"
    shutil.copytree(video_set, folder)
    log_path = next(folder.glob("*_pressure.csv"))
    kpa = pd.read_csv(log_path)
    bar = pd.DataFrame({"time_s": kpa["time_s"], "pressure_bar": kpa["pressure_kpa"] / 100,
                        "measured_psi": kpa["measured_kpa"] / 6.894757293168361})
    bar.to_csv(log_path, index=False)
    log, problems = read_pressure_log(log_path)
    assert problems == [] and log is not None and log.measured_kpa is not None
    assert np.allclose(log.pressure_kpa, kpa["pressure_kpa"], atol=1e-6)
    assert np.allclose(log.measured_kpa, kpa["measured_kpa"], atol=1e-6)
    assert not [p for p in photoset.validate_photoset(folder, decode_images=False) if not p.warning]
    bar["pressure_bar"] = bar["pressure_bar"].astype(object)
    bar.loc[3, "pressure_bar"] = "n/a"
    bar.to_csv(log_path, index=False)
    problem = read_pressure_log(log_path)[1][0]
    assert "line 5: pressure_kpa is missing (an empty or n/a cell)" in problem


def test_first_order_lags_reach_63_percent_after_tau():
    dyn = Dynamics(tau_pressure_s=0.0, tau_psi_s=0.5)
    sim = simulate(
        PressureProfile("steps", max_kpa=50, step_kpa=50, hold_s=5),
        toy_actuator(),
        dyn,
        start_s=0.0,
        end_s=10.0,
    )
    # the step to 50 kPa at 5 s: 210 -> 110 deg
    psi = np.interp([5.0, 5.5, 9.9], sim["time_s"], sim["psi_deg"])
    assert np.isclose(psi[0], 210, atol=0.2) and np.isclose(
        psi[1], 210 - 100 * (1 - np.exp(-1)), atol=0.3
    )
    assert np.isclose(psi[2], 110, atol=0.1)


def test_truncated_avi_cannot_seek_and_is_read_by_skipping(video_set, tmp_path):
    path = tmp_path / "t.avi"
    data = _video(video_set).read_bytes()
    path.write_bytes(data[: int(len(data) * 0.8)])
    info = probe_video(path)
    assert info.frame_count == 135 and not info.seekable
    whole = {f.index: f.data for f in read_frames(probe_video(_video(video_set)), 40, 5)}
    part = list(read_frames(info, 40, 5))
    assert [f.index for f in part] == list(range(40, 45))
    assert all(np.array_equal(f.data, whole[f.index]) for f in part)
    assert [round(f.pts_s, 3) for f in part] == [4.0, 4.1, 4.2, 4.3, 4.4]
    assert cv2.imdecode(part[0].data, cv2.IMREAD_GRAYSCALE).shape == (240, 320)


def test_clips_know_their_span_and_the_log(video_set):
    clip = resolve_clips(photoset.load_photoset(video_set))[0]
    assert clip.n_frames == 135 and clip.clock_offset_s == 0.7 and clip.problems == ()
    assert (
        np.allclose(clip.span_s(), (0.7, 14.1))
        and clip.log is not None
        and clip.log.span_s[0] == 0.0
    )


def test_the_ramp_check_runs_over_time(measured):
    from pipeline.ramp_check import check_ramps

    bad = measured.copy()
    bad.loc[60, "psi_deg"] += 40.0  # one frame read wrongly
    # row order must not matter: frames are ordered by time
    shuffled = bad.sample(frac=1.0, random_state=1)
    out = check_ramps(shuffled).loc[bad.index]
    assert out.loc[60, "status"] == "flagged" and out.loc[60, "reason"].startswith(
        "breaks its ramp"
    )
    assert (out.drop(index=60)["status"] == measured.drop(index=60)["status"]).all()


def test_init_writes_a_video_sets_manifest_from_its_pressure_log(
    video_set, measured, tmp_path, capsys
):
    # a customer with a camera's GX010071.MP4 and a logger's CSV wrote the manifest by hand:
    # init asked for --pressures-kpa, a photo set's; with --pressure-log it writes the video
    # set, the same rows as the renderer's own manifest, and calibration columns like photos'
    from pipeline.cli import main

    own = pd.read_csv(video_set / "manifest.csv").iloc[0]
    folder = tmp_path / "mine"
    folder.mkdir()
    for name in (own["video"], own["pressure_log"], "photoset.yaml"):
        shutil.copy(video_set / name, folder / name)
    init = ["photoset", "init", str(folder), "--pattern"]
    assert main([*init, "*.avi"]) == 2
    assert "is a video: give its pressure log with --pressure-log" in capsys.readouterr().err
    assert main([*init, "*.avi", "--pressure-log", "nolog.csv"]) == 2
    assert "its pressure log nolog.csv is not in" in capsys.readouterr().err
    assert main([*init, "{material}_{actuator}_t{trial}*.avi", "--pressure-log",
                 own["pressure_log"], "--clock-offset-s", str(own["clock_offset_s"])]) == 0
    mine = pd.read_csv(folder / "manifest.csv")
    assert mine.iloc[0][list(mine.columns)].astype(str).tolist() == (
        own[list(mine.columns)].astype(str).tolist()
    )
    capsys.readouterr()
    assert main(["photoset", "check", str(folder)]) == 0
    # and check says what it checked: the video's span on the log clock, the log's
    said = capsys.readouterr().out
    assert "135 frames at 10 fps, 0.70-14.10 s on the log clock (clock_offset_s 0.7)" in said
    assert f"{own['pressure_log']} covers 0.00-" in said and "0 to 80 kPa" in said, said
    out = measure_photoset(folder, jobs=1)
    pd.testing.assert_frame_equal(out[MEASURED], measured[MEASURED])
    assert {"calibration_px", "calibration_mm"} <= set(measured.columns)


def test_the_preview_of_a_video_set_shows_its_first_most_bent_and_last_frames(video_set, tmp_path):
    # the README's step 2 is the preview; it refused a video set ("preview reads photos")
    from pipeline.photoset import load_photoset
    from pipeline.preview import frame_pressures_kpa, preview_frames, write_preview
    from pipeline.video.clips import resolve_clips

    path, tiles = write_preview(video_set, tmp_path / "sheet.png")
    assert tiles == 3 and cv2.imread(str(path)) is not None
    (clip,) = resolve_clips(load_photoset(video_set))
    pressure = frame_pressures_kpa(clip)
    first, top, last = preview_frames(pressure)
    assert (first, last) == (0, 134) and pressure[top] == 80.0
    # a chosen frame (a flagged row's), or the frames the overlays draw (it showed the same
    # three whatever was asked, and refused --image)
    _, tiles = write_preview(video_set, tmp_path / "frames.png", frames=[7, 7, 100])
    assert tiles == 2
    _, tiles = write_preview(video_set, tmp_path / "all.png", every=True)
    assert tiles == 24
    with pytest.raises(UserInputError, match=r"--frame 135: no video of .* holds it \(.* has "
                       r"135 frames; fix: give a frame from 0"):
        write_preview(video_set, tmp_path / "x.png", frames=[135])
    with pytest.raises(UserInputError, match="fix: name a frame with --frame N"):
        write_preview(video_set, tmp_path / "x.png", images=["frame.jpg"])
    # a video that cannot be opened is one tile saying so, not a crash
    broken = _copy(video_set, tmp_path)
    _video(broken).write_bytes(b"not a video")
    path, tiles = write_preview(broken, tmp_path / "broken.png")
    assert tiles == 1 and cv2.imread(str(path)) is not None


def test_a_step_response_filmed_with_a_shutter_open_half_a_frame_is_smeared_and_measured(
    tmp_path,
):
    # --shutter-s: a frame is exposed while the body moves (up to 45 deg a frame here), as a
    # webcam's 1/30 s smears a step response at 15 fps; at rest it is the instantaneous frame
    kw = {
        "profile": PressureProfile("steps", max_kpa=160, step_kpa=160, hold_s=0.6),
        "fps": 15,
        "rest_s": 0.2,
        "scene": "green_fibre",
        "scene_overrides": {"width": 1280, "height": 720},
        "seed": 3,
    }
    truth = render_video(tmp_path / "sharp", "DS20", **kw)
    render_video(tmp_path / "smeared", "DS20", shutter_s=1 / 30, **kw)
    for d in ("sharp", "smeared"):  # its sealed end and cap (else the frames at rest are flagged)
        settings = tmp_path / d / "photoset.yaml"
        settings.write_text(settings.read_text() + "sealed_end_mm: 10\n")
    name = "DS20_A1_t1_steps.avi"
    assert (tmp_path / "sharp" / "truth.csv").read_bytes() == (
        tmp_path / "smeared" / "truth.csv"
    ).read_bytes()
    caps = [cv2.VideoCapture(str(tmp_path / d / name)) for d in ("sharp", "smeared")]
    change = []
    for _ in range(len(truth)):
        a, b = (cap.read()[1].astype(int) for cap in caps)
        change.append(float(np.abs(a - b).mean()))
    still = np.abs(np.gradient(truth["psi_image_deg"].to_numpy())) < 0.01
    assert still.sum() >= 3 and max(np.array(change)[still]) == 0.0, change
    assert max(change) > 0.3, change  # smeared (the body covers a few per cent of the frame)
    m = measure_photoset(tmp_path / "smeared", jobs=2).merge(
        truth, on=["image", "frame"], suffixes=("", "_true")
    )
    err = (m["psi_deg"] - m["psi_image_deg"]).abs()
    ok = m["status"] == "ok"
    assert ok[still].all() and err[ok].max() < 10.0, m[["psi_deg", "psi_image_deg", "status"]]
    # a frame whose tip is a fan of its places over the exposure says so, and is flagged; the
    # sharp video's frames never do (their free ends are at most 1.08 times the body's width)
    smeared = m["reason"].fillna("").str.contains("smeared, the body moving")
    assert smeared.sum() >= 5 and (m.loc[smeared, "status"] == "flagged").all(), m["reason"]
    assert not smeared[still].any()
    sharp_rows = measure_photoset(tmp_path / "sharp", jobs=2)
    assert not sharp_rows["reason"].fillna("").str.contains("smeared").any()
    with pytest.raises(UserInputError, match="shutter_s"):
        render_video(tmp_path / "x", "DS20", shutter_s=0.1, **kw)  # longer than a frame


def test_a_frame_sequence_is_measured_as_the_video_it_was_cut_from(video_set, measured, tmp_path):
    # customer 16 had the frames ffmpeg cut from a step response (frame_%04d.jpg), not the
    # video: it built a manifest of photos, frame by frame, and aggregate pooled every frame at
    # a setpoint, those still moving too; named by ffmpeg's pattern it is the video again
    from pipeline.cli import main

    folder = _copy(video_set, tmp_path)
    (clip,) = resolve_clips(photoset.load_photoset(folder))
    (folder / "frames").mkdir()
    for frame in read_frames(clip.info, 0, clip.n_frames):  # the MJPEG packets: the same bytes
        (folder / "frames" / f"f_{frame.index + 1:04d}.jpg").write_bytes(frame.data.tobytes())
    _video(folder).unlink()
    (folder / "manifest.csv").unlink()
    log = pd.read_csv(video_set / "manifest.csv")["pressure_log"].iloc[0]
    assert main(["photoset", "init", str(folder), "--pattern", "frames/f_%04d.jpg",
                 "--pressure-log", log, "--clock-offset-s", "0.7", "--fps", "10",
                 "--material", "SS40", "--l0-mm", "200"]) == 0
    assert pd.read_csv(folder / "manifest.csv")["video"].tolist() == ["frames/f_%04d.jpg"]
    assert check_photoset(folder) == []
    out = measure_photoset(folder, jobs=2)
    pd.testing.assert_frame_equal(out[MEASURED], measured[MEASURED])
    # each row names its file (customer 27 could not tell which file a flagged frame was: the
    # image column holds the pattern, and frame counts from 0 where the files count from 1)
    assert out["frame_file"].iloc[[0, 49]].tolist() == ["frames/f_0001.jpg", "frames/f_0050.jpg"]
    # a file missing from the sequence is that frame's failed row; the frames after it keep
    # their numbers, times and angles
    kept = (folder / "frames" / "f_0050.jpg").read_bytes()
    (folder / "frames" / "f_0050.jpg").unlink()
    gap = measure_photoset(folder, jobs=2)
    assert gap.loc[49, "status"] == "failed"
    assert gap.loc[49, "reason"] == (
        "frame 49 of f_%04d.jpg (f_0050.jpg) is missing from the sequence"
    )
    assert gap.loc[49, "frame_file"] == "frames/f_0050.jpg"
    pd.testing.assert_frame_equal(
        gap.drop(index=49)[MEASURED], measured.drop(index=49)[MEASURED]
    )
    assert [p.message for p in check_photoset(folder)] == [
        (
            "1 of the 135 frames of sequence frames/f_%04d.jpg are missing (1) or cannot be "
            "decoded: frame 49; they will be failed rows"
        )
    ]
    (folder / "frames" / "f_0050.jpg").write_bytes(kept)
    # without its rate a sequence has no times: refused, naming both ways to give them
    manifest = pd.read_csv(folder / "manifest.csv")
    manifest.drop(columns="fps").to_csv(folder / "manifest.csv", index=False)
    said = [p.message for p in check_photoset(folder)]
    assert [m for m in said if "does not say its frame rate; give its fps (a column of "
            "manifest.csv)" in m], said
    manifest.assign(fps="fast").to_csv(folder / "manifest.csv", index=False)
    assert [p.message for p in check_photoset(folder)] == ["fps 'fast' is not a frame rate"]
    manifest.assign(video="frames/g_%04d.jpg").to_csv(folder / "manifest.csv", index=False)
    (problem,) = check_photoset(folder)
    assert "no file of" in problem.message and "g_<number>.jpg" in problem.message


def test_a_videos_timestamp_column_dates_its_frames_for_the_report(video_set, tmp_path):
    # customer 20: 'Photos taken: no date in the inputs' for a video, whose manifest had no place
    # for one in the README; a timestamp column is carried to every frame and dates the set
    from pipeline.report.data import dataset_dates

    folder = tmp_path / "steps"
    shutil.copytree(video_set, folder)
    manifest = pd.read_csv(folder / "manifest.csv")
    manifest.assign(timestamp="2026-12-04 10:15").to_csv(folder / "manifest.csv", index=False)
    angles = measure_photoset(folder, jobs=1)
    assert (angles["timestamp"] == "2026-12-04 10:15").all()
    first, last, _where = dataset_dates(angles, folder)
    assert first == last == "2026-12-04"
