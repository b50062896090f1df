# ruff: noqa: UP031, RUF046, PLR0124  (MicroPython: %-formatting, explicit int(), NaN test)
"""Pure logic of the Pico firmware: line protocol, DAC and ADC arithmetic, limits, e-stop, load
cell.

This file runs unchanged on the Pico (MicroPython) and on the host (CPython: tests and the
emulator).  It therefore imports nothing, uses no dataclasses and no f-strings, and talks to the
hardware only through a small object passed in (see :class:`Controller`).

Protocol (ASCII, ``\\n``-terminated, 115200 baud); every command gets exactly one reply line:

==================  ==============================================  ==============================
command             reply                                           notes
==================  ==============================================  ==============================
``ID``              ``OK ID <name> <version>``
``SET <kpa>``       ``OK SET <kpa> <dac_code>``                     ``ERR LIMIT`` outside
                                                                    [0, max_kpa], ``ERR ESTOP``
                                                                    while the stop is pressed
``GET``             ``OK GET <setpoint_kpa> <measured_kpa> <0|1>``  measured: regulator monitor
``VENT``            ``OK VENT``                                     setpoint 0 (also under e-stop)
``CFG``             ``OK CFG <kpa_per_code> <max_kpa> <bits>``      added: DAC scaling for hosts
``LOAD``            ``OK LOAD <newtons>``                           added: HX711 load cell
``LOADRAW``         ``OK LOADRAW <counts>``                         added: raw HX711 counts
``TARE [n]``        ``OK TARE <offset_counts>``                     added: zero = mean of n reads
``SCALE [c]``       ``OK SCALE <counts_per_newton>``                added: set (or read) the scale
``WDOG <s>``        ``OK WDOG <s>``                                 added: host watchdog, 0 = off
==================  ==============================================  ==============================

Anything malformed (unknown command, wrong number of arguments, a number that is not finite,
a line longer than :data:`MAX_LINE` or with non-printable characters) gets ``ERR PARSE``; a
load-cell read that times out gets ``ERR HW``.  When the emergency-stop button is pressed the
firmware vents by itself and sends the unsolicited line ``EVT ESTOP`` (once per press).  With
``WDOG <s>`` set, the firmware also vents by itself when no command has arrived for ``s``
seconds while pressure is applied (the host crashed or the cable was pulled) and sends
``EVT WDOG``.

Examples
--------
>>> kpa_to_code(100.0, Config())
819
>>> mcp4921_frame(819).hex()  # 0x3000 (gain 1x, active) | 819
'3333'
>>> c = Controller(SimpleHardware())
>>> c.handle("SET 100")
['OK SET 100.000 819']
>>> c.handle("SET 1000")
['ERR LIMIT']
>>> c.handle("SET abc")
['ERR PARSE']
"""

NAME = "circact-pico"
VERSION = "1.1"
DAC_BITS = 12
DAC_MAX = 4095
MAX_LINE = 64
_NUMBER_CHARS = "0123456789.+-eE"


class Config:
    """Electrical scaling of the rig (defaults: the paper's rig, Section II.C).

    Parameters
    ----------
    full_scale_kpa : float
        Regulator pressure at full-scale command (SMC ITV1031: 0.5 MPa = 500 kPa).
    max_kpa : float
        Highest setpoint the firmware accepts (``ERR LIMIT`` above).  The reservoir gives
        250 +- 35 kPa, so 300 kPa is above anything reachable.
    vref_v : float
        MCP4921 reference voltage (the Pico's 3.3 V rail).
    amp_gain : float
        Gain of the op-amp between the DAC and the regulator's 0-5 V command input.
    reg_input_fs_v : float
        Regulator command voltage for full scale (5 V).
    adc_vref_v : float
        Pico ADC reference (3.3 V).
    monitor_divider : float
        Divider ratio from the regulator's 1-5 V monitor output to the ADC pin (5 V -> 3 V).
    monitor_zero_v, monitor_fs_v : float
        Monitor voltage at 0 kPa and at full scale (1 V and 5 V).
    counts_per_newton : float
        Default HX711 scale (counts per newton) until ``SCALE`` sets it.
    """

    def __init__(self, full_scale_kpa=500.0, max_kpa=300.0, vref_v=3.3, amp_gain=5.0 / 3.3,
                 reg_input_fs_v=5.0, adc_vref_v=3.3, monitor_divider=0.6, monitor_zero_v=1.0,
                 monitor_fs_v=5.0, counts_per_newton=42000.0):
        self.full_scale_kpa = float(full_scale_kpa)
        self.max_kpa = float(max_kpa)
        self.vref_v = float(vref_v)
        self.amp_gain = float(amp_gain)
        self.reg_input_fs_v = float(reg_input_fs_v)
        self.adc_vref_v = float(adc_vref_v)
        self.monitor_divider = float(monitor_divider)
        self.monitor_zero_v = float(monitor_zero_v)
        self.monitor_fs_v = float(monitor_fs_v)
        self.counts_per_newton = float(counts_per_newton)


# ------------------------------------------------------------------------------------------
# arithmetic


