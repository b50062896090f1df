"""The photo-set format shared by every stage (see DESIGN.md, "Photo set"), and its validation.

A photo set is a folder holding images, ``manifest.csv`` (one row per image) and ``photoset.yaml``
(folder-wide settings).  Any setting may also be a manifest column, which then overrides the
folder-wide value for that row (``fixed_end`` becomes ``fixed_end_x`` / ``fixed_end_y``).

:func:`load_photoset` reads ``photoset.yaml`` once and ``manifest.csv`` once and resolves every
row into a :class:`~pipeline.measure.settings.MeasureSettings` -- or into the problems that
prevent it, so one bad row is one ``failed`` measurement and the rest of the set is measured.
Only a set that cannot be read at all (no folder, bad YAML, no manifest, missing columns) is
refused.  :func:`validate_photoset` lists every problem, strictly (``photoset check``, which for a
video set also checks the videos: :mod:`pipeline.photoset_check`).

A *video* photo set has the same two files, but ``manifest.csv`` lists videos instead of images
(columns :data:`VIDEO_REQUIRED_COLUMNS`, optionally :data:`VIDEO_OPTIONAL_COLUMNS` and any
setting): each row is a video file, its pressure log and the offset between their clocks, and
every frame of the video is measured with that row's settings (:mod:`pipeline.video`).

This module knows nothing about where a photo set came from (rig, renderer, a copied folder).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_settings(folder, {"l0_mm": 200.0, "line_color": "black", "positive_turn": "ccw"})
>>> read_settings(folder)["fixed_end"]
'auto'
"""

from __future__ import annotations

import difflib
import functools
import os
import re
import unicodedata
from collections import Counter
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path, PurePosixPath, PureWindowsPath
from typing import Any

import numpy as np
import pandas as pd
import yaml

from pipeline.constants import DIRECTIONS, KPA_PER_UNIT, RAMP_KEYS, VACUUM_KPA, direction_name
from pipeline.errors import UserInputError
from pipeline.fileio import (
    atomic_write_bytes,
    header_line,
    plain_name,
    read_user_csv,
    read_user_text,
    user_path,
    write_table,
)
from pipeline.measure.calibration import CalibrationCache
from pipeline.measure.formats import undecodable
from pipeline.measure.settings import (
    KEYS,
    OVERRIDE_COLUMNS,
    MeasureSettings,
    is_missing,
    merge_calibration,
    number_doubt,
    settings_problems,
    user_float,
)

MANIFEST = "manifest.csv"
SETTINGS = "photoset.yaml"
TRUTH = "truth.csv"

REQUIRED_COLUMNS: tuple[str, ...] = (
    "image",
    "pressure_kpa",
    "direction",
    "material",
    "actuator",
    "trial",
)
OPTIONAL_COLUMNS: tuple[str, ...] = ("step", "timestamp", "measured_pressure_kpa")
#: a manifest may give the pressure in another unit instead of ``pressure_kpa`` (a regulator or
#: gauge that shows bar or psi): the column and its kPa, turned into ``pressure_kpa`` where the
#: manifest is read
PRESSURE_UNITS_KPA: dict[str, float] = {f"pressure_{u}": f for u, f in KPA_PER_UNIT.items()}
#: manifest columns of a video photo set (one row per video; see :mod:`pipeline.video`)
VIDEO_REQUIRED_COLUMNS: tuple[str, ...] = ("video", "pressure_log", "material", "actuator", "trial")
#: ``clock_offset_s``: log time of video time 0 (s, default 0); ``frame_times``: a ``frame, time_s``
#: CSV of the frames' timestamps on the video's clock (default: the container's presentation
#: times); ``fps``: the frames' rate, frame k at k / fps (a frame sequence's, which has none, or a
#: container's that is wrong)
VIDEO_OPTIONAL_COLUMNS: tuple[str, ...] = ("clock_offset_s", "frame_times", "fps")
#: folder-wide settings written by default (the other keys are optional, see KEYS)
SETTING_DEFAULTS: dict[str, Any] = {
    "l0_mm": None,
    "mm_per_px": None,
    "fixed_end": "auto",
    "positive_turn": "ccw",
}
#: manifest columns read as text
_TEXT_COLUMNS = (
    "image",
    "material",
    "actuator",
    "direction",
    "trial",
    "line_color",
    "positive_turn",
    "target",
    "free_end",
    "background",
    "roi",
    "exclude",
    "method",
    "calibration",
    "video",
    "pressure_log",
    "frame_times",
)

#: photo files OpenCV reads (formats.py names the ones it cannot)
IMAGE_SUFFIXES: tuple[str, ...] = (
    ".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp", ".webp", ".avif", ".jp2"
)


def photo_names(folder: Path, subfolders: bool = False) -> list[str]:
    """The photos of ``folder`` by name, sorted; with ``subfolders``, also those in its
    subfolders, by their path in it (``chamber2/00_0kPa.jpg``). Hidden files and folders are left
    out.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("b.jpg", "a.PNG", "c2/a.jpg", ".x/d.jpg", "notes.txt"):
    ...     (root / name).parent.mkdir(exist_ok=True)
    ...     _ = (root / name).write_bytes(b"")
    >>> photo_names(root), photo_names(root, subfolders=True)
    (['a.PNG', 'b.jpg'], ['a.PNG', 'b.jpg', 'c2/a.jpg'])
    """
    paths = folder.rglob("*") if subfolders else folder.iterdir()
    return sorted(
        p.relative_to(folder).as_posix()
        for p in paths
        if p.is_file()
        and p.suffix.lower() in IMAGE_SUFFIXES
        and not any(part.startswith(".") for part in p.relative_to(folder).parts)
    )


def near_name(name: str, names: Sequence[str]) -> str | None:
    """The one of ``names`` a person probably meant by ``name``: the same in another case (a
    camera's ``.JPG``), else the closest by :func:`difflib.get_close_matches` (a typo, ``.jpeg``
    for ``.jpg``); the same for the last part of a full path pasted into a spreadsheet; None when
    none is close.

    Examples
    --------
    >>> names = ["DS20_A1_t1_s015_down_60kPa.jpg", "DS20_A1_t1_s016_down_40kPa.jpg"]
    >>> near_name("ds20_a1_t1_s015_down_60kpa.JPG", names)
    'DS20_A1_t1_s015_down_60kPa.jpg'
    >>> near_name("DS20_A1_t1_s016_down_40kPa.jpeg", names), near_name("empty.jpg", names)
    ('DS20_A1_t1_s016_down_40kPa.jpg', None)
    >>> near_name(r"C:\\Users\\lab\\Fotos\\DS20_A1_t1_s016_down_40kPa.jpg", names)
    'DS20_A1_t1_s016_down_40kPa.jpg'
    """
    for wanted in dict.fromkeys((name, PureWindowsPath(name).name)):  # also a pasted full path
        same_case = [n for n in names if n.lower() == wanted.lower()]
        if same_case:
            return same_case[0]
        close = difflib.get_close_matches(wanted, names, n=1, cutoff=0.9)
        if close:
            return close[0]
    return None


def disk_name(folder: Path, name: str) -> str:
    """``name`` as the file is named in ``folder``: the same letters may be stored in another
    Unicode form (a Mac's disk writes ``a`` + a combining mark where a spreadsheet types ``ä``),
    and a Linux disk tells the two apart (customer 47's 'Probe ä 3.jpg' was said both "does not
    exist" and "not in manifest").  ``name`` itself where it exists or neither form does.

    Examples
    --------
    >>> import tempfile, unicodedata
    >>> root = Path(tempfile.mkdtemp())
    >>> _ = (root / unicodedata.normalize("NFD", "Probe ä.jpg")).write_bytes(b"")
    >>> disk_name(root, "Probe ä.jpg") == unicodedata.normalize("NFD", "Probe ä.jpg")
    True
    """
    if name.isascii() or (folder / name).exists():
        return name
    for form in ("NFC", "NFD"):
        other = unicodedata.normalize(form, name)
        if other != name and (folder / other).exists():
            return other
    return name


def overlay_name(image: str) -> str:
    """The overlay file of a manifest's photo, relative to the overlays folder: the photo's own
    path in the set, as a JPEG (photos in subfolders keep them: two subfolders may hold photos of
    the same name).  Always inside the overlays folder: a photo named from outside the set
    (``../photos/x.jpg``, an absolute path) keeps only its path's names (customer 46's overlays,
    written to ``overlays/../photos/x.jpg``, replaced the photos themselves).

    Examples
    --------
    >>> overlay_name("DS20_A1_t1_0kPa.png"), overlay_name("chamber2/00_0kPa_up.jpg")
    ('DS20_A1_t1_0kPa.jpg', 'chamber2/00_0kPa_up.jpg')
    >>> overlay_name("../photos/t1.JPG"), overlay_name("/lab/x/t2.png")
    ('photos/t1.jpg', 'lab/x/t2.jpg')
    >>> overlay_name("C:\\\\lab\\\\t3.jpg"), overlay_name("D:photos\\\\t4.jpg")
    ('lab/t3.jpg', 'photos/t4.jpg')
    >>> overlay_name("\\\\\\\\server\\\\share\\\\t5.jpg")
    'server/share/t5.jpg'
    """
    # no root, share or drive (/lab, //server/share, C:, D:photos): only names
    parts = re.sub(r"^[A-Za-z]:", "", str(image).replace("\\", "/")).split("/")
    kept = [part for part in parts if part not in ("", ".", "..", "~")]
    return PurePosixPath(*kept).with_suffix(".jpg").as_posix()


