"""Measure a chunk of consecutive frames of one video: the unit of work of the process pool.

A chunk opens the video, seeks to its first frame (:func:`pipeline.video.reader.read_frames`)
and measures each frame as it is read, so a worker holds one frame at a time and a frame is
decoded once: an MJPEG packet exactly as a photo's bytes (reduced and grey,
:func:`~pipeline.measure.core.decode_for_work`), any other frame reduced from its decoded image.
Chunks of :data:`CHUNK_FRAMES` frames amortise the pool's per-task cost and the video's opening.

Like :mod:`pipeline.measure.worker` this imports only OpenCV / numpy (no pandas), and a chunk
never raises: an unreadable frame, or one whose measurement fails, is a ``failed`` frame.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
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
    reduce_image,
    reduction_for,
)
from pipeline.measure.settings import MeasureSettings
from pipeline.measure.worker import result_fields, write_overlay
from pipeline.video.reader import Frame, VideoInfo, read_frames

#: frames per pool task (about 0.5 s of work at 8 ms a frame)
CHUNK_FRAMES = 64
#: columns a chunk returns, each a list with one value per frame
CHUNK_COLUMNS: tuple[str, ...] = (
    "frame",
    "pts_s",
    "psi_deg",
    "kappa_per_mm",
    "length_mm",
    "length_px",
    "width_px",
    "base_direction_deg",
    "base_side_split_deg",
    "method",
    "residual_px",
    "status",
    "reason",
    "seconds",
    "degree",
    "straight_end_mm",
    "past_l0_mm",
)


@dataclass(frozen=True)
class FrameChunk:
    """Frames ``first .. first + count - 1`` of one video and how to measure them (picklable).

    ``settings`` is None for a manifest row that cannot be measured (``reason`` says why);
    ``overlays`` maps frame index -> overlay JPEG path for the frames to draw.
    """

    info: VideoInfo
    first: int
    count: int
    settings: MeasureSettings | None
    method: str = DEFAULT_METHOD
    reason: str = ""
    overlays: tuple[tuple[int, str], ...] = ()
    title: str = ""


def measure_frame(
    frame: Frame, settings: MeasureSettings, method: str, packets: bool
) -> tuple[AngleResult, np.ndarray | None, int]:
    """Measure one frame read by :func:`~pipeline.video.reader.read_frames`.

    Returns the result, the work image (for an overlay) and its reduction factor.
    """
    if frame.data is None:
        return failed(method, frame.reason), None, 1
    grey = decodes_grey(settings)
    if packets:
        img, f = decode_for_work(frame.data, grey=grey)
        if img is None:
            return (
                failed(
                    method,
                    f"frame {frame.index}: its JPEG packet cannot be decoded (the video is "
                    "truncated or corrupt here)",
                ),
                None,
                1,
            )
        return measure_decoded(frame.data, img, f, settings, method=method), img, f
    full = cv2.cvtColor(frame.data, cv2.COLOR_BGR2GRAY) if grey else frame.data
    f = reduction_for(full.shape)
    img = reduce_image(full, f)
    return measure_decoded(None, img, f, settings, method=method, full=full), img, f


def run_chunk(chunk: FrameChunk) -> dict[str, list[Any]]:
    """Measure every frame of a chunk; return :data:`CHUNK_COLUMNS` as lists (one entry per
    frame)."""
    out: dict[str, list[Any]] = {c: [] for c in CHUNK_COLUMNS}
    overlays = dict(chunk.overlays)
    frames = (
        read_frames(chunk.info, chunk.first, chunk.count)
        if chunk.settings is not None
        else iter(())
    )
    for k in range(chunk.first, chunk.first + chunk.count):
        t0 = time.perf_counter()
        img, f = None, 1
        if chunk.settings is None:
            frame = Frame(k, float("nan"), None, chunk.reason)
            res = failed(chunk.method, chunk.reason)
        else:
            frame = next(frames, Frame(k, float("nan"), None, f"frame {k} could not be read"))
            try:
                res, img, f = measure_frame(frame, chunk.settings, chunk.method, chunk.info.packets)
            except Exception as exc:  # noqa: BLE001 - one bad frame never stops the video
                res = failed(
                    chunk.method, f"internal error on this frame: {type(exc).__name__}: {exc}"
                )
        seconds = time.perf_counter() - t0
        if k in overlays:
            write_overlay(overlays[k], img, f, res, f"{chunk.title} frame {k}", chunk.settings)
        fields = result_fields(res, seconds)
        out["frame"].append(k)
        out["pts_s"].append(frame.pts_s)
        for name, value in fields.items():
            out[name].append(value)
    return out
