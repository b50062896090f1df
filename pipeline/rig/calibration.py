"""Calibration of the regulator: achieved pressure (kPa) against DAC code, and its YAML file.

A calibration is a table of points ``(dac_code, pressure_kpa)`` measured on the rig (by the
regulator's monitor output or a reference gauge).  With two points (or ``method="linear"``) the
map is the least-squares straight line; with ``method="piecewise"`` it interpolates linearly
between points (for a regulator that is not linear), holding the end slopes beyond them.

File format (YAML)::

    method: linear            # or piecewise
    points:                   # at least two, distinct codes
      - {dac_code: 0, pressure_kpa: 0.0}
      - {dac_code: 2048, pressure_kpa: 247.1}
    max_kpa: 260              # optional host-side limit (kPa), applied with --max-kpa
    load_counts_per_newton:   # optional HX711 scale sent to the device with SCALE
    device: circact-pico 1.1  # free text: where it was measured

Examples
--------
>>> cal = fit_calibration([0, 4095], [0.0, 500.0])
>>> cal.kpa_to_code(250.0)
2048
>>> round(cal.code_to_kpa(2048), 2)
250.06
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from pipeline.errors import UserInputError
from pipeline.fileio import atomic_write_bytes

METHODS = ("linear", "piecewise")
DAC_MAX = 4095


@dataclass(frozen=True)
class Calibration:
    """Pressure against DAC code.

    Attributes
    ----------
    dac_code : tuple of int
        Codes of the calibration points, increasing.
    pressure_kpa : tuple of float
        Pressure achieved at each code (kPa).
    method : str
        ``"linear"`` or ``"piecewise"``.
    max_kpa : float or None
        Host-side limit stored with the calibration (kPa).
    load_counts_per_newton : float or None
        HX711 scale to send to the device.
    device : str
        Free text naming the device measured.
    """

    dac_code: tuple[int, ...]
    pressure_kpa: tuple[float, ...]
    method: str = "linear"
    max_kpa: float | None = None
    load_counts_per_newton: float | None = None
    device: str = ""

    def _line(self) -> tuple[float, float]:
        slope, intercept = np.polyfit(
            np.asarray(self.dac_code, float), np.asarray(self.pressure_kpa, float), 1
        )
        return float(slope), float(intercept)

    def code_to_kpa(self, code: float) -> float:
        """Pressure (kPa) the regulator reaches at DAC ``code``."""
        if self.method == "linear":
            slope, intercept = self._line()
            return slope * code + intercept
        x, y = np.asarray(self.dac_code, float), np.asarray(self.pressure_kpa, float)
        if code < x[0]:
            return float(y[0] + (code - x[0]) * (y[1] - y[0]) / (x[1] - x[0]))
        if code > x[-1]:
            return float(y[-1] + (code - x[-1]) * (y[-1] - y[-2]) / (x[-1] - x[-2]))
        return float(np.interp(code, x, y))

    def kpa_to_code(self, kpa: float) -> int:
        """Nearest DAC code (0..4095) reaching ``kpa``; 0 kPa always gives code 0 (vent)."""
        if kpa <= 0:
            return 0
        if self.method == "linear":
            slope, intercept = self._line()
            code = (kpa - intercept) / slope
        else:
            x, y = np.asarray(self.dac_code, float), np.asarray(self.pressure_kpa, float)
            if kpa < y[0]:
                code = x[0] + (kpa - y[0]) * (x[1] - x[0]) / (y[1] - y[0])
            elif kpa > y[-1]:
                code = x[-1] + (kpa - y[-1]) * (x[-1] - x[-2]) / (y[-1] - y[-2])
            else:
                code = float(np.interp(kpa, y, x))
        return int(min(max(round(code), 0), DAC_MAX))


def fit_calibration(
    dac_code: Any, pressure_kpa: Any, method: str | None = None, **extra: Any
) -> Calibration:
    """Build a calibration from measured points.

    Parameters
    ----------
    dac_code, pressure_kpa : array-like
        Codes sent and pressures measured (same length, at least 2 distinct codes).
    method : {"linear", "piecewise"} or None
        ``None``: linear for two points, piecewise for more.
    **extra
        ``max_kpa``, ``load_counts_per_newton``, ``device``.

    Raises
    ------
    UserInputError
        Too few points, repeated codes, or a pressure that does not increase with the code.
    """
    codes = np.asarray(dac_code, dtype=float)
    kpa = np.asarray(pressure_kpa, dtype=float)
    if codes.shape != kpa.shape or codes.size < 2:
        raise UserInputError(
            "calibration needs at least two (dac_code, pressure_kpa) points of equal count"
        )
    if not (np.all(np.isfinite(codes)) and np.all(np.isfinite(kpa))):
        raise UserInputError("calibration points must be finite numbers")
    order = np.argsort(codes)
    codes, kpa = codes[order], kpa[order]
    if np.any(np.diff(codes) <= 0):
        raise UserInputError(
            "calibration points repeat a dac_code; keep one reading per code (or average them)"
        )
    method = method or ("linear" if codes.size == 2 else "piecewise")
    if method not in METHODS:
        raise UserInputError(f"calibration method {method!r} is unknown; use one of {METHODS}")
    if method == "piecewise" and np.any(np.diff(kpa) <= 0):
        bad = int(np.argmax(np.diff(kpa) <= 0))
        raise UserInputError(
            f"calibration pressure does not increase between codes {int(codes[bad])} and "
            f"{int(codes[bad + 1])} "
            f"({kpa[bad]:.1f} -> {kpa[bad + 1]:.1f} kPa); points at the supply limit cannot be "
            "calibrated: "
            "drop them or use method linear"
        )
    cal = Calibration(tuple(int(c) for c in codes), tuple(float(p) for p in kpa), method, **extra)
    if method == "linear" and cal._line()[0] <= 0:
        raise UserInputError(
            "calibration slope is not positive: the pressure must rise with the DAC code"
        )
    return cal


def read_calibration(path: str | os.PathLike[str]) -> Calibration:
    """Read a calibration file (format in the module docstring).

    Raises
    ------
    UserInputError
        When the file is missing or malformed, naming the key and the fix.
    """
    path = Path(path)
    if not path.is_file():
        raise UserInputError(
            f"{path}: calibration file not found; create it with 'python -m pipeline rig calibrate "
            f"--port PORT --out {path}'"
        )
    try:
        raw = yaml.safe_load(path.read_text()) or {}
        points = raw["points"]
        codes = [p["dac_code"] for p in points]
        kpa = [p["pressure_kpa"] for p in points]
    except (yaml.YAMLError, KeyError, TypeError) as exc:
        raise UserInputError(
            f"{path}: not a calibration file ({exc!r}); it needs 'points: [{{dac_code: ..., "
            f"pressure_kpa: ...}}, ...]'"
        ) from exc
    extra = {k: raw.get(k) for k in ("max_kpa", "load_counts_per_newton")}
    for key, value in extra.items():
        if value is not None and not (isinstance(value, (int, float)) and value > 0):
            raise UserInputError(f"{path}: {key} = {value!r} must be a positive number or absent")
    try:
        return fit_calibration(
            codes, kpa, raw.get("method"), device=str(raw.get("device", "")), **extra
        )
    except UserInputError as exc:
        raise UserInputError(f"{path}: {exc}") from exc


def write_calibration(path: str | os.PathLike[str], cal: Calibration) -> None:
    """Write a calibration file atomically."""
    data: dict[str, Any] = {
        "method": cal.method,
        "points": [
            {"dac_code": int(c), "pressure_kpa": round(float(p), 4)}
            for c, p in zip(cal.dac_code, cal.pressure_kpa)
        ],
        "max_kpa": cal.max_kpa,
        "load_counts_per_newton": cal.load_counts_per_newton,
        "device": cal.device,
    }
    atomic_write_bytes(Path(path), yaml.safe_dump(data, sort_keys=False).encode())
