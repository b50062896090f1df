"""Start a photo set from a folder of photos: a manifest built from the image file names.

``python -m pipeline photoset init DIR --pattern
'{material}_{actuator}_t{trial}_{pressure_kpa}kPa.jpg'`` writes ``manifest.csv`` (and a starter
``photoset.yaml``); see :func:`init_photoset`.  ``--pressure-log`` makes a video photo set
instead, one row per video (:func:`init_video_photoset`).
"""

from __future__ import annotations

import fnmatch
import os
import re
import unicodedata
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.constants import DIRECTION_WORDS, RAMP_KEYS
from pipeline.errors import UserInputError
from pipeline.measure.formats import undecodable, unreadable_format
from pipeline.photo_log import PLACEMENT_ONLY_COLUMNS, ClockSync, PhotoPlacement, place_photos
from pipeline.photoset import (
    MANIFEST,
    SETTINGS,
    files_named_in,
    named_files,
    photo_names,
    write_manifest,
    write_settings,
)
from pipeline.video.reader import sequence_files
from pipeline.video.timeline import read_pressure_log

#: file endings taken for videos (any OpenCV reads): a pattern matching only these needs
#: ``--pressure-log``
VIDEO_SUFFIXES: tuple[str, ...] = (
    ".avi", ".mp4", ".mov", ".mkv", ".m4v", ".wmv", ".mpg", ".mpeg", ".webm",
)

#: photos read off a sensor's noisy log within this (kPa) sit at one level, as far as where a
#: ramp starts is concerned
SENSOR_LEVEL_KPA = 1.0

_FIELD_PATTERNS: dict[str, str] = {
    "pressure_kpa": r"[-+]?\d+(?:[.,p]\d+)?",
    "measured_pressure_kpa": r"[-+]?\d+(?:[.,p]\d+)?",
    "step": r"\d+",
    "trial": r"[A-Za-z0-9]+",
    "actuator": r"[A-Za-z0-9]+",
    "material": r"[A-Za-z0-9]+",
    "direction": r"[A-Za-z]+",
    "_": r".*?",
}

def _decimal(text: str) -> float:
    """A pressure from a file name: ``12.5``, ``12,5`` or ``12p5``.

    >>> _decimal("12,5"), _decimal("12P5"), _decimal("-3")
    (12.5, 12.5, -3.0)
    """
    return float(text.lower().replace("p", ".").replace(",", "."))


def ramp_pressures(spec: str) -> tuple[float, ...]:
    """The pressures (kPa) of one ramp's photos in order, from ``--pressures-kpa``: a list
    ``0,20,40,20,0``, or ``LOW:HIGH:STEP`` for up from LOW to HIGH and back down to LOW.

    Examples
    --------
    >>> ramp_pressures("0:60:20")
    (0.0, 20.0, 40.0, 60.0, 40.0, 20.0, 0.0)
    >>> ramp_pressures("0, 10, 25.5")
    (0.0, 10.0, 25.5)

    Raises
    ------
    UserInputError
        When it is neither.
    """
    fix = (
        "give the pressures of one ramp's photos in order (0,20,40,20,0), or LOW:HIGH:STEP "
        "(0:180:20 goes up to 180 and back down to 0)"
    )
    try:
        if ":" in spec:
            low, high, step = (float(v) for v in spec.split(":"))
            if not (step > 0 and high > low):
                raise ValueError(spec)
            up = [low + i * step for i in range(int(np.floor((high - low) / step + 1e-9)) + 1)]
            if not np.isclose(up[-1], high):
                raise ValueError(spec)
            return tuple(float(round(v, 9)) for v in up + up[-2::-1])
        values = tuple(float(v) for v in spec.split(","))
    except ValueError:
        raise UserInputError(f"--pressures-kpa {spec!r} cannot be read; {fix}") from None
    return values


def natural_key(name: str) -> tuple[str | int, ...]:
    """Sort key of a file name with its numbers as numbers (``IMG_9`` before ``IMG_10``).

    >>> sorted(["IMG_10.JPG", "IMG_9.JPG", "IMG_1.JPG"], key=natural_key)
    ['IMG_1.JPG', 'IMG_9.JPG', 'IMG_10.JPG']
    """
    parts = re.split(r"(\d+)", name)
    return tuple(int(p) if i % 2 else p.lower() for i, p in enumerate(parts))


