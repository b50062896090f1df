"""The report's own result pages: the Fig. 6 overview, one page per material, the comparison.

Each function returns one A4 :class:`~matplotlib.figure.Figure` (call inside
:func:`pipeline.layout.style.report_style`).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from matplotlib.artist import Artist
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from pipeline.constants import DIRECTIONS
from pipeline.layout.style import (
    A4_PORTRAIT_IN,
    P_LABEL,
    PSI_LABEL,
    Color,
    actuator_colors,
    footer_fraction,
    lighter,
    material_colors,
    page,
)
from pipeline.layout.typeset import NA, Column, Flow, Table, fmt, table_height_pt
from pipeline.report.data import (
    ReportData,
    comparisons,
    material_sources,
    mixed_sources_note,
    modelled_materials,
    rms_row,
)
from pipeline.report.model_page import comparison_note
from pipeline.report.strip import Strip, build_strip, strip_image

#: height kept for the legend under the overview panels (pt)
LEGEND_BAND_PT = 44.0
#: height of the strip photos (px) and the white gap between them (px)
STRIP_PHOTO_PX, STRIP_GAP_PX = 180, 18
#: height of the photo strip band of a material page (pt)
STRIP_BAND_PT = 118.0


# ------------------------------------------------------------------------------------------
# hysteresis plots


#: line styles of successive model curves of one material (one per l0)
CURVE_STYLES: tuple[object, ...] = ("--", ":", "-.", (0, (5, 1, 1, 1)))


def own_file_label(curve: pd.DataFrame) -> str:
    """``", materials FILE"`` for a compare curve of a dataset's own materials file, else ``""``."""
    if "materials_file" not in curve.columns:
        return ""
    suffix = f", materials {curve['materials_file'].iloc[0]}"
    return suffix if str(curve["curve"].iloc[0]).endswith(suffix) else ""


def model_lines(
    data: ReportData, material: str, p_max_kpa: float
) -> list[tuple[str, np.ndarray, np.ndarray, object]]:
    """Model curves of ``material`` to draw: ``(label, pressure, psi, linestyle)``, psi order.

    The curves ``compare`` used (``curve`` column: one per l0 and materials file, labelled with
    them) when present,
    else the plain model curve.  Pressures outside [0, ``p_max_kpa``] are NaN (not drawn).
    """
    c = data.model_curves[data.model_curves["material"].astype(str) == material]
    if "curve" in c.columns and c["curve"].notna().any():
        groups = [
            (g, f"model, l0 {float(g['l0_mm'].iloc[0]):g} mm" + own_file_label(g))
            for _, g in c[c["curve"].notna()].groupby("curve", sort=False)
        ]
    else:
        groups = [(c, "analytical model")] if len(c) else []
    out = []
    for i, (g, label) in enumerate(groups):
        g = g.sort_values("psi_deg", ascending=False, kind="stable")
        p = pd.to_numeric(g["pressure_kpa"], errors="coerce").to_numpy(float)
        s = pd.to_numeric(g["psi_deg"], errors="coerce").to_numpy(float)
        p = np.where((p >= 0) & (p <= p_max_kpa), p, np.nan)
        if np.isfinite(p).any():
            out.append((label, p, s, CURVE_STYLES[i % len(CURVE_STYLES)]))
    return out


