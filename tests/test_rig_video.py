"""``acquire --record video`` (a subprocess) against the pty emulator with the synthetic camera."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.photoset_check import check_photoset
from pipeline.photoset_measure import measure_photoset
from pipeline.rig.emulator import Emulator, Faults, PlantParams

REPO = Path(__file__).resolve().parents[1]


def video_cmd(port: str, out: Path, *extra: str, trials: int = 1) -> list[str]:
    return [
        sys.executable,
        "-m",
        "pipeline",
        "acquire",
        "--record",
        "video",
        "--port",
        port,
        "--camera",
        "synthetic",
        "--material",
        "SS40",
        "--actuator",
        "A1",
        "--trials",
        str(trials),
        "--max-kpa",
        "40",
        "--rate-kpa-s",
        "80",
        "--rest-s",
        "0.2",
        "--fps",
        "10",
        "--log-hz",
        "20",
        "--video-size",
        "160x120",
        "--out",
        str(out),
        "--no-progress",
        *extra,
    ]


def run(cmd: list[str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=120, check=False)


def test_a_continuous_ramp_is_recorded_as_a_video_photo_set_and_resumed(tmp_path):
    out = tmp_path / "rec"
    with Emulator(plant=PlantParams(lag_s=0.1), seed=2) as emu:
        done = run(video_cmd(emu.port, out))
        assert done.returncode == 0, done.stderr
        gets = sum(c.startswith("GET") for c in emu.stats.received)
        sets = [float(c.split()[1]) for c in emu.stats.received if c.startswith("SET")]
        assert emu.setpoint_kpa == 0.0
        assert 1.4 * 20 * 0.8 <= gets <= 1.4 * 20 * 1.3  # GET at the log rate over 0.2 + 1 + 0.2 s
        assert max(sets) == 40.0 and len(set(sets)) > 10  # ramped continuously, not in a few steps
        again = run(video_cmd(emu.port, out, trials=2))  # trial 1 is kept, trial 2 recorded
        assert again.returncode == 0, again.stderr
    assert "1 trial(s) already recorded" in again.stderr
    assert check_photoset(out) == []
    m = pd.read_csv(out / "manifest.csv")
    assert list(m["trial"]) == [1, 2] and (m["clock_offset_s"] == 0).all()
    log = pd.read_csv(out / m["pressure_log"].iloc[0])
    frames = pd.read_csv(out / m["frame_times"].iloc[0])
    assert (
        log["time_s"].iloc[0] < frames["time_s"].iloc[0]
        and frames["time_s"].iloc[-1] < log["time_s"].iloc[-1]
    )
    assert np.allclose(np.diff(frames["time_s"]).mean(), 0.1, atol=0.03)
    angles = measure_photoset(out)
    first = angles[angles["trial"].astype(str) == "1"]
    assert (first["status"] == "ok").mean() > 0.9
    # the recorder's stamps, on the log's clock
    assert np.allclose(first["time_s"], frames["time_s"])
    peak = int(first["measured_pressure_kpa"].idxmax())
    assert (
        first.loc[:peak, "direction"].iloc[:-2].eq("up").all()
        and first.loc[peak + 3 :, "direction"].eq("down").all()
    )
    # bent by the pressure, back at rest later
    assert first["psi_deg"].iloc[0] > first["psi_deg"].min() + 10
    assert 30 < first["measured_pressure_kpa"].max() < 41


def test_an_estop_vents_keeps_the_interrupted_recording_and_a_rerun_records_the_trial(tmp_path):
    out = tmp_path / "rec"
    link = tmp_path / "ttyPICO"
    with Emulator(faults=Faults(estop_at_set=8), link=link) as emu:
        stopped = run(video_cmd(str(link), out))
        assert stopped.returncode == 3, stopped.stderr
        assert emu.setpoint_kpa == 0.0
        assert "emergency stop" in stopped.stderr and "vented to 0 kPa" in stopped.stderr
        assert "re-run the same command to record trial 1 again" in stopped.stderr
        assert not (out / "manifest.csv").exists()
        kept = sorted(p.name for p in out.glob("*.interrupted.*"))
        assert kept == [
            "SS40_A1_t1_ramp.avi.interrupted.avi",
            "SS40_A1_t1_ramp_frames.csv.interrupted.csv",
            "SS40_A1_t1_ramp_pressure.csv.interrupted.csv",
        ]
        emu.release_estop()
        resumed = run(video_cmd(str(link), out))
        assert resumed.returncode == 0, resumed.stderr
    assert len(pd.read_csv(out / "manifest.csv")) == 1 and check_photoset(out) == []


def test_dry_run_and_cameras_that_cannot_record_video(tmp_path):
    plan = run(
        video_cmd(
            "-",
            tmp_path / "rec",
            "--dry-run",
            "--profile",
            "steps",
            "--step-kpa",
            "20",
            "--hold-s",
            "2",
        )
    )
    assert plan.returncode == 0, plan.stderr
    assert (
        "steps of 20 kPa to 40 kPa and back, 2 s each" in plan.stdout
        and "to do: trials [1]" in plan.stdout
    )
    with Emulator() as emu:
        cmd = video_cmd(emu.port, tmp_path / "rec")
        cmd[cmd.index("synthetic")] = "dir:/tmp"
        refused = run(cmd)
    assert refused.returncode == 2 and "cannot record video" in refused.stderr
