"""Pressure profiles for continuous recordings: a triangular ramp or a staircase of steps.

The same profile drives the real rig (``acquire --record video``) and the synthetic video
(:mod:`pipeline.synth.video`), so both are described by the same few numbers.

``ramp``
    0 -> ``max_kpa`` -> 0 at ``rate_kpa_s``, ``cycles`` times.
``steps``
    0, ``step_kpa``, 2 ``step_kpa``, ..., ``max_kpa`` and back down to 0, each level held for
    ``hold_s`` (a step response at every level, on both branches).

Examples
--------
>>> p = PressureProfile("ramp", max_kpa=100, rate_kpa_s=50)
>>> p.duration_s, [float(p.setpoint_kpa(t)) for t in (0, 1, 2, 3, 4)]
(4.0, [0.0, 50.0, 100.0, 50.0, 0.0])
>>> s = PressureProfile("steps", max_kpa=20, step_kpa=10, hold_s=2)
>>> s.duration_s, [float(s.setpoint_kpa(t)) for t in (0, 2.5, 4.1, 6, 9.9)]
(10.0, [0.0, 10.0, 20.0, 10.0, 0.0])
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pipeline.errors import UserInputError

PROFILES: tuple[str, ...] = ("ramp", "steps")


@dataclass(frozen=True)
class PressureProfile:
    """Setpoint against time (see the module docstring); validated on creation.

    Attributes
    ----------
    kind : {"ramp", "steps"}
    max_kpa : float
        Top of the profile (kPa).
    rate_kpa_s : float
        Ramp rate (kPa/s), ``ramp`` only.
    step_kpa, hold_s : float
        Step height (kPa) and hold per level (s), ``steps`` only.
    cycles : int
        Repetitions of the whole profile.
    """

    kind: str
    max_kpa: float
    rate_kpa_s: float = 5.0
    step_kpa: float = 20.0
    hold_s: float = 4.0
    cycles: int = 1

    def __post_init__(self) -> None:
        problems = []
        if self.kind not in PROFILES:
            problems.append(f"profile {self.kind!r} is unknown; use one of {list(PROFILES)}")
        for name in ("max_kpa", "rate_kpa_s", "step_kpa", "hold_s"):
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
                problems.append(f"{name} = {value!r} must be a positive number")
        if not (isinstance(self.cycles, int) and self.cycles >= 1):
            problems.append(f"cycles = {self.cycles!r} must be a whole number >= 1")
        if problems:
            raise UserInputError("; ".join(problems))

    def levels_kpa(self) -> NDArray[np.float64]:
        """Setpoints of one ``steps`` cycle in order: up to ``max_kpa`` (reached exactly) and
        back."""
        n = math.floor(self.max_kpa / self.step_kpa + 1e-9)
        up = [i * self.step_kpa for i in range(n + 1)]
        if self.max_kpa - up[-1] > 1e-6:
            up.append(self.max_kpa)
        return np.array(up + up[-2::-1], dtype=float)

    @property
    def cycle_s(self) -> float:
        """Duration of one cycle (s)."""
        if self.kind == "ramp":
            return 2.0 * self.max_kpa / self.rate_kpa_s
        return float(len(self.levels_kpa()) * self.hold_s)

    @property
    def duration_s(self) -> float:
        """Duration of the whole profile (s)."""
        return float(self.cycles * self.cycle_s)

    def setpoint_kpa(self, t_s: ArrayLike) -> NDArray[np.float64]:
        """Setpoint (kPa) at times ``t_s`` (s from the start); 0 before the start and after the
        end."""
        t = np.asarray(t_s, float)
        inside = (t >= 0) & (t < self.duration_s)
        u = np.mod(np.where(inside, t, 0.0), self.cycle_s)
        if self.kind == "ramp":
            half = self.cycle_s / 2
            p = np.where(u <= half, u, self.cycle_s - u) * self.rate_kpa_s
        else:
            levels = self.levels_kpa()
            p = levels[np.minimum((u / self.hold_s + 1e-9).astype(int), len(levels) - 1)]
        return np.where(inside, p, 0.0)

    def step_times_s(self) -> NDArray[np.float64]:
        """Times (s) at which a ``steps`` profile changes level (empty for a ramp)."""
        if self.kind != "steps":
            return np.empty(0)
        n = len(self.levels_kpa())
        return np.array(
            [c * self.cycle_s + i * self.hold_s for c in range(self.cycles) for i in range(1, n)]
        )
