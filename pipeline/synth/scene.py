"""Render one synthetic top-view photo of an actuator with its exact centreline.

The marker line is filled as the exact polygon ``centreline +- width/2`` at 4x supersampling and
area-averaged, so the centre of the drawn line is the centreline to within ~0.01 px; the
returned ``centreline_px`` is the dense exact curve mapped through the same camera.

Examples
--------
>>> from pipeline.synth import render_actuator, scene_from
>>> r = render_actuator(120.0, 195.0, scene_from("clean", width=320, height=240), seed=1)
>>> r.image.shape, r.centreline_px.shape[1]
((240, 320, 3), 2)
>>> abs(r.psi_image_deg - 120.0) < 0.05
True
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.synth.backdrop import (
    END_CAP_MM,
    NOISE_PAD,
    SHIFT,
    Backdrop,
    clamp_outline_mm,
    make_backdrop,
)
from pipeline.synth.camera import Camera, make_camera
from pipeline.synth.centreline import DEFAULT_N, centreline_mm, turning_angle_deg
from pipeline.synth.presets import SceneParams

#: supersampling factor of the marker-line mask
LINE_SUPERSAMPLING = 4
_GLARE_OPACITY = 0.93


def child_seed(seed: int | np.random.SeedSequence, *keys: int) -> np.random.SeedSequence:
    """A seed derived from ``seed`` and integer ``keys`` (pure: the same inputs give the same seed)."""
    if isinstance(seed, np.random.SeedSequence):
        return np.random.SeedSequence(seed.entropy, spawn_key=tuple(seed.spawn_key) + tuple(keys))
    return np.random.SeedSequence(int(seed), spawn_key=tuple(keys))


@dataclass(frozen=True)
class RenderedImage:
    """One rendered photo and its ground truth.

    Attributes
    ----------
    image : ndarray (H, W, 3) uint8
        BGR image before JPEG compression.
    centreline_px : ndarray (N, 2) float
        Exact centreline of the marker, fixed end first, image coordinates (x right, y down).
    fixed_end_px : tuple of float
        Where the fixed end of the marker is in the image.
    psi_image_deg : float
        Turning angle of ``centreline_px`` as seen on screen (ccw positive): psi itself up to the
        perspective of a tilted camera.
    line_in_frame : bool
        The whole marker line lies inside the image.
    jpeg_quality : int
        Quality used by :attr:`jpeg_bytes`.
    """

    image: NDArray[np.uint8]
    centreline_px: NDArray[np.float64]
    fixed_end_px: tuple[float, float]
    psi_image_deg: float
    line_in_frame: bool
    jpeg_quality: int = 92

    @functools.cached_property
    def jpeg_bytes(self) -> bytes:
        """The image encoded as JPEG with the scene's quality (deterministic)."""
        ok, buf = cv2.imencode(".jpg", self.image, [cv2.IMWRITE_JPEG_QUALITY, int(self.jpeg_quality)])
        if not ok:  # pragma: no cover - OpenCV always encodes a valid uint8 image
            raise RuntimeError("JPEG encoding failed")
        return buf.tobytes()


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
    return [slice(max(a - 1, 0), min(b + 2, len(points))) for a, b in itertools.pairwise(edges) if b > a]


