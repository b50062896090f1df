"""The pressure log of a video and what each frame's time means on it.

A pressure log is a CSV with ``time_s`` (s, strictly increasing), ``pressure_kpa`` (the pressure
asked for: the regulator's setpoint, or the only pressure logged) and optionally ``measured_kpa``
(the pressure the regulator's monitor or a gauge read).  A frame recorded at video time ``t``
(its presentation time, or its entry in a frame-times file) happened at ``t + clock_offset_s`` on
the log's clock.

For each frame this module gives (:func:`frame_conditions`):

``pressure_kpa``, ``measured_pressure_kpa``
    The log linearly interpolated at the frame's time (NaN outside the log's span); across a
    step (below) the setpoint is the one still in force until the step's row, never a value
    between the two levels that was never asked for.
``direction``
    ``up`` / ``down`` from the trend of ``pressure_kpa``: turning points are the extremes the
    pressure leaves by more than :data:`TREND_DEADBAND_KPA` (so logging noise never flips it),
    placed at the last sample of the extreme, so a hold at the top of a ramp still belongs to
    the rising leg, as the peak photo of a stepped ramp does.  Before any change: ``up``.
``step``, ``since_step_s``
    Steps are jumps of ``pressure_kpa`` of at least :data:`STEP_MIN_KPA` between consecutive
    log rows, between two holds (within :data:`HOLD_TOLERANCE_KPA`) of at least
    :data:`STEP_HOLD_MIN_S` each (so the end of a fast ramp is no step); ``step`` counts the steps
    up to the frame (0 before the first) and ``since_step_s`` is the time since the last one (NaN
    before the first).  A continuous ramp has no steps.

Examples
--------
>>> import numpy as np
>>> log = PressureLog("log.csv", np.array([0.0, 1, 2, 3, 4]), np.array([0.0, 10, 20, 10, 0]))
>>> c = frame_conditions(log, np.array([0.5, 2.0, 2.5, 5.0]))
>>> c["pressure_kpa"].tolist()[:3], c["direction"].tolist()
([5.0, 20.0, 15.0], ['up', 'up', 'down', 'down'])
>>> bool(np.isnan(c["pressure_kpa"].iloc[3]))
True
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.constants import DIRECTIONS, KPA_PER_UNIT, VACUUM_KPA
from pipeline.fileio import plain_name, read_user_csv
from pipeline.log_clock import read_log_clock
from pipeline.measure.settings import is_missing, user_floats

LOG_COLUMNS: tuple[str, ...] = ("time_s", "pressure_kpa")
#: the words a regulator's or logger's own header uses for the log's columns (any case, a unit in
#: brackets: "t (s)", "Setpoint [bar]", "Sensor (kPa)"), by the column each stands for
LOG_WORDS: dict[str, tuple[str, ...]] = {
    "time": ("time", "t", "elapsed", "timestamp", "zeit"),
    "pressure": (
        "pressure", "setpoint", "set_pressure", "set", "command", "target", "p_set",
        "pressure_setpoint", "setpoint_pressure", "target_pressure", "commanded_pressure",
        "druck", "solldruck", "sollwert", "soll",
    ),
    "measured": (
        "measured", "sensor", "readback", "read_back", "actual", "feedback", "p_meas",
        "measured_pressure", "pressure_measured", "actual_pressure", "sensor_pressure",
        "pressure_sensor", "p_measured", "istdruck", "istwert", "ist",
    ),
}
#: seconds per unit of a time column
SECONDS_PER_UNIT: dict[str, float] = {"s": 1.0, "ms": 1e-3, "min": 60.0}
FRAME_TIME_COLUMNS: tuple[str, ...] = ("frame", "time_s")
#: a reversal of the pressure trend counts once the pressure left its extreme by this much (kPa)
TREND_DEADBAND_KPA = 1.0
#: a log's trend turns once its pressure leaves an extreme by this many times its row-to-row
#: noise (and by TREND_DEADBAND_KPA at least): a sensor's reading logged alone turned at every
#: wobble, and its photos' or frames' directions with it
NOISE_DEADBANDS = 6.0
#: ... and its extreme lasts as long as its pressure stays within this many times its noise
NOISE_BAND = 3.0
#: rows over which a log's noise is taken at a time (:func:`noise_kpa`)
NOISE_WINDOW_ROWS = 50
#: a jump of the logged pressure of at least this between two log rows may be a step (kPa)
STEP_MIN_KPA = 2.0
#: ... when the pressure then holds (within HOLD_TOLERANCE_KPA) for at least this long (s)
STEP_HOLD_MIN_S = 0.5
HOLD_TOLERANCE_KPA = 0.5


@dataclass(frozen=True)
class PressureLog:
    """A validated pressure log (arrays of equal length, time strictly increasing); ``read_from``
    names the log's own column each was read from (time, setpoint, measured; '' for none)."""

    path: str
    time_s: np.ndarray
    pressure_kpa: np.ndarray
    measured_kpa: np.ndarray | None = None
    read_from: tuple[str, str, str] = ("time_s", "pressure_kpa", "")
    #: a log whose times are dates and clock times (a logger's wall clock): the first row's, from
    #: which ``time_s`` counts; None for a log in seconds
    clock_start: datetime | None = None
    #: a dated log whose dates read either way (``05/12/2026``): the first row read day first
    #: (``clock_start`` is it read month first); None where the dates are plain
    clock_start_dayfirst: datetime | None = None
    #: False when the log's pressure is its measured pressure, logged alone (no setpoint)
    setpoint_logged: bool = True
    #: False for clock times alone (``clock_start`` then on :data:`pipeline.log_clock.UNDATED_DAY`:
    #: the photos' dates give the day)
    clock_dated: bool = True

    def describe_columns(self) -> str:
        """Which of the log's columns were read as what, for ``photoset check``.

        Examples
        --------
        >>> log = PressureLog("l.csv", np.zeros(2), np.zeros(2), np.zeros(2),
        ...                   ("t (s)", "Setpoint [bar]", "sensor_kpa"))
        >>> log.describe_columns()
        "time from 't (s)', setpoint from 'Setpoint [bar]', measured pressure from 'sensor_kpa'"
        >>> PressureLog("l.csv", np.zeros(2), np.zeros(2)).describe_columns()
        "time from 'time_s', setpoint from 'pressure_kpa', no measured pressure"
        """
        time, setpoint, measured = self.read_from
        return (
            f"time from {time!r}, setpoint from {setpoint!r}, "
            + (f"measured pressure from {measured!r}" if measured else "no measured pressure")
        )

    @property
    def span_s(self) -> tuple[float, float]:
        """First and last logged time (s)."""
        return float(self.time_s[0]), float(self.time_s[-1])


