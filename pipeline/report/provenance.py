"""The last page(s): what the report was made from (software, configuration, every input's
sha256)."""

from __future__ import annotations

import dataclasses
import platform
from collections.abc import Sequence
from importlib import metadata

from matplotlib.figure import Figure

from pipeline.layout.style import text_page
from pipeline.layout.typeset import MONO, Column, Flow, Table, rows_that_fit
from pipeline.report.data import ReportData
from pipeline.report.summary import calibration_summary

#: libraries whose versions can change a number or a pixel of the report
LIBRARIES: tuple[str, ...] = (
    "numpy",
    "pandas",
    "scipy",
    "opencv-python-headless",
    "opencv-python",
    "matplotlib",
)


def library_versions() -> list[str]:
    """``name version`` of each installed library of :data:`LIBRARIES`."""
    out = []
    for name in LIBRARIES:
        try:
            out.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            continue
    return out


def provenance_pages(
    data: ReportData, version: str, infos: Sequence[str], warnings: Sequence[str] = ()
) -> list[Figure]:
    """Software, configuration and the sha256 of every input file (portrait A4, as many pages as
    needed)."""
    fig = text_page(label="provenance")
    flow = Flow(fig, top_pt=36.0)
    flow.text("Provenance", size=14.0, weight="bold")
    flow.space(2.0)
    flow.text(
        f"pipeline {version}, Python {platform.python_version()}; "
        + ", ".join(library_versions())
        + ".",
        size=8.0,
    )
    flow.text(
        "The same inputs give the same PDF, byte for byte: nothing on any page comes from the "
        "clock or the "
        "machine.  Each photo set's folder (its photos, manifest.csv, photoset.yaml and any other "
        "file in it) has one sha256 over every file's path, size and sha256: a photo replaced or "
        "edited changes it.",
        size=8.0,
        color="0.25",
    )
    for line in list(data.notes) + list(infos):
        flow.text(line, size=8.0, color="0.25")
    for line in warnings:
        flow.text(f"WARNING: {line}", size=8.0, color="#b00000")
    for style, line in calibration_summary(data):
        flow.text(
            f"Camera calibration: {line}", size=8.0, color="#b00000" if style == "w" else "0.25"
        )
    flow.space(4.0)
    pages = [fig]
    # how the angles were taken (the advisor's first question of a photo set), then the inputs
    measured = tuple((d.name, d.settings) for d in data.datasets if d.settings)
    tables = (
        (
            (Column("Dataset", "left", wrap_pt=100.0), Column("Settings", "left", wrap_pt=380.0)),
            measured,
            (
                "How each photo set was measured (photoset.yaml; the manifest's per-row "
                "settings; for a body what was not given; the method angles.csv names)"
            ),
        ),
        (
            (
                Column("Input", "left", wrap_pt=100.0),
                Column("File", "left", wrap_pt=110.0),
                Column("sha256", "left", family=MONO),
            ),
            tuple((f.role, f.path, f.sha256) for f in data.files),
            "Input files",
        ),
    )
    fresh = False  # a page with nothing on it yet
    for columns, rows, title in tables:
        first = True
        while rows:
            table = Table(
                columns=columns,
                rows=rows,
                title=title + ("" if first else " (continued)"),
                size=7.0,
            )
            k = rows_that_fit(table, flow.width, flow.remaining_pt)
            if k == 0 and fresh:
                raise ValueError(f"a row of {title!r} does not fit on a page")
            if k:
                flow.table(dataclasses.replace(table, rows=rows[:k]))
                flow.space(4.0)
                rows, first, fresh = rows[k:], False, False
            if rows:
                fig = text_page(label="provenance (continued)")
                flow = Flow(fig, top_pt=36.0)
                pages.append(fig)
                fresh = True
    return pages
