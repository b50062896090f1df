"""Aggregate blocked-force tables: force against pressure (mean +- sd per material, Fig. 7A) and
the eccentricity at the maximum pressure per material (Fig. 7B).

Input is one or more per-photo tables, each an ``eccentricity.csv`` written by
``python -m pipeline force measure`` (or just a blocked-force ``manifest.csv``: then there is
no eccentricity).  Needed columns: ``material``, ``direction``, ``pressure_kpa``, ``actuator``,
``trial``, ``force_n``; optional ``force_sd_n``, ``measured_pressure_kpa``, ``eccentricity``,
``status``.

Statistics
----------
Each row is one pressure step of one ramp: ``force_n`` is already the mean of that step's
load-cell samples.  ``force_mean_n`` / ``force_sd_n`` in the summary are the mean and the
*sample* standard deviation (ddof=1, NaN for a single row) of those per-step means across
actuators and trials at a nominal pressure -- the spread shaded in Fig. 7A.
``sample_sd_n`` is the pooled within-step spread of the load cell,
``sqrt(mean(force_sd_n**2))``.  Eccentricities count only photos whose status is ``ok``.

Examples
--------
>>> t = pd.DataFrame({"material": "DS20", "direction": "up", "pressure_kpa": [50.0, 50.0],
...                   "actuator": ["A1", "A2"], "trial": "1", "force_n": [1.0, 2.0]})
>>> force_vs_pressure(t)[["force_mean_n", "force_sd_n", "n"]].round(4).values.tolist()
[[1.5, 0.7071, 2.0]]
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import read_table

REQUIRED: tuple[str, ...] = (
    "material",
    "direction",
    "pressure_kpa",
    "actuator",
    "trial",
    "force_n",
)

FORCE_SUMMARY_COLUMNS: tuple[str, ...] = (
    "material",
    "direction",
    "pressure_kpa",
    "force_mean_n",
    "force_sd_n",
    "n",
    "n_actuators",
    "n_trials",
    "sample_sd_n",
    "measured_pressure_mean_kpa",
    "eccentricity_mean",
    "eccentricity_sd",
    "n_eccentricity",
)
ECCENTRICITY_SUMMARY_COLUMNS: tuple[str, ...] = (
    "material",
    "pressure_kpa",
    "eccentricity_mean",
    "eccentricity_sd",
    "n",
    "n_excluded",
    "force_mean_n",
    "image",
    "image_path",
    "image_eccentricity",
    "centre_x_px",
    "centre_y_px",
    "semi_major_px",
    "semi_minor_px",
    "angle_deg",
)


def read_tables(paths: Sequence[str | os.PathLike[str]]) -> pd.DataFrame:
    """Concatenate per-photo tables, checking the needed columns.

    Raises
    ------
    UserInputError
        When a file is missing, unreadable or lacks a needed column.
    """
    if not paths:
        raise UserInputError(
            "no input table given; pass one or more eccentricity.csv (or blocked manifest.csv) "
            "files"
        )
    frames = []
    for p in map(Path, paths):
        df = read_table(
            p,
            "an eccentricity.csv from 'python -m pipeline force measure' (or a blocked "
            "manifest.csv)",
            required=REQUIRED,
            hint="a blocked-force table needs force_n (newtons) per row: record with 'acquire "
                 "--mode blocked' or 'force synth'",
            dtype={"actuator": str, "trial": str, "material": str, "direction": str},
        )
        df["source"] = str(p)
        frames.append(df)
    return pd.concat(frames, ignore_index=True)


def force_vs_pressure(table: pd.DataFrame) -> pd.DataFrame:
    """Force (N) mean +- sd per material, direction and nominal pressure (kPa).

    Parameters
    ----------
    table : pandas.DataFrame
        Per-photo rows (see module docstring).  Rows without a finite ``force_n`` are ignored.

    Returns
    -------
    pandas.DataFrame
        Columns :data:`FORCE_SUMMARY_COLUMNS`, sorted by material, direction, pressure.
    """
    df = table.copy()
    df["force_n"] = pd.to_numeric(df["force_n"], errors="coerce")
    df["pressure_kpa"] = pd.to_numeric(df["pressure_kpa"], errors="coerce").round(6)
    df = df[np.isfinite(df["force_n"]) & np.isfinite(df["pressure_kpa"])]
    has_e = "eccentricity" in df.columns
    rows = []
    for (material, direction, pressure), g in df.groupby(
        ["material", "direction", "pressure_kpa"], sort=True
    ):
        force = g["force_n"].to_numpy(float)
        row: dict[str, object] = {
            "material": material,
            "direction": direction,
            "pressure_kpa": float(pressure),
            "force_mean_n": float(np.mean(force)),
            "force_sd_n": float(np.std(force, ddof=1)) if len(force) > 1 else float("nan"),
            "n": len(force),
            "n_actuators": int(g["actuator"].nunique()),
            "n_trials": int(g[["actuator", "trial"]].drop_duplicates().shape[0]),
            "sample_sd_n": _pooled_sd(g),
            "measured_pressure_mean_kpa": _mean_or_nan(g, "measured_pressure_kpa"),
        }
        e = _ok_eccentricities(g) if has_e else np.array([])
        row["eccentricity_mean"] = float(np.mean(e)) if len(e) else float("nan")
        row["eccentricity_sd"] = float(np.std(e, ddof=1)) if len(e) > 1 else float("nan")
        row["n_eccentricity"] = len(e)
        rows.append(row)
    return pd.DataFrame(rows, columns=list(FORCE_SUMMARY_COLUMNS))


def eccentricity_at_max_pressure(table: pd.DataFrame) -> pd.DataFrame:
    """Eccentricity at the highest nominal pressure of each material (paper Fig. 7B).

    Parameters
    ----------
    table : pandas.DataFrame
        Per-photo rows with ``eccentricity`` and ``status`` (an ``eccentricity.csv``).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`ECCENTRICITY_SUMMARY_COLUMNS`: mean and sample sd of the ``ok``
        eccentricities at that pressure, how many photos were excluded (flagged/failed), the
        mean force there, and a representative photo (the ok photo closest to the mean) with
        its fitted ellipse (px) for overlays.  Empty when the table has no eccentricity.
    """
    if "eccentricity" not in table.columns:
        return pd.DataFrame(columns=list(ECCENTRICITY_SUMMARY_COLUMNS))
    df = table.copy()
    df["pressure_kpa"] = pd.to_numeric(df["pressure_kpa"], errors="coerce").round(6)
    rows = []
    for material, m in df.groupby("material", sort=True):
        if not np.isfinite(m["pressure_kpa"]).any():
            continue
        p_max = float(m["pressure_kpa"].max())
        g = m[m["pressure_kpa"] == p_max]
        ok = g[_ok_mask(g)]
        e = ok["eccentricity"].to_numpy(float)
        row: dict[str, object] = {
            "material": material,
            "pressure_kpa": p_max,
            "eccentricity_mean": float(np.mean(e)) if len(e) else float("nan"),
            "eccentricity_sd": float(np.std(e, ddof=1)) if len(e) > 1 else float("nan"),
            "n": len(e),
            "n_excluded": int(len(g) - len(e)),
            "force_mean_n": float(pd.to_numeric(g["force_n"], errors="coerce").mean())
            if "force_n" in g
            else float("nan"),
        }
        if len(e):
            rep = ok.iloc[int(np.argmin(np.abs(e - np.mean(e))))]
            row["image"] = rep.get("image")
            row["image_path"] = rep.get("image_path")
            row["image_eccentricity"] = float(rep["eccentricity"])
            for key in (
                "centre_x_px",
                "centre_y_px",
                "semi_major_px",
                "semi_minor_px",
                "angle_deg",
            ):
                row[key] = float(rep[key]) if key in rep.index else float("nan")
        rows.append(row)
    return pd.DataFrame(rows, columns=list(ECCENTRICITY_SUMMARY_COLUMNS))


def _ok_mask(g: pd.DataFrame) -> pd.Series:
    e = pd.to_numeric(g["eccentricity"], errors="coerce")
    ok = np.isfinite(e)
    if "status" in g.columns:
        ok &= g["status"].astype(str) == "ok"
    return ok


def _ok_eccentricities(g: pd.DataFrame) -> np.ndarray:
    return pd.to_numeric(g.loc[_ok_mask(g), "eccentricity"], errors="coerce").to_numpy(float)


def _pooled_sd(g: pd.DataFrame) -> float:
    if "force_sd_n" not in g.columns:
        return float("nan")
    sd = pd.to_numeric(g["force_sd_n"], errors="coerce").to_numpy(float)
    sd = sd[np.isfinite(sd)]
    return float(np.sqrt(np.mean(sd**2))) if len(sd) else float("nan")


def _mean_or_nan(g: pd.DataFrame, column: str) -> float:
    if column not in g.columns:
        return float("nan")
    v = pd.to_numeric(g[column], errors="coerce")
    return float(v.mean()) if v.notna().any() else float("nan")