def plot_hysteresis(
    ax: Axes,
    data: ReportData,
    material: str,
    color: Color,
    *,
    legend: bool = True,
    title: str | None = None,
) -> None:
    """Fig. 6 style: mean +- 1 sd shaded (darker increasing, lighter decreasing), model dashed."""
    h = data.hysteresis[data.hysteresis["material"] == material]
    p_max = float(h["pressure_kpa"].max()) if len(h) else 1.0
    styles = {"up": (color, 0.35, "increasing P"), "down": (lighter(color), 0.35, "decreasing P")}
    for direction in DIRECTIONS:
        b = h[h["direction"] == direction].sort_values("pressure_kpa")
        if b.empty:
            continue
        col, alpha, label = styles[direction]
        p = b["pressure_kpa"].to_numpy(float)
        m = b["psi_mean_deg"].to_numpy(float)
        sd = np.nan_to_num(b["psi_sd_deg"].to_numpy(float))
        ax.fill_between(
            p, m - sd, m + sd, color=col, alpha=alpha, linewidth=0, label=f"± 1 sd, {label}"
        )
        ax.plot(p, m, color=col, marker="o", markersize=2.5, label=f"mean, {label}")
        one = b["n"].to_numpy(float) == 1 if "n" in b.columns else np.zeros(len(b), bool)
        if one.any():  # a level only one photo reached: a value, not a mean (hollow)
            ax.plot(p[one], m[one], linestyle="none", marker="o", markersize=3.5,
                    markerfacecolor="white", markeredgecolor=col, markeredgewidth=0.8)
    for label, mp, ms, style in model_lines(data, material, p_max * 1.02):
        ax.plot(mp, ms, linestyle=style, color="0.15", linewidth=1.2, label=label)
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=0)
    ax.set_xlim(left=0.0, right=max(p_max, 1.0) * 1.03)
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel(PSI_LABEL)
    ax.set_title(
        material if title is None else title,
        color=color if title is None else "black",
        fontweight="bold" if title is None else "normal",
    )
    if legend:
        ax.legend(loc="best", frameon=False)


def legend_proxies(model: bool = True) -> tuple[list[Artist], list[str]]:
    """Neutral legend entries for the hysteresis plots of every material (the model's dashed
    line only where ``model``: some material has one)."""
    dark, light = (0.3, 0.3, 0.3), lighter((0.3, 0.3, 0.3))
    handles: list[Artist] = [
        Line2D([], [], color=dark, marker="o", markersize=2.5),
        Patch(color=dark, alpha=0.35, linewidth=0),
        Line2D([], [], color=light, marker="o", markersize=2.5),
        Patch(color=light, alpha=0.35, linewidth=0),
    ]
    labels = ["mean, increasing P", "± 1 sd, increasing P", "mean, decreasing P",
              "± 1 sd, decreasing P"]
    if model:
        handles.append(Line2D([], [], color="0.15", linestyle="--", linewidth=1.2))
        labels.append("analytical model")
    return handles, labels


def overview_page(data: ReportData) -> Figure:
    """All materials side by side, as the paper's Fig. 6 (one legend for all panels)."""
    materials = data.materials
    colors = material_colors(materials)
    n = max(len(materials), 1)
    ncols = 1 if n == 1 else 2
    nrows = math.ceil(n / ncols)
    fig = page(label="overview", bottom_pt=LEGEND_BAND_PT)
    fig.suptitle("Bending angle versus input pressure (as Fig. 6 of the paper)")
    # one psi scale for all (panels each on their own made a small range look like a large one:
    # customer 24)
    axes = fig.subplots(nrows, ncols, squeeze=False, sharey=True)
    for ax, m in zip(axes.flat, materials, strict=False):
        plot_hysteresis(ax, data, m, colors[m], legend=False)
    for ax in axes[:, 1:].flat:
        ax.set_ylabel("")  # the first column's says it
    for ax in list(axes.flat)[len(materials) :]:
        ax.set_axis_off()
    handles, labels = legend_proxies(model=bool(modelled_materials(data)))
    fig.legend(
        handles,
        labels,
        loc="lower center",
        bbox_to_anchor=(0.5, footer_fraction(A4_PORTRAIT_IN)),
        ncols=3,
        frameon=False,
        title="Each panel in its material's colour; shading: ± 1 standard deviation over actuators "
        "and trials"
        + (
            f"; hollow points: {_alone(data.angles)} alone (n = 1)"
            if "n" in data.hysteresis.columns and (data.hysteresis["n"] == 1).any()
            else ""
        ),
    )
    return fig


# ------------------------------------------------------------------------------------------
# one material


