"""Which model curve each comparison used, and what its RMS means (fitted or predicted).

The comparison page gets a note naming the self-checks (:func:`add_comparison_note`); the page
after it (:func:`model_provenance_page`) lists every comparison.  Everything here reads rms.csv
columns written by ``compare`` (``curve``, ``datasets``, ``l0_mm``,
``l0_source``, ``data_source``, ``rms_kind``, ``model_fit``, ``note``) and the model curves
(``compare_curves.csv`` carries ``curve`` and ``l0_mm``); a table without them (an older
rms.csv) gives no lines rather than an error.
"""

from __future__ import annotations

import math
import textwrap

import pandas as pd
from matplotlib.figure import Figure

from pipeline.report.data import ReportData, fmt
from pipeline.report.pages import _table, page
from pipeline.report.style import LANDSCAPE_SIZE_IN

#: what each ``rms_kind`` means, in words for the reader
RMS_KIND_TEXT: dict[str, str] = {
    "self-check": "SELF-CHECK: the photos are synthetic, rendered from this package's model (synth), "
    "so the RMS checks the measurement chain against the model that drew them; it is not a validation",
    "prediction": "prediction: no model parameter was fitted to these data (k_P is the paper's); "
    "only k_P fitted is a fit to them",
    "mixed": "mixed: synthetic photos (rendered from this package's model) pooled with measured ones; "
    "the RMS is neither a clean self-check nor a validation",
    "unknown": "source of the photos not stated: read the RMS as a prediction only if they are real",
}


def _has(data: ReportData, column: str) -> bool:
    return column in data.rms.columns


def add_comparison_note(fig: Figure, data: ReportData) -> None:
    """Write :func:`comparison_note` under the comparison page's title (nothing when empty)."""
    note = comparison_note(data)
    if note:  # as the title of the page's upper part, so the layout makes room for it
        target = fig.subfigs[0] if fig.subfigs else fig
        target.suptitle(textwrap.fill(note, 190), fontsize=7.5, color="#b00000")


def comparison_note(data: ReportData) -> str:
    """One or two lines for the comparison page: self-checks named, where the l0 table is."""
    if not _has(data, "rms_kind"):
        return ""
    checks = data.rms[data.rms["rms_kind"].astype(str) == "self-check"]
    parts = []
    if len(checks):
        names = ", ".join(f"{r.curve} ({r.datasets})" for r in checks.itertuples())
        parts.append(f"Synthetic: {names}: photos rendered from this package's model, so the RMS "
                     "is a self-check, not a validation.")
    parts.append("Which l0 each model curve used, and what was fitted: next page.")
    return " ".join(parts)


def _row_cells(r: pd.Series) -> list[str]:
    l0 = "n/a" if not math.isfinite(float(r.get("l0_mm", math.nan))) else f"{float(r['l0_mm']):g}"
    k = f"{fmt(r.get('k_p_fit'), 2)} [{fmt(r.get('k_p_ci_low'), 2)}, {fmt(r.get('k_p_ci_high'), 2)}]"
    return [
        str(r.get("curve", r["material"])),
        str(r.get("datasets", "")),
        f"{l0} ({r.get('l0_source', 'n/a')})",
        str(r.get("data_source", "n/a")),
        f"{fmt(r.get('rms_deg'), 1)} ({fmt(r.get('paper_rms_deg'), 1)})",
        str(r.get("rms_kind", "n/a")),
        f"{k} ({fmt(r.get('k_p_paper'), 1)})",
    ]


def model_provenance_page(data: ReportData) -> Figure | None:
    """Table: one row per comparison with its l0, data source and RMS kind; fitted vs predicted.

    ``None`` when rms.csv has no ``curve`` column (nothing to say).
    """
    if not _has(data, "curve") or data.rms.empty:
        return None
    fig = page(LANDSCAPE_SIZE_IN)
    fig.suptitle("Model versus measurements: which model curve, which l0, what was fitted")
    n = len(data.rms)
    top, bottom = fig.subfigures(2, 1, height_ratios=[0.12 + 0.05 * n, 1.0])
    ax = top.subplots()
    header = ["comparison (model curve)", "datasets", "l0 (mm, from)", "photos", "RMS deg (paper)",
              "RMS is", "k_P fitted [95 % CI] (paper)"]
    rows = [_row_cells(r) for _, r in data.rms.iterrows()]
    _table(ax, header, rows, [0.17, 0.16, 0.16, 0.09, 0.11, 0.09, 0.22], fontsize=7.0)
    fit = sorted({str(v) for v in data.rms.get("model_fit", pd.Series(dtype=str)).dropna()})
    lines = [
        "Fitted and predicted.  The RMS compares the model's loading branch, at the l0 shown and the paper's "
        "k_P, with the mean measured curve: nothing in it was fitted to these data.",
        "k_P fitted is the one number fitted to these data (least squares on the angles, bootstrap over "
        "actuators): it is a fit, not an agreement.",
        "Constants of the model fitted to the paper's own numbers: " + ("; ".join(fit) or "n/a") + ".",
        "l0: 'photo set' is the marked length the photos were measured with (angles.csv); 'materials file' "
        "is the model's default, the one parameter the paper's two model results fix (docs/model.md).",
        "A dataset whose l0 differs from the default has its own model curve and row.",
    ]
    for r in data.rms.itertuples():
        kind = str(getattr(r, "rms_kind", ""))
        if kind in RMS_KIND_TEXT:
            lines.append(f"{r.curve}: {RMS_KIND_TEXT[kind]}.")
        note = getattr(r, "note", "")
        if isinstance(note, str) and note:
            lines.append(f"{r.curve}: {note}.")
    bottom.text(0.02, 0.98, "\n".join(lines), va="top", ha="left", fontsize=7.5, wrap=True)
    return fig
