"""Everything in a synthetic photo that does not move during a ramp: table, light, clamp, tube.

A :class:`Backdrop` is built once per ramp (it costs ~30 ms at 1280x960) and reused for every
photo of the ramp; it also holds the lit colour layers of the silicone, the ink and a glare spot,
the light field, the seeded look of the body (:class:`pipeline.synth.body.BodyStyle`) and a pool
of sensor noise, so that rendering one photo costs only the drawing of the actuator.

Clamp styles (``SceneParams.clamp_style``): ``block`` (a dark clamp block with two screws),
``white`` (a white printed clamp) and ``plate`` (a large black plate whose front edge is the
clamp face, with a clamp bar across the actuator's base; it reaches the image border in a
typical view).  In every style the clamp face is the world line x = 0, where the fixed end is.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.synth.body import BodyStyle, make_body_style, shadow_of
from pipeline.synth.camera import Camera
from pipeline.synth.presets import LINE_INK_BGR, SceneParams

#: clamp block behind the fixed end (mm): length along the clamp axis and overhang each side
CLAMP_LENGTH_MM = 25.0
CLAMP_OVERHANG_MM = 5.0
#: the white printed clamp is a little larger
WHITE_CLAMP_LENGTH_MM = 30.0
WHITE_CLAMP_OVERHANG_MM = 6.0
#: black plate: depth behind the clamp face and half-width each side of the actuator (mm)
PLATE_DEPTH_MM = 170.0
PLATE_HALF_WIDTH_MM = 160.0
#: clamp bar on the plate across the actuator's base: length and overhang (mm)
PLATE_BAR_LENGTH_MM = 18.0
PLATE_BAR_OVERHANG_MM = 9.0
TUBE_WIDTH_MM = 6.0
#: sub-pixel bits used with every OpenCV drawing call (1/16 px)
SHIFT = 4
NOISE_PAD = 64

#: colour of a glare spot (BGR, before lighting)
GLARE_BGR = (250, 250, 250)
#: seed stream of the body's look (independent of the table's, so older scenes keep their bytes)
_STYLE_KEY = 7


def child_seed(seed: int | np.random.SeedSequence, *keys: int) -> np.random.SeedSequence:
    """A seed derived from ``seed`` and integer ``keys`` (pure: the same inputs give the same
    seed)."""
    if isinstance(seed, np.random.SeedSequence):
        return np.random.SeedSequence(seed.entropy, spawn_key=tuple(seed.spawn_key) + tuple(keys))
    return np.random.SeedSequence(int(seed), spawn_key=tuple(keys))


@dataclass(frozen=True)
class Backdrop:
    """The static part of a photo, ready to composite actuators on.

    Attributes
    ----------
    camera : Camera
        Placement of the world frame (the clamp) in the image.
    image : ndarray (H, W, 3) uint8
        Lit, blurred table with clamp, tube and distractor marks.
    noise_pool : ndarray (H + 64, W + 64, 3) int16 or None
        Sensor noise; each photo adds a randomly offset window of it.
    gain : ndarray (H, W) float32
        The light field (multiplies every colour: silicone, ink, glare, fibres, dots).
    style : BodyStyle
        Seeded look of the body (light side, fibre spacing, dot positions, shadow direction).
    """

    camera: Camera
    image: NDArray[np.uint8]
    noise_pool: NDArray[np.int16] | None
    gain: NDArray[np.float32]
    style: BodyStyle

    def lit(self, colour: ArrayLike, roi: tuple[int, int, int, int]) -> NDArray[np.uint8]:
        """A colour (BGR) under the scene's light over ``roi = (x0, y0, x1, y1)``."""
        x0, y0, x1, y1 = roi
        return _lit(colour, self.gain[y0:y1, x0:x1])