def _band_polygons(inner: NDArray[np.float64], outer: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    return [np.vstack([inner[c], outer[c][::-1]]) for c in _chunks((inner + outer) / 2)]


def _fill(mask: NDArray[np.uint8], polys: list[NDArray[np.float64]], offset: NDArray[np.float64], factor: int = 1) -> None:
    scaled = [np.round(((p - offset) * factor + (factor - 1) / 2) * (1 << SHIFT)).astype(np.int32) for p in polys]
    for poly in scaled:
        cv2.fillPoly(mask, [poly], 255, cv2.LINE_AA, SHIFT)


def _roi(polys: list[NDArray[np.float64]], margin: float, width: int, height: int) -> tuple[int, int, int, int] | None:
    allp = np.vstack(polys)
    x0 = max(int(np.floor(allp[:, 0].min() - margin)), 0)
    y0 = max(int(np.floor(allp[:, 1].min() - margin)), 0)
    x1 = min(int(np.ceil(allp[:, 0].max() + margin)) + 1, width)
    y1 = min(int(np.ceil(allp[:, 1].max() + margin)) + 1, height)
    if x1 <= x0 or y1 <= y0:
        return None
    return x0, y0, x1, y1


def world_extent_mm(points_mm: NDArray[np.float64], body_width_mm: float) -> NDArray[np.float64]:
    """World points bounding the actuator (line, body, clamp) for framing."""
    body = points_mm + _normals(points_mm) * body_width_mm
    return np.vstack([points_mm, body, clamp_outline_mm(body_width_mm)])


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
    """
    pts = np.asarray(points_mm, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3 or not np.isfinite(pts).all():
        raise UserInputError("points_mm must be a finite (N, 2) array of centreline points with N >= 3")
    body_w = scene.body_width_mm if body_width_mm is None else float(body_width_mm)
    if backdrop is None:
        camera = make_camera(scene, rotation_deg=rotation_deg, fixed_end_px=fixed_end_px,
                             extent_mm=world_extent_mm(pts, body_w))
        backdrop = make_backdrop(scene, camera, seed=child_seed(seed, 0), keepout_mm=[pts])
    camera = backdrop.camera
    rng = np.random.default_rng(child_seed(seed, 1))
    return _compose(pts, scene, camera, backdrop, body_w, rng)


def _compose(pts_mm: NDArray[np.float64], scene: SceneParams, camera: Camera, backdrop: Backdrop,
             body_w: float, rng: np.random.Generator) -> RenderedImage:
    h, w = scene.height, scene.width
    centre_px = camera.to_px(pts_mm)
    idx = _decimate(centre_px)
    nrm_mm = _normals(pts_mm)
    tang_end = pts_mm[-1] - pts_mm[-2]
    tang_end /= np.hypot(*tang_end)
    body_outer_mm = pts_mm[idx] + nrm_mm[idx] * body_w
    cap = [pts_mm[-1] + tang_end * END_CAP_MM, body_outer_mm[-1] + tang_end * END_CAP_MM]
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
        cv2.polylines(edge, [np.round((body_outer_px - off) * (1 << SHIFT)).astype(np.int32)], False, 255,
                      max(1, round(0.6 / scene.mm_per_px)), cv2.LINE_AA, SHIFT)
        a_body = np.maximum(a_body, edge.astype(np.float32) * (min(1.0, opacity + 0.3) / 255.0))
        f = LINE_SUPERSAMPLING
        big = np.zeros((shape[0] * f, shape[1] * f), np.uint8)
        _fill(big, line_polys, off, f)
        ink = cv2.resize(big, (shape[1], shape[0]), interpolation=cv2.INTER_AREA)
        a_ink = ink.astype(np.float32) * (scene.line_contrast / 255.0)
        a_glare = None
        if scene.occluded_fraction > 0:
            u0 = rng.uniform(0.15, 0.85 - scene.occluded_fraction)
            n = len(centre_px)
            seg = centre_px[int(u0 * (n - 1)): int((u0 + scene.occluded_fraction) * (n - 1)) + 1]
            glare = np.zeros(shape, np.uint8)
            cv2.polylines(glare, [np.round((seg - off) * (1 << SHIFT)).astype(np.int32)], False, 255,
                          round(2.5 * scene.line_width_px + 4), cv2.LINE_AA, SHIFT)
            a_glare = cv2.GaussianBlur(glare, (0, 0), 1.0 + scene.line_width_px / 4).astype(np.float32) * (
                _GLARE_OPACITY / 255.0)
        if blur > 0:
            a_body = cv2.GaussianBlur(a_body, (0, 0), blur)
            a_ink = cv2.GaussianBlur(a_ink, (0, 0), blur)
        out = image[y0:y1, x0:x1]
        for layer, alpha in ((backdrop.body_layer, a_body), (backdrop.ink_layer, a_ink), (backdrop.glare_layer, a_glare)):
            if alpha is not None:
                out = cv2.blendLinear(out, layer[y0:y1, x0:x1], 1.0 - alpha, alpha)
        image[y0:y1, x0:x1] = out
    if backdrop.noise_pool is not None:
        dy, dx = rng.integers(0, NOISE_PAD, size=2)
        image = cv2.add(image, backdrop.noise_pool[dy:dy + h, dx:dx + w], dtype=cv2.CV_8U)
    in_frame = bool(((centre_px >= 0) & (centre_px <= [w - 1, h - 1])).all())
    return RenderedImage(
        image=image,
        centreline_px=centre_px,
        fixed_end_px=tuple(float(v) for v in centre_px[0]),
        psi_image_deg=turning_angle_deg(centre_px, y_down=True),
        line_in_frame=in_frame,
        jpeg_quality=scene.jpeg_quality,
    )


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
        Curvature non-uniformity, 0 <= bulge < 1 (see ``centreline_mm``).
    n : int
        Number of centreline points.
    Other parameters are those of :func:`render_curve`.
    """
    pts = centreline_mm(psi_deg, l0_mm, bulge=bulge, n=n)
    return render_curve(pts, scene, seed=seed, fixed_end_px=fixed_end_px, rotation_deg=rotation_deg,
                        backdrop=backdrop, body_width_mm=body_width_mm)
