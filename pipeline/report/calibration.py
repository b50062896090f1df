"""The report's "Camera calibration" lines: which photo sets were measured on a calibrated plane.

Read from the ``calibration_px`` / ``calibration_mm`` columns of angles.csv (the reprojection error
of each row's calibration, empty when the row was measured in the image), so the report states
what the measurement actually used.

Examples
--------
>>> import pandas as pd
>>> a = pd.DataFrame({"dataset": ["lab", "lab", "old"], "calibration_px": [0.05, 0.05, None],
...                   "calibration_mm": [0.014, 0.014, None]})
>>> for style, text in calibration_lines(a, ["lab", "old"]):
...     print(style, text)
h Camera calibration
b lab: calibrated, 2 of 2 photos; reprojection error 0.05 px (0.014 mm on the plane)
b old: not calibrated: psi measured in the image as seen (no correction for the camera's tilt)
"""

from __future__ import annotations

import textwrap
from collections.abc import Sequence

import pandas as pd

from pipeline.measure.calibration import MAX_RMS_PX

#: characters per line (the summary page's width)
WRAP_CHARS = 100


def calibration_lines(angles: pd.DataFrame, datasets: Sequence[str]) -> list[tuple[str, str]]:
    """(style, text) lines for the summary page: a heading, then one line per dataset.

    Parameters
    ----------
    angles : pandas.DataFrame
        All angles rows with a ``dataset`` column (the dataset name).
    datasets : sequence of str
        Dataset names, in report order.

    Returns
    -------
    list of (str, str)
        ``("h", heading)``, then ``("b", text)`` or ``("w", warning)`` per dataset.
    """
    out: list[tuple[str, str]] = [("h", "Camera calibration")]
    for style, text in _dataset_lines(angles, datasets):
        out += [(style, part) for part in textwrap.wrap(text, WRAP_CHARS, subsequent_indent="    ")]
    return out


def _dataset_lines(angles: pd.DataFrame, datasets: Sequence[str]) -> list[tuple[str, str]]:
    lines: list[tuple[str, str]] = []
    for name in datasets:
        rows = angles[angles["dataset"] == name]
        if "calibration_px" not in rows.columns:
            lines.append(
                ("b", f"{name}: unknown (angles.csv written before calibration was recorded)")
            )
            continue
        px = pd.to_numeric(rows["calibration_px"], errors="coerce")
        mm = pd.to_numeric(
            rows.get("calibration_mm", pd.Series(index=rows.index, dtype=float)), errors="coerce"
        )
        n = int(px.notna().sum())
        if n == 0:
            lines.append(
                (
                    "b",
                    (
                        f"{name}: not calibrated: psi measured in the image as seen (no "
                        "correction for the camera's tilt)"
                    ),
                )
            )
            continue
        errors = sorted(
            {
                (round(float(p), 3), round(float(m), 4))
                for p, m in zip(px[px.notna()], mm[px.notna()])
            }
        )
        text = ", ".join(f"{p:.2f} px ({m:.3f} mm on the plane)" for p, m in errors)
        worst = max(p for p, _ in errors)
        lines.append(
            (
                "w" if worst > MAX_RMS_PX else "b",
                f"{name}: calibrated, {n} of {len(rows)} photos; reprojection error {text}"
                + (
                    f" -- above {MAX_RMS_PX:g} px, those rows are flagged"
                    if worst > MAX_RMS_PX
                    else ""
                ),
            )
        )
    return lines
