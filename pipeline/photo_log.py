"""Photos placed on a pressure log by the time their camera wrote into them.

``photoset init DIR --pattern 'IMG_*.JPG' --pressure-log log.csv`` gives each photo the setpoint
in force when it was taken, the measured pressure and the direction, read from the log at its
EXIF time (:func:`pipeline.photo_times.exif_time`).  The camera's clock and the logger's are two
clocks; :class:`ClockSync` says how they relate, either as an offset or, with no sign to get
wrong, as the log's time at one photo (a photo of the logger's screen).

:func:`place_photos` also says what a person should check: photos taken within
:data:`~pipeline.constants.NEAR_STEP_S` of a step of the setpoint; an offset whose opposite
sign would put clearly fewer photos near a step; photos that fall in a gap of the log (a
logger that stopped writing for a while), which are left out, since their pressure is not known;
a log whose dates read either way (``05/12/2026``), read as the photos' own dates say.  Each
photo's ``since_step_s`` (the time since the pressure reached the level it then held,
:func:`held_steps`) goes into the manifest: measure flags a photo taken while the actuator may
still be moving.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace
from datetime import datetime, timedelta
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.constants import NEAR_STEP_S
from pipeline.errors import UserInputError
from pipeline.log_clock import read_clock_text
from pipeline.measure.settings import user_float
from pipeline.photo_times import exif_time
from pipeline.ramp_check import settling
from pipeline.video.timeline import (
    STEP_MIN_KPA,
    PressureLog,
    frame_conditions,
    log_noise_kpa,
    read_pressure_log,
    since_last_step,
    span_text,
    trend_deadband_kpa,
)

#: a stretch between two log rows longer than this many times the log's usual row interval (and
#: than GAP_MIN_S) is a gap: the logger stopped writing, and a photo in it has no known pressure
GAP_ROWS = 5.0
GAP_MIN_S = 1.0
#: the opposite sign of an offset is suggested when it leaves at most this share of the photos
#: near a step that the offset given leaves (and at least 3 fewer)
SIGN_CHECK_SHARE = 0.5
#: a log whose one pressure column varies by more than this (kPa, :func:`noise_kpa`) holds a
#: sensor's reading, not a setpoint
NOISY_KPA = 0.3
#: a log where more than this share of the rows change the setpoint is written a row per
#: setpoint: a long hold there is no gap, and its last setpoint holds for a row's interval more
ROW_PER_SETPOINT_SHARE = 0.5
#: columns of :attr:`PhotoPlacement.table` that are no manifest's
PLACEMENT_ONLY_COLUMNS: tuple[str, ...] = ("near_step_s",)
#: the manifest's record of photos placed on a pressure log (``init`` writes them): the log's
#: name, and each photo's time on the log's clock; ``check`` reads the log again by them
#: (:func:`logged_row_doubts`)
LOG_RECORD_COLUMNS: tuple[str, ...] = ("pressure_log", "log_time_s")


@dataclass(frozen=True)
class ClockSync:
    """How the camera's clock maps onto the log's.

    ``offset_s``: on a log of dates and clock times, how far the logger's clock is ahead of the
    camera's (negative when behind; None: 0, the clocks agree); on a log in seconds, the log's
    time at the first photo.  Or ``photo`` and ``log_time``: the log's time when that photo was
    taken, as written (a clock time ``14:00:10.1``, a date and time, or seconds on a log in
    seconds, whatever its unit), from which the offset follows: best a photo of the logger's
    screen, its clock in view, kept beside the set's folder, out of its ramps.
    """

    offset_s: float | None = None
    photo: str | None = None
    log_time: str | None = None


@dataclass(frozen=True)
class PhotoPlacement:
    """Photos placed on a pressure log (:func:`place_photos`).

    ``table`` has one row per photo placed, in the order taken: ``image``, ``timestamp``
    (ISO 8601, the camera's clock), ``log_time_s``, ``pressure_kpa`` (the setpoint in force),
    ``measured_pressure_kpa`` (when logged), ``direction``, ``near_step_s`` (how far from a
    step of the setpoint, when within :data:`~pipeline.constants.NEAR_STEP_S`; else NaN) and
    ``since_step_s`` (the time since the pressure reached the level it then held,
    :func:`held_steps`; NaN before the first: measure flags a photo taken while settling,
    :func:`pipeline.ramp_check.flag_settling`).
    ``left_out`` are the photos in a gap of the log; ``notes`` and ``warnings`` are lines for
    the user.
    """

    table: pd.DataFrame
    left_out: tuple[str, ...]
    #: the log's one pressure column is a sensor's noisy reading: no two photos share a level,
    #: and the ramps are told apart by the log's trend (``direction``), not the levels
    sensor_only: bool
    notes: tuple[str, ...]
    warnings: tuple[str, ...]


def place_photos(
    folder: str | os.PathLike[str],
    images: list[str],
    log_name: str,
    sync: ClockSync,
) -> PhotoPlacement:
    """Place photos on a pressure log by their EXIF times and read each one's conditions.

    Parameters
    ----------
    folder : path
        Folder holding the photos and the log.
    images : list of str
        The photos' names in ``folder``.
    log_name : str
        The pressure log's name in ``folder``
        (:func:`pipeline.video.timeline.read_pressure_log`).
    sync : ClockSync
        How the camera's clock maps onto the log's.

    Returns
    -------
    PhotoPlacement

    Raises
    ------
    UserInputError
        When the log cannot be read, a photo holds no EXIF time, the clocks' relation is not
        given for a log in seconds (or given twice, or names a photo not among them), or photos
        lie outside the log (with the offsets that would fit them all).
    """
    root = Path(folder)
    log, problems = read_pressure_log(root / log_name)
    if log is None:
        raise UserInputError("--pressure-log: " + "; ".join(problems))
    stamps = _camera_times(root, images)
    notes: list[str] = []
    if log.clock_start is not None and log.clock_start_dayfirst is not None:
        log, note = _date_reading(log, stamps)
        notes.append(note)
    if log.clock_start is not None and not log.clock_dated:
        log, note = _photos_day(log, stamps)
        notes.append(note)
    offset_s, placed_note = _offset(log, log_name, stamps, sync, root)
    notes.append(placed_note)
    camera_s = _camera_seconds(log, stamps)
    log_time = np.round(camera_s + offset_s, 3)  # as the manifest keeps it, for check
    _refuse_outside(log, log_name, stamps, log_time, camera_s)
    in_gap, gap_lines = _gaps(log, stamps, log_time)
    if in_gap.all():
        raise UserInputError(
            f"--pressure-log {log_name}: every photo was taken in a gap of the log, where it has "
            "no rows, so no photo's pressure is known: "
            + "; ".join(line.split("; their pressure")[0] for line in gap_lines)
            + "; give the log that covers them, or check the clocks (--clock-offset-s, "
            "--log-time-at)"
        )
    keep = ~in_gap
    # the log's last row at or before the photo: its setpoint is the one in force (a setpoint
    # is a command, held until the next: a logger writing one row per setpoint gave photos
    # values between two levels), its measured pressure the last read, its direction that row's
    # (against the log's trend, beyond its noise)
    in_force = log.time_s[_rows_in_force(log, log_time[keep])]
    noise, steps = _noise_and_steps(log)
    conditions = frame_conditions(log, in_force, noise_kpa=noise)
    near = _near_step(log_time[keep], steps)
    table = pd.DataFrame(
        {
            "image": stamps.index[keep],
            "timestamp": [f"{t:%Y-%m-%dT%H:%M:%S.%f}"[:-3] for t in stamps[keep]],
            "log_time_s": log_time[keep],
            "pressure_kpa": conditions["pressure_kpa"].round(2).to_numpy(),
        }
    )
    if "measured_pressure_kpa" in conditions.columns:
        table["measured_pressure_kpa"] = conditions["measured_pressure_kpa"].round(2).to_numpy()
    table["direction"] = conditions["direction"].to_numpy()
    table["near_step_s"] = np.where(near < NEAR_STEP_S, near.round(2), np.nan)
    held = held_steps(log, trend_deadband_kpa(noise), _held_span(log)[1])
    table["since_step_s"] = since_last_step(log_time[keep], held)[1].round(2)
    table = table.sort_values("log_time_s", kind="stable").reset_index(drop=True)
    sensor_only = log.measured_kpa is None and (not log.setpoint_logged or noise > NOISY_KPA)
    if sensor_only:
        notes.append(
            f"the log's one pressure column ({log.read_from[1]!r}) is a sensor's reading (its "
            f"noise about {noise:.2g} kPa), not a setpoint, so each photo's pressure is "
            "the reading at its time, and no two photos share a level exactly; set "
            "aggregate.bin_kpa in config.yaml to pool them, and check the ramps below (log the "
            "setpoint too, as its own column, for levels)"
        )
    elif log.measured_kpa is None:
        notes.append("the log holds no measured pressure: the manifest has the setpoints alone")
    if unheld_levels(table) and not sensor_only:
        notes.append(
            "the setpoints at the photos are not levels held for several photos (a continuous "
            "ramp?), so each curve point is one photo: set aggregate.bin_kpa in config.yaml "
            "(e.g. 5) to pool the photos by pressure, within 5 kPa"
        )
    warnings = gap_lines + _near_step_lines(table)
    if log.clock_start is not None and sync.photo is None:  # a sign to get wrong
        flipped = _opposite_sign_line(
            offset_s, camera_s[keep], steps, int(table["near_step_s"].notna().sum())
        )
        warnings += [flipped] if flipped else []
    return PhotoPlacement(
        table,
        tuple(stamps.index[in_gap]),
        sensor_only,
        tuple(notes),
        tuple(warnings),
    )


def _rows_in_force(log: PressureLog, log_time: np.ndarray) -> np.ndarray:
    """The index of the log's last row at or before each time: its setpoint is the one in force
    (a setpoint is a command, held until the next)."""
    return np.clip(np.searchsorted(log.time_s, log_time, side="right") - 1, 0, None)


def _noise_and_steps(log: PressureLog) -> tuple[float, np.ndarray]:
    """The log's noise (kPa; 0 for one written a row per setpoint) and the times of its steps
    beyond that noise."""
    noise = 0.0 if row_per_setpoint(log) else log_noise_kpa(log)
    return noise, jump_times(log, trend_deadband_kpa(noise))


def held_steps(log: PressureLog, tolerance_kpa: float, end_s: float) -> np.ndarray:
    """When the log's pressure reached each level it then held (s): the first row of a run of
    rows within ``tolerance_kpa`` of it that lasts :data:`~pipeline.constants.NEAR_STEP_S` or
    more (until the next run, the last until ``end_s``) and lies at least
    ``max(tolerance_kpa, STEP_MIN_KPA)`` from the held level before it.  What a photo's
    ``since_step_s`` counts from: a staircase of 1 s treads, a sensor's one-row glitch and the
    rows of its rise are no levels held (the rows' own jumps made every photo of a 2.5 kPa/s
    staircase "taken 0.4 s after a step", and a glitch 1.4 s before a mid-hold photo one).

    Examples
    --------
    >>> t = np.arange(0.0, 10.0, 0.5)
    >>> p = np.r_[[0.0] * 6, 9, 18, [20.0] * 8, 26, [20.0] * 3]  # a rise, then a glitch
    >>> held_steps(PressureLog("l.csv", t, p), 1.0, 10.0).tolist()
    [4.0]
    """
    t, p = log.time_s, log.pressure_kpa
    starts = [0]
    for i in range(1, len(p)):
        if abs(p[i] - p[starts[-1]]) > tolerance_kpa:
            starts.append(i)
    first = np.array(starts)
    lasts = np.append(t[first[1:]], max(end_s, float(t[-1])))
    held = first[lasts - t[first] >= NEAR_STEP_S]
    if held.size < 2:
        return np.array([], float)
    moved = np.abs(np.diff(p[held])) >= max(tolerance_kpa, STEP_MIN_KPA)
    return t[held[1:][moved]]


def _held_span(log: PressureLog) -> tuple[float, float]:
    """The log times a photo may take (s): its span, and for a log written a row per setpoint a
    row's usual interval after its last row, where its last setpoint still holds."""
    lo, hi = log.span_s
    if row_per_setpoint(log):
        hi += float(np.median(np.diff(log.time_s)))
    return lo, hi


def row_per_setpoint(log: PressureLog) -> bool:
    """Whether the log is written a row per setpoint (most rows change it) rather than at a
    steady rate.

    Examples
    --------
    >>> row_per_setpoint(PressureLog("l.csv", np.arange(5.0), np.array([0.0, 20, 40, 20, 0])))
    True
    """
    jumps = np.abs(np.diff(log.pressure_kpa)) >= STEP_MIN_KPA
    return bool(jumps.size) and float(jumps.mean()) > ROW_PER_SETPOINT_SHARE


def jump_times(log: PressureLog, least_kpa: float = STEP_MIN_KPA) -> np.ndarray:
    """The times of the log's rows where its setpoint jumps (by ``least_kpa`` or more from the
    row before; a noisy sensor's, beyond its noise): the steps a photo taken near would read on
    either side of, in a dense log or one written a row per setpoint.

    Examples
    --------
    >>> log = PressureLog("l.csv", np.array([0.0, 12, 24, 36]), np.array([0.0, 20, 40, 39.5]))
    >>> jump_times(log).tolist()
    [12.0, 24.0]
    """
    jumps = np.flatnonzero(np.abs(np.diff(log.pressure_kpa)) >= max(least_kpa, STEP_MIN_KPA))
    return log.time_s[jumps + 1]


def _photos_day(log: PressureLog, stamps: pd.Series) -> tuple[PressureLog, str]:
    """A log of clock times alone, on the day that puts its span nearest the photos' (the day
    before, of or after the first photo), with a note saying so."""
    assert log.clock_start is not None
    middle = stamps.min() + (stamps.max() - stamps.min()) / 2
    first_day = stamps.min().to_pydatetime().date()
    starts = [
        datetime.combine(first_day + timedelta(days=k), log.clock_start.time()) for k in (-1, 0, 1)
    ]
    start = min(
        starts,
        key=lambda s: abs((s + timedelta(seconds=log.span_s[1] / 2) - middle).total_seconds()),
    )
    return replace(log, clock_start=start, clock_dated=True), (
        f"the log's clock times have no date: its first row taken as {start:%Y-%m-%d %H:%M:%S}, "
        "the day that puts the log beside the photos"
    )


def _camera_times(root: Path, images: list[str]) -> pd.Series:
    """Each photo's EXIF time (a datetime Series indexed by name), or the error naming those
    without one."""
    times = {str(name): exif_time(root / str(name), original_only=True) for name in images}
    untimed = [name for name, when in times.items() if when is None]
    if untimed:
        raise UserInputError(
            f"--pressure-log: {len(untimed)} photo(s) hold no time the camera wrote (EXIF "
            f"DateTimeOriginal), e.g. {root / untimed[0]}; a pressure log can only be read at "
            "photos whose time is known: give photos straight from the camera (an editor or a "
            "converter may drop it), or give the pressures with --pressures-kpa instead"
        )
    return pd.Series(times).astype("datetime64[ns]")


def _camera_seconds(log: PressureLog, stamps: pd.Series) -> np.ndarray:
    """The photos' times in seconds on the log's clock before any offset: from the log's first
    row (a dated log), else from the first photo."""
    zero = pd.Timestamp(log.clock_start) if log.clock_start is not None else stamps.min()
    return (stamps - zero).dt.total_seconds().to_numpy(float)


def _date_reading(log: PressureLog, stamps: pd.Series) -> tuple[PressureLog, str]:
    """A log whose dates read either way (``05/12/2026``): the reading whose dates the photos'
    own (EXIF, year-month-day) fall on, else month first; with a note saying which."""
    assert log.clock_start is not None and log.clock_start_dayfirst is not None
    first, other = log.clock_start, log.clock_start_dayfirst
    days = set(stamps.dt.date)

    def fits(start: datetime) -> bool:
        end = start + timedelta(seconds=log.span_s[1])
        return any(start.date() <= d <= end.date() for d in days)

    chosen = other if fits(other) and not fits(first) else first
    log = replace(log, clock_start=chosen, clock_start_dayfirst=None)
    why = "as the photos' own dates are" if fits(chosen) else "no reading matches the photos' dates"
    return log, (
        f"the log's dates read either way (day or month first): read as {chosen:%Y-%m-%d}, {why}"
    )


def _offset(
    log: PressureLog, log_name: str, stamps: pd.Series, sync: ClockSync, root: Path
) -> tuple[float, str]:
    """The offset (s) the sync gives, and a line saying where that places the photos (the
    sync's photo, of the logger's clock, in ``root``: one of them or not)."""
    dated = log.clock_start is not None
    if sync.photo is not None and sync.offset_s is not None:
        raise UserInputError(
            "--clock-offset-s and --log-time-at both relate the clocks: give one of them"
        )
    if sync.photo is not None:
        when = (
            stamps[sync.photo].to_pydatetime()
            if sync.photo in stamps.index
            else exif_time(root / sync.photo, original_only=True)
        )
        if when is None:
            raise UserInputError(
                f"--log-time-at {sync.photo}={sync.log_time}: "
                + (
                    f"{root / sync.photo} holds no time the camera wrote (EXIF "
                    "DateTimeOriginal); give a photo straight from the camera"
                    if (root / sync.photo).is_file()
                    else f"no photo {root / sync.photo}; give the photo of the logger's clock "
                    "by its path from the set's folder (../clock.JPG beside it)"
                )
            )
        offset = _offset_at(log, stamps, sync.photo, when, str(sync.log_time))
    elif sync.offset_s is not None:
        offset = float(sync.offset_s)
    elif dated:
        offset = 0.0
    else:
        raise UserInputError(
            f"--pressure-log {log_name}: its times are seconds (from {log.read_from[0]!r}), which "
            "say nothing of when the photos were taken; give --log-time-at PHOTO=SECONDS (the "
            "log's time when that photo was taken) or --clock-offset-s (the log's time at the "
            "first photo; 0 if the log was started as it was taken), or log the logger's dates "
            "and clock times (a 'timestamp' column, 2026-12-06 14:25:01.5)"
        )
    first = stamps.idxmin()
    if dated:
        assert log.clock_start is not None
        ahead = "ahead of" if offset >= 0 else "behind"
        at = stamps[first].to_pydatetime() + timedelta(seconds=offset)
        line = (
            f"the logger's clock taken as {abs(offset):g} s {ahead} the camera's: the first photo, "
            f"{first}, taken at {stamps[first]:%H:%M:%S.%f}"[:-3]
            + f" by the camera, is at {at:%H:%M:%S.%f}"[:-3]
            + " on the log"
        )
    else:
        line = f"the first photo, {first}, taken at log time {offset:g} s"
    return offset, line


def _offset_at(
    log: PressureLog, stamps: pd.Series, photo: str, taken: datetime, written: str
) -> float:
    """The offset that puts ``photo`` (taken at ``taken`` by the camera) at the log time
    ``written``: a clock time or date and time on a dated log, seconds on a log in seconds."""
    fix = (
        f"--log-time-at {photo}={written}: give the log's time when {photo} was taken, "
        + (
            "as a clock time (14:00:10.1) or a date and time"
            if log.clock_start is not None
            else "in seconds on the log's clock (its time column)"
        )
    )
    if log.clock_start is None:
        seconds = user_float(written)
        if not np.isfinite(seconds):
            raise UserInputError(fix)
        return seconds - float((taken - stamps.min()).total_seconds())
    read = read_clock_text(written)  # as the log's own cells are read
    if read is None:
        raise UserInputError(fix)
    clock, dated = read
    if not dated:  # a clock time alone: on the day that puts it nearest the photo's own time
        day = datetime.combine(taken.date(), clock.time())
        clock = min((day + timedelta(days=k) for k in (-1, 0, 1)),
                    key=lambda c: abs((c - taken).total_seconds()))
    return float((clock - taken).total_seconds())


def _refuse_outside(
    log: PressureLog, log_name: str, stamps: pd.Series, log_time: np.ndarray, camera_s: np.ndarray
) -> None:
    """The error naming the photos that lie outside the log and the offsets that would fit (a
    log written a row per setpoint holds its last setpoint for a row's usual interval after its
    last row)."""
    lo, hi = _held_span(log)
    outside = np.flatnonzero(~((log_time >= lo) & (log_time <= hi)))
    if not outside.size:
        return
    first = outside[np.argmin(log_time[outside])] if (log_time[outside] < lo).any() else outside[0]
    what = (
        "the logger's clock ahead of the camera's, s; negative when behind"
        if log.clock_start is not None
        else "the log's time at the first photo, s"
    )
    clock = (
        f" ({log.clock_start:%Y-%m-%d %H:%M:%S} to "
        f"{log.clock_start + timedelta(seconds=hi):%H:%M:%S} on its clock)"
        if log.clock_start is not None
        else ""
    )
    raise UserInputError(
        f"--pressure-log {log_name}: {outside.size} of {len(stamps)} photo(s) lie outside the "
        f"log, whose times span {span_text(log.span_s)}{clock}: {stamps.index[first]} (taken "
        f"{stamps.iloc[first]:%Y-%m-%d %H:%M:%S}) is at log time {log_time[first]:.1f} s; give "
        f"--clock-offset-s ({what}; {offsets_that_fit(camera_s, (lo, hi))}) or "
        "--log-time-at PHOTO=TIME, or move photos that are no ramp's out of the folder"
    )


def offsets_that_fit(placed_s: np.ndarray, span_s: tuple[float, float]) -> str:
    """The clock offsets that put photos (at ``placed_s`` on the log's clock without one) inside
    a log spanning ``span_s``, in words.

    Examples
    --------
    >>> offsets_that_fit(np.array([200.0, 260.0]), (0.0, 100.0))
    'any from -200.0 to -160.0 puts every photo inside the log'
    >>> offsets_that_fit(np.array([0.0, 260.0]), (0.0, 100.0))
    'none puts every photo inside it: the photos span 260 s, the log 100 s'
    """
    low, high = span_s[0] - placed_s.min(), span_s[1] - placed_s.max()
    if low > high:
        return (
            f"none puts every photo inside it: the photos span {np.ptp(placed_s):.0f} s, the log "
            f"{span_s[1] - span_s[0]:.0f} s"
        )
    return f"any from {low:.1f} to {high:.1f} puts every photo inside the log"


def _gaps(
    log: PressureLog, stamps: pd.Series, log_time: np.ndarray
) -> tuple[np.ndarray, list[str]]:
    """Which photos lie in a gap of the log (:data:`GAP_ROWS`), and a warning line per gap (a
    log written a row per setpoint has none: a long hold is one row)."""
    t = log.time_s
    if row_per_setpoint(log):
        return np.zeros(len(log_time), bool), []
    step = np.diff(t)
    limit = max(GAP_MIN_S, GAP_ROWS * float(np.median(step)))
    after = np.clip(np.searchsorted(t, log_time, side="right"), 1, len(t) - 1)
    width = t[after] - t[after - 1]
    in_gap = (width > limit) & (log_time > t[0]) & (log_time < t[-1])
    lines = []
    for row in np.unique(after[in_gap]):
        names = list(stamps.index[in_gap & (after == row)])
        lines.append(
            f"{len(names)} photo(s) ({', '.join(names[:4])}{', ...' if len(names) > 4 else ''}) "
            f"were taken in a gap of the log: no row for {t[row] - t[row - 1]:.1f} s, from log "
            f"time {t[row - 1]:g} to {t[row]:g} s; their pressure is not known, so they are "
            "left out of the manifest (add their rows by hand if you know it)"
        )
    return in_gap, lines


def _near_step(log_time: np.ndarray, steps: np.ndarray) -> np.ndarray:
    """Each time's distance (s) to the nearest step time (inf without steps)."""
    if not steps.size:
        return np.full(len(log_time), np.inf)
    k = np.searchsorted(steps, log_time)
    before = np.abs(log_time - steps[np.clip(k - 1, 0, steps.size - 1)])
    after = np.abs(steps[np.clip(k, 0, steps.size - 1)] - log_time)
    return np.minimum(before, after)


def _near_step_lines(table: pd.DataFrame, limit: int = 12) -> list[str]:
    """A warning and a line per photo taken near a step of the log's setpoint."""
    near = table[table["near_step_s"].notna()]
    if near.empty:
        return []
    lines = [
        f"  {r.image} at log time {r.log_time_s:g} s, {r.near_step_s:g} s from a step of the "
        f"setpoint: given {r.pressure_kpa:g} kPa"
        for r in near.itertuples()
    ]
    if len(lines) > limit:
        more = (
            f"  ... and {len(lines) - limit + 1} more (the manifest's timestamp column has every "
            "photo's time)"
        )
        lines = [*lines[: limit - 1], more]
    n_flagged = int(settling(table["since_step_s"]).sum())
    flags = (
        f"; measure flags the {n_flagged} taken less than {NEAR_STEP_S:g} s after the pressure "
        "reached a level it held (the manifest's since_step_s)"
        if n_flagged
        else ""
    )
    head = (
        f"{len(near)} photo(s) were taken within {NEAR_STEP_S:g} s of a step of the log's "
        "setpoint, where a clock off by a second gives the level on the other side, and the "
        f"actuator may still be moving (check the clocks, and these photos' pressures{flags}):"
    )
    return [head, *lines]


def _opposite_sign_line(
    offset_s: float, camera_s: np.ndarray, steps: np.ndarray, n_near: int
) -> str:
    """A warning when the offset with its sign flipped would put clearly fewer photos near a step
    (a sign mistaken: the logger behind taken for ahead); '' otherwise.

    Examples
    --------
    >>> steps = np.arange(0.0, 100.0, 10.0)
    >>> camera_s = np.arange(10) * 10.0 + 2.5  # taken 2.5 s after each step by the camera
    >>> _opposite_sign_line(-3.0, camera_s, steps, 10)[:46]
    'is the sign of --clock-offset-s -3 right? With'
    >>> _opposite_sign_line(3.0, camera_s, steps, 0)
    ''
    """
    if offset_s == 0 or not steps.size:
        return ""
    flipped = int((_near_step(camera_s - offset_s, steps) < NEAR_STEP_S).sum())
    if flipped > SIGN_CHECK_SHARE * n_near or flipped > n_near - 3:
        return ""
    return (
        f"is the sign of --clock-offset-s {offset_s:g} right? With {-offset_s:g} (the opposite "
        f"sign: positive when the logger's clock is ahead of the camera's) {flipped} photo(s), "
        f"not {n_near}, would lie near a step of the setpoint, and those near a step would read "
        "the level on its other side. Photos taken mid-hold point to the opposite sign; photos "
        "taken just before each step (at the end of its hold) would look like this with the "
        "right one. Settle it with --log-time-at PHOTO=TIME: a photo of the logger's screen and "
        "the time it shows, with no sign to get wrong"
    )


def unheld_levels(manifest: pd.DataFrame) -> bool:
    """Whether the photos' pressures are mostly levels no other photo shares (of another trial,
    or of the other direction): a continuous ramp, read off a log, whose curves would have a
    point per photo.

    Examples
    --------
    >>> stepped = pd.DataFrame({"pressure_kpa": [0, 20, 40, 20, 0] * 2})
    >>> unheld_levels(stepped), unheld_levels(pd.DataFrame({"pressure_kpa": np.arange(10.0)}))
    (False, True)
    """
    counts = manifest["pressure_kpa"].value_counts()
    return len(manifest) >= 4 and bool((counts == 1).sum() > 0.5 * len(manifest))


def logged_row_doubts(
    folder: str | os.PathLike[str], manifest: pd.DataFrame
) -> list[tuple[object, str, str]]:
    """What ``check`` says, each time, of photos ``init`` placed on a pressure log (the
    manifest's :data:`LOG_RECORD_COLUMNS`): a pressure that is no longer the log's setpoint at
    the photo's log time (edited, or the log changed), a log time outside the log, and a photo
    taken near a step of the setpoint.  (The question of an offset's sign is ``init``'s: the
    manifest does not say how the clocks were related.)

    Parameters
    ----------
    folder : path
        The photo set's folder.
    manifest : pandas.DataFrame
        Its manifest, as loaded (``pressure_kpa`` read as numbers).

    Returns
    -------
    list of (index, what, fix)
        One per doubt: the manifest row's index, what is wrong, and the fix.
    """
    if not set(LOG_RECORD_COLUMNS) <= set(manifest.columns):
        return []
    out: list[tuple[object, str, str]] = []
    rows = manifest[manifest["pressure_log"].notna()]
    for name, g in rows.groupby(rows["pressure_log"].astype(str), sort=False):
        log, problems = read_pressure_log(Path(folder) / name)
        if log is None:
            out.append((g.index[0], f"pressure_log {name}: " + "; ".join(problems),
                        "put the log the photos were placed on back beside them"))
            continue
        t = pd.to_numeric(g["log_time_s"], errors="coerce").to_numpy(float)
        known = np.isfinite(t)
        setpoint = np.full(len(g), np.nan)
        setpoint[known] = log.pressure_kpa[_rows_in_force(log, t[known])]
        given = pd.to_numeric(g["pressure_kpa"], errors="coerce").to_numpy(float)
        steps = _noise_and_steps(log)[1]
        near = np.full(len(g), np.inf)
        near[known] = _near_step(t[known], steps)
        lo, hi = _held_span(log)
        flagged = (
            settling(g["since_step_s"]) if "since_step_s" in g else np.zeros(len(g), bool)
        )
        for i, ix in enumerate(g.index):
            if known[i] and not lo <= t[i] <= hi:
                what = f"log_time_s {t[i]:g} lies outside {name} ({span_text(log.span_s)})"
                out.append((ix, what, "run photoset init --pressure-log again"))
                continue
            if known[i] and abs(given[i] - setpoint[i]) > 0.01:
                what = (
                    f"pressure_kpa {given[i]:g} is not the setpoint of {name} at this photo's "
                    f"log time, {t[i]:g} s ({setpoint[i]:g} kPa): edited, or the log changed"
                )
                fix = (
                    "run photoset init --pressure-log again, or correct pressure_kpa (to keep an "
                    "edit made on purpose, empty this row's pressure_log)"
                )
                out.append((ix, what, fix))
            if near[i] < NEAR_STEP_S:
                what = (
                    f"taken {near[i]:.2g} s from a step of {name}'s setpoint: a clock off by a "
                    "second reads the level on the step's other side, and the actuator may still "
                    "be moving"
                )
                if flagged[i]:
                    what += f" (measure flags it: its since_step_s is {g['since_step_s'].iloc[i]})"
                fix = "check the clocks (photoset init --log-time-at) and this pressure"
                out.append((ix, what, fix))
    return out