@dataclass(frozen=True)
class Problem:
    """One thing wrong with a photo set.

    Attributes
    ----------
    file : str
        File the problem is in (``manifest.csv``, ``photoset.yaml`` or an image path).
    line : int or None
        1-based line in ``manifest.csv`` (the header is line 1), or ``None``.
    message : str
        What is wrong.
    fix : str
        What to do about it.
    warning : bool
        A doubt rather than an error (``photoset check`` prints it but still succeeds).
    """

    file: str
    line: int | None
    message: str
    fix: str
    warning: bool = False

    def __str__(self) -> str:
        where = f"{self.file} line {self.line}" if self.line is not None else self.file
        return f"{where}: {'warning: ' if self.warning else ''}{self.message} (fix: {self.fix})"


def problem_lines(problems: Sequence[Problem]) -> list[str]:
    """The problems as lines for a person, the same problem on several rows of one file said
    once with its lines (an empty scene of another shape than the 26 photos of a set was said
    26 times).

    Examples
    --------
    >>> same = [Problem("m.csv", n, "too dark", "relight") for n in (2, 3, 4, 7)]
    >>> for line in problem_lines([*same, Problem("m.csv", 5, "no image", "copy it in")]):
    ...     print(line)
    m.csv lines 2-4, 7 (4 rows): too dark (fix: relight)
    m.csv line 5: no image (fix: copy it in)
    """
    groups: dict[tuple[str, str, str, bool], list[int | None]] = {}
    for p in problems:
        groups.setdefault((p.file, p.message, p.fix, p.warning), []).append(p.line)
    out: list[str] = []
    for (file, message, fix, warning), lines in groups.items():
        numbers = sorted({n for n in lines if n is not None})
        if len(numbers) < 2 or None in lines:
            out.extend(str(Problem(file, n, message, fix, warning)) for n in lines)
            continue
        runs: list[list[int]] = []
        for n in numbers:
            if runs and n == runs[-1][-1] + 1:
                runs[-1].append(n)
            else:
                runs.append([n])
        spans = ", ".join(f"{r[0]}-{r[-1]}" if len(r) > 1 else f"{r[0]}" for r in runs)
        where = f"{file} lines {spans} ({len(numbers)} rows)"
        out.append(f"{where}: {'warning: ' if warning else ''}{message} (fix: {fix})")
    return out


@dataclass(frozen=True)
class PhotoSet:
    """A loaded photo set.

    Attributes
    ----------
    folder : Path
        The photo-set folder.
    settings : dict
        ``photoset.yaml`` as written, with :data:`SETTING_DEFAULTS` filled in.
    manifest : pandas.DataFrame
        The manifest, one row per image (``pressure_kpa`` numeric, NaN where unreadable), plus
        ``manifest_line`` (1-based line in manifest.csv).
    rows : tuple of MeasureSettings or None
        The resolved settings of each manifest row, in order; None for a row that cannot be
        measured (its problems are in :attr:`problems`).
    problems : tuple of Problem
        Every problem of every row (not of the set as a whole, which refuses to load).
    """

    folder: Path
    settings: dict[str, Any]
    manifest: pd.DataFrame
    rows: tuple[MeasureSettings | None, ...]
    problems: tuple[Problem, ...] = ()

    @property
    def is_video(self) -> bool:
        """The manifest lists videos (one row per video) rather than images."""
        return is_video_manifest(self.manifest)

    def image_path(self, image: str) -> Path:
        """Absolute path of an image (or video, or log) named in the manifest."""
        return self.folder / image

    def row_reason(self, position: int) -> str:
        """Why row ``position`` (0-based) cannot be measured, in words ('' when it can)."""
        line = int(self.manifest["manifest_line"].iloc[position])
        return "; ".join(
            f"manifest line {line}: {p.message} (fix: {p.fix})"
            for p in self.problems
            if p.line == line
        )


# --------------------------------------------------------------------------------------------
# reading


def _read_yaml(folder: Path) -> tuple[dict[str, Any] | None, list[Problem]]:
    path = folder / SETTINGS
    name = str(path)
    if not folder.is_dir():
        return None, [
            Problem(
                str(folder),
                None,
                "photo-set folder does not exist",
                "check the path in the config or command",
            )
        ]
    if not path.is_file():
        return None, [
            Problem(
                name,
                None,
                "missing",
                f"create it (python -m pipeline photoset init {folder}) with at least l0_mm",
            )
        ]
    try:
        raw = yaml.safe_load(read_user_text(path)) or {}
    except yaml.YAMLError as exc:
        return None, [Problem(name, None, f"not valid YAML ({exc})", yaml_fix(exc))]
    if not isinstance(raw, dict):
        return None, [
            Problem(name, None, "must be a mapping of key: value", "write e.g. 'l0_mm: 200'")
        ]
    problems = unknown_key_problems(name, raw)
    if any(not p.warning for p in problems):
        return None, problems
    return {**SETTING_DEFAULTS, **raw}, problems


#: a key or column this much like a setting's name (:func:`difflib.get_close_matches` ratio) is
#: taken for a typo of it and refused: as it is it would be ignored, and every photo measured
#: without it (customer 47: ``postive_turn: cw`` in the manifest gave 30 rows ok of the wrong
#: sign, ``mm_per_pix`` in photoset.yaml moved psi 1.4 deg, every row ok)
TYPO_RATIO = 0.8


def typo_of(name: str, names: Sequence[str]) -> str | None:
    """The name of ``names`` that ``name`` is a typo of (:data:`TYPO_RATIO`), or None: not where
    ``name`` only adds to it (``timestamp_s``, ``steps``: another quantity) or ends in another
    word (``l0_cm``, ``pressure_set``); a name short of its unit is one (``sealed_end``).

    Examples
    --------
    >>> typo_of("postive_turn", KEYS), typo_of("mm_per_pix", KEYS), typo_of("operator", KEYS)
    ('positive_turn', 'mm_per_px', None)
    >>> typo_of("sealed_end", KEYS), typo_of("l0_cm", KEYS), typo_of("free_end_x", KEYS)
    ('sealed_end_mm', None, None)
    """
    close = difflib.get_close_matches(name, names, n=1, cutoff=TYPO_RATIO)
    if not close or name.startswith(close[0]):
        return None
    stem, _, last = name.rpartition("_")
    known_stem, _, known_last = close[0].rpartition("_")
    other_word = difflib.SequenceMatcher(None, last, known_last).ratio() < 0.75
    if stem and stem == known_stem and other_word:
        return None
    return close[0]


#: the last word of a column that names a unit: ``l0_cm`` is ``l0_mm`` in another unit
UNIT_WORDS = frozenset({"m", "cm", "mm", "um", "in", "px", "deg", "rad", "s", "ms"})


def yaml_fix(exc: yaml.YAMLError) -> str:
    """The fix for a YAML file PyYAML could not read: a tab (which YAML never takes where
    photoset.yaml would have one) is named with its line (customer 47 got "fix the YAML
    syntax").

    Examples
    --------
    >>> try:
    ...     yaml.safe_load("l0_mm: 200\\nline_color:\\tblack\\n")
    ... except yaml.YAMLError as exc:
    ...     print(yaml_fix(exc))
    replace the tab on line 2 with a space (YAML takes no tabs)
    """
    mark = getattr(exc, "problem_mark", None)
    if "'\\t'" in str(exc) and mark is not None:
        return f"replace the tab on line {mark.line + 1} with a space (YAML takes no tabs)"
    return "fix the YAML syntax" + (f" on line {mark.line + 1}" if mark is not None else "")


def unknown_key_problems(path: str, settings: Mapping[str, Any]) -> list[Problem]:
    """A problem for each key of ``photoset.yaml`` that is not one: a typo of one
    (:func:`typo_of`: ``sealed_end: 8``) is refused, since as it is it would measure as if
    nothing were given; any other key is a warning (ignored), with the closest key as the fix.

    Examples
    --------
    >>> [(p.warning, p.fix[:23]) for p in unknown_key_problems(
    ...     "photoset.yaml", {"l0_mm": 1, "sealed_end": 8, "operator": "Ann"})]
    [(False, 'rename it sealed_end_mm'), (True, 'use only l0_mm, mm_per_')]
    """
    out = []
    keys = ", ".join(KEYS)
    for key in settings:
        if key in KEYS:
            continue
        typo = typo_of(str(key), [k for k in KEYS if k not in settings])
        if typo is not None:
            out.append(Problem(
                path,
                None,
                f"unknown key {key!r}, a typo of {typo}? As it is it would be ignored, and every "
                "photo measured without it",
                f"rename it {typo} (a key of your own needs a name less like a setting's)",
            ))
            continue
        close = difflib.get_close_matches(str(key), KEYS, n=1, cutoff=0.6)
        out.append(
            Problem(
                path,
                None,
                f"unknown key {key!r} is ignored",
                f"did you mean {close[0]}? (the keys: {keys})" if close else f"use only {keys}",
                warning=True,
            )
        )
    return out


