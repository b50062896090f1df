"""Measured hysteresis versus the analytical model: RMS, crossings, range, hysteresis, k_P.

Everything here is a pure function of DataFrames (hysteresis.csv, angles.csv) and of two
callables standing for the model, so the module is testable without :mod:`pipeline.model`:

- ``model_psi(material, pressure_kpa) -> psi_deg`` (the loading branch, used for both
  directions as the paper's single model curve), and
- ``fit_k_p(material, pressure_kpa, psi_deg) -> (k_p, anything)``.

:func:`model_callables` builds both from :mod:`pipeline.model`.

Definitions (per material, on the mean curves of hysteresis.csv)
-----------------------------------------------------------------
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
    ``fit_k_p`` on all included angles.csv rows of the material (both directions); the
    confidence interval is the 2.5-97.5 % percentile range of the fits on bootstrap resamples of
    whole actuators (seeded ``numpy.random.Generator``).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from pipeline.aggregate import actuator_keys, pool_hysteresis
from pipeline.errors import UserInputError

ModelPsi = Callable[[str, np.ndarray], np.ndarray]
FitKp = Callable[[str, np.ndarray, np.ndarray], tuple[float, Any]]

HYSTERESIS_REQUIRED: tuple[str, ...] = ("material", "direction", "pressure_kpa", "psi_mean_deg", "psi_sd_deg", "n")


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
    "material", "rms_deg", "rms_up_deg", "rms_down_deg", "n_levels", "n_model_nan",
    "p_zero_up_kpa", "p_zero_down_kpa", "p_minus_psi0_up_kpa", "p_minus_psi0_down_kpa", "psi0_deg",
    "range_deg", "psi_max_deg", "psi_min_deg", "range_kpa",
    "hysteresis_width_deg", "hysteresis_width_at_kpa",
    "k_p_fit", "k_p_ci_low", "k_p_ci_high", "k_p_boot_n", "n_actuators",
    "k_p_paper", "paper_rms_deg", "paper_p_zero_kpa", "paper_range_deg", "paper_range_kpa",
)


def check_hysteresis(hyst: pd.DataFrame, where: str = "hysteresis.csv") -> None:
    """Raise :class:`UserInputError` if ``hyst`` lacks hysteresis.csv columns or has a bad direction."""
    missing = [c for c in HYSTERESIS_REQUIRED if c not in hyst.columns]
    if missing:
        raise UserInputError(
            f"{where}: missing column(s) {missing}; pass a hysteresis.csv written by 'aggregate'"
        )
    bad = ~hyst["direction"].isin(("up", "down")).to_numpy()
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


def crossing_kpa(pressure_kpa: np.ndarray, psi_deg: np.ndarray, level_deg: float) -> float:
    """Pressure where a curve, walked in the given order, first reaches ``level_deg``.

    Parameters
    ----------
    pressure_kpa, psi_deg : array_like
        The curve in walking order (ascending pressure for ``up``, descending for ``down``);
        non-finite psi points are dropped.
    level_deg : float
        Angle to cross (deg).

    Returns
    -------
    float
        Linearly interpolated pressure (kPa) between the first two consecutive points that
        bracket the level (a point exactly on the level is returned as is); NaN if never reached.

    Examples
    --------
    >>> round(crossing_kpa([0, 10, 20], [100.0, 40.0, -20.0], 0.0), 3)
    16.667
    >>> round(crossing_kpa([20, 10, 0], [-40.0, 20.0, 100.0], 0.0), 3)  # decreasing-pressure walk
    13.333
    """
    p = np.asarray(pressure_kpa, dtype=float)
    s = np.asarray(psi_deg, dtype=float)
    keep = np.isfinite(p) & np.isfinite(s)
    p, s = p[keep], s[keep]
    d = s - level_deg
    for i in range(d.size):
        if d[i] == 0.0:
            return float(p[i])
        if i + 1 < d.size and d[i] * d[i + 1] < 0.0:
            t = d[i] / (d[i] - d[i + 1])
            return float(p[i] + t * (p[i + 1] - p[i]))
    return math.nan


def branch(hyst_material: pd.DataFrame, direction: str) -> tuple[np.ndarray, np.ndarray]:
    """Pressure and mean psi of one direction in ramp order (ascending for up, descending for down)."""
    b = hyst_material[hyst_material["direction"] == direction]
    b = b.sort_values("pressure_kpa", ascending=(direction == "up"), kind="stable")
    return b["pressure_kpa"].to_numpy(dtype=float), b["psi_mean_deg"].to_numpy(dtype=float)


def hysteresis_width(hyst_material: pd.DataFrame) -> tuple[float, float]:
    """Largest |psi_up - psi_down| (deg) over levels present in both directions, and its pressure (kPa).

    Returns ``(nan, nan)`` when no level has finite means in both directions.
    """
    up = hyst_material[hyst_material["direction"] == "up"].set_index("pressure_kpa")["psi_mean_deg"]
    down = hyst_material[hyst_material["direction"] == "down"].set_index("pressure_kpa")["psi_mean_deg"]
    both = pd.concat([up.rename("up"), down.rename("down")], axis=1, join="inner").dropna()
    if both.empty:
        return math.nan, math.nan
    gap = (both["up"] - both["down"]).abs().sort_index()
    p = float(gap.idxmax())
    return float(gap.max()), p


def bootstrap_k_p(
    material: str,
    rows: pd.DataFrame,
    fit_k_p: FitKp,
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
    k_p = float(fit_k_p(material, rows["pressure_kpa"].to_numpy(float), rows["psi_deg"].to_numpy(float))[0])
    actuators = sorted(rows["actuator"].astype(str).unique())
    if len(actuators) < 2 or n_boot <= 0:
        return k_p, math.nan, math.nan, 0
    by_act = {a: g for a, g in rows.groupby(rows["actuator"].astype(str), sort=True)}
    rng = np.random.default_rng(seed)
    fits = []
    memo: dict[tuple[int, ...], float] = {}  # a resample is a multiset of actuators: fit each once
    for _ in range(n_boot):
        pick = tuple(sorted(int(i) for i in rng.choice(len(actuators), size=len(actuators), replace=True)))
        if pick not in memo:
            sample = pd.concat([by_act[actuators[i]] for i in pick], ignore_index=True)
            try:
                memo[pick] = float(
                    fit_k_p(material, sample["pressure_kpa"].to_numpy(float), sample["psi_deg"].to_numpy(float))[0]
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


def compare_material(
    material: str,
    hyst_material: pd.DataFrame,
    rows: pd.DataFrame | None,
    *,
    model_psi: ModelPsi | None,
    fit_k_p: FitKp | None,
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
        Model callables (see module docstring); ``None`` leaves model columns NaN.
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
    for direction in ("up", "down"):
        p_b, s_b = branch(h, direction)
        out[f"p_zero_{direction}_kpa"] = crossing_kpa(p_b, s_b, 0.0)
        out[f"p_minus_psi0_{direction}_kpa"] = crossing_kpa(p_b, s_b, -psi0_deg)
    finite = h[np.isfinite(h["psi_mean_deg"].to_numpy(float))]
    if len(finite):
        out["psi_max_deg"] = float(finite["psi_mean_deg"].max())
        out["psi_min_deg"] = float(finite["psi_mean_deg"].min())
        out["range_deg"] = out["psi_max_deg"] - out["psi_min_deg"]
        out["range_kpa"] = float(finite["pressure_kpa"].max() - finite["pressure_kpa"].min())
    out["hysteresis_width_deg"], out["hysteresis_width_at_kpa"] = hysteresis_width(h)
    out["k_p_boot_n"] = 0
    out["n_actuators"] = 0 if rows is None else int(rows["actuator"].astype(str).nunique())
    if fit_k_p is not None and rows is not None and len(rows):
        k, lo, hi, nb = bootstrap_k_p(material, rows, fit_k_p, n_boot=n_boot, seed=seed)
        out.update(k_p_fit=k, k_p_ci_low=lo, k_p_ci_high=hi, k_p_boot_n=nb)
    paper = PAPER_VALUES.get(material)
    if paper is not None:
        out.update(
            k_p_paper=paper.k_p, paper_rms_deg=paper.rms_deg, paper_p_zero_kpa=paper.p_zero_kpa,
            paper_range_deg=paper.range_deg, paper_range_kpa=paper.range_kpa,
        )
    return out


def included_rows(angles: pd.DataFrame, include_flagged: bool = False) -> pd.DataFrame:
    """Rows used for fitting: status ok (and flagged if asked) with finite psi and pressure.

    The pressure used is ``measured_pressure_kpa`` where present and finite, else the setpoint.
    """
    allowed = {"ok", "flagged"} if include_flagged else {"ok"}
    df = angles[angles["status"].isin(allowed)].copy()
    p = pd.to_numeric(df["pressure_kpa"], errors="coerce").astype(float)
    if "measured_pressure_kpa" in df.columns:
        m = pd.to_numeric(df["measured_pressure_kpa"], errors="coerce").astype(float)
        p = m.where(np.isfinite(m), p)
    df["pressure_kpa"] = p
    df["psi_deg"] = pd.to_numeric(df["psi_deg"], errors="coerce").astype(float)
    df["actuator"] = actuator_keys(df)
    ok = np.isfinite(df["pressure_kpa"]) & np.isfinite(df["psi_deg"])
    return df[ok].reset_index(drop=True)


def compare(
    hyst: pd.DataFrame,
    angles: pd.DataFrame | None = None,
    *,
    model_psi: ModelPsi | None,
    fit_k_p: FitKp | None,
    psi0_deg: Mapping[str, float] | None = None,
    n_boot: int = 200,
    seed: int = 0,
    include_flagged: bool = False,
) -> pd.DataFrame:
    """rms.csv: one row per material of ``hyst`` (see :func:`compare_material`).

    Parameters
    ----------
    hyst : pandas.DataFrame
        hysteresis.csv rows (any number of materials); rows of the same material x direction x
        level (several datasets of one material) are pooled first (:func:`pool_hysteresis`).
    angles : pandas.DataFrame, optional
        angles.csv rows for the k_P fit and its bootstrap; ``None`` skips the fit.
    model_psi, fit_k_p : callable or None
        Model callables; a material the model does not know (callable raises
        :class:`UserInputError`) gets NaN model columns and a warning.
    psi0_deg : mapping, optional
        Rest angle per material (deg); 210 deg (the paper's) for materials not listed.
    n_boot, seed, include_flagged
        Bootstrap resamples, its seed, and whether flagged rows enter the k_P fit.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`RMS_COLUMNS`, materials in sorted order.
    """
    check_hysteresis(hyst)
    hyst = pool_hysteresis(hyst)
    rows_all = None if angles is None else included_rows(angles, include_flagged)
    psi0 = dict(psi0_deg or {})
    records = []
    for material in sorted(hyst["material"].astype(str).unique()):
        hm = hyst[hyst["material"].astype(str) == material]
        rows = None if rows_all is None else rows_all[rows_all["material"].astype(str) == material]
        try:
            rec = compare_material(
                material, hm, rows, model_psi=model_psi, fit_k_p=fit_k_p,
                psi0_deg=float(psi0.get(material, 210.0)), n_boot=n_boot, seed=seed,
            )
        except UserInputError as exc:
            warnings.warn(f"{material}: model unavailable ({exc}); model columns left empty", stacklevel=2)
            rec = compare_material(
                material, hm, rows, model_psi=None, fit_k_p=None,
                psi0_deg=float(psi0.get(material, 210.0)), n_boot=n_boot, seed=seed,
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
        validated here, so a bad one fails before any data is read.

    Returns
    -------
    model_psi, fit_k_p : callable
        Loading-branch psi(P) and the k_P fit, taking a material *name*.
    psi0_deg : dict of str to float
        Rest angle of every material in the file.
    """
    from pipeline import model  # imported lazily: heavy and owned by the model helper

    table = model.load_materials(materials_path)
    model.make_options(**options)  # unknown names or values: a clear error now

    def _material(name: str) -> Any:
        if name not in table:
            raise UserInputError(
                f"{materials_path or 'packaged materials.yaml'}: no material {name!r}; "
                "add it to a materials file and pass --materials PATH"
            )
        return table[name]

    def model_psi(name: str, pressure_kpa: np.ndarray) -> np.ndarray:
        return np.asarray(
            model.psi_deg(_material(name), np.asarray(pressure_kpa, float), branch="loading", **options)
        )

    def fit(name: str, pressure_kpa: np.ndarray, psi_deg: np.ndarray) -> tuple[float, Any]:
        return model.fit_k_p(_material(name), pressure_kpa, psi_deg, **options)

    return model_psi, fit, {n: float(m.psi0_deg) for n, m in table.items()}
