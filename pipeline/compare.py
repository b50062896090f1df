"""Measured hysteresis versus the analytical model: RMS, crossings, range, hysteresis, k_P.

Everything here is a pure function of DataFrames (hysteresis.csv, angles.csv) and of two
callables standing for the model, so the module is testable without :mod:`pipeline.model`:

- ``model_psi(material, pressure_kpa, l0_mm) -> psi_deg`` (the loading branch, used for both
  directions as the paper's single model curve), and
- ``fit_k_p(material, pressure_kpa, psi_deg, l0_mm) -> (k_p, anything)``.

:func:`model_callables` builds both from :mod:`pipeline.model`.

Each dataset's own actuator
---------------------------
angles.csv carries the ``l0_mm`` of every photo (from its photo set).  Datasets of one material
are pooled only when they share l0; each (material, l0) is one comparison (one rms.csv row,
``curve`` names it) against the model evaluated at that l0.  A dataset without l0_mm uses the
model's default l0 (the materials file's, or ``--l0-mm``), and ``l0_source`` says which; a
dataset holding one material at several l0 cannot be split from its hysteresis.csv, so its row
keeps the data figures and leaves the model columns empty, with the reason in ``note``.

A dataset may bring its own materials file (its own silicone or actuator geometry): it is then
compared against a :class:`DatasetModel` built from that file (Ogden terms, k_P, k_t, geometry,
and l0 unless its photos carry their own), pooled only with datasets of the same file, and
``materials_file`` names the file of every row.

Measured and synthetic datasets never pool (``data_sources``): a lab's measured set of a
material beside the synthetic ramps of the same material and l0 is a row of its own, its
``curve`` ending in ``measured`` (the synthetic one's in ``synthetic``).

What the RMS is (``rms_kind``): ``self-check`` when every dataset of the row is synthetic (its
photos were rendered from this package's model, with each actuator's own stiffness and
hysteresis: the RMS validates neither the model nor the measurement), ``prediction`` when none
is (no model parameter is fitted to these data: k_P is the paper's; ``k_p_fit`` is the one
number fitted to them), ``mixed`` or ``unknown`` otherwise.

Definitions (per row, on the mean curves of hysteresis.csv)
-----------------------------------------------------------
RMS
    sqrt(mean((psi_mean - psi_model(P))**2)) over the pressure levels of both directions
    together (the paper's figure), and of each direction; levels where the model or the mean is
    NaN are skipped and counted (``n_model_nan``).
Crossing of a level L (psi = 0, psi = -psi0)
    walking the mean curve in ramp order (``up``: ascending pressure, ``down``: descending),
    the first pair of consecutive levels whose psi bracket L, linearly interpolated in pressure;
    NaN when the curve never reaches L.
Range of motion
    max - min of the mean psi over both directions (deg), with the pressure span of the data.
Hysteresis width
    largest |psi_up - psi_down| over pressure levels present in both directions (deg), and the
    pressure where it occurs.
k_P fit
    ``fit_k_p`` on the included angles.csv rows of the material taken at rising pressure
    (``direction`` up): the model is the loading branch, and the falling leg lags it by the
    hysteresis the model does not hold, which pulls a fit over both legs low (the synthetic DS20
    sets, rendered with k_P = 3.8 on their rising leg, fit 3.84 on it and 3.32 on both legs:
    ``k_p_fit_both``, kept beside it). The confidence interval is the 2.5-97.5 % percentile range
    of the fits on bootstrap resamples of whole actuators (seeded ``numpy.random.Generator``).
"""

from __future__ import annotations

import math
import warnings
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
import pandas as pd

from pipeline.aggregate import actuator_keys, is_used, measured_pressure, pool_hysteresis
from pipeline.constants import DIRECTIONS, PSI0_DEG
from pipeline.errors import UserInputError

ModelPsi = Callable[[str, np.ndarray, "float | None"], np.ndarray]
FitKp = Callable[[str, np.ndarray, np.ndarray, "float | None"], tuple[float, Any]]

HYSTERESIS_REQUIRED: tuple[str, ...] = (
    "material",
    "direction",
    "pressure_kpa",
    "psi_mean_deg",
    "psi_sd_deg",
    "n",
)


@dataclass(frozen=True)
class PaperValues:
    """Values reported in the paper, Section III.A (NaN where the paper gives none).

    Attributes
    ----------
    rms_deg : float
        RMS model error over both directions (deg).
    p_zero_kpa : float
        Measured pressure at psi = 0 ("about", kPa).
    range_deg : float
        Total range of motion (deg).
    range_kpa : float
        Pressure over which that range was reached (kPa).
    k_p : float
        Pressure scale factor k_P of the model.
    """

    rms_deg: float
    p_zero_kpa: float
    range_deg: float
    range_kpa: float
    k_p: float


