"""Exact centrelines of the marked inextensible layer (the ground truth of every synthetic photo).

The curve starts at the fixed end (the origin), leaves it along +x, and turns by a total angle
``psi_deg`` (counter-clockwise positive in a y-up frame, as in the paper's Fig. 3A) over its
length ``l0_mm``.  Curvature is ``kappa(u) = (psi / l0) (1 - bulge cos 2 pi u)`` with
``u = s / l0``: constant for ``bulge = 0`` (a circular arc), larger in the middle than at the
ends for ``bulge > 0`` (the soft actuators past psi = 0), with the same total turning angle.

Real bodies are often not arcs (the curvature concentrated at the tip, or a multi-chamber
actuator of which only some chambers bend): :func:`curvature_weights` gives such profiles and
:func:`weighted_centreline_mm` integrates any profile ``kappa(u) = (psi / l0) w(u)`` (``w``
normalised to mean 1, so the total turning is psi exactly); :func:`actuator_centreline_mm` picks
the profile a scene asks for (``SceneParams.shape``).

Examples
--------
>>> import numpy as np
>>> pts = centreline_mm(90.0, 100.0, n=2001)
>>> np.allclose(pts[-1], [200 / np.pi, 200 / np.pi])
True
>>> round(turning_angle_deg(centreline_mm(-200.0, 195.0, bulge=0.3)), 1)
-200.0
>>> w = curvature_weights(np.linspace(0, 1, 5), "distal", straight_base_fraction=0.5)
>>> bool(w[0] == w[1] == 0 and w[-1] > 1)
True
>>> round(turning_angle_deg(weighted_centreline_mm(150.0, 195.0, curvature_weights(
...     np.linspace(0, 1, 4001), "chambers", chamber_bend=(0, 1, 1)))), 1)
150.0
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import cumulative_simpson

from pipeline.errors import UserInputError
from pipeline.synth.presets import SceneParams

#: default number of points: neighbouring chords turn by < 0.02 deg up to |psi| = 360 deg
DEFAULT_N = 20001


def tangent_angle_rad(u: ArrayLike, psi_deg: float, bulge: float = 0.0) -> NDArray[np.float64]:
    """Tangent direction theta(u) (rad, from +x, ccw) at normalised arc length ``u`` in [0, 1].

    ``theta(u) = psi (u - bulge sin(2 pi u) / (2 pi))``, the integral of the curvature law.
    """
    u = np.asarray(u, dtype=float)
    return np.radians(psi_deg) * (u - bulge * np.sin(2 * np.pi * u) / (2 * np.pi))


def curvature_per_mm(
    u: ArrayLike, psi_deg: float, l0_mm: float, bulge: float = 0.0
) -> NDArray[np.float64]:
    """Curvature kappa(u) in 1/mm (signed, ccw positive) at normalised arc length ``u``."""
    u = np.asarray(u, dtype=float)
    return np.radians(psi_deg) / l0_mm * (1.0 - bulge * np.cos(2 * np.pi * u))


def centreline_mm(
    psi_deg: float, l0_mm: float, *, bulge: float = 0.0, n: int = DEFAULT_N
) -> NDArray[np.float64]:
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


#: ``distal``: the curvature rises from 0 to full over this fraction of the length (a smooth step)
DISTAL_RAMP = 0.15
#: ``distal``: the curvature then grows by this factor from the end of the ramp to the tip
DISTAL_GROWTH = 1.0
#: ``chambers``: each change of weight between chambers is spread over this fraction of the length
CHAMBER_BLEND = 0.04


def _smoothstep(x: NDArray[np.float64]) -> NDArray[np.float64]:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def curvature_weights(
    u: ArrayLike,
    shape: str,
    *,
    bulge: float = 0.0,
    straight_base_fraction: float = 0.35,
    chamber_bend: tuple[float, ...] = (1.0,),
) -> NDArray[np.float64]:
    """Relative curvature ``w(u) >= 0`` along the body (not normalised) for a named shape.

    Parameters
    ----------
    u : array_like
        Normalised arc length from the fixed end (0) to the free end (1).
    shape : {"model", "arc", "distal", "chambers"}
        ``model``: ``1 - bulge cos 2 pi u`` (the renderer's law, :func:`centreline_mm`);
        ``arc``: 1; ``distal``: 0 on the straight base ``u < straight_base_fraction``, a smooth
        step up over :data:`DISTAL_RAMP`, then growing linearly towards the tip;
        ``chambers``: the weight of chamber ``k`` of ``len(chamber_bend)`` equal chambers, its
        changes blended over :data:`CHAMBER_BLEND` (the joints bend too, a little).
    bulge, straight_base_fraction, chamber_bend
        Parameters of the shapes above.

    Returns
    -------
    ndarray
        ``w(u)``; the curvature is ``psi / l0 * w(u) / mean(w)``.
    """
    u = np.asarray(u, dtype=float)
    if shape == "model":
        return 1.0 - bulge * np.cos(2 * np.pi * u)
    if shape == "arc":
        return np.ones_like(u)
    if shape == "distal":
        u0 = straight_base_fraction
        return _smoothstep((u - u0) / DISTAL_RAMP) * (
            1.0 + DISTAL_GROWTH * np.clip(u - u0, 0, None) / max(1 - u0, 1e-9)
        )
    if shape == "chambers":
        b = np.asarray(chamber_bend, dtype=float)
        w = np.full_like(u, b[0])
        for k in range(1, len(b)):
            w += (b[k] - b[k - 1]) * _smoothstep((u - k / len(b)) / CHAMBER_BLEND + 0.5)
        return w
    raise UserInputError(f"shape = {shape!r}: use one of model, arc, distal, chambers")


def weighted_centreline_mm(psi_deg: float, l0_mm: float, weights: ArrayLike) -> NDArray[np.float64]:
    """Centreline whose curvature follows ``weights`` (sampled at equal arc-length steps).

    The tangent angle is ``theta(u) = psi W(u) / W(1)`` with ``W`` the cumulative (trapezoid)
    integral of the weights, so the total turning from the fixed end to the free end -- the tip
    tangent minus the base tangent -- is ``psi_deg`` exactly, and the curve leaves the origin
    along +x.

    Parameters
    ----------
    psi_deg : float
        Total turning angle (deg), ccw positive (y up).
    l0_mm : float
        Length (mm).
    weights : array_like, shape (n,)
        Relative curvature ``>= 0`` at ``n`` equally spaced arc-length positions, not all zero.

    Returns
    -------
    ndarray, shape (n, 2)
        Points in mm, fixed end first.
    """
    from scipy.integrate import cumulative_trapezoid

    w = np.asarray(weights, dtype=float)
    if w.ndim != 1 or len(w) < 3 or not np.isfinite(w).all() or (w < 0).any() or not w.sum() > 0:
        raise UserInputError("weights must be >= 3 finite curvature weights >= 0, not all zero")
    if not np.isfinite(psi_deg) or not l0_mm > 0:
        raise UserInputError(f"psi_deg = {psi_deg!r} must be finite and l0_mm = {l0_mm!r} positive")
    cum = cumulative_trapezoid(w, initial=0.0)
    theta = np.radians(psi_deg) * cum / cum[-1]
    ds = l0_mm / (len(w) - 1)
    x = cumulative_simpson(np.cos(theta), dx=ds, initial=0.0)
    y = cumulative_simpson(np.sin(theta), dx=ds, initial=0.0)
    return np.column_stack([x, y])


def actuator_centreline_mm(
    psi_deg: float, l0_mm: float, scene: SceneParams, *, bulge: float = 0.0, n: int = DEFAULT_N
) -> NDArray[np.float64]:
    """The inextensible layer of an actuator bent to total turning ``psi_deg`` in ``scene.shape``.

    ``shape = "model"`` is :func:`centreline_mm` with the given ``bulge`` (byte-identical to
    today's photos); the other shapes ignore ``bulge`` and follow :func:`curvature_weights`.
    Truth: the curve turns through ``psi_deg`` in total (tip tangent minus base tangent).
    """
    if scene.shape == "model":
        return centreline_mm(psi_deg, l0_mm, bulge=bulge, n=n)
    if n < 3:
        raise UserInputError(f"n = {n!r} must be at least 3 points")
    u = np.linspace(0.0, 1.0, int(n))
    w = curvature_weights(u, scene.shape, straight_base_fraction=scene.straight_base_fraction,
                          chamber_bend=scene.chamber_bend)
    return weighted_centreline_mm(psi_deg, l0_mm, w)


def peak_curvature_per_mm(
    psi_deg: float, l0_mm: float, scene: SceneParams, *, bulge: float = 0.0
) -> float:
    """Largest signed curvature (1/mm, ccw positive) of :func:`actuator_centreline_mm` (psi > 0:
    max; < 0: min)."""
    u = np.linspace(0.0, 1.0, 2001)
    w = curvature_weights(
        u,
        scene.shape,
        bulge=bulge,
        straight_base_fraction=scene.straight_base_fraction,
        chamber_bend=scene.chamber_bend,
    )
    k = np.radians(psi_deg) / l0_mm * w / np.trapezoid(w, u)
    return float(k.max() if psi_deg >= 0 else k.min())


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
