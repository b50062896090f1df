"""Page 1: the summary an advisor reads in a minute.

The run's dates (from the inputs), per material the range of motion, the pressure at psi = 0,
the RMS against the model and the fitted k_P with its confidence interval beside the paper's
values, the data-quality counts with the top reasons in words, whether each dataset is real or
synthetic, the warnings, and where each part of the report is.  Hashes are on the last page
(:mod:`pipeline.report.provenance`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from pipeline.aggregate import (
    aggregate_hysteresis,
    is_used,
    opposite_bending,
    pressure_levels,
    settled_frames,
)
from pipeline.compare import START_BAND_DEG, branch
from pipeline.layout.style import P_LABEL, PSI_LABEL, lighter, material_colors, text_page
from pipeline.layout.typeset import NA, Column, Flow, Table, fmt, table_height_pt
from pipeline.report.accuracy import ACCURACY_NOTE
from pipeline.report.calibration import calibration_lines
from pipeline.report.data import (
    ReportData,
    aggregate_options,
    comparisons,
    material_sources,
    mixed_sources_note,
    modelled_materials,
    rms_row,
)
from pipeline.report.reasons import top_reasons

#: least height (pt) worth giving the overview plot on page 1
MIN_PLOT_PT = 170.0
#: the plot never takes more than this (pt), so page 1 stays a summary
MAX_PLOT_PT = 250.0
#: warnings printed on page 1 (all of them are on the provenance page)
MAX_WARNINGS = 8


def date_line(data: ReportData) -> str:
    """When the photos were taken (from the inputs), or that the inputs hold no date."""
    firsts = [d.first_date for d in data.datasets if d.first_date]
    lasts = [d.last_date for d in data.datasets if d.last_date]
    unclear = [
        f"{d.name}: {d.date_source}" for d in data.datasets if not d.first_date and d.date_source
    ]
    if not firsts:
        return "Photos taken: " + (
            f"not known ({'; '.join(unclear)})"
            if unclear
            else "no date in the inputs (no timestamp column in manifest.csv, no EXIF date in "
            "the photos; synthetic photo sets carry neither)"
        )
    first, last = min(firsts), max(lasts)
    sources = sorted({d.date_source for d in data.datasets if d.first_date and d.date_source})
    undated = [
        f"{d.name} ({d.date_source})" if d.date_source else d.name
        for d in data.datasets
        if not d.first_date
    ]
    span = first if first == last else f"{first} to {last}"
    extra = f"; no date for {', '.join(undated)}" if undated else ""
    return f"Photos taken: {span} (from the {' and '.join(sources)}{extra})"


def results_table(data: ReportData) -> Table:
    """Per material: range of motion, P at psi = 0, RMS and k_P, this run beside the paper."""
    colors = material_colors(data.materials)
    sources = material_sources(data)
    rows, row_colors = [], []
    for m, label, row in comparisons(data):
        g = row.get
        ci = f"{fmt(g('k_p_fit'), 2)} [{fmt(g('k_p_ci_low'), 2)}, {fmt(g('k_p_ci_high'), 2)}]"
        row_colors.append(colors[m])
        # real or synthetic: the quality table's, per dataset (a column of it here made the
        # 13-column table wrap its labels)
        rows.append(
            (
                label,
                fmt(g("range_deg"), 0),
                fmt(g("paper_range_deg"), 0),
                fmt(g("p_zero_up_kpa"), 0),
                fmt(g("p_zero_down_kpa"), 0),
                fmt(g("model_p_zero_kpa"), 0),
                fmt(g("paper_p_zero_kpa"), 0),
                fmt(g("rms_up_deg"), 1),
                fmt(g("rms_deg"), 1),
                fmt(g("paper_rms_deg"), 1),
                ci if fmt(g("k_p_fit"), 2) != NA else NA,
                fmt(g("k_p_paper"), 1),
            )
        )
    notes = [
        ("Range: the range of motion, largest minus smallest mean ψ over both directions.  P at ψ "
         "= 0: where the "
        "mean curve crosses ψ = 0 (linear between levels); model: where the model's loading "
        "branch does (predicted: the paper's k_P, nothing fitted).  RMS: the model (loading "
        "branch) against the mean "
        "curve at the measured levels: over the rising leg, which the loading branch models, and "
        "over both directions as the paper's RMS (the falling leg's hysteresis, not modelled, "
        "makes it larger).  k_P: fitted to this "
        "run's photos at rising pressure (the model's loading branch; the falling leg's "
        "hysteresis would pull it low), 95 % bootstrap interval over actuators (n/a for a "
        "material with one actuator); a fitted value, so its closeness to the paper's k_P "
        "tests nothing."),
    ]
    if data.materials and not modelled_materials(data):
        notes.append(
            "No model comparison: none of this run's materials ("
            + ", ".join(data.materials)
            + ") has a model curve or an RMS against the model, so nothing was predicted or "
            "fitted, and the comparison and model-curve pages are left out (a material the "
            "model does not have: add it to a materials file named in config.yaml, "
            "model.materials_file)."
        )
    notes += missing_notes(data)
    notes += top_left_out_notes(data)
    notes += coarse_crossing_notes(data.angles, aggregate_options(data.run_config))
    notes += [n for n in (mixed_sources_note(data, m) for m in data.materials) if n]
    if any("synthetic" in s for s in sources.values()):
        notes.append(
            "synthetic: rendered by 'synth' from the model with each actuator's own stiffness "
            "and hysteresis, so their RMS tests neither model nor measurement; ψ check below "
            "checks the angles."
        )
    return Table(
        columns=(
            Column("Material", "left"),
            Column("run"),
            Column("paper"),
            Column("rising"),
            Column("falling"),
            Column("model"),
            Column("paper"),
            Column("rising"),
            Column("both"),
            Column("paper"),
            Column("fitted [95 % CI]"),
            Column("paper"),
        ),
        groups=(
            ("", 1),
            ("Range (deg)", 2),
            ("P at ψ = 0 (kPa)", 4),
            ("RMS (deg)", 3),
            ("k_P (-)", 2),
        ),
        rows=tuple(rows),
        title="Results per material, beside the paper (Section III.A)",
        notes=tuple(notes),
        row_colors=tuple(row_colors),
        size=8.0,
    )


#: mean psi of two adjacent pressure levels differing by more than this (deg) across psi = 0: the
#: P at psi = 0 interpolated between them is a straight line across a jump the steps do not resolve
COARSE_CROSSING_DEG = 90.0


def coarse_crossing_notes(
    angles: pd.DataFrame, options: Mapping[str, Any] | None = None
) -> list[str]:
    r"""Per dataset, where psi = 0 is crossed between two adjacent levels whose mean psi differ by
    more than :data:`COARSE_CROSSING_DEG`: the interpolated P at psi = 0 is then a straight line
    across a jump (an actuator snapping through), uncertain by up to the step.

    Where photos (or frames) lie between the two levels but none is in the curve (flagged or
    failed), the note says so, with their commonest cause, instead of asking for smaller steps
    (customer 27: all 60 frames at 120 kPa rising were flagged, the tip out of the picture, and
    the note asked for smaller steps than the 40 kPa taken).

    Parameters
    ----------
    angles : pandas.DataFrame
        angles rows of every dataset, with ``dataset``.
    options : mapping, optional
        ``aggregate_hysteresis`` options (the run's ``bin_kpa``, ``include_flagged``).

    Examples
    --------
    >>> rows = [("up", 0, 210.0), ("up", 20, 190.0), ("up", 40, 128.0), ("up", 60, -18.0)]
    >>> angles = pd.DataFrame([{"dataset": "lab", "image": f"{p}.jpg", "material": "DS20",
    ...     "direction": d, "pressure_kpa": p, "psi_deg": s, "status": "ok", "actuator": "A1",
    ...     "trial": 1, "reason": ""} for d, p, s in rows])
    >>> (note,) = coarse_crossing_notes(angles)
    >>> print(note.replace(", where", ",\nwhere").replace(": its", ":\nits"))
    lab: ψ = 0 is crossed between 40 and 60 kPa rising,
    where the mean ψ jumps from +128 to -18 deg:
    its P at ψ = 0 is a straight line across that jump (take smaller pressure steps there)
    >>> angles.loc[3, "pressure_kpa"] = 80.0
    >>> hidden = angles.iloc[[3]].assign(pressure_kpa=60.0, psi_deg=40.0, status="flagged",
    ...     reason="body touches the image border at its free end: the tip may be outside")
    >>> (note,) = coarse_crossing_notes(pd.concat([angles, hidden], ignore_index=True))
    >>> print(note.replace("; the", ";\nthe").replace(" (", "\n(").replace(": its", ":\nits"))
    lab: ψ = 0 is crossed between 40 and 80 kPa rising, where the mean ψ jumps from +128 to -18 deg;
    the 1 photo at 60 kPa between them is not in the curve
    (flagged: body's tip at the image border, 1):
    its P at ψ = 0 is a straight line across that jump
    (see those rows' reasons in angles.csv; photoset preview shows them)
    """
    opts = dict(options or {})
    out = []
    for name, g in angles.groupby("dataset", sort=True):
        h = aggregate_hysteresis(g, **opts)
        parts = []
        unseen = []  # per part: whether rows between its two levels are left out
        for material in sorted(h["material"].astype(str).unique()):
            for direction, word in (("up", "rising"), ("down", "falling")):
                p, psi = branch(h[h["material"].astype(str) == material], direction)
                keep = np.isfinite(psi)
                p, psi = p[keep], psi[keep]
                for i in range(len(psi) - 1):
                    if psi[i] * psi[i + 1] < 0.0:
                        if abs(psi[i] - psi[i + 1]) > COARSE_CROSSING_DEG:
                            between = _left_out_between(
                                g[g["material"].astype(str) == material], direction,
                                (float(p[i]), float(p[i + 1])), opts,
                            )
                            unseen.append(bool(between))
                            parts.append(
                                f"between {p[i]:g} and {p[i + 1]:g} kPa {word}, where the mean ψ "
                                f"jumps from {psi[i]:+.0f} to {psi[i + 1]:+.0f} deg{between}"
                            )
                        break
        if parts:
            out.append(
                f"{name}: ψ = 0 is crossed "
                + " and ".join(parts)
                + (": its P at ψ = 0 is a straight line across that jump" if len(parts) == 1
                   else ": its P at ψ = 0 values are straight lines across those jumps")
                + (
                    " (see those rows' reasons in angles.csv; photoset preview shows them)"
                    if all(unseen)
                    else " (take smaller pressure steps there)"
                    if not any(unseen)
                    else " (take smaller pressure steps where no row lies between; see the "
                    "reasons of those left out in angles.csv)"
                )
            )
    return out


def opposite_bending_warnings(per_actuator: pd.DataFrame) -> list[str]:
    """A warning per material whose actuators bend opposite ways as the pressure rises
    (:func:`~pipeline.aggregate.opposite_bending`), from the per-actuator curves the report
    plots (a synthetic set left out beside real photos of its material is not among them): its
    mean curve is none of theirs.

    Examples
    --------
    >>> rows = [(a, p, s * p) for a, s in (("1", 2.0), ("2", -1.0)) for p in (0, 50)]
    >>> angles = pd.DataFrame([{"image": f"{a}_{p}.jpg", "material": "SIL", "actuator": a,
    ...     "trial": 1, "direction": "up", "pressure_kpa": p, "psi_deg": psi, "status": "ok"}
    ...     for a, p, psi in rows])
    >>> from pipeline.aggregate import aggregate_per_actuator
    >>> (text,) = opposite_bending_warnings(aggregate_per_actuator(angles))
    >>> print(text[:text.index(":", 5)])
    SIL: its actuators bend opposite ways as the pressure rises (ψ from 0 to 50 kPa rising)
    >>> print(text[text.index("actuator 2"):text.index(";")])
    actuator 2 -50 deg, actuator 1 +100 deg
    """
    found = opposite_bending(per_actuator)
    out = []
    for material, g in found.groupby("material", sort=True):
        spans = {(f, t) for f, t in zip(g["from_kpa"], g["to_kpa"], strict=True)}
        span = (
            f"ψ from {g['from_kpa'].iloc[0]:g} to {g['to_kpa'].iloc[0]:g} kPa rising"
            if len(spans) == 1
            else "ψ from each one's lowest to its highest pressure, rising"
        )
        each = ", ".join(
            f"actuator {a} {r:+.0f} deg" for a, r in zip(g["actuator"], g["rise_deg"], strict=True)
        )
        out.append(
            f"{material}: its actuators bend opposite ways as the pressure rises ({span}): {each}; "
            "its mean curve, range and P at ψ = 0 are none of theirs.  Give each actuator or "
            "chamber that bends its own way its own material (the manifest's material column, "
            "or photoset init --pattern 'chamber{material}/...'); one mounted or photographed "
            "mirrored, its rows positive_turn: cw"
        )
    return out


def _left_out_between(
    rows: pd.DataFrame, direction: str, span_kpa: tuple[float, float], options: Mapping[str, Any]
) -> str:
    """'; the N photos at P kPa between them are not in the curve (flagged: ...)' for the rows of
    one material and direction whose level lies strictly inside ``span_kpa`` and that the curve
    leaves out; '' when there are none."""
    settled = rows[settled_frames(rows)]
    level = pressure_levels(settled, options.get("bin_kpa"))
    lo, hi = sorted(span_kpa)
    inside = (settled["direction"] == direction) & (level > lo + 1e-6) & (level < hi - 1e-6)
    out = settled[inside & ~is_used(settled, bool(options.get("include_flagged")))]
    if out.empty:
        return ""
    levels = sorted(set(level[out.index]))
    at = f"{levels[0]:g} kPa" if len(levels) == 1 else f"{levels[0]:g}-{levels[-1]:g} kPa"
    many = len(out) > 1
    frames = "frame" in out.columns and out["frame"].notna().any()
    since = pd.to_numeric(out.get("since_step_s", pd.Series(np.nan, index=out.index)),
                          errors="coerce")
    if frames and np.isfinite(since[out["frame"].notna()]).any():  # a stepped video's holds
        n_holds = len(out.groupby([c for c in ("image", "step") if c in out.columns]))
        what = f"{len(out)} frame{'s' if many else ''} ending the hold{'s' if n_holds > 1 else ''}"
    else:
        what = f"{len(out)} {'frame' if frames else 'photo'}{'s' if many else ''}"
    causes = top_reasons(out.assign(dataset=""), limit=1).get("", [])
    statuses = "/".join(sorted(set(out["status"].astype(str))))
    why = f" ({statuses}: " + ", ".join(f"{c}, {n}" for c, n in causes) + ")" if causes else ""
    return f"; the {what} at {at} between them {'are' if many else 'is'} not in the curve{why}"


def top_left_out_notes(data: ReportData) -> list[str]:
    """Per material whose photos at its highest pressures were none measured ok: its mean curve,
    and with it its range of motion, stops short of the pressures photographed, which page 1
    does not show (customer 52's pale body, flagged at 100 and 120 kPa: "Range 111 deg" for
    about 178, no word said).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> h = pd.DataFrame({"material": "SIL", "direction": ["up"] * 4 + ["down"] * 3,
    ...                   "pressure_kpa": [0.0, 40, 80, 120, 80, 40, 0],
    ...                   "psi_mean_deg": [0.0, 50, np.nan, np.nan, 95, 55, 1]})
    >>> print(*top_left_out_notes(SimpleNamespace(materials=["SIL"], hysteresis=h)))
    SIL: no photo at 120 kPa was measured ok (the quality table gives the reasons), so its mean \
curve stops at 80 kPa of the 120 kPa photographed: its range of motion and RMS cover the \
pressures up to 80 kPa only.
    """
    out = []
    for m in data.materials:
        h = data.hysteresis[data.hysteresis["material"].astype(str) == m]
        mean = pd.to_numeric(h["psi_mean_deg"], errors="coerce")
        if mean.notna().sum() == 0 or h.loc[mean.notna(), "pressure_kpa"].nunique() < 2:
            continue  # no curve (missing_notes says so)
        top_ok = float(h.loc[mean.notna(), "pressure_kpa"].max())
        above = sorted(float(p) for p in h["pressure_kpa"].unique() if float(p) > top_ok)
        if not above:
            continue
        # pressures as given (rounded, 12.4 and 12.6 kPa read "stops at 12 kPa of 13")
        levels = ", ".join(f"{p:g}" for p in above)
        out.append(
            f"{m}: no photo at {levels} kPa was measured ok (the quality table gives the "
            f"reasons), so its mean curve stops at {top_ok:g} kPa of the {above[-1]:g} kPa "
            f"photographed: its range of motion and RMS cover the pressures up to {top_ok:g} kPa "
            "only."
        )
    return out


def missing_notes(data: ReportData) -> list[str]:
    """Why a value of the results table reads n/a, per material."""
    out = []
    for m in data.materials:
        g = rms_row(data, m)
        if not g:
            out.append(f"{m}: no row in rms.csv, so its comparison values read n/a.")
            continue
        h = data.hysteresis[data.hysteresis["material"] == m]
        if not h["psi_mean_deg"].notna().any():
            out.append(
                f"{m}: no photo was measured ok, so there is no curve and every value reads n/a "
                "(the quality table gives the reasons; photoset preview shows what the settings "
                "select)."
            )
            continue
        measured = h.dropna(subset=["psi_mean_deg"])
        if measured["pressure_kpa"].nunique() == 1:
            # customer 48's PneuNets, ok at 0 kPa alone, read "never reaches ψ = 0 up to 60 kPa"
            out.append(
                f"{m}: only its photos at {fmt(measured['pressure_kpa'].iloc[0], 0)} kPa were "
                "measured ok, so there is no curve and its values read n/a or rest on that one "
                "level (the quality table gives the reasons)."
            )
            continue
        if not np.isfinite(float(g.get("p_zero_up_kpa", np.nan))):
            low = fmt(h["psi_mean_deg"].min(), 0)
            # the highest pressure with a mean: a level whose photos were all left out has none
            top = fmt(measured["pressure_kpa"].max(), 0)
            paper = (
                " (the paper gives none either)"
                if not np.isfinite(float(g.get("paper_p_zero_kpa", np.nan)))
                else ""
            )
            # where the curve starts: its lowest pressure, going up
            up = h[h["direction"] == "up"].dropna(subset=["psi_mean_deg"])
            first = up.sort_values("pressure_kpa")["psi_mean_deg"].iloc[0] if len(up) else np.nan
            out.append(
                # customer 35's straight-at-rest actuator read "never reaches ψ = 0 ...
                # (smallest mean ψ 0°)"
                f"{m}: the curve starts at ψ = {fmt(first, 0)}° (straight at rest) and does not "
                "come back "
                f"through ψ = 0 up to {top} kPa, so P at ψ = 0 (the paper's actuators are bent "
                f"back at rest) reads n/a{paper}."
                if abs(first) <= START_BAND_DEG
                else f"{m}: the mean curve never reaches ψ = 0 up to {top} kPa (smallest mean ψ "
                f"{low}°), so P at ψ = 0 reads n/a{paper}."
            )
    return out


#: a dataset with at most this many flagged or failed photos names them beside its top reasons
#: (customer 24 could not find the one flagged photo page 1 counted)
NAMED_PHOTOS = 3


def quality_table(
    data: ReportData, *, width_pt: float = 511.0, height_pt: float | None = None
) -> Table:
    """Per dataset: real or synthetic, dates, photo counts by status and the top reasons in words.

    When the rows do not fit in ``height_pt``, the datasets with the most flagged and failed photos
    keep their rows and the others are summed into one.
    """
    reasons = top_reasons(data.angles)
    rows, counts = [], []
    for info in data.datasets:
        a = data.angles[data.angles["dataset"] == info.name]
        status = a["status"].astype(str)
        c = np.array(
            [
                len(a),
                (status == "ok").sum(),
                (status == "flagged").sum(),
                (status == "failed").sum(),
            ]
        )
        counts.append(c)
        materials = ", ".join(sorted(a["material"].astype(str).unique()))
        dates = NA if not info.first_date else (info.first_date if info.first_date == info.last_date
                                                else f"{info.first_date} to {info.last_date}")
        why = "; ".join(f"{w} ({n})" for w, n in reasons.get(info.name, [])) or "none"
        doubted = a.loc[status != "ok", "image"].astype(str).tolist()
        if 0 < len(doubted) <= NAMED_PHOTOS:  # few enough to look at (its overlay, the preview)
            why += f": {', '.join(doubted)}"
        rows.append(
            (
                info.name,
                info.source,
                materials,
                dates,
                *(str(int(v)) for v in c),
                info.accuracy.cell(),
                why,
            )
        )
    dated = any(d.first_date for d in data.datasets)

    def table(kept: list[int]) -> Table:
        body = [rows[i] for i in kept]
        rest = [i for i in range(len(rows)) if i not in kept]
        if rest:
            other = sum((counts[i] for i in rest), np.zeros(4, dtype=int))
            body.append(
                (
                    f"{len(rest)} more",
                    "",
                    "",
                    "",
                    *(str(int(v)) for v in other),
                    "",
                    "fewest flagged/failed",
                )
            )
        total = sum(counts, np.zeros(4, dtype=int))
        body.append(("all", "", "", "", *(str(int(v)) for v in total), "", ""))
        columns: tuple[Column, ...] = (
            Column("Dataset", "left", wrap_pt=90.0),
            Column("Data", "left"),
            Column("Material", "left", wrap_pt=90.0),  # a set's several: one a line
            Column("Photos taken", "left"),
            Column("photos"),
            Column("ok"),
            Column("flagged"),
            Column("failed"),
            Column("ψ check (deg)\nmedian / 95 %", "left"),
            Column("Top reasons (photos)", "left", wrap_pt=200.0),
        )
        if not dated:  # the date line above says so once
            columns = columns[:3] + columns[4:]
            body = [r[:3] + r[4:] for r in body]
        return Table(
            columns=columns,
            rows=tuple(body),
            title="Data quality: every photo is ok, flagged or failed",
            notes=(
                ("Flagged and failed photos are left out of the curves and fits; the reasons are "
                 "counted once "
                "per photo.  Data: synthetic = the photo set holds the renderer's truth.csv."),
                ACCURACY_NOTE,
            ),
            size=8.0,
        )

    worst = sorted(range(len(rows)), key=lambda i: (-(counts[i][2] + counts[i][3]), i))
    for keep in range(len(rows), 0, -1):
        candidate = table(sorted(worst[:keep]))
        if height_pt is None or table_height_pt(candidate, width_pt) <= height_pt:
            return candidate
    return candidate


def calibration_summary(data: ReportData) -> list[tuple[str, str]]:
    """Which photo sets were measured on a calibrated plane (:mod:`pipeline.report.calibration`):
    one line per dataset, or one for all when they are alike.  ``("w", text)`` is a warning."""
    names = [d.name for d in data.datasets]
    lines: list[tuple[str, str]] = []
    # after its heading; rejoin wrapped lines
    for style, text in calibration_lines(data.angles, names)[1:]:
        if text.startswith(" ") and lines:
            lines[-1] = (lines[-1][0], f"{lines[-1][1]} {text.strip()}")
        else:
            lines.append((style, text))
    said = {(style, text.split(": ", 1)[-1]) for style, text in lines}
    if len(lines) > 1 and len(said) == 1:  # the same for every set: say it once
        style, text = said.pop()
        return [(style, f"every photo set: {text}")]
    return lines


def nothing_ok(data: ReportData) -> list[str]:
    """A warning for each dataset of which no photo was measured ok: its curves are empty, and
    the page otherwise said so only as n/a (customer 33's 68 photos of a clear body)."""
    out = []
    for name, g in data.angles.groupby("dataset", sort=True):
        if not (g["status"] == "ok").any():
            out.append(
                f"{name}: none of its {len(g)} photos was measured ok, so it adds nothing to the "
                "curves or the comparison; the quality table on this page gives the reasons, and "
                "photoset preview shows what the settings select"
            )
    return out


def summary_page(data: ReportData, version: str, warnings: Sequence[str],
                 contents: Sequence[tuple[str, int]]) -> Figure:
    """Page 1 (portrait A4).

    Parameters
    ----------
    data : ReportData
    version : str
        Software version.
    warnings : sequence of str
        Printed in red.
    contents : sequence of (str, int)
        What is on which page (first page of each part).
    """
    fig = text_page(label="summary")
    flow = Flow(fig, top_pt=36.0)
    flow.text(data.inputs.title, size=16.0, weight="bold")
    flow.space(2.0)
    frames = int(data.angles["frame"].notna().sum()) if "frame" in data.angles.columns else 0
    counted = f"{len(data.angles) - frames} photos" + (f", {frames} video frames" if frames else "")
    flow.text(
        f"Summary of {len(data.datasets)} dataset(s), {counted}, {len(data.materials)} "
        "material(s); "
        f"pipeline {version}.  {date_line(data)}.",
        size=8.5,
        color="0.2",
    )
    flow.space(4.0)
    flow.table(results_table(data))
    flow.space(4.0)
    notes = list(data.notes)
    every = [*nothing_ok(data), *warnings]
    shown = every[:MAX_WARNINGS]
    if len(every) > MAX_WARNINGS:
        shown.append(
            f"... and {len(every) - MAX_WARNINGS} more warning(s), listed on the provenance page"
        )
    contents_h = 9.0 * 1.32 * (1 + int(np.ceil(len(contents) / 2))) + 14.0
    notes_h = sum(8.0 * 1.32 * (1 + len(n) // 110) for n in notes) + 16.0
    warnings_h = sum(8.0 * 1.32 * (1 + len(w) // 100) for w in shown) + (16.0 if shown else 0.0)
    calibration = calibration_summary(data)
    calibration_h = sum(8.0 * 1.32 * (1 + len(t) // 110) for _, t in calibration) + 16.0
    flow.table(
        quality_table(
            data,
            width_pt=flow.width,
            height_pt=flow.remaining_pt - contents_h - notes_h - warnings_h - calibration_h - 8.0,
        )
    )
    flow.heading("Camera calibration", size=9.5)
    for style, text in calibration:
        flow.text(text, size=8.0, color="#b00000" if style == "w" else "black", hanging_pt=9.0)
    if shown:
        flow.heading("Warnings", size=9.5)
        flow.bullets(shown, color="#b00000")
    plot_h = min(MAX_PLOT_PT, flow.remaining_pt - contents_h - notes_h - 8.0)
    if plot_h >= MIN_PLOT_PT and data.hysteresis["psi_mean_deg"].notna().any():
        flow.space(6.0)
        overview_axes(flow.axes(plot_h, top_pad_pt=20.0), data)
    if notes:
        flow.heading("Notes", size=9.5)
        flow.bullets(notes, size=7.5)
    flow.heading("Contents", size=9.5)
    half = int(np.ceil(len(contents) / 2))
    top = flow.y
    for k, (title, number) in enumerate(contents):
        flow.y = top + (k % half) * 9.0 * 1.32 if half else top
        x = flow.x + (0.0 if k < half else flow.width / 2)
        fig.text(
            x, flow.y, f"p. {number}", transform=flow.transform, fontsize=8.0, va="top", color="0.3"
        )
        fig.text(x + 30.0, flow.y, title, transform=flow.transform, fontsize=8.0, va="top")
    return fig


def overview_axes(ax: Axes, data: ReportData) -> None:
    """Mean psi against P of every material: rising pressure solid, falling dashed."""
    colors = material_colors(data.materials)
    for m in data.materials:
        h = data.hysteresis[data.hysteresis["material"] == m]
        for direction, style in (("up", "-"), ("down", "--")):
            b = h[h["direction"] == direction].sort_values("pressure_kpa")
            if len(b):
                ax.plot(b["pressure_kpa"], b["psi_mean_deg"], style, linewidth=1.2,
                        color=colors[m] if direction == "up" else lighter(colors[m], 0.3),
                        label=m if direction == "up" else None)
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=0)
    ax.set_xlim(left=0.0)
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel(PSI_LABEL)
    ax.set_title(
        "Mean bending angle of every material (solid: rising, dashed: falling pressure)",
        fontsize=9.0,
    )
    ax.legend(loc="best", frameon=False, ncols=2)