#: Section III.A of the paper (RMS, psi = 0 crossings, ranges) and Section II.B (k_P).
PAPER_VALUES: dict[str, PaperValues] = {
    "DS20": PaperValues(rms_deg=74.0, p_zero_kpa=65.0, range_deg=436.0, range_kpa=112.0, k_p=3.8),
    "DS30": PaperValues(rms_deg=68.0, p_zero_kpa=105.0, range_deg=424.0, range_kpa=175.0, k_p=1.8),
    "SS40": PaperValues(rms_deg=32.0, p_zero_kpa=215.0, range_deg=265.0, range_kpa=255.0, k_p=2.2),
    "SS50": PaperValues(rms_deg=4.5, p_zero_kpa=math.nan, range_deg=64.0, range_kpa=255.0, k_p=2.2),
}

#: rms.csv columns, in order
RMS_COLUMNS: tuple[str, ...] = (
    "material",
    "curve",
    "datasets",
    "l0_mm",
    "l0_source",
    "materials_file",
    "data_source",
    "rms_kind",
    "model_fit",
    "note",
    "rms_deg",
    "rms_up_deg",
    "rms_down_deg",
    "n_levels",
    "n_model_nan",
    "p_zero_up_kpa",
    "p_zero_down_kpa",
    "p_minus_psi0_up_kpa",
    "p_minus_psi0_down_kpa",
    "model_p_zero_kpa",
    "model_p_minus_psi0_kpa",
    "psi0_deg",
    "range_deg",
    "psi_max_deg",
    "psi_min_deg",
    "range_kpa",
    "hysteresis_width_deg",
    "hysteresis_width_at_kpa",
    "k_p_fit",
    "k_p_ci_low",
    "k_p_ci_high",
    "k_p_boot_n",
    "k_p_fit_both",
    "n_actuators",
    "k_p_paper",
    "paper_rms_deg",
    "paper_p_zero_kpa",
    "paper_range_deg",
    "paper_range_kpa",
)


def check_hysteresis(hyst: pd.DataFrame, where: str = "hysteresis.csv") -> None:
    """Raise :class:`UserInputError` if ``hyst`` lacks hysteresis.csv columns or has a bad
    direction."""
    missing = [c for c in HYSTERESIS_REQUIRED if c not in hyst.columns]
    if missing:
        raise UserInputError(
            f"{where}: missing column(s) {missing}; pass a hysteresis.csv written by 'aggregate'"
        )
    bad = ~hyst["direction"].isin(DIRECTIONS).to_numpy()
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise UserInputError(
            f"{where} line {i + 2}: direction {hyst['direction'].iloc[i]!r}; use 'up' or 'down'"
        )


def rms_deg(psi_measured: np.ndarray, psi_model: np.ndarray) -> tuple[float, int, int]:
    """Root-mean-square difference over the pairs where both values are finite.

    Parameters
    ----------
    psi_measured, psi_model : array_like
        Angles (deg), same shape.

    Returns
    -------
    rms : float
        RMS (deg); NaN when no pair is finite.
    n_used : int
        Pairs used.
    n_model_nan : int
        Pairs skipped because the model value is not finite (measured finite).

    Examples
    --------
    >>> rms_deg([0.0, 3.0, 1.0], [4.0, 3.0, float("nan")])
    (2.8284271247461903, 2, 1)
    """
    a = np.asarray(psi_measured, dtype=float)
    b = np.asarray(psi_model, dtype=float)
    ok = np.isfinite(a) & np.isfinite(b)
    n_nan = int(np.sum(np.isfinite(a) & ~np.isfinite(b)))
    if not ok.any():
        return math.nan, 0, n_nan
    return float(np.sqrt(np.mean((a[ok] - b[ok]) ** 2))), int(ok.sum()), n_nan


#: a curve that starts within this of the level (deg) starts there: its crossing is the first
#: after it has left that band (customer 31's actuator hung straight at rest, psi 0, dipped to
#: -35 deg and came back through 0 at 77 kPa: "P at psi = 0" read 0 kPa, its rest)
START_BAND_DEG = 2.0