def read_settings(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """Read ``photoset.yaml`` with :data:`SETTING_DEFAULTS` filled in; raise when unreadable."""
    raw, problems = _read_yaml(Path(folder))
    if raw is None:
        raise UserInputError("; ".join(str(p) for p in problems))
    return raw


def write_settings(folder: str | os.PathLike[str], settings: Mapping[str, Any]) -> None:
    """Write ``photoset.yaml`` atomically (defaults filled in, keys in a stable order, one a
    line; a key with no value is left out, but ``l0_mm``, which has to be set: ``l0_mm: null``
    says so).

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> write_settings(root, {"l0_mm": 255.0, "roi": [[1, 2], [3, 4]]})
    >>> print((root / SETTINGS).read_text(), end="")
    l0_mm: 255.0
    fixed_end: auto
    positive_turn: ccw
    roi: [[1, 2], [3, 4]]
    """
    data = {
        k: v
        for k, v in {**SETTING_DEFAULTS, **dict(settings)}.items()
        if v is not None or k == "l0_mm"
    }
    if isinstance(data.get("fixed_end"), tuple):
        data["fixed_end"] = [float(x) for x in data["fixed_end"]]
    text = yaml.dump(data, Dumper=_SettingsDumper, sort_keys=False, default_flow_style=False)
    atomic_write_bytes(Path(folder) / SETTINGS, text.encode())


class _SettingsDumper(yaml.SafeDumper):
    """``photoset.yaml`` as a person writes it: one key a line, a point or a range on one line
    (``fixed_end: [812.0, 455.0]``; PyYAML's flow style wrote a set without one as one
    ``{l0_mm: 255.0, ...}`` line)."""


_SettingsDumper.add_representer(
    list, lambda d, v: d.represent_sequence("tag:yaml.org,2002:seq", v, flow_style=True)
)


def is_video_manifest(manifest: pd.DataFrame) -> bool:
    """Whether a manifest lists videos (a ``video`` column and no ``image`` column)."""
    return "video" in manifest.columns and "image" not in manifest.columns


def named_files(folder: str | os.PathLike[str]) -> frozenset[Path]:
    """Every existing file a set's settings name (a ``background`` photo, calibration board
    photos; in ``photoset.yaml`` or a ``manifest.csv`` column), resolved, inside the folder or
    not. Read leniently: a set whose files cannot be parsed names nothing here."""
    folder = Path(folder)
    return files_named_in(folder, *_read_leniently(folder))


def _read_leniently(folder: Path) -> tuple[Any, pd.DataFrame]:
    """``photoset.yaml`` as written and ``manifest.csv`` with its columns' canonical names
    ('Background' -> background); empty where either cannot be read."""
    try:
        raw = yaml.safe_load(read_user_text(folder / SETTINGS)) or {}
    except (OSError, yaml.YAMLError):
        raw = {}
    try:
        manifest = read_user_csv(folder / MANIFEST, dtype=str)
        manifest = manifest.rename(columns=header_names(manifest.columns))
    except (OSError, ValueError, pd.errors.ParserError):
        manifest = pd.DataFrame()
    return raw, manifest


def files_named_in(folder: Path, settings: Any, manifest: pd.DataFrame) -> frozenset[Path]:
    """:func:`named_files` of settings and a manifest already read (``settings`` as in
    ``photoset.yaml``, the manifest with its columns' canonical names)."""
    values: list[Any] = []
    if isinstance(settings, dict):
        values += [settings.get("background"), settings.get("calibration")]
    for column in ("background", "calibration"):
        if column in manifest.columns:
            values += manifest[column].dropna().unique().tolist()
    names: list[str] = []
    for value in values:
        if isinstance(value, str) and value.strip().startswith(("{", "[")):
            try:  # a manifest cell holds YAML
                value = yaml.safe_load(value)
            except yaml.YAMLError:
                continue
        if isinstance(value, dict):
            value = value.get("board")
        items = [value] if isinstance(value, str) else value if isinstance(value, list) else []
        names += [v for v in items if isinstance(v, str)]
    return frozenset(
        path.resolve()
        for name in names
        if name.strip()
        for path in [user_path(name, folder)]  # an absolute name stays absolute
        if path.is_file()
    )


def referenced_files(folder: str | os.PathLike[str]) -> tuple[Path, ...]:
    """Files outside ``folder`` that its settings name: a ``background`` photo or calibration
    board photos given as ``../...`` or an absolute path, in ``photoset.yaml`` or a
    ``manifest.csv`` column, and the manifest's own photos, videos (a frame sequence's files),
    pressure logs and frame times given so (one folder of photos shared by the sets of several
    actuators in one view).

    The workflow digests them with the folder, so replacing such a file re-measures the set
    (results are never stale).  Read leniently: a set whose files cannot be parsed names nothing
    here (``measure`` and ``check`` report it); paths that do not exist are left out.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp()); (root / "set").mkdir()
    >>> for name in ("empty.jpg", "set/board.jpg"):
    ...     _ = (root / name).write_bytes(b"x")
    >>> _ = (root / "set" / SETTINGS).write_text(
    ...     "background: ../empty.jpg\\ncalibration: {board: [board.jpg], square_mm: 5}\\n")
    >>> [p.name for p in referenced_files(root / "set")]
    ['empty.jpg']
    >>> _ = (root / "set" / MANIFEST).write_text("image\\n../shared.jpg\\nboard.jpg\\n")
    >>> _ = (root / "shared.jpg").write_bytes(b"x")
    >>> [p.name for p in referenced_files(root / "set")]
    ['empty.jpg', 'shared.jpg']
    """
    folder = Path(folder)
    raw, manifest = _read_leniently(folder)
    media: set[Path] = set()
    for column in ("image", "video", "pressure_log", "frame_times"):
        if column not in manifest.columns:
            continue
        for name in manifest[column].dropna().unique():
            if not (isinstance(name, str) and name.strip()):
                continue
            path = user_path(name.strip(), folder)
            if column == "video":  # a frame sequence, frame_%04d.jpg: every file it may name
                pattern = re.sub(r"%(0\d+)?d", "*", path.name)
                if pattern != path.name and path.parent.is_dir():
                    media |= {f.resolve() for f in path.parent.glob(pattern) if f.is_file()}
            if path.is_file():
                media.add(path.resolve())
    inside = folder.resolve()
    named = files_named_in(folder, raw, manifest) | media
    return tuple(sorted(p for p in named if not p.is_relative_to(inside)))


def read_manifest(folder: str | os.PathLike[str]) -> pd.DataFrame:
    """Read ``manifest.csv`` as written (text columns kept as text), adding ``manifest_line``.

    A manifest with a ``video`` column and no ``image`` column is a video manifest and needs
    :data:`VIDEO_REQUIRED_COLUMNS` instead of :data:`REQUIRED_COLUMNS`.  A manifest saved by a
    spreadsheet (``;`` and decimal commas, tabs, a Windows code page) is read as such
    (:func:`pipeline.fileio.read_user_csv`).

    Raises
    ------
    UserInputError
        If the file is missing, unparsable or lacks a required column.
    """
    df, problem = _read_manifest(Path(folder))
    if problem is not None:
        raise UserInputError(str(problem))
    assert df is not None
    return df


#: what a spreadsheet saves a manifest as when told to keep its own format
SPREADSHEET_SUFFIXES: tuple[str, ...] = (".xlsx", ".xlsm", ".xls", ".ods", ".numbers")


def manifest_lookalikes(folder: Path) -> list[str]:
    """Files in ``folder`` that are a manifest under another name: ``Manifest.csv``, or one a
    spreadsheet saved in its own format (``manifest.xlsx``, ``manifest.csv.xlsx``, ...).

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("Manifest.CSV", "manifest.csv.xlsx", "notes.xlsx", "IMG_1.JPG"):
    ...     _ = (root / name).write_bytes(b"")
    >>> manifest_lookalikes(root)
    ['Manifest.CSV', 'manifest.csv.xlsx']
    """
    if not folder.is_dir():
        return []
    out = []
    for p in sorted(folder.iterdir()):
        name = p.name.lower()
        stem = name.removesuffix(p.suffix.lower()).removesuffix(".csv")
        if p.name != MANIFEST and (
            name == MANIFEST or (stem == "manifest" and p.suffix.lower() in SPREADSHEET_SUFFIXES)
        ):
            out.append(p.name)
    return out


def _read_manifest(folder: Path) -> tuple[pd.DataFrame | None, Problem | None]:
    """:func:`read_manifest`'s table, or the problem that stops it being read."""
    path = folder / MANIFEST
    if not path.is_file():
        others = manifest_lookalikes(folder)
        return None, Problem(
            str(path),
            None,
            "missing" + (f"; the folder has {others}" if others else ""),
            (
                f"create it with 'python -m pipeline photoset init {folder} --pattern ...'"
                if not others
                else f"rename {others[0]!r} to {MANIFEST}"
                if others[0].lower() == MANIFEST
                else f"save {others[0]!r} as CSV named {MANIFEST} (comma- or ';'-separated)"
            ),
        )
    try:
        # blank lines kept as rows, so that every row keeps its line number in the file
        df = read_user_csv(
            path,
            dtype={c: str for c in _TEXT_COLUMNS},
            keep_default_na=True,
            skip_blank_lines=False,
        )
    except (pd.errors.ParserError, pd.errors.EmptyDataError, OSError) as exc:
        return None, _header_below(path, "") or Problem(
            str(path), None, f"cannot be read as CSV ({exc})",
            "save it as CSV: a header line, then one line per photo",
        )
    df = df.rename(columns=header_names(df.columns))
    units = [c for c in PRESSURE_UNITS_KPA if c in df.columns]
    if "pressure_kpa" not in df.columns and len(units) == 1 and not is_video_manifest(df):
        df = _with_pressure_kpa(df, units[0])
    required = VIDEO_REQUIRED_COLUMNS if is_video_manifest(df) else REQUIRED_COLUMNS
    missing = [c for c in required if c not in df.columns]
    if missing:
        line_one = f" (line 1 reads {list(map(str, df.columns))})"
        return None, _header_below(path, line_one) or Problem(
            str(path),
            1,
            f"missing column(s) {missing}; the header has {list(map(str, df.columns))}",
            f"name the columns {list(required)} in the header line (any case, a unit in brackets "
            "may follow: 'Pressure (kPa)')"
            + ("" if "video" in df.columns else f"; for videos {list(VIDEO_REQUIRED_COLUMNS)}"),
        )
    if {"psi_deg", "status"} <= set(map(str, df.columns)):
        # customer 47 wrote angles.csv over its manifest (measure --out SET/manifest.csv), and
        # measure then stopped with a TypeError
        return None, Problem(
            str(path),
            1,
            "is a table of measured angles (its header has psi_deg and status, which measure "
            "writes), not the list of the photos",
            "put back the manifest that lists the photos (image, pressure_kpa, direction, "
            "material, actuator, trial); 'python -m pipeline photoset init' makes one from the "
            "photos' names",
        )
    typos = column_typo_problems(str(path), df.columns, is_video_manifest(df))
    if typos:
        more = [p.message.split(",", 1)[0].removeprefix("column ") for p in typos[1:]]
        first = typos[0]
        return None, replace(
            first, message=first.message + (f" (so are {', '.join(more)})" if more else "")
        )
    if "direction" in df.columns:  # 'Up', 'decreasing': read as meant, once, here
        df["direction"] = df["direction"].map(direction_name)
    for column in ("image", "video"):
        if column in df.columns:
            df[column] = [disk_name(folder, n) if isinstance(n, str) else n for n in df[column]]
    df["manifest_line"] = np.arange(len(df), dtype=int) + 2
    # rows with every cell empty (a blank line, or the ',,,,,' a spreadsheet leaves under its
    # data) are no photos: left out, not each one 'image name is empty'
    blank = np.column_stack(
        [df[c].map(is_missing).to_numpy(bool) for c in df.columns if c != "manifest_line"]
    ).all(axis=1)
    return df.loc[~blank].reset_index(drop=True), None


def header_names(columns: Iterable[Any]) -> dict[str, str]:
    """The manifest's own names for header cells a person wrote another way: any case, spaces,
    a unit in brackets (``Image``, ``Pressure (kPa)``, ``Pressure [bar]``, ``Fixed end X``).
    A name already written as the manifest writes it is left alone, and so is any other.

    Examples
    --------
    >>> header_names(["Image", "Pressure (kPa)", "Direction", "Notes", "trial"])
    {'Image': 'image', 'Pressure (kPa)': 'pressure_kpa', 'Direction': 'direction'}
    >>> header_names(["Pressure [bar]", "image", "IMAGE"])
    {'Pressure [bar]': 'pressure_bar'}
    """
    known = {
        *REQUIRED_COLUMNS, *OPTIONAL_COLUMNS, *VIDEO_REQUIRED_COLUMNS, *VIDEO_OPTIONAL_COLUMNS,
        *PRESSURE_UNITS_KPA, *OVERRIDE_COLUMNS,
    }
    written = [str(c) for c in columns]
    out: dict[str, str] = {}
    for name in written:
        canonical = plain_name(name)
        if name in known or canonical not in known or canonical in written:
            continue
        if canonical not in out.values():
            out[name] = canonical
    return out


def column_typo_problems(
    path: str, columns: Iterable[Any], video: bool = False
) -> list[Problem]:
    """A problem for each manifest column that is a typo of one a (``video``) manifest knows and
    does not have (:func:`typo_of`; its name as :func:`plain_name` reads it), or a setting's
    column in another unit (``l0_cm``): as it is it would be carried to angles.csv as a column
    of the user's own and the setting ignored on every row.  Other columns of the user's own
    are fine (``pressure_kpa_set``, ``timestamp_s``, ``notes``).

    Examples
    --------
    >>> [p.fix for p in column_typo_problems("m.csv", ["image", "Postive Turn", "operator"])]
    ["rename it positive_turn (a column of your own needs a name less like the manifest's)"]
    >>> column_typo_problems("m.csv", ["fixed_end_px"])[0].fix[:43]
    'give the fixed end as fixed_end_x and fixed'
    >>> column_typo_problems("m.csv", ["l0_cm"])[0].fix
    "convert it to mm and name it l0_mm (a column of your own needs a name less like a setting's)"
    >>> column_typo_problems("m.csv", ["timestamp_s", "steps", "pressure_set", "trial_id"])
    []
    """
    known = (
        (*VIDEO_REQUIRED_COLUMNS, *VIDEO_OPTIONAL_COLUMNS) if video
        else (*REQUIRED_COLUMNS, *OPTIONAL_COLUMNS)
    ) + OVERRIDE_COLUMNS
    names = {str(c): plain_name(str(c)) for c in columns}
    missing = [k for k in known if k not in names.values()]
    out = []
    for column, name in names.items():
        if name in known or name in PRESSURE_UNITS_KPA:
            continue
        stem, _, unit = name.rpartition("_")
        other_unit = [
            k for k in OVERRIDE_COLUMNS
            if unit in UNIT_WORDS and k.rpartition("_")[0] == stem
            and k.rpartition("_")[2] in UNIT_WORDS
        ]
        fix, typo = "", None
        if name.startswith("fixed_end"):  # fixed_end [x, y] in one cell, fixed_end_px, ...
            typo = "fixed_end_x"
            fix = "give the fixed end as fixed_end_x and fixed_end_y columns (a pixel number each)"
        elif other_unit:
            typo = other_unit[0]
            fix = (
                f"convert it to {typo.rpartition('_')[2]} and name it {other_unit[0]} (a column "
                "of your own needs a name less like a setting's)"
            )
        else:
            typo = typo_of(name, missing)
        if typo is None:
            continue
        out.append(Problem(
            path,
            1,
            f"column {column!r}, "
            + (f"{typo} in another unit?" if other_unit else f"a typo of {typo}?")
            + " As it is it would be ignored on every row",
            fix or f"rename it {typo} (a column of your own needs a name less like the manifest's)",
        ))
    return out


def _header_below(path: Path, line_one: str) -> Problem | None:
    """The problem of a manifest whose header stands below line 1 (a title or empty lines above
    it), or None when no line near the top is a header."""
    for required in (REQUIRED_COLUMNS, VIDEO_REQUIRED_COLUMNS):
        below = header_line(path, required)
        if below is not None and below > 1:
            return Problem(
                str(path),
                1,
                f"the header is on line {below}, not on line 1{line_one}",
                f"delete the {below - 1} line(s) above the header (a title or an empty line)",
            )
    return None


def _with_pressure_kpa(df: pd.DataFrame, column: str) -> pd.DataFrame:
    """``df`` with ``pressure_kpa`` from a pressure in another unit (:data:`PRESSURE_UNITS_KPA`),
    beside it; a cell that is no number is kept as written, for the row check to name.

    Examples
    --------
    >>> m = pd.DataFrame({"image": ["a.jpg", "b.jpg", "c.jpg"], "pressure_bar": [0.35, "0,7", "x"]})
    >>> _with_pressure_kpa(m, "pressure_bar")["pressure_kpa"].tolist()
    [35.0, 70.0, 'x']
    """
    values = df[column].map(user_float) * PRESSURE_UNITS_KPA[column]
    kpa = [round(float(v), 6) if np.isfinite(v) else w for v, w in zip(values, df[column])]
    out = df.copy()
    out.insert(int(out.columns.get_loc(column)) + 1, "pressure_kpa", kpa)
    return out


def _row_problems(df: pd.DataFrame, mpath: str) -> list[Problem]:
    """Problems of the manifest rows themselves (not of their settings or images); ``df`` as
    written (a bad pressure is named as it was written)."""
    out: list[Problem] = []
    pressure = df["pressure_kpa"].map(user_float)
    first_line: dict[str, int] = {}
    for i, (line, image, direction) in enumerate(
        zip(df["manifest_line"], df["image"], df["direction"])
    ):
        line = int(line)
        if is_missing(image):
            out.append(
                Problem(
                    mpath,
                    line,
                    "image name is empty",
                    "put the image file name in the 'image' column",
                )
            )
        elif image in first_line:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"image {image!r} is listed twice (also line {first_line[image]})",
                    "remove the duplicate row (a photo of several actuators: one photo set per "
                    "actuator, each with its roi)",
                )
            )
        else:
            first_line[image] = line
        p = pressure.iloc[i]
        if not np.isfinite(p):
            written = df["pressure_kpa"].iloc[i]
            doubt = number_doubt(written)
            out.append(
                Problem(
                    mpath,
                    line,
                    (
                        "pressure_kpa is missing (an empty or n/a cell), not a number"
                        if is_missing(written)
                        else f"pressure_kpa {written!r} could be either number: {doubt}"
                        if doubt
                        else f"pressure_kpa {written!r} is not a number"
                    ),
                    "write the gauge pressure in kPa, e.g. 40"
                    + (", without a thousands separator, with a decimal point" if doubt else ""),
                )
            )
        elif p < VACUUM_KPA:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"pressure_kpa {p:g} is below absolute vacuum ({VACUUM_KPA:g} kPa gauge)",
                    "write the gauge pressure in kPa (>= -101.3)",
                )
            )
        if "measured_pressure_kpa" in df.columns:
            read_back = df["measured_pressure_kpa"].iloc[i]
            if not is_missing(read_back) and not np.isfinite(user_float(read_back)):
                doubt = number_doubt(read_back)
                out.append(
                    Problem(
                        mpath,
                        line,
                        f"measured_pressure_kpa {read_back!r} "
                        + (f"could be either number: {doubt}" if doubt else "is not a number"),
                        "write the pressure read back in kPa with a decimal point, or leave the "
                        "cell empty (the setpoint pressure_kpa is then used)",
                    )
                )
        if "since_step_s" in df.columns:  # what measure flags a settling photo by
            since = df["since_step_s"].iloc[i]
            seconds = np.nan if is_missing(since) else user_float(since)
            if not is_missing(since) and not (np.isfinite(seconds) and seconds >= 0):
                doubt = number_doubt(since)
                out.append(
                    Problem(
                        mpath,
                        line,
                        f"since_step_s {since!r} "
                        + (
                            f"could be either number: {doubt}"
                            if doubt
                            else "is negative" if np.isfinite(seconds) else "is not a number"
                        ),
                        "write the seconds since the pressure reached its level with a decimal "
                        "point, or leave the cell empty (the photo is then not flagged as taken "
                        "while settling)",
                    )
                )
        if direction not in DIRECTIONS:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"direction {direction!r} is unknown",
                    "use 'up' (increasing pressure) or 'down' (decreasing)",
                )
            )
        for key in RAMP_KEYS:
            if is_missing(df[key].iloc[i]):
                out.append(Problem(mpath, line, f"{key} is empty", f"fill in the {key}"))
    if "step" in df.columns:
        dup = df[
            df["step"].notna()
            & df.duplicated([*RAMP_KEYS, "step"], keep="first")
        ]
        for _, row in dup.iterrows():
            out.append(
                Problem(
                    mpath,
                    int(row["manifest_line"]),
                    f"step {row['step']} repeats for material {row['material']}, actuator "
                    f"{row['actuator']}, trial {row['trial']}",
                    "renumber the steps or remove the duplicate row",
                )
            )
    return out


