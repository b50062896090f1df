"""``photoset preview``: one contact sheet that shows whether a photo set's settings work.

For the first photo of every ramp, the one at its highest pressure and the last, a tile shows the
photo with what the settings select tinted (the line colour, or the body), the ``roi`` (yellow) and
``exclude`` (red) outlines, the other candidates outlined in grey, the chosen line or body centre
line (green when ``ok``, orange when ``flagged``), the fixed end (blue circle) with the
``fixed_direction_deg`` as a thin blue line from it (to lay along the body's base), and psi with
the status and the reason -- beside the bare selection mask, and for a calibrated photo the photo
rectified to the actuator's plane (undistorted, seen from straight above) with the centre line as
measured there and the calibration's reprojection error. It is the measurement itself
(:func:`pipeline.measure.core.measure_decoded`), drawn, so what the preview shows is what
``measure`` will do.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np
import pandas as pd

from pipeline.constants import RAMP_KEYS
from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes
from pipeline.measure.body import body_mask
from pipeline.measure.core import (
    AngleResult,
    decode_for_work,
    decodes_grey,
    load_background,
    measure_decoded,
)
from pipeline.measure.extract import line_mask, region_mask
from pipeline.measure.overlay import (
    EXCLUDE_BGR,
    ROI_BGR,
    draw_direction,
    draw_fixed_end,
    draw_tip,
    screen_directions,
    wrap_text,
)
from pipeline.measure.ramp_background import estimates_background
from pipeline.measure.settings import MeasureSettings
from pipeline.photoset import PhotoSet, load_photoset
from pipeline.photoset_measure import second_look_ramps
from pipeline.video.clips import Clip, frame_settings, resolve_clips
from pipeline.video.measure import spread_frames
from pipeline.video.reader import read_frames
from pipeline.video.timeline import frame_conditions

TILE_WIDTH_PX = 480
#: size of the words on a tile (OpenCV simplex font scale) and how many lines a reason may take
TEXT_SCALE = 0.48
REASON_LINES = 6
_STATUS_BGR = {"ok": (60, 200, 60), "flagged": (0, 165, 255), "failed": (40, 40, 230)}
#: a body's ends are shown enlarged this many body widths across, and at least this many work px
END_PANEL_WIDTHS, END_PANEL_MIN_PX = 5.0, 60.0


def selection(
    image_bgr: np.ndarray,
    settings: MeasureSettings,
    scale: float,
    background: np.ndarray | None = None,
) -> np.ndarray:
    """0/1 mask of what the settings select in a (reduced) photo, before any candidate is chosen."""
    if settings.target == "body":
        return body_mask(image_bgr, settings, scale=scale, background_bgr=background).mask
    assert settings.color is not None
    mask = line_mask(image_bgr, settings.color)[0]
    region = region_mask(image_bgr.shape, settings.roi, settings.exclude, scale)
    return mask if region is None else mask & region


def _background(settings: MeasureSettings, shape: tuple[int, ...]) -> np.ndarray | None:
    """The row's empty scene at the size of its photo (None without one, or one of another
    shape: the row's measurement says why)."""
    if settings.background_path is None:
        return None
    loaded = load_background(settings.background_path, (shape[0], shape[1]))
    return None if isinstance(loaded, str) else loaded


def _poly(points: tuple[tuple[float, float], ...], k: float) -> np.ndarray:
    return np.round(np.asarray(points, float) * k * 16).astype(np.int32)


def preview_tile(
    path: str | os.PathLike[str],
    settings: MeasureSettings | None,
    *,
    method: str = "auto",
    title: str = "",
    reason: str = "",
    second_look: bool = False,
) -> np.ndarray:
    """The preview of one photo: annotated photo beside its selection mask (BGR).
    ``second_look``: ``measure`` may look at it again (:func:`tile_reason`)."""
    data = np.fromfile(str(path), dtype=np.uint8) if Path(path).is_file() else np.empty(0, np.uint8)
    return encoded_tile(data, Path(path).name, settings, method=method, title=title, reason=reason,
                        second_look=second_look)