def crossing_kpa(
    pressure_kpa: np.ndarray, psi_deg: np.ndarray, level_deg: float, *, from_rest: bool = True
) -> float:
    """Pressure where a curve, walked in the given order, first reaches ``level_deg``, not
    counting its start where it starts on the level (within :data:`START_BAND_DEG`).

    Parameters
    ----------
    pressure_kpa, psi_deg : array_like
        The curve in walking order (ascending pressure for ``up``, descending for ``down``);
        non-finite psi points are dropped.
    level_deg : float
        Angle to cross (deg).
    from_rest : bool
        The walk starts at the actuator's rest (the loading branch, from its lowest pressure):
        a start on the level is its rest, not a crossing.  False for a walk from the top of the
        ramp (the unloading branch): its start on the level is a crossing where no later one is.

    Returns
    -------
    float
        Linearly interpolated pressure (kPa) between the first two consecutive points that
        bracket the level (a point exactly on the level is returned as is); NaN if never reached,
        and, ``from_rest``, NaN for a curve that starts on the level and never comes back to it:
        its start is its rest, not a crossing (a straight-at-rest actuator's P at psi = 0 read 0
        or 1 kPa by the sign of the noise at rest, else n/a).

    Examples
    --------
    >>> round(crossing_kpa([0, 10, 20], [100.0, 40.0, -20.0], 0.0), 3)
    16.667
    >>> round(crossing_kpa([20, 10, 0], [-40.0, 20.0, 100.0], 0.0), 3)  # decreasing-pressure walk
    13.333
    >>> round(crossing_kpa([0, 10, 20, 30, 40], [0.4, -12.0, -30.0, -5.0, 15.0], 0.0), 3)
    32.5
    >>> crossing_kpa([0, 10, 20], [0.4, -12.0, -30.0], 0.0)  # only at its start: its rest
    nan
    >>> crossing_kpa([0, 10, 20], [-0.4, 12.0, 30.0], 0.0)
    nan
    >>> crossing_kpa([100, 80, 60], [1.5, 20.0, 60.0], 0.0)  # never: near it is not on it
    nan
    >>> round(crossing_kpa([700, 600, 500], [-1.0, 20.0, 60.0], 0.0, from_rest=False), 1)
    695.2
    """
    p = np.asarray(pressure_kpa, dtype=float)
    s = np.asarray(psi_deg, dtype=float)
    keep = np.isfinite(p) & np.isfinite(s)
    p, s = p[keep], s[keep]
    d = s - level_deg
    if d.size and abs(d[0]) <= START_BAND_DEG:  # it starts on the level: from where it leaves
        left = np.flatnonzero(np.abs(d) > START_BAND_DEG)
        later = crossing_kpa(p[left[0] :], d[left[0] :], 0.0) if left.size else math.nan
        if from_rest or not math.isnan(later):
            return later
    for i in range(d.size):  # the first crossing or touch (the start's, off rest, included)
        if d[i] == 0.0:
            return float(p[i])
        if i + 1 < d.size and d[i] * d[i + 1] < 0.0:
            t = d[i] / (d[i] - d[i + 1])
            return float(p[i] + t * (p[i + 1] - p[i]))
    return math.nan


#: pressures (kPa) the model's own psi = 0 is looked for over: past the paper's 674 kPa for SS50
MODEL_CROSSING_GRID_KPA = np.arange(0.0, 1000.5, 0.5)


def model_crossing_kpa(
    model_psi: Callable[[str, np.ndarray], np.ndarray], material: str, level_deg: float
) -> float:
    """Pressure (kPa) at which the model's loading branch reaches ``level_deg``: its prediction
    of P at psi = 0, nothing fitted (NaN when it does not within
    :data:`MODEL_CROSSING_GRID_KPA`).

    Examples
    --------
    >>> round(model_crossing_kpa(lambda m, p: 210.0 - 3.0 * np.asarray(p), "x", 0.0), 1)
    70.0
    """
    grid = MODEL_CROSSING_GRID_KPA
    psi = np.asarray(model_psi(material, grid), dtype=float).reshape(grid.shape)
    return crossing_kpa(grid, psi, level_deg)


def branch(hyst_material: pd.DataFrame, direction: str) -> tuple[np.ndarray, np.ndarray]:
    """Pressure and mean psi of one direction in ramp order (ascending for up, descending for
    down)."""
    b = hyst_material[hyst_material["direction"] == direction]
    b = b.sort_values("pressure_kpa", ascending=(direction == "up"), kind="stable")
    return b["pressure_kpa"].to_numpy(dtype=float), b["psi_mean_deg"].to_numpy(dtype=float)


def hysteresis_width(hyst_material: pd.DataFrame) -> tuple[float, float]:
    """Largest |psi_up - psi_down| (deg) over levels in both directions, and its pressure (kPa).

    Returns ``(nan, nan)`` when no level has finite means in both directions.
    """
    up = hyst_material[hyst_material["direction"] == "up"].set_index("pressure_kpa")["psi_mean_deg"]
    down = hyst_material[hyst_material["direction"] == "down"].set_index("pressure_kpa")[
        "psi_mean_deg"
    ]
    both = pd.concat([up.rename("up"), down.rename("down")], axis=1, join="inner").dropna()
    if both.empty:
        return math.nan, math.nan
    gap = (both["up"] - both["down"]).abs().sort_index()
    p = float(gap.idxmax())
    return float(gap.max()), p


