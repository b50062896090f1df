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
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.backends import backend_pdf
from matplotlib.backends.backend_pdf import PdfPages
from matplotlib.figure import Figure

from pipeline import __version__
from pipeline.fileio import atomic_write_bytes
from pipeline.force import pages as force_pages
from pipeline.layout.style import FOOTER_PT, material_colors, report_style
from pipeline.report.data import (
    ReportData,
    ReportInputs,
    force_inputs,
    load_report_data,
    modelled_materials,
)
from pipeline.report.model_page import model_provenance_page
from pipeline.report.pages import comparison_page, material_page, overview_page
from pipeline.report.provenance import provenance_pages
from pipeline.report.summary import opposite_bending_warnings, summary_page
from pipeline.report.textcheck import FOOTER_GID
from pipeline.study import pages as study_pages
from pipeline.video import pages as video_pages

#: what each page is, for the contents list on page 1 (by figure label; first page of a run of
#: pages)
CONTENTS: dict[str, str] = {
    "overview": "All materials (as Fig. 6)",
    "material": "One page per material: curves, table, photos",
    "comparison": "Comparison with the model and the paper",
    "model-curves": "Which model curve and l0; fitted or predicted",
    "speed-accuracy": "Angle methods: speed against accuracy",
    "stability": "Angle methods: stability, where each breaks",
    "bench-tables": "Angle methods: breakdown, repeatability tables",
    "model-cost": "Model: accuracy against cost",
    "force": "Blocked force and eccentricity (Fig. 7A)",
    "eccentricity": "Eccentricity at the highest pressure (Fig. 7B)",
    "grasp": "Grasping: heaviest mass held (Fig. 8B)",
    "video": "One page per video: every frame, loops, steps",
    "provenance": "Provenance: software, config, sha256 of inputs",
}


#: what the pages from each folder option are, in words, for the provenance page
SOURCE_WORDS: dict[str, str] = {
    "--bench-dir": "the angle-method benchmark",
    "--force-dir": "blocked force and grasping",
    "--video-dirs": "a video dataset",
}


@dataclass(frozen=True)
class ReportResult:
    """What was written, and how long each part took (wall seconds; they never reach the PDF)."""

    path: Path
    pages: int
    materials: tuple[str, ...]
    warnings: tuple[str, ...]
    load_s: float = 0.0
    pages_s: float = 0.0
    pdf_s: float = 0.0


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
    """Save figures as pages of one PDF with a footer; no timestamps, so the bytes depend on the
    figures only."""
    buf = io.BytesIO()
    metadata = {"Title": title, "Creator": f"pipeline {__version__}", "CreationDate": None}
    saved_epoch = os.environ.pop("SOURCE_DATE_EPOCH", None)  # would re-introduce a date
    try:
        with pdf_float_decimals(), PdfPages(buf, metadata=metadata) as pdf:
            for i, fig in enumerate(figures, start=1):
                add_footer(fig, f"{title} | page {i} of {len(figures)}")
                pdf.savefig(fig)
    finally:
        if saved_epoch is not None:
            os.environ["SOURCE_DATE_EPOCH"] = saved_epoch
    return buf.getvalue()


def add_footer(fig: Figure, text: str) -> None:
    """The page line, bottom right, inside the footer band (nothing else is drawn there)."""
    fig.text(
        1.0 - 30.0 / (72.0 * fig.get_figwidth()),
        0.45 * FOOTER_PT / (72.0 * fig.get_figheight()),
        text,
        ha="right",
        va="center",
        fontsize=7.0,
        color="0.4",
        gid=FOOTER_GID,
    )


def contents(figures: list[Figure]) -> list[tuple[str, int]]:
    """(what, first page) of each part, from the page labels (page 1 is the summary)."""
    out: list[tuple[str, int]] = []
    seen: set[str] = set()
    for number, fig in enumerate(figures, start=2):
        kind = str(fig.get_label()).split(" ")[0]
        if kind in CONTENTS and kind not in seen:
            seen.add(kind)
            out.append((CONTENTS[kind], number))
    return out


