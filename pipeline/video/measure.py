"""Measure every frame of a video photo set into angles.csv rows (one row per frame).

Each video is cut into chunks of consecutive frames (:data:`~pipeline.video.worker.CHUNK_FRAMES`;
a video that cannot seek is cut into one part per worker instead), measured in the shared pool
(:func:`pipeline.pool.map_photos`) with the row's resolved settings.  Each frame then gets its time
on the pressure log's clock, the pressure interpolated there, the direction of the pressure's
trend and its step (:func:`pipeline.video.timeline.frame_conditions`).

Nothing is dropped: a frame that cannot be read or decoded (a truncated or corrupt video), one
outside the pressure log, and every frame of a row that cannot be measured (missing video,
unusable log, bad settings) is a ``failed`` row with the reason.  A video that cannot be opened
at all and whose frame count is unknown gives one ``failed`` row with an empty ``frame``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.constants import RAMP_KEYS
from pipeline.photoset import VIDEO_OPTIONAL_COLUMNS, PhotoSet
from pipeline.pool import map_photos
from pipeline.video.clips import Clip, frame_settings, resolve_clips, span_problem
from pipeline.video.reader import SEQUENCE_NUMBER, sequence_file_name
from pipeline.video.timeline import frame_conditions, span_text
from pipeline.video.worker import CHUNK_COLUMNS, CHUNK_FRAMES, FrameChunk, run_chunk

#: overlays drawn per video (evenly spread frames; a video is never written out frame by frame)
OVERLAYS_PER_VIDEO = 24


def spread_frames(n_frames: int, count: int = OVERLAYS_PER_VIDEO) -> list[int]:
    """``count`` frames evenly spread over a video of ``n_frames`` (all of a shorter one; none of
    an empty one): the frames drawn as overlays, and shown by ``photoset preview --all``.

    Examples
    --------
    >>> spread_frames(100, 4), spread_frames(2), spread_frames(0)
    ([0, 33, 66, 99], [0, 1], [])
    """
    return [int(k) for k in np.unique(np.round(np.linspace(0, n_frames - 1, min(count, n_frames))))]


def frame_overlay_name(video: str, frame: int) -> str:
    """Overlay file of one frame, e.g. ``ramp_f000120.jpg`` (a frame sequence's without its
    number's pattern: ``frame_%04d.jpg`` -> ``frame_f000120.jpg``).

    Examples
    --------
    >>> frame_overlay_name("trial1/ramp.avi", 120), frame_overlay_name("frame_%04d.jpg", 7)
    ('ramp_f000120.jpg', 'frame_f000007.jpg')
    """
    stem = SEQUENCE_NUMBER.sub("", Path(video).stem).rstrip("_-. ") or "frame"
    return f"{stem}_f{int(frame):06d}.jpg"


def sequence_file_names(
    video: str, files: tuple[str, ...], frames: pd.api.extensions.ExtensionArray
) -> list[str]:
    """The file of each frame of a frame sequence, as the manifest names its folder (for a frame
    missing from the sequence or past its last file, the file it lacks; '' for a row without a
    frame).

    Examples
    --------
    >>> frames = pd.array([0, 1, 2, None], dtype="Int64")
    >>> sequence_file_names("cam/f_%04d.jpg", ("/d/cam/f_0001.jpg", "", "/d/cam/f_0003.jpg"),
    ...                     frames)
    ['cam/f_0001.jpg', 'cam/f_0002.jpg', 'cam/f_0003.jpg', '']
    >>> sequence_file_names("f_%04d.jpg", ("/d/f_0001.jpg",), pd.array([1], dtype="Int64"))
    ['f_0002.jpg']
    """
    folder = Path(video).parent
    return [
        (folder / sequence_file_name(video, files, int(k))).as_posix()
        if k is not pd.NA and int(k) >= 0 and any(files)
        else ""
        for k in frames
    ]


def chunk_ranges(
    n_frames: int, *, seekable: bool, jobs: int, chunk_frames: int = CHUNK_FRAMES
) -> list[tuple[int, int]]:
    """``(first, count)`` of each chunk of a video.

    Examples
    --------
    >>> chunk_ranges(150, seekable=True, jobs=2)
    [(0, 64), (64, 64), (128, 22)]
    >>> chunk_ranges(150, seekable=False, jobs=2)
    [(0, 75), (75, 75)]
    """
    if n_frames <= 0:
        return []
    size = chunk_frames if seekable else -(-n_frames // max(jobs, 1))
    return [(a, min(size, n_frames - a)) for a in range(0, n_frames, size)]


def _tasks(
    ps: PhotoSet, clips: tuple[Clip, ...], method: str, jobs: int, overlays_dir: Path | None
) -> list[tuple[int, FrameChunk]]:
    tasks = []
    for clip in clips:
        settings = frame_settings(ps, clip)
        reasons = [r for r in (ps.row_reason(clip.position), "; ".join(clip.problems)) if r]
        reason = "; ".join(reasons)
        n = clip.n_frames
        overlays = (
            {k: str(overlays_dir / frame_overlay_name(clip.video, k)) for k in spread_frames(n)}
            if overlays_dir
            else {}
        )
        title = f"{clip.video}"
        for first, count in chunk_ranges(n, seekable=clip.info.seekable, jobs=jobs):
            mine = tuple((k, p) for k, p in overlays.items() if first <= k < first + count)
            tasks.append(
                (
                    clip.position,
                    FrameChunk(
                        clip.info,
                        first,
                        count,
                        None if reason else settings,
                        method,
                        reason,
                        mine,
                        title,
                    ),
                )
            )
    return tasks


def _clip_rows(ps: PhotoSet, clip: Clip, parts: list[dict[str, list]], method: str) -> pd.DataFrame:
    """The angles rows of one clip from its chunks' results (or its one failed row)."""
    if parts:
        df = pd.DataFrame({c: [v for p in parts for v in p[c]] for c in CHUNK_COLUMNS})
    else:  # unopened and no frame count: one row says why
        reason = (
            "; ".join(r for r in (ps.row_reason(clip.position), "; ".join(clip.problems)) if r)
            or "video holds no frame"
        )
        df = pd.DataFrame(
            [
                {c: np.nan for c in CHUNK_COLUMNS}
                | {"frame": pd.NA, "method": method, "status": "failed", "reason": reason}
            ]
        )
    frames = pd.array(df["frame"], dtype="Int64")
    pts = df["pts_s"].to_numpy(float)
    time_s = clip.log_times_s(pts) if parts else np.array([np.nan])
    df = df.drop(columns=["frame", "pts_s"])
    df.insert(0, "image", clip.video)
    df["frame"] = frames
    if clip.info.files:  # a frame sequence: which file each row is (frame counts from 0)
        df["frame_file"] = sequence_file_names(clip.video, clip.info.files, frames)
    df["time_s"] = time_s
    if clip.log is not None:
        cond = frame_conditions(clip.log, time_s)
    else:
        cond = pd.DataFrame(
            {
                "pressure_kpa": np.nan,
                "direction": "up",
                "step": 0,
                "since_step_s": np.nan,
                "in_log": False,
            },
            index=range(len(df)),
        )
    outside = ~cond.pop("in_log").to_numpy(bool) & (df["status"] != "failed").to_numpy()
    if clip.log is not None and outside.any():
        why = (f"no pressure: the frame lies outside the pressure log {Path(clip.log.path).name} "
               f"({span_text(clip.log.span_s)} on the log clock; fix the log or clock_offset_s)")
        for column in (
            "psi_deg",
            "kappa_per_mm",
            "length_mm",
            "length_px",
            "width_px",
            "base_direction_deg",
            "base_side_split_deg",
            "residual_px",
            "degree",
            "straight_end_mm",
            "past_l0_mm",
        ):
            df.loc[outside, column] = np.nan
        df.loc[outside, "status"] = "failed"
        df.loc[outside, "reason"] = why
    df = pd.concat([df.reset_index(drop=True), cond.reset_index(drop=True)], axis=1)
    row = ps.manifest.iloc[clip.position]
    for key in RAMP_KEYS:
        df[key] = row[key]
    settings = ps.rows[clip.position]
    df["l0_mm"] = np.nan if settings is None else settings.l0_mm
    df["fixed_direction_deg"] = np.nan if settings is None else settings.base_given_deg
    df["positive_turn"] = None if settings is None else settings.positive_turn
    df["sealed_end_mm"] = np.nan if settings is None else settings.sealed_end_mm
    df["calibration_px"], df["calibration_mm"] = (
        (np.nan, np.nan) if settings is None else settings.calibration_rms
    )
    # a row's own setting columns as given, as for photos (not those written as used)
    drop = {"video", "pressure_log", "manifest_line", *VIDEO_OPTIONAL_COLUMNS, *df.columns}
    for column in ps.manifest.columns:
        if column not in drop:
            df[column] = row[column]
    return df


def measure_video_set(
    ps: PhotoSet, *, method: str, jobs: int = 1, overlays_dir: Path | None = None
) -> pd.DataFrame:
    """Measure every frame of every video of a video photo set.

    Parameters
    ----------
    ps : PhotoSet
        A loaded video photo set (``ps.is_video``).
    method : str
        Estimator (rows may override it with a ``method`` setting).
    jobs : int
        Worker processes.
    overlays_dir : Path, optional
        Write :data:`OVERLAYS_PER_VIDEO` overlays per video (``<video stem>_f<frame>.jpg``).

    Returns
    -------
    pandas.DataFrame
        One row per frame, videos in manifest order: the measurement columns (``image`` is the
        video's name), ``frame``, ``time_s`` (log clock, s), ``pressure_kpa``,
        ``measured_pressure_kpa`` (when logged), ``direction``, ``step``, ``since_step_s``, the
        ramp keys, ``l0_mm``, ``calibration_px`` and ``calibration_mm`` (as for photos) and the
        manifest's own other columns.
    """
    clips = resolve_clips(ps)
    for clip in clips:
        span = span_problem(clip)
        if span:  # measured anyway: frames outside the log become failed rows
            print(f"warning: manifest line {clip.line}: {span}", file=sys.stderr)
    tasks = _tasks(ps, clips, method, jobs, overlays_dir)
    results = map_photos(
        run_chunk,
        [t for _, t in tasks],
        jobs=jobs,
        preload=["pipeline.video.worker"],
        desc="frame chunks",
    )
    parts: dict[int, list[dict[str, list]]] = {clip.position: [] for clip in clips}
    for (position, _), result in zip(tasks, results):
        parts[position].append(result)
    frames = [_clip_rows(ps, clip, parts[clip.position], method) for clip in clips]
    out = pd.concat(frames, ignore_index=True)
    out["degree"] = pd.array(pd.to_numeric(out["degree"], errors="coerce").round(), dtype="Int64")
    out["step"] = out["step"].astype(int)
    return out
