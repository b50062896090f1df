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

#: not the day the tests run: a time read without its date is dated to today by pandas
START = datetime(2026, 11, 5, 14, 0, 0)
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


def _photo_set(folder: Path, shot_s: float = SHOT_S, logger_ahead_s: float = 5.5) -> Path:
    """Ten photos named by the camera's counter, each ``shot_s`` into its hold, and the logger's
    dated log (its clock ``logger_ahead_s`` ahead of the camera's), in the order a counter that
    rolled over names them."""
    folder.mkdir()
    for i in range(len(LEVELS_KPA)):
        # the counter rolled over after the third photo: name order is not time order
        number = 9997 + i if i < 3 else i - 2
        _photo(folder / f"IMG_{number:04d}.JPG", START + timedelta(seconds=HOLD_S * i + shot_s))
    _log_rows(logger_ahead_s).drop(columns="camera_s").to_csv(folder / "log.csv", index=False)
    return folder


@pytest.fixture
def logged_folder(tmp_path: Path) -> Path:
    """:func:`_photo_set`: photos 6.4 s into their holds, the logger 5.5 s ahead."""
    return _photo_set(tmp_path / "set")


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
    assert m["timestamp"].iloc[1] == "2026-11-05T14:00:18.400"
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
    since = _taken(pd.read_csv(logged_folder / "manifest.csv"))["since_step_s"]
    # since the setpoint last stepped (the second ramp's rest photo: 0 kPa held 24.9 s)
    assert np.allclose(since, [np.nan, *[0.9] * 4, 12.9, *[0.9] * 4], equal_nan=True)
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
    assert "its times are seconds (from 't (s)')" in err and "or --clock-offset-s" in err
    assert "give --log-time-at PHOTO=SECONDS" in err
    assert not (logged_folder / "manifest.csv").exists()
    assert main([*args, "--clock-offset-s", "6.4"]) == 0
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA
    # a minute later: most photos would lie past the log's end
    assert main([*args, "--clock-offset-s", "66.4", "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert "4 of 10 photo(s) lie outside the log, whose times span -15.00-134.50 s" in err
    assert "IMG_0004.JPG (taken 2026-11-05 14:01:18) is at log time 138.4 s" in err
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


def test_a_clock_offset_of_the_wrong_sign_is_named_and_a_photo_of_the_loggers_clock_has_none(
    tmp_path, capsys
):
    """The logger 2 s ahead, photos 3 s into their holds: -2 (behind, the sign mistaken) puts the
    eight photos after a step 1 s before it, reading the level before; the warning says the
    opposite sign puts none there.  The log's time at one photo gives the offset with no sign."""
    folder = _photo_set(tmp_path / "set", shot_s=3.0, logger_ahead_s=2.0)
    args = ["photoset", "init", str(folder), "--pattern", "IMG_*.JPG", "--pressure-log",
            "log.csv", "--material", "DS20", "--l0-mm", "100", "--overwrite"]
    assert main([*args, "--clock-offset-s", "-2"]) == 0
    err = capsys.readouterr().err
    assert "8 photo(s) were taken within 1.5 s of a step" in err
    assert "is the sign of --clock-offset-s -2 right? With 2 (the opposite sign" in err
    assert "0 photo(s), not 8, would lie near a step" in err
    # check says it again, each time (customer 40: said once, then check said OK); and names a
    # pressure edited since
    manifest = pd.read_csv(folder / "manifest.csv")
    assert {"pressure_log", "log_time_s"} <= set(manifest.columns)
    manifest.loc[manifest["image"] == "IMG_9997.JPG", "pressure_kpa"] = 5.0
    manifest.to_csv(folder / "manifest.csv", index=False)
    assert main(["photoset", "check", str(folder)]) == 0
    err = capsys.readouterr().err
    assert "taken 1 s from a step of log.csv's setpoint" in err
    assert "pressure_kpa 5 is not the setpoint of log.csv at this photo's log time" in err
    assert main([*args, "--clock-offset-s", "2"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["photoset", "check", str(folder)]) == 0
    err = capsys.readouterr().err
    assert "from a step of" not in err and "is the sign" not in err
    # a photo of the logger's screen, taken at 13:59:50.2 by the camera, shows 13:59:52.2; kept
    # beside the set's folder, it is none of the ramps' photos, and check does not ask for it
    _photo(tmp_path / "IMG_9996.JPG", START - timedelta(seconds=9.8))
    assert main([*args, "--log-time-at", "../IMG_9996.JPG=13:59:52.2"]) == 0
    out = capsys.readouterr()
    assert "the logger's clock taken as 2 s ahead of the camera's" in out.out
    assert "warning" not in out.err
    m = _taken(pd.read_csv(folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA
    assert main([*args, "--log-time-at", "../IMG_9996.JPG"]) == 2
    assert "give PHOTO=TIME" in capsys.readouterr().err
    assert main([*args, "--log-time-at", "clock.JPG=13:59:52.2"]) == 2
    assert "no photo " in (err := capsys.readouterr().err) and "clock.JPG; give" in err
    # one of the ramps' photos named: measured as one, and said so
    assert main([*args, "--log-time-at", "IMG_9997.JPG=14:00:05"]) == 0
    assert "IMG_9997.JPG, named by --log-time-at, is one of the ramps' photos" in (
        capsys.readouterr().err
    )
    assert len(pd.read_csv(folder / "manifest.csv")) == len(LEVELS_KPA)
    # on a log in seconds, the log's time (s) at that photo
    rows = _log_rows(2.0)
    rows.assign(time_s=rows["camera_s"] + 2.0)[["time_s", "Setpoint (kPa)"]].to_csv(
        folder / "log.csv", index=False
    )
    assert main([*args, "--log-time-at", "../IMG_9996.JPG=-7.8"]) == 0  # the first: 3 s + 2
    assert _taken(pd.read_csv(folder / "manifest.csv"))["pressure_kpa"].tolist() == LEVELS_KPA


def test_photos_in_a_gap_of_the_log_are_left_out_and_named(logged_folder, capsys):
    """A logger that stopped writing for 24 s (a USB hiccup): the two photos taken then have no
    known pressure; they were given the last level logged, and measured ok."""
    rows = _log_rows(5.5)
    gap = (rows["camera_s"] >= 3 * HOLD_S) & (rows["camera_s"] < 5 * HOLD_S)
    rows[~gap].drop(columns="camera_s").to_csv(logged_folder / "log.csv", index=False)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s", "5.5",
                 "--l0-mm", "100"]) == 0
    err = capsys.readouterr().err
    assert "2 photo(s) (IMG_0001.JPG, IMG_0002.JPG) were taken in a gap of the log: no row for " \
        "24.5 s" in err
    assert "left out of the manifest" in err and "do not match the pattern" not in err
    m = pd.read_csv(logged_folder / "manifest.csv")
    assert len(m) == 8 and not m["image"].isin(["IMG_0001.JPG", "IMG_0002.JPG"]).any()
    assert main(["photoset", "check", str(logged_folder)]) == 0
    assert "2 photos in the folder are not in manifest.csv" in capsys.readouterr().err


def test_a_logs_dates_that_read_either_way_are_read_as_the_photos_dates_say(
    logged_folder, capsys
):
    """A logger writing day first, 05/11/2026 (read month first, 11 May, every photo lay
    outside the log, and the error pointed at the clock offset)."""
    rows = _log_rows(5.5)
    stamps = pd.to_datetime(rows["Timestamp"], format="ISO8601")
    rows.assign(Timestamp=stamps.dt.strftime("%d/%m/%Y %H:%M:%S.%f").str[:-3]).drop(
        columns="camera_s"
    ).to_csv(logged_folder / "log.csv", index=False)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s",
                 "5.5"]) == 0
    assert "read as 2026-11-05, as the photos' own dates are" in capsys.readouterr().out
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA


def test_a_log_written_a_row_per_setpoint_gives_each_photo_the_setpoint_in_force(
    logged_folder, capsys
):
    """A logger that writes one row per commanded setpoint (review): the photos read values
    between two levels (10.67, 30.67, ...; the measured pressure too), the top one 'down', and
    were told to bin them; a long hold was taken for a gap, and the last level, after the last
    row, for outside the log."""
    # a row a setpoint; the top of the first ramp held 36 s; no row as the logger stops
    rows_s = [0, 12, 24, 60, 72, 84, 96, 108]
    setpoints = [0, 20, 40, 20, 0, 20, 40, 20]
    pd.DataFrame(
        {
            "Timestamp": [(START + timedelta(seconds=t + 5.5)).isoformat(sep=" ") for t in rows_s],
            "Setpoint (kPa)": setpoints,
            "Sensor (kPa)": [v + 0.2 for v in setpoints],
        }
    ).to_csv(logged_folder / "log.csv", index=False)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s",
                 "5.5"]) == 0
    out = capsys.readouterr()
    assert "continuous ramp" not in out.out and "gap" not in out.err
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    # each photo (12 i + 6.4 s) reads the last row before it, the last a row's interval after
    levels = [0, 20, 40, 40, 40, 20, 0, 20, 40, 20]
    assert m["pressure_kpa"].tolist() == levels
    np.testing.assert_allclose(m["measured_pressure_kpa"], np.add(levels, 0.2))
    assert m["direction"].tolist() == ["up"] * 5 + ["down"] * 2 + ["up", "up", "down"]


