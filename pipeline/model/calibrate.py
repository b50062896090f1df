"""Calibration: the selection protocol of the model's reading, the anchor tables, k_P fits.

The protocol (printed by ``python -m pipeline model calibrate``, see :data:`PROTOCOL`):

1. Candidates are the readings derived from the printed text with no free constant
   (:data:`DERIVED_KEYS`; ``l0_factor="fitted_scale"`` is a fit and ``wall_coords="unscaled"``
   contradicts the text, so neither is a candidate).
2. The paper's two model results (SS50 straight at 674 kPa, SS40 at -psi0 at 378 kPa) fix one
   physical parameter, l0, within 170-270 mm (:func:`fit_l0`: the l0 minimising the worse of the
   two errors).
3. A candidate passes when both are within +-5 % at its l0.
4. Of the passing candidates the one with the fewest departures from the printed equations wins
   (:func:`departures`), ties going to the smaller worst error.
5. The Section III measurements are then scored out of sample (:func:`anchor_table`, group
   ``"measured"``): they choose nothing.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from pipeline.errors import UserInputError
from pipeline.model.anchors import (
    ANCHORS,
    L0_PLAUSIBLE_MM,
    MODEL_ANCHORS,
    MODEL_BAR_PCT,
    Anchor,
)
from pipeline.model.forward import as_numbers, pressure_core, scale_fitted_to_anchors
from pipeline.model.inverse import grid_inverse, psi_rad_core
from pipeline.model.materials import Material, load_materials, resolve_material
from pipeline.model.options import CHOICES, PRINTED, ModelOptions, make_options


def fit_k_p(
    material: str | Material,
    pressure_kpa: ArrayLike,
    psi_deg: ArrayLike,
    *,
    branch: str = "loading",
    confidence: float = 0.95,
    **options: Any,
) -> tuple[float, tuple[float, float]]:
    """Least-squares pressure scale k_P of the model to measured bending angles, as in the paper.

    Minimises sum (psi_model(P_i; k_P) - psi_i)^2 over k_P, where psi_model(P; k_P) is the inverse
    of k_P * P_raw(psi) on ``branch`` (cubic Hermite interpolation of one model grid, exact to
    well under 0.01 deg).  Model angles that are undefined (pressure beyond the modelled range)
    count as ``psi_min_deg``.

    Parameters
    ----------
    material : str or Material
    pressure_kpa, psi_deg : array_like
        Measured pressures (kPa) and angles (deg), same length, at least 2 finite pairs.
    branch : {"loading", "unloading"}
    confidence : float
        Level of the returned interval (Student t on the linearised residuals).
    **options
        Model readings, see :class:`pipeline.model.options.ModelOptions` (``k_p`` is ignored).

    Returns
    -------
    k_p : float
    ci : (float, float)
        Confidence interval of k_p.

    Raises
    ------
    pipeline.errors.UserInputError
        For mismatched lengths or fewer than two finite pairs.
    """
    mat = resolve_material(material)
    p = as_numbers(pressure_kpa, "pressure_kpa").ravel()
    psi = as_numbers(psi_deg, "psi_deg").ravel()
    if p.shape != psi.shape:
        raise UserInputError(
            f"fit_k_p: {p.size} pressures but {psi.size} angles; pass pairs of equal length"
        )
    keep = np.isfinite(p) & np.isfinite(psi) & (p >= 0)
    if keep.sum() < 2:
        raise UserInputError("fit_k_p: need at least two finite (pressure_kpa >= 0, psi_deg) pairs")
    p, psi = p[keep], psi[keep]
    options = {k: v for k, v in options.items() if k != "k_p"}
    opts = make_options(k_p=1.0, **options)
    floor = math.radians(opts.psi_min_deg)

    inverse = grid_inverse(mat, opts, branch)  # P = k P_1(psi): one grid serves every k

    def model_rad(k: float) -> np.ndarray:
        out = inverse(p / k)
        return np.where(np.isfinite(out), out, floor)

    target = np.radians(psi)

    def sse(log_k: float) -> float:
        r = model_rad(math.exp(log_k)) - target
        return float(r @ r)

    # starting point: linear least squares in pressure space, P = k * P_raw(psi)
    raw, _ = pressure_core(mat, target, opts)
    ok = np.isfinite(raw) & (raw > 0)
    k0 = float((raw[ok] @ p[ok]) / (raw[ok] @ raw[ok])) if ok.sum() else mat.k_p
    k0 = k0 if k0 > 0 and math.isfinite(k0) else mat.k_p
    logs = math.log(k0) + np.linspace(-1.5, 1.5, 31)  # coarse scan guards against local minima
    best = logs[int(np.argmin([sse(v) for v in logs]))]
    from scipy import optimize, stats  # here: scipy.stats costs a second at every import

    res = optimize.minimize_scalar(
        sse, bounds=(best - 0.1, best + 0.1), method="bounded", options={"xatol": 1e-10}
    )
    k = math.exp(float(res.x))
    h = 1e-4 * k
    jac = (model_rad(k + h) - model_rad(k - h)) / (2 * h)
    dof = max(p.size - 1, 1)
    s2 = float(res.fun) / dof
    jj = float(jac @ jac)
    se = math.sqrt(s2 / jj) if jj > 0 else math.inf
    half = float(stats.t.ppf(0.5 + confidence / 2, dof)) * se
    return k, (k - half, k + half)


#: options the search varies: every reading of the text that changes the two model results
#: (kt_scaling acts on Dragon Skin only, so those two anchors cannot choose it; eq5="as_printed"
#: has no root and wall_coords="unscaled" contradicts the text: neither is searched)
DERIVED_KEYS: tuple[str, ...] = (
    "jacobian",
    "l0_factor",
    "pressure_area",
    "thickness_phi",
    "thickness_pass",
    "stress",
    "base_width",
)

#: values that are not derivations: never candidates of the protocol
NOT_DERIVED: dict[str, tuple[str, ...]] = {
    "l0_factor": ("fitted_scale",),
    "wall_coords": ("unscaled",),
    "eq5": ("as_printed",),
}

#: the protocol, as printed by ``python -m pipeline model calibrate``
PROTOCOL: tuple[str, ...] = (
    "Selection protocol of the default reading (docs/model.md):",
    "  1. Candidates: every reading derived from the printed Eqs. 1-13 with no free constant,",
    "     all combinations of " + ", ".join(DERIVED_KEYS[:4]) + ",",
    "     " + ", ".join(DERIVED_KEYS[4:]) + " (l0_factor=fitted_scale is a fit and",
    "     wall_coords=unscaled contradicts the text: not candidates).  kt_scaling acts on Dragon",
    "     Skin only, which the two model results do not see: one_minus, the reading of the",
    "     printed k_t scaling that is defined for psi <= 0.",
    "  2. The paper's two model results (SS50 psi = 0 at 674 kPa, SS40 psi = -psi0 at 378 kPa)",
    "     fix at most one physical parameter: l0, within 170-270 mm (the l0 minimising the",
    "     worse of the two errors).  No other number is fitted to them.",
    f"  3. A candidate passes when both are within +-{MODEL_BAR_PCT:g} % at that l0.",
    "  4. Of those, the fewest departures from the printed equations wins (Eq. 4's phi is left",
    "     open by the text and not counted); ties go to the smaller worst error.",
    "  5. The Section III measured points are scored out of sample: they choose nothing.",
)


def _evaluate(anchor: Anchor, mat: Material, opts: ModelOptions) -> float:
    if anchor.kind == "pressure":
        p, _ = pressure_core(mat, np.radians([anchor.at]), opts)
        return float(p[0])
    psi = psi_rad_core(mat, np.array([anchor.at]), opts, "loading")
    return float(np.degrees(psi[0]))


def _need(table: Mapping[str, Material], names: Sequence[str], what: str) -> None:
    missing = sorted(set(names) - set(table))
    if missing:
        raise UserInputError(
            f"{what}: the materials table has no {', '.join(missing)}; the paper's model "
            "results are for SS40 and SS50, so keep those entries in your materials file"
        )


def anchor_table(materials: Mapping[str, Material] | None = None, **options: Any) -> pd.DataFrame:
    """The model beside every figure Section III reports.

    Parameters
    ----------
    materials : mapping of str to Material, optional
        Defaults to the packaged table; anchors of materials it lacks are left out.
    **options
        Model readings and ``l0_mm``, see :class:`pipeline.model.options.ModelOptions`.

    Returns
    -------
    pandas.DataFrame
        One row per anchor: ``group`` (``model``: the paper's model results, in sample;
        ``measured``: Section III data, out of sample), ``anchor``, ``material``, ``unit``
        (kPa or deg), ``at`` (the angle or pressure the value is read at), ``paper``, ``ours``,
        ``off`` (ours - paper, in ``unit``), ``pct_off`` (relative error of what the paper reports:
        the pressure, or for angles the range of motion psi0 - psi), ``paper_range_deg`` and
        ``ours_range_deg`` (angles only), ``l0_mm``.
    """
    table = dict(materials or load_materials())
    opts = make_options(**options)
    rows: list[dict[str, Any]] = []
    for anc in ANCHORS:
        if anc.material not in table:
            continue
        mat = table[anc.material]
        ours = _evaluate(anc, mat, opts)
        row: dict[str, Any] = {
            "group": anc.group,
            "anchor": anc.text,
            "material": anc.material,
            "unit": "kPa" if anc.kind == "pressure" else "deg",
            "at": anc.at,
            "paper": anc.paper,
            "ours": ours,
            "off": ours - anc.paper,
            "paper_range_deg": math.nan,
            "ours_range_deg": math.nan,
            "l0_mm": mat.l0_mm if opts.l0_mm is None else float(opts.l0_mm),
        }
        if anc.kind == "pressure":
            row["pct_off"] = 100.0 * (ours - anc.paper) / abs(anc.paper)
        else:
            paper_range = float(anc.range_deg or (mat.psi0_deg - anc.paper))
            row["paper_range_deg"] = paper_range
            row["ours_range_deg"] = mat.psi0_deg - ours
            row["pct_off"] = 100.0 * (row["ours_range_deg"] - paper_range) / paper_range
        rows.append(row)
    columns = ["group", "anchor", "material", "unit", "at", "paper", "ours", "off", "pct_off",
               "paper_range_deg", "ours_range_deg", "l0_mm"]
    return pd.DataFrame(rows, columns=columns)


def scores(table: pd.DataFrame) -> dict[str, float]:
    """Summary figures of an :func:`anchor_table`.

    Returns
    -------
    dict
        ``ss50_pct``, ``ss40_pct`` (the two model results, % off), ``model_worst_pct``,
        ``undefined_anchors`` (NaN anchors; the RMS figures skip them), ``exp_pressure_rms_pct``
        (the three measured psi = 0 pressures), ``exp_psi_rms_deg`` (the four measured angles) and
        ``exp_range_rms_pct`` (their ranges of motion).
    """
    model = table[table.group == "model"].set_index("material")
    meas = table[table.group == "measured"]
    mp, ma = meas[meas.unit == "kPa"], meas[meas.unit == "deg"]

    def rms(x: pd.Series) -> float:
        x = x.dropna()
        return float(np.sqrt(np.mean(x**2))) if len(x) else math.nan

    ss50 = float(model.pct_off.get("SS50", math.nan))
    ss40 = float(model.pct_off.get("SS40", math.nan))
    return {
        "ss50_pct": ss50,
        "ss40_pct": ss40,
        "model_worst_pct": max(abs(ss50), abs(ss40)) if math.isfinite(ss50 + ss40) else math.nan,
        "undefined_anchors": int(table.ours.isna().sum()),
        "exp_pressure_rms_pct": rms(mp.pct_off),
        "exp_psi_rms_deg": rms(ma.off),
        "exp_range_rms_pct": rms(ma.pct_off),
    }


def _model_worst(table: Mapping[str, Material], opts: ModelOptions, l0: float) -> float:
    """Worse |ours/paper - 1| of the two model results at ``l0`` (inf where undefined)."""
    o = make_options(opts, l0_mm=float(l0))
    worst = 0.0
    for anc in MODEL_ANCHORS:
        p = _evaluate(anc, table[anc.material], o)
        if not (math.isfinite(p) and p > 0):
            return math.inf
        worst = max(worst, abs(p / anc.paper - 1.0))
    return worst


def fit_l0(
    materials: Mapping[str, Material] | None = None,
    bounds: tuple[float, float] = L0_PLAUSIBLE_MM,
    **options: Any,
) -> float:
    """The l0 (mm) at which the paper's two model results are best met: step 2 of the protocol.

    Minimises the worse of the two relative errors over ``bounds``: a scan every 10 mm,
    then Brent's method around the best point (to 0.01 mm).  This is the one physical
    parameter the two anchors may fix; with ``l0_factor="fitted_scale"`` they already fix the
    scale, so fitting l0 as well is refused.

    Parameters
    ----------
    materials : mapping, optional
        Needs SS40 and SS50 (the packaged table by default).
    bounds : (float, float)
        l0 range searched (mm): the 170-270 mm the paper's grasping section implies.
    **options
        Readings (``l0_mm`` is ignored: it is what is fitted).

    Returns
    -------
    float
        l0 in mm; NaN if the anchors are undefined everywhere in ``bounds``.

    Examples
    --------
    >>> round(fit_l0())
    255
    """
    table = dict(materials or load_materials())
    _need(table, ["SS40", "SS50"], "fit_l0")
    opts = make_options(**{k: v for k, v in options.items() if k != "l0_mm"})
    if opts.l0_factor == "fitted_scale":
        raise UserInputError(
            "fit_l0: with l0_factor=fitted_scale the two model results already fix eq12_scale; "
            "they may fix at most one parameter, so pass l0_mm instead of fitting it"
        )
    lo, hi = bounds
    grid = np.linspace(lo, hi, max(2, int(round((hi - lo) / 10.0)) + 1))  # noqa: RUF046 (numpy scalar)
    values = [_model_worst(table, opts, float(v)) for v in grid]
    i = int(np.argmin(values))
    if not math.isfinite(values[i]):
        return math.nan
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    from scipy import optimize

    res = optimize.minimize_scalar(
        lambda v: _model_worst(table, opts, v), bounds=(a, b), method="bounded",
        options={"xatol": 1e-2},
    )
    best = float(res.x) if res.fun <= values[i] else float(grid[i])
    return best


def l0_interval_meeting_bar(
    materials: Mapping[str, Material] | None = None,
    bounds: tuple[float, float] = L0_PLAUSIBLE_MM,
    step_mm: float = 1.0,
    **options: Any,
) -> tuple[float, float]:
    """Smallest and largest l0 (mm, on a ``step_mm`` grid in ``bounds``) meeting the +-5 % bar.

    Shows how loosely the two model results pin l0.  ``(nan, nan)`` when no l0 does.
    """
    table = dict(materials or load_materials())
    _need(table, ["SS40", "SS50"], "l0_interval_meeting_bar")
    opts = make_options(**{k: v for k, v in options.items() if k != "l0_mm"})
    bar = MODEL_BAR_PCT / 100.0
    grid = np.arange(bounds[0], bounds[1] + 1e-9, step_mm)
    ok = [float(v) for v in grid if _model_worst(table, opts, float(v)) <= bar]
    return (min(ok), max(ok)) if ok else (math.nan, math.nan)


def fit_eq12_scale(materials: Mapping[str, Material] | None = None, **options: Any) -> float:
    """The number that, standing for Eq. 12's l0 prefactor, reproduces the paper's model results.

    This is the ``l0_factor="fitted_scale"`` option: a FIT.  Least squares on the log ratios of
    the two model anchors (SS50 straight at 674 kPa, SS40 at -psi0 at 378 kPa) with the prefactor
    dropped: the geometric mean of paper / ours.  One number fitted to two anchors, so only their
    ratio is then tested.

    Parameters
    ----------
    materials : mapping of str to Material, optional
        Defaults to the packaged table (needs SS40 and SS50).
    **options
        Readings and ``l0_mm``; ``l0_factor`` and ``eq12_scale`` are ignored.

    Returns
    -------
    float
        The dimensionless scale.

    Raises
    ------
    pipeline.errors.UserInputError
        If the table lacks SS40 or SS50.

    Examples
    --------
    >>> round(fit_eq12_scale(jacobian="none", thickness_phi="mean", l0_mm=270.0), 4)
    0.3214
    """
    table = dict(materials or load_materials())
    _need(table, ["SS40", "SS50"], "fit_eq12_scale")
    kw = {k: v for k, v in options.items() if k not in ("l0_factor", "eq12_scale")}
    opts = make_options(**kw)
    return scale_fitted_to_anchors(table["SS50"], table["SS40"], opts, opts.l0_mm)


def departures(reading: Mapping[str, str]) -> int:
    """How many options of ``reading`` differ from the printed text (:data:`PRINTED`).

    ``eq5`` and ``kt_scaling`` are not counted: as printed they have no solution (Eq. 5) or no
    wall beyond straight (k_t), so every usable reading departs from them alike.
    """
    return sum(
        1
        for key, value in reading.items()
        if key in PRINTED and key not in ("eq5", "kt_scaling") and PRINTED[key] != value
    )


def search_readings(
    keys: Sequence[str] = DERIVED_KEYS,
    bounds: tuple[float, float] = L0_PLAUSIBLE_MM,
    materials: Mapping[str, Material] | None = None,
    **fixed: Any,
) -> pd.DataFrame:
    """Steps 1-4 of the protocol: every derived combination of ``keys``, its l0, its scores.

    Parameters
    ----------
    keys : sequence of str
        Options to vary over their derived values (:data:`CHOICES` minus :data:`NOT_DERIVED`);
        the others stay at their defaults (or ``fixed``).
    bounds : (float, float)
        l0 range (mm) for :func:`fit_l0`.
    materials : mapping, optional
        Materials table (the packaged one by default).
    **fixed
        Options held fixed for every combination.

    Returns
    -------
    pandas.DataFrame
        One row per combination, ranked by the protocol (the first row is its choice when it
        passes): the readings, ``departures``, ``l0_fit_mm``, ``ss50_pct``, ``ss40_pct``,
        ``model_worst_pct``, ``passes`` (both within +-5 %), and the out-of-sample scores of
        :func:`scores` at that l0 (``exp_pressure_rms_pct``, ``exp_psi_rms_deg``,
        ``exp_range_rms_pct``, ``undefined_anchors``), which do not enter the ranking.
    """
    table = dict(materials or load_materials())
    values = [tuple(v for v in CHOICES[k] if v not in NOT_DERIVED.get(k, ())) for k in keys]
    rows = []
    for combo in itertools.product(*values):
        reading = dict(zip(keys, combo, strict=True))
        kw = {**fixed, **reading}
        l0 = fit_l0(table, bounds, **kw)
        row: dict[str, Any] = {**reading, "departures": departures(reading), "l0_fit_mm": l0}
        if math.isfinite(l0):
            row.update(scores(anchor_table(table, **kw, l0_mm=l0)))
        else:
            row.update(model_worst_pct=math.nan, undefined_anchors=len(ANCHORS))
        rows.append(row)
    df = pd.DataFrame(rows)
    df["passes"] = df["model_worst_pct"] <= MODEL_BAR_PCT
    df = df.sort_values(
        ["passes", "departures", "model_worst_pct"], ascending=[False, True, True],
        kind="stable", na_position="last",
    )
    return df.reset_index(drop=True)


def select_reading(
    search: pd.DataFrame, keys: Sequence[str] = DERIVED_KEYS
) -> dict[str, Any] | None:
    """The protocol's choice from :func:`search_readings`: readings and l0, or ``None``.

    ``None`` means no derived reading meets the bar on both model results.
    """
    passing = search[search["passes"]]
    if passing.empty:
        return None
    best = passing.iloc[0]
    return {**{k: best[k] for k in keys}, "l0_mm": float(best["l0_fit_mm"])}