def metric_table(
    row: dict[str, object], *, title: str = "", extra_notes: tuple[str, ...] = ()
) -> Table:
    """The comparison figures of one material, this run beside the paper."""
    g = row.get
    k_ci = (
        NA
        if fmt(g("k_p_fit"), 2) == NA
        else (f"{fmt(g('k_p_fit'), 2)} [{fmt(g('k_p_ci_low'), 2)}, {fmt(g('k_p_ci_high'), 2)}]")
    )
    width = fmt(g("hysteresis_width_deg"), 0)
    if width != NA:
        width += f" at {fmt(g('hysteresis_width_at_kpa'), 0)} kPa"
    rows = (
        (
            "RMS against the model (deg)",
            fmt(g("rms_up_deg"), 1),
            fmt(g("rms_down_deg"), 1),
            fmt(g("rms_deg"), 1),
            "",
            fmt(g("paper_rms_deg"), 1),
        ),
        (
            "P at ψ = 0 (kPa)",
            fmt(g("p_zero_up_kpa"), 0),
            fmt(g("p_zero_down_kpa"), 0),
            "",
            fmt(g("model_p_zero_kpa"), 0),
            fmt(g("paper_p_zero_kpa"), 0),
        ),
        (
            "P at ψ = -ψ0 (kPa)",
            fmt(g("p_minus_psi0_up_kpa"), 0),
            fmt(g("p_minus_psi0_down_kpa"), 0),
            "",
            fmt(g("model_p_minus_psi0_kpa"), 0),
            NA,
        ),
        (
            "Range of motion (deg)", "", "", fmt(g("range_deg"), 0), "",
            fmt(g("paper_range_deg"), 0),
        ),
        (
            "... over a pressure span of (kPa)",
            "",
            "",
            fmt(g("range_kpa"), 0),
            "",
            fmt(g("paper_range_kpa"), 0),
        ),
        ("Hysteresis width, max |ψ_up - ψ_down| (deg)", "", "", width, "", NA),
        ("k_P fitted to the rising leg [95 % CI] (-)", "", "", k_ci, "", fmt(g("k_p_paper"), 1)),
    )
    return Table(
        columns=(
            Column("Quantity", "left"),
            Column("increasing P"),
            Column("decreasing P"),
            Column("both"),
            Column("model"),
            Column("paper"),
        ),
        rows=rows,
        title=title,
        size=8.0,
        notes=(
            (
                "model: where the model's loading branch (the paper's k_P, this l0) reaches the "
                "angle, predicted, nothing fitted.  paper n/a: the paper reports no such value; "
                "another n/a: not reached within the run's pressures (or no model).  "
                + (
                    f"ψ0 = {fmt(g('psi0_deg'), 1)}°, the rest angle (the model's; for a "
                    "material it does not have, the mean ψ at the lowest rising pressure).  "
                    if fmt(g("psi0_deg"), 1) != NA
                    else ""
                )
                + "k_P is fitted, not predicted: the paper's value stands beside it for "
                "reference only."
            ),
            *extra_notes,
        ),
    )


def spread_of(data: ReportData, material: str) -> str:
    """What a material's mean and sd are over, in words: ``"3 actuators, 18 ramps"``, or ``"the
    2 ramps of one actuator"`` (the plotted photos: a lab's own beside synthetic ones)."""
    per = data.per_actuator[data.per_actuator["material"] == material]
    per = per[per["n"] > 0]  # an actuator none of whose photos is in a curve is no part of it
    if per.empty:
        return "no photo measured ok"
    n_act = int(per["actuator"].nunique())
    n_ramps = int(per.groupby("actuator")["n_trials"].max().sum()) if len(per) else 0
    ramps = f"{n_ramps} ramp{'s' if n_ramps != 1 else ''}"
    return f"the {ramps} of one actuator" if n_act == 1 else f"{n_act} actuators, {ramps}"