def tile_reason(
    res: AngleResult, settings: MeasureSettings | None, *, second_look: bool = False
) -> str:
    """A tile's reason; a doubtful body that ``measure`` looks at again against its ramp's own
    photos (the second look, :func:`~pipeline.measure.ramp_background.estimates_background`) is
    shown as its first look saw it, and says so (a customer saw flagged tiles whose rows
    ``measure`` then wrote ``ok``).  ``second_look``: its row is in a ramp ``measure`` may look
    at again (:func:`~pipeline.photoset_measure.second_look_ramps`; customer 26's one-photo
    ramps were told they would be looked at again).

    Examples
    --------
    >>> from pipeline.measure.core import failed
    >>> from pipeline.measure.settings import resolve_settings
    >>> body = resolve_settings(l0_mm=100.0, target="body", free_end="bends")
    >>> res = failed("tangents", "end direction unstable")
    >>> tile_reason(res, body, second_look=True)
    "first look, measure looks again against its ramp's photos: end direction unstable"
    >>> tile_reason(res, body)
    'end direction unstable'

    A measured body's psi is from its own base, where ``measure`` takes its ramp's:

    >>> from dataclasses import replace
    >>> tile_reason(replace(res, status="flagged"), body)[:58]
    "end direction unstable; psi from this photo's own base dir"

    An ``ok`` one may change too: where its ramp has a doubtful row, ``measure`` takes the
    second look if it is ``ok`` and more than 4 deg away (``SECOND_LOOK_APART_DEG``):

    >>> tile_reason(replace(res, status="ok", reason=""), body, second_look=True)[:62]
    "first look (measure may look again against its ramp's photos):"
    """
    reason = res.reason
    if (
        settings is not None
        and settings.target == "body"
        and settings.fixed_direction_deg is None
        and res.status != "failed"
    ):
        # customer 36's straight body read "+6.4 deg ok" here, +0.4 in measure
        reason = "; ".join(r for r in (reason, OWN_BASE_NOTE) if r)
    if not (second_look and estimates_background(settings)):
        return reason
    if res.status != "ok":
        return f"first look, measure looks again against its ramp's photos: {reason}"
    note = "first look (measure may look again against its ramp's photos)"
    return f"{note}: {reason}" if reason else note


#: a body tile's psi is its own base's; measure's is its ramp's where the ramp's bodies agree
#: on one (customer 42's ramps, whose own bases scattered over 26 deg, took none, as the caption
#: had promised they would)
OWN_BASE_NOTE = (
    "psi from this photo's own base direction (measure takes its ramp's shared one where the "
    "ramp's bodies agree on it: it may differ by a few deg)"
)


def measured_as_measure_does(
    data: np.ndarray, img: np.ndarray, factor: int, settings: MeasureSettings, method: str
) -> AngleResult:
    """``measure``'s own first look at a photo (``img``: its colour decoding, reduced ``factor``
    times): a black line is measured on the luma decoding, as ``measure`` does (on the colour
    one, customer 32's 12 MP phone photos read up to 1.2 deg from ``measure``'s psi)."""
    if decodes_grey(settings):
        grey, grey_factor = decode_for_work(data, grey=True)
        if grey is not None:
            img, factor = grey, grey_factor
    return measure_decoded(data, img, factor, settings, method=method)


