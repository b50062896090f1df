"""Which model curve each comparison used, and what its RMS means (fitted or predicted).

The comparison page gets a note naming the self-checks (:func:`comparison_note`); the page
after it (:func:`model_provenance_page`) lists every comparison.  Everything here reads rms.csv
columns written by ``compare`` (``curve``, ``datasets``, ``l0_mm``, ``l0_source``,
``materials_file``, ``data_source``, ``rms_kind``, ``model_fit``, ``note``) and the model curves
(``compare_curves.csv`` carries ``curve`` and ``l0_mm``); a table without them (an older
rms.csv) gives no lines rather than an error.
"""

from __future__ import annotations

import math

import pandas as pd
from matplotlib.figure import Figure

from pipeline.layout.style import A4_LANDSCAPE_IN, MARGIN_PT, text_page
from pipeline.layout.typeset import NA, Column, Flow, Table, fmt
from pipeline.report.data import ReportData

#: what each ``rms_kind`` means, in words for the reader
RMS_KIND_TEXT: dict[str, str] = {
    "self-check": (
        "SELF-CHECK: the photos are synthetic, rendered by synth from this package's model "
        "with each actuator's own stiffness and hysteresis, so the RMS is not a validation, "
        "nor the angles' error (page 1's ψ check is)"
    ),
    "prediction": "prediction: no model parameter was fitted to these data (k_P is the paper's); "
    "only k_P fitted is a fit to them",
    "mixed": (
        "mixed: synthetic photos (rendered from this package's model) pooled with measured "
        "ones; "
        "the RMS is neither a clean self-check nor a validation"
    ),
    "unknown": (
        "source of the photos not stated: read the RMS as a prediction only if they are real"
    ),
}


def curve_lines(rms: pd.DataFrame) -> list[str]:
    """Per model curve of ``rms`` (rms.csv): what its RMS is (only where there is one: a curve
    without a model compares nothing) and its note.

    Examples
    --------
    >>> rms = pd.DataFrame({"curve": ["DS20", "Pink"], "rms_deg": [12.0, float("nan")],
    ...                     "rms_kind": ["unknown", "unknown"], "note": ["", "no model"]})
    >>> [line[:30] for line in curve_lines(rms)]
    ['DS20: source of the photos not', 'Pink: no model.']
    """
    lines = []
    for r in rms.itertuples():
        kind = str(getattr(r, "rms_kind", ""))
        rms_deg = pd.to_numeric(getattr(r, "rms_deg", math.nan), errors="coerce")
        if kind in RMS_KIND_TEXT and math.isfinite(rms_deg):
            lines.append(f"{r.curve}: {RMS_KIND_TEXT[kind]}.")
        note = getattr(r, "note", "")
        if isinstance(note, str) and note:
            lines.append(f"{r.curve}: {note}.")
    return lines


def _has(data: ReportData, column: str) -> bool:
    return column in data.rms.columns


def comparison_note(data: ReportData) -> str:
    """One or two lines for the comparison page: self-checks named, where the l0 table is."""
    if not _has(data, "rms_kind"):
        return ""
    checks = data.rms[data.rms["rms_kind"].astype(str) == "self-check"]
    parts = []
    if len(checks):
        names = ", ".join(f"{r.curve} ({r.datasets})" for r in checks.itertuples())
        parts.append(
            f"Synthetic: {names}: photos rendered from this package's model, so the RMS "
            "is a self-check, not a validation."
        )
    if _has(data, "materials_file"):
        files: dict[str, list[str]] = {}
        for r in data.rms.itertuples():
            files.setdefault(str(r.materials_file), []).append(str(r.datasets))
        parts.append(
            "Materials file of the model curves: "
            + "; ".join(f"{f} ({', '.join(dict.fromkeys(d))})" for f, d in files.items())
            + "."
        )
    parts.append(
        "Which l0 and materials file each model curve used, and what was fitted: next page."
    )
    return " ".join(parts)


def _row_cells(r: pd.Series) -> tuple[str, ...]:
    l0 = NA if not math.isfinite(float(r.get("l0_mm", math.nan))) else f"{float(r['l0_mm']):g}"
    k = (
        f"{fmt(r.get('k_p_fit'), 2)} "
        f"[{fmt(r.get('k_p_ci_low'), 2)}, {fmt(r.get('k_p_ci_high'), 2)}]"
    )
    return (
        str(r.get("curve", r["material"])),
        str(r.get("datasets", "")),
        f"{l0} ({r.get('l0_source', NA)})",
        str(r.get("materials_file", NA)),
        str(r.get("data_source", NA)),
        fmt(r.get("rms_deg"), 1),
        fmt(r.get("paper_rms_deg"), 1),
        str(r.get("rms_kind", NA)),
        k,
        fmt(r.get("k_p_paper"), 1),
    )


def model_provenance_page(data: ReportData) -> Figure | None:
    """Table: one row per comparison with its l0, data source and RMS kind; fitted vs predicted.

    ``None`` when rms.csv has no ``curve`` column (nothing to say).
    """
    if not _has(data, "curve") or data.rms.empty:
        return None
    fig = text_page(landscape=True, label="model-curves")
    flow = Flow(fig, top_pt=36.0, width_pt=72.0 * A4_LANDSCAPE_IN[0] - 2 * MARGIN_PT)
    flow.text(
        "Model versus measurements: which model curve, which l0, what was fitted",
        size=12.0,
        weight="bold",
    )
    flow.space(4.0)
    rows = tuple(_row_cells(r) for _, r in data.rms.iterrows())
    flow.table(
        Table(
            columns=(
                Column("comparison (model curve)", "left"),
                Column("datasets", "left", wrap_pt=160.0),
                Column("l0 (mm, from)", "left"),
                Column("materials file", "left", wrap_pt=120.0),
                Column("photos", "left"),
                Column("run"),
                Column("paper"),
                Column("RMS is", "left"),
                Column("fitted [95 % CI]"),
                Column("paper"),
            ),
            groups=(("", 5), ("RMS (deg)", 2), ("", 1), ("k_P (-)", 2)),
            rows=rows,
            size=8.0,
        )
    )
    fit = sorted({str(v) for v in data.rms.get("model_fit", pd.Series(dtype=str)).dropna()})
    lines = [
        (
            "Fitted and predicted.  The RMS compares the model's loading branch, at the l0 shown "
            "and the paper's k_P, with the mean measured curve: nothing in it was fitted to these "
            "data."
        ),
        (
            "k_P fitted is the one number fitted to these data (least squares on the angles at "
            "rising pressure, the model's loading branch; bootstrap over actuators): it is a fit, "
            "not an agreement."
        ),
        "Constants of the model fitted to the paper's own numbers: " + ("; ".join(fit) or NA) + ".",
        (
            "l0: 'photo set' is the l0_mm the photos were measured with (angles.csv: a drawn "
            "line's marked length, or a body's length that bends); "
            "'materials file' is the model's default, the one parameter the paper's two model "
            "results fix (docs/model.md); 'dataset's materials file' is the l0 of the dataset's "
            "own materials file (config datasets[].materials_file)."
        ),
        (
            "Materials file: the Ogden terms, k_P, k_t and geometry of the curve (its sha256: "
            "provenance page).  A dataset whose l0 or materials file differs from the default has "
            "its own model curve and row."
        ),
    ]
    lines += curve_lines(data.rms)
    flow.space(4.0)
    flow.bullets(lines, size=8.0)
    return fig
