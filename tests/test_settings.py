"""Settings are parsed once into MeasureSettings; colours; a bad row is a failed row, not a refused
set."""

from __future__ import annotations

import subprocess
import sys

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline import photoset as ps
from pipeline.measure.colors import ColorError, color_mask, parse_color, pick_color
from pipeline.measure.settings import SettingsError, resolve_settings, settings_problems
from pipeline.photoset_measure import measure_photoset
from pipeline.synth import render_actuator, scene_from

L0_MM = 180.0


# ---------------------------------------------------------------------------------------------
# colours


@pytest.mark.parametrize(
    "name",
    [
        "black",
        "white",
        "grey",
        "gray",
        "red",
        "orange",
        "yellow",
        "green",
        "cyan",
        "blue",
        "purple",
        "magenta",
        "pink",
        "violet",
    ],
)
def test_every_colour_name_parses(name):
    spec = parse_color(name)
    assert spec.ranges and spec.describe().startswith(spec.text)


def test_only_the_name_black_is_the_dark_line_filter():
    assert parse_color("black").dark_line
    # an explicit range that bounds only the value means exactly that range
    spec = parse_color("0,0,0-179,255,60")
    assert not spec.dark_line
    # V = 70: inside 'black' (V <= 80) but not inside V <= 60
    img = np.full((10, 10, 3), 70, np.uint8)
    assert color_mask(img, spec).sum() == 0


def test_lists_of_ranges_in_one_cell_and_in_yaml():
    assert parse_color("red;orange").ranges == parse_color(["red", "orange"]).ranges
    assert len(parse_color("0,90,50-10,255,255;170,90,50-179,255,255").ranges) == 2
    with pytest.raises(ColorError, match="chartreuse"):
        parse_color("red;chartreuse")


def test_colours_are_described_in_words():
    assert parse_color("black").describe() == "black (V <= 80)"
    assert "(" not in parse_color("20,80,90-35,255,255").describe()
    assert "H 0-10 or 170-179" in parse_color("red").describe()


@pytest.mark.parametrize(
    "bgr, wraps", [((40, 40, 200), True), ((200, 120, 40), False), ((128, 128, 128), False)]
)
def test_pick_color_selects_what_was_picked(bgr, wraps):
    img = np.zeros((60, 60, 3), np.uint8)
    img[20:40, 20:40] = bgr
    spec = pick_color(img, 30, 30, 4)
    assert (len(spec.ranges) == 2) == wraps  # red's hue wrap gives two ranges
    mask = color_mask(img, spec)
    assert mask[20:40, 20:40].all() and mask.sum() == 400


def test_a_picked_colour_does_not_reach_into_the_black_around_it():
    # customer 26 picked c_20C's red layer (the real strip photos, on a near-black backdrop):
    # the range went down to V 0, where the black's hue is noise, and took in a third of the
    # photo, 20 % of it near-black
    from pathlib import Path

    img = cv2.imread(str(Path(__file__).parent / "data" / "xia2023_strips" / "c_20C.png"))
    value = cv2.cvtColor(img, cv2.COLOR_BGR2HSV)[..., 2]
    for y in (73, 76, 79):  # clicks on the layer, the last ones by its dark edge
        selected = color_mask(img, pick_color(img, 105, y)) > 0
        assert not (selected & (value < 25)).any(), y
        assert selected.mean() < 0.2 and selected[y, 105], y


def test_pick_color_outside_the_image_is_refused():
    with pytest.raises(ColorError, match="outside"):
        pick_color(np.zeros((10, 10, 3), np.uint8), 12, 3)


# ---------------------------------------------------------------------------------------------
# settings


