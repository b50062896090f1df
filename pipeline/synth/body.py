"""The look of an actuator body without a drawn line: a rounded, textured, translucent tube.

The body is the band between the inextensible layer (offset 0) and offset ``body_width_mm`` on its
left (the side a ccw turn bends towards), closed at the free end by a sealed straight end and,
optionally, a rigid tip cap.  Its *centre line* -- offset ``body_width_mm / 2``, midway between the
two long edges -- is parallel to the layer, so it turns through the same total angle psi (tip
tangent minus base tangent); that curve mapped through the camera is the truth of a
``target: body`` photo.  Everything drawn on the body is placed in body coordinates so the outline
stays exact:

- ``s``: arc length along the body (mm, 0 at the clamp face), ``v``: position across it, -1 on the
  layer's edge, +1 on the far edge (per pixel, from the nearest centre-line sample and its local
  frame);
- relief (``body_shading``): a tube lit from a seeded side, thinner (more translucent) towards the
  edges, with refraction rims on both edges;
- ``texture``: ``fibre`` (two helices of thin strands, ``s -/+ pitch * asin(v) / 2 pi`` constant,
  irregular spacing and strength seeded) or ``ribs`` (grooves across the body; the edges bulge a
  little between grooves, by the same amount on both sides, so the centre line does not move);
- chamber joints (``len(chamber_bend) > 1``): a dark, slightly narrower band between chambers
  (symmetric too);
- ``specular``: broken highlight streaks along the body;
- ``dots``: motion-capture dots at seeded arc positions, fixed on the body for a whole ramp;
- ``tip_cap_mm``: a rigid block at the free end, a little wider than the body, straight (it adds
  no turning).

A :class:`BodyStyle` holds the seeded choices and is built once per ramp (with the backdrop), so
the dots and fibres of one actuator stay where they are from photo to photo.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import NDArray

from pipeline.synth.presets import SceneParams

#: width of a fibre strand (Gaussian sigma, mm) and of a refraction rim (mm)
STRAND_SIGMA_MM = 0.16
RIM_MM = 0.55
#: ribs: edge bulge between grooves, as a fraction of the body width (each side)
RIB_BULGE = 0.05
#: chamber joints: half-length of the joint band (mm) and waist (fraction of the width, each side)
JOINT_MM = 1.6
JOINT_WAIST = 0.06
#: tip cap overhang beyond each long edge (fraction of the width, plus 0.5 mm)
CAP_OVERHANG = 0.08
#: soft shadow: offset and blur (mm)
SHADOW_OFFSET_MM = 2.5
SHADOW_BLUR_MM = 2.0
#: dots: how far from the centre line the ``edges`` and ``outline`` layouts put them (fraction of
#: the half-width)
DOT_EDGE_V = {"edges": 0.55, "outline": 1.0}
_TABLE = 256


@dataclass(frozen=True)
class BodyStyle:
    """Seeded appearance of one actuator (fixed for a ramp).

    Attributes
    ----------
    light : tuple of float
        (sin, cos) of the light's direction across the body (the lit side of the tube).
    shadow_dir : tuple of float
        Unit screen direction (x, y) in which shadows fall.
    warp : ndarray (3, 3)
        Irregular spacing of strands/ribs: rows of (amplitude mm, wavelength mm, phase rad).
    strength : ndarray (256,)
        Per-strand / per-rib strength factors.
    streak : ndarray (4, 3)
        Modulation of the highlight along the body: (amplitude, wavelength mm, phase).
    dot_u, dot_v : ndarray
        Arc fraction and across-position of each dot.
    """

    light: tuple[float, float]
    shadow_dir: tuple[float, float]
    warp: NDArray[np.float64]
    strength: NDArray[np.float64]
    streak: NDArray[np.float64]
    dot_u: NDArray[np.float64]
    dot_v: NDArray[np.float64]


def make_body_style(scene: SceneParams, rng: np.random.Generator) -> BodyStyle:
    """Draw the seeded appearance of a body (see :class:`BodyStyle`)."""
    side = rng.uniform(-0.55, 0.55)
    a = rng.uniform(0, 2 * np.pi)
    pitch = scene.texture_pitch_mm
    warp = np.column_stack(
        [
            rng.uniform(0.08, 0.2, 3) * pitch,
            rng.uniform(4, 14, 3) * pitch,
            rng.uniform(0, 2 * np.pi, 3),
        ]
    )
    strength = np.clip(rng.normal(1.0, 0.22, _TABLE), 0.4, 1.5)
    streak = np.column_stack(
        [rng.uniform(0.15, 0.35, 4), rng.uniform(25, 120, 4), rng.uniform(0, 2 * np.pi, 4)]
    )
    n = scene.dots
    if n:
        u = np.linspace(0.12, 0.94, n) + rng.uniform(-0.25, 0.25, n) * (0.82 / max(n, 1))
        v = rng.uniform(-0.08, 0.08, n)
        if scene.dot_layout in DOT_EDGE_V:
            v += DOT_EDGE_V[scene.dot_layout] * np.where(np.arange(n) % 2 == 0, -1.0, 1.0)
    else:
        u = v = np.zeros(0)
    return BodyStyle(
        light=(float(np.sin(side)), float(np.cos(side))),
        shadow_dir=(float(np.cos(a)), float(np.sin(a))),
        warp=warp,
        strength=strength,
        streak=streak,
        dot_u=np.sort(u),
        dot_v=v,
    )


def relief_mm(
    s_mm: NDArray[np.float64], scene: SceneParams, style: BodyStyle, l0_mm: float
) -> NDArray[np.float64]:
    """Outward displacement of both long edges at arc length ``s_mm`` (ribs bulge, joints pinch)."""
    d = np.zeros_like(s_mm)
    w = scene.body_width_mm
    if scene.texture == "ribs":
        d += RIB_BULGE * w * (1.0 - _groove(s_mm, scene, style))
    for s_k in _joints(scene, l0_mm):
        d -= JOINT_WAIST * w * np.exp(-0.5 * ((s_mm - s_k) / JOINT_MM) ** 2)
    return d


def _joints(scene: SceneParams, l0_mm: float) -> NDArray[np.float64]:
    k = len(scene.chamber_bend)
    return np.arange(1, k) * l0_mm / k


def _warped(s_mm: NDArray[np.float64], style: BodyStyle) -> NDArray[np.float64]:
    out = s_mm.copy()
    for amp, lam, ph in style.warp:
        out += amp * np.sin(2 * np.pi * s_mm / lam + ph)
    return out


def _groove(s_mm: NDArray[np.float64], scene: SceneParams, style: BodyStyle) -> NDArray[np.float64]:
    """1 in the middle of a rib groove, 0 on the crests."""
    phase = _warped(s_mm, style) / scene.texture_pitch_mm
    k = np.floor(phase + 0.5).astype(np.int64) % _TABLE
    return (0.5 + 0.5 * np.cos(2 * np.pi * phase)) ** 4 * np.minimum(style.strength[k], 1.2)


def _strands(
    s_mm: NDArray[np.float64],
    v: NDArray[np.float64],
    scene: SceneParams,
    style: BodyStyle,
    mm_per_px: float,
) -> NDArray[np.float64]:
    """Coverage (0-1) of the two fibre helices at body coordinates (anti-aliased to the pixel
    size)."""
    p = scene.texture_pitch_mm
    sw = _warped(s_mm, style)
    turn = p * np.arcsin(np.clip(v, -1, 1)) / (2 * np.pi)
    sigma = max(STRAND_SIGMA_MM, 0.45 * mm_per_px)
    amp = STRAND_SIGMA_MM / sigma
    out = np.zeros_like(s_mm)
    for sign, weight in ((-1.0, 1.0), (1.0, 0.8)):
        phase = (sw + sign * turn) / p
        k = np.floor(phase + 0.5)
        dist_mm = np.abs(phase - k) * p
        strand = np.exp(-0.5 * (dist_mm / sigma) ** 2) * style.strength[k.astype(np.int64) % _TABLE]
        out = np.maximum(out, weight * amp * strand)
    return np.clip(out, 0, 1)


def _streak(s_mm: NDArray[np.float64], style: BodyStyle) -> NDArray[np.float64]:
    m = np.full_like(s_mm, 0.6)
    for amp, lam, ph in style.streak:
        m += amp * np.sin(2 * np.pi * s_mm / lam + ph)
    return np.clip(m, 0, 1)


@dataclass(frozen=True)
class BodyFrame:
    """The body's axis sampled about 1 px apart on screen, with its local frame.

    Attributes
    ----------
    centre_px : ndarray (n, 2)
        Centre line (offset half the width), then the sealed straight end.
    inner_px, outer_px : ndarray (n, 2)
        The two long edges (relief included): layer side, far side.
    s_mm : ndarray (n,)
        Arc length of each sample from the clamp face.
    """

    centre_px: NDArray[np.float64]
    inner_px: NDArray[np.float64]
    outer_px: NDArray[np.float64]
    s_mm: NDArray[np.float64]


def nearest_sample(
    frame: BodyFrame,
    ys: NDArray[np.intp],
    xs: NDArray[np.intp],
    shape: tuple[int, int],
    offset: NDArray[np.float64],
) -> NDArray[np.intp]:
    """Index of the centre-line sample nearest to each pixel ``(ys, xs)`` of a region.

    One labelled distance transform of the region (each sample's pixel a seed), so the cost is
    that of the region, not of the number of pixels times samples.
    """
    seeds = np.ones(shape, np.uint8)
    ij = np.round(frame.centre_px - offset).astype(np.intp)
    inside = (ij[:, 0] >= 0) & (ij[:, 0] < shape[1]) & (ij[:, 1] >= 0) & (ij[:, 1] < shape[0])
    k = np.flatnonzero(inside)
    if len(k) == 0:
        return np.zeros(len(ys), np.intp)
    seeds[ij[k, 1], ij[k, 0]] = 0
    _, labels = cv2.distanceTransformWithLabels(
        seeds, cv2.DIST_L2, 5, labelType=cv2.DIST_LABEL_PIXEL
    )
    lut = np.zeros(int(labels.max()) + 1, np.intp)
    lut[labels[ij[k, 1], ij[k, 0]]] = k
    return lut[labels[ys, xs]]


def body_coordinates(
    frame: BodyFrame, pixels: NDArray[np.float64], nearest: NDArray[np.intp]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Body coordinates (``s`` in mm, ``v`` in -1..1) of image points inside the body.

    Each point is projected on the local frame of its nearest centre-line sample ``nearest``
    (:func:`nearest_sample`): ``s`` from the tangent, ``v`` from the direction and distance
    between the two edges there.
    """
    c = frame.centre_px
    i = nearest
    t = np.gradient(c, axis=0)
    t /= np.maximum(np.hypot(t[:, 0], t[:, 1]), 1e-12)[:, None]
    across = frame.outer_px - frame.inner_px
    half = np.maximum(np.hypot(across[:, 0], across[:, 1]) / 2, 1e-9)
    n = across / (2 * half[:, None])
    ds = np.gradient(frame.s_mm)
    dpx = np.maximum(np.hypot(*np.gradient(c, axis=0).T), 1e-12)
    d = pixels - c[i]
    s = frame.s_mm[i] + (d * t[i]).sum(axis=1) * (ds / dpx)[i]
    v = (d * n[i]).sum(axis=1) / half[i]
    return s, v


def paint_body(
    scene: SceneParams,
    style: BodyStyle,
    frame: BodyFrame,
    coverage: NDArray[np.float32],
    gain: NDArray[np.float32],
    offset: NDArray[np.float64],
    l0_mm: float,
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Premultiplied colour and opacity of the body (no cap, dots or ink) over a region.

    Parameters
    ----------
    scene, style
        Appearance knobs and their seeded choices.
    frame : BodyFrame
        The body's axis in image pixels.
    coverage : ndarray (h, w) float32
        Anti-aliased area of the body outline in each pixel of the region (0-1).
    gain : ndarray (h, w) float32
        The scene's light field over the region.
    offset : ndarray (2,)
        Image position of the region's top-left pixel.
    l0_mm : float
        Length of the layer (chamber joints).

    Returns
    -------
    premultiplied : ndarray (h, w, 3) float32
        Colour times opacity (BGR, 0-255 scale).
    alpha : ndarray (h, w) float32
        Opacity.
    """
    h, w = coverage.shape
    ys, xs = np.nonzero(coverage > 0)
    prem = np.zeros((h, w, 3), np.float32)
    alpha = np.zeros((h, w), np.float32)
    if len(ys) == 0:
        return prem, alpha
    pts = np.column_stack([xs, ys]).astype(np.float64) + offset
    s, v = body_coordinates(frame, pts, nearest_sample(frame, ys, xs, (h, w), offset))
    v = np.clip(v, -1.0, 1.0)
    sh = scene.body_shading
    depth = np.sqrt(1.0 - v * v)
    lam = np.clip(v * style.light[0] + depth * style.light[1], 0, 1)
    bright = (1 - sh) + sh * (0.45 + 0.7 * lam)
    a0 = 1.0 - scene.body_translucency
    a = a0 * (1.0 - 0.45 * sh * (1.0 - depth))
    half_mm = scene.body_width_mm / 2
    groove = np.zeros_like(s)
    if scene.texture == "ribs":
        groove = _groove(s, scene, style) * scene.texture_contrast
        bright *= 1.0 - 0.8 * groove
        a = a + (1 - a) * 0.5 * groove
    joint = np.zeros_like(s)
    for s_k in _joints(scene, l0_mm):
        joint = np.maximum(joint, np.exp(-0.5 * ((s - s_k) / JOINT_MM) ** 2))
    bright *= 1.0 - 0.45 * joint
    a = a + (1 - a) * 0.6 * joint
    g = gain[ys, xs][:, None]
    colour = np.asarray(scene.body_bgr, np.float64)[None, :] * g * bright[:, None]
    # refraction rims on both long edges: darker, denser
    rim = np.exp(-(((1.0 - np.abs(v)) * half_mm / RIM_MM) ** 2)) * min(1.0, 0.25 + sh)
    rim_a = min(1.0, a0 + 0.45)
    pm = colour * a[:, None]
    pm = 0.55 * colour * (rim * rim_a)[:, None] + pm * (1 - rim)[:, None]
    a = rim * rim_a + a * (1 - rim)
    if scene.texture == "fibre":
        f = _strands(s, v, scene, style, scene.mm_per_px) * scene.texture_contrast
        fc = (
            np.asarray(scene.texture_bgr, np.float64)[None, :] * g * (0.75 + 0.25 * bright[:, None])
        )
        pm = fc * f[:, None] + pm * (1 - f)[:, None]
        a = f + a * (1 - f)
    if scene.specular > 0:
        v_h = 0.55 * style.light[0] - 0.2
        spot = (
            np.exp(-0.5 * ((v - v_h) / 0.13) ** 2)
            * _streak(s, style)
            * (1 - 0.8 * groove)
            * (1 - joint)
        )
        pm = pm + (scene.specular * 235.0 * spot * g[:, 0])[:, None]
    cov = coverage[ys, xs].astype(np.float64)
    prem[ys, xs] = (pm * cov[:, None]).astype(np.float32)
    alpha[ys, xs] = (a * cov).astype(np.float32)
    return prem, alpha


def over(prem: NDArray[np.float32], alpha: NDArray[np.float32], colour: NDArray[np.float32],
         layer_alpha: NDArray[np.float32]) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Put a layer (straight colour ``colour``, opacity ``layer_alpha``) over premultiplied
    ``prem``."""
    la = layer_alpha[..., None]
    return colour * la + prem * (1 - la), layer_alpha + alpha * (1 - layer_alpha)


def paint_cap(
    scene: SceneParams,
    style: BodyStyle,
    corners_px: NDArray[np.float64],
    coverage: NDArray[np.float32],
    gain: NDArray[np.float32],
    offset: NDArray[np.float64],
) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
    """Straight colour and opacity of the tip cap (a shaded opaque block) over the region.

    ``corners_px`` are the cap's corners: inner-near, inner-far, outer-far, outer-near.
    """
    h, w = coverage.shape
    colour = np.zeros((h, w, 3), np.float32)
    ys, xs = np.nonzero(coverage > 0)
    if len(ys):
        inner = (corners_px[0] + corners_px[1]) / 2
        outer = (corners_px[2] + corners_px[3]) / 2
        mid, across = (inner + outer) / 2, outer - inner
        half = np.hypot(*across) / 2
        pts = np.column_stack([xs, ys]) + offset
        v = np.clip(((pts - mid) @ (across / (2 * half))) / half, -1, 1)
        lam = np.clip(v * style.light[0] + np.sqrt(1 - v * v) * style.light[1], 0, 1)
        bright = 0.55 + 0.5 * lam
        colour[ys, xs] = (
            np.asarray(scene.tip_cap_bgr, np.float64)[None, :] * (gain[ys, xs] * bright)[:, None]
        ).astype(np.float32)
    return colour, coverage


def paint_dots(
    scene: SceneParams,
    centres_px: NDArray[np.float64],
    radius_px: float,
    shape: tuple[int, int],
    offset: NDArray[np.float64],
    gain: NDArray[np.float32],
    shift_bits: int,
) -> tuple[NDArray[np.float32], NDArray[np.float32], NDArray[np.float32]]:
    """Colour and opacity of the dots (and, for raised white markers, their dark ring).

    Returns
    -------
    colour : ndarray (h, w, 3) float32
    alpha : ndarray (h, w) float32
    ring : ndarray (h, w) float32
        Opacity of a thin dark ring around raised (``white``) markers (drawn first).
    """
    h, w = shape
    f = 1 << shift_bits
    disc = np.zeros((h, w), np.uint8)
    ring = np.zeros((h, w), np.uint8)
    r = max(radius_px, 0.75)
    for c in centres_px:
        cc = tuple(int(x) for x in np.round((c - offset) * f))
        if scene.dot_color == "white":
            cv2.circle(
                ring, cc, int(round((r + max(0.6, 0.12 * r)) * f)), 255, -1, cv2.LINE_AA, shift_bits  # noqa: RUF046 (numpy scalar)
            )
        cv2.circle(disc, cc, int(round(r * f)), 255, -1, cv2.LINE_AA, shift_bits)  # noqa: RUF046 (numpy scalar)
    a = disc.astype(np.float32) / 255.0
    colour = np.zeros((h, w, 3), np.float32)
    if scene.dot_color == "white":
        base = np.array([242.0, 244.0, 245.0], np.float32)
    else:
        base = np.array([30.0, 29.0, 32.0], np.float32)
    colour[:] = base
    colour *= gain[..., None]
    return colour, a, ring.astype(np.float32) / 255.0 * 0.7


def shadow_of(
    alpha: NDArray[np.float32], style: BodyStyle, mm_per_px: float
) -> NDArray[np.float32]:
    """Soft shadow (0-1) cast by an opacity mask: shifted along ``style.shadow_dir`` and blurred.

    The blur is wide, so it is done on a copy reduced to about 3 px per blur sigma and enlarged
    back.
    """
    sigma = SHADOW_BLUR_MM / mm_per_px
    f = max(1.0, sigma / 3.0)
    h, w = alpha.shape
    small = np.minimum(alpha * 2.0, 1.0)
    if f > 1.0:
        small = cv2.resize(
            small, (max(1, round(w / f)), max(1, round(h / f))), interpolation=cv2.INTER_AREA
        )
    sh, sw = small.shape
    fx, fy = sw / w, sh / h
    d = SHADOW_OFFSET_MM / mm_per_px
    m = np.array(
        [[1, 0, style.shadow_dir[0] * d * fx], [0, 1, style.shadow_dir[1] * d * fy]], np.float32
    )
    moved = cv2.warpAffine(small, m, (sw, sh), flags=cv2.INTER_LINEAR)
    out = cv2.GaussianBlur(moved, (0, 0), sigma * fx)
    if f > 1.0:
        out = cv2.resize(out, (w, h), interpolation=cv2.INTER_LINEAR)
    return np.asarray(out, np.float32)