def model_curve_warnings(
    materials: Sequence[str], model_curves: pd.DataFrame, rms: pd.DataFrame
) -> list[str]:
    """Why a material's plot has no dashed model line: the model has no such material (one
    warning for all such, customer 38's three chamber materials gave three), or ``--model-curves``
    holds none for it.

    Examples
    --------
    >>> curves = pd.DataFrame({"material": ["DS20"]})
    >>> rms = pd.DataFrame({"material": ["G1", "G2", "DS30"],
    ...                     "note": ["the model has no material G1", "... has no material G2", ""]})
    >>> for w in model_curve_warnings(["DS20", "DS30", "G1", "G2"], curves, rms):
    ...     print(w[:w.index(" (")] if " (" in w else w)
    DS30: no model curve in --model-curves; its plot has no dashed model line
    G1, G2: the model has no such material, so there is no model line, RMS or fitted k_P
    """
    out, unknown = [], []
    for m in materials:
        if (model_curves["material"].astype(str) == m).any():
            continue
        if "note" in rms.columns and rms.loc[
            rms["material"].astype(str) == m, "note"
        ].astype(str).str.contains("has no material").any():
            unknown.append(m)
        else:
            out.append(f"{m}: no model curve in --model-curves; its plot has no dashed model line")
    if unknown:
        out.append(
            f"{', '.join(unknown)}: the model has no such material, so there is no model line, "
            "RMS or fitted k_P (to compare, add "
            + ("it" if len(unknown) == 1 else "them")
            + " to a materials file named in config.yaml: model.materials_file)"
        )
    return out


def report_figures(data: ReportData) -> tuple[list[Figure], list[str]]:
    """Every page in order, and the warnings printed on the summary page."""
    warnings: list[str] = []
    infos: list[str] = []
    extra: list[Figure] = []
    colors = material_colors(data.materials)
    synthetic_force, grasp_example = force_inputs(data.run_config)
    sources = [
        ("--bench-dir", data.inputs.bench_dir, study_pages.figures),
        (
            "--force-dir",
            data.inputs.force_dir,
            lambda d: force_pages.figures(
                d,
                colors=colors,
                synthetic=synthetic_force,
                grasp_example=grasp_example,
            ),
        ),
    ]
    # a page per video dataset
    sources += [("--video-dirs", d, video_pages.figures) for d in data.inputs.video_dirs]
    for name, folder, build in sources:
        if folder is None:
            continue
        if not folder.is_dir():
            warnings.append(f"{name} {folder} does not exist; its pages are missing")
            continue
        figs = build(folder)
        extra += figs
        infos.append(f"{len(figs)} page(s) of {SOURCE_WORDS[name]} from {folder}")
    if data.inputs.model_curves:
        warnings += model_curve_warnings(data.materials, data.model_curves, data.rms)
    for m in data.materials:
        if not (data.rms["material"].astype(str) == m).any():
            warnings.append(f"{m}: no row in --rms; its comparison values show n/a")
    for d in data.inputs.datasets:
        for label, folder in (("--photosets", d.photoset_dir), ("--overlays", d.overlays_dir)):
            if folder is not None and not folder.is_dir():
                warnings.append(f"{d.name}: {label} folder {folder} does not exist")
    for info in data.datasets:
        warnings += info.doubts
    warnings += opposite_bending_warnings(data.per_actuator)
    body = (
        [overview_page(data)]
        + [material_page(data, m) for m in data.materials]
        + ([comparison_page(data)] if modelled_materials(data) else [])
    )
    if modelled_materials(data):  # which l0, what was fitted
        body += [f for f in [model_provenance_page(data)] if f is not None]
    body += extra + provenance_pages(data, __version__, infos, warnings)
    return [summary_page(data, __version__, warnings, contents(body))] + body, warnings


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
    t0 = time.perf_counter()
    data = load_report_data(inputs)
    t1 = time.perf_counter()
    with report_style():
        figures, warnings = report_figures(data)
        t2 = time.perf_counter()
        pdf = render_pdf(figures, inputs.title)
    path = Path(out)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_write_bytes(path, pdf)
    return ReportResult(
        path=path,
        pages=len(figures),
        materials=tuple(data.materials),
        warnings=tuple(warnings),
        load_s=t1 - t0,
        pages_s=t2 - t1,
        pdf_s=time.perf_counter() - t2,
    )