def bootstrap_k_p(
    material: str,
    rows: pd.DataFrame,
    fit_k_p: Callable[[str, np.ndarray, np.ndarray], tuple[float, Any]],
    *,
    n_boot: int = 200,
    seed: int = 0,
    confidence: float = 0.95,
) -> tuple[float, float, float, int]:
    """Fit k_P on all rows and a percentile confidence interval by resampling actuators.

    Parameters
    ----------
    material : str
        Material name passed to ``fit_k_p``.
    rows : pandas.DataFrame
        Included angles rows of this material: ``actuator``, ``pressure_kpa``, ``psi_deg``.
    fit_k_p : callable
        ``fit_k_p(material, pressure_kpa, psi_deg) -> (k_p, ...)``.
    n_boot : int
        Bootstrap resamples (0: no interval).
    seed : int
        Seed of the ``numpy.random.Generator`` (same seed, same interval).
    confidence : float
        Central coverage of the percentile interval.

    Returns
    -------
    k_p, ci_low, ci_high : float
        Point estimate and interval; the interval is NaN with fewer than two actuators.
    n_ok : int
        Resamples whose fit returned a finite k_P.

    Notes
    -----
    A resample is a multiset of actuators, so the fit of each distinct multiset is computed once
    and reused (with 3 actuators there are only 10 distinct resamples); the percentiles are over
    all ``n_boot`` draws.  With few actuators the interval is coarse.
    """
    if rows.empty:
        return math.nan, math.nan, math.nan, 0
    k_p = float(
        fit_k_p(material, rows["pressure_kpa"].to_numpy(float), rows["psi_deg"].to_numpy(float))[0]
    )
    actuators = sorted(rows["actuator"].astype(str).unique())
    if len(actuators) < 2 or n_boot <= 0:
        return k_p, math.nan, math.nan, 0
    by_act = {a: g for a, g in rows.groupby(rows["actuator"].astype(str), sort=True)}
    rng = np.random.default_rng(seed)
    fits = []
    memo: dict[tuple[int, ...], float] = {}  # a resample is a multiset of actuators: fit each once
    for _ in range(n_boot):
        pick = tuple(
            sorted(int(i) for i in rng.choice(len(actuators), size=len(actuators), replace=True))
        )
        if pick not in memo:
            sample = pd.concat([by_act[actuators[i]] for i in pick], ignore_index=True)
            try:
                memo[pick] = float(
                    fit_k_p(
                        material,
                        sample["pressure_kpa"].to_numpy(float),
                        sample["psi_deg"].to_numpy(float),
                    )[0]
                )
            except UserInputError:  # e.g. too few finite pairs in this resample
                memo[pick] = math.nan
        if math.isfinite(memo[pick]):
            fits.append(memo[pick])
    if not fits:
        return k_p, math.nan, math.nan, 0
    tail = 100.0 * (1.0 - confidence) / 2.0
    lo, hi = np.percentile(fits, [tail, 100.0 - tail])
    return k_p, float(lo), float(hi), len(fits)


def rest_angle_deg(hysteresis: pd.DataFrame) -> tuple[float, str]:
    """psi0 of an actuator the model does not know and where it comes from: the mean psi at the
    lowest pressure of the rising curve (its rest angle, measured), else
    :data:`~pipeline.constants.PSI0_DEG` (the paper's: customer 54's one ``ok`` photo, at
    125 kPa down, gave 210 "measured").

    Examples
    --------
    >>> rest_angle_deg(pd.DataFrame({"direction": ["up", "up", "down"],
    ...     "pressure_kpa": [0.0, 20.0, 0.0], "psi_mean_deg": [213.1, 190.0, 208.0]}))
    (213.1, 'its rest angle, measured')
    >>> rest_angle_deg(pd.DataFrame({"direction": ["up"], "pressure_kpa": [125.0],
    ...     "psi_mean_deg": [118.0]}))[1]
    'its psi at 125 kPa, the lowest measured on its rising curve'
    >>> rest_angle_deg(pd.DataFrame({"direction": ["down"], "pressure_kpa": [0.0],
    ...     "psi_mean_deg": [208.0]}))
    (210.0, "the paper's: no rising curve measured")
    """
    up = hysteresis[(hysteresis["direction"] == "up") & hysteresis["psi_mean_deg"].notna()]
    if up.empty:
        return PSI0_DEG, "the paper's: no rising curve measured"
    lowest = up.loc[up["pressure_kpa"].idxmin()]
    where = (
        "its rest angle, measured"
        if float(lowest["pressure_kpa"]) <= 0.0
        else f"its psi at {float(lowest['pressure_kpa']):g} kPa, the lowest measured on its "
        "rising curve"
    )
    return float(lowest["psi_mean_deg"]), where


