"""Overlays like the paper's Fig. 4B (photo, extracted line, psi) and contact sheets per ramp.

Drawn with OpenCV only (no matplotlib), so parallel workers stay light.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import cv2
import numpy as np

from pipeline.measure.core import AngleResult

#: overlays are at most this wide (px)
OVERLAY_WIDTH_PX = 640
_COLOURS = {"ok": (60, 200, 60), "flagged": (0, 165, 255), "failed": (40, 40, 230)}


def draw_overlay(
    image_bgr: np.ndarray, result: AngleResult, *, scale: float = 1.0, title: str = ""
) -> np.ndarray:
    """The photo with the extracted centre line, the fixed end and psi written on it.

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

    Returns
    -------
    ndarray
        BGR image at most :data:`OVERLAY_WIDTH_PX` wide.
    """
    f = min(1.0, OVERLAY_WIDTH_PX / image_bgr.shape[1])
    out = (
        cv2.resize(image_bgr, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
        if f < 1
        else image_bgr.copy()
    )
    k = f / scale
    colour = _COLOURS.get(result.status, (255, 255, 255))
    if len(result.centreline_px):
        pts = (result.centreline_px - (scale - 1) / 2) * k
        cv2.polylines(out, [np.round(pts * 16).astype(np.int32)], False, colour, 2, cv2.LINE_AA, 4)
        cv2.circle(out, tuple(int(v) for v in np.round(pts[0])), 6, (255, 80, 0), 2, cv2.LINE_AA)
    text = (
        f"psi = {result.psi_deg:+.1f} deg ({result.method})"
        if result.status != "failed"
        else "failed"
    )
    lines = [t for t in (title, text, result.reason[:90]) if t]
    if lines:
        box = out[: 10 + 22 * len(lines), :]
        box[:] = (box * 0.35).astype(np.uint8)
    for i, t in enumerate(lines):
        cv2.putText(
            out,
            t,
            (8, 22 + 22 * i),
            cv2.FONT_HERSHEY_SIMPLEX,
            0.55,
            colour if i else (255, 255, 255),
            1,
            cv2.LINE_AA,
        )
    return out


def note_final_status(overlay_bgr: np.ndarray, status: str, reason: str) -> np.ndarray:
    """The overlay with the photo's final status written along its bottom.

    For a status that the checks over the whole set (the ramp check, the calibration check)
    changed after the photo was drawn, so that its overlay never shows ``ok`` for a row the
    table flags, nor the other way round.
    """
    out = overlay_bgr.copy()
    band = out[-32:, :]
    band[:] = (band * 0.35).astype(np.uint8)
    text = f"then {status}" + (f": {reason}" if reason else "")
    cv2.putText(
        out,
        text[:90],
        (8, out.shape[0] - 11),
        cv2.FONT_HERSHEY_SIMPLEX,
        0.55,
        _COLOURS.get(status, (255, 255, 255)),
        1,
        cv2.LINE_AA,
    )
    return out


def contact_sheet(
    paths: Sequence[Path], *, columns: int = 6, tile_width_px: int = 320
) -> np.ndarray:
    """Tile overlay images (in the given order) into one sheet; unreadable tiles stay grey."""
    if not paths:
        raise ValueError("no overlays for a contact sheet")
    images = [cv2.imread(str(p)) for p in paths]
    h_ref = next(
        (t.shape[0] * tile_width_px // t.shape[1] for t in images if t is not None),
        tile_width_px * 3 // 4,
    )
    grey = np.full((h_ref, tile_width_px, 3), 128, np.uint8)
    tiles: list[np.ndarray] = [
        grey if t is None else cv2.resize(t, (tile_width_px, h_ref), interpolation=cv2.INTER_AREA)
        for t in images
    ]
    rows = int(np.ceil(len(tiles) / columns))
    tiles += [np.zeros_like(grey)] * (rows * columns - len(tiles))
    return np.vstack([np.hstack(tiles[r * columns : (r + 1) * columns]) for r in range(rows)])
