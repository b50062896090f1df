"""The virtual actuator and the ramp protocol of the paper (Section II.C).

Loading branch: the analytical model ``pipeline.model.psi_deg`` (injectable), scaled per actuator
and trial: ``psi(P) = (psi0_i / psi0) * psi_model(P / k_i)`` with a rest angle ``psi0_i`` a few
degrees off and a stiffness ``k_i`` a few percent off.  Unloading branch: the loading curve at a
higher equivalent pressure ``P + 4 h P (P_peak - P) / P_peak`` (``h``: the material's hysteresis
width), so falling pressure needs less pressure for the same angle and the loop closes at 0 and
at the peak.  Past psi = 0 soft actuators bulge (curvature larger mid-length than at the ends).

Examples
--------
>>> import numpy as np
>>> def toy(material, p, branch="loading"):
...     return 210.0 - 2.0 * np.asarray(p, float)
>>> curve = loading_curve("DS20", max_kpa=300, psi_fn=toy)
>>> trial = TrialActuator("DS20", curve, psi0_deg=210.0, stiffness=1.0,
...                       behaviour=BEHAVIOURS["DS20"])
>>> ramp = plan_ramp(trial, step_kpa=50, max_kpa=260, rng=np.random.default_rng(0),
...                  photo_noise=False)
>>> ramp["pressure_kpa"].tolist()
[0.0, 50.0, 100.0, 150.0, 200.0, 250.0, 200.0, 150.0, 100.0, 50.0, 0.0]
>>> ramp["stop_reason"].iloc[0], bool(ramp["psi_deg"].iloc[7] < ramp["psi_deg"].iloc[3])
('minus_psi0', True)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError

PsiFunction = Callable[..., Any]
"""``psi_fn(material, pressure_kpa, branch="loading") -> array of psi (deg)``."""

#: resolution of the tabulated loading curve (kPa)
GRID_STEP_KPA = 0.25


@dataclass(frozen=True)
class ActuatorBehaviour:
    """Variability and hysteresis of one material's actuators (all seeded where used).

    Attributes
    ----------
    hysteresis : float
        Width h of the hysteresis loop, 0-0.25 (fraction of the peak pressure saved on the way
        down at mid-ramp).
    psi0_sd_deg : float
        Actuator-to-actuator standard deviation of the rest angle psi0 (deg).
    stiffness_sd : float
        Actuator-to-actuator relative standard deviation of the stiffness.
    trial_psi0_sd_deg, trial_stiffness_sd : float
        The same from one trial to the next of one actuator.
    photo_sd_deg : float
        Photo-to-photo scatter of psi (deg): creep, settling, friction on the table.
    bulge_max : float
        Curvature non-uniformity reached at psi = -psi0 (0 for stiff silicones); it grows
        linearly from 0 at psi = 0.
    """

    hysteresis: float = 0.08
    psi0_sd_deg: float = 3.0
    stiffness_sd: float = 0.04
    trial_psi0_sd_deg: float = 1.0
    trial_stiffness_sd: float = 0.015
    photo_sd_deg: float = 0.5
    bulge_max: float = 0.0

    def __post_init__(self) -> None:
        if not 0 <= self.hysteresis <= 0.25:
            raise UserInputError(f"hysteresis = {self.hysteresis!r} must be within 0..0.25")
        if not 0 <= self.bulge_max < 1:
            raise UserInputError(f"bulge_max = {self.bulge_max!r} must be within [0, 1)")
        for f in dataclasses.fields(self):
            if getattr(self, f.name) < 0:
                raise UserInputError(f"{f.name} = {getattr(self, f.name)!r} must be >= 0")


#: softer silicones: more hysteresis, less repeatable, bulge past psi = 0 (paper Section III.A)
BEHAVIOURS: dict[str, ActuatorBehaviour] = {
    "DS20": ActuatorBehaviour(
        hysteresis=0.15,
        psi0_sd_deg=4.0,
        stiffness_sd=0.05,
        trial_stiffness_sd=0.03,
        photo_sd_deg=1.5,
        bulge_max=0.35,
    ),
    "DS30": ActuatorBehaviour(
        hysteresis=0.12,
        psi0_sd_deg=3.5,
        stiffness_sd=0.05,
        trial_stiffness_sd=0.025,
        photo_sd_deg=1.2,
        bulge_max=0.25,
    ),
    "SS40": ActuatorBehaviour(
        hysteresis=0.06,
        psi0_sd_deg=3.0,
        stiffness_sd=0.03,
        trial_stiffness_sd=0.01,
        photo_sd_deg=0.6,
    ),
    "SS50": ActuatorBehaviour(
        hysteresis=0.03,
        psi0_sd_deg=2.0,
        stiffness_sd=0.02,
        trial_stiffness_sd=0.008,
        photo_sd_deg=0.4,
    ),
}


def behaviour_for(material: str, **overrides: float) -> ActuatorBehaviour:
    """The behaviour of a material (defaults for unknown ones) with some fields overridden."""
    return dataclasses.replace(BEHAVIOURS.get(material, ActuatorBehaviour()), **overrides)


@dataclass(frozen=True)
class LoadingCurve:
    """The model's loading branch tabulated on a fine pressure grid.

    Attributes
    ----------
    pressure_kpa, psi_deg : ndarray
        Grid and angles; NaN gaps inside the range (snap-through) are bridged linearly.
    limit_kpa : float
        Highest pressure with a modelled angle (beyond it the ramp stops).
    psi0_deg : float
        Modelled rest angle psi(0).
    """

    pressure_kpa: NDArray[np.float64]
    psi_deg: NDArray[np.float64]
    limit_kpa: float
    psi0_deg: float

    def __call__(self, pressure_kpa: ArrayLike) -> NDArray[np.float64]:
        """psi (deg) at the given pressures; NaN above :attr:`limit_kpa`."""
        p = np.asarray(pressure_kpa, dtype=float)
        out = np.interp(p, self.pressure_kpa, self.psi_deg)
        return np.where((p > self.limit_kpa + 1e-9) | (p < 0), np.nan, out)


def _model_psi_fn() -> PsiFunction:
    from pipeline.model import psi_deg  # imported when first needed: the model loads its tables

    return psi_deg


def loading_curve(
    material: str, *, max_kpa: float, psi_fn: PsiFunction | None = None
) -> LoadingCurve:
    """Tabulate the loading branch psi(P) of ``material`` from 0 to ``max_kpa``.

    Parameters
    ----------
    material : str
        Material name understood by ``psi_fn``.
    max_kpa : float
        Highest pressure needed (include headroom for stiffer-than-nominal actuators).
    psi_fn : callable, optional
        ``psi_fn(material, pressure_kpa, branch="loading")``; default ``pipeline.model.psi_deg``.

    Raises
    ------
    UserInputError
        If the model has no finite angle at 0 kPa.
    """
    fn = psi_fn or _model_psi_fn()
    grid = np.arange(0.0, max_kpa + GRID_STEP_KPA, GRID_STEP_KPA)
    psi = np.asarray(fn(material, grid, branch="loading"), dtype=float)
    finite = np.isfinite(psi)
    if not finite[0]:
        raise UserInputError(
            f"material {material!r}: the model gives no angle at 0 kPa; check the material name"
        )
    last = int(np.flatnonzero(finite)[-1])
    grid, psi, finite = grid[: last + 1], psi[: last + 1], finite[: last + 1]
    psi = np.interp(grid, grid[finite], psi[finite])  # bridge snap-through gaps
    return LoadingCurve(
        pressure_kpa=grid, psi_deg=psi, limit_kpa=float(grid[-1]), psi0_deg=float(psi[0])
    )


@dataclass(frozen=True)
class TrialActuator:
    """One actuator in one trial: its own rest angle and stiffness on the model's curve.

    Attributes
    ----------
    material : str
    curve : LoadingCurve
    psi0_deg : float
        Rest angle of this actuator in this trial (deg).
    stiffness : float
        Pressure scale (1 = the model; 1.05 needs 5 % more pressure for the same angle).
    behaviour : ActuatorBehaviour
    """

    material: str
    curve: LoadingCurve
    psi0_deg: float
    stiffness: float
    behaviour: ActuatorBehaviour

    def psi_loading_deg(self, pressure_kpa: ArrayLike) -> NDArray[np.float64]:
        """Angle on the loading branch (rising pressure), deg; NaN beyond the model."""
        return (
            self.psi0_deg
            / self.curve.psi0_deg
            * self.curve(np.asarray(pressure_kpa, float) / self.stiffness)
        )

    def psi_unloading_deg(self, pressure_kpa: ArrayLike, peak_kpa: float) -> NDArray[np.float64]:
        """Angle on the way down from ``peak_kpa``: the loading angle at a higher equivalent
        pressure."""
        p = np.asarray(pressure_kpa, float)
        if peak_kpa <= 0:
            return self.psi_loading_deg(p)
        h = self.behaviour.hysteresis
        return self.psi_loading_deg(p + 4.0 * h * p * (peak_kpa - p) / peak_kpa)

    def bulge(self, psi_deg: ArrayLike) -> NDArray[np.float64]:
        """Curvature non-uniformity at an angle: 0 for psi >= 0, up to ``bulge_max`` at -psi0."""
        frac = np.clip(-np.asarray(psi_deg, float) / self.psi0_deg, 0.0, 1.0)
        return self.behaviour.bulge_max * frac


def draw_actuator(
    material: str, curve: LoadingCurve, behaviour: ActuatorBehaviour, rng: np.random.Generator
) -> tuple[float, float]:
    """Draw one actuator's (psi0_deg, stiffness) around the model's values."""
    psi0 = curve.psi0_deg + rng.normal(0.0, behaviour.psi0_sd_deg)
    stiffness = float(np.exp(rng.normal(0.0, behaviour.stiffness_sd)))
    return float(psi0), stiffness


def draw_trial(
    material: str,
    curve: LoadingCurve,
    behaviour: ActuatorBehaviour,
    actuator: tuple[float, float],
    rng: np.random.Generator,
) -> TrialActuator:
    """One trial of an actuator: its (psi0, stiffness) plus trial-to-trial scatter."""
    psi0 = actuator[0] + rng.normal(0.0, behaviour.trial_psi0_sd_deg)
    stiffness = actuator[1] * float(np.exp(rng.normal(0.0, behaviour.trial_stiffness_sd)))
    return TrialActuator(material, curve, float(psi0), stiffness, behaviour)


def ramp_pressures(
    trial: TrialActuator, *, step_kpa: float, max_kpa: float
) -> tuple[NDArray[np.float64], str]:
    """Pressures of the rising half of the protocol and why it stopped.

    Pressure rises from 0 in ``step_kpa`` steps up to ``max_kpa`` (the last step is clipped to
    it) or until psi reaches -psi0 of this actuator, whichever comes first; it also stops at the
    last step the model can describe.

    Returns
    -------
    pressures : ndarray
        Rising pressures, 0 first, peak last.
    stop_reason : str
        ``"max_pressure"``, ``"minus_psi0"`` or ``"model_limit"``.
    """
    if not step_kpa > 0 or not max_kpa > 0:
        raise UserInputError(
            f"step_kpa = {step_kpa!r} and max_kpa = {max_kpa!r} must be positive pressures in kPa"
        )
    n = int(np.ceil(max_kpa / step_kpa - 1e-9))
    levels = np.minimum(np.arange(n + 1, dtype=float) * float(step_kpa), float(max_kpa))
    psi = trial.psi_loading_deg(levels)
    for k, (p, a) in enumerate(zip(levels, psi)):
        if not np.isfinite(a):
            return levels[:k], "model_limit"
        if a <= -trial.psi0_deg:
            return levels[: k + 1], "minus_psi0"
    return levels, "max_pressure"


def plan_ramp(trial: TrialActuator, *, step_kpa: float, max_kpa: float, rng: np.random.Generator,
              photo_noise: bool = True) -> pd.DataFrame:
    """Every photo of one up-and-down ramp with its true angle.

    Parameters
    ----------
    trial : TrialActuator
    step_kpa, max_kpa : float
        Protocol (see :func:`ramp_pressures`).
    rng : numpy.random.Generator
        Photo-to-photo scatter.
    photo_noise : bool
        Add the behaviour's photo-to-photo scatter.

    Returns
    -------
    pandas.DataFrame
        Columns ``step, pressure_kpa, direction, psi_deg, psi_branch_deg, bulge, stop_reason,
        peak_kpa, psi0_deg, stiffness, hysteresis``; rising photos (peak included) then falling.
    """
    up, reason = ramp_pressures(trial, step_kpa=step_kpa, max_kpa=max_kpa)
    peak = float(up[-1])
    down = up[:-1][::-1]
    psi_branch = np.concatenate([trial.psi_loading_deg(up), trial.psi_unloading_deg(down, peak)])
    scatter = rng.normal(0.0, trial.behaviour.photo_sd_deg, len(psi_branch)) if photo_noise else 0.0
    psi = psi_branch + scatter
    return pd.DataFrame({
        "step": np.arange(len(psi)),
        "pressure_kpa": np.concatenate([up, down]),
        "direction": ["up"] * len(up) + ["down"] * len(down),
        "psi_deg": psi,
        "psi_branch_deg": psi_branch,
        "bulge": trial.bulge(psi),
        "stop_reason": reason,
        "peak_kpa": peak,
        "psi0_deg": trial.psi0_deg,
        "stiffness": trial.stiffness,
        "hysteresis": trial.behaviour.hysteresis,
    })
