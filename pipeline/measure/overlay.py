"""Overlays like the paper's Fig. 4B (photo, extracted line, psi) and contact sheets per ramp.

Drawn with OpenCV only (no matplotlib), so parallel workers stay light.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from pipeline.measure.core import AngleResult
from pipeline.measure.settings import MeasureSettings

#: overlays are at most this wide (px); narrower photos are enlarged to it
OVERLAY_WIDTH_PX, MIN_OVERLAY_WIDTH_PX = 640, 480
#: text size and line height on overlays, and how many lines a reason may take
TEXT_SCALE, LINE_PX, REASON_LINES = 0.5, 20, 5
#: the text bands above and below the photo, and the 2-px line between band and photo (BGR; the
#: report finds the bands by that line: no photo has a whole row of it)
BAND_BGR, DIVIDER_BGR = (40, 40, 40), (200, 0, 200)
#: outlines of the ``roi`` (yellow) and of each ``exclude`` polygon (red), in the overlays as in
#: ``photoset preview``
ROI_BGR, EXCLUDE_BGR = (0, 230, 255), (40, 40, 230)
_COLOURS = {"ok": (60, 200, 60), "flagged": (0, 165, 255), "failed": (40, 40, 230)}


def overlay_lines(result: AngleResult, title: str, width_px: int, height_px: int) -> list[str]:
    """The text of an overlay of a photo ``width_px`` x ``height_px``: the title, psi and the
    reason, wrapped; the band they fill, above the photo, is at most 30 % of its height (the
    report crops it off its photo strip), what does not fit ends in an ellipsis."""
    text = (
        f"psi = {result.psi_deg:+.1f} deg ({result.method})"
        if result.status != "failed"
        else "failed"
    )
    lines = [title] if title else []
    room = max(1, min(REASON_LINES, int(0.3 * height_px / LINE_PX) - len(lines) - 1))
    return [*lines, text, *wrap_text(result.reason, width_px - 16, TEXT_SCALE, room)]


#: the fixed end's mark and the clamp direction's line (BGR), and that line's length as a
#: fraction of the picture's width (long enough to lay along the body's base)
FIXED_END_BGR, DIRECTION_LENGTH_FRACTION = (255, 80, 0), 0.3
#: the free end's direction line, as a fraction of the picture's width (to lay along the tip)
TIP_LENGTH_FRACTION = 0.12


def draw_fixed_end(
    image_bgr: np.ndarray,
    fixed_xy: Sequence[float] | np.ndarray,
    fixed_direction_deg: float | None,
) -> None:
    """Mark the fixed end at ``fixed_xy`` (px of ``image_bgr``) with a circle and, when given,
    the clamp's direction (deg counter-clockwise from +x on screen) with a thin straight line
    from it, to lay against the body's base (in place)."""
    fe = np.asarray(fixed_xy, dtype=float)
    centre = tuple(np.round(fe).astype(int).tolist())
    cv2.circle(image_bgr, centre, 6, FIXED_END_BGR, 2, cv2.LINE_AA)
    if fixed_direction_deg is not None:
        draw_direction(image_bgr, fe, fixed_direction_deg)


def draw_direction(
    image_bgr: np.ndarray,
    from_xy: Sequence[float] | np.ndarray,
    direction_deg: float,
    length_fraction: float = DIRECTION_LENGTH_FRACTION,
) -> None:
    """A thin straight line from ``from_xy`` in ``direction_deg`` (counter-clockwise from +x on
    screen), ``length_fraction`` of the picture's width long (in place)."""
    start = np.asarray(from_xy, dtype=float)
    a = np.deg2rad(direction_deg)
    far = start + length_fraction * image_bgr.shape[1] * np.array([np.cos(a), -np.sin(a)])
    ends = np.round(np.array([start, far]) * 16).astype(int).tolist()  # 4 fractional bits
    cv2.line(image_bgr, ends[0], ends[1], FIXED_END_BGR, 1, cv2.LINE_AA, 4)


