"""The virtual camera: table-plane millimetres to image pixels (placement, scale, tilt).

World frame: millimetres on the table, y up, origin at the fixed end of the marked line,
the line leaving the clamp along +x.  The camera rotates that frame by ``rotation_deg``
(ccw as seen on screen), scales by ``1 / mm_per_px``, flips y (image y is down: a ccw turn in the
world stays a ccw turn on screen) and places the origin at ``fixed_end_px``.  A camera tilt is a
homography ``K R K^-1`` about the image centre, applied to points (never by warping pixels).
A lens adds OpenCV's radial distortion ``x_d = x (1 + k1 r^2)`` in coordinates normalised by the
focal length about the image centre, after the tilt (also applied to points), so the world
millimetres stay the exact physical truth of every photo.

Examples
--------
>>> from pipeline.synth.presets import scene_from
>>> cam = camera_for(scene_from("clean", lens_k1=0.1), rotation_deg=0.0, origin_px=(640.0, 480.0))
>>> corner = cam.to_px([[-180.0, 130.0]])[0]          # far from the centre: pushed outwards
>>> bool(corner[0] < 640 - 600 and corner[1] < 480 - 433)
True
>>> np.allclose(cam.from_px(cam.to_px([[-180.0, 130.0]])), [[-180.0, 130.0]])
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.synth.presets import SceneParams


@dataclass(frozen=True)
class Camera:
    """Placement of the world frame in the image.

    Attributes
    ----------
    width, height : int
        Image size (px).
    mm_per_px : float
        Scale at the image centre (mm per px).
    rotation_deg : float
        Direction of the clamp axis (+x of the world) on screen, ccw from image +x.
    origin_px : tuple of float
        Where the world origin falls before the tilt (image px).
    homography : ndarray, shape (3, 3)
        Tilt homography (identity when the camera looks straight down).
    k1 : float
        Radial lens distortion (OpenCV's k1; > 0 pincushion, < 0 barrel); 0: an ideal lens.
    focal_px : float
        Focal length (px) normalising the distortion radius (only used when ``k1 != 0``).
    """

    width: int
    height: int
    mm_per_px: float
    rotation_deg: float
    origin_px: tuple[float, float]
    homography: NDArray[np.float64]
    k1: float = 0.0
    focal_px: float = 1.0

    def flat_px(self, points_mm: ArrayLike) -> NDArray[np.float64]:
        """World mm -> image px without the tilt."""
        p = np.asarray(points_mm, dtype=float).reshape(-1, 2)
        c, s = np.cos(np.radians(self.rotation_deg)), np.sin(np.radians(self.rotation_deg))
        x = (c * p[:, 0] - s * p[:, 1]) / self.mm_per_px
        y = (s * p[:, 0] + c * p[:, 1]) / self.mm_per_px
        return np.column_stack([self.origin_px[0] + x, self.origin_px[1] - y])

    def to_px(self, points_mm: ArrayLike) -> NDArray[np.float64]:
        """World mm -> image px (x right, y down), tilt and lens included."""
        flat = self.flat_px(points_mm)
        if not np.array_equal(self.homography, np.eye(3)):
            flat = apply_homography(self.homography, flat)
        return distort(flat, self.k1, self.focal_px, (self.width / 2, self.height / 2))

    def from_px(self, points_px: ArrayLike) -> NDArray[np.float64]:
        """Image px -> world mm (the inverse of :meth:`to_px`)."""
        p = undistort(points_px, self.k1, self.focal_px, (self.width / 2, self.height / 2))
        p = apply_homography(np.linalg.inv(self.homography), p) - np.asarray(self.origin_px)
        c, s = np.cos(np.radians(self.rotation_deg)), np.sin(np.radians(self.rotation_deg))
        x, y = p[:, 0] * self.mm_per_px, -p[:, 1] * self.mm_per_px
        return np.column_stack([c * x + s * y, -s * x + c * y])

    @property
    def fixed_end_px(self) -> tuple[float, float]:
        """Where the fixed end (world origin) appears in the image."""
        x, y = self.to_px([[0.0, 0.0]])[0]
        return float(x), float(y)


def distort(
    points_px: ArrayLike, k1: float, focal_px: float, centre_px: tuple[float, float]
) -> NDArray[np.float64]:
    """Radial lens distortion of ideal image points: ``x_d = x (1 + k1 r^2)``, r normalised by
    focal.

    For barrel distortion (``k1 < 0``) the radius is capped where the mapping stops growing
    (``r^2 = 1 / (3 |k1|)``, far outside any photo), so points never fold back into the frame.

    Examples
    --------
    >>> distort([[1100.0, 500.0]], 0.1, 1000.0, (100.0, 500.0))
    array([[1200.,  500.]])
    """
    p = np.asarray(points_px, dtype=np.float64).reshape(-1, 2)
    if k1 == 0:
        return p
    c = np.asarray(centre_px, dtype=np.float64)
    n = (p - c) / focal_px
    r2 = (n**2).sum(axis=1)
    if k1 < 0:
        r2 = np.minimum(r2, 1.0 / (3.0 * -k1))
    return c + n * (1.0 + k1 * r2)[:, None] * focal_px


def undistort(
    points_px: ArrayLike, k1: float, focal_px: float, centre_px: tuple[float, float]
) -> NDArray[np.float64]:
    """The inverse of :func:`distort` (OpenCV's iterative undistortion, run to convergence)."""
    p = np.asarray(points_px, dtype=np.float64).reshape(-1, 1, 2)
    if k1 == 0:
        return p.reshape(-1, 2)
    k = np.array([[focal_px, 0, centre_px[0]], [0, focal_px, centre_px[1]], [0, 0, 1.0]])
    crit = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-12)
    und = cv2.undistortPoints(p, k, np.array([k1, 0, 0, 0, 0.0]), P=k, criteria=crit)
    return np.asarray(und, np.float64).reshape(-1, 2)


def apply_homography(h: NDArray[np.floating[Any]], points_px: ArrayLike) -> NDArray[np.float64]:
    """Apply a 3x3 homography to image points."""
    p = np.asarray(points_px, dtype=np.float64).reshape(-1, 1, 2)
    return np.asarray(cv2.perspectiveTransform(p, h), np.float64).reshape(-1, 2)


def tilt_homography(scene: SceneParams) -> NDArray[np.float64]:
    """Homography of a camera tilted by ``scene.tilt_deg`` about an axis through the image centre.

    The axis lies in the image plane at ``scene.tilt_azimuth_deg``; focal length
    ``scene.focal_px_per_width * width``.
    """
    if scene.tilt_deg == 0:
        return np.eye(3)
    f = scene.focal_px_per_width * scene.width
    k = np.array([[f, 0, scene.width / 2], [0, f, scene.height / 2], [0, 0, 1.0]])
    az = np.radians(scene.tilt_azimuth_deg)
    axis = np.array([np.cos(az), np.sin(az), 0.0]) * np.radians(scene.tilt_deg)
    r, _ = cv2.Rodrigues(axis)
    return k @ r @ np.linalg.inv(k)


def make_camera(
    scene: SceneParams,
    *,
    rotation_deg: float,
    fixed_end_px: tuple[float, float] | None = None,
    extent_mm: ArrayLike | None = None,
) -> Camera:
    """A camera placing the fixed end at ``fixed_end_px`` (as seen, after tilt).

    Parameters
    ----------
    scene : SceneParams
    rotation_deg : float
        Direction of the clamp axis on screen (deg, ccw from image +x).
    fixed_end_px : (x, y), optional
        Where the fixed end should appear; by default the points ``extent_mm`` are centred.
    extent_mm : array_like (n, 2), optional
        World points whose bounding box is centred when ``fixed_end_px`` is None.
    """
    h = tilt_homography(scene)
    if fixed_end_px is None:
        pts = np.zeros((1, 2)) if extent_mm is None else np.asarray(extent_mm, dtype=float)
        probe = Camera(
            scene.width, scene.height, scene.mm_per_px, rotation_deg, (0.0, 0.0), np.eye(3)
        )
        flat = probe.flat_px(pts)
        centre = (flat.min(axis=0) + flat.max(axis=0)) / 2
        origin = (scene.width / 2 - centre[0], scene.height / 2 - centre[1])
    else:
        ideal = undistort(
            [fixed_end_px],
            scene.lens_k1,
            scene_focal_px(scene),
            (scene.width / 2, scene.height / 2),
        )
        origin = tuple(apply_homography(np.linalg.inv(h), ideal)[0])
    return camera_for(
        scene, rotation_deg=rotation_deg, origin_px=(float(origin[0]), float(origin[1]))
    )


def scene_focal_px(scene: SceneParams) -> float:
    """The scene's focal length in pixels (``focal_px_per_width * width``)."""
    return float(scene.focal_px_per_width * scene.width)


def camera_for(
    scene: SceneParams, *, rotation_deg: float, origin_px: tuple[float, float]
) -> Camera:
    """The camera of ``scene`` (its tilt and lens) with the world origin at ``origin_px`` before the
    tilt."""
    return Camera(
        scene.width,
        scene.height,
        scene.mm_per_px,
        float(rotation_deg),
        (float(origin_px[0]), float(origin_px[1])),
        tilt_homography(scene),
        float(scene.lens_k1),
        scene_focal_px(scene),
    )
