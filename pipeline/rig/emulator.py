"""The Pico over a pseudo-terminal: the real firmware logic on a simulated rig, with fault
injection.

The emulator runs :class:`pipeline.rig.firmware.rigcore.Controller` (the code the Pico runs)
against a plant model of the regulator (gain, offset, supply limit, first-order lag, monitor
noise, 12-bit ADC) and of the HX711 load cell (force rising non-linearly with pressure, seeded
noise, an offset to tare).  It serves a pty, so the real driver and ``acquire`` open it like a
USB serial port.

Faults (``--fault`` in ``python -m pipeline rig emulate``):

``drop-after=N``
    answer N commands, then close the connection (the port vanishes like an unplugged cable).
    With ``link`` the emulator then opens a fresh pty behind the same link path and keeps its
    state, as a re-plugged Pico would.
``estop-at-set=K``
    press the emergency stop right after answering the K-th ``SET``.
``slow=S``
    wait S seconds before every reply.
``garbage-every=N``
    send a garbage line (random bytes, some not ASCII) before every N-th reply.

``protocol="base"`` (``--protocol base``) emulates firmware that speaks only the documented base
protocol (``ID``, ``SET``, ``GET``, ``VENT``, ``EVT ESTOP``): every extension command
(:data:`pipeline.rig.protocol.EXTENSIONS`) gets ``ERR PARSE``.

Examples
--------
>>> from pipeline.rig.driver import PicoDriver
>>> with Emulator(seed=1) as emu:
...     with PicoDriver.open(emu.port, max_kpa=260) as rig:
...         _ = rig.set_kpa(50.0)
...         round(rig.get().measured_kpa) in range(45, 52)
True
"""

from __future__ import annotations

import math
import os
import select
import threading
import time
import tty
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING

import numpy as np

from pipeline.errors import UserInputError
from pipeline.rig.firmware import rigcore
from pipeline.rig.protocol import BASE_COMMANDS

if TYPE_CHECKING:
    from typing_extensions import Self

#: what the emulated firmware speaks: everything ``rigcore`` does, or the base protocol only
PROTOCOLS = ("full", "base")


@dataclass(frozen=True)
class PlantParams:
    """Simulated regulator and load cell.

    Attributes
    ----------
    gain, offset_kpa : float
        Achieved pressure = gain * nominal + offset (kPa) for a non-zero command: a calibration
        (``rig calibrate``) recovers them.
    supply_kpa : float
        Reservoir pressure (250 + 35 kPa): the regulator cannot exceed it.
    lag_s : float
        First-order time constant of the pressure (s); 0 = instantaneous.
    monitor_noise_kpa : float
        Standard deviation of the monitor reading (kPa).
    force_n_per_kpa, force_n_per_kpa2 : float
        Blocked force F = a P + b P^2 (N, P in kPa): about 2.7 N at 105 kPa as DS20 in Fig. 7A.
    force_noise_n : float
        Standard deviation of one load-cell reading (N).
    load_counts_per_newton, load_offset_counts : float
        True HX711 scale and zero offset (counts).
    """

    gain: float = 0.97
    offset_kpa: float = -1.5
    supply_kpa: float = 285.0
    lag_s: float = 0.0
    monitor_noise_kpa: float = 0.2
    force_n_per_kpa: float = 0.015
    force_n_per_kpa2: float = 1.0e-4
    force_noise_n: float = 0.02
    load_counts_per_newton: float = 42000.0
    load_offset_counts: float = 8123.0

    def force_n(self, pressure_kpa: float) -> float:
        """Noise-free blocked force (N) at ``pressure_kpa``."""
        p = max(pressure_kpa, 0.0)
        return self.force_n_per_kpa * p + self.force_n_per_kpa2 * p * p


@dataclass(frozen=True)
class Faults:
    """Fault injection (see module docstring); ``None``/0 disables each."""

    drop_after: int | None = None
    estop_at_set: int | None = None
    slow_s: float = 0.0
    garbage_every: int | None = None


def parse_faults(specs: list[str] | None) -> Faults:
    """Parse ``["drop-after=5", "slow=0.1", ...]`` into :class:`Faults`.

    Raises
    ------
    UserInputError
        On an unknown fault or a bad value.
    """
    keys = {"drop-after": ("drop_after", int), "estop-at-set": ("estop_at_set", int),
            "slow": ("slow_s", float), "garbage-every": ("garbage_every", int)}
    values: dict[str, float | int] = {}
    for spec in specs or []:
        name, _, value = spec.partition("=")
        if name not in keys:
            raise UserInputError(
                f"--fault {spec!r}: unknown fault; use one of {', '.join(k + '=N' for k in keys)}"
            )
        attr, kind = keys[name]
        try:
            v = kind(value)
        except ValueError as exc:
            raise UserInputError(
                f"--fault {spec!r}: {value!r} is not a valid {kind.__name__}"
            ) from exc
        if v < 0 or (kind is int and v == 0 and name != "drop-after"):
            raise UserInputError(f"--fault {spec!r}: the value must be positive")
        values[attr] = v
    return Faults(**values)  # type: ignore[arg-type]