def log_header_names(columns: list[str]) -> dict[str, str]:
    """The log's own names (``time_s``, ``pressure_kpa``, ``measured_kpa``, or a pressure in
    another unit, ``pressure_bar``) for a header a regulator or logger wrote its own way; each only
    where one column alone can be meant and the log does not name it already.

    Examples
    --------
    >>> log_header_names(["t (s)", "setpoint (kPa)", "sensor (kPa)"])
    {'t (s)': 'time_s', 'setpoint (kPa)': 'pressure_kpa', 'sensor (kPa)': 'measured_kpa'}
    >>> log_header_names(["Time [ms]", "P set (bar)", "Sensor (kPa)"])
    {'Time [ms]': 'time_ms', 'P set (bar)': 'pressure_bar', 'Sensor (kPa)': 'measured_kpa'}
    >>> log_header_names(["Set Pressure (bar)", "Measured Pressure (bar)"])  # LabVIEW's
    {'Set Pressure (bar)': 'pressure_bar', 'Measured Pressure (bar)': 'measured_bar'}
    >>> log_header_names(["Zeit [ms]", "Druck [mbar]"])
    {'Zeit [ms]': 'time_ms', 'Druck [mbar]': 'pressure_mbar'}
    >>> log_header_names(["time", "setpoint"])  # no unit: none is guessed
    {}
    >>> log_header_names(["time_s", "pressure_kpa"])
    {}
    """
    plain = {c: plain_name(str(c)) for c in columns}
    units = {
        "time": tuple(SECONDS_PER_UNIT),
        "pressure": ("kpa", *KPA_PER_UNIT),
        "measured": ("kpa", *KPA_PER_UNIT),
    }
    canonical = {f"{role}_{unit}" for role, us in units.items() for unit in us}
    out = {  # "Time [ms]", "Pressure (bar)": the log's own names written another way
        c: p for c, p in plain.items() if p in canonical and p != c and p not in columns
    }
    taken = set(plain.values())
    for role in ("time", "pressure", "measured"):
        if any(p.startswith(f"{role}_") and p.split("_", 1)[1] in units[role] for p in taken):
            continue  # named already
        matches = []
        for column, p in plain.items():
            if column in out:
                continue
            for word in LOG_WORDS[role]:  # the unit must be written: 1.2 is kPa or bar
                unit = p[len(word) + 1:] if p.startswith(f"{word}_") else None
                if unit in units[role]:
                    matches.append((column, unit))
                    break
        if len(matches) == 1:
            column, unit = matches[0]
            out[column] = f"{role}_{unit}"
            taken.add(out[column])
    return out


