"""When a photo was taken, from the time its camera wrote into it (EXIF).

Cameras and phones write ``DateTimeOriginal`` (the camera's wall clock, to the second) and most
write ``SubSecTimeOriginal`` (its fraction) too.  :func:`exif_time` reads them; the report dates a
photo set by them, and ``photoset init --pressure-log`` finds each photo's pressure in a pressure
log by them.

Examples
--------
>>> import pathlib, tempfile
>>> path = pathlib.Path(tempfile.mkdtemp()) / "IMG_0001.JPG"
>>> exif = Image.Exif()
>>> exif.get_ifd(EXIF_IFD).update({EXIF_DATETIME_ORIGINAL: "2026:12:06 14:25:01",
...                                EXIF_SUBSEC_ORIGINAL: "25"})
>>> Image.new("RGB", (8, 8)).save(path, exif=exif)
>>> exif_time(path)
datetime.datetime(2026, 12, 6, 14, 25, 1, 250000)
>>> Image.new("RGB", (8, 8)).save(path)  # no EXIF
>>> exif_time(path) is None
True
"""

from __future__ import annotations

import os
from datetime import datetime

from PIL import Image

#: EXIF tags: the Exif IFD; in it DateTimeOriginal and its SubSecTimeOriginal; in IFD0 DateTime and
#: SubSecTime (the time the file was last written by the camera, when the original is missing)
EXIF_IFD = 0x8769
EXIF_DATETIME_ORIGINAL, EXIF_SUBSEC_ORIGINAL = 36867, 37521
EXIF_DATETIME, EXIF_SUBSEC = 306, 37520


def exif_time(path: str | os.PathLike[str], *, original_only: bool = False) -> datetime | None:
    """The time the camera took a photo (``DateTimeOriginal`` with its ``SubSecTimeOriginal``,
    else ``DateTime`` with ``SubSecTime``), as the camera's clock read it, with no time zone.

    Parameters
    ----------
    path : path
        The photo.
    original_only : bool
        Only ``DateTimeOriginal``: ``DateTime`` is the time the file was last written, which an
        editor sets to when it saved the photo (fine for a date, not for a time to the second).

    Returns
    -------
    datetime.datetime or None
        ``None`` when the file cannot be opened or holds no such time.
    """
    try:
        with Image.open(path) as im:
            exif = im.getexif()
    except OSError:
        return None
    sources = [(exif.get_ifd(EXIF_IFD), (EXIF_DATETIME_ORIGINAL, EXIF_SUBSEC_ORIGINAL))]
    if not original_only:
        sources.append((exif, (EXIF_DATETIME, EXIF_SUBSEC)))
    for ifd, (time_tag, subsec_tag) in sources:
        value = ifd.get(time_tag)
        if not isinstance(value, str):
            continue
        try:
            when = datetime.strptime(value.strip("\x00 ")[:19], "%Y:%m:%d %H:%M:%S")
        except ValueError:
            continue
        digits = str(ifd.get(subsec_tag) or exif.get_ifd(EXIF_IFD).get(subsec_tag) or "").strip()
        if digits.isdigit():
            when = when.replace(microsecond=int(digits[:6].ljust(6, "0")))
        return when
    return None
