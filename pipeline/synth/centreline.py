"""Exact centrelines of the marked inextensible layer (the ground truth of every synthetic photo).

The curve starts at the fixed end (the origin), leaves it along +x, and turns by a total angle
``psi_deg`` (counter-clockwise positive in a y-up frame, as in the paper's Fig. 3A) over its
length ``l0_mm``.  Curvature is ``kappa(u) = (psi / l0) (1 - bulge cos 2 pi u)`` with
``u = s / l0``: constant for ``bulge = 0`` (a circular arc), larger in the middle than at the
ends for ``bulge > 0`` (the soft actuators past psi = 0), with the same total turning angle.

Examples
--------
>>> import numpy as np
>>> pts = centreline_mm(90.0, 100.0, n=2001)
>>> np.allclose(pts[-1], [200 / np.pi, 200 / np.pi])
True
>>> round(turning_angle_deg(centreline_mm(-200.0, 195.0, bulge=0.3)), 1)
-200.0
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_simpson

from pipeline.errors import UserInputError

#: default number of points: neighbouring chords turn by < 0.02 deg up to |psi| = 360 deg
DEFAULT_N = 20001


def tangent_angle_rad(u: ArrayLike, psi_deg: float, bulge: float = 0.0) -> NDArray[np.float64]:
    """Tangent direction theta(u) (rad, from +x, ccw) at normalised arc length ``u`` in [0, 1].

    ``theta(u) = psi (u - bulge sin(2 pi u) / (2 pi))``, the integral of the curvature law.
    """
    u = np.asarray(u, dtype=float)
    return np.radians(psi_deg) * (u - bulge * np.sin(2 * np.pi * u) / (2 * np.pi))


def curvature_per_mm(u: ArrayLike, psi_deg: float, l0_mm: float, bulge: float = 0.0) -> NDArray[np.float64]:
    """Curvature kappa(u) in 1/mm (signed, ccw positive) at normalised arc length ``u``."""
    u = np.asarray(u, dtype=float)
    return np.radians(psi_deg) / l0_mm * (1.0 - bulge * np.cos(2 * np.pi * u))


def centreline_mm(psi_deg: float, l0_mm: float, *, bulge: float = 0.0, n: int = DEFAULT_N) -> NDArray[np.float64]:
    """Points of the exact centreline, fixed end first, in mm (x along the clamp, y up).

    Parameters
    ----------
    psi_deg : float
        Total turning angle psi (deg), ccw positive (y up).  Any finite value; photos need
        only -360..360.
    l0_mm : float
        Length of the inextensible layer (mm).
    bulge : float
        Non-uniformity of the curvature, 0 <= bulge < 1: curvature at the ends is
        ``(1 - bulge)`` and in the middle ``(1 + bulge)`` times the mean ``psi / l0``.
    n : int
        Number of points, equally spaced in arc length (>= 2).

    Returns
    -------
    ndarray, shape (n, 2)
        ``[x, y]`` in mm; the first row is ``[0, 0]`` and the tangent there is ``+x``.

    Raises
    ------
    UserInputError
        If ``l0_mm <= 0``, ``bulge`` is outside [0, 1), ``n < 2`` or ``psi_deg`` is not finite.
    """
    if not np.isfinite(psi_deg):
        raise UserInputError(f"psi_deg = {psi_deg!r} must be a finite angle in degrees")
    if not l0_mm > 0:
        raise UserInputError(f"l0_mm = {l0_mm!r} must be a positive length in mm")
    if not 0.0 <= bulge < 1.0:
        raise UserInputError(f"bulge = {bulge!r} must be in [0, 1) (0 = constant curvature)")
    if n < 2:
        raise UserInputError(f"n = {n!r} must be at least 2 points")
    u = np.linspace(0.0, 1.0, int(n))
    theta = tangent_angle_rad(u, psi_deg, bulge)
    if bulge == 0.0:
        # closed form of the circular arc, written with sinc so that psi -> 0 is exact
        s = l0_mm * u
        x = s * np.sinc(theta / np.pi)
        y = s * 0.5 * theta * np.sinc(theta / (2 * np.pi)) ** 2
        return np.column_stack([x, y])
    ds = l0_mm / (n - 1)
    x = cumulative_simpson(np.cos(theta), dx=ds, initial=0.0)
    y = cumulative_simpson(np.sin(theta), dx=ds, initial=0.0)
    return np.column_stack([x, y])


def turning_angle_deg(points: ArrayLike, *, y_down: bool = False) -> float:
    """Total turning angle of a polyline (deg): the sum of the signed turns between chords.

    Parameters
    ----------
    points : array_like, shape (n, 2)
        Polyline vertices in order (n >= 3).
    y_down : bool
        The points are image coordinates (y down); the result is then the turning angle as
        seen on screen, counter-clockwise positive.

    Returns
    -------
    float
        For a dense sampling of a smooth curve this misses only the turn over half a chord at
        each end (``|psi| / (n - 1)`` for an arc).
    """
    p = np.asarray(points, dtype=float)
    d = np.diff(p, axis=0)
    d = d[np.hypot(d[:, 0], d[:, 1]) > 0]
    z = d[:, 0] + 1j * d[:, 1]
    turn = float(np.degrees(np.angle(z[1:] / z[:-1]).sum()))
    return -turn if y_down else turn
