"""Firmware logic on the host: parsing, DAC/ADC arithmetic, limits, e-stop, load cell (no serial
port)."""

from __future__ import annotations

import ast

import pytest

from pipeline.rig.firmware import FIRMWARE_DIR, rigcore
from pipeline.rig.protocol import encode, parse_reply

CFG = rigcore.Config()


def test_dac_code_round_trip_every_code():
    for code in range(rigcore.DAC_MAX + 1):
        assert rigcore.kpa_to_code(rigcore.code_to_kpa(code, CFG), CFG) == code


def test_dac_scaling_and_clipping():
    # 12-bit MCP4921 behind a 5/3.3 amplifier into a 0-5 V, 0-500 kPa regulator: 4096 codes = 500
    # kPa
    assert rigcore.kpa_to_code(250.0, CFG) == 2048
    assert rigcore.kpa_to_code(0.0, CFG) == 0
    assert rigcore.kpa_to_code(-5.0, CFG) == 0
    assert rigcore.kpa_to_code(10_000.0, CFG) == 4095
    codes = [rigcore.kpa_to_code(p / 10, CFG) for p in range(5000)]
    assert codes == sorted(codes)
    assert abs(rigcore.code_to_kpa(1, CFG) - 500.0 / 4096) < 1e-9


@pytest.mark.parametrize("code", [0, 1, 819, 2048, 4095])
def test_mcp4921_frame_bits(code):
    frame = rigcore.mcp4921_frame(code)
    word = (frame[0] << 8) | frame[1]
    assert len(frame) == 2
    assert word >> 15 == 0  # DAC A
    assert (word >> 14) & 1 == 0  # unbuffered Vref
    assert (word >> 13) & 1 == 1  # gain 1x
    assert (word >> 12) & 1 == 1  # output active
    assert word & 0x0FFF == code


def test_mcp4921_frame_rejects_out_of_range():
    for bad in (-1, 4096):
        with pytest.raises(ValueError):
            rigcore.mcp4921_frame(bad)


def test_monitor_adc_round_trip_within_one_lsb():
    # one 12-bit ADC step through the 0.6 divider of a 1-5 V monitor, in kPa
    lsb_kpa = 3.3 / 4095 / 0.6 / 4.0 * 500.0
    for p in [0.0, 0.3, 12.5, 100.0, 249.9, 400.0]:
        u16 = rigcore.kpa_to_monitor_u16(p, CFG)
        assert 0 <= u16 <= 65535
        assert abs(rigcore.monitor_kpa(u16, CFG) - p) <= lsb_kpa
    # MicroPython 12->16 bit scaling
    assert rigcore.kpa_to_monitor_u16(0.0, CFG) & 0xF == rigcore.kpa_to_monitor_u16(0.0, CFG) >> 12


def test_hx711_sign_extension():
    assert rigcore.hx711_signed(0x000001) == 1
    assert rigcore.hx711_signed(0x7FFFFF) == 8388607
    assert rigcore.hx711_signed(0x800000) == -8388608
    assert rigcore.hx711_signed(0xFFFFFF) == -1


@pytest.mark.parametrize(
    "line",
    [
        "",
        "   ",
        "SET",
        "SET 1 2",
        "SET abc",
        "SET 12abc",
        "SET nan",
        "SET inf",
        "SET 1e999",
        "SET 0x10",
        "FOO",
        "GET 1",
        "VENT now",
        "ID x",
        "SET " + "1" * 70,
        "SET\t5",
        b"\xff\xfeSET 5",
        "SCALE 0",
        "TARE 0",
        "TARE 2.5",
        "LOAD 3",
    ],
)
def test_malformed_lines_get_err_parse(line):
    c = rigcore.Controller(rigcore.SimpleHardware())
    assert c.handle(line) == ["ERR PARSE"]
    assert c.setpoint_kpa == 0.0


def test_set_get_vent_and_limits():
    hw = rigcore.SimpleHardware()
    c = rigcore.Controller(hw)
    assert c.handle("ID") == [f"OK ID {rigcore.NAME} {rigcore.VERSION}"]
    assert c.handle("set 100\r\n") == ["OK SET 100.000 819"]  # case and CR tolerated
    assert hw.frames[-1] == rigcore.mcp4921_frame(819)
    reply = parse_reply(c.handle("GET")[0])
    assert reply is not None and reply.fields[0] == "100.000" and reply.fields[2] == "0"
    assert abs(float(reply.fields[1]) - rigcore.code_to_kpa(819, CFG)) < 0.2
    assert c.handle("SET 300") == ["OK SET 300.000 2458"]  # the limit itself is allowed
    assert c.handle("SET 300.01") == ["ERR LIMIT"]
    assert c.handle("SET -1") == ["ERR LIMIT"]
    assert c.setpoint_kpa == 300.0  # refused setpoints change nothing
    assert c.handle("VENT") == ["OK VENT"]
    assert c.setpoint_kpa == 0.0 and hw.code == 0
    cfg_reply = parse_reply(c.handle("CFG")[0])
    assert cfg_reply is not None and abs(float(cfg_reply.fields[0]) - 500.0 / 4096) < 1e-6