def _video_row_problems(df: pd.DataFrame, mpath: str) -> list[Problem]:
    """Problems of the rows of a video manifest themselves (not of their files or settings)."""
    out: list[Problem] = []
    first: dict[str, int] = {}
    ramps: dict[tuple[str, str, str], int] = {}
    offsets = (
        df["clock_offset_s"]
        if "clock_offset_s" in df.columns
        else pd.Series([None] * len(df), index=df.index)
    )
    for i, (line, video, log, offset) in enumerate(
        zip(df["manifest_line"], df["video"], df["pressure_log"], offsets)
    ):
        line = int(line)
        if is_missing(video):
            out.append(
                Problem(
                    mpath,
                    line,
                    "video name is empty",
                    "put the video file name in the 'video' column",
                )
            )
        elif video in first:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"video {video!r} is listed twice (also line {first[video]})",
                    "remove the duplicate row",
                )
            )
        else:
            first[video] = line
        if is_missing(log):
            out.append(
                Problem(
                    mpath,
                    line,
                    "pressure_log is empty",
                    "name the CSV (time_s, pressure_kpa[, measured_kpa]) logged with this video",
                )
            )
        if not is_missing(offset):
            value = pd.to_numeric(pd.Series([offset]), errors="coerce").iloc[0]
            if not np.isfinite(value):
                out.append(
                    Problem(
                        mpath,
                        line,
                        f"clock_offset_s {offset!r} is not a number",
                        "give the log time (s) of the video's first instant, e.g. 1.25, or leave "
                        "it empty for 0",
                    )
                )
        fps = df["fps"].iloc[i] if "fps" in df.columns else None
        if not is_missing(fps) and not user_float(fps) > 0:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"fps {fps!r} is not a frame rate",
                    "give the frames per second the video was recorded at, e.g. 30, or leave it "
                    "empty for the video's own",
                )
            )
        for key in RAMP_KEYS:
            if is_missing(df[key].iloc[i]):
                out.append(Problem(mpath, line, f"{key} is empty", f"fill in the {key}"))
        material, actuator, trial = (str(df[k].iloc[i]) for k in RAMP_KEYS)
        key3 = (material, actuator, trial)
        if key3 in ramps:
            out.append(
                Problem(
                    mpath,
                    line,
                    f"material {key3[0]}, actuator {key3[1]}, trial {key3[2]} is also line "
                    f"{ramps[key3]}",
                    "give each video its own trial number",
                )
            )
        else:
            ramps[key3] = line
    return out


