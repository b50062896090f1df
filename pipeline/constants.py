"""Names and numbers every stage agrees on (DESIGN.md): ramp directions and keys, row statuses,
vacuum."""

from __future__ import annotations

#: ramp directions in a manifest: increasing and decreasing pressure
DIRECTIONS: tuple[str, ...] = ("up", "down")
#: what a person may write for a direction (a manifest's column, a file name's ``{direction}``), in
#: any case: a direction, its meaning or its abbreviation
DIRECTION_WORDS: dict[str, str] = {
    "up": "up", "u": "up", "inc": "up", "increasing": "up", "inflating": "up", "load": "up",
    "loading": "up",
    "down": "down", "d": "down", "dn": "down", "dec": "down", "decreasing": "down",
    "deflating": "down", "unload": "down", "unloading": "down",
}
#: the manifest columns that name one ramp (one trial of one actuator of one material)
RAMP_KEYS: tuple[str, ...] = ("material", "actuator", "trial")
#: measurement status of a row: a trusted number, a doubtful number, no number
STATUSES: tuple[str, ...] = ("ok", "flagged", "failed")
#: how a row whose pressure breaks its ramp's order (a manifest typo) says so in its reason: its
#: psi never enters a curve, flagged rows included (its pressure, not psi, is in doubt)
PRESSURE_OUT_OF_ORDER = "is out of its ramp's order"
#: a photo taken closer than this (s) to a step of its pressure log's setpoint is named by
#: ``photoset init`` and ``check`` (the camera's clock is kept to the second, and a clock offset a
#: little off moves it across), and one taken this soon after a step is ``flagged`` by measure:
#: the actuator may still be moving (customer 39: 41.2 deg 0.4 s after its log's step to 30 kPa,
#: 43.3 settled)
NEAR_STEP_S = 1.5
#: rest bending angle psi0 of the paper's actuators (deg, DESIGN.md): the fallback where no material
#: says its own (a material's is ``Material.psi0_deg``, from the materials file)
PSI0_DEG: float = 210.0
#: absolute vacuum as a gauge pressure (kPa): no pneumatic pressure can be lower
VACUUM_KPA: float = -101.3
#: kPa in one of each other pressure unit a regulator may show (``pressure_bar`` in a manifest,
#: ``pressure_bar``/``measured_bar`` in a video's pressure log)
KPA_PER_UNIT: dict[str, float] = {
    "bar": 100.0, "mbar": 0.1, "psi": 6.894757293168361, "mpa": 1000.0,
}


def direction_name(value: object) -> object:
    """The direction (``up``/``down``) a person meant by ``value`` (:data:`DIRECTION_WORDS`, any
    case, spaces around it); anything else as it is, for the manifest check to name.

    Examples
    --------
    >>> direction_name(" Up "), direction_name("Decreasing"), direction_name("sideways")
    ('up', 'down', 'sideways')
    """
    if isinstance(value, str):
        return DIRECTION_WORDS.get(value.strip().lower(), value)
    return value
