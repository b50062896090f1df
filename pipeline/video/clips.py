"""The rows of a video photo set resolved into clips: video, pressure log, frame times, clocks.

One :class:`Clip` per manifest row, read once (the video probed, the log and frame-times files
read and checked) and used both by ``photoset check`` (:func:`clip_problems`) and by measuring
(:mod:`pipeline.video.measure`).  Time of frame ``k`` on the log's clock:
``frame_times[k] + clock_offset_s`` with a frame-times file, else its presentation time in the
video (``k / fps`` for AVI) ``+ clock_offset_s``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np

from pipeline.measure.settings import MeasureSettings, is_missing, user_float
from pipeline.photoset import MANIFEST, PhotoSet, Problem, geometry_problems
from pipeline.video.reader import VideoInfo, probe_video, read_frames
from pipeline.video.timeline import (
    PressureLog,
    covers,
    read_frame_times,
    read_pressure_log,
    span_text,
)


@dataclass(frozen=True)
class Clip:
    """One video row of a video photo set, its files read and checked.

    Attributes
    ----------
    position, line : int
        0-based row and 1-based line in manifest.csv.
    video : str
        The video's name as in the manifest.
    info : VideoInfo
        The probed video (``opened=False`` when missing or unreadable).
    log : PressureLog or None
        The pressure log (None when unusable; ``problems`` says why).
    frame_times_s : ndarray or None
        Frame timestamps on the video's clock from the ``frame_times`` file, if any.
    clock_offset_s : float
        Log time of video time 0 (s).
    problems : tuple of str
        What keeps every frame of the clip from being measured ('' problems: none).
    """

    position: int
    line: int
    video: str
    info: VideoInfo
    log: PressureLog | None
    frame_times_s: np.ndarray | None
    clock_offset_s: float
    problems: tuple[str, ...] = ()

    @property
    def n_frames(self) -> int:
        """Frames the clip should have: the frame-times file's, else the container's count."""
        return len(self.frame_times_s) if self.frame_times_s is not None else self.info.frame_count

    def nominal_video_times_s(self) -> np.ndarray:
        """Video-clock time of every expected frame before reading it (frame times, else k /
        fps)."""
        if self.frame_times_s is not None:
            return self.frame_times_s
        return np.arange(self.n_frames) * self.info.frame_period_s

    def log_times_s(self, pts_s: np.ndarray) -> np.ndarray:
        """Log-clock times of the frames given their presentation times (NaN where unread).

        The frame-times file wins; without it the presentation time, and for a frame that could
        not be read its nominal time ``k / fps``.
        """
        nominal = self.nominal_video_times_s()
        if self.frame_times_s is None:
            pts = np.asarray(pts_s, float)
            nominal = np.where(np.isfinite(pts), pts, nominal[: len(pts)])
        return nominal + self.clock_offset_s

    def describe(self) -> str:
        """The clip in one line for ``photoset check``: its frames, their span on the log's clock
        and the log's span and pressures (what a wrong ``clock_offset_s`` would show)."""
        if not self.info.opened:
            return f"{self.video}: not read"
        video = (
            f"{self.video}: {self.n_frames} frames at {self.info.fps:g} fps, "
            f"{span_text(self.span_s())} on the log clock (clock_offset_s {self.clock_offset_s:g})"
        )
        if self.log is None:
            return video
        p = self.log.pressure_kpa
        return (
            f"{video}; {Path(self.log.path).name} covers {span_text(self.log.span_s)}, "
            f"{np.nanmin(p):g} to {np.nanmax(p):g} kPa ({self.log.describe_columns()})"
        )

    def span_s(self) -> tuple[float, float]:
        """First and last frame time on the log's clock (NaN when the clip has no frames)."""
        t = self.nominal_video_times_s()
        if not len(t) or not np.isfinite(t).all():
            return math.nan, math.nan
        return float(t[0] + self.clock_offset_s), float(t[-1] + self.clock_offset_s)


def _offset(value: object) -> float:
    if is_missing(value):
        return 0.0
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return 0.0
    return v if math.isfinite(v) else 0.0


def resolve_clips(ps: PhotoSet) -> tuple[Clip, ...]:
    """Read every row of a video photo set (probe the video, read its log and frame times)."""
    m = ps.manifest
    clips = []
    for i in range(len(m)):
        row = m.iloc[i]
        video = "" if is_missing(row["video"]) else str(row["video"])
        problems: list[str] = []
        info = (
            probe_video(ps.image_path(video))
            if video
            else VideoInfo("", False, problem="video name is empty")
        )
        if not info.opened:
            problems.append(info.problem)
        elif info.frame_count == 0:
            problems.append(f"video {video} holds no frame")
        log = None
        if not is_missing(row["pressure_log"]):
            log, log_problems = read_pressure_log(ps.image_path(str(row["pressure_log"])))
            problems += log_problems
        times = None
        if "frame_times" in m.columns and not is_missing(row["frame_times"]):
            times, time_problems = read_frame_times(ps.image_path(str(row["frame_times"])))
            problems += time_problems
        offset = _offset(row["clock_offset_s"]) if "clock_offset_s" in m.columns else 0.0
        fps_cell = row["fps"] if "fps" in m.columns else None  # one not a rate: a row problem
        fps = user_float(fps_cell) if not is_missing(fps_cell) else 0.0
        if info.opened and fps > 0:
            info = replace(info, fps=fps)
            if times is None:  # frame k at k / fps, whatever the container says
                times = np.arange(info.frame_count) / fps
        if info.opened and times is None and not math.isfinite(info.fps) and is_missing(fps_cell):
            problems.append(
                f"video {video} does not say its frame rate; give its fps (a column of "
                "manifest.csv) or a frame_times file (frame, time_s)"
            )
        clips.append(
            Clip(i, int(row["manifest_line"]), video, info, log, times, offset, tuple(problems))
        )
    return tuple(clips)


