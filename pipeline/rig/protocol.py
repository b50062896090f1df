"""Host side of the Pico line protocol: encode commands, parse reply lines.

The device side (and the table of commands) is :mod:`pipeline.rig.firmware.rigcore`.

Examples
--------
>>> encode("SET", 40.0)
b'SET 40.0000\\n'
>>> parse_reply("OK GET 40.000 39.812 0")
Reply(kind='OK', command='GET', fields=('40.000', '39.812', '0'), line='OK GET 40.000 39.812 0')
>>> parse_reply("garbage") is None
True
"""

from __future__ import annotations

from dataclasses import dataclass

BAUDRATE = 115200
EOL = b"\n"
#: reply kinds a well-formed line starts with
KINDS = ("OK", "ERR", "EVT")
#: number of fields after ``OK <COMMAND>`` for each command
OK_FIELDS: dict[str, int] = {
    "ID": 2,
    "SET": 2,
    "GET": 3,
    "VENT": 0,
    "CFG": 3,
    "LOAD": 1,
    "LOADRAW": 1,
    "TARE": 1,
    "SCALE": 1,
    "WDOG": 1,
}
ERRORS = ("LIMIT", "ESTOP", "PARSE", "HW")
#: the documented protocol every firmware speaks (plus the unsolicited ``EVT ESTOP``)
BASE_COMMANDS = ("ID", "SET", "GET", "VENT")
#: optional extensions, by name, with the commands each one brings; the driver probes each at
#: connect with a command that changes nothing (``CFG``, ``WDOG 0``, ``SCALE``) and firmware
#: without it answers ``ERR PARSE``
EXTENSIONS: dict[str, tuple[str, ...]] = {
    "CFG": ("CFG",),
    "WDOG": ("WDOG",),
    "LOAD": ("LOAD", "LOADRAW", "TARE", "SCALE"),
}
#: unsolicited events
EVENTS = ("ESTOP", "WDOG")


@dataclass(frozen=True)
class Reply:
    """One parsed line from the device.

    Attributes
    ----------
    kind : str
        ``OK``, ``ERR`` or ``EVT``.
    command : str
        For ``OK``: the command answered; for ``ERR``: the error (``LIMIT``, ``ESTOP``,
        ``PARSE``, ``HW``); for ``EVT``: the event (``ESTOP`` or ``WDOG``).
    fields : tuple of str
        The remaining words.
    line : str
        The line as received (stripped).
    """

    kind: str
    command: str
    fields: tuple[str, ...]
    line: str


def encode(command: str, *args: float | str) -> bytes:
    """One command line as bytes; floats are written with 4 decimals (0.0001 kPa resolution)."""
    words = [command] + [f"{a:.4f}" if isinstance(a, float) else str(a) for a in args]
    return (" ".join(words)).encode("ascii") + EOL


def parse_reply(raw: bytes | str) -> Reply | None:
    """Parse a reply line; ``None`` for anything that is not a well-formed reply (garbage, noise).

    Numeric fields are checked to be numbers so a corrupted line is never taken for a reading.
    """
    if isinstance(raw, bytes):
        try:
            raw = raw.decode("ascii")
        except UnicodeDecodeError:
            return None
    line = raw.strip()
    words = line.split()
    if len(words) < 2 or words[0] not in KINDS:
        return None
    kind, command, fields = words[0], words[1], tuple(words[2:])
    if kind == "OK":
        if OK_FIELDS.get(command) != len(fields):
            return None
        numeric = fields if command != "ID" else ()
        for f in numeric:
            try:
                float(f)
            except ValueError:
                return None
    elif kind == "ERR":
        if command not in ERRORS or fields:
            return None
    elif command not in EVENTS or fields:
        return None
    return Reply(kind, command, fields, line)