def pattern_to_regex(pattern: str, *, pressure_in_name: bool = True) -> re.Pattern[str]:
    """Compile a file-name pattern such as
    ``'{material}_{actuator}_t{trial}_{pressure_kpa}kPa.jpg'``.

    Fields: ``pressure_kpa``, ``direction``, ``trial``, ``actuator``, ``material``, ``step``,
    ``measured_pressure_kpa`` and ``_`` (anything, ignored); ``*`` matches anything too.
    Decimal points in pressures may be written ``p`` or ``,`` (``12p5``, ``12,5`` = 12.5 kPa).
    Letters match in either case (``kPa`` or ``kpa``, ``.jpg`` or a camera's ``.JPG``).

    Examples
    --------
    >>> pattern_to_regex("{actuator}_{pressure_kpa}kPa.jpg").match("A1_12P5KPA.JPG")["pressure_kpa"]
    '12P5'

    Raises
    ------
    UserInputError
        On an unknown field, or a pattern without ``{pressure_kpa}`` (with one, when
        ``pressure_in_name`` is False: the pressures are given otherwise).
    """
    out, pos = [], 0
    names = []
    pattern = unicodedata.normalize("NFC", pattern)  # names are matched in NFC too
    for m in re.finditer(r"\{([A-Za-z_]+)\}", pattern):
        out.append(re.escape(pattern[pos : m.start()]).replace(r"\*", ".*?"))
        name = m.group(1)
        if name not in _FIELD_PATTERNS:
            raise UserInputError(
                f"pattern field {{{name}}} is unknown; use {sorted(_FIELD_PATTERNS)}"
            )
        if name == "_":
            out.append(_FIELD_PATTERNS["_"])
        else:
            if name in names:
                raise UserInputError(f"pattern field {{{name}}} appears twice")
            names.append(name)
            out.append(f"(?P<{name}>{_FIELD_PATTERNS[name]})")
        pos = m.end()
    out.append(re.escape(pattern[pos:]).replace(r"\*", ".*?"))
    if pressure_in_name and "pressure_kpa" not in names:
        raise UserInputError(
            f"pattern {pattern!r} has no {{pressure_kpa}} field; put it where the file names hold "
            "the pressure, or (a camera's IMG_0001.JPG) give each ramp's pressures in photo order "
            "with --pressures-kpa, e.g. 0:180:20 for 0, 20, ..., 180 and back down to 0, or "
            "read them from a pressure log at each photo's time with --pressure-log LOG.csv"
        )
    if not pressure_in_name and "pressure_kpa" in names:
        raise UserInputError(
            f"pattern {pattern!r} has a {{pressure_kpa}} field and --pressures-kpa (or "
            "--pressure-log) gives them too; use one of the two"
        )
    return re.compile("".join(out) + r"\Z", re.IGNORECASE)  # kPa or kpa, .jpg or .JPG


def init_photoset(
    folder: str | os.PathLike[str],
    pattern: str,
    *,
    defaults: Mapping[str, Any] | None = None,
    settings: Mapping[str, Any] | None = None,
    overwrite: bool = False,
    pressures_kpa: Sequence[float] | Mapping[str | None, Sequence[float]] | None = None,
    leave_out: Sequence[str] = (),
) -> pd.DataFrame:
    """Write a starter ``manifest.csv`` (and ``photoset.yaml`` if absent) from image file names.

    Fields missing from the pattern come from ``defaults`` (``material``, ``actuator``,
    ``trial``).  When the pattern has no ``{direction}``, it is inferred per actuator and trial
    from the order of the photos (by ``step`` if present, else by file name): ``up`` until the
    highest pressure, ``down`` after it (all ``up`` when the pressure never falls).  Photos of
    several ramps taken one after another in one folder (no ``{trial}`` in the pattern) are
    split into trials: by the trials' own
    ``pressures_kpa``, given in the order they were taken, whose photo counts add up to the
    folder's (keyed ``actuator/trial`` over several actuators, with no ``{actuator}`` in the
    pattern either: each actuator's ramps too); or, with one list for them all, wherever the
    pressure has come back down to the lowest of its ramp and rises again
    (:func:`ramp_starts`).  A photo the settings name (``background``, a calibration board) is
    not one of a ramp.

    Parameters
    ----------
    folder : path
        Folder holding the photos.
    pattern : str
        File-name pattern, see :func:`pattern_to_regex`.
    defaults : mapping, optional
        Values for fields the pattern lacks.
    settings : mapping, optional
        ``photoset.yaml`` values to write when that file does not exist yet.
    overwrite : bool
        Replace an existing ``manifest.csv``.
    pressures_kpa : sequence of float, or mapping, optional
        For file names without the pressure (a camera's ``IMG_0001.JPG``): the pressures of each
        ramp's photos in order (:func:`ramp_pressures`); every actuator and trial must have as
        many photos, taken in that order (by ``step`` if the pattern has it, else by file name,
        numbers as numbers).  A mapping gives ramps their own (:func:`pressure_specs`): keyed by
        trial label, or ``actuator/trial``, or None for every other ramp.

    leave_out : sequence of str
        Photos in the folder that are no ramp's (each actuator's own empty scene).
    Returns
    -------
    pandas.DataFrame
        The manifest written.

    Raises
    ------
    UserInputError
        If no file matches, a field is missing with no default, or a manifest exists.
    """
    return _init_photoset(
        folder,
        pattern,
        defaults=defaults,
        settings=settings,
        overwrite=overwrite,
        pressures_kpa=pressures_kpa,
        leave_out=leave_out,
    )[0]