def draw_tip(
    image_bgr: np.ndarray, tip_xy: Sequence[float] | np.ndarray, direction_deg: float
) -> None:
    """Mark where the free end's tangent was read (a dot at ``tip_xy``, px of ``image_bgr``) and
    the direction psi takes it as (a thin line, :data:`TIP_LENGTH_FRACTION` of the picture's
    width, counter-clockwise from +x on screen), to lay along the tip (in place): psi is the
    turn from the base's line to this one."""
    centre = tuple(np.round(np.asarray(tip_xy, dtype=float)).astype(int).tolist())
    cv2.circle(image_bgr, centre, 3, FIXED_END_BGR, -1, cv2.LINE_AA)
    draw_direction(image_bgr, tip_xy, direction_deg, TIP_LENGTH_FRACTION)


def screen_directions(
    result: AngleResult, settings: MeasureSettings
) -> tuple[float | None, float | None]:
    """The two directions psi of a body is measured between, on screen (deg counter-clockwise
    from +x): where it leaves the fixed end (the one given, else its own) and where its free end
    points (that one turned by psi); None where not known, and both None for a calibrated photo,
    whose directions are taken on the plane.

    Examples
    --------
    >>> from pipeline.measure.core import AngleResult
    >>> from pipeline.measure.settings import resolve_settings
    >>> r = AngleResult(-90.0, 0.0, 0.0, "tangents", 0.0, "ok", "", np.zeros((2, 2)),
    ...                 base_direction_deg=-30.0, tip_px=(5.0, 5.0))
    >>> cw = resolve_settings(l0_mm=200, target="body", positive_turn="cw")
    >>> given = resolve_settings(l0_mm=200, target="body", fixed_direction_deg=10.0)
    >>> screen_directions(r, cw), screen_directions(r, given)
    ((30.0, 120.0), (10.0, -80.0))
    """
    if settings.calibration is not None:
        return None, None
    sign, fixed_direction_deg = settings.sign, settings.fixed_direction_deg
    if fixed_direction_deg is not None:
        base: float | None = fixed_direction_deg
    elif np.isfinite(result.base_direction_deg):
        base = sign * result.base_direction_deg
    else:
        base = None
    if base is None or result.tip_px is None or not np.isfinite(result.psi_deg):
        return base, None
    return base, base + sign * result.psi_deg