def _resolve_rows(
    folder: Path, settings: Mapping[str, Any], df: pd.DataFrame
) -> tuple[tuple[MeasureSettings | None, ...], list[Problem], list[Problem]]:
    """Per-row settings; returns (rows, row problems, folder-wide settings problems)."""
    sname, mpath = str(folder / SETTINGS), str(folder / MANIFEST)
    folder_raw = {k: v for k, v in settings.items() if k in KEYS}
    calibrations = CalibrationCache(folder)  # each board photo set is calibrated (or read) once
    _, folder_problems = settings_problems(folder_raw, folder=folder, calibrations=calibrations)
    # a folder-wide l0_mm may be missing when every row has its own
    folder_bad = [
        Problem(sname, None, p.message, p.fix)
        for p in folder_problems
        if p.key != "l0_mm" or "missing" not in p.message
    ]
    overrides = [c for c in OVERRIDE_COLUMNS if c in df.columns]
    rows: list[MeasureSettings | None] = []
    problems: list[Problem] = []
    records = df[overrides].to_dict("records") if overrides else [{}] * len(df)
    for line, row in zip(df["manifest_line"], records):
        raw = dict(folder_raw)
        raw.update({k: v for k, v in row.items() if not is_missing(v)})
        if not is_missing(row.get("calibration")) and not is_missing(folder_raw.get("calibration")):
            raw["calibration"] = merge_calibration(folder_raw["calibration"], row["calibration"])
        resolved, row_problems = settings_problems(raw, folder=folder, calibrations=calibrations)
        rows.append(resolved)
        problems += [Problem(mpath, int(line), p.message, p.fix) for p in row_problems]
    return tuple(rows), problems, folder_bad


def load_photoset(folder: str | os.PathLike[str]) -> PhotoSet:
    """Load a photo set: every row resolved into its settings or into its problems.

    Image files are neither checked nor decoded here (measurement makes a missing or corrupt
    image a ``failed`` row); a bad manifest row is kept with its problems, so the rest of the
    set can still be measured.

    Raises
    ------
    UserInputError
        When the set cannot be read at all (folder, ``photoset.yaml``, ``manifest.csv`` or its
        columns), or a folder-wide setting is invalid; listing every such problem.
    """
    folder = Path(folder)
    settings, problems = _read_yaml(folder)
    df: pd.DataFrame | None = None
    if settings is not None:
        df, problem = _read_manifest(folder)
        if problem is not None:
            problems.append(problem)
    if settings is None or df is None:
        _refuse(folder, problems)
    assert settings is not None and df is not None
    rows, row_problems, folder_bad = _resolve_rows(folder, settings, df)
    if folder_bad:
        _refuse(folder, folder_bad)
    if len(df) == 0:
        _refuse(
            folder, [Problem(str(folder / MANIFEST), None, "has no rows", "add one row per image")]
        )
    if all(r is None for r in rows) and any("l0_mm is missing" in p.message for p in row_problems):
        _refuse(
            folder,
            [
                Problem(
                    str(folder / SETTINGS),
                    None,
                    "l0_mm is missing",
                    "add 'l0_mm: <length of the marked layer in mm>' (or an l0_mm manifest column)",
                )
            ],
        )
    if is_video_manifest(df):
        problems = _video_row_problems(df, str(folder / MANIFEST)) + row_problems
    else:
        problems = _row_problems(df, str(folder / MANIFEST)) + row_problems
        # numbers from here on ('60,5' as a decimal comma writes it, quoted in a comma CSV)
        for column in ("pressure_kpa", "measured_pressure_kpa"):
            if column in df.columns:
                df[column] = df[column].map(user_float).astype(float)
    bad_lines = {p.line for p in problems}
    rows = tuple(None if line in bad_lines else r for line, r in zip(df["manifest_line"], rows))
    problems.sort(key=lambda p: p.line or 0)
    return PhotoSet(
        folder=folder, settings=settings, manifest=df, rows=rows, problems=tuple(problems)
    )


class PhotoSetRefused(UserInputError):
    """A photo set that cannot be loaded at all; ``problems`` are the reasons, each naming its file,
    line and fix."""

    def __init__(self, folder: Path, problems: Sequence[Problem]) -> None:
        self.problems = tuple(problems)
        errors = [p for p in self.problems if not p.warning]
        super().__init__(
            f"photo set {folder} is not valid ({len(errors)} problem(s)):\n  "
            + "\n  ".join(map(str, errors))
        )


def _refuse(folder: Path, problems: list[Problem]) -> None:
    raise PhotoSetRefused(folder, problems)


def load_checked(folder: str | os.PathLike[str]) -> tuple[PhotoSet | None, list[Problem]]:
    """Load a photo set for checking: the set (None when it cannot be loaded) and its problems so
    far.

    The problems are those of ``photoset.yaml`` (unknown keys are warnings), the refusal to load
    when the set cannot be read at all, and every row's problems; :func:`file_problems` adds
    those of the files.
    """
    folder = Path(folder)
    settings, problems = _read_yaml(folder)
    if settings is None:
        return None, problems
    try:
        ps = load_photoset(folder)
    except PhotoSetRefused as exc:
        return None, problems + [p for p in exc.problems if p not in problems]
    return ps, problems + list(ps.problems)


def measurement_doubts(ps: PhotoSet) -> list[Problem]:
    """Warnings of ``check`` that hold whatever the rows measure: a key that is ignored
    (:func:`unknown_key_problems`), photos of the folder left out of the manifest
    (:func:`unlisted_problems`), a video's frames set up as photos
    (:func:`repeated_level_problems`) and a capped body without ``sealed_end_mm``
    (:func:`sealed_end_problems`).  ``measure`` prints them and the report lists them (a
    Snakemake run keeps what ``measure`` prints in the job's log); each is decided by the set's
    content, never by file times.
    """
    return unknown_key_problems(str(ps.folder / SETTINGS), ps.settings) + set_doubts(ps)


def set_doubts(ps: PhotoSet) -> list[Problem]:
    """:func:`measurement_doubts` but the ignored keys, which ``check`` has from reading
    ``photoset.yaml``: the one list both ``check`` and ``measure`` take these from."""
    return (
        ([] if ps.is_video else unlisted_problems(ps))
        + repeated_level_problems(ps)
        + sealed_end_problems(ps)
        + body_width_problems(ps)
    )


