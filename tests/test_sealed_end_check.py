"""A sealed end left out or given shorter than the photos show reads |psi| high: the rows say so
(customer 37: 36 rows ``ok`` 5-7 deg off without ``sealed_end_mm``, 26 with 4 for its 8 mm).
Measured as a user measures a rendered ramp (the real pipeline), its sealed end 25 mm long."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import yaml

from pipeline.photoset_measure import measure_photoset
from pipeline.report.reasons import top_reasons
from pipeline.sealed_end_check import check_sealed_ends
from pipeline.synth.photoset_writer import render_photoset


@pytest.fixture(scope="module")
def ramp(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sealed") / "s"
    truth = render_photoset(
        folder, "DS20", actuators=1, trials=1, seed=3, scene="grey_dots", step_kpa=40,
        scene_overrides={"width": 1280, "height": 960, "sealed_end_mm": 25.0},
    )
    settings = (folder / "photoset.yaml").read_text()
    assert "sealed_end_mm" not in settings
    return folder, settings, truth.set_index("image")["psi_deg"]


def _measured(ramp, sealed_end: str) -> pd.DataFrame:
    folder, settings, truth = ramp
    (folder / "photoset.yaml").write_text(settings + sealed_end)
    out = measure_photoset(folder, jobs=2)
    return out.assign(error_deg=(out["psi_deg"] - out["image"].map(truth)).abs())


@pytest.mark.parametrize(
    ("sealed_end", "cause"),
    [("", "sealed end not given, and this actuator's last 25 mm stay straight in 9 of its photos"),
     ("sealed_end_mm: 10\n", ("sealed end shorter than the photos show: sealed_end_mm is 10 but "
                              "this actuator's last 25 mm stay straight in 9 of its photos"))],
    ids=["left-out", "given-short"],
)
def test_a_sealed_end_shorter_than_the_photos_show_flags_the_rows_it_reads_high(
    ramp, sealed_end, cause
):
    out = _measured(ramp, sealed_end)
    shown = out[["image", "psi_deg", "error_deg", "status", "reason"]]
    said = out["reason"].fillna("").str.startswith(cause)
    assert (out.loc[said, "status"] == "flagged").all()
    # every row 5 deg off or more is flagged for it (before: 7 of 9 within 3-14 deg, ok)
    assert said[out["error_deg"] > 5.0].all(), shown
    assert said.sum() >= 6, shown
    assert out.loc[said, "reason"].str.contains("(about 25 mm)", regex=False).all()
    # the note that a sealed end left out may read |psi| high is not said twice
    assert not out.loc[said, "reason"].str.contains("no sealed_end_mm").any()
    # what the photos show, in angles.csv
    assert np.nanmedian(out["straight_end_mm"]) == pytest.approx(25.0, abs=1.5)


def test_without_a_scale_the_straight_end_is_measured_against_l0_alone(ramp):
    # the body's length without mm_per_px is l0 plus the straight end: against l0 alone the
    # 25 mm read 21 (and a user giving 21 would then pass the check 4 mm short)
    folder, settings, _ = ramp
    unscaled = "".join(s for s in settings.splitlines(keepends=True) if "mm_per_px" not in s)
    out = _measured((folder, unscaled, ramp[2]), "")
    assert np.nanmedian(out["straight_end_mm"]) == pytest.approx(25.0, abs=2.0)
    assert out["reason"].fillna("").str.startswith("sealed end not given").sum() >= 6


def test_a_few_stray_photos_are_no_verdict():
    # 3 of an actuator's 40 photos (20 bent 90 deg or more) read a straight end 3 mm longer than
    # the one given: its high rows were flagged with advice to give the wrong length
    psi = np.r_[np.linspace(0.0, 220.0, 20), np.linspace(220.0, 0.0, 20)]
    seen = np.full(40, np.nan)
    seen[[10, 11, 29]] = 10.0
    rows = pd.DataFrame({"material": "M", "actuator": "A", "psi_deg": psi, "l0_mm": 100.0,
                         "status": "ok", "reason": "", "sealed_end_mm": 7.0,
                         "straight_end_mm": seen})
    assert (check_sealed_ends(rows)["status"] == "ok").all()
    seen[[1, 5, 15, 25, 32]] = 10.5  # 8 of 20: the photos do show it
    assert (check_sealed_ends(rows.assign(straight_end_mm=seen))["status"] == "flagged").any()


def test_the_sealed_end_the_photos_show_given_flags_nothing(ramp):
    out = _measured(ramp, "sealed_end_mm: 25\n")
    assert not out["reason"].fillna("").str.contains("sealed end").any()
    assert out.loc[out["status"] == "ok", "error_deg"].max() < 1.5
    assert (out["sealed_end_mm"] == 25.0).all()


def test_a_videos_frames_are_checked_against_the_sealed_end_too(tmp_path):
    # customer 35's step responses are videos: their frames go through the same check
    from pipeline.synth.video import render_video
    from pipeline.video.profile import PressureProfile

    folder = tmp_path / "video"
    truth = render_video(
        folder, "DS20", profile=PressureProfile("steps", max_kpa=160, step_kpa=80, hold_s=0.5),
        fps=4, rest_s=0.3, scene="grey_dots",
        scene_overrides={"width": 1280, "height": 960, "sealed_end_mm": 25.0}, seed=3,
    )
    assert "sealed_end_mm" not in (folder / "photoset.yaml").read_text()
    out = measure_photoset(folder, jobs=2).merge(truth, on=["image", "frame"], suffixes=("", "_t"))
    said = out["reason"].fillna("").str.startswith("sealed end not given, and this actuator's")
    assert said.sum() >= 3 and (out.loc[said, "status"] == "flagged").all()
    assert out.loc[said, "reason"].str.contains(r"in \d+ of its frames").all()  # not "photos"
    error = (out["psi_deg"] - out["psi_image_deg"]).abs()
    assert not ((out["status"] == "ok") & (error > 5.0)).any(), out.loc[error > 5.0, "reason"]
    assert np.nanmedian(out["straight_end_mm"]) == pytest.approx(25.0, abs=1.5)


def test_a_straight_end_a_little_longer_than_given_is_noted_and_counted_as_no_cause():
    # customer 45 gave its caps without their 2 mm domes: the photos showed 1.6-2.7 mm more, too
    # little to flag, and 7 rows read 3-4 deg high, ok, with empty reasons. Now noted (status
    # kept), but not on a right end read a little long, and the note is no cause in the report
    rows = pd.DataFrame({"material": "M", "actuator": "A", "psi_deg": [20.0, 150, 200, 205],
                         "l0_mm": 95.0, "status": ["ok", "ok", "ok", "flagged"],
                         "reason": ["", "", "", "line partly hidden: 80% of l0 visible"],
                         "sealed_end_mm": 10.0, "straight_end_mm": [np.nan, 11.6, 11.5, 11.7]})
    out = check_sealed_ends(rows)
    assert out["status"].tolist() == rows["status"].tolist()
    noted = out["reason"].str.contains("the photos show a longer straight end")
    assert noted.tolist() == [False, True, True, True], out["reason"].tolist()
    assert "11.6 mm stay straight in 3 of its photos, 1.6 mm more than sealed_end_mm (10)" in (
        out["reason"][2]
    )
    assert top_reasons(out.assign(dataset="d")) == {"d": [("line partly hidden", 1)]}
    # a right 10 mm end read 11.2 (12 % long, under the share) is not noted
    right = check_sealed_ends(rows.assign(straight_end_mm=[np.nan, 11.2, 11.1, 11.2]))
    assert not right["reason"].str.contains("longer straight end").any()


def test_a_straight_end_on_a_body_hardly_bent_is_no_witness():
    # customer 55: straight photos of a body with one faint side read a 26 mm straight end for
    # its 4 (the centre line's wander), and with one bent photo's 12 mm every row was flagged
    # "measure it again ... (about 26 mm)"; the advice followed left 20 of 20 rows flagged
    rows = pd.DataFrame({"material": "M", "actuator": "A", "l0_mm": 95.0, "status": "ok",
                         "psi_deg": [-0.4, -0.2, 3.0, 80.0, 200.0, 193.0], "reason": "",
                         "sealed_end_mm": 4.0,
                         "straight_end_mm": [26.8, 26.4, 25.0, np.nan, np.nan, 12.4]})
    out = check_sealed_ends(rows)
    assert (out["status"] == "ok").all(), out["reason"].tolist()
    assert not out["reason"].str.contains("sealed").any()
    # bent photos showing it are a witness as before
    bent = check_sealed_ends(rows.assign(psi_deg=[60.0, 90.0, 120.0, 80.0, 200.0, 193.0],
                                         straight_end_mm=[12.0, 12.5, 12.2, np.nan, np.nan, 12.4]))
    assert bent["reason"].str.contains("about 12 mm").sum() >= 3


def test_straight_ends_that_scatter_are_no_verdict_and_the_long_ones_are_flagged_alone():
    # customer 49's clear body without its empty scene: 3 frames showed 5.9, 13.5 and 22.7 mm
    # for its 6 (two tips not seen whole, reading psi 7-9 deg low); every bent frame was flagged
    # "measure it again ... (about 13 mm)", 9 of 11 right, and the 13 mm advised put 10 frames
    # ok 13-20 deg low
    psi = np.r_[np.linspace(0.0, 210.0, 15)]
    seen = np.full(15, np.nan)
    seen[[5, 6, 7]] = [5.9, 13.5, 22.7]
    rows = pd.DataFrame({"material": "M", "actuator": "A", "psi_deg": psi, "l0_mm": 100.0,
                         "status": "ok", "reason": "", "sealed_end_mm": 6.0,
                         "straight_end_mm": seen})
    out = check_sealed_ends(rows)
    assert out.index[out["status"] == "flagged"].tolist() == [6, 7]
    assert not out["reason"].str.contains("measure it again").any()
    assert out["reason"][6].startswith(
        "this photo's last 13.5 mm stay straight, twice sealed_end_mm (6) or more, where its "
        "actuator's photos show straight ends that scatter (5.9 to 22.7 mm)"
    )
    # too few photos for a verdict: none flagged alone (a 2 mm end given without its dome
    # showed 4.3 and 4.6 in 2 photos, flagged "its tip may not be seen whole", the review)
    few = check_sealed_ends(rows.assign(sealed_end_mm=2.0, straight_end_mm=np.where(
        np.arange(15) < 13, np.nan, 4.5)))
    assert (few["status"] == "ok").all()
    # straight ends that agree are still a verdict
    agree = check_sealed_ends(rows.assign(straight_end_mm=np.where(np.isnan(seen), np.nan, 13.0)))
    assert agree["reason"].str.contains("measure it again").sum() >= 3


def test_a_sealed_end_too_short_to_show_straight_is_seen_by_the_bodys_length(tmp_path):
    # a 12 mm sealed end on a 255 mm body is under the ~3/64 of the line a straight end must
    # span to show (straight_end_mm all NaN); left out, 8 of 9 rows read 5.5-16 deg off, ok, with
    # a note. With mm_per_px given the body's length shows it: l0_mm, plus the centre line's
    # stretch as it bends (a straight line in psi), plus the end that does not bend
    folder = tmp_path / "s"
    truth = render_photoset(
        folder, "DS20", actuators=1, trials=1, seed=3, scene="grey_dots", step_kpa=40,
        scene_overrides={"width": 1280, "height": 960, "sealed_end_mm": 12.0},
    )
    settings = (folder / "photoset.yaml").read_text()
    assert "mm_per_px" in settings and "sealed_end_mm" not in settings
    out = measure_photoset(folder, jobs=2)
    error = (out["psi_deg"] - out["image"].map(truth.set_index("image")["psi_deg"])).abs()
    assert out["straight_end_mm"].isna().all()
    said = out["reason"].fillna("").str.startswith(
        "sealed end not given, and this actuator's last 14 mm run past l0_mm"
    )
    assert said.sum() >= 5 and (out.loc[said, "status"] == "flagged").all(), out["reason"]
    assert said[error > 6.0].all(), out.assign(error=error)[["psi_deg", "error", "status"]]
    # given, nothing is said, and every row is within 3 deg
    (folder / "photoset.yaml").write_text(settings + "sealed_end_mm: 12\n")
    out = measure_photoset(folder, jobs=2)
    error = (out["psi_deg"] - out["image"].map(truth.set_index("image")["psi_deg"])).abs()
    assert not out["reason"].fillna("").str.contains("sealed end").any(), out["reason"]
    assert (out["status"] == "ok").all() and error.max() < 3.0, error


@pytest.mark.parametrize("scale", [0.97, 1.015])
def test_a_right_sealed_end_is_not_flagged_for_a_scale_a_little_off(tmp_path, scale):
    # the review of the body's-length witness: a right 10 mm end (4 mm sealed, 6 mm cap) on a
    # 255 mm body, mm_per_px 2-3 % off, had 7-9 of 11 right rows flagged and advised 3-19 mm;
    # the body's length is only as good as the scale, so its margin is 2.5 % of the length
    folder = tmp_path / "s"
    render_photoset(folder, "DS30", actuators=1, trials=1, seed=3, scene="green_fibre",
                    step_kpa=40, max_kpa=240, scene_overrides={"width": 640, "height": 480})
    settings = yaml.safe_load((folder / "photoset.yaml").read_text())
    settings.update(sealed_end_mm=10.0, mm_per_px=settings["mm_per_px"] * scale)
    (folder / "photoset.yaml").write_text(yaml.safe_dump(settings))
    out = measure_photoset(folder, jobs=2)
    assert not out["reason"].fillna("").str.contains("sealed end").any(), out["reason"].tolist()
    assert (out["status"] == "ok").sum() >= 10
