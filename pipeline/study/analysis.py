"""Tables of the speed/accuracy and stability study, from the per-image results of :mod:`run`.

Every function here is pure: a DataFrame in, a DataFrame out.  The input is the long table
written by :func:`pipeline.study.run.run_grid` (one row per image and method) with at least the
columns ``case_id, kind, condition, value, nominal, psi_true_deg, bulge, seed, method, psi_deg,
abs_error_deg, status, degree, seconds, decode_seconds``.  ``seconds`` is the time per image
as ``python -m pipeline measure`` spends it (file read + JPEG decode + measurement, one core);
``decode_seconds`` the first decode alone (part of ``seconds``).

Definitions used throughout
---------------------------
failure
    ``status == "failed"`` (or no angle at all).  Error statistics are taken over the images
    that did *not* fail, so a method cannot look accurate by failing on the hard images: the
    failure rate sits next to them.
silent wrong
    ``status == "ok"`` and an absolute error above :data:`SILENT_WRONG_DEG`: a wrong number
    without a warning, the worst outcome.
breakdown point
    Scanning the sweep values outward from the nominal value (nearest first), the first value
    where the 95th-percentile absolute error exceeds :data:`BREAKDOWN_P95_DEG` or any image
    failed.
Pareto front
    Within one condition, the methods that no other method beats on both time per image and
    95th-percentile error.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

#: p95 absolute error (deg) above which a method is said to have broken down
BREAKDOWN_P95_DEG = 2.0
#: an "ok" row with an error above this (deg) is a silent wrong number
SILENT_WRONG_DEG = 5.0
#: the condition name given to the nominal scenes (psi sweep restricted to |psi| <= 300 deg)
NOMINAL = "nominal"
#: |psi| (deg) range of the nominal scenes
NOMINAL_PSI_MAX_DEG = 300.0


# ---------------------------------------------------------------------------------------------
# small functions with known answers (unit-tested on crafted data)


def pareto_front(
    time_s: Sequence[float] | np.ndarray, error_deg: Sequence[float] | np.ndarray
) -> np.ndarray:
    """Mark the points no other point beats on both time and error (both: smaller is better).

    A point is dominated when another point is no worse on both axes and strictly better on
    at least one.  Points with a NaN coordinate are never on the front and dominate nothing.

    Parameters
    ----------
    time_s : array_like, shape (N,)
        Time per image (s).
    error_deg : array_like, shape (N,)
        Error measure, e.g. the 95th-percentile absolute error (deg).

    Returns
    -------
    ndarray of bool, shape (N,)
        True for the points on the front.

    Examples
    --------
    >>> pareto_front([1.0, 2.0, 3.0, 2.5], [5.0, 1.0, 0.5, 2.0]).tolist()
    [True, True, True, False]
    """
    t = np.asarray(time_s, dtype=float)
    e = np.asarray(error_deg, dtype=float)
    if t.shape != e.shape or t.ndim != 1:
        raise ValueError("time_s and error_deg must be 1-D arrays of the same length")
    valid = np.isfinite(t) & np.isfinite(e)
    no_worse = (t[None, :] <= t[:, None]) & (e[None, :] <= e[:, None])
    better = (t[None, :] < t[:, None]) | (e[None, :] < e[:, None])
    dominated = (no_worse & better & valid[None, :]).any(axis=1)
    return valid & ~dominated


def breakdown_point(
    values: Sequence[float] | np.ndarray,
    p95_error_deg: Sequence[float] | np.ndarray,
    failure_rate: Sequence[float] | np.ndarray,
    nominal: float,
    *,
    threshold_deg: float = BREAKDOWN_P95_DEG,
) -> tuple[float, str]:
    """First sweep value, going outward from ``nominal``, where a method breaks down.

    A value breaks the method when its 95th-percentile absolute error exceeds ``threshold_deg``
    or any image failed (``failure_rate > 0``), or when no image gave an angle (p95 is NaN).
    Values are scanned by increasing distance from ``nominal``; on a tie (two values the same
    distance either side) the smaller value comes first.

    Parameters
    ----------
    values : array_like
        Sweep values (any order).
    p95_error_deg, failure_rate : array_like
        Per value, the 95th-percentile absolute error (deg) and the failure rate (0..1).
    nominal : float
        The nominal value of the swept condition.
    threshold_deg : float
        Error limit (deg).

    Returns
    -------
    value : float
        The breakdown value, NaN when the method never breaks down over the sweep.
    reason : str
        ``"failure"``, ``"p95 > 2 deg"`` (with the threshold used) or ``""``.

    Examples
    --------
    >>> breakdown_point([0, 1, 2, 4, 8], [0.2, 0.4, 1.0, 3.0, 9.0], [0, 0, 0, 0, 0.5], nominal=0)
    (4.0, 'p95 > 2 deg')
    >>> breakdown_point([100, 80, 60, 40], [0.1, 0.1, 0.1, 0.1], [0, 0, 0, 0.2], nominal=100)
    (40.0, 'failure')
    """
    v = np.asarray(values, dtype=float)
    p95 = np.asarray(p95_error_deg, dtype=float)
    fail = np.asarray(failure_rate, dtype=float)
    if not (v.shape == p95.shape == fail.shape):
        raise ValueError("values, p95_error_deg and failure_rate must have the same length")
    order = np.lexsort((v, np.abs(v - nominal)))
    for i in order:
        if fail[i] > 0:
            return float(v[i]), "failure"
        if not np.isfinite(p95[i]) or p95[i] > threshold_deg:
            return float(v[i]), f"p95 > {threshold_deg:g} deg"
    return float("nan"), ""


# ---------------------------------------------------------------------------------------------
# tables


def _error_stats(group: pd.DataFrame) -> pd.Series:
    failed = group["status"].eq("failed") | group["psi_deg"].isna()
    err = group.loc[~failed, "abs_error_deg"].to_numpy(dtype=float)
    ok = group["status"].eq("ok")
    return pd.Series(
        {
            "n": len(group),
            "median_abs_error_deg": float(np.median(err)) if err.size else np.nan,
            "p95_abs_error_deg": float(np.percentile(err, 95)) if err.size else np.nan,
            "max_abs_error_deg": float(err.max()) if err.size else np.nan,
            "failure_rate": float(failed.mean()),
            "flagged_rate": float(group["status"].eq("flagged").mean()),
            "silent_wrong_rate": float((ok & (group["abs_error_deg"] > SILENT_WRONG_DEG)).mean()),
            "median_ms_per_image": 1e3 * float(group["seconds"].median()),
            "median_decode_ms": 1e3 * float(group["decode_seconds"].median()),
        }
    )


def with_nominal(results: pd.DataFrame) -> pd.DataFrame:
    """Append the nominal scenes as their own condition :data:`NOMINAL`.

    They are the rows of the ``psi`` sweep with ``|psi| <= NOMINAL_PSI_MAX_DEG`` (all other
    knobs at their nominal values), relabelled; the original rows are kept.
    """
    sel = results[
        (results["condition"] == "psi") & (results["psi_true_deg"].abs() <= NOMINAL_PSI_MAX_DEG)
    ]
    return pd.concat([results, sel.assign(condition=NOMINAL)], ignore_index=True)


def speed_accuracy(results: pd.DataFrame) -> pd.DataFrame:
    """Per method and condition: error, failure rate, time per image, Pareto front.

    Parameters
    ----------
    results : DataFrame
        Per-image results (see module docstring); only ``kind == "sweep"`` rows are used, plus
        the :data:`NOMINAL` condition built by :func:`with_nominal`.

    Returns
    -------
    DataFrame
        Columns ``condition, method, n, median_abs_error_deg, p95_abs_error_deg,
        max_abs_error_deg, failure_rate, flagged_rate, silent_wrong_rate, median_ms_per_image,
        median_decode_ms, pareto``, the nominal condition first.
    """
    sweeps = with_nominal(results[results["kind"] == "sweep"])
    table = (
        sweeps.groupby(["condition", "method"], sort=False)[list(sweeps.columns)]
        .apply(_error_stats)
        .reset_index()
    )
    table["n"] = table["n"].astype(int)
    table["pareto"] = False
    for idx in table.groupby("condition", sort=False).groups.values():
        sub = table.loc[idx]
        table.loc[idx, "pareto"] = pareto_front(
            sub["median_ms_per_image"], sub["p95_abs_error_deg"]
        )
    first = table["condition"].eq(NOMINAL)
    return pd.concat([table[first], table[~first]], ignore_index=True)


def stability(results: pd.DataFrame) -> pd.DataFrame:
    """Per method, condition and sweep value: error and failure rate against the sweep.

    Returns
    -------
    DataFrame
        Columns ``condition, value, nominal, method, n, median_abs_error_deg,
        p95_abs_error_deg, max_abs_error_deg, failure_rate, flagged_rate, silent_wrong_rate,
        median_ms_per_image, median_decode_ms``, sorted by condition (grid order), value, method.
    """
    sweeps = results[results["kind"] == "sweep"]
    table = (
        sweeps.groupby(["condition", "value", "nominal", "method"], sort=False)[
            list(sweeps.columns)
        ]
        .apply(_error_stats)
        .reset_index()
    )
    table["n"] = table["n"].astype(int)
    cond_order = {c: i for i, c in enumerate(dict.fromkeys(sweeps["condition"]))}
    meth_order = {m: i for i, m in enumerate(dict.fromkeys(sweeps["method"]))}
    key = table["condition"].map(cond_order) * 1e9 + table["method"].map(meth_order)
    return (
        table.assign(_k=key)
        .sort_values(["_k", "value"], kind="stable")
        .drop(columns="_k")[
            ["condition", "value", "nominal", "method"]
            + [c for c in table.columns if c not in ("condition", "value", "nominal", "method")]
        ]
        .reset_index(drop=True)
    )


def breakdown(stab: pd.DataFrame, *, threshold_deg: float = BREAKDOWN_P95_DEG) -> pd.DataFrame:
    """Breakdown point per method and condition (see :func:`breakdown_point`).

    Parameters
    ----------
    stab : DataFrame
        Output of :func:`stability`.

    Returns
    -------
    DataFrame
        Columns ``condition, method, nominal, breakdown_value, reason, last_good_value,
        n_values, n_bad_values, bad_values`` (``bad_values``: every breaking value, ``;``
        separated, so a method that recovers further out is visible).
    """
    rows = []
    for (cond, method), g in stab.groupby(["condition", "method"], sort=False):
        nominal = float(g["nominal"].iloc[0])
        value, reason = breakdown_point(
            g["value"],
            g["p95_abs_error_deg"],
            g["failure_rate"],
            nominal,
            threshold_deg=threshold_deg,
        )
        bad = (g["failure_rate"] > 0) | ~(g["p95_abs_error_deg"] <= threshold_deg)
        if np.isfinite(value):
            dist = np.abs(g["value"] - nominal)
            closer = g[dist < abs(value - nominal)]
            last_good = (
                closer.loc[(closer["value"] - nominal).abs().idxmax(), "value"]
                if len(closer)
                else np.nan
            )
            # the last good value on the same side as the breakdown
            same_side = closer[np.sign(closer["value"] - nominal) == np.sign(value - nominal)]
            if len(same_side):
                last_good = same_side.loc[(same_side["value"] - nominal).abs().idxmax(), "value"]
        else:
            last_good = np.nan
        rows.append(
            {
                "condition": cond,
                "method": method,
                "nominal": nominal,
                "breakdown_value": value,
                "reason": reason,
                "last_good_value": float(last_good),
                "n_values": len(g),
                "n_bad_values": int(bad.sum()),
                "bad_values": ";".join(f"{v:g}" for v in g.loc[bad, "value"]),
            }
        )
    return pd.DataFrame(rows)


def repeatability(results: pd.DataFrame) -> pd.DataFrame:
    """Spread of each method over the same scene rendered with different noise seeds.

    Returns
    -------
    DataFrame
        Columns ``psi_true_deg, method, n_seeds, n_failed, mean_psi_deg, bias_deg, sd_deg,
        range_deg, robust_sd_deg`` (1.4826 x median absolute deviation: insensitive to a single
        outlier), ``n_ok, sd_ok_deg`` (over the images with status ``ok`` only).
    """
    rep = results[results["kind"] == "repeat"]
    rows = []
    for (psi, method), g in rep.groupby(["psi_true_deg", "method"], sort=False):
        good = g[~(g["status"].eq("failed") | g["psi_deg"].isna())]
        x = good["psi_deg"].to_numpy(dtype=float)
        x_ok = g.loc[g["status"].eq("ok"), "psi_deg"].to_numpy(dtype=float)
        rows.append(
            {
                "psi_true_deg": float(psi),
                "method": method,
                "n_seeds": len(g),
                "n_failed": len(g) - len(good),
                "mean_psi_deg": float(x.mean()) if x.size else np.nan,
                "bias_deg": float(x.mean() - psi) if x.size else np.nan,
                "sd_deg": float(x.std(ddof=1)) if x.size > 1 else np.nan,
                "range_deg": float(np.ptp(x)) if x.size else np.nan,
                "robust_sd_deg": float(1.4826 * np.median(np.abs(x - np.median(x))))
                if x.size
                else np.nan,
                "n_ok": int(x_ok.size),
                "sd_ok_deg": float(x_ok.std(ddof=1)) if x_ok.size > 1 else np.nan,
            }
        )
    return pd.DataFrame(rows)


def model_choice(results: pd.DataFrame, *, methods: Sequence[str] = ("turning", "auto"),
                 richer_than: int = 1) -> pd.DataFrame:
    """Which curve model each adaptive estimator chose, per condition and sweep value.

    The truth is non-constant curvature exactly when the scene was rendered with ``bulge > 0``.
    A choice is *consistent* when the estimator stayed with the constant-curvature model
    (degree ``<= richer_than``) on constant-curvature scenes and chose a richer one on
    non-constant scenes; ``consistent`` in the table is the share of images that were.
    (A tilted camera makes the imaged arc slightly non-circular: scenes count as constant
    curvature by the rendered centre line, as a user would expect.)

    Parameters
    ----------
    results : DataFrame
        Per-image results with a ``degree`` column (polynomial degree of theta(s); 1 means
        constant curvature).
    methods : sequence of str
        The adaptive methods (those absent from ``results`` are skipped).
    richer_than : int
        Degree of the constant-curvature model.

    Returns
    -------
    DataFrame
        Columns ``method, condition, value, bulge, truth_constant_curvature, n,
        degree_counts, share_richer, consistent``; empty when no method exposes a degree.
    """
    columns = [
        "method",
        "condition",
        "value",
        "bulge",
        "truth_constant_curvature",
        "n",
        "degree_counts",
        "share_richer",
        "consistent",
    ]
    sel = results[
        results["method"].isin(list(methods))
        & (results["kind"] == "sweep")
        & results["degree"].notna()
    ]
    rows = []
    for (method, cond, value, bulge), g in sel.groupby(
        ["method", "condition", "value", "bulge"], sort=False
    ):
        deg = g["degree"].astype(int)
        richer = deg > richer_than
        constant = bool(bulge == 0)
        rows.append(
            {
                "method": method,
                "condition": cond,
                "value": float(value),
                "bulge": float(bulge),
                "truth_constant_curvature": constant,
                "n": len(g),
                "degree_counts": ";".join(
                    f"{d}:{c}" for d, c in sorted(deg.value_counts().items())
                ),
                "share_richer": float(richer.mean()),
                "consistent": float((~richer).mean() if constant else richer.mean()),
            }
        )
    return pd.DataFrame(rows, columns=columns)


def model_choice_summary(choice: pd.DataFrame) -> pd.DataFrame:
    """Per adaptive method: share of constant-curvature images given a richer model than an
    arc, and share of bulged images given one.

    Returns
    -------
    DataFrame
        Columns ``method, n_constant, richer_on_constant, n_bulged, richer_on_bulged`` (NaN
        shares when there are no such images).
    """
    rows = []
    for method, g in choice.groupby("method", sort=False):
        row: dict[str, object] = {"method": method}
        for key, mask in (("constant", g["truth_constant_curvature"].astype(bool)),
                          ("bulged", ~g["truth_constant_curvature"].astype(bool))):
            sub = g[mask]
            n = int(sub["n"].sum())
            row[f"n_{key}"] = n
            row[f"richer_on_{key}"] = (
                float((sub["share_richer"] * sub["n"]).sum() / n) if n else float("nan")
            )
        rows.append(row)
    return pd.DataFrame(
        rows, columns=["method", "n_constant", "richer_on_constant", "n_bulged", "richer_on_bulged"]
    )


def model_cost(**kwargs: object) -> pd.DataFrame:
    """Model quadrature grid size against error and time (:mod:`pipeline.study.model_cost`).

    Parameters
    ----------
    **kwargs
        Passed to :func:`pipeline.study.model_cost.benchmark_model` (grid sizes, repeats, ...).

    Returns
    -------
    DataFrame
        Columns ``grid_n, seconds, max_rel_error`` first, then whatever else the model
        benchmark reports (node counts, forward/inverse split, inverse error in deg).
    """
    from pipeline.study.model_cost import benchmark_model

    table = benchmark_model(**kwargs)  # type: ignore[arg-type]
    first = ["grid_n", "seconds", "max_rel_error"]
    return table[first + [c for c in table.columns if c not in first]]