def _in_seconds(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` with ``time_s`` from a time in ms or min (``time_ms``, ``time_min``)."""
    out = df.copy()
    units = [u for u in SECONDS_PER_UNIT if u != "s" and f"time_{u}" in out.columns]
    if "time_s" not in out.columns and len(units) == 1:
        written = out[f"time_{units[0]}"]
        values = user_floats(written) * SECONDS_PER_UNIT[units[0]]
        out["time_s"] = [float(v) if np.isfinite(v) else w for v, w in zip(values, written)]
    return out


def _in_kpa(df: pd.DataFrame) -> pd.DataFrame:
    """``df`` with ``pressure_kpa`` (``measured_kpa``) from a log in bar, mbar, psi or MPa
    (``pressure_bar``, ``measured_bar``, ...); a cell that is no number is kept as written, for
    :func:`_numbers` to name.

    Examples
    --------
    >>> log = pd.DataFrame({"time_s": [0, 1], "pressure_bar": ["0,5", "x"], "measured_psi": [1, 2]})
    >>> out = _in_kpa(log)
    >>> out["pressure_kpa"].tolist(), out["measured_kpa"].round(2).tolist()
    ([50.0, 'x'], [6.89, 13.79])
    """
    out = df.copy()
    for stem, kpa in (("pressure", "pressure_kpa"), ("measured", "measured_kpa")):
        units = [u for u in KPA_PER_UNIT if f"{stem}_{u}" in out.columns]
        if kpa in out.columns or len(units) != 1:
            continue
        written = out[f"{stem}_{units[0]}"]
        values = user_floats(written) * KPA_PER_UNIT[units[0]]
        out[kpa] = [round(float(v), 6) if np.isfinite(v) else w for v, w in zip(values, written)]
    return out


def _numbers(df: pd.DataFrame, column: str, name: str, problems: list[str]) -> np.ndarray:
    values = user_floats(df[column])
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        i = int(bad[0])
        written = df[column].iloc[i]
        what = (
            "is missing (an empty or n/a cell)" if is_missing(written)
            else f"{written!r} is not a number"
        )
        problems.append(f"{name} line {i + 2}: {column} {what}"
                        + (f" ({bad.size} such rows)" if bad.size > 1 else ""))
    return values


def read_pressure_log(path: str | os.PathLike[str]) -> tuple[PressureLog | None, list[str]]:
    """Read and check a pressure log; return it (None if unusable) and every problem in words.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "log.csv"
    >>> _ = p.write_text("time_s,pressure_kpa\\n0,0\\n1,5\\n1,6\\n")
    >>> print(*read_pressure_log(p)[1])  # doctest: +NORMALIZE_WHITESPACE
    log.csv line 4: time_s 1 does not increase (previous row 1); sort the log by time or drop the
    repeated row
    """
    path = Path(path)
    name = path.name
    if not path.is_file():
        return None, [f"pressure log {name} does not exist"]
    try:
        df = read_user_csv(path)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        return None, [f"pressure log {name} cannot be parsed as CSV ({exc})"]
    columns = [str(c) for c in df.columns]
    own = log_header_names(columns)
    df = _in_kpa(_in_seconds(df.rename(columns=own)))
    clock, clock_problems = read_log_clock(df, name) if "time_s" not in df.columns else (None, [])
    if clock_problems:
        return None, clock_problems
    if clock is not None:
        df = df.assign(time_s=clock.time_s)
    setpoint_logged = "pressure_kpa" in df.columns or "measured_kpa" not in df.columns
    if not setpoint_logged:
        # a log of the measured pressure alone: the only pressure there is
        df = df.rename(columns={"measured_kpa": "pressure_kpa"})
        own = {c: ("pressure_" + n.split("_", 1)[1] if n.startswith("measured_") else n)
               for c, n in own.items()}
    missing = [c for c in LOG_COLUMNS if c not in df.columns]
    if missing:
        header = columns  # as the file writes it
        return None, [
            (
                f"pressure log {name} lacks column(s) {missing} (its header is {header}); it "
                "needs time_s (s; or a 'timestamp' column of dates and clock times) and "
                "pressure_kpa (kPa; or pressure_bar, pressure_mbar, "
                "pressure_psi or pressure_mpa), optionally measured_kpa (or measured_bar, ...); "
                "a logger's own names are read with their unit in brackets ('t (s)', "
                "'Setpoint (kPa)', 'Sensor [bar]')"
            )
        ]
    if len(df) < 2:
        return None, [
            f"pressure log {name} has {len(df)} row(s); at least 2 are needed to interpolate"
        ]
    problems: list[str] = []
    t = _numbers(df, "time_s", name, problems)
    p = _numbers(df, "pressure_kpa", name, problems)
    m = _numbers(df, "measured_kpa", name, problems) if "measured_kpa" in df.columns else None
    if not problems:
        back = np.flatnonzero(np.diff(t) <= 0)
        if back.size:
            i = int(back[0]) + 1
            if clock is None:
                problems.append(
                    f"{name} line {i + 2}: time_s {t[i]:g} does not increase (previous row "
                    f"{t[i - 1]:g}); sort the log by time or drop the repeated row"
                )
            else:
                def at(k: int) -> str:
                    return f"{clock.start + timedelta(seconds=float(t[k])):%H:%M:%S.%f}"[:-3]

                problems.append(
                    f"{name} line {i + 2}: {clock.column} {at(i)} does not increase (previous "
                    f"row {at(i - 1)}); sort the log by time or drop the repeated row"
                    + (
                        f" ({back.size} rows repeat the time before them: a logger writing its "
                        "clock to the whole second more often than once a second; write its times "
                        "with their fraction of a second)"
                        if back.size > 2
                        else ""
                    )
                )
        for column, values in (("pressure_kpa", p), ("measured_kpa", m)):
            if values is not None and (values < VACUUM_KPA).any():
                i = int(np.flatnonzero(values < VACUUM_KPA)[0])
                problems.append(
                    f"{name} line {i + 2}: {column} {values[i]:g} is below absolute vacuum "
                    f"({VACUUM_KPA:g} kPa gauge); log gauge pressures in kPa"
                )
    if problems:
        return None, problems
    read_from = _read_from(columns, own, m is not None)
    if clock is None:
        return PressureLog(str(path), t, p, m, read_from, setpoint_logged=setpoint_logged), []
    return PressureLog(
        str(path),
        t,
        p,
        m,
        (clock.column, read_from[1], read_from[2]),
        clock.start,
        clock.start_dayfirst,
        setpoint_logged=setpoint_logged,
        clock_dated=clock.dated,
    ), []


def _read_from(columns: list[str], own: dict[str, str], measured: bool) -> tuple[str, str, str]:
    """The log's own column that gave its time, setpoint and measured pressure ('' for none), as
    :func:`_in_seconds` and :func:`_in_kpa` take them."""
    renamed = {own.get(c, c): str(c) for c in columns}
    out = []
    for stem, units in (
        ("time", tuple(SECONDS_PER_UNIT)),
        ("pressure", ("kpa", *KPA_PER_UNIT)),
        ("measured", ("kpa", *KPA_PER_UNIT) if measured else ()),
    ):
        hits = [renamed[f"{stem}_{u}"] for u in units if f"{stem}_{u}" in renamed]
        out.append(hits[0] if hits else "")
    return out[0], out[1], out[2]


def read_frame_times(path: str | os.PathLike[str]) -> tuple[np.ndarray | None, list[str]]:
    """Frame timestamps (s, on the video's clock) from a ``frame, time_s`` CSV, frame 0 first.

    Returns the times (None if unusable) and every problem in words.
    """
    path = Path(path)
    name = path.name
    if not path.is_file():
        return None, [f"frame-times file {name} does not exist"]
    try:
        df = read_user_csv(path)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        return None, [f"frame-times file {name} cannot be parsed as CSV ({exc})"]
    if any(c not in df.columns for c in FRAME_TIME_COLUMNS):
        header = list(map(str, df.columns))
        return None, [
            f"frame-times file {name} needs columns {list(FRAME_TIME_COLUMNS)} (its header is "
            + f"{header})"
        ]
    problems: list[str] = []
    frame = _numbers(df, "frame", name, problems)
    t = _numbers(df, "time_s", name, problems)
    if problems:
        return None, problems
    if not np.array_equal(frame, np.arange(len(frame))):
        return None, [
            f"frame-times file {name}: frames must be 0, 1, 2, ... in order, one row each"
        ]
    if (np.diff(t) <= 0).any():
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        return None, [f"frame-times file {name} line {i + 2}: time_s does not increase"]
    return t, []


def turning_points(
    pressure_kpa: np.ndarray, deadband_kpa: float = TREND_DEADBAND_KPA, band_kpa: float = 0.0
) -> np.ndarray:
    """Indices of the confirmed extremes of a pressure series (the last sample of each extreme,
    or, with ``band_kpa``, the last sample within that of it before the pressure left it: a
    noisy hold at the top of a ramp is its top to its end, not to its highest sample).

    Examples
    --------
    >>> turning_points(np.array([0.0, 5, 10, 10, 9.5, 10, 5, 0, 0.3, 4]))
    array([5, 7])
    >>> turning_points(np.array([0.0, 10, 11, 10, 10.5, 0]), 3.0, band_kpa=1.0)
    array([4])
    """
    p = np.asarray(pressure_kpa, float)
    out: list[int] = []
    rising = True
    ext = 0
    for i in range(1, len(p)):
        if rising:
            if p[i] >= p[ext]:
                ext = i
            elif p[ext] - p[i] > deadband_kpa:
                out.append(max(j for j in range(ext, i) if p[j] >= p[ext] - band_kpa))
                rising, ext = False, i
        else:
            if p[i] <= p[ext]:
                ext = i
            elif p[i] - p[ext] > deadband_kpa:
                out.append(max(j for j in range(ext, i) if p[j] <= p[ext] + band_kpa))
                rising, ext = True, i
    return np.array(out, dtype=int)


def since_last_step(time_s: np.ndarray, steps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """How many of the step times ``steps`` (sorted) lie at or before each of ``time_s``, and
    the time (s) since the last of them (NaN before the first).

    Examples
    --------
    >>> k, since = since_last_step(np.array([0.5, 2.0, 3.5]), np.array([1.0, 3.0]))
    >>> k.tolist(), since.tolist()
    ([0, 1, 2], [nan, 1.0, 0.5])
    """
    t = np.asarray(time_s, float)
    k = np.searchsorted(steps, t, side="right")
    since = t - steps[np.maximum(k - 1, 0)] if steps.size else np.full(t.shape, np.nan)
    return k.astype(int), np.where(k > 0, since, np.nan)


def step_times(log: PressureLog) -> np.ndarray:
    """Times (s, log clock) at which ``pressure_kpa`` steps (see the module docstring)."""
    return log.time_s[step_rows(log)]


def step_rows(log: PressureLog) -> np.ndarray:
    """Rows of the log at which ``pressure_kpa`` steps: each step's first row at its new level.

    Examples
    --------
    >>> t = np.arange(0.0, 3.0, 0.5)
    >>> step_rows(PressureLog("log.csv", t, np.array([0.0, 0, 40, 40, 40, 40]))).tolist()
    [2]
    >>> step_rows(PressureLog("log.csv", t, np.array([0.0, 8, 16, 24, 32, 40]))).tolist()  # ramp
    []
    """
    t, p = log.time_s, log.pressure_kpa
    jumps = np.flatnonzero(np.abs(np.diff(p)) >= STEP_MIN_KPA) + 1
    out = []
    for j in jumps:
        k = j
        while k + 1 < len(p) and abs(p[k + 1] - p[j]) <= HOLD_TOLERANCE_KPA:
            k += 1
        i = j - 1
        while i > 0 and abs(p[i - 1] - p[j - 1]) <= HOLD_TOLERANCE_KPA:
            i -= 1
        if t[k] - t[j] >= STEP_HOLD_MIN_S and t[j - 1] - t[i] >= STEP_HOLD_MIN_S:
            out.append(j)
    return np.array(out, dtype=int)


def noise_kpa(pressure_kpa: np.ndarray) -> float:
    """The row-to-row noise of a logged pressure where it is largest (kPa, a standard
    deviation): the median absolute deviation of its second differences (which steps and ramps
    leave at 0 but at their corners) over :data:`NOISE_WINDOW_ROWS` rows at a time, its 95th
    percentile over the log (so a little over an even noise's own), 0 for a setpoint, held,
    stepped or ramped.  A sensor's noise grows
    with its reading: customer 41's was 0.05 kPa at rest and 0.4 at the top, and one median
    over the log (0.12) let the top holds' noise turn the trend.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> round(noise_kpa(np.repeat([0.0, 20, 40], 500) + rng.normal(0, 1.5, 1500)), 1)  # 1.5
    2.0
    >>> levels = np.repeat([0.0, 20, 40], 500)
    >>> round(noise_kpa(levels + rng.normal(0, 1.0, 1500) * levels / 40), 1)  # 1 at the top
    1.0
    >>> ramp = np.concatenate([np.linspace(0, 100, 50), np.linspace(100, 0, 50)])
    >>> noise_kpa(np.repeat([0.0, 20, 40], 500)), round(noise_kpa(ramp), 6)
    (0.0, 0.0)
    """
    p = np.asarray(pressure_kpa, float)
    d1 = np.diff(p)
    d2 = np.diff(p, 2)
    if d2.size < 2:
        return 0.0
    deviation = np.abs(d2 - np.median(d2))
    # a setpoint's steps are no noise (a log cycling 0/40 kPa in 2 s holds read 24 kPa): the
    # second differences beside a jump beyond the log's overall noise are left out
    overall = 1.4826 * float(np.median(deviation)) / np.sqrt(6.0)
    jump = np.abs(d1) >= max(STEP_MIN_KPA, 8.0 * overall)
    deviation = pd.Series(np.where(jump[1:] | jump[:-1], np.nan, deviation))
    window = min(NOISE_WINDOW_ROWS, d2.size)
    local = deviation.rolling(window, center=True, min_periods=window // 2 + 1).median()
    if not np.isfinite(local.to_numpy(float)).any():
        return 0.0
    return float(1.4826 * np.nanpercentile(local.to_numpy(float), 95) / np.sqrt(6.0))


def log_noise_kpa(log: PressureLog) -> float:
    """The noise of a log's pressure column (:func:`noise_kpa`): 0 where the log has a measured
    pressure of its own, its pressure column then being a setpoint."""
    return 0.0 if log.measured_kpa is not None else noise_kpa(log.pressure_kpa)


def trend_deadband_kpa(noise_kpa: float) -> float:
    """How far a log's pressure must leave an extreme for its trend to turn (kPa): at least
    :data:`TREND_DEADBAND_KPA`, and :data:`NOISE_DEADBANDS` times its noise.

    >>> trend_deadband_kpa(0.0), trend_deadband_kpa(0.5)
    (1.0, 3.0)
    """
    return max(TREND_DEADBAND_KPA, NOISE_DEADBANDS * noise_kpa)


def frame_conditions(
    log: PressureLog, time_s: np.ndarray, noise_kpa: float | None = None
) -> pd.DataFrame:
    """Pressure, direction and step of frames at ``time_s`` (log clock), one row per frame;
    the trend turns where the pressure leaves an extreme beyond the log's noise
    (:func:`turning_points` with :func:`trend_deadband_kpa` and :data:`NOISE_BAND` times the
    noise; ``noise_kpa`` by :func:`log_noise_kpa` when not given).

    Returns
    -------
    pandas.DataFrame
        ``pressure_kpa``, ``measured_pressure_kpa`` (only when the log has ``measured_kpa``),
        ``direction``, ``step``, ``since_step_s``, ``in_log`` (the time lies in the log's span).
    """
    t = np.asarray(time_s, float)
    lo, hi = log.span_s
    inside = np.isfinite(t) & (t >= lo) & (t <= hi)
    setpoint = np.interp(t, log.time_s, log.pressure_kpa)
    rows = step_rows(log)
    # a frame between a step's last row at the old level and its first at the new one: the old
    # setpoint, still in force (interpolated, a customer's 120 -> 160 kPa step read 133.3 kPa)
    after = np.searchsorted(log.time_s, t, side="right")  # the first row later than the frame
    held = np.isin(after, rows)
    setpoint = np.where(held, log.pressure_kpa[np.maximum(after - 1, 0)], setpoint)
    out = pd.DataFrame({"pressure_kpa": np.where(inside, setpoint, np.nan)})
    if log.measured_kpa is not None:
        out["measured_pressure_kpa"] = np.where(
            inside, np.interp(t, log.time_s, log.measured_kpa), np.nan
        )
    noise = log_noise_kpa(log) if noise_kpa is None else noise_kpa
    tp = turning_points(log.pressure_kpa, trend_deadband_kpa(noise), NOISE_BAND * noise)
    # direction of each log interval: up until the first turning point, then alternating
    edges = log.time_s[tp]
    # a frame at a peak's own time is still rising, and so is one that holds the peak's setpoint
    # until a step down (its time is then that of the log's last row at the peak: the last frame
    # of a stepped ramp's top hold was 'down' at the peak's level)
    n_turns = np.searchsorted(edges, np.where(held, log.time_s[np.maximum(after - 1, 0)], t))
    out["direction"] = np.where(n_turns % 2 == 0, *DIRECTIONS)
    out["step"], out["since_step_s"] = since_last_step(t, step_times(log))
    out["in_log"] = inside
    return out


def span_text(span: tuple[float, float]) -> str:
    """A time span for messages: ``'0.00-120.00 s'``."""
    return f"{span[0]:.2f}-{span[1]:.2f} s"


def covers(
    log_span: tuple[float, float], video_span: tuple[float, float], slack_s: float = 0.0
) -> bool:
    """Whether the log's span holds the video's (within ``slack_s`` at each end)."""
    return (
        log_span[0] <= video_span[0] + slack_s
        and video_span[1] - slack_s <= log_span[1]
        and not math.isnan(video_span[0])
    )