def draw_overlay(
    image_bgr: np.ndarray,
    result: AngleResult,
    *,
    scale: float = 1.0,
    title: str = "",
    fixed_end_px: Sequence[float] | None = None,
    fixed_direction_deg: float | None = None,
    base_direction_deg: float | None = None,
    tip_direction_deg: float | None = None,
    roi: Sequence[Sequence[float]] | None = None,
    exclude: Sequence[Sequence[Sequence[float]]] = (),
) -> np.ndarray:
    """The photo with the extracted centre line and the fixed end drawn on it, and psi written in
    a band above it (not over it: a tip near the photo's top edge stays in view).

    Parameters
    ----------
    image_bgr : ndarray
        The photo (possibly reduced: ``scale`` original px per px).
    result : AngleResult
        Its measurement (``centreline_px`` in original px).
    scale : float
        Original pixels per pixel of ``image_bgr``.
    title : str
        Text for the first line (e.g. the image name and pressure).
    fixed_end_px : (x, y), optional
        The fixed end as given (original px), marked where it is; without it the line's start.
    fixed_direction_deg : float, optional
        The clamp's direction as given, drawn from the fixed end (:func:`draw_fixed_end`).
    base_direction_deg : float, optional
        Without one given, the body's own base direction psi was measured from (deg
        counter-clockwise from +x on screen), drawn from the line's start.
    tip_direction_deg : float, optional
        The free end's direction as psi takes it (the base's turned by psi; deg counter-clockwise
        from +x on screen), drawn from where it was read (``result.tip_px``: :func:`draw_tip`).
    roi, exclude : optional
        The ``roi`` and ``exclude`` polygons as given (original px), outlined (customer 28 saw
        them in the preview and not here).

    Returns
    -------
    ndarray
        BGR image at most :data:`OVERLAY_WIDTH_PX` wide: the text band, then the photo.
    """
    # small photos are enlarged so that the text leaves most of them visible
    w = image_bgr.shape[1]
    f = OVERLAY_WIDTH_PX / w if w > OVERLAY_WIDTH_PX or w < MIN_OVERLAY_WIDTH_PX else 1.0
    out = (
        cv2.resize(
            image_bgr, None, fx=f, fy=f, interpolation=cv2.INTER_AREA if f < 1 else cv2.INTER_LINEAR
        )
        if f != 1
        else image_bgr.copy()
    )
    k = f / scale
    colour = _COLOURS.get(result.status, (255, 255, 255))
    outlines = ([(roi, ROI_BGR)] if roi is not None else []) + [(p, EXCLUDE_BGR) for p in exclude]
    for poly, bgr in outlines:
        corners = (np.asarray(poly, float) - (scale - 1) / 2) * k
        cv2.polylines(out, [np.round(corners * 16).astype(np.int32)], True, bgr, 1, cv2.LINE_AA, 4)
    if len(result.centreline_px):
        pts = (result.centreline_px - (scale - 1) / 2) * k
        cv2.polylines(out, [np.round(pts * 16).astype(np.int32)], False, colour, 2, cv2.LINE_AA, 4)
    if fixed_end_px is not None:
        draw_fixed_end(out, (np.asarray(fixed_end_px) - (scale - 1) / 2) * k, fixed_direction_deg)
    elif len(result.centreline_px):
        draw_fixed_end(out, pts[0], None)
    drawn_from = pts[0] if len(result.centreline_px) else None
    if fixed_direction_deg is None and base_direction_deg is not None and drawn_from is not None:
        draw_direction(out, drawn_from, base_direction_deg)
    if tip_direction_deg is not None and result.tip_px is not None:
        draw_tip(out, (np.asarray(result.tip_px) - (scale - 1) / 2) * k, tip_direction_deg)
    lines = overlay_lines(result, title, out.shape[1], out.shape[0])
    band = np.full((12 + LINE_PX * len(lines), out.shape[1], 3), BAND_BGR, np.uint8)
    band[-2:] = DIVIDER_BGR
    for i, t in enumerate(lines):
        cv2.putText(
            band,
            t,
            (8, 20 + LINE_PX * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            TEXT_SCALE,
            colour if i or not title else (255, 255, 255),
            1,
            cv2.LINE_AA,
        )
    return np.vstack([band, out])


def final_status_text(
    status: str, reason: str, drawn_reason: str = "", psi_deg: float | None = None
) -> str:
    """What :func:`note_final_status` writes: the final status, psi when the ramp's base direction
    changed it (``psi_deg``), and the reason, less the part of it the overlay already shows
    (``drawn_reason``).

    Examples
    --------
    >>> final_status_text("ok", "", "", psi_deg=214.43)
    "then ok, psi +214.4 deg against its ramp's base direction"
    >>> final_status_text("ok", "psi +212.0 deg against its ramp's base direction (...)", "", 212.0)
    "then ok: psi +212.0 deg against its ramp's base direction (...)"
    >>> final_status_text("flagged", "breaks its ramp: psi -188; tip hook", "tip hook")
    'then flagged: also breaks its ramp: psi -188'
    >>> final_status_text("flagged", "a; b; c", "b")
    'then flagged: also a; c'
    >>> final_status_text("ok", "", "line partly hidden")
    'then ok'
    """
    if drawn_reason and drawn_reason in reason and drawn_reason != reason:
        rest = re.sub(r"(;\s*)+", "; ", reason.replace(drawn_reason, "")).strip("; ")
        reason = f"also {rest}"
    said = "against its ramp's base direction"
    moved = "" if psi_deg is None or said in reason else f", psi {psi_deg:+.1f} deg {said}"
    return f"then {status}{moved}" + (f": {reason}" if reason else "")


def note_final_status(
    overlay_bgr: np.ndarray,
    status: str,
    reason: str,
    drawn_reason: str = "",
    psi_deg: float | None = None,
) -> np.ndarray:
    """The overlay with the photo's final status written in a band below it.

    For a status that the checks over the whole set (the ramp check, the calibration check)
    changed after the photo was drawn, so that its overlay never shows ``ok`` for a row the
    table flags, nor the other way round.  Of ``reason``, what the overlay already shows
    (``drawn_reason``) is left out.
    """
    text = final_status_text(status, reason, drawn_reason, psi_deg)
    room = max(1, min(REASON_LINES, int(0.25 * overlay_bgr.shape[0] / LINE_PX)))
    lines = wrap_text(text, overlay_bgr.shape[1] - 16, TEXT_SCALE, room)
    band = np.full((14 + LINE_PX * len(lines), overlay_bgr.shape[1], 3), BAND_BGR, np.uint8)
    band[:2] = DIVIDER_BGR
    for i, t in enumerate(lines):
        cv2.putText(
            band,
            t,
            (8, 22 + LINE_PX * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            TEXT_SCALE,
            _COLOURS.get(status, (255, 255, 255)),
            1,
            cv2.LINE_AA,
        )
    return np.vstack([overlay_bgr, band])


def wrap_text(text: str, width_px: int, scale: float, max_lines: int) -> list[str]:
    """``text`` broken at spaces into lines no wider than ``width_px`` in OpenCV's simplex font.

    At most ``max_lines`` lines; what does not fit ends the last one with an ellipsis.

    Examples
    --------
    >>> wrap_text("a b c", 1000, 0.48, 3)
    ['a b c']
    >>> lines = wrap_text("the centre line stops short " * 20, 300, 0.48, 3)
    >>> len(lines), lines[-1].endswith("...")
    (3, True)
    """

    def fits(line: str) -> bool:
        return cv2.getTextSize(line, cv2.FONT_HERSHEY_SIMPLEX, scale, 1)[0][0] <= width_px

    lines: list[str] = []
    for word in text.split():
        if lines and fits(f"{lines[-1]} {word}"):
            lines[-1] = f"{lines[-1]} {word}"
        else:
            lines.append(word)
    if len(lines) > max_lines:
        last = lines[max_lines - 1]
        while last and not fits(last + " ..."):
            last = last.rsplit(" ", 1)[0] if " " in last else last[:-1]
        lines = [*lines[: max_lines - 1], last + " ..."]
    return lines


#: a ramp's contact sheet is this wide; its columns are chosen to leave the fewest empty tiles
SHEET_WIDTH_PX = 1920
SHEET_COLUMNS = (4, 5, 6)


def sheet_columns(n: int, choices: Sequence[int] = SHEET_COLUMNS) -> int:
    """Columns of a sheet of ``n`` tiles: of ``choices``, the one leaving the fewest empty tiles
    in its last row (the fewer columns, and so the larger tiles, on a tie); ``n`` itself when
    fewer.

    Examples
    --------
    >>> [sheet_columns(n) for n in (3, 17, 19, 24, 40)]
    [3, 6, 4, 4, 4]
    """
    if n <= min(choices):
        return max(n, 1)
    return min(choices, key=lambda c: (-n % c, c))


def contact_sheet(
    paths: Sequence[Path], *, columns: int | None = None, tile_width_px: int | None = None
) -> np.ndarray:
    """Tile overlay images (in the given order) into one sheet; unreadable tiles stay grey.

    Each tile keeps its overlay's aspect (one with a band below the photo is taller, padded
    under the others in its row, never squeezed); ``columns`` defaults to
    :func:`sheet_columns` and the tiles to :data:`SHEET_WIDTH_PX` across.
    """
    if not paths:
        raise ValueError("no overlays for a contact sheet")
    columns = columns or sheet_columns(len(paths))
    width = tile_width_px or SHEET_WIDTH_PX // columns
    images = [cv2.imread(str(p)) for p in paths]
    tiles: list[np.ndarray] = [
        np.full((width * 3 // 4, width, 3), 128, np.uint8)
        if t is None
        else cv2.resize(
            t, (width, max(1, round(t.shape[0] * width / t.shape[1]))),
            interpolation=cv2.INTER_AREA,
        )
        for t in images
    ]
    rows = []
    for r in range(0, len(tiles), columns):
        row = tiles[r : r + columns]
        row += [np.zeros_like(row[0][:1])] * (columns - len(row))
        h = max(t.shape[0] for t in row)
        # a shorter tile is padded in the bands' grey, not black (customer 28 read the black
        # gaps under tiles without a band as missing photos); an empty place stays black
        rows.append(np.hstack([
            np.vstack([t, np.full((h - t.shape[0], width, 3), BAND_BGR if t.shape[0] > 1 else 0,
                                  np.uint8)])
            for t in row
        ]))
    return np.vstack(rows)