def test_resolved_settings_are_typed():
    s = resolve_settings(
        l0_mm="210",
        mm_per_px=0.2,
        fixed_end=[np.int64(3), 4.5],
        roi=[0, 0, 100, 50],
        exclude=[[[0, 0], [10, 0], [10, 10]]],
        fixed_direction_deg="90",
        target="body",
        line_color="white",
        free_end=" Bends",
    )
    assert s.free_end == "bends" and resolve_settings(l0_mm=1).free_end == "capped"
    assert s.l0_mm == 210.0 and s.fixed_end_px == (3.0, 4.5) and s.fixed_direction_deg == 90.0
    assert len(s.roi) == 4 and len(s.exclude) == 1 and s.color == parse_color("white")
    assert resolve_settings(l0_mm=1, target="body").color is None  # a body needs no colour
    assert resolve_settings(l0_mm=1).color == parse_color("black")  # a line is black by default


@pytest.mark.parametrize(
    "raw, key",
    [
        ({"l0_mm": 0}, "l0_mm"),
        ({}, "l0_mm"),
        ({"l0_mm": 1, "target": "tip"}, "target"),
        ({"l0_mm": 1, "roi": [5, 5, 1, 1]}, "roi"),
        ({"l0_mm": 1, "exclude": [[[0, 0], [1, 1]]]}, "exclude"),
        ({"l0_mm": 1, "fixed_direction_deg": "left"}, "fixed_direction_deg"),
        ({"l0_mm": 1, "fixed_end": "near"}, "fixed_end"),
        ({"l0_mm": 1, "positive_turn": "left"}, "positive_turn"),
        ({"l0_mm": 1, "free_end": "open"}, "free_end"),
        ({"l0_mm": 1, "background": "nope.jpg"}, "background"),
    ],
)
def test_bad_settings_name_the_key_and_the_fix(raw, key, tmp_path):
    settings, problems = settings_problems(raw, folder=tmp_path)
    assert settings is None and [p.key for p in problems] == [key] and problems[0].fix
    with pytest.raises(SettingsError):
        resolve_settings(raw, folder=tmp_path)


def test_load_photoset_reads_each_file_once(photo_folder, monkeypatch):
    from pipeline import photoset_init

    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0},
    )
    calls = {"yaml": 0, "csv": 0}
    real_yaml, real_csv = ps.yaml.safe_load, ps.pd.read_csv

    def count_yaml(*a, **k):
        calls["yaml"] += 1
        return real_yaml(*a, **k)

    def count_csv(*a, **k):
        calls["csv"] += 1
        return real_csv(*a, **k)

    monkeypatch.setattr(ps.yaml, "safe_load", count_yaml)
    monkeypatch.setattr(ps.pd, "read_csv", count_csv)
    loaded = ps.load_photoset(photo_folder)
    assert len(loaded.rows) == 8 and calls == {"yaml": 1, "csv": 1}
    # the measure command loads the set once, for measuring and for its closing doubts
    from pipeline.cli import main

    calls.update(yaml=0, csv=0)
    assert main(["measure", str(photo_folder), "--out", str(photo_folder / "a.csv")]) == 0
    assert calls == {"yaml": 1, "csv": 1}


@pytest.mark.parametrize(
    ("target", "says", "fix"),
    [("line", "line cut short", "a reminder only"), ("body", "optional for a body",
                                                     "otherwise there is nothing to do"),
     ("body+sealed", "optional for a body", "with sealed_end_mm it places the sealed end")],
)
def test_the_warning_of_a_set_without_a_scale_says_what_it_costs(photo_folder, target, says, fix):
    # a line's psi rests on its measured length without a scale; a body's tip angle does not, and
    # only its length check against l0 is lost (its ramp's other photos still check it): three
    # customers with no ruler found the warning noise they could not act on; with a sealed end
    # the scale places it (customer 16 read "nothing to do", and its curled frames 2-4 deg high)
    from pipeline import photoset_init

    sealed = {"sealed_end_mm": 10.0} if target.endswith("+sealed") else {}
    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0, "target": target.removesuffix("+sealed"), **sealed},
    )
    (warning,) = [
        p for p in ps.validate_photoset(photo_folder, warnings=True) if "mm_per_px" in p.message
    ]
    assert warning.warning and says in warning.message and fix in warning.fix