def compare_material(
    material: str,
    hyst_material: pd.DataFrame,
    rows: pd.DataFrame | None,
    *,
    model_psi: Callable[[str, np.ndarray], np.ndarray] | None,
    fit_k_p: Callable[[str, np.ndarray, np.ndarray], tuple[float, Any]] | None,
    psi0_deg: float,
    n_boot: int = 200,
    seed: int = 0,
) -> dict[str, Any]:
    """All comparison figures of one material (one rms.csv row).

    Parameters
    ----------
    material : str
        Material name.
    hyst_material : pandas.DataFrame
        This material's hysteresis.csv rows.
    rows : pandas.DataFrame or None
        This material's included angles rows (for k_P); ``None`` skips the fit.
    model_psi, fit_k_p : callable or None
        ``model_psi(material, pressure_kpa)`` and ``fit_k_p(material, pressure_kpa, psi_deg)`` at
        this row's l0 (:func:`compare` binds it); ``None`` leaves model columns NaN.
    psi0_deg : float
        Rest angle psi0 (deg) for the psi = -psi0 crossing.
    n_boot, seed : int
        Bootstrap settings of :func:`bootstrap_k_p`.

    Returns
    -------
    dict
        Keys :data:`RMS_COLUMNS`.
    """
    h = hyst_material.sort_values(["direction", "pressure_kpa"], kind="stable")
    out: dict[str, Any] = {c: math.nan for c in RMS_COLUMNS}
    out["material"] = material
    out["psi0_deg"] = psi0_deg
    # RMS against the loading branch of the model at the measured levels
    out["n_levels"] = int(np.isfinite(h["psi_mean_deg"].to_numpy(float)).sum())
    out["n_model_nan"] = 0
    if model_psi is not None and len(h):
        p = h["pressure_kpa"].to_numpy(float)
        model = np.asarray(model_psi(material, p), dtype=float).reshape(p.shape)
        meas = h["psi_mean_deg"].to_numpy(float)
        up = (h["direction"] == "up").to_numpy()
        out["rms_deg"], _, out["n_model_nan"] = rms_deg(meas, model)
        out["rms_up_deg"] = rms_deg(meas[up], model[up])[0]
        out["rms_down_deg"] = rms_deg(meas[~up], model[~up])[0]
        out["model_p_zero_kpa"] = model_crossing_kpa(model_psi, material, 0.0)
        out["model_p_minus_psi0_kpa"] = model_crossing_kpa(model_psi, material, -psi0_deg)
    for direction in DIRECTIONS:
        p_b, s_b = branch(h, direction)
        up = direction == "up"  # the loading branch walks from rest
        out[f"p_zero_{direction}_kpa"] = crossing_kpa(p_b, s_b, 0.0, from_rest=up)
        out[f"p_minus_psi0_{direction}_kpa"] = crossing_kpa(p_b, s_b, -psi0_deg, from_rest=up)
    finite = h[np.isfinite(h["psi_mean_deg"].to_numpy(float))]
    if len(finite):
        out["psi_max_deg"] = float(finite["psi_mean_deg"].max())
        out["psi_min_deg"] = float(finite["psi_mean_deg"].min())
    if finite["pressure_kpa"].nunique() >= 2:  # one level is no range (customer 54's "0 deg")
        out["range_deg"] = out["psi_max_deg"] - out["psi_min_deg"]
        out["range_kpa"] = float(finite["pressure_kpa"].max() - finite["pressure_kpa"].min())
    out["hysteresis_width_deg"], out["hysteresis_width_at_kpa"] = hysteresis_width(h)
    out["k_p_boot_n"] = 0
    out["n_actuators"] = 0 if rows is None else int(rows["actuator"].astype(str).nunique())
    if fit_k_p is not None and rows is not None and len(rows):
        rising = rows[rows["direction"].astype(str) == "up"]
        k, lo, hi, nb = bootstrap_k_p(material, rising, fit_k_p, n_boot=n_boot, seed=seed)
        out.update(k_p_fit=k, k_p_ci_low=lo, k_p_ci_high=hi, k_p_boot_n=nb)
        out["k_p_fit_both"] = bootstrap_k_p(material, rows, fit_k_p, n_boot=0)[0]
    paper = PAPER_VALUES.get(material)
    if paper is not None:
        out.update(
            k_p_paper=paper.k_p,
            paper_rms_deg=paper.rms_deg,
            paper_p_zero_kpa=paper.p_zero_kpa,
            paper_range_deg=paper.range_deg,
            paper_range_kpa=paper.range_kpa,
        )
    return out


def included_rows(angles: pd.DataFrame, include_flagged: bool = False) -> pd.DataFrame:
    """Rows used for fitting: status ok (and flagged if asked) with finite psi and pressure.

    The pressure used is ``measured_pressure_kpa`` where present and finite, else the setpoint.
    """
    df = angles[is_used(angles, include_flagged)].copy()
    df["pressure_kpa"] = measured_pressure(df)
    df["psi_deg"] = pd.to_numeric(df["psi_deg"], errors="coerce").astype(float)
    df["actuator"] = actuator_keys(df)
    ok = np.isfinite(df["pressure_kpa"]) & np.isfinite(df["psi_deg"])
    return df[ok].reset_index(drop=True)


@dataclass(frozen=True)
class DatasetModel:
    """The model of a dataset's own materials file, as :func:`compare` calls it.

    Attributes
    ----------
    materials_file : str
        The file, as the config names it (its label in rms.csv and in ``curve``).
    model_psi, fit_k_p : callable
        As :func:`compare`'s, built from this file (:func:`file_model`).
    psi0_deg : mapping of str to float
        Rest angle per material of this file (deg).
    l0_mm : mapping of str to float
        This file's l0 per material (mm), for datasets whose photos carry none.
    """

    materials_file: str
    model_psi: ModelPsi
    fit_k_p: FitKp
    psi0_deg: Mapping[str, float]
    l0_mm: Mapping[str, float]