def _labview(t: pd.Timestamp, p: float, m: float, zone: str) -> str:
    """Date and Time columns, ';' between fields, decimal commas, pressures in bar."""
    return (f"{t:%d.%m.%Y};{t:%H:%M:%S},{t.microsecond // 1000:03d};"
            + f"{p / 100:.3f};{m / 100:.5f}".replace(".", ","))


def _clock_alone(t: pd.Timestamp, p: float, m: float, zone: str) -> str:
    return f"{t:%H:%M:%S.%f},{p},{m}"


def _zoned(t: pd.Timestamp, p: float, m: float, zone: str) -> str:
    return f"{t:%Y-%m-%dT%H:%M:%S.%f}{zone},{p},{m}"


@pytest.mark.parametrize(
    "header, cell",
    [
        ("Date;Time;Set Pressure (bar);Measured Pressure (bar)", _labview),
        ("Time,Setpoint (kPa),Sensor (kPa)", _clock_alone),  # the photos' day taken for theirs
        ("timestamp,setpoint_kPa,sensor_kPa", _zoned),  # summer time starts within the log
    ],
    ids=["labview-date-and-time", "clock-times-alone", "zone-changes"],
)
def test_loggers_own_clocks_are_read(logged_folder, header, cell, capsys):
    rows = _log_rows(5.5)
    stamps = pd.to_datetime(rows["Timestamp"], format="ISO8601")
    zones = ["+01:00"] * len(rows)
    if cell is _zoned:  # after the first minute the wall clock is an hour on, the time is not
        later = (rows["camera_s"] >= 60).to_numpy()
        stamps = stamps.where(~later, stamps + pd.Timedelta(hours=1))
        zones = ["+02:00" if x else "+01:00" for x in later]
    lines = [header] + [
        cell(t, p, m, z)
        for t, p, m, z in zip(
            stamps, rows["Setpoint (kPa)"], rows["Sensor (kPa)"], zones, strict=True
        )
    ]
    (logged_folder / "log.csv").write_text("\n".join(lines) + "\n")
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s",
                 "5.5"]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    m = _taken(pd.read_csv(logged_folder / "manifest.csv"))
    assert m["pressure_kpa"].tolist() == pytest.approx(LEVELS_KPA, abs=0.01)
    assert np.allclose(m["measured_pressure_kpa"], LEVELS_KPA, atol=1.5)  # read, not dropped
    if cell is _clock_alone:
        assert "clock times have no date: its first row taken as 2026-11-05 13:59:50" in out