NO_SEALED_END = "no sealed_end_mm: the tip angle is read where the body's centre line stops"
UNUSED_BODY_KEYS = "free_end and sealed_end_mm are for a body"
UNUSED_METHOD = "method turning is not used where fixed_direction_deg is given"


@pytest.mark.parametrize(
    ("extra", "warnings"),
    [
        # a capped body set without its sealed end: what that costs
        ({"target": "body"}, {NO_SEALED_END}),
        ({"target": "body", "mm_per_px": 0.3, "sealed_end_mm": 6}, set()),
        ({"target": "body", "free_end": "bends"}, set()),
        # body keys on a line set: not used
        ({}, set()),
        ({"free_end": "bends"}, {UNUSED_BODY_KEYS}),
        ({"sealed_end_mm": 5, "mm_per_px": 0.2}, {UNUSED_BODY_KEYS}),
        # a customer's method: turning did nothing, unsaid: with the clamp's direction given a
        # body's psi is its tip tangent against it
        ({"target": "body", "free_end": "bends", "method": "turning",
          "fixed_direction_deg": 90}, {UNUSED_METHOD}),
        ({"target": "body", "free_end": "bends", "method": "turning"}, set()),
        ({"method": "turning", "fixed_direction_deg": 90}, set()),
    ],
)
def test_check_warns_of_the_free_end_settings_a_set_lacks_or_does_not_use(
    photo_folder, extra, warnings
):
    from pipeline import photoset_init

    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0, **extra},
    )
    said = {
        start
        for p in ps.validate_photoset(photo_folder, warnings=True)
        for start in (NO_SEALED_END, UNUSED_BODY_KEYS, UNUSED_METHOD)
        if p.message.startswith(start) and p.warning
    }
    assert said == warnings


@pytest.mark.parametrize("empty_scene", [False, True])
def test_the_sealed_end_warning_names_the_second_look_only_without_an_empty_scene(
    photo_folder, empty_scene
):
    # customer 15 had an empty scene and was told what a set without one lacks
    from pipeline import photoset_init

    cv2.imwrite(str(photo_folder / "empty.png"), np.full((24, 32, 3), 200, np.uint8))
    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0, "target": "body",
                  **({"background": "empty.png"} if empty_scene else {})},
    )
    (warning,) = [p for p in ps.sealed_end_problems(ps.load_photoset(photo_folder))]
    assert warning.message.startswith(NO_SEALED_END)
    assert ("without an empty scene" in warning.message) is not empty_scene


def test_check_refuses_roi_outside_the_photo_and_a_two_point_exclude(photo_folder):
    from pipeline import photoset_init

    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0},
    )
    m = pd.read_csv(photo_folder / "manifest.csv")
    m["roi"] = ["[5000, 5000, 6000, 6000]"] + [""] * (len(m) - 1)
    m["exclude"] = [""] * (len(m) - 1) + ["[[[0, 0], [5, 5]]]"]
    m.to_csv(photo_folder / "manifest.csv", index=False)
    text = "\n".join(map(str, ps.validate_photoset(photo_folder)))
    assert "line 2: roi" in text and "outside" in text
    assert f"line {len(m) + 1}: exclude" in text and "at least 3" in text