class EmulatedHardware:
    """The plant behind the firmware logic (implements the hardware interface of ``Controller``)."""

    def __init__(self, plant: PlantParams, cfg: rigcore.Config, rng: np.random.Generator) -> None:
        self.plant, self.cfg, self.rng = plant, cfg, rng
        self.code = 0
        self.estop = False
        self._p_start = 0.0
        self._t_change = time.monotonic()
        self._target = 0.0

    def _target_for(self, code: int) -> float:
        if code == 0:
            return 0.0
        nominal = rigcore.code_to_kpa(code, self.cfg)
        return float(
            min(max(self.plant.gain * nominal + self.plant.offset_kpa, 0.0), self.plant.supply_kpa)
        )

    def pressure_kpa(self) -> float:
        """True pressure in the actuator now (kPa)."""
        if self.plant.lag_s <= 0:
            return self._target
        dt = time.monotonic() - self._t_change
        return self._target + (self._p_start - self._target) * math.exp(-dt / self.plant.lag_s)

    def write_dac(self, frame: bytes) -> None:
        word = (frame[0] << 8) | frame[1]
        if not word & 0x1000:  # SHDN low: output off
            word &= 0xF000
        self._p_start = self.pressure_kpa()
        self._t_change = time.monotonic()
        self.code = word & 0x0FFF
        self._target = self._target_for(self.code)

    def read_monitor_u16(self) -> int:
        noisy = self.pressure_kpa() + self.rng.normal(0.0, self.plant.monitor_noise_kpa)
        return rigcore.kpa_to_monitor_u16(noisy, self.cfg)

    def estop_pressed(self) -> bool:
        return self.estop

    def read_load_counts(self) -> int:
        force = self.plant.force_n(self.pressure_kpa()) + self.rng.normal(
            0.0, self.plant.force_noise_n
        )
        return int(round(self.plant.load_offset_counts + force * self.plant.load_counts_per_newton))  # noqa: RUF046 (numpy scalar)


@dataclass
class EmulatorStats:
    """What the emulator saw (for tests): every command line received, drops, SET count."""

    received: list[str] = field(default_factory=list)
    drops: int = 0
    sets: int = 0