def kpa_to_code(kpa: float, cfg: Config) -> int:
    """DAC code (0..4095) whose output commands ``kpa`` from the regulator.

    MCP4921 (gain 1x): ``Vout = vref * code / 4096``; the op-amp multiplies by ``amp_gain``
    and the regulator maps ``0..reg_input_fs_v`` volts to ``0..full_scale_kpa``.  Rounded to the
    nearest code and clipped to the DAC range.
    """
    v_reg = kpa / cfg.full_scale_kpa * cfg.reg_input_fs_v
    code = int(round(v_reg / cfg.amp_gain / cfg.vref_v * 4096.0))
    return min(max(code, 0), DAC_MAX)


def code_to_kpa(code: int, cfg: Config) -> float:
    """Nominal regulator pressure (kPa) commanded by DAC ``code`` (inverse of
    :func:`kpa_to_code`)."""
    v_reg = cfg.vref_v * code / 4096.0 * cfg.amp_gain
    return v_reg / cfg.reg_input_fs_v * cfg.full_scale_kpa


def mcp4921_frame(
    code: int, buffered: bool = False, gain_1x: bool = True, active: bool = True
) -> bytes:
    """The two SPI bytes (MSB first) that set the MCP4921 to ``code``.

    Bit 15 = 0 (write DAC A), bit 14 BUF, bit 13 GA (1 = gain 1x), bit 12 SHDN (1 = output on),
    bits 11..0 the code.
    """
    if code < 0 or code > DAC_MAX:
        raise ValueError("DAC code out of range 0..4095: %d" % code)
    word = (int(buffered) << 14) | (int(gain_1x) << 13) | (int(active) << 12) | code
    return bytes([(word >> 8) & 0xFF, word & 0xFF])


def monitor_kpa(u16: int, cfg: Config) -> float:
    """Pressure (kPa) from the regulator monitor voltage read as ``ADC.read_u16()`` (0..65535)."""
    v_mon = u16 / 65535.0 * cfg.adc_vref_v / cfg.monitor_divider
    return (
        (v_mon - cfg.monitor_zero_v) / (cfg.monitor_fs_v - cfg.monitor_zero_v) * cfg.full_scale_kpa
    )


def kpa_to_monitor_u16(kpa: float, cfg: Config) -> int:
    """``read_u16()`` value the Pico's 12-bit ADC returns for a monitor reading of ``kpa``.

    The RP2040 ADC has 12 bits; MicroPython scales them to 16 as ``(raw << 4) | (raw >> 8)``.
    """
    v_adc = (
        cfg.monitor_zero_v + kpa / cfg.full_scale_kpa * (cfg.monitor_fs_v - cfg.monitor_zero_v)
    ) * cfg.monitor_divider
    raw = int(round(v_adc / cfg.adc_vref_v * 4095.0))
    raw = min(max(raw, 0), 4095)
    return (raw << 4) | (raw >> 8)


def hx711_signed(raw24: int) -> int:
    """Two's-complement value of the 24 bits read from an HX711."""
    raw24 &= 0xFFFFFF
    return raw24 - 0x1000000 if raw24 & 0x800000 else raw24


def counts_to_newtons(counts: float, tare_counts: float, counts_per_newton: float) -> float:
    """Force (N) from load-cell counts after taring."""
    return (counts - tare_counts) / counts_per_newton


# ------------------------------------------------------------------------------------------
# parsing


def parse_number(text: str):
    """A finite float from ``text``, or ``None`` if it is not a plain decimal number."""
    if not text or len(text) > 24:
        return None
    for ch in text:
        if ch not in _NUMBER_CHARS:
            return None
    try:
        value = float(text)
    except ValueError:
        return None
    if value != value or value in (float("inf"), float("-inf")):
        return None
    return value


def parse_line(line):
    """Split a command line into ``(COMMAND, [args])``, or ``None`` when malformed.

    Accepts ``str`` or ``bytes``; trailing ``\\r``/``\\n`` and surrounding spaces are ignored,
    the command word is case-insensitive; the line must be printable ASCII of at most
    :data:`MAX_LINE` characters.
    """
    if isinstance(line, (bytes, bytearray)):
        try:
            line = bytes(line).decode("ascii")
        except (UnicodeError, ValueError):
            return None
    line = line.strip()
    if not line or len(line) > MAX_LINE:
        return None
    for ch in line:
        o = ord(ch)
        if o < 32 or o > 126:
            return None
    words = line.split()
    return words[0].upper(), words[1:]


# ------------------------------------------------------------------------------------------
# the controller


class SimpleHardware:
    """Hardware stand-in with no physics: a DAC that records, a monitor that echoes the setpoint.

    Used by doctests and unit tests of the protocol; the emulator supplies a real plant model.
    """

    def __init__(self, cfg=None):
        self.cfg = cfg or Config()
        self.frames = []
        self.code = 0
        self.estop = False
        self.load_counts = 0

    def write_dac(self, frame: bytes) -> None:
        self.frames.append(frame)
        self.code = ((frame[0] << 8) | frame[1]) & 0x0FFF

    def read_monitor_u16(self) -> int:
        return kpa_to_monitor_u16(code_to_kpa(self.code, self.cfg), self.cfg)

    def estop_pressed(self) -> bool:
        return self.estop

    def read_load_counts(self):
        return self.load_counts


