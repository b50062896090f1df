"""The settings one photo is measured with, resolved once into a typed, frozen object.

A photo set's ``photoset.yaml`` holds folder-wide values and ``manifest.csv`` may override any
of them per row (DESIGN.md, "Photo set").  :func:`resolve_settings` turns the merged raw values
of one row into a :class:`MeasureSettings` -- or into the list of problems that prevent it --
and nothing downstream (measure, force, rig, preview) decodes a setting again.

Keys
----
``l0_mm``
    Length of the marked inextensible layer (mm, > 0). Required.
``mm_per_px``
    Image scale (mm per px, > 0); without it psi is the total turning of the measured line.
``line_color``
    Colour of the target (see :mod:`pipeline.measure.colors`).  For ``target: line`` the
    default is ``black``; for ``target: body`` the default is none: the body is whatever
    differs from the background.
``fixed_end``
    ``auto`` or a pixel ``[x, y]`` near the clamped end (manifest: ``fixed_end_x``,
    ``fixed_end_y``).
``positive_turn``
    ``ccw`` or ``cw``: the on-screen turning (fixed end -> free end) that counts positive.
``target``
    ``line`` (a drawn line, the paper's method) or ``body`` (the actuator's own outline).
``background``
    A photo of the empty scene (file name in the folder): the body is what differs from it.
``roi``
    Where the actuator can be: a box ``[x0, y0, x1, y1]`` or a polygon ``[[x, y], ...]`` (px).
``exclude``
    Polygons (or boxes) to ignore: a ruler, a clamp plate, a label.
``fixed_direction_deg``
    Direction in which the actuator leaves the clamp, on screen, degrees counter-clockwise from
    +x: psi is then the free end's tangent against this direction.
``free_end``
    ``capped`` (the default: an actuator's sealed end, which does not bend; psi is the direction
    where the body's centre line stops) or ``bends`` (a free strip cut at its end, with no sealed
    end: the end's turning is carried on to the body's last pixel).  ``target: body`` only.
``sealed_end_mm``
    Length of the actuator's end that does not bend, from where its chamber ends to its tip
    (sealed end and any cap, mm, >= 0): psi is then read that far back from the tip's face, not
    where the centre line stops.  Needs ``mm_per_px`` or ``calibration``; ``target: body`` with
    ``free_end: capped`` only.
``body_width_mm``
    The body's width as the camera sees it (mm, > 0; a PneuNet's strip and chambers together):
    with ``mm_per_px`` a photo whose body is read more than 20 % wider or narrower is flagged
    (its shadow taken in, or a faint side left out; :func:`pipeline.measure.quality.width_off`).
    ``target: body`` only; leave it out for a body that swells under pressure.
``method``
    The estimator for these photos (a key of :data:`pipeline.measure.METHODS`); without it the
    run's method (``--method``, config ``measure.method``) applies.
``calibration``
    A photo of a printed checkerboard lying in the actuator's plane, its square size and inner
    corners: ``{board: board.jpg, square_mm: 25, inner_corners: [9, 6]}`` (``board`` may list
    more photos, the first in the plane, the others for the lens).  psi is then measured on the
    plane (:mod:`pipeline.measure.calibration`) and ``mm_per_px`` is not used.  In a manifest
    column: such a mapping, or only the board photo's name (square and corners from
    photoset.yaml), for sets taken over several sessions.

Examples
--------
>>> s = resolve_settings({"l0_mm": 210, "roi": [0, 0, 100, 50], "target": "body"})
>>> s.target, s.color, s.roi[2]
('body', None, (100.0, 50.0))
>>> resolve_settings({"l0_mm": -1})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
pipeline.measure.settings.SettingsError: l0_mm = -1 must be a positive number (fix: set l0_mm ...)
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from pipeline.fileio import user_path
from pipeline.measure.calibration import (
    Calibration,
    CalibrationCache,
    CalibrationError,
    describe_problem,
)
from pipeline.measure.colors import BLACK, ColorError, ColorSpec, parse_color

#: a polygon in image pixels: ((x, y), ...)
Polygon = tuple[tuple[float, float], ...]

TARGETS: tuple[str, ...] = ("line", "body")
POSITIVE_TURNS: tuple[str, ...] = ("ccw", "cw")
FREE_ENDS: tuple[str, ...] = ("capped", "bends")
#: every settings key, as it may appear in photoset.yaml (fixed_end as fixed_end_x/_y in rows)
KEYS: tuple[str, ...] = (
    "l0_mm", "mm_per_px", "line_color", "fixed_end", "positive_turn", "target", "background", "roi",
    "exclude", "fixed_direction_deg", "free_end", "sealed_end_mm", "method", "calibration",
    "body_width_mm",
)
#: manifest columns that override photoset.yaml per row
OVERRIDE_COLUMNS: tuple[str, ...] = (
    "l0_mm",
    "mm_per_px",
    "line_color",
    "fixed_end_x",
    "fixed_end_y",
    "positive_turn",
    "target",
    "background",
    "roi",
    "exclude",
    "fixed_direction_deg",
    "free_end",
    "sealed_end_mm",
    "method",
    "calibration",
    "body_width_mm",
)


@dataclass(frozen=True)
class SettingProblem:
    """Why one setting cannot be used: the key, what is wrong, and the fix."""

    key: str
    message: str
    fix: str

    def __str__(self) -> str:
        return f"{self.message} (fix: {self.fix})"


class SettingsError(ValueError):
    """Settings that cannot be resolved; ``problems`` lists each one."""

    def __init__(self, problems: Sequence[SettingProblem]):
        self.problems = tuple(problems)
        super().__init__("; ".join(map(str, self.problems)))


@dataclass(frozen=True)
class MeasureSettings:
    """Everything that says how one photo is measured (resolved, validated, picklable).

    Attributes
    ----------
    l0_mm : float
        Length of the marked inextensible layer (mm).
    mm_per_px : float or None
        Image scale; None: psi is the total turning of the measured line.
    color : ColorSpec or None
        Colour of the line or body; None (body only): whatever differs from the background.
    fixed_end_px : (x, y) or None
        Pixel near the clamped end; None: guessed.
    positive_turn : {"ccw", "cw"}
        On-screen turning (fixed end -> free end) that counts as positive psi.
    target : {"line", "body"}
        A drawn line, or the actuator's body.
    background_path : str or None
        Photo of the empty scene (absolute path).
    background_estimated : bool
        ``background_path`` is not a photo of the empty scene but an estimate of it from the
        other photos of the ramp (:mod:`pipeline.measure.ramp_background`): where it still shows
        the body, the backdrop decides.
    video_frame : bool
        A frame of a video, exposed while the actuator may move (set by the video measurement,
        not a key): a free end wider than the body is then a smeared one.
    roi : Polygon or None
        Where the actuator can be (px); None: the whole photo.
    exclude : tuple of Polygon
        Regions to ignore (px).
    fixed_direction_deg : float or None
        Known direction (deg, ccw from +x on screen) in which the actuator leaves the clamp.
    free_end : {"capped", "bends"}
        The body's free end is a sealed end that does not bend, or a cut end that bends with the
        rest (``target: body``).
    sealed_end_mm : float or None
        Length of the body's end that does not bend (mm); None: unknown, psi is read where the
        centre line stops.
    method : str or None
        Estimator for these photos; None: the run's.
    body_width_mm : float or None
        The body's width as the camera sees it (mm); None: not checked.
    calibration : Calibration or None
        Board photo(s), square size, inner corners and the computed plane calibration; None:
        measured in the image (scaled by ``mm_per_px``).
    """

    l0_mm: float
    mm_per_px: float | None = None
    color: ColorSpec | None = BLACK
    fixed_end_px: tuple[float, float] | None = None
    positive_turn: str = "ccw"
    target: str = "line"
    background_path: str | None = None
    background_estimated: bool = False
    video_frame: bool = False
    roi: Polygon | None = None
    exclude: tuple[Polygon, ...] = ()
    fixed_direction_deg: float | None = None
    free_end: str = "capped"
    sealed_end_mm: float | None = None
    method: str | None = None
    calibration: Calibration | None = None
    body_width_mm: float | None = None

    @property
    def sign(self) -> float:
        """+1 for ``ccw``, -1 for ``cw``."""
        return 1.0 if self.positive_turn == "ccw" else -1.0

    @property
    def base_given_deg(self) -> float:
        """``fixed_direction_deg`` in the convention of a measured base direction (clockwise
        with ``positive_turn: cw``, as psi); NaN when not given."""
        given = self.fixed_direction_deg
        return float("nan") if given is None else self.sign * given

    @property
    def calibration_rms(self) -> tuple[float, float]:
        """Reprojection error (px, mm) of the camera calibration the photo is measured with
        (angles.csv's ``calibration_px`` and ``calibration_mm``); NaN without one."""
        plane = None if self.calibration is None else self.calibration.plane
        return (float("nan"),) * 2 if plane is None else (plane.rms_px, plane.rms_mm)

    def describe_color(self) -> str:
        """The selection in words, for reasons and previews."""
        if self.color is None:
            return "differs from the " + (
                "background photo" if self.background_path else "backdrop"
            )
        return f"line_color {self.color.describe()}"


def is_missing(value: Any) -> bool:
    """True for None, NaN and empty strings (an empty manifest cell).

    Examples
    --------
    >>> is_missing(float("nan")), is_missing(""), is_missing(0)
    (True, True, False)
    """
    if value is None:
        return True
    if isinstance(value, float) and math.isnan(value):
        return True
    return isinstance(value, str) and not value.strip()


#: digit groups: 1,234,567 or 1,234.5 (English); 1.234.567 or 1.234,5 (German)
_GROUPED_POINT = re.compile(r"[+-]?\d{1,3}(?:,\d{3})+\.\d+|[+-]?\d{1,3}(?:,\d{3}){2,}")
_GROUPED_COMMA = re.compile(r"[+-]?\d{1,3}(?:\.\d{3})+,\d+|[+-]?\d{1,3}(?:\.\d{3}){2,}")
#: one comma before three digits: 1,500 is 1500 in English and 1.5 in German
_AMBIGUOUS = re.compile(r"[+-]?[1-9]\d{0,2},\d{3}")


def user_float(value: Any) -> float:
    """A number as a person wrote it (a YAML number, or text with a decimal point or comma, or
    with digit groups); NaN when it is none (``True`` is none either) or when it could be either
    of two numbers (see :func:`number_doubt`).

    Examples
    --------
    >>> user_float("0,3"), user_float(" 12.5 "), user_float(4)
    (0.3, 12.5, 4.0)
    >>> user_float("1,234.5"), user_float("1.234,5"), user_float("2,500,000")
    (1234.5, 1234.5, 2500000.0)
    >>> [math.isnan(user_float(v)) for v in ("1,2,3", "255 mm", True, None, "1,500")]
    [True, True, True, True, True]
    """
    if isinstance(value, bool):
        return float("nan")
    if isinstance(value, str):
        text = value.strip()
        if _AMBIGUOUS.fullmatch(text):
            return float("nan")
        if _GROUPED_POINT.fullmatch(text):
            value = text.replace(",", "")
        elif _GROUPED_COMMA.fullmatch(text):
            value = text.replace(".", "").replace(",", ".")
        else:
            value = text.replace(",", ".", 1)
    try:
        return float(value)
    except (TypeError, ValueError):
        return float("nan")


def user_floats(values: pd.Series) -> np.ndarray:
    """:func:`user_float` of every cell, the plain numbers read at once (a long pressure log).

    Examples
    --------
    >>> user_floats(pd.Series([1, "2,5", "x", None])).tolist()[:3]
    [1.0, 2.5, nan]
    """
    out = pd.to_numeric(values, errors="coerce").to_numpy(float, copy=True)
    odd = ~np.isfinite(out)
    out[odd] = [user_float(v) for v in values[odd]]
    return out


def number_doubt(value: Any) -> str:
    """Why a written number is not read, when it is neither number nor nonsense; else "".

    Examples
    --------
    >>> number_doubt("1,500")
    '1500 with a thousands separator, or 1.5 with a decimal comma?'
    >>> number_doubt("1.5"), number_doubt("abc")
    ('', '')
    """
    text = value.strip() if isinstance(value, str) else ""
    if not _AMBIGUOUS.fullmatch(text):
        return ""
    whole, part = text.split(",")
    decimal = f"{whole}.{part.rstrip('0') or '0'}"
    return f"{whole}{part} with a thousands separator, or {decimal} with a decimal comma?"


def _number(
    raw: Mapping[str, Any], key: str, problems: list[SettingProblem], fix: str
) -> float | None:
    value: Any = raw.get(key)  # anything a user wrote; float() refuses what is no number
    if is_missing(value):
        return None
    number = user_float(value)
    if not math.isfinite(number) or number <= 0:
        doubt = number_doubt(value)
        problems.append(
            SettingProblem(
                key,
                f"{key} = {value!r} "
                + (f"could be either number: {doubt}" if doubt else "must be a positive number"),
                f"write it without a thousands separator, with a decimal point; {fix}"
                if doubt
                else fix,
            )
        )
        return None
    return number


def _choice(
    raw: Mapping[str, Any],
    key: str,
    choices: tuple[str, ...],
    problems: list[SettingProblem],
    fix: str,
) -> str:
    """``raw[key]`` as one of ``choices`` (case and spaces ignored; missing: the first), or the
    first with a problem added.

    Examples
    --------
    >>> problems = []
    >>> _choice({"target": " Body"}, "target", TARGETS, problems, "fix"), problems
    ('body', [])
    >>> _choice({"target": "tip"}, "target", TARGETS, problems, "use line or body")
    'line'
    >>> problems[0].message
    "target = 'tip'"
    """
    value = raw.get(key)
    choice = choices[0] if is_missing(value) else str(value).strip().lower()
    if choice not in choices:
        problems.append(SettingProblem(key, f"{key} = {value!r}", fix))
        return choices[0]
    return choice


def _points(value: Any, key: str) -> Polygon:
    """A polygon from ``[[x, y], ...]`` or a box ``[x0, y0, x1, y1]`` (strings parsed as YAML)."""
    if isinstance(value, str):
        import yaml

        try:
            value = yaml.safe_load(value)
        except yaml.YAMLError as exc:
            raise ValueError(f"{key} {value!r} is not a list ({exc})") from None
    if not isinstance(value, (list, tuple)):
        raise ValueError(  # noqa: TRY004 (callers report ValueError as a Problem)
            f"{key} = {value!r} is not a box [x0, y0, x1, y1] or a polygon [[x, y], ...]"
        )
    if len(value) == 4 and all(
        isinstance(v, numbers.Real) and not isinstance(v, bool) for v in value
    ):
        x0, y0, x1, y1 = (float(v) for v in value)
        if not (x1 > x0 and y1 > y0):
            raise ValueError(f"{key} box {list(value)} needs x1 > x0 and y1 > y0")
        return ((x0, y0), (x1, y0), (x1, y1), (x0, y1))
    pts = []
    for p in value:
        if not (
            isinstance(p, (list, tuple))
            and len(p) == 2
            and all(isinstance(c, numbers.Real) and not isinstance(c, bool) for c in p)
        ):
            raise ValueError(f"{key} point {p!r} is not [x, y]")
        pts.append((float(p[0]), float(p[1])))
    if len(pts) < 3:
        raise ValueError(f"{key} polygon has {len(pts)} point(s); a polygon needs at least 3")
    return tuple(pts)


def _fixed_end(
    raw: Mapping[str, Any], problems: list[SettingProblem]
) -> tuple[float, float] | None:
    if "fixed_end_x" in raw or "fixed_end_y" in raw:
        x, y = raw.get("fixed_end_x"), raw.get("fixed_end_y")
        if not (is_missing(x) and is_missing(y)):
            fx, fy = user_float(x), user_float(y)
            if math.isfinite(fx) and math.isfinite(fy):
                return fx, fy
            problems.append(
                SettingProblem(
                    "fixed_end",
                    f"fixed_end_x, fixed_end_y = {x!r}, {y!r}",
                    "give both as pixel numbers, or leave both empty",
                )
            )
            return None
    fe = raw.get("fixed_end", "auto")
    if is_missing(fe) or fe == "auto":
        return None
    if (
        isinstance(fe, (list, tuple))
        and len(fe) == 2
        and all(isinstance(v, numbers.Real) and not isinstance(v, bool) for v in fe)
    ):
        return float(fe[0]), float(fe[1])
    problems.append(
        SettingProblem(
            "fixed_end",
            f"fixed_end = {fe!r}",
            "use 'auto' or a pixel position [x, y] near the clamped end",
        )
    )
    return None


_CALIBRATION_FIX = (
    "write calibration as {board: <board photo>, square_mm: <square side in mm>, "
    "inner_corners: [<columns>, <rows>]}"
)


def _yaml_value(value: Any) -> Any:
    if isinstance(value, str):
        import yaml

        try:
            return yaml.safe_load(value)
        except yaml.YAMLError:
            return value
    return value


def merge_calibration(folder_value: Any, row_value: Any) -> Any:
    """A row's ``calibration`` on top of the folder-wide one: a board photo name (or list) keeps
    the folder's square size and corners; a mapping overrides the keys it gives.

    Examples
    --------
    >>> given = {"board": "a.jpg", "square_mm": 20, "inner_corners": [9, 6]}
    >>> merge_calibration(given, "b.jpg")["board"]
    'b.jpg'
    >>> merge_calibration({"board": "a.jpg", "square_mm": 20}, "{square_mm: 25}")
    {'board': 'a.jpg', 'square_mm': 25}
    """
    row = _yaml_value(row_value)
    base = _yaml_value(folder_value)
    if not isinstance(base, Mapping):
        return row
    if isinstance(row, Mapping):
        return {**base, **row}
    return {**base, "board": row}


def _calibration(
    raw: Mapping[str, Any],
    folder: Any,
    problems: list[SettingProblem],
    cache: CalibrationCache | None,
) -> Calibration | None:
    """The ``calibration`` setting, computed (or read from the store) -- or its problems."""
    value = raw.get("calibration")
    if is_missing(value):
        return None
    value = _yaml_value(value)
    if isinstance(value, (str, list, tuple)):
        value = {"board": value}
    if not isinstance(value, Mapping):
        problems.append(
            SettingProblem(
                "calibration",
                f"calibration = {raw.get('calibration')!r} is not a mapping",
                _CALIBRATION_FIX,
            )
        )
        return None
    bad = len(problems)
    unknown = sorted(set(map(str, value)) - {"board", "square_mm", "inner_corners"})
    if unknown:
        problems.append(
            SettingProblem("calibration", f"calibration key(s) {unknown} unknown", _CALIBRATION_FIX)
        )
    boards = value.get("board")
    boards = [boards] if isinstance(boards, str) else boards
    paths: list[str] = []
    if (
        not isinstance(boards, (list, tuple))
        or not boards
        or not all(isinstance(b, str) and b.strip() for b in boards)
    ):
        problems.append(
            SettingProblem(
                "calibration",
                f"calibration board = {value.get('board')!r}: name the board photo(s)",
                _CALIBRATION_FIX,
            )
        )
    else:
        for b in boards:
            path = user_path(b, folder)
            if not path.is_file():
                problems.append(
                    SettingProblem(
                        "calibration",
                        f"calibration board photo {b!r} does not exist",
                        "put the photo of the checkerboard (lying where the actuator lies) in the "
                        "photo-set folder and name it in calibration: board",
                    )
                )
            paths.append(str(path.resolve()))
    square = _number(
        value,
        "square_mm",
        problems,
        "set calibration square_mm to the side of one board square in mm (measure the print)",
    )
    if square is None and not any(p.key == "square_mm" for p in problems[bad:]):
        problems.append(
            SettingProblem(
                "calibration",
                "calibration square_mm is missing",
                "add square_mm: <side of one board square in mm> to calibration",
            )
        )
    corners = value.get("inner_corners")
    if isinstance(corners, str):  # "9x6" or "9, 6"
        corners = corners.lower().replace("x", ",").split(",")
    try:
        if not (isinstance(corners, (list, tuple)) and len(corners) == 2):
            raise ValueError(corners)
        cols, rows = (int(str(c).strip()) for c in corners)  # "9.5" and True are refused
        if not (2 <= cols <= 100 and 2 <= rows <= 100):
            raise ValueError(corners)
    except ValueError:
        problems.append(
            SettingProblem(
                "calibration",
                f"calibration inner_corners = {value.get('inner_corners')!r}",
                "give [columns, rows] of inner corners (where four squares meet): a board of 10 x "
                "7 squares has [9, 6]",
            )
        )
        cols = rows = 0
    if len(problems) > bad or square is None:
        return None
    spec = Calibration(tuple(paths), square, (cols, rows))
    try:
        return (cache if cache is not None else CalibrationCache(folder)).resolve(spec)
    except CalibrationError as exc:
        message, fix = describe_problem(spec, exc)
        problems.append(SettingProblem("calibration", message, fix))
        return None


def _body_width(
    raw: Mapping[str, Any], problems: list[SettingProblem], target: str
) -> float | None:
    """``body_width_mm`` as a width > 0 (mm), or None when not given; a problem when it is no such
    width, or given for a drawn line.

    Examples
    --------
    >>> problems = []
    >>> _body_width({"body_width_mm": "14"}, problems, "body"), problems
    (14.0, [])
    >>> _body_width({"body_width_mm": 0}, problems, "body"), problems[0].key
    (None, 'body_width_mm')
    """
    value: Any = raw.get("body_width_mm")
    if is_missing(value):
        return None
    width = user_float(value)
    if not math.isfinite(width) or width <= 0:
        problems.append(
            SettingProblem(
                "body_width_mm",
                f"body_width_mm = {value!r} must be a width > 0",
                "give the body's width in mm as the camera sees it, or leave body_width_mm out",
            )
        )
        return None
    if target != "body":
        problems.append(
            SettingProblem(
                "body_width_mm",
                "body_width_mm is given for a drawn line (target: line)",
                "leave body_width_mm out, or use target: body",
            )
        )
        return None
    return width


def _sealed_end(
    raw: Mapping[str, Any], problems: list[SettingProblem], free_end: str
) -> float | None:
    """``sealed_end_mm`` as a length >= 0 (mm), or None when not given; a problem when it is no
    such length or when the body's end bends (``free_end: bends``). Without ``mm_per_px`` it is
    turned into pixels with the body's length against ``l0_mm + sealed_end_mm``
    (:func:`pipeline.measure.core.length_scale_mm_per_px`); a line does not use it
    (``photoset check`` warns of that instead).

    Examples
    --------
    >>> problems = []
    >>> _sealed_end({"sealed_end_mm": "8"}, problems, "capped"), problems
    (8.0, [])
    >>> _sealed_end({"sealed_end_mm": 8}, problems, "bends"), problems[0].key
    (None, 'sealed_end_mm')
    """
    value: Any = raw.get("sealed_end_mm")
    if is_missing(value):
        return None
    length = user_float(value)
    fix = (
        "give the length in mm from where the chamber ends to the tip (sealed end and cap), or "
        "leave sealed_end_mm out"
    )
    if not math.isfinite(length) or length < 0:
        problems.append(
            SettingProblem("sealed_end_mm", f"sealed_end_mm = {value!r} must be a length >= 0", fix)
        )
        return None
    if free_end == "bends":
        problems.append(
            SettingProblem(
                "sealed_end_mm",
                "sealed_end_mm is given but free_end is 'bends' (an end that bends has no sealed "
                "end)",
                "leave sealed_end_mm out, or use free_end: capped",
            )
        )
        return None
    return length


def settings_problems(
    raw: Mapping[str, Any], *, folder: Any = None, calibrations: CalibrationCache | None = None
) -> tuple[MeasureSettings | None, list[SettingProblem]]:
    """Resolve one row's raw settings; return the settings (None if impossible) and every problem.

    Parameters
    ----------
    raw : mapping
        Merged ``photoset.yaml`` and manifest-row values (missing keys take their defaults).
    folder : path, optional
        Photo-set folder; ``background`` and the calibration board photos are resolved against
        it and must exist.
    calibrations : CalibrationCache, optional
        The calibrations of this photo set (stored ones, and each computed once); by default a
        new one reading the folder's store.

    Returns
    -------
    settings : MeasureSettings or None
    problems : list of SettingProblem
    """
    problems: list[SettingProblem] = []
    l0 = _number(raw, "l0_mm", problems, "set l0_mm to the length of the marked layer in mm")
    if l0 is None and not any(p.key == "l0_mm" for p in problems):
        problems.append(
            SettingProblem(
                "l0_mm",
                "l0_mm is missing",
                "add 'l0_mm: <length of the marked layer in mm>' to photoset.yaml (or an l0_mm "
                "manifest column)",
            )
        )
    mpp = _number(
        raw,
        "mm_per_px",
        problems,
        "set mm_per_px to the image scale in mm per pixel, or leave it out",
    )
    target = _choice(
        raw, "target", TARGETS, problems,
        "use 'line' (a drawn line) or 'body' (the actuator's outline)",
    )
    turn = _choice(raw, "positive_turn", POSITIVE_TURNS, problems, "use 'ccw' or 'cw'")
    color: ColorSpec | None = BLACK if target == "line" else None
    if not is_missing(raw.get("line_color")):
        try:
            color = parse_color(raw["line_color"])
        except ColorError as exc:
            problems.append(SettingProblem("line_color", str(exc), "fix line_color"))
    fixed_end = _fixed_end(raw, problems)
    direction: Any = raw.get("fixed_direction_deg")
    fixed_direction: float | None = None
    if not is_missing(direction):
        fixed_direction = user_float(direction)
        if not math.isfinite(fixed_direction):
            problems.append(
                SettingProblem(
                    "fixed_direction_deg",
                    f"fixed_direction_deg = {direction!r} is not a number",
                    "give the direction in degrees, counter-clockwise from +x on screen (0 = to "
                    "the right, 90 = up)",
                )
            )
            fixed_direction = None
    free_end = _choice(
        raw, "free_end", FREE_ENDS, problems,
        "use 'capped' (a sealed end that does not bend) or 'bends' (a free strip that bends right "
        "to its cut end)",
    )
    sealed_end = _sealed_end(raw, problems, free_end)
    body_width = _body_width(raw, problems, target)
    roi: Polygon | None = None
    if not is_missing(raw.get("roi")):
        try:
            roi = _points(raw["roi"], "roi")
        except ValueError as exc:
            problems.append(
                SettingProblem(
                    "roi",
                    str(exc),
                    "write roi as [x0, y0, x1, y1] or [[x, y], [x, y], [x, y], ...] in pixels",
                )
            )
    exclude: list[Polygon] = []
    ex = raw.get("exclude")
    if not is_missing(ex):
        if isinstance(ex, str):
            import yaml

            try:
                ex = yaml.safe_load(ex)
            except yaml.YAMLError:
                pass
        items = ex if isinstance(ex, (list, tuple)) else [ex]
        if items and all(isinstance(v, numbers.Real) for v in items):
            items = [items]  # one box
        for i, item in enumerate(items):
            try:
                exclude.append(_points(item, f"exclude[{i}]"))
            except ValueError as exc:
                problems.append(
                    SettingProblem(
                        "exclude",
                        str(exc),
                        "write exclude as a list of polygons [[[x, y], [x, y], [x, y]], ...] or "
                        "boxes [[x0, y0, x1, y1], ...]",
                    )
                )
    method: str | None = None
    if not is_missing(raw.get("method")):
        from pipeline.measure.estimators import METHODS

        method = str(raw["method"]).strip()
        if method not in METHODS:
            problems.append(
                SettingProblem(
                    "method",
                    f"method = {raw['method']!r} is unknown",
                    f"use one of {', '.join(METHODS)}",
                )
            )
    background: str | None = None
    if not is_missing(raw.get("background")):
        path = user_path(str(raw["background"]), folder)
        if not path.is_file():
            problems.append(
                SettingProblem(
                    "background",
                    f"background photo {str(raw['background'])!r} does not exist",
                    "put a photo of the empty scene in the photo-set folder and name it in "
                    "'background'",
                )
            )
        background = str(path)
    calibration = _calibration(raw, folder, problems, calibrations)
    if problems or l0 is None:
        return None, problems
    return MeasureSettings(
        l0_mm=l0,
        mm_per_px=mpp,
        color=color,
        fixed_end_px=fixed_end,
        positive_turn=turn,
        target=target,
        background_path=background,
        roi=roi,
        exclude=tuple(exclude),
        fixed_direction_deg=fixed_direction,
        free_end=free_end,
        sealed_end_mm=sealed_end,
        method=method,
        calibration=calibration,
        body_width_mm=body_width,
    ), []


def resolve_settings(
    raw: Mapping[str, Any] | None = None,
    *,
    folder: Any = None,
    calibrations: CalibrationCache | None = None,
    **values: Any,
) -> MeasureSettings:
    """Resolve settings given as a mapping and/or keywords; raise :class:`SettingsError` if bad.

    Examples
    --------
    >>> resolve_settings(l0_mm=150, line_color="red", fixed_end=[10, 20]).fixed_end_px
    (10.0, 20.0)
    """
    settings, problems = settings_problems(
        {**(raw or {}), **values}, folder=folder, calibrations=calibrations
    )
    if settings is None:
        raise SettingsError(problems)
    return settings
