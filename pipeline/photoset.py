"""The photo-set format shared by every stage (see DESIGN.md, "Photo set").

A photo set is a folder holding images, ``manifest.csv`` (one row per image) and ``photoset.yaml``
(folder-wide settings).  Any setting may also be a manifest column, which then overrides the
folder-wide value for that row (``fixed_end`` becomes ``fixed_end_x`` / ``fixed_end_y``).

This module reads, validates and writes that format; it knows nothing about where a photo set
came from (rig, synthetic renderer, a folder a lab copied in).

Examples
--------
>>> import tempfile, pathlib
>>> folder = pathlib.Path(tempfile.mkdtemp())
>>> write_settings(folder, {"l0_mm": 200.0, "line_color": "black", "positive_turn": "ccw"})
>>> read_settings(folder)["fixed_end"]
'auto'
"""

from __future__ import annotations

import os
import re
import tempfile
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from pipeline.errors import UserInputError

MANIFEST = "manifest.csv"
SETTINGS = "photoset.yaml"
TRUTH = "truth.csv"

REQUIRED_COLUMNS: tuple[str, ...] = ("image", "pressure_kpa", "direction", "material", "actuator", "trial")
OPTIONAL_COLUMNS: tuple[str, ...] = ("step", "timestamp", "measured_pressure_kpa")
DIRECTIONS: tuple[str, ...] = ("up", "down")
POSITIVE_TURNS: tuple[str, ...] = ("ccw", "cw")

#: folder-wide settings and their defaults (``None``: required)
SETTING_DEFAULTS: dict[str, Any] = {
    "l0_mm": None,
    "mm_per_px": None,
    "line_color": "black",
    "fixed_end": "auto",
    "positive_turn": "ccw",
}
#: settings that may be overridden per manifest row (column names)
OVERRIDE_COLUMNS: tuple[str, ...] = ("l0_mm", "mm_per_px", "line_color", "fixed_end_x", "fixed_end_y", "positive_turn")

#: named marker colours as lists of HSV ranges in OpenCV units (H 0-179, S and V 0-255)
NAMED_LINE_COLORS: dict[str, tuple[tuple[tuple[int, int, int], tuple[int, int, int]], ...]] = {
    "black": (((0, 0, 0), (179, 255, 80)),),
    "blue": (((95, 80, 40), (130, 255, 255)),),
    "green": (((40, 70, 40), (85, 255, 255)),),
    "red": (((0, 90, 50), (10, 255, 255)), ((170, 90, 50), (179, 255, 255))),
}

IMAGE_SUFFIXES: tuple[str, ...] = (".jpg", ".jpeg", ".png", ".tif", ".tiff", ".bmp")

