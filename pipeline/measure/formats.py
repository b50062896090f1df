"""Why a photo could not be decoded, in words a user can act on.

OpenCV reads JPEG, PNG, TIFF, WebP, BMP, AVIF and JPEG 2000, but not the HEIC/HEIF photos a phone
takes by default, camera raw files or JPEG XL: a lab's first photo set often arrives in one of
those, and "corrupt or not an image" would send its owner looking for damage that is not there.
"""

from __future__ import annotations

from pathlib import PurePath

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
