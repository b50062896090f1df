"""A logger's own clock in a pressure log: dates and clock times rather than seconds.

Loggers write the time their own way: one column of dates and clock times
(``2026-12-06 14:25:01.5``, ``2026-12-06T14:25:01+01:00``, ``06.12.2026 14:25:01,5``,
``12/06/2026 14:25:01``), a ``Date`` column beside a ``Time`` column (LabVIEW), or clock times
alone (``14:25:01.5``).  :func:`read_log_clock` reads any of these into seconds from the first
row and the first row's wall-clock time:

- a whole column is read one way: day first or month first is decided for the column (a day
  over 12 somewhere says which; dots are day first), never cell by cell;
- slashes whose every day and month is 12 or less read either way: both readings are kept, for
  the photos' own dates to decide (:mod:`pipeline.photo_log`);
- a time zone is kept while counting the seconds (a log across a change of summer time counts
  on), and the first row's own wall clock is its start;
- clock times alone have no date: the photos' dates give it, and a time that runs back by more
  than 12 hours has passed midnight.

Examples
--------
>>> df = pd.DataFrame({"Date": ["06.12.2026", "06.12.2026"], "Time": ["23:59:59,5", "00:00:01"]})
>>> clock, problems = read_log_clock(df.assign(Date=["06.12.2026", "07.12.2026"]), "log.csv")
>>> clock.time_s.tolist(), clock.start, clock.column, problems
([0.0, 1.5], datetime.datetime(2026, 12, 6, 23, 59, 59, 500000), 'Date + Time', [])
>>> read_log_clock(pd.DataFrame({"time": ["23:59:59", "00:00:01"]}), "log.csv")[0].time_s
array([0., 2.])
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from datetime import datetime, timedelta

import numpy as np
import pandas as pd

from pipeline.fileio import plain_name
from pipeline.measure.settings import user_floats

#: names of a column that may hold dates and clock times (any case)
DATED_TIME_NAMES: tuple[str, ...] = ("time", "timestamp", "datetime", "date_time", "date")
#: a date written day.month.year, or with slashes or dashes (either order), the rest after it
_NUMERIC_DATE = re.compile(r"\s*(\d{1,2})([./-])(\d{1,2})\2(\d{4}|\d{2})(?!\d)(.*)")
#: a clock time alone (``14:25:01.5``, ``2:25:01 PM``)
_CLOCK_TIME = re.compile(
    r"\s*(\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d*)?))?\s*([AaPp]\.?[Mm]\.?)?\s*"
)
#: a time zone at a cell's end
_ZONE = re.compile(r"(Z|[+-]\d{2}:?\d{2})\s*$")
#: the day used for clock times alone until the photos give theirs
UNDATED_DAY = datetime(2000, 1, 1)


@dataclass(frozen=True)
class LogClock:
    """A log's times read from its own clock.

    ``time_s`` counts seconds from the first row; ``start`` is the first row's wall clock (on
    :data:`UNDATED_DAY` when ``dated`` is False: clock times alone); ``start_dayfirst`` is the
    first row read day first when the dates read either way (else None); ``column`` names what
    was read (``'Timestamp'``, ``'Date + Time'``).
    """

    time_s: np.ndarray
    start: datetime
    column: str
    start_dayfirst: datetime | None = None
    dated: bool = True


def _hours(hour: int, half: str | None) -> int:
    """A clock's hour in 24: ``12 AM`` is 0, ``2 PM`` is 14."""
    if not half:
        return hour
    return hour % 12 + (12 if half[0].lower() == "p" else 0)


def _in_24_hours(text: str) -> str:
    """A cell's clock time written in 24 hours (``2:00:01 PM`` -> ``14:00:01``)."""

    def clock(m: re.Match[str]) -> str:
        return f"{_hours(int(m[1]), m[4]):02d}:{m[2]}" + (f":{m[3]}" if m[3] else "")

    return re.sub(
        r"(\d{1,2}):(\d{2})(?::(\d{2}(?:\.\d*)?))?\s*([AaPp]\.?[Mm]\.?)(?![A-Za-z])",
        clock,
        text,
    )


def read_clock_text(text: str) -> tuple[datetime, bool] | None:
    """One date and time, or clock time alone, read as a log's cells are (``--log-time-at``):
    the time and whether it has a date; None when it is neither.

    Examples
    --------
    >>> read_clock_text("06.12.2026 14:00:08,5")
    (datetime.datetime(2026, 12, 6, 14, 0, 8, 500000), True)
    >>> read_clock_text("2:00:01 PM")[0].time(), read_clock_text("lunch")
    (datetime.time(14, 0, 1), None)
    """
    clock, problems = read_log_clock(pd.DataFrame({"timestamp": [text]}), "")
    if clock is None or problems:
        return None
    return clock.start, clock.dated