def clamp_outline_mm(body_width_mm: float, style: str = "block") -> NDArray[np.float64]:
    """Corners of the clamp (block, white clamp or plate) in world mm; its front edge is x = 0."""
    if style == "plate":
        x0, y0, y1 = (
            -PLATE_DEPTH_MM,
            body_width_mm / 2 - PLATE_HALF_WIDTH_MM,
            body_width_mm / 2 + PLATE_HALF_WIDTH_MM,
        )
    elif style == "white":
        x0, y0, y1 = (
            -WHITE_CLAMP_LENGTH_MM,
            -WHITE_CLAMP_OVERHANG_MM,
            body_width_mm + WHITE_CLAMP_OVERHANG_MM,
        )
    else:
        x0, y0, y1 = -CLAMP_LENGTH_MM, -CLAMP_OVERHANG_MM, body_width_mm + CLAMP_OVERHANG_MM
    return np.array([[x0, y0], [0.0, y0], [0.0, y1], [x0, y1]])


def light_gain(scene: SceneParams, rng: np.random.Generator) -> NDArray[np.float32]:
    """Multiplicative light field: a linear gradient in a random direction times vignetting."""
    h, w = scene.height, scene.width
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    half_diag = float(np.hypot(cx, cy))
    a = rng.uniform(0, 2 * np.pi)
    gain = (
        1.0
        + 0.5 * scene.lighting_gradient * ((x - cx) * np.cos(a) + (y - cy) * np.sin(a)) / half_diag
    )
    if scene.vignetting > 0:
        gain *= 1.0 - scene.vignetting * (((x - cx) ** 2 + (y - cy) ** 2) / half_diag**2)
    return gain.astype(np.float32)


