"""The photo-set format: init from file names, validation naming every bad row, atomic writes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest
import yaml

from pipeline import photoset as ps
from pipeline import photoset_init
from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes
from pipeline.measure.colors import ColorError, parse_color

PATTERN = "{material}_{actuator}_t{trial}_s{step}_{pressure_kpa}kPa.jpg"


def test_init_reads_fields_and_infers_direction(photo_folder):
    df = photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    df = df.sort_values(["trial", "step"]).reset_index(drop=True)
    assert list(df["pressure_kpa"]) == [0, 10, 20, 10, 0, 0, 10, 20]
    assert list(df["direction"]) == ["up", "up", "up", "down", "down", "up", "up", "up"]
    assert set(df["material"]) == {"DS30"} and set(df["actuator"]) == {"A2"}
    loaded = ps.load_photoset(photo_folder)
    assert len(loaded.manifest) == 8
    assert all(r.l0_mm == 210.0 for r in loaded.rows)
    assert ps.validate_photoset(photo_folder) == []


def test_each_overlay_names_its_actuator_as_the_preview_does(photo_folder):
    # customer 45's three sets of the same photos, one per actuator, drew overlays titled alike
    from pipeline.photoset_measure import _tasks

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    titles = [t.title for t in _tasks(ps.load_photoset(photo_folder), "auto", None)]
    assert titles[0] == "DS30_A2_t1_s00_0kPa.jpg  DS30 A2 t1  0 kPa up", titles
    assert titles[-1] == "DS30_A2_t2_s02_20kPa.jpg  DS30 A2 t2  20 kPa up", titles


def test_init_refuses_to_overwrite_and_unknown_field(photo_folder):
    photoset_init.init_photoset(photo_folder, PATTERN)
    with pytest.raises(UserInputError, match="already exists"):
        photoset_init.init_photoset(photo_folder, PATTERN)
    with pytest.raises(UserInputError, match="unknown"):
        photoset_init.pattern_to_regex("{pressure}_{pressure_kpa}.jpg")
    with pytest.raises(UserInputError, match="no image .* matches"):
        photoset_init.init_photoset(photo_folder, "{pressure_kpa}psi.png", overwrite=True)


def test_pressure_with_p_as_decimal_point():
    m = photoset_init.pattern_to_regex("P{pressure_kpa}_{direction}.png").match("P12p5_dec.png")
    assert m and m["pressure_kpa"] == "12p5" and m["direction"] == "dec"


def test_a_decimal_comma_in_a_file_name_is_a_pressure_and_directions_are_one_vocabulary(tmp_path):
    # 'A1_12,5kPa.jpg' (a German lab's file names) did not match the pattern and was left out; the
    # directions a file name and a manifest may say are the same words
    from pipeline.constants import direction_name

    for name in ("A1_0kPa_u.jpg", "A1_12,5kPa_inc.jpg", "A1_0kPa_Unloading.jpg"):
        (tmp_path / name).write_bytes(b"")
    df = photoset_init.init_photoset(
        tmp_path, "{actuator}_{pressure_kpa}kPa_{direction}.jpg", defaults={"material": "DS20"}
    )
    got = df.set_index("image")[["pressure_kpa", "direction"]].to_dict("index")
    assert got == {
        "A1_0kPa_u.jpg": {"pressure_kpa": 0.0, "direction": "up"},
        "A1_12,5kPa_inc.jpg": {"pressure_kpa": 12.5, "direction": "up"},
        "A1_0kPa_Unloading.jpg": {"pressure_kpa": 0.0, "direction": "down"},
    }
    assert [direction_name(w) for w in ("u", "INC", "Unloading", "sideways")] == [
        "up", "up", "down", "sideways"
    ]


def test_check_names_every_bad_row_and_its_fix(photo_folder):
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    m = pd.read_csv(photo_folder / "manifest.csv")
    m.loc[1, "direction"] = "sideways"
    m.loc[2, "pressure_kpa"] = np.nan
    m.loc[3, "image"] = "missing.jpg"
    m.loc[4, "step"] = m.loc[0, "step"]  # same trial: duplicate step
    m.to_csv(photo_folder / "manifest.csv", index=False)
    (photo_folder / m.loc[5, "image"]).write_bytes(b"not a jpeg")
    problems = ps.validate_photoset(photo_folder)
    text = "\n".join(map(str, problems))
    assert "line 3: direction 'sideways' is unknown" in text
    assert "line 4: pressure_kpa" in text and "not a number" in text
    assert "line 5: image 'missing.jpg' does not exist" in text
    assert "line 6: step" in text and "repeats" in text
    assert "line 7: image" in text and "cannot be decoded" in text
    assert all(p.fix for p in problems)
    # the command line prints the same and exits 1
    out = subprocess.run(
        [sys.executable, "-m", "pipeline", "photoset", "check", str(photo_folder)],
        capture_output=True,
        text=True, check=False,
    )
    assert out.returncode == 1 and "direction 'sideways'" in out.stderr


def test_init_on_a_folder_of_heic_photos_says_to_export_them(tmp_path):
    for i in range(3):
        (tmp_path / f"IMG_00{i}.HEIC").write_bytes(b"....ftypheic")
    with pytest.raises(UserInputError, match=r"holds 3 photo\(s\) such as 'IMG_000.HEIC': a HEIC"):
        photoset_init.init_photoset(tmp_path, PATTERN)


def test_a_phones_heic_photo_is_named_as_such_with_the_export_fix(photo_folder):
    # OpenCV reads no HEIC (a phone's default) nor camera raw: "corrupt" would send the user
    # looking for damage; check names the format and the fix, measure fails that row alone
    from pipeline.photoset_measure import measure_photoset

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    m = pd.read_csv(photo_folder / "manifest.csv")
    for row, name in ((1, "IMG_0042.HEIC"), (2, "DSC_0007.NEF")):
        (photo_folder / name).write_bytes(os.urandom(3000))
        m.loc[row, "image"] = name
    m.to_csv(photo_folder / "manifest.csv", index=False)
    text = "\n".join(map(str, ps.validate_photoset(photo_folder)))
    assert "line 3: image 'IMG_0042.HEIC' cannot be decoded (a HEIC/HEIF photo, which" in text
    assert "export the photos as JPEG" in text and "Most Compatible" in text
    assert "'DSC_0007.NEF' cannot be decoded (a camera raw file, which OpenCV cannot read)" in text
    # an empty scene from the same phone: check says so on every row that uses it
    (photo_folder / "empty.heic").write_bytes(os.urandom(3000))
    settings = yaml.safe_load((photo_folder / "photoset.yaml").read_text())
    settings["background"] = "empty.heic"
    (photo_folder / "photoset.yaml").write_text(yaml.safe_dump(settings))
    text = "\n".join(map(str, ps.validate_photoset(photo_folder)))
    assert "line 2: background photo empty.heic cannot be decoded (a HEIC/HEIF photo" in text
    angles = measure_photoset(photo_folder).set_index("image")
    assert angles.loc["IMG_0042.HEIC", "status"] == "failed"
    assert "a HEIC/HEIF photo" in angles.loc["IMG_0042.HEIC", "reason"]
    assert "a camera raw file" in angles.loc["DSC_0007.NEF", "reason"]
    others = angles.drop(index=["IMG_0042.HEIC", "DSC_0007.NEF"])  # blank photos: measured,
    assert len(others) == len(m) - 2  # found no line, and said so
    assert not others["reason"].str.contains("cannot be decoded").any(), others["reason"].tolist()


def test_missing_l0_is_reported_unless_every_row_has_it(photo_folder):
    photoset_init.init_photoset(photo_folder, PATTERN)
    assert any("l0_mm is missing" in str(p) for p in ps.validate_photoset(photo_folder))
    m = pd.read_csv(photo_folder / "manifest.csv")
    m["l0_mm"] = 180.0
    m.to_csv(photo_folder / "manifest.csv", index=False)
    assert ps.validate_photoset(photo_folder) == []


def test_row_overrides_win_over_folder_settings(photo_folder):
    photoset_init.init_photoset(
        photo_folder, PATTERN, settings={"l0_mm": 210.0, "line_color": "black", "fixed_end": [5, 6]}
    )
    m = pd.read_csv(photo_folder / "manifest.csv")
    m["l0_mm"] = [np.nan] * (len(m) - 1) + [150.0]
    m["line_color"] = ["blue"] + [np.nan] * (len(m) - 1)
    m.to_csv(photo_folder / "manifest.csv", index=False)
    rows = ps.load_photoset(photo_folder).rows
    assert rows[-1].l0_mm == 150.0 and all(r.l0_mm == 210.0 for r in rows[:-1])
    assert rows[0].color == parse_color("blue") and all(
        r.color == parse_color("black") for r in rows[1:]
    )
    assert all(r.fixed_end_px == (5.0, 6.0) for r in rows)


def test_bad_settings_values_are_named(photo_folder):
    photoset_init.init_photoset(photo_folder, PATTERN)
    (photo_folder / "photoset.yaml").write_text(
        "l0_mm: -3\npositive_turn: left\nline_color: chartreuse\n"
    )
    text = "\n".join(map(str, ps.validate_photoset(photo_folder)))
    assert "l0_mm = -3" in text and "positive_turn = 'left'" in text and "chartreuse" in text


@pytest.mark.parametrize(
    "value, expected",
    [("red", 2), ("0,0,0-179,255,60", 1), ({"lower": [1, 2, 3], "upper": [4, 5, 6]}, 1)],
)
def test_line_color_ranges(value, expected):
    assert len(parse_color(value).ranges) == expected


def test_line_color_rejects_bad_range():
    with pytest.raises(ColorError):
        parse_color("10,0,0-5,255,255")


def test_append_rows_is_idempotent(tmp_path):
    row = {
        "image": "a.jpg",
        "pressure_kpa": 10,
        "direction": "up",
        "material": "DS20",
        "actuator": "A1",
        "trial": 1,
        "step": 0,
    }
    ps.append_manifest_rows(tmp_path, [row])
    ps.append_manifest_rows(tmp_path, [row, {**row, "image": "b.jpg", "step": 1}])
    df = pd.read_csv(tmp_path / "manifest.csv")
    assert list(df["image"]) == ["a.jpg", "b.jpg"]
    assert not list(tmp_path.glob(".*.tmp"))


def test_atomic_write_gives_normal_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        atomic_write_bytes(tmp_path / "report.pdf", b"%PDF")
    finally:
        os.umask(old)
    assert (tmp_path / "report.pdf").stat().st_mode & 0o777 == 0o644


def test_folder_hsv_range_fills_rows_without_their_own_colour(photo_folder):
    photoset_init.init_photoset(
        photo_folder,
        PATTERN,
        settings={"l0_mm": 210.0, "line_color": {"lower": [0, 0, 0], "upper": [179, 255, 60]}},
    )
    m = pd.read_csv(photo_folder / "manifest.csv")
    m["line_color"] = ["blue"] + [np.nan] * (len(m) - 1)
    m.to_csv(photo_folder / "manifest.csv", index=False)
    rows = ps.load_photoset(photo_folder).rows
    assert rows[0].color == parse_color("blue")
    assert all(
        r.color.ranges == (((0, 0, 0), (179, 255, 60)),) and not r.color.dark_line for r in rows[1:]
    )


def test_overlays_of_photos_named_from_outside_the_set_stay_in_the_overlays_folder(tmp_path):
    # README, "Several actuators in one photo": photos shared from ../photos. Their overlays were
    # written to overlays/../photos/x.jpg: run from the folder above, the photos themselves
    # (customer 46's six originals replaced by 640 px overlays, without a word)
    import cv2

    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("clean", width=480, height=360)
    (tmp_path / "photos").mkdir()
    (tmp_path / "A1").mkdir()
    names = []
    for step, (kpa, angle) in enumerate(zip((0, 20, 40), (200.0, 60.0, -100.0))):
        r = render_actuator(angle, 200.0, scene, seed=step)
        names.append(f"s{step}_{kpa}kPa.jpg")
        (tmp_path / "photos" / names[-1]).write_bytes(r.jpeg_bytes)
    before = {n: (tmp_path / "photos" / n).read_bytes() for n in names}
    pd.DataFrame({
        "image": [f"../photos/{n}" for n in names], "pressure_kpa": [0, 20, 40],
        "direction": "up", "material": "DS20", "actuator": "A1", "trial": 1,
    }).to_csv(tmp_path / "A1" / "manifest.csv", index=False)
    (tmp_path / "A1" / "photoset.yaml").write_text("l0_mm: 200\n")
    # the overlays folder beside the photos' folder: overlays/../photos is photos
    angles = measure_photoset(tmp_path / "A1", overlays_dir=tmp_path / "overlays", ramp_check=False)
    assert (angles["status"] == "ok").all(), angles[["image", "reason"]]
    assert {n: (tmp_path / "photos" / n).read_bytes() for n in names} == before
    for n in names:
        overlay = cv2.imread(str(tmp_path / "overlays" / "photos" / n))
        assert overlay is not None and overlay.shape[1] == 480


def test_photos_in_subfolders_with_the_same_names_keep_their_own_rows_and_overlays(tmp_path):
    # a lab's three-chamber ramps, one subfolder a chamber, the same file names in each: init
    # reads a pattern with '/', and each photo gets its own overlay (they were keyed by the
    # file's stem, so chamber 2's overwrote chamber 1's); chamber 2 is WebP, which init now lists
    import cv2

    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("clean", width=480, height=360)
    psi = {"1": [200.0, 60.0, -100.0], "2": [200.0, 120.0, 10.0]}
    for chamber, ext in (("1", "jpg"), ("2", "webp")):
        (tmp_path / f"chamber{chamber}").mkdir()
        for step, (kpa, angle) in enumerate(zip((0, 20, 40), psi[chamber])):
            r = render_actuator(angle, 200.0, scene, seed=step)
            img = cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), cv2.IMREAD_COLOR)
            cv2.imwrite(str(tmp_path / f"chamber{chamber}" / f"s{step}_{kpa}kPa.{ext}"), img)
    df = photoset_init.init_photoset(
        tmp_path, "chamber{actuator}/s{step}_{pressure_kpa}kPa.*", defaults={"material": "DS20"},
        settings={"l0_mm": 200.0},
    )
    assert sorted(df["image"]) == [
        f"chamber{c}/s{k}_{p}kPa.{e}" for c, e in (("1", "jpg"), ("2", "webp"))
        for k, p in enumerate((0, 20, 40))
    ]
    assert ps.validate_photoset(tmp_path) == []
    angles = measure_photoset(tmp_path, overlays_dir=tmp_path / "ov", ramp_check=False)
    assert (angles["status"] == "ok").all(), angles[["image", "reason"]]
    for chamber in ("1", "2"):
        got = angles[angles["actuator"] == chamber].sort_values("step")["psi_deg"]
        assert np.allclose(got, psi[chamber], atol=3.0), (chamber, got.tolist())
    ov = tmp_path / "ov"
    overlays = sorted(p.relative_to(ov).as_posix() for p in ov.rglob("s*"))
    assert overlays == [
        f"chamber{c}/s{k}_{p}kPa.jpg" for c in "12" for k, p in enumerate((0, 20, 40))
    ]
    one, two = (cv2.imread(str(tmp_path / "ov" / f"chamber{c}" / "s2_40kPa.jpg")) for c in "12")
    assert one is not None and two is not None and np.abs(one.astype(int) - two).mean() > 1.0


def test_a_photo_of_another_size_than_its_set_is_named_by_check(photo_folder):
    # fixed_end, roi, exclude and mm_per_px are pixels of one framing: a phone turned to portrait
    # or a cropped photo puts them elsewhere (measure flagged such photos "no body reaches
    # fixed_end", without saying why)
    import cv2

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    assert not [p for p in ps.validate_photoset(photo_folder, warnings=True) if p.line]
    turned = "DS30_A2_t1_s02_20kPa.jpg"
    cv2.imwrite(str(photo_folder / turned), np.full((32, 24, 3), 200, np.uint8))
    sized = [p for p in ps.validate_photoset(photo_folder, warnings=True) if "framing" in p.message]
    assert len(sized) == 1 and sized[0].warning and sized[0].line == 4, sized
    assert f"image {turned!r} is 24x32 px where 7 of the set's photos are 32x24" in sized[0].message
    assert "manifest.csv" in sized[0].file and "32x24" in sized[0].fix
    assert ps.validate_photoset(photo_folder) == []  # a warning: the set is still measured
    # the fix names each pixel setting the set gives; once the row gives its own of each (the
    # fixed end as the README's fixed_end_x/_y columns) the warning goes (customer 45's stayed)
    settings_file = photo_folder / "photoset.yaml"
    settings_file.write_text(settings_file.read_text() + "roi: [0, 0, 30, 20]\n")

    def framing():
        found = ps.validate_photoset(photo_folder, warnings=True)
        return [p for p in found if "framing" in p.message]

    assert "give this row its own fixed_end, roi in manifest.csv" in framing()[0].fix
    manifest = ps.read_manifest(photo_folder).drop(columns="manifest_line")
    own = manifest["image"] == turned
    for column, value in (("fixed_end_x", 12), ("fixed_end_y", 30)):
        manifest[column] = np.where(own, value, None)
    manifest.to_csv(photo_folder / "manifest.csv", index=False)
    still = framing()
    assert len(still) == 1 and "its own fixed_end, roi" in still[0].fix  # the roi not yet its own
    manifest["roi"] = np.where(own, "[0, 0, 20, 30]", None)
    manifest.to_csv(photo_folder / "manifest.csv", index=False)
    assert not framing()


def test_photos_the_pattern_misses_are_named_by_init_and_check_not_left_out_unseen(
    photo_folder, capsys
):
    # a camera's .JPG, a 'kpa' typed by hand and a copy named '(1)': init matched the first two
    # only with the exact case and left all three out of the manifest without a word
    import cv2

    from pipeline.cli import main

    img = np.full((24, 32, 3), 200, np.uint8)
    names = ("DS30_A2_t3_s00_0KPA.JPG", "DS30_A2_t3_s01_10kpa.jpg", "DS30_A2_t3_s01_10kPa (1).jpg")
    for name in names:
        cv2.imwrite(str(photo_folder / name), img)
    cv2.imwrite(str(photo_folder / "empty.jpg"), img)
    args = ["photoset", "init", str(photo_folder), "--pattern", PATTERN, "--l0-mm", "200"]
    assert main([*args, "--background", "empty.jpg"]) == 0
    out = capsys.readouterr()
    assert "wrote" in out.out and "10 photos" in out.out, out.out
    assert "1 photo(s) do not match the pattern" in out.err
    assert "'DS30_A2_t3_s01_10kPa (1).jpg'" in out.err and "empty.jpg" not in out.err
    manifest = pd.read_csv(photo_folder / "manifest.csv")
    assert manifest.set_index("image").loc["DS30_A2_t3_s00_0KPA.JPG", "pressure_kpa"] == 0.0
    problems = ps.validate_photoset(photo_folder, warnings=True)
    left = [p for p in problems if "not in manifest" in p.message]
    assert len(left) == 1 and left[0].warning and "(1).jpg" in left[0].message, left
    assert "empty.jpg" not in left[0].message  # the empty scene the settings name is not a photo


@pytest.mark.parametrize(
    ("encoding", "separator", "line_end", "space"),
    [
        ("utf-8-sig", ";", "\r\n", ""),  # Excel, "CSV UTF-8", where the decimal mark is a comma
        ("cp1252", ";", "\r\n", ""),  # Excel's "CSV" on Windows there: its code page, not UTF-8
        ("utf-8", "\t", "\n", ""),  # "text, tab delimited"
        ("utf-8", ",", "\n", " "),  # typed by hand, a space after each comma
    ],
)
def test_a_manifest_saved_by_a_spreadsheet_is_read_as_its_comma_separated_twin(
    tmp_path, encoding, separator, line_end, space
):
    # a lab in Germany or France saves manifest.csv from Excel: ';' between the fields and decimal
    # commas; the set was refused ('missing column(s) [image, pressure_kpa, ...]' although the
    # header shows them) and nothing was measured
    import cv2

    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("clean", width=480, height=360)
    rows = [("Aktor_ä_0kPa.jpg", 0.0, "up", 150.0), ("Aktor_ä_12-5kPa.jpg", 12.5, "up", 60.0)]
    for image, _kpa, _direction, psi in rows:
        r = render_actuator(psi, 200.0, scene, seed=3)
        cv2.imwrite(str(tmp_path / image), cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), 1))
    ps.write_settings(tmp_path, {"l0_mm": 200.0, "mm_per_px": scene.mm_per_px})
    decimal = "," if separator != "," else "."
    header = ["image", "pressure_kpa", "direction", "material", "actuator", "trial", "mm_per_px"]
    lines = [header] + [
        [image, f"{kpa:g}".replace(".", decimal), direction, "DS20", "A1", "1",
         f"{scene.mm_per_px}".replace(".", decimal)]
        for image, kpa, direction, _psi in rows
    ]
    text = line_end.join((separator + space).join(cells) for cells in lines) + line_end
    (tmp_path / ps.MANIFEST).write_bytes(text.encode(encoding))
    assert ps.validate_photoset(tmp_path) == []
    manifest = ps.read_manifest(tmp_path)
    assert manifest["image"].tolist() == [r[0] for r in rows]
    assert manifest["pressure_kpa"].tolist() == [0.0, 12.5]
    assert manifest["mm_per_px"].tolist() == [scene.mm_per_px] * 2
    angles = measure_photoset(tmp_path, ramp_check=False)
    assert (angles["status"] == "ok").all(), angles[["image", "reason"]]
    assert angles["pressure_kpa"].tolist() == [0.0, 12.5]
    assert np.allclose(angles["psi_deg"], [r[3] for r in rows], atol=3.0), angles["psi_deg"]


def test_a_manifest_whose_header_names_differ_is_one_problem_naming_the_header_and_the_fix(
    photo_folder,
):
    # 'Photo' and 'P (kPa)': check listed 'missing column(s)' with '(fix: see message)', the file
    # named twice, and left the user to guess which names were wrong
    path = photo_folder / ps.MANIFEST
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    lines = path.read_text().splitlines()
    header = lines[0]
    # the manifest's names written another way are read as meant ('Image' was refused)
    lines[0] = header.replace("image", "Image").replace("pressure_kpa", "Pressure (kPa)")
    path.write_text("\n".join(lines) + "\n")
    assert not [p for p in ps.validate_photoset(photo_folder) if not p.warning]
    assert ps.load_photoset(photo_folder).manifest["pressure_kpa"].notna().all()
    # ... everywhere the manifest is read: a 'Background' column is watched by the digest
    (photo_folder.parent / "empty.jpg").write_bytes(b"x")
    m = pd.read_csv(path)
    m["Background"] = "../empty.jpg"
    m.to_csv(path, index=False)
    assert ps.referenced_files(photo_folder) == ((photo_folder.parent / "empty.jpg").resolve(),)
    lines[0] = header.replace("image", "Photo").replace("pressure_kpa", "P (kPa)")
    path.write_text("\n".join(lines) + "\n")
    problems = ps.validate_photoset(photo_folder)
    assert len(problems) == 1, problems
    (p,) = problems
    assert (p.file, p.line) == (str(path), 1)
    assert "['image', 'pressure_kpa']" in p.message and "'P (kPa)'" in p.message
    assert "see message" not in p.fix and "header" in p.fix
    assert str(path) not in p.message
    out = subprocess.run(
        [sys.executable, "-m", "pipeline", "photoset", "check", str(photo_folder)],
        capture_output=True, text=True, check=False,
    )
    # listed as the set's one problem (exit 1), not the command's error (exit 2)
    assert out.returncode == 1, out.stderr
    assert f"{path} line 1: missing column(s) ['image', 'pressure_kpa']" in out.stderr


def test_a_mistyped_photo_name_and_a_capitalised_direction_are_named_or_read_as_meant(tmp_path):
    # a manifest typed by hand: 'Up' and 'decreasing' for the directions, and a photo named with
    # the camera's '.JPG' and 'kpa' where the file is '..._60kPa.jpg'. Before: 'Up' was a failed
    # row, and the photo 'does not exist' (measure: 'No such file or directory') with no hint
    import cv2

    from pipeline.photoset_measure import measure_photoset
    from pipeline.synth import render_actuator, scene_from

    scene = scene_from("clean", width=480, height=360)
    for name, psi in (("A1_0kPa.jpg", 150.0), ("A1_60kPa.jpg", 60.0), ("A1_0kPa_b.jpg", 150.0)):
        r = render_actuator(psi, 200.0, scene, seed=3)
        cv2.imwrite(str(tmp_path / name), cv2.imdecode(np.frombuffer(r.jpeg_bytes, np.uint8), 1))
    ps.write_settings(tmp_path, {"l0_mm": 200.0, "mm_per_px": scene.mm_per_px})
    (tmp_path / ps.MANIFEST).write_text(
        "image,pressure_kpa,direction,material,actuator,trial\n"
        "A1_0kPa.jpg,0,Up,DS20,A1,1\n"
        "a1_60kpa.JPG,60,Up,DS20,A1,1\n"
        "A1_0kPa_b.jpg,0,decreasing,DS20,A1,1\n"
    )
    assert ps.read_manifest(tmp_path)["direction"].tolist() == ["up", "up", "down"]
    problems = [p for p in ps.validate_photoset(tmp_path) if not p.warning]
    assert [(p.line, p.message) for p in problems] == [
        (3, f"image 'a1_60kpa.JPG' does not exist in {tmp_path}; it has 'A1_60kPa.jpg'")
    ]
    assert problems[0].fix.startswith("correct the name in the 'image' column to 'A1_60kPa.jpg'")
    angles = measure_photoset(tmp_path, ramp_check=False).set_index("image")
    assert angles["status"].to_dict() == {
        "A1_0kPa.jpg": "ok", "a1_60kpa.JPG": "failed", "A1_0kPa_b.jpg": "ok"
    }, angles["reason"]
    assert "it has 'A1_60kPa.jpg'" in angles.loc["a1_60kpa.JPG", "reason"]
    assert angles["direction"].tolist() == ["up", "up", "down"]


def test_a_deleted_photo_is_not_pointed_at_another_rows_photo(tmp_path):
    # customer 30 moved IMG_4310.JPG out of the folder; check said to rename the row to
    # 'IMG_4321.JPG', the photo of another row, which would then be measured at two pressures
    import cv2

    for name in ("IMG_4310.JPG", "IMG_4321.JPG", "IMG_4311.JPG"):
        cv2.imwrite(str(tmp_path / name), np.zeros((40, 60, 3), np.uint8))
    (tmp_path / "IMG_4310.JPG").unlink()
    ps.write_settings(tmp_path, {"l0_mm": 200.0})
    (tmp_path / ps.MANIFEST).write_text(
        "image,pressure_kpa,direction,material,actuator,trial\n"
        "IMG_4310.JPG,100,up,DS20,A1,1\nIMG_4311.JPG,120,up,DS20,A1,1\n"
        "IMG_4321.JPG,0,down,DS20,A1,1\n"
    )
    (missing,) = [p for p in ps.validate_photoset(tmp_path) if p.line == 2]
    assert "it has" not in missing.message and "IMG_4321" not in missing.fix, missing
    assert missing.fix == "copy the photo in or remove the row"
    # a photo no row names is still offered
    cv2.imwrite(str(tmp_path / "IMG_4310.jpg"), np.zeros((40, 60, 3), np.uint8))
    (missing,) = [p for p in ps.validate_photoset(tmp_path) if p.line == 2]
    assert missing.fix.startswith("correct the name in the 'image' column to 'IMG_4310.jpg'")


def test_a_cameras_numbered_photos_take_the_ramps_pressures_in_number_order(tmp_path):
    # IMG_1.JPG ... IMG_11.JPG hold no pressure: init refused the pattern ('the pressure must come
    # from the file name'); now each ramp's pressures are given in photo order, IMG_9 before
    # IMG_10 (as text IMG_10 sorted before IMG_2, which would put the ramp's top in the middle)
    for i in range(1, 12):
        (tmp_path / f"IMG_{i}.JPG").write_bytes(b"")
    with pytest.raises(UserInputError, match="--pressures-kpa"):
        photoset_init.init_photoset(tmp_path, "IMG_*.JPG", defaults={"material": "DS20"})
    assert photoset_init.ramp_pressures("0:100:20") == (0, 20, 40, 60, 80, 100, 80, 60, 40, 20, 0)
    df = photoset_init.init_photoset(
        tmp_path, "IMG_*.JPG", defaults={"material": "DS20"},
        pressures_kpa=photoset_init.ramp_pressures("0:100:20"),
    )
    assert df["image"].tolist() == [f"IMG_{i}.JPG" for i in range(1, 12)]
    assert df["pressure_kpa"].tolist() == [0, 20, 40, 60, 80, 100, 80, 60, 40, 20, 0]
    assert df["direction"].tolist() == ["up"] * 6 + ["down"] * 5
    assert ps.read_manifest(tmp_path)["pressure_kpa"].tolist() == df["pressure_kpa"].tolist()
    with pytest.raises(UserInputError, match=r"has 11 photo\(s\) \(IMG_1.JPG ... IMG_11.JPG\) but "
                       "--pressures-kpa gives 9 pressures"):
        photoset_init.init_photoset(
            tmp_path, "IMG_*.JPG", defaults={"material": "DS20"}, overwrite=True,
            pressures_kpa=photoset_init.ramp_pressures("0:80:20"),
        )
    with pytest.raises(UserInputError, match="use one of the two"):
        photoset_init.init_photoset(
            tmp_path, "IMG_{pressure_kpa}.JPG", overwrite=True, pressures_kpa=(0.0,)
        )
    with pytest.raises(UserInputError, match="cannot be read"):
        photoset_init.ramp_pressures("0:100")
    out = subprocess.run(
        [sys.executable, "-m", "pipeline", "photoset", "init", str(tmp_path), "--pattern",
         "IMG_*.JPG", "--material", "DS20", "--pressures-kpa", "0,50,100,100,50,0,0,0,0,0,0",
         "--overwrite"],
        capture_output=True, text=True, check=False,
    )
    assert out.returncode == 0, out.stderr
    assert ps.read_manifest(tmp_path)["pressure_kpa"].tolist()[:6] == [0, 50, 100, 100, 50, 0]


def test_trials_of_their_own_length_take_their_own_pressures(tmp_path):
    # two trials in camera folders, trial 1 up to 40 kPa and back (5 photos), trial 2 up to 60
    # (7): one --pressures-kpa for every ramp was refused for one of them, and users joined two
    # manifests by hand; now each trial may have its own
    for trial, n in ((1, 5), (2, 7)):
        (tmp_path / f"trial{trial}").mkdir()
        for i in range(1, n + 1):
            (tmp_path / f"trial{trial}" / f"IMG_{i:04d}.JPG").write_bytes(b"")
    base = [sys.executable, "-m", "pipeline", "photoset", "init", str(tmp_path), "--pattern",
            "trial{trial}/IMG_*.JPG", "--material", "DS20", "--l0-mm", "100"]
    out = subprocess.run(base + ["--pressures-kpa", "1=0:40:20"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 2 and "trial 2" in out.stderr and "2=SPEC" in out.stderr, out.stderr
    out = subprocess.run(base + ["--pressures-kpa", "1=0:40:20", "--pressures-kpa", "2=0:60:20"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    assert f"wrote {tmp_path}/photoset.yaml" in out.stdout
    m = ps.read_manifest(tmp_path)
    assert m.groupby("trial")["pressure_kpa"].apply(list).to_dict() == {
        "1": [0, 20, 40, 20, 0], "2": [0, 20, 40, 60, 40, 20, 0]
    }
    assert m.groupby("trial")["direction"].apply(list)["2"] == ["up"] * 4 + ["down"] * 3
    # one spec for every ramp still names the ramp and the per-trial form when it does not fit
    with pytest.raises(UserInputError, match=r"trial 2 has 7 photo\(s\).*--pressures-kpa 2=SPEC"):
        photoset_init.init_photoset(
            tmp_path, "trial{trial}/IMG_*.JPG", defaults={"material": "DS20"}, overwrite=True,
            pressures_kpa=photoset_init.pressure_specs(["0:40:20"]),
        )
    with pytest.raises(UserInputError, match="given twice"):
        photoset_init.pressure_specs(["1=0:40:20", "1=0:60:20"])


def test_ramps_taken_one_after_another_in_one_folder_are_split_into_trials(tmp_path):
    # customer 18: a phone's IMG_5201 ... IMG_5243 in one folder, ramp 1 to 180 kPa (19 photos),
    # three deleted, ramp 2 to 200 (21). Each trial's spec was refused ('trial 1 has 40 photos'),
    # and one 40-value list for both wrote 30 up and 10 down in one trial; now either splits them
    names = [f"IMG_{n}.JPG" for n in [*range(5201, 5220), *range(5223, 5244)]]
    for name in names:
        (tmp_path / name).write_bytes(b"")
    want = {
        "1": list(photoset_init.ramp_pressures("0:180:20")),
        "2": list(photoset_init.ramp_pressures("0:200:20")),
    }
    base = [sys.executable, "-m", "pipeline", "photoset", "init", str(tmp_path), "--pattern",
            "IMG_*.JPG", "--material", "DS20", "--overwrite"]
    for specs in (
        ["--pressures-kpa", "1=0:180:20", "--pressures-kpa", "2=0:200:20"],
        ["--pressures-kpa", ",".join(f"{v:g}" for v in want["1"] + want["2"])],
    ):
        out = subprocess.run(base + specs, capture_output=True, text=True, check=False)
        assert out.returncode == 0, out.stderr
        assert "A1 trial 2: IMG_5223.JPG ... IMG_5243.JPG, 21 photos, 0 -> 200 -> 0 kPa" in (
            out.stdout
        )
        m = ps.read_manifest(tmp_path)
        assert m.groupby("trial")["pressure_kpa"].apply(list).to_dict() == want
        assert m.groupby("trial")["direction"].apply(list).to_dict() == {
            "1": ["up"] * 10 + ["down"] * 9, "2": ["up"] * 11 + ["down"] * 10
        }
        assert m.groupby("trial")["step"].max().to_dict() == {"1": 18, "2": 20}
    # trials' specs that do not add up name the counts, not 'trial 1 has 40 photos'
    out = subprocess.run(base + ["--pressures-kpa", "1=0:180:20", "--pressures-kpa", "2=0:180:20"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 2 and "give 38 pressures (1: 19, 2: 19)" in out.stderr, out.stderr
    # the photo repeated at the bottom begins the next ramp; a hold at the top splits nothing
    assert photoset_init.ramp_starts([0, 50, 0, 0, 50, 0]) == [0, 3]
    assert photoset_init.ramp_starts([0, 50, 50, 0, 0]) == [0]


def test_two_actuators_ramps_and_the_empty_scene_in_one_camera_folder_are_told_apart(tmp_path):
    # customer 22: IMG_1001 ... IMG_1078, actuator A1's two ramps then A2's (21 and 19 photos),
    # and IMG_1079 the empty rig. The A2/... specs were silently dropped ('78 photos but the
    # trials' --pressures-kpa give 38 pressures (1: 19, 2: 19)'), and the empty scene, named
    # by --background, was counted as a ramp's photo
    for n in range(1001, 1080):
        (tmp_path / f"IMG_{n}.JPG").write_bytes(b"")
    specs = {"A1/1": "0:180:20", "A1/2": "0:180:20", "A2/1": "0:200:20", "A2/2": "0:180:20"}
    base = [sys.executable, "-m", "pipeline", "photoset", "init", str(tmp_path), "--pattern",
            "IMG_*.JPG", "--material", "DS30", "--target", "body", "--l0-mm", "255",
            "--background", "IMG_1079.JPG"]
    for key, spec in specs.items():
        base += ["--pressures-kpa", f"{key}={spec}"]
    out = subprocess.run(base, capture_output=True, text=True, check=False)
    assert out.returncode == 0, out.stderr
    m = ps.read_manifest(tmp_path)
    assert "IMG_1079.JPG" not in set(m["image"]) and len(m) == 78
    got = m.groupby(["actuator", "trial"], sort=False)["pressure_kpa"].apply(list).to_dict()
    assert got == {
        tuple(k.split("/")): list(photoset_init.ramp_pressures(v)) for k, v in specs.items()
    }
    assert m.loc[m["image"] == "IMG_1039.JPG", ["actuator", "trial", "step"]].values.tolist() == [
        ["A2", "1", 0]
    ]
    assert "A2 trial 1: IMG_1039.JPG ... IMG_1059.JPG, 21 photos" in out.stdout
    # the ramps' specs that do not add up name each ramp's count
    out = subprocess.run(base[:-2] + ["--pressures-kpa", "A2/2=0:160:20", "--overwrite"],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 2, out.stderr
    assert "give 76 pressures (A1/1: 19, A1/2: 19, A2/1: 21, A2/2: 17)" in out.stderr


def test_a_manifest_kept_in_a_spreadsheets_own_format_is_named_not_silently_ignored(photo_folder):
    # the manifest edited in Excel and saved as manifest.xlsx: manifest.csv, unchanged, was read
    # as it was with no word; a 'Manifest.csv' was only 'missing'
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    path = photo_folder / ps.MANIFEST
    xlsx = photo_folder / "manifest.xlsx"
    xlsx.write_bytes(b"PK")
    os.utime(xlsx, (path.stat().st_mtime + 60,) * 2)
    (warning,) = [
        p for p in ps.validate_photoset(photo_folder, warnings=True) if "xlsx" in p.message
    ]
    assert warning.warning and warning.message == (
        "manifest.xlsx is newer than manifest.csv: edits saved only there are not read"
    )
    out = subprocess.run(  # measure (a Snakemake job's log) says so too
        [sys.executable, "-m", "pipeline", "measure", str(photo_folder), "--out",
         str(photo_folder.parent / "angles.csv")],
        capture_output=True, text=True, check=False,
    )
    assert out.returncode == 0 and "manifest.xlsx is newer than manifest.csv" in out.stderr
    os.utime(xlsx, (path.stat().st_mtime - 60,) * 2)  # older: the CSV was saved after it
    assert not [
        p for p in ps.validate_photoset(photo_folder, warnings=True) if "xlsx" in p.message
    ]
    path.rename(photo_folder / "Manifest.csv")
    (problem,) = [p for p in ps.validate_photoset(photo_folder) if not p.warning]
    assert problem.message == "missing; the folder has ['Manifest.csv', 'manifest.xlsx']"
    assert problem.fix == "rename 'Manifest.csv' to manifest.csv"
    # the workbook itself saved under the CSV's name: its zip bytes were shown as the 'header'
    import zipfile

    with zipfile.ZipFile(path, "w") as book:
        book.writestr("xl/workbook.xml", "<workbook/>")
    (problem,) = [p for p in ps.validate_photoset(photo_folder) if not p.warning]
    assert "it is a spreadsheet workbook (.xlsx, .xls or .ods) named .csv" in problem.message


def test_a_bad_pressure_is_named_as_written_and_a_quoted_decimal_comma_is_a_number(photo_folder):
    # the problem said "pressure_kpa np.float64(nan) is not a number" for any bad cell; and a
    # comma CSV from a German-locale LibreOffice quotes "12,5", which was that same NaN
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    lines = (photo_folder / ps.MANIFEST).read_text().splitlines()
    cells = [line.split(",") for line in lines]
    column = cells[0].index("pressure_kpa")
    cells[1][column], cells[2][column] = "abc", '"12,5"'
    (photo_folder / ps.MANIFEST).write_text("\n".join(",".join(c) for c in cells) + "\n")
    problems = [p for p in ps.validate_photoset(photo_folder) if "pressure_kpa" in p.message]
    assert [(p.line, p.message) for p in problems] == [(2, "pressure_kpa 'abc' is not a number")]
    assert ps.load_photoset(photo_folder).manifest["pressure_kpa"].iloc[1] == 12.5


def test_blank_rows_a_spreadsheet_leaves_are_no_photos_and_line_numbers_stay_true(photo_folder):
    # Excel leaves ',,,,,' rows under the data: each was five problems ('image name is empty',
    # 'material is empty', ...) and a refused set; a blank line in the middle shifted every later
    # line number by one
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    lines = (photo_folder / ps.MANIFEST).read_text().splitlines()
    n = len(lines) - 1
    empty = "," * (lines[0].count(","))
    lines.insert(2, "")
    lines.insert(4, empty)
    lines[6] = lines[6].replace(",up,", ",sideways,").replace(",down,", ",sideways,")
    lines += [empty, empty]
    (photo_folder / ps.MANIFEST).write_text("\n".join(lines) + "\n")
    problems = [p for p in ps.validate_photoset(photo_folder) if not p.warning]
    assert [(p.line, "sideways" in p.message) for p in problems] == [(7, True)]
    assert len(ps.read_manifest(photo_folder)) == n


def test_a_title_above_the_manifests_header_is_named_with_the_fix(photo_folder):
    # a spreadsheet with a title row: the problem showed 'the header has ['Ramp of 3 June', ...]'
    # and asked to name the columns, which the file already did
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    text = (photo_folder / ps.MANIFEST).read_text()
    (photo_folder / ps.MANIFEST).write_text("Ramp of 3 June, DS20\n\n" + text)
    problems = [p for p in ps.validate_photoset(photo_folder) if not p.warning]
    assert [(p.line, p.message[:38]) for p in problems] == [
        (1, "the header is on line 3, not on line 1")
    ]
    assert problems[0].fix.startswith("delete the 2 line(s) above the header")


def test_a_number_that_could_be_either_of_two_is_named_not_guessed(photo_folder):
    # '1,500' is 1500 to an English spreadsheet and 1.5 to a German one: it was read as 1.5
    # without a word; a measured pressure that was no number was dropped without one
    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    m = pd.read_csv(photo_folder / ps.MANIFEST, dtype=str)
    m["measured_pressure_kpa"] = ["1,234.5", "abc"] + [""] * (len(m) - 2)
    m.loc[m.index[2], "pressure_kpa"] = "1,500"
    m.loc[m.index[3], "pressure_kpa"] = "-150"  # checked with a measured_pressure_kpa column too
    m.to_csv(photo_folder / ps.MANIFEST, index=False)
    problems = {p.line: p for p in ps.validate_photoset(photo_folder) if "pressure" in p.message}
    assert sorted(problems) == [3, 4, 5]
    assert "below absolute vacuum" in problems[5].message
    assert problems[3].message == "measured_pressure_kpa 'abc' is not a number"
    assert problems[4].message == (
        "pressure_kpa '1,500' could be either number: 1500 with a thousands separator, or 1.5 "
        "with a decimal comma?"
    )
    assert "without a thousands separator" in problems[4].fix
    assert ps.load_photoset(photo_folder).manifest["measured_pressure_kpa"].iloc[0] == 1234.5
    (photo_folder / ps.SETTINGS).write_text("l0_mm: '1,250'\n")
    problems = [p for p in ps.validate_photoset(photo_folder) if "l0_mm" in p.message]
    assert problems and "1250 with a thousands separator, or 1.25" in problems[0].message


def test_settings_and_a_materials_file_saved_by_windows_notepad_are_read(photo_folder, tmp_path):
    # an older Notepad saves in the Windows code page: 'für' in a comment crashed check, measure
    # and Snakemake with a UnicodeDecodeError traceback
    from pipeline.model.materials import load_materials

    photoset_init.init_photoset(photo_folder, PATTERN)
    (photo_folder / ps.SETTINGS).write_bytes(
        "# Aktor für Versuch 3 (Dragon Skin 30, Länge gemessen)\nl0_mm: 210\n".encode("cp1252")
    )
    assert ps.read_settings(photo_folder)["l0_mm"] == 210
    problems = ps.validate_photoset(photo_folder, decode_images=False)
    assert not [p for p in problems if "l0" in p.message or "YAML" in p.message], problems
    from pipeline.model import materials

    packaged = (Path(materials.__file__).parent / "materials.yaml").read_text()
    mine = tmp_path / "materials.yaml"
    mine.write_bytes(("# Härte: Shore 20A, gemessen am 03.12.\n" + packaged).encode("cp1252"))
    assert load_materials(mine)["DS20"].k_p == load_materials()["DS20"].k_p


def test_a_manifest_in_bar_or_psi_is_read_as_kpa_and_a_bad_cell_is_named(photo_folder):
    # a regulator that shows bar: 'missing column(s) [pressure_kpa]' refused the set
    from pipeline.photoset_measure import measure_photoset

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 210.0})
    m = pd.read_csv(photo_folder / ps.MANIFEST)
    kpa = m.pop("pressure_kpa")
    for column, per_kpa in (("pressure_psi", 6.894757293168361), ("pressure_bar", 100.0)):
        m.insert(1, column, kpa / per_kpa)
        m.to_csv(photo_folder / ps.MANIFEST, index=False)
        assert ps.read_manifest(photo_folder)["pressure_kpa"].tolist() == kpa.tolist()
        del m[column]
    assert ps.validate_photoset(photo_folder, decode_images=False) == []
    angles = measure_photoset(photo_folder, ramp_check=False)
    assert angles["pressure_kpa"].tolist() == kpa.tolist()
    assert angles["pressure_bar"].tolist() == (kpa / 100.0).tolist()  # as written, beside it
    m.insert(1, "pressure_bar", (kpa / 100.0).astype(object))
    m.loc[2, "pressure_bar"], m.loc[3, "pressure_bar"] = "0.4 bar", ""
    m.to_csv(photo_folder / ps.MANIFEST, index=False)
    problems = ps.validate_photoset(photo_folder, decode_images=False)
    assert [(p.line, p.message) for p in problems] == [
        (4, "pressure_kpa '0.4 bar' is not a number"),
        (5, "pressure_kpa is missing (an empty or n/a cell), not a number"),  # was 'nan'
    ]


def test_the_preview_shows_each_ramps_most_bent_photo_not_only_its_two_rests(photo_folder):
    # on a ramp up and back down, the first and last photos are both at rest: a user saw four
    # near-identical resting curls and not the photos where the settings fail; the photo at the
    # ramp's highest pressure is shown between them
    from pipeline.preview import preview_rows

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    loaded = ps.load_photoset(photo_folder)
    shown = loaded.manifest.iloc[preview_rows(loaded)]
    assert shown[["trial", "pressure_kpa"]].values.tolist() == [
        ["1", 0.0], ["1", 20.0], ["1", 0.0], ["2", 0.0], ["2", 20.0]
    ]
    assert len(preview_rows(loaded, every=True)) == len(loaded.manifest) == 8


def test_the_preview_shows_the_photos_named_and_refuses_a_name_not_in_the_manifest(
    photo_folder, tmp_path_factory, capsys
):
    # a flagged row's reason says "check with photoset preview", whose sheet of three photos a
    # ramp need not hold that row (customers 10 and 11): --image shows it
    from pipeline.cli import main
    from pipeline.preview import preview_rows

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    loaded = ps.load_photoset(photo_folder)
    names = loaded.manifest["image"].tolist()
    assert preview_rows(loaded, images=[names[3], names[1]]) == [3, 1]
    out = tmp_path_factory.mktemp("sheet") / "one.png"
    assert main(["photoset", "preview", str(photo_folder), "--image", names[3], "--out",
                 str(out)]) == 0
    assert "1 photo(s)" in capsys.readouterr().out and out.is_file()
    with pytest.raises(UserInputError, match=r"--image IMG_9\.JPG: no such photo in .*manifest"):
        preview_rows(loaded, images=["IMG_9.JPG"])
    # --frame is a video set's
    assert main(["photoset", "preview", str(photo_folder), "--frame", "3", "--out",
                 str(out)]) == 2
    assert "is a set of photos, not videos (fix: name a photo with --image NAME)" in (
        capsys.readouterr().err
    )


def test_check_warns_of_a_material_the_model_does_not_have(photo_folder):
    # customer 24 named the materials as the lab does (softA, stiffB) and learnt only from the
    # finished PDF that nothing was compared with the model
    from pipeline.photoset_check import check_photoset

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    assert not [p for p in check_photoset(photo_folder, warnings=True) if "material" in p.message]
    m = ps.read_manifest(photo_folder).drop(columns="manifest_line")
    m.loc[m.index[2:], "material"] = "softA"
    m.to_csv(photo_folder / ps.MANIFEST, index=False)
    (warning,) = [p for p in check_photoset(photo_folder, warnings=True) if "softA" in p.message]
    assert warning.warning and warning.line == 4 and "not compared with the model" in (
        warning.message
    )
    assert "model.materials_file" in warning.fix


def test_check_warns_of_a_pressure_out_of_its_ramps_order_naming_the_line(photo_folder):
    # customer 30 typed 100 kPa as 1000: check said OK and the curves got a level at 1000 kPa
    from pipeline.photoset_check import check_photoset

    def order(folder):
        return [p for p in check_photoset(folder, warnings=True) if "ramp's order" in p.message]

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    assert not order(photo_folder)
    m = ps.read_manifest(photo_folder).drop(columns="manifest_line")
    m.loc[1, "pressure_kpa"] = 100.0  # trial 1: 0, 10, 20, 10, 0 kPa
    m.to_csv(photo_folder / ps.MANIFEST, index=False)
    (warning,) = order(photo_folder)
    assert warning.warning and warning.line == 3 and warning.file.endswith(ps.MANIFEST)
    assert warning.message == (
        "pressure 100 kPa is out of its ramp's order (0 -> 100 -> 20 kPa by step): a typo?"
    )
    assert warning.fix.startswith("correct pressure_kpa, direction or step on this line")


@pytest.mark.parametrize(
    ("backdrop", "gain", "warned"),
    [
        ((200, 200, 200), (1.0, 1.0, 1.0), ""),
        ((200, 200, 200), (1.02, 0.97, 1.0), ""),  # a little drift
        ((200, 200, 200), (0.7, 0.7, 0.7), "30% darker"),
        ((150, 150, 150), (1.22, 1.22, 1.22), "22% brighter"),  # the other way
        ((200, 200, 200), (1.0, 1.0, 0.8), "channels 21% apart"),  # white balance
        ((200, 90, 20), (1.0, 1.0, 0.6), ""),  # a blue card's red is too dark for a ratio
        ((20, 22, 18), (0.7, 0.7, 0.7), ""),  # a black backdrop: levels too low to compare
        ((255, 255, 255), (0.9, 0.9, 0.9), ""),  # a clipped white backdrop says nothing
        # ... but an empty scene clipped where the photos are not does (customer 52's at 1.25
        # the exposure, 88% white: measure failed 32 of 52 photos, and check said nothing)
        ((220, 220, 220), (1.25, 1.25, 1.25), ("is overexposed, taken at another exposure "
                                               "than this ramp's first photo: 100% of it is "
                                               "white, 0%")),
    ],
)
def test_check_warns_of_an_empty_scene_taken_at_another_exposure(
    photo_folder, backdrop, gain, warned
):
    # customer 42's empty scene at 0.72 of the photos' exposure and another white balance: 5 rows
    # of its grey-blue body `ok` and 7-10 deg off, and check said OK
    from pipeline.photoset_check import check_photoset

    photo = np.full((60, 80, 3), backdrop, np.uint8)
    photo[10:40, 20:60] = (60, 120, 220)  # a body over a quarter of the photo
    for path in photo_folder.glob("*.jpg"):
        cv2.imwrite(str(path), photo)
    empty = np.clip(np.full((60, 80, 3), backdrop, float) * gain, 0, 255).astype(np.uint8)
    cv2.imwrite(str(photo_folder / "empty.png"), empty)
    photoset_init.init_photoset(
        photo_folder, PATTERN, settings={"l0_mm": 150.0, "target": "body",
                                         "background": "empty.png", "fixed_end": [2, 12]}
    )
    got = [p for p in check_photoset(photo_folder, warnings=True) if "exposure" in p.message]
    assert [p.line for p in got] == ([2, 7] if warned else []), got  # each ramp's first row
    if warned:
        assert got[0].warning and got[0].message.startswith("background photo empty.png ")
        assert "overexposed" in warned or got[0].message.startswith(
            "background photo empty.png was taken at another exposure or white balance than "
            "this ramp's first photo"
        )
        assert warned in got[0].message and "lock" in got[0].fix
    assert not check_photoset(photo_folder)  # a warning, not an error


@pytest.mark.parametrize("background", ["first photo", "its copy", "an empty scene"])
def test_check_warns_of_an_empty_scene_that_is_one_of_the_photos(photo_folder, background):
    # customer 44 named a photo of the actuator as the empty scene: 0 of 26 ok, and check warned
    # only of the ramp whose first photo it was
    import shutil

    from pipeline.photoset_check import check_photoset

    photos = sorted(photo_folder.glob("*.jpg"))
    for k, path in enumerate(photos):  # each photo its own bytes
        cv2.imwrite(str(path), np.full((24, 32, 3), 100 + 10 * k, np.uint8))
    shutil.copy(photos[0], photo_folder / "copy.jpg")
    cv2.imwrite(str(photo_folder / "empty.png"), np.full((24, 32, 3), 90, np.uint8))
    name = {"first photo": photos[0].name, "its copy": "copy.jpg",
            "an empty scene": "empty.png"}[background]
    photoset_init.init_photoset(
        photo_folder, PATTERN, settings={"l0_mm": 150.0, "target": "body", "fixed_end": [2, 12]}
    )
    with open(photo_folder / ps.SETTINGS, "a") as fh:  # named by hand, after init
        fh.write(f"background: {name}\n")
    got = [p for p in check_photoset(photo_folder, warnings=True) if "taken out" in p.message]
    if background == "an empty scene":
        assert not got
        return
    (warning,) = got
    assert warning.warning and warning.line == 2
    assert warning.message.startswith(
        f"background photo {name} is "
        + ("a copy of " + photos[0].name + ", " if background == "its copy" else "")
        + "one of this set's photos of the actuator"
    ), warning.message
    assert "with the actuator removed" in warning.fix


def test_check_warns_that_a_fixed_end_left_auto_is_guessed(photo_folder):
    # customer 25 left fixed_end out: check said OK, and measure then flagged all 36 bodies
    # "fixed end guessed; set fixed_end" (the README said check would say so)
    from pipeline.photoset_check import check_photoset

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0, "target": "body"})
    (warning,) = [p for p in check_photoset(photo_folder, warnings=True) if "auto" in p.message]
    assert warning.warning and warning.file.endswith(ps.SETTINGS)
    assert "for 8 of 8 rows" in warning.message and "every body measured so is flagged" in (
        warning.message
    )
    assert "fixed_end: [x, y]" in warning.fix
    assert not check_photoset(photo_folder)  # a warning, not an error
    yaml = photo_folder / ps.SETTINGS
    yaml.write_text(yaml.read_text().replace("fixed_end: auto", "fixed_end: [3, 12]"))
    assert ps.read_settings(photo_folder)["fixed_end"] == [3.0, 12.0]
    assert not [p for p in check_photoset(photo_folder, warnings=True) if "auto" in p.message]


def test_photos_all_at_one_pressure_are_all_taken_rising(tmp_path):
    # customer 26 gave ten strips one pressure each, all 0 kPa: init called them "1 up, 9 down"
    # (down after the first highest pressure, though it never fell)
    for i in range(1, 6):
        (tmp_path / f"IMG_{i}.JPG").write_bytes(b"")
    df = photoset_init.init_photoset(
        tmp_path, "IMG_*.JPG", defaults={"material": "DS20"}, pressures_kpa=(0.0,) * 5
    )
    assert df["direction"].tolist() == ["up"] * 5
    # a ramp held at its top, then let down: the hold is still counted falling, as before
    df = photoset_init.init_photoset(
        tmp_path, "IMG_*.JPG", defaults={"material": "DS20"}, overwrite=True,
        pressures_kpa=(0.0, 20.0, 20.0, 10.0, 0.0),
    )
    assert df["direction"].tolist() == ["up", "up", "down", "down", "down"]


def test_check_names_calibration_for_unlisted_checkerboard_photos(photo_folder):
    # customer 32's tilted phone: the checkerboard photos were only "not in manifest.csv", and
    # measured without the calibration every row was ok and up to 20 deg off
    from pipeline.photoset_check import check_photoset

    photoset_init.init_photoset(photo_folder, PATTERN, settings={"l0_mm": 150.0})
    (photo_folder / "checkerboard_1.jpg").write_bytes((photo_folder / next(
        p.name for p in photo_folder.glob("*.jpg"))).read_bytes())
    (unlisted,) = [p for p in check_photoset(photo_folder, warnings=True)
                   if "not in manifest.csv" in p.message]
    assert unlisted.fix.startswith("if 'checkerboard_1.jpg' and the like are photos of a "
                                   "checkerboard for the camera's calibration, name them")
    # a photo named otherwise: the fix as before
    (photo_folder / "checkerboard_1.jpg").rename(photo_folder / "IMG_9.jpg")
    (unlisted,) = [p for p in check_photoset(photo_folder, warnings=True)
                   if "not in manifest.csv" in p.message]
    assert unlisted.fix.startswith("add a row for each")


def test_init_gives_each_actuator_its_own_empty_scene(tmp_path, capsys):
    # customer 36 photographed the empty scene once per actuator; --background took one file
    from pipeline.cli import main

    for actuator, empty in (("O1", "empty_0146.jpg"), ("T1", "empty_0101.jpg")):
        for name in (f"{actuator}/IMG_01.jpg", f"{actuator}/IMG_02.jpg", f"{actuator}/{empty}"):
            (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
            cv2.imwrite(str(tmp_path / name), np.zeros((8, 8, 3), np.uint8))
    # the pattern takes the empty scenes in too: they are left out of the ramps
    init = ["photoset", "init", str(tmp_path), "--pattern", "{actuator}/*.jpg",
            "--pressures-kpa", "0,20", "--l0-mm", "100", "--target", "body", "--material", "DS20"]
    assert main([*init, "--background", "{actuator}/empty_*.jpg"]) == 0
    manifest = pd.read_csv(tmp_path / "manifest.csv")
    assert dict(zip(manifest["actuator"], manifest["background"], strict=True)) == {
        "O1": "O1/empty_0146.jpg", "T1": "T1/empty_0101.jpg"}
    assert len(manifest) == 4 and not manifest["image"].str.contains("empty").any()
    assert "background: O1 O1/empty_0146.jpg, T1 T1/empty_0101.jpg" in capsys.readouterr().out
    # an actuator without one, or with two, is named
    (tmp_path / "T1/empty_0102.jpg").write_bytes(b"")
    assert main([*init, "--background", "{actuator}/empty_*.jpg", "--overwrite"]) == 2
    assert "actuator T1 has 2 photos of the empty scene" in capsys.readouterr().err


def test_a_photo_named_in_another_unicode_form_is_the_same_photo(tmp_path):
    # customer 47: a Mac wrote 'Probe ä 3.jpg' as 'a' + a combining mark (NFD), the spreadsheet
    # typed 'ä' (NFC): check said both "does not exist" and "not in manifest", and photoset
    # init's pattern matched none
    import unicodedata

    from pipeline.photoset_check import check_photoset

    img = np.full((24, 32, 3), 200, np.uint8)
    for kpa in (0, 10, 20):
        name = unicodedata.normalize("NFD", f"Probe ä_{kpa}kPa.jpg")
        cv2.imencode(".jpg", img)[1].tofile(str(tmp_path / name))
    typed = unicodedata.normalize("NFC", "Probe ä_{pressure_kpa}kPa.jpg")
    manifest = photoset_init.init_photoset(
        tmp_path, typed, settings={"l0_mm": 150.0}, defaults={"material": "DS20"}
    )
    assert len(manifest) == 3
    rows = pd.read_csv(tmp_path / ps.MANIFEST)
    rows["image"] = [unicodedata.normalize("NFC", n) for n in rows["image"]]  # as typed
    rows.to_csv(tmp_path / ps.MANIFEST, index=False)
    said = [str(p) for p in check_photoset(tmp_path, warnings=True)]
    assert not [p for p in said if "does not exist" in p or "not in manifest" in p], said
    loaded = ps.load_photoset(tmp_path)
    assert all(loaded.image_path(n).is_file() for n in loaded.manifest["image"])