def test_a_day_first_log_across_midnight_reads_its_dates_one_way(tmp_path):
    """12/11/2026 23:59 then 13/11/2026 00:00 (review): read cell by cell, the first was
    11 December and the log 'did not increase'."""
    from pipeline.video.timeline import read_pressure_log

    path = tmp_path / "log.csv"
    path.write_text("Timestamp,pressure_kpa\n12/11/2026 23:59:59,0\n13/11/2026 00:00:01,5\n")
    log, problems = read_pressure_log(path)
    assert problems == [] and log is not None
    assert log.clock_start == datetime(2026, 11, 12, 23, 59, 59) and log.time_s.tolist() == [0, 2]
    assert log.clock_start_dayfirst is None  # 13 says day first: no other reading


def test_a_photo_with_only_the_time_an_editor_saved_it_is_refused(logged_folder, capsys):
    """IFD0 DateTime is when the file was last written: a photo re-saved keeps only that."""
    exif = Image.Exif()
    exif[306] = "2026:11:05 14:00:20"  # DateTime, no DateTimeOriginal
    Image.new("RGB", (32, 24)).save(logged_folder / "IMG_0004.JPG", exif=exif)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20"]) == 2
    assert "IMG_0004.JPG" in capsys.readouterr().err


def test_every_photo_in_a_gap_is_refused_without_a_manifest(logged_folder, capsys):
    rows = _log_rows(5.5)
    rows[(rows["camera_s"] < 0) | (rows["camera_s"] > 125)].drop(columns="camera_s").to_csv(
        logged_folder / "log.csv", index=False
    )
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20"]) == 2
    err = capsys.readouterr().err
    assert "every photo was taken in a gap of the log" in err and "manifest" not in err
    assert not (logged_folder / "manifest.csv").exists()


