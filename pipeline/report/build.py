"""Assemble the report PDF with byte-identical output for identical inputs.

Determinism: no creation date (``CreationDate`` None, ``SOURCE_DATE_EPOCH`` ignored), fonts shipped
with matplotlib embedded as TrueType, photos decoded and resized with fixed settings, pages drawn
from input content only (no paths of temporary files, no clock).  Each ``python -m pipeline report``
run writes the same bytes for the same inputs, and so do repeated builds in one process: numbers
are written with 6 decimals (see :func:`pdf_float_decimals`).
"""

from __future__ import annotations

import contextlib
import io
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg", force=False)
import matplotlib.pyplot as plt
from matplotlib.backends import backend_pdf
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from pipeline import __version__
from pipeline.fileio import atomic_write_bytes
from pipeline.report.data import ReportData, ReportInputs, load_report_data
from pipeline.report.extra import extra_pages
from pipeline.report.model_page import add_comparison_note, model_provenance_page
from pipeline.report.pages import (
    comparison_page,
    material_page,
    overview_page,
    summary_lines,
    text_pages,
)
from pipeline.report.style import report_style


@dataclass(frozen=True)
class ReportResult:
    """What was written."""

    path: Path
    pages: int
    materials: tuple[str, ...]
    warnings: tuple[str, ...]


#: decimals of the numbers matplotlib writes into the PDF (it writes 10; paths already use 6)
PDF_FLOAT_DECIMALS = 6


@contextlib.contextmanager
def pdf_float_decimals(decimals: int = PDF_FLOAT_DECIMALS) -> Iterator[None]:
    """Write PDF numbers with ``decimals`` digits while the context is open (restored afterwards).

    Matplotlib computes positions with BLAS/SIMD arithmetic whose last bit can depend on memory
    alignment, so a coordinate may come out 1 ulp apart in two processes; written with 10 decimals
    that occasionally changes a digit (a 1e-10 pt move) and the bytes.  1e-6 pt (4e-7 mm) is far
    below anything visible and makes such flips vanishingly rare.
    """
    original = backend_pdf.pdfRepr

    def pdf_repr(obj: object) -> bytes:
        if isinstance(obj, (float, np.floating)) and np.isfinite(obj):
            text = (b"%.*f" % (decimals, float(obj))).rstrip(b"0").rstrip(b".")
            return b"0" if text in (b"", b"-0", b"-") else text
        return original(obj)

    backend_pdf.pdfRepr = pdf_repr
    try:
        yield
    finally:
        backend_pdf.pdfRepr = original


def render_pdf(figures: list[Figure], title: str) -> bytes:
    """Save figures as pages of one PDF; no timestamps, so the bytes depend on the figures only."""
    buf = io.BytesIO()
    metadata = {"Title": title, "Creator": f"pipeline {__version__}", "CreationDate": None}
    saved_epoch = os.environ.pop("SOURCE_DATE_EPOCH", None)  # would re-introduce a date
    try:
        with pdf_float_decimals(), PdfPages(buf, metadata=metadata) as pdf:
            for i, fig in enumerate(figures, start=1):
                fig.text(0.99, 0.004, f"{title} | page {i} of {len(figures)}", ha="right", va="bottom",
                         fontsize=6.5, color="0.4")
                pdf.savefig(fig)
    finally:
        if saved_epoch is not None:
            os.environ["SOURCE_DATE_EPOCH"] = saved_epoch
    return buf.getvalue()


def report_figures(data: ReportData) -> tuple[list[Figure], list[str]]:
    """Every page in order, and the warnings printed on the summary page."""
    bench = extra_pages("pipeline.bench.pages", data.inputs.bench_dir)
    force = extra_pages("pipeline.force.pages", data.inputs.force_dir)
    videos = [extra_pages("pipeline.video.pages", d) for d in data.inputs.video_dirs]  # one page per video dataset
    warnings = bench.warnings + force.warnings + [w for v in videos for w in v.warnings]
    if data.inputs.model_curves:
        for m in data.materials:
            if not (data.model_curves["material"].astype(str) == m).any():
                warnings.append(f"{m}: no model curve in --model-curves; its plot has no dashed model line")
    for m in data.materials:
        if not (data.rms["material"].astype(str) == m).any():
            warnings.append(f"{m}: no row in --rms; its comparison values show n/a")
    for d in data.inputs.datasets:
        for label, folder in (("--photosets", d.photoset_dir), ("--overlays", d.overlays_dir)):
            if folder is not None and not folder.is_dir():
                warnings.append(f"{d.name}: {label} folder {folder} does not exist")
    config_digest = data.digests.get(str(data.inputs.config)) if data.inputs.config is not None else None
    lines = summary_lines(data, __version__, config_digest, warnings, bench.infos + force.infos + [i for v in videos for i in v.infos])
    figures = text_pages(data.inputs.title, lines)
    figures.append(overview_page(data))
    figures += [material_page(data, m) for m in data.materials]
    comparison = comparison_page(data)
    add_comparison_note(comparison, data)  # self-checks named; which l0, what was fitted: next page
    figures += [comparison] + [f for f in [model_provenance_page(data)] if f is not None]
    return figures + [f for v in videos for f in v.figures] + bench.figures + force.figures, warnings


def build_report(inputs: ReportInputs, out: str | os.PathLike[str]) -> ReportResult:
    """Load the inputs, draw every page and write the PDF atomically.

    Parameters
    ----------
    inputs : ReportInputs
    out : path-like
        The PDF to write (parent folders are created).

    Returns
    -------
    ReportResult
    """
    data = load_report_data(inputs)
    with report_style():
        figures, warnings = report_figures(data)
        try:
            pdf = render_pdf(figures, inputs.title)
        finally:
            for fig in figures:
                plt.close(fig)
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, pdf)
    return ReportResult(path=path, pages=len(figures), materials=tuple(data.materials), warnings=tuple(warnings))