def init_logged_photoset(
    folder: str | os.PathLike[str],
    pattern: str,
    pressure_log: str,
    sync: ClockSync,
    *,
    defaults: Mapping[str, Any] | None = None,
    settings: Mapping[str, Any] | None = None,
    overwrite: bool = False,
    leave_out: Sequence[str] = (),
) -> tuple[pd.DataFrame, PhotoPlacement]:
    """Write a starter ``manifest.csv`` (and ``photoset.yaml`` if absent) of photos whose
    pressures come from a pressure log, read at the time each photo was taken
    (:func:`pipeline.photo_log.place_photos`).

    Each photo gets the setpoint in force, the measured pressure (when logged), the direction and
    its ``timestamp``; the photos go in the order taken, and ramps taken one after another (no
    ``{trial}`` in the pattern) split into trials where the pressure, back at its lowest, rises
    again.  Photos in a gap of the log are left out.

    Parameters
    ----------
    folder, pattern, defaults, settings, overwrite, leave_out
        As for :func:`init_photoset` (the pattern holds no ``{pressure_kpa}``).
    pressure_log : str
        The log's name in ``folder``.
    sync : ClockSync
        How the camera's clock maps onto the log's.

    Returns
    -------
    tuple of (pandas.DataFrame, PhotoPlacement)
        The manifest written, and the placement (its lines for the user).

    Raises
    ------
    UserInputError
        As :func:`init_photoset` and :func:`pipeline.photo_log.place_photos`; then no manifest
        is written.
    """
    df, placement = _init_photoset(
        folder,
        pattern,
        defaults=defaults,
        settings=settings,
        overwrite=overwrite,
        leave_out=leave_out,
        pressure_log=(pressure_log, sync),
    )
    assert placement is not None
    return df, placement


def _init_photoset(
    folder: str | os.PathLike[str],
    pattern: str,
    *,
    defaults: Mapping[str, Any] | None,
    settings: Mapping[str, Any] | None,
    overwrite: bool,
    leave_out: Sequence[str],
    pressures_kpa: Sequence[float] | Mapping[str | None, Sequence[float]] | None = None,
    pressure_log: tuple[str, ClockSync] | None = None,
) -> tuple[pd.DataFrame, PhotoPlacement | None]:
    """:func:`init_photoset` and :func:`init_logged_photoset`: the manifest written, and the
    placement on the log (None without one)."""
    folder = _new_manifest_folder(folder, overwrite)
    if names_videos(folder, pattern):
        videos = _matching_videos(folder, pattern)
        raise UserInputError(
            (f"{folder / videos[0]} is a video" if videos else f"{pattern!r} names a video's "
             "frames")
            + ": give its pressure log with --pressure-log (a video photo set, one row per "
            "video: README, 'Videos')"
        )
    regex = pattern_to_regex(
        pattern, pressure_in_name=pressures_kpa is None and pressure_log is None
    )
    defaults = {"material": None, "actuator": "A1", "trial": "1", **(defaults or {})}
    # the empty scene and calibration boards the settings name are no photos of a ramp
    named = files_named_in(folder, dict(settings or {}), pd.DataFrame()) | named_files(folder)
    named |= {(folder / name).resolve() for name in leave_out}
    rows, unmatched = [], []
    for name in sorted(photo_names(folder, subfolders="/" in pattern), key=natural_key):
        if (folder / name).resolve() in named:
            continue
        m = regex.match(unicodedata.normalize("NFC", name))  # a Mac's NFD names
        if not m:
            unmatched.append(name)
            continue
        fields = m.groupdict()
        row: dict[str, Any] = {"image": name, **_ramp_keys(name, fields, defaults)}
        if pressures_kpa is None and pressure_log is None:
            row["pressure_kpa"] = _decimal(fields["pressure_kpa"])
        if fields.get("step") is not None:
            row["step"] = int(fields["step"])
        if fields.get("measured_pressure_kpa") is not None:
            row["measured_pressure_kpa"] = _decimal(fields["measured_pressure_kpa"])
        if fields.get("direction") is not None:
            word = fields["direction"].lower()
            if word not in DIRECTION_WORDS:
                raise UserInputError(
                    f"{name}: direction {fields['direction']!r} unknown; use up/down (or "
                    "inc/dec)"
                )
            row["direction"] = DIRECTION_WORDS[word]
        rows.append(row)
    if not rows:
        unreadable = sorted(
            p.relative_to(folder).as_posix()
            for p in (folder.rglob("*") if "/" in pattern else folder.iterdir())
            if unreadable_format(p.name)
        )
        raise UserInputError(
            f"no image in {folder} matches pattern {pattern!r}"
            + (f" (e.g. {unmatched[0]!r} does not)" if unmatched else " (no images found)")
            + (
                f"; it holds {len(unreadable)} photo(s) such as {unreadable[0]!r}: "
                + "{}; {}".format(*undecodable(unreadable[0]))
                if unreadable
                else ""
            )
        )
    df = pd.DataFrame(rows)
    trials_in_names = "trial" in regex.groupindex
    if pressures_kpa is not None:
        df = _with_pressures(
            df,
            {k: tuple(v) for k, v in pressures_kpa.items()}
            if isinstance(pressures_kpa, Mapping)
            else {None: tuple(pressures_kpa)},
            trials_in_order=not trials_in_names,
            actuators_in_order="actuator" not in regex.groupindex,
        )
        if not trials_in_names and "direction" not in df.columns:
            df = _split_ramps(df)
    placement = None
    if pressure_log is not None:
        placement = place_photos(folder, df["image"].tolist(), *pressure_log)
        logged = placement.table
        given = [c for c in logged.columns if c != "image"]  # the log's, not the names'
        df = df.drop(columns=given, errors="ignore").merge(logged, on="image")  # gaps' go
        df["pressure_log"] = pressure_log[0]  # the record check reads the log again by
        df = df.sort_values("log_time_s", kind="stable").reset_index(drop=True)
        if not trials_in_names:
            df = df.drop(columns=["step"], errors="ignore")
            df = _split_by_trend(df) if placement.sensor_only else _split_ramps(df)
        df["direction"] = _rising_from_the_start(df, placement.sensor_only)
    if "direction" not in df.columns:
        df["direction"] = _infer_directions(df)
    if "step" not in df.columns:
        df["step"] = df.groupby(list(RAMP_KEYS), sort=False).cumcount()
    write_manifest(folder, df.drop(columns=list(PLACEMENT_ONLY_COLUMNS), errors="ignore"))
    if not (folder / SETTINGS).exists():
        write_settings(folder, {"l0_mm": None, **dict(settings or {})})
    return df, placement