@dataclass(frozen=True)
class Group:
    """One comparison: the datasets of one material that share one l0 (one rms.csv row).

    Attributes
    ----------
    material : str
    l0_mm : float or None
        l0 of the model curve; ``None``: not known here, the model's own default is used.
    l0_source : str
        ``"photo set"`` (angles.csv's l0_mm), or where the model default came from.
    datasets : tuple of str
    mixed : bool
        The one dataset of this group holds the material at several l0: no model curve fits.
    note : str
        Why the model columns are empty, or an empty string.
    materials_file : str
        The datasets' own materials file (:class:`DatasetModel`); empty: the run's model.
    source_label : str
        ``"measured"`` or ``"synthetic"`` when another group shares this one's material, l0 and
        materials file but not its kind of data (measured photos never pool with rendered ones);
        named in :attr:`curve`.
    """

    material: str
    l0_mm: float | None
    l0_source: str
    datasets: tuple[str, ...]
    mixed: bool = False
    note: str = ""
    materials_file: str = ""
    source_label: str = ""

    @property
    def curve(self) -> str:
        """Label of the row and of its model curve, e.g. ``"SS50, l0 220 mm"``.

        A dataset's own materials file is named in it: ``"SS50, l0 240 mm, materials soft.yaml"``.
        """
        if self.mixed:
            base = f"{self.material}, {' + '.join(self.datasets)} (several l0)"
        else:
            base = self.material if self.l0_mm is None else f"{self.material}, l0 {self.l0_mm:g} mm"
        if self.materials_file:
            base = f"{base}, materials {self.materials_file}"
        return f"{base}, {self.source_label}" if self.source_label else base


def comparison_groups(
    hyst: pd.DataFrame,
    angles: pd.DataFrame | None,
    default_l0_mm: Mapping[str, float] | None = None,
    default_l0_source: str = "materials file",
    dataset_models: Mapping[str, DatasetModel] | None = None,
    data_sources: Mapping[str, str] | None = None,
) -> list[Group]:
    """Split the (dataset, material) pairs of ``hyst`` into comparisons of one material and one l0.

    Parameters
    ----------
    hyst : pandas.DataFrame
        hysteresis.csv rows with a ``dataset`` column.
    angles : pandas.DataFrame or None
        angles.csv rows with ``dataset`` and (from ``measure``) ``l0_mm``.
    default_l0_mm : mapping of str to float, optional
        The model's l0 per material, for datasets without their own; a material not listed
        gets ``l0_mm=None`` (the model's own default, source ``"model default"``).
    default_l0_source : str
        Where ``default_l0_mm`` comes from (shown in ``l0_source``).
    dataset_models : mapping of str to DatasetModel, optional
        The own materials file of some datasets: their default l0 is that file's (source
        ``"dataset's materials file"``) and they pool only with datasets of the same file.
    data_sources : mapping of str to str, optional
        ``"synthetic"`` or ``"measured"`` per dataset: datasets pool only with datasets of the
        same kind (a lab's measured DS20 set beside the synthetic DS20 ramps is its own row).

    Returns
    -------
    list of Group
        Sorted by material, the run's model before datasets' own files, the default l0 first,
        then by l0; a dataset holding one material at several l0 is a group of its own
        (``mixed``) with the reason in ``note``.
    """
    defaults = dict(default_l0_mm or {})
    own = dict(dataset_models or {})
    kinds = dict(data_sources or {})
    pairs = hyst[["dataset", "material"]].astype(str).drop_duplicates()
    have_l0 = angles is not None and "l0_mm" in angles.columns
    found: dict[tuple[Any, ...], Group] = {}
    for dataset, material in pairs.itertuples(index=False):
        fm = own.get(dataset)
        mfile = fm.materials_file if fm else ""
        l0s: list[float] = []
        if have_l0:
            assert angles is not None  # have_l0 says so
            sel = angles[
                (angles["dataset"].astype(str) == dataset)
                & (angles["material"].astype(str) == material)
            ]
            values = pd.to_numeric(sel["l0_mm"], errors="coerce").to_numpy(float)
            l0s = sorted({float(v) for v in values[np.isfinite(values)]})
        if len(l0s) > 1:
            note = (
                f"dataset {dataset!r} holds {material} actuators of several l0 "
                f"({', '.join(f'{v:g}' for v in l0s)} mm) pooled in one hysteresis.csv: no single "
                "model "
                "curve fits them; split the photo set into one dataset per l0 to compare with the "
                "model"
            )
            found[(material, "several", dataset)] = Group(
                material,
                None,
                "several l0 in one dataset",
                (dataset,),
                mixed=True,
                note=note,
                materials_file=mfile,
            )
            continue
        if l0s:
            l0, source = l0s[0], "photo set"
        elif fm is not None and material in fm.l0_mm:
            l0, source = float(fm.l0_mm[material]), "dataset's materials file"
        elif fm is None and material in defaults:
            l0, source = float(defaults[material]), default_l0_source
        else:
            l0, source = None, "model default"
        key = (material, l0, mfile, kinds.get(dataset, "unknown"))
        prev = found.get(key)
        if prev is None:
            found[key] = Group(material, l0, source, (dataset,), materials_file=mfile)
        else:
            sources = prev.l0_source.split(" + ")
            merged = " + ".join(sources + ([source] if source not in sources else []))
            found[key] = Group(
                material, l0, merged, prev.datasets + (dataset,), materials_file=mfile
            )
    # the same curve for two kinds of data: each row names its kind
    shared = Counter(k[:3] for k in found if k[1] != "several")
    for k, g in found.items():
        if k[1] != "several" and shared[k[:3]] > 1:
            found[k] = replace(g, source_label=str(k[3]))
    file_l0 = {fm.materials_file: fm.l0_mm for fm in own.values()}

    def order(g: Group) -> tuple[str, int, str, int, float]:
        l0 = math.inf if g.l0_mm is None else g.l0_mm
        default = file_l0.get(g.materials_file, {}) if g.materials_file else defaults
        return (
            g.material,
            1 if g.materials_file else 0,
            g.materials_file,
            0 if (g.l0_mm is None or g.l0_mm == default.get(g.material)) else 1,
            l0,
        )

    return sorted(found.values(), key=order)