def plot_per_actuator(ax: Axes, data: ReportData, material: str, color: Color) -> None:
    """Mean psi of each actuator (over its trials): solid increasing, dashed decreasing pressure."""
    per = data.per_actuator[data.per_actuator["material"] == material]
    markers = "os^vD<>ph*"
    # each actuator its own colour (one colour for all, told apart by markers only, hid an
    # actuator's curve under another's: customer 22); the material's own for the first
    palette = [color, *[c for c in actuator_colors() if c != color]]
    for i, (actuator, g) in enumerate(per.groupby("actuator", sort=True)):
        own = palette[i % len(palette)]
        for direction, ls in (("up", "-"), ("down", "--")):
            b = g[g["direction"] == direction].sort_values("pressure_kpa")
            if b.empty:
                continue
            ax.plot(
                b["pressure_kpa"],
                b["psi_mean_deg"],
                linestyle=ls,
                marker=markers[i % len(markers)],
                markersize=2.5,
                linewidth=0.9,
                color=own if direction == "up" else lighter(own, 0.4),
                label=f"{actuator}" if direction == "up" else None,
            )
    ax.axhline(0.0, color="0.5", linewidth=0.6, zorder=0)
    ax.set_xlim(left=0.0)
    ax.set_xlabel(P_LABEL)
    ax.set_ylabel(PSI_LABEL)
    ax.set_title("Per actuator, mean over its trials (solid: increasing, dashed: decreasing P)")
    if len(per):
        ax.legend(
            title="actuator",
            loc="best",
            frameon=False,
            ncols=2 if per["actuator"].nunique() > 4 else 1,
        )


def draw_strip(fig: Figure, flow: Flow, strip: Strip | None) -> None:
    """Photos of one ramp in a row at the flow's position (down to its bottom), captioned with
    pressure and measured psi."""
    if strip is None or not strip.photos:
        flow.text(
            "No photos for this material (pass --photosets / --overlays to show a ramp).", size=8.0
        )
        return
    direction = "increasing" if strip.direction == "up" else "decreasing"
    video = len(set(strip.images)) == 1 and len(strip.photos) > 1  # frames of one video
    names = (
        f"frames of {strip.images[0]}"
        if video
        else f"files {strip.images[0]} to {strip.images[-1]}"
        if len(strip.images) > 1
        else f"file {strip.images[0]}"
    )
    flow.text(
        f"{'Frames' if video else 'Photos'} across one ramp (as Fig. 5): actuator "
        f"{strip.actuator_label}, trial {strip.trial}, {direction} pressure; {names}; "
        f"{strip.note}.",
        size=7.5,
    )
    flow.space(2.0)
    image, spans = strip_image(strip.photos, STRIP_PHOTO_PX, STRIP_GAP_PX)
    labels = [
        ("ψ: none" if not math.isfinite(photo.psi_deg) else f"ψ = {photo.psi_deg:.0f}°")
        + ("" if photo.status == "ok" else f" ({photo.status})")
        + (", photo not found" if photo.image is None else "")
        for photo in strip.photos
    ]
    lines = 2
    for _ in range(2):
        caption = lines * 7.5 * 1.32
        # pt per px
        scale = min(
            flow.width / image.shape[1], max(flow.remaining_pt - caption, 20.0) / image.shape[0]
        )
        # a caption wider than its photo (narrow portrait tiles at the foot of a full page)
        # would print over its neighbour's: the status then takes a line of its own
        narrowest = min(scale * (x1 - x0 + STRIP_GAP_PX) for x0, x1 in spans)
        if lines == 3 or max(len(t) for t in labels) * 0.55 * 7.5 <= narrowest:
            break
        lines = 3
    top = flow.y
    for (x0, x1), photo, label in zip(spans, strip.photos, labels, strict=True):
        x = flow.x + scale * (x0 + x1) / 2
        fig.text(
            x,
            top,
            f"{round(photo.pressure_kpa, 1):g} kPa",  # a frame's is interpolated: 21.3, not 21.3333
            transform=flow.transform,
            fontsize=7.5,
            ha="center",
            va="top",
        )
        fig.text(
            x,
            top + 7.5 * 1.32,
            label.replace(" (", "\n(", 1) if lines == 3 else label,
            transform=flow.transform,
            fontsize=7.5,
            ha="center",
            va="top",
            color="black" if photo.status == "ok" else "#b00000",
        )
    width, height = scale * image.shape[1], scale * image.shape[0]
    ax = fig.add_axes(
        (
            flow.x / flow.page_w,
            (flow.page_h - top - caption - height) / flow.page_h,
            width / flow.page_w,
            height / flow.page_h,
        )
    )
    ax.set_axis_off()
    ax.imshow(image, interpolation="none", aspect="auto")
    flow.y = top + caption + height


