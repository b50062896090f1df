"""The real pyserial driver against the emulator through a real pseudo-terminal."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from pipeline.errors import UserInputError
from pipeline.rig.calibration import fit_calibration, read_calibration, write_calibration
from pipeline.rig.cli import run_calibration
from pipeline.rig.driver import (
    EStopError,
    LimitError,
    PicoDriver,
    PortLostError,
    UnsupportedError,
    WatchdogError,
)
from pipeline.rig.emulator import Emulator, Faults, PlantParams, parse_faults
from pipeline.rig.firmware import rigcore

REPO = Path(__file__).resolve().parents[1]


def test_set_get_through_pty_follows_the_plant():
    plant = PlantParams(gain=0.95, offset_kpa=-2.0, monitor_noise_kpa=0.0)
    with Emulator(plant=plant, seed=1) as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        assert rig.info is not None and rig.info.name == rigcore.NAME and rig.info.max_kpa == 300.0
        for p in (0.0, 40.0, 200.0):
            result = rig.set_kpa(p)
            assert result.dac_code == rigcore.kpa_to_code(p, rigcore.Config())
            reading = rig.get()
            assert reading.setpoint_kpa == pytest.approx(p)
            expected = (
                0.0
                if p == 0
                else 0.95 * rigcore.code_to_kpa(result.dac_code, rigcore.Config()) - 2.0
            )
            assert reading.measured_kpa == pytest.approx(expected, abs=0.2)  # one ADC step
            assert not reading.estop
    assert emu.setpoint_kpa == 0.0  # leaving the context vents


def test_base_protocol_firmware_connects_and_extensions_are_optional(tmp_path):
    """Firmware that speaks only ID, SET, GET, VENT: set/get/vent work, extensions raise without
    being sent."""
    with Emulator(protocol="base", seed=1) as emu, PicoDriver.open(emu.port, max_kpa=150) as rig:
        assert rig.info is not None and rig.info.extensions == frozenset()
        assert rig.info.missing == ("CFG", "WDOG", "LOAD") and rig.info.max_kpa is None
        probes = list(emu.stats.received)
        # each probed once, no retry on ERR PARSE
        assert probes == ["ID", "CFG", "WDOG 0.0000", "SCALE"]
        assert rig.set_kpa(100).pressure_kpa == 100
        assert rig.get().setpoint_kpa == 100
        with pytest.raises(LimitError) as info:  # the host limit from the caller still applies
            rig.set_kpa(151)
        assert info.value.sent is False
        for call in (lambda: rig.set_watchdog(5), rig.tare, rig.load_n, rig.get_scale):
            with pytest.raises(UnsupportedError, match="does not speak"):
                call()
        assert emu.stats.received[len(probes):] == ["SET 100.0000", "GET"]  # nothing else was sent
    assert emu.setpoint_kpa == 0.0  # leaving the context vents
    cal = fit_calibration([0, 4095], [0.0, 500.0])
    with Emulator(protocol="base") as emu:
        with pytest.raises(UnsupportedError, match="no CFG"):
            PicoDriver.open(emu.port, max_kpa=150, calibration=cal)
        assert not [c for c in emu.stats.received if c.startswith("SET")]
    # our firmware: everything found
    with Emulator() as emu, PicoDriver.open(emu.port, max_kpa=150) as rig:
        assert rig.info is not None and rig.info.missing == () and rig.info.max_kpa == 300.0


def test_host_limit_refuses_before_sending():
    with Emulator() as emu, PicoDriver.open(emu.port, max_kpa=120) as rig:
        rig.set_kpa(120)
        before = list(emu.stats.received)
        for bad in (120.5, 300.0, -1.0, float("nan")):
            with pytest.raises(LimitError) as info:
                rig.set_kpa(bad)
            assert info.value.sent is False
        time.sleep(0.05)
        assert emu.stats.received == before  # nothing reached the device
        assert emu.setpoint_kpa == 120.0


def test_device_limit_is_reported():
    with (
        Emulator(cfg=rigcore.Config(max_kpa=150)) as emu,
        PicoDriver.open(emu.port, max_kpa=400) as rig,
    ):
        with pytest.raises(LimitError) as info:
            rig.set_kpa(200)
        assert info.value.sent is True and "150" in str(info.value)
        assert emu.stats.received[-1].startswith("SET 200")
        assert emu.setpoint_kpa == 0.0


def test_garbage_lines_are_skipped():
    with (
        Emulator(faults=Faults(garbage_every=1), seed=4) as emu,
        PicoDriver.open(emu.port, max_kpa=260) as rig,
    ):
        for p in range(0, 101, 10):
            assert rig.set_kpa(p).pressure_kpa == p
            assert rig.get().setpoint_kpa == p
        assert rig.garbage_lines >= 22


def test_slow_replies_ok_within_timeout_and_lost_beyond():
    with (
        Emulator(faults=Faults(slow_s=0.05)) as emu,
        PicoDriver.open(emu.port, max_kpa=260, timeout_s=1.0) as rig,
    ):
        rig.set_kpa(30)
        assert rig.get().setpoint_kpa == 30
    with (
        Emulator(faults=Faults(slow_s=0.6)) as emu,
        pytest.raises(PortLostError, match="no reply"),
    ):
        PicoDriver.open(emu.port, max_kpa=260, timeout_s=0.3)


def test_dropped_connection_raises_port_lost():
    with Emulator(faults=Faults(drop_after=6)) as emu:
        rig = PicoDriver.open(emu.port, max_kpa=260)  # ID, CFG, WDOG 0, SCALE
        rig.set_kpa(10)
        rig.get()
        with pytest.raises(PortLostError):
            rig.set_kpa(20)
        assert rig.safe_vent(timeout_s=0.2) is False
        rig.close()
        assert emu.stats.drops == 1


def test_dropped_connection_with_link_reconnects(tmp_path):
    link = tmp_path / "ttyPICO"
    with Emulator(faults=Faults(drop_after=5), link=link):
        rig = PicoDriver.open(str(link), max_kpa=260)
        rig.set_kpa(50)
        with pytest.raises(PortLostError):
            rig.get()
        rig.close()
        # same name, new pty, same device state
        with PicoDriver.open(str(link), max_kpa=260) as rig2:
            assert rig2.get().setpoint_kpa == 50.0


def test_estop_event_during_sleep_and_refused_set():
    with Emulator() as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        rig.set_kpa(100)
        emu.press_estop()
        with pytest.raises(EStopError):
            rig.sleep(1.0)
        assert emu.setpoint_kpa == 0.0 and emu.pressure_kpa == 0.0
        with pytest.raises(EStopError):
            rig.set_kpa(50)
        with pytest.raises(EStopError):
            rig.get()
        rig.vent()  # allowed while pressed
        emu.release_estop()
        rig.set_kpa(50)
        assert rig.get().setpoint_kpa == 50


def test_device_watchdog_vents_a_silent_host():
    with Emulator() as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        assert rig.set_watchdog(0.2) == pytest.approx(0.2)
        rig.set_kpa(100)
        with pytest.raises(WatchdogError):
            rig.sleep(1.0)
        assert emu.setpoint_kpa == 0.0
        rig.set_watchdog(0)
        rig.set_kpa(100)
        rig.sleep(0.4)
        assert emu.setpoint_kpa == 100.0


def test_estop_fault_at_kth_set():
    with (
        Emulator(faults=Faults(estop_at_set=2)) as emu,
        PicoDriver.open(emu.port, max_kpa=260) as rig,
    ):
        rig.set_kpa(10)
        rig.sleep(0.05)
        rig.set_kpa(20)
        with pytest.raises(EStopError):
            rig.sleep(0.5)
        assert emu.setpoint_kpa == 0.0


@pytest.mark.parametrize("points", [[30, 250], [0, 60, 120, 180, 240]])
def test_calibration_routine_corrects_the_regulator(points, tmp_path):
    plant = PlantParams(gain=0.93, offset_kpa=-3.0, monitor_noise_kpa=0.1)
    with Emulator(plant=plant, seed=2) as emu:
        with PicoDriver.open(emu.port, max_kpa=260) as rig:
            cal = run_calibration(
                rig, [float(p) for p in points], settle_s=0.0, samples=4, max_kpa=255
            )
            rig.set_kpa(200)
            uncalibrated = rig.get().measured_kpa
        path = tmp_path / "cal.yaml"
        write_calibration(path, cal)
        cal2 = read_calibration(path)
        assert (
            cal2.method == ("linear" if len(points) == 2 else "piecewise") and cal2.max_kpa == 255
        )
        with PicoDriver.open(emu.port, max_kpa=260, calibration=cal2) as rig:
            assert rig.max_kpa == 255
            errors = []
            for p in (50.0, 120.0, 200.0):
                rig.set_kpa(p)
                errors.append(np.mean([rig.get().measured_kpa for _ in range(4)]) - p)
    assert abs(uncalibrated - 200) > 10  # the plant is off by ~17 kPa at 200 kPa
    assert max(abs(e) for e in errors) < 1.0


def test_calibration_fit_and_file_errors(tmp_path):
    cal = fit_calibration([0, 1000, 2000], [0.0, 115.0, 240.0])
    assert cal.method == "piecewise"
    assert cal.kpa_to_code(115.0) == 1000 and cal.kpa_to_code(0) == 0
    assert abs(cal.code_to_kpa(1500) - 177.5) < 1e-9
    with pytest.raises(UserInputError, match="at least two"):
        fit_calibration([0], [0.0])
    with pytest.raises(UserInputError, match="repeat"):
        fit_calibration([5, 5], [0.0, 1.0])
    with pytest.raises(UserInputError, match="does not increase"):
        fit_calibration([0, 10, 20], [0.0, 5.0, 5.0], "piecewise")
    bad = tmp_path / "bad.yaml"
    bad.write_text("points: 3\n")
    with pytest.raises(UserInputError, match="bad.yaml"):
        read_calibration(bad)
    with pytest.raises(UserInputError, match="not found"):
        read_calibration(tmp_path / "none.yaml")


def test_load_cell_tare_readings_and_scale():
    plant = PlantParams(force_noise_n=0.01)
    with Emulator(plant=plant, seed=5) as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        offset = rig.tare(20)
        assert abs(offset - plant.load_offset_counts) < 0.01 * plant.load_counts_per_newton
        assert abs(np.mean(rig.load_samples(10))) < 0.01
        rig.set_kpa(100)
        p_true = emu.pressure_kpa
        samples = rig.load_samples(20)
        assert np.mean(samples) == pytest.approx(plant.force_n(p_true), abs=0.01)
        assert 0.003 < np.std(samples, ddof=1) < 0.03
        assert rig.set_scale(plant.load_counts_per_newton / 2) == pytest.approx(21000)
        assert np.mean(rig.load_samples(10)) == pytest.approx(2 * plant.force_n(p_true), abs=0.03)
        assert rig.load_raw() > plant.load_offset_counts


def test_parse_faults():
    assert parse_faults(
        ["drop-after=5", "slow=0.1", "garbage-every=3", "estop-at-set=2"]
    ) == Faults(5, 2, 0.1, 3)
    for bad in (["boom=1"], ["slow=x"], ["garbage-every=0"]):
        with pytest.raises(UserInputError):
            parse_faults(bad)


def test_emulate_cli_prints_port_and_serves_until_killed():
    proc = subprocess.Popen(
        [sys.executable, "-m", "pipeline", "rig", "emulate", "--seed", "1"],
        cwd=REPO,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        line = proc.stdout.readline()
        assert line.startswith("PORT /dev/")
        with PicoDriver.open(line.split()[1], max_kpa=260) as rig:
            rig.set_kpa(25)
            assert rig.get().setpoint_kpa == 25
        assert proc.poll() is None  # still serving after the client left
    finally:
        proc.terminate()
        assert proc.wait(timeout=5) == 0


def test_calibrate_cli_from_monitor_and_from_readings(tmp_path, capsys):
    from pipeline.cli import main

    with Emulator(plant=PlantParams(gain=0.9, offset_kpa=-2.0)) as emu:
        path = tmp_path / "cal.yaml"
        code = main(
            [
                "rig",
                "calibrate",
                "--port",
                emu.port,
                "--out",
                str(path),
                "--points-kpa",
                "0,100,200",
                "--settle-s",
                "0",
                "--samples",
                "3",
                "--max-kpa",
                "250",
            ]
        )
        assert code == 0 and "3 points" in capsys.readouterr().out
        cal = read_calibration(path)
        assert cal.method == "piecewise" and cal.max_kpa == 250
        assert cal.code_to_kpa(cal.dac_code[-1]) == pytest.approx(
            0.9 * rigcore.code_to_kpa(cal.dac_code[-1], rigcore.Config()) - 2, abs=0.5
        )
        assert emu.setpoint_kpa == 0.0
    readings = tmp_path / "gauge.csv"
    readings.write_text("dac_code,pressure_kpa\n400,47.5\n2000,242.0\n")
    assert main(["rig", "calibrate", "--readings", str(readings), "--out", str(path)]) == 0
    assert read_calibration(path).method == "linear"
    readings.write_text("code,kpa\n1,2\n")
    assert main(["rig", "calibrate", "--readings", str(readings), "--out", str(path)]) == 2


def test_load_cli_sets_scale_from_a_known_force(tmp_path, capsys):
    from pipeline.cli import main

    plant = PlantParams(force_noise_n=0.005)
    with Emulator(plant=plant, seed=9) as emu:
        rig = PicoDriver.open(emu.port, max_kpa=260)
        rig.tare(20)
        rig.set_scale(21000.0)  # wrong by a factor 2
        rig.set_kpa(120)
        known = plant.force_n(emu.pressure_kpa)  # the "weight" hanging on the cell
        rig.close()  # no vent: keep the force on
        assert (
            main(
                ["rig", "load", "--port", emu.port, "--known-n", f"{known:.5f}", "--samples", "20"]
            )
            == 0
        )
        out = capsys.readouterr().out
        new_scale = float(out.split("scale ")[1].split()[0])
        assert new_scale == pytest.approx(plant.load_counts_per_newton, rel=0.01)
        assert emu.controller.counts_per_newton == pytest.approx(new_scale, rel=1e-6)
