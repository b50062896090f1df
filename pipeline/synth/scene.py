"""Render one synthetic top-view photo of an actuator with its exact centreline.

The marker line is filled as the exact polygon ``centreline +- width/2`` at 4x supersampling and
area-averaged, so the centre of the drawn line is the centreline to within ~0.01 px; the
returned ``centreline_px`` is the dense exact curve mapped through the same camera.

Scenes with ``target: body`` (no drawn line needed) take as truth the body's own centre line,
midway between its two long edges (the layer offset by half the body width): parallel to the
layer, it turns through the same total angle psi in the world; ``psi_image_deg`` is its turning
as seen on screen through the camera (tip tangent minus base tangent, ccw positive), exactly as
for the line.  Bodies with relief, texture, highlights, dots or a tip cap are painted by
:mod:`pipeline.synth.body`; the plain flat band of the line scenes keeps its old pixels.

Examples
--------
>>> from pipeline.synth import render_actuator, scene_from
>>> r = render_actuator(120.0, 195.0, scene_from("clean", width=320, height=240), seed=1)
>>> r.image.shape, r.centreline_px.shape[1]
((240, 320, 3), 2)
>>> abs(r.psi_image_deg - 120.0) < 0.05
True
>>> b = render_actuator(120.0, 195.0, scene_from("green_fibre", width=320, height=240), seed=1)
>>> b.target, abs(b.psi_image_deg - 120.0) < 0.6     # 1 deg of camera tilt shows a little
('body', True)
"""

from __future__ import annotations

import dataclasses
import functools
import itertools
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.synth.backdrop import (
    GLARE_BGR,
    NOISE_PAD,
    SHIFT,
    Backdrop,
    child_seed,
    clamp_outline_mm,
    make_backdrop,
)
from pipeline.synth.body import (
    CAP_OVERHANG,
    RIB_BULGE,
    BodyFrame,
    over,
    paint_body,
    paint_cap,
    paint_dots,
    relief_mm,
    shadow_of,
)
from pipeline.synth.camera import Camera, make_camera
from pipeline.synth.centreline import DEFAULT_N, actuator_centreline_mm, turning_angle_deg
from pipeline.synth.presets import LINE_INK_BGR, SEALED_END_MM, SceneParams

#: supersampling factor of the marker-line mask
LINE_SUPERSAMPLING = 4
#: how far beyond the body a soft shadow reaches (mm)
SHADOW_REACH_MM = 10.0
_GLARE_OPACITY = 0.93
#: a body whose far edge would come closer than this fraction of the radius of curvature to the
#: centre of curvature is refused (its outline would fold over itself)
FOLD_LIMIT = 0.92

__all__ = [
    "RenderedImage",
    "child_seed",
    "encode_jpeg",
    "render_actuator",
    "render_background",
    "render_curve",
    "world_extent_mm",
]


def encode_jpeg(image: NDArray[np.uint8], quality: int) -> bytes:
    """``image`` encoded as JPEG at ``quality`` (deterministic bytes)."""
    ok, buf = cv2.imencode(".jpg", image, [cv2.IMWRITE_JPEG_QUALITY, int(quality)])
    if not ok:  # pragma: no cover - OpenCV always encodes a valid uint8 image
        raise RuntimeError("JPEG encoding failed")
    return buf.tobytes()