def backgrounds_by_actuator(
    folder: str | os.PathLike[str], pattern: str, actuators: Sequence[str]
) -> dict[str, str]:
    """Each actuator's photo of the empty scene: ``pattern`` (a name in ``folder``, ``*`` and
    ``?`` allowed) with ``{actuator}`` standing for its label; exactly one file must match.

    Raises
    ------
    UserInputError
        Naming the actuator, the pattern and what matched.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("A1/empty_0146.JPG", "A2/empty_0101.JPG"):
    ...     (root / name).parent.mkdir(exist_ok=True); _ = (root / name).write_bytes(b"")
    >>> backgrounds_by_actuator(root, "{actuator}/empty_*.JPG", ["A1", "A2"])
    {'A1': 'A1/empty_0146.JPG', 'A2': 'A2/empty_0101.JPG'}
    """
    root = Path(folder)
    out = {}
    for actuator in actuators:
        wanted = pattern.replace("{actuator}", str(actuator))
        found = sorted(p.relative_to(root).as_posix() for p in root.glob(wanted) if p.is_file())
        if len(found) != 1:
            raise UserInputError(
                f"--background {pattern}: actuator {actuator} has "
                + (f"{len(found)} photos of the empty scene ({', '.join(found[:3])})" if found
                   else f"no photo of the empty scene ({wanted} matches nothing in {root})")
                + "; give each actuator exactly one (or one --background FILE for the set)"
            )
        out[str(actuator)] = found[0]
    return out