def _table(scene: SceneParams, rng: np.random.Generator) -> NDArray[np.float32]:
    h, w = scene.height, scene.width
    table = np.empty((h, w, 3), np.float32)
    table[:] = np.asarray(scene.table_bgr, np.float32)
    if scene.background == "textured" and scene.texture_strength > 0:
        tex = np.zeros((h, w), np.float32)
        for cell, amp in ((48, 1.0), (12, 0.5), (3, 0.25)):
            small = rng.standard_normal((h // cell + 2, w // cell + 2)).astype(np.float32)
            tex += amp * cv2.resize(small, (w, h), interpolation=cv2.INTER_CUBIC)
        table += (scene.texture_strength / 1.2) * tex[..., None]
    return table


def _keepout_mask(
    scene: SceneParams, camera: Camera, keepout_mm: Sequence[NDArray[np.float64]], margin_mm: float
) -> NDArray[np.uint8]:
    mask = np.zeros((scene.height, scene.width), np.uint8)
    thick = max(1, round(2 * margin_mm / scene.mm_per_px))
    for pts in keepout_mm:
        px = camera.to_px(pts)
        cv2.polylines(
            mask,
            [np.round(px * (1 << SHIFT)).astype(np.int32)],
            False,
            255,
            thick,
            cv2.LINE_8,
            SHIFT,
        )
    cv2.fillPoly(
        mask,
        [
            np.round(
                camera.to_px(clamp_outline_mm(scene.body_width_mm, scene.clamp_style))
                * (1 << SHIFT)
            ).astype(np.int32)
        ],
        255,
        cv2.LINE_8,
        SHIFT,
    )
    return mask


def _distractors(
    img: NDArray[np.float32],
    scene: SceneParams,
    keepout: NDArray[np.uint8],
    rng: np.random.Generator,
) -> None:
    h, w = keepout.shape
    ink = np.asarray(LINE_INK_BGR[scene.line_color], np.float32)
    drawn = 0
    for _ in range(scene.distractor_marks * 30):
        if drawn >= scene.distractor_marks:
            break
        length_px = rng.uniform(8, 60) / scene.mm_per_px
        c = rng.uniform([0, 0], [w, h])
        a = rng.uniform(0, np.pi)
        bend = rng.uniform(-0.6, 0.6)
        t = np.linspace(-0.5, 0.5, 24)
        pts = c + np.column_stack([t * length_px, bend * length_px * (t**2 - 0.25)]) @ np.array(
            [[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        ij = np.round(pts).astype(int)
        inside = (ij[:, 0] >= 0) & (ij[:, 0] < w) & (ij[:, 1] >= 0) & (ij[:, 1] < h)
        if inside.any() and keepout[ij[inside, 1], ij[inside, 0]].any():
            continue
        if scene.distractor_color == "line" and drawn % 2 == 0:
            colour, opacity = ink, rng.uniform(0.7, 1.0)
        else:
            colour, opacity = np.full(3, rng.uniform(70, 140), np.float32), rng.uniform(0.3, 0.7)
        thick = max(1, round(rng.uniform(0.4, 1.6) / scene.mm_per_px))
        mask = np.zeros((h, w), np.uint8)
        cv2.polylines(
            mask,
            [np.round(pts * (1 << SHIFT)).astype(np.int32)],
            False,
            255,
            thick,
            cv2.LINE_AA,
            SHIFT,
        )
        x0, y0, bw, bh = cv2.boundingRect(mask)
        if bw == 0:
            continue
        a_roi = mask[y0:y0 + bh, x0:x0 + bw, None].astype(np.float32) * (opacity / 255.0)
        roi = img[y0:y0 + bh, x0:x0 + bw]
        roi += (colour - roi) * a_roi
        drawn += 1


def _poly(
    img: NDArray[np.float32], camera: Camera, pts_mm: ArrayLike, colour: tuple[float, float, float]
) -> None:
    px = np.round(camera.to_px(pts_mm) * (1 << SHIFT)).astype(np.int32)
    cv2.fillPoly(img, [px], colour, cv2.LINE_AA, SHIFT)


def _screw(img: NDArray[np.float32], camera: Camera, at_mm: tuple[float, float], radius_px: int,
           head: tuple[float, float, float], socket: tuple[float, float, float]) -> None:
    s = 1 << SHIFT
    c = tuple(np.round(camera.to_px([at_mm])[0] * s).astype(int))
    cv2.circle(img, c, radius_px * s, head, -1, cv2.LINE_AA, SHIFT)
    cv2.circle(img, c, max(1, radius_px // 2) * s, socket, -1, cv2.LINE_AA, SHIFT)


def _clamp_mask(
    scene: SceneParams, camera: Camera, tube_px: NDArray[np.float64] | None, tube_width: int
) -> NDArray[np.uint8]:
    mask = np.zeros((scene.height, scene.width), np.uint8)
    s = 1 << SHIFT
    if tube_px is not None:
        cv2.polylines(
            mask,
            [np.round(tube_px * s).astype(np.int32)],
            False,
            255,
            tube_width,
            cv2.LINE_AA,
            SHIFT,
        )
    if scene.clamp:
        outline = camera.to_px(clamp_outline_mm(scene.body_width_mm, scene.clamp_style))
        cv2.fillPoly(mask, [np.round(outline * s).astype(np.int32)], 255, cv2.LINE_AA, SHIFT)
    return mask


def _draw_tube_and_clamp(
    img: NDArray[np.float32],
    scene: SceneParams,
    camera: Camera,
    rng: np.random.Generator,
    style: BodyStyle | None = None,
) -> None:
    s = 1 << SHIFT
    bw = scene.body_width_mm
    px = None
    width = max(2, round(TUBE_WIDTH_MM / scene.mm_per_px))
    if scene.tube:
        t = np.linspace(0, 700, 200)
        bend = rng.uniform(-1, 1) * 1e-3
        tube = np.column_stack([-CLAMP_LENGTH_MM - t, bw / 2 + bend * t**2])
        px = camera.to_px(tube)
    if scene.shadow > 0 and style is not None and (px is not None or scene.clamp):
        cast = _clamp_mask(scene, camera, px, width).astype(np.float32) / 255.0
        img *= (1.0 - scene.shadow * shadow_of(cast, style, scene.mm_per_px))[..., None]
    if px is not None:
        mask: NDArray[np.uint8] = np.zeros(img.shape[:2], np.uint8)
        cv2.polylines(
            mask, [np.round(px * s).astype(np.int32)], False, 255, width, cv2.LINE_AA, SHIFT
        )
        edge = np.zeros_like(mask)
        cv2.polylines(
            edge, [np.round(px * s).astype(np.int32)], False, 255, width + 2, cv2.LINE_AA, SHIFT
        )
        edge = np.asarray(cv2.subtract(edge, cv2.erode(mask, np.ones((3, 3), np.uint8))), np.uint8)
        bx, by, bw_, bh = cv2.boundingRect(cv2.bitwise_or(mask, edge))  # only where the tube is
        if bw_ > 0:
            win, m, e = (
                img[by : by + bh, bx : bx + bw_],
                mask[by : by + bh, bx : bx + bw_],
                edge[by : by + bh, bx : bx + bw_],
            )
            win += (np.asarray((215, 222, 225), np.float32) - win) * (
                m[..., None].astype(np.float32) * (0.55 / 255)
            )
            win += (np.asarray((120, 125, 128), np.float32) - win) * (
                e[..., None].astype(np.float32) * (0.35 / 255)
            )
    if not scene.clamp:
        return
    outline_mm = clamp_outline_mm(bw, scene.clamp_style)
    r = max(2, round(2.5 / scene.mm_per_px))
    if scene.clamp_style == "block":
        outline = camera.to_px(outline_mm)
        cv2.fillPoly(
            img, [np.round(outline * s).astype(np.int32)], (72, 74, 78), cv2.LINE_AA, SHIFT
        )
        inner = camera.to_px(outline_mm * 0.8 + np.array([-0.1 * CLAMP_LENGTH_MM, 0.1 * bw]))
        cv2.polylines(
            img,
            [np.round(inner * s).astype(np.int32)],
            True,
            (105, 108, 112),
            2,
            cv2.LINE_AA,
            SHIFT,
        )
        for y in (0.1 * bw, 0.9 * bw):
            _screw(img, camera, (-CLAMP_LENGTH_MM / 2, y), r, (150, 152, 155), (55, 56, 58))
    elif scene.clamp_style == "white":
        # a white printed clamp: a slightly darker rim (the chamfer), a lit top face, steel screws
        _poly(img, camera, outline_mm, (196, 199, 202))
        inset = 1.5  # mm
        x0, y0, y1 = outline_mm[0, 0], outline_mm[0, 1], outline_mm[2, 1]
        _poly(
            img,
            camera,
            [
                [x0 + inset, y0 + inset],
                [-inset, y0 + inset],
                [-inset, y1 - inset],
                [x0 + inset, y1 - inset],
            ],
            (228, 231, 233),
        )
        for y in (-0.5 * WHITE_CLAMP_OVERHANG_MM, bw + 0.5 * WHITE_CLAMP_OVERHANG_MM):
            _screw(
                img,
                camera,
                (-WHITE_CLAMP_LENGTH_MM / 2, y),
                max(2, round(2.0 / scene.mm_per_px)),
                (168, 172, 176),
                (70, 72, 75),
            )
    else:
        # a black anodised plate, lit unevenly, a bevel along its front edge and a clamp bar
        h, w = img.shape[:2]
        mask = np.zeros((h, w), np.uint8)
        cv2.fillPoly(
            mask, [np.round(camera.to_px(outline_mm) * s).astype(np.int32)], 255, cv2.LINE_AA, SHIFT
        )
        ang = rng.uniform(0, 2 * np.pi)
        bx, by, bw_, bh = cv2.boundingRect(mask)
        if bw_ > 0:
            a = mask[by:by + bh, bx:bx + bw_].astype(np.float32)[..., None] / 255.0
            yy, xx = np.mgrid[by:by + bh, bx:bx + bw_].astype(np.float32)
            sheen = 8.0 + 8.0 * ((xx / w) * np.cos(ang) + (yy / h) * np.sin(ang))
            win = img[by:by + bh, bx:bx + bw_]
            win *= 1 - a
            win += (np.array([29, 29, 32], np.float32)[None, None, :] + sheen[..., None]) * a
        bevel = camera.to_px([[0.0, outline_mm[1, 1]], [0.0, outline_mm[2, 1]]])
        cv2.polylines(img, [np.round(bevel * s).astype(np.int32)], False, (68, 69, 73),
                      max(1, round(0.8 / scene.mm_per_px)), cv2.LINE_AA, SHIFT)
        bar = np.array(
            [
                [-PLATE_BAR_LENGTH_MM, -PLATE_BAR_OVERHANG_MM],
                [0.0, -PLATE_BAR_OVERHANG_MM],
                [0.0, bw + PLATE_BAR_OVERHANG_MM],
                [-PLATE_BAR_LENGTH_MM, bw + PLATE_BAR_OVERHANG_MM],
            ]
        )
        _poly(img, camera, bar, (44, 44, 48))
        cv2.polylines(img, [np.round(camera.to_px(bar) * s).astype(np.int32)], True, (60, 61, 65),
                      max(1, round(0.5 / scene.mm_per_px)), cv2.LINE_AA, SHIFT)
        for y in (-0.5 * PLATE_BAR_OVERHANG_MM, bw + 0.5 * PLATE_BAR_OVERHANG_MM):
            _screw(
                img,
                camera,
                (-PLATE_BAR_LENGTH_MM / 2, y),
                max(2, round(2.2 / scene.mm_per_px)),
                (92, 94, 98),
                (35, 35, 38),
            )


def _lit(colour: ArrayLike, gain: NDArray[np.float32]) -> NDArray[np.uint8]:
    c = np.asarray(colour, np.float32)
    return np.clip(gain[..., None] * c, 0, 255).astype(np.uint8)


def make_backdrop(
    scene: SceneParams,
    camera: Camera,
    *,
    seed: int | np.random.SeedSequence,
    keepout_mm: Sequence[NDArray[np.float64]] = (),
) -> Backdrop:
    """Build the static part of the photos of one ramp.

    Parameters
    ----------
    scene : SceneParams
    camera : Camera
        Placement of the clamp (world origin) in the image.
    seed : int or numpy.random.SeedSequence
        Seeds the table texture, light direction, distractors, tube bend and noise pool.
    keepout_mm : sequence of (n, 2) arrays
        World polylines the actuator can occupy (distractor marks keep clear of them by the
        body width plus 8 mm).

    Returns
    -------
    Backdrop
    """
    rng = np.random.default_rng(seed)
    style = make_body_style(scene, np.random.default_rng(child_seed(seed, _STYLE_KEY)))
    gain = (
        light_gain(scene, rng)
        if scene.background != "plain"
        else np.ones((scene.height, scene.width), np.float32)
    )
    albedo = _table(scene, rng)
    if scene.distractor_marks:
        keepout = _keepout_mask(scene, camera, keepout_mm, scene.body_width_mm + 8.0)
        _distractors(albedo, scene, keepout, rng)
    _draw_tube_and_clamp(albedo, scene, camera, rng, style)
    image = np.clip(albedo * gain[..., None], 0, 255).astype(np.uint8)
    if scene.blur_sigma_px > 0:
        image = cv2.GaussianBlur(image, (0, 0), scene.blur_sigma_px)
    pool = None
    if scene.noise_sigma > 0:
        shape = (scene.height + NOISE_PAD, scene.width + NOISE_PAD, 3)
        pool = np.rint(rng.standard_normal(shape, dtype=np.float32) * scene.noise_sigma).astype(
            np.int16
        )
    return Backdrop(camera=camera, image=image, noise_pool=pool, gain=gain, style=style)