def single_photo_note(data: ReportData, material: str) -> str:
    """A sentence naming the levels of ``material`` that one photo alone reached (``n`` = 1 in
    the hysteresis table: drawn hollow, a value with no spread), else ``""``.

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> h = pd.DataFrame({"material": "DS30", "direction": ["up", "up", "up", "down"],
    ...                   "pressure_kpa": [160.0, 180.0, 200.0, 180.0], "n": [1, 4, 1, 1]})
    >>> single_photo_note(SimpleNamespace(hysteresis=h), "DS30")
    'Hollow points: one photo alone at 160 and 200 kPa rising, 180 kPa falling (n = 1, no spread).'
    """
    h = data.hysteresis[data.hysteresis["material"].astype(str) == material]
    if "n" not in h.columns:
        return ""
    said = []
    for direction, word in (("up", "rising"), ("down", "falling")):
        levels = sorted(h.loc[(h["n"] == 1) & (h["direction"] == direction), "pressure_kpa"])
        if levels:
            listed = [f"{p:g}" for p in levels]
            head = ", ".join(listed[:-1]) + " and " if len(listed) > 1 else ""
            said.append(f"{head}{listed[-1]} kPa {word}")
    if not said:
        return ""
    rows = data.angles if hasattr(data, "angles") else pd.DataFrame()
    if "material" in rows.columns:
        rows = rows[rows["material"].astype(str) == material]
    return f"Hollow points: {_alone(rows)} alone at {', '.join(said)} (n = 1, no spread)."


def _alone(angles: pd.DataFrame) -> str:
    """What a point with n = 1 is: one photo, or one video trial (the mean of its frames at that
    level; customer 27's read "one photo alone" for some 12 frames)."""
    frames = angles["frame"].notna() if "frame" in angles.columns else pd.Series(False)
    if not frames.any():
        return "one photo"
    return "one video trial (its frames' mean)" if frames.all() else "one photo or video trial"


def material_page(data: ReportData, material: str) -> Figure:
    """One material: Fig. 6 plot, per-actuator curves, comparison table, Fig. 5-style photo
    strip."""
    color = material_colors(data.materials)[material]
    mine = [(label, row) for m, label, row in comparisons(data) if m == material]
    label, row = mine[0]
    others = [
        f"{lab}: RMS {fmt(r.get('rms_deg'), 1)} deg, k_P fitted {fmt(r.get('k_p_fit'), 2)}"
        for lab, r in mine[1:]
    ]
    table = metric_table(
        row,
        title=f"{label}: this run beside the paper (rms.csv)",
        extra_notes=tuple(
            f"Also compared: {o} (all comparisons: the model-curve page)." for o in others
        )
        + tuple(n for n in (mixed_sources_note(data, material), single_photo_note(data, material))
                if n),
    )
    table_h = table_height_pt(table, 595.0 - 84.0)
    fig = page(label=f"material {material}", bottom_pt=table_h + STRIP_BAND_PT + 12.0)
    source = material_sources(data)[material]
    kind = {
        "synthetic": " (synthetic photos, rendered from the model)",
        "real + synthetic": " (real and synthetic photos)",
    }.get(source, "")
    fig.suptitle(
        f"{material}: bending angle versus pressure{kind}", color=color, fontweight="bold"
    )
    top, bottom = fig.subfigures(2, 1, squeeze=False, height_ratios=[1.45, 1.0])[:, 0]
    plot_hysteresis(
        top.subplots(),
        data,
        material,
        color,
        title=f"Mean ± 1 sd over {spread_of(data, material)} (as Fig. 6)"
        + ("; dashed: analytical model" if material in modelled_materials(data) else ""),
    )
    plot_per_actuator(bottom.subplots(), data, material, color)
    flow = Flow(fig, top_pt=72.0 * fig.get_figheight() - (22.0 + table_h + STRIP_BAND_PT + 6.0))
    flow.table(table)
    flow.space(4.0)
    draw_strip(fig, flow, build_strip(data, material))
    return fig


# ------------------------------------------------------------------------------------------
# all materials