def init_video_photoset(
    folder: str | os.PathLike[str],
    pattern: str,
    pressure_log: str,
    *,
    clock_offset_s: float | None = None,
    fps: float | None = None,
    defaults: Mapping[str, Any] | None = None,
    settings: Mapping[str, Any] | None = None,
    overwrite: bool = False,
) -> pd.DataFrame:
    """Write a starter ``manifest.csv`` of a video photo set, one row per video matching
    ``pattern``, or one row of the frame sequence ``pattern`` names (``frame_%04d.jpg``), and
    ``photoset.yaml`` if absent.

    Parameters
    ----------
    folder : path
        Folder holding the videos and their pressure logs.
    pattern : str
        File-name pattern of the videos (:func:`pattern_to_regex`'s fields but
        ``{pressure_kpa}``: ``{material}``, ``{actuator}``, ``{trial}``, ``*``).
    pressure_log : str
        The pressure log's name in ``folder``; ``{video}`` in it stands for each video's name
        without its ending (``{video}_pressure.csv``).
    clock_offset_s : float, optional
        The log's time at each video's first frame (s), written as ``clock_offset_s``.
    fps : float, optional
        The frames' rate, written as ``fps`` (a frame sequence has none of its own).
    defaults, settings, overwrite
        As for :func:`init_photoset`.

    Returns
    -------
    pandas.DataFrame
        The manifest written.

    Raises
    ------
    UserInputError
        If no video matches, a video's log is missing or cannot be read
        (:func:`pipeline.video.timeline.read_pressure_log`), a field has no default, or a
        manifest exists.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> _ = (root / "GX010071.MP4").write_bytes(b"")
    >>> _ = (root / "GX010071_log.csv").write_text("t (s),Setpoint (kPa)\\n0,0\\n9,80\\n")
    >>> init_video_photoset(root, "GX*.MP4", "{video}_log.csv", clock_offset_s=0.5,
    ...                     defaults={"material": "DS20"}).to_dict("records")
    [{'video': 'GX010071.MP4', 'pressure_log': 'GX010071_log.csv', 'material': 'DS20', \
'actuator': 'A1', 'trial': '1', 'clock_offset_s': 0.5}]

    Several videos of one actuator, the pattern naming no trial, are its trials in name order
    (each was trial 1, and ``check`` refused the manifest it had just written):

    >>> _ = (root / "GX010072.MP4").write_bytes(b"")
    >>> _ = (root / "GX010072_log.csv").write_text("t (s),Setpoint (kPa)\\n0,0\\n9,80\\n")
    >>> init_video_photoset(root, "GX*.MP4", "{video}_log.csv", defaults={"material": "DS20"},
    ...                     overwrite=True)[["video", "trial"]].to_dict("records")
    [{'video': 'GX010071.MP4', 'trial': '1'}, {'video': 'GX010072.MP4', 'trial': '2'}]
    """
    folder = _new_manifest_folder(folder, overwrite)
    regex = pattern_to_regex(pattern, pressure_in_name=False)
    given_defaults = defaults
    defaults = {"material": None, "actuator": "A1", "trial": "1", **(defaults or {})}
    rows = []
    frames = sequence_files(folder / pattern)
    if frames is None:
        names = _matching_videos(folder, pattern)
    else:  # a frame sequence is one video
        names = [pattern] if frames else []
    for name in names:
        m = regex.match(unicodedata.normalize("NFC", name))  # a Mac's NFD names
        if not m:
            continue
        log = pressure_log.replace("{video}", Path(name).stem)
        if not (folder / log).is_file():
            raise UserInputError(
                f"{name}: its pressure log {log} is not in {folder}; put the log (a CSV with "
                "time_s and pressure_kpa) beside the video and give its name with --pressure-log"
            )
        _, problems = read_pressure_log(folder / log)
        if problems:  # said now, not first by check
            raise UserInputError(f"{name}: " + "; ".join(problems))
        row: dict[str, Any] = {"video": name, "pressure_log": log}
        row |= _ramp_keys(name, m.groupdict(), defaults)
        if clock_offset_s is not None:
            row["clock_offset_s"] = clock_offset_s
        if fps is not None:
            row["fps"] = fps
        rows.append(row)
    if not rows:
        raise UserInputError(
            f"no file in {folder} is a frame of the sequence {pattern!r} (its number where the "
            "pattern has %04d, or %d unpadded)"
            if frames is not None
            else f"no video in {folder} matches pattern {pattern!r} (videos end in "
            f"{', '.join(VIDEO_SUFFIXES)}; a frame sequence is named like frame_%04d.jpg)"
        )
    df = pd.DataFrame(rows)
    if "trial" not in regex.groupindex and "trial" not in (given_defaults or {}):
        keys = ["material", "actuator"]
        shared = df.groupby(keys, dropna=False)["video"].transform("size") > 1
        df.loc[shared, "trial"] = (df[shared].groupby(keys, dropna=False).cumcount() + 1).astype(
            str
        )
    write_manifest(folder, df)
    if not (folder / SETTINGS).exists():
        write_settings(folder, {"l0_mm": None, **dict(settings or {})})
    return df


def _new_manifest_folder(folder: str | os.PathLike[str], overwrite: bool) -> Path:
    """``folder`` as a path, checked to be a folder whose manifest may be written."""
    folder = Path(folder)
    if not folder.is_dir():
        raise UserInputError(f"{folder}: not a folder; give the folder that holds the photos")
    if (folder / MANIFEST).exists() and not overwrite:
        raise UserInputError(f"{folder / MANIFEST} already exists; pass --overwrite to replace it")
    return folder


def names_videos(folder: str | os.PathLike[str], pattern: str) -> bool:
    """Whether ``pattern`` names videos in ``folder`` (and no photo), or frames cut from one
    (``frame_%04d.jpg``): a video photo set's."""
    root = Path(folder)
    if sequence_files(root / pattern) is not None:
        return True
    return bool(_matching_videos(root, pattern)) and not any(
        fnmatch_name(n, pattern) for n in photo_names(root, "/" in pattern)
    )


def _matching_videos(folder: Path, pattern: str) -> list[str]:
    """The videos in ``folder`` (its subfolders with a ``/`` in ``pattern``) whose names match
    ``pattern`` with every field a wildcard, in name order (numbers as numbers)."""
    paths = folder.rglob("*") if "/" in pattern else folder.iterdir()
    names = (p.relative_to(folder).as_posix() for p in paths if p.is_file())
    return sorted(
        (n for n in names if n.lower().endswith(VIDEO_SUFFIXES) and fnmatch_name(n, pattern)),
        key=natural_key,
    )


def fnmatch_name(name: str, pattern: str) -> bool:
    """Whether ``name`` matches ``pattern`` with each ``{field}`` and ``*`` a wildcard (any case).

    Examples
    --------
    >>> fnmatch_name("GX010071.AVI", "GX*.avi"), fnmatch_name("A1_20kPa.jpg", "{actuator}_*.png")
    (True, False)
    """
    return fnmatch.fnmatch(name.lower(), re.sub(r"\{[A-Za-z_]+\}", "*", pattern).lower())


