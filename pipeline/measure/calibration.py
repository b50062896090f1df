"""Camera calibration from a checkerboard photo: the actuator's plane in millimetres.

A photo set's ``calibration:`` names a photo of a printed checkerboard lying where the actuator
lies (the *plane* photo), its square size and its inner-corner count, and optionally more board
photos in other poses for the lens.  :func:`calibrate_files` finds the board in each photo
(OpenCV ``findChessboardCornersSB``), estimates the lens (``calibrateCamera``: focal length and
radial distortion k1 about the image centre from one photo; k2 as well from three or more) and
the homography from the undistorted image to the board's plane (``findHomography``).  The
result, a :class:`PlaneCalibration`, maps image points to the plane.

Only the extracted centre line is mapped (:func:`pipeline.measure.core.plane_centreline`, once
the line is ready), never the image: a few hundred points cost
microseconds.  The plane frame is scaled to *plane pixels* of :attr:`PlaneCalibration.mm_per_px`
mm and turned to match the photo at the board's centre, so every downstream number (lengths,
residuals, the ramp check) keeps its pixel meaning while psi, the curvature and ``length_mm``
are those of the physical plane (psi = mean curvature in 1/mm times ``l0_mm``).

Measured (``python -m pipeline bench calibration``, 8 rendered poses with the camera
3-8 deg off nadir and |k1| <= 0.1, 106 lab photos at 1280x960, one board photo each): |psi
error| against the physical angle, ok rows, median 0.042 deg and p95 0.18 deg calibrated,
against 2.0 deg and 10.4 deg for the same photos measured in the image with ``mm_per_px``; the
fitted k1 is within 0.003 of the rendered one, the reprojection error 0.03-0.05 px.  Mapping a
centre line of ~210 points costs 0.06 ms.

Examples
--------
>>> import cv2, numpy as np
>>> img = np.full((480, 640), 230, np.uint8)              # a 10 x 7 squares board, 40 px squares
>>> for j in range(7):
...     for i in range(10):
...         if (i + j) % 2 == 0:
...             x, y = 120 + 40 * i, 100 + 40 * j
...             _ = cv2.rectangle(img, (x, y), (x + 39, y + 39), 20, -1)
>>> corners = find_board(img, (9, 6))
>>> corners.shape
(54, 2)
>>> cal = calibrate_views([corners], (640, 480), (9, 6), square_mm=20.0)
>>> round(cal.mm_per_px, 3), cal.rms_px < 0.1
(0.5, True)
>>> np.round(cal.to_plane([[200.0, 200.0], [300.0, 200.0]]), 1)  # plane px: the photo itself here
array([[200., 200.],
       [300., 200.]])
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Sequence
from dataclasses import asdict, dataclass, replace
from pathlib import Path
from typing import Any

import cv2
import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.measure.formats import read_image, undecodable

#: a calibration whose reprojection error is above this (px) is doubtful: every row using it is
#: flagged
MAX_RMS_PX = 1.0
#: board photos needed before k2 is estimated as well as k1
VIEWS_FOR_K2 = 3
#: the file ``photoset calibrate`` stores the calibrations of a photo set in
STORE = "calibration.json"
#: changes whenever the model or the algorithm changes (stored calibrations are then recomputed)
MODEL_VERSION = "plane-k1k2-fixed-centre-v1"
_UNDISTORT_CRITERIA = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 40, 1e-9)


class CalibrationError(ValueError):
    """A calibration that cannot be computed (board not found, photos of different sizes)."""


class CalibrationMismatch(ValueError):
    """A photo that the calibration does not fit (another resolution than the board photo)."""


@dataclass(frozen=True)
class PlaneCalibration:
    """The mapping from a photo's pixels to the actuator's plane.

    Attributes
    ----------
    image_size : (int, int)
        (width, height) of the board photo; the photos must have the same.
    camera_matrix : tuple of 9 float
        Row-major 3x3 camera matrix (px).
    dist_coeffs : tuple of 5 float
        OpenCV distortion (k1, k2, p1, p2, k3); p1 = p2 = k3 = 0 here.
    homography : tuple of 9 float
        Row-major 3x3 homography from undistorted image px to plane px.
    mm_per_px : float
        Size of a plane px (mm): the scale at the board's centre.
    rms_px : float
        RMS reprojection error of the lens model over every board corner (px).
    rms_mm : float
        RMS distance between the board corners mapped to the plane and their true places (mm).
    views : int
        Board photos used.
    corners : int
        Board corners used (all views).
    fingerprint : str
        sha256 of the model version, the board size and the board photos' bytes.
    """

    image_size: tuple[int, int]
    camera_matrix: tuple[float, ...]
    dist_coeffs: tuple[float, ...]
    homography: tuple[float, ...]
    mm_per_px: float
    rms_px: float
    rms_mm: float
    views: int
    corners: int
    fingerprint: str = ""

    @property
    def k(self) -> NDArray[np.float64]:
        """Camera matrix as a 3x3 array."""
        return np.asarray(self.camera_matrix, float).reshape(3, 3)

    @property
    def h(self) -> NDArray[np.float64]:
        """Image (undistorted px) -> plane px homography as a 3x3 array."""
        return np.asarray(self.homography, float).reshape(3, 3)

    @property
    def k1(self) -> float:
        """Radial distortion coefficient k1 (OpenCV's, at the fitted focal length)."""
        return float(self.dist_coeffs[0])

    @property
    def doubtful(self) -> bool:
        """Reprojection error above :data:`MAX_RMS_PX`."""
        return not self.rms_px <= MAX_RMS_PX

    def describe(self) -> str:
        """One line: error, scale, lens."""
        return (f"reprojection error {self.rms_px:.2f} px ({self.rms_mm:.3f} mm on the plane), "
                f"{self.mm_per_px:.4f} mm/px, k1 {self.k1:+.3f}, {self.views} board photo(s)")

    def to_plane(self, points_px: ArrayLike) -> NDArray[np.float64]:
        """Image px (x right, y down) -> plane px (undistorted, rectified; ``mm_per_px`` mm
        each)."""
        p = np.asarray(points_px, np.float64).reshape(-1, 1, 2)
        und = cv2.undistortPoints(
            p, self.k, np.asarray(self.dist_coeffs), P=self.k, criteria=_UNDISTORT_CRITERIA
        )
        return np.asarray(cv2.perspectiveTransform(und, self.h), np.float64).reshape(-1, 2)

    def to_image(self, points_plane: ArrayLike) -> NDArray[np.float64]:
        """Plane px -> image px (the inverse of :meth:`to_plane`)."""
        q = np.asarray(points_plane, np.float64).reshape(-1, 1, 2)
        und = cv2.perspectiveTransform(q, np.linalg.inv(self.h)).reshape(-1, 2)
        k = self.k
        rays = np.column_stack([(und - k[:2, 2]) / [k[0, 0], k[1, 1]], np.ones(len(und))])
        px, _ = cv2.projectPoints(rays, np.zeros(3), np.zeros(3), k, np.asarray(self.dist_coeffs))
        return np.asarray(px, np.float64).reshape(-1, 2)

    def to_mm(self, points_px: ArrayLike) -> NDArray[np.float64]:
        """Image px -> plane mm (the plane px times ``mm_per_px``)."""
        return self.to_plane(points_px) * self.mm_per_px


@dataclass(frozen=True)
class Calibration:
    """The ``calibration`` setting of a photo (resolved by :mod:`pipeline.measure.settings`).

    Attributes
    ----------
    boards : tuple of str
        Board photos (absolute paths); the first lies in the actuator's plane, any others only
        help to estimate the lens.
    square_mm : float
        Side of one board square (mm).
    inner_corners : (int, int)
        Inner corners (columns, rows): where four squares meet; a board of 10 x 7 squares has 9 x 6.
    plane : PlaneCalibration or None
        The computed calibration (None only in a spec not yet computed).
    stored : bool
        ``plane`` was read from the photo set's :data:`STORE` (``photoset calibrate``), not
        computed while loading.
    """

    boards: tuple[str, ...]
    square_mm: float
    inner_corners: tuple[int, int]
    plane: PlaneCalibration | None = None
    stored: bool = False

    @property
    def key(self) -> tuple[tuple[str, ...], float, tuple[int, int]]:
        """What identifies the spec (without the result)."""
        return self.boards, self.square_mm, self.inner_corners

    @property
    def board_size(self) -> str:
        """The inner corners in words, e.g. ``9x6 inner corners``."""
        return f"{self.inner_corners[0]}x{self.inner_corners[1]} inner corners"


# --------------------------------------------------------------------------------------------
# finding the board and calibrating


def board_points_mm(inner_corners: tuple[int, int], square_mm: float) -> NDArray[np.float64]:
    """Inner corners in board mm (x along the columns, y along the rows), row by row.

    Examples
    --------
    >>> board_points_mm((3, 2), 10.0).tolist()
    [[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [0.0, 10.0], [10.0, 10.0], [20.0, 10.0]]
    """
    cols, rows = inner_corners
    j, i = np.mgrid[0:rows, 0:cols]
    return np.column_stack([i.ravel(), j.ravel()]).astype(float) * float(square_mm)


def find_board(
    grey: NDArray[np.uint8], inner_corners: tuple[int, int]
) -> NDArray[np.float64] | None:
    """Sub-pixel inner corners of a chessboard in a grey photo, row by row; None when not found.

    Tries OpenCV's sector-based detector as it is, then with normalised contrast and an
    exhaustive search (slower; for dim or uneven light).
    """
    size = (int(inner_corners[0]), int(inner_corners[1]))
    for flags in (0, cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_EXHAUSTIVE):
        found, corners = cv2.findChessboardCornersSB(grey, size, flags=flags)
        if found and corners is not None and len(corners) == size[0] * size[1]:
            return corners.reshape(-1, 2).astype(np.float64)
    return None


def _jacobian(h: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
    e = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    q = cv2.perspectiveTransform((p + e).reshape(-1, 1, 2), h).reshape(-1, 2)
    return np.column_stack([(q[0] - q[1]) / 2, (q[2] - q[3]) / 2])


def _plane_frame(
    h_mm: NDArray[np.float64], centre_px: NDArray[np.float64]
) -> tuple[NDArray[np.float64], float]:
    """Homography to plane px: board mm scaled by the centre's scale, turned (and un-mirrored) to
    the photo."""
    j = _jacobian(h_mm, centre_px)  # mm per undistorted px at the centre
    s = float(np.sqrt(abs(np.linalg.det(j))))
    u, _, vt = np.linalg.svd(np.linalg.inv(j))
    r = u @ vt  # the rotation (or reflection) nearest to mm -> px
    c_mm = cv2.perspectiveTransform(centre_px.reshape(1, 1, 2), h_mm).reshape(2)
    frame = np.eye(3)
    frame[:2, :2] = r / s
    frame[:2, 2] = centre_px - r @ c_mm / s
    return frame @ h_mm, s


def calibrate_views(
    corners_px: Sequence[NDArray[np.float64]],
    image_size: tuple[int, int],
    inner_corners: tuple[int, int],
    square_mm: float,
) -> PlaneCalibration:
    """Calibrate from the board corners found in one or more photos; the first lies in the plane.

    The lens model has the principal point at the image centre, square pixels and no tangential
    distortion; the focal length and k1 are fitted (k2 too from :data:`VIEWS_FOR_K2` photos).

    Parameters
    ----------
    corners_px : sequence of ndarray (rows * cols, 2)
        Corners of each board photo, row by row (:func:`find_board`).
    image_size : (int, int)
        (width, height) of the photos.
    inner_corners : (int, int)
        (columns, rows).
    square_mm : float
        Side of a square (mm).

    Returns
    -------
    PlaneCalibration
    """
    w, h = int(image_size[0]), int(image_size[1])
    board = board_points_mm(inner_corners, square_mm)
    obj = np.column_stack([board, np.zeros(len(board))]).astype(np.float32)
    k0 = np.array(
        [
            [float(max(w, h)), 0.0, (w - 1) / 2],
            [0.0, float(max(w, h)), (h - 1) / 2],
            [0.0, 0.0, 1.0],
        ]
    )
    flags = (
        cv2.CALIB_USE_INTRINSIC_GUESS
        | cv2.CALIB_FIX_PRINCIPAL_POINT
        | cv2.CALIB_FIX_ASPECT_RATIO
        | cv2.CALIB_ZERO_TANGENT_DIST
        | cv2.CALIB_FIX_K3
    )
    if len(corners_px) < VIEWS_FOR_K2:
        flags |= cv2.CALIB_FIX_K2
    rms, k, dist, _, _ = cv2.calibrateCamera(
        [obj] * len(corners_px),
        [np.asarray(c, np.float32).reshape(-1, 1, 2) for c in corners_px],
        (w, h),
        k0,
        np.zeros(5),
        flags=flags,
    )
    dist = np.asarray(dist, float).ravel()[:5]
    plane = np.asarray(corners_px[0], np.float64).reshape(-1, 1, 2)
    und = cv2.undistortPoints(plane, k, dist, P=k, criteria=_UNDISTORT_CRITERIA).reshape(-1, 2)
    homography, _ = cv2.findHomography(und, board, 0)
    if homography is None:  # pragma: no cover - 4+ non-collinear corners always give one
        raise CalibrationError("the board corners do not define a plane")
    h_mm = np.asarray(homography, np.float64)
    residual = cv2.perspectiveTransform(und.reshape(-1, 1, 2), h_mm).reshape(-1, 2) - board
    h_plane, s = _plane_frame(h_mm, und.mean(axis=0))
    return PlaneCalibration(
        image_size=(w, h),
        camera_matrix=tuple(float(v) for v in k.ravel()),
        dist_coeffs=tuple(float(v) for v in dist),
        homography=tuple(float(v) for v in (h_plane / h_plane[2, 2]).ravel()),
        mm_per_px=s,
        rms_px=float(rms),
        rms_mm=float(np.sqrt((residual**2).sum(axis=1).mean())),
        views=len(corners_px),
        corners=int(sum(len(c) for c in corners_px)),
    )


def fingerprint(
    boards: Sequence[str | os.PathLike[str]], square_mm: float, inner_corners: tuple[int, int]
) -> str:
    """sha256 of the model version, the board size and every board photo's bytes."""
    digest = hashlib.sha256(f"{MODEL_VERSION}|{float(square_mm)!r}|{tuple(inner_corners)}".encode())
    for path in boards:
        digest.update(hashlib.sha256(Path(path).read_bytes()).digest())
    return digest.hexdigest()


def calibrate_files(
    boards: Sequence[str | os.PathLike[str]], square_mm: float, inner_corners: tuple[int, int]
) -> PlaneCalibration:
    """Calibrate from board photo files (the first in the actuator's plane).

    Raises
    ------
    CalibrationError
        A photo cannot be read, has another resolution than the first, or the board (of
        ``inner_corners``) is not found in it; the message names the file.
    """
    corners, size = [], None
    for path in boards:
        name = Path(path).name
        decoded = read_image(path, grey=True)
        if decoded is None:
            raise CalibrationError(
                "calibration board photo {!r} cannot be decoded ({}; {})".format(
                    name, *undecodable(name)
                )
            )
        grey = np.asarray(decoded, np.uint8)
        this = (grey.shape[1], grey.shape[0])
        if size is not None and this != size:
            raise CalibrationError(
                f"calibration board photo {name!r} is {this[0]}x{this[1]} px but "
                f"{Path(boards[0]).name!r} is "
                f"{size[0]}x{size[1]} px: every board photo must come from the camera at the "
                "resolution of the photos"
            )
        size = this
        found = find_board(grey, inner_corners)
        if found is None:
            raise CalibrationError(
                f"calibration board photo {name!r}: no chessboard with "
                f"{inner_corners[0]}x{inner_corners[1]} "
                "inner corners found"
            )
        corners.append(found)
    assert size is not None
    cal = calibrate_views(corners, size, inner_corners, square_mm)
    return replace(cal, fingerprint=fingerprint(boards, square_mm, inner_corners))


# --------------------------------------------------------------------------------------------
# the photo set's store (``photoset calibrate``) and the calibrations of one load


def read_store(folder: str | os.PathLike[str]) -> dict[str, PlaneCalibration]:
    """Stored calibrations of a photo set by fingerprint ({} without a readable store)."""
    path = Path(folder) / STORE
    try:
        entries = json.loads(path.read_text(encoding="utf-8")).get("calibrations", [])
        out = {}
        for e in entries:
            fields = {k: e[k] for k in PlaneCalibration.__dataclass_fields__}
            for key in ("image_size", "camera_matrix", "dist_coeffs", "homography"):
                fields[key] = tuple(fields[key])
            out[str(e["fingerprint"])] = PlaneCalibration(**fields)
        return out
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return {}


def store_entry(cal: Calibration, folder: str | os.PathLike[str]) -> dict[str, Any]:
    """A calibration as stored (board photos named relative to the folder where possible)."""
    assert cal.plane is not None
    names = []
    for b in cal.boards:
        try:
            names.append(str(Path(b).relative_to(Path(folder).resolve())))
        except ValueError:
            names.append(str(b))
    return {
        "boards": names,
        "square_mm": cal.square_mm,
        "inner_corners": list(cal.inner_corners),
        **asdict(cal.plane),
    }


def write_store(folder: str | os.PathLike[str], calibrations: Sequence[Calibration]) -> Path:
    """Write :data:`STORE` (atomically) with these calibrations; return its path."""
    from pipeline.fileio import atomic_write_bytes

    entries = [store_entry(c, folder) for c in calibrations if c.plane is not None]
    text = json.dumps(
        {
            "format": 1,
            "note": "written by 'python -m pipeline photoset calibrate'; do not edit",
            "calibrations": entries,
        },
        indent=1,
    )
    path = Path(folder) / STORE
    atomic_write_bytes(path, (text + "\n").encode())
    return path


class CalibrationCache:
    """The calibrations of one photo-set load: the stored ones, and those computed now (once each).

    A stored calibration is used when its fingerprint matches the board photos and sizes as
    they are now; otherwise (never stored, or the photos changed) it is computed again.
    """

    def __init__(self, folder: str | os.PathLike[str] | None = None) -> None:
        self._stored = read_store(folder) if folder is not None else {}
        self._done: dict[tuple[Any, ...], Calibration | CalibrationError] = {}

    def resolve(self, spec: Calibration) -> Calibration:
        """``spec`` with its :class:`PlaneCalibration`; raise :class:`CalibrationError` if
        impossible."""
        if spec.key not in self._done:
            try:
                fp = fingerprint(spec.boards, spec.square_mm, spec.inner_corners)
                if fp in self._stored:
                    self._done[spec.key] = replace(spec, plane=self._stored[fp], stored=True)
                else:
                    self._done[spec.key] = replace(
                        spec,
                        plane=calibrate_files(spec.boards, spec.square_mm, spec.inner_corners),
                        stored=False,
                    )
            except CalibrationError as exc:
                self._done[spec.key] = exc
            except OSError as exc:
                self._done[spec.key] = CalibrationError(
                    f"calibration board photo cannot be read ({exc.strerror or exc})"
                )
        done = self._done[spec.key]
        if isinstance(done, CalibrationError):
            raise done
        return done


# --------------------------------------------------------------------------------------------
# measuring on the plane (pipeline.measure.core.plane_centreline maps the centre line)


def check_size(
    plane: PlaneCalibration, shape: Sequence[int], scale: float, board: str = "the board photo"
) -> None:
    """Raise :class:`CalibrationMismatch` unless an image of ``shape`` reduced by ``scale`` fits
    ``plane``.

    Examples
    --------
    >>> cal = PlaneCalibration((1280, 960), (1.0,) * 9, (0.0,) * 5, (1.0,) * 9, 0.3, 0.1, 0.01, 1,
    ...                        54)
    >>> check_size(cal, (240, 320, 3), 4.0)
    >>> check_size(cal, (180, 320, 3), 4.0)  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    pipeline.measure.calibration.CalibrationMismatch: the photo is 1280x720 px but ...
    """
    w, h = plane.image_size
    if abs(shape[1] * scale - w) > scale or abs(shape[0] * scale - h) > scale:
        raise CalibrationMismatch(
            f"the photo is {round(shape[1] * scale)}x{round(shape[0] * scale)} px but {board} is "
            f"{w}x{h} px: "
            "calibrate with a board photo taken by this camera at this resolution"
        )


def rectify(
    image: NDArray[np.uint8], plane: PlaneCalibration, scale: float = 1.0
) -> NDArray[np.uint8]:
    """The photo (reduced by ``scale``) remapped to the plane: undistorted and seen from straight
    above.

    Output pixel (x, y) shows plane px (x * scale, y * scale), so the result lies over the photo
    at the board's centre.
    """
    hh, ww = image.shape[:2]
    ys, xs = np.mgrid[0:hh, 0:ww].astype(np.float64)
    src = plane.to_image(np.column_stack([xs.ravel(), ys.ravel()]) * scale) / scale
    mx = src[:, 0].reshape(hh, ww).astype(np.float32)
    my = src[:, 1].reshape(hh, ww).astype(np.float32)
    out = cv2.remap(image, mx, my, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT, borderValue=0)
    return np.asarray(out, np.uint8)


def describe_problem(cal: Calibration, exc: Exception) -> tuple[str, str]:
    """(message, fix) of a calibration that cannot be computed."""
    text = str(exc)
    if "no chessboard" in text:
        # a pose photo other than the first (which gives the plane) may simply be left out
        poses = [Path(b).name for b in cal.boards[1:]]
        spare = next((n for n in poses if f"{n!r}" in text), None)
        return text, (
            "check inner_corners (count where four squares meet: a board of 10 x 7 squares has 9 x "
            "6) "
            "and that the whole board is in the photo, flat, sharp and evenly lit"
            + (
                f"; or leave {spare} out of board (a pose photo: the others still calibrate)"
                if spare is not None
                else ""
            )
        )
    if "px but" in text:
        return text, "take every board photo with the camera and resolution of the actuator photos"
    return text, "re-take or re-export the board photo"
