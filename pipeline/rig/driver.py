"""pyserial driver for the Pico pressure controller (protocol in
:mod:`pipeline.rig.firmware.rigcore`).

The driver refuses a setpoint above its ``max_kpa`` *before* sending anything, converts
pressures through a :class:`~pipeline.rig.calibration.Calibration` when one is given, skips
garbage lines, notices ``EVT ESTOP`` at any time, and turns a vanished or silent port into
:class:`PortLostError`.

It needs only the base protocol (``ID``, ``SET``, ``GET``, ``VENT``, ``EVT ESTOP``).  The
extensions (:data:`~pipeline.rig.protocol.EXTENSIONS`: ``CFG``, ``WDOG``, the load cell) are
probed at connect and recorded in :attr:`DeviceInfo.extensions`; a command of a missing extension
raises :class:`UnsupportedError` without being sent.

Examples
--------
Against the emulator (a real pseudo-terminal)::

    from pipeline.rig.emulator import Emulator
    with Emulator() as emu, PicoDriver.open(emu.port, max_kpa=260) as rig:
        rig.set_kpa(40.0)
        print(rig.get().measured_kpa)
"""

from __future__ import annotations

import contextlib
import logging
import math
import sys
import time
from dataclasses import dataclass
from types import TracebackType
from typing import TYPE_CHECKING

import numpy as np
import serial

from pipeline.errors import UserInputError
from pipeline.rig.calibration import Calibration
from pipeline.rig.protocol import BAUDRATE, EXTENSIONS, Reply, encode, parse_reply

if TYPE_CHECKING:
    from typing_extensions import Self

log = logging.getLogger(__name__)

_PORT_ERRORS: tuple[type[BaseException], ...] = (serial.SerialException, OSError)
# POSIX: a hung-up tty raises termios.error (not an OSError) from tcdrain/tcsetattr
if sys.platform != "win32":
    import termios

    _PORT_ERRORS = (*_PORT_ERRORS, termios.error)
#: opening a port: the port errors, and pyserial's ValueError for a malformed port or URL
_OPEN_ERRORS: tuple[type[BaseException], ...] = (*_PORT_ERRORS, ValueError)

#: garbage lines tolerated while waiting for one reply
MAX_GARBAGE_PER_REPLY = 20


class RigError(Exception):
    """Base class of every rig failure; the message says what happened and what to do."""


class PortLostError(RigError):
    """The serial port vanished, failed, or the device stopped answering."""


class EStopError(RigError):
    """The emergency stop is (or was) pressed; the device has vented."""


class LimitError(RigError):
    """A setpoint outside the limits.  ``sent`` tells whether the device refused it (``ERR LIMIT``)
    or the host refused it before sending (``sent=False``)."""

    def __init__(self, message: str, *, sent: bool) -> None:
        super().__init__(message)
        self.sent = sent


class DeviceError(RigError):
    """The device answered ``ERR PARSE`` / ``ERR HW`` or something inconsistent."""


class ParseError(DeviceError):
    """The device answered ``ERR PARSE``: it did not understand the command."""


class WatchdogError(RigError):
    """The device vented by itself because the host sent nothing for longer than its watchdog."""


class UnsupportedError(RigError, UserInputError):
    """The firmware does not speak the protocol extension a command or an option needs."""


@dataclass(frozen=True)
class DeviceInfo:
    """What the device says about itself (``ID``, and ``CFG`` when it has that extension).

    Attributes
    ----------
    name, version : str
        From ``ID``.
    extensions : frozenset of str
        Names of the :data:`~pipeline.rig.protocol.EXTENSIONS` the firmware answered at connect.
    kpa_per_code, max_kpa : float or None
        Nominal kPa per DAC code and the firmware's own limit (kPa), from ``CFG``; ``None``
        without it.
    dac_bits : int or None
        DAC resolution, from ``CFG``.
    """

    name: str
    version: str
    extensions: frozenset[str] = frozenset(EXTENSIONS)
    kpa_per_code: float | None = None
    max_kpa: float | None = None
    dac_bits: int | None = None

    @property
    def missing(self) -> tuple[str, ...]:
        """Extensions the firmware does not have, in :data:`~pipeline.rig.protocol.EXTENSIONS`
        order."""
        return tuple(name for name in EXTENSIONS if name not in self.extensions)


@dataclass(frozen=True)
class PressureReading:
    """One ``GET``: setpoint and monitor reading (kPa), and the stop button state."""

    setpoint_kpa: float
    measured_kpa: float
    estop: bool


