"""Everything in a synthetic photo that does not move during a ramp: table, light, clamp, tube.

A :class:`Backdrop` is built once per ramp (it costs ~30 ms at 1280x960) and reused for every
photo of the ramp; it also holds the lit colour layers of the silicone, the ink and a glare spot,
and a pool of sensor noise, so that rendering one photo costs only the drawing of the actuator.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.synth.camera import Camera
from pipeline.synth.presets import LINE_INK_BGR, SceneParams

#: clamp block behind the fixed end (mm): length along the clamp axis and overhang each side
CLAMP_LENGTH_MM = 25.0
CLAMP_OVERHANG_MM = 5.0
TUBE_WIDTH_MM = 6.0
#: sealed end cap of silicone beyond the free end of the marked layer (mm)
END_CAP_MM = 4.0
#: sub-pixel bits used with every OpenCV drawing call (1/16 px)
SHIFT = 4
NOISE_PAD = 64

_GLARE_BGR = (250, 250, 250)


@dataclass(frozen=True)
class Backdrop:
    """The static part of a photo, ready to composite actuators on.

    Attributes
    ----------
    camera : Camera
        Placement of the world frame (the clamp) in the image.
    image : ndarray (H, W, 3) uint8
        Lit, blurred table with clamp, tube and distractor marks.
    body_layer, ink_layer, glare_layer : ndarray (H, W, 3) uint8
        Silicone, marker ink and glare colours under the same lighting.
    noise_pool : ndarray (H + 64, W + 64, 3) int16 or None
        Sensor noise; each photo adds a randomly offset window of it.
    """

    camera: Camera
    image: NDArray[np.uint8]
    body_layer: NDArray[np.uint8]
    ink_layer: NDArray[np.uint8]
    glare_layer: NDArray[np.uint8]
    noise_pool: NDArray[np.int16] | None


def clamp_outline_mm(body_width_mm: float) -> NDArray[np.float64]:
    """Corners of the clamp block in world mm (its front edge is the fixed end, x = 0)."""
    y0, y1 = -CLAMP_OVERHANG_MM, body_width_mm + CLAMP_OVERHANG_MM
    return np.array([[-CLAMP_LENGTH_MM, y0], [0.0, y0], [0.0, y1], [-CLAMP_LENGTH_MM, y1]])


def light_gain(scene: SceneParams, rng: np.random.Generator) -> NDArray[np.float32]:
    """Multiplicative light field: a linear gradient in a random direction times vignetting."""
    h, w = scene.height, scene.width
    y, x = np.mgrid[0:h, 0:w].astype(np.float32)
    cx, cy = (w - 1) / 2, (h - 1) / 2
    half_diag = float(np.hypot(cx, cy))
    a = rng.uniform(0, 2 * np.pi)
    gain = 1.0 + 0.5 * scene.lighting_gradient * ((x - cx) * np.cos(a) + (y - cy) * np.sin(a)) / half_diag
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


def _keepout_mask(scene: SceneParams, camera: Camera, keepout_mm: Sequence[NDArray[np.float64]], margin_mm: float) -> NDArray[np.uint8]:
    mask = np.zeros((scene.height, scene.width), np.uint8)
    thick = max(1, round(2 * margin_mm / scene.mm_per_px))
    for pts in keepout_mm:
        px = camera.to_px(pts)
        cv2.polylines(mask, [np.round(px * (1 << SHIFT)).astype(np.int32)], False, 255, thick, cv2.LINE_8, SHIFT)
    cv2.fillPoly(mask, [np.round(camera.to_px(clamp_outline_mm(scene.body_width_mm)) * (1 << SHIFT)).astype(np.int32)],
                 255, cv2.LINE_8, SHIFT)
    return mask


def _distractors(img: NDArray[np.float32], scene: SceneParams, keepout: NDArray[np.uint8], rng: np.random.Generator) -> None:
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
        cv2.polylines(mask, [np.round(pts * (1 << SHIFT)).astype(np.int32)], False, 255, thick, cv2.LINE_AA, SHIFT)
        x0, y0, bw, bh = cv2.boundingRect(mask)
        if bw == 0:
            continue
        a_roi = mask[y0:y0 + bh, x0:x0 + bw, None].astype(np.float32) * (opacity / 255.0)
        roi = img[y0:y0 + bh, x0:x0 + bw]
        roi += (colour - roi) * a_roi
        drawn += 1


def _draw_tube_and_clamp(img: NDArray[np.float32], scene: SceneParams, camera: Camera, rng: np.random.Generator) -> None:
    s = 1 << SHIFT
    bw = scene.body_width_mm
    if scene.tube:
        t = np.linspace(0, 700, 200)
        bend = rng.uniform(-1, 1) * 1e-3
        tube = np.column_stack([-CLAMP_LENGTH_MM - t, bw / 2 + bend * t**2])
        px = camera.to_px(tube)
        width = max(2, round(TUBE_WIDTH_MM / scene.mm_per_px))
        mask = np.zeros(img.shape[:2], np.uint8)
        cv2.polylines(mask, [np.round(px * s).astype(np.int32)], False, 255, width, cv2.LINE_AA, SHIFT)
        a = mask[..., None].astype(np.float32) * (0.55 / 255)
        img += (np.asarray((215, 222, 225), np.float32) - img) * a
        edge = np.zeros_like(mask)
        cv2.polylines(edge, [np.round(px * s).astype(np.int32)], False, 255, width + 2, cv2.LINE_AA, SHIFT)
        edge = cv2.subtract(edge, cv2.erode(mask, np.ones((3, 3), np.uint8)))
        img += (np.asarray((120, 125, 128), np.float32) - img) * (edge[..., None].astype(np.float32) * (0.35 / 255))
    if scene.clamp:
        outline = camera.to_px(clamp_outline_mm(bw))
        cv2.fillPoly(img, [np.round(outline * s).astype(np.int32)], (72, 74, 78), cv2.LINE_AA, SHIFT)
        inner = camera.to_px(clamp_outline_mm(bw) * 0.8 + np.array([-0.1 * CLAMP_LENGTH_MM, 0.1 * bw]))
        cv2.polylines(img, [np.round(inner * s).astype(np.int32)], True, (105, 108, 112), 2, cv2.LINE_AA, SHIFT)
        r = max(2, round(2.5 / scene.mm_per_px))
        for y in (0.1 * bw, 0.9 * bw):
            c = camera.to_px([[-CLAMP_LENGTH_MM / 2, y]])[0]
            cv2.circle(img, tuple(np.round(c * s).astype(int)), r * s, (150, 152, 155), -1, cv2.LINE_AA, SHIFT)
            cv2.circle(img, tuple(np.round(c * s).astype(int)), (r // 2) * s, (55, 56, 58), -1, cv2.LINE_AA, SHIFT)


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
    gain = light_gain(scene, rng) if scene.background != "plain" else np.ones((scene.height, scene.width), np.float32)
    albedo = _table(scene, rng)
    if scene.distractor_marks:
        keepout = _keepout_mask(scene, camera, keepout_mm, scene.body_width_mm + 8.0)
        _distractors(albedo, scene, keepout, rng)
    _draw_tube_and_clamp(albedo, scene, camera, rng)
    image = np.clip(albedo * gain[..., None], 0, 255).astype(np.uint8)
    if scene.blur_sigma_px > 0:
        image = cv2.GaussianBlur(image, (0, 0), scene.blur_sigma_px)
    pool = None
    if scene.noise_sigma > 0:
        shape = (scene.height + NOISE_PAD, scene.width + NOISE_PAD, 3)
        pool = np.rint(rng.standard_normal(shape, dtype=np.float32) * scene.noise_sigma).astype(np.int16)
    return Backdrop(
        camera=camera,
        image=image,
        body_layer=_lit(scene.body_bgr, gain),
        ink_layer=_lit(LINE_INK_BGR[scene.line_color], gain),
        glare_layer=_lit(_GLARE_BGR, gain),
        noise_pool=pool,
    )