def sealed_end_problems(ps: PhotoSet) -> list[Problem]:
    """A warning when a capped body's rows give no ``sealed_end_mm`` (``check`` lists it;
    ``measure`` prints it, as every row may still come out ``ok``)."""
    lacking = [
        r
        for r in ps.rows
        if r is not None
        and r.target == "body"
        and r.free_end == "capped"
        and r.sealed_end_mm is None
    ]
    if not lacking:
        return []
    no_scene = any(r.background_path is None for r in lacking)
    # measured on rendered bodies (python -m pipeline bench realscenes --sealed-end-mm 8; the
    # 12 MP set: python -m pipeline synth S --material DS30 --scene grey_dots --actuators 1
    # --trials 2 --step-kpa 20 --seed 141 --set sealed_end_mm=8 --set width=4000 --set height=3000)
    return [
        Problem(
            str(ps.folder / SETTINGS),
            None,
            "no sealed_end_mm: the tip angle is read where the body's centre line stops, which "
            "runs on into a sealed end or cap that does not bend, so a curled body reads high "
            "(|psi| above 100 deg: 2-7 deg on a customer's body with an 8 mm one, 5-12 deg above "
            "150 on rendered bodies with 8-12 mm; the rows stay ok, each saying so)"
            + (
                " (and without an empty scene, a doubtful body gets no second look against its "
                "ramp's own photos)"
                if no_scene
                else ""
            ),
            "measure the actuator's end that does not bend (from where the chamber ends to the "
            "tip, cap included) and set sealed_end_mm",
            warning=True,
        )
    ]


def body_width_problems(ps: PhotoSet) -> list[Problem]:
    """A warning when rows give ``body_width_mm`` without ``mm_per_px`` (or with a
    ``calibration``): their width is then not checked (the review of stop 60)."""
    unchecked = [
        r
        for r in ps.rows
        if r is not None
        and r.body_width_mm is not None
        and (not r.mm_per_px or r.calibration is not None)
    ]
    if not unchecked:
        return []
    return [
        Problem(
            str(ps.folder / SETTINGS),
            None,
            f"body_width_mm is given for {len(unchecked)} photo(s) without mm_per_px (or with a "
            "calibration): their body's width read is not checked against it",
            "give mm_per_px (a ruler in the photo), or leave body_width_mm out",
            warning=True,
        )
    ]


def newer_spreadsheet_problems(folder: Path) -> list[Problem]:
    """A warning when a spreadsheet copy of the manifest is newer than ``manifest.csv``: edits
    saved in the spreadsheet's own format are not read, and the photos would be measured with
    the manifest as it was (``check`` lists it; ``measure`` prints it)."""
    mpath = folder / MANIFEST
    try:
        read_at = mpath.stat().st_mtime
    except OSError:
        return []
    out = []
    for name in manifest_lookalikes(folder):
        if Path(name).suffix.lower() in SPREADSHEET_SUFFIXES and (
            (folder / name).stat().st_mtime > read_at
        ):
            out.append(
                Problem(
                    str(mpath),
                    None,
                    f"{name} is newer than {MANIFEST}: edits saved only there are not read",
                    f"save {name} as CSV named {MANIFEST} (comma- or ';'-separated), or delete it",
                    warning=True,
                )
            )
    return out


def missing_image_problem(
    ps: PhotoSet, line: int, image: str, in_folder: Sequence[str]
) -> Problem:
    """The problem of manifest line ``line``, whose photo ``image`` is not in the set's folder,
    naming the photo of the folder (``in_folder``, :func:`photo_names`) it probably means: one
    that no other row names (a customer deleted ``IMG_4310.JPG`` and was told to rename the row
    to ``IMG_4321.JPG``, another row's photo, which would then be measured twice)."""
    named = set(ps.manifest["image"].astype(str))
    near = near_name(image, [n for n in in_folder if n not in named])
    return Problem(
        str(ps.folder / MANIFEST),
        line,
        f"image {image!r} does not exist in {ps.folder}" + (f"; it has {near!r}" if near else ""),
        (f"correct the name in the 'image' column to {near!r}, or " if near else "")
        + "copy the photo in or remove the row",
    )


def file_problems(
    ps: PhotoSet, *, decode_images: bool = True, require_images: bool = True
) -> list[Problem]:
    """Problems of a loaded set's images (missing, undecodable, settings outside the photo) and
    calibrations, and the doubt of a set without a scale.

    A video set's videos and pressure logs are not checked here but by
    :func:`pipeline.video.clips.clip_problems` (:func:`pipeline.photoset_check.check_photoset`
    does both).
    """
    folder, mpath = ps.folder, str(ps.folder / MANIFEST)
    problems: list[Problem] = []
    sizes: dict[str, tuple[int, int] | None] = {}
    images = [] if ps.is_video else list(zip(ps.manifest["manifest_line"], ps.manifest["image"]))
    in_folder: list[str] | None = None  # the folder's photos, listed once if a row's is missing
    for (line, image), settings_row in zip(images, ps.rows):
        if is_missing(image):
            continue
        path = folder / str(image)
        if not path.is_file():
            if require_images:
                if in_folder is None:
                    in_folder = photo_names(folder, subfolders=True) if folder.is_dir() else []
                problems.append(missing_image_problem(ps, int(line), str(image), in_folder))
            continue
        if not decode_images:
            continue
        size = sizes.get(str(image)) if str(image) in sizes else _image_size(path)
        sizes[str(image)] = size
        if size is None:
            why, fix = undecodable(str(image))
            problems.append(
                Problem(mpath, int(line), f"image {image!r} cannot be decoded ({why})", fix)
            )
        elif settings_row is not None:
            problems += geometry_problems(mpath, int(line), settings_row, size)
    own_framing = _own_framing(ps)
    problems += size_problems(
        mpath,
        [(line, image) for line, image in images if int(line) not in own_framing],
        sizes,
        framing_keys(ps.settings),
        pixels_given=_pixel_settings_given(ps.settings),
    )
    problems += _calibration_problems(ps)
    problems += newer_spreadsheet_problems(ps.folder)
    unscaled = [
        r for r in ps.rows if r is not None and r.mm_per_px is None and r.calibration is None
    ]
    if unscaled:
        # a line's psi is its curvature times l0 with a scale, its measured turning without; a
        # body's psi is its tip angle either way, and the scale only checks its length
        problems.append(
            Problem(
                str(folder / SETTINGS),
                None,
                "no mm_per_px: psi will be the turning of the measured line, so a line cut short "
                "by the clamp or the border reads low"
                if any(r.target == "line" for r in unscaled)
                else "no mm_per_px (optional for a body): a body's length is then checked "
                "against the other photos of its ramp only, not against l0_mm",
                "set mm_per_px if a ruler or a known length is in view (a body's width, in mm "
                "over px across its outline on the photo, not width_px, which a faint side "
                "narrows; or its length when straight; a rough one does)"
                + (
                    ": with sealed_end_mm it places the sealed end, which the body's own length, "
                    "changed by its bending, places less well (|psi| above 150 deg about 1 deg "
                    "higher with a 10 mm one)"
                    if any(r.sealed_end_mm for r in unscaled)
                    else "; otherwise there is nothing to do"
                )
                if all(r.target == "body" for r in unscaled)
                else "with a ruler in view, measure the image scale (mm per pixel) and set "
                "mm_per_px; without one, a known length in the photo does (a body's width across "
                "it, in mm over px), or leave it out (a reminder only)",
                warning=True,
            )
        )
    guessed = [r for r in ps.rows if r is not None and r.fixed_end_px is None]
    if guessed:
        problems.append(
            Problem(
                str(folder / SETTINGS),
                None,
                f"fixed_end is auto for {len(guessed)} of "
                f"{sum(r is not None for r in ps.rows)} rows: the end the actuator leaves the "
                "clamp at is guessed in each photo or frame"
                + (
                    ", and every body measured so is flagged ('fixed end guessed')"
                    if any(r.target == "body" for r in guessed)
                    else " (a line whose clamp is not seen is flagged 'fixed end guessed')"
                ),
                "set fixed_end: [x, y], the pixel where the actuator leaves the clamp (any image "
                "viewer shows it; photoset preview marks the end each photo was measured from)",
                warning=True,
            )
        )
    if any(
        r is not None and r.target == "line" and (r.free_end != "capped" or r.sealed_end_mm)
        for r in ps.rows
    ):
        problems.append(
            Problem(
                str(folder / SETTINGS),
                None,
                "free_end and sealed_end_mm are for a body (target: body); a drawn line is "
                "measured between its own ends, so they are not used for its rows",
                "leave them out, or set target: body to measure the actuator's outline",
                warning=True,
            )
        )
    problems += set_doubts(ps)
    unused = sorted({
        r.method
        for r in ps.rows
        if r is not None
        and r.target == "body"
        and r.fixed_direction_deg is not None
        and r.method not in (None, "auto", "tangents")
    })
    if unused:
        problems.append(
            Problem(
                str(folder / SETTINGS),
                None,
                f"method {', '.join(unused)} is not used where fixed_direction_deg is given: a "
                "body's psi is then its free end's tangent against that direction (method "
                "tangents)",
                "leave method out (or leave fixed_direction_deg out to measure with it)",
                warning=True,
            )
        )
    return problems


#: ``photoset preview`` names its sheet ``<set>_preview.jpg``: one written into the set's own
#: folder is no photo of it
PREVIEW_SHEET_SUFFIX = "_preview"


def unlisted_photos(
    folder: Path,
    listed: Iterable[str],
    subfolders: bool = True,
    named: frozenset[Path] | None = None,
) -> list[str]:
    """The photos of ``folder`` (:func:`photo_names`) that are neither ``listed`` (the manifest's
    images) nor files the set's settings name (``named``, else read with :func:`named_files`:
    the empty scene, calibration boards), nor a preview sheet (``*_preview.jpg``/``.png`` not
    listed).

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("a.jpg", "b.jpg", "set_preview.jpg"):
    ...     _ = (root / name).write_bytes(b"")
    >>> unlisted_photos(root, ["a.jpg"])
    ['b.jpg']
    """
    taken = {(folder / name).resolve() for name in listed} | (
        named_files(folder) if named is None else named
    )
    return [
        n
        for n in photo_names(folder, subfolders)
        if (folder / n).resolve() not in taken
        and not (
            Path(n).stem.endswith(PREVIEW_SHEET_SUFFIX)
            and Path(n).suffix.lower() in (".jpg", ".png")
        )
    ]


