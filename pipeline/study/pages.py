"""Report pages of the study: ``figures(bench_dir)`` reads the CSV tables and draws them.

Draws nothing for a table that is missing, so a partial study still gives the pages it can; a
table that is present but unreadable stops the report with an error naming the file.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from pipeline.fileio import read_table
from pipeline.study import charts

#: the tables a bench directory holds (written by ``python -m pipeline bench study``)
TABLES: tuple[str, ...] = (
    "speed_accuracy.csv", "stability.csv", "breakdown.csv", "repeatability.csv", "model_choice.csv",
    "model_cost.csv",
)


def _read(bench_dir: Path, name: str) -> pd.DataFrame | None:
    path = Path(bench_dir) / name
    return (
        read_table(path, f"the bench's {name} (rerun 'python -m pipeline bench study')")
        if path.is_file()
        else None
    )


def figures(bench_dir: Path) -> list[Figure]:
    """The bench pages: speed/accuracy, stability panels, breakdown/repeatability/model-choice
    tables and model accuracy against cost.

    Parameters
    ----------
    bench_dir : Path
        Output directory of ``python -m pipeline bench study``.

    Returns
    -------
    list of matplotlib.figure.Figure
        In report order; empty when the directory holds none of the tables.
    """
    bench_dir = Path(bench_dir)
    out: list[Figure] = []
    sa = _read(bench_dir, "speed_accuracy.csv")
    if sa is not None and not sa.empty:
        out.append(charts.speed_accuracy_figure(sa))
    stab = _read(bench_dir, "stability.csv")
    if stab is not None and not stab.empty:
        out.append(charts.stability_figure(stab))
    bd, choice, rep = (
        _read(bench_dir, n) for n in ("breakdown.csv", "model_choice.csv", "repeatability.csv")
    )
    if any(t is not None for t in (bd, choice, rep)):
        empty = pd.DataFrame()
        out.append(
            charts.tables_figure(
                bd if bd is not None else empty,
                choice if choice is not None else empty,
                rep if rep is not None else empty,
            )
        )
    cost = _read(bench_dir, "model_cost.csv")
    if cost is not None:
        out.append(charts.model_cost_figure(cost))
    return out