def comparison_notes(data: ReportData) -> list[str]:
    """Sentences under the comparison table (what each figure is; what is fitted; self-checks
    named)."""
    notes = [
        (
            "RMS: the model's loading branch at the measured pressure levels against the mean "
            "curve.  Crossings: interpolated linearly along each ramp.  n/a: not reached by the "
            "mean curve, or not reported by the paper.  paper: what the paper reports for its "
            "own actuators over its own pressure span (its RMS: its model against its mean "
            "measured curve)."
        ),
        (
            "k_P is fitted to this run's photos at rising pressure, the model's loading branch "
            "(bootstrap interval over actuators; n/a with one): a fitted value, so its closeness "
            "to the paper's k_P is not evidence for the model."
        ),
    ]
    note = comparison_note(data)
    return notes + ([note] if note else []) + span_notes(data)


def span_notes(data: ReportData) -> list[str]:
    """Per material whose mean curve stops well short of the paper's pressure span: its range of
    motion is not comparable with the paper's, nor P at psi = 0 where the paper's lies beyond
    (customer 28 read a 0-160 kPa ramp's range of 135 deg beside the paper's 265 deg over 255 kPa
    as a shortfall).

    Examples
    --------
    >>> from types import SimpleNamespace
    >>> rms = pd.DataFrame({"material": ["SS40", "DS30"], "paper_range_kpa": [255.0, 175.0],
    ...                     "paper_p_zero_kpa": [215.0, 105.0]})
    >>> h = pd.DataFrame({"material": ["SS40"] * 2 + ["DS30"] * 2, "psi_mean_deg": 100.0,
    ...                   "pressure_kpa": [0.0, 160.0, 0.0, 150.0]})
    >>> for note in span_notes(SimpleNamespace(materials=["SS40", "DS30"], rms=rms, hysteresis=h)):
    ...     print(note)
    SS40: its mean curve reaches 160 kPa, the paper's 255 kPa: its range of motion is not \
comparable with the paper's, nor P at ψ = 0, which the paper finds at 215 kPa.
    DS30: its mean curve reaches 150 kPa, the paper's 175 kPa: its range of motion is not \
comparable with the paper's.
    """
    out = []
    for m in data.materials:
        g = rms_row(data, m)
        paper = float(g.get("paper_range_kpa", math.nan))
        h = data.hysteresis
        h = h[(h["material"].astype(str) == m) & np.isfinite(h["psi_mean_deg"].astype(float))]
        top = float(h["pressure_kpa"].max()) if len(h) else math.nan
        if not (math.isfinite(top) and math.isfinite(paper) and top < SPAN_SHORT * paper):
            continue
        p_zero = float(g.get("paper_p_zero_kpa", math.nan))
        out.append(
            f"{m}: its mean curve reaches {top:g} kPa, the paper's {paper:g} kPa: its range of "
            "motion is not comparable with the paper's"
            + (
                f", nor P at ψ = 0, which the paper finds at {p_zero:g} kPa."
                if math.isfinite(p_zero) and top < p_zero
                else "."
            )
        )
    return out


#: a run whose pressures reach less than this fraction of the paper's span is said to stop short
SPAN_SHORT = 0.9