@pytest.mark.parametrize("noise", ["1.5 kPa", "0.7 % of the reading", "0.02 kPa"])
def test_a_sensor_logged_alone_gives_directions_by_its_trend_not_its_noise(
    logged_folder, noise, capsys
):
    """One pressure column, a sensor's noisy reading (review: half the photos of a noisy log got
    the wrong direction, the trend turning at every wobble; customer 41: noise growing with the
    reading, 0.05 kPa at rest, 0.4 at the top, left 20 of 100 photos the wrong direction and a
    German 'Zeit [ms];Sensor [mbar]' log was refused)."""
    rows = _log_rows(5.5)
    level = rows["Setpoint (kPa)"].to_numpy()
    rng = np.random.default_rng(3)
    sd = {"1.5 kPa": 1.5, "0.02 kPa": 0.02}.get(noise, 0.007 * level + 0.05)
    reading_mbar = 10 * (level + rng.normal(0, 1, len(rows)) * sd)
    log_ms = 1000 * (rows["camera_s"] + 20.0)  # the software started 20 s before the camera's 0
    lines = ["Zeit [ms];Sensor [mbar]"] + [
        f"{t:.0f};{v:.1f}".replace(".", ",") for t, v in zip(log_ms, reading_mbar, strict=True)
    ]
    (logged_folder / "log.csv").write_text("\r\n".join(lines) + "\r\n")
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s",
                 str(20 + SHOT_S)]) == 0, capsys.readouterr().err
    assert "is a sensor's reading (its noise about" in capsys.readouterr().out
    m = _taken(pd.read_csv(logged_folder / "manifest.csv", dtype={"trial": str}))
    assert m["direction"].tolist() == ["up", "up", "up", "down", "down"] * 2
    assert m["trial"].tolist() == ["1"] * 5 + ["2"] * 5  # the second photo at 0 starts trial 2
    np.testing.assert_allclose(m["pressure_kpa"], LEVELS_KPA, atol=5)


