"""The real ``acquire`` command (a subprocess) against the emulator through a real pty.

The emulator runs in this process (a thread), so the tests can see what the device saw and
its final state (vented or not); ``--link`` gives it a stable port name across dropped
connections, like a udev symlink for a re-plugged Pico.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from pipeline.photoset import load_photoset, validate_photoset
from pipeline.rig.acquire import EXIT_CODES, failure_status
from pipeline.rig.cameras import CameraError
from pipeline.rig.driver import EStopError, LimitError, PortLostError, RigError
from pipeline.rig.emulator import Emulator, Faults, PlantParams

REPO = Path(__file__).resolve().parents[1]
COLUMNS = [
    "image",
    "pressure_kpa",
    "direction",
    "material",
    "actuator",
    "trial",
    "step",
    "timestamp",
    "measured_pressure_kpa",
]
FULL_RAMP = [0, 50, 100, 120, 100, 50, 0]  # --step-kpa 50 --max-kpa 120


@pytest.fixture(scope="module")
def photo(tmp_path_factory) -> Path:
    """A small PNG the ``cmd:`` camera copies for every shot."""
    path = tmp_path_factory.mktemp("cam") / "shot.png"
    img = np.full((60, 80, 3), 255, np.uint8)
    cv2.line(img, (10, 30), (70, 30), (0, 0, 0), 3)
    cv2.imwrite(str(path), img)
    return path


def acquire_cmd(port: str, out: Path, photo: Path, *extra: str, trials: int = 2) -> list[str]:
    return [
        sys.executable,
        "-m",
        "pipeline",
        "acquire",
        "--port",
        port,
        "--camera",
        f"cmd:cp {photo} {{path}}",
        "--material",
        "DS20",
        "--actuator",
        "A1",
        "--trials",
        str(trials),
        "--step-kpa",
        "50",
        "--max-kpa",
        "120",
        "--settle-s",
        "0",
        "--l0-mm",
        "200",
        "--out",
        str(out),
        "--no-progress",
        *extra,
    ]


def run(cmd: list[str], timeout: float = 60) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        cmd, cwd=REPO, capture_output=True, text=True, timeout=timeout, check=False
    )


def main_inprocess(cmd: list[str], capsys) -> tuple[int, str, str]:
    """Run the same command line through ``pipeline.cli.main`` in this process (cheap checks)."""
    from pipeline.cli import main

    code = main(cmd[3:])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def manifest(out: Path) -> pd.DataFrame:
    return pd.read_csv(out / "manifest.csv")


def assert_consistent(out: Path) -> pd.DataFrame:
    """The folder is a valid photo set: every row's image exists, no duplicates, steps in ramp
    order."""
    assert validate_photoset(out, decode_images=True) == []
    df = manifest(out)
    assert list(df.columns[: len(COLUMNS)]) == COLUMNS
    assert not df.duplicated(["trial", "step"]).any()
    for _, g in df.groupby("trial"):
        steps = g["step"].to_numpy()
        assert list(steps) == list(range(len(steps)))  # contiguous from 0
        assert list(g["pressure_kpa"]) == FULL_RAMP[: len(g)]
    return df


def test_full_short_ramp(tmp_path, photo):
    out = tmp_path / "set"
    plant = PlantParams(gain=0.97, offset_kpa=-1.5, monitor_noise_kpa=0.0)
    with Emulator(plant=plant, seed=1) as emu:
        done = run(acquire_cmd(emu.port, out, photo))
        assert done.returncode == 0, done.stderr
        assert emu.setpoint_kpa == 0.0
        sets = [line for line in emu.stats.received if line.startswith("SET")]
    assert (done.stdout + done.stderr).count("14 photo(s)") == 1  # said once, not again by the CLI
    assert "acquire: done: 14 photo(s) taken, 0 already recorded" in done.stderr
    df = assert_consistent(out)
    assert len(df) == 14
    assert list(df["direction"]) == ["up"] * 4 + ["down"] * 3 + ["up"] * 4 + ["down"] * 3
    assert list(df["trial"]) == [1] * 7 + [2] * 7
    assert set(df["material"]) == {"DS20"} and set(df["actuator"]) == {"A1"}
    pressed = df["pressure_kpa"] > 0
    expected = 0.97 * df.loc[pressed, "pressure_kpa"] - 1.5
    assert np.allclose(df.loc[pressed, "measured_pressure_kpa"], expected, atol=0.3)
    assert len(sets) == 14
    ps = load_photoset(out)
    assert ps.settings["l0_mm"] == 200.0 and ps.settings["positive_turn"] == "ccw"
    assert (out / df["image"].iloc[0]).read_bytes() == photo.read_bytes()


def test_estop_mid_ramp_vents_keeps_data_then_resumes(tmp_path, photo):
    out = tmp_path / "set"
    link = tmp_path / "ttyPICO"
    with Emulator(faults=Faults(estop_at_set=5), link=link) as emu:
        stopped = run(acquire_cmd(str(link), out, photo))
        assert emu.setpoint_kpa == 0.0 and emu.pressure_kpa == 0.0
        assert stopped.returncode == 3
        assert "emergency stop" in stopped.stderr and "vented to 0 kPa" in stopped.stderr
        assert "re-run the same command to resume" in stopped.stderr
        kept = assert_consistent(out)
        assert 0 < len(kept) < 14
        # the photo of the step during which the stop was pressed was discarded
        assert len(kept) == 4
        emu.release_estop()
        resumed = run(acquire_cmd(str(link), out, photo))
        assert resumed.returncode == 0, resumed.stderr
    assert "acquire: done: 10 photo(s) taken, 4 already recorded" in resumed.stderr
    assert len(assert_consistent(out)) == 14


def test_dropped_connection_then_rerun_resumes_without_duplicates(tmp_path, photo):
    out = tmp_path / "set"
    link = tmp_path / "ttyPICO"
    with Emulator(faults=Faults(drop_after=16), link=link) as emu:
        first = run(acquire_cmd(str(link), out, photo, "--watchdog-s", "2"))
        assert first.returncode == 4, first.stderr
        assert "lost" in first.stderr and "COULD NOT VENT" in first.stderr
        assert emu.stats.received[-1].startswith(("SET", "GET"))  # the host could not vent ...
        deadline = time.monotonic() + 8
        while emu.setpoint_kpa > 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert emu.setpoint_kpa == 0.0  # ... so the device's watchdog did
        kept = assert_consistent(out)
        n_kept = len(kept)
        assert 0 < n_kept < 14
        stamps = dict(zip(kept["image"], kept["timestamp"]))
        received_before = len(emu.stats.received)
        second = run(acquire_cmd(str(link), out, photo))
        assert second.returncode == 0, second.stderr
        resumed_sets = [c for c in emu.stats.received[received_before:] if c.startswith("SET")]
    said = f"acquire: done: {14 - n_kept} photo(s) taken, {n_kept} already recorded"
    assert said in second.stderr
    df = assert_consistent(out)
    assert len(df) == 14
    for image, stamp in stamps.items():  # recorded rows untouched
        assert df.loc[df["image"] == image, "timestamp"].item() == stamp
    # the resumed trial was brought back along its pressure history before the first missing step
    first_missing = kept.iloc[-1]
    assert float(resumed_sets[0].split()[1]) <= float(first_missing["pressure_kpa"]) + 50


def test_sigint_vents_and_keeps_manifest_intact(tmp_path, photo):
    out = tmp_path / "set"
    with Emulator() as emu:
        cmd = acquire_cmd(emu.port, out, photo, trials=6)
        cmd[cmd.index("--settle-s") + 1] = "0.15"
        proc = subprocess.Popen(
            cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
        )
        deadline = time.monotonic() + 30
        while time.monotonic() < deadline:
            if (out / "manifest.csv").is_file() and len(manifest(out)) >= 3:
                break
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=20)
        assert proc.returncode == 130
        assert emu.setpoint_kpa == 0.0
    assert "interrupted" in err and "vented to 0 kPa" in err and "Traceback" not in err
    df = assert_consistent(out)
    assert 3 <= len(df) < 42


def test_limit_refused_before_anything_is_sent(tmp_path, photo, capsys):
    out = tmp_path / "set"
    cal = tmp_path / "cal.yaml"
    cal.write_text(
        "method: linear\npoints:\n- {dac_code: 0, pressure_kpa: 0}\n- {dac_code: 4095, "
        "pressure_kpa: 500}\nmax_kpa: 100\n"
    )
    with Emulator() as emu:
        code, _, err = main_inprocess(
            acquire_cmd(emu.port, out, photo, "--calibration", str(cal)), capsys
        )
        assert not [c for c in emu.stats.received if c.startswith("SET")]
    assert code == 6
    assert "above the driver limit 100 kPa" in err


def test_base_protocol_firmware_ramp_completes_and_vents(tmp_path, photo, capsys):
    """Firmware with only ID/SET/GET/VENT/EVT ESTOP: the ramp runs to --max-kpa, vents, and says
    what it lacked."""
    out = tmp_path / "set"
    with Emulator(protocol="base", seed=2) as emu:
        code, _, err = main_inprocess(
            acquire_cmd(emu.port, out, photo, "--watchdog-s", "5", trials=1), capsys
        )
        assert code == 0, err
        assert emu.setpoint_kpa == 0.0 and emu.pressure_kpa == 0.0
        received = list(emu.stats.received)
    df = assert_consistent(out)
    assert list(df["pressure_kpa"]) == FULL_RAMP
    assert received[-1] == "VENT"
    sets = [float(c.split()[1]) for c in received if c.startswith("SET")]
    assert max(sets) == 120.0  # the limit came from the command line
    extension_commands = [c for c in received if c.split()[0] not in ("ID", "SET", "GET", "VENT")]
    # probed once at connect, never used
    assert extension_commands == ["CFG", "WDOG 0.0000", "SCALE"]
    assert "not used: firmware circact-pico 1.1 has no CFG" in err and "--max-kpa 120 kPa" in err
    assert "has no WDOG" in err and "acquire: done" in err
    out_blocked = tmp_path / "blocked"
    with Emulator(protocol="base") as emu:
        code, _, err = main_inprocess(
            acquire_cmd(emu.port, out_blocked, photo, "--mode", "blocked", trials=1), capsys
        )
        assert not [c for c in emu.stats.received if c.startswith("SET")]  # nothing pressurised
    assert code == EXIT_CODES["error"] and "blocked mode needs the load cell" in err
    assert not (out_blocked / "manifest.csv").exists()


def test_garbage_from_device_is_ignored(tmp_path, photo, capsys):
    out = tmp_path / "set"
    with Emulator(faults=Faults(garbage_every=2), seed=3) as emu:
        code, _, err = main_inprocess(acquire_cmd(emu.port, out, photo), capsys)
    assert code == 0, err
    n = int(err.split("ignored ")[1].split()[0])
    assert n >= 10
    assert len(assert_consistent(out)) == 14


def test_blocked_mode_records_force_statistics(tmp_path, photo, capsys):
    out = tmp_path / "set"
    plant = PlantParams(monitor_noise_kpa=0.0, force_noise_n=0.02)
    with Emulator(plant=plant, seed=7) as emu:
        code, _, err = main_inprocess(
            acquire_cmd(
                emu.port, out, photo, "--mode", "blocked", "--force-samples", "8", trials=1
            ),
            capsys,
        )
        assert code == 0, err
        assert [c for c in emu.stats.received if c.startswith("TARE")]
    df = assert_consistent(out)
    assert {"force_n", "force_sd_n", "force_samples"} <= set(df.columns)
    assert (df["force_samples"] == 8).all()
    expected = [
        plant.force_n(p) - plant.force_n(0.0) for p in df["measured_pressure_kpa"].clip(lower=0)
    ]
    assert np.allclose(df["force_n"], expected, atol=0.04)  # 4 sd of the mean of 8 readings
    assert ((df["force_sd_n"] > 0.005) & (df["force_sd_n"] < 0.05)).all()
    up = df[df["direction"] == "up"]["force_n"].to_numpy()
    assert np.all(np.diff(up) > 0)
    # non-linear: the force per kPa grows with pressure
    slopes = np.diff(up) / np.diff(df[df["direction"] == "up"]["measured_pressure_kpa"].to_numpy())
    assert slopes[-1] > 1.2 * slopes[0]
    assert load_photoset(out).manifest["force_n"].notna().all()


def test_dry_run_prints_plan_and_resume_point(tmp_path, photo, capsys):
    out = tmp_path / "set"
    code, text, _ = main_inprocess(acquire_cmd("", out, photo, "--dry-run"), capsys)
    assert code == 0
    assert "up 0 50 100 120" in text and "trial 2: 7 steps, 0 recorded, start at step 0" in text
    assert "synthetic camera" not in text  # a real camera's photos keep the settings listed
    assert not out.exists()
    with Emulator(faults=Faults(drop_after=16)) as emu:
        assert run(acquire_cmd(emu.port, out, photo)).returncode == 4
    n = len(manifest(out))
    code, text, _ = main_inprocess(acquire_cmd("", out, photo, "--dry-run"), capsys)
    assert code == 0
    assert f"trial 1: 7 steps, {n} recorded, resume at step {n} ({FULL_RAMP[n]} kPa" in text
    assert f"after passing {' '.join(str(p) for p in FULL_RAMP[1:n])} kPa without photos" in text
    assert "trial 2: 7 steps, 0 recorded" in text


def test_bad_options_exit_2(tmp_path, photo, capsys):
    code, _, err = main_inprocess(
        acquire_cmd("/dev/null", tmp_path / "x", photo, "--trials", "0"), capsys
    )
    assert code == 2 and "--trials" in err
    code, _, err = main_inprocess(acquire_cmd("/nonexistent/tty", tmp_path / "x", photo), capsys)
    assert code == 4 and "cannot open serial port" in err


def test_watched_folder_camera(tmp_path, photo, capsys):
    """``dir:`` takes the first image that arrives after each request (a feeder writes one every 30
    ms)."""
    watch = tmp_path / "watch"
    watch.mkdir()
    (watch / "old.png").write_bytes(photo.read_bytes())  # present before: never used
    stop = threading.Event()

    def feeder() -> None:
        i = 0
        while not stop.is_set():
            img = np.full((40, 40, 3), i % 256, np.uint8)
            _, buf = cv2.imencode(".png", img)
            tmp = watch / f".tmp{i}"
            tmp.write_bytes(buf.tobytes())
            os.replace(tmp, watch / f"img{i:05d}.png")
            i += 1
            time.sleep(0.03)

    thread = threading.Thread(target=feeder, daemon=True)
    thread.start()
    out = tmp_path / "set"
    try:
        with Emulator() as emu:
            cmd = acquire_cmd(emu.port, out, photo, trials=1)
            cmd[cmd.index("--camera") + 1] = f"dir:{watch}"
            code, _, err = main_inprocess(cmd, capsys)
    finally:
        stop.set()
        thread.join()
    assert code == 0, err
    df = assert_consistent(out)
    images = [(out / name).read_bytes() for name in df["image"]]
    assert len(set(images)) == len(images)  # a different file each step
    assert photo.read_bytes() not in images


def synthetic_cmd(port: str, out: Path, *extra: str, step: int = 40, top: int = 120) -> list[str]:
    return [
        sys.executable,
        "-m",
        "pipeline",
        "acquire",
        "--port",
        port,
        "--camera",
        "synthetic:clean",
        "--material",
        "DS20",
        "--actuator",
        "A1",
        "--trials",
        "1",
        "--step-kpa",
        str(step),
        "--max-kpa",
        str(top),
        "--settle-s",
        "0",
        "--out",
        str(out),
        "--no-progress",
        *extra,
    ]


def test_synthetic_camera_virtual_rig(tmp_path):
    out = tmp_path / "set"
    with Emulator(seed=2) as emu:
        done = run(synthetic_cmd(emu.port, out, "--no-stop-at-psi0"), timeout=120)
    assert done.returncode == 0, done.stderr
    ps = load_photoset(out)
    assert ps.settings["fixed_end"] != "auto" and ps.settings["mm_per_px"] > 0
    assert len(ps.manifest) == 7
    first = cv2.imread(str(out / ps.manifest["image"].iloc[0]))
    top = cv2.imread(str(out / ps.manifest["image"].iloc[3]))
    assert first is not None and top is not None and first.shape == top.shape
    assert np.mean(np.abs(first.astype(int) - top.astype(int))) > 1  # the actuator moved
    # the virtual camera frames the whole line at every step (it zooms out for a long actuator)
    from pipeline.photoset_measure import measure_photoset

    angles = measure_photoset(out)
    assert (angles["status"] == "ok").all(), angles[["image", "status", "reason"]]


def test_synthetic_ramp_stops_when_psi_reaches_minus_psi0(tmp_path):
    """Live measurement ends the up leg once psi <= -psi0; the down leg mirrors it; resume keeps
    it."""
    from pipeline.measure import measure_image
    from pipeline.model import load_materials, psi_deg

    psi0 = load_materials()["DS20"].psi0_deg
    out = tmp_path / "set"
    # ID, CFG, WDOG 0, SCALE, VENT, WDOG, VENT, then SET+GET per step: the port drops right after
    # the
    # 6th photo (100 kPa), the one that reaches -psi0, before any down step: the re-run must find
    # the peak
    with Emulator(seed=2, faults=Faults(drop_after=19)) as emu:
        first = run(synthetic_cmd(emu.port, out, "--stop-at-psi0", step=20, top=260), timeout=120)
    assert first.returncode == 4
    kept = manifest(out)
    assert len(kept) == 6 and set(kept["direction"]) == {"up"}
    with Emulator(seed=2) as emu:
        done = run(synthetic_cmd(emu.port, out, "--stop-at-psi0", step=20, top=260), timeout=120)
    assert done.returncode == 0, done.stderr
    assert "6 already recorded" in done.stderr
    ps = load_photoset(out)
    df = ps.manifest
    up, down = df[df["direction"] == "up"], df[df["direction"] == "down"]
    peak = up["pressure_kpa"].max()
    assert peak < 260  # stopped early
    assert list(down["pressure_kpa"]) == sorted(up["pressure_kpa"][:-1], reverse=True)
    assert df["step"].tolist() == list(range(len(df)))
    # the stop is where the measured psi first reaches -psi0 (and not before)
    psis = [
        measure_image(cv2.imread(str(out / name)), settings).psi_deg
        for name, settings in zip(df["image"], ps.rows)
        if name in set(up["image"])
    ]
    assert psis[-1] <= -psi0 and all(p > -psi0 for p in psis[:-1])
    assert float(psi_deg("DS20", np.array([peak]))[0]) < -psi0 + 30


def test_synthetic_blocked_rig(tmp_path, capsys):
    out = tmp_path / "set"
    with Emulator(seed=3) as emu:
        code, _, err = main_inprocess(
            synthetic_cmd(
                emu.port, out, "--mode", "blocked", "--force-samples", "3", step=50, top=100
            ),
            capsys,
        )
    assert code == 0, err
    df = load_photoset(out).manifest
    assert len(df) == 5 and df["force_n"].notna().all() and (df["force_samples"] == 3).all()


def test_rig_benchmark_times_a_real_live_measurement():
    """The live-psi figure of ``bench rig`` is the cost of measuring, not of a failed
    measurement."""
    from pipeline.bench.rig import synthetic_costs

    costs = synthetic_costs(2)
    assert costs["live_psi_measured"] == 2
    assert costs["live_psi_measure_median_ms"] > 0


@pytest.mark.parametrize(
    ("exc", "status"),
    [
        (KeyboardInterrupt(), "interrupted"),
        (EStopError("EVT ESTOP"), "estop"),
        (PortLostError("port gone"), "port_lost"),
        (CameraError("no frame"), "camera"),
        (LimitError("over max", sent=True), "limit"),
        (RigError("other rig trouble"), "error"),
        (ValueError("bug"), "error"),
    ],
)
def test_every_failure_of_a_run_has_its_status_and_exit_code(exc, status):
    got, message = failure_status(exc)
    assert got == status and message
    assert got in EXIT_CODES


def test_a_resume_with_another_ramp_is_refused_before_the_port_is_opened(tmp_path):
    # customer 21 resumed a set begun at 10 kPa steps with --step-kpa 20: it was accepted and
    # trial 1 became 0, 10, ..., 90, then 200 kPa, one trial of two ramps (only the ramp check
    # of measure caught it). Now the recorded steps are checked against the command's ramp
    rows = [
        {"image": f"DS20_A1_t1_s{k:03d}_up_{p}kPa.jpg", "pressure_kpa": p, "direction": "up",
         "material": "DS20", "actuator": "A1", "trial": 1, "step": k}
        for k, p in enumerate((0, 10, 20))
    ]
    pd.DataFrame(rows).to_csv(tmp_path / "manifest.csv", index=False)
    for r in rows:
        (tmp_path / r["image"]).write_bytes(b"x")
    base = [sys.executable, "-m", "pipeline", "acquire", "--camera", "synthetic", "--material",
            "DS20", "--actuator", "A1", "--trials", "1", "--out", str(tmp_path)]
    # no --port: refused for the ramp before the missing port is even noticed
    out = subprocess.run(base + ["--step-kpa", "20"], capture_output=True, text=True, check=False)
    assert out.returncode == 2, out.stderr
    assert "trial 1's step 1 was taken at 10 kPa up, where this ramp has 20 kPa up" in out.stderr
    assert "--port" not in out.stderr
    out = subprocess.run(base + ["--step-kpa", "10", "--dry-run"], capture_output=True, text=True,
                         check=False)
    assert out.returncode == 0 and "3 recorded, resume at step 3 (30 kPa up)" in out.stdout
    # the plan says where the photo set's fixed end comes from (not the 'auto' it lists)
    assert "the synthetic camera writes its own scene's fixed_end" in out.stdout
