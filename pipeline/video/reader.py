"""Open a video with OpenCV and stream its frames, never holding more than one in memory.

MJPEG videos (what most lab USB cameras record, and what the synthetic rig writes) are read as
their JPEG packets (``CAP_PROP_FORMAT = -1``): the measurement then decodes each packet exactly as
it decodes a photo, directly at reduced size and in grey for a black line
(:func:`pipeline.measure.core.decode_for_work`), which is several times cheaper than a full colour
decode.  Any other codec OpenCV's FFmpeg can read (MPEG-4, H.264 where the build has a decoder)
is read as decoded frames.

A *frame sequence* (the files ``ffmpeg -i video.mp4 frame_%04d.jpg`` writes, or a high-speed
camera's export) is read as a video named by that pattern, ``frame_%04d.jpg``: frame ``k`` is the
``k``-th number from the lowest one present, and its file's bytes are its packet, decoded like a
photo.  A number missing between the lowest and the highest is an unreadable frame, never a
shift of the ones after it.  A sequence has no frame rate of its own (``fps`` NaN).

Seeking: a chunk of frames starts with a seek, checked against the frame's presentation time
(``k / fps``); where the container cannot seek (a truncated AVI has lost its index and OpenCV
then returns frame 0 whatever is asked) the reader skips packets from the start instead, so a
frame index always means the same frame.

Examples
--------
>>> import tempfile, os, cv2, numpy as np
>>> path = os.path.join(tempfile.mkdtemp(), "clip.avi")
>>> w = cv2.VideoWriter(path, cv2.VideoWriter.fourcc(*"MJPG"), 10, (64, 48))
>>> for i in range(5):
...     _ = w.write(np.full((48, 64, 3), 40 * i, np.uint8))
>>> w.release()
>>> info = probe_video(path)
>>> info.frame_count, info.fps, info.packets, info.seekable
(5, 10.0, True, True)
>>> [(f.index, round(f.pts_s, 2)) for f in read_frames(info, 3, 2)]
[(3, 0.3), (4, 0.4)]
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

#: four-character codes whose packets are plain JPEG images
JPEG_FOURCCS: frozenset[str] = frozenset({"MJPG", "mjpg", "MJPA", "AVRn", "JPEG", "jpeg"})
#: consecutive unreadable frames after which the rest of a chunk is given up
MAX_CONSECUTIVE_FAILURES = 2


@dataclass(frozen=True)
class VideoInfo:
    """What a video file is, as far as OpenCV can tell without decoding it.

    Attributes
    ----------
    path : str
        The file.
    opened : bool
        OpenCV could open it.
    frame_count : int
        Frames the container announces (0 when unknown or unopened); a truncated file may
        hold fewer.
    fps : float
        Nominal frame rate (NaN when unknown).
    width, height : int
        Frame size (px).
    fourcc : str
        Codec four-character code ('' when unknown).
    packets : bool
        Frames can be read as JPEG packets (MJPEG whose first packet decodes as a JPEG).
    seekable : bool
        A seek lands on the frame asked for (checked in the middle of the video).
    problem : str
        Why the video cannot be read ('' when it can).
    files : tuple of str
        Of a frame sequence: frame k's file ('' where its number is missing); empty for a video.
    """

    path: str
    opened: bool
    frame_count: int = 0
    fps: float = math.nan
    width: int = 0
    height: int = 0
    fourcc: str = ""
    packets: bool = False
    seekable: bool = False
    problem: str = ""
    files: tuple[str, ...] = ()

    @property
    def frame_period_s(self) -> float:
        """1 / fps (s); NaN when the rate is unknown."""
        return 1.0 / self.fps if self.fps and math.isfinite(self.fps) and self.fps > 0 else math.nan


@dataclass(frozen=True)
class Frame:
    """One frame as read: ``data`` is a JPEG packet (1-D uint8) or a decoded BGR image, or None.

    ``pts_s`` is the presentation time in the video (s, NaN when unread); ``reason`` says why
    ``data`` is None.
    """

    index: int
    pts_s: float
    data: np.ndarray | None
    reason: str = ""


def _fourcc(cap: cv2.VideoCapture) -> str:
    code = int(cap.get(cv2.CAP_PROP_FOURCC))
    if code <= 0:
        return ""
    return "".join(chr((code >> (8 * i)) & 0xFF) for i in range(4)).strip("\x00")


def _open(path: str, packets: bool) -> cv2.VideoCapture:
    cap = cv2.VideoCapture(path, cv2.CAP_FFMPEG)
    if packets and cap.isOpened():
        cap.set(cv2.CAP_PROP_FORMAT, -1)
    return cap


def _pts_s(cap: cv2.VideoCapture) -> float:
    return float(cap.get(cv2.CAP_PROP_POS_MSEC)) / 1000.0


def _lands_on(cap: cv2.VideoCapture, index: int, fps: float) -> bool:
    """Seek to ``index`` and check with the presentation time that it got there (cap is left after
    it)."""
    if not cap.set(cv2.CAP_PROP_POS_FRAMES, float(index)):
        return False
    ok = cap.grab()
    return bool(ok) and abs(_pts_s(cap) - index / fps) <= 0.5 / fps


#: the frame number in a frame sequence's name, as ffmpeg writes it: %d, or %0Nd zero-padded
SEQUENCE_NUMBER = re.compile(r"%(0\d+)?d")


def sequence_files(path: str | Path) -> tuple[str, ...] | None:
    """The files of the frame sequence ``path`` names (``frames/frame_%04d.jpg``), frame k at
    k places from the lowest number present ('' where a number is missing); None when ``path``
    names no sequence.

    Examples
    --------
    >>> import tempfile
    >>> root = Path(tempfile.mkdtemp())
    >>> for name in ("f_0001.jpg", "f_0002.jpg", "f_0004.jpg", "f_00003.jpg", "f_2.jpg"):
    ...     _ = (root / name).write_bytes(b"x")
    >>> [Path(f).name if f else "" for f in sequence_files(root / "f_%04d.jpg")]
    ['f_0001.jpg', 'f_0002.jpg', '', 'f_0004.jpg']
    >>> sequence_files(root / "f_0001.jpg") is None, sequence_files(root / "g_%d.png")
    (True, ())
    """
    path = Path(path)
    found = list(SEQUENCE_NUMBER.finditer(path.name))
    if len(found) != 1:
        return None
    m = found[0]
    width = int(m.group(1)) if m.group(1) else 1
    name = re.compile(
        re.escape(path.name[: m.start()]) + rf"(\d{{{width},}})" + re.escape(path.name[m.end():])
    )
    numbers: dict[int, str] = {}
    if path.parent.is_dir():
        for entry in path.parent.iterdir():
            hit = name.fullmatch(entry.name)
            # zero-padded to its width (%04d: 9999 is followed by 10000; 00003 is not its 3)
            digits = hit.group(1) if hit else ""
            if hit and entry.is_file() and (
                not m.group(1) or len(digits) == width or digits[0] != "0"
            ):
                numbers[int(digits)] = str(entry)
    if not numbers:
        return ()
    lo, hi = min(numbers), max(numbers)
    return tuple(numbers.get(n, "") for n in range(lo, hi + 1))


def sequence_file_name(pattern: str, files: tuple[str, ...], k: int) -> str:
    """The name of frame ``k``'s file in the sequence ``pattern`` whose files are ``files`` (as
    :func:`sequence_files` gives them): the file found, or the one missing at that number.

    Examples
    --------
    >>> files = ("/d/f_0007.jpg", "", "/d/f_0009.jpg")
    >>> [sequence_file_name("d/f_%04d.jpg", files, k) for k in range(4)]
    ['f_0007.jpg', 'f_0008.jpg', 'f_0009.jpg', 'f_0010.jpg']
    """
    if k < len(files) and files[k]:
        return Path(files[k]).name
    if not any(files):
        return ""
    name = Path(pattern).name
    m = SEQUENCE_NUMBER.search(name)
    first = Path(next(f for f in files if f)).name
    if m is None or not first:
        return ""
    number = int(first[m.start() : len(first) - (len(name) - m.end())]) + k
    return name[: m.start()] + m.group(0) % number + name[m.end() :]


def _probe_sequence(path: str, files: tuple[str, ...]) -> VideoInfo:
    """A frame sequence described as a video: its frames are its files, packets of one image
    each; seekable; no frame rate."""
    name = Path(path).name
    if not files:
        return VideoInfo(
            path,
            False,
            problem=f"video {name}: no file of {Path(path).parent} is named like it (a frame "
            f"sequence, {SEQUENCE_NUMBER.sub('<number>', name)})",
        )
    first = cv2.imread(files[0]) if files[0] else None
    if first is None:
        return VideoInfo(
            path, False, problem=f"video {name}: its first frame {Path(files[0]).name} cannot be "
            "decoded"
        )
    height, width = first.shape[:2]
    return VideoInfo(path, True, len(files), math.nan, width, height, "", True, True, "", files)


def probe_video(path: str | Path) -> VideoInfo:
    """Open ``path`` and describe it (frame count, rate, size, codec, packet reading, seeking);
    a frame sequence's name (``frame_%04d.jpg``) describes its files.

    Never raises: a file OpenCV cannot open gives ``opened=False`` and the reason.
    """
    path = str(path)
    files = sequence_files(path)
    if files is not None:
        return _probe_sequence(path, files)
    if not Path(path).is_file():
        return VideoInfo(path, False, problem=f"video {Path(path).name} does not exist")
    cap = _open(path, packets=False)
    if not cap.isOpened():
        return VideoInfo(
            path,
            False,
            problem=f"video {Path(path).name} cannot be opened by OpenCV (not a video, "
            "an unsupported codec, or truncated before its header was complete)",
        )
    try:
        count = round(cap.get(cv2.CAP_PROP_FRAME_COUNT))
        fps = float(cap.get(cv2.CAP_PROP_FPS))
        fps = fps if math.isfinite(fps) and fps > 0 else math.nan
        width, height = (
            int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)),
            int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT)),
        )
        fourcc = _fourcc(cap)
    finally:
        cap.release()
    packets = False
    if fourcc in JPEG_FOURCCS:
        cap = _open(path, packets=True)
        ok, data = cap.read()
        cap.release()
        packets = (
            bool(ok)
            and data is not None
            and data.size > 4
            and bytes(data.ravel()[:2]) == b"\xff\xd8"
            and (cv2.imdecode(data.ravel(), cv2.IMREAD_REDUCED_GRAYSCALE_8) is not None)
        )
    if count <= 0:  # the container does not say: count by reading (slow for long non-MJPEG videos)
        count = sum(
            1
            for f in read_frames(
                VideoInfo(path, True, 0, fps, width, height, fourcc, packets), 0, None
            )
            if f.data is not None
        )
    seekable = False
    if count > 2 and math.isfinite(fps):
        cap = _open(path, packets)
        seekable = _lands_on(cap, count // 2, fps)
        cap.release()
    return VideoInfo(path, True, max(count, 0), fps, width, height, fourcc, packets, seekable)


def read_frames(info: VideoInfo, first: int, count: int | None) -> Iterator[Frame]:
    """Frames ``first .. first + count - 1`` of a probed video, in order, one at a time.

    Yields exactly ``count`` frames (all frames to the end when ``count`` is None); a frame that
    cannot be read has ``data=None`` and the reason.  After
    :data:`MAX_CONSECUTIVE_FAILURES` unreadable frames the rest are not attempted.
    """
    name = Path(info.path).name
    end = None if count is None else first + count
    if not info.opened:
        for k in range(first, end if end is not None else first):
            yield Frame(k, math.nan, None, info.problem)
        return
    if info.files:
        yield from _sequence_frames(info, first, len(info.files) if end is None else end)
        return
    cap = _open(info.path, info.packets)
    try:
        k = first
        if first > 0:
            landed = info.seekable and _lands_on(cap, first, info.fps)
            if landed:
                cap.set(cv2.CAP_PROP_POS_FRAMES, float(first))
            else:  # no usable index: skip packets from the start
                cap.release()
                cap = _open(info.path, info.packets)
                skipped = 0
                while skipped < first and cap.grab():
                    skipped += 1
                if skipped < first:
                    reason = (
                        f"frame could not be read from {name}: the video ends or is corrupt after "
                        "frame "
                        f"{skipped - 1} (the container announces {info.frame_count} frames)"
                    )
                    for j in range(first, end if end is not None else first):
                        yield Frame(j, math.nan, None, reason)
                    return
        failures = 0
        while end is None or k < end:
            ok, data = (False, None) if failures >= MAX_CONSECUTIVE_FAILURES else cap.read()
            if not ok or data is None or data.size == 0:
                if end is None:
                    return
                failures += 1
                yield Frame(
                    k,
                    math.nan,
                    None,
                    f"frame {k} could not be read from {name}: the video is truncated or "
                    f"corrupt here (the container announces {info.frame_count} frames)",
                )
                k += 1
                continue
            failures = 0
            yield Frame(k, _pts_s(cap), data.ravel() if info.packets else data)
            k += 1
    finally:
        cap.release()


def _sequence_frames(info: VideoInfo, first: int, end: int) -> Iterator[Frame]:
    """Frames ``first .. end - 1`` of a frame sequence: each file's bytes, or the reason."""
    for k in range(first, end):
        file = info.files[k] if k < len(info.files) else ""
        data = np.fromfile(file, np.uint8) if file else np.empty(0, np.uint8)
        if data.size:
            yield Frame(k, math.nan, data)
            continue
        why = "is empty" if file else "is missing from the sequence"
        its = sequence_file_name(info.path, info.files, k)
        yield Frame(
            k, math.nan, None,
            f"frame {k} of {Path(info.path).name}{f' ({its})' if its else ''} {why}",
        )