@dataclass(frozen=True)
class SetResult:
    """One ``SET``: the pressure asked for (kPa), the nominal value sent and the DAC code
    applied."""

    pressure_kpa: float
    sent_kpa: float
    dac_code: int


class PicoDriver:
    """Talk to the rig over a serial port.

    Parameters
    ----------
    link : serial.Serial
        An open port (see :meth:`open`).
    max_kpa : float
        Host-side limit (kPa): a higher setpoint raises :class:`LimitError` and is never sent.
        A calibration's own ``max_kpa``, when lower, applies instead.
    calibration : Calibration, optional
        Maps the pressure wanted to the DAC code; without it the firmware's nominal scaling is used.
    timeout_s : float
        Longest wait for one reply before the port counts as lost (s).
    """

    def __init__(
        self,
        link: serial.Serial,
        *,
        max_kpa: float,
        calibration: Calibration | None = None,
        timeout_s: float = 2.0,
    ) -> None:
        self.link = link
        self.calibration = calibration
        limits = [max_kpa] + ([calibration.max_kpa] if calibration and calibration.max_kpa else [])
        self.max_kpa = float(min(limits))
        self.timeout_s = timeout_s
        self.info: DeviceInfo | None = None
        self.garbage_lines = 0
        self._estop_seen = False
        self._watchdog_seen = False
        self._buf = b""

    # -- opening / closing ------------------------------------------------------------------

    @classmethod
    def open(cls, port: str, *, max_kpa: float, calibration: Calibration | None = None,
             timeout_s: float = 2.0) -> PicoDriver:
        """Open ``port`` (a device path such as ``/dev/ttyACM0`` or a pyserial URL), identify the
        device.

        Raises
        ------
        PortLostError
            If the port cannot be opened or the device does not answer ``ID``.
        """
        try:
            link = serial.serial_for_url(
                port, baudrate=BAUDRATE, timeout=0.05, write_timeout=timeout_s
            )
        except _OPEN_ERRORS as exc:
            raise PortLostError(
                f"cannot open serial port {port!r}: {exc}; check the cable and the --port name"
            ) from exc
        driver = cls(link, max_kpa=max_kpa, calibration=calibration, timeout_s=timeout_s)
        try:
            driver.connect()
        except BaseException:
            driver.close()
            raise
        return driver

    def connect(self) -> DeviceInfo:
        """Discard stale input, read ``ID``, probe the extensions, send the calibration's load-cell
        scale.

        Raises
        ------
        UnsupportedError
            A calibration is given but the firmware does not report its DAC scaling (no ``CFG``).
        """
        self._drain()
        name, version = self._command("ID").fields
        cfg = self._probe("CFG")
        found = {"CFG"} if cfg else set()
        if self._probe("WDOG", 0.0):  # 0 = off: changes nothing the host relies on
            found.add("WDOG")
        if self._probe("SCALE"):  # reads the scale
            found.add("LOAD")
        self.info = DeviceInfo(
            name, version, frozenset(found),
            kpa_per_code=float(cfg.fields[0]) if cfg else None,
            max_kpa=float(cfg.fields[1]) if cfg else None,
            dac_bits=int(cfg.fields[2]) if cfg else None,
        )
        if self.calibration is not None and cfg is None:
            raise UnsupportedError(
                f"firmware {name} {version} does not report its DAC scaling (no CFG command), so "
                "the "
                "calibration (kPa <-> DAC code) cannot be applied; run without --calibration (the "
                "firmware's "
                "own scaling; measured_pressure_kpa still records the regulator's monitor) or "
                "flash the "
                "firmware of pipeline/rig/firmware"
            )
        if self.calibration and self.calibration.load_counts_per_newton and "LOAD" in found:
            self.set_scale(self.calibration.load_counts_per_newton)
        return self.info

    def supports(self, extension: str) -> bool:
        """Whether the firmware answered the probe of ``extension`` (a key of ``EXTENSIONS``) at
        connect."""
        return self.info is not None and extension in self.info.extensions

    def _require(self, extension: str, what: str) -> None:
        if self.info is not None and extension not in self.info.extensions:
            commands = "/".join(EXTENSIONS[extension])
            raise UnsupportedError(
                f"firmware {self.info.name} {self.info.version} does not speak {commands} (an "
                "extension of the "
                f"protocol), which {what} needs; flash the firmware of pipeline/rig/firmware to "
                "use it"
            )

    def _probe(self, command: str, *args: float) -> Reply | None:
        """Send an extension command once; ``None`` when the firmware answers ``ERR PARSE``."""
        try:
            return self._command(command, *args, retries=0)
        except ParseError:
            log.info("firmware does not speak %s (ERR PARSE): extension not used", command)
            return None

    def close(self) -> None:
        """Close the port (never raises)."""
        with contextlib.suppress(Exception):  # closing a dead port must not mask the real error
            self.link.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.safe_vent()
        self.close()

    # -- pressure -----------------------------------------------------------------------------

    def set_kpa(self, pressure_kpa: float) -> SetResult:
        """Set the regulator to ``pressure_kpa``.

        Raises
        ------
        LimitError
            Above ``max_kpa`` or negative (not sent), or refused by the device (``ERR LIMIT``).
        EStopError
            The stop is pressed.
        """
        p = float(pressure_kpa)
        if not math.isfinite(p) or p < 0:
            raise LimitError(
                f"refused setpoint {pressure_kpa!r} kPa: must be a number >= 0 (nothing sent)",
                sent=False,
            )
        if p > self.max_kpa + 1e-9:
            raise LimitError(
                f"refused setpoint {p:g} kPa: above the host limit max_kpa = {self.max_kpa:g} kPa "
                "(nothing sent)",
                sent=False,
            )
        want_code = None
        sent = p
        if (
            self.calibration is not None
            and self.info is not None
            and self.info.kpa_per_code is not None
        ):
            want_code = self.calibration.kpa_to_code(p)
            sent = want_code * self.info.kpa_per_code
        r = self._command("SET", sent)
        code = int(r.fields[1])
        if want_code is not None and code != want_code:
            log.warning("device applied DAC code %d, calibration asked for %d", code, want_code)
        return SetResult(p, sent, code)

    def get(self) -> PressureReading:
        """Setpoint, monitor reading (kPa) and stop state; raises :class:`EStopError` if pressed."""
        r = self._command("GET")
        reading = PressureReading(float(r.fields[0]), float(r.fields[1]), r.fields[2] == "1")
        if reading.estop:
            self._estop_seen = True
            self._raise_estop()
        return reading

    def vent(self) -> None:
        """Set 0 kPa (allowed while the stop is pressed)."""
        self._command("VENT", raise_estop=False)

    def safe_vent(self, timeout_s: float = 1.0) -> bool:
        """Try to vent; ``True`` if the device acknowledged.  Never raises (used on the way out)."""
        saved = self.timeout_s
        self.timeout_s = timeout_s
        try:
            self.vent()
            return True
        except Exception:  # noqa: BLE001 - best effort on a port that may be gone
            return False
        finally:
            self.timeout_s = saved

    def sleep(self, seconds: float) -> None:
        """Wait ``seconds`` while watching the port for ``EVT ESTOP`` (raised at once)."""
        deadline = time.monotonic() + seconds
        while True:
            self._raise_estop()
            left = deadline - time.monotonic()
            if left <= 0:
                return
            line = self._read_line(time.monotonic() + min(left, 0.05))
            if line is not None:
                self._dispatch_unsolicited(line)

    def check_events(self) -> None:
        """Read whatever is waiting without blocking; raise :class:`EStopError` on ``EVT ESTOP``."""
        while True:
            line = self._read_line(time.monotonic())
            if line is None:
                break
            self._dispatch_unsolicited(line)
        self._raise_estop()

    # -- load cell ------------------------------------------------------------------------------

    def load_n(self) -> float:
        """One load-cell reading (N, after tare and scale)."""
        self._require("LOAD", "reading the load cell")
        return float(self._command("LOAD").fields[0])

    def load_samples(self, count: int, interval_s: float = 0.0) -> np.ndarray:
        """``count`` load-cell readings (N), ``interval_s`` apart, watching for the stop."""
        out = np.empty(count)
        for i in range(count):
            if i and interval_s > 0:
                self.sleep(interval_s)
            out[i] = self.load_n()
        return out

    def load_raw(self) -> int:
        """One raw HX711 reading (counts)."""
        self._require("LOAD", "reading the load cell")
        return int(self._command("LOADRAW").fields[0])

    def tare(self, reads: int = 10) -> int:
        """Zero the load cell on the mean of ``reads`` readings; returns the offset (counts)."""
        self._require("LOAD", "taring the load cell")
        return int(self._command("TARE", int(reads)).fields[0])

    def set_scale(self, counts_per_newton: float) -> float:
        """Set the load-cell scale (counts per newton)."""
        self._require("LOAD", "setting the load-cell scale")
        return float(self._command("SCALE", float(counts_per_newton)).fields[0])

    def set_watchdog(self, seconds: float) -> float:
        """Make the device vent by itself after ``seconds`` without a command (0 turns it off)."""
        self._require("WDOG", "the device watchdog (--watchdog-s)")
        return float(self._command("WDOG", float(seconds)).fields[0])

    def get_scale(self) -> float:
        """Current load-cell scale (counts per newton)."""
        self._require("LOAD", "reading the load-cell scale")
        return float(self._command("SCALE").fields[0])

    # -- line handling ----------------------------------------------------------------------------

    def _note_event(self, reply: Reply) -> None:
        if reply.command == "WDOG":
            self._watchdog_seen = True
        else:
            self._estop_seen = True

    def _raise_estop(self) -> None:
        if self._watchdog_seen:
            self._watchdog_seen = False
            raise WatchdogError(
                "the device vented by itself: no command reached it within its watchdog time "
                "(host too slow, e.g. a camera longer than --watchdog-s); re-run to resume"
            )
        if self._estop_seen:
            self._estop_seen = False
            raise EStopError(
                "emergency stop pressed: the device vented; release the button and re-run to resume"
            )

    def _drain(self) -> None:
        try:
            self.link.reset_input_buffer()
        except _PORT_ERRORS as exc:
            raise PortLostError(f"serial port {self.link.port!r} failed: {exc}") from exc
        self._buf = b""

    def _read_line(self, deadline: float) -> bytes | None:
        """One line (without ``\\n``) or ``None`` at the deadline."""
        while b"\n" not in self._buf:
            try:
                waiting = self.link.in_waiting
                chunk = (
                    self.link.read(max(1, waiting))
                    if waiting or time.monotonic() < deadline
                    else b""
                )
            except _PORT_ERRORS as exc:
                raise PortLostError(
                    f"serial port {self.link.port!r} lost ({exc}); reconnect the rig and re-run "
                    "the same command to resume"
                ) from exc
            if chunk:
                self._buf += chunk
            elif time.monotonic() >= deadline:
                return None
        line, self._buf = self._buf.split(b"\n", 1)
        return line

    def _dispatch_unsolicited(self, line: bytes) -> None:
        reply = parse_reply(line)
        if reply is not None and reply.kind == "EVT":
            self._note_event(reply)
        elif line.strip():
            self.garbage_lines += 1
            log.debug("ignored line from device: %r", line[:80])

    def _command(
        self, command: str, *args: float, raise_estop: bool = True, retries: int = 1
    ) -> Reply:
        for attempt in range(retries + 1):
            try:
                self.link.write(encode(command, *args))
                self.link.flush()
            except _PORT_ERRORS as exc:
                raise PortLostError(
                    f"serial port {self.link.port!r} lost while sending {command} ({exc}); "
                    "reconnect the rig and re-run the same command to resume"
                ) from exc
            reply = self._await_reply(command)
            if reply.kind == "ERR" and reply.command == "PARSE" and attempt < retries:
                log.warning("device answered ERR PARSE to %s; sending it again", command)
                continue
            break
        if reply.kind == "ERR":
            if reply.command == "ESTOP":
                self._estop_seen = False
                raise EStopError(
                    "emergency stop pressed: the device refused the setpoint and vented; "
                    "release the button and re-run to resume"
                )
            if reply.command == "LIMIT":
                limit = (
                    f" ({self.info.max_kpa:g} kPa)"
                    if self.info and self.info.max_kpa is not None
                    else ""
                )
                raise LimitError(
                    f"device refused {command} {args[0] if args else ''}: above its limit{limit}",
                    sent=True,
                )
            kind = ParseError if reply.command == "PARSE" else DeviceError
            raise kind(f"device answered {reply.line!r} to {command}")
        if raise_estop:
            self._raise_estop()
        return reply

    def _await_reply(self, command: str) -> Reply:
        deadline = time.monotonic() + self.timeout_s
        garbage = 0
        while True:
            line = self._read_line(deadline)
            if line is None:
                raise PortLostError(
                    f"no reply to {command} within {self.timeout_s:g} s from {self.link.port!r}: "
                    "the device is not "
                    "answering; check power and cable, then re-run the same command to resume"
                )
            reply = parse_reply(line)
            if reply is None:
                if line.strip():
                    garbage += 1
                    self.garbage_lines += 1
                    log.debug("ignored garbage line from device: %r", line[:80])
                    if garbage > MAX_GARBAGE_PER_REPLY:
                        raise DeviceError(
                            f"more than {MAX_GARBAGE_PER_REPLY} garbage lines while waiting for "
                            f"{command}; check the baud rate ({BAUDRATE}) and the port"
                        )
                continue
            if reply.kind == "EVT":
                self._note_event(reply)
                continue
            if reply.kind == "OK" and reply.command != command:
                log.warning("ignored stale reply %r while waiting for %s", reply.line, command)
                continue
            return reply
