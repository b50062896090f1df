"""Real photographs with independent labels (tests/data/xia2023_strips, see its README).

The committed photo set is measured as a lab runs it (``measure`` on the folder, one
photoset.yaml, a fixed end per row because the strips are free) and scored against labels.csv.
What must hold: no row is ``ok`` outside its tolerance (a wrong number is flagged or failed, with a
reason in words), and at least as many rows are within tolerance as today (8 of 10, d_20C and
c_20C among them, flagged; the issue's target of 9 is not reached: see ``python -m pipeline bench
realscenes``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pipeline.bench.realscenes import dev_set

DEV_SET = Path(__file__).parent / "data" / "xia2023_strips"


@pytest.fixture(scope="module")
def measured():
    return dev_set(DEV_SET)


def test_no_wrong_ok_on_real_photos(measured):
    ok = measured[measured["status"] == "ok"]
    wrong = ok[ok["error_deg"].abs() > ok["tolerance_deg"]]
    assert wrong.empty, wrong[["image", "psi_deg", "psi_signed_net_deg", "tolerance_deg"]]


def test_real_photos_within_tolerance(measured):
    within = (measured["error_deg"].abs() <= measured["tolerance_deg"]).sum()
    assert within >= 8, measured[["image", "psi_deg", "psi_signed_net_deg", "status", "reason"]]


def test_a_ring_whose_ends_touch_is_opened_by_an_exclude_box_over_the_gap():
    # c_20C's two ends touch through the orange halo: the selection is one closed loop, walked
    # only in part (-252 deg for a label of -333 +- 19); its row's exclude box over the dark gap
    # between the ends opens the ring and it is walked round to its other end. Without the box
    # the reason names that fix.
    from dataclasses import replace

    import cv2
    import pandas as pd

    from pipeline.measure import measure_image
    from pipeline.photoset import load_photoset

    label = pd.read_csv(DEV_SET / "labels.csv").set_index("image").loc["images/c_20C.png"]
    row = load_photoset(DEV_SET).rows[0]
    assert row.exclude  # the committed manifest gives c_20C its box
    img = cv2.imread(str(DEV_SET / "c_20C.png"))
    opened = measure_image(img, row)
    closed = measure_image(img, replace(row, exclude=None))
    tolerance = label["tolerance_deg"]
    assert abs(opened.psi_deg - label["psi_signed_net_deg"]) <= tolerance, opened.psi_deg
    assert abs(closed.psi_deg - label["psi_signed_net_deg"]) > 3 * tolerance, closed.psi_deg
    assert "an exclude box over the gap between them opens the ring" in closed.reason
    assert opened.status == closed.status == "flagged"
    # with the box, a small loop the strip's tail makes is still there: the reason says the box
    # given may miss the gap (customer 26 added the box and was told to add one, as if none was)
    assert "one given may miss the gap" in opened.reason
    assert "one given" not in closed.reason


def test_a_cut_strip_is_measured_to_its_end(tmp_path):
    # the strips have no sealed end (photoset.yaml: free_end: bends): d_60C's red layer ends
    # ragged, its centre line stops short of the end face, and without carrying the end's
    # turning on to the last pixel the near-closed U reads 11 deg low (outside its 10 deg)
    import shutil

    import pandas as pd

    from pipeline.photoset import read_settings, write_settings

    folder = tmp_path / "strips"
    shutil.copytree(DEV_SET, folder)
    label = pd.read_csv(folder / "labels.csv").set_index("image").loc["images/d_60C.png"]
    errors = {}
    for free_end in ("bends", "capped"):
        write_settings(folder, {**read_settings(folder), "free_end": free_end})
        table = dev_set(folder).set_index("image")
        errors[free_end] = abs(table.loc["d_60C.png", "error_deg"])
    assert errors["bends"] <= label["tolerance_deg"] < errors["capped"], errors


@pytest.mark.parametrize(("name", "shrink"), [("d_40C.png", 0.75), ("d_50C.png", 1.0)])
def test_a_real_strip_too_few_pixels_across_for_a_steady_reading_is_flagged(name, shrink):
    # customer 51's variants of the dev set: d_40C shrunk to 0.75 (INTER_AREA) read +4.8 for a
    # label of +17.3 +- 10, and d_50C with noise (sigma 4) +44.0 for +56.5 +- 10, both ok; the
    # red layer is 4-6 px across, and measured again at 80 % and 125 % of the photo's size their
    # psi moves 9-15 deg.  As shipped, d_50C (ok, 3.6 deg off; 46-71 deg over 8 noise seeds)
    # moves 9 deg so: flagged too
    from dataclasses import replace

    import cv2
    import pandas as pd

    from pipeline.measure import measure_image
    from pipeline.photoset import load_photoset

    ps = load_photoset(DEV_SET)
    i = int(np.flatnonzero(ps.manifest["image"].astype(str).to_numpy() == name)[0])
    row = ps.rows[i]
    assert row is not None and row.fixed_end_px is not None
    img = cv2.imread(str(DEV_SET / name))
    h, w = img.shape[:2]
    size = (round(w * shrink), round(h * shrink))
    img = cv2.resize(img, size, interpolation=cv2.INTER_AREA) if shrink != 1.0 else img
    fx, fy = row.fixed_end_px
    scaled = (round((fx + 0.5) * size[0] / w - 0.5), round((fy + 0.5) * size[1] / h - 0.5))
    res = measure_image(img, replace(row, fixed_end_px=scaled))
    assert res.status == "flagged", (res.psi_deg, res.reason)
    from pipeline.measure.core import STEADY_DEG

    moved = float(res.reason.split("psi moves ")[1].split(" deg")[0])
    assert moved > STEADY_DEG and "px across here, too few for a steady reading" in res.reason
    label = pd.read_csv(DEV_SET / "labels.csv").set_index("image").loc[f"images/{name}"]
    assert np.isfinite(res.psi_deg) and label["tolerance_deg"] == 10.0


def test_every_doubtful_real_photo_says_why(measured):
    doubtful = measured[measured["status"] != "ok"]
    assert len(doubtful) and doubtful["reason"].str.len().min() > 10
    # words, not reprs
    assert not doubtful["reason"].str.contains(r"\(\(\(|array\(|np\.", regex=True).any()
    # a runaway fit's figure is not quoted (c_20C's smooth fit ran to thousands of degrees)
    quoted = doubtful["reason"].str.extractall(r"disagree by (\d+) deg")[0].astype(int)
    assert (quoted <= 360).all(), quoted
    assert doubtful["reason"].str.contains("disagree by more than a full turn").any()


def test_an_overlay_shows_the_status_the_ramp_check_gave(tmp_path):
    # c_30C is ok on its own and flagged by the ramp check (line length): its overlay, drawn
    # green before the check, says so along its bottom; d_50C, flagged on its own (its reading
    # is not steady) and not by the ramp check, is left as drawn
    import cv2
    import numpy as np

    from pipeline.photoset_measure import measure_photoset

    angles = measure_photoset(DEV_SET, overlays_dir=tmp_path)
    assert angles.set_index("image").loc["c_30C.png", "status"] == "flagged"

    def orange_at_bottom(name):
        band = cv2.imread(str(tmp_path / name))[-32:].astype(int)
        b, g, r = band[..., 0], band[..., 1], band[..., 2]
        return bool(((r > 180) & (g > 100) & (g < 200) & (b < 90)).sum() > 30)

    assert orange_at_bottom("c_30C.jpg")
    assert not orange_at_bottom("d_50C.jpg")
    assert np.isfinite(angles["psi_deg"]).all()


@pytest.mark.parametrize(("name", "magic"), [("sheet.png", b"\x89PNG"), ("sheet.JPG", b"\xff\xd8")])
def test_the_preview_of_the_dev_set_is_written_as_its_name_says(tmp_path, name, magic):
    import cv2

    from pipeline.preview import write_preview

    path, tiles = write_preview(DEV_SET, tmp_path / name)
    assert tiles == 4  # first and last photo of each strip's temperature series
    assert path.read_bytes()[:4].startswith(magic)
    assert cv2.imread(str(path)) is not None


def test_a_preview_name_that_is_no_image_format_is_refused(tmp_path):
    from pipeline.errors import UserInputError
    from pipeline.preview import write_preview

    with pytest.raises(UserInputError, match=r"\.jpg or \.png"):
        write_preview(DEV_SET, tmp_path / "sheet.gif")
    assert not (tmp_path / "sheet.gif").exists()


def test_an_overlay_of_a_small_photo_is_enlarged_and_shows_its_reason_wrapped(tmp_path):
    # the dev strips are 200 px wide: their overlays were 200 px with one 90-character reason
    # line running off the photo; now enlarged, with the reason wrapped in a band of at most
    # 30 % of the photo (the report's strip crops that band off)
    import cv2

    from pipeline.measure import measure_image
    from pipeline.measure.overlay import (
        LINE_PX,
        draw_overlay,
        final_status_text,
        note_final_status,
        overlay_lines,
    )
    from pipeline.photoset import load_photoset
    from pipeline.report.strip import crop_banner

    ps = load_photoset(DEV_SET)
    img = cv2.imread(str(DEV_SET / "c_20C.png"))
    res = measure_image(img, ps.rows[0])
    assert res.status == "flagged" and len(res.reason) > 300
    out = draw_overlay(img, res, title="c_20C.png")
    assert out.shape[1] == 640
    photo_h = round(img.shape[0] * 640 / img.shape[1])
    lines = overlay_lines(res, "c_20C.png", 640, photo_h)
    assert len(lines) >= 5 and lines[-1].endswith("...")
    # the text is a band above the photo, not over it: the photo's top rows are all in view
    band = 12 + LINE_PX * len(lines)
    assert band <= 0.3 * photo_h and out.shape[0] == band + photo_h
    top = cv2.resize(img, (640, photo_h), interpolation=cv2.INTER_LINEAR)[:band]
    assert np.abs(out[band : 2 * band].astype(int) - top.astype(int)).mean() < 2.0
    noted = note_final_status(out, "flagged", "breaks its ramp", "")
    assert noted.shape[0] > out.shape[0] and (noted[: out.shape[0]] == out).all()
    assert crop_banner(noted).shape[0] == photo_h
    # the report's photo strip shows the photo alone, its bands cut before it is made small
    # (customer 22's strip kept a sliver of one band or the other on 4 of 6 tiles)
    from pipeline.report.strip import load_thumbnail

    path = tmp_path / "overlay.jpg"
    cv2.imwrite(str(path), noted)
    thumb = load_thumbnail(path, banner=True)
    assert thumb is not None and thumb.shape[0] == round(photo_h * thumb.shape[1] / 640)
    assert " ".join(lines[2:]).startswith(res.reason.split(";")[0])
    assert final_status_text("flagged", "breaks its ramp; x", "x") == (
        "then flagged: also breaks its ramp"
    )


def test_the_realscenes_bench_scores_the_real_photos_alone_with_n_0(capsys):
    # --n 0 (no rendered analogues) used to crash on scoring an empty table after the real photos
    from pipeline.bench.realscenes import main

    assert main(["--n", "0"]) == 0
    out = capsys.readouterr().out
    assert "xia2023_strips" in out and "synthetic analogues" not in out
    with pytest.raises(SystemExit):  # refused before the real photos run
        main(["--n", "-1"])
    assert "xia2023_strips" not in capsys.readouterr().out


def test_the_realscenes_bench_sets_a_scene_knob_in_every_analogue(capsys):
    # --set shadow=0.5: darker shadows in every analogue (where a method breaks is measured from
    # the command line, not a scratch script); an unknown knob is refused with the valid ones
    from pipeline.bench.realscenes import body_cases, main
    from pipeline.errors import UserInputError

    assert main(["--dev-set", "none", "--n", "1", "--no-fixed-direction", "--set", "shadow=0"]) == 0
    assert ", shadow=0 (right" in capsys.readouterr().out
    plain = body_cases(1, scenes=("grey_dots",), width=640, height=480)
    dark = body_cases(1, scenes=("grey_dots",), width=640, height=480, scene_set={"shadow": 0.9})
    assert plain["psi_deg"].iloc[0] != dark["psi_deg"].iloc[0]
    with pytest.raises(UserInputError, match="nokey"):  # refused before the real photos run
        main(["--n", "1", "--set", "nokey=1"])
    assert "xia2023_strips" not in capsys.readouterr().out


def test_an_overlay_marks_the_fixed_end_where_it_was_given_with_the_clamps_direction():
    # two customers read the blue circle as their fixed_end, but it sat where the centre line
    # starts (100-300 px along a translucent body whose base the selection misses); it marks
    # the fixed end as given, and a given fixed_direction_deg is a thin line from it to lay
    # along the body's base
    from dataclasses import replace

    from pipeline.measure.core import failed
    from pipeline.measure.overlay import draw_overlay

    img = np.full((480, 640, 3), 128, np.uint8)
    line = np.c_[np.linspace(150.0, 400.0, 60), np.full(60, 300.0)]
    res = replace(failed("tangents", ""), status="ok", psi_deg=10.0, centreline_px=line)
    out = draw_overlay(img, res, fixed_end_px=(50.0, 300.0), fixed_direction_deg=90.0)
    photo = out[out.shape[0] - 480 :].astype(int)

    def blue(x: int, y: int) -> bool:
        b, g, r = photo[y, x]
        return b > 200 and g < 140 and r < 60

    assert blue(50, 294) and blue(50, 200) and not blue(80, 200)  # the circle, the direction
    assert not blue(150, 294)  # not at the line's start
    # without a given fixed end, the line's start is marked as before
    photo = draw_overlay(img, res)[-480:].astype(int)
    assert blue(150, 294) and not blue(50, 200)
    # without a direction given, the body's own that psi was measured from is drawn from there
    photo = draw_overlay(img, res, base_direction_deg=90.0)[-480:].astype(int)
    assert blue(150, 200) and not blue(50, 200)


def test_an_overlay_whose_psi_the_ramps_base_direction_moved_says_its_final_psi(tmp_path):
    # a customer found an overlay's psi 0.8 deg from angles.csv's with nothing said: the ramp's
    # shared base direction moved it by less than the 1 deg that writes a reason; the final psi
    # is written below the photo, and an overlay whose row nothing changed is left as drawn
    import cv2
    import pandas as pd

    from pipeline.photoset_measure import note_changed_statuses

    for name in ("a.jpg", "b.jpg"):
        cv2.imwrite(str(tmp_path / name), np.full((200, 300, 3), 128, np.uint8))
    drawn = pd.DataFrame({"status": "ok", "reason": "", "psi_deg": [215.2, 100.0]})
    final = drawn.assign(image=["a.jpg", "b.jpg"], psi_deg=[214.4, 100.0])
    note_changed_statuses(final, drawn, tmp_path)
    assert cv2.imread(str(tmp_path / "a.jpg")).shape[0] > 200
    assert cv2.imread(str(tmp_path / "b.jpg")).shape[0] == 200


@pytest.mark.parametrize(
    ("width", "noise", "size", "psi"),
    [
        (5.0, 2.0, (3200, 2400), 200.0),
        (5.0, 2.0, (3200, 2400), -90.0),
        (5.0, 6.0, (1200, 900), 200.0),
        (5.0, 6.0, (1200, 900), -160.0),
    ],
)
def test_a_steady_thin_body_is_not_lost_to_its_steadiness_check(width, noise, size, psi):
    # the review of the steadiness check: a body 22 px across in a 3200x2400 photo, unsteady at
    # /4, was measured at /2, where another flag ("2 candidate bodies") stopped the refinement:
    # flagged 30-170 deg off, right at full size; and a body 8 px across at 1200x900 read the
    # clamp block at 80 % ("psi moves 71-171 deg"): 10 right rows flagged.  Now a finer reading
    # is sought while not ok, and a reading of another object (another width or length) is no
    # evidence
    import cv2
    from test_body import body_photo, settings_for

    from pipeline.measure import measure_image

    img, fe, _ = body_photo(psi, width=width, noise=noise, seed=int(width + abs(psi)))
    k = size[0] / img.shape[1]
    img = cv2.resize(img, size, interpolation=cv2.INTER_CUBIC if k > 1 else cv2.INTER_AREA)
    fe = ((fe[0] + 0.5) * k - 0.5, (fe[1] + 0.5) * k - 0.5)
    res = measure_image(img, settings_for(fe))
    assert res.status == "ok", res.reason
    assert res.psi_deg == pytest.approx(psi, abs=4.0)