def rms_kind(sources: Sequence[str]) -> str:
    """``self-check`` (all synthetic), ``prediction`` (none synthetic), ``mixed`` or ``unknown``."""
    known = [s for s in sources if s in ("synthetic", "measured")]
    if len(known) < len(sources) or not known:
        return "unknown"
    if all(s == "synthetic" for s in known):
        return "self-check"
    return "prediction" if all(s == "measured" for s in known) else "mixed"


def compare(
    hyst: pd.DataFrame,
    angles: pd.DataFrame | None = None,
    *,
    model_psi: ModelPsi | None,
    fit_k_p: FitKp | None,
    psi0_deg: Mapping[str, float] | None = None,
    default_l0_mm: Mapping[str, float] | None = None,
    default_l0_source: str = "materials file",
    data_sources: Mapping[str, str] | None = None,
    model_fit: str = "",
    n_boot: int = 200,
    seed: int = 0,
    include_flagged: bool = False,
    materials_file: str = "",
    dataset_models: Mapping[str, DatasetModel] | None = None,
) -> pd.DataFrame:
    """rms.csv: one row per material and l0 (see the module docstring and :func:`compare_material`).

    Parameters
    ----------
    hyst : pandas.DataFrame
        hysteresis.csv rows (any number of materials and datasets; a ``dataset`` column names
        them, one dataset when absent); rows of one comparison (same material and l0) are pooled
        first (:func:`pool_hysteresis`).
    angles : pandas.DataFrame, optional
        angles.csv rows (with the same ``dataset`` names) for each dataset's ``l0_mm`` and for the
        k_P fit and its bootstrap; ``None``: default l0, no fit.
    model_psi, fit_k_p : callable or None
        Model callables taking the l0 (mm, or None for the model's default) last; a material
        the model does not know, or an l0 it refuses (the callable raises
        :class:`UserInputError`), gets NaN model columns, the reason in ``note`` and a warning.
    psi0_deg : mapping, optional
        Rest angle per material (deg); materials not listed (not in the model's table) use their
        own, measured (:func:`rest_angle_deg`), and ``note`` says so.
    default_l0_mm : mapping, optional
        The model's l0 per material for datasets without their own (materials not listed: the
        callables get ``l0_mm=None``, the model's own default).
    default_l0_source : str
        Where that default comes from, for ``l0_source``.
    data_sources : mapping, optional
        ``"synthetic"`` or ``"measured"`` per dataset name, for ``data_source`` and ``rms_kind``.
    model_fit : str
        What in the model is fitted to the paper's numbers (``model_fit`` column).
    n_boot, seed, include_flagged
        Bootstrap resamples, its seed, and whether flagged rows enter the k_P fit.
    materials_file : str
        The materials file of the model above (for ``materials_file``).
    dataset_models : mapping of str to DatasetModel, optional
        Datasets with their own materials file: they are compared against that file's model
        (its callables, psi0 and l0) instead of the one above, in rows of their own.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`RMS_COLUMNS`, ordered by material, the default l0 first.
    """
    check_hysteresis(hyst)
    hyst = hyst.copy()
    if "dataset" not in hyst.columns:
        hyst["dataset"] = ""
    hyst["dataset"] = hyst["dataset"].astype(str)
    if angles is not None:
        angles = angles.copy()
        if "dataset" not in angles.columns:
            angles["dataset"] = ""
        angles["dataset"] = angles["dataset"].astype(str)
    rows_all = None if angles is None else included_rows(angles, include_flagged)
    psi0 = dict(psi0_deg or {})
    sources = dict(data_sources or {})
    own = dict(dataset_models or {})
    by_file = {fm.materials_file: fm for fm in own.values()}
    records = []
    for group in comparison_groups(
        hyst, angles, dict(default_l0_mm or {}), default_l0_source, own, sources
    ):
        material, l0 = group.material, group.l0_mm
        fm = by_file.get(group.materials_file)
        run_psi, run_fit, run_psi0 = (
            (fm.model_psi, fm.fit_k_p, fm.psi0_deg) if fm else (model_psi, fit_k_p, psi0)
        )
        in_group = hyst["dataset"].isin(group.datasets) & (hyst["material"].astype(str) == material)
        hm = pool_hysteresis(hyst[in_group].drop(columns="dataset"))
        rows = None
        if rows_all is not None:
            rows = rows_all[
                rows_all["dataset"].isin(group.datasets)
                & (rows_all["material"].astype(str) == material)
            ]
        usable = not group.mixed
        psi_fn = (
            (lambda m, p, l0=l0, f=run_psi: f(m, p, l0)) if run_psi is not None and usable else None
        )
        fit_fn = (
            (lambda m, p, s, l0=l0, f=run_fit: f(m, p, s, l0))
            if run_fit is not None and usable
            else None
        )
        note = group.note
        material_psi0_deg = run_psi0.get(material)
        rest = ""
        if material_psi0_deg is None:  # a material the model does not know: its own rest angle
            material_psi0_deg, source = rest_angle_deg(hm)
            rest = f"psi0 {material_psi0_deg:.1f} deg: {source}"
        try:
            rec = compare_material(
                material, hm, rows, model_psi=psi_fn, fit_k_p=fit_fn, psi0_deg=material_psi0_deg,
                n_boot=n_boot, seed=seed,
            )
        except UserInputError as exc:
            warnings.warn(
                f"{group.curve}: model unavailable ({exc}); model columns left empty", stacklevel=2
            )
            note = f"model unavailable: {exc}"
            rec = compare_material(
                material, hm, rows, model_psi=None, fit_k_p=None, psi0_deg=material_psi0_deg,
                n_boot=n_boot, seed=seed,
            )
        if note and group.note:
            warnings.warn(f"{group.curve}: {note}", stacklevel=2)
        note = "; ".join(n for n in (note, rest) if n)
        data = [sources.get(d, "unknown") for d in group.datasets]
        rec.update(
            curve=group.curve,
            datasets=" + ".join(group.datasets),
            l0_mm=math.nan if l0 is None else l0,
            l0_source=group.l0_source,
            materials_file=group.materials_file or materials_file,
            data_source=" + ".join(sorted(set(data))),
            rms_kind=rms_kind(data),
            model_fit=model_fit,
            note=note,
        )
        records.append(rec)
    return pd.DataFrame(records, columns=list(RMS_COLUMNS))