def encoded_tile(
    data: np.ndarray,
    name: str,
    settings: MeasureSettings | None,
    *,
    method: str = "auto",
    title: str = "",
    reason: str = "",
    second_look: bool = False,
) -> np.ndarray:
    """:func:`preview_tile` of an encoded image (``data``: its bytes, e.g. a video's frame as a
    JPEG packet; ``name`` for messages)."""
    img, f = decode_for_work(data) if data.size else (None, 1)
    if img is None or settings is None:
        blank = np.full((TILE_WIDTH_PX * 3 // 4, 2 * TILE_WIDTH_PX, 3), 60, np.uint8)
        why = reason or (
            f"{name} cannot be read" if img is None else "row cannot be measured"
        )
        for i, t in enumerate((title, "failed", why[:110])):
            cv2.putText(
                blank,
                t,
                (10, 30 + 26 * i),
                cv2.FONT_HERSHEY_SIMPLEX,
                0.55,
                (255, 255, 255),
                1,
                cv2.LINE_AA,
            )
        return blank
    res = measured_as_measure_does(data, img, f, settings, method)
    sel = selection(img, settings, float(f), _background(settings, img.shape))
    k = TILE_WIDTH_PX / img.shape[1]
    small = cv2.resize(
        img, (TILE_WIDTH_PX, round(img.shape[0] * k)), interpolation=cv2.INTER_AREA
    )
    mask_small = cv2.resize(
        sel * 255, (small.shape[1], small.shape[0]), interpolation=cv2.INTER_AREA
    )
    tint = small.copy()
    tint[mask_small > 127] = (
        0.45 * tint[mask_small > 127] + 0.55 * np.array([255, 0, 255])
    ).astype(np.uint8)
    kk = k / f  # original px -> tile px
    contours, _ = cv2.findContours(
        (mask_small > 127).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE
    )
    cv2.drawContours(
        tint,
        [c for c in contours if cv2.arcLength(c, True) > 30],
        -1,
        (160, 160, 160),
        1,
        cv2.LINE_AA,
    )
    if settings.roi is not None:
        cv2.polylines(tint, [_poly(settings.roi, kk)], True, ROI_BGR, 2, cv2.LINE_AA, 4)
    for poly in settings.exclude:
        cv2.polylines(tint, [_poly(poly, kk)], True, EXCLUDE_BGR, 2, cv2.LINE_AA, 4)
    colour = _STATUS_BGR.get(res.status, (255, 255, 255))
    if len(res.centreline_px):
        cv2.polylines(
            tint,
            [np.round(res.centreline_px * kk * 16).astype(np.int32)],
            False,
            colour,
            2,
            cv2.LINE_AA,
            4,
        )
    if settings.fixed_end_px is not None:
        draw_fixed_end(tint, np.asarray(settings.fixed_end_px) * kk, settings.fixed_direction_deg)
    # what psi is measured between, as in the overlays
    base_deg, tip_deg = screen_directions(res, settings)
    if settings.fixed_direction_deg is None and base_deg is not None and len(res.centreline_px):
        draw_direction(tint, res.centreline_px[0] * kk, base_deg)
    if tip_deg is not None and res.tip_px is not None:
        draw_tip(tint, np.asarray(res.tip_px) * kk, tip_deg)
    text = [
        title,
        f"psi = {res.psi_deg:+.1f} deg  {res.status}" if res.status != "failed" else "failed",
        *wrap_text(
            tile_reason(res, settings, second_look=second_look),
            2 * tint.shape[1] - 16,
            TEXT_SCALE,
            REASON_LINES,
        ),
    ]
    # the words in a band above the photo and its mask: the whole reason, none of the photo hidden
    band = np.full((12 + 20 * len(text), 2 * tint.shape[1], 3), 30, np.uint8)
    for i, t in enumerate(text):
        cv2.putText(
            band,
            t,
            (8, 20 + 20 * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            TEXT_SCALE,
            colour if i else (255, 255, 255),
            1,
            cv2.LINE_AA,
        )
    right = cv2.cvtColor(mask_small, cv2.COLOR_GRAY2BGR)
    labels = (width_label(res, settings), f"selected: {settings.describe_color()}"[:60])
    for i, label in enumerate(label for label in labels if label):
        cv2.putText(
            right,
            label,
            (8, right.shape[0] - 10 - 18 * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.45,
            (0, 200, 255),
            1,
            cv2.LINE_AA,
        )
    size = (small.shape[1], small.shape[0])
    rectified = rectified_panel(img, float(f), settings, res, size)
    ends = []
    if tip_deg is not None and res.tip_px is not None and base_deg is not None:
        fixed = settings.fixed_end_px or tuple(res.centreline_px[0])
        ends = [
            end_panel(img, float(f), res, fixed, base_deg, size, free_end=False),
            end_panel(img, float(f), res, res.tip_px, tip_deg, size, free_end=True),
        ]
    panels = np.hstack([tint, right] + [p for p in (*ends, rectified) if p is not None])
    band = cv2.copyMakeBorder(
        band, 0, 0, 0, panels.shape[1] - band.shape[1], cv2.BORDER_CONSTANT, value=(30, 30, 30)
    )
    return np.vstack([band, panels])


def width_label(res: AngleResult, settings: MeasureSettings) -> str:
    """How wide the chosen body (edge to edge, what ``body_width_mm`` is checked against) or line
    was read, in mm where ``mm_per_px`` is given: a body read much narrower than it is has lost
    a side to the backdrop (customer 52's off-white body on light grey paper: about 6.5 mm of its
    14 selected, and the reasons pointed at the clamp), one read wider has taken in its shadow.
    Empty when no width was read.

    Examples
    --------
    >>> from pipeline.measure.core import failed
    >>> from pipeline.measure.settings import resolve_settings
    >>> from dataclasses import replace
    >>> res = replace(failed("tangents", ""), status="ok", line_width_px=64.0)
    >>> width_label(res, resolve_settings(l0_mm=100.0, target="body", mm_per_px=0.1))
    'body read 6.4 mm wide (64 px)'
    >>> width_label(res, resolve_settings(l0_mm=100.0))
    'line read 64 px wide'
    """
    width_px = res.body_width_px if np.isfinite(res.body_width_px) else res.line_width_px
    if res.status == "failed" or not np.isfinite(width_px) or width_px <= 0:
        return ""
    what = "body" if settings.target == "body" else "line"
    if not settings.mm_per_px:
        return f"{what} read {width_px:.0f} px wide"
    return f"{what} read {width_px * settings.mm_per_px:.1f} mm wide ({width_px:.0f} px)"


def end_panel(
    img: np.ndarray,
    scale: float,
    res: AngleResult,
    at_px: tuple[float, float],
    direction_deg: float,
    size: tuple[int, int],
    *,
    free_end: bool,
) -> np.ndarray | None:
    """One end of a body enlarged about ``at_px`` (original px): :data:`END_PANEL_WIDTHS` of its
    widths across, with its centre line and the direction psi is measured from there (None
    without a width).  At the fixed end: its mark and the base's line (given, or the body's own),
    which should lie along the body's base; at the free end: the dot where its tangent was read
    and the direction psi takes it as, which should lie along the tip, the dot where the body
    stops bending.  On a 12 MP photo the tile shows either as a few pixels.

    Examples
    --------
    >>> from pipeline.measure.core import AngleResult
    >>> img = np.full((300, 400, 3), 200, np.uint8)
    >>> line = np.c_[np.linspace(50.0, 300.0, 50), np.full(50, 150.0)]
    >>> res = AngleResult(0.0, 0.0, 0.0, "tangents", 0.0, "ok", "", line,
    ...                   line_width_px=20.0, tip_px=(300.0, 150.0))
    >>> panel = end_panel(img, 1.0, res, res.tip_px, 0.0, (480, 360), free_end=True)
    >>> panel.shape, tuple(int(v) for v in panel[180, 240])  # the dot, in the middle
    ((360, 480, 3), (255, 80, 0))
    """
    if not np.isfinite(res.line_width_px):
        return None
    base = np.asarray(img if img.ndim == 3 else cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), np.uint8)
    centre = np.asarray(at_px, float) / scale  # work px
    across = max(END_PANEL_WIDTHS * res.line_width_px / scale, END_PANEL_MIN_PX)
    zoom = size[0] / across
    shift = np.array(size, float) / 2 - zoom * centre
    to_panel = np.array([[zoom, 0.0, shift[0]], [0.0, zoom, shift[1]]])
    panel = cv2.warpAffine(
        base, to_panel, size, flags=cv2.INTER_LINEAR if zoom > 1 else cv2.INTER_AREA,
        borderMode=cv2.BORDER_CONSTANT, borderValue=(30, 30, 30),
    )
    if len(res.centreline_px):
        q = res.centreline_px / scale * zoom + shift
        colour = _STATUS_BGR.get(res.status, (255, 255, 255))
        cv2.polylines(panel, [np.round(q * 16).astype(np.int32)], False, colour, 2, cv2.LINE_AA, 4)
    if free_end:
        draw_tip(panel, centre * zoom + shift, direction_deg)
    else:
        draw_fixed_end(panel, centre * zoom + shift, direction_deg)
    label = f"{'free' if free_end else 'fixed'} end, {END_PANEL_WIDTHS:g} body widths across"
    (w, h), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
    cv2.rectangle(panel, (0, size[1] - h - 16), (w + 14, size[1]), (30, 30, 30), -1)
    cv2.putText(
        panel, label, (8, size[1] - 10), cv2.FONT_HERSHEY_SIMPLEX, 0.45, (0, 200, 255), 1,
        cv2.LINE_AA,
    )
    return panel


def rectified_panel(img: np.ndarray, scale: float, settings: MeasureSettings, res: AngleResult,
                    size: tuple[int, int]) -> np.ndarray | None:
    """A calibrated photo on the plane, with the centre line mapped there (None when
    uncalibrated)."""
    from pipeline.measure.calibration import CalibrationMismatch, check_size, rectify

    cal = settings.calibration
    if cal is None or cal.plane is None:
        return None
    base = np.asarray(img if img.ndim == 3 else cv2.cvtColor(img, cv2.COLOR_GRAY2BGR), np.uint8)
    try:
        check_size(cal.plane, base.shape, scale)
    except CalibrationMismatch as exc:
        panel = np.full((size[1], size[0], 3), 60, np.uint8)
        cv2.putText(
            panel,
            str(exc)[:60],
            (8, 24),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.45,
            (40, 40, 230),
            1,
            cv2.LINE_AA,
        )
        return panel
    panel = rectify(base, cal.plane, scale)
    k = size[0] / panel.shape[1]
    panel = np.asarray(cv2.resize(panel, size, interpolation=cv2.INTER_AREA), np.uint8)
    if len(res.centreline_px):
        q = cal.plane.to_plane(res.centreline_px) / scale * k
        colour = _STATUS_BGR.get(res.status, (255, 255, 255))
        cv2.polylines(panel, [np.round(q * 16).astype(np.int32)], False, colour, 2, cv2.LINE_AA, 4)
    text = [
        f"on the plane ({Path(cal.boards[0]).name})",
        f"reprojection error {cal.plane.rms_px:.2f} px, {cal.plane.rms_mm:.3f} mm",
        f"{cal.plane.mm_per_px:.4f} mm/px, k1 {cal.plane.k1:+.3f}",
    ]
    warn = cal.plane.doubtful
    for i, t in enumerate(text):
        cv2.putText(
            panel,
            t,
            (8, 20 + 20 * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.48,
            (0, 165, 255) if warn else (255, 255, 255),
            1,
            cv2.LINE_AA,
        )
    return panel


def preview_rows(
    ps: PhotoSet, every: bool = False, images: Sequence[str] = ()
) -> list[int]:
    """Positions (0-based) of the photos a preview shows: the first of every ramp, the last at
    its highest pressure (the most bent: on a ramp up and back down the first and last are both
    at rest; of a step response's frames, the settled one) and the last (or all, or the
    ``images`` named, in their order).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> frames = pd.DataFrame({"pressure_kpa": [0, 0, 80, 80, 80, 0], "material": "DS20",
    ...                        "actuator": "A1", "trial": 1, "step": range(6)})
    >>> preview_rows(SimpleNamespace(manifest=frames))
    [0, 4, 5]
    """
    m = ps.manifest.reset_index(drop=True)
    if images:
        names = m["image"].astype(str).tolist()
        missing = [name for name in images if name not in names]
        if missing:
            raise UserInputError(
                f"--image {missing[0]}: no such photo in {ps.folder / 'manifest.csv'} (fix: give "
                f"its name as in the manifest's image column, e.g. {names[0]})"
            )
        return [names.index(name) for name in images]
    if every:
        return list(range(len(m)))
    order = m.sort_values("step", kind="stable") if "step" in m.columns else m
    rows: list[int] = []
    for _, ramp in order.groupby(list(RAMP_KEYS), sort=False):
        pressure = pd.to_numeric(ramp["pressure_kpa"], errors="coerce")
        top = pressure[pressure == pressure.max()].index[-1] if pressure.notna().any() else (
            ramp.index[0]
        )
        for ix in (ramp.index[0], top, ramp.index[-1]):
            if int(ix) not in rows:
                rows.append(int(ix))
    return rows


def frame_pressures_kpa(clip: Clip) -> np.ndarray:
    """The logged pressure (kPa) at each frame of a video (NaN without a log)."""
    if clip.log is None:
        return np.full(clip.n_frames, np.nan)
    times = clip.nominal_video_times_s() + clip.clock_offset_s
    return frame_conditions(clip.log, times)["pressure_kpa"].to_numpy(float)


def preview_frames(pressure_kpa: np.ndarray) -> list[int]:
    """The frames a preview shows of a video whose frames are at ``pressure_kpa``: the first, the
    last at the highest pressure (the most bent: at the end of a held step, settled) and the last.

    Examples
    --------
    >>> preview_frames(np.array([0.0, 40.0, 80.0, 80.0, 40.0, 0.0])), preview_frames(np.zeros(1))
    ([0, 3, 5], [0])
    """
    finite = np.isfinite(pressure_kpa)
    top = 0
    if finite.any():
        top = int(np.flatnonzero(pressure_kpa == np.max(pressure_kpa[finite]))[-1])
    return list(dict.fromkeys((0, top, len(pressure_kpa) - 1)))


def video_tiles(
    ps: PhotoSet, method: str = "auto", *, frames: Sequence[int] = (), every: bool = False
) -> list[np.ndarray]:
    """The preview tiles of a video photo set: of every video its first frame, the one at the
    highest logged pressure (the most bent) and its last; or the ``frames`` given (numbered as
    ``angles.csv``'s ``frame``, from 0); or, with ``every``, the frames ``--overlays`` draws.

    Raises
    ------
    UserInputError
        A frame given that no video of the set holds, naming the videos' frame counts.
    """
    clips = resolve_clips(ps)
    longest = max((c.n_frames for c in clips if c.info.opened), default=0)
    beyond = [k for k in frames if not 0 <= k < longest]
    if beyond:
        raise UserInputError(
            f"--frame {beyond[0]}: no video of {ps.folder} holds it ("
            + ", ".join(f"{c.video} has {c.n_frames}" for c in clips)
            + " frames; fix: give a frame from 0 to one less than its count, as angles.csv's "
            "frame column numbers them)"
        )
    tiles = []
    for clip in clips:
        if not clip.info.opened or not clip.n_frames:
            blank = np.empty(0, np.uint8)
            why = "; ".join(clip.problems) or "video holds no frame"
            tiles.append(encoded_tile(blank, clip.video, None, title=clip.video, reason=why))
            continue
        pressure = frame_pressures_kpa(clip)
        picks = (
            [k for k in dict.fromkeys(frames) if k < clip.n_frames]
            if frames
            else spread_frames(clip.n_frames)
            if every
            else preview_frames(pressure)
        )
        for k in picks:
            frame = next(read_frames(clip.info, k, 1))
            data = (
                np.empty(0, np.uint8)
                if frame.data is None
                else frame.data
                if frame.data.ndim == 1
                else cv2.imencode(".png", frame.data)[1]
            )
            title = f"{clip.video} frame {k}" + (
                f"  {pressure[k]:g} kPa" if np.isfinite(pressure[k]) else ""
            )
            tiles.append(
                encoded_tile(data, f"{clip.video} frame {k}", frame_settings(ps, clip),
                             method=method, title=title, reason=frame.reason)
            )
    return tiles


def write_preview(
    folder: str | os.PathLike[str],
    out: str | os.PathLike[str],
    *,
    method: str = "auto",
    every: bool = False,
    images: Sequence[str] = (),
    frames: Sequence[int] = (),
) -> tuple[Path, int]:
    """Write the preview contact sheet of a photo set (of the ``images`` named, or of a video
    set the ``frames``, when given); return its path and the tile count.

    The sheet is a JPEG, or a PNG when ``out`` ends in ``.png``; another ending is refused before
    anything is measured.
    """
    path = Path(out)
    encoding = {".jpg": ".jpg", ".jpeg": ".jpg", ".png": ".png"}.get(path.suffix.lower())
    if encoding is None:
        raise UserInputError(
            f"--out {out}: the preview is written as a JPEG or a PNG (fix: end the name in .jpg "
            "or .png)"
        )
    ps = load_photoset(folder)
    if ps.is_video and images:
        raise UserInputError(
            f"--image {images[0]}: {ps.folder} is a video set, whose preview shows frames along "
            f"each video (fix: name a frame with --frame N, N as in angles.csv's frame column)"
        )
    if frames and not ps.is_video:
        raise UserInputError(
            f"--frame {frames[0]}: {ps.folder} is a set of photos, not videos (fix: name a photo "
            "with --image NAME)"
        )
    tiles = video_tiles(ps, method, frames=frames, every=every) if ps.is_video else []
    again = {i for ramp in second_look_ramps(ps) for i in ramp}
    for i in [] if ps.is_video else preview_rows(ps, every, images):
        row = ps.manifest.iloc[i]
        title = (
            f"{row['image']}  {row['material']} {row['actuator']} t{row['trial']}  "
            f"{row['pressure_kpa']:g} kPa {row['direction']}"
        )
        tiles.append(
            preview_tile(
                ps.image_path(str(row["image"])),
                ps.rows[i],
                method=method,
                title=title,
                reason=ps.row_reason(i),
                second_look=i in again,
            )
        )
    height, width = max(t.shape[0] for t in tiles), max(t.shape[1] for t in tiles)
    tiles = [
        cv2.copyMakeBorder(
            t,
            0,
            height - t.shape[0] + 4,
            0,
            width - t.shape[1],
            cv2.BORDER_CONSTANT,
            value=(30, 30, 30),
        )
        for t in tiles
    ]
    per_row = 2 if width <= 3 * TILE_WIDTH_PX else 1  # a body's tiles, with both ends: one
    sheet = np.vstack(
        [
            np.hstack(tiles[i : i + per_row])
            if i + per_row <= len(tiles)
            else np.hstack([tiles[i], np.zeros_like(tiles[i])])
            for i in range(0, len(tiles), per_row)
        ]
    )
    params = [cv2.IMWRITE_JPEG_QUALITY, 88] if encoding == ".jpg" else []
    _ok, buf = cv2.imencode(encoding, sheet, params)
    atomic_write_bytes(path, buf.tobytes())
    return path, len(tiles)


def empty_first_photos(folder: str | os.PathLike[str]) -> pd.DataFrame:
    """The first photo of every ramp whose settings select (almost) nothing in it.

    Returns
    -------
    pandas.DataFrame
        ``manifest_line``, ``image``, ``what`` (the selection in words) per such photo.
    """
    ps = load_photoset(folder)
    out = []
    m = ps.manifest.reset_index(drop=True)
    order = m.sort_values("step", kind="stable") if "step" in m.columns else m
    for _, ramp in order.groupby(list(RAMP_KEYS), sort=False):
        i = int(ramp.index[0])
        s = ps.rows[i]
        path = ps.image_path(str(m["image"].iloc[i]))
        if s is None or not path.is_file():
            continue
        data = np.fromfile(str(path), dtype=np.uint8)
        img, f = decode_for_work(data) if data.size else (None, 1)
        if img is None:
            continue
        sel = selection(img, s, float(f), _background(s, img.shape))
        if int(sel.sum()) < 25:
            out.append(
                {
                    "manifest_line": int(m["manifest_line"].iloc[i]),
                    "image": str(m["image"].iloc[i]),
                    "what": s.describe_color(),
                }
            )
    return pd.DataFrame(out, columns=["manifest_line", "image", "what"])