def test_estop_vents_reports_once_and_blocks_set():
    hw = rigcore.SimpleHardware()
    c = rigcore.Controller(hw)
    c.handle("SET 150")
    hw.estop = True
    assert c.poll() == ["EVT ESTOP"]
    assert c.setpoint_kpa == 0.0 and hw.code == 0  # vented by the firmware itself
    assert c.poll() == []  # one event per press
    assert c.handle("SET 50") == ["ERR ESTOP"]
    assert c.handle("GET")[0].endswith(" 1")
    assert c.handle("VENT") == ["OK VENT"]
    hw.estop = False
    assert c.handle("SET 50") == ["OK SET 50.000 410"]
    hw.estop = True
    # a press between commands is reported before the reply
    assert c.handle("GET")[0] == "EVT ESTOP"


def test_watchdog_vents_when_the_host_goes_silent():
    hw = rigcore.SimpleHardware()
    c = rigcore.Controller(hw)
    assert c.poll(idle_ms=10**9) == []  # off by default
    assert c.handle("WDOG 1.5") == ["OK WDOG 1.500"]
    c.handle("SET 80")
    assert c.poll(idle_ms=1500) == []
    assert c.poll(idle_ms=1501) == ["EVT WDOG"]
    assert c.setpoint_kpa == 0.0 and hw.code == 0
    assert c.poll(idle_ms=5000) == []  # already vented: no repeat
    for bad in ("WDOG", "WDOG -1", "WDOG 4000", "WDOG x"):
        assert c.handle(bad) == ["ERR PARSE"]
    assert parse_reply("EVT WDOG").command == "WDOG"


def test_load_cell_tare_scale():
    hw = rigcore.SimpleHardware()
    c = rigcore.Controller(hw)
    hw.load_counts = 5000
    assert c.handle("TARE 4") == ["OK TARE 5000"]
    assert c.handle("LOAD") == ["OK LOAD 0.00000"]
    hw.load_counts = 5000 + 84000
    assert c.handle("LOAD") == ["OK LOAD 2.00000"]  # default 42000 counts/N
    assert c.handle("SCALE 21000") == ["OK SCALE 21000.0000"]
    assert c.handle("LOAD") == ["OK LOAD 4.00000"]
    assert c.handle("LOADRAW") == ["OK LOADRAW 89000"]
    hw.load_counts = None
    assert c.handle("LOAD") == ["ERR HW"]


def test_host_protocol_encode_parse():
    assert encode("SET", 12.5) == b"SET 12.5000\n"
    assert encode("TARE", 3) == b"TARE 3\n"
    assert parse_reply("OK SET 12.500 102").fields == ("12.500", "102")
    assert parse_reply("EVT ESTOP").kind == "EVT"
    for junk in [
        "OK GET 1 2",
        "OK GET 12.0 x7 ??",
        "ERR WHAT",
        b"\xff\xfe",
        "OK",
        "hello world",
        "EVT FIRE",
    ]:
        assert parse_reply(junk) is None


def test_firmware_files_are_micropython_portable():
    """rigcore imports nothing; main.py imports only MicroPython modules and rigcore; both
    compile."""
    core = ast.parse((FIRMWARE_DIR / "rigcore.py").read_text())
    assert not [n for n in ast.walk(core) if isinstance(n, (ast.Import, ast.ImportFrom))]
    assert not [n for n in ast.walk(core) if isinstance(n, ast.JoinedStr)]  # no f-strings
    main = ast.parse((FIRMWARE_DIR / "main.py").read_text())
    imported = {a.name for n in ast.walk(main) if isinstance(n, ast.Import) for a in n.names}
    imported |= {n.module for n in ast.walk(main) if isinstance(n, ast.ImportFrom)}
    assert imported <= {"sys", "time", "machine", "micropython", "select", "rigcore"}
    compile((FIRMWARE_DIR / "main.py").read_text(), "main.py", "exec")
