"""Colours that select the marker line or the actuator body: names, HSV ranges, a picker.

A colour is written by the user as a name (``black``, ``white``, ``grey``, ``red``, ``orange``,
``yellow``, ``green``, ``cyan``, ``blue``, ``purple``, ``magenta``), an explicit HSV range
``"h,s,v-h,s,v"`` in OpenCV units (H 0-179, S and V 0-255), a mapping
``{lower: [h, s, v], upper: [h, s, v]}``, or several of these: a YAML list, or one manifest cell
with the parts separated by ``;`` (``"red;orange"``,
``"0,90,50-10,255,255;170,90,50-179,255,255"``). It is parsed once, by :func:`parse_color`, into a
:class:`ColorSpec`.

Only the *name* ``black`` selects a dark drawn line by its local darkness (a black-hat filter
that ignores the clamp and shadows, see :func:`pipeline.measure.extract.line_mask`); an explicit
range always means exactly that range.

Examples
--------
>>> parse_color("blue").ranges
(((95, 80, 40), (130, 255, 255)),)
>>> parse_color("0,0,0-179,255,60").dark_line
False
>>> parse_color("red").describe()
'red (H 0-10 or 170-179, S >= 90, V >= 50)'
>>> len(parse_color("red;orange").ranges)
3
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

#: one HSV box in OpenCV units: ((h, s, v) lower, (h, s, v) upper), bounds included
HsvRange = tuple[tuple[int, int, int], tuple[int, int, int]]

#: named colours as HSV boxes (OpenCV units); red wraps around H = 0
NAMED_COLORS: dict[str, tuple[HsvRange, ...]] = {
    "black": (((0, 0, 0), (179, 255, 80)),),
    "white": (((0, 0, 170), (179, 50, 255)),),
    "grey": (((0, 0, 70), (179, 45, 200)),),
    "red": (((0, 90, 50), (10, 255, 255)), ((170, 90, 50), (179, 255, 255))),
    "orange": (((8, 110, 90), (22, 255, 255)),),
    "yellow": (((20, 80, 90), (35, 255, 255)),),
    "green": (((40, 70, 40), (85, 255, 255)),),
    "cyan": (((85, 70, 50), (100, 255, 255)),),
    "blue": (((95, 80, 40), (130, 255, 255)),),
    "purple": (((130, 60, 40), (150, 255, 255)),),
    "magenta": (((145, 70, 60), (172, 255, 255)),),
}
_ALIASES = {"gray": "grey", "violet": "purple", "pink": "magenta"}
_LIMITS = (179, 255, 255)
_RANGE_RE = re.compile(r"(\d+),(\d+),(\d+)-(\d+),(\d+),(\d+)")


class ColorError(ValueError):
    """A colour value that is neither a known name nor a valid HSV range (message says the fix)."""


@dataclass(frozen=True)
class ColorSpec:
    """A parsed colour: the HSV boxes it selects and how the user wrote it.

    Attributes
    ----------
    text : str
        The value as written (a name, a range, or ``;``-joined parts), for messages.
    ranges : tuple of HsvRange
        The HSV boxes; a pixel is selected when it lies in any of them.
    dark_line : bool
        True for the name ``black`` alone: a drawn dark line is found by its local darkness
        (black-hat), and a grey decoding of the photo is enough.
    """

    text: str
    ranges: tuple[HsvRange, ...]
    dark_line: bool = False

    def describe(self) -> str:
        """The colour in words, e.g. ``black (V <= 80)``.

        Examples
        --------
        >>> parse_color("black").describe()
        'black (V <= 80)'
        >>> parse_color("20,80,90-35,255,255").describe()
        'H 20-35, S >= 80, V >= 90'
        """
        names = [p for p in self.text.split(";") if _name(p) in NAMED_COLORS]
        words = _describe_ranges(self.ranges)
        if names and len(names) == len(self.text.split(";")):
            return f"{self.text} ({words})"
        return words


def _name(part: str) -> str:
    low = part.strip().lower()
    return _ALIASES.get(low, low)


def _bound(label: str, lo: int, hi: int, top: int) -> str | None:
    if lo == 0 and hi == top:
        return None
    if lo == 0:
        return f"{label} <= {hi}"
    if hi == top:
        return f"{label} >= {lo}"
    return f"{label} {lo}-{hi}"


def _describe_ranges(ranges: Sequence[HsvRange]) -> str:
    # red-like pairs that share S and V bounds read as one hue list
    if (
        len(ranges) == 2
        and ranges[0][0][1:] == ranges[1][0][1:]
        and ranges[0][1][1:] == ranges[1][1][1:]
    ):
        (a, b), (c, d) = ranges
        hue = f"H {a[0]}-{b[0]} or {c[0]}-{d[0]}"
        rest = [t for t in (_bound("S", a[1], b[1], 255), _bound("V", a[2], b[2], 255)) if t]
        return ", ".join([hue, *rest])
    parts = []
    for lo, hi in ranges:
        bits = [_bound(k, lo[i], hi[i], _LIMITS[i]) for i, k in enumerate("HSV")]
        parts.append(", ".join(b for b in bits if b) or "any colour")
    return " or ".join(parts)


def _check_range(lo: Sequence[int], hi: Sequence[int], text: str) -> HsvRange:
    if (
        len(lo) != 3
        or len(hi) != 3
        or any(not 0 <= a <= b <= m for a, b, m in zip(lo, hi, _LIMITS))
    ):
        raise ColorError(
            f"HSV range {text!r} is invalid: need 0 <= lower <= upper with H <= 179 and S, V <= "
            "255 "
            "(OpenCV units; a hue that wraps, like red, is two ranges joined by ';')"
        )
    return (int(lo[0]), int(lo[1]), int(lo[2])), (int(hi[0]), int(hi[1]), int(hi[2]))


def _parse_part(part: Any) -> tuple[str, tuple[HsvRange, ...]]:
    if isinstance(part, Mapping):
        try:
            lo, hi = [int(x) for x in part["lower"]], [int(x) for x in part["upper"]]
        except (KeyError, TypeError, ValueError) as exc:
            raise ColorError(
                f"colour range {dict(part)!r} needs 'lower' and 'upper' lists of three integers "
                "[h, s, v]"
            ) from exc
        text = f"{lo[0]},{lo[1]},{lo[2]}-{hi[0]},{hi[1]},{hi[2]}"
        return text, (_check_range(lo, hi, text),)
    if not isinstance(part, str):
        raise ColorError(f"colour {part!r} is not understood")
    text = part.strip()
    name = _name(text)
    if name in NAMED_COLORS:
        return name, NAMED_COLORS[name]
    m = _RANGE_RE.fullmatch(re.sub(r"\s+", "", text))
    if m:
        v = [int(x) for x in m.groups()]
        return text, (_check_range(v[:3], v[3:], text),)
    raise ColorError(
        f"colour {text!r} is not a known name ({', '.join(NAMED_COLORS)}) nor an HSV range "
        "'h,s,v-h,s,v' (OpenCV units: H 0-179, S/V 0-255); 'python -m pipeline photoset pick-color "
        "IMAGE --at X,Y' prints one"
    )


def parse_color(value: Any) -> ColorSpec:
    """Parse a colour value (name, range, mapping, or a list / ``;``-string of them).

    Parameters
    ----------
    value : str or mapping or list
        See the module docstring.

    Returns
    -------
    ColorSpec

    Raises
    ------
    ColorError
        Naming the bad part and the accepted forms.

    Examples
    --------
    >>> parse_color({"lower": [0, 0, 0], "upper": [179, 255, 60]}).ranges
    (((0, 0, 0), (179, 255, 60)),)
    >>> parse_color(["red", "yellow"]).text
    'red;yellow'
    """
    if isinstance(value, ColorSpec):
        return value
    if isinstance(value, str):
        parts: list[Any] = [p for p in value.split(";") if p.strip()]
    elif isinstance(value, Mapping):
        parts = [value]
    elif isinstance(value, (list, tuple)):
        parts = list(value)
    else:
        raise ColorError(
            f"colour {value!r} is not understood; give a name, an HSV range or a list of them"
        )
    if not parts:
        raise ColorError("colour is empty; give a name such as 'black' or an HSV range")
    texts: list[str] = []
    ranges: list[HsvRange] = []
    for part in parts:
        text, rng = _parse_part(part)
        texts.append(text)
        ranges.extend(rng)
    text = ";".join(texts)
    return ColorSpec(text=text, ranges=tuple(ranges), dark_line=(text == "black"))


BLACK = parse_color("black")


def color_mask(image_bgr: np.ndarray, spec: ColorSpec) -> np.ndarray:
    """0/1 mask of the pixels inside any of the colour's HSV boxes (exactly those boxes).

    Parameters
    ----------
    image_bgr : ndarray, shape (H, W, 3), uint8
    spec : ColorSpec

    Returns
    -------
    ndarray, shape (H, W), uint8
    """
    hsv = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2HSV)
    out = np.zeros(image_bgr.shape[:2], np.uint8)
    for lo, hi in spec.ranges:
        out |= np.asarray(cv2.inRange(hsv, lo, hi), np.uint8)
    return (out > 0).astype(np.uint8)


#: a picked colour's range reaches no darker than this value (V, 0-255), or half the sample's
#: median value when that is darker
PICK_DARKEST_V = 40.0


def pick_color(image_bgr: np.ndarray, x: float, y: float, radius_px: float = 4.0) -> ColorSpec:
    """An HSV range selecting the colour around a pixel (a disc of ``radius_px``).

    Hue is taken on the circle (red's wrap at H = 0 gives two ranges); saturation and value
    from the 2nd-98th percentiles, widened by a margin so lighting changes along the actuator
    stay inside.  A grey pixel (low saturation) gives a range that bounds only S and V.

    Parameters
    ----------
    image_bgr : ndarray, shape (H, W, 3), uint8
    x, y : float
        Pixel (x right, y down).
    radius_px : float
        Radius of the sampled disc (px).

    Returns
    -------
    ColorSpec

    Raises
    ------
    ColorError
        When the point is outside the image.

    Examples
    --------
    >>> img = np.zeros((20, 20, 3), np.uint8); img[:] = (40, 40, 200)     # BGR red
    >>> pick_color(img, 10, 10).text
    '0,144,130-6,255,255;174,144,130-179,255,255'
    """
    h, w = image_bgr.shape[:2]
    if not (0 <= x < w and 0 <= y < h):
        raise ColorError(f"--at {x:g},{y:g} is outside the {w}x{h} image")
    yy, xx = np.mgrid[0:h, 0:w]
    disc = (xx - x) ** 2 + (yy - y) ** 2 <= max(radius_px, 0.5) ** 2
    hsv = cv2.cvtColor(image_bgr, cv2.COLOR_BGR2HSV)[disc].astype(float)
    s_lo, s_hi = np.percentile(hsv[:, 1], [2, 98])
    v_lo, v_hi = np.percentile(hsv[:, 2], [2, 98])
    # hue is noise in near-black pixels, as in grey ones: a coloured range reaches no darker than
    # PICK_DARKEST_V, or half the sample's median (a red strip's pick on a dark backdrop went
    # down to V 0 and took in 20 % of the photo, its black surroundings)
    dark_floor = min(PICK_DARKEST_V, 0.5 * float(np.median(hsv[:, 2])))
    s_lo, v_lo = max(0.0, s_lo - 60.0), max(0.0, v_lo - 70.0)
    s_hi, v_hi = min(255.0, s_hi + 60.0), min(255.0, v_hi + 60.0)
    if np.median(hsv[:, 1]) < 45:  # grey: hue is noise
        lo, hi = (0, 0, int(v_lo)), (179, int(max(s_hi, 45)), int(v_hi))
        return parse_color(f"{lo[0]},{lo[1]},{lo[2]}-{hi[0]},{hi[1]},{hi[2]}")
    v_lo = max(v_lo, dark_floor)
    ang = hsv[:, 0] * (2 * np.pi / 180.0)
    centre = float(np.angle(np.mean(np.exp(1j * ang))) % (2 * np.pi)) * 180.0 / (2 * np.pi)
    dev = (hsv[:, 0] - centre + 90.0) % 180.0 - 90.0
    half = float(np.clip(np.percentile(np.abs(dev), 98) + 6.0, 6.0, 30.0))
    h_lo, h_hi = centre - half, centre + half
    s_v = f"{int(s_lo)},{int(v_lo)}", f"{int(s_hi)},{int(v_hi)}"
    if h_lo < 0:
        return parse_color(
            f"0,{s_v[0]}-{int(h_hi)},{s_v[1]};{int(180 + h_lo)},{s_v[0]}-179,{s_v[1]}"
        )
    if h_hi > 179:
        return parse_color(
            f"0,{s_v[0]}-{int(h_hi - 180)},{s_v[1]};{int(h_lo)},{s_v[0]}-179,{s_v[1]}"
        )
    return parse_color(f"{int(h_lo)},{s_v[0]}-{int(h_hi)},{s_v[1]}")