HsvRange = tuple[tuple[int, int, int], tuple[int, int, int]]


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
    """

    file: str
    line: int | None
    message: str
    fix: str

    def __str__(self) -> str:
        where = f"{self.file} line {self.line}" if self.line is not None else self.file
        return f"{where}: {self.message} (fix: {self.fix})"


@dataclass(frozen=True)
class PhotoSet:
    """A loaded photo set.

    Attributes
    ----------
    folder : Path
        The photo-set folder.
    settings : dict
        Folder-wide settings from ``photoset.yaml`` with defaults filled in.
    manifest : pandas.DataFrame
        The manifest, one row per image, plus the resolved per-row settings columns
        ``l0_mm``, ``mm_per_px``, ``line_color``, ``fixed_end_x``, ``fixed_end_y``,
        ``positive_turn`` and ``manifest_line`` (1-based line in manifest.csv).
    """

    folder: Path
    settings: dict[str, Any]
    manifest: pd.DataFrame

    def image_path(self, image: str) -> Path:
        """Absolute path of an image named in the manifest."""
        return self.folder / image


# --------------------------------------------------------------------------------------------
# settings


def line_color_ranges(value: Any) -> tuple[HsvRange, ...]:
    """HSV ranges (OpenCV units) selecting a marker colour.

    Parameters
    ----------
    value : str or mapping or list
        A colour name (``black``, ``blue``, ``red``, ``green``), a mapping
        ``{"lower": [h, s, v], "upper": [h, s, v]}``, a list of such mappings (for hues that wrap,
        like red), or the string ``"h,s,v-h,s,v"``.

    Returns
    -------
    tuple of ((h, s, v), (h, s, v))

    Raises
    ------
    UserInputError
        If the value is neither a known name nor a valid range.

    Examples
    --------
    >>> line_color_ranges("blue")
    (((95, 80, 40), (130, 255, 255)),)
    >>> line_color_ranges("0,0,0-179,255,60")
    (((0, 0, 0), (179, 255, 60)),)
    """
    if isinstance(value, str):
        name = value.strip().lower()
        if name in NAMED_LINE_COLORS:
            return NAMED_LINE_COLORS[name]
        m = re.fullmatch(r"\s*(\d+),(\d+),(\d+)\s*-\s*(\d+),(\d+),(\d+)\s*", name)
        if m:
            v = [int(x) for x in m.groups()]
            return (_check_hsv_range((tuple(v[:3]), tuple(v[3:]))),)
        raise UserInputError(
            f"line_color {value!r} is not a known colour; use one of {sorted(NAMED_LINE_COLORS)} "
            "or an HSV range such as '0,0,0-179,255,80' (OpenCV units: H 0-179, S/V 0-255)"
        )
    if isinstance(value, Mapping):
        value = [value]
    if isinstance(value, (list, tuple)) and value and all(isinstance(v, Mapping) for v in value):
        out = []
        for v in value:
            try:
                lo, hi = tuple(int(x) for x in v["lower"]), tuple(int(x) for x in v["upper"])
            except (KeyError, TypeError, ValueError) as exc:
                raise UserInputError(
                    f"line_color range {v!r} needs 'lower' and 'upper' lists of three integers [h, s, v]"
                ) from exc
            out.append(_check_hsv_range((lo, hi)))
        return tuple(out)
    raise UserInputError(
        f"line_color {value!r} is not understood; give a name ({', '.join(sorted(NAMED_LINE_COLORS))}) "
        "or {lower: [h, s, v], upper: [h, s, v]}"
    )


def _check_hsv_range(rng: tuple[tuple[int, ...], tuple[int, ...]]) -> HsvRange:
    lo, hi = rng
    limits = (179, 255, 255)
    if len(lo) != 3 or len(hi) != 3 or any(not 0 <= a <= b <= m for a, b, m in zip(lo, hi, limits)):
        raise UserInputError(
            f"HSV range {lo}-{hi} is invalid: need 0 <= lower <= upper with H <= 179, S and V <= 255"
        )
    return (lo[0], lo[1], lo[2]), (hi[0], hi[1], hi[2])  # type: ignore[return-value]


def read_settings(folder: str | os.PathLike[str]) -> dict[str, Any]:
    """Read ``photoset.yaml`` with defaults filled in; raise a clear error when it is bad.

    Parameters
    ----------
    folder : path
        The photo-set folder.

    Returns
    -------
    dict
        Keys of :data:`SETTING_DEFAULTS` (and any extra keys found, kept as they are).
    """
    problems = _settings_problems(Path(folder), require_l0=False)
    if problems:
        raise UserInputError("; ".join(str(p) for p in problems))
    raw = yaml.safe_load((Path(folder) / SETTINGS).read_text()) or {}
    return {**SETTING_DEFAULTS, **raw}


def _settings_problems(folder: Path, require_l0: bool = True) -> list[Problem]:
    path = folder / SETTINGS
    name = str(path)
    if not folder.is_dir():
        return [Problem(str(folder), None, "photo-set folder does not exist", "check the path in the config or command")]
    if not path.is_file():
        return [Problem(name, None, "missing", f"create it (python -m pipeline photoset init {folder}) with at least l0_mm")]
    try:
        raw = yaml.safe_load(path.read_text()) or {}
    except yaml.YAMLError as exc:
        return [Problem(name, None, f"not valid YAML ({exc})", "fix the YAML syntax")]
    if not isinstance(raw, dict):
        return [Problem(name, None, "must be a mapping of key: value", "write e.g. 'l0_mm: 200'")]
    out: list[Problem] = []
    s = {**SETTING_DEFAULTS, **raw}
    if s["l0_mm"] is None and require_l0:
        out.append(Problem(name, None, "l0_mm is missing", "add 'l0_mm: <length of the marked layer in mm>' (or an l0_mm manifest column)"))
    out += _value_problems(name, None, s)
    return out


def _value_problems(file: str, line: int | None, s: Mapping[str, Any]) -> list[Problem]:
    out: list[Problem] = []
    for key in ("l0_mm", "mm_per_px"):
        v = s.get(key)
        if v is None or (isinstance(v, float) and np.isnan(v)):
            continue
        if not isinstance(v, (int, float, np.number)) or not np.isfinite(v) or v <= 0:
            out.append(Problem(file, line, f"{key} = {v!r} must be a positive number", f"set {key} to a length in mm" + ("" if key == "l0_mm" else " per pixel, or leave it out")))
    turn = s.get("positive_turn")
    if turn is not None and turn not in POSITIVE_TURNS:
        out.append(Problem(file, line, f"positive_turn = {turn!r}", "use 'ccw' or 'cw'"))
    color = s.get("line_color")
    if color is not None and not (isinstance(color, float) and np.isnan(color)):
        try:
            line_color_ranges(color)
        except UserInputError as exc:
            out.append(Problem(file, line, str(exc), "fix line_color"))
    fe = s.get("fixed_end")
    if fe is not None and fe != "auto":
        if not (isinstance(fe, (list, tuple)) and len(fe) == 2 and all(isinstance(x, (int, float)) for x in fe)):
            out.append(Problem(file, line, f"fixed_end = {fe!r}", "use 'auto' or a pixel position [x, y] near the clamped end"))
    return out


def write_settings(folder: str | os.PathLike[str], settings: Mapping[str, Any]) -> None:
    """Write ``photoset.yaml`` atomically (defaults filled in, keys in a stable order)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    data = {**SETTING_DEFAULTS, **dict(settings)}
    if isinstance(data.get("fixed_end"), tuple):
        data["fixed_end"] = [float(x) for x in data["fixed_end"]]
    text = yaml.safe_dump(data, sort_keys=False, default_flow_style=None)
    atomic_write_bytes(folder / SETTINGS, text.encode())


