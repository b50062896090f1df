"""A photo of a printed checkerboard lying in the actuator's plane, through the same virtual camera.

The board is drawn as exact polygons in world millimetres, each edge densified so the lens
distortion bends it as it bends the actuator, mapped by :meth:`Camera.to_px` (tilt and lens), filled
at 4x supersampling and area-averaged, then lit, blurred and noised like the scene's photos.  The
returned ``corners_px`` are the exact image positions of the inner corners: the truth a
calibration is tested against.

Examples
--------
>>> from pipeline.synth import make_camera, scene_from
>>> scene = scene_from("clean", width=640, height=480, tilt_deg=5.0, lens_k1=-0.1)
>>> camera = make_camera(scene, rotation_deg=0.0, fixed_end_px=(320.0, 240.0))
>>> board = render_board(scene, camera, seed=1)
>>> board.image.shape, board.corners_px.shape, board.square_mm
((480, 640, 3), (54, 2), 27.0)
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import NDArray

from pipeline.fileio import atomic_write_bytes
from pipeline.synth.backdrop import SHIFT, light_gain, make_backdrop
from pipeline.synth.camera import Camera
from pipeline.synth.presets import SceneParams

#: inner corners (columns, rows) of the default board (a 10 x 7 squares print)
BOARD_INNER_CORNERS: tuple[int, int] = (9, 6)
#: share of the frame the board covers (its squares are rounded down to whole millimetres)
BOARD_FILL = 0.8
#: white paper around the squares, in squares
PAPER_MARGIN_SQUARES = 0.6
PAPER_BGR = (236, 238, 238)
BOARD_INK_BGR = (32, 30, 30)
_SUPERSAMPLING = 4
_EDGE_POINTS = 16


@dataclass(frozen=True)
class BoardPhoto:
    """A rendered board photo and its truth.

    Attributes
    ----------
    image : ndarray (H, W, 3) uint8
        BGR photo (encode as JPEG with the scene's quality to write it).
    corners_px : ndarray (rows * cols, 2)
        Exact image positions of the inner corners, row by row.
    corners_mm : ndarray (rows * cols, 2)
        The same corners in world mm (the actuator's plane).
    inner_corners : (int, int)
        Inner corners (columns, rows).
    square_mm : float
        Side of one square (mm).
    """

    image: NDArray[np.uint8]
    corners_px: NDArray[np.float64]
    corners_mm: NDArray[np.float64]
    inner_corners: tuple[int, int]
    square_mm: float


def board_square_mm(scene: SceneParams, inner_corners: tuple[int, int] = BOARD_INNER_CORNERS,
                    fill: float = BOARD_FILL) -> float:
    """Whole-mm square size making the board cover ``fill`` of the frame.

    Examples
    --------
    >>> from pipeline.synth import scene_from
    >>> board_square_mm(scene_from("lab"))      # 384 x 288 mm frame
    27.0
    """
    cols, rows = inner_corners
    w_mm, h_mm = scene.width * scene.mm_per_px, scene.height * scene.mm_per_px
    return float(max(1.0, np.floor(fill * min(w_mm / (cols + 1 + 2 * PAPER_MARGIN_SQUARES),
                                               h_mm / (rows + 1 + 2 * PAPER_MARGIN_SQUARES)))))


def _polygon(corners_uv: NDArray[np.float64]) -> NDArray[np.float64]:
    """A closed quadrilateral with every edge cut into ``_EDGE_POINTS`` pieces."""
    t = np.linspace(0.0, 1.0, _EDGE_POINTS, endpoint=False)[:, None]
    return np.vstack([a + t * (b - a) for a, b in zip(corners_uv, np.roll(corners_uv, -1, axis=0))])


def _mask(
    polys_px: list[NDArray[np.float64]], shape: tuple[int, int], blur_px: float
) -> NDArray[np.float32]:
    f = _SUPERSAMPLING
    big = np.zeros((shape[0] * f, shape[1] * f), np.uint8)
    pts = [np.round((p * f + (f - 1) / 2) * (1 << SHIFT)).astype(np.int32) for p in polys_px]
    cv2.fillPoly(big, pts, 255, cv2.LINE_AA, SHIFT)
    alpha = (
        cv2.resize(big, (shape[1], shape[0]), interpolation=cv2.INTER_AREA).astype(np.float32)
        / 255.0
    )
    if blur_px > 0:
        return np.asarray(cv2.GaussianBlur(alpha, (0, 0), blur_px), np.float32)
    return alpha


def render_board(
    scene: SceneParams,
    camera: Camera,
    *,
    seed: int | np.random.SeedSequence,
    inner_corners: tuple[int, int] = BOARD_INNER_CORNERS,
    square_mm: float | None = None,
    centre_mm: tuple[float, float] | None = None,
    angle_deg: float = 3.0,
) -> BoardPhoto:
    """Render a checkerboard lying on the table (the actuator's plane) as ``camera`` sees it.

    Parameters
    ----------
    scene : SceneParams
        Light, blur and noise of the photo.
    camera : Camera
        The camera of the photos (tilt and lens included).
    seed : int or numpy.random.SeedSequence
        Seeds the table, light and noise.
    inner_corners : (int, int)
        Inner corners (columns, rows); the board has one square more each way.
    square_mm : float, optional
        Side of a square; default :func:`board_square_mm`.
    centre_mm : (x, y), optional
        Board centre in world mm; default the point seen at the image centre.
    angle_deg : float
        Board rotation against the image axes (deg), as a hand lays it roughly square.

    Returns
    -------
    BoardPhoto
    """
    cols, rows = inner_corners
    sq = board_square_mm(scene, inner_corners) if square_mm is None else float(square_mm)
    h, w = scene.height, scene.width
    centre = (
        camera.from_px([[w / 2, h / 2]])[0] if centre_mm is None else np.asarray(centre_mm, float)
    )
    a = np.radians(angle_deg - camera.rotation_deg)
    # board frame: u right, v down as seen (world y is up), origin at the board centre
    axes = np.array([[np.cos(a), np.sin(a)], [np.sin(a), -np.cos(a)]]) * sq

    def world(uv: NDArray[np.float64]) -> NDArray[np.float64]:
        return centre + (np.asarray(uv, float) - [(cols + 1) / 2, (rows + 1) / 2]) @ axes

    m = PAPER_MARGIN_SQUARES
    paper = [
        camera.to_px(
            world(
                _polygon(
                    np.array(
                        [
                            [-m, -m],
                            [cols + 1 + m, -m],
                            [cols + 1 + m, rows + 1 + m],
                            [-m, rows + 1 + m],
                        ]
                    )
                )
            )
        )
    ]
    squares = [
        camera.to_px(
            world(_polygon(np.array([[i, j], [i + 1, j], [i + 1, j + 1], [i, j + 1]], float)))
        )
        for j in range(rows + 1)
        for i in range(cols + 1)
        if (i + j) % 2 == 0
    ]
    backdrop = make_backdrop(scene, camera, seed=seed)
    rng = np.random.default_rng(seed)
    gain = light_gain(scene, rng)[..., None]
    img = backdrop.image.astype(np.float32)
    for polys, colour in ((paper, PAPER_BGR), (squares, BOARD_INK_BGR)):
        alpha = _mask(polys, (h, w), scene.blur_sigma_px)[..., None]
        img += (np.asarray(colour, np.float32) * gain - img) * alpha
    if scene.noise_sigma > 0:
        img += rng.standard_normal(img.shape, dtype=np.float32) * scene.noise_sigma
    grid = np.array([[i, j] for j in range(1, rows + 1) for i in range(1, cols + 1)], float)
    corners_mm = world(grid)
    return BoardPhoto(
        np.clip(np.rint(img), 0, 255).astype(np.uint8),
        camera.to_px(corners_mm),
        corners_mm,
        (cols, rows),
        sq,
    )


def write_board_photo(path: str | os.PathLike[str], scene: SceneParams, camera: Camera, *,
                      seed: int | np.random.SeedSequence) -> dict[str, Any]:
    """Render the board for ``camera``, write it as a JPEG and return its ``calibration:`` value."""
    board = render_board(scene, camera, seed=seed)
    ok, buf = cv2.imencode(".jpg", board.image, [cv2.IMWRITE_JPEG_QUALITY, int(scene.jpeg_quality)])
    if not ok:  # pragma: no cover - OpenCV always encodes a valid uint8 image
        raise RuntimeError("JPEG encoding failed")
    atomic_write_bytes(Path(path), buf.tobytes())
    return {
        "board": Path(path).name,
        "square_mm": board.square_mm,
        "inner_corners": list(board.inner_corners),
    }
