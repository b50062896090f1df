"""Measure one photo of a photo set: the unit of work of the process pool.

Only OpenCV / numpy / scipy are imported here (no pandas, no matplotlib), so worker processes
start fast.  A task never raises: a bad photo becomes a ``failed`` row.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from pipeline.measure.core import (
    DEFAULT_METHOD,
    AngleResult,
    decode_for_work,
    decodes_grey,
    failed,
    measure_decoded,
)
from pipeline.measure.formats import undecodable
from pipeline.measure.settings import MeasureSettings


@dataclass(frozen=True)
class Task:
    """Everything needed to measure one photo (picklable).

    ``settings`` is None for a manifest row that cannot be measured; ``reason`` then says why.
    """

    path: str
    settings: MeasureSettings | None
    method: str = DEFAULT_METHOD
    overlay_path: str | None = None
    title: str = ""
    reason: str = ""


def run_task(task: Task, data: np.ndarray | None = None) -> dict[str, Any]:
    """Measure one photo (``data``: its bytes when already read); return the angles.csv fields
    (without the manifest columns)."""
    t0 = time.perf_counter()
    img, f = None, 1
    res: AngleResult
    try:
        if task.settings is None:
            res = failed(task.method, task.reason)
        else:
            if data is None:
                data = np.fromfile(task.path, dtype=np.uint8)
            if data.size:
                img, f = decode_for_work(data, grey=decodes_grey(task.settings))
            res = (
                failed(
                    task.method,
                    "unreadable image: {} cannot be decoded ({}; {})".format(
                        task.path, *undecodable(str(task.path))
                    ),
                )
                if img is None
                else measure_decoded(data, img, f, task.settings, method=task.method)
            )
    except OSError as exc:
        res = failed(task.method, f"unreadable image: {task.path}: {exc.strerror or exc}")
    except Exception as exc:  # noqa: BLE001 - one bad photo never stops the set
        res = failed(task.method, f"internal error on this photo: {type(exc).__name__}: {exc}")
    seconds = time.perf_counter() - t0
    if task.overlay_path is not None:
        write_overlay(task.overlay_path, img, f, res, task.title, task.settings)
    # the centre line (image px) rides along for the ramp's estimate of its empty scene
    return {**result_fields(res, seconds), "centreline_px": res.centreline_px}


def write_overlay(
    path: str,
    img: np.ndarray | None,
    factor: int,
    res: AngleResult,
    title: str,
    settings: MeasureSettings | None = None,
) -> None:
    """Draw ``res`` on the work image ``img`` (reduced by ``factor``; grey or BGR), with the
    fixed end and clamp direction of ``settings`` as given, and write a JPEG."""
    from pipeline.measure.overlay import draw_overlay, screen_directions

    base = img if img is not None else np.full((480, 640, 3), 90, np.uint8)
    if base.ndim == 2:
        base = cv2.cvtColor(base, cv2.COLOR_GRAY2BGR)
    given = settings if img is not None else None  # not on the blank stand-in
    base_deg, tip_deg = screen_directions(res, given) if given else (None, None)
    out = draw_overlay(
        base,
        res,
        scale=float(factor) if img is not None else 1.0,
        title=title,
        fixed_end_px=given.fixed_end_px if given else None,
        fixed_direction_deg=given.fixed_direction_deg if given else None,
        base_direction_deg=base_deg,
        tip_direction_deg=tip_deg,
        roi=given.roi if given else None,
        exclude=given.exclude if given else (),
    )
    Path(path).parent.mkdir(parents=True, exist_ok=True)  # a photo in a subfolder of its set
    cv2.imwrite(path, out, [cv2.IMWRITE_JPEG_QUALITY, 85])


def result_fields(res: AngleResult, seconds: float) -> dict[str, Any]:
    """The angles.csv measurement fields of one result (without image and manifest columns)."""
    return {
        "psi_deg": res.psi_deg,
        "kappa_per_mm": res.kappa_per_mm,
        "length_mm": res.length_mm,
        "length_px": res.length_px,
        "width_px": res.line_width_px,
        "base_direction_deg": res.base_direction_deg,
        "base_side_split_deg": res.base_side_split_deg,
        "method": res.method,
        "residual_px": res.residual_px,
        "status": res.status,
        "reason": res.reason,
        "seconds": seconds,
        "degree": res.degree if res.status != "failed" else None,
        "straight_end_mm": res.straight_end_mm,
        "past_l0_mm": res.past_l0_mm,
    }