def model_callables(
    materials_path: str | None = None, **options: Any
) -> tuple[ModelPsi, FitKp, dict[str, float]]:
    """Model callables and psi0 per material from :mod:`pipeline.model`.

    Parameters
    ----------
    materials_path : str, optional
        Materials YAML (the packaged one when ``None``).
    **options
        Model readings (:class:`pipeline.model.ModelOptions`), applied to both callables;
        validated here, so a bad one fails before any data is read.  ``l0_mm`` here is only the
        default: the callables take the l0 of each comparison.

    Returns
    -------
    model_psi, fit_k_p : callable
        Loading-branch psi(P) and the k_P fit, taking a material *name* and the l0 (mm) last.
    psi0_deg : dict of str to float
        Rest angle of every material in the file.
    """
    from pipeline import model  # imported lazily: heavy and owned by the model helper

    table = model.load_materials(materials_path)
    model.make_options(**options)  # unknown names or values: a clear error now
    readings = {k: v for k, v in options.items() if k != "l0_mm"}
    default_l0 = options.get("l0_mm")

    def _material(name: str) -> Any:
        if name not in table:
            raise UserInputError(
                f"{materials_path or 'the packaged materials.yaml'} has no material {name!r}, "
                "so its photos are measured and not compared with the model; to compare, copy "
                "an entry of pipeline/model/materials.yaml into your own materials file with the "
                "material's Ogden fit and name that file in config.yaml (model.materials_file, "
                "or the dataset's materials_file; --materials PATH without Snakemake)"
            )
        return table[name]

    def model_psi(name: str, pressure_kpa: np.ndarray, l0_mm: float | None) -> np.ndarray:
        return np.asarray(
            model.psi_deg(
                _material(name),
                np.asarray(pressure_kpa, float),
                branch="loading",
                l0_mm=default_l0 if l0_mm is None else l0_mm,
                **readings,
            )
        )

    def fit(
        name: str, pressure_kpa: np.ndarray, psi_deg: np.ndarray, l0_mm: float | None
    ) -> tuple[float, Any]:
        l0 = default_l0 if l0_mm is None else l0_mm
        return model.fit_k_p(_material(name), pressure_kpa, psi_deg, l0_mm=l0, **readings)

    return model_psi, fit, {n: float(m.psi0_deg) for n, m in table.items()}


def file_model(materials_path: str, **options: Any) -> DatasetModel:
    """:class:`DatasetModel` of one materials file (a dataset's own), with the run's readings.

    Parameters
    ----------
    materials_path : str
        The materials YAML, as the config names it.
    **options
        Model readings, as :func:`model_callables` (``l0_mm`` is not this file's l0: the file's
        own l0 is used for datasets whose photos carry none).

    Raises
    ------
    UserInputError
        If the file cannot be read or an option is bad.
    """
    from pipeline import model

    table = model.load_materials(materials_path)
    model_psi, fit, psi0 = model_callables(materials_path, **options)
    return DatasetModel(
        materials_path, model_psi, fit, psi0, {n: float(m.l0_mm) for n, m in table.items()}
    )