def test_clock_texts_are_read_one_way_in_the_log_and_in_log_time_at(tmp_path, logged_folder,
                                                                     capsys):
    """Slashes whose every day and month is 12 or less across midnight: read day first the log
    spans 1 day, month first 30 (review: read month first and refused); AM/PM clock times, and
    --log-time-at with a decimal comma, are read like the log's cells (they were dated today)."""
    from pipeline.video.timeline import read_pressure_log

    path = tmp_path / "log.csv"
    path.write_text("Timestamp,pressure_kpa\n05/11/2026 23:59:59,0\n06/11/2026 00:00:01,5\n")
    log, _ = read_pressure_log(path)
    assert log is not None and log.time_s.tolist() == [0, 2]
    assert log.clock_start == datetime(2026, 11, 5, 23, 59, 59)
    rows = _log_rows(5.5)
    stamps = pd.to_datetime(rows["Timestamp"], format="ISO8601")
    rows.assign(Time=stamps.dt.strftime("%I:%M:%S.%f %p"))[["Time", "Setpoint (kPa)"]].to_csv(
        logged_folder / "log.csv", index=False
    )
    (logged_folder / "clock").mkdir()
    _photo(logged_folder / "clock" / "IMG_9996.JPG", START - timedelta(seconds=9.8))
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20",
                 "--log-time-at", "clock/IMG_9996.JPG=1:59:55,7 PM"]) == 0, (
        capsys.readouterr().err
    )
    assert "5.5 s ahead of the camera's" in capsys.readouterr().out
    assert _taken(pd.read_csv(logged_folder / "manifest.csv"))["pressure_kpa"].tolist() == (
        LEVELS_KPA
    )


def test_a_setpoint_cycling_fast_is_no_noise_and_check_reads_the_rows_init_read(tmp_path, capsys):
    """A log that first cycles 0/40 kPa in 2 s holds (review: its steps were taken for noise of
    24 kPa, every photo 'up', one trial, 'a sensor's reading'); photos taken on a row's own time
    (review: check, reading the log time rounded to the ms, found the next row and said the
    pressure was edited)."""
    folder = _photo_set(tmp_path / "set", shot_s=6.5, logger_ahead_s=5.5)
    rows = _log_rows(5.5)
    cycling = rows["camera_s"] < -5
    rows.loc[cycling, "Setpoint (kPa)"] = np.where(
        (rows.loc[cycling, "camera_s"] // 2) % 2 == 0, 0.0, 40.0
    )
    rows[["Timestamp", "Setpoint (kPa)"]].to_csv(folder / "log.csv", index=False)
    assert main(["photoset", "init", str(folder), "--pattern", "IMG_*.JPG", "--pressure-log",
                 "log.csv", "--material", "DS20", "--clock-offset-s", "5.5",
                 "--l0-mm", "100"]) == 0
    assert "sensor" not in capsys.readouterr().out
    m = _taken(pd.read_csv(folder / "manifest.csv", dtype={"trial": str}))
    assert m["pressure_kpa"].tolist() == LEVELS_KPA
    assert m["direction"].tolist() == ["up", "up", "up", "down", "down"] * 2
    assert m["trial"].tolist() == ["1"] * 5 + ["2"] * 5
    assert main(["photoset", "check", str(folder)]) == 0
    err = capsys.readouterr().err
    assert "is not the setpoint" not in err and "from a step" not in err


def test_a_quiet_sensor_logged_alone_with_clock_times_stays_a_sensor(logged_folder, capsys):
    """Dating a log of clock times alone (or choosing how its dates read) rebuilt it and forgot
    that its one pressure is a sensor's (re-read of the change): the photos were then split by
    levels, not by the trend."""
    rows = _log_rows(5.5)
    stamps = pd.to_datetime(rows["Timestamp"], format="ISO8601")
    quiet = rows["Setpoint (kPa)"] + np.random.default_rng(5).normal(0, 0.02, len(rows))
    log = pd.DataFrame({"Time": stamps.dt.strftime("%H:%M:%S.%f"), "Sensor (kPa)": quiet.round(3)})
    log.to_csv(logged_folder / "log.csv", index=False)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--material", "DS20", "--clock-offset-s",
                 "5.5"]) == 0
    assert "is a sensor's reading" in capsys.readouterr().out