@dataclass(frozen=True)
class RenderedImage:
    """One rendered photo and its ground truth.

    Attributes
    ----------
    image : ndarray (H, W, 3) uint8
        BGR image before JPEG compression.
    centreline_px : ndarray (N, 2) float
        Exact centre line of the target (the marker for ``target: line``, the body's centre
        line for ``target: body``), fixed end first, image coordinates (x right, y down).
    fixed_end_px : tuple of float
        Where the fixed end of that centre line is in the image (at the clamp face).
    psi_image_deg : float
        Turning angle of ``centreline_px`` as seen on screen (ccw positive): psi itself up to the
        perspective of a tilted camera.
    line_in_frame : bool
        The whole of ``centreline_px`` lies inside the image.
    jpeg_quality : int
        Quality used by :attr:`jpeg_bytes`.
    target : str
        ``line`` or ``body`` (what ``centreline_px`` is).
    layer_px : ndarray (N, 2) float or None
        The marked inextensible layer (where a marker line is, or would be, drawn).
    fixed_direction_deg : float
        On-screen direction in which ``centreline_px`` leaves the clamp (deg, ccw from +x).
    dots_px : ndarray (k, 2) float
        Centres of the motion-capture dots (empty without dots).
    """

    image: NDArray[np.uint8]
    centreline_px: NDArray[np.float64]
    fixed_end_px: tuple[float, float]
    psi_image_deg: float
    line_in_frame: bool
    jpeg_quality: int = 92
    target: str = "line"
    layer_px: NDArray[np.float64] | None = None
    fixed_direction_deg: float = float("nan")
    dots_px: NDArray[np.float64] = dataclasses.field(default_factory=lambda: np.zeros((0, 2)))

    @functools.cached_property
    def jpeg_bytes(self) -> bytes:
        """The image encoded as JPEG with the scene's quality (deterministic)."""
        return encode_jpeg(self.image, self.jpeg_quality)


def _normals(points: NDArray[np.float64]) -> NDArray[np.float64]:
    t = np.gradient(points, axis=0)
    t /= np.maximum(np.hypot(t[:, 0], t[:, 1]), 1e-12)[:, None]
    return np.column_stack([-t[:, 1], t[:, 0]])


def _decimate(points_px: NDArray[np.float64], spacing_px: float = 1.0) -> NDArray[np.intp]:
    length = float(np.hypot(*np.diff(points_px, axis=0).T).sum())
    step = max(1, int(len(points_px) * spacing_px / max(length, 1e-9)))
    idx = np.arange(0, len(points_px), step)
    if idx[-1] != len(points_px) - 1:
        idx = np.append(idx, len(points_px) - 1)
    return idx


def _chunks(points: NDArray[np.float64], max_turn_deg: float = 90.0) -> list[slice]:
    """Overlapping index ranges each turning less than ``max_turn_deg`` (no self-overlap)."""
    d = np.diff(points, axis=0)
    ang = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    bins = np.floor((ang - ang[0]) / np.radians(max_turn_deg)).astype(int)
    starts = np.flatnonzero(np.diff(bins)) + 1
    edges = [0, *starts.tolist(), len(points) - 1]
    return [
        slice(max(a - 1, 0), min(b + 2, len(points))) for a, b in itertools.pairwise(edges) if b > a
    ]


def _band_polygons(
    inner: NDArray[np.float64], outer: NDArray[np.float64]
) -> list[NDArray[np.float64]]:
    return [np.vstack([inner[c], outer[c][::-1]]) for c in _chunks((inner + outer) / 2)]


def _fill(
    mask: NDArray[np.uint8],
    polys: list[NDArray[np.float64]],
    offset: NDArray[np.float64],
    factor: int = 1,
) -> None:
    scaled = [
        np.round(((p - offset) * factor + (factor - 1) / 2) * (1 << SHIFT)).astype(np.int32)
        for p in polys
    ]
    for poly in scaled:
        cv2.fillPoly(mask, [poly], 255, cv2.LINE_AA, SHIFT)


def _roi(
    polys: list[NDArray[np.float64]], margin: float, width: int, height: int
) -> tuple[int, int, int, int] | None:
    allp = np.vstack(polys)
    x0 = max(int(np.floor(allp[:, 0].min() - margin)), 0)
    y0 = max(int(np.floor(allp[:, 1].min() - margin)), 0)
    x1 = min(int(np.ceil(allp[:, 0].max() + margin)) + 1, width)
    y1 = min(int(np.ceil(allp[:, 1].max() + margin)) + 1, height)
    if x1 <= x0 or y1 <= y0:
        return None
    return x0, y0, x1, y1


def world_extent_mm(
    points_mm: NDArray[np.float64],
    body_width_mm: float,
    tip_mm: float = 0.0,
    sealed_mm: float = SEALED_END_MM,
) -> NDArray[np.float64]:
    """World points bounding the actuator (line, body, its end and tip cap, clamp block) for
    framing.

    A clamp plate is left out: it is meant to reach the border.
    """
    nrm = _normals(points_mm)
    body = points_mm + nrm * body_width_mm
    parts = [points_mm, body, clamp_outline_mm(body_width_mm)]
    if tip_mm > 0:
        t = points_mm[-1] - points_mm[-2]
        t = t / np.hypot(*t)
        reach, over_mm = sealed_mm + tip_mm, CAP_OVERHANG * body_width_mm + 0.5
        parts.append(
            np.array(
                [
                    points_mm[-1] + t * reach - nrm[-1] * over_mm,
                    body[-1] + t * reach + nrm[-1] * over_mm,
                ]
            )
        )
    return np.vstack(parts)


