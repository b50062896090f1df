"""Reading a user's photo, and why one could not be decoded, in words a user can act on.

OpenCV reads JPEG, PNG, TIFF, WebP, BMP, AVIF and JPEG 2000, but not the HEIC/HEIF photos a phone
takes by default, camera raw files or JPEG XL: a lab's first photo set often arrives in one of
those, and "corrupt or not an image" would send its owner looking for damage that is not there.

A scientific camera's 16-bit PNG or TIFF often holds 10, 12 or 14 bits: OpenCV's 8-bit decoding
keeps the top 8 of 16, so 12-bit data came out in grey levels 0-15, a black photo.
:func:`decode_image` scales such a photo by the bits it uses instead.
"""

from __future__ import annotations

from os import PathLike
from pathlib import PurePath

import cv2
import numpy as np

#: camera raw file extensions (Adobe DNG, Canon, Nikon, Sony, Fujifilm, Olympus, Panasonic,
#: Pentax, Samsung, Sigma, Hasselblad, Phase One, Leica, Kodak, Minolta)
RAW_EXTENSIONS = frozenset(
    {".dng", ".cr2", ".cr3", ".crw", ".nef", ".nrw", ".arw", ".srf", ".sr2", ".raf", ".orf"}
    | {".rw2", ".pef", ".srw", ".x3f", ".3fr", ".iiq", ".rwl", ".kdc", ".mrw", ".erf", ".raw"}
)
#: what a file OpenCV cannot read is, by extension
_KIND = {
    ".heic": "a HEIC/HEIF photo",
    ".heif": "a HEIC/HEIF photo",
    ".jxl": "a JPEG XL photo",
    **dict.fromkeys(RAW_EXTENSIONS, "a camera raw file"),
}
#: a photo that is none of these and still cannot be decoded
_DAMAGED = (
    "corrupt, truncated or not an image",
    "re-export or re-take the photo, or remove the row",
)
#: the fix for a photo of a format OpenCV cannot read
_EXPORT = "export the photos as JPEG (or PNG / TIFF) and use those instead"
_PHONE = " (an iPhone takes JPEGs with Settings > Camera > Formats > Most Compatible)"


def unreadable_format(name: str) -> str | None:
    """What the file is when OpenCV cannot read its format (by its extension), else None.

    Examples
    --------
    >>> unreadable_format("IMG_0042.heic"), unreadable_format("a.JPG")
    ('a HEIC/HEIF photo', None)
    """
    return _KIND.get(PurePath(name).suffix.lower())


def undecodable(name: str) -> tuple[str, str]:
    """(why, fix) for a photo that could not be decoded, from its file name.

    Examples
    --------
    >>> why, fix = undecodable("IMG_0042.HEIC")
    >>> why
    'a HEIC/HEIF photo, which OpenCV cannot read'
    >>> fix.startswith("export the photos as JPEG") and "iPhone" in fix
    True
    >>> undecodable("scan_3.NEF")[0]
    'a camera raw file, which OpenCV cannot read'
    >>> undecodable("p_20kPa.jpg")
    ('corrupt, truncated or not an image', 're-export or re-take the photo, or remove the row')
    """
    kind = unreadable_format(name)
    if kind is None:
        return _DAMAGED
    phone = _PHONE if "HEIC" in kind else ""
    return f"{kind}, which OpenCV cannot read", _EXPORT + phone


def to_8bit(image: np.ndarray) -> np.ndarray:
    """``image`` as 8 bits a channel; 16-bit data scaled by the bits its brightest pixel uses.

    A 12-bit camera's values (0-4095, in a 16-bit file) fill 0-255 whatever the file's depth,
    as they would in that camera's own 8-bit export; data using all 16 bits is read as OpenCV
    reads it (the top 8). Floating-point data (a 32-bit TIFF) is scaled from [0, 1], or from
    [0, its maximum] when that is larger.

    Examples
    --------
    >>> twelve_bit = np.array([[0, 2048, 4095]], np.uint16)
    >>> to_8bit(twelve_bit).tolist(), to_8bit(twelve_bit * 16).tolist()
    ([[0, 128, 255]], [[0, 128, 255]])
    >>> to_8bit(np.array([[0.0, 0.5, 1.0]], np.float32)).tolist()
    [[0, 128, 255]]
    """
    if image.dtype == np.uint8:
        return image
    if image.dtype == np.uint16:
        bits = max(8, int(image.max(initial=0)).bit_length())
        return cv2.convertScaleAbs(image, alpha=255.0 / ((1 << bits) - 1))
    data = np.nan_to_num(image.astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    top = float(data.max(initial=0.0))
    return cv2.convertScaleAbs(data, alpha=255.0 / max(top, 1.0))


def decode_image(data: np.ndarray, grey: bool = False) -> np.ndarray | None:
    """A photo's bytes decoded to 8-bit BGR (or grey), turned upright by its EXIF orientation;
    None if they cannot be decoded. A 16-bit or floating-point photo goes through
    :func:`to_8bit`.
    """
    if not data.size:
        return None
    mode = cv2.IMREAD_GRAYSCALE if grey else cv2.IMREAD_COLOR
    image = cv2.imdecode(data, mode | cv2.IMREAD_ANYDEPTH)
    return None if image is None else to_8bit(image)


def read_image(path: str | PathLike[str], grey: bool = False) -> np.ndarray | None:
    """:func:`decode_image` of the file at ``path``; None if it is missing or cannot be decoded."""
    try:
        data = np.fromfile(str(path), dtype=np.uint8)
    except OSError:
        return None
    return decode_image(data, grey)