def comparison_table(data: ReportData) -> Table:
    """Every rms.csv figure per material, beside the paper's."""
    colors = material_colors(data.materials)
    rows, row_colors = [], []
    for m, label, row in comparisons(data):
        g = row.get
        row_colors.append(colors[m])
        ci = (
            NA
            if fmt(g("k_p_fit"), 2) == NA
            else (f"{fmt(g('k_p_fit'), 2)} [{fmt(g('k_p_ci_low'), 2)}, {fmt(g('k_p_ci_high'), 2)}]")
        )
        width = fmt(g("hysteresis_width_deg"), 0)
        rows.append(
            (
                label,
                fmt(g("rms_deg"), 1),
                fmt(g("rms_up_deg"), 1),
                fmt(g("rms_down_deg"), 1),
                fmt(g("paper_rms_deg"), 1),
                fmt(g("p_zero_up_kpa"), 0),
                fmt(g("p_zero_down_kpa"), 0),
                fmt(g("paper_p_zero_kpa"), 0),
                fmt(g("p_minus_psi0_up_kpa"), 0),
                fmt(g("p_minus_psi0_down_kpa"), 0),
                fmt(g("range_deg"), 0),
                fmt(g("paper_range_deg"), 0),
                fmt(g("range_kpa"), 0),
                fmt(g("paper_range_kpa"), 0),
                width if width == NA else f"{width} at {fmt(g('hysteresis_width_at_kpa'), 0)}",
                ci,
                fmt(g("k_p_paper"), 1),
            )
        )
    return Table(
        columns=(
            Column("Material", "left"),
            Column("both"),
            Column("incr."),
            Column("decr."),
            Column("paper"),
            Column("incr."),
            Column("decr."),
            Column("paper"),
            Column("incr."),
            Column("decr."),
            Column("run"),
            Column("paper"),
            Column("run"),
            Column("paper"),
            Column("deg at kPa"),
            Column("fitted [95 % CI]"),
            Column("paper"),
        ),
        groups=(
            ("", 1),
            ("RMS vs model (deg)", 4),
            ("P at ψ = 0 (kPa)", 3),
            ("P at ψ = -ψ0 (kPa)", 2),
            ("Range (deg)", 2),
            ("Span (kPa)", 2),
            ("Hysteresis", 1),
            ("k_P (-)", 2),
        ),
        rows=tuple(rows),
        title="Every figure of rms.csv, one row per comparison (material and l0)",
        notes=tuple(comparison_notes(data)),
        size=8.0,
        row_colors=tuple(row_colors),
    )


def comparison_page(data: ReportData) -> Figure:
    """Table of RMS, crossings and range per material beside the paper's values, and bar charts."""
    materials = data.materials
    colors = material_colors(materials)
    table = comparison_table(data)
    width = 842.0 - 84.0
    table_h = table_height_pt(table, width)
    fig = page(landscape=True, label="comparison", top_pt=36.0 + 22.0 + table_h + 8.0)
    flow = Flow(fig, top_pt=36.0, width_pt=width)
    flow.text(
        "Model versus measurements, beside the values reported in the paper (Section III.A)",
        size=12.0,
        weight="bold",
    )
    flow.space(3.0)
    flow.table(table)
    axes = fig.subplots(1, 3)
    x = np.arange(len(materials))
    bars = (
        ("RMS against the model, both directions", "RMS (deg)", "rms_deg", "paper_rms_deg", 1),
        (
            "Pressure at ψ = 0 (increasing P)",
            "P at ψ = 0 (kPa)",
            "p_zero_up_kpa",
            "paper_p_zero_kpa",
            0,
        ),
        ("Total range of motion", "Range of motion (deg)", "range_deg", "paper_range_deg", 0),
    )
    for ax, (title, ylabel, ours_key, paper_key, _digits) in zip(axes, bars, strict=True):
        ours = np.array([float(rms_row(data, m).get(ours_key, math.nan)) for m in materials])
        paper = np.array([float(rms_row(data, m).get(paper_key, math.nan)) for m in materials])
        c = [colors[m] for m in materials]
        ax.bar(x - 0.2, np.nan_to_num(ours), width=0.4, color=c)
        ax.bar(
            x + 0.2,
            np.nan_to_num(paper),
            width=0.4,
            color=[lighter(v, 0.6) for v in c],
            hatch="///",
            edgecolor=[lighter(v, 0.2) for v in c],
            linewidth=0,
        )
        top = np.nanmax(np.concatenate([ours, paper, [1.0]]))
        for xi, v in zip(
            np.concatenate([x - 0.2, x + 0.2]), np.concatenate([ours, paper]), strict=True
        ):
            if not math.isfinite(v):
                ax.text(xi, 0.02 * top, NA, ha="center", va="bottom", fontsize=7.5, color="0.25")
        ax.set_ylim(0.0, top * 1.08)
        ax.set_xticks(x, materials)
        ax.set_xlabel("Material (left bar: this run; right, hatched: paper)")
        ax.set_ylabel(ylabel)
        ax.set_title(title)
        ax.grid(axis="x", visible=False)
    return fig
