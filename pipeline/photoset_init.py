"""Start a photo set from a folder of photos: a manifest built from the image file names.

``python -m pipeline photoset init DIR --pattern
'{material}_{actuator}_t{trial}_{pressure_kpa}kPa.jpg'`` writes ``manifest.csv`` (and a starter
``photoset.yaml``); see :func:`init_photoset`.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.constants import DIRECTION_WORDS
from pipeline.errors import UserInputError
from pipeline.measure.formats import undecodable, unreadable_format
from pipeline.photoset import MANIFEST, SETTINGS, photo_names, write_manifest, write_settings

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


def pattern_to_regex(pattern: str) -> re.Pattern[str]:
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
        On an unknown field or a pattern without ``{pressure_kpa}``.
    """
    out, pos = [], 0
    names = []
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
    if "pressure_kpa" not in names:
        raise UserInputError(
            f"pattern {pattern!r} has no {{pressure_kpa}} field; the pressure must come from the "
            "file name"
        )
    return re.compile("".join(out) + r"\Z", re.IGNORECASE)  # kPa or kpa, .jpg or .JPG


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
    for name in photo_names(folder, subfolders="/" in pattern):
        m = regex.match(name)
        if not m:
            unmatched.append(name)
            continue
        fields = m.groupdict()
        row: dict[str, Any] = {"image": name}
        for key in ("material", "actuator", "trial"):
            row[key] = fields.get(key) or defaults.get(key)
            if row[key] is None:
                raise UserInputError(
                    f"{name}: no {key} in the file name and no default; pass --{key}"
                )
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