def _ramp_keys(name: str, fields: Mapping[str, Any], defaults: Mapping[str, Any]) -> dict:
    """``material``, ``actuator`` and ``trial`` of a file from its name's ``fields``, else from
    ``defaults``."""
    row = {}
    for key in RAMP_KEYS:
        row[key] = fields.get(key) or defaults.get(key)
        if row[key] is None:
            raise UserInputError(f"{name}: no {key} in the file name and no default; pass --{key}")
    return row


def pressure_specs(specs: Sequence[str]) -> dict[str | None, tuple[float, ...]]:
    """Each ``--pressures-kpa`` read: ``SPEC`` for every ramp, or ``LABEL=SPEC`` for the ramps of
    trial ``LABEL`` (or ``actuator/trial``), whose photos may be more or fewer.

    Examples
    --------
    >>> pressure_specs(["1=0:40:20", "A2/1=0,5", "0:20:20"])
    {'1': (0.0, 20.0, 40.0, 20.0, 0.0), 'A2/1': (0.0, 5.0), None: (0.0, 20.0, 0.0)}
    """
    out: dict[str | None, tuple[float, ...]] = {}
    for spec in specs:
        label, _, values = spec.rpartition("=")
        key = label.strip() or None
        if key in out:
            raise UserInputError(
                f"--pressures-kpa {spec!r}: "
                + ("a second spec for every ramp" if key is None else f"{key} is given twice")
                + "; give each ramp's pressures once (TRIAL=SPEC for a trial of its own)"
            )
        out[key] = ramp_pressures(values)
    return out


def _with_pressures(
    df: pd.DataFrame,
    pressures_kpa: Mapping[str | None, tuple[float, ...]],
    *,
    trials_in_order: bool = False,
    actuators_in_order: bool = False,
) -> pd.DataFrame:
    """``df`` with each ramp's photos given its pressures in order (by step, else by name):
    those of its ``actuator/trial``, else of its trial, else those for every ramp (key None).

    With ``trials_in_order`` (the file names hold no trial), a group whose photo count is the sum
    of the trials' own specs (two or more, keyed ``trial`` or ``actuator/trial``) is split in
    photo order: the first spec's trial takes the first photos, and so on.  With
    ``actuators_in_order`` too (nor the actuator) and specs naming several actuators, every
    spec's ramp is taken in that order, its actuator with it.
    """
    out = df.copy()
    out["pressure_kpa"] = np.nan
    for (material, actuator, trial), g in out.groupby(
        list(RAMP_KEYS), sort=False
    ):
        order = g.sort_values("step") if "step" in g.columns else g
        ramp = f"material {material}, actuator {actuator}, trial {trial}"
        keyed = [
            (key.rpartition("/")[0] or str(actuator), key.rpartition("/")[2], values)
            for key, values in pressures_kpa.items()
            if key is not None
        ]
        # the actuators, too, one after another in one folder (no actuator in the names): every
        # ramp's spec in the order given; else this actuator's
        own = (
            keyed
            if actuators_in_order and len({a for a, _, _ in keyed}) > 1
            else [k for k in keyed if k[0] == str(actuator)]
        )
        if trials_in_order and len(own) > 1 and len(order) == sum(len(v) for _, _, v in own):
            start = 0  # ramps taken one after another: the first ramp's photos come first
            for ramp_actuator, label, values in own:
                rows = order.index[start : start + len(values)]
                out.loc[rows, "pressure_kpa"] = values
                out.loc[rows, "actuator"] = ramp_actuator
                out.loc[rows, "trial"] = label
                start += len(values)
            continue
        if trials_in_order and len(own) > 1:
            several = len({a for a, _, _ in own}) > 1
            counts = ", ".join(
                f"{a + '/' if several else ''}{label}: {len(v)}" for a, label, v in own
            )
            raise UserInputError(
                f"material {material}"
                + ("" if several else f", actuator {actuator}")
                + f": {len(order)} photo(s) ({order['image'].iloc[0]} ... "
                f"{order['image'].iloc[-1]}) but the "
                + ("ramps'" if several else "trials'")
                + f" --pressures-kpa give {sum(len(v) for _, _, v in own)} pressures ({counts}); "
                "taken one after another in one folder, the ramps' photos must add up to its "
                "photos: a photo missing, deleted or extra (move it out), or a spec that is not "
                "the ramp's"
            )
        key = next(
            (k for k in (f"{actuator}/{trial}", str(trial), None) if k in pressures_kpa), "none"
        )
        if key == "none":
            raise UserInputError(
                f"{ramp} ({order['image'].iloc[0]} ...): no --pressures-kpa for it; add "
                f"--pressures-kpa {trial}=SPEC (or one SPEC for every ramp)"
            )
        pressures = pressures_kpa[key]
        if len(order) != len(pressures):
            raise UserInputError(
                f"{ramp} has {len(order)} "
                f"photo(s) ({order['image'].iloc[0]} ... {order['image'].iloc[-1]}) but "
                "--pressures-kpa "
                + ("" if key is None else f"{key}=... ")
                + f"gives {len(pressures)} pressures; give one pressure per photo of a ramp (a "
                "missing or extra photo: add or move it; a trial of its own length: "
                f"--pressures-kpa {trial}=SPEC"
                + (
                    "; trials taken one after another in this folder: each trial's spec, in the "
                    "order they were taken (--pressures-kpa 1=0:180:20 --pressures-kpa "
                    f"2=0:200:20), whose photos add up to its {len(order)}"
                    if trials_in_order
                    else ""
                )
                + "; or write the manifest by hand)"
            )
        out.loc[order.index, "pressure_kpa"] = pressures
    return out