def frame_settings(ps: PhotoSet, clip: Clip) -> MeasureSettings | None:
    """The settings a clip's frames are measured with: its manifest row's, marked
    ``video_frame`` (exposed while the body may move); None where the row cannot be measured."""
    row = ps.rows[clip.position]
    return None if row is None else replace(row, video_frame=True)


def span_problem(clip: Clip) -> str:
    """'' when the clip's pressure log covers its frames, else the message naming both spans."""
    if clip.log is None or not clip.n_frames:
        return ""
    video_span = clip.span_s()
    if math.isnan(video_span[0]) or covers(clip.log.span_s, video_span, slack_s=1e-6):
        return ""
    return (
        f"video {clip.video} spans {span_text(video_span)} on the log clock (frames "
        f"0-{clip.n_frames - 1}, "
        f"clock_offset_s {clip.clock_offset_s:g}) but its pressure log {Path(clip.log.path).name} "
        "covers "
        f"{span_text(clip.log.span_s)}: frames outside the log would have no pressure"
    )


def readable_frames(info: VideoInfo) -> int:
    """Frames of the video that can be read and decoded, reading it through once (packets are
    decoded at 1/8 size: enough to know the JPEG is whole)."""
    n = 0
    for frame in read_frames(info, 0, info.frame_count or None):
        if frame.data is None:
            break
        if info.packets and cv2.imdecode(frame.data, cv2.IMREAD_REDUCED_GRAYSCALE_8) is None:
            break
        n += 1
    return n


def clip_problems(
    ps: PhotoSet, *, decode: bool = True, require_files: bool = True
) -> list[Problem]:
    """Every problem of the files of a video photo set (``photoset check``), one per thing wrong.

    Parameters
    ----------
    ps : PhotoSet
        A loaded video photo set.
    decode : bool
        Also read every frame (a truncated or corrupt video is found here).
    require_files : bool
        Report missing videos and logs.
    """
    mpath = str(ps.folder / MANIFEST)
    out: list[Problem] = []
    for clip, settings in zip(resolve_clips(ps), ps.rows):
        for message in clip.problems:
            if "does not exist" in message and not require_files:
                continue
            fix = (
                "copy the file into the photo-set folder or fix its name in manifest.csv"
                if "does not exist" in message
                else "give the log a header line naming time_s and pressure_kpa (or the "
                "logger's own names with their unit in brackets: 't (s)', 'Setpoint (kPa)')"
                if "lacks column" in message
                else "save the log as a CSV file (comma, semicolon or tab between the fields)"
                if "cannot be parsed" in message
                else "correct the file and line the message names"
            )
            out.append(Problem(mpath, clip.line, message, fix))
        span = span_problem(clip)
        if span:
            out.append(
                Problem(
                    mpath,
                    clip.line,
                    span,
                    "give the pressure log of the whole recording, or correct clock_offset_s",
                )
            )
        if not clip.info.opened:
            continue
        if clip.frame_times_s is not None and len(clip.frame_times_s) != clip.info.frame_count:
            out.append(
                Problem(
                    mpath,
                    clip.line,
                    f"frame_times lists {len(clip.frame_times_s)} frames but video {clip.video} "
                    f"announces {clip.info.frame_count}",
                    "use the frame-times file written with this video",
                    warning=len(clip.frame_times_s) < clip.info.frame_count,
                )
            )
        if settings is not None:
            out += geometry_problems(
                mpath, clip.line, settings, (clip.info.width, clip.info.height)
            )
        if clip.info.files:
            out += _sequence_problems(mpath, clip, decode)
        elif decode:
            n = readable_frames(clip.info)
            if n < clip.n_frames:
                out.append(
                    Problem(
                        mpath,
                        clip.line,
                        f"only frames 0-{n - 1} of the {clip.n_frames} of video {clip.video} can "
                        "be "
                        "read (truncated or corrupt); the others will be failed rows",
                        "copy the whole file again from the camera, or accept the failed frames",
                    )
                )
    return out


def _sequence_problems(mpath: str, clip: Clip, decode: bool) -> list[Problem]:
    """The frames of a frame sequence that are missing (a number skipped) or, with ``decode``,
    cannot be decoded: one problem naming the first files, as each will be a failed row."""
    bad = [
        Path(f).name if f else f"frame {k}"
        for k, f in enumerate(clip.info.files)
        if not f or (decode and cv2.imread(f, cv2.IMREAD_REDUCED_GRAYSCALE_8) is None)
    ]
    missing = sum(1 for f in clip.info.files if not f)
    if not bad:
        return []
    shown = ", ".join(bad[:3]) + (", ..." if len(bad) > 3 else "")
    return [
        Problem(
            mpath,
            clip.line,
            f"{len(bad)} of the {clip.n_frames} frames of sequence {clip.video} "
            + (f"are missing ({missing}) or cannot be decoded" if decode else "are missing")
            + f": {shown}; they will be failed rows",
            "copy the frames again from where they were cut, or accept the failed frames",
        )
    ]
