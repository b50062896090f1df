"""measure's cache (``--cache``; the workflow keeps one per dataset): a run cut off resumes, and
only what changed is measured again (customer 30: Ctrl-C during measure lost all 84 photos of
the set, and one re-shot photo re-measured all of them)."""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
import yaml

from pipeline.photoset_measure import measure_photoset, summary

REPO = Path(__file__).resolve().parents[1]


def _sample(folder: Path, rows: int, copies: int = 1) -> Path:
    """The committed sample set's first ``rows`` photos (``copies`` times, as other trials)."""
    folder.mkdir()
    shutil.copy(REPO / "sample_images" / "photoset.yaml", folder)
    manifest = pd.read_csv(REPO / "sample_images" / "manifest.csv").head(rows)
    parts = []
    for k in range(copies):
        part = manifest.copy()
        part["image"] = [f"c{k}_{name}" for name in manifest["image"]]
        part["trial"] = [f"{t}{k}" for t in manifest["trial"].astype(str)]
        for src, dst in zip(manifest["image"], part["image"], strict=True):
            shutil.copy(REPO / "sample_images" / src, folder / dst)
        parts.append(part)
    pd.concat(parts).to_csv(folder / "manifest.csv", index=False)
    return folder


def _entries(cache: Path) -> list[Path]:
    return sorted(cache.glob("*.json"))


def test_an_unchanged_photo_is_read_back_and_a_changed_one_measured_again(tmp_path):
    folder, cache = _sample(tmp_path / "set", 12), tmp_path / "cache"
    first = measure_photoset(folder, cache_dir=cache, overlays_dir=tmp_path / "ov1")
    assert first.attrs["from_cache"] == 0 and len(_entries(cache)) == 12
    again = measure_photoset(folder, cache_dir=cache, overlays_dir=tmp_path / "ov2")
    assert again.attrs["from_cache"] == 12
    pd.testing.assert_frame_equal(first, again)
    # its summary counts the seconds of this run's work, none (customer 33 read "17.4 s")
    assert summary(again).endswith("(0.0 s of work)")
    assert not summary(first).endswith("(0.0 s of work)")
    for overlay in (tmp_path / "ov1").glob("*.jpg"):
        assert overlay.read_bytes() == (tmp_path / "ov2" / overlay.name).read_bytes()
    # a run cut off before 4 photos were done: those are measured, the rest read back
    for entry in _entries(cache)[:4]:
        entry.unlink()
    resumed = measure_photoset(folder, cache_dir=cache)
    assert resumed.attrs["from_cache"] == 8
    pd.testing.assert_frame_equal(first.drop(columns="seconds"), resumed.drop(columns="seconds"))
    # a photo re-shot under the same name: that one is measured again, and reads its new psi
    images = first["image"].tolist()
    shutil.copy(folder / images[9], folder / images[2])
    reshot = measure_photoset(folder, cache_dir=cache)
    assert reshot.attrs["from_cache"] == 11
    assert reshot.at[2, "psi_deg"] == pytest.approx(first.at[9, "psi_deg"], abs=1e-9)
    assert reshot.at[2, "psi_deg"] != pytest.approx(first.at[2, "psi_deg"], abs=1.0)
    assert len(_entries(cache)) == 13  # the old photo's entry is kept (up to 2 per used one)
    # a setting changed: every photo again; changed back: every photo read back (customer 33's
    # set was measured again in full)
    settings = folder / "photoset.yaml"
    ccw = settings.read_text()
    settings.write_text(ccw.replace("positive_turn: ccw", "positive_turn: cw"))
    turned = measure_photoset(folder, cache_dir=cache)
    assert turned.attrs["from_cache"] == 0
    assert turned.at[0, "psi_deg"] == pytest.approx(-reshot.at[0, "psi_deg"], abs=1e-9)
    assert set(turned["positive_turn"]) == {"cw"} and set(reshot["positive_turn"]) == {"ccw"}
    settings.write_text(ccw)
    back = measure_photoset(folder, cache_dir=cache)
    assert back.attrs["from_cache"] == 12
    pd.testing.assert_frame_equal(reshot.drop(columns="seconds"), back.drop(columns="seconds"))


