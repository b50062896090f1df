"""Grasp logs: a CSV a lab fills in by hand, and the heaviest mass held against pressure (Fig. 8B).

Log format (one row per grasp attempt; header names as below, any extra column such as
``comment`` is kept and ignored):

=============  =========================================================================
column         meaning
=============  =========================================================================
material       actuator material, e.g. ``DS20``
object         what was grasped (free text, e.g. ``ring 90 mm ID``)
side           ``inside`` (actuator inside the object) or ``outside``
diameter_mm    the object's diameter at the grasp (inner for inside, outer for outside), mm
mass_g         mass of the object with its load, g
pressure_kpa   input pressure while holding, kPa (gauge, >= 0)
held           ``yes``/``no`` (also ``true``/``false``, ``1``/``0``, ``y``/``n``)
=============  =========================================================================

Examples
--------
>>> log = read_grasp_log(EXAMPLE_LOG)
>>> s = heaviest_held(log)
>>> int(s.query("material == 'SS50'")["max_mass_held_g"].max())
1000
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.fileio import read_table

#: the example log shipped with the package (values transcribed from the paper's text, Fig. 8B/8C)
EXAMPLE_LOG = Path(__file__).with_name("data") / "grasp_example.csv"

GRASP_COLUMNS: tuple[str, ...] = (
    "material",
    "object",
    "side",
    "diameter_mm",
    "mass_g",
    "pressure_kpa",
    "held",
)
SIDES: tuple[str, ...] = ("inside", "outside")
_HELD_WORDS: dict[str, bool] = {
    "yes": True, "y": True, "true": True, "1": True, "1.0": True,
    "no": False, "n": False, "false": False, "0": False, "0.0": False,
}

SUMMARY_COLUMNS: tuple[str, ...] = (
    "material", "side", "diameter_mm", "pressure_kpa", "max_mass_held_g", "n_attempts", "n_held",
)


def read_grasp_log(path: str | os.PathLike[str]) -> pd.DataFrame:
    """Read and validate a grasp log; refuse it listing every bad row.

    Parameters
    ----------
    path : path
        The CSV file.

    Returns
    -------
    pandas.DataFrame
        The log with typed columns: ``diameter_mm``, ``mass_g``, ``pressure_kpa`` floats,
        ``held`` bool, ``side`` lower-case, plus ``log_line`` (1-based line in the file).

    Raises
    ------
    UserInputError
        When the file is missing or unreadable, a column is missing, or any row is invalid
        (every problem is listed with its line number and the fix).
    """
    path = Path(path)
    raw = read_table(path, "the grasp-log CSV the lab filled in", dtype=str, keep_default_na=False,
                     skipinitialspace=True)
    raw.columns = [str(c).strip().lower() for c in raw.columns]
    missing = [c for c in GRASP_COLUMNS if c not in raw.columns]
    if missing:
        raise UserInputError(
            f"{path}: missing column(s) {missing}; the header must contain "
            f"{', '.join(GRASP_COLUMNS)}"
        )
    if raw.empty:
        raise UserInputError(f"{path}: no rows; add one row per grasp attempt")
    return validate_grasp_log(raw, source=str(path))


def validate_grasp_log(raw: pd.DataFrame, *, source: str = "grasp log") -> pd.DataFrame:
    """Type and check a grasp log read as strings (see :func:`read_grasp_log`).

    Parameters
    ----------
    raw : pandas.DataFrame
        Columns of :data:`GRASP_COLUMNS` as strings (extra columns kept).
    source : str
        File name used in error messages.

    Returns
    -------
    pandas.DataFrame

    Raises
    ------
    UserInputError
        Listing every bad row as ``<source> line N, column C: problem (fix: ...)``.
    """
    problems: list[str] = []
    out = raw.copy()
    out["log_line"] = np.arange(len(out), dtype=int) + 2
    held_values: list[bool] = []
    numbers: dict[str, list[float]] = {"diameter_mm": [], "mass_g": [], "pressure_kpa": []}
    fixes = {
        "diameter_mm": "write the object's diameter in mm, e.g. 90",
        "mass_g": "write the mass in grams, e.g. 700",
        "pressure_kpa": "write the gauge pressure in kPa, e.g. 40",
    }
    for i, row in out.iterrows():
        line = int(row["log_line"])
        where = f"{source} line {line}"
        for key in ("material", "object"):
            if str(row[key]).strip() == "":
                problems.append(f"{where}, column {key}: empty (fix: fill in the {key})")
        side = str(row["side"]).strip().lower()
        if side not in SIDES:
            problems.append(
                f"{where}, column side: {row['side']!r} (fix: write 'inside' or 'outside')"
            )
        out.at[i, "side"] = side
        for key, values in numbers.items():
            text = str(row[key]).strip()
            try:
                value = float(text)
            except ValueError:
                value = float("nan")
            if not np.isfinite(value):
                problems.append(
                    f"{where}, column {key}: {text!r} is not a number (fix: {fixes[key]})"
                )
            elif value < 0 or (value == 0 and key != "pressure_kpa"):
                problems.append(
                    f"{where}, column {key}: {value:g} must be "
                    f"{'>= 0' if key == 'pressure_kpa' else '> 0'} (fix: {fixes[key]})"
                )
            values.append(value)
        word = str(row["held"]).strip().lower()
        if word not in _HELD_WORDS:
            problems.append(f"{where}, column held: {row['held']!r} (fix: write yes or no)")
        held_values.append(_HELD_WORDS.get(word, False))
    if problems:
        raise UserInputError(
            f"{source}: {len(problems)} problem(s) in the grasp log:\n  " + "\n  ".join(problems)
        )
    for key, values in numbers.items():
        out[key] = np.asarray(values, dtype=float)
    out["held"] = np.asarray(held_values, dtype=bool)
    out["material"] = out["material"].str.strip()
    out["object"] = out["object"].str.strip()
    return out


def heaviest_held(log: pd.DataFrame) -> pd.DataFrame:
    """Heaviest mass held per material, side, object diameter and pressure.

    Parameters
    ----------
    log : pandas.DataFrame
        A validated log (:func:`read_grasp_log`).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`SUMMARY_COLUMNS`; ``max_mass_held_g`` is NaN where no attempt at that
        pressure held (e.g. the actuator buckled), sorted by material, side, diameter, pressure.
    """
    keys = ["material", "side", "diameter_mm", "pressure_kpa"]
    rows = []
    for key, g in log.groupby(keys, sort=True):
        held = g.loc[g["held"], "mass_g"]
        rows.append(
            dict(
                zip(keys, key),
                max_mass_held_g=float(held.max()) if len(held) else float("nan"),
                n_attempts=len(g),
                n_held=len(held),
            )
        )
    return pd.DataFrame(rows, columns=list(SUMMARY_COLUMNS))