# --------------------------------------------------------------------------------------------
# manifest


def read_manifest(folder: str | os.PathLike[str]) -> pd.DataFrame:
    """Read ``manifest.csv`` as written (strings kept as strings), adding ``manifest_line``.

    Raises
    ------
    UserInputError
        If the file is missing, unparsable or lacks a required column.
    """
    path = Path(folder) / MANIFEST
    if not path.is_file():
        raise UserInputError(f"{path}: missing; create it with 'python -m pipeline photoset init {folder} --pattern ...'")
    try:
        df = pd.read_csv(path, dtype={"image": str, "material": str, "actuator": str, "direction": str, "trial": str})
    except (pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise UserInputError(f"{path}: cannot be parsed as CSV ({exc}); fix the file") from exc
    missing = [c for c in REQUIRED_COLUMNS if c not in df.columns]
    if missing:
        raise UserInputError(
            f"{path}: missing column(s) {missing}; the header must contain {list(REQUIRED_COLUMNS)}"
        )
    df["manifest_line"] = np.arange(len(df), dtype=int) + 2
    return df


def resolve_settings(manifest: pd.DataFrame, settings: Mapping[str, Any]) -> pd.DataFrame:
    """Add the per-row effective settings (manifest column overrides photoset.yaml value).

    Parameters
    ----------
    manifest : pandas.DataFrame
        As returned by :func:`read_manifest`.
    settings : mapping
        As returned by :func:`read_settings`.

    Returns
    -------
    pandas.DataFrame
        A copy with columns ``l0_mm``, ``mm_per_px``, ``line_color``, ``fixed_end_x``,
        ``fixed_end_y`` (NaN for ``auto``) and ``positive_turn`` filled for every row.
    """
    df = manifest.copy()
    fe = settings.get("fixed_end", "auto")
    folder_fe = (np.nan, np.nan) if fe in (None, "auto") else (float(fe[0]), float(fe[1]))
    folder_values = {
        "l0_mm": settings.get("l0_mm"),
        "mm_per_px": settings.get("mm_per_px"),
        "line_color": settings.get("line_color", "black"),
        "positive_turn": settings.get("positive_turn", "ccw"),
        "fixed_end_x": folder_fe[0],
        "fixed_end_y": folder_fe[1],
    }
    for key, value in folder_values.items():
        fill = np.nan if value is None else value
        rows = df[key] if key in df.columns else [None] * len(df)
        df[key] = pd.Series([fill if _is_missing(v) else v for v in rows], index=df.index, dtype=object)
    for key in ("l0_mm", "mm_per_px", "fixed_end_x", "fixed_end_y", "pressure_kpa"):
        df[key] = pd.to_numeric(df[key], errors="coerce")
    return df


def _is_missing(value: Any) -> bool:
    return value is None or (isinstance(value, (float, np.floating)) and np.isnan(value))


def load_photoset(folder: str | os.PathLike[str]) -> PhotoSet:
    """Load a photo set, refusing it with every problem listed when it is not valid.

    Image files are checked for existence but not decoded (measurement flags unreadable ones
    per image, so one bad photo never stops the set).

    Raises
    ------
    UserInputError
        Listing every problem (file, line, fix).
    """
    folder = Path(folder)
    problems = validate_photoset(folder, decode_images=False, require_images=False)
    if problems:
        raise UserInputError(
            f"photo set {folder} is not valid ({len(problems)} problem(s)):\n  " + "\n  ".join(map(str, problems))
        )
    settings = read_settings(folder)
    manifest = resolve_settings(read_manifest(folder), settings)
    return PhotoSet(folder=folder, settings=settings, manifest=manifest)


def validate_photoset(
    folder: str | os.PathLike[str], *, decode_images: bool = True, require_images: bool = True
) -> list[Problem]:
    """Every problem of a photo set, each naming the file, the manifest line and the fix.

    Parameters
    ----------
    folder : path
        The photo-set folder.
    decode_images : bool
        Also decode every image with OpenCV to catch truncated or corrupt files.
    require_images : bool
        Report images named in the manifest that are missing.  Loading for measurement sets
        this to False: a missing image is then a ``failed`` row, not a refused set.

    Returns
    -------
    list of Problem
        Empty when the photo set is valid.
    """
    folder = Path(folder)
    problems = _settings_problems(folder, require_l0=False)
    if problems and not folder.is_dir():
        return problems
    try:
        df = read_manifest(folder)
    except UserInputError as exc:
        return problems + [Problem(str(folder / MANIFEST), None, str(exc), "see message")]
    l0_in_rows = "l0_mm" in df.columns and bool(pd.to_numeric(df["l0_mm"], errors="coerce").notna().all())
    if not l0_in_rows and not problems and read_settings(folder).get("l0_mm") is None:
        problems.append(Problem(str(folder / SETTINGS), None, "l0_mm is missing", "add 'l0_mm: <length of the marked layer in mm>' (or an l0_mm manifest column)"))
    mpath = str(folder / MANIFEST)
    if len(df) == 0:
        problems.append(Problem(mpath, None, "has no rows", "add one row per image"))
    pressure = pd.to_numeric(df["pressure_kpa"], errors="coerce")
    seen_images: dict[str, int] = {}
    for i, row in df.iterrows():
        line = int(row["manifest_line"])
        image = row["image"]
        if not isinstance(image, str) or not image.strip():
            problems.append(Problem(mpath, line, "image name is empty", "put the image file name in the 'image' column"))
        else:
            if image in seen_images:
                problems.append(Problem(mpath, line, f"image {image!r} is listed twice (also line {seen_images[image]})", "remove the duplicate row"))
            seen_images.setdefault(image, line)
            path = folder / image
            if not path.is_file():
                if require_images:
                    problems.append(Problem(mpath, line, f"image {image!r} does not exist in {folder}", "copy the photo in or remove the row"))
            elif decode_images and not _image_decodes(path):
                problems.append(Problem(mpath, line, f"image {image!r} cannot be decoded (corrupt, truncated or not an image)", "re-export or re-take the photo, or remove the row"))
        if not np.isfinite(pressure.iloc[i]):
            problems.append(Problem(mpath, line, f"pressure_kpa {row['pressure_kpa']!r} is not a number", "write the pressure in kPa, e.g. 40"))
        elif pressure.iloc[i] < 0:
            problems.append(Problem(mpath, line, f"pressure_kpa {pressure.iloc[i]} is negative", "use gauge pressure in kPa (>= 0)"))
        if row["direction"] not in DIRECTIONS:
            problems.append(Problem(mpath, line, f"direction {row['direction']!r} is unknown", "use 'up' (increasing pressure) or 'down' (decreasing)"))
        for key in ("material", "actuator", "trial"):
            if pd.isna(row[key]) or str(row[key]).strip() == "":
                problems.append(Problem(mpath, line, f"{key} is empty", f"fill in the {key}"))
        overrides = {k: row[k] for k in ("l0_mm", "mm_per_px", "positive_turn", "line_color") if k in df.columns and not pd.isna(row[k])}
        if overrides:
            problems += _value_problems(mpath, line, overrides)
    if "step" in df.columns:
        keys = ["material", "actuator", "trial", "step"]
        dup = df[df.duplicated(keys, keep="first")]
        for _, row in dup.iterrows():
            problems.append(Problem(mpath, int(row["manifest_line"]), f"step {row['step']} repeats for material {row['material']}, actuator {row['actuator']}, trial {row['trial']}", "renumber the steps or remove the duplicate row"))
    return problems


def _image_decodes(path: Path) -> bool:
    import cv2

    data = np.fromfile(str(path), dtype=np.uint8)
    return data.size > 0 and cv2.imdecode(data, cv2.IMREAD_REDUCED_GRAYSCALE_8) is not None


# --------------------------------------------------------------------------------------------
# writing (atomic, so an interrupted acquisition never leaves a half-written file)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically: temporary file in the same folder, fsync, rename."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        os.fchmod(fd, 0o666 & ~_current_umask())  # mkstemp makes 0600; a normal file honours the umask
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    _fsync_dir(path.parent)


def _current_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _fsync_dir(folder: Path) -> None:
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def write_manifest(folder: str | os.PathLike[str], rows: pd.DataFrame) -> None:
    """Write ``manifest.csv`` atomically (required columns first, ``manifest_line`` dropped)."""
    df = rows.drop(columns=["manifest_line"], errors="ignore")
    first = [c for c in REQUIRED_COLUMNS if c in df.columns]
    df = df[first + [c for c in df.columns if c not in first]]
    atomic_write_bytes(Path(folder) / MANIFEST, df.to_csv(index=False, lineterminator="\n").encode())


def append_manifest_rows(folder: str | os.PathLike[str], rows: Iterable[Mapping[str, Any]]) -> pd.DataFrame:
    """Append rows to ``manifest.csv`` atomically; rows whose image is already listed are replaced.

    Returns
    -------
    pandas.DataFrame
        The manifest as written.
    """
    path = Path(folder) / MANIFEST
    new = pd.DataFrame(list(rows))
    if path.is_file():
        old = pd.read_csv(path, dtype=str)
        old = old[~old["image"].isin(new["image"].astype(str))]
        df = pd.concat([old, new.astype(str)], ignore_index=True)
    else:
        df = new
    write_manifest(folder, df)
    return df


# --------------------------------------------------------------------------------------------
# init from file names


_FIELD_PATTERNS: dict[str, str] = {
    "pressure_kpa": r"[-+]?\d+(?:[.p]\d+)?",
    "measured_pressure_kpa": r"[-+]?\d+(?:[.p]\d+)?",
    "step": r"\d+",
    "trial": r"[A-Za-z0-9]+",
    "actuator": r"[A-Za-z0-9]+",
    "material": r"[A-Za-z0-9]+",
    "direction": r"[A-Za-z]+",
    "_": r".*?",
}

_DIRECTION_WORDS: dict[str, str] = {
    "up": "up", "u": "up", "inc": "up", "increasing": "up", "load": "up", "loading": "up",
    "down": "down", "d": "down", "dn": "down", "dec": "down", "decreasing": "down", "unload": "down", "unloading": "down",
}


def pattern_to_regex(pattern: str) -> re.Pattern[str]:
    """Compile a file-name pattern such as ``'{material}_{actuator}_t{trial}_{pressure_kpa}kPa.jpg'``.

    Fields: ``pressure_kpa``, ``direction``, ``trial``, ``actuator``, ``material``, ``step``,
    ``measured_pressure_kpa`` and ``_`` (anything, ignored); ``*`` matches anything too.
    Decimal points in pressures may be written ``p`` (``12p5`` = 12.5 kPa).

    Raises
    ------
    UserInputError
        On an unknown field or a pattern without ``{pressure_kpa}``.
    """
    out, pos = [], 0
    names = []
    for m in re.finditer(r"\{([A-Za-z_]+)\}", pattern):
        out.append(re.escape(pattern[pos : m.start()]).replace(r"\*", ".*?"))
        name = m.group(1)
        if name not in _FIELD_PATTERNS:
            raise UserInputError(f"pattern field {{{name}}} is unknown; use {sorted(_FIELD_PATTERNS)}")
        if name == "_":
            out.append(_FIELD_PATTERNS["_"])
        else:
            if name in names:
                raise UserInputError(f"pattern field {{{name}}} appears twice")
            names.append(name)
            out.append(f"(?P<{name}>{_FIELD_PATTERNS[name]})")
        pos = m.end()
    out.append(re.escape(pattern[pos:]).replace(r"\*", ".*?"))
    if "pressure_kpa" not in names:
        raise UserInputError(f"pattern {pattern!r} has no {{pressure_kpa}} field; the pressure must come from the file name")
    return re.compile("".join(out) + r"\Z")


def init_photoset(
    folder: str | os.PathLike[str],
    pattern: str,
    *,
    defaults: Mapping[str, Any] | None = None,
    settings: Mapping[str, Any] | None = None,
    overwrite: bool = False,
) -> pd.DataFrame:
    """Write a starter ``manifest.csv`` (and ``photoset.yaml`` if absent) from image file names.

    Fields missing from the pattern come from ``defaults`` (``material``, ``actuator``,
    ``trial``).  When the pattern has no ``{direction}``, it is inferred per actuator and trial
    from the order of the photos (by ``step`` if present, else by file name): ``up`` until the
    highest pressure, ``down`` after it.

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

    Returns
    -------
    pandas.DataFrame
        The manifest written.

    Raises
    ------
    UserInputError
        If no file matches, a field is missing with no default, or a manifest exists.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise UserInputError(f"{folder}: not a folder; give the folder that holds the photos")
    if (folder / MANIFEST).exists() and not overwrite:
        raise UserInputError(f"{folder / MANIFEST} already exists; pass --overwrite to replace it")
    regex = pattern_to_regex(pattern)
    defaults = {"material": None, "actuator": "A1", "trial": "1", **(defaults or {})}
    rows, unmatched = [], []
    for path in sorted(p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES):
        m = regex.match(path.name)
        if not m:
            unmatched.append(path.name)
            continue
        fields = m.groupdict()
        row: dict[str, Any] = {"image": path.name}
        for key in ("material", "actuator", "trial"):
            row[key] = fields.get(key) or defaults.get(key)
            if row[key] is None:
                raise UserInputError(f"{path.name}: no {key} in the file name and no default; pass --{key}")
        row["pressure_kpa"] = float(fields["pressure_kpa"].replace("p", "."))
        if fields.get("step") is not None:
            row["step"] = int(fields["step"])
        if fields.get("measured_pressure_kpa") is not None:
            row["measured_pressure_kpa"] = float(fields["measured_pressure_kpa"].replace("p", "."))
        if fields.get("direction") is not None:
            word = fields["direction"].lower()
            if word not in _DIRECTION_WORDS:
                raise UserInputError(f"{path.name}: direction {fields['direction']!r} unknown; use up/down (or inc/dec)")
            row["direction"] = _DIRECTION_WORDS[word]
        rows.append(row)
    if not rows:
        raise UserInputError(
            f"no image in {folder} matches pattern {pattern!r}"
            + (f" (e.g. {unmatched[0]!r} does not)" if unmatched else " (no images found)")
        )
    df = pd.DataFrame(rows)
    if "direction" not in df.columns:
        df["direction"] = _infer_directions(df)
    if "step" not in df.columns:
        df["step"] = df.groupby(["material", "actuator", "trial"], sort=False).cumcount()
    write_manifest(folder, df)
    if not (folder / SETTINGS).exists():
        write_settings(folder, {"l0_mm": None, **dict(settings or {})})
    return df


def _infer_directions(df: pd.DataFrame) -> pd.Series:
    out = pd.Series("up", index=df.index, dtype=object)
    order = "step" if "step" in df.columns else "image"
    for _, g in df.groupby(["material", "actuator", "trial"], sort=False):
        g = g.sort_values(order)
        peak = int(np.argmax(g["pressure_kpa"].to_numpy()))
        out.loc[g.index[peak + 1 :]] = "down"
    return out
