"""Scene parameters of the virtual camera and table, and the named presets.

Every knob of a synthetic photo is a field of :class:`SceneParams`; :data:`SCENE_PRESETS` holds
sensible combinations and :func:`scene_from` derives a scene from a preset with overrides (the
config's ``scene_set`` mapping and ``--set KEY=VALUE`` on the command line end up there).

Presets: ``clean``, ``lab``, ``hard`` (the paper's drawn marker line on a bench) and three scenes
of actuators that carry no drawn line (``target: body``), modelled on the real photo kinds kept
back for checking: ``green_fibre`` (translucent fibre-wound body, green chroma backdrop, white
clamp, supply tube), ``grey_dots`` (opaque silicone with motion-capture dots, grey backdrop,
black clamp plate), ``grey_dots_clear`` (the same rig, a translucent body) and
``dark_translucent`` (translucent ribbed body with a tip cap over a black backdrop).

Examples
--------
>>> scene_from("lab", noise_sigma=0.0).noise_sigma
0.0
>>> s = scene_from("lab", width=640, height=480)      # same field of view, half the pixels
>>> round(s.mm_per_px / SCENE_PRESETS["lab"].mm_per_px, 3)
2.0
>>> g = scene_from("green_fibre", table_bgr="grey")   # colour knobs also take a name
>>> g.target, g.marker_line, g.table_bgr
('body', False, (128, 130, 129))
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from pipeline.errors import UserInputError

#: default length of a body's sealed end past its chamber (mm): straight, no turning
SEALED_END_MM = 4.0
#: marker colours (BGR ink) for the names understood by ``pipeline.photoset.line_color_ranges``
LINE_INK_BGR: dict[str, tuple[int, int, int]] = {
    "black": (28, 26, 30),
    "blue": (165, 70, 25),
    "red": (35, 30, 190),
    "green": (60, 150, 35),
}

#: named colours (BGR) accepted by every colour knob (``table_bgr=green``, ``body_bgr=clear`` ...)
NAMED_BGR: dict[str, tuple[int, int, int]] = {
    "bench": (188, 196, 202),      # today's pale bench top
    "green": (58, 160, 40),        # chroma-key backdrop as a camera sees it under studio light
    "grey": (128, 130, 129),       # photographer's mid-grey card / painted board
    "black": (24, 23, 25),         # black velvet / matt black card
    "white": (236, 238, 240),
    "clear": (222, 226, 228),      # clear / milky silicone (Ecoflex, Dragon Skin)
    "pink": (150, 140, 228),       # pigmented silicone
    "blue": (200, 150, 70),
    "orange": (60, 140, 240),
    "tan": (110, 165, 205),        # Kevlar / aramid thread
}

BACKGROUNDS: tuple[str, ...] = ("plain", "gradient", "textured")
DISTRACTOR_COLORS: tuple[str, ...] = ("grey", "line")
TARGETS: tuple[str, ...] = ("line", "body")
SHAPES: tuple[str, ...] = ("model", "arc", "distal", "chambers")
TEXTURES: tuple[str, ...] = ("none", "fibre", "ribs")
CLAMP_STYLES: tuple[str, ...] = ("block", "white", "plate")
DOT_COLORS: tuple[str, ...] = ("white", "dark")
DOT_LAYOUTS: tuple[str, ...] = ("centre", "edges", "outline")
#: knobs that are colours (three integers 0-255, B, G, R, or a name of NAMED_BGR)
COLOR_KEYS: tuple[str, ...] = ("table_bgr", "body_bgr", "texture_bgr", "tip_cap_bgr")


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
        Standard deviation of the mounting angle from one actuator/trial to the next, degrees
        (the actuator turns in its clamp; the clamp, plate, tube and table stay put).
    marker_line : bool
        Draw the marker line along the inextensible layer (False: a body with no drawn line).
    target : str
        What a photo set of this scene asks the measurement to measure, and what its truth
        curve is: ``line`` (the drawn marker) or ``body`` (the body's own centre line, midway
        between its two long edges; any curve parallel to the inextensible layer turns through
        the same total angle psi).  ``line`` needs ``marker_line``.
    shape : str
        How the curvature is spread along the body (total turning psi in every case):
        ``model`` (the virtual actuator's law: an arc, bulging past psi = 0 for soft
        silicones), ``arc`` (constant curvature), ``distal`` (a straight base, curvature
        growing towards the tip), ``chambers`` (piecewise: each chamber bends in proportion to
        its weight in ``chamber_bend``).
    straight_base_fraction : float
        ``distal``: fraction of the length at the fixed end that stays straight (0-0.8).
    chamber_bend : tuple of float
        One weight per chamber, fixed end first (``--set chamber_bend=0,1,1``: the base chamber
        stays straight).  More than one chamber also draws the joints between them.
    body_shading : float
        Relief across the body, 0-1: 0 is today's flat band; > 0 shades the body as a rounded
        tube (light from a seeded side), draws rims on both long edges and thins a
        translucent body towards its edges.
    texture : str
        ``none``, ``fibre`` (a double helix of thin strands wound around the body, seeded
        irregular spacing) or ``ribs`` (pleats: periodic bands across the body with slightly
        bulging edges, seeded irregular spacing).
    texture_pitch_mm : float
        Winding pitch of the fibre or spacing of the ribs (mm).
    texture_contrast : float
        Strength of the strands or grooves, 0-1.
    texture_bgr : tuple of int
        Colour of the fibre strands (BGR).
    specular : float
        Strength of the specular highlight streaks along the body, 0-1.
    dots : int
        Number of motion-capture dots on the body (0 = none), spread along its length.
    dot_color : str
        ``white`` (retro-reflective markers lit from the camera) or ``dark`` (printed dots).
    dot_diameter_mm : float
        Dot diameter (mm).
    dot_layout : str
        ``centre`` (on the body's centre line), ``edges`` (alternating near the two faces) or
        ``outline`` (alternating on the two edges, each standing half out of the body's outline:
        markers stuck along its top and bottom faces).
    tip_cap_mm : float
        Length of a rigid end block at the free end (mm, 0 = none); it is a little wider than
        the body and coloured ``tip_cap_bgr``.
    sealed_end_mm : float
        Length of the body's sealed end past its chamber (mm): straight, as wide as the body, in
        its colour; it adds no turning (``bench realscenes --sealed-end-mm`` varies it).
    tip_cap_bgr : tuple of int
        Colour of the tip cap (BGR).
    clamp_style : str
        ``block`` (today's dark clamp), ``white`` (a white printed clamp) or ``plate`` (a large
        black plate the actuator emerges from; it may reach the image border).
    shadow : float
        Strength of the soft shadows the body and clamp cast on the backdrop, 0-1.
    background_photo : bool
        Photo sets of this scene also hold ``background.jpg``, the empty scene (same camera,
        light and clamp, no actuator, its own sensor noise), named in ``photoset.yaml``.
    known_fixed_direction : bool
        Photo sets of this scene state, per photo, the on-screen direction in which the
        actuator leaves the clamp (manifest column ``fixed_direction_deg``).
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
    marker_line: bool = True
    target: str = "line"
    shape: str = "model"
    straight_base_fraction: float = 0.35
    chamber_bend: tuple[float, ...] = (1.0,)
    body_shading: float = 0.0
    texture: str = "none"
    texture_pitch_mm: float = 3.0
    texture_contrast: float = 0.35
    texture_bgr: tuple[int, int, int] = (70, 80, 90)
    specular: float = 0.0
    dots: int = 0
    dot_color: str = "white"
    dot_diameter_mm: float = 4.0
    dot_layout: str = "centre"
    tip_cap_mm: float = 0.0
    sealed_end_mm: float = SEALED_END_MM
    tip_cap_bgr: tuple[int, int, int] = (40, 40, 44)
    clamp_style: str = "block"
    shadow: float = 0.0
    background_photo: bool = False
    known_fixed_direction: bool = False
    lens_k1: float = 0.0

    @property
    def plain_body(self) -> bool:
        """The body is today's flat translucent band (no relief, texture, highlights, dots or
        cap)."""
        return (
            self.body_shading == 0
            and self.texture == "none"
            and self.specular == 0
            and self.dots == 0
            and self.tip_cap_mm == 0
            and len(self.chamber_bend) == 1
            and self.shadow == 0
        )

    def __post_init__(self) -> None:
        problems = _problems(self)
        if problems:
            raise UserInputError("scene parameters: " + "; ".join(problems))


def _problems(s: SceneParams) -> list[str]:
    out = []
    if not (16 <= s.width <= 20000 and 16 <= s.height <= 20000):
        out.append(f"width/height = {s.width}x{s.height} px must be 16..20000")
    for key in (
        "mm_per_px",
        "line_width_px",
        "body_width_mm",
        "focal_px_per_width",
        "texture_pitch_mm",
        "dot_diameter_mm",
    ):
        if not getattr(s, key) > 0:
            out.append(f"{key} = {getattr(s, key)!r} must be > 0")
    for key in (
        "texture_strength",
        "noise_sigma",
        "blur_sigma_px",
        "lighting_gradient",
        "vignetting",
        "tilt_deg",
        "rotation_jitter_deg",
        "tip_cap_mm",
        "sealed_end_mm",
    ):
        if not getattr(s, key) >= 0:
            out.append(f"{key} = {getattr(s, key)!r} must be >= 0")
    for key in (
        "line_contrast",
        "body_translucency",
        "body_shading",
        "texture_contrast",
        "specular",
        "shadow",
    ):
        if not 0 <= getattr(s, key) <= 1:
            out.append(f"{key} = {getattr(s, key)!r} must be between 0 and 1")
    if s.background not in BACKGROUNDS:
        out.append(f"background = {s.background!r}: use one of {list(BACKGROUNDS)}")
    if s.distractor_color not in DISTRACTOR_COLORS:
        out.append(
            f"distractor_color = {s.distractor_color!r}: use one of {list(DISTRACTOR_COLORS)}"
        )
    if s.line_color not in LINE_INK_BGR:
        out.append(f"line_color = {s.line_color!r}: the renderer draws {sorted(LINE_INK_BGR)}")
    if s.distractor_marks < 0:
        out.append("distractor_marks must be >= 0")
    if not 1 <= s.jpeg_quality <= 100:
        out.append(f"jpeg_quality = {s.jpeg_quality!r} must be 1..100")
    if not 0 <= s.occluded_fraction <= 0.5:
        out.append(f"occluded_fraction = {s.occluded_fraction!r} must be 0..0.5")
    if not abs(s.lens_k1) <= 0.3:
        out.append(
            f"lens_k1 = {s.lens_k1!r} must be within -0.3..0.3 (a phone or action camera is about "
            "-0.1)"
        )
    if s.tilt_deg > 20:
        out.append(
            f"tilt_deg = {s.tilt_deg} is more than 20 deg; a copy stand is never that far off"
        )
    for key in COLOR_KEYS:
        v = getattr(s, key)
        if len(v) != 3 or any(not 0 <= int(c) <= 255 for c in v):
            out.append(
                f"{key} = {v!r} must be three integers 0-255 (B, G, R) or a colour name "
                f"{sorted(NAMED_BGR)}"
            )
    for key, allowed in (
        ("target", TARGETS),
        ("shape", SHAPES),
        ("texture", TEXTURES),
        ("clamp_style", CLAMP_STYLES),
        ("dot_color", DOT_COLORS),
        ("dot_layout", DOT_LAYOUTS),
    ):
        if getattr(s, key) not in allowed:
            out.append(f"{key} = {getattr(s, key)!r}: use one of {list(allowed)}")
    if s.target == "line" and not s.marker_line:
        out.append(
            "target = 'line' needs marker_line = true (a body without a drawn line is measured as "
            "target = 'body')"
        )
    if not 0 <= s.straight_base_fraction <= 0.8:
        out.append(f"straight_base_fraction = {s.straight_base_fraction!r} must be 0..0.8")
    bend = s.chamber_bend
    if (
        not 1 <= len(bend) <= 8
        or any(not (np.isfinite(b) and b >= 0) for b in bend)
        or not sum(bend) > 0
    ):
        out.append(f"chamber_bend = {bend!r} must be 1 to 8 weights >= 0, not all 0 (e.g. 0,1,1)")
    if not 0 <= s.dots <= 60:
        out.append(f"dots = {s.dots!r} must be 0..60")
    if s.body_width_mm > 60:
        out.append(
            f"body_width_mm = {s.body_width_mm} mm is wider than any actuator this renders (<= 60 "
            "mm)"
        )
    return out


#: (B) an opaque pigmented silicone actuator with retro-reflective motion-capture dots, clamped in
#: a black plate on a grey board; curvature concentrated towards the tip
_GREY_DOTS = SceneParams(
    background="textured",
    table_bgr=NAMED_BGR["grey"],
    texture_strength=3.0,
    lighting_gradient=0.25,
    vignetting=0.25,
    marker_line=False,
    target="body",
    shape="distal",
    straight_base_fraction=0.3,
    body_width_mm=20.0,
    body_bgr=NAMED_BGR["pink"],
    body_translucency=0.08,
    body_shading=0.7,
    specular=0.35,
    dots=8,
    dot_color="white",
    dot_diameter_mm=5.0,
    clamp_style="plate",
    tube=True,
    shadow=0.2,
    tilt_deg=1.0,
    noise_sigma=3.0,
    blur_sigma_px=0.8,
    jpeg_quality=88,
    rotation_jitter_deg=1.5,
    known_fixed_direction=True,
)


#: named scenes: ``clean`` (ideal photo), ``lab`` (a realistic bench photo), ``hard`` (worst case)
SCENE_PRESETS: dict[str, SceneParams] = {
    "clean": SceneParams(
        background="plain",
        lighting_gradient=0.0,
        vignetting=0.0,
        body_translucency=0.6,
        noise_sigma=0.0,
        blur_sigma_px=0.0,
        jpeg_quality=95,
        tilt_deg=0.0,
        rotation_jitter_deg=0.0,
    ),
    "lab": SceneParams(
        background="textured",
        texture_strength=6.0,
        lighting_gradient=0.15,
        vignetting=0.18,
        distractor_marks=5,
        distractor_color="grey",
        line_contrast=0.95,
        body_translucency=0.45,
        tilt_deg=1.0,
        noise_sigma=2.5,
        blur_sigma_px=0.8,
        jpeg_quality=90,
        rotation_jitter_deg=1.5,
    ),
    "hard": SceneParams(
        background="textured",
        texture_strength=12.0,
        lighting_gradient=0.35,
        vignetting=0.35,
        distractor_marks=12,
        distractor_color="line",
        line_width_px=4.0,
        line_contrast=0.85,
        body_translucency=0.3,
        tilt_deg=3.0,
        noise_sigma=6.0,
        blur_sigma_px=1.5,
        jpeg_quality=75,
        occluded_fraction=0.05,
        rotation_jitter_deg=3.0,
    ),
    # (A) a translucent fibre-wound segment of three chambers on a green chroma backdrop (cloth),
    # white printed clamp and its supply tube; the base chamber bends little
    "green_fibre": SceneParams(
        background="textured",
        table_bgr=NAMED_BGR["green"],
        texture_strength=5.0,
        lighting_gradient=0.2,
        vignetting=0.22,
        marker_line=False,
        target="body",
        shape="chambers",
        chamber_bend=(0.25, 1.0, 1.0),
        body_width_mm=16.0,
        body_bgr=NAMED_BGR["clear"],
        body_translucency=0.5,
        body_shading=0.6,
        texture="fibre",
        texture_pitch_mm=2.5,
        texture_contrast=0.55,
        texture_bgr=(55, 75, 95),
        specular=0.5,
        tip_cap_mm=6.0,
        tip_cap_bgr=(228, 230, 232),
        clamp_style="white",
        tube=True,
        shadow=0.25,
        tilt_deg=1.0,
        noise_sigma=2.5,
        blur_sigma_px=0.8,
        jpeg_quality=90,
        rotation_jitter_deg=1.5,
        background_photo=True,
    ),
    # (B) an opaque pigmented silicone actuator with motion-capture dots on grey (_GREY_DOTS)
    "grey_dots": _GREY_DOTS,
    # (B) the same rig with a translucent (clear) silicone actuator: the body over the plate is
    # faint
    "grey_dots_clear": dataclasses.replace(
        _GREY_DOTS,
        body_width_mm=18.0,
        body_bgr=NAMED_BGR["clear"],
        body_translucency=0.7,
        specular=0.5,
        shadow=0.15,
        background_photo=True,
    ),
    # (B) a translucent ribbed silicone actuator over a black backdrop, with a printed tip cap
    "dark_translucent": SceneParams(
        background="textured",
        table_bgr=NAMED_BGR["black"],
        texture_strength=2.0,
        lighting_gradient=0.15,
        vignetting=0.3,
        marker_line=False,
        target="body",
        body_width_mm=14.0,
        body_bgr=NAMED_BGR["white"],
        body_translucency=0.6,
        body_shading=0.8,
        texture="ribs",
        texture_pitch_mm=6.0,
        texture_contrast=0.4,
        specular=0.7,
        tip_cap_mm=8.0,
        tip_cap_bgr=(190, 192, 196),
        clamp_style="block",
        tube=True,
        shadow=0.0,
        tilt_deg=1.0,
        noise_sigma=3.5,
        blur_sigma_px=0.8,
        jpeg_quality=90,
        rotation_jitter_deg=1.5,
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
            raise UserInputError(
                f"scene preset {preset!r} is unknown; use one of {sorted(SCENE_PRESETS)}"
            )
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


def _items(text: str) -> list[str]:
    """``"0,1,1"``, ``"[0, 1, 1]"`` or ``"(0,1,1)"`` -> ``["0", "1", "1"]``."""
    return [x for x in text.strip().strip("[]()").replace(" ", "").split(",") if x != ""]


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
        if kind == "tuple[float, ...]":
            items = _items(value) if isinstance(value, str) else list(np.atleast_1d(value))
            return tuple(float(x) for x in items)
        if kind.startswith("tuple"):
            if isinstance(value, str) and value.strip().lower() in NAMED_BGR:
                return NAMED_BGR[value.strip().lower()]
            items = _items(value) if isinstance(value, str) else list(value)
            out = tuple(int(x) for x in items)
            if len(out) != 3:
                raise ValueError(value)
            return out
        return str(value).strip()
    except (TypeError, ValueError) as exc:
        hint = f" or a colour name {sorted(NAMED_BGR)}" if key in COLOR_KEYS else ""
        raise UserInputError(f"scene key {key} = {value!r} is not a valid {kind}{hint}") from exc