def ramp_starts(pressures_kpa: Sequence[float]) -> list[int]:
    """Where each ramp begins in the pressures of ramps taken one after another.

    A new ramp begins where the pressure, having come back down to the lowest of its ramp so far,
    rises again; a pressure repeated at that bottom (the last photo of one ramp, the first of the
    next) begins the new ramp. A hold or a repeated photo on the way (two photos at 180, or at
    140 going down) and a minor loop that turns back up above the ramp's start do not.

    Examples
    --------
    >>> ramp_starts([0, 20, 40, 20, 0, 0, 30, 60, 30, 0])
    [0, 5]
    >>> ramp_starts([0, 20, 0, 20, 0])  # no photo repeated at the bottom
    [0, 3]
    >>> ramp_starts([0, 40, 80, 40, 60, 80, 40, 0, 0, 0])  # a minor loop, zeros at the end
    [0]
    """
    p = [float(v) for v in pressures_kpa]
    starts, fell = [0], False
    for i in range(1, len(p)):
        if p[i] < p[i - 1]:
            fell = True
        elif p[i] > p[i - 1] and fell and p[i - 1] <= min(p[starts[-1] : i]):
            repeated = i - 2 >= starts[-1] and p[i - 2] == p[i - 1]
            starts.append(i - 1 if repeated else i)
            fell = False
    return starts


def _split_ramps(df: pd.DataFrame) -> pd.DataFrame:
    """Each ramp of a group holding several (:func:`ramp_starts`, photo order) as a trial of its
    own: labels counted on from the group's (``1`` -> ``1``, ``2``, ...; ``x`` -> ``x-1``, ...)."""
    out = df.copy()
    for (_, _, trial), g in df.groupby(list(RAMP_KEYS), sort=False):
        order = g.sort_values("step") if "step" in g.columns else g
        starts = ramp_starts(order["pressure_kpa"].tolist())
        if len(starts) == 1:
            continue
        for k, (a, b) in enumerate(zip(starts, [*starts[1:], len(order)], strict=True)):
            label = str(int(trial) + k) if str(trial).isdigit() else f"{trial}-{k + 1}"
            out.loc[order.index[a:b], "trial"] = label
    return out


def _split_by_trend(df: pd.DataFrame) -> pd.DataFrame:
    """Each ramp of a group (photo order) as a trial of its own, a new one where the direction
    turns from ``down`` to ``up``: for pressures read off a sensor, whose noise hides which
    photos share the lowest level (:func:`_split_ramps` compares them).

    Photos ``down`` before the group's first ``up`` one (at rest, after another actuator's
    ramps) start its first ramp; the last of two photos at the bottom between two ramps (within
    :func:`sensor_level_kpa` of each other) starts the next, as :func:`ramp_starts` has it.

    Examples
    --------
    >>> df = pd.DataFrame({"material": "m", "actuator": "a", "trial": "1",
    ...                    "direction": ["down", "up", "up", "down", "down", "up", "down"],
    ...                    "pressure_kpa": [0.1, 20, 40, 20, 0.2, 20, 0]})
    >>> _split_by_trend(df)["trial"].tolist()
    ['1', '1', '1', '1', '1', '2', '2']
    >>> _split_by_trend(df.assign(pressure_kpa=[0.1, 20, 40, 0.3, 0.2, 20, 0]))["trial"].tolist()
    ['1', '1', '1', '1', '2', '2', '2']
    """
    out = df.copy()
    for (_, _, trial), g in df.groupby(list(RAMP_KEYS), sort=False):
        up = (g["direction"] == "up").to_numpy()
        p = g["pressure_kpa"].to_numpy(float)
        starts = np.flatnonzero(up[1:] & ~up[:-1]) + 1  # a rise after a fall
        starts = starts[starts > np.argmax(up)]  # (not the group's first rise)
        tolerance = sensor_level_kpa(p)
        starts = np.array([
            j - 1 if j >= 2 and not up[j - 2] and abs(p[j - 1] - p[j - 2]) <= tolerance else j
            for j in starts
        ], dtype=int)
        k = np.zeros(len(g), dtype=int)
        for j in starts:
            k[j:] += 1
        if not starts.size:
            continue
        out.loc[g.index, "trial"] = [
            str(int(trial) + i) if str(trial).isdigit() else f"{trial}-{i + 1}" for i in k
        ]
    return out


