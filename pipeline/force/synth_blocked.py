"""Synthetic blocked-force photo sets with known eccentricity and force.

In the blocked-force test (paper Section II.C, Fig. 4C) one end of the actuator is clamped and
the free end is tied by an inextensible string to a load cell; with pressure the marked
inextensible layer (length ``l0_mm``) forms an ellipse (Fig. 7B).  This module renders that:
the marker line is an arc of length ``l0_mm`` on an ellipse of eccentricity ``e``, covering
``arc_fraction`` of its perimeter (0.58 ~ a 210 deg rest angle), with the opening between the
two ends centred on the ellipse at parametric angle ``gap_deg`` (0 = at an end of the major
axis, 90 = at an end of the minor axis), leaving the clamp along the clamp axis.

Force and eccentricity against pressure follow simple, seeded, non-linear curves per material
chosen to pass through the paper's reported values (:data:`BLOCKED_MATERIALS`):
``F(P) = F_ref (P / P_ref) ** gamma`` and ``e(P) = e_max sqrt(P / P_max)``, each actuator
scaled by a seeded factor, each trial jittered, each force step averaged from
``force_samples`` noisy load-cell samples.  These curves are *illustrative*, not a model.

Output: an ordinary photo set (``manifest.csv``, ``photoset.yaml``, images) whose manifest
also has ``measured_pressure_kpa``, ``force_n``, ``force_sd_n`` and ``force_samples``, plus
``truth.csv`` (``image``, ``eccentricity``, ``force_true_n``, ``semi_major_mm``,
``semi_minor_mm``, ``arc_fraction``, ``gap_deg``, ``rotation_deg`` -- the clamp axis on screen).

Examples
--------
>>> shape = blocked_arc_mm(0.6, 270.0, arc_fraction=0.58)
>>> round(shape.semi_minor_mm / shape.semi_major_mm, 3)
0.8
>>> bool(np.allclose(shape.points_mm[0], 0.0))
True
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError
from pipeline.force.ellipse import ellipse_points, perimeter


@dataclass(frozen=True)
class BlockedMaterial:
    """Illustrative blocked-force behaviour of one material (values from the paper's text).

    Attributes
    ----------
    name : str
    max_kpa : float
        Highest pressure of the blocked-force ramp (kPa).
    force_ref_n, pressure_ref_kpa : float
        The curve passes through ``force_ref_n`` newtons at ``pressure_ref_kpa``.
    gamma : float
        Exponent of the force curve (> 1: stiffening, as in Fig. 7A).
    eccentricity_max : float
        Eccentricity at ``max_kpa``.
    """

    name: str
    max_kpa: float
    force_ref_n: float
    pressure_ref_kpa: float
    gamma: float
    eccentricity_max: float


#: paper Section III.B: DS20 2.7 N at 105 kPa (e 0.6), DS30 2.1 N at 112 kPa (e 0.5 at 120 kPa),
#: SS40 5.1 N and SS50 1.6 N at 210 kPa (e 0.55 and 0.4)
BLOCKED_MATERIALS: dict[str, BlockedMaterial] = {
    "DS20": BlockedMaterial("DS20", 105.0, 2.7, 105.0, 1.6, 0.60),
    "DS30": BlockedMaterial("DS30", 120.0, 2.1, 112.0, 2.0, 0.50),
    "SS40": BlockedMaterial("SS40", 210.0, 5.1, 210.0, 1.5, 0.55),
    "SS50": BlockedMaterial("SS50", 210.0, 1.6, 210.0, 1.1, 0.40),
}


def blocked_material(material: str) -> BlockedMaterial:
    """The :class:`BlockedMaterial` of a name; UserInputError naming the known ones."""
    if material not in BLOCKED_MATERIALS:
        raise UserInputError(
            f"material {material!r} has no blocked-force curve; use one of "
            f"{sorted(BLOCKED_MATERIALS)}"
        )
    return BLOCKED_MATERIALS[material]


def blocked_force_n(material: str, pressure_kpa: ArrayLike) -> NDArray[np.float64]:
    """Illustrative mean blocked force (N) at ``pressure_kpa`` (kPa) for a material.

    Examples
    --------
    >>> float(blocked_force_n("DS20", 105.0))
    2.7
    """
    m = blocked_material(material)
    p = np.clip(np.asarray(pressure_kpa, dtype=float), 0.0, None)
    return m.force_ref_n * (p / m.pressure_ref_kpa) ** m.gamma


def blocked_eccentricity(material: str, pressure_kpa: ArrayLike) -> NDArray[np.float64]:
    """Illustrative mean eccentricity at ``pressure_kpa`` (kPa) for a material.

    Examples
    --------
    >>> float(blocked_eccentricity("SS50", 210.0))
    0.4
    """
    m = blocked_material(material)
    p = np.clip(np.asarray(pressure_kpa, dtype=float), 0.0, None)
    return m.eccentricity_max * np.sqrt(p / m.max_kpa)


@dataclass(frozen=True)
class BlockedShape:
    """The marker line of a blocked actuator.

    Attributes
    ----------
    points_mm : ndarray (n, 2)
        Centre line in mm, fixed end first at the origin, y up, walking counter-clockwise.
    semi_major_mm, semi_minor_mm : float
    eccentricity, arc_fraction, gap_deg : float
        As requested.
    major_axis_deg : float
        Direction of the major axis in this frame (deg, ccw from +x, in [0, 180)).
    """

    points_mm: NDArray[np.float64]
    semi_major_mm: float
    semi_minor_mm: float
    eccentricity: float
    arc_fraction: float
    gap_deg: float
    major_axis_deg: float


def blocked_arc_mm(
    eccentricity: float,
    l0_mm: float,
    *,
    arc_fraction: float = 0.58,
    gap_deg: float = 0.0,
    n: int = 600,
) -> BlockedShape:
    """Arc of length ``l0_mm`` on an ellipse of eccentricity ``eccentricity``.

    Parameters
    ----------
    eccentricity : float
        0 <= e < 1.
    l0_mm : float
        Length of the marked line (mm).
    arc_fraction : float
        Fraction of the ellipse's perimeter the line covers (0 < f <= 1).
    gap_deg : float
        Parametric angle of the middle of the opening (0: a major-axis end).
    n : int
        Number of points, evenly spaced by arc length.

    Returns
    -------
    BlockedShape
    """
    if not 0.0 <= eccentricity < 1.0:
        raise UserInputError(f"eccentricity {eccentricity} must be in [0, 1)")
    if not 0.0 < arc_fraction <= 1.0:
        raise UserInputError(f"arc_fraction {arc_fraction} must be in (0, 1]")
    ratio = float(np.sqrt(1.0 - eccentricity**2))
    a = l0_mm / (arc_fraction * perimeter(1.0, ratio))
    b = a * ratio
    tt = np.linspace(0.0, 2.0 * np.pi, 40001)
    speed = np.hypot(a * np.sin(tt), b * np.cos(tt))
    s = np.r_[0.0, np.cumsum((speed[1:] + speed[:-1]) / 2.0 * np.diff(tt))]
    total = s[-1]
    gap = np.deg2rad(gap_deg)
    mid = np.interp(np.mod(gap + np.pi, 2.0 * np.pi), tt, s)
    ss = mid - l0_mm / 2.0 + np.linspace(0.0, l0_mm, n)
    t = _t_of_s(ss, tt, s, total)
    pts = ellipse_points((0.0, 0.0, a, b, 0.0), t)
    # fixed end at the origin, leaving it along +x (the renderer puts the clamp behind it along -x)
    start_dir = pts[1] - pts[0]
    turn = -np.arctan2(start_dir[1], start_dir[0])
    c, si = np.cos(turn), np.sin(turn)
    pts = (pts - pts[0]) @ np.array([[c, si], [-si, c]])
    return BlockedShape(
        points_mm=pts,
        semi_major_mm=float(a),
        semi_minor_mm=float(b),
        eccentricity=float(eccentricity),
        arc_fraction=float(arc_fraction),
        gap_deg=float(gap_deg),
        major_axis_deg=float(np.mod(np.rad2deg(turn), 180.0)),
    )


def _t_of_s(
    ss: NDArray[np.float64], tt: NDArray[np.float64], s: NDArray[np.float64], total: float
) -> NDArray[np.float64]:
    """Parametric angle at arc lengths ``ss`` (may run past the 0/2pi seam), unwrapped."""
    laps = np.floor(ss / total)
    return np.interp(ss - laps * total, s, tt) + 2.0 * np.pi * laps


def _rng(seed: int, material: str) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence([int(seed), zlib.crc32(material.encode())]))


def blocked_ramp_table(
    material: str,
    *,
    actuators: int = 3,
    trials: int = 3,
    seed: int = 1,
    step_kpa: float = 10.0,
    max_kpa: float | None = None,
    force_samples: int = 10,
    arc_fraction: float = 0.58,
    gap_deg: float = 0.0,
) -> pd.DataFrame:
    """Per-photo conditions of a synthetic blocked-force set (no images): the seeded truth.

    Returns
    -------
    pandas.DataFrame
        One row per photo: image, pressure_kpa, direction (``up``), material, actuator, trial,
        step, measured_pressure_kpa, force_n, force_sd_n, force_samples, and the truth columns
        eccentricity, force_true_n, arc_fraction, gap_deg, rotation_deg (clamp axis on screen, deg).
    """
    m = blocked_material(material)
    if actuators < 1 or trials < 1 or force_samples < 2 or not step_kpa > 0:
        raise UserInputError(
            "need actuators >= 1, trials >= 1, force_samples >= 2 and step_kpa > 0"
        )
    top = m.max_kpa if max_kpa is None else float(max_kpa)
    pressures = np.arange(0.0, top + 1e-9, step_kpa)
    if pressures[-1] < top - 1e-9:
        pressures = np.r_[pressures, top]
    rng = _rng(seed, material)
    rows = []
    for i in range(actuators):
        actuator = f"A{i + 1}"
        force_scale = float(np.exp(rng.normal(0.0, 0.08)))
        e_scale = float(np.exp(rng.normal(0.0, 0.04)))
        act_fraction = float(np.clip(arc_fraction + rng.normal(0.0, 0.02), 0.3, 1.0))
        act_gap = float(gap_deg + rng.normal(0.0, 8.0))
        for trial in range(1, trials + 1):
            trial_scale = float(np.exp(rng.normal(0.0, 0.03)))
            rotation = float(rng.normal(0.0, 3.0))
            for step, p in enumerate(pressures):
                true_f = float(blocked_force_n(material, p)) * force_scale * trial_scale
                noise_sd = 0.02 + 0.01 * true_f
                samples = true_f + rng.normal(0.0, noise_sd, force_samples)
                e = float(np.clip(blocked_eccentricity(material, p) * e_scale, 0.0, 0.95))
                rows.append(
                    {
                        "image": f"{material}_{actuator}_t{trial}_s{step:02d}_{p:g}kPa.jpg",
                        "pressure_kpa": float(p),
                        "direction": "up",
                        "material": material,
                        "actuator": actuator,
                        "trial": str(trial),
                        "step": step,
                        "measured_pressure_kpa": round(float(p + rng.normal(0.0, 0.4)), 2)
                        if p > 0
                        else 0.0,
                        "force_n": round(float(np.mean(samples)), 4),
                        "force_sd_n": round(float(np.std(samples, ddof=1)), 4),
                        "force_samples": int(force_samples),
                        "eccentricity": e,
                        "force_true_n": true_f,
                        "arc_fraction": act_fraction,
                        "gap_deg": act_gap,
                        "rotation_deg": rotation,
                    }
                )
    return pd.DataFrame(rows)


MANIFEST_COLUMNS: tuple[str, ...] = (
    "image", "pressure_kpa", "direction", "material", "actuator", "trial", "step",
    "measured_pressure_kpa", "force_n", "force_sd_n", "force_samples",
)
TRUTH_COLUMNS: tuple[str, ...] = (
    "image",
    "eccentricity",
    "force_true_n",
    "semi_major_mm",
    "semi_minor_mm",
    "arc_fraction",
    "gap_deg",
    "rotation_deg",
    "pressure_kpa",
    "material",
    "actuator",
    "trial",
)


def render_blocked_photoset(
    out_dir: str | os.PathLike[str],
    material: str,
    *,
    actuators: int = 3,
    trials: int = 3,
    seed: int = 1,
    scene: str = "lab",
    scene_overrides: Mapping[str, Any] | None = None,
    step_kpa: float = 10.0,
    max_kpa: float | None = None,
    l0_mm: float = 270.0,
    force_samples: int = 10,
    arc_fraction: float = 0.58,
    gap_deg: float = 0.0,
) -> pd.DataFrame:
    """Render a synthetic blocked-force photo set (see module docstring).

    Parameters
    ----------
    out_dir : path
        Folder to write; written under a temporary name and renamed when complete, so an
        interrupted render leaves nothing (:func:`pipeline.folders.staged_folder`).
    material : str
        A key of :data:`BLOCKED_MATERIALS`.
    actuators, trials : int
        Ramps rendered: actuators x trials, each 0..max_kpa in ``step_kpa`` steps (kPa).
    seed : int
        Seed of every random choice (same seed, same files).
    scene : str
        Scene preset of :mod:`pipeline.synth` (``clean``, ``lab``, ``hard``).
    scene_overrides : mapping, optional
        Scene knobs to override.
    step_kpa, max_kpa : float
        Pressure step and top of the ramp (kPa); ``max_kpa`` defaults to the material's.
    l0_mm : float
        Length of the marked line (mm).
    force_samples : int
        Load-cell samples averaged per step.
    arc_fraction, gap_deg : float
        Mean shape of the line, see :func:`blocked_arc_mm` (each actuator jittered).

    Returns
    -------
    pandas.DataFrame
        The manifest written.
    """
    from pipeline.fileio import atomic_write_bytes, write_table
    from pipeline.folders import staged_folder
    from pipeline.photoset import TRUTH, write_manifest, write_settings
    from pipeline.synth import child_seed, render_curve, scene_from

    with staged_folder(out_dir, marker=TRUTH) as tmp:  # the set appears complete or not at all
        sc = scene_from(scene, **dict(scene_overrides or {}))
        table = blocked_ramp_table(
            material,
            actuators=actuators,
            trials=trials,
            seed=seed,
            step_kpa=step_kpa,
            max_kpa=max_kpa,
            force_samples=force_samples,
            arc_fraction=arc_fraction,
            gap_deg=gap_deg,
        )
        truth_rows = []
        fixed_ends = []
        for k, row in table.iterrows():
            shape = blocked_arc_mm(
                row["eccentricity"], l0_mm, arc_fraction=row["arc_fraction"], gap_deg=row["gap_deg"]
            )
            image = render_curve(
                shape.points_mm,
                sc,
                seed=child_seed(int(seed), zlib.crc32(material.encode()), int(k)),
                rotation_deg=row["rotation_deg"],
            )
            atomic_write_bytes(tmp / row["image"], image.jpeg_bytes)
            fixed_ends.append(tuple(float(v) for v in image.fixed_end_px))
            truth_rows.append(
                {
                    "image": row["image"],
                    "eccentricity": shape.eccentricity,
                    "force_true_n": row["force_true_n"],
                    "semi_major_mm": shape.semi_major_mm,
                    "semi_minor_mm": shape.semi_minor_mm,
                    "arc_fraction": shape.arc_fraction,
                    "gap_deg": shape.gap_deg,
                    "rotation_deg": row["rotation_deg"],
                    "pressure_kpa": row["pressure_kpa"],
                    "material": material,
                    "actuator": row["actuator"],
                    "trial": row["trial"],
                }
            )
        manifest = table[list(MANIFEST_COLUMNS)].copy()
        manifest["fixed_end_x"] = [round(x, 1) for x, _ in fixed_ends]
        manifest["fixed_end_y"] = [round(y, 1) for _, y in fixed_ends]
        write_manifest(tmp, manifest)
        write_settings(
            tmp,
            {
                "l0_mm": float(l0_mm),
                "mm_per_px": float(sc.mm_per_px),
                "line_color": sc.line_color,
                "fixed_end": "auto",
                "positive_turn": "ccw",
            },
        )
        truth = pd.DataFrame(truth_rows, columns=list(TRUTH_COLUMNS))
        write_table(truth, tmp / TRUTH, float_format=None)
    return manifest