#: this many photos of one ramp at one pressure and direction look like a video's frames
FRAMES_AT_ONE_LEVEL = 5


def repeated_level_problems(ps: PhotoSet) -> list[Problem]:
    """A warning when a ramp has :data:`FRAMES_AT_ONE_LEVEL` or more photos at one pressure and
    direction: frames cut from a video (a step response) set up as photos, whose curves would
    average each level's frames, those still moving towards it too.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> _ = (root / SETTINGS).write_text("l0_mm: 200\\n")
    >>> rows = "".join(f"f_{k}.jpg,{40 * (k > 2)},up,DS20,A1,1\\n" for k in range(8))
    >>> _ = (root / MANIFEST).write_text("image,pressure_kpa,direction,material,actuator,trial\\n"
    ...                                  + rows)
    >>> print(repeated_level_problems(load_photoset(root))[0].message[:64])
    5 photos of ramp DS20 A1 1 are at 40 kPa up (frames of a video?)
    """
    m = ps.manifest
    if ps.is_video or not {"pressure_kpa", "direction", *RAMP_KEYS} <= set(m.columns):
        return []
    counts = m.groupby([*RAMP_KEYS, "direction", "pressure_kpa"], sort=False).size()
    many = counts[counts >= FRAMES_AT_ONE_LEVEL]
    if many.empty:
        return []
    (material, actuator, trial, direction, pressure), n = next(iter(many.items()))
    return [
        Problem(
            str(ps.folder / MANIFEST),
            None,
            f"{n} photos of ramp {material} {actuator} {trial} are at {pressure:g} kPa "
            f"{direction} (frames of a video?)"
            + (f", and {len(many) - 1} more such level(s)" if len(many) > 1 else "")
            + ": the curves average each level's photos, those still moving towards it too",
            "measure frames cut from a video as the video they are: a video row naming them "
            "like frame_%04d.jpg, with fps (README, Videos); repeated photos of a settled "
            "level are fine as they are",
            warning=True,
        )
    ]


#: a photo named like a calibration board's
BOARD_NAME = re.compile(r"checker|chess|board|calib|charuco", re.IGNORECASE)
#: ... and like a photo of the empty scene
EMPTY_NAME = re.compile(r"empty|background|backdrop|bg", re.IGNORECASE)


def unlisted_problems(ps: PhotoSet) -> list[Problem]:
    """A warning when photos in the set's folder (or its subfolders) are neither rows of
    ``manifest.csv`` nor files its settings name (the empty scene, calibration boards): a photo
    whose name did not match ``photoset init``'s pattern is otherwise left out unseen.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("a_0kPa.jpg", "a_10kpa.jpg", "empty.jpg"):
    ...     _ = (root / name).write_bytes(b"")
    >>> _ = (root / SETTINGS).write_text("l0_mm: 200\\nbackground: empty.jpg\\n")
    >>> _ = (root / MANIFEST).write_text(
    ...     "image,pressure_kpa,direction,material,actuator,trial\\na_0kPa.jpg,0,up,DS20,A1,1\\n")
    >>> print(unlisted_problems(load_photoset(root))[0].message)
    1 photo in the folder is not in manifest.csv and will not be measured: 'a_10kpa.jpg'

    A photo named like an empty scene's is pointed to ``background``:

    >>> _ = (root / "empty_scene_A2.jpg").write_bytes(b"")
    >>> unlisted_problems(load_photoset(root))[0].fix[:52]
    "if 'empty_scene_A2.jpg' and the like are photos of t"
    """
    left = unlisted_photos(
        ps.folder,
        [str(i) for i in ps.manifest["image"] if not is_missing(i)],
        named=files_named_in(ps.folder, ps.settings, ps.manifest),
    )
    if not left:
        return []
    shown = ", ".join(repr(n) for n in left[:3]) + (", ..." if len(left) > 3 else "")
    boards = [n for n in left if BOARD_NAME.search(Path(n).stem)]
    empties = [n for n in left if EMPTY_NAME.search(Path(n).stem)]
    return [
        Problem(
            str(ps.folder / MANIFEST),
            None,
            f"{len(left)} photo{'s' if len(left) > 1 else ''} in the folder "
            f"{'are' if len(left) > 1 else 'is'} not in manifest.csv and will not be measured: "
            f"{shown}",
            (
                f"if {boards[0]!r} and the like are photos of a checkerboard for the camera's "
                "calibration, name them in photoset.yaml (calibration: {board: [...], "
                "square_mm: ..., inner_corners: [..., ...]}; README, 'A tilted camera or a real "
                "lens'): without it a camera not square to the plane or a lens that distorts "
                "puts psi off; else "
                if boards and "calibration" not in ps.settings
                else ""
            )
            + (
                # customer 36 was told to move its empty scenes out of the folder
                f"if {empties[0]!r} and the like are photos of the empty scene, name them as "
                "background (photoset.yaml: background: NAME; or a background column in "
                "manifest.csv, each actuator's rows their own; README, 'Measuring photos "
                "without a drawn line'); else "
                if empties
                else ""
            )
            + "add a row for each (or rename them to photoset init's pattern and run it again "
            "with --overwrite), or move them out of the folder if they do not belong to the set",
            warning=True,
        )
    ]


#: settings in pixels of one framing (a photo of another size needs its own)
FRAMING_KEYS: tuple[str, ...] = ("fixed_end", "mm_per_px", "roi", "exclude", "background")


def framing_keys(settings: Any) -> tuple[str, ...]:
    """The :data:`FRAMING_KEYS` a set's ``photoset.yaml`` gives (``fixed_end`` always: ``auto``
    is guessed per photo, but a row of its own says where its clamp is).

    >>> framing_keys({"l0_mm": 90, "roi": [0, 0, 10, 10], "fixed_end": [3, 4]})
    ('fixed_end', 'roi')
    """
    given = settings if isinstance(settings, dict) else {}
    return tuple(k for k in FRAMING_KEYS if k == "fixed_end" or given.get(k) is not None)


def _pixel_settings_given(settings: Any) -> bool:
    """Whether a set's ``photoset.yaml`` gives any setting in pixels (a ``fixed_end`` other
    than ``auto``, or another of :data:`FRAMING_KEYS`)."""
    given = settings if isinstance(settings, dict) else {}
    fixed = given.get("fixed_end")
    return (fixed is not None and str(fixed).strip().lower() != "auto") or any(
        given.get(k) is not None for k in FRAMING_KEYS if k != "fixed_end"
    )


def _own_framing(ps: PhotoSet) -> set[int]:
    """Manifest lines that give their own value of each of the set's :func:`framing_keys`
    (``fixed_end`` as one column or as ``fixed_end_x``)."""
    manifest = ps.manifest
    own = pd.Series(True, index=manifest.index)
    for key in framing_keys(ps.settings):
        given = pd.Series(False, index=manifest.index)
        for column in (key, f"{key}_x"):
            if column in manifest.columns:
                given |= ~manifest[column].map(is_missing).astype(bool)
        own &= given
    return {int(line) for line in manifest.loc[own, "manifest_line"]}


def size_problems(
    manifest: str,
    images: Sequence[tuple[int, str]],
    sizes: Mapping[str, tuple[int, int] | None],
    keys: Sequence[str] = ("fixed_end", "mm_per_px"),
    *,
    pixels_given: bool = True,
) -> list[Problem]:
    """A warning for each photo whose size differs from that of most of its set's photos (more
    than half; else from the first photo's): ``fixed_end``, ``roi``, ``exclude``, the
    background photo and ``mm_per_px`` are pixels of one framing. Pass the rows that do not
    give their own of each of the set's ``keys`` (:func:`framing_keys`; a set of crops, each
    with its own, is not warned of). ``pixels_given``: whether the set gives any setting in
    pixels; without, photos of several sizes, none of them most photos', are not warned of.

    Examples
    --------
    >>> sizes = {"a.jpg": (1280, 960), "b.jpg": (960, 1280), "c.jpg": (1280, 960)}
    >>> [p.line for p in size_problems("m.csv", [(2, "a.jpg"), (3, "b.jpg"), (4, "c.jpg")], sizes)]
    [3]

    Where no size is most photos' (customer 46: half of its set portrait), against the first's:

    >>> [p.line for p in size_problems("m.csv", [(3, "b.jpg"), (4, "c.jpg")], sizes)]
    [4]
    """
    known: list[tuple[int, str, tuple[int, int]]] = []
    for line, image in images:
        size = sizes.get(str(image))
        if size is not None:
            known.append((line, str(image), size))
    counts = Counter(size for _, _, size in known)
    if len(counts) < 2:
        return []
    (w, h), n = counts.most_common(1)[0]
    if 2 * n <= len(known):
        if not pixels_given:  # crops of several sizes, nothing given in pixels: nothing to say
            return []
        # no size of most photos (half portrait): the first photo's, for which the set's pixel
        # settings were most likely written
        (w, h) = known[0][2]
        n = counts[(w, h)]
    return [
        Problem(
            manifest,
            int(line),
            f"image {image!r} is {size[0]}x{size[1]} px where {n} of the set's photos are {w}x{h}: "
            "fixed_end, roi, exclude, the background photo and mm_per_px are pixels of one "
            "framing (a cropped or resized photo, or a phone turned to portrait?)",
            f"use the photo as taken, at {w}x{h}, or give this row its own "
            + ", ".join(keys) + " in manifest.csv",
            warning=True,
        )
        for line, image, size in known
        if size != (w, h)
    ]