def test_a_photo_taken_while_settling_is_measured_flagged_and_kept_out_of_the_curve(
    tmp_path, repo
):
    """A photo taken 0.4 s after its setpoint stepped (the manifest's ``since_step_s``, as
    ``init`` writes it) is measured, flagged with the reason, and not averaged into its level;
    one taken 1.6 s after, or whose since_step_s was emptied, counts."""
    from pipeline.aggregate import aggregate_hysteresis
    from pipeline.report.reasons import words

    folder = tmp_path / "set"
    folder.mkdir()
    rows = pd.read_csv(repo / "sample_images" / "manifest.csv").head(6)
    for name in [*rows["image"], "photoset.yaml"]:
        (folder / name).write_bytes((repo / "sample_images" / name).read_bytes())
    rows["since_step_s"] = [np.nan, 5.0, 0.4, 1.6, np.nan, 6.0]
    rows.to_csv(folder / "manifest.csv", index=False)
    assert main(["measure", str(folder), "--out", str(tmp_path / "angles.csv")]) == 0
    angles = pd.read_csv(tmp_path / "angles.csv")
    assert angles["status"].tolist() == ["ok", "ok", "flagged", "ok", "ok", "ok"]
    reason = angles["reason"].iloc[2]
    assert reason.startswith("taken 0.4 s after a step of its pressure log's setpoint")
    assert words(reason) == "taken while settling after a step"
    curve = aggregate_hysteresis(angles).set_index("pressure_kpa")
    assert curve.loc[20.0, "n"] == 0 and curve.loc[20.0, "n_excluded"] == 1
    assert curve.loc[30.0, "n"] == 1


def test_only_levels_held_count_as_steps_for_since_step_s(tmp_path):
    """Review: a staircase of 1 s treads logged a row per setpoint (2.5 kPa a row) made every
    photo "taken 0.4 s after a step", and a sensor's one-row glitch 1.4 s before a mid-hold
    photo made it one; the level the pressure reached and held is what since_step_s counts
    from."""
    from pipeline.photo_log import ClockSync, place_photos

    def since(folder: Path, log: pd.DataFrame) -> np.ndarray:
        log.to_csv(folder / "log.csv", index=False)
        photos = sorted(p.name for p in folder.glob("IMG_*.JPG"))
        return place_photos(folder, photos, "log.csv", ClockSync(offset_s=5.5)).table[
            "since_step_s"
        ].to_numpy()

    folder = _photo_set(tmp_path / "stairs")
    t = np.arange(-15.0, 135.0, 1.0)
    stairs = pd.DataFrame({
        "Timestamp": [(START + timedelta(seconds=x + 5.5)).isoformat(sep=" ") for x in t],
        "Setpoint (kPa)": np.interp(t, [0, 60, 120], [0, 150, 0]),
    })
    assert np.isnan(since(folder, stairs)).all()
    rows = _log_rows(5.5)
    reading = rows["Setpoint (kPa)"].to_numpy() + np.random.default_rng(3).normal(0, 0.2, len(rows))
    reading[np.searchsorted(rows["camera_s"].to_numpy(), 100.5)] += 4.0  # 1.4 s before a photo
    got = since(folder, pd.DataFrame({"Timestamp": rows["Timestamp"], "Sensor (kPa)": reading}))
    assert np.nanmin(got) > 5.0, got  # every photo 6.4 s into its hold (the rest photos more)


def test_a_since_step_s_typed_by_hand_that_is_no_time_is_named_by_check(logged_folder, capsys):
    # review: "abc" or "-0.3" were taken silently (a settling photo kept, a settled one flagged)
    assert main(["photoset", "init", str(logged_folder), "--pattern", "IMG_*.JPG",
                 "--pressure-log", "log.csv", "--clock-offset-s", "5.5", "--material", "DS20",
                 "--l0-mm", "100"]) == 0
    m = pd.read_csv(logged_folder / "manifest.csv", dtype={"since_step_s": str})
    m.loc[1, "since_step_s"], m.loc[2, "since_step_s"] = "abc", "-0.3"
    m.loc[3, "since_step_s"] = "1,2"  # a decimal comma: read as 1.2, as measure reads it
    m.to_csv(logged_folder / "manifest.csv", index=False)
    capsys.readouterr()
    assert main(["photoset", "check", str(logged_folder)]) == 1
    err = capsys.readouterr().err
    assert "manifest.csv line 3: since_step_s 'abc' is not a number" in err
    assert "manifest.csv line 4: since_step_s '-0.3' is negative" in err
    assert "line 5: since_step_s" not in err
