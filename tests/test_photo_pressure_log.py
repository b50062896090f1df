"""Photos whose pressures come from a pressure log, read at the time the camera wrote into each
photo (``photoset init --pressure-log`` on photos)."""

from __future__ import annotations

from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from pipeline.cli import main
from pipeline.photo_times import EXIF_DATETIME_ORIGINAL, EXIF_IFD, EXIF_SUBSEC_ORIGINAL

START = datetime(2026, 12, 6, 14, 0, 0)
#: two ramps 0 -> 40 -> 0 kPa, one after the other, each level held HOLD_S
LEVELS_KPA = [0, 20, 40, 20, 0] * 2
HOLD_S = 12.0
#: where in its hold each photo is taken (s)
SHOT_S = 6.4


def _photo(path: Path, when: datetime | None) -> None:
    exif = Image.Exif()
    if when is not None:
        exif.get_ifd(EXIF_IFD).update(
            {
                EXIF_DATETIME_ORIGINAL: when.strftime("%Y:%m:%d %H:%M:%S"),
                EXIF_SUBSEC_ORIGINAL: f"{when.microsecond // 10000:02d}",
            }
        )
    Image.new("RGB", (32, 24), (200, 200, 200)).save(path, exif=exif)


def _log_rows(logger_ahead_s: float = 0.0) -> pd.DataFrame:
    """The logger's rows every 0.5 s from 15 s before the first hold to 15 s after the last,
    dated by its own clock."""
    rng = np.random.default_rng(0)
    t = np.arange(-15.0, HOLD_S * len(LEVELS_KPA) + 15, 0.5)
    setpoint = np.array(LEVELS_KPA, float)[
        np.clip((t // HOLD_S).astype(int), 0, len(LEVELS_KPA) - 1)
    ]
    return pd.DataFrame(
        {
            "camera_s": t,
            "Timestamp": [
                (START + timedelta(seconds=float(x) + logger_ahead_s)).isoformat(sep=" ")
                for x in t
            ],
            "Setpoint (kPa)": setpoint,
            "Sensor (kPa)": (setpoint + rng.normal(0, 0.3, t.size)).round(3),
        }
    )


@pytest.fixture
def logged_folder(tmp_path: Path) -> Path:
    """Ten photos named by the camera's counter, taken mid-hold, and the logger's dated log (its
    clock 5.5 s ahead of the camera's), in the order a counter that rolled over names them."""
    folder = tmp_path / "set"
    folder.mkdir()
    for i in range(len(LEVELS_KPA)):
        # the counter rolled over after the third photo: name order is not time order
        number = 9997 + i if i < 3 else i - 2
        _photo(folder / f"IMG_{number:04d}.JPG", START + timedelta(seconds=HOLD_S * i + SHOT_S))
    _log_rows(logger_ahead_s=5.5).drop(columns="camera_s").to_csv(folder / "log.csv", index=False)
    return folder


def _taken(manifest: pd.DataFrame) -> pd.DataFrame:
    return manifest.sort_values("timestamp").reset_index(drop=True)


def test_photos_get_the_logs_setpoint_measured_pressure_direction_and_trial_at_their_time(
    logged_folder, capsys
):
    code = main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--clock-offset-s", "5.5", "--material", "DS20",
                 "--l0-mm", "100"])
    assert code == 0
    out = capsys.readouterr()
    assert "pressures read from log.csv at the photos' EXIF times" in out.out
    assert "warning" not in out.err  # every photo is mid-hold
    m = _taken(pd.read_csv(logged_folder / "manifest.csv", dtype={"trial": str}))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA
    assert np.allclose(m["measured_pressure_kpa"], LEVELS_KPA, atol=1.5)
    assert m["direction"].tolist() == ["up", "up", "up", "down", "down"] * 2
    assert m["trial"].tolist() == ["1"] * 5 + ["2"] * 5  # split where the second ramp starts
    assert m["step"].tolist() == list(range(5)) * 2  # in the order taken, not by name
    assert m["image"].iloc[0] == "IMG_9997.JPG" and m["image"].iloc[3] == "IMG_0001.JPG"
    assert m["timestamp"].iloc[1] == "2026-12-06T14:00:18.400"
    assert code == main(["photoset", "check", str(logged_folder)])