def read_log_clock(df: pd.DataFrame, name: str) -> tuple[LogClock | None, list[str]]:
    """The log's clock from its time column(s), or None where it has none (its time is in
    seconds, or no column is named as a time), with the problems in words (a cell that is no
    date and time, naming its line).

    Parameters
    ----------
    df : pandas.DataFrame
        The log as read, its own column names.
    name : str
        The log's file name, for the problems.
    """
    values, column = _clock_cells(df)
    if values is None or np.isfinite(user_floats(values)).any():  # seconds with no unit
        return None, []
    cells = [_in_24_hours(re.sub(r"(\d:\d{2}),(\d)", r"\1.\2", str(v).strip())) for v in values]
    if all(_CLOCK_TIME.fullmatch(c) for c in cells):
        return _clock_times(cells, column), []
    readings = _numeric_date_readings(cells)
    stamps, start, problems = _parse(readings[0] if readings else cells, values, column, name)
    if stamps is None:
        return None, problems
    other = None
    if readings and len(readings) > 1:  # either way: both read, the likelier kept
        alt, alt_start, _ = _parse(readings[1], values, column, name)
        if alt is not None and np.array_equal(alt, stamps):
            other = alt_start  # the same times: the photos' dates decide
        elif alt is not None and _likelier(alt, stamps):
            stamps, start = alt, alt_start  # (a day-first log across midnight: 1 day, not 30)
    return LogClock(stamps, start, column, other), []


def _likelier(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether times ``a`` are a likelier reading of a log than ``b``: increasing where ``b`` is
    not, else over a shorter span."""
    a_up, b_up = bool(np.all(np.diff(a) >= 0)), bool(np.all(np.diff(b) >= 0))
    if a_up != b_up:
        return a_up
    return float(np.ptp(a)) < float(np.ptp(b))


def _clock_cells(df: pd.DataFrame) -> tuple[pd.Series | None, str]:
    """The cells holding the log's clock: a Date and a Time column joined, else the one column
    named as a time."""
    plain = {plain_name(str(c)): c for c in df.columns}
    if "date" in plain and "time" in plain:
        joined = df[plain["date"]].astype(str) + " " + df[plain["time"]].astype(str)
        return joined, f"{plain['date']} + {plain['time']}"
    named = [c for p, c in plain.items() if p in DATED_TIME_NAMES]
    if len(named) != 1:
        return None, ""
    return df[named[0]], str(named[0])


def _clock_times(cells: list[str], column: str) -> LogClock:
    """Clock times alone: seconds since midnight, on past midnight where they run back more than
    12 hours."""
    seconds = []
    for c in cells:
        m = _CLOCK_TIME.fullmatch(c)
        assert m is not None
        seconds.append(_hours(int(m[1]), m[4]) * 3600 + int(m[2]) * 60 + float(m[3] or 0))
    s = np.asarray(seconds, float)
    s = s + 86400.0 * np.concatenate([[0], np.cumsum(np.diff(s) < -43200)])
    return LogClock(s - s[0], UNDATED_DAY + timedelta(seconds=float(s[0])), column, dated=False)


def _numeric_date_readings(cells: list[str]) -> list[list[str]]:
    """Cells whose dates are written with dots or slashes, rewritten year-month-day: the one
    reading the column allows, or two (month first, then day first) where every day and month is
    12 or less and the dates use slashes; [] for other dates."""
    found = [_NUMERIC_DATE.fullmatch(c) for c in cells]
    if not found or not all(found):
        return []
    first = [int(m[1]) for m in found if m]
    second = [int(m[3]) for m in found if m]
    dots = all(m[2] == "." for m in found if m)

    def iso(day_first: bool) -> list[str]:
        out = []
        for m in found:
            assert m is not None
            a, b, year = int(m[1]), int(m[3]), m[4]
            day, month = (a, b) if day_first else (b, a)
            full_year = int(year) + 2000 if len(year) == 2 else int(year)
            out.append(f"{full_year}-{month:02d}-{day:02d}{m[5]}")
        return out

    if max(first) > 12 or dots:
        return [iso(True)]
    if max(second) > 12:
        return [iso(False)]
    return [iso(False), iso(True)]


def _parse(
    cells: list[str], written: pd.Series, column: str, name: str
) -> tuple[np.ndarray | None, datetime, list[str]]:
    """Seconds from the first row, the first row's wall clock, and the problems."""
    zoned = any(_ZONE.search(c) for c in cells)
    stamps = pd.to_datetime(pd.Series(cells), errors="coerce", format="ISO8601", utc=zoned)
    if stamps.isna().any() and not stamps.notna().any():
        stamps = pd.to_datetime(pd.Series(cells), errors="coerce", format="mixed", utc=zoned)
    bad = np.flatnonzero(stamps.isna().to_numpy())
    if bad.size:
        i = int(bad[0])
        problem = (
            f"{name} line {i + 2}: {column} {written.iloc[i]!r} is not a date and time (like "
            "2026-12-06 14:25:01.5)"
        )
        return None, UNDATED_DAY, [problem]
    start = pd.Timestamp(cells[0])
    if start.tzinfo is not None:  # the first row's own wall clock
        start = start.tz_localize(None)
    seconds = (stamps - stamps.iloc[0]).dt.total_seconds().to_numpy(float)
    return seconds, start.to_pydatetime(), []