class Emulator:
    """Serve the Pico protocol on a pseudo-terminal from a background thread.

    Parameters
    ----------
    plant : PlantParams, optional
        Simulated rig.
    faults : Faults, optional
        Fault injection.
    seed : int
        Seed of the noise generator.
    cfg : rigcore.Config, optional
        Firmware configuration (limits, scaling).
    link : path, optional
        Also expose the port as this symbolic link (kept across dropped connections).
    protocol : {"full", "base"}
        ``"base"``: answer ``ERR PARSE`` to every extension command (firmware that speaks only
        ``ID``, ``SET``, ``GET``, ``VENT`` and ``EVT ESTOP``).
    """

    def __init__(
        self,
        *,
        plant: PlantParams | None = None,
        faults: Faults | None = None,
        seed: int = 0,
        cfg: rigcore.Config | None = None,
        link: str | os.PathLike[str] | None = None,
        protocol: str = "full",
    ) -> None:
        if protocol not in PROTOCOLS:
            raise UserInputError(
                f"emulator protocol {protocol!r}: use one of {', '.join(PROTOCOLS)}"
            )
        self.protocol = protocol
        self.plant = plant or PlantParams()
        self.faults = faults or Faults()
        self.cfg = cfg or rigcore.Config()
        self.hw = EmulatedHardware(self.plant, self.cfg, np.random.default_rng(seed))
        self.controller = rigcore.Controller(self.hw, self.cfg)
        self.link = Path(link) if link else None
        self.stats = EmulatorStats()
        self._garbage_rng = np.random.default_rng(seed + 1)
        self._replies = 0
        self._last_command = time.monotonic()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._master = self._slave = -1
        self.slave_name = ""
        self._open_pty()

    # -- public ---------------------------------------------------------------------------------

    @property
    def port(self) -> str:
        """The port to open: the link path if any, else the pty slave device."""
        return str(self.link) if self.link else self.slave_name

    @property
    def pressure_kpa(self) -> float:
        """True simulated pressure (kPa)."""
        return self.hw.pressure_kpa()

    @property
    def setpoint_kpa(self) -> float:
        """The firmware's current setpoint (kPa)."""
        return self.controller.setpoint_kpa

    def press_estop(self) -> None:
        """Press the emergency-stop button (the firmware vents and sends ``EVT ESTOP``)."""
        self.hw.estop = True

    def release_estop(self) -> None:
        """Release the emergency-stop button."""
        self.hw.estop = False

    def start(self) -> Emulator:
        """Start serving in a daemon thread."""
        self._thread = threading.Thread(
            target=self.serve_forever, name="pico-emulator", daemon=True
        )
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stop serving and close the pty."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2)
        self._close_pty()
        if self.link is not None:
            self.link.unlink(missing_ok=True)

    def __enter__(self) -> Self:
        self.start()
        return self

    def __exit__(
        self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.stop()

    def serve_forever(self) -> None:
        """Answer commands until :meth:`stop` (runs in the caller's thread)."""
        buf = b""
        while not self._stop.is_set():
            for event in self.controller.poll(int((time.monotonic() - self._last_command) * 1000)):
                self._write(event)
            try:
                ready, _, _ = select.select([self._master], [], [], 0.01)
                data = os.read(self._master, 4096) if ready else b""
            except OSError:  # no reader on the other side right now
                data = b""
                time.sleep(0.01)
            buf += data
            while b"\n" in buf and not self._stop.is_set():
                line, buf = buf.split(b"\n", 1)
                if not self._serve_line(line):
                    buf = b""
                    break

    # -- internals ------------------------------------------------------------------------------

    def _serve_line(self, line: bytes) -> bool:
        """Answer one line; ``False`` when the connection was dropped instead."""
        text = line.decode("ascii", "replace").strip()
        if (
            self.faults.drop_after is not None
            and self.stats.drops == 0
            and len(self.stats.received) >= self.faults.drop_after
        ):
            self.stats.drops += 1
            self._drop()
            return False
        self.stats.received.append(text)
        self._last_command = time.monotonic()
        replies = self._answer(line)
        if self.faults.slow_s > 0:
            time.sleep(self.faults.slow_s)
        for reply in replies:
            self._replies += 1
            if self.faults.garbage_every and self._replies % self.faults.garbage_every == 0:
                self._write_raw(self._garbage())
            self._write(reply)
        if replies[-1].startswith("OK SET"):
            self.stats.sets += 1
            if self.faults.estop_at_set is not None and self.stats.sets == self.faults.estop_at_set:
                self.press_estop()
        return True

    def _answer(self, line: bytes) -> list[str]:
        """The firmware's reply lines; base-protocol firmware does not know the extensions."""
        if self.protocol == "base":
            parsed = rigcore.parse_line(line)
            if parsed is not None and parsed[0] not in BASE_COMMANDS:
                return [*self.controller.poll(), "ERR PARSE"]
        return self.controller.handle(line)

    def _garbage(self) -> bytes:
        kind = int(self._garbage_rng.integers(3))
        if kind == 0:
            return bytes(self._garbage_rng.integers(128, 256, size=12).astype(np.uint8)) + b"\n"
        if kind == 1:
            return b"OK GET 12.0 x7 ??\n"  # looks like a reply but is corrupt
        return b"#boot noise %d\r\n" % int(self._garbage_rng.integers(1000))

    def _write(self, line: str) -> None:
        self._write_raw(line.encode("ascii") + b"\n")

    def _write_raw(self, data: bytes) -> None:
        try:
            os.write(self._master, data)
        except (BlockingIOError, OSError):
            pass  # nobody reading / buffer full: the bytes are lost, as on a real wire

    def _open_pty(self) -> None:
        master, slave = os.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        self._master, self._slave = master, slave
        self.slave_name = os.ttyname(slave)
        if self.link is not None:
            tmp = self.link.with_name(self.link.name + ".tmp")
            tmp.unlink(missing_ok=True)
            os.symlink(self.slave_name, tmp)
            os.replace(tmp, self.link)

    def _close_pty(self) -> None:
        for fd in (self._master, self._slave):
            if fd >= 0:
                try:
                    os.close(fd)
                except OSError:
                    pass
        self._master = self._slave = -1

    def _drop(self) -> None:
        old = (self._master, self._slave)
        if self.link is not None:
            self._open_pty()  # the link points at the new pty before the old one vanishes
        else:
            self._stop.set()
        for fd in old:
            try:
                os.close(fd)
            except OSError:
                pass
        if self.link is None:
            self._master = self._slave = -1