def _fixed_direction_deg(camera: Camera, curve_mm: NDArray[np.float64]) -> float:
    """On-screen direction (deg, ccw from +x) of the tangent of ``curve_mm`` at its first point."""
    t = -3 * curve_mm[0] + 4 * curve_mm[1] - curve_mm[2]  # one-sided, second order
    ends = camera.to_px([curve_mm[0], curve_mm[0] + 1e-3 * t / np.hypot(*t)])
    d = ends[1] - ends[0]
    return float(np.degrees(np.arctan2(-d[1], d[0])))


def check_body_fits(
    points_mm: NDArray[np.float64], scene: SceneParams, body_width_mm: float | None = None
) -> None:
    """Refuse a body whose outline would fold over itself on the inside of a bend.

    The body lies on the left of the layer (ccw side), so where the layer turns ccw with
    curvature ``kappa``, the far edge (``body_width_mm``, default the scene's, plus the ribs'
    bulge) must stay inside the radius ``1 / kappa``: ``kappa * width < FOLD_LIMIT``.

    Raises
    ------
    UserInputError
        Naming the curvature and the knobs that relieve it.
    """
    width = (scene.body_width_mm if body_width_mm is None else body_width_mm) * (
        1 + (RIB_BULGE if scene.texture == "ribs" else 0.0))
    d = np.diff(points_mm, axis=0)
    ds = np.hypot(d[:, 0], d[:, 1])
    k = np.diff(np.unwrap(np.arctan2(d[:, 1], d[:, 0]))) / np.maximum((ds[1:] + ds[:-1]) / 2, 1e-12)
    k_max = float(k.max()) if len(k) else 0.0
    if k_max * width >= FOLD_LIMIT:
        raise UserInputError(
            f"the body would fold over itself: curvature {k_max:.4f} /mm (radius {1 / k_max:.1f} "
            "mm) on the side of a "
            f"{width:g} mm wide body; use a smaller |psi|, a narrower body (body_width_mm), a "
            "longer l0 or a "
            "gentler shape (straight_base_fraction, chamber_bend)"
        )