def test_a_background_photo_of_another_shape_is_refused_and_its_rows_fail(photo_folder):
    # an empty scene taken in portrait for landscape photos cannot be laid over them: check names
    # the rows, and measure makes each a failed row with the reason, not a number
    import cv2

    from pipeline import photoset_init

    cv2.imwrite(str(photo_folder / "empty.jpg"), np.full((32, 24, 3), 200, np.uint8))
    photoset_init.init_photoset(
        photo_folder,
        "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg",
        settings={"l0_mm": 210.0, "target": "body", "background": "empty.jpg"},
    )
    problems = ps.validate_photoset(photo_folder)
    text = "\n".join(map(str, problems))
    assert len(problems) == 8, text
    assert "line 2:" in text and "background photo empty.jpg is 24x32 px" in text
    assert "the photo is 32x24 px" in text and "orientation" in text
    assert "turned by 90 deg against it" in text  # an orientation tag lost, customer 42
    # said once for its rows (customer 42's check said it 26 times)
    assert ps.problem_lines(problems) == [
        str(problems[0]).replace("line 2:", "lines 2-9 (8 rows):")
    ]
    got = measure_photoset(photo_folder, ramp_check=False)
    assert (got["status"] == "failed").all()
    assert got["reason"].str.contains("background photo empty.jpg is 24x32 px").all()
    # the same shape, another resolution: laid over the photo (resized)
    cv2.imwrite(str(photo_folder / "empty.jpg"), np.full((48, 64, 3), 200, np.uint8))
    assert "background" not in "\n".join(map(str, ps.validate_photoset(photo_folder)))


# ---------------------------------------------------------------------------------------------
# one bad row is one failed row