def validate_photoset(
    folder: str | os.PathLike[str],
    *,
    decode_images: bool = True,
    require_images: bool = True,
    warnings: bool = False,
) -> list[Problem]:
    """Every problem of a photo set of images, each naming the file, the manifest line and the fix.

    For a video set only its rows, settings and calibrations: ``photoset check``
    (:func:`pipeline.photoset_check.check_photoset`) also checks its videos and pressure logs.

    Parameters
    ----------
    folder : path
        The photo-set folder.
    decode_images : bool
        Also decode every image with OpenCV to catch truncated or corrupt files, and check that
        an ``roi`` lies inside its photo.
    require_images : bool
        Report images named in the manifest that are missing.
    warnings : bool
        Also list doubts (``Problem.warning``) that do not make the set invalid.

    Returns
    -------
    list of Problem
        Empty when the photo set is valid (and, with ``warnings``, nothing is doubtful).
    """
    ps, problems = load_checked(folder)
    if ps is not None:
        problems += file_problems(ps, decode_images=decode_images, require_images=require_images)
    return [p for p in problems if warnings or not p.warning]


def scale_too_fine(l0_mm: float, mm_per_px: float, image_size: tuple[int, int]) -> bool:
    """Whether a line of ``l0_mm`` at ``mm_per_px`` could not lie in a photo of ``image_size``
    even curled into a ring (its diameter, l0 / pi, longer than the photo's diagonal): a scale ten
    times too fine, such as a board's ``square_mm`` of 2.5 for 25 mm squares (customer 32:
    "0.0106 mm per px" passed calibrate and check, and every row read "10% of l0 visible").

    Examples
    --------
    >>> scale_too_fine(210.0, 0.0106, (4032, 3024)), scale_too_fine(210.0, 0.106, (4032, 3024))
    (True, False)
    """
    return l0_mm / mm_per_px / np.pi > float(np.hypot(*image_size))


def _calibration_problems(ps: PhotoSet) -> list[Problem]:
    """Doubts about the calibrations: a large reprojection error (every row using it), not stored,
    mm_per_px unused."""
    from pipeline.measure.calibration import MAX_RMS_PX

    mpath, sname = str(ps.folder / MANIFEST), str(ps.folder / SETTINGS)
    out: list[Problem] = []
    seen: set[tuple[object, ...]] = set()
    for line, s in zip(ps.manifest["manifest_line"], ps.rows):
        cal = None if s is None else s.calibration
        if cal is None or cal.plane is None:
            continue
        board = Path(cal.boards[0]).name
        if cal.plane.doubtful:
            out.append(
                Problem(
                    mpath,
                    int(line),
                    f"calibration {board}: reprojection error {cal.plane.rms_px:.2f} px is above "
                    f"{MAX_RMS_PX:g} px: the row's psi is flagged",
                    "re-take the board photo flat, sharp and evenly lit, "
                    "check square_mm and inner_corners, or add board photos in other poses",
                    warning=True,
                )
            )
        if cal.key not in seen:
            seen.add(cal.key)
            if s is not None and scale_too_fine(s.l0_mm, cal.plane.mm_per_px, cal.plane.image_size):
                out.append(
                    Problem(
                        sname,
                        None,
                        f"calibration {board} gives {cal.plane.mm_per_px:.4g} mm per px, at which "
                        f"l0_mm = {s.l0_mm:g} is {s.l0_mm / cal.plane.mm_per_px:.0f} px long: "
                        "more than the photo could hold even curled into a ring",
                        "check the calibration's square_mm (the side of one square, in mm: 25 "
                        "for 25 mm squares, not 2.5) and l0_mm",
                        warning=True,
                    )
                )
            if not cal.stored:
                out.append(
                    Problem(
                        sname,
                        None,
                        f"calibration {board} is not stored (computed each time the set is read)",
                        f"run 'python -m pipeline photoset calibrate {ps.folder}'",
                        warning=True,
                    )
                )
        if s is not None and s.mm_per_px is not None and ("mm_per_px", cal.key) not in seen:
            seen.add(("mm_per_px", cal.key))
            out.append(
                Problem(
                    sname,
                    None,
                    f"mm_per_px is not used where calibration {board} applies (the plane gives the "
                    "scale)",
                    "remove mm_per_px, or keep it for the uncalibrated rows",
                    warning=True,
                )
            )
    return out


def geometry_problems(
    file: str, line: int, s: MeasureSettings, size: tuple[int, int]
) -> list[Problem]:
    """Settings of a row that do not fit its photo of ``size`` (width, height): calibration, roi,
    fixed end."""
    w, h = size
    out = []
    cal = s.calibration
    if cal is not None and cal.plane is not None and tuple(cal.plane.image_size) != (w, h):
        cw, ch = cal.plane.image_size
        out.append(
            Problem(
                file,
                line,
                f"the photo is {w}x{h} px but calibration board photo {Path(cal.boards[0]).name} "
                "is "
                f"{cw}x{ch} px",
                "take the board photo with the camera and resolution of the actuator photos "
                "(or give this row its own calibration)",
            )
        )
    roi_outside = False
    if s.roi is not None:
        xs, ys = [p[0] for p in s.roi], [p[1] for p in s.roi]
        roi_outside = max(xs) <= 0 or max(ys) <= 0 or min(xs) >= w or min(ys) >= h
        if roi_outside:
            out.append(
                Problem(
                    file,
                    line,
                    f"roi {list(s.roi)} lies outside the {w}x{h} photo",
                    "give roi in pixels of this photo (x right, y down)",
                )
            )
    if not roi_outside and (s.roi is not None or s.exclude):
        from pipeline.measure.extract import region_mask

        region = region_mask((h, w), s.roi, s.exclude)
        if region is not None and not region.any():
            out.append(
                Problem(
                    file,
                    line,
                    "exclude covers all of the roi" if s.roi is not None
                    else "exclude covers the whole photo",
                    "exclude only what is not the actuator (a plate, a ruler, a label), in pixels "
                    f"of this {w}x{h} photo (x right, y down; photoset preview draws the outlines)",
                )
            )
    if s.background_path is not None:
        from pipeline.measure.core import same_aspect, turned_by_90

        try:  # keyed by the file's time too: a replaced photo is read again
            bsize = _background_size(s.background_path, os.stat(s.background_path).st_mtime_ns)
        except OSError:
            bsize = (w, h)  # a missing background is the settings' problem
        if bsize is None:
            why, fix = undecodable(s.background_path)
            out.append(
                Problem(
                    file,
                    line,
                    f"background photo {Path(s.background_path).name} cannot be decoded ({why})",
                    fix,
                )
            )
        elif not same_aspect(bsize, (w, h)):
            turned = turned_by_90(bsize, (w, h))
            out.append(
                Problem(
                    file,
                    line,
                    f"the photo is {w}x{h} px but background photo "
                    f"{Path(s.background_path).name} is {bsize[0]}x{bsize[1]} px: it cannot be "
                    "laid over the photo"
                    + (
                        " (turned by 90 deg against it: a phone's photos are stored sideways "
                        "with an orientation tag, which an editor or a copy may have dropped or "
                        "applied to one and not the other)"
                        if turned
                        else ""
                    ),
                    "take the empty scene with the camera, resolution and orientation of the "
                    "actuator photos"
                    + (", or save it upright as they show" if turned else ""),
                )
            )
    if s.fixed_end_px is not None and not (
        0 <= s.fixed_end_px[0] < w and 0 <= s.fixed_end_px[1] < h
    ):
        out.append(
            Problem(
                file,
                line,
                f"fixed_end {list(s.fixed_end_px)} lies outside the {w}x{h} photo",
                "give the pixel near the clamped end (x right, y down)",
            )
        )
    return out


@functools.lru_cache(maxsize=8)
def _background_size(path: str, mtime_ns: int) -> tuple[int, int] | None:
    """(width, height) of a background photo, read once per check (``mtime_ns``: the cache key
    of its version)."""
    return _image_size(Path(path))


def _image_size(path: Path) -> tuple[int, int] | None:
    import cv2

    data = np.fromfile(str(path), dtype=np.uint8)
    if data.size == 0:
        return None
    img = cv2.imdecode(data, cv2.IMREAD_REDUCED_GRAYSCALE_8)
    if img is None:
        return None
    full = (
        cv2.imdecode(data, cv2.IMREAD_UNCHANGED)
        if path.suffix.lower() not in (".jpg", ".jpeg")
        else None
    )
    if full is not None:
        return full.shape[1], full.shape[0]
    from pipeline.measure.core import jpeg_size

    return jpeg_size(data)


# --------------------------------------------------------------------------------------------
# writing (atomic, so an interrupted acquisition never leaves a half-written file)


def write_manifest(folder: str | os.PathLike[str], rows: pd.DataFrame) -> None:
    """Write ``manifest.csv`` atomically (required columns first, ``manifest_line`` dropped)."""
    df = rows.drop(columns=["manifest_line"], errors="ignore")
    first = [
        c
        for c in (VIDEO_REQUIRED_COLUMNS if is_video_manifest(df) else REQUIRED_COLUMNS)
        if c in df.columns
    ]
    df = df[first + [c for c in df.columns if c not in first]]
    write_table(df, Path(folder) / MANIFEST, float_format=None)  # the input as given: every digit


def append_manifest_rows(
    folder: str | os.PathLike[str], rows: Iterable[Mapping[str, Any]]
) -> pd.DataFrame:
    """Append rows to ``manifest.csv`` atomically; rows whose image (video) is already listed are
    replaced.

    Returns
    -------
    pandas.DataFrame
        The manifest as written.
    """
    path = Path(folder) / MANIFEST
    new = pd.DataFrame(list(rows))
    if path.is_file():
        old = pd.read_csv(path, dtype=str)
        key = "video" if is_video_manifest(old) else "image"
        old = old[~old[key].isin(new[key].astype(str))]
        df = pd.concat([old, new.astype(str)], ignore_index=True)
    else:
        df = new
    write_manifest(folder, df)
    return df