def ramp_lines(manifest: pd.DataFrame, limit: int = 12) -> list[str]:
    r"""One line per ramp of a new manifest, in photo order, for the user to check the split.

    Examples
    --------
    >>> m = pd.DataFrame({"image": [f"IMG_{i}.JPG" for i in range(1, 7)], "material": "DS20",
    ...                   "actuator": "A1", "trial": ["1"] * 3 + ["2"] * 3,
    ...                   "pressure_kpa": [0.0, 20.0, 0.0, 0.0, 40.0, 0.0]})
    >>> print("\n".join(ramp_lines(m)))
    A1 trial 1: IMG_1.JPG ... IMG_3.JPG, 3 photos, 0 -> 20 -> 0 kPa
    A1 trial 2: IMG_4.JPG ... IMG_6.JPG, 3 photos, 0 -> 40 -> 0 kPa
    >>> print(ramp_lines(m.assign(material=["1"] * 3 + ["2"] * 3))[1])
    material 2, A1 trial 2: IMG_4.JPG ... IMG_6.JPG, 3 photos, 0 -> 40 -> 0 kPa
    """
    lines = []
    several = manifest["material"].nunique() > 1  # then each line names its material
    for (material, actuator, trial), g in manifest.groupby(list(RAMP_KEYS), sort=False):
        p = g["pressure_kpa"].to_numpy(float)
        lines.append(
            (f"material {material}, " if several else "")
            + f"{actuator} trial {trial}: {g['image'].iloc[0]} ... {g['image'].iloc[-1]}, "
            f"{len(g)} photos, {p[0]:g} -> {p.max():g} -> {p[-1]:g} kPa"
        )
    if len(lines) > limit:
        lines = [*lines[: limit - 1], f"... and {len(lines) - limit + 1} more ramps"]
    return lines


def sensor_level_kpa(pressure_kpa: np.ndarray) -> float:
    """Within how much (kPa) two photos of a ramp read off a sensor's noisy log sit at one level:
    :data:`SENSOR_LEVEL_KPA`, or 5 % of the ramp's span.

    >>> sensor_level_kpa(np.array([0.0, 30.0, 60.0])), sensor_level_kpa(np.array([0.0, 5.0]))
    (3.0, 1.0)
    """
    return max(SENSOR_LEVEL_KPA, 0.05 * float(np.ptp(pressure_kpa)))


def _rising_from_the_start(df: pd.DataFrame, sensor: bool = False) -> pd.Series:
    """``df``'s directions (in photo order), but ``up`` for the photos that begin a ramp at its
    lowest pressure (for a ``sensor``'s noisy reading, within :func:`sensor_level_kpa`): held at
    the bottom between two ramps, the log still falls there (the last photo of one ramp and the
    first of the next are both at 0 kPa).

    Examples
    --------
    >>> df = pd.DataFrame({"material": "m", "actuator": "a", "trial": "2",
    ...                    "pressure_kpa": [0, 0, 20, 0],
    ...                    "direction": ["down", "down", "up", "down"]})
    >>> _rising_from_the_start(df).tolist()
    ['up', 'up', 'up', 'down']
    """
    out = df["direction"].copy()
    for _, g in df.groupby(list(RAMP_KEYS), sort=False):
        p = g["pressure_kpa"].to_numpy(float)
        tolerance_kpa = sensor_level_kpa(p) if sensor else 0.0
        other = np.abs(p - p[0]) > tolerance_kpa
        lead = int(np.argmax(other)) if other.any() else len(p)
        if p[0] <= p.min() + tolerance_kpa:
            out.loc[g.index[:lead]] = "up"
    return out


def _infer_directions(df: pd.DataFrame) -> pd.Series:
    """Each ramp rises to its first highest pressure and falls after it: ``up`` to the peak,
    ``down`` after it, unless the pressure never falls below the peak (a ramp held at its top,
    or photos all at one pressure: customer 26's ten at 0 kPa were "1 up, 9 down").

    Examples
    --------
    >>> df = pd.DataFrame({"material": "m", "actuator": "a", "trial": 1, "step": range(5),
    ...                    "pressure_kpa": [0, 20, 40, 20, 0]})
    >>> _infer_directions(df).tolist()
    ['up', 'up', 'up', 'down', 'down']
    >>> _infer_directions(df.assign(pressure_kpa=0)).tolist()
    ['up', 'up', 'up', 'up', 'up']
    """
    out = pd.Series("up", index=df.index, dtype=object)
    for _, g in df.groupby(list(RAMP_KEYS), sort=False):
        g = (
            g.sort_values("step")
            if "step" in df.columns
            else g.sort_values("image", key=lambda names: names.map(natural_key))
        )
        pressure = g["pressure_kpa"].to_numpy()
        peak = int(np.argmax(pressure))
        if (pressure[peak + 1 :] < pressure[peak]).any():
            out.loc[g.index[peak + 1 :]] = "down"
    return out
