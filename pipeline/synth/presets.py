"""Scene parameters of the virtual camera and table, and the named presets.

Every knob of a synthetic photo is a field of :class:`SceneParams`; :data:`SCENE_PRESETS` holds
sensible combinations (``clean``, ``lab``, ``hard``) and :func:`scene_from` derives a scene from a
preset with overrides (the config's ``synthetic.scene`` mapping and ``--set KEY=VALUE`` on the
command line end up there).

Examples
--------
>>> scene_from("lab", noise_sigma=0.0).noise_sigma
0.0
>>> s = scene_from("lab", width=640, height=480)      # same field of view, half the pixels
>>> round(s.mm_per_px / SCENE_PRESETS["lab"].mm_per_px, 3)
2.0
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from pipeline.errors import UserInputError

#: marker colours (BGR ink) for the names understood by ``pipeline.photoset.line_color_ranges``
LINE_INK_BGR: dict[str, tuple[int, int, int]] = {
    "black": (28, 26, 30),
    "blue": (165, 70, 25),
    "red": (35, 30, 190),
    "green": (60, 150, 35),
}

BACKGROUNDS: tuple[str, ...] = ("plain", "gradient", "textured")
DISTRACTOR_COLORS: tuple[str, ...] = ("grey", "line")


@dataclass(frozen=True)
class SceneParams:
    """Every knob of the virtual scene (table, actuator appearance, camera).

    Attributes
    ----------
    width, height : int
        Image size in pixels.
    mm_per_px : float
        Scale on the table plane (mm per pixel) at the image centre.
    background : str
        Table kind: ``plain`` (uniform), ``gradient`` (uniform colour, uneven light) or
        ``textured`` (low-frequency texture, e.g. a worn bench top).
    table_bgr : tuple of int
        Table colour (BGR, 0-255) before lighting.
    texture_strength : float
        Amplitude of the table texture in grey levels (``textured`` only).
    lighting_gradient : float
        Relative brightness change across the frame (0 = even light), direction seeded.
    vignetting : float
        Relative darkening in the corners (0 = none).
    distractor_marks : int
        Number of pen marks / scratches / tape edges on the table (never touching the actuator).
    distractor_color : str
        ``grey`` (pencil-like marks) or ``line`` (the marker's own colour: the hard case).
    line_color : str
        Marker colour name: ``black``, ``blue``, ``red`` or ``green``.
    line_width_px : float
        Width of the marker line in pixels (drawn exactly, sub-pixel anti-aliased).
    line_contrast : float
        Opacity of the ink, 0-1 (1 = the ink colour itself; lower = faded marker).
    body_width_mm : float
        In-plane width of the silicone body beside the marker line (b + a0 + t0 = 14 mm).
    body_translucency : float
        How much table shows through the silicone, 0 (opaque) to 1 (invisible).
    body_bgr : tuple of int
        Silicone colour (BGR).
    clamp, tube : bool
        Draw the clamp block at the fixed end and the supply tube leaving it.
    tilt_deg : float
        Camera tilt away from looking straight down (perspective), degrees.
    tilt_azimuth_deg : float
        Direction of the tilt axis in the image, degrees.
    focal_px_per_width : float
        Focal length in units of the image width (1.2 = a normal lens).
    noise_sigma : float
        Sensor noise standard deviation in grey levels.
    blur_sigma_px : float
        Gaussian optical blur, pixels.
    jpeg_quality : int
        JPEG quality (1-100) of the written images.
    occluded_fraction : float
        Fraction of the marker length hidden under a glare spot (0-0.5).
    rotation_jitter_deg : float
        Standard deviation of the mounting angle from one actuator/trial to the next, degrees.
    lens_k1 : float
        Radial lens distortion (OpenCV's k1 at ``focal_px_per_width``; > 0 pincushion, < 0
        barrel, 0 an ideal lens), see :mod:`pipeline.synth.camera`.
    """

    width: int = 1280
    height: int = 960
    mm_per_px: float = 0.3
    background: str = "gradient"
    table_bgr: tuple[int, int, int] = (188, 196, 202)
    texture_strength: float = 0.0
    lighting_gradient: float = 0.12
    vignetting: float = 0.15
    distractor_marks: int = 0
    distractor_color: str = "grey"
    line_color: str = "black"
    line_width_px: float = 6.0
    line_contrast: float = 1.0
    body_width_mm: float = 14.0
    body_translucency: float = 0.45
    body_bgr: tuple[int, int, int] = (222, 226, 228)
    clamp: bool = True
    tube: bool = True
    tilt_deg: float = 0.0
    tilt_azimuth_deg: float = 30.0
    focal_px_per_width: float = 1.2
    noise_sigma: float = 0.0
    blur_sigma_px: float = 0.0
    jpeg_quality: int = 92
    occluded_fraction: float = 0.0
    rotation_jitter_deg: float = 1.5
    lens_k1: float = 0.0

    def __post_init__(self) -> None:
        problems = _problems(self)
        if problems:
            raise UserInputError("scene parameters: " + "; ".join(problems))


def _problems(s: SceneParams) -> list[str]:
    out = []
    if not (16 <= s.width <= 20000 and 16 <= s.height <= 20000):
        out.append(f"width/height = {s.width}x{s.height} px must be 16..20000")
    for key in ("mm_per_px", "line_width_px", "body_width_mm", "focal_px_per_width"):
        if not getattr(s, key) > 0:
            out.append(f"{key} = {getattr(s, key)!r} must be > 0")
    for key in ("texture_strength", "noise_sigma", "blur_sigma_px", "lighting_gradient", "vignetting",
                "tilt_deg", "rotation_jitter_deg"):
        if not getattr(s, key) >= 0:
            out.append(f"{key} = {getattr(s, key)!r} must be >= 0")
    for key in ("line_contrast", "body_translucency"):
        if not 0 <= getattr(s, key) <= 1:
            out.append(f"{key} = {getattr(s, key)!r} must be between 0 and 1")
    if s.background not in BACKGROUNDS:
        out.append(f"background = {s.background!r}: use one of {list(BACKGROUNDS)}")
    if s.distractor_color not in DISTRACTOR_COLORS:
        out.append(f"distractor_color = {s.distractor_color!r}: use one of {list(DISTRACTOR_COLORS)}")
    if s.line_color not in LINE_INK_BGR:
        out.append(f"line_color = {s.line_color!r}: the renderer draws {sorted(LINE_INK_BGR)}")
    if s.distractor_marks < 0:
        out.append("distractor_marks must be >= 0")
    if not 1 <= s.jpeg_quality <= 100:
        out.append(f"jpeg_quality = {s.jpeg_quality!r} must be 1..100")
    if not 0 <= s.occluded_fraction <= 0.5:
        out.append(f"occluded_fraction = {s.occluded_fraction!r} must be 0..0.5")
    if not abs(s.lens_k1) <= 0.3:
        out.append(f"lens_k1 = {s.lens_k1!r} must be within -0.3..0.3 (a phone or action camera is about -0.1)")
    if s.tilt_deg > 20:
        out.append(f"tilt_deg = {s.tilt_deg} is more than 20 deg; a copy stand is never that far off")
    for key in ("table_bgr", "body_bgr"):
        v = getattr(s, key)
        if len(v) != 3 or any(not 0 <= int(c) <= 255 for c in v):
            out.append(f"{key} = {v!r} must be three integers 0-255 (B, G, R)")
    return out


#: named scenes: ``clean`` (ideal photo), ``lab`` (a realistic bench photo), ``hard`` (worst case)
SCENE_PRESETS: dict[str, SceneParams] = {
    "clean": SceneParams(
        background="plain", lighting_gradient=0.0, vignetting=0.0, body_translucency=0.6,
        noise_sigma=0.0, blur_sigma_px=0.0, jpeg_quality=95, tilt_deg=0.0, rotation_jitter_deg=0.0,
    ),
    "lab": SceneParams(
        background="textured", texture_strength=6.0, lighting_gradient=0.15, vignetting=0.18,
        distractor_marks=5, distractor_color="grey", line_contrast=0.95, body_translucency=0.45,
        tilt_deg=1.0, noise_sigma=2.5, blur_sigma_px=0.8, jpeg_quality=90, rotation_jitter_deg=1.5,
    ),
    "hard": SceneParams(
        background="textured", texture_strength=12.0, lighting_gradient=0.35, vignetting=0.35,
        distractor_marks=12, distractor_color="line", line_width_px=4.0, line_contrast=0.85,
        body_translucency=0.3, tilt_deg=3.0, noise_sigma=6.0, blur_sigma_px=1.5, jpeg_quality=75,
        occluded_fraction=0.05, rotation_jitter_deg=3.0,
    ),
}

_FIELD_TYPES: dict[str, Any] = {f.name: f.type for f in dataclasses.fields(SceneParams)}


def scene_from(preset: str | SceneParams = "lab", **overrides: Any) -> SceneParams:
    """A scene from a named preset with some knobs overridden.

    When ``width`` is overridden but ``mm_per_px`` is not, ``mm_per_px`` (and ``line_width_px``
    and ``blur_sigma_px`` unless given) are rescaled so the field of view and the look stay the
    same: ``scene_from("lab", width=640, height=480)`` is the lab photo at half resolution.

    Parameters
    ----------
    preset : str or SceneParams
        A key of :data:`SCENE_PRESETS` or a scene to start from.
    **overrides
        Field values; strings are converted to the field's type (so command-line
        ``KEY=VALUE`` pairs can be passed as they are).

    Returns
    -------
    SceneParams

    Raises
    ------
    UserInputError
        For an unknown preset or key, or a value of the wrong type or range.
    """
    if isinstance(preset, SceneParams):
        base = preset
    else:
        if preset not in SCENE_PRESETS:
            raise UserInputError(f"scene preset {preset!r} is unknown; use one of {sorted(SCENE_PRESETS)}")
        base = SCENE_PRESETS[preset]
    unknown = sorted(set(overrides) - set(_FIELD_TYPES))
    if unknown:
        raise UserInputError(f"scene key(s) {unknown} unknown; valid keys: {sorted(_FIELD_TYPES)}")
    values = {k: _convert(k, v) for k, v in overrides.items()}
    if "width" in values and "mm_per_px" not in values:
        factor = base.width / values["width"]
        values["mm_per_px"] = base.mm_per_px * factor
        values.setdefault("line_width_px", base.line_width_px / factor)
        values.setdefault("blur_sigma_px", base.blur_sigma_px / factor)
    return dataclasses.replace(base, **values)


def _convert(key: str, value: Any) -> Any:
    kind = str(_FIELD_TYPES[key])
    try:
        if kind == "int":
            if isinstance(value, float) and not value.is_integer():
                raise ValueError(value)
            return int(value)
        if kind == "float":
            return float(value)
        if kind == "bool":
            if isinstance(value, str):
                low = value.strip().lower()
                if low not in ("true", "false", "yes", "no", "1", "0", "on", "off"):
                    raise ValueError(value)
                return low in ("true", "yes", "1", "on")
            return bool(value)
        if kind.startswith("tuple"):
            items = value.split(",") if isinstance(value, str) else list(value)
            out = tuple(int(x) for x in items)
            if len(out) != 3:
                raise ValueError(value)
            return out
        return str(value)
    except (TypeError, ValueError) as exc:
        raise UserInputError(f"scene key {key} = {value!r} is not a valid {kind}") from exc