def render_curve(
    points_mm: ArrayLike,
    scene: SceneParams,
    *,
    seed: int | np.random.SeedSequence,
    fixed_end_px: tuple[float, float] | None = None,
    rotation_deg: float = 0.0,
    backdrop: Backdrop | None = None,
    body_width_mm: float | None = None,
) -> RenderedImage:
    """Render a marker line along any centreline, with the silicone body, on the scene's table.

    Parameters
    ----------
    points_mm : array_like (N, 2)
        Dense centreline in world mm (y up), fixed end first; the clamp sits behind the first
        point along -x (so give curves that leave the origin along +x, as
        :func:`~pipeline.synth.centreline.centreline_mm` does).
    scene : SceneParams
    seed : int or numpy.random.SeedSequence
        Seeds everything random in this photo (same seed, same pixels).
    fixed_end_px : (x, y), optional
        Image position of the fixed end; by default the actuator is centred in the frame.
        Ignored when ``backdrop`` is given (its camera decides).
    rotation_deg : float
        Direction of the clamp axis on screen (deg, ccw from image +x).  Ignored with ``backdrop``.
    backdrop : Backdrop, optional
        Pre-built static scene (table, clamp, tube, noise) to reuse across the photos of a ramp.
    body_width_mm : float, optional
        Width of the silicone body beside the line (default ``scene.body_width_mm``).

    Returns
    -------
    RenderedImage
        With ``target: body`` its truth is the body's centre line, ``points_mm`` offset to the
        left by half the body width (the same total turning in the world).

    Raises
    ------
    UserInputError
        For bad points, or (``target: body``) a body that would fold over itself.
    """
    pts = np.asarray(points_mm, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3 or not np.isfinite(pts).all():
        raise UserInputError(
            "points_mm must be a finite (N, 2) array of centreline points with N >= 3"
        )
    body_w = scene.body_width_mm if body_width_mm is None else float(body_width_mm)
    if backdrop is None:
        camera = make_camera(scene, rotation_deg=rotation_deg, fixed_end_px=fixed_end_px,
                             extent_mm=world_extent_mm(pts, body_w, scene.tip_cap_mm,
                                                       scene.sealed_end_mm))
        backdrop = make_backdrop(scene, camera, seed=child_seed(seed, 0), keepout_mm=[pts])
    camera = backdrop.camera
    rng = np.random.default_rng(child_seed(seed, 1))
    return compose_photo(pts, scene, camera, backdrop, body_w, rng)


def compose_photo(
    pts_mm: NDArray[np.float64],
    scene: SceneParams,
    camera: Camera,
    backdrop: Backdrop,
    body_w: float,
    rng: np.random.Generator,
) -> RenderedImage:
    """One photo of the actuator whose layer is ``pts_mm`` over ``backdrop``, seen by ``camera``."""
    if scene.target == "body":
        check_body_fits(pts_mm, scene, body_w)
    if not scene.plain_body:
        return _compose_body(pts_mm, scene, camera, backdrop, body_w, rng)
    h, w = scene.height, scene.width
    centre_px = camera.to_px(pts_mm)
    idx = _decimate(centre_px)
    nrm_mm = _normals(pts_mm)
    tang_end = pts_mm[-1] - pts_mm[-2]
    tang_end /= np.hypot(*tang_end)
    body_outer_mm = pts_mm[idx] + nrm_mm[idx] * body_w
    sealed = scene.sealed_end_mm
    cap = [pts_mm[-1] + tang_end * sealed, body_outer_mm[-1] + tang_end * sealed]
    body_inner_px = camera.to_px(np.vstack([pts_mm[idx], cap[:1]]))
    body_outer_px = camera.to_px(np.vstack([body_outer_mm, cap[1:]]))
    line_c = centre_px[idx]
    line_n = _normals(centre_px)[idx]
    half = scene.line_width_px / 2
    line_polys = _band_polygons(line_c - line_n * half, line_c + line_n * half)
    body_polys = _band_polygons(body_inner_px, body_outer_px)
    blur = scene.blur_sigma_px
    roi = _roi(body_polys + line_polys, 3 * blur + 4, w, h)
    image = backdrop.image.copy()
    if roi is not None:
        x0, y0, x1, y1 = roi
        off = np.array([x0, y0], float)
        shape = (y1 - y0, x1 - x0)
        body = np.zeros(shape, np.uint8)
        _fill(body, body_polys, off)
        opacity = 1.0 - scene.body_translucency
        a_body = body.astype(np.float32) * (opacity / 255.0)
        edge = np.zeros(shape, np.uint8)
        cv2.polylines(
            edge,
            [np.round((body_outer_px - off) * (1 << SHIFT)).astype(np.int32)],
            False,
            255,
            max(1, round(0.6 / scene.mm_per_px)),
            cv2.LINE_AA,
            SHIFT,
        )
        a_body = np.maximum(a_body, edge.astype(np.float32) * (min(1.0, opacity + 0.3) / 255.0))
        f = LINE_SUPERSAMPLING
        big = np.zeros((shape[0] * f, shape[1] * f), np.uint8)
        _fill(big, line_polys, off, f)
        ink = cv2.resize(big, (shape[1], shape[0]), interpolation=cv2.INTER_AREA)
        a_ink = ink.astype(np.float32) * (
            (scene.line_contrast if scene.marker_line else 0.0) / 255.0
        )
        a_glare = _glare(centre_px, scene, rng, shape, off)
        if blur > 0:
            a_body = np.asarray(cv2.GaussianBlur(a_body, (0, 0), blur), np.float32)
            a_ink = np.asarray(cv2.GaussianBlur(a_ink, (0, 0), blur), np.float32)
        out = image[y0:y1, x0:x1]
        for colour, alpha in (
            (scene.body_bgr, a_body),
            (LINE_INK_BGR[scene.line_color], a_ink),
            (GLARE_BGR, a_glare),
        ):
            if alpha is not None:
                out = cv2.blendLinear(out, backdrop.lit(colour, roi), 1.0 - alpha, alpha)
        image[y0:y1, x0:x1] = out
    if backdrop.noise_pool is not None:
        dy, dx = rng.integers(0, NOISE_PAD, size=2)
        image = cv2.add(image, backdrop.noise_pool[dy:dy + h, dx:dx + w], dtype=cv2.CV_8U)
    return _result(image, scene, camera, pts_mm, nrm_mm, body_w, centre_px)


def _glare(
    centre_px: NDArray[np.float64],
    scene: SceneParams,
    rng: np.random.Generator,
    shape: tuple[int, int],
    off: NDArray[np.float64],
) -> NDArray[np.float32] | None:
    """Opacity of a glare spot hiding ``occluded_fraction`` of the layer (None without one)."""
    if scene.occluded_fraction <= 0:
        return None
    u0 = rng.uniform(0.15, 0.85 - scene.occluded_fraction)
    n = len(centre_px)
    seg = centre_px[int(u0 * (n - 1)): int((u0 + scene.occluded_fraction) * (n - 1)) + 1]
    glare = np.zeros(shape, np.uint8)
    cv2.polylines(glare, [np.round((seg - off) * (1 << SHIFT)).astype(np.int32)], False, 255,
                  round(2.5 * scene.line_width_px + 4), cv2.LINE_AA, SHIFT)
    return cv2.GaussianBlur(glare, (0, 0), 1.0 + scene.line_width_px / 4).astype(np.float32) * (
        _GLARE_OPACITY / 255.0
    )


def _result(
    image: NDArray[np.uint8],
    scene: SceneParams,
    camera: Camera,
    pts_mm: NDArray[np.float64],
    nrm_mm: NDArray[np.float64],
    body_w: float,
    layer_px: NDArray[np.float64],
    dots_px: NDArray[np.float64] | None = None,
) -> RenderedImage:
    """The photo with its truth: the target's exact centre line through the camera and its
    turning."""
    h, w = scene.height, scene.width
    curve_mm = pts_mm if scene.target == "line" else pts_mm + nrm_mm * (body_w / 2)
    curve = layer_px if scene.target == "line" else camera.to_px(curve_mm)
    in_frame = bool(((curve >= 0) & (curve <= [w - 1, h - 1])).all())
    return RenderedImage(
        image=image,
        centreline_px=curve,
        fixed_end_px=(float(curve[0, 0]), float(curve[0, 1])),
        psi_image_deg=turning_angle_deg(curve, y_down=True),
        line_in_frame=in_frame,
        jpeg_quality=scene.jpeg_quality,
        target=scene.target,
        layer_px=layer_px,
        fixed_direction_deg=_fixed_direction_deg(camera, curve_mm),
        dots_px=np.zeros((0, 2)) if dots_px is None else dots_px,
    )


def _compose_body(
    pts_mm: NDArray[np.float64],
    scene: SceneParams,
    camera: Camera,
    backdrop: Backdrop,
    body_w: float,
    rng: np.random.Generator,
) -> RenderedImage:
    """One photo of a rounded / textured / dotted body (see :mod:`pipeline.synth.body`)."""
    h, w = scene.height, scene.width
    mpp = scene.mm_per_px
    style, gain_full = backdrop.style, backdrop.gain
    layer_px = camera.to_px(pts_mm)
    nrm_mm = _normals(pts_mm)
    hw = body_w / 2
    chord = np.hypot(*np.diff(pts_mm, axis=0).T)
    s_dense = np.concatenate([[0.0], np.cumsum(chord)])
    l0 = float(s_dense[-1])
    centre_mm = pts_mm + nrm_mm * hw
    idx = _decimate(camera.to_px(centre_mm))  # ~1 px apart on screen
    tang = pts_mm[-1] - pts_mm[-2]
    tang /= np.hypot(*tang)
    m = max(2, int(np.ceil(scene.sealed_end_mm / mpp)) + 1)
    ext = np.linspace(0.0, scene.sealed_end_mm, m)[1:]
    s_ax = np.concatenate([s_dense[idx], l0 + ext])
    c_ax = np.vstack([centre_mm[idx], centre_mm[-1] + ext[:, None] * tang])
    n_ax = np.vstack([nrm_mm[idx], np.repeat(nrm_mm[-1:], len(ext), axis=0)])
    half_ax = (hw + relief_mm(s_ax, scene, style, l0))[:, None]
    frame = BodyFrame(centre_px=camera.to_px(c_ax), inner_px=camera.to_px(c_ax - n_ax * half_ax),
                      outer_px=camera.to_px(c_ax + n_ax * half_ax), s_mm=s_ax)
    body_polys = _band_polygons(frame.inner_px, frame.outer_px)
    polys = list(body_polys)
    cap_px = None
    if scene.tip_cap_mm > 0:
        base = c_ax[-1]
        half_cap = hw + CAP_OVERHANG * body_w + 0.5
        cap_mm = np.array(
            [
                base - nrm_mm[-1] * half_cap,
                base - nrm_mm[-1] * half_cap + tang * scene.tip_cap_mm,
                base + nrm_mm[-1] * half_cap + tang * scene.tip_cap_mm,
                base + nrm_mm[-1] * half_cap,
            ]
        )
        cap_px = camera.to_px(cap_mm)
        polys.append(cap_px)
    dots_px = np.zeros((0, 2))
    if len(style.dot_u):
        s_k = style.dot_u * l0
        at = np.column_stack([np.interp(s_k, s_dense, pts_mm[:, j]) for j in range(2)])
        nk = np.column_stack([np.interp(s_k, s_dense, nrm_mm[:, j]) for j in range(2)])
        dots_px = camera.to_px(at + nk * (hw * (1 + style.dot_v))[:, None])
    line_polys: list[NDArray[np.float64]] = []
    if scene.marker_line:
        lidx = _decimate(layer_px)
        line_c, line_n = layer_px[lidx], _normals(layer_px)[lidx]
        half = scene.line_width_px / 2
        line_polys = _band_polygons(line_c - line_n * half, line_c + line_n * half)
    blur = scene.blur_sigma_px
    margin = 3 * blur + 4 + (SHADOW_REACH_MM / mpp if scene.shadow > 0 else 0.0)
    roi = _roi(polys + line_polys, margin, w, h)
    image = backdrop.image.copy()
    if roi is not None:
        x0, y0, x1, y1 = roi
        off = np.array([x0, y0], float)
        shape = (y1 - y0, x1 - x0)
        gain = gain_full[y0:y1, x0:x1]
        cover = np.zeros(shape, np.uint8)
        _fill(cover, body_polys, off)
        prem, alpha = paint_body(
            scene, style, frame, cover.astype(np.float32) / 255.0, gain, off, l0
        )
        if cap_px is not None:
            cm = np.zeros(shape, np.uint8)
            _fill(cm, [cap_px], off)
            colour, a = paint_cap(scene, style, cap_px, cm.astype(np.float32) / 255.0, gain, off)
            prem, alpha = over(prem, alpha, colour, a)
        if len(dots_px):
            radius = scene.dot_diameter_mm / 2 / mpp
            colour, a, ring = paint_dots(scene, dots_px, radius, shape, off, gain, SHIFT)
            prem, alpha = over(
                prem, alpha, np.zeros_like(colour) + np.float32(40) * gain[..., None], ring
            )
            prem, alpha = over(prem, alpha, colour, a)
        if line_polys:
            f = LINE_SUPERSAMPLING
            big = np.zeros((shape[0] * f, shape[1] * f), np.uint8)
            _fill(big, line_polys, off, f)
            a_ink = cv2.resize(big, (shape[1], shape[0]), interpolation=cv2.INTER_AREA).astype(
                np.float32
            ) * (scene.line_contrast / 255.0)
            prem, alpha = over(
                prem,
                alpha,
                backdrop.lit(LINE_INK_BGR[scene.line_color], roi).astype(np.float32),
                a_ink,
            )
        out = image[y0:y1, x0:x1].astype(np.float32)
        if scene.shadow > 0:
            out *= (1.0 - scene.shadow * shadow_of(alpha, style, mpp))[..., None]
        if blur > 0:
            prem = np.asarray(cv2.GaussianBlur(prem, (0, 0), blur), np.float32)
            alpha = np.asarray(cv2.GaussianBlur(alpha, (0, 0), blur), np.float32)
        out = out * (1.0 - alpha[..., None]) + prem
        a_glare = _glare(layer_px, scene, rng, shape, off)
        if a_glare is not None:
            out += (backdrop.lit(GLARE_BGR, roi).astype(np.float32) - out) * a_glare[..., None]
        image[y0:y1, x0:x1] = np.clip(out + 0.5, 0, 255).astype(np.uint8)
    if backdrop.noise_pool is not None:
        dy, dx = rng.integers(0, NOISE_PAD, size=2)
        image = cv2.add(image, backdrop.noise_pool[dy:dy + h, dx:dx + w], dtype=cv2.CV_8U)
    return _result(image, scene, camera, pts_mm, nrm_mm, body_w, layer_px, dots_px)


def render_background(
    backdrop: Backdrop, scene: SceneParams, *, seed: int | np.random.SeedSequence
) -> NDArray[np.uint8]:
    """The empty scene: the backdrop (table, light, clamp, tube) with its own sensor noise, no
    actuator.

    Same camera, lighting and clamp as the photos rendered on ``backdrop``; the noise window is
    drawn from ``seed`` (a real background photo has its own noise too).
    """
    image = backdrop.image.copy()
    if backdrop.noise_pool is not None:
        dy, dx = np.random.default_rng(seed).integers(0, NOISE_PAD, size=2)
        image = cv2.add(
            image,
            backdrop.noise_pool[dy : dy + scene.height, dx : dx + scene.width],
            dtype=cv2.CV_8U,
        )
    return image




def render_actuator(
    psi_deg: float,
    l0_mm: float,
    scene: SceneParams,
    *,
    seed: int | np.random.SeedSequence,
    bulge: float = 0.0,
    fixed_end_px: tuple[float, float] | None = None,
    rotation_deg: float = 0.0,
    backdrop: Backdrop | None = None,
    body_width_mm: float | None = None,
    n: int = DEFAULT_N,
) -> RenderedImage:
    """Render an actuator bent to total turning angle ``psi_deg`` (see :func:`render_curve`).

    Parameters
    ----------
    psi_deg : float
        Total turning angle (deg), ccw positive as seen on screen.
    l0_mm : float
        Length of the marked inextensible layer (mm).
    bulge : float
        Curvature non-uniformity, 0 <= bulge < 1 (see ``centreline_mm``), for ``scene.shape``
        ``model``; the other shapes (``arc``, ``distal``, ``chambers``) spread the same total
        turning as :func:`pipeline.synth.centreline.actuator_centreline_mm` says.
    n : int
        Number of centreline points.
    Other parameters are those of :func:`render_curve`.
    """
    pts = actuator_centreline_mm(psi_deg, l0_mm, scene, bulge=bulge, n=n)
    return render_curve(pts, scene, seed=seed, fixed_end_px=fixed_end_px, rotation_deg=rotation_deg,
                        backdrop=backdrop, body_width_mm=body_width_mm)


def render_with_background(
    psi_deg: float,
    l0_mm: float,
    scene: SceneParams,
    *,
    seed: int,
    bulge: float = 0.0,
) -> tuple[RenderedImage, NDArray[np.uint8]]:
    """The photo :func:`render_actuator` renders (same arguments, same pixels) and its empty
    scene (:func:`render_background`): the ``background`` photo a user would take.

    Examples
    --------
    >>> from pipeline.synth.presets import scene_from
    >>> sc = scene_from("green_fibre", width=320, height=240)
    >>> photo, empty = render_with_background(90.0, 200.0, sc, seed=3)
    >>> photo.jpeg_bytes == render_actuator(90.0, 200.0, sc, seed=3).jpeg_bytes, empty.shape
    (True, (240, 320, 3))
    """
    pts = actuator_centreline_mm(psi_deg, l0_mm, scene, bulge=bulge)
    camera = make_camera(
        scene,
        rotation_deg=0.0,
        extent_mm=world_extent_mm(pts, scene.body_width_mm, scene.tip_cap_mm, scene.sealed_end_mm),
    )
    backdrop = make_backdrop(scene, camera, seed=child_seed(seed, 0), keepout_mm=[pts])
    photo = render_curve(pts, scene, seed=seed, backdrop=backdrop)
    return photo, render_background(backdrop, scene, seed=child_seed(seed, 2))