def test_a_camera_clock_off_by_a_hold_is_named_or_placed_where_the_offset_says(
    logged_folder, capsys
):
    """Without the offset (the logger 5.5 s ahead) the photos are 0.9 s after the steps: the
    eight that follow a step are named; a whole hold off, each reads the level before its own,
    as the offset given says."""
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20"]) == 0
    err = capsys.readouterr().err
    assert "8 photo(s) were taken within 1.5 s of a step of the log's setpoint" in err
    assert "IMG_9998.JPG at log time 27.9 s, 0.9 s from a step of the setpoint" in err
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s", "-6.5",
                 "--overwrite"]) == 0
    assert "warning" not in capsys.readouterr().err
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == [0, *LEVELS_KPA[:-1]]


def test_a_log_in_seconds_needs_the_offset_and_photos_outside_the_log_are_refused(
    logged_folder, capsys
):
    rows = _log_rows()
    rows.rename(columns={"camera_s": "t (s)"}).drop(columns="Timestamp").to_csv(
        logged_folder / "log.csv", index=False
    )
    args = ["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG", "--pressure-log",
            "log.csv", "--material", "DS20"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "its times are seconds (from 't (s)')" in err and "give --clock-offset-s" in err
    assert not (logged_folder / "manifest.csv").exists()
    assert main([*args, "--clock-offset-s", "6.4"]) == 0
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA
    # a minute later: most photos would lie past the log's end
    assert main([*args, "--clock-offset-s", "66.4", "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert "4 of 10 photo(s) lie outside the log, whose times span -15.00-134.50 s" in err
    assert "IMG_0004.JPG (taken 2026-12-06 14:01:18) is at log time 138.4 s" in err
    assert "any from -15.0 to 26.5 puts every photo inside the log" in err


def test_a_photo_without_the_cameras_time_is_named_with_the_fix(logged_folder, capsys):
    _photo(logged_folder / "IMG_0004.JPG", None)  # re-saved by an editor
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20"]) == 2
    err = capsys.readouterr().err
    assert "1 photo(s) hold no time the camera wrote (EXIF DateTimeOriginal)" in err
    assert "IMG_0004.JPG" in err and "--pressures-kpa instead" in err
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--pressures-kpa", "0:40:20"]) == 2
    assert "give one of them" in capsys.readouterr().err


def test_a_loggers_dated_times_are_read_on_its_own_clock(tmp_path):
    """A logger that writes ISO times with its zone: the wall clock it shows is kept (the
    camera's EXIF time has no zone), and ``check`` names the column the time came from."""
    from pipeline.video.timeline import read_pressure_log

    path = tmp_path / "log.csv"
    path.write_text(
        "Timestamp,Setpoint (kPa)\n"
        "2026-12-06T14:00:00.000+01:00,0\n2026-12-06T14:00:00.500+01:00,0\n"
        "2026-12-06T14:00:02.250+01:00,20\n"
    )
    log, problems = read_pressure_log(path)
    assert problems == [] and log is not None
    assert log.clock_start == datetime(2026, 12, 6, 14, 0, 0)
    assert log.time_s.tolist() == [0.0, 0.5, 2.25]
    assert log.describe_columns().startswith("time from 'Timestamp', setpoint from")


def test_photos_of_a_continuous_ramp_read_the_setpoint_between_rows_and_are_told_to_bin(
    logged_folder, capsys
):
    t = np.arange(0.0, 120.5, 0.5)
    setpoint = np.interp(t, [0, 60, 120], [0, 40, 0])
    pd.DataFrame({"time_s": t, "pressure_kpa": setpoint}).to_csv(
        logged_folder / "log.csv", index=False
    )
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--clock-offset-s", "0", "--trial", "1"]) == 2
    assert "--material" in capsys.readouterr().err  # the pattern has none and none given
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--clock-offset-s", "3", "--material", "DS20"]) == 0
    out = capsys.readouterr()
    assert "not levels held for several photos" in out.out and "aggregate.bin_kpa" in out.out
    assert "warning" not in out.err  # a continuous ramp has no steps
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    taken_s = 3 + 12.0 * np.arange(10)  # the first photo at log time 3 s
    np.testing.assert_allclose(m["pressure_kpa"], np.interp(taken_s, [0, 60, 120], [0, 40, 0]),
                               atol=0.01)
    assert m["direction"].tolist() == ["up"] * 5 + ["down"] * 5
    assert "measured_pressure_kpa" not in m.columns