class Controller:
    """The firmware's state machine, independent of the hardware.

    Parameters
    ----------
    hw : object
        Provides ``write_dac(frame: bytes)``, ``read_monitor_u16() -> int``,
        ``estop_pressed() -> bool`` and ``read_load_counts() -> int or None`` (``None``: the
        HX711 did not answer).
    cfg : Config, optional
        Electrical scaling and limits.
    """

    def __init__(self, hw, cfg=None):
        self.hw = hw
        self.cfg = cfg or Config()
        self.setpoint_kpa = 0.0
        self.code = 0
        self.estop = False
        self.tare_counts = 0.0
        self.counts_per_newton = self.cfg.counts_per_newton
        self.watchdog_ms = 0
        self._apply(0.0)

    def _apply(self, kpa: float) -> int:
        code = kpa_to_code(kpa, self.cfg)
        self.hw.write_dac(mcp4921_frame(code))
        self.setpoint_kpa = kpa
        self.code = code
        return code

    def vent(self) -> None:
        """Set the regulator to 0 kPa."""
        self._apply(0.0)

    def poll(self, idle_ms: int = 0) -> list:
        """Check the stop button and the host watchdog.

        Parameters
        ----------
        idle_ms : int
            Milliseconds since the last command line arrived (the caller keeps the clock).

        Returns
        -------
        list of str
            ``['EVT ESTOP']`` on a new press, ``['EVT WDOG']`` when the watchdog (``WDOG``) ran
            out with pressure applied; both vent.
        """
        pressed = bool(self.hw.estop_pressed())
        if pressed and not self.estop:
            self.estop = True
            self.vent()
            return ["EVT ESTOP"]
        if not pressed:
            self.estop = False
        if self.watchdog_ms > 0 and idle_ms > self.watchdog_ms and self.code != 0:
            self.vent()
            return ["EVT WDOG"]
        return []

    def measured_kpa(self) -> float:
        """Regulator output pressure (kPa) from its monitor voltage."""
        return monitor_kpa(self.hw.read_monitor_u16(), self.cfg)

    def handle(self, line) -> list:
        """Reply lines for one command line (any pending ``EVT ESTOP`` first)."""
        out = self.poll()
        out.append(self._reply(line))
        return out

    def _reply(self, line) -> str:
        parsed = parse_line(line)
        if parsed is None:
            return "ERR PARSE"
        cmd, args = parsed
        n = len(args)
        if cmd == "ID" and n == 0:
            return "OK ID %s %s" % (NAME, VERSION)
        if cmd == "SET" and n == 1:
            kpa = parse_number(args[0])
            if kpa is None:
                return "ERR PARSE"
            if self.estop:
                return "ERR ESTOP"
            if kpa < 0.0 or kpa > self.cfg.max_kpa:
                return "ERR LIMIT"
            code = self._apply(kpa)
            return "OK SET %.3f %d" % (kpa, code)
        if cmd == "GET" and n == 0:
            return "OK GET %.3f %.3f %d" % (
                self.setpoint_kpa,
                self.measured_kpa(),
                1 if self.estop else 0,
            )
        if cmd == "VENT" and n == 0:
            self.vent()
            return "OK VENT"
        if cmd == "CFG" and n == 0:
            return "OK CFG %.7f %.3f %d" % (code_to_kpa(1, self.cfg), self.cfg.max_kpa, DAC_BITS)
        if cmd == "LOAD" and n == 0:
            counts = self.hw.read_load_counts()
            if counts is None:
                return "ERR HW"
            return "OK LOAD %.5f" % counts_to_newtons(
                counts, self.tare_counts, self.counts_per_newton
            )
        if cmd == "LOADRAW" and n == 0:
            counts = self.hw.read_load_counts()
            return "ERR HW" if counts is None else "OK LOADRAW %d" % counts
        if cmd == "TARE" and n <= 1:
            reads = 10
            if n == 1:
                value = parse_number(args[0])
                if value is None or value != int(value) or not 1 <= value <= 255:
                    return "ERR PARSE"
                reads = int(value)
            total = 0
            for _ in range(reads):
                counts = self.hw.read_load_counts()
                if counts is None:
                    return "ERR HW"
                total += counts
            self.tare_counts = total / reads
            return "OK TARE %d" % int(round(self.tare_counts))
        if cmd == "WDOG" and n == 1:
            value = parse_number(args[0])
            if value is None or not 0.0 <= value <= 3600.0:
                return "ERR PARSE"
            self.watchdog_ms = int(value * 1000)
            return "OK WDOG %.3f" % value
        if cmd == "SCALE" and n <= 1:
            if n == 1:
                value = parse_number(args[0])
                if value is None or value == 0.0:
                    return "ERR PARSE"
                self.counts_per_newton = value
            return "OK SCALE %.4f" % self.counts_per_newton
        return "ERR PARSE"