def test_the_cache_keeps_the_least_recently_used_entries_up_to_twice_the_sets(tmp_path):
    folder, cache = _sample(tmp_path / "set", 2), tmp_path / "cache"
    settings = folder / "photoset.yaml"
    text = settings.read_text()
    assert "l0_mm: " in text
    for l0 in (250, 251, 252, 253):  # four settings: the first one's 2 entries are one too many
        settings.write_text(re.sub(r"l0_mm: .*", f"l0_mm: {l0}", text))
        assert measure_photoset(folder, cache_dir=cache).attrs["from_cache"] == 0
    assert len(_entries(cache)) == 6
    for l0, cached in ((251, 2), (250, 0)):
        settings.write_text(re.sub(r"l0_mm: .*", f"l0_mm: {l0}", text))
        assert measure_photoset(folder, cache_dir=cache).attrs["from_cache"] == cached


def test_measure_cut_off_by_ctrl_c_resumes_where_it_stopped(tmp_path, sigint_as_in_a_terminal):
    # 840 photos: seconds of work, so that Ctrl-C lands part-way (and SIGINT as a terminal sends
    # it: under pytest-xdist the workers ignore it, and so did measure, which ran to the end)
    folder, cache = _sample(tmp_path / "set", 42, copies=20), tmp_path / "cache"
    cmd = [sys.executable, "-m", "pipeline", "measure", str(folder), "--out",
           str(tmp_path / "a.csv"), "--cache", str(cache), "--jobs", "2"]
    # Ctrl-C as a terminal sends it: to the whole process group, the pool's workers too
    run = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           start_new_session=True)
    deadline = time.monotonic() + 60
    while len(_entries(cache)) < 10 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    os.killpg(run.pid, signal.SIGINT)
    try:
        run.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(run.pid, signal.SIGKILL)
        run.communicate()
        pytest.fail("measure --jobs 2 did not stop within 60 s of Ctrl-C")
    done = len(_entries(cache))
    assert done >= 10 and run.returncode != 0, (done, run.returncode)  # cut off part-way
    assert done < 20 * 42
    resumed = subprocess.run(cmd, capture_output=True, text=True, check=False)
    assert resumed.returncode == 0, resumed.stderr
    assert f"{done} as measured by an earlier run (--cache)" in resumed.stdout, resumed.stdout
    clean = measure_photoset(folder, jobs=2)
    pd.testing.assert_frame_equal(
        pd.read_csv(tmp_path / "a.csv").drop(columns="seconds"),
        pd.read_csv(_written(clean, tmp_path / "clean.csv")).drop(columns="seconds"),
    )


def _written(angles: pd.DataFrame, path: Path) -> Path:
    from pipeline.photoset_measure import write_angles

    write_angles(angles, path)
    return path


def test_a_cache_folder_in_the_photo_set_is_refused_and_other_files_are_never_pruned(tmp_path):
    # the review: --cache SET pruned every .jpg and .json of the set: the photos were deleted
    from pipeline.errors import UserInputError

    folder = _sample(tmp_path / "set", 4)
    photos = sorted(p.name for p in folder.glob("*.jpg"))
    for inside in (folder, folder / "cache"):
        with pytest.raises(UserInputError, match="give a folder of its own outside it"):
            measure_photoset(folder, cache_dir=inside)
    assert sorted(p.name for p in folder.glob("*.jpg")) == photos
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "notes.json").write_text("{}")
    (cache / "photo.jpg").write_bytes(b"x")
    measure_photoset(folder, cache_dir=cache)
    assert (cache / "notes.json").is_file() and (cache / "photo.jpg").is_file()
    assert len(_entries(cache)) == 4 + 1


def test_a_replaced_empty_scene_is_measured_again_in_the_same_process(tmp_path):
    # the review: the empty scene was kept per path in a process, so a replaced one was read as
    # the old, and that result stored under the new one's key and served to later runs
    import cv2

    from pipeline.synth.photoset_writer import render_photoset

    folder, cache = tmp_path / "set", tmp_path / "cache"
    render_photoset(folder, "DS20", actuators=1, trials=1, seed=2, scene="green_fibre",
                    step_kpa=80.0, scene_overrides={"width": 640, "height": 480})
    background = folder / str(yaml.safe_load((folder / "photoset.yaml").read_text())["background"])
    first = measure_photoset(folder, cache_dir=cache)
    empty = cv2.imread(str(background))
    cv2.imwrite(str(background), cv2.flip(empty, 1))  # another empty scene
    again = measure_photoset(folder, cache_dir=cache)
    assert again.attrs["from_cache"] == 0
    fresh = measure_photoset(folder)
    pd.testing.assert_frame_equal(again.drop(columns="seconds"), fresh.drop(columns="seconds"))
    assert not again["psi_deg"].equals(first["psi_deg"]) or not again["status"].equals(
        first["status"]
    )
