"""The ramp protocol and what an output folder already holds (so a re-run resumes).

Ramp (paper Section II.C): 0 kPa, up in steps of ``step_kpa`` to ``max_kpa`` (the last step may
be smaller so ``max_kpa`` itself is reached), then down through the same pressures to 0 kPa.
When live measurement stops the up leg early at step ``peak`` (psi reached -psi0), the down
leg starts from there.  Steps are numbered 0, 1, ... within a trial; the peak is the last
``up`` step and is photographed once.

Examples
--------
>>> ramp_pressures(10, 25)
[0.0, 10.0, 20.0, 25.0]
>>> [(s.step, s.pressure_kpa, s.direction) for s in trial_sequence(1, [0.0, 10.0, 20.0], peak=2)]
[(0, 0.0, 'up'), (1, 10.0, 'up'), (2, 20.0, 'up'), (3, 10.0, 'down'), (4, 0.0, 'down')]
>>> image_name("DS20", "A1", 2, 3, 12.5, "down", ".jpg")
'DS20_A1_t2_s003_down_12p5kPa.jpg'
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from pipeline.errors import UserInputError
from pipeline.photoset import MANIFEST, SETTINGS, read_settings


@dataclass(frozen=True)
class StepPlan:
    """One photo of the ramp: trial (1-based), step (0-based), setpoint (kPa), direction."""

    trial: int
    step: int
    pressure_kpa: float
    direction: str


def ramp_pressures(step_kpa: float, max_kpa: float) -> list[float]:
    """Up-leg setpoints (kPa): 0, step, 2 step, ..., max_kpa.

    Raises
    ------
    UserInputError
        If ``step_kpa`` or ``max_kpa`` is not positive.
    """
    if not (step_kpa > 0 and max_kpa > 0):
        raise UserInputError(f"--step-kpa ({step_kpa}) and --max-kpa ({max_kpa}) must be positive")
    n = int(np.floor(max_kpa / step_kpa + 1e-9))
    levels = [round(i * step_kpa, 6) for i in range(n + 1)]
    if max_kpa - levels[-1] > 1e-6:
        levels.append(round(float(max_kpa), 6))
    return [float(v) for v in levels]


def trial_sequence(trial: int, up_kpa: list[float], peak: int | None = None) -> list[StepPlan]:
    """All steps of one trial with the up leg ending at index ``peak`` (default: the last level)."""
    peak = len(up_kpa) - 1 if peak is None else peak
    up = [StepPlan(trial, i, up_kpa[i], "up") for i in range(peak + 1)]
    down = [StepPlan(trial, peak + 1 + j, p, "down") for j, p in enumerate(reversed(up_kpa[:peak]))]
    return up + down


def pressure_label(pressure_kpa: float) -> str:
    """Pressure for a file name: ``12.5`` -> ``12p5``, ``40.0`` -> ``40``."""
    return f"{pressure_kpa:g}".replace(".", "p")


def image_name(
    material: str,
    actuator: str,
    trial: int,
    step: int,
    pressure_kpa: float,
    direction: str,
    suffix: str,
) -> str:
    """File name of one photo (unique per material, actuator, trial and step)."""
    pressure = pressure_label(pressure_kpa)
    return f"{material}_{actuator}_t{trial}_s{step:03d}_{direction}_{pressure}kPa{suffix}"


def recorded_steps(folder: str | os.PathLike[str], material: str, actuator: str) -> pd.DataFrame:
    """Manifest rows already recorded for ``material``/``actuator`` whose image file exists.

    Returns
    -------
    pandas.DataFrame
        Columns of the manifest plus integer ``trial_n`` and ``step_n``; empty when the folder
        holds no manifest yet.  A row whose image is missing does not count (it is re-taken).

    Raises
    ------
    UserInputError
        If the manifest exists but lacks the ``step`` column this protocol relies on.
    """
    folder = Path(folder)
    path = folder / MANIFEST
    if not path.is_file():
        return pd.DataFrame(columns=["image", "direction", "trial_n", "step_n"])
    df = pd.read_csv(path, dtype=str)
    if "step" not in df.columns:
        raise UserInputError(
            f"{path}: has no 'step' column, so it was not written by acquire; use a new --out "
            "folder"
        )
    df = df[(df["material"] == material) & (df["actuator"] == actuator)].copy()
    df["trial_n"] = pd.to_numeric(df["trial"], errors="coerce")
    df["step_n"] = pd.to_numeric(df["step"], errors="coerce")
    exists = df["image"].map(lambda name: isinstance(name, str) and (folder / name).is_file())
    return df[exists & df["trial_n"].notna() & df["step_n"].notna()].astype(
        {"trial_n": int, "step_n": int}
    )


def known_peak(rows: pd.DataFrame, n_levels: int) -> int | None:
    """Peak step of a trial fixed by its recorded rows (the step before the first ``down`` row)."""
    down = rows.loc[rows["direction"] == "down", "step_n"]
    if down.empty:
        return None
    return int(min(down.min() - 1, n_levels - 1))


def recorded_mismatch(rows: pd.DataFrame, sequence: list[StepPlan]) -> str | None:
    """How the recorded rows of a trial disagree with the planned ``sequence`` (a resume with
    another ``--step-kpa`` or ``--max-kpa`` would mix two ramps in one trial), or ``None``.

    Examples
    --------
    >>> seq = trial_sequence(1, [0.0, 10.0, 20.0])
    >>> rows = pd.DataFrame({"step_n": [0, 1], "pressure_kpa": ["0", "20"],
    ...                      "direction": ["up", "up"]})
    >>> recorded_mismatch(rows, seq)
    'step 1 was taken at 20 kPa up, where this ramp has 10 kPa up'
    >>> recorded_mismatch(rows.iloc[:1], seq) is None
    True
    """
    planned = {p.step: p for p in sequence}
    for _, row in rows.sort_values("step_n").iterrows():
        plan = planned.get(int(row["step_n"]))
        try:
            kpa = float(row["pressure_kpa"])
        except (TypeError, ValueError):
            continue  # a hand-edited cell: the photo set's own check names it
        taken = f"step {int(row['step_n'])} was taken at {kpa:g} kPa {row['direction']}"
        if plan is None:
            return f"{taken}, past the end of this ramp"
        if abs(plan.pressure_kpa - kpa) > 1e-6 or plan.direction != row["direction"]:
            return f"{taken}, where this ramp has {plan.pressure_kpa:g} kPa {plan.direction}"
    return None


def first_missing(sequence: list[StepPlan], recorded: set[int]) -> int | None:
    """Index in ``sequence`` of the first step not recorded, or ``None`` when the trial is
    complete."""
    for i, plan in enumerate(sequence):
        if plan.step not in recorded:
            return i
    return None


def approach_path(sequence: list[StepPlan], start: int) -> list[float]:
    """Setpoints (kPa) to pass through, without photos, before resuming at ``sequence[start]``.

    Starting from a vented rig, the actuator is brought along the same pressure history as an
    uninterrupted ramp (up through the recorded up steps, then down to the resume point), so a
    resumed ``down`` step sees the same hysteresis branch.
    """
    return [p.pressure_kpa for p in sequence[1:start]]


def check_settings(folder: str | os.PathLike[str], settings: dict[str, Any]) -> bool:
    """Whether ``photoset.yaml`` must be written; refuse a folder whose settings disagree.

    Returns
    -------
    bool
        ``True`` when the folder has no ``photoset.yaml`` yet.

    Raises
    ------
    UserInputError
        If an existing ``photoset.yaml`` has a different value for one of ``settings``.
    """
    path = Path(folder) / SETTINGS
    if not path.is_file():
        return True
    old = read_settings(folder)
    for key, value in settings.items():
        if value is None:
            continue
        have = old.get(key)
        same = (
            np.allclose(np.asarray(have, float), np.asarray(value, float), rtol=1e-6)
            if isinstance(value, (int, float, list, tuple)) and have is not None and have != "auto"
            else have == value
        )
        if not same:
            raise UserInputError(
                f"{path}: {key} is {have!r} but this run gives {value!r}; use the same options as "
                "the run that "
                "created the folder (to resume) or a new --out folder"
            )
    return False