@pytest.fixture(scope="module")
def small_set(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bad_rows")
    scene = scene_from("clean", width=480, height=360)
    rows = []
    for i, psi in enumerate(np.linspace(150.0, -60.0, 9)):
        r = render_actuator(float(psi), L0_MM, scene, seed=i)
        name = f"p{i}.jpg"
        (folder / name).write_bytes(r.jpeg_bytes)
        rows.append(
            {
                "image": name,
                "pressure_kpa": 10.0 * i,
                "direction": "up",
                "material": "DS20",
                "actuator": "A1",
                "trial": "1",
                "step": i,
                "fixed_end_x": r.fixed_end_px[0],
                "fixed_end_y": r.fixed_end_px[1],
            }
        )
    ps.write_manifest(folder, pd.DataFrame(rows))
    ps.write_settings(folder, {"l0_mm": L0_MM, "mm_per_px": scene.mm_per_px, "line_color": "black"})
    return folder


BAD_ROWS = {
    "pressure_kpa": ("abc", "not a number"),
    "direction": ("sideways", "direction 'sideways' is unknown"),
    "line_color": ("chartreuse", "chartreuse"),
    "material": ("", "material is empty"),
}


def test_each_kind_of_bad_row_fails_alone_and_the_rest_is_measured(small_set, tmp_path):
    import shutil

    folder = tmp_path / "set"
    shutil.copytree(small_set, folder)
    m = pd.read_csv(folder / "manifest.csv", dtype=str)
    m["line_color"] = ""
    for i, (column, (value, _)) in enumerate(BAD_ROWS.items(), start=1):
        m.loc[i, column] = value
    m.loc[6, "pressure_kpa"] = "-150"  # below absolute vacuum
    m.loc[7, "pressure_kpa"] = "-40"  # a vacuum-driven actuator: fine
    m = pd.concat([m, m.iloc[[0]]], ignore_index=True)  # a duplicated row
    m.to_csv(folder / "manifest.csv", index=False)
    # photoset check stays strict and names every row
    check = subprocess.run(
        [sys.executable, "-m", "pipeline", "photoset", "check", str(folder)],
        capture_output=True,
        text=True, check=False,
    )
    assert check.returncode == 1
    for _, message in BAD_ROWS.values():
        assert message in check.stderr
    assert "below absolute vacuum" in check.stderr and "listed twice" in check.stderr
    angles = measure_photoset(folder, ramp_check=False)
    failed = set(angles.index[angles["status"] == "failed"])
    assert failed == {1, 2, 3, 4, 6, 9}, angles[["image", "status", "reason"]]
    for i, (_, message) in enumerate(BAD_ROWS.values(), start=1):
        assert (
            message in angles.loc[i, "reason"]
            and f"manifest line {i + 2}" in angles.loc[i, "reason"]
        )
    assert "vacuum" in angles.loc[6, "reason"] and "twice" in angles.loc[9, "reason"]
    assert (angles.loc[[0, 5, 7, 8], "status"] == "ok").all()
    assert angles.loc[7, "pressure_kpa"] == -40.0
    # the stages after measure take the set as it is, its failed rows out of the curves: the
    # failed 'sideways' row stopped aggregate, and customer 44's run kept the report before it
    from pipeline.aggregate import aggregate_hysteresis, read_angles

    angles.to_csv(tmp_path / "angles.csv", index=False)
    curves = aggregate_hysteresis(read_angles([tmp_path / "angles.csv"]))
    assert curves["n"].sum() == 4 and set(curves["direction"]) == {"up"}, curves


@pytest.mark.parametrize(
    ("raw", "message"),
    [
        ({"sealed_end_mm": -2, "mm_per_px": 0.3}, "must be a length >= 0"),
        ({"sealed_end_mm": "abc", "mm_per_px": 0.3}, "must be a length >= 0"),
        ({"sealed_end_mm": True, "mm_per_px": 0.3}, "must be a length >= 0"),
        ({"sealed_end_mm": 8, "mm_per_px": 0.3, "free_end": "bends"}, "an end that bends"),
    ],
)
def test_a_sealed_end_that_cannot_be_used_is_a_problem_naming_the_key(raw, message):
    settings, problems = settings_problems({"l0_mm": 200, "target": "body", **raw})
    assert settings is None
    assert [p.key for p in problems] == ["sealed_end_mm"] and message in problems[0].message


@pytest.mark.parametrize("target", ["line", "body"])
def test_a_sealed_end_needs_no_scale(target):
    # a line does not use it (check warns of that); a body without mm_per_px turns it into pixels
    # with its length against l0_mm + sealed_end_mm (tests/test_body.py measures that)
    settings, problems = settings_problems({"l0_mm": 200, "sealed_end_mm": 8, "target": target})
    assert problems == [] and settings is not None and settings.sealed_end_mm == 8.0


def test_a_sealed_end_is_a_length_in_mm_or_not_given():
    assert resolve_settings(l0_mm=200, target="body").sealed_end_mm is None
    s = resolve_settings(l0_mm=200, target="body", mm_per_px=0.3, sealed_end_mm="8.5")
    assert s.sealed_end_mm == 8.5
    assert resolve_settings(l0_mm=200, mm_per_px=0.3, sealed_end_mm=0).sealed_end_mm == 0.0


def test_a_number_written_with_a_decimal_comma_is_read_and_a_list_of_them_is_not():
    # 'mm_per_px: 0,3' in photoset.yaml (or a manifest cell) was refused: 'must be a positive
    # number'
    s = resolve_settings(l0_mm="255", mm_per_px="0,3", sealed_end_mm="4,5")
    assert (s.l0_mm, s.mm_per_px, s.sealed_end_mm) == (255.0, 0.3, 4.5)
    with pytest.raises(SettingsError, match="l0_mm = '1,2,3' must be a positive number"):
        resolve_settings(l0_mm="1,2,3")


def test_pick_color_on_a_body_the_colour_of_its_backdrop_points_to_leaving_the_colour_out(
    tmp_path, capsys
):
    # a translucent grey body on grey: every spot picked selects most of the photo, and "pick on
    # a purer spot" was all it said (customer 13: there is none)
    from pipeline.cli import main

    img = np.full((60, 80, 3), 128, np.uint8)
    img[25:35, 10:70] = 136  # the body, a shade lighter
    cv2.imwrite(str(tmp_path / "grey.png"), img)
    assert main(["photoset", "pick-color", str(tmp_path / "grey.png"), "--at", "40,30"]) == 0
    out = capsys.readouterr().out
    assert "that is a lot" in out and "leave line_color out" in out, out
