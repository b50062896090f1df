"""Write a video with OpenCV's ``VideoWriter`` (FFmpeg back-end): the codecs that work, or a clear
refusal.

MJPEG in AVI works in every OpenCV build with FFmpeg (and is what most USB lab cameras record);
MPEG-4 Part 2 too.  H.264 needs an encoder (libx264, OpenH264) that the pip wheels of OpenCV do
not ship: there the request is refused with the codecs that work, instead of a silent fallback.
"""

from __future__ import annotations

from pathlib import Path

import cv2

from pipeline.errors import UserInputError

#: codec name -> (four-character code, file suffix)
CODECS: dict[str, tuple[str, str]] = {
    "mjpg": ("MJPG", ".avi"),
    "mp4v": ("mp4v", ".avi"),
    "h264": ("avc1", ".mp4"),
}


def open_writer(path: Path, codec: str, fps: float, size: tuple[int, int]) -> cv2.VideoWriter:
    """An open ``VideoWriter`` for ``codec`` (a key of :data:`CODECS`), or a clear refusal.

    Raises
    ------
    UserInputError
        Unknown codec, or one this OpenCV build cannot encode (named with those it can).
    """
    if codec not in CODECS:
        raise UserInputError(f"codec {codec!r} is unknown; use one of {sorted(CODECS)}")
    fourcc, _ = CODECS[codec]
    writer = cv2.VideoWriter(
        str(path), cv2.CAP_FFMPEG, cv2.VideoWriter.fourcc(*fourcc), float(fps), size
    )
    if not writer.isOpened():
        writer.release()
        Path(path).unlink(missing_ok=True)
        raise UserInputError(
            f"this OpenCV build cannot encode {codec} (FourCC {fourcc}); use codec mjpg (what USB "
            "lab "
            "cameras record) or mp4v"
        )
    return writer
